"""Many (clip, character) pairs through one latent-iteration batch.

The single-pair path (:func:`motionlab.retargeting.pipeline.retarget`) prepares the source,
prepares the target, solves, and turns the answer into B's Motion. :func:`solve_pairs` runs the
same four steps for a list of pairs, but solves all of them together with
:func:`motionlab.retargeting.solver.solve_many`: each pair keeps its own loss, Adam step,
stopping rule and best iterate, and every number of a sequence is computed without looking at
the other sequences of the batch, so each output is bit-for-bit the single-pair output (a test
checks it).

**What can share a batch.** The network's latent is per frame and a clip is solved as one
sequence (no windows, no seams, as in the single-pair path). By default (the CPU)
:func:`plan_batches` groups pairs by length (one clip onto all characters always qualifies;
clips of equal length join them) and cuts each group so that a batch holds at most
``max_frames`` frames, chosen from memory by :func:`batch_frames`. With ``pad=True`` (``expand``
on a GPU, whose steps cost little more for many sequences than for a few) pairs of any
length share a batch, longest first, each padded to the batch's longest
(:func:`motionlab.retargeting.solver.solve_many` with ``lengths``: a padded sequence's result is
the one it gets alone, a test checks it).

Taught in ``notebooks/07_expanding_a_database.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import torch

from motionlab.core import humanoid, metrics
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.pipeline import (
    PreparedPair,
    PreparedSource,
    RetargetResult,
    finish,
    prepare_pair,
    prepare_source,
    term_inputs,
)
from motionlab.retargeting.solver import SolverConfig, SolverResult, solve_many

__all__ = [
    "BYTES_PER_FRAME",
    "Pair",
    "PairResult",
    "batch_frames",
    "plan_batches",
    "prepare_jobs",
    "solve_jobs",
    "finish_job",
    "solve_pairs",
    "quality",
]

BYTES_PER_FRAME = 32_000
"""Memory one sequence frame takes in a latent-iteration step (forward + backward + Adam state,
float32, the default network), rounded up from a measurement: the peak resident memory of
``solve_many`` grew by about 20 kB per frame between 1,500 and 15,000 frames on the CPU
(``python benchmarks/bench_expand.py --memory`` prints the figure)."""


@dataclass
class Pair:
    """One job: ``clip`` onto ``character``.

    Attributes
    ----------
    clip : str                 the clip's name (output file stem)
    character : str            the character's name (output folder)
    source : Motion            the clip as loaded (any mappable rig)
    target : Skeleton          the character's rest skeleton (any mappable rig or canonical)
    frames : int               frames after resampling to the checkpoint's rate
    prepared : PreparedSource or None   the source side, when already computed
    job : PreparedPair or None the pair prepared for the network, when already computed
    """

    clip: str
    character: str
    source: Motion
    target: Skeleton
    frames: int
    prepared: PreparedSource | None = None
    job: PreparedPair | None = None


@dataclass
class PairResult:
    """The outcome of one pair: the retargeted clip and its measures.

    Attributes
    ----------
    clip, character : str
    result : RetargetResult
    batch_size : int           sequences solved together
    seconds : float            the pair's share of the batch's wall time (batch time / batch size)
    """

    clip: str
    character: str
    result: RetargetResult
    batch_size: int
    seconds: float


def batch_frames(device: str | torch.device = "cpu", fraction: float = 0.25, cap: int = 20_000) -> int:
    """Frames per batch that fit in ``fraction`` of the free memory of ``device``.

    On a GPU the free memory is ``torch.cuda.mem_get_info``; on the CPU ``MemAvailable`` of
    ``/proc/meminfo`` (2 GiB assumed where that file does not exist). On the CPU, ``cap`` also
    applies: beyond a few thousand frames a step is compute-bound and larger batches gain nothing.
    """
    device = torch.device(device)
    if device.type == "cuda":
        free, _ = torch.cuda.mem_get_info(device)
        cap *= 10  # a GPU step is far from compute-bound at the CPU's cap
    else:
        free = 2 << 30
        try:
            with open("/proc/meminfo") as f:
                for line in f:
                    if line.startswith("MemAvailable:"):
                        free = int(line.split()[1]) * 1024
                        break
        except OSError:
            pass
    return int(max(1, min(cap, fraction * free // BYTES_PER_FRAME)))


def plan_batches(pairs: Sequence[Pair], max_frames: int, pad: bool = False) -> list[list[Pair]]:
    """Cut pairs into batches of at most ``max_frames`` frames (at least one pair); deterministic.

    ``pad=False``: pairs of equal length only, longest clips first, pairs kept in their given order
    within a length. ``pad=True``: pairs of any length, longest first (ties in their given order);
    a batch's frames are its pairs × its longest pair's frames (the padded size), and a batch's
    shortest pair has at least half its longest one's frames, so that at most half of a batch is
    padding.

    Raises
    ------
    ValueError when ``max_frames`` < 1.
    """
    if max_frames < 1:
        raise ValueError(f"max_frames must be >= 1, got {max_frames}")
    if pad:
        batches: list[list[Pair]] = []
        for p in sorted(pairs, key=lambda p: -p.frames):
            longest = batches[-1][0].frames if batches else 0
            if not batches or (len(batches[-1]) + 1) * longest > max_frames or 2 * p.frames < longest:
                batches.append([])
            batches[-1].append(p)
        return batches
    by_length: dict[int, list[Pair]] = {}
    for p in pairs:
        by_length.setdefault(p.frames, []).append(p)
    batches = []
    for frames in sorted(by_length, reverse=True):
        group = by_length[frames]
        size = max(1, max_frames // frames)
        batches.extend(group[i : i + size] for i in range(0, len(group), size))
    return batches


def quality(result: RetargetResult, unit: float = 0.01) -> dict[str, float]:
    """Foot penetration (cm, mean depth of the four foot joints below y = 0) and skating (cm/s,
    mean horizontal foot speed while touching the ground) of a retargeted clip
    (:func:`motionlab.core.metrics.foot_penetration` / :func:`~motionlab.core.metrics.foot_skating`).
    ``unit``: metres per length unit of the target's file (:func:`motionlab.core.motion_files.file_unit`;
    its positions were read as centimetres)."""
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    pos = result.positions * (unit / 0.01)  # metres
    return {
        "penetration_cm": 100.0 * metrics.foot_penetration(pos, feet),
        "skating_cm_s": 100.0 * metrics.foot_skating(pos, feet, result.motion.fps),
    }


def prepare_jobs(
    checkpoint: Checkpoint, pairs: Sequence[Pair], solver: SolverConfig | None = None, root_mode: str = "stride"
) -> list[PreparedPair]:
    """Each pair's :class:`~motionlab.retargeting.pipeline.PreparedPair` (its ``job`` when given);
    a source shared by several pairs is prepared once.

    Raises ``ValueError`` when a pair's prepared length differs from its planned ``frames``.
    """
    prepared: dict[int, PreparedSource] = {}
    jobs = []
    for p in pairs:
        if p.job is None:
            key = id(p.source)
            if key not in prepared:
                prepared[key] = p.prepared or prepare_source(p.source, checkpoint, "full", solver)
        job = p.job or prepare_pair(prepared[id(p.source)], p.target, root_mode)
        if job.source.motion.num_frames != p.frames:
            raise ValueError(f"pair {p.clip!r}: {job.source.motion.num_frames} frames, planned {p.frames}")
        jobs.append(job)
    return jobs


def _stacked(tensors: list[torch.Tensor], frames: int) -> torch.Tensor:
    """(1, T_i, ...) tensors as one (N, frames, ...) tensor, each padded by repeating its last frame."""
    return torch.cat([torch.cat([t, t[:, -1:].expand((1, frames - t.shape[1]) + t.shape[2:])], 1) for t in tensors])


def solve_jobs(
    checkpoint: Checkpoint, jobs: Sequence[PreparedPair], solver: SolverConfig | None = None
) -> list[SolverResult]:
    """The latent iteration of every job in one batch (:func:`~motionlab.retargeting.solver.solve_many`);
    jobs of other lengths are padded to the longest (``lengths``).

    Raises ``ValueError`` (from ``solve_many``) when the lengths differ and a registered term does
    not honour padded frames (:func:`motionlab.retargeting.terms.unpadded`).
    """
    inputs = [term_inputs(checkpoint, j) for j in jobs]
    lengths = [j.source.x.shape[1] for j in jobs]
    T = max(lengths)
    x = _stacked([j.source.x for j in jobs], T)
    return solve_many(
        checkpoint.model,
        x,
        _stacked([j.source.theta for j in jobs], T),
        torch.stack([j.offsets for j in jobs]),
        _stacked([j.root_height for j in jobs], T),
        solver or SolverConfig(),
        root_xz=_stacked([j.root_xz for j in jobs], T),
        yaw=_stacked([j.source.yaw for j in jobs], T),
        planted=_stacked([j.source.planted for j in jobs], T),
        fps=torch.tensor([j.source.motion.fps for j in jobs], dtype=x.dtype, device=x.device),
        inputs={key: _stacked([i[key] for i in inputs], T) for key in inputs[0]},
        lengths=lengths,
    )


def finish_job(pair: Pair, job: PreparedPair, res: SolverResult, batch_size: int, seconds: float) -> PairResult:
    """The pair's :class:`PairResult`: B's Motion and its checks (:func:`~motionlab.retargeting.pipeline.finish`)."""
    r = finish(job, res.local_rot[0], "full", res.history, res.stop_reason, res.steps, res.seconds, res.best_step)
    return PairResult(pair.clip, pair.character, r, batch_size, seconds)


def solve_pairs(
    checkpoint: Checkpoint,
    pairs: Sequence[Pair],
    solver: SolverConfig | None = None,
    root_mode: str = "stride",
) -> list[PairResult]:
    """Retarget every pair with one batched latent iteration: :func:`prepare_jobs`,
    :func:`solve_jobs`, :func:`finish_job`.

    Steps per pair are those of :func:`~motionlab.retargeting.pipeline.retarget` with
    ``method="full"``. Raises ``ValueError`` as :func:`prepare_jobs` and :func:`solve_jobs`.
    """
    if not pairs:
        return []
    start = time.perf_counter()
    jobs = prepare_jobs(checkpoint, pairs, solver, root_mode)
    solved = solve_jobs(checkpoint, jobs, solver)
    share = (time.perf_counter() - start) / len(pairs)
    return [finish_job(p, j, r, len(pairs), share) for p, j, r in zip(pairs, jobs, solved)]
