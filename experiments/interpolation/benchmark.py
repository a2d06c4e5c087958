"""An in-betweening benchmark in the style of the LaFAN1 protocol (Harvey et al. 2020).

Protocol (as in the LaFAN1 evaluation code, restated):

* clips at 30 fps, cut into windows of 65 frames every 40 frames; each window is moved so the
  root's mean ground position over the window is the origin, and turned about +Y so that the root
  of the last context frame (frame 9) faces +Z; local quaternions are made sign-continuous in time;
* for a transition length ``N`` in {5, 15, 30, 45}: frames 0–9 are the context, frames 10 … 9+N
  are to be filled, frame 10+N is the target (only that one future frame is given);
* every method's output (local quaternions) is made sign-continuous with the last context frame
  (:func:`continuous` over ``[frame 9, outputs …]``) *before* FK, as LaFAN1's inputs are; nothing
  is flipped at scoring time — a method whose quaternions jump to the other hemisphere pays for
  it in L2Q and NPSS, exactly as in the official code;
* **L2Q**: mean over windows and filled frames of ``‖q̂ − q‖₂`` over all joints' *global*
  quaternions stacked (the truth: FK of the sign-continuous local quaternions);
* **L2P**: mean over windows and frames of ``‖(x̂ − μ)/σ − (x − μ)/σ‖₂`` over all joints' global
  positions stacked, with per-coordinate μ, σ of global positions. LaFAN1 takes them from its
  training subjects; here they come from a fixed set of clips of the *same skeleton* kept apart
  from the scored windows (``experiments/interpolation/bench_inbetween.py`` names both sets), one skeleton at a
  time (statistics mixing two rigs mean nothing for either);
* **NPSS** (Gopalakrishnan et al. 2019): per dimension of the stacked global quaternions, the
  earth mover's distance between the normalised power spectra (real FFT part squared, cumulative)
  of truth and prediction, averaged with the truth's total power as weights.

Any folder of BVH files can be evaluated; clips are reduced to the 22-joint humanoid
(:func:`motionlab.core.humanoid.to_canonical`) and resampled to 30 fps. These are *not* LaFAN1
numbers: LaFAN1 is not available here, so report the data the table was computed on.

Run ``experiments/interpolation/bench_inbetween.py``.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from motionlab.core import quat
from motionlab.core.fk import fk
from motionlab.core.motion import Motion
from motionlab.interpolation.demo import load_clips
from motionlab.interpolation.inbetween import interpolate, log, zero_velocity

__all__ = [
    "GAPS",
    "N_PAST",
    "Windows",
    "load_clips",
    "make_windows",
    "continuous",
    "continue_from_context",
    "position_stats",
    "l2q",
    "l2p",
    "npss",
    "method_zero_velocity",
    "method_interpolation",
    "method_hermite",
    "method_library",
    "choose_max_cost",
    "choose_fill",
    "action_label",
    "evaluate",
    "format_table",
]

GAPS = (5, 15, 30, 45)
N_PAST = 10


@dataclass
class Windows:
    """Benchmark windows of one skeleton.

    Attributes
    ----------
    local_rot : ndarray (W, T, J, 4)   sign-continuous local rotations
    trans : ndarray (W, T, J, 3)       local translations (root: world position), metres
    clip : ndarray (W,) of int         which clip each window was cut from
    start : ndarray (W,) of int        first frame of each window in its clip
    parents : ndarray (J,)
    names : list of str                clip names
    """

    local_rot: np.ndarray
    trans: np.ndarray
    clip: np.ndarray
    start: np.ndarray
    parents: np.ndarray
    names: list = field(default_factory=list)

    def __len__(self) -> int:
        return int(self.local_rot.shape[0])

    def fk(self) -> tuple[np.ndarray, np.ndarray]:
        return fk(self.local_rot, self.trans, self.parents)


def continuous(q: np.ndarray, axis: int = -3) -> np.ndarray:
    """Quaternions made sign-continuous along ``axis`` (time): each takes the sign closer to its
    predecessor. ``q`` has shape (..., T, J, 4) with time at ``axis``."""
    q = np.moveaxis(np.asarray(q, dtype=np.float64), axis, 0).copy()
    dots = np.sum(q[1:] * q[:-1], axis=-1, keepdims=True)
    flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
    q[1:] *= flips
    return np.moveaxis(q, 0, axis)


def make_windows(
    motions: Sequence[Motion], window: int = 65, offset: int = 40, n_past: int = N_PAST, center: bool = True
) -> Windows:
    """Cut clips into LaFAN1-style windows (see the module docstring).

    Windows start at 0, ``offset``, … while ``start + window < T``. All clips must share a skeleton.
    """
    if not motions:
        raise ValueError("no clips to cut into windows")
    sk = motions[0].skeleton
    rots, trans, clip, start = [], [], [], []
    for i, m in enumerate(motions):
        if m.skeleton.names != sk.names:
            raise ValueError(f"clip {m.name!r} has another skeleton than {motions[0].name!r}; evaluate them apart")
        t_all = m.translations()
        s = 0
        while s + window < m.num_frames:
            rots.append(m.local_rot[s : s + window])
            trans.append(t_all[s : s + window])
            clip.append(i)
            start.append(s)
            s += offset
    if not rots:
        raise ValueError(f"no clip is longer than one window ({window} frames)")
    rot = continuous(np.stack(rots), axis=1)
    tr = np.stack(trans).copy()
    if center:
        xz = tr[:, :, 0, [0, 2]].mean(axis=1)  # (W, 2)
        tr[:, :, 0, 0] -= xz[:, None, 0]
        tr[:, :, 0, 2] -= xz[:, None, 1]
        # face +Z at the last context frame: rotate root rotation and position about +Y
        yaw = quat.yaw(rot[:, n_past - 1, 0])
        turn = quat.from_yaw(-yaw)[:, None]  # (W, 1, 4)
        rot = rot.copy()
        rot[:, :, 0] = quat.mul(turn, rot[:, :, 0])
        tr[:, :, 0] = quat.rotate(turn, tr[:, :, 0])
        rot = continuous(rot, axis=1)
    return Windows(rot, tr, np.array(clip), np.array(start), sk.parents, [m.name for m in motions])


def position_stats(motions: Sequence[Motion]) -> tuple[np.ndarray, np.ndarray]:
    """Per-coordinate mean and std (J*3,) of global positions over windows of 50 frames every 20."""
    w = make_windows(motions, window=50, offset=20)
    _, pos = w.fk()
    flat = pos.reshape(-1, pos.shape[-2] * 3)
    return flat.mean(axis=0), np.maximum(flat.std(axis=0), 1e-8)


def l2q(pred_global_rot, true_global_rot) -> float:
    """Mean over windows and frames of ‖q̂ − q‖ over all joints (W, N, J, 4), as given: no sign is
    flipped here (make the prediction sign-continuous with its context first, see :func:`evaluate`)."""
    p, t = np.asarray(pred_global_rot), np.asarray(true_global_rot)
    return float(np.mean(np.sqrt(np.sum((p - t) ** 2, axis=(-2, -1)))))


def continue_from_context(rot, last_context) -> np.ndarray:
    """Local quaternions (W, N, J, 4) made sign-continuous in time starting from the last context
    frame (W, J, 4), which keeps its sign (LaFAN1's treatment of inputs, applied to outputs)."""
    seq = np.concatenate([np.asarray(last_context)[:, None], np.asarray(rot, dtype=np.float64)], axis=1)
    return continuous(seq, axis=1)[:, 1:]


def l2p(pred_global_pos, true_global_pos, mean, std) -> float:
    """Mean over windows and frames of the normalised position error (W, N, J, 3)."""
    p = np.asarray(pred_global_pos).reshape(pred_global_pos.shape[:-2] + (-1,))
    t = np.asarray(true_global_pos).reshape(true_global_pos.shape[:-2] + (-1,))
    return float(np.mean(np.sqrt(np.sum(((p - mean) / std - (t - mean) / std) ** 2, axis=-1))))


def npss(true_seq, pred_seq) -> float:
    """Normalised power spectrum similarity between (B, T, D) sequences (lower is better)."""
    t, p = np.asarray(true_seq, dtype=np.float64), np.asarray(pred_seq, dtype=np.float64)
    if t.shape != p.shape or t.ndim != 3:
        raise ValueError(f"expected two (B, T, D) arrays of equal shape, got {t.shape} and {p.shape}")
    pt = np.real(np.fft.fft(t, axis=1)) ** 2
    pp = np.real(np.fft.fft(p, axis=1)) ** 2
    tot_t, tot_p = pt.sum(axis=1), pp.sum(axis=1)
    cdf_t = np.cumsum(pt / np.where(tot_t > 0, tot_t, 1.0)[:, None], axis=1)
    cdf_p = np.cumsum(pp / np.where(tot_p > 0, tot_p, 1.0)[:, None], axis=1)
    emd = np.sum(np.abs(cdf_p - cdf_t), axis=1)  # (B, D)
    if tot_t.sum() <= 0:
        return float(emd.mean())
    return float(np.average(emd, weights=tot_t))


# ---------------------------------------------------------------------------- methods
# A method takes (windows, n_past, gap) and returns (rot (W, gap, J, 4), trans (W, gap, J, 3))
Method = Callable[[Windows, int, int], tuple[np.ndarray, np.ndarray]]


def _fill_trans(w: Windows, root: np.ndarray, n_past: int, gap: int) -> np.ndarray:
    trans = np.repeat(w.trans[:, n_past - 1 : n_past], gap, axis=1).copy()
    trans[:, :, 0] = root
    return trans


def method_zero_velocity(w: Windows, n_past: int, gap: int):
    """Repeat the last context frame."""
    rot, root = zero_velocity(w.local_rot[:, n_past - 1], w.trans[:, n_past - 1, 0], gap)
    return rot, _fill_trans(w, root, n_past, gap)


def method_interpolation(w: Windows, n_past: int, gap: int):
    """SLERP of local rotations + linear root (the LaFAN1 'Interp.' baseline)."""
    a, b = n_past - 1, n_past + gap
    rot, root = interpolate(w.local_rot[:, a], w.trans[:, a, 0], w.local_rot[:, b], w.trans[:, b, 0], gap)
    return rot, _fill_trans(w, root, n_past, gap)


def method_hermite(w: Windows, n_past: int, gap: int):
    """Quadratic root with the context's last velocity + SLERP rotations (a cheap improvement)."""
    a, b = n_past - 1, n_past + gap
    vel = w.trans[:, a, 0] - w.trans[:, a - 1, 0]
    rot, root = interpolate(
        w.local_rot[:, a], w.trans[:, a, 0], w.local_rot[:, b], w.trans[:, b, 0], gap, root="hermite", vel_a=vel
    )
    return rot, _fill_trans(w, root, n_past, gap)


def action_label(name: str) -> str:
    """The action of a clip from its file stem: ``"dataset-2_walk-turn-left_normal_001"`` →
    ``"walk-turn-left"`` (Bandai Namco naming); any other stem is its own action, lower-cased
    with a trailing take number removed (``"Running"`` → ``"running"``)."""
    m = re.match(r"dataset-\d+_([^_]+)_", name)
    if m:
        return m.group(1)
    return re.sub(r"[_-]?\d+$", "", name).lower()


def method_library(
    library,
    k: int = 1,
    leave_one_out: bool = True,
    same_action: bool = True,
    max_cost: float | None = None,
    fallback: Method | None = None,
) -> Method:
    """motionlab's key-pose-guided filling (:class:`~.library.MotionLibrary`) as a benchmark method.

    With ``leave_one_out`` the library clip with the window's own clip name is never used. With
    ``same_action`` a gap is filled only from recordings of its own action node (the library's
    labels against :func:`action_label` of the window's clip). A gap whose best stretch costs more
    than ``max_cost`` (no recording matches its ends well; see :func:`choose_max_cost`), or whose
    node holds no other recording, falls back to ``fallback`` — plain interpolation by default,
    which is what the paper does inside a node (:func:`choose_fill` picks it on apart windows).
    """
    fallback = method_interpolation if fallback is None else fallback

    def run(w: Windows, n_past: int, gap: int):
        rot, trans, cost = _library_fill(library, w, n_past, gap, k, leave_one_out, same_action)
        none = ~np.isfinite(cost) if max_cost is None else ~(cost <= max_cost)
        if np.any(none):
            i_rot, i_trans = fallback(w, n_past, gap)
            rot[none], trans[none] = i_rot[none], i_trans[none]
        return rot, trans

    return run


def _library_fill(library, w: Windows, n_past: int, gap: int, k: int, leave_one_out: bool, same_action: bool):
    a, b = n_past - 1, n_past + gap
    exclude = None
    if leave_one_out:
        index = {name: i for i, name in enumerate(library.names)}
        exclude = np.array([index.get(w.names[c], -1) for c in w.clip])
    labels = [action_label(w.names[c]) for c in w.clip] if same_action else None
    return library.fill(
        w.local_rot[:, a - 1 : a + 1], w.trans[:, a - 1 : a + 1], w.local_rot[:, b], w.trans[:, b], gap,
        k=k, exclude_clip=exclude, query_labels=labels,
    )  # fmt: skip


def _window_l2p(w: Windows, rot, trans, n_past: int, gap: int, stats) -> np.ndarray:
    """L2P of each window (W,) (the mean over its filled frames)."""
    mean, std = stats
    sl = slice(n_past, n_past + gap)
    _, true_pos = fk(w.local_rot[:, sl], w.trans[:, sl], w.parents)
    _, pos = fk(rot, trans, w.parents)
    d = (pos - true_pos).reshape(pos.shape[:2] + (-1,)) / std
    return np.sqrt(np.sum(d * d, axis=-1)).mean(axis=1)


def _limit_and_total(windows: Windows, library, stats, gaps, k, same_action, n_past, fallback: Method):
    """The cost limit minimising the summed L2P of ``windows`` when gaps above it use ``fallback``,
    and that sum."""
    costs, lib_err, fb_err = [], [], []
    for gap in gaps:
        rot, trans, cost = _library_fill(library, windows, n_past, gap, k, True, same_action)
        f_rot, f_trans = fallback(windows, n_past, gap)
        ok = np.isfinite(cost)
        rot[~ok], trans[~ok] = f_rot[~ok], f_trans[~ok]
        costs.append(np.where(ok, cost, np.inf))
        lib_err.append(_window_l2p(windows, rot, trans, n_past, gap, stats))
        fb_err.append(_window_l2p(windows, f_rot, f_trans, n_past, gap, stats))
    c, lib, fb = np.concatenate(costs), np.concatenate(lib_err), np.concatenate(fb_err)
    candidates = np.concatenate([[-np.inf], np.unique(c[np.isfinite(c)]), [np.inf]])
    total = np.array([np.sum(np.where(c <= t, lib, fb)) for t in candidates])
    i = int(np.argmin(total))
    return max(float(candidates[i]), 0.0), float(total[i])


def choose_max_cost(
    windows: Windows,
    library,
    stats,
    gaps: Sequence[int] = (15, 30),
    k: int = 1,
    same_action: bool = True,
    n_past: int = N_PAST,
    fallback: Method | None = None,
) -> float:
    """The matching cost above which the library fill is not trusted, chosen on ``windows`` that
    must be kept apart from any scored window (leave-one-clip-out fills).

    Every window's best-stretch cost and its L2P with the library fill and with ``fallback``
    (plain interpolation by default) are computed at each gap; the threshold is the one (among
    the observed costs, and ``inf``) that minimises the summed L2P when windows above it use the
    fallback instead.
    """
    fallback = method_interpolation if fallback is None else fallback
    return _limit_and_total(windows, library, stats, gaps, k, same_action, n_past, fallback)[0]


def choose_fill(
    windows: Windows,
    library,
    stats,
    fallbacks: dict[str, Method],
    gaps: Sequence[int] = (15, 30),
    k: int = 1,
    same_action: bool = True,
    n_past: int = N_PAST,
) -> tuple[str, float, dict[str, float]]:
    """The fallback (a name of ``fallbacks``) and cost limit of :func:`method_library` that together
    give the lowest summed L2P on ``windows`` (kept apart from any scored window), and each
    fallback's summed L2P there (with its own best limit)."""
    if not fallbacks:
        raise ValueError("choose_fill needs at least one fallback method")
    scores = {name: _limit_and_total(windows, library, stats, gaps, k, same_action, n_past, f)
              for name, f in fallbacks.items()}  # fmt: skip
    best = min(scores, key=lambda name: scores[name][1])
    return best, scores[best][0], {name: total for name, (_, total) in scores.items()}


def evaluate(
    windows: Windows,
    methods: dict[str, Method],
    stats: tuple[np.ndarray, np.ndarray],
    gaps: Sequence[int] = GAPS,
    n_past: int = N_PAST,
) -> dict[tuple[str, str, int], float]:
    """``{(method, metric, gap): value}`` for metrics ``"L2Q"``, ``"L2P"``, ``"NPSS"``."""
    mean, std = stats
    T = windows.local_rot.shape[1]
    res = {}
    for gap in gaps:
        if n_past + gap + 1 > T:
            raise ValueError(f"windows of {T} frames cannot hold {n_past} context + {gap} gap + 1 target frames")
        sl = slice(n_past, n_past + gap)
        true_rot, true_pos = fk(windows.local_rot[:, sl], windows.trans[:, sl], windows.parents)
        for name, method in methods.items():
            rot, trans = method(windows, n_past, gap)
            rot = continue_from_context(rot, windows.local_rot[:, n_past - 1])
            g_rot, g_pos = fk(rot, trans, windows.parents)
            res[(name, "L2Q", gap)] = l2q(g_rot, true_rot)
            res[(name, "L2P", gap)] = l2p(g_pos, true_pos, mean, std)
            flat = lambda x: x.reshape(x.shape[0], x.shape[1], -1)  # noqa: E731
            res[(name, "NPSS", gap)] = npss(flat(true_rot), flat(g_rot))
    return res


def format_table(res: dict, gaps: Sequence[int] = GAPS) -> str:
    """The LaFAN1-style table: one block per metric, one row per method, one column per gap."""
    methods = list(dict.fromkeys(k[0] for k in res))
    lines = []
    for metric, fmt in (("L2Q", "{:7.3f}"), ("L2P", "{:7.3f}"), ("NPSS", "{:7.4f}")):
        lines.append(f"=== {metric} ===")
        lines.append(f"{'gap (frames)':<32}" + "".join(f"{g:>8d}" for g in gaps))
        for m in methods:
            lines.append(f"{m:<32}" + "".join(" " + fmt.format(res[(m, metric, g)]) for g in gaps))
        lines.append("")
    return "\n".join(lines)


def angular_velocity(local_rot: np.ndarray) -> np.ndarray:
    """Per-frame rotation vectors ``log(q[t-1]⁻¹ q[t])`` (..., T-1, J, 3) (helper for methods)."""
    return log(quat.mul(quat.conj(local_rot[..., :-1, :, :]), local_rot[..., 1:, :, :]))
