"""Throughput of expanding a motion database: one process per pair vs batched vs Ray.

Same inputs, same run: source clips × characters, retargeted three ways, each writing BVH files:

1. ``motionlab retarget`` once per pair (a new Python process each: import, checkpoint, solve);
2. ``expand`` in this process (network loaded once, pairs of equal length in one batch), with
   its default of one torch thread and, for comparison, with two;
3. ``expand --backend ray`` with a local Ray instance of 2 workers (when Ray is installed).

Throughput is source frames (at the checkpoint's rate) per second of wall time, start-up
included. For each ``expand`` run it prints the batch count, the time split (load: read and
prepare the sources; solve: the batches; write: files and manifest) and, on a GPU, the peak GPU
memory (``torch.cuda.max_memory_allocated``). The machine's load average is printed before and
after (other jobs share the CPU). The outputs of all three are compared byte for byte.
``--skip-per-process`` leaves out the slow one-process-per-pair run (then the batched outputs are
compared with each other).

Usage::

    MOTIONLAB_DATA=/work/shared/data python benchmarks/bench_expand.py              # 4 Aj clips x 4 characters
    python benchmarks/bench_expand.py --clips 10 --device cuda                     # on a GPU
    python benchmarks/bench_expand.py --synthetic                                  # no real data
    python benchmarks/bench_expand.py --memory                                     # bytes per frame of a batch
    python benchmarks/bench_expand.py --verify OUT                                 # OUT's files == retarget's

On a GPU (issue 40; ``docs/performance.md``): all of Aj's clips onto the six Table 1 characters,
compared with a CPU run of the same pairs (``motionlab expand ... --device cpu -o REF``)::

    python benchmarks/bench_expand.py --clips all --table1-characters --device cuda \
        --skip-per-process --skip-ray --reference REF

``--device-loop`` runs the iteration as a GPU does, its rules on the device
(:mod:`motionlab.retargeting.device_loop`), on any device: on the CPU (eagerly, no graph) its
outputs can be compared with a CPU run's byte for byte::

    python benchmarks/bench_expand.py --clips 8 --table1-characters --device cpu --pad \
        --skip-per-process --skip-ray --keep REF
    python benchmarks/bench_expand.py --clips 8 --table1-characters --device cpu --pad \
        --skip-per-process --skip-ray --device-loop --reference REF

``--device-loop replay`` does more of what a GPU does: each batch's step is recorded once and
replayed as a CUDA graph replays it (``tests/retargeting/replay.py``, on any device, about half
the eager speed), so a CPU run shows whether the recorded step gives the host loop's outputs.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import torch


def _load() -> str:
    return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg())


def _inputs(args, folder: Path):
    """Source clip paths and ``NAME=rig.bvh`` character specs (presets written as T-pose rigs)."""
    from motionlab.core import bvh, humanoid
    from motionlab.core.motion import Motion
    from motionlab.retargeting import expand as ex

    if args.synthetic:
        from motionlab import synthetic

        (folder / "clips").mkdir()
        clips = synthetic.dataset(10 if args.clips == "all" else int(args.clips), seed=7, num_frames=150)
        sources = [bvh.save(folder / "clips" / f"clip{i}.bvh", m) for i, m in enumerate(clips)]
        names = [f"char{i}" for i in range(args.characters)]
        skeletons = synthetic.character_set(args.characters, seed=3)
    else:
        from motionlab import data
        from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_TARGETS

        root = data.data_root() / "mixamo"
        if args.clips == "all":
            sources = sorted((root / "Aj").glob("*.bvh"))
        else:
            sources = [root / "Aj" / f"{a}.bvh" for a in DEFAULT_ANIMATIONS[: int(args.clips)]]
        if args.table1_characters:
            args.characters = len(DEFAULT_TARGETS)
        real = list(DEFAULT_TARGETS[: len(DEFAULT_TARGETS) if args.table1_characters else max(args.characters - 1, 1)])
        names = real + list(ex.PRESETS)[: args.characters - len(real)]
        skeletons = [humanoid.to_canonical_skeleton(bvh.load(root / t / "Running.bvh").skeleton) for t in real]
        skeletons += [ex.characters(presets=[n])[0].skeleton for n in names[len(real) :]]
    (folder / "rigs").mkdir(exist_ok=True)
    specs = []
    for name, sk in zip(names, skeletons):
        rig = Motion(sk, np.tile([1.0, 0, 0, 0], (2, 22, 1)), np.tile(sk.offsets[0], (2, 1)), 60.0)
        specs.append(f"{name}={bvh.save(folder / 'rigs' / f'{name}.bvh', rig)}")
    return [str(s) for s in sources], specs


def _per_process(sources, specs, out: Path, args) -> float:
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([str(Path(__file__).resolve().parents[1]), os.environ.get("PYTHONPATH", "")]),
    )
    start = time.perf_counter()
    for s in sources:
        for spec in specs:
            name, rig = spec.split("=", 1)
            (out / name).mkdir(parents=True, exist_ok=True)
            cmd = [
                sys.executable,
                "-m",
                "motionlab",
                "retarget",
                s,
                "--target",
                rig,
                "-o",
                str(out / name / f"{Path(s).stem}.bvh"),
                "-q",
                "--keep-implausible",  # as expand, which writes implausible outputs with a flag
                "--network",
                "synthetic",  # the shipped network, as the batched runs below load it
            ]
            if args.device:
                cmd += ["--device", args.device]
            subprocess.run(cmd, check=True, env=env)
    return time.perf_counter() - start


def _expand(sources, specs, out: Path, args, backend: str, threads=None):
    from motionlab import retargeting
    from motionlab.retargeting import expand as ex

    start = time.perf_counter()
    ckpt = retargeting.load_default(args.device, args.dtype)
    if ckpt.device.type == "cuda":
        torch.cuda.reset_peak_memory_stats(ckpt.device)
    job = ex.expand(
        sources, ex.characters(*specs), out, ckpt, backend=backend, workers=2, threads=threads,
        host_workers=args.host_workers, pad=args.pad,
    )  # fmt: skip
    split = ", ".join(f"{k} {v:.1f} s" for k, v in job.timings.items())
    memory = ""
    if ckpt.device.type == "cuda":
        memory = f", peak GPU memory {torch.cuda.max_memory_allocated(ckpt.device) / 2**20:.0f} MiB"
    print(f"  {backend}{'' if threads is None else f' ({threads} threads)'} on {ckpt.device} ({args.dtype}): "
          f"{job.batches} batches, {job.done} outputs, {job.source_frames} source frames in {job.seconds:.1f} s = "
          f"{job.throughput:.0f} source frames/s in expand; {split}{memory}")  # fmt: skip
    return time.perf_counter() - start, job


def _same(a: Path, b: Path) -> tuple[int, int]:
    files = sorted(p.relative_to(a) for p in a.rglob("*.bvh"))
    same = sum((b / f).is_file() and (b / f).read_bytes() == (a / f).read_bytes() for f in files)
    return same, len(files)


def _compare(out: Path, reference: Path) -> None:
    """Largest joint-position difference (cm) between OUT's outputs and REF's files of the same name."""
    from motionlab.core import bvh

    found, same = {}, 0
    for ref in sorted(reference.rglob("*.bvh")):
        mine = out / ref.relative_to(reference)
        if mine.is_file():
            d = 100 * float(np.abs(bvh.load(mine).global_positions() - bvh.load(ref).global_positions()).max())
            found[str(ref.relative_to(reference))] = d
            same += mine.read_bytes() == ref.read_bytes()
    if not found:
        print(f"outputs vs the reference {reference}: no file of the same name")
        return
    d = np.array(list(found.values()))
    worst = sorted(found, key=found.get, reverse=True)[:3]
    print(f"outputs vs the reference {reference}: {len(d)} files compared; {same} byte for byte, {int((d == 0).sum())} equal to the "
          f"files' 6 decimals, {int((d <= 0.01).sum())} within 0.01 cm; largest joint differences "
          + ", ".join(f"{found[w]:.2g} cm ({w})" for w in worst))  # fmt: skip


def _memory(args) -> None:
    """Peak resident memory of solve_many at two batch sizes, in child processes: the slope per frame."""
    code = (
        "import resource,sys,torch,numpy as np\n"
        "from motionlab.retargeting import load_default, solver\n"
        "ck=load_default('cpu'); N,T=int(sys.argv[1]),150\n"
        "x=torch.randn(N,T,70); th=torch.nn.functional.normalize(torch.randn(N,T,22,4),dim=-1)\n"
        "off=torch.tensor(np.array(ck.skeleton.offsets),dtype=torch.float32).expand(N,22,3).clone()\n"
        "b=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
        "solver.solve_many(ck.model,x,th,off,torch.full((N,T),0.9),solver.SolverConfig(max_steps=3,threshold=0,patience=0))\n"
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss-b)\n"
    )
    kb = {}
    for n in (10, 100):
        r = subprocess.run([sys.executable, "-c", code, str(n)], check=True, capture_output=True, text=True)
        kb[n * 150] = int(r.stdout.split()[-1])
    (f0, k0), (f1, k1) = sorted(kb.items())
    print(f"peak memory of a solve_many step: {k0 / 1024:.0f} MiB at {f0} frames, {k1 / 1024:.0f} MiB at {f1} frames; "
          f"{1024 * (k1 - k0) / (f1 - f0) / 1000:.1f} kB per frame (batching.BYTES_PER_FRAME assumes 32 kB)")  # fmt: skip


def _verify(out: Path) -> None:
    """Every ok row of OUT's manifest against the single-pair path (pipeline.retarget), byte for byte."""
    from motionlab import retargeting
    from motionlab.core import bvh, humanoid
    from motionlab.retargeting import expand as ex

    torch.set_num_threads(1)  # results do not depend on it; it is faster on a shared CPU
    ckpt = retargeting.load_default()
    rows = [r for r in ex.read_manifest(out) if r["status"] == "ok"]
    sources: dict = {}
    same = 0
    for r in rows:
        origin = r["character_file"]
        if origin.startswith("preset:"):
            target = ex.characters(presets=[origin[len("preset:") :]])[0].skeleton
        else:
            target = humanoid.to_canonical_skeleton(bvh.load(origin).skeleton)
        if r["source"] not in sources:
            sources[r["source"]] = bvh.load(r["source"])
        single = retargeting.retarget(sources[r["source"]], target, ckpt)
        same += (out / r["output"]).read_text() == bvh.dumps(single.motion)
    print(f"verify {out}: {same} of {len(rows)} outputs equal the single-pair path byte for byte; "
          f"{len(list(out.rglob('*.bvh')))} BVH files, {len(rows)} ok rows")  # fmt: skip


