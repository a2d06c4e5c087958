"""Root alignment (paper C, eq. 3): bring one motion into another's frame before blending.

Two clips start wherever and facing wherever their capture put them. Before interpolating from
frame ``A(m)`` to frame ``B(n)``, the whole of ``B`` is moved rigidly by

.. math::  P_A(t) = T_{\\theta, x, y, z}\\, P_B(t), \\qquad
           T: \\; p \\mapsto R_y(\\theta)\\, p + (x, y, z)^\\top,

a rotation by θ about the vertical (+Y) axis and a translation. Rotating about any other axis would
tilt the character off the ground, so only the heading changes. θ is the difference of the two
frames' headings and the translation moves ``B(n)``'s root onto ``A(m)``'s; by default only the
horizontal part (``y = 0``) is used, so the character keeps its own height above the floor.

:func:`fit_points` solves the same problem in the least-squares sense for two point clouds
(2-D Procrustes about the vertical), as motion-graph distances do.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import quat
from motionlab.core.fk import fk
from motionlab.core.motion import Motion

__all__ = [
    "RigidYaw",
    "reference_joint",
    "reference_transform",
    "carry_by_reference",
    "estimate",
    "fit_points",
    "apply",
    "align_to",
]


@dataclass(frozen=True)
class RigidYaw:
    """The transform ``p ↦ R_y(theta) p + translation``.

    Attributes
    ----------
    theta : float                      rotation about +Y, radians
    translation : ndarray, shape (3,)  metres
    """

    theta: float
    translation: np.ndarray

    @property
    def rotation(self) -> np.ndarray:
        """The quaternion (4,) of ``R_y(theta)``."""
        return quat.from_yaw(self.theta)

    def apply_points(self, p) -> np.ndarray:
        """Transform points (..., 3)."""
        return quat.rotate(self.rotation, np.asarray(p, dtype=np.float64)) + self.translation

    def apply_rotations(self, q) -> np.ndarray:
        """Transform global rotations (..., 4): ``R_y(theta) ⊗ q``."""
        return quat.mul(self.rotation, q)

    def inverse(self) -> RigidYaw:
        inv_rot = quat.from_yaw(-self.theta)
        return RigidYaw(-self.theta, -quat.rotate(inv_rot, self.translation))


def reference_joint(motion: Motion) -> int:
    """The joint that carries the character through the world.

    Usually the root (0). Some rigs (Bandai Namco) keep the root fixed at the origin and move the
    hips with position channels; then the non-root joint whose translation varies most is used.
    """
    if np.ptp(motion.root_pos, axis=0).max(initial=0.0) > 1e-6 or motion.local_pos is None:
        return 0
    spread = np.ptp(motion.local_pos[:, 1:], axis=0).max(axis=-1)
    return int(np.argmax(spread)) + 1 if spread.size and spread.max() > 1e-6 else 0


def reference_transform(motion: Motion, frames=None, joint: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Global rotation (..., 4) and position (..., 3) of the reference joint at ``frames``."""
    j = reference_joint(motion) if joint is None else int(joint)
    sel = slice(None) if frames is None else frames
    if j == 0:
        return motion.local_rot[sel, 0], motion.root_pos[sel]
    rot, pos = fk(motion.local_rot[sel], motion.translations()[sel], motion.skeleton.parents)
    return rot[..., j, :], pos[..., j, :]


def carry_by_reference(motion: Motion, a: int, b: int, joint: int | None = None) -> Motion:
    """A copy of ``motion`` whose frames ``a+1 … b-1`` carry the body by the reference joint, as
    the recording does.

    Filling a gap moves and turns the body through joint 0 (the root's translation and rotation).
    On a rig whose reference joint ``j`` lies below joint 0 (:func:`reference_joint`: Bandai Namco's
    ``joint_Root`` held at the origin while the hips' channels carry the walker) that moves the
    joints above ``j`` off the place the recording keeps them in, and they jump back at frame ``b``.
    Here the joints from 0 down to ``j``'s parent take, on frames ``a+1 … b-1``, the values
    interpolated between the known frames ``a`` and ``b`` (SLERP for rotations, linear for
    translations: held where the recording holds them), and ``j``'s local rotation and translation
    take over the difference, so that ``j`` and every joint below it keep their world rotations and
    positions. Joints hanging off the chain above ``j`` elsewhere follow the interpolated chain.
    With ``j = 0`` the copy equals ``motion``.

    Parameters
    ----------
    motion : Motion, finite at frames ``a … b``
    a, b : int, known frames bounding the filled frames, ``0 <= a < b < T``
    joint : the reference joint; default :func:`reference_joint` of the finite frames outside
        ``a+1 … b-1`` (the filled frames would hide a still joint 0)

    Raises
    ------
    ValueError
        ``a``, ``b`` out of order or range, non-finite frames ``a … b``, or a reference joint below
        joint 0 in a motion without per-frame translations (``local_pos``), which could not carry it.
    """
    a, b = int(a), int(b)
    if not 0 <= a < b < motion.num_frames:
        raise ValueError(f"expected known frames 0 <= a < b < {motion.num_frames}, got a={a}, b={b}")
    j = _reference_outside(motion, a, b) if joint is None else int(joint)
    out = motion.copy()
    if j == 0 or b - a < 2:
        return out
    if motion.local_pos is None:
        name = motion.skeleton.names[j]
        raise ValueError(f"joint {name!r} cannot carry the body: the motion has no per-frame translations (local_pos)")
    frames = np.arange(a, b + 1)
    trans = motion.translations()[frames]
    if not (np.all(np.isfinite(trans)) and np.all(np.isfinite(motion.local_rot[frames]))):
        raise ValueError(f"frames {a} … {b} must be finite before the body can be carried by joint {j}")
    parents = motion.skeleton.parents
    g_rot, g_pos = fk(motion.local_rot[frames], trans, parents)
    chain = np.asarray(motion.skeleton.ancestors(j), dtype=np.int64)
    w = ((frames[1:-1] - a) / (b - a))[:, None]  # (F, 1)
    inner = frames[1:-1]
    out.local_rot[np.ix_(inner, chain)] = quat.slerp(motion.local_rot[a, chain], motion.local_rot[b, chain], w)
    out.local_pos[np.ix_(inner, chain)] = trans[0, chain] + w[..., None] * (trans[-1, chain] - trans[0, chain])
    out.root_pos[inner] = out.local_pos[inner, 0]
    new_rot, new_pos = fk(out.local_rot[inner], out.translations()[inner], parents)
    p = parents[j]
    turn_back = quat.inv(new_rot[:, p])
    out.local_rot[inner, j] = quat.normalize(quat.mul(turn_back, g_rot[1:-1, j]))
    out.local_pos[inner, j] = quat.rotate(turn_back, g_pos[1:-1, j] - new_pos[:, p])
    return out


