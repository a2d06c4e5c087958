"""Fast forward kinematics for large batches: the same answer as ``fk_torch.fk_positions``, quicker.

The plain FK in :mod:`motionlab.core.fk_torch` runs about 40 small tensor operations per joint.
Each one streams the whole batch through memory, so a 100k-frame batch spends most of its
time waiting on memory and on Python. This module changes three things:

1. **Component-major blocks.** Frames are cut into blocks of :data:`BLOCK` (16) and each block
   is transposed from ``(16, J, 4)`` to ``(J·4, 16)``. Now "the ``w`` of joint ``j`` for 16
   frames" is 16 adjacent floats, exactly one AVX-512 register (two AVX2 registers).
2. **Chunks that stay in cache.** The batch is processed ``chunk`` frames at a time (default
   :data:`DEFAULT_CHUNK`). The transposed inputs, the few intermediates inductor keeps and the
   output of one chunk stay in cache between the kernel's loops.
3. **One compiled kernel per skeleton.** ``torch.compile`` (inductor, C++ on the CPU) unrolls
   the joint loop of one chunk into a single vectorised C++ function. The tree is baked in,
   and only global quaternions that some child needs are computed.

The first call for a new skeleton (parents), dtype, chunk size or torch thread count compiles,
which is slow (much faster when inductor's on-disk cache already holds the kernel);
:func:`warmup` does it ahead of time and returns how long it took. If ``torch.compile`` is missing or
fails, a warning is issued once and the same blocked algorithm runs eagerly. That fallback is
slower, but it gives the same result.

Threads: the kernel splits each chunk between torch's threads, with a few OpenMP barriers per
chunk. When other processes keep the cores busy, a spinning thread at a barrier can wait a
whole scheduler time slice for a descheduled one, which makes it many times slower. On a shared
machine, set ``OMP_WAIT_POLICY=PASSIVE`` before starting Python, or call
``torch.set_num_threads(1)``.

Positions only, forward only: with gradients enabled on an input that requires them, on a
non-CPU device, or for a dtype other than float32/float64, the call is passed to
:func:`motionlab.core.fk_torch.fk_positions` unchanged.

:func:`fk_positions_fast_np` is the NumPy version of the same blocked algorithm, without
compilation.

Tip: on Linux, page faults on fresh output memory can cost as much as the FK itself. NumPy
already asks for transparent huge pages. For torch, set ``THP_MEM_ALLOC_ENABLE=1`` in the
environment before ``import torch``; ``benchmarks/bench_fk.py`` does this.
"""

from __future__ import annotations

import math
import threading
import time
import types
import warnings

import numpy as np
import torch

from motionlab.core import fk_torch

__all__ = [
    "BLOCK",
    "DEFAULT_CHUNK",
    "EAGER_CHUNK",
    "fk_positions_fast",
    "fk_positions_fast_np",
    "warmup",
    "is_compiled",
]

BLOCK = 16
"""Frames per block: one 512-bit vector of float32. Chunks are multiples of it."""

DEFAULT_CHUNK = 8192
"""Frames per compiled call. For 22 joints in float32 a chunk's working set is about 1.8 KB
per frame (15 MB), which stays in the last-level cache; a bigger chunk also pays the per-call
overhead and the thread barriers fewer times."""

EAGER_CHUNK = 65536
"""Frames per step of the eager fallback, long enough to amortise per-operation overhead."""

_NUMPY_DTYPE = {torch.float32: np.float32, torch.float64: np.float64}
_FAST_DTYPES = tuple(_NUMPY_DTYPE)
_kernels: dict[tuple, object] = {}  # key -> compiled callable, or None after a failed compile
_lock = threading.Lock()
_warned = False


