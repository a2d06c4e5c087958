"""``motionlab demo``: the main job on built-in data, no downloads, no training.

1. make a synthetic performance (idle → walk → run → jump → walk → squat) on the character the
   shipped network was trained on;
2. make new characters with other proportions (longer legs, short arms, …), and one more,
   :func:`long_shins`: the source character with its shins alone lengthened;
3. retarget the performance onto each of them three ways — copying local rotations, the network
   without iteration, and the full latent iteration — with the shipped pretrained network;
4. write everything as BVH to the output folder, a figure of the long-shins case's feet, and print
   a table.

Because the motion is procedural, the generator can also perform the same segments directly on
each new character; that *procedural reference* gives an error to compare against (it is one
plausible answer, not the only one).

Why the extra character: the random characters scale every bone of a leg alike, and the root rule
(``synthetic.ROOT_MODE``) scales the root by the same factor, so copied rotations put the feet
exactly where the generator does and the full method has nothing to fix. Copying is exact only
for such a uniform leg chain; the smallest change that breaks it is the *ratio* of its bones, so
the demo lengthens one bone (the shins) by the character sampler's largest leg factor
(``characters.RANGES["legs"][1]``, not tuned to the result). There, copied rotations slide the
planted feet; the table shows what the full method changes (planted-foot slide, lowest joint,
plausibility, :mod:`motionlab.retargeting.plausibility`).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from motionlab.core import bvh, files, humanoid, metrics
from motionlab.core.skeleton import Skeleton

__all__ = ["run_demo", "long_shins", "SEGMENTS", "MARKER", "METHODS"]

MARKER = ".motionlab-demo"
"""File the demo leaves in its output folder: a folder holding it belongs to the demo, and a
re-run replaces the demo's own files there without ``force``."""

SEGMENTS = [("idle", 40), ("walk", 140), ("run", 110), ("jump", 70), ("walk", 80), ("squat", 100)]
"""The demo performance: (behaviour, frames at 60 fps)."""

METHODS = ("copy", "network", "full")
"""The three ways the demo retargets (:func:`motionlab.retargeting.retarget`'s ``method``)."""

CASE = "long shins"
"""The table's name for the :func:`long_shins` character."""


def long_shins(skeleton: Skeleton, factor: float | None = None) -> Skeleton:
    """``skeleton`` with both shins (knee to ankle) alone lengthened by ``factor`` (default: the
    character sampler's largest leg factor, ``characters.RANGES["legs"][1]``), its lowest joint
    kept on the ground; thighs and feet unchanged, so the leg's bone ratio changes.

    Raises
    ------
    ValueError when ``skeleton`` is not the canonical 22-joint humanoid or ``factor`` is not > 0.
    """
    from motionlab.synthetic import characters

    factor = characters.RANGES["legs"][1] if factor is None else float(factor)
    if not humanoid.is_canonical(skeleton):
        raise ValueError("long_shins: expected the canonical 22-joint humanoid skeleton")
    if not (np.isfinite(factor) and factor > 0):
        raise ValueError(f"long_shins: factor must be a positive number, got {factor}")
    offsets = skeleton.offsets.copy()
    for shin_end in ("LeftFoot", "RightFoot"):  # a joint's offset is the bone from its parent (the knee)
        offsets[skeleton.index(shin_end)] *= factor
    stretched = Skeleton(skeleton.names, skeleton.parents, offsets, skeleton.end_sites)
    offsets[0, 1] += skeleton.rest_positions()[:, 1].min() - stretched.rest_positions()[:, 1].min()
    return Skeleton(skeleton.names, skeleton.parents, offsets, skeleton.end_sites)


