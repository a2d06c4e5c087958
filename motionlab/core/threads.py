"""How many CPU threads torch uses for a piece of work.

torch splits each operation over all cores. For the small tensors of an interactive solve (one
clip of a few hundred frames) the threads spend more time waiting for each other than
computing, and when another program keeps the cores busy a waiting thread may not be scheduled
for a whole time slice: the same solve then takes several times longer. So work below
:data:`SMALL_ROWS` rows per step runs on one thread; larger work keeps torch's own setting.
The threshold and the measurements behind it are printed by ``benchmarks/bench_threads.py``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import torch

__all__ = ["SMALL_ROWS", "threads_for", "torch_threads"]

SMALL_ROWS = 8192
"""Rows (sequences × frames) per step up to which one thread is used."""


def threads_for(rows: int) -> int:
    """Threads for work of ``rows`` rows per step: 1 up to :data:`SMALL_ROWS`, else torch's setting."""
    if rows < 0:
        raise ValueError(f"rows must be >= 0, got {rows}")
    return 1 if rows <= SMALL_ROWS else torch.get_num_threads()


@contextlib.contextmanager
def torch_threads(count: int) -> Iterator[int]:
    """Run the block with torch on ``count`` threads, restoring the previous count afterwards."""
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
