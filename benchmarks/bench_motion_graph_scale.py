"""Structured motion graphs at the scale of whole recording sessions: build time and memory per
stage, ``graph-search`` and ``graph-info`` per command, connectivity per behaviour.

Libraries (``--cases KIND:FRAMES ...``): ``session`` — the shared takes of every behaviour under
``MOTIONLAB_DATA/bandai_namco/sessions`` (walk, wave-both-hands, raise-up-both-hands: 817 takes,
125 k frames) repeated under new take numbers until the requested size exists; ``walk`` — the walk
takes only (175 takes, 44 k frames). Below the shared size whole takes are drawn round-robin over
the styles. Each case is built in a fresh process (its peak resident memory, ``ru_maxrss``, is its
own) with ``--workers`` threads and saved as a ``.mlgraph`` file (its edges SHA-256 printed:
equal hashes, the same graph); then every request runs
``--repeat`` times as its own ``motionlab graph-search`` command, timed from start to exit
(start-up included), with the command's CPU seconds and peak resident memory
(``getrusage(RUSAGE_CHILDREN)`` of a wrapper process with that one child); and ``graph-info``
likewise. The last line per case says the slowest ``graph-search`` command and the largest peak
against the goals. With ``--keep DIR`` the graph is written to ``DIR/KIND-FRAMES.mlgraph`` and,
when that file exists already, used as it is (no build: only the commands run).

    python benchmarks/bench_motion_graph_scale.py                   # session:370000 walk:1000000
    python benchmarks/bench_motion_graph_scale.py --cases walk:1000 walk:10000   # quick
    python benchmarks/bench_motion_graph_scale.py --cases session:370000 --keep /tmp/graphs  # then commands only
    python benchmarks/bench_motion_graph_scale.py --cases session:370000 --backend ray --repeat 1  # Ray's build

Goals (issue 43): a session-sized build (370 k frames) <= 60 s and <= 1.5 GB on the 2-core
machine, 1 M frames <= 3 GB; ``graph-search`` <= 2 s per command, start-up included, and
<= 0.5 GB; every behaviour >= 95 % of its frames in its largest strongly connected component
(:func:`motionlab.motion_graphs.report.build_report`: the component of the behaviour's own
frames, as a share of its takes' frames).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

THRESHOLD_M = None  # None: the library default, motion_graphs.distance.DEFAULT_THRESHOLD
CASES = ("session:370000", "walk:1000000")
REQUESTS = {
    "session": (
        "walk:normal:200,walk:elderly:200",
        "walk:normal:100,wave-both-hands:normal:60,walk:normal:100",
        "walk:active:100,raise-up-both-hands:feminine:60",
        # crossing pools entered at hundreds of frames (11.2 s and 2.7 s per command before
        # the walks from all entries at once)
        "wave-both-hands:youthful:500,raise-up-both-hands:elderly:90,walk:exhausted:2000",
        "raise-up-both-hands:normal:40,raise-up-both-hands:active:40,wave-both-hands:masculine:300",
    ),
    "walk": ("walk:normal:200,walk:elderly:200", "walk:normal:200,walk:active:200,walk:feminine:200"),
}
GOAL_SCC = 95.0
GOAL_SEARCH_S, GOAL_SEARCH_GB = 2.0, 0.5


def session(frames: int, behaviours: str = "walk"):
    """Motions of about ``frames`` frames: the shared takes of ``behaviours`` (a folder under
    ``sessions/``, or ``all`` for every behaviour), repeated under new take numbers."""
    from motionlab import data
    from motionlab.core.motion import Motion
    from motionlab.motion_graphs import clips, naming

    root = data.data_root() / "bandai_namco" / "sessions"
    folders = (
        sorted(p for p in root.iterdir() if p.is_dir())
        if behaviours == "all" and root.is_dir()
        else [root / behaviours]
    )
    if not all(f.is_dir() for f in folders) or not folders:
        raise data.DataNotFound(f"needs {folders[0] if folders else root}: {data.HOW_TO}")
    takes = [m for f in folders for m in clips.load_folder(f)]
    by_style: dict[tuple[str, str], list] = {}
    for m in takes:
        lab = naming.parse_name(m.name)
        by_style.setdefault((lab.behaviour, lab.style), []).append(m)
    # round-robin over styles so every size has every style it can
    order = [ms[i] for i in range(max(map(len, by_style.values()))) for ms in by_style.values() if i < len(ms)]
    out, total, rep = [], 0, 0
    while total < frames:
        for m in order:
            if total >= frames:
                break
            lab = naming.parse_name(m.name)
            name = f"{lab.behaviour}_{lab.style}_{rep:03d}{lab.take}"
            # shares the arrays of the loaded take: a repeat costs no memory before the build
            out.append(Motion(m.skeleton, m.local_rot, m.root_pos, m.fps, None, name))
            total += m.num_frames
        rep += 1
    return out


def _gb(kib: int) -> float:
    return kib * 1024 / 1e9  # ru_maxrss is in KiB on Linux; GB = 10^9 bytes, as the stage table


def build_case(kind: str, frames: int, out: Path, workers: int, backend: str = "local") -> dict:
    """Build one case in this process (``backend``: ``structured.build_structured``'s) and save it
    to ``out``; the figures as a dict."""
    from motionlab.motion_graphs import distance, io, report, structured

    rms = THRESHOLD_M or distance.DEFAULT_THRESHOLD
    clock = report.StageClock()
    with clock("load"):
        motions = session(frames, "all" if kind == "session" else kind)
    t0, c0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_SELF)
    g = structured.build_structured(motions, distance.threshold_from(rms), workers=workers, backend=backend)
    build_s = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_SELF)
    clock.extend(g.info["stages"])
    with clock("report"):
        rep = report.build_report(g)
        summary = g.summary()
    with clock("save"):
        io.save(out, g, overwrite=True, summary=summary)
    return dict(edges_sha=edges_sha(g),
        kind=kind, frames=g.num_frames, takes=len(motions), threshold_m=rms, workers=workers, backend=backend,
        build_s=build_s,
        cpu_s=(c1.ru_utime + c1.ru_stime) - (c0.ru_utime + c0.ru_stime), transitions=summary["transitions"],
        peak_gb=_gb(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss), file_mb=out.stat().st_size / 1e6,
        stages=clock.rows, behaviours={b: v["percent"] for b, v in rep["behaviours"].items()},
    )  # fmt: skip


def edges_sha(g) -> str:
    """SHA-256 of the graph's alive frames, edges, costs and edge kinds (as
    ``tests/motion_graphs/test_build_scale.py`` hashes them): equal hashes, the same graph."""
    import hashlib

    import numpy as np

    h = hashlib.sha256()
    for a in (g.alive, g.src, g.dst, g.cost, g.kind):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def measure(cmd: list[str]) -> dict:
    """Run ``cmd`` as this process's only child: wall seconds and its peak resident memory."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return dict(rc=p.returncode, wall_s=wall, cpu_s=use.ru_utime + use.ru_stime, peak_gb=_gb(use.ru_maxrss),
                out=p.stdout[-2000:], err=p.stderr[-2000:])  # fmt: skip