# ---------------------------------------------------------------------------------- the chain
def _chain_positions(parents: tuple[int, ...], w, x, y, z, px, py, pz) -> list:
    """World positions of every joint as a flat list ``[x0, y0, z0, x1, ...]`` of 3J arrays.

    ``w, x, y, z`` (local quaternion components) and ``px, py, pz`` (local translations) are
    sequences indexed by joint. Their items may be torch tensors, NumPy arrays or floats of any
    one broadcastable shape. Only ``+ - *`` are used, so the same code serves torch (eager or
    traced) and NumPy. Per joint ``j`` with parent ``p``::

        g[j]   = g[p] ⊗ q[j]                          (Hamilton product)
        pos[j] = pos[p] + v + w_p t + u_p × t,   t = 2 u_p × v,   v = local translation
    """
    num_joints = len(parents)
    needed = set(parents[1:])  # joints whose global rotation a child uses
    gw, gx, gy, gz = {0: w[0]}, {0: x[0]}, {0: y[0]}, {0: z[0]}
    pos = [(px[0], py[0], pz[0])]
    for j in range(1, num_joints):
        p = parents[j]
        aw, ax, ay, az = gw[p], gx[p], gy[p], gz[p]
        vx, vy, vz = px[j], py[j], pz[j]
        tx = 2.0 * (ay * vz - az * vy)
        ty = 2.0 * (az * vx - ax * vz)
        tz = 2.0 * (ax * vy - ay * vx)
        ox, oy, oz = pos[p]
        pos.append(
            (
                ox + vx + aw * tx + (ay * tz - az * ty),
                oy + vy + aw * ty + (az * tx - ax * tz),
                oz + vz + aw * tz + (ax * ty - ay * tx),
            )
        )
        if j in needed:
            bw, bx, by, bz = w[j], x[j], y[j], z[j]
            gw[j] = aw * bw - ax * bx - ay * by - az * bz
            gx[j] = aw * bx + ax * bw + ay * bz - az * by
            gy[j] = aw * by - ax * bz + ay * bw + az * bx
            gz[j] = aw * bz + ax * by - ay * bx + az * bw
    return [c for xyz in pos for c in xyz]


# ---------------------------------------------------------------------------------- torch kernel
def _make_block_fn(parents: tuple[int, ...], shared: bool):
    """The per-chunk function ``(rot, pos_or_root, offsets, out) -> transposed inputs``.

    ``rot`` is (C, J, 4) and ``out`` is (C, J, 3), which is written in place. C is a multiple
    of :data:`BLOCK`. With ``shared`` the translations are ``root`` (C, 3) plus ``offsets``
    (J, 3), the same for every frame. Otherwise ``pos`` is (C, J, 3) and ``offsets`` is unused.
    The transposed inputs are returned only so that inductor stores them in a buffer of their
    own. Without that it would fold the transpose into the arithmetic as strided loads, which
    it does not vectorise.
    """
    num_joints = len(parents)

    def block_fk(rot, pos, offsets, out):
        n_blocks = rot.shape[0] // BLOCK
        rot_t = rot.reshape(n_blocks, BLOCK, num_joints * 4).transpose(1, 2).contiguous()
        w, x, y, z = (rot_t[:, k::4].unbind(1) for k in range(4))  # each: J tensors (n_blocks, BLOCK)
        if shared:
            root_t = pos.reshape(n_blocks, BLOCK, 3).transpose(1, 2).contiguous()
            px, py, pz = ([root_t[:, k]] + [offsets[j, k] for j in range(1, num_joints)] for k in range(3))
            pos_t = root_t
        else:
            pos_t = pos.reshape(n_blocks, BLOCK, num_joints * 3).transpose(1, 2).contiguous()
            px, py, pz = (pos_t[:, k::3].unbind(1) for k in range(3))
        rows = _chain_positions(parents, w, x, y, z, px, py, pz)
        res = torch.stack(rows, dim=1)  # (n_blocks, 3J, BLOCK)
        out.view(n_blocks, BLOCK, num_joints * 3).copy_(res.transpose(1, 2))
        return rot_t, pos_t

    # A fresh code object per skeleton gives each its own torch.compile cache entry (Dynamo
    # caches per code object and stops compiling after 8 variants of one).
    name = f"block_fk_{len(_kernels)}"
    code = block_fk.__code__.replace(co_name=name)
    return types.FunctionType(code, block_fk.__globals__, name, None, block_fk.__closure__)


def _eager_chunk(parents: tuple[int, ...], shared: bool, rot, pos, offsets, out) -> None:
    """The fallback for one chunk of any length: whole-chunk component-major rows, eager torch.

    Eager torch pays a few microseconds per operation, so the rows here are as long as the
    chunk (see :data:`EAGER_CHUNK`) instead of 16-frame blocks.
    """
    num_frames, num_joints = rot.shape[0], len(parents)
    rot_t = rot.reshape(num_frames, num_joints * 4).t().contiguous()
    w, x, y, z = (rot_t[k::4] for k in range(4))
    if shared:
        root_t = pos.t().contiguous()
        px, py, pz = ([root_t[k]] + offsets[1:, k].tolist() for k in range(3))
    else:
        pos_t = pos.reshape(num_frames, num_joints * 3).t().contiguous()
        px, py, pz = (pos_t[k::3] for k in range(3))
    rows = _chain_positions(parents, w, x, y, z, px, py, pz)
    out.view(num_frames, num_joints * 3).copy_(torch.stack(rows, dim=1))


