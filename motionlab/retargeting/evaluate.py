"""Table 1 of paper A on real data: retarget A's clips to other characters, compare with theirs.

Works on any folder laid out as ``<Character>/<Animation>.bvh``: for every target character B
and animation, A's clip is retargeted onto B's canonical T-pose skeleton (B's rig alone, none
of B's motion) and compared with B's real clip reduced to the same 22 joints.

Metrics (all from :mod:`motionlab.core.metrics`, positions in world space):

* ``mse`` (cm²) and ``mse/h²`` — squared joint-position error over frames, joints and axes; the
  second divides by B's height² (``h`` = the rest height of B's **22-joint** skeleton, highest
  minus lowest joint, as the literature and motionlab's conventions define it; Aj: 141.95 cm,
  the paper gives 141.97), the de facto metric; ``pose mse/h²`` does the same after subtracting each
  frame's root position (pose only, root trajectory removed);
* ``mpjpe`` (cm) — mean per-joint Euclidean error;
* ``smooth`` (cm/frame²) — mean acceleration magnitude (the real clips' value is printed too);
* ``pen`` (% of h) — mean depth of the four foot joints below the ground;
* ``skate`` (cm/s) — mean horizontal foot speed while touching the ground (a foot joint below
  5 cm): it counts low swinging feet and misses floating ones, so it depends on the root height too;
* ``slide`` (cm/s) — mean horizontal speed of the feet on the frames where A's foot is planted
  (:func:`motionlab.retargeting.pipeline.source_contacts`): how still a planted foot stays;
* ``time`` (s) — wall time of the method per clip (network + latent iteration).

**The protocol differs from the paper's** (§3): the paper trains on Malcolm and retargets Aj
onto BigVegas, Claire and Mutant (200 clips); those targets are not in the shared data, so
motionlab trains on Aj's own other clips and retargets Aj's 10 ``retarget_gt`` animations onto
six other Mixamo characters. The network never sees the evaluated animations (they are left
out of training); ``folds=K`` also handles folders where every clip of the source is evaluated,
by training K networks, each without one K-th of the animations.

Rows: :data:`ROWS` (kept with the same labels and order across versions) and
:data:`ABLATIONS` (the full method with one of motionlab's additions switched off).

Alignment with the ground truth: every method uses the root trajectory of
:mod:`motionlab.retargeting.pipeline`: A's trajectory scaled about the world origin by B/A
leg sizes (so the start is A's start scaled, with A's heading). Mixamo's own clips start at
the origin too, so no per-clip fitting to the ground truth is done.

Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from motionlab.core import humanoid, metrics, preprocess
from motionlab.retargeting import terms
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.pipeline import retarget, source_contacts
from motionlab.retargeting.real import DEFAULT_ANIMATIONS, DEFAULT_SOURCE, training_clips
from motionlab.retargeting.solver import SolverConfig

__all__ = [
    "DEFAULT_SOURCE",
    "DEFAULT_TARGETS",
    "DEFAULT_ANIMATIONS",
    "ROWS",
    "ABLATIONS",
    "rows_with_root",
    "Evaluation",
    "training_clips",
    "shared_animations",
    "evaluate",
]

DEFAULT_TARGETS = ("BigVegas", "Kaya", "SportyGranny", "Goblin_m", "Mousey_m", "Vampire_m")
ROWS: tuple[tuple[str, str, str], ...] = (
    ("copy rotations, root x leg length", "copy", "legs"),
    ("copy rotations, our root", "copy", "stride"),
    ("no iteration", "network", "stride"),
    ("full method", "full", "stride"),
)
"""Table rows as ``(label, method, root_mode)``: the first is the data notes' plain baseline
(everything scaled by thigh + shin); the others share the pipeline's default root trajectory."""

ABLATIONS: tuple[tuple, ...] = (
    ("full, paper's two losses", "full", "stride", {"paper_terms": True}),
    ("full, encoder start", "full", "stride", {"init": "encoder", "lr": 0.1}),
    ("full, without q_delta", "full", "stride", {"correction": False}),
    ("full, plain Adam", "full", "stride", {"backtrack": False}),
    ("full, rotations-only start", "full", "stride", {"project_lengths": False}),
    ("full, without L_clear", "full", "stride", {"without": "clearance"}),
)
"""The full method with one addition switched off: ``(label, method, root_mode, options)``, where
``options`` are :class:`SolverConfig` fields, ``correction=False`` (q_Δ replaced by the identity)
``paper_terms=True`` (every loss term but the paper's two weighted 0: :data:`terms.PAPER_TERMS`)
or ``without=NAME`` (that registered term weighted 0)."""


def rows_with_root(root_mode: str, ablations: bool = False) -> tuple[tuple, ...]:
    """:data:`ROWS` (and :data:`ABLATIONS`) with the root of every row but the plain baseline set to ``root_mode``."""
    rows = ROWS + (ABLATIONS if ablations else ())
    if root_mode == ROWS[-1][2]:
        return rows
    return rows[:1] + tuple((r[0].replace("our root", f"root {root_mode}"), r[1], root_mode, *r[3:]) for r in rows[1:])


