"""The Skeleton: joint names, a parent tree and rest offsets.

A skeleton is immutable. Joints are stored in topological order (every parent precedes its
children) with exactly one root (parent ``-1``) at index 0. Offsets are in metres, expressed in
the parent's frame at rest (the rest pose has identity local rotations), and the root's offset
is its rest position.

Taught in ``notebooks/00_quaternions_and_fk.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Skeleton", "SkeletonError"]


class SkeletonError(ValueError):
    """An invalid joint tree: bad parent order, several roots, unknown or duplicate names."""


@dataclass(frozen=True, eq=False)
class Skeleton:
    """A joint hierarchy.

    Attributes
    ----------
    names : tuple of str, length J          joint names, unique
    parents : ndarray of int, shape (J,)    parent index, ``-1`` for the root; ``parents[j] < j``
    offsets : ndarray, shape (J, 3)         rest offset from the parent joint, metres
    end_sites : dict {joint index: ndarray (3,)}
        BVH ``End Site`` offsets (metres), kept so that files round-trip and heads have a top.
    channels : tuple of tuple of str, or None
        The BVH channel layout of each joint (e.g. ``("Xposition", ..., "Zrotation")``);
        used by ``bvh.save`` to write a file back in its own layout (with the missing rotation
        axes added: three rotation channels per joint, for Blender). ``None``: the default
        layout (root: positions + ZYX rotations, others: ZYX rotations).
    """

    names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)
    channels: tuple[tuple[str, ...], ...] | None = None

    def __post_init__(self) -> None:
        names = tuple(str(n) for n in self.names)
        parents = np.array(self.parents, dtype=np.int64).reshape(-1)  # a copy: never alias the caller's array
        offsets = np.asarray(self.offsets, dtype=np.float64)
        n = len(names)
        if n == 0:
            raise SkeletonError("a skeleton needs at least one joint")
        if parents.shape != (n,):
            raise SkeletonError(f"expected {n} parent indices (one per joint), got {parents.shape[0]}")
        if offsets.shape != (n, 3):
            raise SkeletonError(f"expected offsets of shape ({n}, 3), got {offsets.shape}")
        if not np.all(np.isfinite(offsets)):
            bad = names[int(np.argwhere(~np.isfinite(offsets))[0, 0])]
            raise SkeletonError(f"offset of joint {bad!r} is not finite")
        if parents[0] != -1:
            raise SkeletonError(f"joint 0 ({names[0]!r}) must be the root (parent -1), got parent {parents[0]}")
        for j in range(1, n):
            if parents[j] == -1:
                raise SkeletonError(f"joint {names[j]!r} is a second root; a skeleton has exactly one")
            if not 0 <= parents[j] < j:
                raise SkeletonError(
                    f"joint {names[j]!r} (index {j}) has parent index {parents[j]}; parents must precede their children"
                )
        seen: dict[str, int] = {}
        for j, name in enumerate(names):
            if name in seen:
                raise SkeletonError(f"duplicate joint name {name!r} (indices {seen[name]} and {j})")
            seen[name] = j
        end_sites = {}
        for j, off in dict(self.end_sites).items():
            if not 0 <= int(j) < n:
                raise SkeletonError(f"end site attached to joint index {j}, but there are {n} joints")
            end_sites[int(j)] = np.array(off, dtype=np.float64).reshape(3)
        if self.channels is not None and len(self.channels) != n:
            raise SkeletonError(f"expected {n} channel layouts (one per joint), got {len(self.channels)}")
        parents.setflags(write=False)
        offsets = offsets.copy()
        offsets.setflags(write=False)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "end_sites", end_sites)
        if self.channels is not None:
            object.__setattr__(self, "channels", tuple(tuple(c) for c in self.channels))

    # ------------------------------------------------------------------ basic queries
    @property
    def num_joints(self) -> int:
        """Number of joints J."""
        return len(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def __repr__(self) -> str:
        return f"Skeleton({self.num_joints} joints, root={self.names[0]!r}, height={self.height():.3f} m)"

    def index(self, name: str) -> int:
        """Index of the joint called ``name``; a ``KeyError`` lists close names when absent.

        Raises
        ------
        KeyError naming ``name`` and the closest joint names when there is no such joint.
        """
        try:
            return self.names.index(name)
        except ValueError:
            close = [n for n in self.names if name.lower() in n.lower()][:5]
            hint = f"; similar: {close}" if close else ""
            raise KeyError(f"no joint named {name!r} in this skeleton{hint}") from None

    def children(self, j: int) -> list[int]:
        """Indices of the direct children of joint ``j``."""
        return [int(c) for c in np.flatnonzero(self.parents == j)]

    def subtree(self, j: int) -> np.ndarray:
        """Mask (J,) of joint ``j`` and every joint below it (one pass: parents precede children)."""
        inside = np.zeros(self.num_joints, dtype=bool)
        inside[j] = True
        for k in range(j + 1, self.num_joints):
            inside[k] = inside[self.parents[k]]
        return inside

    def ancestors(self, j: int) -> list[int]:
        """Indices of the joints above joint ``j``, from joint 0 down to ``j``'s parent (empty for 0)."""
        chain, k = [], int(self.parents[j])
        while k >= 0:  # one walk up the chain of parents
            chain.append(k)
            k = int(self.parents[k])
        return chain[::-1]

    def depth(self) -> np.ndarray:
        """Number of ancestors of each joint, shape (J,)."""
        d = np.zeros(self.num_joints, dtype=np.int64)
        for j in range(1, self.num_joints):
            d[j] = d[self.parents[j]] + 1
        return d

    # ------------------------------------------------------------------ geometry
    def rest_positions(self) -> np.ndarray:
        """World positions (J, 3) in the rest pose (identity rotations), metres."""
        pos = np.zeros((self.num_joints, 3))
        pos[0] = self.offsets[0]
        for j in range(1, self.num_joints):
            pos[j] = pos[self.parents[j]] + self.offsets[j]
        return pos

    def bone_lengths(self) -> np.ndarray:
        """Length (J,) of the bone from each joint's parent to it, metres (0 for the root)."""
        lengths = np.linalg.norm(self.offsets, axis=-1)
        lengths[0] = 0.0
        return lengths

    def height(self) -> float:
        """Rest-pose height: highest minus lowest joint along +Y, metres (end sites not counted)."""
        y = self.rest_positions()[:, 1]
        return float(y.max() - y.min())

    # ------------------------------------------------------------------ derived skeletons
    def with_offsets(self, offsets: np.ndarray) -> Skeleton:
        """The same tree with new rest offsets (J, 3); end sites scale with their bone.

        Raises
        ------
        SkeletonError when ``offsets`` is not (J, 3).
        """
        offsets = np.asarray(offsets, dtype=np.float64)
        if offsets.shape != self.offsets.shape:
            raise SkeletonError(f"expected offsets of shape {self.offsets.shape}, got {offsets.shape}")
        end_sites = {}
        for j, off in self.end_sites.items():
            old = np.linalg.norm(self.offsets[j])
            ratio = np.linalg.norm(offsets[j]) / old if old > 1e-12 else 1.0
            end_sites[j] = off * ratio
        return Skeleton(self.names, self.parents, offsets, end_sites, self.channels)

    def scaled(self, factor: float) -> Skeleton:
        """Uniformly scaled copy (every offset and end site times ``factor``)."""
        return Skeleton(
            self.names,
            self.parents,
            self.offsets * factor,
            {j: o * factor for j, o in self.end_sites.items()},
            self.channels,
        )

    def renamed(self, names: Sequence[str]) -> Skeleton:
        """The same skeleton with new joint names."""
        return Skeleton(tuple(names), self.parents, self.offsets, self.end_sites, self.channels)

    def subset(self, keep: Sequence[int]) -> tuple[Skeleton, np.ndarray]:
        """Skeleton of the joints ``keep`` (topological order kept); each joint re-parents to its
        nearest kept ancestor with the rest offset summed along the removed chain.

        Returns the new skeleton and the kept indices as an array.

        Raises
        ------
        SkeletonError when ``keep`` drops the root joint.
        """
        keep = np.array(sorted(set(int(k) for k in keep)), dtype=np.int64)
        if keep.size == 0 or keep[0] != 0:
            raise SkeletonError("a subset must keep the root joint")
        new_index = -np.ones(self.num_joints, dtype=np.int64)
        new_index[keep] = np.arange(keep.size)
        rest = self.rest_positions()
        parents, offsets = [], []
        for j in keep:
            p = self.parents[j]
            while p >= 0 and new_index[p] < 0:
                p = self.parents[p]
            parents.append(-1 if p < 0 else int(new_index[p]))
            offsets.append(self.offsets[j] if p < 0 else rest[j] - rest[p])
        end_sites = {int(new_index[j]): o for j, o in self.end_sites.items() if new_index[j] >= 0}
        return Skeleton(tuple(self.names[j] for j in keep), np.array(parents), np.array(offsets), end_sites), keep

    def equals(self, other: Skeleton, atol: float = 1e-9) -> bool:
        """Same names, parents and offsets (within ``atol``)."""
        return (
            self.names == other.names
            and np.array_equal(self.parents, other.parents)
            and np.allclose(self.offsets, other.offsets, atol=atol)
        )