def _row(name: str, result, ref: np.ndarray, planted: np.ndarray, fps: float, height: float, seconds: float) -> dict:
    """One table row: the error against the procedural reference, the planted feet's slide (A's
    contact frames), the lowest joint, feet below the ground, smoothness and the plausibility verdict."""
    feet = [humanoid.JOINTS.index(j) for j in humanoid.FEET]
    n = min(len(result.positions), len(ref), len(planted))
    pos = result.positions[:n]
    p = result.plausibility
    return {
        "method": name,
        "mpjpe_cm": 100 * metrics.mpjpe(pos, ref[:n]),
        "slide_cms": 100 * metrics.planted_slide(pos, feet, planted[:n], fps),
        "lowest_cm": 100 * float(pos[..., 1].min()),
        "pen_pct": 100 * metrics.foot_penetration(pos, feet) / height,
        "smooth": 100 * metrics.smoothness(pos),
        "plausible": "yes" if p is None or p.ok else "no: " + ", ".join(p.failed),
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


def _character_rows(label, target, performance, planted, checkpoint, seed, out_dir: Path, curves) -> list[dict]:
    """Retarget the performance onto ``target`` by each method: one table row per method.

    ``label``: the character's number, or :data:`CASE`. Writes the full method's result as
    ``character_{label}.bvh`` (``long_shins.bvh`` for the case); when ``curves`` is a dict, stores
    each method's feet there (:func:`_foot_curves`).
    """
    from motionlab import synthetic
    from motionlab.retargeting import retarget

    reference = synthetic.sequence(SEGMENTS, target, fps=60, seed=seed).global_positions()
    height = target.height()
    rows = []
    for method in METHODS:
        # the procedural reference scales strides by thigh + shin: scale the root the same way
        t0 = time.perf_counter()
        result = retarget(performance, target, checkpoint, method, root_mode=synthetic.ROOT_MODE)
        row = _row(method, result, reference, planted, performance.fps, height, time.perf_counter() - t0)
        legs = f"legs {humanoid.leg_length(target) / height:.2f}·h"
        row["character"] = f"{label} ({height:.2f} m, {legs})" if label != CASE else f"{CASE} ({legs})"
        rows.append(row)
        if method == "full":
            name = f"character_{label}" if label != CASE else "long_shins"
            result.motion.name = name
            bvh.save(out_dir / f"{name}.bvh", result.motion, overwrite=True)
        if curves is not None:
            curves[method] = _foot_curves(result.positions, planted, performance.fps)
    return rows


def _foot_curves(pos: np.ndarray, planted: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: the lowest toe height (m) and the fastest planted foot joint's horizontal speed
    (m/s; ``nan`` where A plants no foot)."""
    toes = [humanoid.JOINTS.index(j) for j in ("LeftToeBase", "RightToeBase")]
    feet = [humanoid.JOINTS.index(j) for j in humanoid.FEET]
    n = min(len(pos), len(planted))
    speed = np.linalg.norm(np.diff(pos[:n, feet][..., [0, 2]], axis=0), axis=-1) * fps  # (n-1, 4)
    both = planted[1:n] & planted[: n - 1]
    fastest = np.where(both.any(axis=1), np.where(both, speed, 0.0).max(axis=1), np.nan)
    return pos[:, toes, 1].min(axis=1), fastest


_COLUMNS = (
    ("mpjpe_cm", "MPJPE vs procedural ref (cm)", ".2f"),
    ("slide_cms", "planted-foot slide (cm/s)", ".2f"),
    ("lowest_cm", "lowest joint (cm, < 0: under the floor)", ".2f"),
    ("pen_pct", "feet below ground (% height)", ".3f"),
    ("smooth", "smoothness (cm/frame²)", ".3f"),
    ("plausible", "plausible", "s"),
    ("seconds", "time (s)", ".2f"),
)


def _table(rows: list[dict]) -> str:
    """The demo's Markdown tables: one row per character and method; then per method the mean
    over the random characters (plausible: how many of them) and the long-shins case; then what
    the full method changed on the case."""
    head = lambda first: "| " + " | ".join([first, "method"] + [t for _, t, _ in _COLUMNS]) + " |"  # noqa: E731
    rule = "|" + "---|" * (len(_COLUMNS) + 2)
    cells = lambda r: " | ".join(format(r[k], f) for k, _, f in _COLUMNS)  # noqa: E731
    lines = [head("character"), rule] + [f"| {r['character']} | {r['method']} | {cells(r)} |" for r in rows]
    lines += ["", head("summary"), rule]
    random = [r for r in rows if not r["character"].startswith(CASE)]
    n = len(random) // len(METHODS)
    for method in METHODS:
        sel = [r for r in random if r["method"] == method]
        mean = {k: float(np.mean([r[k] for r in sel])) for k, _, f in _COLUMNS if f != "s"}
        mean["lowest_cm"] = min(r["lowest_cm"] for r in sel)  # the lowest of all, not a mean
        mean["plausible"] = f"{sum(r['plausible'] == 'yes' for r in sel)}/{len(sel)}"
        lines.append(f"| mean over {n} random character{'s' * (n != 1)} | {method} | {cells(mean)} |")
    case = {r["method"]: r for r in rows if r["character"].startswith(CASE)}
    lines += [f"| {CASE} | {m} | {cells(case[m])} |" for m in METHODS if m in case]
    lines += ["", "(random characters: lowest joint is the lowest of them all; plausible counts those that passed)"]
    if {"copy", "full"} <= set(case):
        c, f = case["copy"], case["full"]
        lines += ["", f"On {CASE}, copied rotations slide the planted feet at {c['slide_cms']:.2f} cm/s; the full method "
                      f"keeps them at {f['slide_cms']:.2f} cm/s (lowest joint {c['lowest_cm']:.2f} -> {f['lowest_cm']:.2f} cm)."]  # fmt: skip
    return "\n".join(lines)


def _plot_foot_heights(curves: dict, fps: float, path: Path) -> None:
    """Save the long-shins case's lowest toe height and planted-foot speed per frame, one line per
    method, as a PNG."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for method, (low, speed) in curves.items():
        ax.plot(np.arange(len(low)) / fps, 100 * low, label=method, lw=1.2)
        bx.plot(np.arange(1, len(speed) + 1) / fps, 100 * speed, label=method, lw=1.0)
    ax.axhline(0, color="k", lw=0.8)
    ax.set_ylabel("lowest toe height (cm)")
    ax.set_title(f"{CASE}: lowest toe height (below 0 = through the floor) and planted feet's speed")
    ax.legend()
    bx.set_xlabel("time (s)")
    bx.set_ylabel("fastest planted foot (cm/s)")
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
    planned = [out_dir / "source.bvh", out_dir / "foot_heights.png", out_dir / "summary.md", out_dir / "long_shins.bvh"]
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

    from motionlab.retargeting.pipeline import source_contacts

    planted = source_contacts(performance)  # A's planted feet (T, 4), the frames the slide is measured on
    targets = [*enumerate(synthetic.character_set(characters, seed=seed + 1)), (CASE, long_shins(source_skeleton))]
    rows, curves = [], {}
    for label, target in tqdm(targets, desc="characters"):
        rows += _character_rows(label, target, performance, planted, checkpoint, seed, out_dir,
                                curves if label == CASE else None)  # fmt: skip
    table = _table(rows)
    files.atomic_write(out_dir / "summary.md", lambda f: f.write("# motionlab demo\n\n" + table + "\n"), True)
    print()
    print(table)
    _plot_foot_heights(curves, performance.fps, out_dir / "foot_heights.png")
    print(f"\nwrote {len(planned)} files to {out_dir}/ (open the .bvh files in Blender or `motionlab view`)")
    return 0