_CM = 100.0  # metres → file units (centimetres)


def _load(path: Path):
    from motionlab.core import bvh  # imported here: the BVH module is optional for the rest

    return bvh.load(path)


def shared_animations(folder: str | Path, source: str, targets: Sequence[str]) -> list[str]:
    """The animation stems that ``source`` and every target have in ``folder``, sorted.

    Raises
    ------
    FileNotFoundError for a missing character folder; ValueError when no animation is shared.
    """
    folder = Path(folder)
    for name in (source, *targets):
        if not (folder / name).is_dir():
            raise FileNotFoundError(f"character folder {folder / name} not found")
    common = {p.stem for p in (folder / source).glob("*.bvh")}
    for t in targets:
        common &= {p.stem for p in (folder / t).glob("*.bvh")}
    if not common:
        raise ValueError(f"no animation shared by {source} and {list(targets)} in {folder}")
    return sorted(common)


@dataclass
class Evaluation:
    """Per-clip records and the summary table.

    Attributes
    ----------
    records : list of dict   one per (row label, target, animation) with every metric
    ground_truth : list of dict   the real clips' own smoothness, penetration and skating
    rows : list of str       row labels in order
    """

    records: list = field(default_factory=list)
    ground_truth: list = field(default_factory=list)
    rows: list = field(default_factory=list)

    def summary(self) -> dict[str, dict[str, float]]:
        """Mean of every metric per row label (and ``"ground truth"``)."""
        out = {}
        for label in self.rows:
            recs = [r for r in self.records if r["row"] == label]
            keys = [k for k in recs[0] if isinstance(recs[0][k], float)] if recs else []
            out[label] = {k: float(np.mean([r[k] for r in recs])) for k in keys}
        if self.ground_truth:
            keys = [k for k in self.ground_truth[0] if isinstance(self.ground_truth[0][k], float)]
            out["ground truth"] = {k: float(np.mean([r[k] for r in self.ground_truth])) for k in keys}
        return out

    def table(self) -> str:
        """The summary as a fixed-width text table (units in the header)."""
        s = self.summary()
        cols = [
            ("mse", "MSE cm²", "{:9.2f}"),
            ("mse_h2", "MSE/h²", "{:9.2e}"),
            ("pose_mse_h2", "pose MSE/h²", "{:11.2e}"),
            ("mpjpe", "MPJPE cm", "{:8.2f}"),
            ("smooth", "smooth cm/f²", "{:12.3f}"),
            ("pen", "pen %h", "{:7.3f}"),
            ("skate", "skate cm/s", "{:10.2f}"),
            ("time", "time s/clip", "{:11.3f}"),
            ("slide", "slide cm/s", "{:10.2f}"),
        ]
        n = len(self.records) // max(len(self.rows), 1)
        width = max([len(r) for r in s] + [12])
        head = f"{'method':<{width}} " + " ".join(f"{c[1]:>{len(c[2].format(0.0))}}" for c in cols)
        lines = [
            f"Retargeting evaluation over {n} clips (h = target height, 1 file unit = 1 cm)",
            head,
            "-" * len(head),
        ]
        for label, vals in s.items():
            cells = []
            for key, _, fmt in cols:
                w = len(fmt.format(0.0))
                cells.append(fmt.format(vals[key]) if key in vals else " " * (w - 1) + "-")
            lines.append(f"{label:<{width}} " + " ".join(cells))
        return "\n".join(lines)

    def breakdown(self, key: str = "mse_h2") -> str:
        """Per target character: the mean of ``key`` for every row (a text table)."""
        targets = list(dict.fromkeys(r["target"] for r in self.records))
        width = max([len(r) for r in self.rows] + [12])
        head = f"{key + ' by target':<{width}} " + " ".join(f"{t[:12]:>12}" for t in targets)
        lines = [head, "-" * len(head)]
        for label in self.rows:
            cells = []
            for t in targets:
                vals = [r[key] for r in self.records if r["row"] == label and r["target"] == t]
                cells.append(f"{np.mean(vals):12.2e}" if vals else f"{'-':>12}")
            lines.append(f"{label:<{width}} " + " ".join(cells))
        return "\n".join(lines)


def _gt_metrics(pos: np.ndarray, fps: float, height: float, planted: np.ndarray) -> dict:
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    n = min(len(pos), len(planted))
    return {
        "smooth": metrics.smoothness(pos) * _CM,
        "pen": 100 * metrics.foot_penetration(pos, feet) / height,
        "skate": metrics.foot_skating(pos, feet, fps) * _CM,
        "slide": metrics.planted_slide(pos[:n], feet, planted[:n], fps) * _CM,
    }


