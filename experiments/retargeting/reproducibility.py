"""Do two numeric back ends give the same latent iteration? With and without the step grid.

The latent iteration (paper A, eqs. 9–17) runs on several (clip, character) pairs twice, in two
subprocesses: once with this machine's kernels, once with another numeric back end (torch's AVX2
kernels, MKL's compatible path, numpy without AVX-512, one thread: the settings of `.ci/run`'s
pinned test pass). For each pair it prints the Adam steps and stop of both runs and the largest
relative difference of their loss histories, with the step grid of ``solver.step_grid`` and
without it (spacing 2⁻⁶⁰ of a step: no rounding in practice).

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.retargeting.reproducibility
    python -m experiments.retargeting.reproducibility            # synthetic clips only
    python -m experiments.retargeting.reproducibility --training [--real]

``--training`` trains the same network under each back end instead (a small synthetic set with
``TrainConfig.grid`` on and off; with ``--real`` also the network of ``retargeting.load_real``,
Aj's clips with evaluate's settings, grid on: the cached network against trainings in child
processes under back end B and under ``real.PINNED_BACK_END``, P, side by side), and prints how many parameter tensors differ
between the back ends, the largest difference, the final loss and the mean joint error of the
trained network on clips it never saw. Back end C (torch and numpy without SIMD kernels) is a
harsher check for a machine whose own kernels are back end B's.

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

from motionlab.retargeting.real import PINNED_BACK_END

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
NO_SIMD = {
    **OTHER_BACK_END,
    "ATEN_CPU_CAPABILITY": "default",
    "NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR",
}
"""Back end C: torch's and numpy's scalar kernels, one thread."""
REAL_BACK_ENDS = {"B": OTHER_BACK_END, "P": PINNED_BACK_END}
"""The back ends the real network is trained again under: B, and P, the one ``load_real`` trains under."""
SMALL = {"clips": 8, "steps": 200, "batch_size": 16}
"""The small training run: synthetic clips (seed 0), Adam steps, windows per step."""


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


def _held_out_error(ckpt, motions) -> float:
    """Mean joint-position error (cm) of the network's reconstruction of ``motions`` on their own skeleton."""
    import numpy as np
    import torch

    from motionlab.core import preprocess
    from motionlab.retargeting.features import clip_features

    err = []
    for m in motions:
        c = preprocess.prepare(m, ckpt.fps)
        f = clip_features(c)
        x = torch.tensor(ckpt.stats.normalize(f.x), dtype=ckpt.dtype)[None]
        offsets = torch.tensor(c.skeleton.offsets, dtype=ckpt.dtype)
        offsets[0] = 0.0  # as in training: the root's offset zeroed
        with torch.no_grad():
            out = ckpt.model(x, offsets[None])
        err.append(np.linalg.norm(out.positions[0].numpy() - f.positions, axis=-1).ravel())
    return 100 * float(np.concatenate(err).mean())


def _train_weights(which: str, grid: bool, path: str) -> dict:
    """Runs in the child process: trains ``which`` ("small" or "real"), saves the weights to ``path``."""
    import torch

    from motionlab import synthetic
    from motionlab.retargeting.train import TrainConfig, train

    if which == "small":
        motions, held = synthetic.dataset(SMALL["clips"], seed=0), synthetic.dataset(4, seed=321)
        cfg = TrainConfig(steps=SMALL["steps"], batch_size=SMALL["batch_size"], device="cpu", grid=grid)
    else:
        from motionlab import data
        from motionlab.core import bvh
        from motionlab.retargeting import real
        from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS

        motions = [bvh.load(p) for p in real.training_paths()]
        held = [bvh.load(data.clip_path("mixamo", "Aj", a)) for a in DEFAULT_ANIMATIONS]
        cfg = real.train_config(device="cpu", grid=grid)
    ckpt, history = train(motions, cfg, progress=False)
    torch.save(ckpt.model.state_dict(), path)
    return {"loss": history[-1]["loss"], "held_out_cm": _held_out_error(ckpt, held), "seconds": ckpt.info["seconds"]}


