"""Adam's update of the latent offset and backtracking's step-size factors: the arithmetic that
the solver's host loop (:mod:`.solver`) and the device loop (:mod:`.device_loop`) both run.

Written out rather than ``torch.optim.Adam``, whose arithmetic it follows, because every row of a
batch has its own step size and step count (the rows of one problem share them), and because
each iterate is put back on a grid (:func:`.grid.step_grid`), so that the iterates are the same
on every CPU.
"""

from __future__ import annotations

import torch

__all__ = ["BETAS", "EPS", "GROW", "SHRINK", "bias_corrections", "update"]

BETAS, EPS = (0.9, 0.999), 1e-8
"""Adam's defaults (Kingma and Ba 2015), as ``torch.optim.Adam`` has them."""

GROW, SHRINK = 1.1, 0.5
"""Backtracking's step-size factors after a step that lowered ``L_iter`` and after one that did
not: the "bold driver" rule's classic values (grow a little on success, halve on failure), not
tuned here; the step never grows past the configured ``lr · std(φ₀)``."""


def bias_corrections(count: int) -> tuple[float, float]:
    """``(1 − β₁ᶜ, √(1 − β₂ᶜ))`` for step count ``c = count`` (≥ 1), as Python floats (as Adam's)."""
    b1, b2 = BETAS
    return 1 - b1 ** float(count), (1 - b2 ** float(count)) ** 0.5


def update(delta, grad, m, v, step_size, root2, grid) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """One Adam step of the rows given: ``(m, v, δ)`` after it, δ rounded to ``grid``. All (rows, T,
    D) but ``step_size`` (``lr / (1 − β₁ᶜ)``), ``root2`` (``√(1 − β₂ᶜ)``) and ``grid``, (rows, 1, 1).
    The inputs are not changed."""
    b1, b2 = BETAS
    m = m.lerp(grad, 1 - b1)
    v = v.mul(b2).addcmul_(grad, grad, value=1 - b2)
    d = delta + (-step_size * m) / (v.sqrt() / root2).add_(EPS)
    return m, v, torch.round(d / grid) * grid
