"""FK throughput and BVH parse speed of motionlab, next to the best-known installable peer.

The peer is upc-pymotion (NumPy; ``pip install upc-pymotion``, import name ``pymotion``). It is
optional: without it the motionlab rows are still printed. Goals on a 2-core CPU: torch FK of
at least 5 M frames/s on large batches, and BVH parsing of at least 20 MB/s.

Usage::

    python benchmarks/bench_fk.py                                  # synthetic data
    MOTIONLAB_DATA=/path/to/shared/data python benchmarks/bench_fk.py
    python benchmarks/bench_fk.py --frames 262144 --threads 2 --repeats 9

FK: a batch of ``--frames`` frames (default 131072) of 22 joints in float32, world positions
out. With ``MOTIONLAB_DATA`` set, the skeleton and rotations come from the largest Mixamo clip,
reduced to the 22-joint humanoid and tiled to the batch size. Without it, the canonical
22-joint humanoid (``humanoid.canonical_skeleton``) gets random unit quaternions (seed 0) and
random root positions. Every implementation gets the same arrays. The peer is given what its
API takes: local rotations, root positions and (J, 3) offsets. Its output is checked against
``fk.fk`` before timing. Each row is the median of ``--repeats`` timed runs, then the best run;
one-off warm-up (torch.compile) is excluded from the rows and printed separately.

BVH: the largest ``.bvh`` under ``MOTIONLAB_DATA``, or without it a synthetic file written with
``bvh.save`` to a temporary folder; then a generated file of ``--big-mb`` MB (default 200): that
file's frame lines repeated. MB/s is file bytes / seconds of ``bvh.load`` (motionlab: text to a
Motion with quaternions). For the peer it is ``BVH().load`` (text to Euler arrays, its parse-only
load, the row the ratios use), then ``get_data()`` on top (Euler to quaternions, the comparable
output; skipped for the big file). Rows run interleaved, one run of each per round; the table
gives wall-clock and CPU-time medians. Memory: the peak resident set a second ``bvh.load`` adds
in a fresh process (``VmHWM``, reset after a warm-up load), result included.

Environment, set before torch is imported unless already set, and printed:

* ``THP_MEM_ALLOC_ENABLE=1``, so that torch, like NumPy, backs large arrays with transparent
  huge pages. Page faults on fresh 4 KiB pages otherwise cost as much as the FK itself on some
  virtual machines.
* ``OMP_WAIT_POLICY=PASSIVE``, only when the 1-minute load average at start exceeds half the
  usable cores (other processes are running), or always with ``--omp-wait-policy=passive``
  (``--omp-wait-policy=default`` never). Then a thread that waits at a barrier sleeps
  instead of spinning, and the scheduler can run the thread it waits for. With the default
  spinning, two-thread torch rows on a busy 2-core machine come out 10-50x slower and erratic.

The load average is printed with the results. Slow rows stop repeating after about
``--budget`` seconds.
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("THP_MEM_ALLOC_ENABLE", "1")  # must precede `import torch`
_CORES = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
_START_LOAD = os.getloadavg()[0] if hasattr(os, "getloadavg") else 0.0
_BUSY = _START_LOAD > 0.5 * _CORES
# --omp-wait-policy is read here, before torch (and OpenMP) start; argparse only checks it later
_POLICY = "auto"
for _i, _arg in enumerate(sys.argv):
    if _arg.startswith("--omp-wait-policy="):
        _POLICY = _arg.split("=", 1)[1]
    elif _arg == "--omp-wait-policy" and _i + 1 < len(sys.argv):
        _POLICY = sys.argv[_i + 1]
if _POLICY == "passive" or (_POLICY == "auto" and _BUSY):
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import platform  # noqa: E402
import re  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import torch  # noqa: E402

from motionlab.core import bvh, fk, fk_fast, fk_torch, humanoid, quat  # noqa: E402
from motionlab.core.motion import Motion  # noqa: E402

PEER_HINT = "pip install upc-pymotion"


# ---------------------------------------------------------------------------------- helpers
def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _load() -> str:
    try:
        return " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "n/a"


def _busy_note() -> None:
    if _BUSY and torch.get_num_threads() > 1:
        print(
            f"note: load average {_START_LOAD:.1f} on {_CORES} cores at the start: other processes compete for the "
            "CPU, so the multi-threaded rows got about one core; rerun on an idle machine for the multi-core figures."
        )


def _time(fn, repeats: int, budget: float) -> list[float]:
    """Wall-clock seconds of up to ``repeats`` calls after one untimed call; stops after ``budget`` s."""
    t_end = time.perf_counter() + budget
    fn()
    times = []
    while len(times) < repeats and (not times or time.perf_counter() < t_end):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return times


def _print_table(header: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(r[i]) for r in [header] + rows) for i in range(len(header))]
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for r in rows:
        print("| " + " | ".join(v.ljust(w) for v, w in zip(r, widths)) + " |")


def _import_peer():
    try:
        import pymotion  # noqa: F401
        from pymotion.io.bvh import BVH
        from pymotion.ops import skeleton_np
    except ImportError:
        return None
    try:
        from importlib.metadata import version

        ver = version("upc-pymotion")
    except Exception:
        ver = "?"
    return {"BVH": BVH, "skeleton_np": skeleton_np, "version": ver}


# ---------------------------------------------------------------------------------- data
def _largest_bvh(root: Path, under: str = "") -> Path | None:
    files = [p for p in (root / under).rglob("*.bvh") if p.is_file()]
    return max(files, key=lambda p: p.stat().st_size) if files else None


def _fk_data(frames: int, rng: np.random.Generator):
    """(local_rot (N,22,4), root (N,3), offsets (22,3), parents, description), float32."""
    root_dir = os.environ.get("MOTIONLAB_DATA", "").strip()
    clip = _largest_bvh(Path(root_dir), "mixamo") if root_dir and Path(root_dir, "mixamo").is_dir() else None
    if clip is not None:
        motion = humanoid.to_canonical(bvh.load(clip))
        reps = -(-frames // motion.num_frames)
        rot = np.tile(motion.local_rot, (reps, 1, 1))[:frames]
        root = np.tile(motion.root_pos, (reps, 1))[:frames]
        offsets = motion.skeleton.offsets
        parents = motion.skeleton.parents
        what = (
            f"real: {clip.relative_to(root_dir)} ({motion.num_frames} frames) reduced to the 22-joint humanoid, "
            f"tiled to {frames} frames"
        )
    else:
        skeleton = humanoid.canonical_skeleton()
        rot = quat.normalize(rng.normal(size=(frames, skeleton.num_joints, 4)))
        root = rng.normal(scale=[2.0, 0.05, 2.0], size=(frames, 3)) + skeleton.offsets[0]
        offsets = skeleton.offsets
        parents = skeleton.parents
        what = (
            "synthetic: humanoid.canonical_skeleton() (22 joints, 1.75 m) with random unit quaternions "
            f"(seed 0), {frames} frames (set MOTIONLAB_DATA to use a real Mixamo clip)"
        )
    f32 = np.float32
    return rot.astype(f32), root.astype(f32), offsets.astype(f32), np.asarray(parents), what


def _bvh_file(tmp: Path, rng: np.random.Generator) -> tuple[Path, str]:
    root_dir = os.environ.get("MOTIONLAB_DATA", "").strip()
    if root_dir and Path(root_dir).is_dir():
        path = _largest_bvh(Path(root_dir))
        if path is not None:
            return path, f"largest file under MOTIONLAB_DATA: {path.relative_to(root_dir)}"
    skeleton = humanoid.canonical_skeleton()
    frames = 12000
    angles = np.cumsum(rng.normal(scale=0.02, size=(frames, skeleton.num_joints, 3)), axis=0)
    motion = Motion(
        skeleton,
        quat.from_euler(angles, "zyx"),
        np.cumsum(rng.normal(scale=0.01, size=(frames, 3)), axis=0) + skeleton.offsets[0],
        fps=60.0,
    )
    path = bvh.save(tmp / "synthetic_large.bvh", motion, overwrite=True)
    return path, (
        f"synthetic: {frames} frames of the 22-joint humanoid written by bvh.save to {path} "
        "(set MOTIONLAB_DATA to use the largest real file)"
    )


# ---------------------------------------------------------------------------------- FK
def bench_fk(args, peer) -> None:
    rng = np.random.default_rng(0)
    rot, root, offsets, parents, what = _fk_data(args.frames, rng)
    n, num_joints = rot.shape[:2]
    local_pos = np.broadcast_to(offsets, (n, num_joints, 3)).copy()
    local_pos[:, 0] = root
    t_rot, t_pos, t_root, t_off = (torch.from_numpy(a) for a in (rot, local_pos, root, offsets))
    print(f"\n## FK: {n} frames x {num_joints} joints, float32, world positions\n")
    print(f"data: {what}")

    # --- agreement on a few frames, so that the comparison is like for like
    ref = fk.fk(rot[:64].astype(np.float64), local_pos[:64].astype(np.float64), parents)[1]
    checks = {
        "fk_torch.fk_positions": fk_torch.fk_positions(t_rot[:64], t_pos[:64], parents).numpy(),
        "fk_fast.fk_positions_fast_np": fk_fast.fk_positions_fast_np(rot[:64], local_pos[:64], parents),
    }
    if peer is not None:
        peer_parents = parents.copy()
        peer_parents[0] = 0  # pymotion's convention: the root is its own parent (never read)
        checks["pymotion fk_quat"] = peer["skeleton_np"].fk_quat(rot[:64], root[:64], offsets, peer_parents)[0]
        checks["pymotion fk"] = peer["skeleton_np"].fk(rot[:64], root[:64], offsets, peer_parents)[0]
    for name, pos in checks.items():
        print(f"check: {name:<30s} vs fk.fk (float64) on 64 frames: max |diff| = {np.abs(pos - ref).max():.2e} m")

    # --- warm-up of the compiled kernels (excluded from the table)
    warm = {}
    for shared in (False, True):
        warm[shared] = fk_fast.warmup(parents, shared_offsets=shared, chunk=args.chunk)
    for shared, label in ((False, "per-frame local_pos"), (True, "offsets + root_pos")):
        state = (
            "compiled" if fk_fast.is_compiled(parents, shared_offsets=shared, chunk=args.chunk) else "EAGER FALLBACK"
        )
        print(
            f"warm-up: fk_positions_fast ({label}): {warm[shared]:.1f} s ({state}; inductor's disk cache makes reruns quicker)"
        )
    fast = fk_fast.fk_positions_fast(t_rot[:64], t_pos[:64], parents, chunk=args.chunk).numpy()
    fast_shared = fk_fast.fk_positions_fast(t_rot[:64], t_off, parents, root_pos=t_root[:64], chunk=args.chunk).numpy()
    print(
        f"check: {'fk_fast.fk_positions_fast':<30s} vs fk.fk (float64) on 64 frames: max |diff| = {np.abs(fast - ref).max():.2e} m"
    )
    print(
        f"check: {'  ... with offsets + root_pos':<30s} vs fk.fk (float64) on 64 frames: max |diff| = {np.abs(fast_shared - ref).max():.2e} m"
    )

    # --- timing
    slow = max(1, min(args.repeats, 5))
    cases = []
    if peer is not None:
        sk = peer["skeleton_np"]
        cases += [
            ("pymotion fk_quat (numpy)", "pos+rot", lambda: sk.fk_quat(rot, root, offsets, peer_parents), slow, True),
            ("pymotion fk, matrices (numpy)", "pos+rot", lambda: sk.fk(rot, root, offsets, peer_parents), slow, True),
        ]
    cases += [
        ("motionlab fk.fk (numpy)", "pos+rot", lambda: fk.fk(rot, local_pos, parents), slow, False),
        (
            "motionlab fk_fast.fk_positions_fast_np (numpy)",
            "pos",
            lambda: fk_fast.fk_positions_fast_np(rot, local_pos, parents),
            args.repeats,
            False,
        ),
        (
            "motionlab fk_torch.fk_positions (torch eager)",
            "pos",
            lambda: fk_torch.fk_positions(t_rot, t_pos, parents),
            slow,
            False,
        ),
        (
            "motionlab fk_fast, compile=False (torch eager)",
            "pos",
            lambda: fk_fast.fk_positions_fast(t_rot, t_pos, parents, chunk=args.chunk, compile=False),
            slow,
            False,
        ),
        (
            "motionlab fk_fast.fk_positions_fast (torch compiled)",
            "pos",
            lambda: fk_fast.fk_positions_fast(t_rot, t_pos, parents, chunk=args.chunk),
            args.repeats,
            False,
        ),
        (
            "  ... offsets + root_pos (peer's inputs)",
            "pos",
            lambda: fk_fast.fk_positions_fast(t_rot, t_off, parents, root_pos=t_root, chunk=args.chunk),
            args.repeats,
            False,
        ),
    ]
    results = []
    for name, outputs, fn, repeats, is_peer in cases:
        times = _time(fn, repeats, args.budget)
        results.append((name, outputs, n / statistics.median(times), n / min(times), len(times), is_peer))
    peer_best = max((r[2] for r in results if r[5]), default=None)
    header = ["implementation", "output", "frames/s (median)", "best run", "runs", "ratio vs peer"]
    rows = []
    for name, outputs, med, best, repeats, _ in results:
        ratio = f"{med / peer_best:.2f}x" if peer_best else "n/a"
        rows.append([name, outputs, f"{med / 1e6:.3f} M", f"{best / 1e6:.3f} M", str(repeats), ratio])
    print()
    _print_table(header, rows)
    if peer_best:
        print("\nratio = median frames/s / the faster pymotion row's median frames/s.")
    else:
        print(f"\npeer not installed: {PEER_HINT}  (then rerun for the ratio column)")
    print("'pos+rot' rows also return global rotations; the 'pos' rows return positions only.")
    _busy_note()


# ---------------------------------------------------------------------------------- BVH
_MEMORY_PROBE = """
import sys
from motionlab.core import bvh

