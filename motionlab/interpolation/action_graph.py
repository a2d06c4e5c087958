"""The finite-state action graph (paper C, §2.2): action nodes, allowed transitions, best frames.

* **Nodes** are actions (stand, walk, run, squat …). Each holds a recorded clip of that action,
  its per-frame features (:mod:`.features`) and a few *key frames* (:func:`.keyposes.key_frames`).
* **Edges** are allowed transitions ``a → b``. They come from data — wherever one action follows
  another in a recording (:meth:`ActionGraph.add_transitions_from`) — and from a user-editable list
  (:meth:`ActionGraph.allow`, :meth:`ActionGraph.forbid`, ``"walk -> stand"`` strings).
* **Key frames** of a node: :func:`.keyposes.node_key_frames` (PPCA latent, medoids of k-means
  sub-clusters), the one PPCA implementation of :mod:`.ppca`.
* **Best transition frames** between two nodes: the pair ``(i, j)`` of *key frames* of the two clips
  with the smallest inter-frame distance ``D(f_a(i), f_b(j))`` (eq. 2, §3.1).
* **Paths**: the shortest chain of allowed transitions from one action to another (breadth-first),
  e.g. run → walk → stand → squat.

Taught in ``notebooks/06_keypose_interpolation.ipynb``; drawn by :func:`.plots.draw_action_graph`.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from motionlab.core.motion import Motion, check_one_rig
from motionlab.interpolation.features import distance_matrix, pose_features
from motionlab.interpolation.keyposes import node_key_frames

__all__ = ["ActionNode", "ActionGraph", "GraphError", "parse_transition"]


class GraphError(ValueError):
    """An unknown action, a malformed transition, or no path between two actions."""


@dataclass
class ActionNode:
    """One action of the graph.

    Attributes
    ----------
    name : str
    motion : Motion            a recording of the action
    features : ndarray (T, D)  :func:`~.features.pose_features` of ``motion``
    keys : ndarray (n,) of int key frames (indices into ``motion``), in time order
    """

    name: str
    motion: Motion
    features: np.ndarray
    keys: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


def parse_transition(text: str) -> tuple[str, str]:
    """``"walk -> stand"`` → ``("walk", "stand")``.

    Raises
    ------
    GraphError when ``text`` is not ``from -> to``.
    """
    parts = [p.strip() for p in str(text).split("->")]
    if len(parts) != 2 or not all(parts):
        raise GraphError(f"expected a transition written 'from -> to', got {text!r}")
    return parts[0], parts[1]


class ActionGraph:
    """A finite-state machine over actions (see the module docstring)."""

    def __init__(self) -> None:
        self.nodes: dict[str, ActionNode] = {}
        self.edges: set[tuple[str, str]] = set()
        self._best: dict[tuple[str, str], tuple[int, int, float]] = {}
        self._library = None

    def __repr__(self) -> str:
        return f"ActionGraph({len(self.nodes)} actions, {len(self.edges)} transitions)"

    # ------------------------------------------------------------------ building
    def add_node(self, name: str, motion: Motion, num_keys: int = 5, seed: int = 0) -> ActionNode:
        """Add (or replace) the action ``name`` recorded by ``motion`` (at least 2 frames).

        Raises
        ------
        ValueError when ``motion`` is on another skeleton or at another frame rate than the
        graph's other actions.
        """
        others = [n.motion for n in self.nodes.values() if n.name != str(name)]
        if others:
            check_one_rig([others[0], motion.copy(name=str(name))], group=f"the action {others[0].name!r}")
        feats = pose_features(motion)
        keys, _ = node_key_frames(feats, num_keys, q=4, seed=seed)
        node = ActionNode(str(name), motion, feats, keys)
        self.nodes[node.name] = node
        self._best = {k: v for k, v in self._best.items() if name not in k}
        self._library = None
        return node

    def _need(self, *names: str) -> None:
        for n in names:
            if n not in self.nodes:
                raise GraphError(f"unknown action {n!r}; the graph has {sorted(self.nodes)}")

    def allow(self, transitions: Iterable[str | tuple[str, str]], both_ways: bool = False) -> None:
        """Add allowed transitions: ``("walk", "stand")`` pairs or ``"walk -> stand"`` strings; all
        of them or, when one names an unknown action or is malformed, none (the error names it)."""
        pairs = [parse_transition(t) if isinstance(t, str) else (str(t[0]), str(t[1])) for t in transitions]
        for a, b in pairs:
            self._need(a, b)
        for a, b in pairs:
            self.edges.add((a, b))
            if both_ways:
                self.edges.add((b, a))

    def forbid(self, transitions: Iterable[str | tuple[str, str]]) -> None:
        """Remove transitions (missing ones are ignored)."""
        for t in transitions:
            a, b = parse_transition(t) if isinstance(t, str) else (str(t[0]), str(t[1]))
            self.edges.discard((a, b))

    def add_transitions_from(self, labels: Sequence[str]) -> list[tuple[str, str]]:
        """Add an edge wherever one action follows another in a per-frame (or per-segment) label
        sequence of a recording; returns the edges found (labels not in the graph are skipped)."""
        found = []
        prev = None
        for lab in labels:
            lab = str(lab)
            if lab not in self.nodes:
                continue
            if prev is not None and lab != prev:
                found.append((prev, lab))
                self.edges.add((prev, lab))
            prev = lab
        return found

    # ------------------------------------------------------------------ queries
    def successors(self, name: str) -> list[str]:
        return sorted(b for a, b in self.edges if a == name)

    def path(self, start: str, goal: str) -> list[str]:
        """Shortest chain of allowed transitions ``[start, …, goal]`` (breadth-first search).

        Raises
        ------
        GraphError when no chain of allowed transitions leads from ``start`` to ``goal``.
        """
        self._need(start, goal)
        prev: dict[str, str | None] = {start: None}
        todo = deque([start])
        while todo:
            n = todo.popleft()
            if n == goal:
                out = [n]
                while prev[out[-1]] is not None:
                    out.append(prev[out[-1]])
                return out[::-1]
            for m in self.successors(n):
                if m not in prev:
                    prev[m] = n
                    todo.append(m)
        raise GraphError(f"no chain of allowed transitions leads from {start!r} to {goal!r}")

    def best_transition(self, a: str, b: str) -> tuple[int, int, float]:
        """``(i, j, D)``: key frame ``i`` of ``a``'s clip and key frame ``j`` of ``b``'s clip with the
        smallest inter-frame distance ``D`` (eq. 2; cached). Only the nodes' key frames
        (:attr:`ActionNode.keys`, from PPCA) are searched, as in the paper's §3.1.

        Raises
        ------
        GraphError when either action has no key frames.
        """
        self._need(a, b)
        if (a, b) not in self._best:
            ka, kb = self.nodes[a].keys, self.nodes[b].keys
            if ka.size == 0 or kb.size == 0:
                raise GraphError(f"action {a if ka.size == 0 else b!r} has no key frames")
            d = distance_matrix(self.nodes[a].features[ka], self.nodes[b].features[kb])
            i, j = np.unravel_index(int(np.argmin(d)), d.shape)
            self._best[(a, b)] = (int(ka[i]), int(kb[j]), float(d[i, j]))
        return self._best[(a, b)]

    def classify(self, features) -> list[str]:
        """The action of each feature row (N, D): the node holding the nearest frame."""
        f = np.atleast_2d(np.asarray(features, dtype=np.float64))
        names = list(self.nodes)
        best = np.stack([distance_matrix(f, self.nodes[n].features).min(axis=1) for n in names], axis=1)
        return [names[i] for i in np.argmin(best, axis=1)]

    def library(self):
        """The nodes' clips as a :class:`~.library.MotionLibrary` labelled by action (cached)."""
        from motionlab.interpolation.library import MotionLibrary

        if self._library is None:
            names = list(self.nodes)
            self._library = MotionLibrary([self.nodes[n].motion for n in names], labels=names)
        return self._library

    def transition_table(self) -> list[tuple[str, str, int, int, float]]:
        """``(from, to, frame in from, frame in to, distance)`` for every edge, sorted."""
        return [(a, b, *self.best_transition(a, b)) for a, b in sorted(self.edges)]
