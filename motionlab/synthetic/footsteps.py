"""Footsteps: where and when each foot is planted, and how it travels between plants.

A foot's life is a list of *plants*. While planted the foot pivots but never slides::

    land ──(roll: heel or toe pivot)── flat ──(foot flat)── heel ──(heel-off: toe pivot)── lift

and between one plant's ``lift`` and the next one's ``land`` it swings along an arc. The
planner walks through the events in time order (a Python loop over footsteps, not frames):

* a gait-clock event (the phase crosses an integer for the left foot, a half-integer for the
  right) moves the foot to where the body will be a little before mid-stance,
  ``base(t + 0.4 stance)``, plus half the step width sideways (people land a foot closer in
  front of them than they leave it behind). When standing, the same clock only takes a *settling* step if
  the foot is off its standing spot;
* a jump's take-off lifts both feet together and lands them side by side ``distance`` ahead.

:func:`evaluate` then turns the plants into per-frame ankle targets, foot pitch/yaw, toe bend
and contact labels, all vectorised over frames.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import quat
from motionlab.synthetic.timeline import Timeline, smoothstep

__all__ = ["Plant", "FootTracks", "plan", "evaluate", "foot_pose", "JUMP_TOE_OFF", "JUMP_TOE_LAND"]

_FAR = 1e6  # "forever" in seconds
_MIN_STANCE = 0.12  # s: a foot stays down at least this long
_MIN_SWING = 0.15  # s: and swings at least this long
_MAX_BEHIND = 0.75  # leg lengths: a planted foot lifts before the body is this far ahead of it
_UNDER_BODY = 0.4  # the body passes over a planted foot this far into its stance (0.5: midway)
_MAX_AHEAD = 0.6  # leg lengths: a foot lands at most this far ahead of the body
_SETTLE = 0.04  # fraction of leg length a standing foot may be off its spot before it steps
JUMP_TOE_OFF = 0.6  # rad: foot pitch at take-off
JUMP_TOE_LAND = 0.35  # rad: toes first on landing
_SWING_PEAK = 0.75  # exponent < 1 moves the swing's highest point earlier
_MOVING = 0.05  # gait weight below which the character is standing
_SETTLE_SWING = 0.3  # s: swing time of a settling step
_SIDES = (1.0, -1.0)  # sideways sign of each foot: left foot on +X


@dataclass
class Plant:
    """One foot placement. Times in seconds, positions in metres, angles in radians.

    ``ankle`` is the ankle's position when the foot lies flat; ``yaw`` its heading;
    ``p_land``/``p_off`` the foot pitch at touch-down/lift-off (< 0 toes up, pivoting on the
    heel; > 0 heel up, pivoting on the toe). ``swing_height`` and ``tuck`` shape the swing
    *into* this plant; ``jump`` marks a ballistic swing (both feet in flight).
    """

    land: float
    flat: float
    heel: float
    lift: float
    ankle: np.ndarray
    yaw: float
    p_land: float = 0.0
    p_off: float = 0.0
    swing_height: float = 0.0
    tuck: float = 0.0
    jump: bool = False


@dataclass
class FootTracks:
    """Per-frame targets of one foot on the padded grid (N frames).

    ankle (N, 3) metres; pitch, yaw, toe_bend (N,) radians; ankle_contact, toe_contact (N,)
    bool: the ankle (foot flat) / the toe joint is planted; heel_down (N,) bool: planted with
    the heel on the ground (flat, or rolling onto the heel after touch-down); swing (N,): how
    far through a step's swing (0 at lift-off, 1 at touch-down), −1 when planted or jumping;
    lands_heel (N,) bool: the coming touch-down puts the heel down first (or flat).
    """

    ankle: np.ndarray
    pitch: np.ndarray
    yaw: np.ndarray
    toe_bend: np.ndarray
    ankle_contact: np.ndarray
    toe_contact: np.ndarray
    heel_down: np.ndarray
    swing: np.ndarray
    lands_heel: np.ndarray


def _yaw_dirs(heading) -> tuple[np.ndarray, np.ndarray]:
    """Forward and left unit vectors (..., 2) in the ground plane (x, z) for a heading."""
    heading = np.asarray(heading, dtype=np.float64)
    fwd = np.stack([np.sin(heading), np.cos(heading)], axis=-1)
    left = np.stack([np.cos(heading), -np.sin(heading)], axis=-1)
    return fwd, left


def foot_pose(ankle_flat, yaw, pitch, toe, heel) -> np.ndarray:
    """Ankle position (..., 3) of a foot pitched about its heel (pitch < 0) or toe (> 0).

    The pivot (heel or toe point) stays where it is when the foot lies flat with its ankle at
    ``ankle_flat`` (..., 3) and heading ``yaw`` (...); ``toe`` and ``heel`` (3,) are the toe
    joint and heel point relative to the ankle in the rest foot frame.
    """
    pitch = np.asarray(pitch, dtype=np.float64)
    pivot = np.where(pitch[..., None] >= 0.0, toe, heel)
    q_yaw = quat.from_yaw(yaw)
    q_pitch = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), pitch)
    return ankle_flat + quat.rotate(q_yaw, pivot - quat.rotate(q_pitch, pivot))


@dataclass
class _Planner:
    """What :func:`plan` reads while it places steps: the timeline, the character and the path (N frames)."""

    tl: Timeline
    geo: object  # body.Geometry
    heading: np.ndarray  # (N,) radians
    base: np.ndarray  # (N, 2) metres; shifted in place after each jump

    def stand_spot(self, f: int, when: float) -> tuple[np.ndarray, float]:
        """Where foot ``f`` stands (x, z) and its yaw, beside the path at time ``when``."""
        t, base, tl = self.tl.time, self.base, self.tl
        psi = float(np.interp(when, t, self.heading))
        _, left = _yaw_dirs(psi)
        xz = np.array([np.interp(when, t, base[:, 0]), np.interp(when, t, base[:, 1])])
        xz = xz + left * _SIDES[f] * 0.5 * tl.at("step_width", when) * self.geo.hip_width
        return xz, psi + _SIDES[f] * float(tl.at("toe_out", when))

    def ankle3(self, f: int, xz: np.ndarray) -> np.ndarray:
        return np.array([xz[0], self.geo.ankle_height[f], xz[1]])

    def events(self, phase: np.ndarray) -> list[tuple[float, int, int]]:
        """``(time, kind, index)`` in time order: kind 0 a gait-clock step of foot ``index``,
        1 jump ``index``'s take-off, 2 a settling step (index 0 the first, 1 the second)."""
        t, tl = self.tl.time, self.tl
        events: list[tuple[float, int, int]] = []
        for f in (0, 1):
            offset = 0.5 * f
            levels = np.arange(np.ceil(phase[0] - offset), np.floor(phase[-1] - offset) + 1) + offset
            events += [(float(x), 0, f) for x in np.interp(levels, phase, t)]
        events += [(j.takeoff, 1, k) for k, j in enumerate(tl.jumps)]
        gait = tl.gait
        # coming to a stop: two quick settling steps, the farther foot first (decided when they happen)
        stops = np.flatnonzero((gait[:-1] >= _MOVING) & (gait[1:] < _MOVING)) + 1
        for k in stops:
            events += [(t[k] + _SETTLE_SWING, 2, 0), (t[k] + 2.0 * _SETTLE_SWING, 2, 1)]
        events.sort()
        return events

    def lift_time(self, cur: Plant, when: float, swing: float) -> float:
        """When the foot planted as ``cur`` lifts for a step landing at ``when``.

        No earlier than the foot has stood a moment and no action holds it down; a shorter
        swing is fine (a swing shorter than ``_MIN_SWING`` is skipped by the caller).
        """
        t, leg = self.tl.time, self.geo.leg
        lift = min(when - swing, _falls_behind(cur, t, self.base, self.heading, _MAX_BEHIND * leg))
        lift = max(lift, max(cur.land, cur.flat) + _MIN_STANCE)
        for a, b in self.tl.locks:
            if a < when and b > lift:
                lift = max(lift, b)
        return lift

    def landing(self, f: int, when: float, cycle: float, duty: float, noise: np.ndarray) -> tuple[np.ndarray, float]:
        """Where (x, z) and with which yaw foot ``f`` lands at ``when``: a little before mid-stance, varied by ``noise``."""
        t, tl, geo, base = self.tl.time, self.tl, self.geo, self.base
        g = float(np.interp(when, t, tl.gait))
        xz, yaw = self.stand_spot(f, when + _UNDER_BODY * duty * cycle)
        fwd, left = _yaw_dirs(yaw - _SIDES[f] * float(tl.at("toe_out", when)))
        step = float(tl.at("stride", when)) * geo.leg
        xz = xz + g * (0.03 * step * noise[0] * fwd + 0.04 * geo.hip_width * noise[1] * left)
        yaw = yaw + g * 0.03 * noise[2]
        # never reach farther ahead of the body than a leg can (the mid-stance guess assumes
        # the current cadence, which a transition may change)
        base_now = np.array([np.interp(when, t, base[:, 0]), np.interp(when, t, base[:, 1])])
        ahead = float(np.dot(xz - base_now, fwd))
        return xz - fwd * max(ahead - _MAX_AHEAD * geo.leg, 0.0), yaw

    def step(self, plants: list[list[Plant]], when: float, kind: int, idx: int, noise: np.ndarray) -> None:
        """Take the step of a kind-0 or kind-2 event (see :meth:`events`), unless it is too short or not needed."""
        tl, leg = self.tl, self.geo.leg
        f = idx
        if kind == 2:  # settling step: the foot farther from its spot goes first
            away = [np.linalg.norm(self.stand_spot(k, when)[0] - plants[k][-1].ankle[[0, 2]]) for k in (0, 1)]
            f = int(np.argmax(away)) if idx == 0 else int(np.argmin(away))
        cur = plants[f][-1]
        cycle = 2.0 / float(tl.at("cadence", when))
        duty = float(tl.at("duty", when))
        swing = _SETTLE_SWING if kind == 2 else max((1.0 - duty) * cycle, 0.2)
        lift = self.lift_time(cur, when, swing)
        if when - lift < _MIN_SWING:
            return
        g = float(np.interp(when, tl.time, tl.gait))
        xz, yaw = self.landing(f, when, cycle, duty, noise)
        dist = float(np.linalg.norm(xz - cur.ankle[[0, 2]]))
        if g < _MOVING and dist < _SETTLE * leg:
            return
        scale = float(np.clip(dist / (0.8 * leg), 0.25, 1.0))
        cur.lift = lift
        cur.heel = max(lift - float(np.clip(0.35 * (lift - cur.flat), 0.04, 0.3)), cur.flat)
        cur.p_off = float(tl.at("toe_off", when)) * scale
        p_land = float(tl.at("heel_strike", when)) * scale
        roll = min(0.12, 0.25 * duty * cycle) if p_land != 0.0 else 0.0
        height = float(tl.at("foot_lift", when)) * leg * float(np.clip(0.3 + dist / (0.6 * leg), 0.3, 1.0))
        plants[f].append(Plant(when, when + roll, _FAR, _FAR, self.ankle3(f, xz), yaw, p_land, 0.0, height))