def _key(parents, shared, dtype, chunk):
    # The thread count is baked into the kernel (and Dynamo guards on it), so it is part of the key.
    return (parents, shared, dtype, chunk, torch.get_num_threads())


def _get_kernel(parents, shared, dtype, chunk, use_compile):
    """A compiled block function for this key, or ``None`` if compiling is off or has failed."""
    if not use_compile:
        return None
    key = _key(parents, shared, dtype, chunk)
    with _lock:
        if key not in _kernels:
            try:
                if not hasattr(torch, "compile"):
                    raise RuntimeError(f"torch {torch.__version__} has no torch.compile")
                _kernels[key] = torch.compile(_make_block_fn(parents, shared), dynamic=False, fullgraph=True)
            except Exception as err:  # torch.compile missing or refusing: eager fallback
                _compile_failed(key, err)
        return _kernels[key]


def _compile_failed(key, err) -> None:
    global _warned
    _kernels[key] = None
    if not _warned:
        _warned = True
        warnings.warn(
            f"fk_fast: torch.compile failed ({type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}); "
            "using the slower eager version of the same algorithm",
            RuntimeWarning,
            stacklevel=3,
        )


def _run_chunk(kernel, key, rot, pos, offsets, out) -> bool:
    """Run the compiled kernel on one chunk; False (after warning once) if it failed."""
    try:
        kernel(rot, pos, offsets, out)
        return True
    except Exception as err:  # compilation happens on the first call; fall back for good
        with _lock:
            _compile_failed(key, err)
        return False


def _check_parents(parents, num_joints: int) -> tuple[int, ...]:
    if isinstance(parents, torch.Tensor):
        parents = parents.tolist()
    parents = tuple(int(p) for p in np.asarray(parents).reshape(-1).tolist())
    if len(parents) != num_joints:
        raise ValueError(f"expected {num_joints} parent indices (one per joint), got {len(parents)}")
    if num_joints and parents[0] != -1:
        raise ValueError(f"joint 0 must be the root (parent -1), got parent {parents[0]}")
    for j in range(1, num_joints):
        if not 0 <= parents[j] < j:
            raise ValueError(f"joint {j} has parent {parents[j]}; parents must precede their children")
    return parents


def _check_chunk(chunk: int) -> int:
    chunk = int(chunk)
    if chunk < BLOCK or chunk % BLOCK:
        raise ValueError(f"chunk must be a positive multiple of {BLOCK} frames, got {chunk}")
    return chunk


def _check_fast_args(local_rot, local_pos, parents, root_pos, chunk) -> tuple[tuple[int, ...], int, torch.Size]:
    """Checked ``(parents, chunk, batch)`` for :func:`fk_positions_fast`; ``batch`` is the broadcast leading shape."""
    if not isinstance(local_rot, torch.Tensor) or not isinstance(local_pos, torch.Tensor):
        raise ValueError(
            f"expected torch tensors, got {type(local_rot).__name__} and {type(local_pos).__name__} "
            "(use fk_positions_fast_np for NumPy arrays)"
        )
    if local_rot.ndim < 2 or local_rot.shape[-1] != 4:
        raise ValueError(f"expected local_rot of shape (..., J, 4), got {tuple(local_rot.shape)}")
    num_joints = local_rot.shape[-2]
    if local_pos.ndim < 2 or local_pos.shape[-2:] != (num_joints, 3):
        raise ValueError(f"expected local_pos of shape (..., {num_joints}, 3), got {tuple(local_pos.shape)}")
    if root_pos is not None and (root_pos.ndim < 1 or root_pos.shape[-1] != 3):
        raise ValueError(f"expected root_pos of shape (..., 3), got {tuple(root_pos.shape)}")
    parents = _check_parents(parents, num_joints)
    chunk = _check_chunk(chunk)
    try:
        batch = torch.broadcast_shapes(
            local_rot.shape[:-2], local_pos.shape[:-2], *(() if root_pos is None else (root_pos.shape[:-1],))
        )
    except RuntimeError:
        raise ValueError(
            f"leading shapes do not broadcast: local_rot {tuple(local_rot.shape)}, local_pos {tuple(local_pos.shape)}"
            + ("" if root_pos is None else f", root_pos {tuple(root_pos.shape)}")
        ) from None
    return parents, chunk, batch