def status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1])

bvh.load(sys.argv[1])  # warm-up: touches the code and library pages a first call maps in
try:  # reset the high-water mark to the current size (Linux >= 4.0)
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
except OSError:
    pass
before = status("VmHWM")
motion = bvh.load(sys.argv[1])
print(before, status("VmHWM"), motion.num_frames)
"""


def _load_memory(path: Path) -> tuple[float, int]:
    """Peak resident memory added by ``bvh.load(path)`` in a fresh Python (bytes), and the frames read.

    Linux's ``VmHWM`` (peak resident set, KiB) is reset after the imports and one warm-up load
    (which maps in code and library pages once), then read after a second load: the growth is
    what loading needed at its peak, result included.
    """
    import subprocess

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).resolve().parents[1]), *sys.path]))
    out = subprocess.run(
        [sys.executable, "-c", _MEMORY_PROBE, str(path)], capture_output=True, text=True, env=env, check=True
    ).stdout.split()
    return (int(out[1]) - int(out[0])) * 1024.0, int(out[2])


def _generated_bvh(source: Path, folder: Path, target_mb: float) -> Path:
    """A ~``target_mb`` MB BVH: ``source``'s header and its frame lines repeated (Frames: updated)."""
    raw = source.read_bytes()
    cut = raw.find(b"\n", raw.find(b"Frame Time")) + 1
    header, block = raw[:cut], raw[cut:]
    if not block.endswith(b"\n"):
        block += b"\n"
    frames = sum(1 for line in block.split(b"\n") if line.strip())
    repeats = max(1, round(target_mb * 1e6 / len(block)))
    header = re.sub(rb"Frames:\s*\d+", b"Frames: %d" % (frames * repeats), header, count=1)
    path = folder / f"generated_{target_mb:.0f}MB.bvh"
    with open(path, "wb") as f:
        f.write(header)
        for _ in range(repeats):
            f.write(block)
    return path


