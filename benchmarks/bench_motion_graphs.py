"""Motion-graph experiments of paper B, measured: build time, connectivity, search time,
transition smoothness, and a 100k-frame build.

    python benchmarks/bench_motion_graphs.py            # real data when MOTIONLAB_DATA is set
    python benchmarks/bench_motion_graphs.py --quick    # smaller sizes
    python benchmarks/bench_motion_graphs.py --skip-large

Data (printed with every table): Bandai Namco dataset-1 walk/run/dash styles (real; no
transition clips exist between those behaviours), Mixamo Aj clips with real transition clips
(idle → walk, jump/land → idle), and synthetic stand-ins from motionlab.synthetic where real
clips are missing (behaviour transitions walk ↔ run ↔ idle, the 100k-frame scale test).

On a busy machine set OPENBLAS_NUM_THREADS=1: a two-thread BLAS fighting other processes for
two cores runs ~10x slower; the value in effect is printed.
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
import warnings

import numpy as np

from motionlab import data
from motionlab.motion_graphs import clips, distance, graph, search, structured, synthesis

THRESHOLD_M = 0.03  # RMS metres


def _print_table(title: str, header: list[str], rows: list[list]) -> None:
    print(f"\n## {title}\n")
    cells = [header] + [[f"{v:.3g}" if isinstance(v, float) else str(v) for v in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    for k, r in enumerate(cells):
        print("| " + " | ".join(v.ljust(w) for v, w in zip(r, widths)) + " |")
        if k == 0:
            print("|" + "|".join("-" * (w + 2) for w in widths) + "|")


def _frames(ms) -> int:
    return sum(m.num_frames for m in ms)


def _real_sets(quick: bool):
    """(19-clip set, 6-clip set, source text) from Bandai, or synthetic stand-ins."""
    if data.has_data("bandai_namco", "dataset-1"):
        styles19 = {
            "walk": ("normal", "happy", "sad", "angry", "proud", "tired", "old"),
            "run": ("happy", "sad", "angry", "proud", "tired", "old"),
            "dash": ("happy", "sad", "angry", "proud", "tired", "old"),
        }
        set19 = []
        for b, ss in styles19.items():
            set19 += clips.bandai_styles([b], ss)
        set6 = clips.bandai_styles(["walk"], ("normal", "happy", "angry")) + clips.bandai_styles(
            ["run"], ("happy", "sad", "angry")
        )
        return set19, set6, "real: Bandai Namco dataset-1 (take 001), reduced to 22 joints, 30 fps"
    lib = clips.synthetic_library(seconds=4.0 if quick else 6.0, transitions=False)
    return lib, lib[:6], "SYNTHETIC stand-ins (MOTIONLAB_DATA not set)"


def experiment_build(set19, source: str, thr: float) -> None:
    t = time.perf_counter()
    std = graph.build_standard(set19, thr)
    t_std = time.perf_counter() - t
    t = time.perf_counter()
    plain = structured.build_structured(set19, thr, style_pairs="none")
    t_plain = time.perf_counter() - t
    t = time.perf_counter()
    st = structured.build_structured(set19, thr)
    t_st = time.perf_counter() - t
    rows = [
        [
            "standard (Kovar, all pairs + SCC pruning)",
            len(set19),
            _frames(set19),
            f"{t_std:.2f}",
            f"{std.info['comparisons']:,}",
            "140 min",
        ],
        [
            "structured, no interpolation space (as in the paper)",
            len(set19),
            _frames(set19),
            f"{t_plain:.2f}",
            f"{plain.info['comparisons']:,}",
            "57 min",
        ],
        [
            "structured + interpolation space (hub pairs)",
            len(set19),
            _frames(set19),
            f"{t_st:.2f}",
            f"{st.info['comparisons']:,}",
            "-",
        ],
    ]
    _print_table(
        f"1. Build time ({source})",
        ["graph", "clips", "frames", "seconds", "frame pairs compared", "paper (19 clips, 2,236 frames)"],
        rows,
    )
    print(
        f"\nstructured: {st.info['intermediates']} intermediate motions, registration {st.info['registration_seconds']:.2f} s; "
        f"speed-up over the paper: standard {140 * 60 / t_std:,.0f}x, structured {57 * 60 / t_plain:,.0f}x "
        f"({57 * 60 / t_st:,.0f}x with the interpolation space)"
    )
    for key, lines in sorted(st.info.get("conditions", {}).items()):
        print(f"  {key}: {len(lines)} (e.g. {lines[0]})")


def experiment_connectivity(set6, source: str, thr: float) -> None:
    rows = []
    for name, build in (
        ("standard", lambda: graph.build_standard(set6, thr, prune=False)),
        ("standard, pruned (largest SCC)", lambda: graph.build_standard(set6, thr)),
        ("interpolation space, no pruning (like wcMG)", lambda: structured.build_wcmg(set6, thr)),
        ("structured", lambda: structured.build_structured(set6, thr)),
    ):
        t = time.perf_counter()
        g = build()
        dt = time.perf_counter() - t
        s = g.summary()
        rows.append(
            [
                name,
                s["clips"],
                s["frames"],
                s["transitions"],
                s["largest_scc"],
                f"{s['largest_scc'] / max(s['frames'], 1):.0%}",
                s["dead_ends"],
                f"{dt:.2f}",
            ]
        )
    _print_table(
        f"2. Connectivity, {len(set6)} clips / {_frames(set6)} frames ({source})",
        ["graph", "clips", "frames", "transition points", "largest SCC (frames)", "of all", "dead ends", "build s"],
        rows,
    )


def _timed_search(fn, g, req, repeats=20) -> float:
    fn(g, req)  # warm: imports and first-touched memory (each search reads the graph afresh)
    t = time.perf_counter()
    for _ in range(repeats):
        fn(g, req)
    return (time.perf_counter() - t) / repeats * 1000


def experiment_search(quick: bool, thr: float) -> None:
    rows = []
    sizes = (2, 4) if quick else (2, 4, 8, 16)
    from motionlab import synthetic

    rng = np.random.default_rng(0)
    for n_styles in sizes:
        styles = {"idle": {"normal": {}}, "walk": {"normal": {}}, "run": {"normal": {}}}
        for k in range(1, n_styles):
            for b in ("walk", "run"):
                st = synthetic.random_style(b, rng, 0.6)
                styles[b][f"s{k}"] = {f: getattr(st, f) for f in ("stride", "cadence", "bounce", "arm_swing", "lean")}
        lib = clips.synthetic_library(seconds=6.0, styles=styles)
        req = "idle:normal:60,walk:normal:200,run:s1:150,walk:s1:180,idle:normal:90"
        g = structured.build_structured(lib, thr)
        t_st = _timed_search(search.search, g, req)
        r = search.search(g, req)
        infos = [
            graph.ClipInfo(m.name, "clip", *m.name.split("_")[:2]) if "_to_" not in m.name else graph.ClipInfo(m.name)
            for m in lib
        ]
        gs = graph.build_standard(lib, thr, infos=infos)
        try:
            t_sd = _timed_search(search.search_standard, gs, req, repeats=5)
        except search.SearchError as e:
            t_sd = f"fails: {str(e)[:40]}"
        rows.append(
            [
                len(lib),
                g.num_alive,
                f"{t_st:.2f}",
                max(abs(e) for e in r.errors),
                gs.num_alive,
                t_sd if isinstance(t_sd, str) else f"{t_sd:.2f}",
            ]
        )
    _print_table(
        "3. Search time for a 5-segment request vs graph size (SYNTHETIC clips: idle/walk/run with random styles and synthetic transition clips)",
        [
            "clips",
            "structured frames",
            "structured ms",
            "max |length error| (frames)",
            "standard frames",
            "standard (Dijkstra) ms",
        ],
        rows,
    )


def experiment_smoothness(thr: float) -> None:
    rows = []
    cases = []
    if data.has_data("bandai_namco", "dataset-1"):
        bw = clips.bandai_styles(["walk"], ("normal", "happy", "sad", "angry", "proud"))
        cases.append(
            (
                "real Bandai walks (style transitions)",
                bw,
                "walk:angry:200,walk:happy:150,walk:sad:150,walk:normal:120,walk:proud:200",
            )
        )
    if data.has_data("mixamo", "Aj"):
        aj = clips.mixamo_aj()
        cases.append(("real Mixamo Aj (idle->walk clip)", aj, "idle:normal:90,walk:catwalk:200"))
    cases.append(
        (
            "SYNTHETIC idle/walk/run",
            clips.synthetic_library(),
            "idle:normal:60,walk:happy:200,run:tired:150,walk:sad:120,idle:normal:90",
        )
    )
    for label, ms, req in cases:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = structured.build_structured(ms, thr)
        try:
            r = search.search(g, req)
        except search.SearchError as e:
            rows.append([label, req, f"search fails: {e}", "", "", "", ""])
            continue
        g.check_path(r.pieces)
        t = r.transitions()
        for mode, kw in (
            ("hard cut, root-aligned", dict(blend=0, align="root")),
            ("blend 8, root-aligned", dict(blend=8, align="root")),
            ("blend 8, root-aligned + root shift", dict(blend=8, align="root", fix_feet=True)),
            ("hard cut, foot-aligned", dict(blend=0, align="foot")),
            ("blend 8, foot-aligned (default)", dict(blend=8, align="foot")),
        ):
            m = synthesis.synthesize(g, r.pieces, **kw)
            q = synthesis.transition_quality(m, t)
            rows.append(
                [
                    label,
                    mode,
                    len(t),
                    f"{q['smoothness']:.4f}",
                    f"{q['max_jump']:.3f}",
                    f"{q['max_jump_all']:.3f}",
                    f"{q['foot_skating']:.3f}",
                ]
            )
        print(f"\n{label}: request {req}\n" + r.report())
    _print_table(
        "4. Transition smoothness (windows of ±5 frames around every jump)",
        [
            "data",
            "synthesis",
            "jumps",
            "mean accel. m/frame² (metrics.smoothness)",
            "max joint step m (windows)",
            "max joint step m (whole)",
            "foot skating m/s",
        ],
        rows,
    )


def experiment_large(quick: bool) -> None:
    from motionlab import synthetic

    rng = np.random.default_rng(1)
    n_styles = 6 if quick else 26
    styles: dict = {"walk": {"normal": {}}, "run": {"normal": {}}}
    for k in range(1, n_styles):
        for b in ("walk", "run"):
            st = synthetic.random_style(b, rng, 0.6)
            styles[b][f"s{k}"] = {f: getattr(st, f) for f in ("stride", "cadence", "bounce", "arm_swing", "lean")}
    lib = clips.synthetic_library(seconds=20.0, styles=styles)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t = time.perf_counter()
    g = structured.build_structured(lib, distance.threshold_from(THRESHOLD_M))
    dt = time.perf_counter() - t
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    req = "walk:normal:300,walk:s1:300,run:s2:300,run:normal:300,walk:s3:300"
    ms = _timed_search(search.search, g, req)
    _print_table(
        "5. Scale: structured graph from SYNTHETIC clips (20 s each, 30 fps; hub style pairs)",
        [
            "input clips",
            "input frames",
            "graph frames (with intermediates)",
            "alive",
            "transitions",
            "build s",
            "peak RSS MB (process)",
            "5-segment search ms",
        ],
        [
            [
                len(lib),
                _frames(lib),
                g.num_frames,
                g.num_alive,
                g.num_transitions,
                f"{dt:.1f}",
                f"{rss:.0f} (before: {rss0:.0f})",
                f"{ms:.2f}",
            ]
        ],
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--skip-large", action="store_true")
    args = ap.parse_args(argv)
    thr = distance.threshold_from(THRESHOLD_M)
    print(
        f"# motion graphs benchmark  (threshold {THRESHOLD_M} m RMS, window {distance.DEFAULT_WINDOW} frames; "
        f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}; {os.cpu_count()} CPUs; MOTIONLAB_DATA={os.environ.get('MOTIONLAB_DATA', 'unset')})"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        set19, set6, source = _real_sets(args.quick)
    experiment_build(set19, source, thr)
    experiment_connectivity(set6, source, thr)
    experiment_search(args.quick, thr)
    experiment_smoothness(thr)
    if not args.skip_large:
        experiment_large(args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
