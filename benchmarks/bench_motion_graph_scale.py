"""Structured motion graph build at scale: time, peak memory and connectivity against frames.

The shared Bandai Namco dataset-2 walk takes (``MOTIONLAB_DATA/bandai_namco/sessions/walk``,
7 styles, 175 takes, about 44 k frames) are loaded once and repeated under new take numbers
until a session of the requested size exists (1 k → 1 M frames; below 44 k, whole takes are
drawn round-robin over the styles). Each size is built in a fresh process, so its peak
resident memory (``ru_maxrss``) is its own; the graph is saved and loaded back to time the
file round trip.

    python benchmarks/bench_motion_graph_scale.py                 # 1k 10k 100k 1M
    python benchmarks/bench_motion_graph_scale.py --sizes 1000 10000   # quick
    MOTIONLAB_QUICK=1 python benchmarks/bench_motion_graph_scale.py    # 1k and 10k only

Goal (issue 13): 1 M frames in <= 3 min with peak memory <= 3 GB on the 2-core CPU.
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

THRESHOLD_M = 0.03
SIZES = (1_000, 10_000, 100_000, 1_000_000)


def session(frames: int):
    """Motions of about ``frames`` frames: the shared walk takes, repeated under new take numbers."""
    from motionlab import data
    from motionlab.core.motion import Motion
    from motionlab.motion_graphs import clips, naming

    folder = data.data_root() / "bandai_namco" / "sessions" / "walk"
    if not folder.is_dir():
        raise data.DataNotFound(f"needs {folder}: {data.HOW_TO}")
    takes = clips.load_folder(folder)
    by_style: dict[str, list] = {}
    for m in takes:
        by_style.setdefault(naming.parse_name(m.name).style, []).append(m)
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


def one(frames: int) -> dict:
    from motionlab.motion_graphs import distance, io, report, structured

    t0 = time.perf_counter()
    motions = session(frames)
    t_load = time.perf_counter() - t0
    quiet = not sys.stderr.isatty()
    t0 = time.perf_counter()
    g = structured.build_structured(motions, distance.threshold_from(THRESHOLD_M), progress=not quiet)
    t_build = time.perf_counter() - t0
    peak_build = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t0 = time.perf_counter()
    rep = report.build_report(g)
    t_report = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "g.mlgraph"
        t0 = time.perf_counter()
        io.save(path, g)
        t_save = time.perf_counter() - t0
        size = path.stat().st_size
        t0 = time.perf_counter()
        io.load(path)
        t_loadg = time.perf_counter() - t0
    return dict(
        frames=sum(m.num_frames for m in motions),
        takes=len(motions),
        load_s=t_load,
        build_s=t_build,
        report_s=t_report,
        save_s=t_save,
        file_mb=size / 1e6,
        load_graph_s=t_loadg,
        transitions=g.num_transitions,
        scc_percent=rep["percent"],
        peak_build_mb=peak_build,
        peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=None)
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(one(args.one)))
        return 0
    sizes = args.sizes or (SIZES[:2] if os.environ.get("MOTIONLAB_QUICK") else SIZES)
    print(f"threshold {THRESHOLD_M} m; machine: {os.cpu_count()} CPUs, load average {os.getloadavg()}")
    head = (
        "frames", "takes", "build s", "peak GB (build)", "peak GB (+report, save, load)", "SCC %", "transitions",
        "report s", "file MB", "save s", "load s",
    )  # fmt: skip
    print(" | ".join(head))
    for n in sizes:
        p = subprocess.run(
            [sys.executable, __file__, "--one", str(n)], capture_output=True, text=True, env=os.environ.copy()
        )
        if p.returncode != 0:
            print(f"{n}: failed\n{p.stderr[-2000:]}")
            return 1
        r = json.loads(p.stdout.strip().splitlines()[-1])
        print(
            f"{r['frames']} | {r['takes']} | {r['build_s']:.1f} | {r['peak_build_mb'] / 1024:.2f} | "
            f"{r['peak_mb'] / 1024:.2f} | {r['scc_percent']:.1f} | {r['transitions']} | {r['report_s']:.1f} | "
            f"{r['file_mb']:.0f} | {r['save_s']:.1f} | {r['load_graph_s']:.1f}"
        )
    print(f"load average after: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
