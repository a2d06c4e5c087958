"""The Ray backend of the structured build: the comparisons inside each style as Ray tasks.

Ray (https://docs.ray.io) is an optional extra: ``pip install "motionlab[cluster]"``.
``build_structured(..., backend="ray")`` (``motionlab graph-build --backend ray``) sends each
style's frames to one Ray task, which computes its takes' point clouds and the transition
candidates of every take with itself and with its neighbouring takes
(:func:`.structured.style_task`, which calls :func:`.structured.pool_pair_candidates` as the
local backend does). The calling
process keeps everything else (ports, pruning, links, the structure table) and reads the
answers in style order, so the graph equals the local build's, edge for edge.

Where Ray runs: ``address`` (or the ``RAY_ADDRESS`` environment variable) names an existing
cluster; without one, a local Ray instance with ``workers`` CPUs is started and shut down
afterwards.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from contextlib import contextmanager

__all__ = ["INSTALL_HINT", "START_TIMEOUT_S", "session", "pool_candidates"]

START_TIMEOUT_S = 600.0
"""How long :func:`session` keeps trying to start a local Ray instance, seconds."""

INSTALL_HINT = 'graph-build --backend ray needs Ray: pip install "motionlab[cluster]" (or pip install ray)'


def _ray():
    try:
        import ray
    except ImportError:
        raise ImportError(INSTALL_HINT) from None
    return ray


@contextmanager
def session(address: str | None = None, workers: int = 2):
    """Ray, initialised for the ``with`` block: the cluster at ``address`` (or ``RAY_ADDRESS``),
    else a local instance with ``workers`` CPUs, shut down at the end (a Ray already initialised
    by the caller is used as it is and left running).

    Raises ``ImportError`` saying how to install Ray, ``ValueError`` for ``workers < 1``."""
    ray = _ray()
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    address = address or os.environ.get("RAY_ADDRESS") or None
    started = not ray.is_initialized()
    if started:
        kw = dict(address=address) if address else dict(num_cpus=workers)
        _start(ray, dict(kw, include_dashboard=False, log_to_driver=False), START_TIMEOUT_S)
    try:
        yield ray
    finally:
        if started:
            ray.shutdown()


def _start(ray, kwargs: dict, timeout: float) -> None:
    """``ray.init(**kwargs)``, tried again while a local node misses Ray's own 30-second start
    window (a busy machine) until ``timeout`` seconds have passed."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            ray.init(**kwargs)
            return
        except Exception as e:  # Ray raises a bare Exception when its node starts too slowly
            ray.shutdown()
            if "timed out during startup" not in str(e) or time.monotonic() > deadline:
                raise


def pool_candidates(graph, pools: Sequence[tuple], ring_pairs: Callable, opt, task: Callable) -> Callable:
    """Submit one Ray task per style and return ``run(key, takes, pairs)``, which waits for that
    style's answer (:func:`.structured.pool_pair_candidates`) and returns it with ``None`` (the
    caller computes the port rows).

    ``pools``: ``(key, graph clip indices of its takes)`` in build order; ``ring_pairs(n,
    neighbours)``: the take pairs of a style of ``n`` takes; ``opt``: the build's options
    (``threshold``, ``window``, ``min_loop``, ``neighbours``); ``task(skeleton, rot, root, fps,
    lengths, pairs, threshold, window, min_loop)``: one style's candidates from its frames (a
    module-level function, :func:`.structured.style_task`). Needs :func:`session` active."""
    ray = _ray()
    task = ray.remote(num_cpus=1)(task)
    skeleton = ray.put(graph.skeleton)
    refs = {}
    for key, ks in pools:
        st, sp = graph.clips[ks[0]].start, graph.clips[ks[-1]].stop
        lengths = [graph.clips[c].num_frames for c in ks]
        refs[key] = task.remote(skeleton, graph.local_rot[st:sp], graph.root_pos[st:sp], graph.fps, lengths,
                                ring_pairs(len(ks), opt.neighbours), opt.threshold, opt.window, opt.min_loop)  # fmt: skip

    def run(key, ks, pairs):
        return ray.get(refs.pop(key)), None

    return run
