"""Motion graphs (Kovar et al. 2002) and the structured motion graph of paper B.

* :mod:`.distance` — Kovar's point-cloud frame distance for whole clip pairs, transition candidates;
* :mod:`.graph` — the graph data structure, the standard graph and its pruning;
* :mod:`.registration` — DTW time registration, root alignment and blends;
* :mod:`.structured` — structure table of pooled takes, transition clips, interpolation space,
  local pruning; :mod:`.cycles` — gait cycles from foot contacts; :mod:`.segments` — gait or
  standing action from the motion, stances and segments; :mod:`.stance_links` — links between
  styles and behaviours where their stances match; :mod:`.report` — the build report;
* :mod:`.search` — requests of (behaviour, style, frames) segments, under a search cost
  (``search_path(graph, request, cost=...)``, default :func:`.search.default_cost`); the
  standard-graph baseline;
* :mod:`.synthesis` — a path turned into one continuous, blended motion;
* :mod:`.io` — save/load (``.mlgraph``, npz + JSON); :mod:`.naming` — clip-name labels;
* :mod:`.clips` — real clips through ``MOTIONLAB_DATA`` or synthetic stand-ins; :mod:`.plots`.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import importlib

_SUBMODULES = frozenset(
    ("clips", "cycles", "distance", "graph", "io", "naming", "registration", "report", "search", "segments",
     "stance_links", "structured", "synthesis")
)  # fmt: skip
_NAMES = {
    "ClipInfo": "graph", "GraphError": "graph", "MotionGraph": "graph", "build_standard": "graph",
    "Planner": "search", "SearchError": "search", "SearchResult": "search", "Segment": "search",
    "default_cost": "search", "parse_request": "search", "search_standard": "search", "search_path": "search",
    "build_structured": "structured", "structure_rows": "structured",
    "synthesize": "synthesis", "transition_quality": "synthesis",
}  # fmt: skip
"""Where each public name lives; a submodule is imported when one of its names is first used, so
that a command importing one module (``graph-search``: io, search, synthesis) does not import
the build's modules."""


def __getattr__(name: str):
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _NAMES:
        value = getattr(
            importlib.import_module(f"{__name__}.{_NAMES[name]}"), "search" if name == "search_path" else name
        )
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "distance",
    "registration",
    "search",
    "synthesis",
    "io",
    "naming",
    "clips",
    "cycles",
    "segments",
    "stance_links",
    "report",
    "ClipInfo",
    "GraphError",
    "MotionGraph",
    "build_standard",
    "build_structured",
    "structure_rows",
    "Planner",
    "SearchError",
    "SearchResult",
    "Segment",
    "default_cost",
    "parse_request",
    "search_path",
    "search_standard",
    "synthesize",
    "transition_quality",
]
