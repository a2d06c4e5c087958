"""The host's share of a database expansion, in worker processes, so that a GPU does not wait.

Reading, preparing, checking and writing a pair (BVH text, resampling, features, forward
kinematics, the plausibility checks) is CPU work done pair by pair, while a GPU solves a whole
batch at once (``docs/performance.md`` gives the split of the time). :func:`pool` starts worker
processes for that work; :func:`motionlab.retargeting.expand.expand` plans its batches from the
BVH headers, has the workers read and prepare the clips in the order the batches need them, and
solves each batch as soon as its clips are ready, while the workers prepare the next ones and
finish and encode the outputs of the last. A clip that no worker has started when its batch
needs it (the workers take seconds to start) is prepared in this process instead. Each worker
holds a CPU copy of the checkpoint (:func:`checkpoint`): preparing a clip needs its feature
statistics, frame rate and float type. The workers are forked from a fresh
server process that has imported motionlab once (``forkserver``), never from this one, which is
safe beside CUDA. Results are the same as in one process (a test checks it).
"""

from __future__ import annotations

import copy
import dataclasses
import multiprocessing
import os
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

import torch

from motionlab.retargeting.checkpoint import Checkpoint

__all__ = ["MAX_WORKERS", "default_workers", "pool", "checkpoint", "cpu_copy"]

MAX_WORKERS = 4
"""Most worker processes :func:`default_workers` starts. The host's share is small beside the
solve and its results come back through one pipe, so more workers do not load faster; they take
cores from the thread that launches the GPU's kernels (``docs/performance.md`` measures 2 to 15)."""

_CHECKPOINT: Checkpoint | None = None


def default_workers(device: str | torch.device) -> int:
    """0 on the CPU (its cores run the latent iteration); on a GPU every core but one, at most
    :data:`MAX_WORKERS`."""
    if torch.device(device).type == "cpu":
        return 0
    return max(0, min(MAX_WORKERS, (os.cpu_count() or 1) - 1))


def _start(cpu_checkpoint: Checkpoint) -> None:
    global _CHECKPOINT
    torch.set_num_threads(1)  # many workers: one thread each
    _CHECKPOINT = cpu_checkpoint


def checkpoint() -> Checkpoint | None:
    """This worker's CPU copy of the checkpoint (None outside a worker)."""
    return _CHECKPOINT


def cpu_copy(checkpoint: Checkpoint) -> Checkpoint:
    """``checkpoint`` with a copy of its network on the CPU (what a worker holds)."""
    return dataclasses.replace(checkpoint, model=copy.deepcopy(checkpoint.model).cpu())


@contextmanager
def pool(checkpoint: Checkpoint, workers: int) -> Iterator[Executor | None]:
    """``workers`` processes holding a CPU copy of ``checkpoint``; None when ``workers`` < 1
    (the caller then does the work itself)."""
    if workers < 1:
        yield None
        return
    cpu = cpu_copy(checkpoint)
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(["motionlab.retargeting.expand"])
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_start, initargs=(cpu,)) as executor:
        yield executor
