"""``motionlab demo``, the README's main command, end to end on one random character and the long-shins case."""

from __future__ import annotations

import re

import numpy as np
import pytest

from motionlab.core import bvh, humanoid
from motionlab.demo import run_demo


def _summary(table: str, first: str) -> dict:
    """The summary rows whose first cell starts with ``first``: method -> numeric cells and the verdict."""
    out = {}
    for m in re.finditer(rf"^\| {re.escape(first)}[^|]* \| (copy|network|full) \| (.+) \|$", table, re.M):
        cells = m.group(2).split(" | ")
        # columns: MPJPE cm, planted-foot slide cm/s, lowest joint cm, below ground % h, smoothness, plausible, time s
        out[m.group(1)] = dict(
            zip(("mpjpe", "slide", "lowest", "pen", "smooth"), map(float, cells[:5])), plausible=cells[5]
        )
    return out


@pytest.mark.slow
def test_demo_writes_its_files_and_a_sensible_table(tmp_path, capsys):
    assert run_demo(tmp_path, characters=1, seed=0) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert names == {
        "source.bvh",
        "character_0.bvh",
        "long_shins.bvh",
        "foot_heights.png",
        "summary.md",
        ".motionlab-demo",
    }
    out = bvh.load(tmp_path / "character_0.bvh")
    assert humanoid.is_canonical(out.skeleton) and out.num_frames == bvh.load(tmp_path / "source.bvh").num_frames
    table = (tmp_path / "summary.md").read_text()
    assert "| full |" in capsys.readouterr().out  # the table is printed too
    means, case = _summary(table, "mean over 1 random character"), _summary(table, "long shins")
    assert set(means) == set(case) == {"copy", "network", "full"}
    for method, row in [*means.items(), *case.items()]:
        assert row["mpjpe"] < 5.0, f"{method}: {row['mpjpe']} cm from the procedural reference"
        assert row["pen"] < 0.5, f"{method}: feet {row['pen']} % of the height below ground"
    assert means["full"]["pen"] <= means["network"]["pen"], "the iteration must not push the feet further down"
    # the case where copying fails: copied rotations slide the planted feet, the full method keeps them still
    assert case["copy"]["slide"] > means["copy"]["slide"], "long shins should be where copying slides"
    assert case["full"]["slide"] < case["copy"]["slide"], "the full method must reduce copy's slide on long shins"
    assert case["full"]["lowest"] >= min(case["copy"]["lowest"], 0.0), "nor push a joint under the floor"
    assert case["full"]["plausible"] == "yes"
    assert "On long shins, copied rotations slide the planted feet" in table


def test_long_shins_changes_the_shins_only():
    """The demo's case: both shins alone longer by the sampler's largest leg factor, feet on the ground."""
    from motionlab.demo import long_shins
    from motionlab.synthetic import characters

    sk = humanoid.canonical_skeleton()
    ls = long_shins(sk)
    bone = lambda s, j: float(np.linalg.norm(s.offsets[s.index(j)]))  # noqa: E731
    for side in ("Left", "Right"):
        assert bone(ls, f"{side}Foot") == pytest.approx(characters.RANGES["legs"][1] * bone(sk, f"{side}Foot"))
        assert bone(ls, f"{side}Leg") == bone(sk, f"{side}Leg") and bone(ls, f"{side}ToeBase") == bone(
            sk, f"{side}ToeBase"
        )
    assert ls.rest_positions()[:, 1].min() == pytest.approx(sk.rest_positions()[:, 1].min())
    with pytest.raises(ValueError, match="factor"):
        long_shins(sk, 0.0)


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
