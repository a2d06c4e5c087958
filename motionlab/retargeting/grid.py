"""The grid iterates are rounded to, so that the latent iteration and training take the same steps
on every CPU (``docs/reproducibility.md``).

Its own module because both :mod:`.solver` and :mod:`.train` use it: the real network's cache key
(:data:`.real.TRAINING_CODE`) covers this file, not the solver's.
"""

from __future__ import annotations

import math

__all__ = ["step_grid"]


def step_grid(size: float) -> float:
    """The spacing iterates are rounded to: the power of two just below ``size · 2⁻¹²``.

    The latent iteration (:mod:`.solver`) rounds its start φ₀ to ``step_grid(std(φ₀))`` and the
    latent offset, after each Adam step, to ``step_grid(lr)`` (``lr`` the group's actual step
    size); training (:mod:`.train`) rounds the weights the same way. Differences
    in the last bits of the gradients (another CPU's kernels add in another order) are rounded
    away instead of growing step by step, so the iterates, and the step at which the stopping rule
    stops, are the same on every CPU (``docs/reproducibility.md``,
    ``experiments/retargeting/reproducibility.py``).
    """
    return 2.0 ** math.floor(math.log2(size) - 12)
