"""When the latent iteration should stop: the stop rule's settings against running all steps.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.stopping [--set build|check] [--seconds 4]

Retargets a set of clips onto Mixamo characters (their ``Running.bvh`` rigs) with the network of
``retargeting.load_real`` under several stop rules (:class:`SolverConfig`'s ``patience`` and
``min_delta``; ``patience 0``: all ``max_steps`` steps) and prints per rule the median steps and
solver seconds, the returned ``L_iter`` as a ratio of the all-steps run's (median and worst), and
the planted-foot slide (``Plausibility.slide``, cm/s: median and worst) with its worst excess
over the all-steps run.

``--set build`` are clips that no table of ``docs/rigs.md`` or Table 1 uses (Aj's training clips
and one take per studio); ``--set check`` are the rig matrices' family clips and the held-out
clips of ``experiments.retargeting.rigs --flags``.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from motionlab import data, retargeting
from motionlab.core import bvh
from motionlab.retargeting.solver import SolverConfig

BUILD = [
    "mixamo/Aj/Box_Turn.bvh",
    "mixamo/Aj/Catwalk_Walk.bvh",
    "mixamo/Aj/Golf_Post_Shot.bvh",
    "mixamo/Aj/Hit_Reaction.bvh",
    "mixamo/Aj/Dancing_Running_Man.bvh",
    "bandai_namco/dataset-1/run/dataset-1_run_active_001.bvh",
    "bandai_namco/dataset-1/kick/dataset-1_kick_normal_001.bvh",
    "cmu/131/131_03.bvh",
    "xia/walk/proud_ganimator.bvh",
]
"""Clips the stop rule is chosen on."""

CHECK = [
    "mixamo/Aj/Catwalk_Idle_To_Walk_Forward.bvh",
    "bandai_namco/dataset-1/walk/dataset-1_walk_normal_001.bvh",
    "cmu/131/131_01.bvh",
    "xia/walk/neutral_01_000.bvh",
    "xia/walk/strutting_01_000.bvh",
    "bandai_namco/dataset-1/walk-left/dataset-1_walk-left_normal_001.bvh",
]
"""Clips the chosen rule is checked on (rig matrix and held-out flag clips)."""

TARGETS = ("Goblin_m", "Mousey_m", "Kaya")

RULES = {
    "all steps": dict(patience=0),
    "patience 10, 0.1 %": dict(patience=10, min_delta=1e-3),
    "patience 10, 0.3 %": dict(patience=10, min_delta=3e-3),
    "patience 10, 1 %": dict(patience=10, min_delta=1e-2),
    "patience 5, 1 %": dict(patience=5, min_delta=1e-2),
    "lr 0.04": dict(lr=0.04),
    "lr 0.08": dict(lr=0.08),
    "lr 0.08, 50 steps": dict(lr=0.08, max_steps=50),
}


def clip(path, seconds: float):
    m = bvh.load(path)
    n = min(m.num_frames, max(2, int(round(seconds * m.fps))))
    return m.copy(
        local_rot=m.local_rot[:n], root_pos=m.root_pos[:n], local_pos=None if m.local_pos is None else m.local_pos[:n]
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", choices=("build", "check"), default="build")
    ap.add_argument("--seconds", type=float, default=4.0, help="length of each clip used (default 4 s)")
    ap.add_argument("--rules", nargs="+", choices=list(RULES), default=list(RULES), help="rules compared (default all)")
    args = ap.parse_args(argv)
    rules = {k: RULES[k] for k in dict.fromkeys(["all steps", *args.rules])}
    warnings.simplefilter("ignore", UserWarning)
    try:
        root = data.data_root()
        sources = [clip(root / rel, args.seconds) for rel in (BUILD if args.set == "build" else CHECK)]
        targets = [bvh.load(root / "mixamo" / t / "Running.bvh") for t in TARGETS]
        ckpt = retargeting.load_real("cpu", progress=False)
    except (data.DataNotFound, OSError, ValueError) as e:  # bvh.BVHError is a ValueError
        raise SystemExit(f"stopping: {e}") from None
    rows = {name: [] for name in rules}
    for s in sources:
        for t in targets:
            for name, kw in rules.items():
                t0 = time.perf_counter()
                run = retargeting.retarget(s, t, ckpt, "full", SolverConfig(**kw))
                rows[name].append(
                    (run.steps, time.perf_counter() - t0, min(run.history["loss"]), 100 * run.plausibility.slide)
                )
    ref = np.array(rows["all steps"])
    print(f"{len(sources)} clips x {len(targets)} targets ({args.set} set, first {args.seconds:g} s of each)")
    print(
        f"{'rule':<22}{'steps':>7}{'time s':>8}{'L ratio med':>12}{'worst':>8}{'slide med':>10}{'worst':>7}{'excess':>8}"
    )
    for name in rules:
        r = np.array(rows[name])
        ratio, excess = r[:, 2] / ref[:, 2], r[:, 3] - ref[:, 3]
        print(f"{name:<22}{np.median(r[:, 0]):7.0f}{np.median(r[:, 1]):8.2f}{np.median(ratio):12.3f}{ratio.max():8.3f}"
              f"{np.median(r[:, 3]):10.2f}{r[:, 3].max():7.2f}{excess.max():8.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
