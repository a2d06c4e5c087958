"""Instructor's key for notebook 06 (key-pose interpolation and gap filling)."""

import numpy as np


def my_held_out_q(clips):
    """Exercise 1: q in (1, 2, 4, 8, 16, 32) with the best likelihood on the last quarter of every clip."""
    from motionlab.interpolation import features
    from motionlab.interpolation.ppca import PPCA

    train, test = [], []
    for clip in clips.values():
        f = features.pose_features(clip)
        k = len(f) - max(int(round(0.25 * len(f))), 1)
        train.append(f[:k])
        test.append(f[k:])
    train, test = np.concatenate(train), np.concatenate(test)
    mean, std = train.mean(axis=0), np.maximum(train.std(axis=0), 1e-6)
    best = max(
        (1, 2, 4, 8, 16, 32), key=lambda q: PPCA(q).fit((train - mean) / std).log_likelihood((test - mean) / std)
    )
    return best


def my_walk_spacing(walk):
    """Exercise 2: the largest spacing of (10, 15, 20, 30, 45, 60) frames at which the walk experiment
    keeps every one of the 13 joints under 6° (mean over the filled frames)."""
    from motionlab.core import quat
    from motionlab.interpolation import gaps

    joints = ["Hips", "Spine", "Neck", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg", "LeftFoot", "RightFoot",
              "LeftArm", "RightArm", "LeftForeArm", "RightForeArm"]  # fmt: skip
    idx = [walk.skeleton.names.index(n) for n in joints]
    largest = 0
    for every in (10, 15, 20, 30, 45, 60):
        kept = np.arange(5, walk.num_frames, every)
        span = walk[5 : kept[-1] + 1]
        broken = span.copy()
        lost = np.setdiff1d(np.arange(span.num_frames), kept - 5)
        broken.local_rot[lost] = np.nan
        broken.root_pos[lost] = np.nan
        if broken.local_pos is not None:
            broken.local_pos[lost] = np.nan
        filled, _ = gaps.fill(broken, method="slerp", root="hermite")
        per_joint = np.degrees(quat.angle_between(filled.local_rot[lost][:, idx], span.local_rot[lost][:, idx]).mean(0))
        if per_joint.max() < 6.0:
            largest = every
    return largest


def my_smallest_gap(walk):
    """Exercise 3: remove 1, 2, 3, … frames from frame 100 on until the rule flags the step before them."""
    from motionlab.interpolation import detect

    n = 1
    while 99 not in detect.consecutive_gaps(walk[np.r_[0:100, 100 + n : walk.num_frames]]):
        n += 1
    return n


def my_key_frames(clips):
    """Exercise 4: walk → stand's best transition D between 5 key frames per node over the smallest D
    between any two frames of the two clips."""
    from motionlab.interpolation import features
    from motionlab.interpolation.action_graph import ActionGraph

    graph = ActionGraph()
    for name in ("walk", "stand"):
        graph.add_node(name, clips[name], num_keys=5)
    d_keys = graph.best_transition("walk", "stand")[2]
    walk_f, stand_f = features.pose_features(clips["walk"]), features.pose_features(clips["stand"])
    d_all = features.distance_matrix(walk_f, stand_f).min()
    return round(float(d_keys / d_all), 2)
