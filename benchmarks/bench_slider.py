"""Notebook 04's legs slider in the kernel: the latent solve per release, and the Gauss–Newton chunk.

1. ``--chunks``: seconds of one Gauss–Newton round of the solver's start
   (``solver.gauss_newton_step``) for chunks of 16 … 2048 frames, on the inputs of notebook 04's
   slider (120-frame walk, 239 frames at the network's rate, one row) and on two held-out sizes:
   a 960-frame clip and a batch of 8 rows of 239 frames; each median of ``--repeats`` rounds,
   sizes interleaved. It also checks that the round's step does not depend on the chunk.
2. the slider (default): the editor's solve (``proportion_solver(clip, max_steps=30)``, legs
   1.30 → 1.60 in 0.05 steps, arms 0.8, as notebook 04) timed in-process, median and max, and each
   result compared with a fresh ``retarget(..., "full")`` of the same skeleton (largest joint
   difference, metres, must be 0).

Prints the load average before and after. ``--code DIR`` imports motionlab from another
checkout (e.g. ``git worktree add /tmp/old <commit>``) to time an older version the same way
(part 2 only). Usage (repository root)::

    python benchmarks/bench_slider.py                      # the slider's solve
    python benchmarks/bench_slider.py --code /tmp/old      # ... with an older motionlab
    python benchmarks/bench_slider.py --chunks             # the chunk sweep
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import torch

CHUNKS = (16, 32, 64, 128, 256, 2048)


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def _round_inputs(ckpt, clip, skeleton):
    from motionlab import retargeting
    from motionlab.retargeting import solver

    """The arguments of the solver's first Gauss–Newton round for ``clip`` on ``skeleton``."""
    seen = []
    real = solver.gauss_newton_step

    def spy(*args):
        seen.append(args)
        return real(*args)

    solver.gauss_newton_step = spy
    try:
        retargeting.retarget(clip, skeleton, ckpt, "full", solver=retargeting.SolverConfig(max_steps=0))
    finally:
        solver.gauss_newton_step = real
    return seen[0]


def chunks(ckpt, repeats: int) -> None:
    """Part 1: one Gauss–Newton round per chunk size, three problem sizes."""
    from motionlab import synthetic
    from motionlab.core import humanoid, threads
    from motionlab.retargeting import solver

    skeleton = humanoid.canonical_skeleton()
    target = humanoid.scale_bones(skeleton, legs=1.3, arms=0.8)
    walk = _round_inputs(ckpt, synthetic.generate("walk", skeleton, 120, 30.0, seed=1), target)
    long = _round_inputs(ckpt, synthetic.generate("walk", skeleton, 480, 30.0, seed=2), target)
    model, phi, rot, emb, damping = walk
    batch = (model, phi.repeat(8, 1, 1), rot.repeat(8, 1, 1, 1), emb.expand(8, -1), damping)
    size = lambda args: "x".join(map(str, args[1].shape[:2]))  # noqa: E731
    cases = {f"slider {size(walk)}": walk, f"held-out {size(long)}": long, f"held-out {size(batch)}": batch}
    shipped, rows = solver.PROJECT_FRAMES, {}
    print(f"part 1: one Gauss-Newton round, seconds (median of {repeats}); load before {_load()}")
    try:
        with torch.no_grad(), threads.torch_threads(1):
            for name, args in cases.items():
                solver.PROJECT_FRAMES = 10**9
                reference = solver.gauss_newton_step(*args)[0]
                for c in CHUNKS:
                    solver.PROJECT_FRAMES = c
                    same = bool(torch.equal(solver.gauss_newton_step(*args)[0], reference))
                    rows[(name, c)] = ([], same)
            for _ in range(repeats):
                for name, args in cases.items():
                    for c in CHUNKS:
                        solver.PROJECT_FRAMES = c
                        start = time.perf_counter()
                        solver.gauss_newton_step(*args)
                        rows[(name, c)][0].append(time.perf_counter() - start)
    finally:
        solver.PROJECT_FRAMES = shipped
    print(f"{'chunk':>6} " + " ".join(f"{n:>16}" for n in cases))
    for c in CHUNKS:
        cells = [f"{statistics.median(rows[(n, c)][0]):9.3f}{'' if rows[(n, c)][1] else ' (DIFF)':>7}" for n in cases]
        print(f"{c:6d} " + " ".join(f"{x:>16}" for x in cells))
    print(f"motionlab's chunk on the CPU: PROJECT_FRAMES = {shipped}; load after {_load()}")


def slider(ckpt, repeats: int) -> None:
    """Part 2: the editor's solve per release, and the same result as a fresh retarget."""
    import motionlab
    from motionlab import retargeting, synthetic
    from motionlab.core import humanoid
    from motionlab.retargeting.proportions import proportion_solver

    skeleton = humanoid.canonical_skeleton()
    clip = synthetic.generate("walk", skeleton, 120, 30.0, seed=1)  # as notebook 04
    solve = proportion_solver(clip, max_steps=30)
    config = retargeting.SolverConfig(max_steps=30)
    print(
        f"part 2: notebook 04's legs slider, solve per release (motionlab from {Path(motionlab.__file__).parents[1]})"
    )
    print(f"load before {_load()}")
    seconds, worst = [], 0.0
    for k in range(repeats + 1):
        target = humanoid.scale_bones(skeleton, legs=1.3 + 0.05 * (k % 7), arms=0.8)
        start = time.perf_counter()
        motion, history = solve(target)
        seconds.append(time.perf_counter() - start)
        fresh = retargeting.retarget(clip, target, ckpt, "full", solver=config).motion
        diff = float(np.abs(motion.global_positions() - fresh.global_positions()).max())
        worst = max(worst, diff)
        print(f"  legs {1.3 + 0.05 * (k % 7):.2f}  solve {seconds[-1]:.3f} s  steps {len(history['loss']) - 1:2d}  "
              f"L_iter {history['loss'][-1]:.6g}  vs fresh retarget {diff:.3g} m" + ("  (warm-up)" if k == 0 else ""))  # fmt: skip
    timed = seconds[1:]
    print(f"solve median {statistics.median(timed):.3f} s, max {max(timed):.3f} s over {len(timed)} releases; "
          f"largest difference from a fresh retarget {worst:.3g} m; load after {_load()}")  # fmt: skip


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--chunks", action="store_true", help="part 1: the Gauss-Newton chunk sweep")
    parser.add_argument("--repeats", type=int, default=7, help="rounds per chunk size, or timed releases (default 7)")
    parser.add_argument(
        "--code", type=Path, default=Path(__file__).resolve().parents[1], help="motionlab checkout to import"
    )
    args = parser.parse_args(argv)
    sys.path.insert(0, str(args.code.resolve()))
    from motionlab import retargeting

    ckpt = retargeting.load_default()
    if args.chunks:
        chunks(ckpt, args.repeats)
    else:
        slider(ckpt, args.repeats)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