def plan(tl: Timeline, geo, heading: np.ndarray, phase: np.ndarray, base: np.ndarray, rng: np.random.Generator):
    """Place every footstep of the clip.

    Parameters
    ----------
    tl : Timeline                 blended parameters and actions
    geo : body.Geometry           bone lengths and foot shape of the character
    heading : ndarray (N,)        travel direction, radians about +Y
    phase : ndarray (N,)          gait clock in cycles (increasing)
    base : ndarray (N, 2)         planned (x, z) path of the body, metres
    rng : numpy Generator         small random variations of each step

    Returns
    -------
    plants : [left plants, right plants], each a list of :class:`Plant` in time order
    base : ndarray (N, 2)         the path, shifted after each jump to where it landed
    """
    planner = _Planner(tl, geo, heading, base.copy())
    plants: list[list[Plant]] = []
    for f in (0, 1):
        xz, yaw = planner.stand_spot(f, tl.time[0])
        plants.append([Plant(-_FAR, -_FAR, _FAR, _FAR, planner.ankle3(f, xz), yaw)])
    for when, kind, idx in planner.events(phase):
        if kind == 1:
            _jump(tl.jumps[idx], tl, geo, plants, planner.base, heading, planner.ankle3)
            continue
        noise = rng.standard_normal(3)  # drawn for every event, so one skip shifts nothing
        planner.step(plants, when, kind, idx, noise)
    return plants, planner.base


