"""``compare_counts --families``: its held-out takes and its cuts."""

import numpy as np

from experiments.interpolation import check_gaps, compare_counts
from tests.conftest import require_data


def test_every_family_pattern_finds_takes_outside_the_choose_set():
    """Each glob of ``FAMILIES`` matches a take (a glob that matches nothing would shrink a family
    silently), and none is a take the count rules were chosen on."""
    root = require_data()
    chosen = {f.resolve() for f in check_gaps.sets(root, quick=False)["CHOOSE"]}
    for label, patterns in compare_counts.FAMILIES.items():
        for pattern in patterns:
            found = {f.resolve() for f in root.glob(pattern)}
            assert found, (label, pattern)
            assert not found & chosen, (label, pattern)


def test_family_cuts_are_seeded_and_leave_twenty_frames_on_each_side():
    root = require_data("xia").parent
    patterns = compare_counts.FAMILIES["Xia (walks, runs; 120 fps)"]
    a = compare_counts.family_cuts(root, patterns, 12, np.random.default_rng(3))
    b = compare_counts.family_cuts(root, patterns, 12, np.random.default_rng(3))
    assert [(m.name, s, n) for m, s, n in a] == [(m.name, s, n) for m, s, n in b]
    assert len(a) == 12
    for m, s, n in a:
        assert 1 <= n <= 30 and s >= 20 and s + n <= m.num_frames - 20
