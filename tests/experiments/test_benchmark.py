"""The LaFAN1-style benchmark: windows, metrics, and the interpolation row against a from-scratch version."""

import numpy as np
import pytest

from experiments.interpolation import benchmark as bm
from motionlab.interpolation.library import MotionLibrary
from tests.interpolation.conftest import toy_motion


@pytest.fixture(scope="module")
def clips():
    return [toy_motion(150, speed=s, phase=p) for s, p in ((1.2, 0.0), (1.4, 1.0), (1.0, 2.0))]


@pytest.fixture(scope="module")
def windows(clips):
    for i, c in enumerate(clips):
        c.name = f"clip{i}"
    return bm.make_windows(clips)


def slow_reference_interpolation(rot, root, n_past, gap):
    """Straightforward per-window, per-frame, per-joint SLERP + linear root, written from the formula."""
    W, _, J, _ = rot.shape
    out_rot = np.zeros((W, gap, J, 4))
    out_root = np.zeros((W, gap, 3))
    a, b = n_past - 1, n_past + gap
    for w in range(W):
        for k in range(1, gap + 1):
            t = k / (gap + 1)
            out_root[w, k - 1] = (1 - t) * root[w, a] + t * root[w, b]
            for j in range(J):
                q, p = rot[w, a, j], rot[w, b, j]
                d = float(np.dot(q, p))
                if d < 0:
                    p, d = -p, -d
                omega = np.arccos(min(d, 1.0))
                if omega < 1e-9:
                    r = (1 - t) * q + t * p
                else:
                    r = (np.sin((1 - t) * omega) * q + np.sin(t * omega) * p) / np.sin(omega)
                out_rot[w, k - 1, j] = r / np.linalg.norm(r)
    return out_rot, out_root


def test_windows_shape_and_facing(windows):
    assert windows.local_rot.shape[1:] == (65, 7, 4)
    assert len(windows) == 3 * 3  # starts 0, 40, 80 in each 150-frame clip
    from motionlab.core import quat

    np.testing.assert_allclose(quat.yaw(windows.local_rot[:, bm.N_PAST - 1, 0]), 0.0, atol=1e-9)
    np.testing.assert_allclose(windows.trans[:, :, 0, [0, 2]].mean(axis=1), 0.0, atol=1e-9)


@pytest.mark.parametrize("gap", bm.GAPS)
def test_interpolation_row_matches_independent_implementation(windows, gap):
    rot, trans = bm.method_interpolation(windows, bm.N_PAST, gap)
    ref_rot, ref_root = slow_reference_interpolation(windows.local_rot, windows.trans[:, :, 0], bm.N_PAST, gap)
    np.testing.assert_allclose(trans[:, :, 0], ref_root, atol=1e-12)
    sign = np.sign(np.sum(rot * ref_rot, axis=-1, keepdims=True))
    np.testing.assert_allclose(rot * sign, ref_rot, atol=1e-10)
    np.testing.assert_allclose(trans[:, :, 1:], windows.trans[:, bm.N_PAST : bm.N_PAST + gap, 1:], atol=1e-12)


def test_metrics_known_answers():
    rng = np.random.default_rng(0)
    q = rng.normal(size=(4, 6, 3, 4))
    assert bm.l2q(q, q) == 0.0
    assert bm.l2q(-q, q) > 0.0  # no sign flip at scoring (LaFAN1's protocol)
    x = rng.normal(size=(4, 6, 3, 3))
    mean, std = np.zeros(9), np.full(9, 2.0)
    shifted = x + np.array([1.0, 0.0, 0.0])
    assert bm.l2p(shifted, x, mean, std) == pytest.approx(np.sqrt(3) / 2)
    seq = rng.normal(size=(2, 30, 5))
    assert bm.npss(seq, seq) == pytest.approx(0.0, abs=1e-12)
    assert bm.npss(seq, rng.normal(size=seq.shape) * 5) > 0


