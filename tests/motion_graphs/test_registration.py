"""DTW registration and blends."""

from __future__ import annotations

import numpy as np

from motionlab.motion_graphs import distance, registration


def _brute(c):
    ta, tb = c.shape
    acc = np.full((ta, tb), np.inf)
    acc[0], acc[:, 0] = c[0], c[:, 0]
    for i in range(1, ta):
        for j in range(1, tb):
            acc[i, j] = c[i, j] + min(acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
    return acc


def test_dtw_path_cost_matches_the_recursion():
    rng = np.random.default_rng(0)
    for _ in range(5):
        c = rng.random((rng.integers(4, 25), rng.integers(4, 25)))
        reg = registration.dtw(c)
        p = reg.path
        assert p[0, 0] == 0 or p[0, 1] == 0
        assert p[-1, 0] == c.shape[0] - 1 or p[-1, 1] == c.shape[1] - 1
        steps = np.diff(p, axis=0)
        assert np.all(steps >= 0) and np.all(steps.sum(axis=1) >= 1) and np.all(steps <= 1)
        np.testing.assert_allclose(_brute(c)[p[-1, 0], p[-1, 1]], c[p[:, 0], p[:, 1]].sum())


def test_dtw_finds_a_time_stretch():
    t = np.linspace(0, 4 * np.pi, 80)
    a = np.sin(t)
    b = np.sin(np.linspace(0, 4 * np.pi, 120))
    reg = registration.dtw((a[:, None] - b[None, :]) ** 2)
    slope = np.polyfit(reg.path[:, 0], reg.path[:, 1], 1)[0]
    assert abs(slope - 1.5) < 0.1


def test_blend_endpoints(library):
    names = [m.name for m in library]
    a, b = library[names.index("walk_normal")], library[names.index("walk_happy")]
    reg = registration.register(a, b)
    m0 = registration.blend(a, b, reg, 0.0)
    i0 = reg.path[0, 0]
    np.testing.assert_allclose(m0.global_positions(), a.global_positions()[i0 : i0 + len(m0)], atol=1e-9)
    m1 = registration.blend(a, b, reg, 1.0)
    j0 = reg.path[0, 1]
    d = distance.distance_matrix(m1.global_positions(), b.global_positions()[j0 : j0 + len(m1)])
    # B itself, up to a ground transform: apart only by the rounding of points to distance.GRID
    assert distance.rms(np.diag(d)).max() < 2 * np.sqrt(3) * distance.GRID
    mid = registration.blend(a, b, reg, 0.5)
    assert min(len(m0), len(m1)) <= len(mid) <= max(len(m0), len(m1))
    np.testing.assert_allclose(np.linalg.norm(mid.local_rot, axis=-1), 1.0, atol=1e-9)
