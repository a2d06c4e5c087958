"""Finding dropped frames in a motion stream, and how many went missing (paper C, §3.3).

A BVH file with a constant frame time cannot say that frames are missing; the motion has to. The
measure is :func:`joint_steps`: the root-mean-square over joints of every joint's *world*
displacement between stream frames ``t`` and ``t+1``, metres per step.

**Stream against the graph** (:func:`track`, :func:`graph_gaps`; the paper's rule). Each stream
frame ``M_c`` is tracked to a graph frame ``M_i`` by matching the :data:`TRACK_CONTEXT` seconds of
stream beside it, time-warped by the tempi :data:`TRACK_RATES`, and

.. math::  r(t) = \\frac{s(t)}{\\rho(t)\\,\\bar s_{\\text{graph}}(i(t))}, \\qquad
           D(M_c, M_i) = \\frac{r(t)}{\\operatorname{median}_{\\text{around } t}\\, r}

with ``s(t)`` the stream's joint step into frame ``t``, ``ρ`` the matched tempo and
``s̄_graph(i)`` the graph clip's joint step at the matched frame (mean over ``i−2 … i+2``, never
below :data:`STEP_FLOOR`). The typical value around ``t`` is the larger of the medians of
:data:`WINDOW` values on each side and of the two adjacent values, so only an isolated jump counts;
an adjacent value that is itself more than Δ times its own side medians is left out (two gaps one
frame apart would each hide the other).
With nothing missing ``D ≈ 1``; with ``n`` frames missing ``D ≈ n+1``. ``D > Δ`` flags a gap
(:data:`DELTA` = 2.5: one missing frame gives ``D ≈ 2`` and is not flagged).

**Stream against itself** (:func:`consecutive_gaps`, no graph; what ``motionlab fill-gaps`` uses
without ``--action``): ``D = s(t) / max(median before, median after, s(t−1), s(t+1)) > Δ``, and
steps below :data:`STEP_FLOOR` are never flagged.

**How many frames** (:func:`estimate_missing`): from the ground distance the reference joint
covers across the gap against the motion on both sides (step cycle, mean speed, step phase, or
the speeds at the gap's edges, chosen per gap by :func:`count_choice`), and optionally the time
other recordings of the action need between the poses that bound it (:mod:`.recorded`).
Timestamps, where the input has them, give the count exactly (:func:`~.gaps.timestamp_gaps`);
without them each count is an estimate, given with the range it is likely in
(:func:`estimate_counts`), which ``motionlab fill-gaps`` states.

How these rules do on the shared data: ``docs/results_interpolation.md`` (``python -m
experiments.interpolation.check_gaps``). Taught in ``notebooks/06_keypose_interpolation.ipynb``;
``motionlab fill-gaps`` uses it.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from motionlab.core.motion import Motion
from motionlab.interpolation.alignment import reference_joint
from motionlab.interpolation.features import heading_frame
from motionlab.interpolation.recorded import body_features, recorded_missing

__all__ = [
    "DELTA",
    "STEP_FLOOR",
    "WINDOW",
    "TRANSIENT",
    "changes_speed",
    "HELD",
    "held_steps",
    "TRACK_CONTEXT",
    "TRACK_RATES",
    "track_features",
    "check_delta",
    "HEIGHT_FRAMES",
    "body_height",
    "joint_steps",
    "consecutive_ratio",
    "consecutive_gaps",
    "GraphTrack",
    "track",
    "graph_gaps",
    "LOCAL_SECONDS",
    "REHEARSAL_SECONDS",
    "SIGNIFICANCE",
    "COUNT_TOLERANCE",
    "SIZES_SECONDS",
    "SIZES",
    "SIZE_PLACES",
    "CountChoice",
    "count_choice",
    "MissingCount",
    "estimate_counts",
    "estimate_missing",
    "detect_counts",
    "detect",
]

DELTA = 2.5
"""Default Δ: a step 2.5× the typical step is a gap (one missing frame gives about 2×)."""

STEP_FLOOR = 0.05
"""Steps slower than this fraction of the body height per second are never flagged."""

WINDOW = 8
"""Steps on each side whose median is the typical step (:func:`consecutive_gaps`)."""

LOCAL_SECONDS = 0.1
"""Seconds of ground speeds on each side of a gap that the local count fits (:func:`_local_count`)."""

REHEARSAL_SECONDS = 2.0
"""How far from a gap, on each side, the two counts are rehearsed (:func:`count_choice`)."""

SIGNIFICANCE = 0.05
"""The local count replaces the stride count only where it wins the rehearsal by a one-sided sign
test at this level (the cuts that one count gets right and the other wrong; the usual 5%)."""

HELD = 1e-6
"""A step that moves no joint by more than this fraction of the body height (RMS) repeats its
frame exactly: a held pose, as in Mixamo clips padded to 60 frames with copies of their last
pose (:func:`held_steps`; :func:`.demo.trim_frozen` trims such a tail off the action clips).
Held frames carry no speed and no timing, so the counts read nothing from them
(:func:`count_choice`)."""

COUNT_TOLERANCE = 0.1
"""A count is right within this fraction of the true count, or one frame, whichever is more: what
the rehearsal scores (:func:`count_choice`), and the least a count's range spans on each side
(:class:`MissingCount`)."""

SIZES_SECONDS = 1.0
"""The longest gap, in seconds, that a count's range tries as the true size (or three times the
count, if longer; :func:`_plausible_range`): as far as the counts read the motion on each side."""

SIZES = 10
"""How many gap sizes, spaced geometrically from one frame, a count's range tries (:func:`_plausible_range`)."""

SIZE_PLACES = 8
"""Places on each side of a gap at which each tried size is cut out (:func:`_plausible_range`)."""

TRANSIENT = 0.2
"""Relative difference of the mean ground speeds on the two sides of a gap above which the body is
taken to be speeding up or slowing down, and the count comes from the step phase
(:func:`estimate_missing`, :func:`changes_speed`)."""


def changes_speed(v_before: float, v_after: float) -> bool:
    """Whether a body whose mean ground speeds are ``v_before`` and ``v_after`` on the two sides of
    a gap is speeding up or slowing down across it: they differ by more than ``TRANSIENT`` of their
    mean. The one rule for both the missing count (:func:`estimate_missing`) and the root across a
    stride fill (:func:`.gaps.fill`)."""
    return abs(v_before - v_after) > TRANSIENT * 0.5 * (v_before + v_after)


def check_delta(delta, name: str = "delta") -> float:
    """Δ as a float, or a ``ValueError`` naming ``name`` unless it is a finite number above 1.

    Δ compares a step with the typical step; Δ <= 1 would flag ordinary motion as dropped frames.

    Raises
    ------
    ValueError naming ``name`` unless Δ is a finite number above 1.
    """
    try:
        value = float(delta)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number above 1 (a multiple of the typical step), got {delta!r}") from None
    if not np.isfinite(value) or value <= 1.0:
        raise ValueError(f"{name} must be a finite number above 1 (a multiple of the typical step), got {delta!r}")
    return value


HEIGHT_FRAMES = 101
"""Frames, evenly spaced over the clip, that :func:`body_height` measures the body in."""


def body_height(motion: Motion) -> float:
    """The body's height in the clip (metres, at least 1 cm).

    Measured on the body alone: the reference joint (:func:`~.alignment.reference_joint`, the joint
    that carries the character) and the joints below it; not the end sites, which some exporters
    place well off the body (a hat's or hair's tip). A marker above the reference joint, such as a
    root joint left on the floor at the origin while the hips carry the walker, is not part of the
    body, so where the walker is in the capture volume does not change the height. In each of :data:`HEIGHT_FRAMES` frames evenly
    spaced over the clip, the body's highest point minus its lowest (Y up), or half its largest
    extent along any axis where that is more (a body lying down); the median over those frames.

    Parameters
    ----------
    motion : Motion with at least one frame

    Returns
    -------
    float, metres: for a body that stands or walks, the height from its lowest joint (a toe) to its
    highest (the head top where the rig has a joint there, else the head joint).
    """
    frames = np.unique(np.linspace(0, motion.num_frames - 1, HEIGHT_FRAMES).round().astype(np.int64))
    body = motion.skeleton.subtree(reference_joint(motion))  # (J,) mask
    extent = np.ptp(motion[frames].global_positions()[:, body], axis=1)  # (F, 3)
    per_frame = np.maximum(extent[:, 1], 0.5 * extent.max(axis=1))
    return max(float(np.median(per_frame)), 0.01)