def _bvh_rows(path: Path, peer, repeats: int, budget: float, peer_quats: bool = True) -> None:
    size_mb = path.stat().st_size / 1e6
    ours = lambda: bvh.load(path)  # noqa: E731
    cases = [("motionlab bvh.load (text -> Motion with quaternions)", ours, False)]
    if peer is not None:

        def peer_parse():
            b = peer["BVH"]()
            b.load(str(path))
            return b

        cases.append(("pymotion BVH().load (text -> Euler arrays)", peer_parse, True))
        if peer_quats:
            cases.append(("pymotion BVH().load + get_data() (-> quaternions)", lambda: peer_parse().get_data(), True))
    # rows are interleaved (one run of each per round), so that a busy spell hits all of them alike;
    # wall-clock and CPU seconds of this process (all rows are single-threaded) are both kept
    wall: dict[str, list[float]] = {name: [] for name, _, _ in cases}
    cpu: dict[str, list[float]] = {name: [] for name, _, _ in cases}
    for _, fn, _ in cases:
        fn()  # warm-up: file cache, imports
    t_end = time.perf_counter() + budget * len(cases)
    while min(len(t) for t in wall.values()) < repeats and (not all(wall.values()) or time.perf_counter() < t_end):
        for name, fn, _ in cases:
            t0, c0 = time.perf_counter(), time.process_time()
            fn()
            wall[name].append(time.perf_counter() - t0)
            cpu[name].append(time.process_time() - c0)
    med = {name: size_mb / statistics.median(wall[name]) for name in wall}
    med_cpu = {name: size_mb / statistics.median(cpu[name]) for name in cpu}
    peer_name = next((name for name, _, p in cases if p), None)
    rows = []
    for name, _, _ in cases:
        ratio = f"{med[name] / med[peer_name]:.2f}x" if peer_name else "n/a"
        ratio_cpu = f"{med_cpu[name] / med_cpu[peer_name]:.2f}x" if peer_name else "n/a"
        best = size_mb / min(wall[name])
        rows.append(
            [name, f"{med[name]:.1f}", f"{best:.1f}", f"{med_cpu[name]:.1f}", str(len(wall[name])), ratio, ratio_cpu]
        )
    header = [
        "implementation",
        "MB/s (median)",
        "best run",
        "MB/s of CPU time",
        "runs",
        "ratio vs peer parse-only",
        "same, CPU time",
    ]
    _print_table(header, rows)
    peak, frames = _load_memory(path)
    print(
        f"\nmotionlab bvh.load memory: peak RSS +{peak / 1e6:.0f} MB for a {size_mb:.0f} MB file "
        f"({peak / (size_mb * 1e6):.2f}x the file, result included; {frames} frames; fresh process)"
    )
    if peer_name:
        ours_name = cases[0][0]
        print(
            f"parse speed: motionlab {med[ours_name] / med[peer_name]:.2f}x pymotion's parse-only load "
            f"(median wall-clock MB/s; {med_cpu[ours_name] / med_cpu[peer_name]:.2f}x in CPU time)"
        )
    else:
        print(f"\npeer not installed: {PEER_HINT}  (then rerun for the ratio column)")


