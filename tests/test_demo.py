"""``motionlab demo``, the README's main command, end to end on one character."""

from __future__ import annotations

import re

import pytest

from motionlab.core import bvh, humanoid
from motionlab.demo import run_demo


@pytest.mark.slow
def test_demo_writes_its_files_and_a_sensible_table(tmp_path, capsys):
    assert run_demo(tmp_path, characters=1, seed=0) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert names == {"source.bvh", "character_0.bvh", "foot_heights.png", "summary.md", ".motionlab-demo"}
    out = bvh.load(tmp_path / "character_0.bvh")
    assert humanoid.is_canonical(out.skeleton) and out.num_frames == bvh.load(tmp_path / "source.bvh").num_frames
    table = (tmp_path / "summary.md").read_text()
    assert "| full |" in capsys.readouterr().out  # the table is printed too
    means = {
        m: [float(x) for x in re.search(rf"^\| {m} \| (.+) \|$", table, re.M).group(1).split(" | ")]
        for m in ("copy", "network", "full")
    }
    # columns: MPJPE cm, below ground % h, skating m/s, smoothness, time s
    for method, (mpjpe, pen, _, _, _) in means.items():
        assert mpjpe < 5.0, f"{method}: {mpjpe} cm from the procedural reference"
        assert pen < 0.5, f"{method}: feet {pen} % of the height below ground"
    assert means["full"][1] <= means["network"][1], "the iteration must not push the feet further down"


def test_demo_never_overwrites_without_force(tmp_path):
    (tmp_path / "summary.md").write_text("mine")
    with pytest.raises(FileExistsError, match="summary.md"):
        run_demo(tmp_path, characters=1)
    assert (tmp_path / "summary.md").read_text() == "mine"


def test_demo_reruns_in_its_own_folder_and_keeps_foreign_files(tmp_path, monkeypatch):
    """The demo owns its output folder: a second run replaces its files without --force."""
    import motionlab.demo as demo

    monkeypatch.setattr(demo, "SEGMENTS", [("idle", 20), ("walk", 40)])  # small and quick
    assert run_demo(tmp_path, characters=1, seed=0) == 0
    first = (tmp_path / "summary.md").read_text()
    assert run_demo(tmp_path, characters=1, seed=0) == 0  # used to need force=True
    assert (tmp_path / "summary.md").read_text().splitlines()[:4] == first.splitlines()[:4]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".motionlab-tmp")]
    other = tmp_path.parent / f"{tmp_path.name}_mine"
    other.mkdir()
    (other / "source.bvh").write_text("mine")  # a folder the demo never wrote: refused without force
    with pytest.raises(FileExistsError, match="did not write"):
        run_demo(other, characters=1)
    assert (other / "source.bvh").read_text() == "mine"