def _positions(motion: Motion) -> np.ndarray:
    return motion.global_positions()  # (T, J, 3)


def _rms_steps(positions: np.ndarray) -> np.ndarray:
    """RMS over joints of each step's displacement, (T, J, 3) → (T-1,)."""
    return np.sqrt(np.mean(np.sum(np.diff(positions, axis=0) ** 2, axis=-1), axis=-1))


def joint_steps(motion: Motion) -> np.ndarray:
    """RMS over joints of each joint's world displacement from frame ``t`` to ``t+1``.

    Returns
    -------
    ndarray, shape (T-1,), metres per stream step
    """
    return _rms_steps(_positions(motion))


def held_steps(motion: Motion) -> np.ndarray:
    """Which steps ``t → t+1`` repeat their frame (``HELD``): (T-1,) bool."""
    return joint_steps(motion) <= HELD * body_height(motion)


def _side_medians(steps: np.ndarray, window: int) -> tuple[np.ndarray, np.ndarray]:
    """Median of the ``window`` steps before and after each step (NaN where there are none)."""
    n = len(steps)
    pad = np.concatenate([np.full(window, np.nan), steps, np.full(window, np.nan)])
    idx = np.arange(n)[:, None] + np.arange(window)[None, :]
    with warnings.catch_warnings():  # an all-NaN window (clip edge) has no median: NaN is the answer
        warnings.simplefilter("ignore", RuntimeWarning)
        before = np.nanmedian(pad[idx], axis=1)
        after = np.nanmedian(pad[idx + window + 1], axis=1)
    return before, after


def _typical(values: np.ndarray, window: int, delta: float, floor: float = 0.0) -> np.ndarray:
    """The typical value around each of ``values`` (T,): the larger of the medians of ``window``
    values on each side and of the two adjacent values, where an adjacent value counts only when
    it is not itself more than ``delta`` times the larger of its own side medians and ``floor``
    (two gaps one frame apart: each would vouch for the other). NaN where nothing is known."""
    before, after = _side_medians(values, window)
    side = np.fmax(np.fmax(before, after), floor)
    pad = np.array([np.nan])
    near = []
    for v, s in ((values[:-1], side[:-1]), (values[1:], side[1:])):
        near.append(np.where(v > delta * s, np.nan, v))
    prev, nxt = np.concatenate([pad, near[0]]), np.concatenate([near[1], pad])
    return np.fmax(np.fmax(before, after), np.fmax(prev, nxt))


def consecutive_ratio(motion: Motion, window: int = WINDOW, delta: float = DELTA) -> tuple[np.ndarray, np.ndarray]:
    """``D(t) = s(t) / max(median before, median after, s(t−1), s(t+1))`` for every step, a
    neighbouring step left out where it is itself a jump by ``delta`` (:func:`_typical`), and the
    steps ``s``.

    Returns
    -------
    ratio : ndarray (T-1,)   dimensionless (0 where the step is below the floor)
    steps : ndarray (T-1,)   metres per stream step (:func:`joint_steps`)
    """
    steps = joint_steps(motion)
    floor = STEP_FLOOR * body_height(motion) / motion.fps
    typical = _typical(steps, int(window), delta, floor)
    typical = np.where(np.isfinite(typical), np.maximum(typical, floor), np.inf)
    ratio = np.where(steps > floor, steps / typical, 0.0)
    return ratio, steps


def consecutive_gaps(motion: Motion, delta: float = DELTA, window: int = WINDOW) -> list[int]:
    """Stream steps ``t → t+1`` (indices ``t``) where frames were dropped, judged against the stream
    itself: ``D(t) > Δ`` (see the module docstring)."""
    delta = check_delta(delta)
    if motion.num_frames < 3:
        return []
    ratio, _ = consecutive_ratio(motion, window, delta)
    return [int(t) for t in np.flatnonzero(ratio > delta)]


# ---------------------------------------------------------------------------- against the graph
@dataclass
class GraphTrack:
    """The stream tracked in an action graph (:func:`track`).

    Attributes
    ----------
    node : list of str          action node of each stream frame (T,)
    frame : ndarray (T,)        frame of that node's clip it is matched to
    distance : ndarray (T,)     ``D(M_c, M_i)`` of each frame (frame 0: 0), dimensionless
    delta : float               Δ used
    """

    node: list
    frame: np.ndarray
    distance: np.ndarray
    delta: float

    def gaps(self) -> list[int]:
        """Steps ``t → t+1`` with ``D > Δ`` at frame ``t+1``."""
        return [int(t) - 1 for t in np.flatnonzero(self.distance > self.delta)]


TRACK_RATES = np.geomspace(0.5, 2.0, 13)
"""Tempi ``ρ`` (graph seconds per stream second, 12% apart) at which a stream window is matched in
the graph (:func:`track`): from a walker twice as slow as the recordings to one twice as fast."""

TRACK_CONTEXT = 0.4
"""Seconds of stream frames in one matched window (:func:`track`; 12 frames at 30 fps, the
context of :data:`.recorded.CONTEXT`)."""


