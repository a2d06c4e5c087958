"""Benchmark of the retargeting system (paper A): training time and latent-solver speed.

Goals (2-core CPU): training on Aj's clips to a stable loss in <= 10 minutes; the latent solver
<= 1 s median per 120-frame window.

Usage::

    MOTIONLAB_DATA=/work/shared/data python benchmarks/bench_retarget.py            # train + solve
    python benchmarks/bench_retarget.py --checkpoint /tmp/motionlab_aj.pt           # solver only
    python benchmarks/bench_retarget.py --synthetic                                 # no real data

"Stable" means the mean loss of the last 10% of steps changed by less than 10% relative to
the 10% before it.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import torch


def _train(args):
    from motionlab.core import bvh
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, training_clips
    from motionlab.retargeting.train import TrainConfig, train, training_set

    t0 = time.perf_counter()
    if args.synthetic:
        from motionlab import synthetic

        motions = synthetic.dataset(args.synthetic_clips, seed=0)
    else:
        from motionlab import data

        clips = training_clips(data.data_root() / "mixamo", "Aj", DEFAULT_ANIMATIONS)
        motions = [bvh.load(p) for p in clips]
    ds = training_set(motions, progress=False)
    prep = time.perf_counter() - t0
    ckpt, history = train(ds, TrainConfig(steps=args.steps, log_every=10), progress=True)
    losses = np.array([h["loss"] for h in history])
    k = max(len(losses) // 10, 1)
    last, before = losses[-k:].mean(), losses[-2 * k : -k].mean()
    change = abs(last - before) / before
    print(
        f"training: {len(motions)} clips, {len(ds)} windows, preprocessing {prep:.1f} s, {args.steps} steps in {ckpt.info['seconds']:.1f} s "
        f"({1000 * ckpt.info['seconds'] / args.steps:.0f} ms/step), total {prep + ckpt.info['seconds']:.1f} s"
    )
    print(
        f"  loss {losses[0]:.4g} -> {last:.4g}; last-10% vs previous-10% change {100 * change:.1f}% ({'stable' if change < 0.1 else 'NOT stable'})"
    )
    print(f"  final mean joint error in training (recon x 6): {100 * 6 * history[-1]['recon']:.2f} cm")
    return ckpt


def _solve(ckpt, args):
    from motionlab.core import bvh, humanoid, preprocess
    from motionlab.retargeting.features import clip_features
    from motionlab.retargeting.pipeline import root_scale
    from motionlab.retargeting.solver import SolverConfig, solve

    if args.synthetic:
        from motionlab import synthetic

        sources = synthetic.dataset(6, seed=123, num_frames=240)
        targets = [synthetic.random_character(i) for i in range(3)]
    else:
        from motionlab import data
        from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_TARGETS

        root = data.data_root() / "mixamo"
        sources = [bvh.load(root / "Aj" / f"{a}.bvh") for a in DEFAULT_ANIMATIONS]
        targets = [
            humanoid.to_canonical_skeleton(bvh.load(root / t / "Running.bvh").skeleton) for t in DEFAULT_TARGETS[:3]
        ]
    cfg = SolverConfig()
    times, steps, reasons = [], [], []
    for src in sources:
        c = preprocess.prepare(src, ckpt.fps)
        f = clip_features(c)
        x = ckpt.stats.normalize(preprocess.pad_to(f.x, 120)[:120])
        rot = preprocess.pad_to(f.local_rot, 120)[:120]
        for tgt in targets:
            r = root_scale(c.skeleton, tgt)
            height = preprocess.pad_to(c.root_pos[:, 1] * r[1], 120)[:120]
            res = solve(
                ckpt.model,
                torch.tensor(x, dtype=torch.float32)[None],
                torch.tensor(rot, dtype=torch.float32)[None],
                torch.tensor(tgt.offsets, dtype=torch.float32),
                torch.tensor(height, dtype=torch.float32)[None],
                cfg,
            )
            times.append(res.seconds)
            steps.append(res.steps)
            reasons.append(res.stop_reason)
    med = statistics.median(times)
    print(
        f"latent solver: {len(times)} windows of 120 frames, median {med:.3f} s (min {min(times):.3f}, max {max(times):.3f}), "
        f"median {statistics.median(steps):.0f} steps ({1000 * sum(times) / max(sum(steps), 1):.1f} ms/step); "
        f"stops: { {r: reasons.count(r) for r in sorted(set(reasons))} }  goal <= 1 s: {'met' if med <= 1.0 else 'MISSED'}"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--checkpoint", help="skip training and use this checkpoint")
    p.add_argument("--steps", type=int, default=1500, help="training steps (default 1500)")
    p.add_argument("--synthetic", action="store_true", help="use motionlab.synthetic data instead of MOTIONLAB_DATA")
    p.add_argument("--synthetic-clips", type=int, default=300)
    p.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's default)")
    args = p.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    print(
        f"torch {torch.__version__}, {torch.get_num_threads()} threads, device {'cuda' if torch.cuda.is_available() else 'cpu'}"
    )
    if args.checkpoint:
        from motionlab.retargeting import checkpoint

        ckpt = checkpoint.load(args.checkpoint)
    else:
        ckpt = _train(args)
    _solve(ckpt, args)


if __name__ == "__main__":
    main()
