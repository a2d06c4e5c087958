"""Shared small graphs for the motion-graph tests (synthetic clips, built once per session)."""

from __future__ import annotations

import pytest

from motionlab.motion_graphs import clips, distance, structured

STYLES = {
    "walk": {"normal": {}, "happy": {"stride": 0.95, "cadence": 2.1, "bounce": 0.035, "arm_swing": 0.5}},
    "run": {"normal": {}},
}
THRESHOLD = distance.threshold_from(0.03)


@pytest.fixture(scope="session")
def library():
    """Synthetic walk (2 styles), run, and walk<->run transition clips, 4 s at 30 fps."""
    return clips.synthetic_library(fps=30.0, seconds=4.0, styles=STYLES)


@pytest.fixture(scope="session")
def sgraph(library):
    return structured.build_structured(library, THRESHOLD)