def _falls_behind(plant: Plant, t: np.ndarray, base: np.ndarray, heading: np.ndarray, limit: float) -> float:
    """First time after ``plant`` lands when the path is more than ``limit`` metres ahead of it."""
    fwd, _ = _yaw_dirs(heading)
    ahead = np.sum((base - plant.ankle[[0, 2]]) * fwd, axis=-1)
    late = np.flatnonzero((t > plant.flat) & (ahead > limit))
    return float(t[late[0]]) if late.size else _FAR


def _jump(jump, tl, geo, plants, base, heading, ankle3) -> None:
    t = tl.time
    centre = 0.5 * (plants[0][-1].ankle[[0, 2]] + plants[1][-1].ankle[[0, 2]])
    psi = float(np.interp(jump.takeoff, t, heading))
    fwd, left = _yaw_dirs(psi)
    centre = centre + fwd * jump.distance
    half = 0.5 * float(tl.at("step_width", jump.land)) * geo.hip_width
    toe_out = float(tl.at("toe_out", jump.land))
    for f, side in ((0, 1.0), (1, -1.0)):
        cur = plants[f][-1]
        cur.lift = jump.takeoff
        cur.heel = max(jump.bottom, cur.flat)
        cur.p_off = JUMP_TOE_OFF
        flat = jump.land + 0.5 * (jump.absorb - jump.land)
        plants[f].append(
            Plant(
                jump.land, flat, _FAR, _FAR, ankle3(f, centre + side * half * left), psi + side * toe_out,
                p_land=JUMP_TOE_LAND, swing_height=jump.height, tuck=0.08 * geo.leg, jump=True,
            )
        )  # fmt: skip
    # the body travels with the jump: shift the rest of the path so it is centred on the landing
    landed_at = np.array([np.interp(jump.land, t, base[:, 0]), np.interp(jump.land, t, base[:, 1])])
    ramp = smoothstep((t - jump.takeoff) / max(jump.land - jump.takeoff, 1e-6))
    base += ramp[:, None] * (centre - landed_at)


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def evaluate(plants: list[Plant], t: np.ndarray, toe: np.ndarray, heel: np.ndarray) -> FootTracks:
    """Per-frame targets of one foot from its plants (vectorised over the N frames of ``t``).

    ``toe``/``heel`` (3,): toe joint / heel point relative to the ankle in the rest foot frame.
    """
    get = lambda name: np.array([getattr(p, name) for p in plants], dtype=np.float64)  # noqa: E731
    land, flat, heel_t, lift = get("land"), get("flat"), get("heel"), get("lift")
    yaw, p_land, p_off = get("yaw"), get("p_land"), get("p_off")
    height, tuck, jump = get("swing_height"), get("tuck"), get("jump").astype(bool)
    ankle_flat = np.stack([p.ankle for p in plants])

    i = np.clip(np.searchsorted(land, t, side="right") - 1, 0, len(plants) - 1)
    j = np.minimum(i + 1, len(plants) - 1)
    planted = t <= lift[i]

    # planted: roll onto the flat foot, stay flat, then peel the heel off over the toe
    rolling = t < flat[i]
    peeling = t > heel_t[i]
    roll_pitch = p_land[i] * (1.0 - smoothstep((t - land[i]) / np.maximum(flat[i] - land[i], 1e-9)))
    peel_pitch = p_off[i] * smoothstep((t - heel_t[i]) / np.maximum(lift[i] - heel_t[i], 1e-9))
    plant_pitch = np.where(rolling, roll_pitch, np.where(peeling, peel_pitch, 0.0))
    plant_ankle = foot_pose(ankle_flat[i], yaw[i], plant_pitch, toe, heel)

    # swinging from plant i (heel up) to plant j (touching down)
    u = np.clip((t - lift[i]) / np.maximum(land[j] - lift[i], 1e-9), 0.0, 1.0)
    s = np.where(jump[j], u, smoothstep(u))  # a jump's feet fly at constant horizontal speed
    start = foot_pose(ankle_flat[i], yaw[i], p_off[i], toe, heel)
    end = foot_pose(ankle_flat[j], yaw[j], p_land[j], toe, heel)
    # a step leaves and meets the ground at rest (sin², highest early); a jump's feet fly with the body
    bump = np.where(jump[j], 4.0 * u * (1.0 - u), np.sin(np.pi * u**_SWING_PEAK) ** 2)
    swing_ankle = start + (end - start) * s[:, None]
    swing_ankle[:, 1] += height[j] * bump + tuck[j] * np.sin(np.pi * u) ** 2
    swing_pitch = p_off[i] + (p_land[j] - p_off[i]) * s
    swing_yaw = yaw[i] + _wrap(yaw[j] - yaw[i]) * s
    swing_bend = -np.maximum(p_off[i], 0.0) * (1.0 - smoothstep(u / 0.4)) - np.maximum(p_land[j], 0.0) * smoothstep(
        (u - 0.6) / 0.4
    )
    # never let the toe or the ankle dip below the ground while swinging
    q_foot = quat.mul(quat.from_yaw(swing_yaw), quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), swing_pitch))
    toe_y = swing_ankle[:, 1] + quat.rotate(q_foot, toe)[:, 1]
    swing_ankle[:, 1] += np.maximum(np.maximum(-toe_y, -swing_ankle[:, 1]), 0.0)

    return FootTracks(
        ankle=np.where(planted[:, None], plant_ankle, swing_ankle),
        pitch=np.where(planted, plant_pitch, swing_pitch),
        yaw=np.where(planted, yaw[i], swing_yaw),
        toe_bend=np.where(planted, -np.maximum(plant_pitch, 0.0), swing_bend),
        ankle_contact=planted & ~rolling & ~peeling,
        toe_contact=planted & (plant_pitch >= 0.0),
        heel_down=planted & (plant_pitch <= 0.0),
        swing=np.where(planted | jump[j], -1.0, u),
        lands_heel=p_land[j] <= 0.0,
    )
