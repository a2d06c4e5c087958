"""The latent iteration as the solver of the bone-proportion sliders.

:class:`motionlab.viz.proportions.ProportionEditor` takes any ``solve(skeleton)`` callable, so
``viz`` needs no retargeting; this module gives the one that retargets by the latent iteration
(§2.2 of the retargeting paper, :func:`motionlab.retargeting.retarget`)::

    from motionlab.retargeting.proportions import proportion_solver
    from motionlab.viz.proportions import ProportionEditor

    editor = ProportionEditor(clip, solve=proportion_solver(clip, max_steps=30))

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

from collections.abc import Callable

from motionlab.core import humanoid
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = ["proportion_solver"]


def proportion_solver(
    source: Motion, method: str = "full", max_steps: int | None = None
) -> Callable[[Skeleton], tuple[Motion, dict]]:
    """``solve(skeleton) -> (Motion, history)``: ``source`` retargeted onto ``skeleton``.

    Parameters
    ----------
    source : the motion to retarget (any rig :func:`humanoid.find_mapping` knows; reduced to the
        22-joint humanoid once, here)
    method : ``"full"`` (the latent iteration), ``"network"`` or ``"copy"``, as in
        :func:`motionlab.retargeting.retarget`
    max_steps : step limit of the latent iteration (default: 100, 30 in ``MOTIONLAB_QUICK`` mode)

    Returns
    -------
    solve : callable; ``solve(skeleton)`` returns the motion on ``skeleton`` (a 22-joint
        humanoid) and the solver's loss history (``{"loss": [...], ...}``)

    Raises
    ------
    ValueError
        ``source`` is not a Motion, ``method`` is none of the three, or its rig does not map onto
        the humanoid.
    CheckpointError
        The shipped network cannot be loaded (``method`` other than ``"copy"``).
    """
    from motionlab import retargeting
    from motionlab.retargeting import pipeline
    from motionlab.settings import pick

    if not isinstance(source, Motion):
        raise ValueError(f"expected a Motion, got {type(source).__name__}")
    if method not in pipeline.METHODS:
        raise ValueError(f"method must be one of {pipeline.METHODS}, got {method!r}")
    if not humanoid.is_canonical(source.skeleton):
        source = humanoid.to_canonical(source)
    checkpoint = retargeting.load_default() if method != "copy" else None
    config = retargeting.SolverConfig(max_steps=max_steps if max_steps is not None else pick(100, 30))

    def solve(skeleton: Skeleton):
        result = retargeting.retarget(source, skeleton, checkpoint, method=method, solver=config)
        return result.motion, result.history

    return solve
