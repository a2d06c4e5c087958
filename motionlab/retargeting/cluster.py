"""The Ray backend of :func:`motionlab.retargeting.expand.expand`.

Ray (https://docs.ray.io) is an optional extra: ``pip install "motionlab[cluster]"``.
``expand(..., backend="ray")`` starts ``workers`` Ray *actors*; each receives the checkpoint
once (through Ray's object store, so the workers need no shared file system) and solves whole
batches with :func:`motionlab.retargeting.batching.solve_pairs`, the function the local backend
calls. The batches are those the local backend would run, and every sequence's numbers do not
depend on its batch, so the outputs equal the local backend's. Only the calling process writes
files and the manifest, so resumption and atomic writes work as in the local backend.

Where Ray runs: ``address`` (or the ``RAY_ADDRESS`` environment variable) names an existing
cluster (``ray start --head`` on one machine, ``ray start --address=HEAD:6379`` on the others);
without one, a local Ray instance with ``workers`` CPUs is started and shut down afterwards.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import replace
from pathlib import Path

from motionlab.retargeting import checkpoint as ck
from motionlab.retargeting.batching import Pair, PairResult, solve_pairs
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.solver import SolverConfig

__all__ = ["INSTALL_HINT", "require_ray", "solve_batches_ray"]

INSTALL_HINT = 'the Ray backend needs Ray: pip install "motionlab[cluster]" (or pip install ray)'


def require_ray():
    """The ``ray`` module, or ``ImportError`` saying how to install it.

    Raises
    ------
    ImportError saying how to install ray.
    """
    try:
        import ray
    except ImportError:
        raise ImportError(INSTALL_HINT) from None
    return ray


def _checkpoint_bytes(checkpoint: Checkpoint) -> bytes:
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "net.pt"
        ck.save(path, checkpoint)
        return path.read_bytes()


def _placement(checkpoint: Checkpoint) -> tuple[str, str]:
    """``(device type, float type name)`` of the caller's network: where each actor loads its copy
    (Ray shows an actor its own GPU(s) as ``cuda:0``)."""
    return checkpoint.device.type, next(name for name, t in ck.DTYPES.items() if t == checkpoint.dtype)


class _Worker:
    """One Ray actor: the checkpoint loaded once, on the caller's device type and float type, then
    :func:`solve_pairs` per batch."""

    def __init__(self, blob: bytes, threads: int, device: str, dtype: str) -> None:
        import torch

        torch.set_num_threads(threads)
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "net.pt"
            path.write_bytes(blob)
            self.checkpoint = ck.load(path, device, dtype)

    def solve(self, pairs: list[Pair], solver: SolverConfig, root_mode: str) -> list[PairResult]:
        return solve_pairs(self.checkpoint, pairs, solver, root_mode)


def solve_batches_ray(
    checkpoint: Checkpoint,
    batches: Sequence[Sequence[Pair]],
    solver: SolverConfig,
    root_mode: str,
    address: str | None = None,
    workers: int = 2,
) -> Iterator[list[PairResult]]:
    """Solve ``batches`` on Ray actors; yields each batch's results as it completes.

    Each actor runs the network on the checkpoint's device type and float type: on a GPU the
    actors share the caller's GPU (``num_gpus = 1 / workers`` each), on the CPU one core each.

    Raises
    ------
    ImportError without Ray; ValueError when ``workers`` < 1.
    """
    ray = require_ray()
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    address = address or os.environ.get("RAY_ADDRESS") or None
    started = False
    if not ray.is_initialized():
        if address:
            ray.init(address=address, include_dashboard=False, log_to_driver=False)
        else:
            ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
        started = True
    try:
        device, dtype = _placement(checkpoint)
        gpus = 1.0 / workers if device == "cuda" else 0
        actor = ray.remote(num_cpus=1, num_gpus=gpus)(_Worker)
        blob = ray.put(_checkpoint_bytes(checkpoint))
        pool = [actor.remote(blob, 1, device, dtype) for _ in range(workers)]
        pending = {}
        queue = [[replace(p, prepared=None) for p in b] for b in batches]  # workers prepare sources themselves
        free = list(pool)
        while queue or pending:
            while queue and free:
                a = free.pop()
                pending[a.solve.remote(queue.pop(0), solver, root_mode)] = a
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                free.append(pending.pop(ref))
                yield ray.get(ref)
    finally:
        if started:
            ray.shutdown()
