"""Style: the knobs of the procedural motion generator, with a default set per behaviour.

Lengths are fractions of the character's leg length (thigh + shin) or of its hip width, so
one style fits every body; angles are radians, times seconds. A behaviour's defaults are
:func:`default_style`; pass a :class:`Style` or a dict of overrides to the generator::

    gaits.generate("walk", skeleton, 240, style={"stride": 0.9, "arm_swing": 0.5})

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

__all__ = ["BEHAVIOURS", "Style", "default_style", "resolve_style", "random_style"]

BEHAVIOURS: tuple[str, ...] = ("idle", "walk", "run", "jump", "squat")
"""The behaviours the generator knows."""


@dataclass(frozen=True)
class Style:
    """How a behaviour is performed.

    Attributes
    ----------
    stride : float        step length (one foot to the other) / leg length

    cadence : float       steps per second (also the clock of settling steps when standing)
    duty : float          fraction of a gait cycle each foot spends on the ground (walk > 0.5,
                          run < 0.5: both feet in the air between steps)
    foot_lift : float     swing clearance of the ankle / leg length
    bounce : float        vertical pelvis oscillation / leg length; > 0 highest at mid-stance
                          (walking, inverted pendulum), < 0 lowest at mid-stance (running, spring)
    crouch : float        pelvis lowered below standing height / leg length
    lean : float          forward torso lean, radians
    arm_swing : float     shoulder swing amplitude, radians (opposite to the legs)
    elbow : float         elbow flexion, radians
    arm_out : float       arm abduction, radians (keeps the hands off the body)
    step_width : float    lateral distance between the feet / hip width
    toe_out : float       outward foot yaw, radians
    heel_strike : float   foot pitch at touch-down, radians (< 0: heel first)
    toe_off : float       foot pitch at lift-off, radians (> 0: heel raised, rolling on the toes)
    hip_twist : float     pelvis yaw amplitude, radians (the chest counter-rotates)
    sway : float          lateral weight shift / leg length
    turn_rate : float     heading change, radians per second (> 0 turns left, towards +X)
    jump_height : float   rise of the pelvis during a jump's flight / leg length
    jump_distance : float horizontal distance covered by a jump / leg length
    squat_depth : float   pelvis drop at the bottom of a squat / leg length
    period : float        seconds from one jump or squat to the next; 0: as fast as natural

    The stepping knobs ``cadence``, ``duty``, ``foot_lift``, ``heel_strike`` and ``toe_off``
    also shape the settling steps of the standing behaviours; ``stride``, ``turn_rate``,
    ``bounce``, ``hip_twist`` and ``arm_swing`` act only while walking or running. A planted
    foot travels ``2 · duty · stride`` leg lengths relative to the body; far above 1 the feet
    cannot keep up (the planner lifts them early and the pelvis sinks), which no gait does.
    """

    stride: float = 0.0
    cadence: float = 1.6
    duty: float = 0.7
    foot_lift: float = 0.08
    bounce: float = 0.0
    crouch: float = 0.01
    lean: float = 0.03
    arm_swing: float = 0.0
    elbow: float = 0.15
    arm_out: float = 0.2
    step_width: float = 1.1
    toe_out: float = 0.12
    heel_strike: float = 0.0
    toe_off: float = 0.15
    hip_twist: float = 0.0
    sway: float = 0.025
    turn_rate: float = 0.0
    jump_height: float = 0.3
    jump_distance: float = 0.0
    squat_depth: float = 0.45
    period: float = 0.0

    def replace(self, **changes) -> Style:
        """A copy with some fields changed (checked like the constructor's)."""
        return resolve_style(self, changes)


_DEFAULTS: dict[str, Style] = {
    "idle": Style(),
    "walk": Style(
        stride=0.78, cadence=1.85, duty=0.62, foot_lift=0.08, bounce=0.02, crouch=0.015, lean=0.05,
        arm_swing=0.3, elbow=0.3, arm_out=0.18, step_width=0.9, toe_out=0.1, heel_strike=-0.25,
        toe_off=0.6, hip_twist=0.08, sway=0.02,
    ),
    "run": Style(
        stride=1.45, cadence=2.8, duty=0.36, foot_lift=0.3, bounce=-0.045, crouch=0.05, lean=0.14,
        arm_swing=0.55, elbow=1.45, arm_out=0.25, step_width=0.6, toe_out=0.05, heel_strike=-0.08,
        toe_off=0.8, hip_twist=0.12, sway=0.01,
    ),
    "jump": Style(arm_out=0.25, step_width=1.0, toe_out=0.1, jump_height=0.3, jump_distance=0.3, sway=0.01),
    "squat": Style(step_width=1.3, toe_out=0.3, squat_depth=0.45, sway=0.005),
}  # fmt: skip

# allowed ranges: wide enough for caricature, narrow enough that the geometry stays solvable
_RANGES: dict[str, tuple[float, float]] = {
    "stride": (0.0, 2.0),
    "cadence": (0.8, 4.0),
    "duty": (0.25, 0.85),
    "foot_lift": (0.0, 0.5),
    "bounce": (-0.1, 0.1),
    "crouch": (0.0, 0.3),
    "lean": (-0.3, 0.6),
    "arm_swing": (0.0, 1.0),
    "elbow": (0.0, 2.2),
    "arm_out": (0.05, 0.8),
    "step_width": (0.0, 2.5),
    "toe_out": (-0.3, 0.6),
    "heel_strike": (-0.5, 0.3),
    "toe_off": (0.0, 1.0),
    "hip_twist": (0.0, 0.4),
    "sway": (0.0, 0.1),
    "turn_rate": (-1.5, 1.5),
    "jump_height": (0.02, 0.8),
    "jump_distance": (0.0, 1.5),
    "squat_depth": (0.0, 0.7),
    "period": (0.0, 20.0),
}

FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(Style))


