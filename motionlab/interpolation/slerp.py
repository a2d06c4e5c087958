"""SLERP along a gap: the weights α(k), quaternion paths, and Euler interpolation for contrast.

The paper (Yang, Su, Yan, Li and Liu 2019, key-pose-constrained interpolation of human motion sequences) fills ``N`` missing frames between a known frame ``A(m)`` and a
known frame ``B(n)`` with

.. math::

    s_k = \\operatorname{slerp}(q_A, q_B, \\alpha(k)), \\qquad
    \\operatorname{slerp}(q, p, \\alpha) = \\frac{\\sin((1-\\alpha)\\Omega)}{\\sin\\Omega} q
    + \\frac{\\sin(\\alpha\\Omega)}{\\sin\\Omega} p, \\qquad \\cos\\Omega = |q \\cdot p|,

for ``k = 1 … N`` and ``0 < α(k) < 1``. The paper leaves α open; we offer

* ``"linear"``: ``α(k) = k / (N + 1)`` (constant angular speed, the LaFAN1 baseline);
* ``"ease"``: ``α = (1 - cos(π u)) / 2`` with ``u = k / (N + 1)`` (ease-in-out: zero speed at
  both ends, faster in the middle);
* ``"smoothstep"``: ``α = 3u² - 2u³`` (the same idea as a cubic).

Every function is vectorised over leading batch dimensions (windows, joints) and over the ``N``
in-between frames: there is no Python loop over frames.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat

__all__ = ["CURVES", "alphas", "slerp_path", "lerp_path", "euler_lerp_path", "angular_speed"]

CURVES = ("linear", "ease", "smoothstep")
"""Names of the α(k) curves :func:`alphas` knows."""


def alphas(num: int, curve: str = "linear") -> np.ndarray:
    """Interpolation weights α(k), k = 1 … ``num``, strictly between 0 and 1.

    Parameters
    ----------
    num : int     number of in-between frames N (>= 0)
    curve : str   one of :data:`CURVES`

    Returns
    -------
    ndarray, shape (num,)   increasing weights; ``alphas(N)[k-1]`` is α(k)

    Raises
    ------
    ValueError unless ``num`` is a whole number >= 0 and ``curve`` one of :data:`CURVES`.
    """
    if int(num) != num or num < 0:
        raise ValueError(f"expected a non-negative whole number of in-between frames, got {num!r}")
    if curve not in CURVES:
        raise ValueError(f"unknown α(k) curve {curve!r}; expected one of {CURVES}")
    u = np.arange(1, int(num) + 1, dtype=np.float64) / (int(num) + 1)
    if curve == "linear":
        return u
    if curve == "ease":
        return 0.5 * (1.0 - np.cos(np.pi * u))
    return u * u * (3.0 - 2.0 * u)


def _weights(num_or_alpha, curve: str) -> np.ndarray:
    if np.ndim(num_or_alpha) == 0:
        return alphas(int(num_or_alpha), curve)
    a = np.asarray(num_or_alpha, dtype=np.float64)
    if a.ndim != 1:
        raise ValueError(f"expected α as a 1-D array of weights, got shape {a.shape}")
    return a


def slerp_path(q_a, q_b, num, curve: str = "linear") -> np.ndarray:
    """SLERP from ``q_a`` to ``q_b`` at the in-between weights.

    Parameters
    ----------
    q_a, q_b : array, shape (..., 4)    unit quaternions (w, x, y, z) at the two known frames
    num : int or array (N,)             number of in-between frames, or the weights α themselves
    curve : str                         α curve when ``num`` is an int (see :func:`alphas`)

    Returns
    -------
    ndarray, shape (..., N, 4)   the in-between rotations, short arc; the frame axis is inserted
    just before the last one, so ``(B, J, 4)`` inputs give ``(B, J, N, 4)`` — use
    ``np.moveaxis(out, -2, -3)`` for frames-before-joints.
    """
    q_a, q_b = quat.check(q_a, "q_a"), quat.check(q_b, "q_b")
    a = _weights(num, curve)
    return quat.slerp(q_a[..., None, :], q_b[..., None, :], a)


def lerp_path(p_a, p_b, num, curve: str = "linear") -> np.ndarray:
    """Linear interpolation of vectors ``(..., D)`` at the weights; returns ``(..., N, D)``."""
    p_a, p_b = np.asarray(p_a, dtype=np.float64), np.asarray(p_b, dtype=np.float64)
    a = _weights(num, curve)[:, None]
    return p_a[..., None, :] + a * (p_b - p_a)[..., None, :]


def euler_lerp_path(q_a, q_b, num, order: str = "zxy", curve: str = "linear") -> np.ndarray:
    """Interpolate Euler angles linearly (the naive way), returned as quaternions ``(..., N, 4)``.

    Both ends are converted with :func:`motionlab.core.quat.to_euler` (middle angle in
    [-π/2, π/2]) and each angle is blended on its own. Near gimbal lock, or when an angle wraps
    past ±π, the path makes detours that SLERP does not; the notebook measures them.
    """
    e_a = quat.to_euler(quat.check(q_a, "q_a"), order)
    e_b = quat.to_euler(quat.check(q_b, "q_b"), order)
    return quat.from_euler(lerp_path(e_a, e_b, num, curve), order)


def angular_speed(path) -> np.ndarray:
    """Angle (radians) between consecutive rotations of a path ``(..., N, 4)``: shape (..., N-1)."""
    path = quat.check(path, "path")
    return quat.angle_between(path[..., 1:, :], path[..., :-1, :])