def _reference_fk(local_rot, local_pos, parents, root_pos, batch, out):
    """:func:`fk_torch.fk_positions` with ``root_pos`` applied (gradients, other devices and dtypes)."""
    if root_pos is not None:
        local_pos = local_pos.expand(batch + (local_rot.shape[-2], 3)).clone()
        local_pos[..., 0, :] = root_pos
    result = fk_torch.fk_positions(local_rot, local_pos, parents)
    if out is not None:
        out.copy_(result)
        return out
    return result


def _flat_inputs(local_rot, local_pos, root_pos, batch, n: int):
    """Inputs flattened to ``n`` frames: ``(rot (n, J, 4), pos, offsets (J, 3), shared)``.

    ``shared``: one set of offsets for all frames, and ``pos`` is only the root (n, 3);
    otherwise ``pos`` is every joint's (n, J, 3) and ``offsets`` are zeros.
    """
    num_joints, dtype = local_rot.shape[-2], local_rot.dtype
    rot = local_rot.expand(batch + (num_joints, 4)).reshape(n, num_joints, 4)
    shared = math.prod(local_pos.shape[:-2]) == 1
    if shared:  # one set of offsets for all frames; per-frame data is only the root
        offsets = local_pos.reshape(num_joints, 3).to(dtype).contiguous()
        if root_pos is None:
            root = offsets[0].expand(n, 3)
        else:
            root = root_pos.to(dtype).expand(batch + (3,)).reshape(n, 3)
        pos = root.contiguous() if root_pos is not None else root
    else:
        full = local_pos.to(dtype).expand(batch + (num_joints, 3))
        if root_pos is not None:
            full = full.clone()
            full[..., 0, :] = root_pos
        pos = full.reshape(n, num_joints, 3)
        offsets = torch.zeros(num_joints, 3, dtype=dtype)
    return rot, pos, offsets, shared


def _result_buffer(out, batch, n: int, num_joints: int, dtype) -> torch.Tensor:
    """The (n, J, 3) tensor to write into: a view of ``out`` (checked), or a new one."""
    if out is None:
        # NumPy allocates big buffers on transparent huge pages, which saves one page fault per
        # 4 KiB on first touch; torch does so only with THP_MEM_ALLOC_ENABLE=1.
        return torch.from_numpy(np.empty((n, num_joints, 3), dtype=_NUMPY_DTYPE[dtype]))
    if tuple(out.shape) != tuple(batch) + (num_joints, 3) or out.dtype != dtype or not out.is_contiguous():
        raise ValueError(
            f"expected out as a contiguous {dtype} tensor of shape {tuple(batch) + (num_joints, 3)}, "
            f"got {out.dtype} {tuple(out.shape)}"
        )
    return out.view(n, num_joints, 3)


def _compiled_chunks(kernel, key, rot, pos, offsets, result, chunk: int) -> int:
    """Run the compiled kernel over whole chunks, then the tail padded with identity rotations.

    Returns how many frames were done (fewer than all if the kernel failed part way).
    """
    n, num_joints, dtype = rot.shape[0], rot.shape[1], rot.dtype
    done = 0
    full_chunks = n // chunk * chunk
    for start in range(0, full_chunks, chunk):
        stop = start + chunk
        if not _run_chunk(
            kernel, key, rot[start:stop].contiguous(), pos[start:stop].contiguous(), offsets, result[start:stop]
        ):
            break
        done = stop
    if done == full_chunks < n:  # the tail, padded to a whole chunk with identity rotations
        rest = n - full_chunks
        rot_c = torch.zeros((chunk, num_joints, 4), dtype=dtype)
        rot_c[:, :, 0] = 1.0
        rot_c[:rest] = rot[full_chunks:]
        pos_c = torch.zeros((chunk,) + tuple(pos.shape[1:]), dtype=dtype)
        pos_c[:rest] = pos[full_chunks:]
        tail = torch.empty((chunk, num_joints, 3), dtype=dtype)
        if _run_chunk(kernel, key, rot_c, pos_c, offsets, tail):
            result[full_chunks:] = tail[:rest]
            done = n
    return done


