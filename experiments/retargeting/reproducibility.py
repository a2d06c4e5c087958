"""Do two numeric back ends give the same latent iteration? With and without the step grid.

The latent iteration (paper A, eqs. 9–17) runs on several (clip, character) pairs twice, in two
subprocesses: once with this machine's kernels, once with another numeric back end (torch's AVX2
kernels, MKL's compatible path, numpy without AVX-512, one thread: the settings of `.ci/run`'s
second test pass). For each pair it prints the Adam steps and stop of both runs and the largest
relative difference of their loss histories, with the step grid of ``solver.step_grid`` and
without it (spacing 2⁻⁶⁰ of a step: no rounding in practice).

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.retargeting.reproducibility
    python -m experiments.retargeting.reproducibility            # synthetic clips only

The pairs: Aj's clips of the ``retarget_gt`` set onto other Mixamo characters when the course
data is there (:data:`CHOSEN_ON`, looked at while the grids were chosen, and :data:`HELD_OUT`,
run only afterwards), and synthetic clips onto synthetic characters always.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

OTHER_BACK_END = {
    "ATEN_CPU_CAPABILITY": "avx2",
    "MKL_CBWR": "COMPATIBLE",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",
}
CHOSEN_ON = [("Running", "Mousey_m"), ("Jumping", "Goblin_m"), ("Jazz_Dancing", "Kaya"), ("Run_Arc_Left", "BigVegas")]
"""Pairs looked at while the grids were chosen (the step grid alone diverged on Jumping and
Run_Arc_Left, which is why the start is put on the grid too)."""
HELD_OUT = [
    ("Body_Jab_Cross", "SportyGranny"),
    ("Standing_To_Crouch", "Vampire_m"),
    ("Catwalk_Idle_To_Walk_Forward", "Mousey_m"),
    ("Injured_Walk_Left_Turn", "Goblin_m"),
    ("Standing_Turn_Right_90", "Kaya"),
    ("Standing_Land_To_Standing_Idle", "BigVegas"),
]
"""Pairs run only after the choice, to check it."""
REAL_PAIRS = CHOSEN_ON + HELD_OUT


def _pairs() -> list[tuple[str, str]]:
    from motionlab import data

    real = [p for p in REAL_PAIRS if data.has_data("mixamo", p[1])] if data.has_data("mixamo", "Aj") else []
    return real + [("synthetic run", "synthetic 0"), ("synthetic walk", "synthetic 1")]


def _run_pairs(grid_off: bool) -> list[dict]:
    """Runs in the child process: every pair, its steps, stop and loss history."""
    from motionlab import data, synthetic
    from motionlab.core import bvh
    from motionlab.retargeting import load_default, retarget, solver

    if grid_off:
        solver.step_grid = lambda lr: 2.0**-60 * lr  # noqa: E731 - the ablation: no rounding in practice
    ckpt = load_default("cpu")
    out = []
    for clip, character in _pairs():
        if clip.startswith("synthetic"):
            kind, seed = clip.split()[1], int(character.split()[1])
            source = synthetic.generate(kind, ckpt.skeleton, 150, ckpt.fps, seed=seed)
            target = synthetic.character_set(2, seed=3)[seed]
        else:
            source = bvh.load(data.clip_path("mixamo", "Aj", clip))
            target = bvh.load(data.clip_path("mixamo", character, clip)).skeleton
        r = retarget(source, target, ckpt)
        held = "" if (clip, character) in CHOSEN_ON or clip.startswith("synthetic") else " *"
        out.append(
            {"pair": f"{clip} -> {character}{held}", "steps": r.steps, "stop": r.stop_reason, "loss": r.history["loss"]}
        )
    return out


def _child(env_extra: dict, grid_off: bool) -> list[dict]:
    env = dict(os.environ, **env_extra)
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    code = f"import json, sys; sys.path.insert(0, {repo!r}); from experiments.retargeting import reproducibility as b; print(json.dumps(b._run_pairs({grid_off})))"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args(argv)
    print("back end A: this machine's; back end B:", ", ".join(f"{k}={v}" for k, v in OTHER_BACK_END.items()))
    print("* held out: run only after the grids were chosen")
    print(f"{'pair':44s} {'grid':>5s} {'steps A':>10s} {'steps B':>10s} {'max rel. loss difference':>25s}")
    for grid_off in (False, True):
        a, b = _child({}, grid_off), _child(OTHER_BACK_END, grid_off)
        for ra, rb in zip(a, b):
            n = min(len(ra["loss"]), len(rb["loss"]))
            diff = max(abs(x - y) / max(abs(x), 1e-300) for x, y in zip(ra["loss"][:n], rb["loss"][:n]))
            steps = f"{ra['steps']:5d} {ra['stop'][:4]:>4s}", f"{rb['steps']:5d} {rb['stop'][:4]:>4s}"
            print(f"{ra['pair']:44s} {'off' if grid_off else 'on':>5s} {steps[0]:>10s} {steps[1]:>10s} {diff:25.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