def evaluate(
    folder: str | Path,
    checkpoint: Checkpoint | None,
    source: str = DEFAULT_SOURCE,
    targets: Sequence[str] = DEFAULT_TARGETS,
    animations: Sequence[str] | None = DEFAULT_ANIMATIONS,
    rows: Sequence[tuple[str, str, str]] = ROWS,
    solver: SolverConfig | None = None,
    progress: bool = True,
) -> Evaluation:
    """Run every row's method on every (target, animation) pair and collect the metrics.

    Parameters
    ----------
    folder : a folder laid out as ``<Character>/<Animation>.bvh``
    checkpoint : the network trained on ``source`` (None is allowed when only "copy" rows run)
    source, targets : character folder names
    animations : clip stems; ``None``: every stem that the source and all targets share
    rows : ``(label, method, root_mode[, options])``, see :data:`ROWS` and :data:`ABLATIONS`
    solver : latent iteration settings for the "full" rows
    """
    folder = Path(folder)
    animations = _check_inputs(folder, checkpoint, source, targets, animations, rows)
    result = Evaluation(rows=[r[0] for r in rows])
    sources, planted = {}, {}
    pairs = [(t, a) for t in targets for a in animations]
    for target, anim in tqdm(pairs, desc="evaluating", disable=not progress):
        src_path, gt_path = folder / source / f"{anim}.bvh", folder / target / f"{anim}.bvh"
        if not src_path.is_file() or not gt_path.is_file():
            warnings.warn(
                f"skipping {target}/{anim}: {src_path if not src_path.is_file() else gt_path} missing", stacklevel=2
            )
            continue
        gt_rig = _load(gt_path)
        fps = checkpoint.fps if checkpoint is not None else gt_rig.fps
        if anim not in sources:
            sources[anim] = _load(src_path)
            planted[anim] = source_contacts(preprocess.prepare(sources[anim], fps))
        gt = preprocess.prepare(gt_rig, fps)
        gt_pos = gt.global_positions()
        height = gt.skeleton.height()  # the 22-joint rest height
        result.ground_truth.append(
            {"target": target, "animation": anim, **_gt_metrics(gt_pos, fps, height, planted[anim])}
        )
        for row in rows:
            out = _run_row(row, sources[anim], gt_rig.skeleton, checkpoint, solver, fps)
            rec = _record(out, gt_pos, fps, height, planted[anim], f"{target}/{anim}")
            result.records.append({"row": row[0], "target": target, "animation": anim, **rec})
    return result


def _check_inputs(folder: Path, checkpoint, source, targets, animations, rows) -> list[str]:
    """The animations to evaluate; raises when a character folder, the animations or a needed checkpoint is missing."""
    if not (folder / source).is_dir():
        raise FileNotFoundError(f"source character folder {folder / source} not found")
    for t in targets:
        if not (folder / t).is_dir():
            raise FileNotFoundError(f"target character folder {folder / t} not found")
    if animations is None:
        animations = shared_animations(folder, source, targets)
    if not animations:
        raise ValueError(f"no animation shared by {source} and {list(targets)} in {folder}")
    if checkpoint is None and any(r[1] != "copy" for r in rows):
        raise ValueError("a checkpoint is needed for the network rows")
    return list(animations)


def _run_row(row: tuple, source, target, checkpoint: Checkpoint | None, solver: SolverConfig | None, fps: float):
    """One row's method on one pair (:func:`retarget`) at ``fps`` (the ground truth's rate), q_Δ
    switched off for the call where the row asks."""
    _, method, root_mode = row[:3]
    options = dict(row[3]) if len(row) > 3 else {}
    correction = options.pop("correction", True)
    off = {options.pop("without"): 0.0} if "without" in options else {}
    if options.pop("paper_terms", False):
        off = {t.name: 0.0 for t in terms.registered() if t.name not in terms.PAPER_TERMS}
    if off:
        options["weights"] = {**(solver or SolverConfig()).weights, **off}
    cfg = dataclasses.replace(solver or SolverConfig(), **options)
    model = checkpoint.model if checkpoint is not None else None
    if model is not None:
        model.use_correction = correction
    try:
        return retarget(source, target, checkpoint, method, cfg, root_mode, fps=fps)
    finally:
        if model is not None:
            model.use_correction = True


def _record(out, gt_pos: np.ndarray, fps: float, height: float, planted: np.ndarray, name: str) -> dict:
    """Every metric of one retargeted clip against the real one (the first frames both have)."""
    pos = out.positions
    n = min(len(pos), len(gt_pos))
    if len(pos) != len(gt_pos):
        warnings.warn(f"{name}: {len(pos)} generated vs {len(gt_pos)} real frames; comparing {n}", stacklevel=3)
    p, g = pos[:n], gt_pos[:n]
    rel_p, rel_g = p - p[:, :1], g - g[:, :1]
    return {
        "mse": metrics.mse(p, g) * _CM**2,
        "mse_h2": metrics.mse(p, g, height=height),
        "pose_mse_h2": metrics.mse(rel_p, rel_g, height=height),
        "mpjpe": metrics.mpjpe(p, g) * _CM,
        **_gt_metrics(p, fps, height, planted),
        "time": out.seconds,
        "steps": out.steps,
        "stop_reason": out.stop_reason,
    }
