r"""Kovar's frame distance, for all frame pairs of two clips at once.

Kovar, Gleicher and Pighin (2002) compare frame :math:`i` of clip A with frame :math:`j` of
clip B through *point clouds*: the joint positions of a short window of frames around each
frame. Because a character may walk anywhere and face any way, B's cloud is first moved by the
ground transform :math:`T_{\theta,x_0,z_0}` (a turn by :math:`\theta` about the vertical
axis, then a shift on the ground) that brings it closest to A's:

.. math::

    D(i, j) = \min_{\theta, x_0, z_0} \sum_k w_k \,\lVert p_k - T_{\theta,x_0,z_0}\, p'_k \rVert^2 .

With weights summing to 1 the optimum is closed-form. Centre both clouds horizontally on their
weighted means (:math:`c = p - \bar p`, :math:`y` stays), then

.. math::

    D = S_A(i) + S_B(j) - 2\,Y(i, j) - 2\sqrt{a(i,j)^2 + b(i,j)^2},

    a = \sum_k w_k (c_x c'_x + c_z c'_z), \quad b = \sum_k w_k (c_x c'_z - c_z c'_x),
    \quad Y = \sum_k w_k\, y\, y', \quad S = \sum_k w_k \lVert c \rVert^2 ,

and :math:`\tan\theta = b / a`. :math:`a`, :math:`b` and :math:`Y` are inner products of
per-frame feature rows, so the whole matrix :math:`D` is three matrix products: no loop over
frame pairs. Rows are done in blocks, so memory stays bounded for long clips.

Unit of :math:`D`: m² (a weighted *mean* squared point distance); :func:`rms` turns a value
into metres. Windows are centred (``window`` frames, clamped at the clip ends) and tapered;
joints are weighted equally. Both choices are documented in ``notebooks/05_motion_graphs``.

**Exact sums.** Which cells are candidates is decided by comparisons (local minimum, threshold),
so :math:`D` must not depend on the order in which a BLAS kernel adds up the products. Point
coordinates are therefore put on a grid of :data:`GRID` metres (a power of two, so they stay
exact binary numbers) and the weights are small integers (:attr:`CloudFeatures.unit_weights`):
every product and partial sum is then a whole multiple of ``GRID²`` below 2⁵³ of them, which
float64 holds exactly, in any order, on any CPU, in any block size. Only the final few
element-wise operations round, and those are the same everywhere (IEEE 754).

Transition candidates are the *local minima* of :math:`D` (no smaller value among the 8
neighbouring cells) below a threshold, see :func:`candidates` and :func:`threshold_from`.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import contextlib
import functools
import time
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

__all__ = [
    "CloudFeatures",
    "cloud_features",
    "distance_matrix",
    "distance_blocks",
    "local_minima",
    "candidates",
    "block_cells",
    "BLOCK_CELLS",
    "alignment",
    "rms",
    "threshold_from",
    "DEFAULT_WINDOW",
    "DEFAULT_THRESHOLD",
    "GRID",
]

DEFAULT_THRESHOLD = 0.04
"""The default transition threshold, metres RMS between aligned point clouds (pass it through
:func:`threshold_from`): ``graph-build``'s ``--distance-threshold`` and library callers use it.
The rule that chose it and its check on held-out takes: ``docs/results_motion_graphs.md``."""

DEFAULT_WINDOW = 5
"""Frames per point cloud (centred on the frame): 5 frames ≈ 0.17 s at 30 fps."""

GRID = 2.0**-18
"""Spacing (metres, ≈ 3.8 µm) of the grid the cloud points are rounded to, so that sums are exact."""

_JOINT_WEIGHT_LEVELS = 16  # joint weights are rounded to multiples of 1/16 of the largest
_EXACT_LIMIT = 2.0**52  # sums of whole grid units below this are exact in float64

BLOCK_CELLS = 1 << 20
"""Most cells of ``D`` computed at once (:func:`block_cells` takes fewer when memory is short)."""

_BYTES_PER_CELL = 56  # float64 block, [a | b] (two cells), Y and two temporaries
_MEMORY_SHARE = 16  # a block takes at most this fraction of the memory available


@dataclass
class CloudFeatures:
    """Per-frame point-cloud rows of one clip (see the module docstring).

    Attributes
    ----------
    centred : ndarray, shape (T, 2n)   ``[c_x | c_z]`` horizontally centred window points, m,
                                       whole multiples of :data:`GRID`
    height  : ndarray, shape (T, n)    ``y`` of the window points, m, multiples of :data:`GRID`
    weights : ndarray, shape (n,)      point weights, summing to 1
    self_term : ndarray, shape (T,)    ``S = Σ w (c_x² + c_z² + y²)``, m²
    mean_xz : ndarray, shape (T, 2)    weighted horizontal centroid of each cloud, m
    unit_weights : ndarray, shape (n,) whole numbers proportional to ``weights``
                                       (``weights = unit_weights / unit_weights.sum()``): the
                                       products use them, so that every sum is exact
    """

    centred: np.ndarray
    height: np.ndarray
    weights: np.ndarray
    self_term: np.ndarray
    mean_xz: np.ndarray
    unit_weights: np.ndarray

    def __len__(self) -> int:
        return int(self.centred.shape[0])

    def __getitem__(self, frames) -> CloudFeatures:
        return CloudFeatures(
            self.centred[frames],
            self.height[frames],
            self.weights,
            self.self_term[frames],
            self.mean_xz[frames],
            self.unit_weights,
        )


def _window_weights(window: int) -> np.ndarray:
    # a tent taper in whole numbers: the centre frame counts most, the window's ends least (1)
    h = (window - 1) // 2
    return (h + 1 - np.abs(np.arange(window) - h)).astype(np.float64)


def _unit_joint_weights(joint_weights, num_joints: int) -> np.ndarray:
    if joint_weights is None:
        return np.ones(num_joints)
    jw = np.asarray(joint_weights, dtype=np.float64)
    if jw.shape != (num_joints,) or not np.all(np.isfinite(jw)) or np.any(jw < 0) or jw.sum() <= 0:
        raise ValueError(f"joint_weights must be {num_joints} finite non-negative numbers with a positive sum")
    return np.round(jw / jw.max() * _JOINT_WEIGHT_LEVELS)


def cloud_features(global_pos, window: int = DEFAULT_WINDOW, joint_weights=None) -> CloudFeatures:
    """Point-cloud rows of every frame of a clip.

    Parameters
    ----------
    global_pos : ndarray, shape (T, J, 3)   world joint positions, metres, Y up
    window : odd int                         frames per cloud, centred (clamped at the ends)
    joint_weights : ndarray, shape (J,), optional   (uniform by default; rounded to multiples
        of 1/16 of the largest, so that sums stay exact)

    Raises
    ------
    ValueError
        for a bad shape, window or weights, and for clouds too large for exact sums (points
        tens of metres from their window's centre or above the ground: not metres?)
    """
    pos = np.asarray(global_pos, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[-1] != 3 or pos.shape[0] < 1:
        raise ValueError(f"expected global positions of shape (T, J, 3), got {pos.shape}")
    if not (isinstance(window, (int, np.integer)) and window >= 1 and window % 2 == 1):
        raise ValueError(f"window must be a positive odd number of frames, got {window}")
    if not np.all(np.isfinite(pos)):
        raise ValueError("global positions hold non-finite values (NaN or inf)")
    T, J, _ = pos.shape
    units = (_window_weights(window)[:, None] * _unit_joint_weights(joint_weights, J)[None, :]).reshape(-1)
    total = units.sum()
    h = window // 2
    idx = np.clip(np.arange(T)[:, None] + np.arange(-h, h + 1)[None, :], 0, T - 1)  # (T, K)
    cloud = np.round(pos / GRID)[idx].reshape(T, window * J, 3)  # (T, n, 3), whole grid units
    mean_xz = np.stack([cloud[:, :, 0] @ units, cloud[:, :, 2] @ units], axis=1) / total  # exact sums
    cx = np.round(cloud[:, :, 0] - mean_xz[:, :1])
    cz = np.round(cloud[:, :, 2] - mean_xz[:, 1:])
    y = cloud[:, :, 1]
    self_units = (cx * cx + cz * cz + y * y) @ units
    if self_units.max() >= _EXACT_LIMIT:
        reach = float(np.sqrt(self_units.max() / total) * GRID)
        raise ValueError(
            f"point clouds reach {reach:.3g} m (root mean square) from their centre line: too large for "
            f"exact distances (up to about {np.sqrt(_EXACT_LIMIT / total) * GRID:.3g} m); are the positions in metres?"
        )
    return CloudFeatures(
        np.concatenate([cx, cz], axis=1) * GRID,
        y * GRID,
        units / total,
        self_units * GRID**2 / total,
        mean_xz * GRID,
        units,
    )


def _as_features(x, window: int) -> CloudFeatures:
    return x if isinstance(x, CloudFeatures) else cloud_features(x, window)


@functools.cache
def _blas_controller():
    """threadpoolctl's view of the BLAS libraries numpy uses (built once; None if unavailable)."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        return None
    return ThreadpoolController()


def _one_blas_thread():
    """Run BLAS single-threaded: these products are a few hundred columns wide, too small for a
    second BLAS thread to pay for itself beside the build's own threads."""
    ctl = _blas_controller()
    return ctl.limit(limits=1, user_api="blas") if ctl is not None else contextlib.nullcontext()


def block_cells(available: int | None = None) -> int:
    """Cells of ``D`` per block: :data:`BLOCK_CELLS`, or fewer so that a block and its
    temporaries take at most 1/16 of ``available`` bytes (default: the memory the system reports
    available), and never fewer than 65,536. The candidates do not depend on it."""
    if available is None:
        available = _available_memory()
    return int(min(BLOCK_CELLS, max(1 << 16, available // (_MEMORY_SHARE * _BYTES_PER_CELL))))


_MEMORY_SECONDS = 1.0  # the memory available is read again after this long
_memory_read: list = [-np.inf, 0]  # (when, bytes)


def _available_memory() -> int:
    """The memory the system reports available, bytes, read at most once every
    :data:`_MEMORY_SECONDS` (a build compares thousands of clip pairs)."""
    now = time.monotonic()
    if now - _memory_read[0] > _MEMORY_SECONDS:
        try:
            import psutil

            _memory_read[1] = int(psutil.virtual_memory().available)
        except (ImportError, OSError):  # pragma: no cover - psutil is a dependency
            _memory_read[1] = BLOCK_CELLS * _BYTES_PER_CELL * _MEMORY_SHARE
        _memory_read[0] = now
    return _memory_read[1]


def _block(fa: CloudFeatures, fb: CloudFeatures, rows: slice, right: np.ndarray, yb: np.ndarray) -> np.ndarray:
    units = fa.unit_weights
    left = fa.centred[rows] * np.concatenate([units, units])  # (r, 2n); exact: see the module docstring
    tb = fb.centred.shape[0]
    with _one_blas_thread():
        ab = left @ right  # (r, 2 Tb): [a | b] times the weights' total, exact in any summation order
        cross_y = (fa.height[rows] * units) @ yb
    a, b = ab[:, :tb], ab[:, tb:]
    # S_A + S_B - (2 Y + 2 sqrt(a² + b²)) / Σw, in place (the same operations in the same order)
    root = np.multiply(a, a)
    root += np.multiply(b, b, out=b)
    np.sqrt(root, out=root)
    root *= 2.0
    cross_y *= 2.0
    cross_y += root
    cross_y /= units.sum()
    d = np.add(fa.self_term[rows, None], fb.self_term[None, :], out=root)
    d -= cross_y
    return np.maximum(d, 0.0, out=d)


def _check_pair(fa: CloudFeatures, fb: CloudFeatures) -> None:
    if fa.height.shape[1] != fb.height.shape[1] or not np.array_equal(fa.unit_weights, fb.unit_weights):
        raise ValueError(
            "the two clips have different joint counts, window sizes or joint weights; they cannot be compared"
        )


def _right(fb: CloudFeatures) -> tuple[np.ndarray, np.ndarray]:
    n = fb.height.shape[1]
    cx, cz = fb.centred[:, :n], fb.centred[:, n:]
    # a = [cx|cz]·[cx'|cz'],  b = [cx|cz]·[cz'|-cx']
    right = np.concatenate([fb.centred, np.concatenate([cz, -cx], axis=1)], axis=0).T  # (2n, 2 Tb)
    return np.ascontiguousarray(right), np.ascontiguousarray(fb.height.T)


def distance_blocks(
    a, b, window: int = DEFAULT_WINDOW, block_rows: int | None = None
) -> Iterator[tuple[int, np.ndarray]]:
    """Yield ``(first_row, D[rows])`` blocks of the distance matrix, in row order.

    ``a``, ``b``: positions (T, J, 3) or :class:`CloudFeatures`. Each block has at most
    ``block_rows`` rows (default: :func:`block_cells` cells per block).
    """
    fa, fb = _as_features(a, window), _as_features(b, window)
    _check_pair(fa, fb)
    right, yb = _right(fb)
    rows = block_rows or max(1, block_cells() // max(len(fb), 1))
    for r0 in range(0, len(fa), rows):
        yield r0, _block(fa, fb, slice(r0, min(r0 + rows, len(fa))), right, yb)


def distance_matrix(a, b=None, window: int = DEFAULT_WINDOW) -> np.ndarray:
    """The full matrix ``D`` (Ta, Tb) in m²; ``b=None`` compares ``a`` with itself.

    For long clips prefer :func:`candidates`, which never holds the whole matrix.
    """
    fa = _as_features(a, window)
    fb = fa if b is None else _as_features(b, window)
    out = np.empty((len(fa), len(fb)))
    for r0, blk in distance_blocks(fa, fb, window):
        out[r0 : r0 + len(blk)] = blk
    return out


def alignment(fa: CloudFeatures, fb: CloudFeatures, i, j) -> tuple[np.ndarray, np.ndarray]:
    """The optimal ground transform taking B's cloud ``j`` onto A's cloud ``i``.

    Returns ``theta`` (radians, turn about +Y) and ``shift`` (..., 3) with ``shift[..., 1] = 0``
    such that ``p ≈ R_y(theta) p' + shift``.
    """
    i, j = np.asarray(i), np.asarray(j)
    n = fa.height.shape[1]
    w2 = np.concatenate([fa.weights, fa.weights])
    ca, cb = fa.centred[i].astype(np.float64), fb.centred[j].astype(np.float64)
    a = np.sum(ca * w2 * cb, axis=-1)
    cb_perp = np.concatenate([cb[..., n:], -cb[..., :n]], axis=-1)
    b = np.sum(ca * w2 * cb_perp, axis=-1)
    # R_y(θ) maps (x, z) to (x cosθ + z sinθ, -x sinθ + z cosθ); maximising Σ w c·R c' gives θ:
    theta = np.arctan2(b, a)
    ma, mb = fa.mean_xz[i], fb.mean_xz[j]
    c, s = np.cos(theta), np.sin(theta)
    sx = ma[..., 0] - (c * mb[..., 0] + s * mb[..., 1])
    sz = ma[..., 1] - (-s * mb[..., 0] + c * mb[..., 1])
    return theta, np.stack([sx, np.zeros_like(sx), sz], axis=-1)


def local_minima(block: np.ndarray, above: np.ndarray | None = None, below: np.ndarray | None = None) -> np.ndarray:
    """Mask of cells no larger than any of their 8 neighbours.

    ``above``/``below``: the matrix rows just before/after the block (``None`` at the
    matrix's edge), so blocks give the same answer as the whole matrix.
    """
    r, c = block.shape
    inf_row = np.full((1, c), np.inf)
    top = inf_row if above is None else above.reshape(1, c)
    bottom = inf_row if below is None else below.reshape(1, c)
    padded = np.concatenate([top, block, bottom], axis=0)
    padded = np.pad(padded, ((0, 0), (1, 1)), constant_values=np.inf)
    centre = padded[1:-1, 1:-1]
    mask = np.ones((r, c), dtype=bool)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            if di == 1 and dj == 1:
                continue
            mask &= centre <= padded[di : di + r, dj : dj + c]
    return mask


def _minima_under(d: np.ndarray, first: int, count: int, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``first … first + count - 1`` of the rows ``d`` of ``D``: the cells below ``threshold``
    that are no larger than any of their 8 neighbours (as :func:`local_minima`; the rows of ``d``
    around them are the neighbours, cells beyond ``d``'s edges count as ``inf``). Only the cells
    below the threshold are tested, so the work follows the candidates kept.

    Returns the cells' row (from ``first``) and column indices, in row-major order."""
    core = d[first : first + count]
    if not np.isfinite(threshold) or np.count_nonzero(core < threshold) * 4 > core.size:
        above = d[first - 1] if first > 0 else None
        below = d[first + count] if first + count < d.shape[0] else None
        return np.nonzero(local_minima(core, above, below) & (core < threshold))
    ii, jj = np.nonzero(core < threshold)
    rows, cols = d.shape
    padded = np.full((rows + 2, cols + 2), np.inf)  # cells beyond d's edges: inf, no constraint
    padded[1:-1, 1:-1] = d
    at = (ii + first + 1) * (cols + 2) + (jj + 1)  # each cell in the padded array, flat
    flat = padded.reshape(-1)
    value = flat[at]
    keep = np.ones(ii.size, dtype=bool)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di or dj:
                keep &= value <= flat[at + di * (cols + 2) + dj]
    return ii[keep], jj[keep]


def candidates(
    a,
    b=None,
    threshold: float = np.inf,
    window: int = DEFAULT_WINDOW,
    min_gap: int = 0,
    rows: slice | None = None,
    cols: slice | None = None,
    block_rows: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Transition candidates: local minima of ``D`` below ``threshold`` (m²).

    Parameters
    ----------
    a, b : positions (T, J, 3) or :class:`CloudFeatures`; ``b=None`` compares a clip with itself
    threshold : largest accepted distance, m² (see :func:`threshold_from`)
    min_gap : with ``b=None``, drop pairs with ``|i - j| < min_gap`` (the trivial diagonal)
    rows, cols : only these frames of ``a`` / ``b`` take part
    block_rows : rows per block (memory bound); the answer does not depend on it

    Returns
    -------
    i, j : int arrays (frame of ``a``, frame of ``b``, absolute indices)
    cost : float array, m²
    """
    fa = _as_features(a, window)
    same = b is None
    fb = fa if same else _as_features(b, window)
    r0_, r1_ = (rows.start or 0, len(fa) if rows.stop is None else rows.stop) if rows else (0, len(fa))
    c0_, c1_ = (cols.start or 0, len(fb) if cols.stop is None else cols.stop) if cols else (0, len(fb))
    _check_pair(fa, fb)
    sub_a, sub_b = fa[r0_:r1_], fb[c0_:c1_]
    if len(sub_a) == 0 or len(sub_b) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    right, yb = _right(sub_b)
    n_rows = block_rows or max(1, block_cells() // max(len(sub_b), 1))
    out_i, out_j, out_c = [], [], []
    T = len(sub_a)
    for start in range(0, T, n_rows):
        stop = min(start + n_rows, T)
        lo, hi = max(start - 1, 0), min(stop + 1, T)  # one extra row each side for the 3x3 test
        d = _block(sub_a, sub_b, slice(lo, hi), right, yb)
        ii, jj = _minima_under(d, start - lo, stop - start, threshold)
        core = d[start - lo : start - lo + (stop - start)]
        gi, gj = ii + start + r0_, jj + c0_
        if same and min_gap > 0:
            keep = np.abs(gi - gj) >= min_gap
            ii, jj, gi, gj = ii[keep], jj[keep], gi[keep], gj[keep]
        out_i.append(gi)
        out_j.append(gj)
        out_c.append(core[ii, jj])
    return np.concatenate(out_i), np.concatenate(out_j), np.concatenate(out_c)


def rms(d) -> np.ndarray:
    """Distance values (m²) as a root-mean-square point distance in metres."""
    return np.sqrt(np.maximum(np.asarray(d, dtype=np.float64), 0.0))


def threshold_from(rms_metres: float | None = None, relative: float | None = None, scale: float | None = None) -> float:
    """A threshold in m² for :func:`candidates`.

    Either absolute — ``rms_metres``: accept poses whose aligned clouds differ by at most this
    many metres (root mean square over the weighted points) — or *relative to the data*:
    ``relative × scale`` metres, where ``scale`` is a size of the data, by convention the
    character's height (so ``relative=0.03`` accepts 3% of the height, about 5 cm for an adult).

    Raises
    ------
    ValueError unless exactly one of ``rms_metres`` and ``relative`` is given, positive
    (``relative`` with a positive ``scale``).
    """
    if (rms_metres is None) == (relative is None):
        raise ValueError("give exactly one of rms_metres (absolute) or relative (with scale)")
    if rms_metres is not None:
        if not rms_metres > 0:
            raise ValueError(f"threshold must be positive metres, got {rms_metres}")
        return float(rms_metres) ** 2
    if scale is None or not scale > 0 or not relative > 0:
        raise ValueError(f"a relative threshold needs positive relative and scale, got {relative} and {scale}")
    return float(relative * scale) ** 2
