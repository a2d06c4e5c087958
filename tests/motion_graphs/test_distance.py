"""Kovar's frame distance: symmetry, invariance, closed form vs. explicit alignment, blocks."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import quat
from motionlab.motion_graphs import distance


def grid_tolerance(d) -> np.ndarray:
    """How far D (m²) may move when every point is rounded to ``distance.GRID`` in both clouds:
    each point moves by at most e = 2·√3·GRID (its own rounding and its centring's), so
    |ΔD| <= 2·√D·e + e²."""
    e = 2.0 * np.sqrt(3.0) * distance.GRID
    return 2.0 * np.sqrt(np.asarray(d)) * e + e * e


@pytest.fixture(scope="module")
def walk_pos(library):
    return library[[m.name for m in library].index("walk_normal")].global_positions()[:60]


@pytest.fixture(scope="module")
def run_pos(library):
    return library[[m.name for m in library].index("run_normal")].global_positions()[:50]


def test_same_clip_symmetric_with_zero_diagonal(walk_pos):
    d = distance.distance_matrix(walk_pos)
    np.testing.assert_allclose(d, d.T, atol=1e-12)
    np.testing.assert_allclose(np.diag(d), 0.0, atol=1e-12)
    assert d.min() >= 0.0
    assert d[0, 30] > 1e-4  # different poses are apart


def test_invariant_to_turning_and_shifting_one_clip(walk_pos, run_pos):
    q = quat.from_yaw(np.array(1.1))
    moved = quat.rotate(q, run_pos) + np.array([2.5, 0.0, -4.0])
    d = distance.distance_matrix(walk_pos, run_pos)
    assert np.all(np.abs(distance.distance_matrix(walk_pos, moved) - d) <= 2 * grid_tolerance(d))


def test_lifting_a_clip_changes_the_distance(walk_pos):
    """Only ground moves are factored out: a vertical shift is a real difference."""
    lifted = walk_pos + np.array([0.0, 0.1, 0.0])
    d = distance.distance_matrix(walk_pos, lifted)
    assert np.all(np.abs(np.diag(d) - 0.01) <= grid_tolerance(0.01))  # (0.1 m)^2 for every point


def test_closed_form_equals_explicit_alignment(walk_pos, run_pos):
    fa, fb = distance.cloud_features(walk_pos), distance.cloud_features(run_pos)
    i, j = np.array([3, 17, 40]), np.array([5, 22, 9])
    theta, shift = distance.alignment(fa, fb, i, j)
    d = distance.distance_matrix(fa, fb)
    h = distance.DEFAULT_WINDOW // 2
    for a, b, t, s in zip(i, j, theta, shift):
        ia = np.clip(np.arange(a - h, a + h + 1), 0, len(walk_pos) - 1)
        ib = np.clip(np.arange(b - h, b + h + 1), 0, len(run_pos) - 1)
        pa = walk_pos[ia].reshape(-1, 3)
        pb = quat.rotate(quat.from_yaw(np.array(t)), run_pos[ib].reshape(-1, 3)) + s
        explicit = np.sum(fa.weights * np.sum((pa - pb) ** 2, axis=-1))
        assert abs(d[a, b] - explicit) <= grid_tolerance(explicit)
        # and no other turn does better
        for other in (t + 0.05, t - 0.05):
            pb2 = quat.rotate(quat.from_yaw(np.array(other)), run_pos[ib].reshape(-1, 3))
            pb2 = pb2 + (pa - pb2).T @ fa.weights * np.array([1.0, 0.0, 1.0])
            assert np.sum(fa.weights * np.sum((pa - pb2) ** 2, axis=-1)) >= explicit - 1e-12


def test_blocks_do_not_change_candidates(walk_pos, run_pos):
    """Bit for bit: every sum is exact (module docstring), so the summation order a block size or
    a BLAS kernel picks cannot change D."""
    full = distance.candidates(walk_pos, run_pos, threshold=np.inf)
    small = distance.candidates(walk_pos, run_pos, threshold=np.inf, block_rows=7)
    for x, y in zip(full, small):
        np.testing.assert_array_equal(x, y)


def test_candidates_are_local_minima_below_threshold(walk_pos, run_pos):
    d = distance.distance_matrix(walk_pos, run_pos)
    thr = np.quantile(d, 0.2)
    i, j, c = distance.candidates(walk_pos, run_pos, threshold=thr)
    assert i.size > 0 and np.all(c < thr)
    np.testing.assert_allclose(c, d[i, j])
    padded = np.pad(d, 1, constant_values=np.inf)
    for a, b in zip(i, j):
        assert d[a, b] <= padded[a : a + 3, b : b + 3].min() + 1e-15


def test_self_candidates_respect_min_gap(walk_pos):
    i, j, _ = distance.candidates(walk_pos, None, threshold=np.inf, min_gap=10)
    assert i.size > 0 and np.all(np.abs(i - j) >= 10)


def test_bad_input():
    with pytest.raises(ValueError, match=r"\(T, J, 3\)"):
        distance.cloud_features(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="odd"):
        distance.cloud_features(np.zeros((5, 2, 3)), window=4)
    with pytest.raises(ValueError, match="exactly one"):
        distance.threshold_from()
    assert distance.threshold_from(relative=0.02, scale=1.5) == pytest.approx(0.03**2)


def test_any_summation_order_gives_the_same_bits(walk_pos, run_pos):
    """The points of a cloud taken in another order sum in another order: D stays bit for bit
    the same, which is what makes candidates independent of the CPU's BLAS kernels."""
    fa, fb = distance.cloud_features(walk_pos), distance.cloud_features(run_pos)
    n = fa.height.shape[1]
    order = np.random.default_rng(0).permutation(n)

    def shuffled(f):
        cols = np.concatenate([order, order + n])
        return distance.CloudFeatures(
            f.centred[:, cols], f.height[:, order], f.weights[order], f.self_term, f.mean_xz, f.unit_weights[order]
        )

    np.testing.assert_array_equal(
        distance.distance_matrix(shuffled(fa), shuffled(fb)), distance.distance_matrix(fa, fb)
    )


def test_clouds_too_large_for_exact_sums_are_refused(walk_pos):
    with pytest.raises(ValueError, match="are the positions in metres"):
        distance.cloud_features(walk_pos * 100.0)  # centimetres