def test_evaluate_table_and_ordering(clips, windows):
    stats = bm.position_stats(clips)
    lib = MotionLibrary(clips, labels=[bm.action_label(c.name) for c in clips])
    methods = {
        "zero-velocity": bm.method_zero_velocity,
        "interpolation": bm.method_interpolation,
        "motionlab": bm.method_library(lib),
    }
    res = bm.evaluate(windows, methods, stats)
    table = bm.format_table(res)
    assert "L2P" in table and "motionlab" in table
    for gap in (15, 30):
        assert res[("interpolation", "L2P", gap)] < res[("zero-velocity", "L2P", gap)]
        assert res[("motionlab", "L2P", gap)] < res[("interpolation", "L2P", gap)]


def test_library_fill_meets_both_ends(clips, windows):
    lib = MotionLibrary(clips)
    a, b = bm.N_PAST - 1, bm.N_PAST + 15
    w = windows
    rot, trans, cost = lib.fill(
        w.local_rot[:, a - 1 : a + 1], w.trans[:, a - 1 : a + 1], w.local_rot[:, b], w.trans[:, b], 15
    )
    assert rot.shape == (len(w), 15, 7, 4) and trans.shape == (len(w), 15, 7, 3) and cost.shape == (len(w),)
    np.testing.assert_allclose(np.linalg.norm(rot, axis=-1), 1.0, atol=1e-9)
    with pytest.raises(ValueError, match="at least one frame"):
        lib.fill(w.local_rot[:, a - 1 : a + 1], w.trans[:, a - 1 : a + 1], w.local_rot[:, b], w.trans[:, b], 0)


def test_continuous_removes_sign_flips():
    q = np.tile(np.array([1.0, 0.0, 0.0, 0.0]), (5, 1, 1))
    q[2] *= -1
    q[3] *= -1
    out = bm.continuous(q, axis=0)
    assert np.all(out[..., 0] > 0)


def test_outputs_continue_the_context_sign_before_scoring(windows):
    """A method returning -q scores exactly like one returning q (made continuous with the last
    context frame before FK), while l2q itself flips nothing."""

    def negated(w, n_past, gap):
        rot, trans = bm.method_interpolation(w, n_past, gap)
        return -rot, trans

    stats = (np.zeros(7 * 3), np.ones(7 * 3))
    res = bm.evaluate(windows, {"interp": bm.method_interpolation, "neg": negated}, stats, gaps=(15, 45))
    for gap in (15, 45):
        assert res[("neg", "L2Q", gap)] == pytest.approx(res[("interp", "L2Q", gap)], abs=1e-12)
    last = windows.local_rot[:, bm.N_PAST - 1]
    out = bm.continue_from_context(-np.repeat(last[:, None], 3, axis=1), last)
    np.testing.assert_allclose(out, np.repeat(last[:, None], 3, axis=1))


def test_cost_limit_chosen_on_apart_windows(clips, windows):
    lib = MotionLibrary(clips, labels=[bm.action_label(c.name) for c in clips])
    stats = bm.position_stats(clips)
    limit = bm.choose_max_cost(windows, lib, stats, gaps=(15,), k=1)
    assert limit >= 0.0
    capped = bm.method_library(lib, k=1, max_cost=-1.0)  # nothing trusted: plain interpolation
    rot, trans = capped(windows, bm.N_PAST, 15)
    i_rot, i_trans = bm.method_interpolation(windows, bm.N_PAST, 15)
    np.testing.assert_allclose(rot, i_rot)
    np.testing.assert_allclose(trans, i_trans)


def test_fallback_and_limit_chosen_together_on_apart_windows(clips, windows):
    lib = MotionLibrary(clips, labels=[bm.action_label(c.name) for c in clips])
    stats = bm.position_stats(clips)
    simple = {"interp": bm.method_interpolation, "zero": bm.method_zero_velocity}
    name, limit, totals = bm.choose_fill(windows, lib, stats, simple, gaps=(15,), k=1)
    assert name == min(totals, key=totals.get) == "interp"  # standing still loses to interpolating
    assert limit == bm.choose_max_cost(windows, lib, stats, gaps=(15,), k=1)
    capped = bm.method_library(lib, k=1, max_cost=-1.0, fallback=bm.method_zero_velocity)
    rot, _ = capped(windows, bm.N_PAST, 15)
    np.testing.assert_allclose(rot, bm.method_zero_velocity(windows, bm.N_PAST, 15)[0])
    with pytest.raises(ValueError, match="at least one"):
        bm.choose_fill(windows, lib, stats, {}, gaps=(15,))
