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

from motionlab.motion_graphs import (
    clips,
    cycles,
    distance,
    io,
    naming,
    registration,
    report,
    search,
    segments,
    stance_links,
    synthesis,
)
from motionlab.motion_graphs.graph import ClipInfo, GraphError, MotionGraph, build_standard
from motionlab.motion_graphs.search import (
    Planner,
    SearchError,
    SearchResult,
    Segment,
    default_cost,
    parse_request,
    search_standard,
)
from motionlab.motion_graphs.search import search as search_path
from motionlab.motion_graphs.structured import build_structured, structure_rows
from motionlab.motion_graphs.synthesis import synthesize, transition_quality

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
