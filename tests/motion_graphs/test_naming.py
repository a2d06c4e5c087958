"""Clip names -> labels; a take number never makes a style."""

from __future__ import annotations

import pytest

from motionlab.motion_graphs.naming import MIXAMO_AJ, ClipLabel, NamingError, label_name, parse_name


@pytest.mark.parametrize(
    "name, text, take",
    [
        ("Walk_creepingly", "walk_creepingly", None),
        ("Walk_happily_to_Run_fast", "walk_happily_to_run_fast", None),
        ("Transition_Walk_normal_Run_slowly", "walk_normal_to_run_slowly", None),
        ("dataset-1_walk_angry_001.bvh", "walk_angry_001", "001"),
        ("data/dataset-1_walk-back_not-confident_001", "walk-back_not-confident_001", "001"),
        ("dataset-2_walk_normal_017", "walk_normal_017", "017"),
        ("Walk_angry_3", "walk_angry_3", "3"),
    ],
)
def test_forms(name, text, take):
    lab = parse_name(name)
    assert label_name(lab) == text and lab.take == take
    assert parse_name(label_name(lab)) == lab  # the canonical text reads back to the same label


def test_takes_share_a_style():
    a, b = parse_name("dataset-2_walk_normal_001"), parse_name("dataset-2_walk_normal_050")
    assert a.key == b.key == ("walk", "normal") and a.take != b.take


def test_name_map_and_errors():
    lab = parse_name("Catwalk_Idle_To_Walk_Forward", MIXAMO_AJ)
    assert lab.kind == "transition" and lab.key == ("idle", "normal") and lab.to_key == ("walk", "catwalk")
    with pytest.raises(NamingError, match="Behaviour_style"):
        parse_name("Jazz_Dancing_Twice")
    with pytest.raises(NamingError, match="name map"):
        parse_name("X", {"X": "not a label"})


def test_callable_name_map():
    # another naming scheme: "<subject>-<style>-<behaviour>-take<k>"
    def scheme(stem):
        bits = stem.split("-")
        return f"{bits[2]}_{bits[1]}_{bits[3][4:]}" if len(bits) == 4 else None

    lab = parse_name("s07-proud-walk-take12", scheme)
    assert lab == ClipLabel("basic", "walk", "proud", take="12")
    assert parse_name("Walk_sad", scheme).key == ("walk", "sad")  # None falls back to the built-in forms
    assert parse_name("x", lambda s: ClipLabel("basic", "run", "fast")).key == ("run", "fast")


@pytest.mark.parametrize("name", ["Idle_1", "Troca_1", "131_03", "angry_13_000", "walk_1_to_run_2", "Walk_2_3"])
def test_a_number_is_never_a_style(name):
    """Mixamo's ``Idle_1``, CMU's ``131_03`` and Xia et al.'s ``angry_13_000`` used to give styles
    ``1``, ``03`` and ``13`` (and behaviours ``idle``, ``131``, ``angry``): a take number made a
    style, which the module forbids. Refused, naming the folder reading."""
    with pytest.raises(NamingError, match="a style is not a number .*--behaviour-folders"):
        parse_name(name)


@pytest.mark.parametrize(
    "name, folder, text, take",
    [
        ("angry_13_000", "run", "run_angry_13-000", "13-000"),  # Xia et al.
        ("sexy_01_001", "walk", "walk_sexy_01-001", "01-001"),
        ("normal_ganimator", "walk", "walk_normal-ganimator", None),  # no number: the whole name is the style
        ("Walk_happily", "walk", "walk_happily", None),  # a name that names the folder's behaviour reads as always
        ("dataset-2_walk_active_001", "walk", "walk_active_001", "001"),
        ("dataset-1_kick_normal_001", "behaviours", "kick_normal_001", "001"),  # Bandai Namco's names say it all
        ("Walk_happily_to_Run_fast", "walk", "walk_happily_to_run_fast", None),  # a transition reads as always
    ],
)
def test_a_behaviour_folder_names_the_behaviour(name, folder, text, take):
    lab = parse_name(name, behaviour=folder)
    assert label_name(lab) == text and lab.take == take
    assert parse_name(label_name(lab)) == lab


def test_a_behaviour_folder_refuses_what_it_cannot_read():
    with pytest.raises(NamingError, match="cannot read a style from clip name '131_03' in behaviour folder '131'"):
        parse_name("131_03", behaviour="131")
    with pytest.raises(NamingError, match="folder name 'my walks' is not a behaviour name"):
        parse_name("angry_13_000", behaviour="my walks")
