"""Benchmark of the retargeting system (paper A): training, decoder fidelity, q_Δ, solver speed.

Goals (2-core CPU): training on Aj's clips to a stable loss in <= 10 minutes; the latent solver
<= 1 s median per 120-frame window; on Aj's 10 held-back ``retarget_gt`` clips (never trained
on) a reconstruction error <= 2 cm (issue 30) and the iteration within 1° of A's upper-body rotations.

Printed, in order: training; decoder fidelity (reconstruction by the network alone, and the
upper-body rotation error of the encoder's latent, of the Gauss–Newton start and after the
iteration, on every target); how far q_Δ departs from the identity on the shared characters and
on synthetic bone-length sweeps, and how much it changes with the skeleton; solver time.

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

from motionlab.core import humanoid, quat
from motionlab.retargeting.features import clip_features


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
    ckpt, history = train(
        ds, TrainConfig(steps=args.steps, log_every=10, pose_augment=args.pose_augment), progress=True
    )
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


UPPER = [j for j, n in enumerate(humanoid.JOINTS) if j > 0 and not any(k in n for k in ("UpLeg", "Leg", "Foot", "Toe"))]
"""Spine, neck, head, shoulders, arms and hands: the joints Mixamo copies exactly."""


def _degrees(a, b):
    """Angle (degrees) between unit quaternions, elementwise over (..., 4)."""
    return np.degrees(2 * np.arccos(np.clip(np.abs((np.asarray(a) * np.asarray(b)).sum(-1)), 0, 1)))


def _fidelity(ckpt, args):
    from motionlab import data, synthetic
    from motionlab.core import bvh, preprocess
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_TARGETS
    from motionlab.retargeting.pipeline import retarget, target_skeleton
    from motionlab.retargeting.solver import SolverConfig, project_latent

    if args.synthetic:
        sources = synthetic.dataset(4, seed=321, num_frames=240)
        targets = {f"synthetic {i}": synthetic.random_character(i) for i in range(3)}
    else:
        root = data.data_root() / "mixamo"
        sources = [bvh.load(root / "Aj" / f"{a}.bvh") for a in DEFAULT_ANIMATIONS]
        targets = {t: target_skeleton(bvh.load(root / t / "Running.bvh").skeleton) for t in DEFAULT_TARGETS}
    model = ckpt.model
    err, enc_deg, gn_deg = [], [], []
    for src in sources:
        c = preprocess.prepare(src, ckpt.fps)
        f = clip_features(c)
        x = torch.tensor(ckpt.stats.normalize(f.x), dtype=ckpt.dtype)[None]
        own = torch.tensor(c.skeleton.offsets, dtype=ckpt.dtype)
        target = torch.tensor(f.local_rot, dtype=ckpt.dtype)[None]
        with torch.no_grad():
            phi = model.encode(x)
            out = model.decode(phi, own)
            gn = model.decode(project_latent(model, phi, target, own), own)
        err.append(np.linalg.norm(out.positions[0].numpy() - f.positions, axis=-1))
        enc_deg.append(_degrees(out.local_rot[0].numpy(), f.local_rot)[:, UPPER])
        gn_deg.append(_degrees(gn.local_rot[0].numpy(), f.local_rot)[:, UPPER])
    err = np.concatenate(err)
    what = "synthetic clips" if args.synthetic else "Aj's 10 held-back retarget_gt clips"
    print(f"decoder fidelity on {what} (never trained on):")
    print(
        f"  reconstruction by the network alone (encoder -> decoder -> FK on A): mean joint error {100 * err.mean():.2f} cm "
        f"(upper body {100 * err[:, UPPER].mean():.2f}, legs {100 * np.delete(err, [0] + UPPER, axis=1).mean():.2f}); "
        f"goal <= 2 cm: {'met' if 100 * err.mean() <= 2 else 'MISSED'}"
    )
    print(
        f"  upper-body local rotations vs A, median: encoder's latent {np.median(np.concatenate(enc_deg)):.2f} deg, "
        f"after the Gauss-Newton start {np.median(np.concatenate(gn_deg)):.3f} deg"
    )
    after = {}
    for name, sk in targets.items():
        degs = []
        for src in sources[: 3 if args.quick else None]:
            res = retarget(src, sk, ckpt, "full", SolverConfig())
            f = clip_features(preprocess.prepare(src, ckpt.fps))
            rot = res.motion.local_rot.copy()
            rot[:, 0] = quat.mul(quat.from_yaw(-f.yaw), rot[:, 0])  # root back into A's heading frame
            degs.append(_degrees(rot, f.local_rot)[:, UPPER])
        after[name] = float(np.median(np.concatenate(degs)))
    worst = max(after.values())
    print(
        "  after the full iteration on each target, median upper-body angle to A: "
        + ", ".join(f"{k} {v:.3f}" for k, v in after.items())
        + f" deg; goal <= 1 deg: {'met' if worst <= 1 else 'MISSED'}"
    )
    # q_delta: departure from the identity, and dependence on the skeleton
    c = preprocess.prepare(sources[0], ckpt.fps)
    x = torch.tensor(ckpt.stats.normalize(clip_features(c).x), dtype=ckpt.dtype)[None]
    base = humanoid.to_canonical_skeleton(ckpt.skeleton)
    sweeps = {f"legs x{s}": humanoid.scale_bones(base, legs=s) for s in (0.6, 1.0, 1.6)}
    sweeps.update({f"arms x{s}": humanoid.scale_bones(base, arms=s) for s in (0.6, 1.6)})
    sweeps.update({"overall x0.5": humanoid.scale_bones(base, overall=0.5)})
    with torch.no_grad():
        phi = model.encode(x)
        ref = model.decode(phi, torch.tensor(base.offsets, dtype=ckpt.dtype)).q_delta[0].numpy()
        print(
            "q_delta on one clip's latent: median angle from the identity / median change from the training skeleton's q_delta"
        )
        for name, sk in {**targets, **sweeps}.items():
            qd = model.decode(phi, torch.tensor(sk.offsets, dtype=ckpt.dtype)).q_delta[0].numpy()
            print(
                f"  {name:<14} {np.median(_degrees(qd, np.array([1.0, 0, 0, 0]))):6.2f} deg  "
                f"{np.median(_degrees(qd, ref)):6.3f} deg (max {_degrees(qd, ref).max():.2f})"
            )


def _window(motion, ckpt, frames: int = 120):
    """``motion``'s first ``frames`` frames at the network's rate, the last frame repeated to fill them."""
    from motionlab.core import preprocess

    n = int(round(frames * motion.fps / ckpt.fps))
    pad = lambda a: None if a is None else preprocess.pad_to(a, n)[:n]  # noqa: E731
    return motion.copy(local_rot=pad(motion.local_rot), root_pos=pad(motion.root_pos), local_pos=pad(motion.local_pos))


def _solve(ckpt, args):
    """The latent iteration as ``motionlab retarget`` runs it (:func:`pipeline.solve_pair`, every
    term's inputs), timed on 120-frame windows."""
    from motionlab.core import bvh
    from motionlab.retargeting.pipeline import prepare_pair, prepare_source, solve_pair
    from motionlab.retargeting.solver import SolverConfig

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
    times, steps, reasons, frames = [], [], [], set()
    for src in sources:
        prepared = prepare_source(_window(src, ckpt), ckpt, "full", cfg)
        frames.add(prepared.x.shape[1])
        for tgt in targets:
            res = solve_pair(ckpt, prepare_pair(prepared, tgt), cfg)
            times.append(res.seconds)
            steps.append(res.steps)
            reasons.append(res.stop_reason)
    med = statistics.median(times)
    print(
        f"latent solver: {len(times)} windows of {'/'.join(map(str, sorted(frames)))} frames, median {med:.3f} s "
        f"(min {min(times):.3f}, max {max(times):.3f}), median {statistics.median(steps):.0f} steps "
        f"({1000 * sum(times) / max(sum(steps), 1):.1f} ms/step); "
        f"stops: { {r: reasons.count(r) for r in sorted(set(reasons))} }  goal <= 1 s: {'met' if med <= 1.0 else 'MISSED'}"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--checkpoint", help="skip training and use this checkpoint")
    p.add_argument("--steps", type=int, default=1500, help="training steps (default 1500)")
    p.add_argument(
        "--pose-augment", type=float, default=0.0, help="TrainConfig.pose_augment: batch fraction with joints turned"
    )
    p.add_argument("--synthetic", action="store_true", help="use motionlab.synthetic data instead of MOTIONLAB_DATA")
    p.add_argument("--synthetic-clips", type=int, default=300)
    p.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's default)")
    p.add_argument("--quick", action="store_true", help="fewer clips per target in the fidelity part")
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
    _fidelity(ckpt, args)
    _solve(ckpt, args)


if __name__ == "__main__":
    main()
