"""What the latent iteration does on one pair: the planted-foot slide and each loss term over the steps.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.iteration_trace SOURCE.bvh [--target Kaya]

Retargets SOURCE (any rig motionlab reads) onto a Mixamo character (its ``Running.bvh`` rig)
with the network trained on Aj's real clips (``retargeting.load_real``) under several solver
settings, and prints per setting the planted-foot slide of the output (cm/s,
``Plausibility.slide``), the steps, the stop reason and the step whose iterate is returned
(``best_step``: the lowest L_iter), then each term's value at the start, its lowest and at the
last step. Copying the rotations and the network without iteration are the reference rows.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from motionlab import data, retargeting
from motionlab.core import bvh
from motionlab.retargeting.solver import SolverConfig

SETTINGS = {
    "default": SolverConfig(),
    "no plateau stop": SolverConfig(patience=0),
    "300 steps": SolverConfig(max_steps=300, patience=0),
    "lambda_contact 2": SolverConfig(lambda_contact=2.0),
    "lr 0.002": SolverConfig(lr=0.002),
    "lr 0.0002": SolverConfig(lr=0.0002),
}
"""Solver settings compared (the default first)."""


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="a BVH file")
    ap.add_argument("--target", default="Kaya", help="a Mixamo character of the course data (default Kaya)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore", UserWarning)
    try:
        rig = data.data_root() / "mixamo" / args.target / "Running.bvh"
        source, target = bvh.load(args.source), bvh.load(rig)
    except (data.DataNotFound, OSError, bvh.BVHError) as e:
        raise SystemExit(f"iteration_trace: {e}") from None
    ckpt = retargeting.load_real("cpu", progress=False)
    for method in ("copy", "network"):
        run = retargeting.retarget(source, target, ckpt, method)
        print(f"{method:<17} slide {100 * run.plausibility.slide:6.2f} cm/s")
    for label, cfg in SETTINGS.items():
        run = retargeting.retarget(source, target, ckpt, "full", cfg)
        print(f"{label:<17} slide {100 * run.plausibility.slide:6.2f} cm/s, {run.steps} steps ({run.stop_reason}), "
              f"returned step {run.best_step}")  # fmt: skip
        for term, values in run.history.items():
            v = np.asarray(values)
            print(f"    {term:<8} start {v[0]:.4g}, lowest {v.min():.4g} (step {int(v.argmin())}), last {v[-1]:.4g}")


if __name__ == "__main__":
    main()
