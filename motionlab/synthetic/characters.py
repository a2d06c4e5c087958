"""Characters: random humanoids with other proportions, for retargeting experiments.

Every character is the canonical 22-joint T-pose (:func:`~motionlab.core.humanoid.canonical_skeleton`)
with its bone groups stretched by :func:`~motionlab.core.humanoid.scale_bones` (legs, arms,
spine, neck) and then scaled to a random stature. A :class:`Character` *is* a
:class:`~motionlab.core.skeleton.Skeleton`, so it goes wherever a skeleton does, and also
carries a name and the factors it was made with::

    cast = characters.character_set(30, seed=0)
    cast[3].name, cast[3].proportions["legs"], cast[3].height()

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from motionlab.core.humanoid import JOINTS, canonical_skeleton, scale_bones
from motionlab.core.skeleton import Skeleton

__all__ = ["Character", "RANGES", "stature", "random_character", "character_set"]

RANGES: dict[str, tuple[float, float]] = {
    "legs": (0.7, 1.35),
    "arms": (0.7, 1.4),
    "spine": (0.8, 1.3),
    "neck": (0.8, 1.3),
    "height": (1.0, 2.1),
}
"""Default sampling ranges: bone-group factors (1 = average adult) and stature in metres."""


@dataclass(frozen=True, eq=False)
class Character(Skeleton):
    """A canonical 22-joint skeleton with a name and the proportions it was made from.

    Attributes
    ----------
    name : str                  e.g. ``"char07"``
    proportions : dict          ``legs``, ``arms``, ``spine``, ``neck`` factors and ``height`` (m)
    """

    name: str = ""
    proportions: dict[str, float] = field(default_factory=dict)

    def __repr__(self) -> str:
        parts = ", ".join(f"{k}={v:.2f}" for k, v in self.proportions.items())
        return f"Character({self.name!r}, {parts})"


def stature(skeleton: Skeleton) -> float:
    """Top of the head (the head's end site, if any) above the lowest joint at rest, metres."""
    rest = skeleton.rest_positions()
    head = JOINTS.index("Head")
    top = rest[head, 1] + (skeleton.end_sites[head][1] if head in skeleton.end_sites else 0.0)
    return float(max(top, rest[:, 1].max()) - rest[:, 1].min())


def _generator(rng) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, (int, np.integer)):
        return np.random.default_rng(rng)
    raise ValueError(f"expected a numpy Generator, an int seed or None, got {type(rng).__name__}")


def random_character(
    rng: np.random.Generator | int | None = 0, name: str = "", **ranges: tuple[float, float]
) -> Character:
    """A plausible humanoid with random proportions.

    Parameters
    ----------
    rng : numpy Generator, or an int seed
    name : str                      the character's name (default ``"character"``)
    **ranges : (low, high)          override entries of :data:`RANGES`
        (``legs``, ``arms``, ``spine``, ``neck`` factors; ``height`` in metres)

    Returns
    -------
    Character   T-pose, Y up, facing +Z, lowest joint at the canonical skeleton's height

    Raises
    ------
    ValueError for an unknown proportion range or one not 0 < low <= high.
    """
    rng = _generator(rng)
    unknown = sorted(set(ranges) - set(RANGES))
    if unknown:
        raise ValueError(f"unknown proportion ranges {unknown}; expected some of {sorted(RANGES)}")
    bounds = {**RANGES, **ranges}
    for key, (lo, hi) in bounds.items():
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
            raise ValueError(f"range {key!r} must satisfy 0 < low <= high, got ({lo}, {hi})")
    draw = {key: float(rng.uniform(*bounds[key])) for key in ("legs", "arms", "spine", "neck", "height")}
    body = scale_bones(canonical_skeleton(), draw["legs"], draw["arms"], draw["spine"], draw["neck"])
    body = body.scaled(draw["height"] / stature(body))
    return Character(body.names, body.parents, body.offsets, body.end_sites, name=name or "character", proportions=draw)


def character_set(n: int, seed: int = 0, **ranges: tuple[float, float]) -> list[Character]:
    """``n`` random characters named ``"char00"``, ``"char01"``, …; deterministic under ``seed``.

    Raises
    ------
    ValueError unless ``n`` is a whole number >= 0.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"n must be a non-negative integer, got {n!r}")
    rng = np.random.default_rng(seed)
    return [random_character(rng, f"char{i:02d}", **ranges) for i in range(int(n))]
