"""What the latent iteration does on one pair: the planted-foot slide and each loss term over the steps.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.iteration_trace SOURCE.bvh [--target Kaya] [--brief]

Retargets SOURCE (any rig motionlab reads) onto a Mixamo character (its ``Running.bvh`` rig)
with the network trained on Aj's real clips (``retargeting.load_real``) under several solver
settings, and prints per setting the planted-foot slide of the output (cm/s,
``Plausibility.slide``), the steps, the stop reason and the step whose iterate is returned
(``best_step``: the lowest L_iter), then each term's value at the start, its lowest and at the
last step, and the shortest raw quaternion of the start (F_qlinear before normalisation, see
``solver.project_latent``). Copying the rotations and the network without iteration are the
reference rows.
"""

from __future__ import annotations

import argparse
import warnings
from contextlib import contextmanager

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.core import bvh
from motionlab.retargeting import solver
from motionlab.retargeting.solver import SolverConfig

OLD = dict(project_lengths=False, backtrack=False)
"""The solver before it kept the raw quaternions' lengths and backtracked."""

SETTINGS = {
    "default": SolverConfig(),
    "rotations-only start": SolverConfig(project_lengths=False),
    "plain Adam": SolverConfig(backtrack=False),
    "neither (old)": SolverConfig(**OLD),
    "  no plateau stop": SolverConfig(**OLD, patience=0),
    "  300 steps": SolverConfig(**OLD, max_steps=300, patience=0),
    "  lambda_contact 2": SolverConfig(**OLD, lambda_contact=2.0),
    "  lr 0.002": SolverConfig(**OLD, lr=0.002),
    "  lr 0.0002": SolverConfig(**OLD, lr=0.0002),
}
"""Solver settings compared: the default first; without the length-keeping start
(``project_lengths``), without backtracking (``backtrack``), without either, and variations of
the last (indented)."""


@contextmanager
def shortest_raw_quaternion(found: list):
    """While active, append to ``found`` the shortest raw quaternion ``‖W φ + b‖`` (F_qlinear,
    before normalisation) of every start :func:`solver.project_latent` returns."""
    real = solver.project_latent

    def spy(model, *args, **kwargs):
        out = real(model, *args, **kwargs)
        with torch.no_grad():
            found.append(float(model.f_qlinear(out).unflatten(-1, (22, 4)).norm(dim=-1).min()))
        return out

    solver.project_latent = spy
    try:
        yield found
    finally:
        solver.project_latent = real


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="a BVH file")
    ap.add_argument("--target", default="Kaya", help="a Mixamo character of the course data (default Kaya)")
    ap.add_argument("--checkpoint", help="a network file to use instead of retargeting.load_real's")
    ap.add_argument("--brief", action="store_true", help="one line per setting, without the terms")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore", UserWarning)
    try:
        rig = data.data_root() / "mixamo" / args.target / "Running.bvh"
        source, target = bvh.load(args.source), bvh.load(rig)
    except (data.DataNotFound, OSError, bvh.BVHError) as e:
        raise SystemExit(f"iteration_trace: {e}") from None
    try:
        ckpt = (
            retargeting.load(args.checkpoint, "cpu")
            if args.checkpoint
            else retargeting.load_real("cpu", progress=False)
        )
    except (OSError, ValueError) as e:
        raise SystemExit(f"iteration_trace: {e}") from None
    for method in ("copy", "network"):
        run = retargeting.retarget(source, target, ckpt, method)
        print(f"{method:<20} slide {100 * run.plausibility.slide:6.2f} cm/s")
    for label, cfg in SETTINGS.items():
        with shortest_raw_quaternion([]) as shortest:
            run = retargeting.retarget(source, target, ckpt, "full", cfg)
        print(f"{label:<20} slide {100 * run.plausibility.slide:6.2f} cm/s, {run.steps} steps ({run.stop_reason}), "
              f"returned step {run.best_step}; shortest raw quaternion at the start {min(shortest):.3f}")  # fmt: skip
        for term, values in () if args.brief else run.history.items():
            v = np.asarray(values)
            print(f"    {term:<8} start {v[0]:.4g}, lowest {v.min():.4g} (step {int(v.argmin())}), last {v[-1]:.4g}")


if __name__ == "__main__":
    main()
