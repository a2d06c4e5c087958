"""Clip names -> labels."""

from __future__ import annotations

import pytest

from motionlab.motion_graphs.naming import MIXAMO_AJ, NamingError, label_name, parse_name


@pytest.mark.parametrize(
    "name, text",
    [
        ("Walk_creepingly", "walk_creepingly"),
        ("Walk_happily_to_Run_fast", "walk_happily_to_run_fast"),
        ("Transition_Walk_normal_Run_slowly", "walk_normal_to_run_slowly"),
        ("dataset-1_walk_angry_001.bvh", "walk_angry"),
        ("data/dataset-1_walk-back_not-confident_001", "walk-back_not-confident"),
        ("dataset-1_walk_normal_002", "walk_normal-2"),
    ],
)
def test_forms(name, text):
    assert label_name(parse_name(name)) == text


def test_name_map_and_errors():
    lab = parse_name("Catwalk_Idle_To_Walk_Forward", MIXAMO_AJ)
    assert lab.kind == "transition" and lab.key == ("idle", "normal") and lab.to_key == ("walk", "catwalk")
    with pytest.raises(NamingError, match="Behaviour_style"):
        parse_name("Jazz_Dancing_Twice")
    with pytest.raises(NamingError, match="name map"):
        parse_name("X", {"X": "not a label"})