def _measured(cmd: list[str]) -> dict:
    """:func:`measure` in a fresh wrapper process, so the peak is this command's alone."""
    p = subprocess.run([sys.executable, __file__, "--measure", json.dumps(cmd)], capture_output=True, text=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def commands(graph: Path, kind: str, tmp: Path, repeat: int) -> list[tuple[str, dict]]:
    """``graph-info`` and ``repeat`` runs of one ``graph-search`` per request of ``kind``, each a
    fresh command."""
    motionlab = [sys.executable, "-m", "motionlab.cli"]
    rows = [("graph-info", _measured([*motionlab, "graph-info", str(graph)]))]
    for k, req in enumerate(REQUESTS[kind]):
        out = tmp / f"search{k}.bvh"
        for _ in range(repeat):
            rows.append((req, _measured([*motionlab, "graph-search", str(graph), "--request", req, "-o", str(out),
                                         "--force", "-q"])))  # fmt: skip
    req = REQUESTS[kind][-1]
    only = [sys.executable, "-c", GRAPH_COMMANDS_ONLY, "graph-search", str(graph), "--request", req, "-o",
            str(tmp / "only.bvh"), "--force", "-q"]  # fmt: skip
    rows.append((f"{req}, graph commands only", _measured(only)))
    imp = _measured([sys.executable, "-c", "import motionlab.cli as c; c.build_parser()"])
    rows.append(("(motionlab's start-up alone: importing every system's commands)", imp))
    return rows


def search_verdict(rows: list[tuple[str, dict]], kind: str) -> str:
    """The slowest ``graph-search`` command of ``rows`` and the largest peak, against the goals."""
    runs = [m for name, m in rows if name in REQUESTS[kind]]
    if not runs or any(m["rc"] != 0 for m in runs):
        return "graph-search: a command failed (see the rows above)"
    wall, gb = max(m["wall_s"] for m in runs), max(m["peak_gb"] for m in runs)
    cpu = max(m["cpu_s"] for m in runs)
    ok = wall <= GOAL_SEARCH_S and gb <= GOAL_SEARCH_GB
    return (f"graph-search per command, start-up included ({len(runs)} commands): slowest {wall:.2f} s wall "
            f"(most CPU {cpu:.2f} s), largest peak {gb:.2f} GB; goal <= {GOAL_SEARCH_S:g} s and "
            f"<= {GOAL_SEARCH_GB:g} GB: {'met' if ok else 'NOT met'}")  # fmt: skip


GRAPH_COMMANDS_ONLY = """import argparse, sys
from motionlab.motion_graphs import cli
p = argparse.ArgumentParser(); cli.register(p.add_subparsers())
a = p.parse_args(sys.argv[1:])
try:
    sys.exit(a.func(a))
except ValueError as e:  # CLIError, GraphError
    sys.exit(f"error: {e}")"""
"""The ``graph-*`` commands without importing the other systems' commands (``motionlab``'s
start-up imports every system, torch included)."""


def build_in_child(case: str, graph: Path, workers: int, backend: str = "local") -> dict | None:
    """Build ``case`` in a fresh process and save it to ``graph``; print its figures."""
    kind = case.split(":")[0]
    load = os.getloadavg()
    p = subprocess.run([sys.executable, __file__, "--one", case, "--graph", str(graph), "--workers", str(workers),
                        "--backend", backend], capture_output=True, text=True)  # fmt: skip
    if p.returncode != 0:
        print(f"{case}: build failed\n{p.stderr[-3000:]}")
        return None
    r = json.loads(p.stdout.strip().splitlines()[-1])
    print(f"\n## {kind} library, {r['frames']} frames, {r['takes']} takes, threshold {r['threshold_m']} m, "
          f"{r['workers']} {'threads' if backend == 'local' else 'Ray workers'}; load average before {load[0]:.1f}")  # fmt: skip
    print(f"build {r['build_s']:.1f} s wall ({r['cpu_s']:.1f} s CPU), peak {r['peak_gb']:.2f} GB (whole process: "
          f"library, build, report, save); {r['transitions']} transitions; file {r['file_mb']:.0f} MB")  # fmt: skip
    print(f"edges SHA-256 (alive, src, dst, cost, kind): {r['edges_sha']}")
    from motionlab.motion_graphs.report import format_stages

    print(format_stages(r["stages"]))
    print(f"largest strongly connected component per behaviour (goal >= {GOAL_SCC:g}%):")
    for b, v in sorted(r["behaviours"].items()):
        print(f"  {b}: {v:.1f}% {'met' if v >= GOAL_SCC else 'NOT met'}")
    return r


def run_case(case: str, workers: int, keep: Path | None = None, repeat: int = 3, backend: str = "local") -> int:
    kind, frames = case.split(":")
    with tempfile.TemporaryDirectory() as d:
        graph = (keep or Path(d)) / (f"{kind}-{frames}.mlgraph" if keep else "g.mlgraph")
        if keep and graph.is_file():
            print(f"\n## {kind} library, {frames} frames: the graph kept in {graph} (not built again)")
        elif build_in_child(case, graph, workers, backend) is None:
            return 1
        print(f"load average before the commands {os.getloadavg()[0]:.1f}")
        print("command | wall s (start-up included) | CPU s | peak GB | result")
        rows = commands(graph, kind, Path(d), repeat)
        for name, m in rows:
            first = (m["out"].strip().splitlines() or m["err"].strip().splitlines() or [""])[0][:70]
            print(f"{name} | {m['wall_s']:.2f} | {m['cpu_s']:.2f} | {m['peak_gb']:.2f} | rc {m['rc']} {first}")
        print(search_verdict(rows, kind))
        print(f"load average after {os.getloadavg()[0]:.1f}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=None, help="KIND:FRAMES, KIND session or walk")
    ap.add_argument("--workers", type=int, default=2, help="build threads (default 2, the machine's cores)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each graph-search request (default 3)")
    ap.add_argument(
        "--backend",
        choices=("local", "ray"),
        default="local",
        help="the build's backend (ray: compare its edges SHA-256)",
    )
    ap.add_argument("--keep", type=Path, help="folder for the graphs: KIND-FRAMES.mlgraph, used again when there")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--graph", help=argparse.SUPPRESS)
    ap.add_argument("--measure", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.measure:
        print(json.dumps(measure(json.loads(args.measure))))
        return 0
    if args.one:
        kind, frames = args.one.split(":")
        print(json.dumps(build_case(kind, int(frames), Path(args.graph), args.workers, args.backend)))
        return 0
    cases = args.cases or (["walk:1000", "walk:10000"] if os.environ.get("MOTIONLAB_QUICK") else list(CASES))
    print(f"machine: {os.cpu_count()} CPUs, load average {os.getloadavg()}")
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
    return max(run_case(c, args.workers, args.keep, max(args.repeat, 1), args.backend) for c in cases)


if __name__ == "__main__":
    sys.exit(main())
