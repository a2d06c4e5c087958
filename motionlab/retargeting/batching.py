"""Many (clip, character) pairs through one latent-iteration batch.

The single-pair path (:func:`motionlab.retargeting.pipeline.retarget`) prepares the source,
prepares the target, solves, and turns the answer into B's Motion. :func:`solve_pairs` runs the
same four steps for a list of pairs, but solves all of them together with
:func:`motionlab.retargeting.solver.solve_many`: each pair keeps its own loss, Adam step,
stopping rule and best iterate, and every number of a sequence is computed without looking at
the other sequences of the batch, so each output is bit-for-bit the single-pair output (a test
checks it).

**What can share a batch.** The network's latent is per frame and a clip is solved as one
sequence (no windows, no seams, as in the single-pair path), so the sequences of one batch must
have the same number of frames. :func:`plan_batches` therefore groups pairs by length (one clip
onto all characters always qualifies; clips of equal length join them) and cuts each group so
that a batch holds at most ``max_frames`` frames, chosen from memory by :func:`batch_frames`.

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
from motionlab.retargeting.pipeline import PreparedSource, RetargetResult, finish, prepare_pair, prepare_source
from motionlab.retargeting.solver import SolverConfig, solve_many

__all__ = ["BYTES_PER_FRAME", "Pair", "PairResult", "batch_frames", "plan_batches", "solve_pairs", "quality"]

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
    prepared : PreparedSource or None   the source side, when already computed in this process
    """

    clip: str
    character: str
    source: Motion
    target: Skeleton
    frames: int
    prepared: PreparedSource | None = None


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


def plan_batches(pairs: Sequence[Pair], max_frames: int) -> list[list[Pair]]:
    """Group pairs of equal length into batches of at most ``max_frames`` frames (at least one pair).

    Longest clips first, pairs kept in their given order within a length; deterministic.

    Raises
    ------
    ValueError when ``max_frames`` < 1.
    """
    if max_frames < 1:
        raise ValueError(f"max_frames must be >= 1, got {max_frames}")
    by_length: dict[int, list[Pair]] = {}
    for p in pairs:
        by_length.setdefault(p.frames, []).append(p)
    batches = []
    for frames in sorted(by_length, reverse=True):
        group = by_length[frames]
        size = max(1, max_frames // frames)
        batches.extend(group[i : i + size] for i in range(0, len(group), size))
    return batches


def quality(result: RetargetResult) -> dict[str, float]:
    """Foot penetration (cm, mean depth of the four foot joints below y = 0) and skating (cm/s,
    mean horizontal foot speed while touching the ground) of a retargeted clip
    (:func:`motionlab.core.metrics.foot_penetration` / :func:`~motionlab.core.metrics.foot_skating`)."""
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    pos = result.positions
    return {
        "penetration_cm": 100.0 * metrics.foot_penetration(pos, feet),
        "skating_cm_s": 100.0 * metrics.foot_skating(pos, feet, result.motion.fps),
    }


def solve_pairs(
    checkpoint: Checkpoint,
    pairs: Sequence[Pair],
    solver: SolverConfig | None = None,
    root_mode: str = "stride",
) -> list[PairResult]:
    """Retarget every pair with one batched latent iteration (all pairs must have equal ``frames``).

    Steps per pair are those of :func:`~motionlab.retargeting.pipeline.retarget` with
    ``method="full"``; the solve is :func:`~motionlab.retargeting.solver.solve_many`.
    Raises ``ValueError`` when the pairs differ in length.
    """
    if not pairs:
        return []
    lengths = {p.frames for p in pairs}
    if len(lengths) != 1:
        raise ValueError(f"a batch needs pairs of one length, got lengths {sorted(lengths)}")
    solver = solver or SolverConfig()
    prepared: dict[int, PreparedSource] = {}
    jobs = []
    for p in pairs:
        key = id(p.source)
        if key not in prepared:
            prepared[key] = p.prepared or prepare_source(p.source, checkpoint, "full", solver)
        jobs.append(prepare_pair(prepared[key], p.target, root_mode))
    if jobs[0].source.motion.num_frames != pairs[0].frames:
        raise ValueError(
            f"pair {pairs[0].clip!r}: {jobs[0].source.motion.num_frames} frames, planned {pairs[0].frames}"
        )
    start = time.perf_counter()
    x = torch.cat([j.source.x for j in jobs])
    theta = torch.cat([j.source.theta for j in jobs])
    offsets = torch.stack([j.offsets for j in jobs])
    height = torch.cat([j.root_height for j in jobs])
    solved = solve_many(
        checkpoint.model,
        x,
        theta,
        offsets,
        height,
        solver,
        root_xz=torch.cat([j.root_xz for j in jobs]),
        yaw=torch.cat([j.source.yaw for j in jobs]),
        planted=torch.cat([j.source.planted for j in jobs]),
        fps=torch.tensor([j.source.motion.fps for j in jobs], dtype=x.dtype, device=x.device),
        inputs={"floor": torch.cat([j.floor for j in jobs])},
    )
    out = []
    for p, job, res in zip(pairs, jobs, solved):
        r = finish(job, res.local_rot[0], "full", res.history, res.stop_reason, res.steps, res.seconds, res.best_step)
        out.append(PairResult(p.clip, p.character, r, len(pairs), 0.0))
    share = (time.perf_counter() - start) / len(pairs)
    for o in out:
        o.seconds = share
    return out