def fk_positions_fast(
    local_rot: torch.Tensor,
    local_pos: torch.Tensor,
    parents,
    *,
    root_pos: torch.Tensor | None = None,
    chunk: int = DEFAULT_CHUNK,
    compile: bool = True,  # noqa: A002 - mirrors the torch.compile wording users know
    out: torch.Tensor | None = None,
) -> torch.Tensor:
    """World joint positions (..., J, 3), equal to ``fk_torch.fk_positions`` but faster on big batches.

    Parameters
    ----------
    local_rot : Tensor, shape (..., J, 4)   unit quaternions (w, x, y, z) relative to the parent
    local_pos : Tensor, shape (..., J, 3) or (J, 3)
        Offset from the parent joint (root: world position), metres. Leading shapes broadcast
        with ``local_rot``. When it does not vary over the batch (e.g. the skeleton's offsets),
        only the root position (if any) is read per frame.
    parents   : sequence of int, length J   parent index, -1 for the root, parents[j] < j
    root_pos  : Tensor, shape (..., 3), optional
        World position of the root per frame. It replaces ``local_pos[..., 0, :]``, so that
        ``local_pos`` can be the (J, 3) rest offsets (the layout pymotion and BVH use).
    chunk     : int   frames per compiled call, a multiple of :data:`BLOCK`; one kernel per value
    compile   : bool  False runs the blocked algorithm eagerly (no compile time, slower)
    out       : Tensor, shape (..., J, 3), optional   contiguous buffer to write into (reused memory)

    Returns
    -------
    Tensor, shape (..., J, 3), dtype of ``local_rot``

    Notes
    -----
    Forward only. When gradients are needed, on non-CPU devices and for dtypes other than
    float32/float64, the call falls through to :func:`motionlab.core.fk_torch.fk_positions`.
    """
    parents, chunk, batch = _check_fast_args(local_rot, local_pos, parents, root_pos, chunk)
    num_joints, dtype = local_rot.shape[-2], local_rot.dtype
    needs_grad = torch.is_grad_enabled() and any(
        t is not None and t.requires_grad for t in (local_rot, local_pos, root_pos)
    )
    if needs_grad or local_rot.device.type != "cpu" or dtype not in _FAST_DTYPES:
        return _reference_fk(local_rot, local_pos, parents, root_pos, batch, out)

    n = math.prod(batch)
    rot, pos, offsets, shared = _flat_inputs(local_rot, local_pos, root_pos, batch, n)
    result = _result_buffer(out, batch, n, num_joints, dtype)
    if n == 0:
        return result.view(batch + (num_joints, 3)) if out is None else out

    kernel = _get_kernel(parents, shared, dtype, chunk, compile)
    key = _key(parents, shared, dtype, chunk)
    with torch.no_grad():
        done = _compiled_chunks(kernel, key, rot, pos, offsets, result, chunk) if kernel is not None else 0
        for start in range(done, n, EAGER_CHUNK):  # eager fallback (compile off or failed)
            stop = min(start + EAGER_CHUNK, n)
            _eager_chunk(parents, shared, rot[start:stop], pos[start:stop], offsets, result[start:stop])
    return result.view(batch + (num_joints, 3)) if out is None else out


def warmup(
    parents,
    *,
    dtype: torch.dtype = torch.float32,
    shared_offsets: bool = False,
    chunk: int = DEFAULT_CHUNK,
) -> float:
    """Compile the kernel for this skeleton ahead of time; returns the seconds the first call took.

    ``shared_offsets`` picks the variant used when ``local_pos`` is the same for every frame
    (or ``root_pos`` is given); ``False`` the variant for per-frame ``local_pos``. Calling it
    again for the same key costs one chunk of FK (milliseconds).
    """
    parents = tuple(int(p) for p in np.asarray(parents).reshape(-1).tolist())
    parents = _check_parents(parents, len(parents))
    chunk = _check_chunk(chunk)
    num_joints = len(parents)
    rot = torch.zeros((chunk, num_joints, 4), dtype=dtype)
    rot[..., 0] = 1.0
    offsets = torch.zeros((num_joints, 3), dtype=dtype)
    t0 = time.perf_counter()
    if shared_offsets:
        fk_positions_fast(rot, offsets, parents, root_pos=torch.zeros((chunk, 3), dtype=dtype), chunk=chunk)
    else:
        fk_positions_fast(rot, torch.zeros((chunk, num_joints, 3), dtype=dtype), parents, chunk=chunk)
    return time.perf_counter() - t0