def _reference_outside(motion: Motion, a: int, b: int) -> int:
    """:func:`reference_joint` of the finite frames of ``motion`` outside ``a+1 … b-1``."""
    frames = np.r_[0 : a + 1, b : motion.num_frames]
    frames = frames[np.all(np.isfinite(motion.root_pos[frames]), axis=1)]
    return reference_joint(motion[frames])


def estimate(rot_a, pos_a, rot_b, pos_b, vertical: bool = False) -> RigidYaw:
    """The transform taking reference frame ``b`` onto reference frame ``a``.

    Parameters
    ----------
    rot_a, rot_b : array (4,)   global rotations of the reference joint (heading is read with
                                :func:`motionlab.core.quat.yaw`)
    pos_a, pos_b : array (3,)   its global positions, metres
    vertical : bool             also translate along y (default: horizontal only)

    Returns
    -------
    RigidYaw ``T`` with ``yaw(T.rotation ⊗ rot_b) = yaw(rot_a)`` and ``T(pos_b) = pos_a``
    (in x and z; in y too when ``vertical``).

    Raises
    ------
    ValueError unless the rotations are (4,) and the positions (3,).
    """
    rot_a, rot_b = quat.check(rot_a, "rot_a"), quat.check(rot_b, "rot_b")
    pos_a, pos_b = np.asarray(pos_a, dtype=np.float64), np.asarray(pos_b, dtype=np.float64)
    if rot_a.shape != (4,) or rot_b.shape != (4,) or pos_a.shape != (3,) or pos_b.shape != (3,):
        raise ValueError(
            f"expected one frame each: rotations (4,) and positions (3,), got {rot_a.shape}, {pos_a.shape}, "
            f"{rot_b.shape}, {pos_b.shape}"
        )
    theta = float(np.angle(np.exp(1j * (quat.yaw(rot_a) - quat.yaw(rot_b)))))
    t = pos_a - quat.rotate(quat.from_yaw(theta), pos_b)
    if not vertical:
        t[1] = 0.0
    return RigidYaw(theta, t)


def fit_points(points_a, points_b, weights=None) -> RigidYaw:
    """Least-squares yaw + horizontal translation with ``T(points_b) ≈ points_a``.

    Minimises ``Σ w_i |a_i − (R_y(θ) b_i + t)|²`` over θ and ``t = (t_x, 0, t_z)``; with centred
    x/z coordinates the optimum is ``θ = atan2(Σ w (a_x b_z − a_z b_x), Σ w (a_x b_x + a_z b_z))``.

    Parameters
    ----------
    points_a, points_b : array, shape (P, 3)   corresponding points, metres
    weights : array (P,), optional             non-negative weights (default: all 1)

    Raises
    ------
    ValueError unless the point sets are two (P, 3) arrays of equal shape and the weights
    (P,), non-negative, with a positive sum.
    """
    a, b = np.asarray(points_a, dtype=np.float64), np.asarray(points_b, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"expected two (P, 3) point sets of equal shape, got {a.shape} and {b.shape}")
    w = np.ones(len(a)) if weights is None else np.asarray(weights, dtype=np.float64)
    if w.shape != (len(a),) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError(f"expected {len(a)} non-negative weights with a positive sum")
    w = w / w.sum()
    ca, cb = w @ a, w @ b
    da, db = a - ca, b - cb
    num = np.sum(w * (da[:, 0] * db[:, 2] - da[:, 2] * db[:, 0]))
    den = np.sum(w * (da[:, 0] * db[:, 0] + da[:, 2] * db[:, 2]))
    theta = float(np.arctan2(num, den))
    t = ca - quat.rotate(quat.from_yaw(theta), cb)
    t[1] = 0.0
    return RigidYaw(theta, t)


def apply(motion: Motion, transform: RigidYaw) -> Motion:
    """A copy of ``motion`` moved rigidly by ``transform`` (root rotation and position)."""
    rot = motion.local_rot.copy()
    rot[:, 0] = transform.apply_rotations(motion.local_rot[:, 0])
    return motion.copy(local_rot=rot, root_pos=transform.apply_points(motion.root_pos))


def align_to(motion: Motion, target: Motion, frame: int = 0, to_frame: int = -1, vertical: bool = False) -> Motion:
    """``motion`` moved so that its frame ``frame`` has the heading and ground position of
    ``target``'s frame ``to_frame`` (eq. 3)."""
    j = reference_joint(target)
    ra, pa = reference_transform(target, [to_frame], joint=j)
    rb, pb = reference_transform(motion, [frame], joint=j)
    return apply(motion, estimate(ra[0], pa[0], rb[0], pb[0], vertical=vertical))
