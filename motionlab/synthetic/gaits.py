"""Procedural humanoid motion: idle, walk, run, jump and squat on any 22-joint character.

This is motionlab's built-in data: everything runs on a fresh machine without downloads::

    from motionlab.synthetic import gaits
    walk = gaits.generate("walk", skeleton, num_frames=240, fps=60, seed=0)
    clip = gaits.sequence([("idle", 60), ("walk", 120), ("run", 120), ("jump", 60), ("squat", 90)],
                          skeleton, fps=60, seed=0)

How a clip is made (each step vectorised over frames):

1. :mod:`~.timeline` blends the segments' :class:`~.style.Style` into per-frame parameters
   (cross-fades of ``blend`` seconds) and schedules jumps and squats;
2. the heading integrates ``turn_rate``; the gait clock (phase, in cycles) integrates
   ``cadence / 2``; the planned path integrates ``stride · leg · cadence`` along the heading;
3. :mod:`~.footsteps` plants each foot where the body will be at mid-stance, so a planted foot
   never slides, and swings it along an arc between plants;
4. :mod:`~.body` places the pelvis over the feet (clamped so the legs reach), solves the legs
   with two-bone IK (:mod:`~.ik`), and adds spine counter-rotation, arm swing and a steady head.

The result is deterministic under ``seed``: the seed drives small variations of step timing,
placement and arm swing, and the idle sway. Units: metres, radians; Y up; the character faces
+Z at frame 0 with its root above the origin.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from motionlab.core.humanoid import canonical_skeleton, is_canonical
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.synthetic import actions, footsteps
from motionlab.synthetic.body import Geometry, pose
from motionlab.synthetic.style import BEHAVIOURS, Style, default_style, resolve_style
from motionlab.synthetic.timeline import build

__all__ = ["generate", "sequence", "BEHAVIOURS"]


def _check_skeleton(skeleton: Skeleton | None) -> Skeleton:
    if skeleton is None:
        return canonical_skeleton()
    if not isinstance(skeleton, Skeleton) or not is_canonical(skeleton):
        got = (
            f"{skeleton.num_joints} joints starting {skeleton.names[:3]}"
            if isinstance(skeleton, Skeleton)
            else type(skeleton).__name__
        )
        raise ValueError(
            f"expected a canonical 22-joint humanoid skeleton (motionlab.core.humanoid.JOINTS), got {got}; "
            "reduce a rig with humanoid.to_canonical_skeleton first"
        )
    geo = Geometry.from_skeleton(skeleton)
    if not (geo.leg > 1e-3 and geo.hip_width > 1e-4):
        raise ValueError(f"skeleton legs are degenerate: leg length {geo.leg:.4g} m, hip width {geo.hip_width:.4g} m")
    return skeleton


def _check_segments(segments) -> list[tuple[str, int, Style]]:
    if isinstance(segments, (str, bytes)) or not isinstance(segments, Sequence) or len(segments) == 0:
        raise ValueError(f"expected a non-empty list of (behaviour, num_frames[, style]) tuples, got {segments!r}")
    out = []
    for k, item in enumerate(segments):
        if not isinstance(item, (tuple, list)) or len(item) not in (2, 3):
            raise ValueError(
                f"segment {k}: expected (behaviour, num_frames) or (behaviour, num_frames, style), got {item!r}"
            )
        behaviour, frames = item[0], item[1]
        if behaviour not in BEHAVIOURS:
            raise ValueError(f"segment {k}: unknown behaviour {behaviour!r}; expected one of {BEHAVIOURS}")
        if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 1:
            raise ValueError(f"segment {k} ({behaviour}): num_frames must be a positive integer, got {frames!r}")
        style = item[2] if len(item) == 3 else None
        out.append((behaviour, int(frames), resolve_style(default_style(behaviour), style)))
    return out


def _smooth_noise(rng: np.random.Generator, t: np.ndarray, hz: float, waves: int = 3) -> np.ndarray:
    """A slow random signal (N,) in [-1, 1]: a sum of sines with random frequencies and phases."""
    freqs = hz * rng.uniform(0.6, 1.4, waves)
    phases = rng.uniform(0.0, 2.0 * np.pi, waves)
    return np.mean(np.sin(2.0 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]), axis=0)


def sequence(
    segments: Sequence[tuple],
    skeleton: Skeleton | None = None,
    fps: float = 60.0,
    seed: int = 0,
    blend: float = 0.4,
    return_contacts: bool = False,
) -> Motion | tuple[Motion, np.ndarray]:
    """Behaviours one after another with smooth transitions.

    Parameters
    ----------
    segments : list of ``(behaviour, num_frames)`` or ``(behaviour, num_frames, style)``
        behaviour in :data:`BEHAVIOURS`; style a :class:`Style` or a dict of overrides of the
        behaviour's defaults (:func:`~.style.default_style`).
    skeleton : canonical 22-joint Skeleton (any proportions); ``None``: ``canonical_skeleton()``
    fps : float          frames per second
    seed : int           seed of the small random variations
    blend : float        cross-fade duration at each boundary, seconds
    return_contacts : bool   also return the foot contact labels

    Returns
    -------
    motion : Motion with T = Σ num_frames frames, named ``"idle>walk>…"``
    contacts : ndarray of bool, shape (T, 4), only if ``return_contacts``
        whether each joint of :data:`~motionlab.core.humanoid.FEET` (LeftFoot, RightFoot,
        LeftToeBase, RightToeBase) is planted on the ground in that frame.

    Raises
    ------
    ValueError unless ``fps`` > 0 and ``blend`` >= 0 (finite).
    """
    skeleton = _check_skeleton(skeleton)
    segs = _check_segments(segments)
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a positive number, got {fps}")
    if not (np.isfinite(blend) and blend >= 0):
        raise ValueError(f"blend must be a non-negative number of seconds, got {blend}")
    geo = Geometry.from_skeleton(skeleton)
    tl = build(segs, geo.leg, float(fps), float(blend))
    rng = np.random.default_rng(seed)
    t, first, dt = tl.time, tl.first, 1.0 / tl.fps
    P = tl.params

    # travel direction, gait clock and planned path
    heading = np.cumsum(P["turn_rate"]) * dt
    heading -= heading[first]
    rate = 0.5 * P["cadence"] * (1.0 + 0.03 * _smooth_noise(rng, t, 0.4))
    phase = np.cumsum(rate) * dt
    phase += rng.uniform(0.0, 1.0) - phase[first]
    speed = P["stride"] * geo.leg * P["cadence"]
    base = np.cumsum(speed[:, None] * np.stack([np.sin(heading), np.cos(heading)], axis=-1), axis=0) * dt
    base -= base[first]
    noise = {
        name: _smooth_noise(rng, t, hz) for name, hz in (("sway", 0.2), ("look", 0.15), ("arm", 0.5), ("breath", 0.25))
    }

    plants, base = footsteps.plan(tl, geo, heading, phase, base, rng)
    feet = [footsteps.evaluate(plants[f], t, geo.toe[f], geo.heel[f]) for f in (0, 1)]
    extra = actions.curves(
        tl, geo.leg, geo.rise_on_toes(footsteps.JUMP_TOE_OFF), geo.rise_on_toes(footsteps.JUMP_TOE_LAND)
    )
    local_rot, root = pose(geo, tl, heading, phase, base, feet, extra, noise)

    frames = slice(first, first + tl.num_frames)
    root = root[frames].copy()
    root[:, [0, 2]] -= root[0, [0, 2]]
    name = ">".join(b for b, _, _ in segs)
    motion = Motion(skeleton, local_rot[frames], root, float(fps), name=name)
    if not return_contacts:
        return motion
    contacts = np.stack(
        [feet[0].ankle_contact, feet[1].ankle_contact, feet[0].toe_contact, feet[1].toe_contact], axis=-1
    )[frames]
    return motion, contacts


def generate(
    behaviour: str,
    skeleton: Skeleton | None = None,
    num_frames: int = 240,
    fps: float = 60.0,
    style: Style | Mapping[str, float] | None = None,
    seed: int = 0,
    return_contacts: bool = False,
) -> Motion | tuple[Motion, np.ndarray]:
    """One behaviour for ``num_frames`` frames; see :func:`sequence` for the parameters.

    Examples
    --------
    >>> m = generate("run", num_frames=120, style={"stride": 1.6}, seed=3)
    >>> m.local_rot.shape, m.fps
    ((120, 22, 4), 60.0)
    """
    return sequence([(behaviour, num_frames, style)], skeleton, fps, seed, return_contacts=return_contacts)
