"""Shared small graphs for the motion-graph tests (synthetic clips, built once per session)."""

from __future__ import annotations

import pytest

from motionlab import data
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


def session_walk_takes(per_style: int, styles=("normal", "elderly", "feminine")) -> list:
    """The first ``per_style`` dataset-2 walk takes of each style (real mocap), prepared at 30 fps
    and named by their files; the test is skipped without the data."""
    from motionlab.core import bvh

    if not data.has_data("bandai_namco", "sessions", "walk"):
        pytest.skip(f"needs real mocap (bandai_namco/sessions/walk): {data.HOW_TO}")
    root = data.data_root() / "bandai_namco" / "sessions" / "walk"
    return [
        clips.prepare(bvh.load(path), 30.0).copy(name=path.stem)
        for style in styles
        for path in sorted(root.glob(f"dataset-2_walk_{style}_*.bvh"))[:per_style]
    ]
