"""The simple baseline every retargeting result is compared with: copy the rotations.

Copy-rotation puts A's local joint rotations unchanged on B's skeleton and scales A's root
trajectory by B/A leg sizes (see :mod:`motionlab.retargeting.pipeline` for the root policy).
Because Mixamo keeps most local rotations when it retargets, this is a strong baseline on the
shared data; its weakness is the feet (they sink or float when the legs' proportions differ).

The other baseline, the network without iteration, is ``retarget(..., method="network")``.

Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = ["copy_rotation"]


def copy_rotation(source: Motion, target: Skeleton | Motion, root_mode: str = "legs") -> Motion:
    """A's local rotations on B's canonical skeleton, root trajectory scaled by ``root_mode``.

    ``"legs"`` (default): every axis by thigh + shin, the plain baseline of the data notes;
    ``"stride"`` and ``"hips"``: see :mod:`motionlab.retargeting.pipeline`.

    Returns a Motion on B's canonical 22-joint skeleton (at A's frame rate).
    """
    from motionlab.retargeting.pipeline import retarget

    return retarget(source, target, None, method="copy", root_mode=root_mode).motion
