"""The latent iteration with its bookkeeping on the device, so that one CUDA graph holds a whole step.

:mod:`.solver` runs each step of the iteration (decode, the terms, the gradient) and then, on the
host, the rules around it: the stopping rule and the best iterate (``solver._Track``),
backtracking and Adam's update (``solver._adam_step``, :mod:`.adam`). On a GPU those rules are what the step
waits on: small kernels launched one by one from Python, and a read-back of the losses at every
step (``docs/performance.md``). Here the same rules are tensor operations over
every row of the batch, a group that has stopped masked rather than dropped, so that the step and
its rules are recorded together as one CUDA graph (:mod:`.graphs`). The host then reads one
flag, whether any group still runs, every :data:`CHECK_EVERY` steps; steps replayed after every
group has stopped change nothing.

Each group's numbers are those of the host's rules: the same float64 operations in the same
order (a test runs both on the CPU and compares steps, stops, histories and outputs). Two
quantities the host computes from Python floats come from tables or the same formula here:
Adam's bias corrections (:func:`.adam.bias_corrections`, made once on the host for every step
count) and the step grid (:func:`step_grids`, :func:`.grid.step_grid`'s formula).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from tqdm.auto import tqdm

from motionlab.retargeting import adam, graphs

__all__ = ["CHECK_EVERY", "iterate", "step_grids"]

CHECK_EVERY = 8
"""Steps replayed between two reads of "does any group still run?" (one wait for the device
each). At most ``CHECK_EVERY − 1`` steps are replayed after the last group stops. Not tuned: a
round number between waiting at every step and wasting many steps after the last stop."""

REASONS = ("max_steps", "threshold", "plateau")
"""``SolverResult.stop_reason`` by the code the device keeps (0, 1, 2)."""


def step_grids(lr: torch.Tensor) -> torch.Tensor:
    """:func:`.grid.step_grid` of each step size in ``lr`` (any shape, positive), by the same
    formula ``2 ** floor(log2(lr) − 12)``, on ``lr``'s device and float type."""
    return torch.exp2(torch.floor(torch.log2(lr) - 12.0))


@dataclass
class _State:
    """The host rules' state as tensors: per group (G,) and per row (N,), on the batch's device.

    ``running``: still iterating; ``evaluated``: evaluated at the last step; ``best_value`` and
    ``best_step``: the lowest ``L_iter`` and its step; ``plateau`` and ``since``: the plateau
    rule's best and the steps since it; ``reason``: index into :data:`REASONS`; ``steps``: Adam
    updates made; ``it``: the steps replayed; ``history`` (max_steps + 2, G, 1 + terms): row ``t``
    holds step ``t``'s values (the last row takes the steps replayed after the last stop); per row
    ``lr``, ``lr_max`` and Adam's step ``count``; ``bias1`` and ``root2`` indexed by ``count``."""

    running: torch.Tensor
    evaluated: torch.Tensor
    best_value: torch.Tensor
    best_step: torch.Tensor
    plateau: torch.Tensor
    since: torch.Tensor
    reason: torch.Tensor
    steps: torch.Tensor
    it: torch.Tensor
    history: torch.Tensor
    lr: torch.Tensor
    lr_max: torch.Tensor
    count: torch.Tensor
    bias1: torch.Tensor
    root2: torch.Tensor

    def tensors(self) -> list:
        return list(vars(self).values())


def _state(p, steps, terms: int) -> _State:
    """The rules' starting state for ``p`` (``solver._Problem``) and ``steps`` (``solver._Steps``)."""
    groups, device, dtype = len(p.sizes), steps.delta.device, steps.delta.dtype
    bias1, root2 = zip(*map(adam.bias_corrections, range(p.cfg.max_steps + 2)))  # count 0: rows not stepped

    def per_group(fill, kind=dtype):
        return torch.full((groups,), fill, dtype=kind, device=device)

    def host(values):
        return torch.as_tensor(values, dtype=dtype, device=device)

    return _State(
        running=per_group(True, torch.bool),
        evaluated=per_group(False, torch.bool),
        best_value=per_group(float("inf")),
        best_step=per_group(0, torch.int64),
        plateau=per_group(float("inf")),
        since=per_group(0, torch.int64),
        reason=per_group(0, torch.int64),
        steps=per_group(0, torch.int64),
        it=torch.zeros((), dtype=torch.int64, device=device),
        history=torch.zeros((p.cfg.max_steps + 2, groups, terms), dtype=dtype, device=device),
        lr=host(steps.lr),
        lr_max=host(steps.lr if steps.lr_max is None else steps.lr_max),
        count=torch.zeros(len(steps.lr), dtype=torch.int64, device=device),
        bias1=host(bias1),
        root2=host(root2),
    )


