"""Where a GPU expansion spends its solve time, and what two candidate changes would save (issue 40).

Prepares all of Aj's clips × the six Table 1 characters as ``expand`` does (host workers), plans
the padded batches, then times the latent iteration of every batch (``batching.solve_jobs``,
device synchronised) with the Gauss–Newton start in chunks as large as free memory allows (as
shipped) and in chunks of ``solver.PROJECT_GPU_FRAMES`` frames (the least a GPU chunk holds). Then it profiles the batch with the most
rows: Python (cProfile, top functions by own time) and the device (``torch.profiler``: top
operators by device time, kernel launches per step). Results of the variants are compared with
the shipped ones (largest joint difference, cm).

Usage::

    MOTIONLAB_DATA=/path/to/data python benchmarks/profile_expand_gpu.py [--clips N] [--device cuda]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import time

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.retargeting import batching, host, solver
from motionlab.retargeting import expand as ex
from motionlab.retargeting.evaluate import DEFAULT_TARGETS


def _pairs(ckpt, clips: int):
    root = data.data_root() / "mixamo"
    chars = ex.characters(*[f"{n}={root / n / 'Running.bvh'}" for n in DEFAULT_TARGETS])
    paths = sorted((root / "Aj").glob("*.bvh"))[:clips]
    targets = [(c.name, c.skeleton) for c in chars]
    cfg = solver.SolverConfig()
    with host.pool(ckpt, host.default_workers(ckpt.device)) as pool:
        prepared = [pool.submit(ex.prepare_clip, p, None, targets, "stride", cfg) for p in paths]
        pairs = []
        for p, f in zip(paths, prepared):
            motion, prep, _, jobs = f.result()
            pairs += [batching.Pair(p.stem, n, motion, s, prep.motion.num_frames, prep, jobs[n]) for n, s in targets]
    return pairs


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


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--clips", type=int, default=1000, help="first N of Aj's clips (default: all)")
    p.add_argument("--device", default="cuda")
    p.add_argument("--dtype", default="float64", choices=("float64", "float32"))
    args = p.parse_args(argv)
    ckpt = retargeting.load_default(args.device, args.dtype)
    clock = time.perf_counter()
    pairs = _pairs(ckpt, args.clips)
    batches = batching.plan_batches(pairs, batching.batch_frames(ckpt.device), pad=True)
    frames = sum(p.frames for p in pairs)
    print(f"{len(pairs)} pairs, {frames} frames prepared in {time.perf_counter() - clock:.1f} s; batches (rows x frames): "
          + ", ".join(f"{len(b)}x{b[0].frames}" for b in batches))  # fmt: skip
    shipped = solver.PROJECT_BYTES_PER_FRAME
    variants = {"chunks by free memory": shipped, f"chunks of {solver.PROJECT_GPU_FRAMES}": 10**15}
    reference = None
    for name, per_frame in variants.items():
        solver.PROJECT_BYTES_PER_FRAME = per_frame
        out, seconds = _run(ckpt, batches)
        pos = np.concatenate([r.positions[0].reshape(-1) for r in out])
        diff = "" if reference is None else f"; vs the first {100 * np.abs(pos - reference).max():.2g} cm"
        reference = pos if reference is None else reference
        steps = max(r.steps for r in out)
        print(f"{name:<22} solve {sum(seconds):6.2f} s = {frames / sum(seconds):7.0f} frames/s; per batch "
              + " ".join(f"{s:.2f}" for s in seconds) + f"; most steps {steps}{diff}")  # fmt: skip
    solver.PROJECT_BYTES_PER_FRAME = shipped
    widest = max(batches, key=len)
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

        with profile(activities=[ProfilerActivity.CPU, ProfilerActivity.CUDA]) as tp:
            res = batching.solve_jobs(ckpt, [p.job for p in widest])
            _sync(ckpt.device)
        table = tp.key_averages().table(sort_by="self_cuda_time_total", row_limit=15, max_name_column_width=40)
        launches = sum(e.count for e in tp.key_averages() if e.key.startswith("cudaLaunchKernel"))
        print(f"--- device profile: {launches} kernel launches for {max(r.steps for r in res)} steps")
        print(table)


if __name__ == "__main__":
    main()
