"""One step of the latent iteration as a CUDA graph: its hundreds of kernels launched as one.

On a GPU the batched latent iteration (:mod:`motionlab.retargeting.solver`) is bound by kernel
launches, not by arithmetic: one step (decode, every loss term, the gradient, the stopping rule
and Adam's update) is hundreds of small kernels, and launching them from Python takes longer than
the GPU takes to run them (``docs/performance.md`` has the profile). A CUDA graph records those
kernels once and replays them with one launch. The step then has to be the same every time: the
same tensors (updated in place), the same shapes (every row of the batch, also rows whose problem
has stopped: they are masked, :mod:`.device_loop`) and nothing that waits for the device.

:class:`StepGraph` records a step on CUDA and replays it; elsewhere it runs the same step eagerly,
so the CPU exercises the same all-rows arithmetic. Three tests check on the CPU what a GPU would
otherwise find out: the step gives the solver's host loop's numbers; it reads nothing back from
the device and copies nothing from the host (a graph could not record either); and replayed as a
graph replays it (``tests/retargeting/replay.py`` re-runs the recorded aten ops on the same
tensors) it gives the eager step's numbers, so it depends on no Python number, no tensor replaced
between steps and no state left out of ``keep``.

**On by default on CUDA**; ``MOTIONLAB_CUDA_GRAPHS=0`` switches it off (:func:`enabled`): the
iteration then runs the host loop, as on the CPU, and ``benchmarks/gpu_check.sh`` (stage
``eager``) measures the one against the other.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Sequence

import torch

__all__ = ["enabled", "StepGraph"]

WARMUP = 3
"""Eager runs of the step on a side stream before it is recorded (as torch's CUDA graph notes ask)."""


def enabled(device: str | torch.device) -> bool:
    """Whether the iteration on ``device`` replays its step as a CUDA graph: on CUDA devices unless
    the environment sets ``MOTIONLAB_CUDA_GRAPHS=0``.

    Raises
    ------
    ValueError when ``MOTIONLAB_CUDA_GRAPHS`` is set to anything but ``0`` or ``1``.
    """
    value = os.environ.get("MOTIONLAB_CUDA_GRAPHS") or "1"
    if value not in ("0", "1"):
        raise ValueError(f"MOTIONLAB_CUDA_GRAPHS must be 0 (off) or 1 (on, the default), got {value!r}")
    return value == "1" and torch.device(device).type == "cuda"


class StepGraph:
    """``step()`` (the losses and ``leaf``'s gradient, nothing that waits for the device) recorded
    once on CUDA, replayed by :meth:`run`.

    :meth:`run` returns the recorded outputs: the same tensors each time, overwritten by the next
    run (read or copy them first). ``leaf.grad`` is likewise one tensor that every run overwrites;
    it may be changed in place between runs, never replaced. Off CUDA, or when recording fails
    (with a warning), :meth:`run` calls ``step`` eagerly after clearing ``leaf.grad``.

    ``keep``: tensors that ``step`` changes in place (a state it carries from step to step); the
    warm-up runs before recording leave them as they were.
    """

    def __init__(self, step: Callable[[], tuple], leaf: torch.Tensor, keep: Sequence[torch.Tensor] = ()) -> None:
        self._step, self._leaf, self._graph, self._out, self._keep = step, leaf, None, None, list(keep)
        if leaf.device.type == "cuda":
            try:
                self._record()
            except RuntimeError as err:  # an operation that cannot be recorded: run eagerly
                self._graph = None
                warnings.warn(f"the latent iteration runs without a CUDA graph: {err}", RuntimeWarning, stacklevel=3)

    def _record(self) -> None:
        device = self._leaf.device
        with torch.no_grad():
            saved = [t.clone() for t in self._keep]  # on the current stream, before the side one waits for it
        side = torch.cuda.Stream(device=device)
        side.wait_stream(torch.cuda.current_stream(device))
        try:
            with torch.cuda.stream(side):
                for _ in range(WARMUP):
                    self._leaf.grad = None
                    self._step()
        finally:  # the state as it was, also when a warm-up run fails
            torch.cuda.current_stream(device).wait_stream(side)
            with torch.no_grad():
                for t, before in zip(self._keep, saved):
                    t.copy_(before)
        self._leaf.grad = None
        graph = torch.cuda.CUDAGraph()
        with torch.cuda.graph(graph):
            out = self._step()
        self._graph, self._out = graph, out

    @property
    def recorded(self) -> bool:
        """True when :meth:`run` replays a CUDA graph."""
        return self._graph is not None

    def run(self) -> tuple:
        """One step: the outputs of ``step()``, with ``leaf.grad`` holding the gradient."""
        if self._graph is None:
            self._leaf.grad = None
            return self._step()
        self._graph.replay()
        return self._out
