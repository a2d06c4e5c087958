"""How long a gap's end velocities count: the horizon of ``"hermite"`` rotations, chosen on clips kept apart.

    python -m experiments.interpolation.hermite_horizon

The LaFAN1-protocol windows of :mod:`experiments.interpolation.bench_inbetween` (65 frames every
40, 10 context frames, gaps of 5, 15, 30 and 45 frames, 30 fps), both groups (Bandai Namco,
Mixamo Aj), root linear, rotations filled by :func:`motionlab.interpolation.inbetween.interpolate`:
SLERP, the one-sided quadratic (the start velocity over the whole gap, motionlab's ``"hermite"``
before this study), and the cubic with both end velocities counted over ``min(L, H)`` frames for
each horizon ``H``. Each line gives L2P and L2Q per gap over SLERP's (below 1: closer to the
recording), and their mean. ``H`` is chosen on the apart clips' windows alone (the lowest mean);
the scored clips' windows then check it.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from experiments.interpolation import benchmark as bm
from experiments.interpolation.bench_inbetween import groups
from motionlab.core import quat
from motionlab.interpolation.inbetween import interpolate, log

HORIZONS = (2, 4, 6, 8, 10, 12, 13, 14, 15, 16, 18, 20, 24)
"""Horizons tried, in frames at 30 fps."""


def _ang(w: bm.Windows, t: int) -> np.ndarray:
    """Per-frame rotation vectors ``log(q[t-1]⁻¹ q[t])`` of every window, (B, J, 3)."""
    return log(quat.mul(quat.conj(w.local_rot[:, t - 1]), w.local_rot[:, t]))


def method(horizon: float | None, two_sided: bool = True):
    """A fill: linear root, ``"hermite"`` rotations with the given horizon (None: the whole gap)."""

    def fill(w: bm.Windows, n_past: int, gap: int):
        a, b = n_past - 1, n_past + gap
        rot, root = interpolate(w.local_rot[:, a], w.trans[:, a, 0], w.local_rot[:, b], w.trans[:, b, 0], gap,
                                rotation="hermite", ang_vel_a=_ang(w, a), horizon=horizon,
                                ang_vel_b=_ang(w, b + 1) if two_sided else None)  # fmt: skip
        return rot, bm._fill_trans(w, root, n_past, gap)

    return fill


def ratios(windows: bm.Windows, stats, methods: dict) -> dict:
    """``{name: (L2P and L2Q per gap over SLERP's)}``."""
    res = bm.evaluate(windows, {"SLERP": bm.method_interpolation, **methods}, stats)
    return {
        name: [res[(name, m, g)] / res[("SLERP", m, g)] for m in ("L2P", "L2Q") for g in bm.GAPS] for name in methods
    }


def main(argv=None) -> int:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    root = os.environ.get("MOTIONLAB_DATA")
    if not root:
        sys.exit("set MOTIONLAB_DATA to the shared data folder (e.g. export MOTIONLAB_DATA=/path/to/shared/data)")
    methods = {"one-sided, whole gap": method(None, two_sided=False), "two-sided, whole gap": method(None)}
    methods |= {f"two-sided, H = {h}": method(h) for h in HORIZONS}
    found: dict[str, dict[str, list]] = {"apart": {n: [] for n in methods}, "scored": {n: [] for n in methods}}
    for _group, scored, apart, _ in groups(Path(root)):
        held = bm.load_clips(apart, fps=30.0)
        stats = bm.position_stats(held)
        for part, clips in (("apart", held), ("scored", bm.load_clips(scored, fps=30.0))):
            for n, r in ratios(bm.make_windows(clips), stats, methods).items():
                found[part][n] += r
    head = " ".join(f"{m}{g:>3}" for m in ("L2P", "L2Q") for g in bm.GAPS)
    for part, rows in found.items():
        print(f"--- {part} clips' windows, both groups; over SLERP's: {head} (Bandai Namco, then Mixamo Aj); mean")
        for n, r in rows.items():
            print(f"{n:<24} " + " ".join(f"{x:.3f}" for x in r) + f"  mean {np.mean(r):.4f}")
    best = min(HORIZONS, key=lambda h: np.mean(found["apart"][f"two-sided, H = {h}"]))
    scored = found["scored"][f"two-sided, H = {best}"]
    print(f"chosen on the apart clips: H = {best} frames ({best / 30:.3f} s); on the scored clips its mean is "
          f"{np.mean(scored):.4f} of SLERP's (worst {max(scored):.3f}), the one-sided quadratic's "
          f"{np.mean(found['scored']['one-sided, whole gap']):.4f} (worst {max(found['scored']['one-sided, whole gap']):.3f})")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
