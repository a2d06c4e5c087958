"""Where a GPU expansion spends its solve time, and what replaying each step as a CUDA graph saves (issue 40).

Prepares all of Aj's clips × the six Table 1 characters as ``expand`` does (host workers), plans
the padded batches, solves the smallest once to warm the device up (not timed), then times the
latent iteration of every batch (``batching.solve_jobs``, device synchronised) with its step
replayed as a CUDA graph (``MOTIONLAB_CUDA_GRAPHS=1``, :mod:`motionlab.retargeting.graphs`),
launched eagerly (``MOTIONLAB_CUDA_GRAPHS=0``), and as a graph again (the default on CUDA). Then it
profiles the batch with the most rows: Python (cProfile, top functions by own time) and the device (``torch.profiler``: top
operators by device time, kernel launches per step) and, on CUDA, the split of its solve into the graph
replays' device time (CUDA events) and the rest (``--widest-only`` skips the three timings of every
batch). Results of the variants are compared with
the first run's (largest joint difference, cm). On a GPU it first splits ``expand``'s load time:
preparing the clips in one process, and in pools of workers (start, prepare, shut down).

Usage::

    MOTIONLAB_DATA=/path/to/data python benchmarks/profile_expand_gpu.py [--clips N] [--device cuda]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import pstats
import time

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.retargeting import batching, host, solver
from motionlab.retargeting import expand as ex
from motionlab.retargeting.evaluate import DEFAULT_TARGETS


def _jobs(clips: int) -> list:
    """``prepare_clip``'s arguments (but the checkpoint) for the first ``clips`` of Aj's clips."""
    root = data.data_root() / "mixamo"
    chars = ex.characters(*[f"{n}={root / n / 'Running.bvh'}" for n in DEFAULT_TARGETS])
    targets = [(c.name, c.skeleton) for c in chars]
    return [(p, None, targets, "stride", solver.SolverConfig()) for p in sorted((root / "Aj").glob("*.bvh"))[:clips]]


def _pairs(ckpt, clips: int):
    with host.pool(ckpt, host.default_workers(ckpt.device)) as pool:
        args = _jobs(clips)
        prepared = [pool.submit(ex.prepare_clip, *a) for a in args] if pool else args
        pairs = []
        for a, f in zip(args, prepared):
            motion, prep, _, jobs = f.result() if pool else ex.prepare_clip(*f, ckpt)
            pairs += [batching.Pair(a[0].stem, n, motion, s, prep.motion.num_frames, prep, jobs[n]) for n, s in a[2]]
    return pairs


def _host_split(ckpt, clips: int) -> None:
    """Where ``expand``'s load time goes: preparing the clips in this process, and in pools of
    workers (starting the pool, then preparing and sending the results back)."""
    args = _jobs(clips)
    clock = time.perf_counter()
    for a in args:
        ex.prepare_clip(*a, ckpt)
    line = [f"in this process {time.perf_counter() - clock:.1f} s"]
    for workers in sorted({host.default_workers(ckpt.device), 4} - {0}):
        clock = time.perf_counter()
        with host.pool(ckpt, workers) as pool:
            pool.submit(int).result()  # every worker need not be up: the pool starts them as work comes
            started = time.perf_counter()
            for f in [pool.submit(ex.prepare_clip, *a) for a in args]:
                f.result()
            done = time.perf_counter()
        line.append(f"{workers} workers: first up {started - clock:.1f} s, prepare {done - started:.1f} s, "
                    f"shut down {time.perf_counter() - done:.1f} s")  # fmt: skip
    print(f"host: preparing {len(args)} clips " + "; ".join(line))


def _sync(device):
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def _run(ckpt, batches):
    out, seconds = [], []
    for b in batches:
        _sync(ckpt.device)
        start = time.perf_counter()
        out += batching.solve_jobs(ckpt, [p.job for p in b])
        _sync(ckpt.device)
        seconds.append(time.perf_counter() - start)
    return out, seconds


def _replay_share(ckpt, batch) -> None:
    """The widest batch's solve split into the device time of the graph's replays (CUDA events; a
    replay holds the whole step, its rules and Adam's update included, :mod:`.device_loop`) and
    everything else (the start, recording the graph, the host's loop and its waits)."""
    from motionlab.retargeting import graphs

    run, spans = graphs.StepGraph.run, []

    def timed(self):
        begin, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        begin.record()
        out = run(self)
        end.record()
        spans.append((begin, end))
        return out

    graphs.StepGraph.run = timed
    try:
        _sync(ckpt.device)
        clock = time.perf_counter()
        res = batching.solve_jobs(ckpt, [p.job for p in batch])
        _sync(ckpt.device)
        wall = time.perf_counter() - clock
    finally:
        graphs.StepGraph.run = run
    replay = sum(b.elapsed_time(e) for b, e in spans) / 1000
    steps = max(r.steps for r in res)
    print(f"widest batch ({len(batch)} rows x {batch[0].frames} frames): solve {wall:.2f} s, {len(spans)} replays "
          f"{replay:.2f} s on the device ({1000 * replay / len(spans):.1f} ms each), the rest {wall - replay:.2f} s "
          f"({1000 * (wall - replay) / max(steps, 1):.1f} ms per step)")  # fmt: skip


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--clips", type=int, default=1000, help="first N of Aj's clips (default: all)")
    p.add_argument("--device", default="cuda")
    p.add_argument("--dtype", default="float64", choices=("float64", "float32"))
    p.add_argument("--rows", type=int, default=12, help="operators shown in each device profile (default 12)")
    p.add_argument("--widest-only", action="store_true", help="skip timing every batch three ways")
    args = p.parse_args(argv)
    ckpt = retargeting.load_default(args.device, args.dtype)
    if ckpt.device.type != "cpu":
        _host_split(ckpt, args.clips)
    clock = time.perf_counter()
    pairs = _pairs(ckpt, args.clips)
    batches = batching.plan_batches(pairs, batching.batch_frames(ckpt.device), pad=True)
    frames = sum(p.frames for p in pairs)
    print(f"{len(pairs)} pairs, {frames} frames prepared in {time.perf_counter() - clock:.1f} s; batches (rows x frames): "
          + ", ".join(f"{len(b)}x{b[0].frames}" for b in batches))  # fmt: skip
    _run(ckpt, batches[-1:])  # warm-up (kernel loading, cuDNN's choice of algorithms): not timed
    variants = [("step as a CUDA graph", "1"), ("step launched eagerly", "0"), ("step as a CUDA graph, again", "1")]
    variants = variants[:0] if args.widest_only else variants
    reference = None  # A, B, A: a drift between runs shows as a difference between the two A runs
    for name, graphs_on in variants:
        os.environ["MOTIONLAB_CUDA_GRAPHS"] = graphs_on
        out, seconds = _run(ckpt, batches)
        pos = np.concatenate([r.positions[0].reshape(-1) for r in out])
        diff = "" if reference is None else f"; vs the first {100 * np.abs(pos - reference).max():.2g} cm"
        reference = pos if reference is None else reference
        steps = max(r.steps for r in out)
        print(f"{name:<29} solve {sum(seconds):6.2f} s = {frames / sum(seconds):7.0f} frames/s; per batch "
              + " ".join(f"{s:.2f}" for s in seconds) + f"; most steps {steps}{diff}")  # fmt: skip
    os.environ.pop("MOTIONLAB_CUDA_GRAPHS", None)
    widest = max(batches, key=len)
    if ckpt.device.type == "cuda":
        _replay_share(ckpt, widest)
    prof = cProfile.Profile()
    prof.enable()
    batching.solve_jobs(ckpt, [p.job for p in widest])
    _sync(ckpt.device)
    prof.disable()
    text = io.StringIO()
    pstats.Stats(prof, stream=text).sort_stats("tottime").print_stats(18)
    print(f"--- Python profile of the widest batch ({len(widest)} rows x {widest[0].frames} frames)")
    print("\n".join(line for line in text.getvalue().splitlines() if line.strip())[:6000])
    if ckpt.device.type == "cuda":
        from torch.profiler import ProfilerActivity, profile

        for graphs_on in ("1", "0"):
            os.environ["MOTIONLAB_CUDA_GRAPHS"] = graphs_on
            with profile(activities=[ProfilerActivity.CPU, ProfilerActivity.CUDA]) as tp:
                res = batching.solve_jobs(ckpt, [p.job for p in widest])
                _sync(ckpt.device)
            table = tp.key_averages().table(
                sort_by="self_cuda_time_total", row_limit=args.rows, max_name_column_width=40
            )
            count = {
                k: sum(e.count for e in tp.key_averages() if e.key.startswith(k))
                for k in ("cudaLaunchKernel", "cudaGraphLaunch")
            }
            print(f"--- device profile, MOTIONLAB_CUDA_GRAPHS={graphs_on}: {count['cudaLaunchKernel']} kernel launches "
                  f"and {count['cudaGraphLaunch']} graph launches for {max(r.steps for r in res)} steps")  # fmt: skip
            print(table)
        os.environ.pop("MOTIONLAB_CUDA_GRAPHS")


if __name__ == "__main__":
    main()
