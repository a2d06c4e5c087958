"""Actions: the body programmes of jumps and squats, as additive per-frame curves.

Each scheduled :class:`~.timeline.JumpAction` or :class:`~.timeline.SquatAction` adds, on the
padded time grid, a pelvis height change ``dy``, a backwards hip shift ``back``, extra torso
``lean``, an arm raise ``arm`` (shoulder flexion) and extra ``elbow`` flexion. All curves are 0
outside the action, so they simply add on top of the blended standing pose.

A jump's pelvis height is C¹ (continuous with its velocity) through every phase:

* counter-movement: smoothstep down by ``dip``;
* push: cubic Hermite from the bottom at rest to take-off height with upward speed ``v₀ = √(2gh)``;
* flight: ballistic, ``y(u) = lerp(y_takeoff, y_land, u) + 4 h u (1 − u)`` for ``u`` in [0, 1];
* landing: Hermite from ``−v₀`` down to the absorbing dip at rest, then smoothstep back up.

Horizontally the hips move back in the crouch and forward through the push, leaving with the
feet's flight speed ``distance / flight time``.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

import numpy as np

from motionlab.synthetic.timeline import Timeline, ease_track, smoothstep

__all__ = ["curves", "hermite"]

CURVES: tuple[str, ...] = ("dy", "back", "lean", "arm", "elbow")


def hermite(t, t0: float, t1: float, p0: float, p1: float, v0: float, v1: float) -> np.ndarray:
    """Cubic with value ``p0``/``p1`` and slope ``v0``/``v1`` (per second) at ``t0``/``t1``."""
    span = max(t1 - t0, 1e-9)
    s = np.clip((np.asarray(t, dtype=np.float64) - t0) / span, 0.0, 1.0)
    m0, m1 = v0 * span, v1 * span
    return (
        (2 * s**3 - 3 * s**2 + 1) * p0 + (s**3 - 2 * s**2 + s) * m0 + (-2 * s**3 + 3 * s**2) * p1 + (s**3 - s**2) * m1
    )


def _jump_height(t: np.ndarray, j, rise_takeoff: float, rise_land: float) -> np.ndarray:
    v0 = j.takeoff_speed
    u = np.clip((t - j.takeoff) / max(j.land - j.takeoff, 1e-9), 0.0, 1.0)
    pieces = [
        (t < j.bottom, -j.dip * smoothstep((t - j.crouch) / max(j.bottom - j.crouch, 1e-9))),
        (t < j.takeoff, hermite(t, j.bottom, j.takeoff, -j.dip, rise_takeoff, 0.0, v0)),
        (t < j.land, rise_takeoff + (rise_land - rise_takeoff) * u + 4.0 * j.height * u * (1.0 - u)),
        (t < j.absorb, hermite(t, j.land, j.absorb, rise_land, -j.dip_land, -v0, 0.0)),
    ]
    out = -j.dip_land * (1.0 - smoothstep((t - j.absorb) / max(j.recover - j.absorb, 1e-9)))
    for mask, value in reversed(pieces):
        out = np.where(mask, value, out)
    return np.where(t < j.crouch, 0.0, out)


def _jump_back(t: np.ndarray, j, leg: float) -> np.ndarray:
    """Hips behind the feet (metres): back in the counter-movement, then forward through the
    push so the pelvis leaves with the feet's horizontal flight speed, and back on landing."""
    glide = j.distance / max(j.land - j.takeoff, 1e-9)  # the feet's horizontal speed in flight
    crouched, landed = 0.12 * leg * j.vigour, 0.1 * leg * j.vigour
    pieces = [
        (t < j.bottom, crouched * smoothstep((t - j.crouch) / max(j.bottom - j.crouch, 1e-9))),
        (t < j.takeoff, hermite(t, j.bottom, j.takeoff, crouched, 0.0, 0.0, -glide)),
        (t < j.land, np.zeros_like(t)),
        (t < j.absorb, hermite(t, j.land, j.absorb, 0.0, landed, -glide, 0.0)),
    ]
    out = landed * (1.0 - smoothstep((t - j.absorb) / max(j.recover - j.absorb, 1e-9)))
    for mask, value in reversed(pieces):
        out = np.where(mask, value, out)
    return np.where(t < j.crouch, 0.0, out)


def curves(tl: Timeline, leg: float, rise_takeoff: float, rise_land: float) -> dict[str, np.ndarray]:
    """Sum of every action's additive curves on the grid ``tl.time``.

    Parameters
    ----------
    tl : Timeline
    leg : float             leg length, metres
    rise_takeoff : float    pelvis height at take-off above standing (heels raised, knees
                            slightly bent), metres
    rise_land : float       pelvis height at touch-down above standing (toes first), metres

    Returns
    -------
    dict with ``dy`` and ``back`` (N,) in metres, ``lean``, ``arm``, ``elbow`` (N,) in radians
    """
    t = tl.time
    out = {name: np.zeros_like(t) for name in CURVES}
    for j in tl.jumps:
        keys = [j.crouch, j.bottom, j.takeoff, j.land, j.absorb, j.recover]
        out["dy"] += _jump_height(t, j, rise_takeoff, rise_land)
        v = j.vigour
        out["back"] += _jump_back(t, j, leg)
        out["lean"] += v * ease_track(t, keys, [0.0, 0.4, -0.05, 0.1, 0.35, 0.0])
        swing_keys = [j.crouch, j.bottom, j.takeoff + 0.5 * (j.land - j.takeoff), j.land, j.absorb, j.recover]
        out["arm"] += v * ease_track(t, swing_keys, [0.0, -0.6, 1.3, 0.8, 0.5, 0.0])
        out["elbow"] += v * ease_track(t, keys, [0.0, 0.25, 0.1, 0.3, 0.3, 0.0])
    for s in tl.squats:
        depth = ease_track(t, [s.start, s.bottom, s.rise, s.end], [0.0, 1.0, 1.0, 0.0])
        ratio = s.depth / leg
        out["dy"] -= s.depth * depth
        out["back"] += 0.55 * s.depth * depth
        out["lean"] += 1.3 * ratio * depth
        # arms forward to about horizontal: the shoulder angle is relative to the leaning chest
        out["arm"] += (1.35 * min(1.0, 2.5 * ratio) + 1.3 * ratio) * depth
        out["elbow"] -= 0.1 * depth
    return out