def _start_child(env_extra: dict, training: tuple | None = None, grid_off: bool = False) -> subprocess.Popen:
    env = dict(os.environ, **env_extra)
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    call = f"b._train_weights{training!r}" if training else f"b._run_pairs({grid_off})"
    code = f"import json, sys; sys.path.insert(0, {repo!r}); from experiments.retargeting import reproducibility as b; print(json.dumps({call}))"
    return subprocess.Popen(
        [sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def _finish_child(child: subprocess.Popen) -> list[dict] | dict:
    out, err = child.communicate()
    if child.returncode:
        raise RuntimeError(f"the child process failed:\n{err}")
    return json.loads(out.strip().splitlines()[-1])


def _child(env_extra: dict, grid_off: bool, training: tuple | None = None) -> list[dict] | dict:
    return _finish_child(_start_child(env_extra, training, grid_off))


def _compare_weights(path_a: str, path_b: str) -> tuple[int, int, float]:
    """(parameter tensors that differ, of how many, largest absolute difference) between two saved state dicts."""
    import torch

    a, b = torch.load(path_a), torch.load(path_b)
    differ = [k for k in a if not torch.equal(a[k], b[k])]
    largest = max((float((a[k] - b[k]).abs().max()) for k in differ), default=0.0)
    return len(differ), len(a), largest


def training(real: bool, small: bool = True, real_back_ends: str = "BP") -> None:
    """Prints, per training run and grid setting, whether back ends B and C give back end A's weights
    (the real run: each of ``real_back_ends``, keys of :data:`REAL_BACK_ENDS`)."""
    import tempfile

    print("back end A: this machine's; B:", ", ".join(f"{k}={v}" for k, v in OTHER_BACK_END.items()))
    print(
        "back end C: B with ATEN_CPU_CAPABILITY=default, NPY_DISABLE_CPU_FEATURES="
        + NO_SIMD["NPY_DISABLE_CPU_FEATURES"]
    )
    print(
        f"small: {SMALL['clips']} synthetic clips, {SMALL['steps']} steps of {SMALL['batch_size']} windows; held out: 4 other synthetic clips"
    )
    print("real: retargeting.load_real's network (Aj's clips but Table 1's 10, evaluate's settings, grid on):")
    print("      A = the cached one, B and P = trained again in children; held out: those 10")
    print("back end P (real.PINNED_BACK_END):", ", ".join(f"{k}={v}" for k, v in REAL_BACK_ENDS["P"].items()))
    head = f"{'run':6s} {'grid':>4s} {'back end':>8s} {'differing tensors':>18s} {'max |diff|':>11s} {'final loss':>11s} {'held-out cm':>11s} {'train s':>8s}"
    print(head)
    print("-" * len(head))
    with tempfile.TemporaryDirectory() as tmp:
        real_paths = {k: os.path.join(tmp, f"real_{k}.pt") for k in "ABP"}
        if real:  # minutes per run: back ends B and P train beside the rest; A is the cached network
            others = {k: _start_child(REAL_BACK_ENDS[k], ("real", True, real_paths[k])) for k in real_back_ends}
        for grid in (True, False) if small else ():
            paths = {k: os.path.join(tmp, f"small_{grid}_{k}.pt") for k in "ABC"}
            for k, env in {"A": {}, "B": OTHER_BACK_END, "C": NO_SIMD}.items():
                _row("small", grid, k, _child(env, False, ("small", grid, paths[k])), paths)
        if real:
            _row("real", True, "A", _real_cached(real_paths["A"]), real_paths)
            for k, child in others.items():
                _row("real", True, k, _finish_child(child), real_paths)


def _real_cached(path: str) -> dict:
    """Back end A of the real run: ``retargeting.load_real``'s network (this process's back end)."""
    import torch

    from motionlab import data
    from motionlab.core import bvh
    from motionlab.retargeting import real
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS

    ckpt = real.load_real("cpu")
    torch.save(ckpt.model.state_dict(), path)
    held = [bvh.load(data.clip_path("mixamo", "Aj", a)) for a in DEFAULT_ANIMATIONS]
    return {
        "loss": ckpt.info["final_loss"],
        "held_out_cm": _held_out_error(ckpt, held),
        "seconds": ckpt.info["seconds"],
    }


def _row(which: str, grid: bool, k: str, r: dict, paths: dict) -> None:
    n, total, largest = _compare_weights(paths["A"], paths[k])
    print(
        f"{which:6s} {'on' if grid else 'off':>4s} {k:>8s} {f'{n} of {total}':>18s} {largest:11.1e} "
        f"{r['loss']:11.6g} {r['held_out_cm']:11.4f} {r['seconds']:8.0f}",
        flush=True,
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--training", action="store_true", help="compare trained weights instead of iterations")
    parser.add_argument("--real", action="store_true", help="with --training: also the real network (minutes)")
    parser.add_argument("--no-small", action="store_true", help="with --training --real: the real network only")
    parser.add_argument(
        "--real-back-ends", default="BP", choices=["BP", "B", "P"], help="with --real: train under these"
    )
    args = parser.parse_args(argv)
    if args.training:
        training(args.real, small=not args.no_small, real_back_ends=args.real_back_ends)
        return 0
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
