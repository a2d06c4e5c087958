"""Timeline: a list of behaviour segments turned into per-frame parameters and actions.

Each segment ``(behaviour, frames, style)`` contributes its :class:`~.style.Style` with a
weight that is 1 inside the segment and cross-fades to the next one over ``blend`` seconds
centred on the boundary (smoothstep weights that always sum to 1). Every numeric style field
becomes a per-frame curve, so a walk-to-run transition is a smooth change of stride, cadence,
duty factor, bounce and arm swing, and the gait phase never jumps.

Jumps and squats are *actions*: timed events (crouch, take-off, flight, landing; down, hold,
up) scheduled inside their segment. Their timings shrink when a segment is too short for a
full action, and the stepping planner must not move a foot while one is under way (``locks``).

The time grid is padded before frame 0 and after the last frame so that a clip can start in
the middle of a walk (the planner has already taken a few steps) and look ahead at its end.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from motionlab.synthetic.style import BEHAVIOURS, FIELDS, Style

__all__ = ["Segment", "JumpAction", "SquatAction", "Timeline", "build", "smoothstep", "ease_track", "GRAVITY"]

GRAVITY = 9.81
"""Acceleration of the ballistic flight of a jump, m/s²."""

# nominal phase durations in seconds
_JUMP_CROUCH, _JUMP_PUSH, _JUMP_ABSORB, _JUMP_RECOVER, _JUMP_GAP = 0.4, 0.2, 0.25, 0.4, 0.3
_SQUAT_DOWN, _SQUAT_HOLD, _SQUAT_UP, _SQUAT_PAUSE = 1.0, 0.3, 0.9, 0.4
_MIN_COMPRESSION = {"jump": 0.6, "squat": 0.5}  # shortest action, as a fraction of the natural one
_GAIT_FIELDS = ("cadence", "duty", "foot_lift", "heel_strike", "toe_off")
_GAIT_ONLY = ("stride", "turn_rate", "bounce", "hip_twist", "arm_swing")
_FIRST_ACTION_DELAY = 0.1  # s: an action in the first segment starts this late
# s: after walking or running, time to plant the feet side by side before a jump/squat starts
_SETTLE_BEFORE = {"jump": 0.45, "squat": 0.65}


def smoothstep(x) -> np.ndarray:
    """``3x² − 2x³`` of ``x`` clipped to [0, 1]: 0 → 1 with zero slope at both ends."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def ease_track(t, times, values) -> np.ndarray:
    """Piecewise smoothstep interpolation of keys ``(times[k], values[k])`` at times ``t``.

    Before the first key the first value holds, after the last the last value. Keys with equal
    times jump.
    """
    t = np.asarray(t, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    span = np.maximum(times[k + 1] - times[k], 1e-9)
    s = smoothstep((t - times[k]) / span)
    return values[k] + (values[k + 1] - values[k]) * s


@dataclass(frozen=True)
class Segment:
    """A behaviour between ``start`` and ``end`` seconds (clip time, frame 0 at 0 s)."""

    behaviour: str
    start: float
    end: float
    style: Style


@dataclass(frozen=True)
class JumpAction:
    """One jump: times in seconds, lengths in metres.

    crouch → bottom: counter-movement down; bottom → takeoff: push (heels rise);
    takeoff → land: ballistic flight; land → absorb: knees absorb; absorb → recover: stand up.
    ``vigour`` (0–1) shrinks the arm swing and lean of a jump squeezed into a short segment.
    """

    crouch: float
    bottom: float
    takeoff: float
    land: float
    absorb: float
    recover: float
    height: float
    distance: float
    dip: float
    dip_land: float
    vigour: float = 1.0

    @property
    def takeoff_speed(self) -> float:
        """Vertical speed (m/s) at take-off, from the flight apex: ``√(2 g h)``."""
        return float(np.sqrt(2.0 * GRAVITY * self.height))


@dataclass(frozen=True)
class SquatAction:
    """One squat: down from ``start`` to ``bottom``, hold until ``rise``, up until ``end``."""

    start: float
    bottom: float
    rise: float
    end: float
    depth: float


@dataclass
class Timeline:
    """Per-frame parameters on a padded time grid.

    Attributes
    ----------
    time : ndarray, shape (N,)          seconds; ``time[first]`` is 0 (the clip's frame 0)
    first : int                         index of the clip's first frame in the padded grid
    num_frames : int                    frames of the clip, T
    fps : float
    weights : ndarray, shape (N, 5)     weight of each behaviour of :data:`BEHAVIOURS`
    params : dict str -> ndarray (N,)   every :class:`Style` field, blended
    segments, jumps, squats, locks      the schedule; ``locks`` are (start, end) seconds
        during which no foot may leave its place except as part of the action
    """

    time: np.ndarray
    first: int
    num_frames: int
    fps: float
    weights: np.ndarray
    params: dict[str, np.ndarray]
    segments: list[Segment] = field(default_factory=list)
    jumps: list[JumpAction] = field(default_factory=list)
    squats: list[SquatAction] = field(default_factory=list)
    locks: list[tuple[float, float]] = field(default_factory=list)

    @property
    def gait(self) -> np.ndarray:
        """Weight (N,) of stepping locomotion (walk + run); ``1 − gait`` is standing."""
        return self.weights[:, BEHAVIOURS.index("walk")] + self.weights[:, BEHAVIOURS.index("run")]

    def at(self, name: str, t) -> np.ndarray:
        """Parameter ``name`` at arbitrary times ``t`` (linear interpolation on the grid)."""
        return np.interp(t, self.time, self.params[name])


def _jumps(style: Style, start: float, end_limit: float, leg: float) -> list[JumpAction]:
    height = style.jump_height * leg

    def flight(h: float) -> float:
        return 2.0 * np.sqrt(2.0 * max(h, 0.0) / GRAVITY)

    one = _JUMP_CROUCH + _JUMP_PUSH + flight(height) + _JUMP_ABSORB
    avail = max(end_limit - start, 0.0)
    c = 1.0 if one <= avail else max(avail / one, _MIN_COMPRESSION["jump"])
    crouch, push, absorb, recover = (c * d for d in (_JUMP_CROUCH, _JUMP_PUSH, _JUMP_ABSORB, _JUMP_RECOVER))
    height *= c * c  # flight time scales with √height, so the whole jump scales with c
    one = crouch + push + flight(height) + absorb
    spacing = style.period if style.period > 0 else one + recover + _JUMP_GAP
    spacing = max(spacing, one + 0.5 * recover)
    count = 1 + max(int(np.floor((avail - one) / spacing + 1e-9)), 0)
    out = []
    for k in range(count):
        t0 = start + k * spacing
        bottom = t0 + crouch
        takeoff = bottom + push
        land = takeoff + flight(height)
        absorb_end = land + absorb
        out.append(
            JumpAction(
                crouch=t0,
                bottom=bottom,
                takeoff=takeoff,
                land=land,
                absorb=absorb_end,
                recover=absorb_end + recover,
                height=height,
                distance=style.jump_distance * leg * c,
                dip=0.2 * leg * min(1.0, c * 1.3),
                dip_land=0.15 * leg * min(1.0, c * 1.3),
                vigour=c,
            )
        )
    return out


def _squats(style: Style, start: float, end_limit: float, leg: float) -> list[SquatAction]:
    one = _SQUAT_DOWN + _SQUAT_HOLD + _SQUAT_UP
    avail = max(end_limit - start, 0.0)
    c = 1.0 if one <= avail else max(avail / one, _MIN_COMPRESSION["squat"])
    down, hold, up = (c * d for d in (_SQUAT_DOWN, _SQUAT_HOLD, _SQUAT_UP))
    one = down + hold + up
    spacing = style.period if style.period > 0 else one + _SQUAT_PAUSE
    spacing = max(spacing, one + 0.1)
    count = 1 + max(int(np.floor((avail - one) / spacing + 1e-9)), 0)
    out = []
    for k in range(count):
        t0 = start + k * spacing
        out.append(SquatAction(t0, t0 + down, t0 + down + hold, t0 + one, style.squat_depth * leg))
    return out


def _fade_halves(segments, durations: np.ndarray, blend: float, fps: float) -> list[float]:
    """Half-width (seconds) of the cross-fade at the start of each segment (0 for the first).

    Never more than 45 % of either neighbour; starting or stopping (gait <-> standing) takes
    twice as long as other changes.
    """
    moving = [b in ("walk", "run") for b, _, _ in segments]
    return [0.0] + [
        max(
            min(
                0.5 * blend * (2.0 if moving[i - 1] != moving[i] else 1.0), 0.45 * durations[i - 1], 0.45 * durations[i]
            ),
            0.5 / fps,
        )
        for i in range(1, len(segments))
    ]


def _schedule_actions(segments, bounds: np.ndarray, half: list[float], pad_after: float, leg: float):
    """``(jumps, squats, locks)`` of the jump and squat segments.

    An action that cannot fit its segment (even squeezed) pushes the later segments back in
    ``bounds`` (modified in place), so that nothing starts moving before a jump has landed or a
    squat is up.
    """
    moving = [b in ("walk", "run") for b, _, _ in segments]
    jumps, squats, locks = [], [], []
    last = len(segments) - 1
    for i, (behaviour, _, style) in enumerate(segments):
        if behaviour not in ("jump", "squat") or bounds[i] > bounds[-1] + pad_after:
            continue
        start = bounds[i] + (half[i] if i > 0 else _FIRST_ACTION_DELAY)
        if i > 0 and moving[i - 1]:
            start += _SETTLE_BEFORE[behaviour]
        end_limit = bounds[i + 1] - (half[i + 1] if i < last else 0.0)
        if behaviour == "jump":
            new_jumps = _jumps(style, start, end_limit, leg)
            jumps += new_jumps
            # settling steps may finish during the first part of the counter-movement
            new_locks = [(j.bottom - 0.3 * (j.bottom - j.crouch), j.absorb) for j in new_jumps]
        else:
            new_squats = _squats(style, start, end_limit, leg)
            squats += new_squats
            new_locks = [(q.start, q.end) for q in new_squats]
        locks += new_locks
        overrun = new_locks[-1][1] - end_limit
        if i < last and overrun > 0:
            bounds[i + 1 : last + 1] += overrun
    return jumps, squats, locks


def _segment_weights(time: np.ndarray, bounds: np.ndarray, half: list[float], count: int) -> np.ndarray:
    """Weight (N, count) of each segment: smoothstep fades that sum to 1 on every frame."""

    def up(i: int) -> np.ndarray:  # 0 → 1 around the start of segment i
        if i == 0:
            return np.ones_like(time)
        if i == count:
            return np.zeros_like(time)
        return smoothstep((time - bounds[i] + half[i]) / (2.0 * half[i]))

    return np.stack([up(i) - up(i + 1) for i in range(count)], axis=-1)


def _hold_gait_fields(params: dict, segments, seg_w: np.ndarray, gait: np.ndarray) -> None:
    """Re-blend the stepping fields of ``params`` in place.

    The stepping knobs of a gait keep their values while the gait fades out (a runner stops
    with quick, ever shorter steps, not with slow walking ones): average them over the
    locomotion segments only, and over the standing ones once no gait is left. The travel
    and swing amplitudes belong to the gait alone and fade out with it.
    """
    moving_mask = np.array([b in ("walk", "run") for b, _, _ in segments])
    for name in _GAIT_FIELDS + _GAIT_ONLY:
        values = np.array([getattr(st, name) for _, _, st in segments])
        walking = seg_w[:, moving_mask] @ values[moving_mask] / np.maximum(gait, 1e-12)
        standing = seg_w[:, ~moving_mask] @ values[~moving_mask] / np.maximum(1.0 - gait, 1e-12)
        params[name] = np.where(gait > 1e-3, walking, standing) if name in _GAIT_FIELDS else gait * walking


def build(
    segments: list[tuple[str, int, Style]],
    leg: float,
    fps: float,
    blend: float,
    pad_before: float = 2.5,
    pad_after: float = 1.5,
) -> Timeline:
    """Blend the segments' styles and schedule their actions.

    Parameters
    ----------
    segments : list of (behaviour, num_frames, Style)   already validated
    leg : float       leg length (thigh + shin), metres; action sizes scale with it
    fps : float       frames per second
    blend : float     cross-fade duration at each boundary, seconds
    pad_before, pad_after : float   seconds of extra grid before frame 0 / after the last frame
    """
    frames = np.array([n for _, n, _ in segments], dtype=np.int64)
    bounds = np.concatenate([[0], np.cumsum(frames)]) / fps  # segment i: [bounds[i], bounds[i+1])
    total = int(frames.sum())
    n_before = int(np.ceil(pad_before * fps))
    n_after = int(np.ceil(pad_after * fps))
    time = (np.arange(n_before + total + n_after) - n_before) / fps
    half = _fade_halves(segments, frames / fps, blend, fps)
    jumps, squats, locks = _schedule_actions(segments, bounds, half, pad_after, leg)

    seg_w = _segment_weights(time, bounds, half, len(segments))
    weights = np.zeros((len(time), len(BEHAVIOURS)))
    params = {name: np.zeros_like(time) for name in FIELDS}
    segs = []
    for i, (behaviour, _, style) in enumerate(segments):
        w = seg_w[:, i]
        weights[:, BEHAVIOURS.index(behaviour)] += w
        for name in FIELDS:
            params[name] += w * getattr(style, name)
        segs.append(Segment(behaviour, float(bounds[i]), float(max(bounds[i + 1], bounds[i])), style))
    gait = weights[:, BEHAVIOURS.index("walk")] + weights[:, BEHAVIOURS.index("run")]
    _hold_gait_fields(params, segments, seg_w, gait)
    return Timeline(time, n_before, total, float(fps), weights, params, segs, jumps, squats, locks)