def _clips(text: str) -> str:
    if text != "all" and not (text.isdigit() and int(text) > 0):
        raise argparse.ArgumentTypeError(f"expected a positive number of clips or 'all', got {text!r}")
    return text


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument(
        "--clips",
        default="4",
        type=_clips,
        help="source clips: N of Aj's retarget_gt animations, or all of Aj's (default 4)",
    )
    p.add_argument("--table1-characters", action="store_true", help="the six Table 1 characters (no presets)")
    p.add_argument(
        "--host-workers",
        type=int,
        help="expand's host worker processes (default: none on the CPU, cores - 1 but at most 4 on a GPU)",
    )
    p.add_argument(
        "--pad", action="store_true", default=None, help="pad pairs of other lengths into one batch (default: on a GPU)"
    )
    p.add_argument(
        "--reference", metavar="REF", help="compare the local run's outputs with REF's files of the same names (cm)"
    )
    p.add_argument("--keep", metavar="DIR", help="copy the local run's outputs to DIR")
    p.add_argument("--compare", nargs=2, metavar=("OUT", "REF"), help="only compare OUT's outputs with REF's (cm)")
    p.add_argument("--characters", type=int, default=4, help="characters: real ones, then presets (default 4)")
    p.add_argument("--synthetic", action="store_true", help="synthetic clips and characters instead of MOTIONLAB_DATA")
    p.add_argument("--device", help="torch device for all three (default: cuda if available, else cpu)")
    p.add_argument(
        "--dtype",
        choices=("float64", "float32"),
        default="float64",
        help="the network's float type in expand (retarget per process: float64)",
    )
    p.add_argument("--memory", action="store_true", help="only measure memory per batch frame")
    p.add_argument("--skip-per-process", action="store_true", help="leave out the one-process-per-pair run")
    p.add_argument("--skip-ray", action="store_true", help="leave out the Ray run")
    p.add_argument("--verify", metavar="OUT", help="only check OUT's outputs against the single-pair path")
    p.add_argument(
        "--device-loop",
        nargs="?",
        const="eager",
        choices=("eager", "replay"),
        help="run the iteration's rules as on a GPU (motionlab.retargeting.device_loop) on any device: "
        "eagerly (the default), or its step recorded once and replayed as a CUDA graph does",
    )
    args = p.parse_args()
    if args.device_loop:  # the switch a GPU takes (graphs.enabled), taken on every device
        from motionlab.retargeting import graphs

        graphs.enabled = lambda device: True
        if args.device_loop == "replay":
            sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
            from tests.retargeting.replay import Replayed

            graphs.StepGraph = Replayed
    if args.memory:
        return _memory(args)
    if args.verify:
        return _verify(Path(args.verify))
    if args.compare:
        return _compare(Path(args.compare[0]), Path(args.compare[1]))
    gpu = f", {torch.cuda.get_device_name()}" if torch.cuda.is_available() else ""
    print(f"torch {torch.__version__}, {torch.get_num_threads()} threads, {os.cpu_count()} CPUs{gpu}; {_load()}")
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        sources, specs = _inputs(args, d)
        from motionlab.core import bvh

        frames = sum(bvh.load(s).resample(60.0).num_frames for s in sources) * len(specs)
        pairs = len(sources) * len(specs)
        print(f"{len(sources)} clips x {len(specs)} characters = {pairs} pairs, {frames} source frames")
        results = {}
        if not args.skip_per_process:
            results["one process per pair"] = _per_process(sources, specs, d / "per_process", args)
        t, job = _expand(sources, specs, d / "local", args, "local")
        results["local batched"] = t
        if args.reference:
            _compare(d / "local", Path(args.reference))
        if args.keep:
            import shutil

            shutil.copytree(d / "local", args.keep, dirs_exist_ok=True)
        if not args.device or args.device == "cpu":
            t, job = _expand(sources, specs, d / "local2", args, "local", threads=2)
            results["local batched, 2 threads"] = t
        try:
            if args.skip_ray:
                raise ImportError
            import ray  # noqa: F401

            t, job = _expand(sources, specs, d / "ray", args, "ray")
            results["Ray local, 2 workers"] = t
        except ImportError:
            print('  Ray local: skipped (--skip-ray, or Ray is not installed: pip install "motionlab[cluster]")')
        base = frames / next(iter(results.values()))
        for label, t in results.items():
            fps = frames / t
            print(f"{label:<22} {t:8.1f} s  {fps:8.0f} source frames/s  {fps / base:6.1f}x")
        reference = "per_process" if (d / "per_process").is_dir() else "local"
        for other in ("local", "local2", "ray"):
            if other != reference and (d / other).is_dir():
                s, n = _same(d / reference, d / other)
                print(f"outputs of {other} equal to {reference}: {s} of {n} files byte for byte")
        print(_load())


if __name__ == "__main__":
    main()