def is_compiled(
    parents, *, dtype: torch.dtype = torch.float32, shared_offsets: bool = False, chunk: int = DEFAULT_CHUNK
) -> bool:
    """Whether a compiled kernel is in use for this key (False after a fallback to eager)."""
    parents = tuple(int(p) for p in (parents.tolist() if hasattr(parents, "tolist") else parents))
    return _kernels.get(_key(parents, shared_offsets, dtype, _check_chunk(chunk))) is not None


# ---------------------------------------------------------------------------------- NumPy
def fk_positions_fast_np(local_rot, local_pos, parents, *, root_pos=None, chunk: int = 8192) -> np.ndarray:
    """World joint positions (..., J, 3) in NumPy, blocked like :func:`fk_positions_fast`.

    The same result as ``fk.fk_positions``. Each chunk is transposed to component-major rows
    of ``chunk`` frames, so every NumPy operation is one long contiguous vector operation.

    Parameters
    ----------
    local_rot : array, shape (..., J, 4)   unit quaternions (w, x, y, z) relative to the parent
    local_pos : array, shape (..., J, 3) or (J, 3)   offsets from the parent (root: world position), metres
    parents   : sequence of int, length J
    root_pos  : array, shape (..., 3), optional   replaces ``local_pos[..., 0, :]``
    chunk     : int   frames per step (8192 keeps a 22-joint chunk within a few MB)

    Raises
    ------
    ValueError when an array has the wrong trailing shape, the leading shapes do not
    broadcast, or ``chunk`` < 1.
    """
    local_rot = np.asarray(local_rot)
    if local_rot.ndim < 2 or local_rot.shape[-1] != 4:
        raise ValueError(f"expected local_rot of shape (..., J, 4), got {local_rot.shape}")
    if not np.issubdtype(local_rot.dtype, np.floating):
        local_rot = local_rot.astype(np.float64)
    dtype = local_rot.dtype
    num_joints = local_rot.shape[-2]
    local_pos = np.asarray(local_pos, dtype=dtype)
    if local_pos.ndim < 2 or local_pos.shape[-2:] != (num_joints, 3):
        raise ValueError(f"expected local_pos of shape (..., {num_joints}, 3), got {local_pos.shape}")
    if root_pos is not None:
        root_pos = np.asarray(root_pos, dtype=dtype)
        if root_pos.ndim < 1 or root_pos.shape[-1] != 3:
            raise ValueError(f"expected root_pos of shape (..., 3), got {root_pos.shape}")
    parents = _check_parents(parents, num_joints)
    chunk = int(chunk)
    if chunk < 1:
        raise ValueError(f"chunk must be a positive number of frames, got {chunk}")
    shapes = [local_rot.shape[:-2], local_pos.shape[:-2]] + ([] if root_pos is None else [root_pos.shape[:-1]])
    try:
        batch = np.broadcast_shapes(*shapes)
    except ValueError:
        raise ValueError(f"leading shapes do not broadcast: {shapes}") from None
    n = math.prod(batch)
    rot = np.broadcast_to(local_rot, batch + (num_joints, 4)).reshape(n, num_joints, 4)
    shared = math.prod(local_pos.shape[:-2]) == 1
    if shared:
        offsets = local_pos.reshape(num_joints, 3)
        root = np.broadcast_to(offsets[0] if root_pos is None else root_pos, batch + (3,)).reshape(n, 3)
    else:
        full = np.broadcast_to(local_pos, batch + (num_joints, 3))
        if root_pos is not None:
            full = full.copy()
            full[..., 0, :] = root_pos
        pos = full.reshape(n, num_joints, 3)
    result = np.empty((n, num_joints, 3), dtype=dtype)
    for start in range(0, n, chunk):
        stop = min(start + chunk, n)
        rot_t = np.ascontiguousarray(rot[start:stop].reshape(stop - start, num_joints * 4).T)
        w, x, y, z = (rot_t[k::4] for k in range(4))
        if shared:
            root_t = np.ascontiguousarray(root[start:stop].T)
            px, py, pz = ([root_t[k]] + [offsets[j, k] for j in range(1, num_joints)] for k in range(3))
        else:
            pos_t = np.ascontiguousarray(pos[start:stop].reshape(stop - start, num_joints * 3).T)
            px, py, pz = (pos_t[k::3] for k in range(3))
        rows = _chain_positions(parents, w, x, y, z, px, py, pz)
        result[start:stop].reshape(stop - start, num_joints * 3).T[...] = np.stack(rows)
    return result.reshape(batch + (num_joints, 3))
