"""What L_floor (motionlab.retargeting.terms, issue 41 item 1) changes on notebook 07's case.

Aj's Jumping retargeted onto the ``long_arms`` preset (arms x 1.35) with the shipped network, as
notebook 07 does, with and without the floor term: the deepest joint of the output, the
plausibility check, the returned iterate's losses and the planted-foot slide::

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.floor_term [--steps 20 100]
    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.floor_term --character Mousey_m --steps 100

``--character`` is an ``expand`` preset or a Mixamo character of the course data (its rig from
its Running clip); ``--clip`` one of Aj's clips.
"""

from __future__ import annotations

import argparse

import numpy as np

from motionlab import data, retargeting
from motionlab.core import bvh, humanoid, metrics
from motionlab.retargeting import expand, pipeline, terms
from motionlab.retargeting.solver import SolverConfig


def run(source, target, ckpt, steps: int) -> dict:
    result = retargeting.retarget(source, target, ckpt, "full", SolverConfig(max_steps=steps))
    pos = result.positions
    frame, joint = np.unravel_index(np.argmin(pos[..., 1]), pos.shape[:2])
    src = pipeline.prepare_source(source, ckpt, "copy").motion
    feet = [humanoid.JOINTS.index(n) for n in humanoid.FEET]
    n = min(len(pos), src.num_frames)
    slide = metrics.planted_slide(pos[:n], feet, pipeline.source_contacts(src)[:n], result.motion.fps)
    return {
        "deepest": f"{humanoid.JOINTS[joint]} {100 * pos[frame, joint, 1]:.1f} cm (frame {frame})",
        "plausible": "yes" if result.plausibility.ok else "no: " + ", ".join(result.plausibility.failed),
        "steps": f"{result.steps} ({result.stop_reason}), kept {result.best_step}",
        "L_iter": f"{result.losses['loss']:.5f}",
        "L_angle": f"{result.losses['angle']:.5f}",
        "L_floor cm": f"{100 * result.losses.get('floor', 0.0):.3f}",
        "slide cm/s": f"{100 * slide:.2f}",
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--steps", type=int, nargs="+", default=[20, 100], help="solver step limits (notebook 07: 20 quick, 100)"
    )
    parser.add_argument("--character", default="long_arms", help="preset or Mixamo character (default long_arms)")
    parser.add_argument("--clip", default="Jumping", help="Aj's clip (default Jumping)")
    args = parser.parse_args(argv)
    root = data.data_root() / "mixamo"
    source = bvh.load(root / "Aj" / f"{args.clip}.bvh")
    if args.character in expand.PRESETS:
        target = humanoid.scale_bones(humanoid.canonical_skeleton(), **expand.PRESETS[args.character])
    else:
        target = bvh.load(root / args.character / "Running.bvh").skeleton
    ckpt = retargeting.load_default("cpu")
    src_low = humanoid.to_canonical(source).global_positions()[..., 1].min(axis=0)
    print(
        f"Aj/{args.clip} -> {args.character} {expand.PRESETS.get(args.character, '')}; A's lowest hand "
        f"{100 * min(src_low[humanoid.JOINTS.index('LeftHand')], src_low[humanoid.JOINTS.index('RightHand')]):.1f} cm"
    )
    for steps in args.steps:
        with_floor = run(source, target, ckpt, steps)
        floor = terms.unregister("floor")
        try:
            without = run(source, target, ckpt, steps)
        finally:
            terms.register(floor)
        print(f"\nmax_steps {steps}:")
        print(f"  {'':12} {'without L_floor':>34} {'with L_floor (weight ' + format(floor.weight, 'g') + ')':>34}")
        for key in with_floor:
            print(f"  {key:12} {without[key]:>34} {with_floor[key]:>34}")


if __name__ == "__main__":
    main()
