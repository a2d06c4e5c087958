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

    def my_conj(q):
        ...
    exercises.conj.check(my_conj)          # ✓ my_conj is right on 3 cases

The named exercises, by notebook (each module holds its exercises' cases, references and
typical mistakes):

* :mod:`~motionlab.exercises.basics`: 00 ``conj``, ``slerp``, ``hand_height``; 01 ``heading``,
  ``window_count``; 04 ``pose_error``, ``joint_speed``;
* :mod:`~motionlab.exercises.retargeting`: 02 ``recon_loss``, ``combine``, ``rotations``;
  03 ``foot_loss``, ``root_scale``, ``angle_loss``;
* :mod:`~motionlab.exercises.motion_graphs`: 05 ``local_minima``, ``distance_matrix``.

Experiments (:class:`Question`: change a parameter, run the experiment, type the number it gives;
the check reruns it on the notebook's own inputs): 03 ``foot_weight`` (λ_foot in the paper's
set-up), 06 ``held_out_q`` (q by likelihood on truly held-out frames), ``walk_spacing`` (the
paper's walk experiment with key frames further apart) and ``smallest_gap`` (the fewest dropped
frames the stream-against-itself rule finds), 05
``vanishing_threshold`` (the graph threshold at which a style leaves the pruned standard graph).

Their reference solutions, as a student would write them, are in ``instructor/solutions/`` (the
instructor's key, outside the students' ``notebooks/`` folder), and ``tests/test_exercises.py`` runs every check against the key, typical wrong
answers and an alternative correct answer. :func:`check` is the same machinery for ad-hoc checks
(:mod:`~motionlab.exercises.core`).
"""

from __future__ import annotations

from .basics import conj, hand_height, heading, joint_speed, pose_error, slerp, window_count
from .core import Exercise, Mistake, Question, Result, check
from .interpolation import held_out_q, smallest_gap, walk_spacing
from .motion_graphs import distance_matrix, local_minima, vanishing_threshold
from .retargeting import angle_loss, combine, foot_loss, foot_weight, recon_loss, root_scale, rotations

__all__ = [
    "Exercise",
    "Mistake",
    "Question",
    "Result",
    "check",
    "conj",
    "slerp",
    "hand_height",
    "heading",
    "window_count",
    "pose_error",
    "joint_speed",
    "recon_loss",
    "combine",
    "rotations",
    "foot_loss",
    "root_scale",
    "angle_loss",
    "local_minima",
    "distance_matrix",
    "foot_weight",
    "held_out_q",
    "walk_spacing",
    "smallest_gap",
    "vanishing_threshold",
    "EXERCISES",
    "EXPERIMENTS",
]

EXERCISES: dict[str, Exercise] = {
    "conj": conj,
    "slerp": slerp,
    "hand_height": hand_height,
    "heading": heading,
    "window_count": window_count,
    "pose_error": pose_error,
    "joint_speed": joint_speed,
    "recon_loss": recon_loss,
    "combine": combine,
    "rotations": rotations,
    "foot_loss": foot_loss,
    "root_scale": root_scale,
    "angle_loss": angle_loss,
    "local_minima": local_minima,
    "distance_matrix": distance_matrix,
}
"""Every named exercise of the notebooks that asks for a function, by the attribute name the notebooks use.

:meta hide-value:
"""

EXPERIMENTS: dict[str, Question] = {
    "foot_weight": foot_weight,
    "held_out_q": held_out_q,
    "walk_spacing": walk_spacing,
    "smallest_gap": smallest_gap,
    "vanishing_threshold": vanishing_threshold,
}
"""Every experiment exercise (a :class:`Question`: change a parameter, run, report a number).

:meta hide-value:
"""
