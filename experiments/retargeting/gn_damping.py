"""How the Gauss–Newton start's relative damping is chosen: condition numbers and residual angles.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.gn_damping [--seconds 3] [--damping 1e-3 1e-5 ...]
    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.gn_damping --evaluate CHECKPOINT --damping 1e-3 1e-6

For each rig family's clip (:data:`experiments.retargeting.rig_matrix.FAMILY_CLIPS`, plus the
synthetic walk) projected onto another family's rig by
:func:`motionlab.retargeting.solver.project_latent` with each relative damping ``d`` (the
solver's rounds and smoothing), prints, over the clip's frames at the returned start: the
largest and median condition number of the damped normal equations ``J Jᵀ + μ I`` (μ = d ×
mean diag J Jᵀ), the largest ``λ_max / mean diag`` (so the bound ``cond ≤ 1 + λ_max / μ``), and
the start's angle to A's rotations (largest and 99th percentile over frames and joints, degrees).

The rule (``docs/rigs.md``): the smallest ``d`` on the grid whose normal equations keep at least
half of float64's digits on every frame of the choosing families (``cond ≤ 1 / √ε``: the
Cholesky solve's relative error, about ``cond · ε``, stays below ``√ε``), chosen on the
``--choose`` families and checked on the others.

With ``--evaluate CHECKPOINT`` (Table 1's network, ``motionlab evaluate``'s): Table 1's copy
and full rows (:func:`motionlab.retargeting.evaluate.evaluate`) with each damping, one line each.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from experiments.retargeting import rig_matrix
from motionlab import data, retargeting
from motionlab.core import humanoid
from motionlab.retargeting import checkpoint, evaluate, pipeline, solver

TARGET_OF = {"mixamo": "bandai", "bandai": "mixamo", "cmu": "mixamo", "xia": "mixamo", "synthetic": "mixamo"}
"""The rig each family's clip is projected onto (another family's)."""
GRID = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
HALF_DIGITS = 1.0 / np.sqrt(np.finfo(np.float64).eps)
"""The largest condition number that keeps half of float64's digits in the solve."""


def measure(ckpt, source, target, damping: float, cfg: solver.SolverConfig) -> dict:
    """Condition numbers and the start's residual angles of one projection."""
    src = pipeline.prepare_source(source, ckpt, "full")
    pair = pipeline.prepare_pair(src, target)
    model = ckpt.model
    smooth = solver.smoother(cfg.smooth_sigma, model.encode(src.x).shape[-1], src.x.dtype)
    with torch.no_grad():
        phi0 = model.encode(src.x)
        phi = solver.project_latent(
            model, phi0, src.theta, pair.offsets, cfg.project_iters, damping, smooth, cfg.project_exact
        )
        emb = model.skeleton_embedding(pair.offsets)
        T, D = phi.shape[1], phi.shape[2]
        out, jac = model.rotation_jacobian(phi.reshape(T, D), emb.expand(T, -1))
        jjt = jac @ jac.transpose(1, 2)
        mean_diag = jjt.diagonal(dim1=1, dim2=2).mean(-1)
        eig = torch.linalg.eigvalsh(jjt)  # ascending
        mu = damping * mean_diag
        cond = ((eig[:, -1] + mu) / (eig[:, 0].clamp_min(0) + mu)).numpy()
        q = out.reshape(T, len(humanoid.JOINTS), 4)
        dot = (q * src.theta[0]).sum(-1).abs().clamp(max=1.0)
        angle = np.degrees(2 * torch.arccos(dot).numpy())
    return {
        "cond_max": float(cond.max()),
        "cond_med": float(np.median(cond)),
        "lam": float((eig[:, -1] / mean_diag).max()),
        "angle_max": float(angle.max()),
        "angle_p99": float(np.percentile(angle, 99)),
    }


def table1(path: str, dampings) -> None:
    """Table 1's "copy rotations, our root" and "full method" rows with each damping."""
    ckpt = checkpoint.load(path)
    rows = tuple(r for r in evaluate.ROWS if r[0] in ("copy rotations, our root", "full method"))
    keys = ("mse_h2", "pose_mse_h2", "skate", "slide")
    print(f"{'damping':>8} {'row':<26} " + " ".join(f"{k:>12}" for k in keys))
    for d in dampings:
        ev = evaluate.evaluate(
            data.data_root() / "mixamo", ckpt, rows=rows, solver=solver.SolverConfig(project_damping=d), progress=False
        )
        summary = ev.summary()
        for row in (r[0] for r in rows):
            print(f"{d:>8.0e} {row:<26} " + " ".join(f"{summary[row][k]:>12.3e}" for k in keys))
    truth = summary["ground truth"]
    print(f"{'':>8} {'ground truth':<26} {'-':>12} {'-':>12} {truth['skate']:>12.3e} {truth['slide']:>12.3e}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="seconds of each family's clip (default 3)")
    ap.add_argument("--damping", type=float, nargs="+", default=list(GRID), help="relative dampings to measure")
    ap.add_argument("--choose", nargs="+", default=["mixamo", "bandai"], help="families the rule is chosen on")
    ap.add_argument("--evaluate", metavar="CHECKPOINT", help="Table 1's copy and full rows with each damping instead")
    args = ap.parse_args(argv)
    start = time.perf_counter()
    if args.evaluate:
        table1(args.evaluate, args.damping)
        print(f"{time.perf_counter() - start:.0f} s")
        return
    ckpt = retargeting.load_default()
    clips = rig_matrix.family_clips(data.data_root() if data.has_data() else None, args.seconds)
    cfg = solver.SolverConfig()
    rows = []
    print(f"{'source':<10} {'target':<8} {'damping':>8} {'cond max':>10} {'cond med':>10} {'lam/diag':>8} "
          f"{'deg max':>8} {'deg p99':>8}")  # fmt: skip
    for family, clip in clips.items():
        tgt = TARGET_OF[family]
        target = clips[tgt] if tgt in clips else clips["synthetic"]
        for d in args.damping:
            m = measure(ckpt, clip, target, d, cfg)
            rows.append((family, d, m))
            print(f"{family:<10} {tgt:<8} {d:>8.0e} {m['cond_max']:>10.3g} {m['cond_med']:>10.3g} {m['lam']:>8.2f} "
                  f"{m['angle_max']:>8.3f} {m['angle_p99']:>8.4f}")  # fmt: skip
    print(f"\nrule: the smallest damping with cond <= 1/sqrt(eps) = {HALF_DIGITS:.3g} on every frame")
    for label, fams in (("chosen on", args.choose), ("checked on", [f for f in clips if f not in args.choose])):
        ok = [
            d for d in args.damping if all(m["cond_max"] <= HALF_DIGITS for f, dd, m in rows if dd == d and f in fams)
        ]
        print(f"{label:<11} {','.join(fams):<28} smallest damping within the bound: {min(ok) if ok else 'none':}")
    print(f"{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
