"""Helpers for tests and notebook check cells.

They ship with the package so that notebooks can check an exercise with the same tools the
test suite uses::

    from motionlab import testing
    rng = np.random.default_rng(0)
    q = testing.random_quat(rng, (5,))
    testing.assert_quat_close(quat.mul(q, quat.inv(q)), quat.IDENTITY)

Quaternions are ``(w, x, y, z)``; ``q`` and ``-q`` are the same rotation, so comparisons here
ignore the sign of each quaternion.
"""

from __future__ import annotations

import numpy as np

from motionlab.core.skeleton import Skeleton

__all__ = ["assert_quat_close", "random_quat", "random_skeleton"]


def _as_numpy(x) -> np.ndarray:
    """Array view of ``x``; torch tensors are detached and moved to the CPU first."""
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.asarray(x, dtype=np.float64)


def assert_quat_close(actual, desired, atol: float = 1e-6) -> None:
    """Assert that two sets of quaternions describe the same rotations, up to sign.

    Each quaternion of ``actual`` is compared with the matching one of ``desired`` and with
    its negation; the closer of the two must agree component-wise within ``atol``.

    Parameters
    ----------
    actual, desired : array or Tensor, shape (..., 4)
        Quaternions (w, x, y, z). Leading shapes must broadcast (``desired`` may be a single
        quaternion such as ``quat.IDENTITY``).
    atol : float
        Absolute tolerance on each component.

    Raises
    ------
    AssertionError
        With the index and values of the worst pair when they differ.
    """
    a, b = _as_numpy(actual), _as_numpy(desired)
    if a.ndim == 0 or b.ndim == 0 or a.shape[-1] != 4 or b.shape[-1] != 4:
        raise AssertionError(f"expected (..., 4) quaternions, got shapes {a.shape} and {b.shape}")
    try:
        a, b = np.broadcast_arrays(a, b)
    except ValueError:
        raise AssertionError(f"quaternion shapes do not match: {a.shape} vs {b.shape}") from None
    same = np.max(np.abs(a - b), axis=-1)
    flipped = np.max(np.abs(a + b), axis=-1)
    err = np.minimum(same, flipped)
    if not np.all(err <= atol):  # also catches NaN
        worst = np.unravel_index(np.argmax(np.where(np.isnan(err), np.inf, err)), err.shape)
        raise AssertionError(
            f"quaternions differ (up to sign) by {err[worst]:.3g} > atol={atol:g} "
            f"at index {tuple(int(i) for i in worst)}: {a[worst]} vs {b[worst]} "
            f"({int(np.sum(~(err <= atol)))} of {err.size} differ)"
        )


def random_quat(rng: np.random.Generator, shape: int | tuple[int, ...] = ()) -> np.ndarray:
    """Unit quaternions drawn uniformly over all rotations.

    Parameters
    ----------
    rng : numpy.random.Generator    e.g. ``np.random.default_rng(0)``
    shape : int or tuple of int     leading shape; ``()`` gives a single quaternion

    Returns
    -------
    ndarray, shape (*shape, 4), float64
        Unit quaternions (w, x, y, z), with either sign of ``w``.
    """
    shape = (shape,) if isinstance(shape, (int, np.integer)) else tuple(shape)
    q = rng.standard_normal(shape + (4,))
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    # a standard normal 4-vector is never (numerically) zero, but guard the division anyway
    q = np.where(n > 1e-9, q / np.where(n > 1e-9, n, 1.0), np.array([1.0, 0.0, 0.0, 0.0]))
    return q


def random_skeleton(rng: np.random.Generator, num_joints: int, bone_scale: float = 0.2) -> Skeleton:
    """A random valid skeleton: a tree with parents before children and one root at index 0.

    Parameters
    ----------
    rng : numpy.random.Generator
    num_joints : int          J >= 1
    bone_scale : float        standard deviation of each offset component, metres

    Returns
    -------
    Skeleton
        Joints named ``"j0"`` … ``"j{J-1}"``; ``parents[j]`` drawn uniformly from ``0 … j-1``;
        offsets (J, 3) normally distributed (the root's offset is its rest position).

    Raises
    ------
    ValueError when ``num_joints`` < 1.
    """
    if int(num_joints) < 1:
        raise ValueError(f"a skeleton needs at least one joint, got num_joints={num_joints}")
    num_joints = int(num_joints)
    parents = np.full(num_joints, -1, dtype=np.int64)
    for j in range(1, num_joints):
        parents[j] = rng.integers(0, j)
    offsets = rng.normal(scale=bone_scale, size=(num_joints, 3))
    names = tuple(f"j{j}" for j in range(num_joints))
    return Skeleton(names, parents, offsets)
