"""Check cells for the notebooks' exercises.

Every exercise asks the student to write a small function. Its check runs the student's
function and a reference on the same inputs and answers in one line, without ever stopping the
notebook:

* ``✓`` the answer agrees (with the reference, or with another correct convention the exercise
  accepts, e.g. a forward difference where the reference uses a central one);
* ``…`` the stub still raises ``NotImplementedError``: the exercise is not attempted yet, and
  *Run All* goes on to the next cell;
* ``✗`` the answer disagrees. When it matches a *typical mistake* the exercise knows about, the
  message gives that mistake's hint (what to look at, never the solution); otherwise it says
  which case failed and by how much, without printing the expected value.

Put the check last in its cell: the returned :class:`Result` displays as its message::

    def my_window_count(num_frames, window=120, stride=30):
        ...
    exercises.window_count.check(my_window_count)   # ✓ my_window_count is right on 7 case(s)

The named exercises, by notebook (each module holds its exercises' cases, references and
typical mistakes):

* :mod:`~motionlab.exercises.basics`: 00 ``hand_height``; 01 ``window_count``; 04 ``joint_speed``;
* :mod:`~motionlab.exercises.retargeting`: 03 ``contact_loss``;
* :mod:`~motionlab.exercises.motion_graphs`: 05 ``local_minima``.

Experiments (:class:`Question`: change a parameter, run the experiment, type the number it gives;
the check reruns it on the notebook's own inputs): 00 ``nlerp_turn`` (the largest turn nlerp
takes at nearly constant speed), ``euler_order`` (the same angles in another channel order); 00b
``reader_order`` (a reader that ignores the channel order); 01 ``hips_heading``
(the heading from the hips alone); 02 ``q_delta_legs`` (how much q_Δ changes on shorter legs),
``no_correction`` (decoding without q_Δ); 03 ``encoder_start`` (motionlab without the
Gauss–Newton start), ``contact_weight`` (a fifth of the contact weight), ``foot_weight`` (λ_foot in
the paper-like set-up), ``theta_directions`` (θ as bone directions); 04 ``shorter_legs`` (whether
copying's pose error follows the change of leg length); 05 ``style_change``
(the ``dwell`` at which a style change lasts a gait cycle), ``vanishing_threshold`` (the graph
threshold at which a style leaves the pruned standard graph), ``transition_clip`` (what joins two
behaviours without their recorded transition clip); 06 ``held_out_q`` (q by likelihood on truly
held-out frames), ``walk_spacing`` (how far apart the walk experiment's key frames may be),
``smallest_gap`` (the fewest dropped frames the stream-against-itself rule finds), ``key_frames``
(what searching transitions between key frames only costs); 07
``arm_length`` (how low a longer arm reaches under the floor).

Their reference solutions, as a student would write them, are in ``instructor/solutions/`` (the
instructor's key, outside the students' ``notebooks/`` folder), and ``tests/test_exercises.py`` runs every check against the key, typical wrong
answers and an alternative correct answer. :func:`check` is the same machinery for ad-hoc checks
(:mod:`~motionlab.exercises.core`).
"""

from __future__ import annotations

from .basics import (
    euler_order,
    hand_height,
    hips_heading,
    joint_speed,
    nlerp_turn,
    reader_order,
    shorter_legs,
    window_count,
)
from .core import Exercise, Mistake, Question, Result, check
from .interpolation import held_out_q, key_frames, smallest_gap, walk_spacing
from .motion_graphs import local_minima, style_change, transition_clip, vanishing_threshold
from .retargeting import (
    arm_length,
    contact_loss,
    contact_weight,
    encoder_start,
    foot_weight,
    no_correction,
    q_delta_legs,
    theta_directions,
)

__all__ = [
    "Exercise",
    "Mistake",
    "Question",
    "Result",
    "check",
    "hand_height",
    "window_count",
    "joint_speed",
    "contact_loss",
    "local_minima",
    "nlerp_turn",
    "euler_order",
    "hips_heading",
    "shorter_legs",
    "q_delta_legs",
    "no_correction",
    "encoder_start",
    "contact_weight",
    "foot_weight",
    "held_out_q",
    "walk_spacing",
    "smallest_gap",
    "vanishing_threshold",
    "style_change",
    "arm_length",
    "reader_order",
    "theta_directions",
    "transition_clip",
    "key_frames",
    "EXERCISES",
    "EXPERIMENTS",
]

EXERCISES: dict[str, Exercise] = {
    "hand_height": hand_height,
    "window_count": window_count,
    "joint_speed": joint_speed,
    "contact_loss": contact_loss,
    "local_minima": local_minima,
}
"""Every named exercise of the notebooks that asks for a function, by the attribute name the notebooks use.

:meta hide-value:
"""

EXPERIMENTS: dict[str, Question] = {
    "nlerp_turn": nlerp_turn,
    "euler_order": euler_order,
    "hips_heading": hips_heading,
    "shorter_legs": shorter_legs,
    "q_delta_legs": q_delta_legs,
    "no_correction": no_correction,
    "encoder_start": encoder_start,
    "contact_weight": contact_weight,
    "foot_weight": foot_weight,
    "held_out_q": held_out_q,
    "walk_spacing": walk_spacing,
    "smallest_gap": smallest_gap,
    "vanishing_threshold": vanishing_threshold,
    "style_change": style_change,
    "arm_length": arm_length,
    "reader_order": reader_order,
    "theta_directions": theta_directions,
    "transition_clip": transition_clip,
    "key_frames": key_frames,
}
"""Every experiment exercise (a :class:`Question`: change a parameter, run, report a number).

:meta hide-value:
"""
