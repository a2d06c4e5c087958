"""Package-wide settings read from the environment.

``MOTIONLAB_DATA``
    folder of real BVH files (see :mod:`motionlab.data`).
``MOTIONLAB_CACHE``
    folder of the network trained on real motion on first use (default ``~/.cache/motionlab``;
    see :mod:`motionlab.retargeting.real`).
``MOTIONLAB_DEVICE``
    the torch device the retargeting network runs on when none is named (default: CUDA when
    available, else the CPU; see :mod:`motionlab.retargeting.devices`). The test suite sets it to
    ``cpu``: its known answers and the notebooks' stored outputs were made on the CPU.
``MOTIONLAB_QUICK``
    when set to 1/true/yes, notebooks and long-running demos use a reduced mode
    (fewer training steps, fewer clips) through the same code path. CI sets it.
"""

from __future__ import annotations

import os

__all__ = ["quick_mode", "pick"]

_TRUE = {"1", "true", "yes", "on"}


def quick_mode() -> bool:
    """True when ``MOTIONLAB_QUICK`` asks for the reduced (CI) mode."""
    return os.environ.get("MOTIONLAB_QUICK", "").strip().lower() in _TRUE


def pick(full, quick):
    """``quick`` in quick mode, ``full`` otherwise: ``steps = pick(2000, 50)``."""
    return quick if quick_mode() else full
