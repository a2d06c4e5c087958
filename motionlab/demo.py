"""``motionlab demo``: the main job on built-in data, no downloads, no training.

1. make a synthetic performance (idle → walk → run → jump → walk → squat) on the character the
   shipped network was trained on;
2. make new characters with other proportions (longer legs, short arms, …);
3. retarget the performance onto each of them three ways — copying local rotations, the network
   without iteration, and the full latent iteration — with the shipped pretrained network;
4. write everything as BVH to the output folder, a figure of foot heights, and print a table.

Because the motion is procedural, the generator can also perform the same segments directly on
each new character; that *procedural reference* gives an error to compare against (it is one
plausible answer, not the only one).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from motionlab.core import bvh, files, humanoid, metrics

__all__ = ["run_demo", "SEGMENTS", "MARKER"]

MARKER = ".motionlab-demo"
"""File the demo leaves in its output folder: a folder holding it belongs to the demo, and a
re-run replaces the demo's own files there without ``force``."""

SEGMENTS = [("idle", 40), ("walk", 140), ("run", 110), ("jump", 70), ("walk", 80), ("squat", 100)]
"""The demo performance: (behaviour, frames at 60 fps)."""


def _row(name: str, pos: np.ndarray, ref: np.ndarray, fps: float, height: float, seconds: float) -> dict:
    feet = [humanoid.JOINTS.index(j) for j in humanoid.FEET]
    return {
        "method": name,
        "mpjpe_cm": 100 * metrics.mpjpe(pos, ref),
        "pen_pct": 100 * metrics.foot_penetration(pos, feet) / height,
        "skate": metrics.foot_skating(pos, feet, fps),
        "smooth": 100 * metrics.smoothness(pos),
        "seconds": seconds,
    }


def _claim(out_dir: Path, planned: list[Path], force: bool) -> None:
    """Make ``out_dir`` the demo's folder; refuse (without ``force``) to replace files the demo did not write."""
    if out_dir.exists() and not out_dir.is_dir():
        raise NotADirectoryError(f"output folder {out_dir} is a file; expected a folder")
    owned = (out_dir / MARKER).is_file()
    clash = [p for p in planned if p.exists()]
    if clash and not owned and not force:
        raise FileExistsError(
            f"{clash[0]} exists (and {len(clash) - 1} more) in {out_dir}, which an earlier demo did not write; "
            "add --force to replace them (force=True in Python), or choose another -o folder"
        )
    out_dir.mkdir(parents=True, exist_ok=True)
    files.atomic_write(
        out_dir / MARKER, lambda f: f.write("written by `motionlab demo`; a re-run replaces its files\n"), True
    )


def _character_rows(i, target, performance, checkpoint, seed: int, out_dir: Path, curves: dict) -> list[dict]:
    """Retarget the performance onto ``target`` by each method: one table row per method.

    Writes the full method's result as ``character_{i}.bvh``; for character 0, stores each
    method's lowest toe height per frame (T,) in ``curves``.
    """
    from motionlab import synthetic
    from motionlab.retargeting import retarget

    reference = synthetic.sequence(SEGMENTS, target, fps=60, seed=seed).global_positions()
    height = target.height()
    rows = []
    for method in ("copy", "network", "full"):
        t0 = time.perf_counter()
        # the procedural reference scales strides by thigh + shin: scale the root the same way
        result = retarget(performance, target, checkpoint, method, root_mode=synthetic.ROOT_MODE)
        seconds = time.perf_counter() - t0
        n = min(len(result.positions), len(reference))
        row = _row(method, result.positions[:n], reference[:n], performance.fps, height, seconds)
        row["character"] = f"{i} ({height:.2f} m, legs {humanoid.leg_length(target) / height:.2f}·h)"
        rows.append(row)
        if method == "full":
            result.motion.name = f"character_{i}"
            bvh.save(out_dir / f"character_{i}.bvh", result.motion, overwrite=True)
        if i == 0:
            feet = [humanoid.JOINTS.index(j) for j in ("LeftToeBase", "RightToeBase")]
            curves[method] = result.positions[:, feet, 1].min(axis=1)
    return rows