def _resampled(x: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``x`` (N, D) linearly interpolated at times ``0, step, 2·step, …`` (in rows), and
    those times."""
    times = np.arange(int(np.floor((len(x) - 1) / step + 1e-9)) + 1) * step
    i0 = np.minimum(np.floor(times).astype(np.int64), len(x) - 1)
    i1 = np.minimum(i0 + 1, len(x) - 1)
    w = (times - i0)[:, None]
    return (1.0 - w) * x[i0] + w * x[i1], times


def _window_costs(q: np.ndarray, g: np.ndarray, k: int, block: int = 512) -> tuple[np.ndarray, np.ndarray]:
    """For every window of ``k`` stream rows ``q[t : t+k]`` (D-dimensional), the lowest mean squared
    distance to a window of ``k`` consecutive rows of ``g`` and where that window starts.

    Returns
    -------
    cost : ndarray (T-k+1,)   mean over the window of the squared distance per row
    start : ndarray (T-k+1,)  first row of the best window of ``g`` (int)
    """
    nq, ng = len(q) - k + 1, len(g) - k + 1
    cost, start = np.full(nq, np.inf), np.zeros(nq, dtype=np.int64)
    if nq < 1 or ng < 1:
        return cost, start
    gg = np.sum(g * g, axis=1)
    for a in range(0, nq, block):  # blocks of stream windows bound the memory, not a loop over frames
        b = min(nq, a + block)
        rows = q[a : b + k - 1]
        d = np.maximum(np.sum(rows * rows, axis=1)[:, None] + gg[None, :] - 2.0 * rows @ g.T, 0.0)
        w = sum(d[i : i + b - a, i : i + ng] for i in range(k))  # the K diagonals of each window
        start[a:b] = np.argmin(w, axis=1)
        cost[a:b] = w[np.arange(b - a), start[a:b]] / k
    return cost, start


@dataclass
class _Match:
    """Best graph match of each stream window (see :func:`_match_windows`)."""

    cost: np.ndarray  # (W,) mean squared distance per frame
    node: np.ndarray  # (W,) node index
    time: np.ndarray  # (W,) graph frame (float) matched to the window's first stream frame
    rate: np.ndarray  # (W,) graph frames per stream frame


def _match_windows(q: np.ndarray, clips: list, k: int, fps: float, rates: np.ndarray) -> _Match:
    """Every window of ``k`` stream frames ``q`` (T, J, 6: positions, weighted velocities) matched to
    the graph clips ``clips`` (pairs of features (N, J, 6) and frame rate) at every tempo ``ρ`` of
    ``rates``, time-warped linearly (the graph's velocities scaled by ``ρ``)."""
    n = len(q) - k + 1
    best = _Match(np.full(n, np.inf), np.zeros(n, np.int64), np.zeros(n), np.ones(n))
    q = q.reshape(len(q), -1)
    for c, (feat, clip_fps) in enumerate(clips):
        for rho in rates:
            step = rho * clip_fps / fps  # graph frames per stream frame
            g, times = _resampled((feat * np.array([1.0, 1.0, 1.0, rho, rho, rho])).reshape(len(feat), -1), step)
            cost, start = _window_costs(q, g, k)
            better = cost < best.cost
            best.cost[better], best.node[better] = cost[better], c
            best.time[better], best.rate[better] = times[start[better]], step
    return best


def track_features(motion: Motion, ref: int, difference: str = "central") -> np.ndarray:
    """What :func:`track` compares frames by, per frame and body joint (the reference joint ``ref``
    and the joints below it): heading-frame position and weighted heading-frame velocity
    (:func:`.recorded.body_features`, velocities by ``difference``: ``"central"``, ``"backward"``
    or ``"forward"``). The velocity carries the travel speed, so a stream that walks is never
    matched to a graph clip standing still.

    Returns
    -------
    ndarray, shape (T, J', 6): positions (metres) in ``[..., :3]``, velocities in ``[..., 3:]``
    """
    feat, _ = body_features(motion, ref=ref, difference=difference)
    return feat.reshape(len(feat), -1, 6)


def track(
    motion: Motion,
    graph,
    delta: float | None = None,
    *,
    features: Callable[[Motion, int, str], np.ndarray] = track_features,
    context: float | None = None,
    rates=None,
) -> GraphTrack:
    """Track every stream frame in the graph and compute ``D(M_c, M_i)`` (module docstring).

    **The match.** A single frame's pose is a poor clue to where a walker is in the gait cycle
    when the walker differs from the recordings: matched by pose alone, the shuffling steps of an
    elderly walker land on graph frames where the recorded walker stands still or moves slower,
    and the stream's ordinary step then looks like a jump. So *windows* are matched: the ``K``
    stream frames (``context`` seconds) ending at frame ``t`` and the ``K`` starting at
    ``t+1`` are each compared with every run of graph frames, time-warped by every tempo ``ρ`` of
    ``rates`` (the graph's velocities scaled by ``ρ``). Frames are compared by ``features``; by
    default the body alone, heading-frame positions and weighted velocities of the reference joint
    and the joints below it (:func:`track_features`), so where the take was recorded in the capture
    volume does not matter; the velocities are one-sided (backward in a window ending at ``t``,
    forward in one starting at ``t+1``), so no window differences across the step it judges. Of
    the two windows beside the step ``t → t+1`` the one matched better is kept: near a gap, the
    window that spans it matches badly.

    **The distance.** The graph then predicts the stream's step at that point: the graph clip's
    joint step at the matched frame (mean over five frames), times ``ρ``. ``r(t)`` is the stream's
    step over that prediction, and ``D = r / (typical r around t)`` as in the module docstring.

    The work grows as stream frames × graph frames × the tempi (matrix products, in blocks of
    512 stream windows, so memory stays bounded).

    Raises ``ValueError`` for an empty graph, a stream on another skeleton, a Δ that
    :func:`check_delta` refuses, a ``context`` or ``rates`` outside what is stated below, or
    ``features`` that do not give (T, J', 6) arrays.

    Parameters
    ----------
    motion : Motion on the graph's skeleton, at any frame rate
    graph : :class:`~.action_graph.ActionGraph`
    delta : Δ; default :data:`DELTA`
    features : keyword-only; ``features(motion, ref, difference)`` gives what frames are compared
        by, an array (T, J', 6), per frame and joint positions in ``[..., :3]`` and velocities in
        ``[..., 3:]`` (scaled by ``ρ`` on the graph's side), ``ref`` being the reference joint
        (:func:`~.alignment.reference_joint`) and ``difference`` ``"backward"``, ``"forward"``
        (stream windows) or ``"central"`` (graph clips). Default :func:`track_features`.
    context : keyword-only; seconds of stream in one matched window, finite and >= 0; default
        :data:`TRACK_CONTEXT`. A window holds ``round(context · fps)`` frames, at least one and at
        most half the stream, so ``0`` matches single frames.
    rates : keyword-only; the tempi ``ρ`` (graph seconds per stream second), a non-empty 1-D
        array of positive finite numbers; default :data:`TRACK_RATES`. ``[1.0]`` matches
        without time warping.
    """
    if not graph.nodes:
        raise ValueError("the action graph has no actions to track the stream in")
    sk = next(iter(graph.nodes.values())).motion.skeleton
    if sk.names != motion.skeleton.names:
        raise ValueError("the stream uses another skeleton than the action graph's clips")
    delta = check_delta(DELTA if delta is None else delta)
    context, rates = _check_tracking(features, context, rates)
    names = list(graph.nodes)
    T = motion.num_frames
    if T < 4:
        return GraphTrack([names[0]] * T, np.zeros(T, np.int64), np.zeros(T), delta)
    k = max(1, min(int(round(context * motion.fps)), T // 2))
    ref = reference_joint(motion)
    clips, speeds = _graph_clips(graph, ref, features)
    # windows ending at a frame take backward velocities, windows starting at one forward velocities
    ending = _match_windows(_features(features, motion, ref, "backward"), clips, k, motion.fps, rates)
    starting = _match_windows(_features(features, motion, ref, "forward"), clips, k, motion.fps, rates)
    use_back, node, rate, at = _step_matches(ending, starting, k, T)
    first = np.cumsum([0] + [len(x) for x in speeds])[:-1]  # each node's first row in the joined speeds
    joined = np.concatenate(speeds)
    predicted = np.interp(first[node] + at, np.arange(len(joined)), joined) * rate  # metres per stream step
    dist = _distances(motion, predicted, delta)
    frame_of = np.concatenate([[starting.time[0]], at + np.where(use_back, rate, 0.0)])
    node_of = np.concatenate([[starting.node[0]], node])
    return GraphTrack([names[c] for c in node_of], np.rint(frame_of).astype(np.int64), dist, delta)


def _check_tracking(features, context, rates) -> tuple[float, np.ndarray]:
    """The ``context`` (seconds) and ``rates`` (R,) that :func:`track` matches with, defaults
    filled in, or its ``ValueError``."""
    if not callable(features):
        raise ValueError(f"features must be a function (motion, ref, difference) -> (T, J, 6), got {features!r}")
    context = TRACK_CONTEXT if context is None else context
    try:
        context = float(context)
    except (TypeError, ValueError):
        raise ValueError(f"context must be a number of seconds >= 0, got {context!r}") from None
    if not np.isfinite(context) or context < 0:
        raise ValueError(f"context must be a finite number of seconds >= 0, got {context!r}")
    rates = np.asarray(TRACK_RATES if rates is None else rates, dtype=np.float64)
    if rates.ndim != 1 or rates.size == 0 or not np.all(np.isfinite(rates) & (rates > 0)):
        raise ValueError(f"rates must be a non-empty 1-D array of positive tempi, got {rates!r}")
    return context, rates


def _features(features, motion: Motion, ref: int, difference: str) -> np.ndarray:
    """``features(motion, ref, difference)``, checked to be (T, J', 6)."""
    feat = np.asarray(features(motion, ref, difference))
    if feat.ndim != 3 or len(feat) != motion.num_frames or feat.shape[-1] != 6:
        raise ValueError(f"features must give ({motion.num_frames}, J, 6) arrays, got shape {feat.shape}")
    return feat


def _graph_clips(graph, ref: int, features) -> tuple[list, list]:
    """Per graph node: ``(features (N, J', 6), fps)`` of its clip and its joint step per frame
    (N,), metres, smoothed over five frames (what :func:`track` predicts the stream's step from)."""
    clips, speeds = [], []
    for node in graph.nodes.values():
        m = node.motion
        s = joint_steps(m)  # metres per graph frame, step into frame i+1
        s = np.concatenate([s[:1], 0.5 * (s[1:] + s[:-1]), s[-1:]]) if len(s) > 1 else np.repeat(s, 2)
        speeds.append(np.convolve(np.pad(s, 2, mode="edge"), np.ones(5) / 5.0, mode="valid"))
        clips.append((_features(features, m, ref, "central"), m.fps))
    return clips, speeds


def _step_matches(ending: _Match, starting: _Match, k: int, T: int):
    """For each step ``t → t+1`` (``t = 0 … T-2``) of a ``T``-frame stream, the better matched of
    the window of ``k`` frames ending at ``t`` (``ending``, index ``t-k+1``) and the one starting at
    ``t+1`` (``starting``). Returns ``use_back`` (T-1,) bool, True where the window ending at ``t``
    won; its ``node`` (T-1,) and ``rate`` (T-1,), graph frames per stream frame; and ``at`` (T-1,),
    the graph frame matched to ``t`` (window ending there) or to ``t+1`` (window starting there)."""
    steps_at = np.arange(T - 1)
    back = np.clip(steps_at - k + 1, 0, None)
    ahead = np.clip(steps_at + 1, None, T - k)
    cb = np.where(steps_at - k + 1 >= 0, ending.cost[back], np.inf)
    ca = np.where(steps_at + 1 <= T - k, starting.cost[ahead], np.inf)
    use_back = cb <= ca
    node = np.where(use_back, ending.node[back], starting.node[ahead])
    rate = np.where(use_back, ending.rate[back], starting.rate[ahead])
    at = np.where(use_back, ending.time[back] + (k - 1) * ending.rate[back], starting.time[ahead])
    return use_back, node, rate, at


def _distances(motion: Motion, predicted: np.ndarray, delta: float) -> np.ndarray:
    """``D`` (T,) of every stream frame (frame 0: 0) from the predicted steps (T-1,), metres per
    stream step: ``r = s / prediction`` over the typical ``r`` around each step (module
    docstring, :func:`_typical` with ``delta``), 0 where the stream's step is below
    :data:`STEP_FLOOR`."""
    floor = STEP_FLOOR * body_height(motion) / motion.fps
    s = joint_steps(motion)
    r = s / np.maximum(predicted, floor)
    typical = _typical(r, WINDOW, delta)
    typical = np.where(np.isfinite(typical) & (typical > 0), typical, np.inf)
    return np.concatenate([[0.0], np.where(s > floor, r / typical, 0.0)])


def graph_gaps(
    motion: Motion,
    graph,
    delta: float | None = None,
    *,
    features: Callable[[Motion, int, str], np.ndarray] = track_features,
    context: float | None = None,
    rates=None,
) -> list[int]:
    """Steps ``t → t+1`` where frames were dropped, the stream tracked in ``graph`` (§3.3):
    :meth:`GraphTrack.gaps` of :func:`track`, which takes ``delta`` and the keyword-only
    ``features``, ``context`` and ``rates`` (and raises) as documented there."""
    return track(motion, graph, delta, features=features, context=context, rates=rates).gaps()


# ---------------------------------------------------------------------------- how many
def _turn(ground: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Change of travel direction (radians) between the ground displacements over ``lo`` and ``hi``
    (index arrays of steps, each ``a → a+1``)."""
    da = ground[lo[-1] + 1] - ground[lo[0]] if lo.size else np.zeros(3)
    db = ground[hi[-1] + 1] - ground[hi[0]] if hi.size else np.zeros(3)
    if np.linalg.norm(da) < 1e-9 or np.linalg.norm(db) < 1e-9:
        return 0.0
    return float(abs(np.angle(np.exp(1j * (np.arctan2(db[0], db[2]) - np.arctan2(da[0], da[2]))))))


def _step_period(speed: np.ndarray, lo: int, hi: int) -> tuple[int | None, float]:
    """The lag in ``lo … hi`` frames at which the speed signal (N,) best correlates with itself,
    and that normalised autocorrelation (``None, -1`` when the signal is too short).

    Only lags up to half the signal are tried, so that a period is claimed only where the signal
    holds two of it (at a longer lag the correlation rests on a few pairs of frames).
    """
    if len(speed) < 2 * lo:  # not two of even the shortest period (an empty side, say)
        return None, -1.0
    x = speed - speed.mean()
    best, lag_best = -1.0, None
    for lag in range(lo, min(hi, len(x) // 2) + 1):  # a loop over lags, not frames
        a, b = x[:-lag], x[lag:]
        r = float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b) + 1e-18))
        if r > best:
            best, lag_best = r, lag
    return lag_best, best


def _phase_count(gstep: np.ndarray, distance: float, before: np.ndarray, after: np.ndarray, fps: float):
    """Frames ``n + 1`` spanning ``distance`` when the gap repeats the step cycle of its sides, or
    ``None`` when neither side is periodic enough (see :func:`estimate_missing`)."""
    lo, hi = max(2, int(round(0.3 * fps))), int(round(1.3 * fps))
    estimates = []
    for seq in (gstep[before], gstep[after][::-1]):  # after: predicted backwards from the gap's end
        period, r = _step_period(seq, lo, hi)
        if period is None or r < 0.5:
            continue
        cycle = seq[-period:]  # the last cycle before the gap (or the first after, reversed)
        reps = int(np.ceil(distance / max(float(cycle.sum()), 1e-12))) + 1
        cum = np.concatenate([[0.0], np.cumsum(np.tile(cycle, reps))])
        estimates.append(float(np.interp(distance, cum, np.arange(len(cum)))))
    return float(np.mean(estimates)) if estimates else None


def _body_pose(motion: Motion, ref: int | None = None) -> np.ndarray:
    """Heading-frame positions (T, 3K) of the reference joint (``ref``, default
    :func:`~.alignment.reference_joint`) and the K-1 joints below it.

    Joints outside the reference joint's subtree are left out: in rigs carried by a hips channel
    (Bandai Namco) joint 0 is a marker at the world origin, whose heading-frame position is the
    walker's distance from the origin, not part of the pose.
    """
    g_rot, g_pos = motion.fk()
    return _pose_of(motion, g_rot, g_pos, reference_joint(motion) if ref is None else ref)


def _pose_of(motion: Motion, g_rot: np.ndarray, g_pos: np.ndarray, j: int) -> np.ndarray:
    """:func:`_body_pose` from the global rotations and positions ``motion.fk()`` gave."""
    local, _, _ = heading_frame(g_rot, g_pos, j)
    return local[:, motion.skeleton.subtree(j)].reshape(len(local), -1)


MIN_PAIRS = 5
"""Fewest pairs of frames one lag apart that :func:`_stride` averages over."""


def _stride(sides: list, fps: float) -> float | None:
    """The stride period (frames, sub-frame) of the pose sequences ``sides`` (each (N_k, D), the
    known frames on either side of a gap, both at the same gait), or ``None``.

    The mean squared pose difference at lag ``L`` (0.5–1.6 s), pooled over the pairs of frames
    ``L`` apart inside each side, has its first deep minimum at one stride (one step later the pose
    is mirrored, far away): the smallest local minimum no deeper than 1.5× the lowest, refined by a
    parabola. ``None`` when even the lowest is above the pose variance (half the mean squared
    difference of unrelated frames: not cyclic), or fewer than ``MIN_PAIRS`` pairs span a lag.
    """
    sides = [x for x in sides if len(x) > 1]
    if not sides:
        return None
    lo, hi = int(round(0.5 * fps)), int(round(1.6 * fps))
    if hi <= lo + 2:
        return None
    lags = np.arange(lo, hi + 1)
    sums, counts = np.zeros(len(lags)), np.zeros(len(lags))
    for x in sides:  # two sides, a loop over lags inside
        for k, lag in enumerate(lags[lags < len(x)]):
            sums[k] += np.sum((x[lag:] - x[:-lag]) ** 2)
            counts[k] += len(x) - lag
    ok = counts >= MIN_PAIRS
    if ok.sum() < 3:
        return None
    lags, d = lags[ok], sums[ok] / counts[ok]
    pooled = np.concatenate(sides)
    variance = np.mean(np.sum((pooled - pooled.mean(0)) ** 2, axis=1))
    if variance < 1e-8 * pooled.shape[1] or d.min() > variance:  # a pose held still has no stride either
        return None
    inner = (d[1:-1] <= d[:-2]) & (d[1:-1] <= d[2:]) & (d[1:-1] <= 1.5 * d.min())
    if not inner.any():
        return None
    i = int(np.argmax(inner)) + 1
    return float(lags[i] + _vertex(d[i - 1 : i + 2]))


def _vertex(d3: np.ndarray) -> float:
    """Offset (−0.5 … 0.5) of the minimum of the parabola through three equally spaced values."""
    den = d3[0] - 2.0 * d3[1] + d3[2]
    return float(np.clip(0.5 * (d3[0] - d3[2]) / den, -0.5, 0.5)) if den > 0 else 0.0


def _match(q: np.ndarray, cand: np.ndarray) -> float:
    """Sub-frame index of the row of ``cand`` (P, D) nearest to ``q`` (D,)."""
    d = np.sum((cand - q) ** 2, axis=1)
    i = int(np.argmin(d))
    return float(i + (_vertex(d[i - 1 : i + 2]) if 0 < i < len(d) - 1 else 0.0))


def _phase_missing(pose: np.ndarray, t: int, start: int, stop: int, guess: float, fps: float) -> float | None:
    """The missing count at step ``t → t+1`` from the step phase, the one nearest ``guess``.

    The stride period ``P`` is read off both sides (up to three seconds each, between the
    neighbouring gaps ``start … stop``). The first frame after the gap is matched to the last
    stride before it (frame ``j``: then ``n ≡ j − t − 1``, mod ``P``) and the last frame before the
    gap to the first stride after it (frame ``j'``: ``n ≡ t − j'``). The two residues, where both
    exist, must agree within a tenth of a stride, else ``None``; ``n`` is the residue plus the whole
    number of strides that brings it nearest to ``guess``, and ``None`` where that says no frame
    is missing (below one half), which a detected gap contradicts.
    """
    far = int(round(3.0 * fps))
    before, after = pose[max(start, t - far) : t + 1], pose[t + 1 : min(stop + 1, t + 1 + far)]
    period = _stride([before, after], fps)
    if period is None:
        return None
    p = int(np.ceil(period))
    residues = []
    if len(before) >= p:
        residues.append(_match(pose[t + 1], before[-p:]) - p)
    if len(after) >= p:
        residues.append(-1.0 - _match(pose[t], after[:p]))
    if not residues:
        return None
    x = np.asarray(residues)
    if len(x) == 2 and abs((x[0] - x[1] + 0.5 * period) % period - 0.5 * period) > 0.1 * period:
        return None
    x = float(np.angle(np.mean(np.exp(2j * np.pi * x / period)))) * period / (2.0 * np.pi)
    n = x + round((guess - x) / period) * period
    return n if n >= 0.5 else None  # "nothing missing" contradicts the gap: the phase cannot tell


def estimate_missing(motion: Motion, steps_at, seconds: float = 1.0, takes=None) -> list[int]:
    """How many frames went missing at each stream step ``t → t+1`` in ``steps_at``.

    From the motion on both sides of each gap (the known steps end at the neighbouring gaps and
    at the nearest held step, :data:`HELD`), not from the jump alone:

    * the ground distance across the gap is the chord ``|g(t+1) − g(t)|`` of the reference joint's
      ground point, lengthened to the arc of a circle turning by the change ``ψ`` of travel
      direction between the two sides, ``arc = chord · (ψ/2) / sin(ψ/2)``;
    * **stride count**: where the ground speed on a side (up to two seconds) repeats with a period
      of 0.3–1.3 s (normalised autocorrelation ≥ 0.5, :func:`_step_period`), ``n + 1`` is where
      that side's nearest cycle, repeated, covers the arc (both sides averaged); otherwise
      ``n + 1 = arc / v`` with ``v`` the mean ground speed over ``seconds`` on each side. Where the
      two sides' mean speeds differ by more than :data:`TRANSIENT` (:func:`changes_speed`), the
      step phase decides instead (:func:`_phase_missing`: ``n`` modulo the stride period from the
      poses that bound the gap, the value nearest the distance estimate), or, where no stride can
      be read, the mean of the two edge speeds over the nearest 0.35 s;
    * **local count** (:func:`_local_count`): the ``n`` for which a quadratic in time through the
      ground speeds of the nearest :data:`LOCAL_SECONDS` on both sides covers the arc. It replaces
      the stride count only where, on gaps of the same length cut out of the known frames beside
      the real one (up to :data:`REHEARSAL_SECONDS`), it gets significantly more of them within
      10% (or one frame): a one-sided sign test at :data:`SIGNIFICANCE` (:func:`count_choice`);
    * a body that does not travel (speed below :data:`STEP_FLOOR`): the ``n`` for which one cubic
      in time fits every joint's positions over the nearest :data:`LOCAL_SECONDS` on both sides
      best (:func:`_in_place_count`), or where it has no answer, ``n + 1`` is the joint step across
      the gap over the median joint step around it (the step ratio, which also widens the range);
    * with ``takes`` (other recordings of the action, never this one): the mean of the count above
      and how long the recordings need from the pose before the gap to the pose after it,
      time-scaled to the stream (:func:`~.recorded.recorded_missing`).

    The count is an estimate: the stream alone cannot tell how fast the body moved inside the gap
    (frame times can, :func:`~.gaps.timestamp_gaps`). :func:`estimate_counts` gives each count with
    the range it is likely in.

    Parameters
    ----------
    motion : Motion, the stream with the frames already missing (nothing inserted)
    steps_at : sequence of int, steps ``t → t+1`` that hide missing frames, in ``0 … T-2``
    seconds : float, the mean-speed window on each side, seconds
    takes : :class:`~.recorded.RecordedTakes`, optional, other recordings of the stream's action

    Returns
    -------
    list of int, the estimated missing count per step (at least 1), in the order of ``sorted(steps_at)``

    Raises
    ------
    ValueError
        if a step lies outside ``0 … T-2``.
    """
    return [c.count for c in estimate_counts(motion, steps_at, seconds, takes)]


@dataclass(frozen=True)
class MissingCount:
    """How many frames went missing in one gap (:func:`estimate_counts`): the estimate and the
    range ``low … high`` (inclusive) it is likely in."""

    count: int
    """The estimate, at least 1 (what :func:`estimate_missing` gives)."""
    low: int
    """The fewest frames likely missing, at least 1."""
    high: int
    """The most frames likely missing."""
    untried: int | None = None
    """Where the range is open above, the shortest gap size that could not be tried as this one's
    true size (too few known frames beside it: a short clip, a near end or gap), and the range
    reaches the longest that could; else ``None``. The range says nothing of gaps that long
    (:func:`_plausible_range`)."""


def estimate_counts(motion: Motion, steps_at, seconds: float = 1.0, takes=None) -> list[MissingCount]:
    """:func:`estimate_missing`'s count at each step ``t → t+1`` in ``steps_at``, with its range.

    The range holds every count within :data:`COUNT_TOLERANCE` of the estimate (or one frame), both
    the stride and the local count (where they disagree, neither can be trusted alone; where the
    body does not travel, the in-place count and the step ratio), and where
    the count was rehearsed on cuts of the same length beside the gap (:func:`count_choice`), every
    count its errors there point to (the gap's count less each error; on cuts where the body does
    not travel, the step ratio's errors too), and every gap size up to a second (or three times the
    count) whose cuts beside the gap can be counted as this one was (:func:`_plausible_range`: a
    repeating or slowing motion can hide a longer gap). With ``takes`` it is
    that of the stream's own count widened to the tolerance about the mean with the recordings.
    Parameters and raises: those of :func:`estimate_missing`.

    Returns
    -------
    list of :class:`MissingCount`, in the order of ``sorted(steps_at)``
    """
    at = sorted(int(t) for t in steps_at)
    if not at:
        return []
    if at[0] < 0 or at[-1] > motion.num_frames - 2:
        raise ValueError(
            f"clip {motion.name!r}: steps that hide missing frames must lie in 0 … {motion.num_frames - 2} "
            f"(step t is frame t → t+1), got {at}"
        )
    arrays = _Arrays.of(motion)
    out = []
    for t in at:
        start = max([g + 1 for g in at if g < t], default=0)  # known steps between neighbouring gaps
        stop = min([g for g in at if g > t], default=len(arrays.gstep))
        choice = _choose(arrays, t, start, stop, seconds)
        n, low, high = choice.count, choice.low, choice.high
        if takes is not None:
            rec = recorded_missing(motion, t, takes, n, start, stop)
            n = n if rec is None else 0.5 * (n + rec[0])
        count = max(1, int(round(n)))
        band = _tolerance(count)
        out.append(MissingCount(count, min(low, band[0]), max(high, band[1]), choice.untried))
    return out


def _tolerance(count: int) -> tuple[int, int]:
    """The counts within :data:`COUNT_TOLERANCE` of ``count`` or one frame of it, at least 1."""
    tol = max(1.0, COUNT_TOLERANCE * count)
    return max(1, int(math.ceil(count - tol - 1e-9))), int(math.floor(count + tol + 1e-9))


@dataclass
class CountChoice:
    """The stream's two counts for one gap and the rehearsal that chose between them
    (:func:`count_choice`; counts in frames missing, ``n``, not rounded)."""

    stride: float
    """The stride count: ground distance over the step cycle, mean speed or step phase; where the body
    does not travel, the in-place count (:func:`_in_place_count`, else the step ratio)."""
    local: float | None
    """The local count (a quadratic through the edge speeds); ``None`` where it has no answer or
    the body does not travel."""
    stride_only: int
    """Rehearsal cuts that only the stride count got within :data:`COUNT_TOLERANCE` (or one frame)."""
    local_only: int
    """Rehearsal cuts that only the local count got within :data:`COUNT_TOLERANCE` (or one frame)."""
    p: float
    """One-sided sign test of ``local_only`` against ``stride_only``."""
    count: float
    """The count used: the local one where ``p < SIGNIFICANCE`` and it has an answer, else the stride one."""
    low: int = 1
    """The fewest frames likely missing, at least 1: the least of ``count`` less its tolerance
    (:data:`COUNT_TOLERANCE`), the stride and local counts (the step ratio in place of the local
    count where the body does not travel; rounded), ``count`` less its largest error on the
    rehearsal cuts (rounded) and the gap sizes that could have given ``count`` (:func:`_plausible_range`)."""
    high: int = 1
    """The most frames likely missing: the most of ``count`` plus its tolerance, the counts ``low``
    takes, ``count`` less its smallest error on the rehearsal cuts and those gap sizes."""
    ratio: float | None = None
    """Where the body does not travel, the step ratio (the joint step across the gap over the
    median joint step around it, less one; :func:`_step_ratio`); ``None`` otherwise."""
    untried: int | None = None
    """Where the range is open above (:func:`_plausible_range`: too few known frames beside the gap
    to try longer sizes, and the range reaches the longest it could try), the next size, else ``None``."""


def count_choice(motion: Motion, t: int, start: int = 0, stop: int | None = None, seconds: float = 1.0) -> CountChoice:
    """Both stream counts of the gap at step ``t → t+1`` of ``motion`` (known steps ``start …
    stop``, default the whole stream) and the rehearsal between them (:func:`estimate_missing`).

    Raises
    ------
    ValueError unless 0 <= start <= t < stop <= the motion's last step + 1.
    """
    last = motion.num_frames - 2  # the last step
    stop = last + 1 if stop is None else int(stop)
    t, start = int(t), int(start)
    if not 0 <= start <= t < stop <= last + 1:
        raise ValueError(
            f"clip {motion.name!r}: the gap's step must lie in start … stop-1 of steps 0 … {last} "
            f"(0 <= start <= t < stop <= {last + 1}), got t={t}, start={start}, stop={stop}"
        )
    return _choose(_Arrays.of(motion), t, start, stop, seconds)


def _choose(a: _Arrays, t: int, start: int, stop: int, seconds: float) -> CountChoice:
    start, stop = _moving_bounds(a, t, start, stop)
    n, arc = _stride_count(a, t, start, stop, seconds)
    local = None if arc is None else _local_count(a.gstep, t, start, stop, arc, n, a.fps)
    m = max(1, int(round(n)))
    stride, local_at, travels, ratio_at = _rehearse(a, t, start, stop, m, seconds)
    stride_only, local_only, p = 0, 0, 1.0
    if local is not None:  # the rehearsal chooses between the two counts
        tol = max(1.0, COUNT_TOLERANCE * m)
        hit_stride = travels & (np.abs(np.round(stride) - m) <= tol)
        hit_local = travels & (np.abs(np.round(local_at) - m) <= tol)  # NaN: no hit
        stride_only, local_only = int(np.sum(hit_stride & ~hit_local)), int(np.sum(hit_local & ~hit_stride))
        p = _sign_test(local_only, stride_only)
    use_local = local is not None and p < SIGNIFICANCE
    count = local if use_local else n
    low, high = _tolerance(max(1, int(round(count))))
    ratio = _in_place_ratio(a, t, start, stop, seconds) if arc is None else None
    for other in (x for x in (n, local, ratio) if x is not None):  # where the counts disagree, all
        low, high = min(low, max(1, int(round(other)))), max(high, int(round(other)))
    if stride.size:  # the count's errors on the rehearsal cuts widen its range
        errors = (np.where(np.isfinite(local_at), local_at, stride) if use_local else stride) - m
        errors = np.concatenate([errors, ratio_at[np.isfinite(ratio_at)] - m])  # in place: both counts' errors
        low = min(low, max(1, int(math.floor(count - errors.max() + 0.5))))
        high = max(high, int(math.floor(count - errors.min() + 0.5)))
    low, high, untried = _plausible_range(a, t, start, stop, count, use_local, seconds, low, high)
    return CountChoice(n, local, stride_only, local_only, p, count, low, high, ratio, untried)


def _moving_bounds(a: _Arrays, t: int, start: int, stop: int) -> tuple[int, int]:
    """The known steps ``start … stop`` around step ``t`` cut short at the nearest held step on
    each side (``HELD``): copies of one frame are not motion the counts can read."""
    held = np.flatnonzero(a.jsteps <= a.held)
    lower, upper = held[held < t], held[held > t]
    start = max(start, int(lower[-1]) + 1) if lower.size else start
    stop = min(stop, int(upper[0])) if upper.size else stop
    return start, stop


@dataclass
class _Arrays:
    """What the counts read off a stream, per frame: the reference joint's ground point ``ground``
    (T, 3), the ground distance ``gstep`` (T-1,) and RMS joint step ``jsteps`` (T-1,) of each step,
    heading-frame body poses ``pose`` (T, 3K, :func:`_body_pose`), world joint positions
    ``positions`` (T, J, 3), the frame rate, the slowest travelling speed ``floor`` (metres per
    frame) and the RMS joint step ``held`` at or below which a step repeats its frame (``HELD``)."""

    ground: np.ndarray
    gstep: np.ndarray
    jsteps: np.ndarray
    pose: np.ndarray
    positions: np.ndarray
    fps: float
    floor: float
    held: float

    @classmethod
    def of(cls, motion: Motion) -> _Arrays:
        g_rot, g_pos = motion.fk()
        j = reference_joint(motion)
        ground = g_pos[:, j] * np.array([1.0, 0.0, 1.0])
        height = body_height(motion)
        floor = STEP_FLOOR * height / motion.fps
        return cls._from(ground, g_pos, _pose_of(motion, g_rot, g_pos, j), motion.fps, floor, HELD * height)

    @classmethod
    def _from(cls, ground, positions, pose, fps, floor, held) -> _Arrays:
        gstep = np.linalg.norm(np.diff(ground, axis=0), axis=-1)
        return cls(ground, gstep, _rms_steps(positions), pose, positions, float(fps), float(floor), float(held))

    def without(self, keep: np.ndarray) -> _Arrays:
        """The stream of frames ``keep`` (indices) only."""
        return _Arrays._from(self.ground[keep], self.positions[keep], self.pose[keep], self.fps, self.floor, self.held)


def _stride_count(a: _Arrays, t: int, start: int, stop: int, seconds: float) -> tuple[float, float | None]:
    """The stride count ``n`` at step ``t → t+1`` (known steps ``start … stop``) and the arc it
    covers (``None`` when the body does not travel): every rule of :func:`estimate_missing` but
    the local count and the recordings."""
    gstep, fps = a.gstep, a.fps
    half = max(3, int(round(seconds * fps)))
    far = max(half, int(round(2.0 * fps)))
    before, after = _sides(t, start, stop, half)
    if before.size + after.size == 0:
        return 0.0, None
    speeds = [float(np.mean(gstep[w])) for w in (before, after) if w.size]
    v = float(np.mean(speeds))
    if v <= a.floor:
        ratio = _step_ratio(a, t, before, after)
        fitted = _in_place_count(a, t, start, stop, max(ratio, 1.0))
        return (ratio if fitted is None else fitted), None
    psi = min(_turn(a.ground, before, after), 0.9 * np.pi)
    arc = gstep[t] * ((0.5 * psi) / np.sin(0.5 * psi) if psi > 1e-6 else 1.0)
    long_before = np.arange(max(start, t - far), t)
    long_after = np.arange(t + 1, min(stop, t + 1 + far))
    frames = _phase_count(gstep, arc, long_before, long_after, fps)
    n = (arc / v if frames is None else frames) - 1.0
    if len(speeds) == 2 and changes_speed(*speeds):
        phased = _phase_missing(a.pose, t, start, stop, n, fps)
        if phased is None:
            near = max(2, int(round(0.35 * fps)))
            edge = [float(np.mean(gstep[w])) for w in (before[-near:], after[:near])]
            n = arc / float(np.mean(edge)) - 1.0
        else:
            n = phased
    return n, float(arc)


def _in_place_ratio(a: _Arrays, t: int, start: int, stop: int, seconds: float) -> float:
    """The step ratio (:func:`_step_ratio`) of an in-place gap, over ``seconds`` on each side."""
    before, after = _sides(t, start, stop, max(3, int(round(seconds * a.fps))))
    return _step_ratio(a, t, before, after) if before.size + after.size else 0.0


def _sides(t: int, start: int, stop: int, half: int) -> tuple[np.ndarray, np.ndarray]:
    """The known steps up to ``half`` before step ``t`` and after it (within ``start … stop``)."""
    return np.arange(max(start, t - half), t), np.arange(t + 1, min(stop, t + 1 + half))


def _step_ratio(a: _Arrays, t: int, before: np.ndarray, after: np.ndarray) -> float:
    """``n`` from the joint step across the gap at step ``t → t+1`` over the median joint step of
    the steps ``before`` and ``after`` it (the step ratio; both index arrays, not both empty)."""
    win = np.concatenate([before, after])
    return float(a.jsteps[t] / max(float(np.median(a.jsteps[win])), 1e-9) - 1.0)


def _in_place_count(a: _Arrays, t: int, start: int, stop: int, guess: float) -> float | None:
    """The in-place count at step ``t → t+1`` (known steps ``start … stop``): the ``n`` for which one
    cubic in time fits every joint coordinate of the nearest :data:`LOCAL_SECONDS` of frames on
    both sides (at least three frames a side where the known steps allow) best, by least squares,
    over ``n = 0, 1, …`` up to 3 × ``guess`` or two seconds of frames, whichever is more. Frame
    ``t`` is at time 0, frame ``t+1`` at ``n + 1``. ``None`` where a side has fewer than two frames
    or both fewer than five (a cubic and one more), or the best ``n`` is the last one tried (the fit
    has no minimum: it only improves as the gap grows).
    """
    w = max(3, int(round(LOCAL_SECONDS * a.fps)))
    kb = np.arange(max(start, t - w + 1), t + 1)  # frames before the gap, its first frame t
    ka = np.arange(t + 1, min(stop, t + w) + 1)
    if kb.size < 2 or ka.size < 2 or kb.size + ka.size < 5:
        return None
    y = a.positions[np.concatenate([kb, ka])].reshape(kb.size + ka.size, -1)
    y = y - y.mean(0)
    grid = np.arange(int(max(3.0 * guess, 2.0 * a.fps)) + 1, dtype=np.float64)  # n
    x = np.concatenate([np.broadcast_to(kb - t, (len(grid), kb.size)), (ka - t - 1)[None, :] + grid[:, None] + 1.0], 1)
    x = (x - x.mean(1, keepdims=True)) / (x[:, -1:] - x[:, :1])  # well-conditioned times, one span
    q, _ = np.linalg.qr(np.stack([x**d for d in range(4)], axis=-1))  # (G, W, 4): each n's cubic
    residual = np.square(y[None] - q @ (q.transpose(0, 2, 1) @ y[None])).sum((1, 2))
    best = int(np.argmin(residual))
    return None if best == len(grid) - 1 else float(grid[best])


def _local_count(gstep: np.ndarray, t: int, start: int, stop: int, arc: float, guess: float, fps: float):
    """The local count at step ``t → t+1``: the ``n`` for which a quadratic in time through the
    ground speeds of the nearest ``LOCAL_SECONDS`` on both sides covers ``arc`` in the gap's
    ``n + 1`` steps, or ``None`` (too few speeds, or no such ``n``).

    Stream step ``k → k+1`` is placed at its middle in time, frame ``t`` at 0: at ``k − t + ½``
    before the gap, and at ``k − t + ½ + n`` after it, where stream frame ``t+1`` lies at ``n + 1``
    (the step ``t+1 → t+2`` at ``n + 1½``). For every ``n`` on a grid (0 … 3× ``guess``, quarter
    frames) the quadratic is fitted by least squares (one batched solve) and integrated over
    ``0 … n+1``; of the ``n`` where the integral crosses ``arc`` the one nearest ``guess`` is kept,
    interpolated between grid points. Where the speed changes linearly in time the count is exact.
    """
    w = max(3, int(round(LOCAL_SECONDS * fps)))
    kb = np.arange(max(start, t - w), t)
    ka = np.arange(t + 1, min(stop, t + 1 + w))
    if kb.size + ka.size < 4 or kb.size == 0 or ka.size == 0:
        return None
    grid = np.arange(0.0, max(3.0 * guess, 10.0), 0.25)  # (G,)
    scale = grid + 1.0  # times in units of the gap, for a well-conditioned fit
    x = np.concatenate([np.broadcast_to(kb - t + 0.5, (len(grid), kb.size)),
                        (ka - t + 0.5)[None, :] + grid[:, None]], axis=1) / scale[:, None]  # fmt: skip
    y = np.concatenate([gstep[kb], gstep[ka]])
    basis = np.stack([np.ones_like(x), x, x * x], axis=-1)  # (G, W, 3)
    normal = np.einsum("gwi,gwj->gij", basis, basis)
    coef = np.linalg.solve(normal, np.einsum("gwi,w->gi", basis, y)[..., None])[..., 0]  # (G, 3)
    covered = (coef[:, 0] + coef[:, 1] / 2.0 + coef[:, 2] / 3.0) * scale  # the integral over 0 … n+1
    f = covered - arc
    cross = np.flatnonzero((f[:-1] < 0.0) & (f[1:] >= 0.0))
    if not cross.size:
        return None
    found = grid[cross] + 0.25 * (-f[cross]) / (f[cross + 1] - f[cross])
    return float(found[np.argmin(np.abs(found - guess))])


def _plausible_range(
    a: _Arrays, t: int, start: int, stop: int, count: float, use_local: bool, seconds: float, low: int, high: int
) -> tuple[int, int, int | None]:
    """``low … high`` widened to every gap size that could have given ``count`` at step ``t → t+1``
    (known steps ``start … stop``): the range by test inversion, so that it holds gaps the count
    undercounts; and the shortest size above it that could not be tried, if any.

    :data:`SIZES` sizes ``k``, geometric from one frame to the larger of three times ``count`` and
    :data:`SIZES_SECONDS` of frames (:func:`_longest_size`), are each cut out at up to
    :data:`SIZE_PLACES` evenly spaced places on each side (:func:`_rehearse`) and counted by the
    rule the real gap used (the local count where ``use_local`` and it has an answer, else the
    stride count). ``k`` could have given ``count`` where at least three cuts fit and ``count``
    (rounded) lies between the least and the most of their counts (rounded), widened by its
    tolerance (:data:`COUNT_TOLERANCE`, or one frame). Where three cuts of the longest size do not
    fit beside the gap, the sizes stop at the longest that does (:func:`_longest_tried`). The range
    is the span of the sizes that could have given ``count`` and ``low … high``, so the sizes inside
    ``low … high`` are not tried, and the others are tried from each end inwards up to the first
    that could have given ``count``. Where the sizes stopped short and the range reaches the last
    of them, nothing says that a longer gap would look different: the range is open above, and the
    third value is the next size, else ``None``. A loop over sizes, each over its cuts.
    """
    m = max(1, int(round(count)))
    tol = max(1.0, COUNT_TOLERANCE * m)
    top, tried = _longest_size(count, a.fps), _longest_tried(a, t, start, stop)
    sizes = np.unique(np.round(np.geomspace(1, top, SIZES)).astype(int))
    if tried < top:
        sizes = np.unique(np.r_[sizes[sizes < tried], tried]) if tried else sizes[:0]

    def could(k: int) -> bool:
        stride, local, _, _ = _rehearse(a, t, start, stop, k, seconds, SIZE_PLACES, use_local)
        got = np.round(np.where(np.isfinite(local), local, stride) if use_local else stride)
        return got.size >= 3 and got.min() - tol <= m <= got.max() + tol

    high = next((k for k in sizes[sizes > high][::-1].tolist() if could(k)), high)
    low = next((k for k in sizes[sizes < low].tolist() if could(k)), low)
    return low, high, (tried + 1 if tried < top and high >= tried else None)


def _longest_size(count: float, fps: float) -> int:
    """The longest gap size :func:`_plausible_range` tries for a gap counted ``count`` frames."""
    return max(3 * max(1, int(round(count))), int(round(SIZES_SECONDS * fps)), 2)


def _rehearsal_sides(a: _Arrays, t: int, start: int, stop: int) -> tuple[tuple[int, int], tuple[int, int], int]:
    """The known frames ``lo … hi-1`` on each side of the gap at step ``t → t+1`` (known steps
    ``start … stop``) that :func:`_rehearse` cuts, up to ``REHEARSAL_SECONDS`` away, and the frames
    ``edge`` a cut keeps on both its sides (``LOCAL_SECONDS``, at least three)."""
    far = int(round(REHEARSAL_SECONDS * a.fps))
    edge = max(3, int(round(LOCAL_SECONDS * a.fps)))  # what the local count fits on
    return (max(start, t - far), t + 1), (t + 1, min(stop + 1, t + 1 + far)), edge


def _longest_tried(a: _Arrays, t: int, start: int, stop: int) -> int:
    """The longest gap size of which at least three cuts fit beside step ``t → t+1`` (known steps
    ``start … stop``; :func:`_rehearse` fits ``hi - lo - 2 edge + 1 - m`` cuts of ``m`` frames on a
    side), 0 if none."""
    before, after, edge = _rehearsal_sides(a, t, start, stop)
    spans = np.array([hi - lo - 2 * edge + 1 for lo, hi in (before, after)])
    sizes = np.arange(1, max(spans.max(), 1) + 1)
    fits = np.clip(spans[None, :] - sizes[:, None], 0, None).sum(axis=1) >= 3
    return int(sizes[fits].max()) if fits.any() else 0


def _rehearse(a: _Arrays, t: int, start: int, stop: int, m: int, seconds: float, places=None, local=True):
    """Both counts of gaps of ``m`` frames rehearsed on the known frames beside the real gap at step
    ``t → t+1`` (known steps ``start … stop``).

    On each side (up to ``REHEARSAL_SECONDS``; never across the gap) ``m`` frames are cut out at
    every place that leaves ``LOCAL_SECONDS`` (at least three frames) of known frames on both sides
    of the cut (at most ``places`` of them, evenly spaced, where given), and both counts are made
    for each cut as for a real gap (the local one only with ``local``; a loop over cuts, each count
    vectorised over its frames). The cuts overlap, so they are not independent trials: the sign
    test of :func:`estimate_missing` on them overstates the evidence, and its 5% is nominal.

    Returns
    -------
    stride : ndarray (C,), the stride count of each cut (the in-place count where the body does
        not travel)
    local : ndarray (C,), the local count of each cut, NaN where it has none (or not ``local``)
    travels : ndarray (C,) bool, whether the body travels at the cut
    ratio : ndarray (C,), the step ratio of each cut where the body does not travel, NaN elsewhere
    """
    before, after, edge = _rehearsal_sides(a, t, start, stop)
    counts = []
    for lo, hi in (before, after):
        at = np.arange(lo + edge - 1, hi - m - edge)
        if places is not None and at.size > places:
            at = at[np.round(np.linspace(0, at.size - 1, places)).astype(int)]
        for p in at.tolist():  # frames p+1 … p+m cut out
            keep = np.r_[lo : p + 1, p + 1 + m : hi]
            sub = a.without(keep)
            tp = p - lo
            n, arc = _stride_count(sub, tp, 0, len(sub.gstep), seconds)
            fit = None if arc is None or not local else _local_count(sub.gstep, tp, 0, len(sub.gstep), arc, n, a.fps)
            ratio = _in_place_ratio(sub, tp, 0, len(sub.gstep), seconds) if arc is None else np.nan
            counts.append((n, np.nan if fit is None else fit, arc is not None, ratio))
    x = np.asarray(counts, dtype=np.float64).reshape(-1, 4)
    return x[:, 0], x[:, 1], x[:, 2] > 0, x[:, 3]


def _sign_test(wins: int, losses: int) -> float:
    """One-sided sign test: the chance of ``wins`` or more of ``wins + losses`` fair coin tosses."""
    k = wins + losses
    return sum(math.comb(k, i) for i in range(wins, k + 1)) / 2.0**k


def detect_counts(motion: Motion, graph=None, delta: float | None = None, takes=None) -> list[tuple[int, MissingCount]]:
    """Dropped frames as ``(after frame t, missing count with its range)``: :func:`graph_gaps` with a
    graph, :func:`consecutive_gaps` without, counts from :func:`estimate_counts` (with the other
    recordings ``takes`` if given). Raises what those raise."""
    if graph is not None:
        at = graph_gaps(motion, graph, delta)
    else:
        at = consecutive_gaps(motion, DELTA if delta is None else delta)
    return list(zip(at, estimate_counts(motion, at, takes=takes)))


def detect(motion: Motion, graph=None, delta: float | None = None, takes=None) -> list[tuple[int, int]]:
    """Dropped frames as ``(after frame t, estimated missing count)``, ready for
    :func:`~.gaps.insert_missing`: :func:`detect_counts` without the ranges."""
    return [(t, c.count) for t, c in detect_counts(motion, graph, delta, takes)]
