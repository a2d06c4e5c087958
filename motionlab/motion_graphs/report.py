"""The build report of a structured motion graph: one table instead of a wall of warnings.

Per behaviour and style: takes, recorded frames, whole gait cycles, transitions (jump edges
that start at the style's frames: inside the style, into interpolation spaces and transition
clips), the share of its frames in the behaviour's largest strongly
connected component, and the frames pruned. Conditions met while building (a take pruned, a
forced transition, a missing link …) are counted once, with an example. Below the table, the
summary lines scripts may read::

    largest strongly connected component: <frames> frames (<percent>%)
    largest strongly connected component of <behaviour>: <frames> frames (<percent>%)

Frames here are *recorded* frames (basic takes and transition clips, as loaded); the
intermediate motions of the interpolation spaces carry the search between styles but are not
counted, so a percentage says how much of the recorded material the search can use. The
behaviour's component is taken in the sub-graph of that behaviour's frames (its takes and
intermediate motions), its percentage is of that behaviour's takes.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from motionlab.core import files
from motionlab.motion_graphs.graph import MotionGraph

__all__ = ["build_report", "format_report", "to_json", "write_report", "COLUMNS", "StageClock", "format_stages"]

COLUMNS = ("behaviour", "style", "takes", "frames", "cycles", "transitions", "in largest", "pruned")


def _pct(a: int, b: int) -> float:
    return round(100.0 * a / b, 1) if b else 0.0


def build_report(graph: MotionGraph) -> dict:
    """The report's data (JSON-ready).

    Returns
    -------
    dict with ``rows`` (one per behaviour/style: ``behaviour``, ``style``, ``takes``, ``frames``,
    ``cycles``, ``transitions``, ``in_largest`` (frames), ``in_largest_percent``, ``pruned``),
    ``behaviours`` (per behaviour: ``frames``, ``largest_scc``, ``percent``, ``kind`` (gait or
    action), ``segments`` (whole segments of an action, cycles of a gait), ``styles``,
    ``style_pairs`` and ``reachable_pairs`` (ordered style pairs joined by the behaviour's own
    links)), ``behaviour_links`` (ordered behaviour pairs joined directly: ``source``,
    ``target``, ``via`` → number of links), ``largest_scc`` and ``recorded_frames``
    (whole graph), ``percent``, ``conditions`` (kind → ``count``, ``example``) and ``info``
    (build times and counts; ``threshold`` in metres RMS, the unit of ``graph-build --distance-threshold``).
    """
    n = graph.num_frames
    recorded = np.zeros(n, dtype=bool)
    behaviour_frames: dict[str, np.ndarray] = {}
    style_clips: dict[tuple[str, str], list[int]] = {}
    for k, c in enumerate(graph.clips):
        if c.kind in ("basic", "transition", "clip"):
            recorded[c.start : c.stop] = True
        if c.behaviour is not None and c.kind in ("basic", "intermediate"):
            m = behaviour_frames.setdefault(c.behaviour, np.zeros(n, dtype=bool))
            m[c.start : c.stop] = True
        if c.kind == "basic":
            style_clips.setdefault((c.behaviour, c.style), []).append(k)
    live = graph.alive[graph.src] & graph.alive[graph.dst]
    cells = graph.table.get("behaviours", {})
    rows, behaviours = [], {}
    for b in sorted(behaviour_frames):
        comp = graph.largest_component(behaviour_frames[b])
        takes_b = np.zeros(n, dtype=bool)
        for (bb, s), ks in sorted(style_clips.items()):
            if bb == b:
                rows.append(_style_row(graph, b, s, ks, comp, live, cells.get(b, {}).get(s, {}), takes_b))
        total = int(takes_b.sum())
        got = int((comp & takes_b).sum())
        behaviours[b] = dict(frames=total, largest_scc=got, percent=_pct(got, total), **_kind(cells.get(b, {})))
        behaviours[b].update(_reachable(graph.table.get("links", []), b, sorted(cells.get(b, {}))))
    comp = graph.largest_component()
    got, total = int((comp & recorded).sum()), int(recorded.sum())
    conditions = {
        kind: dict(count=len(lines), example=lines[0])
        for kind, lines in graph.info.get("conditions", {}).items()
        if lines
    }
    info = {k: v for k, v in graph.info.items() if k != "conditions"}
    if "threshold" in info:  # the graph keeps it squared (m²); the report says it as --threshold does
        info["threshold"] = round(float(np.sqrt(info["threshold"])), 9)
    return dict(
        rows=rows,
        behaviours=behaviours,
        behaviour_links=_behaviour_links(graph.table.get("links", [])),
        recorded_frames=total,
        largest_scc=got,
        percent=_pct(got, total),
        conditions=conditions,
        info=info,
    )


def _style_row(graph: MotionGraph, b: str, s: str, ks: list[int], comp, live, cell: dict, takes_b) -> dict:
    """One report row: the takes ``ks`` of style ``s`` against the behaviour's largest component
    ``comp`` (frame mask); marks their frames in ``takes_b``."""
    mine = np.zeros(graph.num_frames, dtype=bool)
    for k in ks:
        mine[graph.clips[k].start : graph.clips[k].stop] = True
    takes_b |= mine
    frames, inside = int(mine.sum()), int((comp & mine).sum())
    return dict(
        behaviour=b,
        style=s,
        takes=len(ks),
        frames=frames,
        cycles=sum(int(t.get("cycles", 0)) for t in cell.get("takes", [])),
        transitions=int(np.sum(live & mine[graph.src])),
        in_largest=inside,
        in_largest_percent=_pct(inside, frames),
        pruned=int((mine & ~graph.alive).sum()),
    )


def _kind(cells: dict) -> dict:
    """Kind of a behaviour (the kind of most of its takes) and its whole segments or cycles."""
    takes = [t for cell in cells.values() for t in cell.get("takes", [])]
    kinds = [t.get("kind") for t in takes if t.get("kind")]
    kind = max(sorted(set(kinds)), key=kinds.count) if kinds else "-"
    cuts = sum(int(t.get("segments" if kind == "action" else "cycles", 0)) for t in takes)
    return dict(kind=kind, segments=cuts)


def _reachable(links: list[dict], behaviour: str, styles: list[str]) -> dict:
    """Ordered style pairs of ``behaviour`` joined by a chain of its own links (the search's hops)."""
    out: dict[str, set[str]] = {s: set() for s in styles}
    for link in links:
        if link["from"][0] == behaviour and link["to"][0] == behaviour and link["routes"]:
            out[link["from"][1]].add(link["to"][1])
    reached = 0
    for s in styles:
        seen, todo = {s}, [s]
        while todo:
            for t in out[todo.pop()] - seen:
                seen.add(t)
                todo.append(t)
        reached += len(seen) - 1
    return dict(styles=len(styles), style_pairs=len(styles) * (len(styles) - 1), reachable_pairs=reached)


def _behaviour_links(links: list[dict]) -> list[dict]:
    """Ordered behaviour pairs joined directly, and through what (links and their style pairs)."""
    found: dict[tuple[str, str], dict[str, int]] = {}
    for link in links:
        a, b = link["from"][0], link["to"][0]
        if a != b and link["routes"]:
            via = "stance" if link["via"] == "stance" else link["via"]
            n = found.setdefault((a, b), {})
            n[via] = n.get(via, 0) + 1
    return [dict(source=a, target=b, via=v) for (a, b), v in sorted(found.items())]


def format_report(report: dict) -> str:
    """The report as text: the table, the conditions, the summary lines."""
    cells = [list(COLUMNS)]
    for r in report["rows"]:
        cells.append(
            [r["behaviour"], r["style"], str(r["takes"]), str(r["frames"]), str(r["cycles"]), str(r["transitions"]),
             f"{r['in_largest_percent']:.1f}%", str(r["pruned"])]
        )  # fmt: skip
    widths = [max(len(row[i]) for row in cells) for i in range(len(COLUMNS))]
    right = [False, False] + [True] * (len(COLUMNS) - 2)
    lines = [
        "  ".join((v.rjust(w) if rr else v.ljust(w)) for v, w, rr in zip(row, widths, right)).rstrip() for row in cells
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    if report["conditions"]:
        lines.append("conditions (each counted once):")
        for kind, c in sorted(report["conditions"].items()):
            lines.append(f"  {kind}: {c['count']} (e.g. {c['example']})")
    else:
        lines.append("conditions: none")
    lines.append(
        "behaviour: kind, whole segments (actions) or cycles (gaits), share in its largest component, styles reachable"
    )
    for b, v in sorted(report["behaviours"].items()):
        lines.append(
            f"  {b}: {v.get('kind', '-')}, {v.get('segments', 0)} segments/cycles, {v['percent']:.1f}%, "
            f"{v.get('reachable_pairs', 0)}/{v.get('style_pairs', 0)} style pairs reachable"
        )
    links = report.get("behaviour_links", [])
    lines.append("links between behaviours:" + ("" if links else " none"))
    for x in links:
        via = ", ".join(f"{k} ({n} style pair{'s' * (n != 1)})" for k, n in sorted(x["via"].items()))
        lines.append(f"  {x['source']} -> {x['target']}: {via}")
    lines.append(f"largest strongly connected component: {report['largest_scc']} frames ({report['percent']:.1f}%)")
    for b, v in sorted(report["behaviours"].items()):
        lines.append(f"largest strongly connected component of {b}: {v['largest_scc']} frames ({v['percent']:.1f}%)")
    return "\n".join(lines)


def to_json(report: dict) -> str:
    """The report as JSON text (what :func:`write_report` writes)."""
    return json.dumps(report, indent=1, default=float)


def write_report(path: str | os.PathLike, report: dict, overwrite: bool = False) -> Path:
    """Write the report as JSON (atomically); refuses to replace a file unless ``overwrite``.

    Raises ``FileExistsError`` (exists), ``IsADirectoryError`` (a folder) or another ``OSError``
    naming the path.
    """
    return files.atomic_write(path, lambda f: f.write(to_json(report)), overwrite=overwrite, what="report")


def _peak_mb() -> float:
    """Peak resident memory of this process so far, MB (``ru_maxrss``: KiB on Linux, bytes on macOS)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1e6 if sys.platform == "darwin" else peak * 1024 / 1e6


def _rss_mb() -> float:
    """Resident memory of this process now, MB (0 where ``/proc`` is missing)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6
    except (OSError, ValueError, IndexError):  # pragma: no cover - not Linux
        return 0.0


class StageClock:
    """Seconds and memory of named stages of a long job (a graph build, a command).

    ``with clock("distances"): ...`` times one stage; a stage entered again adds its seconds.
    :attr:`rows` lists the stages in the order first entered, each a dict with ``stage``,
    ``seconds``, ``peak_mb`` (the process's peak resident memory when the stage last ended: a
    stage that raised the peak shows it first) and ``rss_mb`` (resident memory then), MB.
    """

    def __init__(self):
        self.rows: list[dict] = []

    @contextmanager
    def __call__(self, stage: str):
        t = time.perf_counter()
        try:
            yield
        finally:
            row = next((r for r in self.rows if r["stage"] == stage), None)
            if row is None:
                row = {"stage": stage, "seconds": 0.0}
                self.rows.append(row)
            row["seconds"] += time.perf_counter() - t
            row["peak_mb"], row["rss_mb"] = round(_peak_mb(), 1), round(_rss_mb(), 1)

    def extend(self, rows: list[dict]) -> None:
        """Append stages measured elsewhere (e.g. a build's ``info["stages"]``)."""
        self.rows.extend(dict(r) for r in rows)


def format_stages(rows: list[dict]) -> str:
    """Stage rows (:class:`StageClock`) as a table: seconds, peak so far and resident memory, GB."""
    lines = [f"{'stage':<22} {'seconds':>8} {'peak GB':>8} {'RSS GB':>7}"]
    for r in rows:
        lines.append(f"{r['stage']:<22} {r['seconds']:8.2f} {r['peak_mb'] / 1e3:8.2f} {r['rss_mb'] / 1e3:7.2f}")
    lines.append(f"{'total':<22} {sum(r['seconds'] for r in rows):8.2f} {max(r['peak_mb'] for r in rows) / 1e3:8.2f}")
    return "\n".join(lines)
