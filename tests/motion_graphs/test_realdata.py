"""On real mocap (skipped unless MOTIONLAB_DATA points at the shared data)."""

from __future__ import annotations

import warnings

import pytest

from motionlab import data
from motionlab.motion_graphs import clips, search, structured
from tests.motion_graphs.conftest import THRESHOLD, session_walk_takes

pytestmark = pytest.mark.realdata


def test_bandai_walk_styles_end_to_end():
    if not data.has_data("bandai_namco", "dataset-1", "walk"):
        pytest.skip(f"needs real mocap (bandai_namco/dataset-1): {data.HOW_TO}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ms = clips.bandai_styles(["walk"], ("normal", "happy", "angry"))
    g = structured.build_structured(ms, THRESHOLD)
    assert g.dead_ends().size == 0
    assert set(g.table["behaviours"]["walk"]) == {"normal", "happy", "angry"}
    r = search.search(g, "walk:angry:200,walk:happy:150,walk:normal:150")
    g.check_path(r.pieces)
    for req, got in zip(r.requested, r.achieved):
        assert abs(got - req) <= max(2, search.TOLERANCE * req)


def test_session_takes_pool_and_connect():
    """Four takes each of three dataset-2 walk styles: one style per name, whatever the take;
    the behaviour's largest component holds >= 90% of its frames; every style reaches every other."""
    from motionlab.motion_graphs import distance, report

    ms = session_walk_takes(4)
    g = structured.build_structured(ms, distance.threshold_from(0.03))
    assert sorted(g.table["behaviours"]["walk"]) == ["elderly", "feminine", "normal"]
    assert all(len(c["takes"]) == 4 for c in g.table["behaviours"]["walk"].values())
    rep = report.build_report(g)
    assert rep["behaviours"]["walk"]["percent"] >= 90.0, report.format_report(rep)
    for a in ("normal", "elderly", "feminine"):
        for b in ("normal", "elderly", "feminine"):
            if a != b:
                r = search.search(g, f"walk:{a}:150,walk:{b}:150")
                g.check_path(r.pieces)
                for req, got in zip(r.requested, r.achieved):
                    assert abs(got - req) <= max(2, search.TOLERANCE * req)
