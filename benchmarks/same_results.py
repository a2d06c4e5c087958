"""Do two checkouts of motionlab retarget to the same numbers? A bit-identity check for speed work.

``--code DIR --out FILE``: with motionlab imported from checkout ``DIR``, retarget Aj's Jumping,
Run_Arc_Left and Running onto Goblin_m, Kaya and Mousey_m (``retarget(..., "full")``), four of
those pairs in one padded batch (``batching.solve_pairs``), and notebook 04's slider solve
(``proportion_solver(walk, max_steps=30)``) at four settings; save joint positions, steps, best
step, stop reason and the L_iter history of each to ``FILE`` (.npz).

``--compare A B``: print, per case, the largest position difference (metres), the steps and the
last L_iter of both files, and the largest difference over all cases.

Usage (repository root, ``MOTIONLAB_DATA`` set; ``git worktree add /tmp/old <commit>``)::

    python benchmarks/same_results.py --code /tmp/old --out /tmp/old.npz
    python benchmarks/same_results.py --code . --out /tmp/new.npz
    python benchmarks/same_results.py --compare /tmp/old.npz /tmp/new.npz
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

CLIPS = ("Jumping", "Run_Arc_Left", "Running")
CHARACTERS = ("Goblin_m", "Kaya", "Mousey_m")
SLIDER = ((1.3, 0.8), (1.35, 0.8), (1.0, 1.0), (0.7, 1.2))


def _record(out: dict, key: str, positions, history: dict, steps=None, best=None, reason=None) -> None:
    out[f"{key}/pos"] = np.asarray(positions)
    out[f"{key}/loss"] = np.asarray(history["loss"], dtype=float)
    if steps is not None:
        out[f"{key}/steps"] = np.array([steps, best])
        out[f"{key}/reason"] = np.array(reason)


def dump(path: Path) -> None:
    """Run every case with the imported motionlab and save the results to ``path``."""
    from motionlab import data, retargeting, synthetic
    from motionlab.core import bvh, humanoid
    from motionlab.retargeting import batching, pipeline
    from motionlab.retargeting.proportions import proportion_solver

    root = data.data_root() / "mixamo"
    ckpt = retargeting.load_default("cpu")
    clips = {c: bvh.load(root / "Aj" / f"{c}.bvh") for c in CLIPS}
    targets = {c: bvh.load(root / c / "Running.bvh").skeleton for c in CHARACTERS}
    out: dict = {}
    for c, clip in clips.items():
        for t, target in targets.items():
            r = retargeting.retarget(clip, target, ckpt, "full")
            _record(out, f"full/{c}/{t}", r.positions, r.history, r.steps, r.best_step, r.stop_reason)
    frames = {c: pipeline.prepare_source(clips[c], ckpt).motion.num_frames for c in CLIPS[:2]}
    pairs = [batching.Pair(c, t, clips[c], targets[t], frames[c]) for c in CLIPS[:2] for t in CHARACTERS[:2]]
    for p, r in zip(pairs, batching.solve_pairs(ckpt, pairs)):
        res = r.result
        _record(
            out, f"pairs/{p.clip}/{p.character}", res.positions, res.history, res.steps, res.best_step, res.stop_reason
        )
    skeleton = humanoid.canonical_skeleton()
    solve = proportion_solver(synthetic.generate("walk", skeleton, 120, 30.0, seed=1), max_steps=30)
    for legs, arms in SLIDER:
        motion, history = solve(humanoid.scale_bones(skeleton, legs=legs, arms=arms))
        _record(out, f"slider/legs {legs}/arms {arms}", motion.global_positions(), history)
    np.savez(path, **out)
    print(f"{len(out)} arrays saved to {path}")


def compare(a_path: Path, b_path: Path) -> float:
    """Print the per-case comparison; the largest position difference (inf for unequal shapes)."""
    a, b = np.load(a_path), np.load(b_path)
    worst = 0.0
    for key in sorted({k.rsplit("/", 1)[0] for k in a.files}):
        x, y = a[f"{key}/pos"], b[f"{key}/pos"]
        diff = float(np.abs(x - y).max()) if x.shape == y.shape else float("inf")
        worst = max(worst, diff)
        la, lb = a[f"{key}/loss"], b[f"{key}/loss"]
        line = f"{key:28s} positions {diff:.3g} m  L_iter {la[-1]:.6g} / {lb[-1]:.6g} ({len(la)} / {len(lb)} values)"
        if f"{key}/steps" in a.files:
            line += f"  steps {a[f'{key}/steps'].tolist()} / {b[f'{key}/steps'].tolist()}"
            line += f"  stop {a[f'{key}/reason']} / {b[f'{key}/reason']}"
        print(line)
    print(f"largest position difference over all cases: {worst:.3g} m")
    return worst


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--code", type=Path, help="motionlab checkout to import")
    parser.add_argument("--out", type=Path, help="results file (.npz) to write")
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("A", "B"), help="two results files")
    args = parser.parse_args(argv)
    if args.compare:
        return 0 if compare(*args.compare) == 0.0 else 1
    if args.code is None or args.out is None:
        parser.error("give --code and --out, or --compare A B")
    sys.path.insert(0, str(args.code.resolve()))
    dump(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
