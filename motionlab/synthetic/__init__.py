"""Built-in synthetic motion: procedural humanoid clips and random characters, no downloads.

* :mod:`~motionlab.synthetic.gaits` — :func:`generate` one behaviour (idle, walk, run, jump,
  squat) or a :func:`sequence` of them with smooth transitions, on any 22-joint character;
* :mod:`~motionlab.synthetic.style` — :class:`Style`, the knobs (stride, cadence, bounce, arm
  swing, crouch, lean, …) and their defaults per behaviour;
* :mod:`~motionlab.synthetic.characters` — random humanoids with other proportions;
* :mod:`~motionlab.synthetic.clips` — :func:`dataset`, a varied set of clips on one character;
* :mod:`~motionlab.synthetic.ik` — analytic two-bone IK.

Inside, one step each: :mod:`~.timeline` (segments → blended per-frame parameters, scheduled
jumps and squats), :mod:`~.footsteps` (where and when each foot is planted),
:mod:`~.actions` (the jump and squat programmes), :mod:`~.body` (pelvis, IK legs, spine, arms).

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from motionlab.synthetic import ik
from motionlab.synthetic.characters import Character, character_set, random_character
from motionlab.synthetic.clips import dataset
from motionlab.synthetic.gaits import generate, sequence
from motionlab.synthetic.style import BEHAVIOURS, Style, default_style, random_style

ROOT_MODE = "legs"
"""The retargeting root rule that matches this generator (``retarget(..., root_mode=ROOT_MODE)``):
it makes every stride ``style.stride × (thigh + shin)`` long and puts the pelvis at the height the
legs reach, so B's path is A's scaled by the thigh + shin ratio. Mixamo's retargets follow the
leg chain instead (the pipeline's default, ``"stride"``); compare with a reference made the same way."""

__all__ = [
    "ROOT_MODE",
    "BEHAVIOURS",
    "Style",
    "default_style",
    "random_style",
    "generate",
    "sequence",
    "Character",
    "random_character",
    "character_set",
    "dataset",
    "ik",
]
