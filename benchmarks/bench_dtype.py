"""float64 or float32 for the retargeting network: how far apart the results are, and the speed of each.

The same (clip, character) pairs retargeted by the full method (``retarget``, default solver
settings) with the network in float64 (the default: the same numbers on every CPU) and in
float32, on one device. Prints, per pair and over all, the largest and mean distance between the
two outputs' joints (cm), whether the iteration stopped at the same step, and the wall time of
each choice. On a GPU (``--device cuda``) the float64 run is also compared with the CPU's float64
run (the tolerance of ``tests/retargeting/test_devices.py``)::

    MOTIONLAB_DATA=/path/to/data python benchmarks/bench_dtype.py                 # CPU
    MOTIONLAB_DATA=/path/to/data python benchmarks/bench_dtype.py --device cuda   # a GPU
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.core import bvh, humanoid
from motionlab.retargeting import expand
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS


def _pairs(clips: int, frames: int):
    root = data.data_root() / "mixamo"
    for anim in DEFAULT_ANIMATIONS[:clips]:
        m = bvh.load(root / "Aj" / f"{anim}.bvh")
        m = m.__class__(m.skeleton, m.local_rot[:frames], m.root_pos[:frames], m.fps, None, anim)
        for name in ("long_legs", "long_arms"):
            yield f"{anim} -> {name}", m, humanoid.scale_bones(humanoid.canonical_skeleton(), **expand.PRESETS[name])


def _run(ckpt, pairs):
    out, start = [], time.perf_counter()
    for _, source, target in pairs:
        r = retargeting.retarget(source, target, ckpt, "full")
        out.append((r.positions, r.best_step, r.steps))
    if ckpt.device.type == "cuda":
        torch.cuda.synchronize()
    return out, time.perf_counter() - start


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--device", default="cpu", help="torch device (default cpu)")
    p.add_argument("--clips", type=int, default=2, help="Aj's Table 1 animations used (default 2), x 2 characters")
    p.add_argument("--frames", type=int, default=240, help="first frames of each clip (default 240)")
    args = p.parse_args()
    print(f"torch {torch.__version__}, device {args.device}, {torch.get_num_threads()} threads; "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")  # fmt: skip
    pairs = list(_pairs(args.clips, args.frames))
    runs = {dtype: _run(retargeting.load_default(args.device, dtype), pairs) for dtype in ("float64", "float32")}
    if args.device != "cpu":
        runs["cpu float64"] = _run(retargeting.load_default("cpu", "float64"), pairs)
    (ref, t64), (f32, t32) = runs["float64"], runs["float32"]
    worst = []
    for (label, _, _), a, b in zip(pairs, ref, f32):
        d = 100 * np.linalg.norm(a[0] - b[0], axis=-1)
        worst.append(d.max())
        same = "same" if a[1:] == b[1:] else f"{a[1]}/{a[2]} vs {b[1]}/{b[2]}"
        print(f"  {label:<36} float32 vs float64: max {d.max():.4f} cm, mean {d.mean():.5f} cm; kept step/steps {same}")
    print(f"float32 vs float64 over {len(pairs)} pairs: largest joint distance {max(worst):.4f} cm")
    if "cpu float64" in runs:
        cpu = runs["cpu float64"][0]
        gap = max(100 * np.abs(a[0] - c[0]).max() for a, c in zip(ref, cpu))
        print(f"{args.device} float64 vs cpu float64: largest coordinate difference {gap:.2e} cm")
    print(f"wall time on {args.device}: float64 {t64:.1f} s, float32 {t32:.1f} s ({t64 / t32:.2f}x)")


if __name__ == "__main__":
    main()
