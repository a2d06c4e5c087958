"""Why Table 1's skating column exceeds the ground truth's: where the foot joints sit above the floor.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.foot_clearance

Retargets Table 1's 60 pairs (Aj's 10 animations onto the six characters) with the full method and
the network trained on real motion (``retargeting.load_real``), and prints per target character:

* ``sole``: the height (cm) of B's toe joints when B stands, read from its rest root offset
  (:func:`motionlab.core.rest_pose.sole_height`), and ``planted toe``: the median height of the
  toe joints over the frames where Mixamo's own clips plant them (the contact detector's labels):
  the check that the rest offset says where the rig's own takes put the floor;
* ``lowest toe``: the lowest toe joint over the 10 clips, in Mixamo's own clips (the ground
  truth) and in motionlab's output;
* the skating column's two factors: frames (foot joints × frame pairs) below its 5 cm window
  (:func:`motionlab.core.metrics.foot_skating`) and their mean horizontal speed (cm/s).

A foot joint held lower counts more swinging frames in the window; the window's count and speed
multiply into the skating column.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from motionlab import data, retargeting
from motionlab.core import bvh, contacts, humanoid, preprocess, rest_pose
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_TARGETS

WINDOW_M = 0.05
"""The skating column's height window (:func:`motionlab.core.metrics.foot_skating`'s default)."""

TOES = [humanoid.JOINTS.index(f) for f in humanoid.FEET if "Toe" in f]
"""The toe joints' indices (the lower two of :data:`motionlab.core.humanoid.FEET`)."""


def window(pos: np.ndarray, fps: float) -> tuple[int, float]:
    """(foot-joint frame pairs below :data:`WINDOW_M` in both frames, their summed speed in m/s)."""
    p = pos[:, [humanoid.JOINTS.index(f) for f in humanoid.FEET]]
    speed = np.linalg.norm(np.diff(p[..., [0, 2]], axis=0), axis=-1) * fps
    low = (p[1:, :, 1] < WINDOW_M) & (p[:-1, :, 1] < WINDOW_M)
    return int(low.sum()), float(speed[low].sum())


def main(argv=None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    warnings.simplefilter("ignore", UserWarning)
    try:
        folder = data.data_root() / "mixamo"
    except data.DataNotFound as e:
        raise SystemExit(f"foot_clearance: {e}") from None
    ckpt = retargeting.load_real("cpu", progress=False)
    print(f"{'target':<13} {'sole':>5} {'planted toe':>11} {'lowest toe: truth':>18} {'ours':>6}   "
          f"{'window frames: truth':>20} {'ours':>6}   {'their speed cm/s: truth':>23} {'ours':>6}")  # fmt: skip
    for target in DEFAULT_TARGETS:
        low, counts = {"truth": [], "ours": []}, {"truth": np.zeros(2), "ours": np.zeros(2)}
        planted = []
        for anim in DEFAULT_ANIMATIONS:
            truth_rig = bvh.load(folder / target / f"{anim}.bvh")
            truth_motion = preprocess.prepare(truth_rig, ckpt.fps, stand=True)
            truth = truth_motion.global_positions()
            planted.append(contacts.planted_toe_heights(truth_motion))
            ours = retargeting.retarget(bvh.load(folder / "Aj" / f"{anim}.bvh"), truth_rig.skeleton, ckpt).positions
            n = min(len(truth), len(ours))
            for name, pos in (("truth", truth[:n]), ("ours", ours[:n])):
                low[name].append(pos[:, TOES, 1].min())
                counts[name] += window(pos, ckpt.fps)
        sole = 100 * rest_pose.sole_height(truth_motion.skeleton)
        planted_cm = 100 * float(np.median(np.concatenate(planted)))
        (tn, ts), (on, os_) = counts["truth"], counts["ours"]
        print(f"{target:<13} {sole:>5.1f} {planted_cm:>11.1f} {100 * min(low['truth']):>18.1f} {100 * min(low['ours']):>6.1f}   "
              f"{tn:>20.0f} {on:>6.0f}   {100 * ts / tn:>23.1f} {100 * os_ / on:>6.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
