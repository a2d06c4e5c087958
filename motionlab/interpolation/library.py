"""Key-pose-guided in-betweening: fill a gap with the best-matching stretch of recorded motion.

SLERP between two poses makes legs glide: half a second of walking is not a straight path
through pose space. The action graph's nodes hold real recordings of each action, so a gap of
``N`` frames between a known frame ``a`` and a known frame ``b`` can be filled by

1. **search** — among all library frames ``s`` (of the allowed action nodes), the stretch
   ``s … s+L`` (``L = N + 1``) whose ends look like the gap's ends, minimising

   .. math::  c(s) = \\lVert P_a - P_s\\rVert^2 + w_v^2 \\lVert V_a - V_s\\rVert^2
              + \\lVert P_b - P_{s+L}\\rVert^2 + w_d^2 \\lVert \\Delta_{ab} - \\Delta_{s,s+L}\\rVert^2

   with ``P`` heading-frame joint positions, ``V`` joint velocities (both from :mod:`.features`)
   and ``Δ`` the root's ground displacement and turn across the gap, seen from the first frame —
   the minimum inter-frame distance of the paper, applied at both ends at once;
2. **root alignment** (eq. 3) of the stretch onto frame ``a``: yaw about +Y and a floor translation;
3. **blending** the remaining mismatch away: with ``α_k = k / L``,

   .. math::  q_k = \\operatorname{slerp}(\\delta_a, \\delta_b, \\alpha_k) \\otimes q^{s}_{k}, \\quad
              \\delta_a = q_a (q^s_0)^{-1},\\; \\delta_b = q_b (q^s_L)^{-1},

   and the same linear blend of offsets for root (and joint) translations, so the result meets
   both known frames exactly and keeps the recording's detail in between.

The ``k`` best stretches can be averaged (sign-aligned quaternion mean) to reduce variance.
Everything is batched over gaps (windows): one matrix product scores every candidate.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motionlab.core import quat
from motionlab.core.fk import fk
from motionlab.core.motion import Motion, check_one_rig
from motionlab.interpolation.alignment import reference_joint
from motionlab.interpolation.features import VELOCITY_WEIGHT, heading_frame

__all__ = ["MotionLibrary"]


def _wrap(a):
    return np.angle(np.exp(1j * a))


class MotionLibrary:
    """Recorded clips of one skeleton, indexed for gap filling.

    Parameters
    ----------
    motions : sequence of Motion     clips on one skeleton (same joint names and parents), one fps
    labels : sequence of str, optional   the action of each clip (used to restrict searches)
    velocity_weight : float          ``w_v`` in seconds
    displacement_weight : float      ``w_d`` (dimensionless, times √J internally)
    """

    def __init__(
        self,
        motions: Sequence[Motion],
        labels: Sequence[str] | None = None,
        velocity_weight: float = VELOCITY_WEIGHT,
        displacement_weight: float = 1.0,
    ) -> None:
        """Index the clips (and their labels) for searches.

        Raises
        ------
        ValueError for no clip, or a label count other than the clip count.
        """
        motions = list(motions)
        if not motions:
            raise ValueError("a motion library needs at least one clip")
        check_one_rig(motions, group="the library")
        sk = motions[0].skeleton
        self.labels = [str(lab) for lab in labels] if labels is not None else [m.name for m in motions]
        if len(self.labels) != len(motions):
            raise ValueError(f"expected {len(motions)} labels, got {len(self.labels)}")
        self.skeleton = sk
        self.parents = sk.parents
        self.fps = motions[0].fps
        self.ref = reference_joint(motions[0])
        self.names = [m.name for m in motions]
        self.velocity_weight = float(velocity_weight)
        self.displacement_weight = float(displacement_weight)
        self.local_rot = np.concatenate([m.local_rot for m in motions])
        self.trans = np.concatenate([m.translations() for m in motions])
        self.clip = np.concatenate([np.full(m.num_frames, i) for i, m in enumerate(motions)])
        self.frame = np.concatenate([np.arange(m.num_frames) for m in motions])
        self.length = np.array([m.num_frames for m in motions])[self.clip]
        g_rot, g_pos = fk(self.local_rot, self.trans, self.parents)
        self._pos, self.yaw, self.ground = heading_frame(g_rot, g_pos, self.ref)
        prev = np.maximum(np.arange(len(self.clip)) - 1, 0)
        prev = np.where(self.frame > 0, prev, np.arange(len(self.clip)))
        self._vel = quat.rotate(quat.from_yaw(-self.yaw)[:, None], g_pos - g_pos[prev])
        self._ref_rot = g_rot[:, self.ref]

    @property
    def num_frames(self) -> int:
        return int(len(self.clip))

    # ------------------------------------------------------------------ features
    def _query(self, pos_a, vel_a, pos_b, disp, dyaw) -> np.ndarray:
        J = pos_a.shape[-2]
        cv = self.velocity_weight * self.fps
        cd = self.displacement_weight * np.sqrt(J)
        flat = lambda x: x.reshape(x.shape[:-2] + (-1,))  # noqa: E731
        return np.concatenate(
            [
                flat(pos_a),
                cv * flat(vel_a),
                flat(pos_b),
                cd * disp,
                cd * 0.5 * np.stack([np.cos(dyaw), np.sin(dyaw)], -1),
            ],
            axis=-1,
        )

    def _keys(self, gap: int) -> tuple[np.ndarray, np.ndarray]:
        """Candidate start frames ``s`` (those with ``s+gap`` in the same clip, ``s >= 1``) and their keys."""
        s = np.flatnonzero((self.frame >= 1) & (self.frame + gap < self.length))
        if s.size == 0:
            raise ValueError(f"no library stretch is {gap + 1} frames long: every clip is shorter")
        e = s + gap
        rot = quat.from_yaw(-self.yaw[s])
        d = quat.rotate(rot, self.ground[e] - self.ground[s])[:, [0, 2]]
        keys = self._query(self._pos[s], self._vel[s], self._pos[e], d, _wrap(self.yaw[e] - self.yaw[s]))
        return s, keys

    def window_query(self, rot_ctx, trans_ctx, rot_b, trans_b) -> np.ndarray:
        """Query vectors (W, K) of gaps given frames ``a-1, a`` (W, 2, J, ·) and ``b`` (W, J, ·)."""
        r = np.concatenate([rot_ctx, rot_b[:, None]], axis=1)
        t = np.concatenate([trans_ctx, trans_b[:, None]], axis=1)
        g_rot, g_pos = fk(r, t, self.parents)
        pos, yaw, ground = heading_frame(g_rot, g_pos, self.ref)
        turn = quat.from_yaw(-yaw[:, 1])
        vel = quat.rotate(turn[:, None], g_pos[:, 1] - g_pos[:, 0])
        disp = quat.rotate(turn, ground[:, 2] - ground[:, 1])[:, [0, 2]]
        return self._query(pos[:, 1], vel, pos[:, 2], disp, _wrap(yaw[:, 2] - yaw[:, 1]))

    # ------------------------------------------------------------------ search
    def search(
        self,
        query: np.ndarray,
        gap: int,
        k: int = 1,
        exclude_clip=None,
        allowed_labels: Sequence[str] | None = None,
        query_labels: Sequence[str] | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` best start frames (W, k) for gaps of ``gap`` frames between ends, and costs (W, k).

        ``exclude_clip`` (W,) of int, optional: a clip index per query that may not be used
        (leave-one-out evaluation). ``allowed_labels``: only clips with these labels.
        ``query_labels`` (W,) of str, optional: each query may only use clips of its own label
        (the action node it lies in). A query with no usable stretch gets cost ``inf``.

        Raises
        ------
        ValueError when no stretch of the library (with the allowed labels) is long enough.
        """
        s, keys = self._keys(gap)
        if allowed_labels is not None:
            ok = np.isin(np.array(self.labels)[self.clip[s]], list(allowed_labels))
            s, keys = s[ok], keys[ok]
        if s.size == 0:
            raise ValueError(f"no library stretch is {gap + 1} frames long (with the allowed labels)")
        q = np.asarray(query, dtype=np.float64)
        cost = np.sum(q * q, axis=1)[:, None] + np.sum(keys * keys, axis=1)[None, :] - 2.0 * q @ keys.T
        if exclude_clip is not None:
            cost = np.where(self.clip[s][None, :] == np.asarray(exclude_clip)[:, None], np.inf, cost)
        if query_labels is not None:
            lib_labels = np.array(self.labels)[self.clip[s]]
            cost = np.where(lib_labels[None, :] == np.asarray(query_labels, dtype=str)[:, None], cost, np.inf)
        k = min(int(k), s.size)
        idx = np.argpartition(cost, k - 1, axis=1)[:, :k]
        c = np.take_along_axis(cost, idx, axis=1)
        order = np.argsort(c, axis=1)
        idx, c = np.take_along_axis(idx, order, axis=1), np.take_along_axis(c, order, axis=1)
        return s[idx], np.maximum(c, 0.0)

    # ------------------------------------------------------------------ filling
    def fill(
        self,
        rot_ctx,
        trans_ctx,
        rot_b,
        trans_b,
        num: int,
        k: int = 1,
        exclude_clip=None,
        allowed_labels: Sequence[str] | None = None,
        query_labels: Sequence[str] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Fill ``num`` frames in each of W gaps (raises ValueError for arrays of the wrong shapes or ``num`` < 1).

        Parameters
        ----------
        rot_ctx : array (W, 2, J, 4)     local rotations of frames ``a-1`` and ``a``
        trans_ctx : array (W, 2, J, 3)   their local translations (root: world position), metres
        rot_b : array (W, J, 4)          local rotations of frame ``b = a + num + 1``
        trans_b : array (W, J, 3)        its translations
        num : int                        N >= 1

        Returns
        -------
        rot : ndarray (W, N, J, 4)
        trans : ndarray (W, N, J, 3)
        cost : ndarray (W,)              matching cost of the best stretch (``inf``: none was
                                         allowed; that gap's frames are then meaningless)
        """
        rot_ctx, rot_b = quat.check(rot_ctx, "rot_ctx"), quat.check(rot_b, "rot_b")
        trans_ctx, trans_b = np.asarray(trans_ctx, dtype=np.float64), np.asarray(trans_b, dtype=np.float64)
        W = rot_ctx.shape[0]
        if rot_ctx.shape[1] != 2 or rot_b.shape != (W,) + rot_ctx.shape[2:] or trans_ctx.shape[:3] != rot_ctx.shape[:3]:
            raise ValueError(
                f"expected rot_ctx (W, 2, J, 4), trans_ctx (W, 2, J, 3), rot_b (W, J, 4); got "
                f"{rot_ctx.shape}, {trans_ctx.shape}, {rot_b.shape}"
            )
        if num < 1:
            raise ValueError(f"need at least one frame to fill, got num={num}")
        L = num + 1
        query = self.window_query(rot_ctx, trans_ctx, rot_b, trans_b)
        starts, cost = self.search(query, L, k, exclude_clip, allowed_labels, query_labels)
        frames = starts[..., None] + np.arange(L + 1)  # (W, k, L+1)
        seg_rot = self.local_rot[frames]  # (W, k, L+1, J, 4)
        seg_trans = self.trans[frames].copy()
        # root alignment (eq. 3): the stretch's first frame onto frame a, about +Y and along the floor
        g_rot, g_pos = fk(rot_ctx[:, 1], trans_ctx[:, 1], self.parents)
        yaw_a = quat.yaw(g_rot[:, self.ref])
        ground_a = g_pos[:, self.ref] * np.array([1.0, 0.0, 1.0])
        s0 = starts
        theta = _wrap(yaw_a[:, None] - self.yaw[s0])  # (W, k)
        turn = quat.from_yaw(theta)
        shift = ground_a[:, None] - quat.rotate(turn, self.ground[s0])
        seg_rot[..., 0, :] = quat.mul(turn[:, :, None], seg_rot[..., 0, :])
        seg_trans[..., 0, :] = quat.rotate(turn[:, :, None], seg_trans[..., 0, :]) + shift[:, :, None]
        # blend the end mismatches away
        alpha = np.arange(1, L) / L  # (N,)
        qa, qb = rot_ctx[:, 1][:, None], rot_b[:, None]  # (W, 1, J, 4)
        d_a = quat.mul(qa, quat.conj(seg_rot[:, :, 0]))  # (W, k, J, 4)
        d_b = quat.mul(qb, quat.conj(seg_rot[:, :, L]))
        delta = quat.slerp(d_a[:, :, None], d_b[:, :, None], alpha[:, None])  # (W, k, N, J, 4)
        rot = quat.mul(delta, seg_rot[:, :, 1:L])
        off_a = trans_ctx[:, 1][:, None] - seg_trans[:, :, 0]
        off_b = trans_b[:, None] - seg_trans[:, :, L]
        a = alpha[:, None, None]
        trans = seg_trans[:, :, 1:L] + (1 - a) * off_a[:, :, None] + a * off_b[:, :, None]
        if rot.shape[1] > 1:  # average the usable ones of the k candidates
            usable = np.isfinite(cost)[:, :, None, None, None]
            usable[:, :1] = True
            ref = rot[:, :1]
            sign = np.where(np.sum(rot * ref, axis=-1, keepdims=True) < 0, -1.0, 1.0)
            rot = np.sum(np.where(usable, rot * sign, 0.0), axis=1)
            rot = rot / np.linalg.norm(rot, axis=-1, keepdims=True)
            trans = np.sum(np.where(usable, trans, 0.0), axis=1) / np.sum(usable, axis=1)
        else:
            rot, trans = rot[:, 0], trans[:, 0]
        return rot, trans, cost[:, 0]
