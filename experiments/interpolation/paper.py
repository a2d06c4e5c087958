"""The experiments of the key-pose paper (Yang et al. 2019, §4), on the shared real mocap.

**Walk within one node (Fig. 6/7, Table 1).** The paper takes 495 frames of a CMU walk at 120 Hz,
keeps frames 5 and 35 and interpolates 10, 15, …, 30 between them ("at regular intervals"), and
plots the left hip (``lThigh``) angles, true dashed against interpolated solid. Here:
:func:`walk_experiment` keeps every ``every``-th frame (5, 35, 65, … for ``every = 30``), removes
the rest and fills each gap inside the walk node (SLERP of rotations, Hermite root). The paper's
13 walking joints (Table 1's list is not in the text) are read as the CMU skeleton's hips, lower
spine, neck, both thighs, shins, feet, upper arms and forearms (:data:`WALK_JOINTS`, canonical
names). The paper gives no numbers; we measure the angle error per joint and the position error.

**Across nodes (Fig. 8).** Frame 1 is running, frame 12 squatting, frames 2–11 missing; the graph
gives run → walk → stand → squat; the key poses of walk and stand go in at frames 5 and 8 (at
their best transition frames, root-aligned), and interpolation fills the rest.
:func:`run_to_squat` does exactly this with the Mixamo Aj clips of
:data:`~.demo.BEHAVIOUR_CLIPS`, each checked by content (:mod:`.labels`).

``experiments/interpolation/reproduce_keypose_paper.py`` prints both and draws the README figure; notebook 06
shows them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.interpolation import demo, gaps
from motionlab.interpolation.alignment import reference_joint, reference_transform

__all__ = ["WALK_JOINTS", "WalkResult", "walk_experiment", "RunSquatResult", "run_to_squat_graph", "run_to_squat"]

WALK_JOINTS = demo.WALK_JOINTS


@dataclass
class WalkResult:
    """What :func:`walk_experiment` measured.

    Attributes
    ----------
    truth, filled : Motion          the walk and its filled copy (same frames)
    kept : ndarray (K,) of int      frames kept (the paper's 5, 35, …)
    angle_error : dict              joint name -> mean geodesic angle error over filled frames, degrees
    hip_true, hip_filled : ndarray (T, 3)   left-hip Euler angles (order ``zyx``), degrees
    position_error : float          mean joint position error over filled frames / body height
    """

    truth: Motion
    filled: Motion
    kept: np.ndarray
    angle_error: dict
    hip_true: np.ndarray
    hip_filled: np.ndarray
    position_error: float


def walk_experiment(walk: Motion, first: int = 5, every: int = 30, root: str = "hermite") -> WalkResult:
    """Keep frames ``first, first+every, …`` of a canonical walk, fill the rest, compare.

    Parameters
    ----------
    walk : Motion on the 22-joint canonical skeleton (any frame rate)
    first, every : int   kept frames; the paper's 5 and 35 are ``first=5, every=30``
    root : ``"hermite"`` or ``"linear"`` (see :func:`~.gaps.fill`)
    """
    if every < 2 or not 0 <= first < walk.num_frames:
        raise ValueError(f"need every >= 2 and 0 <= first < {walk.num_frames}, got first={first}, every={every}")
    kept = np.arange(first, walk.num_frames, every)
    if kept.size < 2:
        raise ValueError(
            f"a {walk.num_frames}-frame walk keeps fewer than two frames with first={first}, every={every}"
        )
    span = walk[first : kept[-1] + 1]
    broken = span.copy()
    lost = np.setdiff1d(np.arange(span.num_frames), kept - first)
    broken.local_rot[lost] = np.nan
    broken.root_pos[lost] = np.nan
    if broken.local_pos is not None:
        broken.local_pos[lost] = np.nan
    filled, _ = gaps.fill(broken, method="slerp", root=root)
    names = list(walk.skeleton.names)
    idx = [names.index(n) for n in WALK_JOINTS]
    err = np.degrees(quat.angle_between(filled.local_rot[lost][:, idx], span.local_rot[lost][:, idx]).mean(axis=0))
    hip = names.index("LeftUpLeg")
    height = float(np.ptp(span[:1].global_positions()[0, :, 1]))
    pos_err = np.linalg.norm(filled.global_positions()[lost] - span.global_positions()[lost], axis=-1).mean()
    return WalkResult(
        span,
        filled,
        kept,
        {n: float(e) for n, e in zip(WALK_JOINTS, err)},
        np.degrees(quat.to_euler(span.local_rot[:, hip], "zyx")),
        np.degrees(quat.to_euler(filled.local_rot[:, hip], "zyx")),
        float(pos_err / height),
    )


@dataclass
class RunSquatResult:
    """What :func:`run_to_squat` produced.

    Attributes
    ----------
    motion : Motion                 frame 0 = the last run frame (paper frame 1) … the first squat
                                    frame (paper frame 12), plus context either side
    first : int                     index of paper frame 1 in ``motion``
    path : list of str              actions through the gap
    anchors : list of int           indices of the inserted key poses (paper frames 5 and 8)
    keys : list of (str, int, bool) node, frame of its clip placed, whether it is a PPCA key frame
    travel : float                  root ground distance covered across the gap, metres
    speeds : ndarray (missing+1,)   root ground speed of each step from paper frame 1 to 12, m/s
    run_speed : float               the run's root ground speed before the gap, m/s
    below : float                   how far the lowest foot of the filled frames goes below the floor, metres
    """

    motion: Motion
    first: int
    path: list
    anchors: list
    keys: list
    travel: float
    speeds: np.ndarray
    run_speed: float
    below: float


run_to_squat_graph = demo.fig8_graph
"""The graph of Fig. 8 (:func:`motionlab.interpolation.demo.fig8_graph`)."""


def run_to_squat(clips: dict[str, Motion], missing: int = 10, context: int = 10) -> RunSquatResult:
    """Fig. 8: ``context`` frames of running, ``missing`` lost frames, then a squat; filled through
    the graph (key poses of the intermediate nodes at their best transition frames).

    The squat is placed facing the run's last heading, ahead of the last run frame by the distance
    the runner covers slowing uniformly to rest over the gap (half the run speed × its duration);
    the paper does not say where its squat stands, and a squat on the spot would force a stop.
    """
    g = demo.fig8_graph(clips)
    run, squat = clips["run"], clips["squat"]
    ref = reference_joint(run)
    joined, where = demo.run_squat_gap(clips, missing, context)
    _, path = reference_transform(run[run.num_frames - context :], joint=ref)
    v = np.linalg.norm(np.diff(path[:, [0, 2]], axis=0), axis=1).mean()
    filled, report = gaps.fill(joined, method="graph", graph=g)
    a, b = where[0] - 1, where[1]
    keys, prev = [], report[0].path[0]
    for name in report[0].path[1:-1]:
        _, j, _ = g.best_transition(prev, name)
        keys.append((name, int(j), bool(j in g.nodes[name].keys)))
        prev = name
    _, p = reference_transform(filled, np.arange(a, b + 1), joint=ref)
    travel = float(np.linalg.norm((p[-1] - p[0])[[0, 2]]))
    speeds = np.linalg.norm(np.diff(p[:, [0, 2]], axis=0), axis=1) * run.fps
    floor = min(float(run.global_positions()[:, 1:, 1].min()), float(squat.global_positions()[:, 1:, 1].min()))
    below = floor - float(filled[a + 1 : b].global_positions()[:, 1:, 1].min())
    below = below if below > 1e-9 else 0.0  # rounding below a nanometre is not a foot in the floor
    return RunSquatResult(filled, a, report[0].path, report[0].anchors, keys, travel, speeds, float(v * run.fps), below)