def _table(rows: list[dict]) -> str:
    """The demo's Markdown tables: one row per character and method, then the means per method."""
    header = "| character | method | MPJPE vs procedural ref (cm) | feet below ground (% height) | foot skating (m/s) | smoothness (cm/frame²) | time (s) |"
    lines = [header, "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['character']} | {r['method']} | {r['mpjpe_cm']:.2f} | {r['pen_pct']:.3f} | {r['skate']:.3f} | "
            f"{r['smooth']:.3f} | {r['seconds']:.2f} |"
        )
    means = {}
    for method in ("copy", "network", "full"):
        sel = [r for r in rows if r["method"] == method]
        means[method] = {
            k: float(np.mean([r[k] for r in sel])) for k in ("mpjpe_cm", "pen_pct", "skate", "smooth", "seconds")
        }
    lines += [
        "",
        "| mean over characters | MPJPE (cm) | below ground (% h) | skating (m/s) | smoothness | time (s) |",
        "|---|---|---|---|---|---|",
    ]
    for method, m in means.items():
        lines.append(
            f"| {method} | {m['mpjpe_cm']:.2f} | {m['pen_pct']:.3f} | {m['skate']:.3f} | {m['smooth']:.3f} | {m['seconds']:.2f} |"
        )
    return "\n".join(lines)


def _plot_foot_heights(curves: dict, fps: float, path: Path) -> None:
    """Save character 0's lowest toe height per frame, one line per method, as a PNG."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 3))
    t = np.arange(len(next(iter(curves.values())))) / fps
    for method, y in curves.items():
        ax.plot(t[: len(y)], 100 * y, label=method, lw=1.2)
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("lowest toe height (cm)")
    ax.set_title("character 0: lowest toe height per frame (below 0 = through the floor)")
    ax.legend()
    fig.tight_layout()
    files.atomic_write(path, lambda f: fig.savefig(f, format="png", dpi=110), True, binary=True)
    plt.close(fig)


def run_demo(out_dir: str | Path = "outputs/demo", characters: int = 4, seed: int = 0, force: bool = False) -> int:
    """Run the demo; returns 0.

    ``out_dir`` belongs to the demo once it ran there (a :data:`MARKER` file): running again replaces
    the demo's files. Files in a folder the demo did not write are only replaced with ``force``.
    """
    from motionlab import synthetic
    from motionlab.retargeting import load_default

    out_dir = Path(out_dir)
    planned = [out_dir / "source.bvh", out_dir / "foot_heights.png", out_dir / "summary.md"]
    planned += [out_dir / f"character_{i}.bvh" for i in range(characters)]
    _claim(out_dir, planned, force)

    checkpoint = load_default()
    source_skeleton = checkpoint.skeleton
    print(f"pretrained network: {checkpoint.path if hasattr(checkpoint, 'path') else 'motionlab/assets'}")
    performance = synthetic.sequence(SEGMENTS, source_skeleton, fps=60, seed=seed)
    performance.name = "source"
    bvh.save(out_dir / "source.bvh", performance, overwrite=True)
    print(
        f"source: {performance.num_frames} frames on a {source_skeleton.height():.2f} m character "
        f"({' → '.join(s for s, _ in SEGMENTS)})"
    )

    targets = synthetic.character_set(characters, seed=seed + 1)
    rows, curves = [], {}
    for i, target in enumerate(tqdm(targets, desc="characters")):
        rows += _character_rows(i, target, performance, checkpoint, seed, out_dir, curves)
    table = _table(rows)
    files.atomic_write(out_dir / "summary.md", lambda f: f.write("# motionlab demo\n\n" + table + "\n"), True)
    print()
    print(table)
    _plot_foot_heights(curves, performance.fps, out_dir / "foot_heights.png")
    print(f"\nwrote {len(planned)} files to {out_dir}/ (open the .bvh files in Blender or `motionlab view`)")
    return 0
