"""How many CPU threads torch uses for a piece of work.

torch splits each operation over all cores. On a quiet machine that makes even a small solve
faster, but when another program keeps the cores busy, each operation waits for its slowest
thread, and a thread that is not scheduled holds up every step: a one-clip solve then takes
many times longer. So interactive work, up to :data:`SMALL_ROWS` rows (sequences × frames) per
step, runs on one thread: it gives up the second thread's gain on a quiet machine to stay fast on
a busy one. Larger work keeps torch's own setting. ``benchmarks/bench_threads.py`` prints both
sides of that trade, quiet and under load.

A batch job over many clips (``motionlab expand``) runs on one thread on the CPU whatever its
size (:func:`batch_threads`): it runs long and unattended, so a machine that turns busy while it
runs costs the most there; on a quiet machine it gives up the second thread's gain
(``benchmarks/bench_expand.py`` prints both; docs/performance.md).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import torch

__all__ = ["SMALL_ROWS", "batch_threads", "threads_for", "torch_threads"]

SMALL_ROWS = 8192
"""Rows (sequences × frames) per step up to which one thread is used: one clip of up to about two
minutes at 60 fps, the size of interactive work (the proportion sliders, ``retarget`` of a clip,
the demo)."""


def threads_for(rows: int) -> int:
    """Threads for work of ``rows`` rows per step: 1 up to :data:`SMALL_ROWS`, else torch's setting.

    Raises
    ------
    ValueError when ``rows`` < 0.
    """
    if rows < 0:
        raise ValueError(f"rows must be >= 0, got {rows}")
    return 1 if rows <= SMALL_ROWS else torch.get_num_threads()


def batch_threads(device: str | torch.device, requested: int | None = None) -> int:
    """Threads for a batch job over many clips on ``device``: ``requested`` when given (>= 1),
    else 1 on the CPU and torch's setting on other devices (module docstring).

    Raises
    ------
    ValueError when ``requested`` < 1.
    """
    if requested is not None:
        if requested < 1:
            raise ValueError(f"requested must be >= 1 thread, got {requested}")
        return requested
    return 1 if torch.device(device).type == "cpu" else torch.get_num_threads()


@contextlib.contextmanager
def torch_threads(count: int) -> Iterator[int]:
    """Run the block with torch on ``count`` threads, restoring the previous count afterwards.

    Raises
    ------
    ValueError when ``count`` < 1.
    """
    if count < 1:
        raise ValueError(f"count must be >= 1 thread, got {count}")
    before = torch.get_num_threads()
    if count != before:
        torch.set_num_threads(count)
    try:
        yield count
    finally:
        if torch.get_num_threads() != before:
            torch.set_num_threads(before)
