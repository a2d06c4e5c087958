"""Every ordered pair of rig families, retargeted both ways, passes the plausibility check.

One shared clip per family (:data:`experiments.retargeting.rig_matrix.FAMILY_CLIPS`, first 2 s):
Mixamo, Bandai Namco, CMU and Xia from MOTIONLAB_DATA (skipped with the how-to without it)
and motionlab's synthetic character (always). ``experiments/retargeting/rigs.py`` prints the numbers.
"""

from __future__ import annotations

import pytest

from experiments.retargeting import rig_matrix
from motionlab import data, retargeting
from motionlab.retargeting.solver import SolverConfig
from tests.conftest import require_data

FAST = SolverConfig(max_steps=20)
FAMILIES = (*rig_matrix.FAMILY_CLIPS, "synthetic")


@pytest.fixture(scope="module")
def ckpt():
    return retargeting.load_default("cpu")


@pytest.fixture(scope="module")
def clips():
    return rig_matrix.family_clips(data.data_root() if data.has_data() else None, seconds=2.0)


@pytest.mark.slow
@pytest.mark.parametrize("source", FAMILIES)
def test_every_pair_from_source_is_plausible(source, clips, ckpt):
    if source != "synthetic":
        require_data(*rig_matrix.FAMILY_CLIPS[source].split("/"))
    targets = [t for t in FAMILIES if t != source and t in clips]
    if not targets:
        require_data()  # only the synthetic character without data: nothing to pair with
    rows = rig_matrix.pair_matrix(clips, ckpt, FAST, pairs={(source, t) for t in targets})
    assert len(rows) == len(targets)
    bad = [f"{r['source']}->{r['target']}: {r['failed']}" for r in rows if not r["ok"]]
    assert not bad, "\n" + rig_matrix.table(rows)
    for r in rows:  # at the source's frame rate
        assert r["fps"] == pytest.approx(clips[source].fps, rel=1e-4)


def test_synthetic_onto_presets_is_plausible(ckpt):
    """Without data: the synthetic character onto other proportions, both ways."""
    from motionlab import synthetic
    from motionlab.core import humanoid

    walk = rig_matrix.family_clips(None, seconds=1.0)["synthetic"]
    long = humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.3, arms=0.8)
    other = synthetic.generate("walk", long, num_frames=60, fps=30, seed=1)
    rows = rig_matrix.pair_matrix({"synthetic": walk, "long_legs": other}, ckpt, FAST)
    assert [r["ok"] for r in rows] == [True, True], rig_matrix.table(rows)
    assert rows[1]["fps"] == 30  # a 30 fps source stays 30 fps