def _check_behaviour(behaviour: str) -> str:
    if behaviour not in BEHAVIOURS:
        raise ValueError(f"unknown behaviour {behaviour!r}; expected one of {BEHAVIOURS}")
    return behaviour


def default_style(behaviour: str) -> Style:
    """The default :class:`Style` of ``behaviour`` (one of :data:`BEHAVIOURS`)."""
    return _DEFAULTS[_check_behaviour(behaviour)]


def resolve_style(base: Style, style: Style | Mapping[str, float] | None) -> Style:
    """``style`` itself, or ``base`` with the overrides of a dict; every field range-checked.

    Raises
    ------
    ValueError naming the field, the value and the allowed range.
    """
    if style is None:
        out = base
    elif isinstance(style, Style):
        out = style
    elif isinstance(style, Mapping):
        unknown = sorted(set(style) - set(FIELDS))
        if unknown:
            raise ValueError(f"unknown style fields {unknown}; expected some of {FIELDS}")
        out = dataclasses.replace(base, **{k: float(v) for k, v in style.items()})
    else:
        raise ValueError(f"expected style as a Style, a dict of overrides or None, got {type(style).__name__}")
    for name in FIELDS:
        value = getattr(out, name)
        lo, hi = _RANGES[name]
        if not (np.isfinite(value) and lo <= value <= hi):
            raise ValueError(f"style field {name!r} must lie in [{lo}, {hi}], got {value}")
    return out


def random_style(behaviour: str, rng: np.random.Generator, amount: float = 1.0) -> Style:
    """The default style of ``behaviour`` with every knob jittered (a different performer).

    ``amount`` scales the jitter (0: the defaults). Turning is added to locomotion half the time.
    """
    s = default_style(behaviour)
    u = lambda lo, hi: 1.0 + amount * rng.uniform(lo, hi)  # noqa: E731
    a = lambda lo, hi: amount * rng.uniform(lo, hi)  # noqa: E731
    changes = {
        "stride": s.stride * u(-0.2, 0.2),
        "cadence": s.cadence * u(-0.1, 0.1),
        "foot_lift": s.foot_lift * u(-0.25, 0.25),
        "bounce": s.bounce * u(-0.3, 0.3),
        "crouch": s.crouch + a(0.0, 0.04),
        "lean": s.lean + a(-0.04, 0.1),
        "arm_swing": s.arm_swing * u(-0.4, 0.4),
        "elbow": s.elbow + a(-0.1, 0.3),
        "arm_out": s.arm_out + a(0.0, 0.12),
        "step_width": s.step_width * u(-0.15, 0.15),
        "toe_out": s.toe_out + a(-0.05, 0.08),
        "hip_twist": s.hip_twist * u(-0.3, 0.3),
        "sway": s.sway * u(-0.3, 0.3),
        "jump_height": s.jump_height * u(-0.3, 0.3),
        "jump_distance": s.jump_distance * u(-0.8, 0.8),
        "squat_depth": s.squat_depth * u(-0.3, 0.15),
    }
    if behaviour in ("walk", "run") and rng.random() < 0.5:
        changes["turn_rate"] = amount * rng.uniform(-0.5, 0.5)
    changes = {k: float(np.clip(v, *_RANGES[k])) for k, v in changes.items()}
    return dataclasses.replace(s, **changes)
