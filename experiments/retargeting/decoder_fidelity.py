"""Why does the network alone not reconstruct Aj's held-back clips to 2 cm (issue 30)? Measured.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.retargeting.decoder_fidelity
    python -m experiments.retargeting.decoder_fidelity --checkpoint /tmp/motionlab_Aj.pt --half-steps 1500

"Reconstruction by the network alone" is encoder -> decoder -> FK on Aj's own skeleton
(``benchmarks/bench_retarget.py``), mean joint error in cm, root-relative. Printed, on Aj's 10
held-back ``retarget_gt`` clips and on 10 of his training clips:

1. **the gap**: the same network's error on clips it trained on and on clips it never saw;
2. **the decoder's reach**: the error when the decoder is given the best latent for the clip
   (the Gauss-Newton projection of :func:`solver.project_latent` onto A's rotations) instead of
   the encoder's: what the decoder *can* say, so the rest is the encoder's;
3. **novelty**: for every held-back frame, the nearest pose among all training frames (mirrors
   included, as in training; root-relative joint positions, nearest by RMS); its mean joint
   error is what looking the pose up would give. Per clip beside the network's error, with the
   rank correlation of the two;
4. **clip ends**: the error on the first and last 10 frames against the middle (the temporal
   convolutions pad at the ends);
5. with ``--half-steps N``: a network trained on every second training clip (N steps),
   its held-back error against the full set's: what doubling the data gives.

The network is Aj's, trained by ``motionlab evaluate`` (``<tmp>/motionlab_Aj.pt``): the same
clips and settings as ``bench_retarget.py``'s training.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.core import bvh, preprocess
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, training_clips
from motionlab.retargeting.features import clip_features
from motionlab.retargeting.solver import project_latent
from motionlab.retargeting.train import TrainConfig, mirrored, train

EDGE = 10
"""Frames at each end of a clip counted as its ends."""


def reconstruct(ckpt, motion):
    """Per-frame mean joint error (cm, (T,)) of the encoder's latent and of the projected one, and A's positions (T, 22, 3)."""
    c = preprocess.prepare(motion, ckpt.fps)
    f = clip_features(c)
    x = torch.tensor(ckpt.stats.normalize(f.x), dtype=ckpt.dtype)[None]
    own = torch.tensor(c.skeleton.offsets, dtype=ckpt.dtype)
    rot = torch.tensor(f.local_rot, dtype=ckpt.dtype)[None]
    with torch.no_grad():
        phi = ckpt.model.encode(x)
        enc = ckpt.model.decode(phi, own).positions[0].numpy()
        best = ckpt.model.decode(project_latent(ckpt.model, phi, rot, own), own).positions[0].numpy()
    err = [100 * np.linalg.norm(p - f.positions, axis=-1).mean(1) for p in (enc, best)]
    return err[0], err[1], f.positions


def nearest_pose_error(poses: np.ndarray, library: np.ndarray) -> np.ndarray:
    """For each pose (N, 22, 3), the mean joint error (cm) of the library's (M, 22, 3) nearest by RMS."""
    lib = torch.as_tensor(library.reshape(len(library), -1))
    out = []
    for chunk in np.array_split(poses, max(len(poses) // 256, 1)):
        q = torch.as_tensor(chunk.reshape(len(chunk), -1))
        idx = torch.cdist(q, lib).argmin(1).numpy()
        out.append(100 * np.linalg.norm(chunk - library[idx], axis=-1).mean(1))
    return np.concatenate(out)


def rank_correlation(a, b) -> float:
    ra, rb = np.argsort(np.argsort(a)), np.argsort(np.argsort(b))
    return float(np.corrcoef(ra, rb)[0, 1])


def report(ckpt, held: dict, seen: dict, library: np.ndarray) -> None:
    """Items 1-4 of the module docstring."""
    rows = {}
    for group, clips in (("held back", held), ("trained on", seen)):
        for name, m in clips.items():
            enc, best, pos = reconstruct(ckpt, m)
            rows[name] = (group, enc, best, nearest_pose_error(pos, library) if group == "held back" else None)
    print(
        f"{'clip':<32} {'':<10} {'network cm':>10} {'best latent':>11} {'nearest pose':>12} {'ends':>6} {'middle':>6}"
    )
    for name, (group, enc, best, nn) in rows.items():
        ends = np.r_[enc[:EDGE], enc[-EDGE:]].mean()
        near = f"{nn.mean():12.2f}" if nn is not None else f"{'-':>12}"
        print(
            f"{name[:32]:<32} {group:<10} {enc.mean():10.2f} {best.mean():11.3f} {near} {ends:6.2f} {enc[EDGE:-EDGE].mean():6.2f}"
        )
    for group in ("held back", "trained on"):
        enc = np.concatenate([r[1] for r in rows.values() if r[0] == group])
        best = np.concatenate([r[2] for r in rows.values() if r[0] == group])
        print(f"{group:<10} all frames: network {enc.mean():.2f} cm, decoder with the best latent {best.mean():.3f} cm")
    held_rows = [r for r in rows.values() if r[0] == "held back"]
    nn_all = np.concatenate([r[3] for r in held_rows])
    enc_all = np.concatenate([r[1] for r in held_rows])
    ends = np.concatenate([np.r_[r[1][:EDGE], r[1][-EDGE:]] for r in held_rows])
    middle = np.concatenate([r[1][EDGE:-EDGE] for r in held_rows])
    print(
        f"held back: nearest training pose {nn_all.mean():.2f} cm; rank correlation with the network's error "
        f"per clip {rank_correlation([r[3].mean() for r in held_rows], [r[1].mean() for r in held_rows]):+.2f}, "
        f"per frame {rank_correlation(nn_all, enc_all):+.2f}; "
        f"network on frames whose nearest pose is within 2 cm: {enc_all[nn_all <= 2].mean():.2f} cm "
        f"({100 * (nn_all <= 2).mean():.0f}% of frames), beyond 4 cm: {enc_all[nn_all > 4].mean():.2f} cm "
        f"({100 * (nn_all > 4).mean():.0f}%)"
    )
    print(f"held back: first/last {EDGE} frames {ends.mean():.2f} cm, middle {middle.mean():.2f} cm")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", help="Aj's network (default: <tmp>/motionlab_Aj.pt, from motionlab evaluate)")
    ap.add_argument("--half-steps", type=int, default=0, help="also train on every second training clip (N steps)")
    args = ap.parse_args(argv)
    try:
        root = data.data_root() / "mixamo"
    except data.DataNotFound as e:
        sys.exit(f"decoder_fidelity: {e}")
    path = Path(args.checkpoint or Path(tempfile.gettempdir()) / "motionlab_Aj.pt")
    if not path.is_file():
        sys.exit(f"no checkpoint {path}: run `motionlab evaluate` first (it trains Aj's network there)")
    ckpt = retargeting.load(str(path))
    paths = training_clips(root, "Aj", DEFAULT_ANIMATIONS)
    train_motions = [bvh.load(p) for p in paths]
    held = {a: bvh.load(root / "Aj" / f"{a}.bvh") for a in DEFAULT_ANIMATIONS}
    seen = {p.stem: m for p, m in list(zip(paths, train_motions))[:: max(len(paths) // 10, 1)][:10]}
    prepared = [preprocess.prepare(m, ckpt.fps) for m in train_motions]
    library = np.concatenate([clip_features(v).positions for c in prepared for v in (c, mirrored(c))])
    print(f"network {path}; {len(paths)} training clips ({len(library)} frames with mirrors), {len(held)} held back")
    report(ckpt, held, seen, library)
    if args.half_steps:
        half, _ = train(train_motions[::2], TrainConfig(steps=args.half_steps), progress=False)
        err = {
            k: np.concatenate([reconstruct(c, m)[0] for m in held.values()]).mean()
            for k, c in (("half", half), ("all", ckpt))
        }
        print(
            f"held back, network alone: {err['half']:.2f} cm trained on {len(train_motions[::2])} clips ({args.half_steps} steps), "
            f"{err['all']:.2f} cm on {len(train_motions)}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