def bench_bvh(args, peer) -> None:
    rng = np.random.default_rng(1)
    with tempfile.TemporaryDirectory(prefix="motionlab_bench_") as tmp:
        path, what = _bvh_file(Path(tmp), rng)
        print(f"\n## BVH parse: {path.name}, {path.stat().st_size / 1e6:.2f} MB\n")
        print(f"file: {what}")
        print(f"motionlab reads {bvh.load(path)!r}\n")
        _bvh_rows(path, peer, max(1, min(args.repeats, 7)), args.budget)
        if args.big_mb > 0:
            big = _generated_bvh(path, Path(tmp), args.big_mb)
            print(f"\n## BVH parse: generated {big.name}, {big.stat().st_size / 1e6:.1f} MB\n")
            print(f"file: the frame lines of {path.name} repeated (Frames: updated), written to {tmp}\n")
            _bvh_rows(big, peer, max(1, min(args.repeats, 3)), 4 * args.budget, peer_quats=False)


# ---------------------------------------------------------------------------------- main
def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=131072, help="FK batch size (default 131072)")
    parser.add_argument("--repeats", type=int, default=7, help="timed runs of the fast rows (slow rows: at most 5)")
    parser.add_argument(
        "--chunk", type=int, default=fk_fast.DEFAULT_CHUNK, help="fk_fast chunk (frames per compiled call)"
    )
    parser.add_argument("--threads", type=int, default=None, help="torch threads (default: the usable cores)")
    parser.add_argument("--budget", type=float, default=8.0, help="seconds after which a row stops repeating")
    parser.add_argument("--skip-bvh", action="store_true", help="FK only")
    parser.add_argument(
        "--big-mb", type=float, default=200.0, help="size of the generated BVH file, MB (default 200; 0: none)"
    )
    parser.add_argument("--skip-fk", action="store_true", help="BVH only")
    parser.add_argument(
        "--omp-wait-policy",
        choices=["auto", "passive", "default"],
        default="auto",
        help="auto: OMP_WAIT_POLICY=PASSIVE when the machine is busy at start; passive: always; default: leave it",
    )
    args = parser.parse_args(argv)
    if args.frames < 1 or args.repeats < 1:
        parser.error("--frames and --repeats must be positive")

    cores = _CORES
    torch.set_num_threads(args.threads or cores)
    peer = _import_peer()
    t_start = time.perf_counter()
    print("# motionlab FK and BVH benchmark\n")
    print(f"machine: {_cpu_model()}; {cores} usable cores (os.cpu_count() = {os.cpu_count()}); {platform.platform()}")
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, torch {torch.__version__} "
        f"({torch.get_num_threads()} threads), THP_MEM_ALLOC_ENABLE={os.environ.get('THP_MEM_ALLOC_ENABLE')}"
    )
    print(
        f"peer: upc-pymotion {peer['version']}"
        if peer
        else f"peer: upc-pymotion not importable; install it with `{PEER_HINT}`"
    )
    print(f"load average at start: {_load()}")
    print(
        f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY', '(unset: spin)')}"
        + (
            " (set here)"
            if _POLICY == "passive"
            else " (set here: the machine was busy at start)"
            if _BUSY and _POLICY == "auto"
            else ""
        )
    )

    if not args.skip_fk:
        bench_fk(args, peer)
    if not args.skip_bvh:
        bench_bvh(args, peer)
    print(f"\nload average at end: {_load()}; total time {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