def _record(s: _State, p, parts: torch.Tensor, out, phi, track) -> torch.Tensor:
    """``solver._Track.record`` for every running group at once: the history, the best iterate,
    the plateau rule and the stop. ``parts`` (G, 1 + terms); returns the groups (G,) whose
    ``L_iter`` is their lowest yet."""
    s.evaluated.copy_(s.running)
    cfg, value, run = p.cfg, parts[:, 0], s.evaluated
    s.history.index_copy_(0, torch.clamp(s.it, max=len(s.history) - 1).view(1), parts[None])
    improved = run & (value < s.best_value)  # Adam can overshoot: keep the best iterate seen
    s.best_value.copy_(torch.where(improved, value, s.best_value))
    s.best_step.copy_(torch.where(improved, s.steps, s.best_step))
    rows = improved[p.group_of_row]
    for best, now in ((track.best_rot, out.local_rot), (track.best_pos, out.positions), (track.best_phi, phi)):
        best.copy_(torch.where(rows.view((-1,) + (1,) * (best.ndim - 1)), now.detach(), best))
    gain = run & (value < s.plateau * (1.0 - cfg.min_delta))
    s.plateau.copy_(torch.where(gain, value, s.plateau))
    s.since.copy_(torch.where(gain, 0, torch.where(run, s.since + 1, s.since)))
    threshold = value < cfg.threshold
    plateau = ~threshold & (s.since >= cfg.patience) if cfg.patience else torch.zeros_like(threshold)
    stop = run & (threshold | plateau | (s.steps >= cfg.max_steps))
    s.reason.copy_(torch.where(stop & threshold, 1, torch.where(stop & plateau, 2, s.reason)))
    s.running.copy_(run & ~stop)
    return improved


def _backtrack(s: _State, steps, better: torch.Tensor, worse: torch.Tensor) -> None:
    """``solver._backtrack`` on the rows ``better`` and ``worse`` (N,) (disjoint masks)."""
    grad, b, w = steps.delta.grad, better[:, None, None], worse[:, None, None]
    steps.best_delta.copy_(torch.where(b, steps.delta, steps.best_delta))
    steps.best_grad.copy_(torch.where(b, grad, steps.best_grad))
    lr = torch.where(better, torch.minimum(s.lr * adam.GROW, s.lr_max), s.lr)
    s.lr.copy_(torch.where(worse, s.lr * adam.SHRINK, lr))
    steps.delta.copy_(torch.where(w, steps.best_delta, steps.delta))
    grad.copy_(torch.where(w, steps.best_grad, grad))
    steps.m.masked_fill_(w, 0.0)
    steps.v.masked_fill_(w, 0.0)
    s.count.masked_fill_(worse, 0)
    steps.grid.copy_(step_grids(s.lr)[:, None, None])


def _update(s: _State, p, steps, improved: torch.Tensor) -> None:
    """``solver._adam_step`` on the rows of the groups still running (backtracking first when
    configured); the other rows keep their δ, moments and step count."""
    going = s.running[p.group_of_row]
    with torch.no_grad():
        if p.cfg.backtrack:
            _backtrack(s, steps, improved[p.group_of_row] & going, ~improved[p.group_of_row] & going)
        s.count.add_(going.to(torch.int64))
        step_size, root2 = (s.lr / s.bias1[s.count])[:, None, None], s.root2[s.count][:, None, None]
        m, v, delta = adam.update(steps.delta, steps.delta.grad, steps.m, steps.v, step_size, root2, steps.grid)
        g = going[:, None, None]
        steps.m.copy_(torch.where(g, m, steps.m))
        steps.v.copy_(torch.where(g, v, steps.v))
        steps.delta.copy_(torch.where(g, delta, steps.delta))
        s.steps.add_(s.running.to(torch.int64))
        s.it.add_(1)


def _whole_step(p, losses: Callable[[], tuple], steps, track, s: _State) -> Callable[[], tuple]:
    """The step :class:`graphs.StepGraph` records: ``losses()`` (every row's ``(out, phi, parts)``
    and gradient, ``solver._all_rows_step``), then the rules and the update."""

    def step() -> tuple:
        out, phi, parts = losses()
        _update(s, p, steps, _record(s, p, parts, out, phi, track))
        return (s.running,)

    return step


def iterate(p, losses: Callable[[], tuple], steps, track, callback=None, progress=False) -> None:
    """Run the latent iteration of ``p`` (``solver._Problem``) from ``steps`` (``solver._Steps``)
    to the last group's stop, each step ``losses()`` (every row's losses and gradient) and then the
    rules; fill ``track`` (``solver._Track``) as the host's loop does. With a ``callback`` the host
    reads each step's values (one wait per step)."""
    s = _state(p, steps, len(track.keys))
    kept = s.tensors() + [steps.delta, steps.m, steps.v, steps.grid, track.best_rot, track.best_pos, track.best_phi]
    kept += [t for t in (steps.best_delta, steps.best_grad) if t is not None]
    graph = graphs.StepGraph(_whole_step(p, losses, steps, track, s), steps.delta, keep=kept)
    every = 1 if callback is not None else CHECK_EVERY
    bar = tqdm(total=p.cfg.max_steps, desc="latent iteration", disable=not progress, leave=False)
    while True:
        for _ in range(every):
            graph.run()
        if callback is not None:
            _report(s, track.keys, callback)
        if not bool(s.running.any()):  # the host waits for the device here, once per `every` steps
            break
        bar.update(min(every, bar.total - bar.n))
    bar.close()
    _fill(s, track)


def _report(s: _State, keys: tuple, callback) -> None:
    """``callback(step, values)`` for each group evaluated at the last step, in group order."""
    step = int(s.it) - 1
    values = s.history[min(step, len(s.history) - 1)].tolist()
    for g in np.flatnonzero(s.evaluated.cpu().numpy()):
        callback(step, dict(zip(keys, values[g])))


def _fill(s: _State, track) -> None:
    """Copy the device's per-group results into ``track``'s host lists."""
    history, steps = s.history.cpu().numpy(), s.steps.tolist()
    track.steps[:], track.best_step[:] = steps, s.best_step.tolist()
    track.best_value[:] = s.best_value.tolist()
    track.reasons[:] = [REASONS[r] for r in s.reason.tolist()]
    for g, n in enumerate(steps):
        track.histories[g] = {k: history[: n + 1, g, j].tolist() for j, k in enumerate(track.keys)}
