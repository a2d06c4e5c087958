"""Print the experiment exercises' reference values on the notebooks' own inputs (course data,
quick mode), the numbers quoted in this folder's model answers.

    MOTIONLAB_DATA=/path/to/data MOTIONLAB_QUICK=1 python instructor/answers/reference_values.py

02's values depend on the network notebook 02 trains: they are computed from the checkpoint it
saves (``02_aj_quick.pt`` in ``motionlab_notebooks/`` of the temporary folder), so run notebook 02
first; without that file they are skipped with a line that says so.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

from motionlab import data, retargeting
from motionlab import exercises as ex
from motionlab.core import bvh, humanoid, preprocess
from motionlab.interpolation import demo
from motionlab.motion_graphs import clips


def main() -> None:
    warnings.simplefilter("ignore", UserWarning)
    if not data.has_data("mixamo", "Aj"):
        raise SystemExit("needs the course data: set MOTIONLAB_DATA")
    print(f"00 ex1 nlerp_turn      {ex.nlerp_turn.reference():.0f} deg")
    print(f"00 ex2 euler_order     {ex.euler_order.reference():.1f} deg")
    running = data.clip_path("mixamo", "Aj", "Running")
    print(f"00b ex1 reader_order   {ex.reader_order.reference(running):.1f} deg")
    run = demo.trim_frozen(bvh.load(data.clip_path("mixamo", "Aj", "Run_Arc_Left")))
    print(
        f"01 ex1 hips_heading    {ex.hips_heading.reference(preprocess.prepare(run, fps=60).global_positions()):.1f} deg"
    )
    _notebook_02(data.clip_path("mixamo", "Aj", "Run_Arc_Left"))
    source = run
    target = demo.trim_frozen(bvh.load(data.clip_path("mixamo", "Mousey_m", "Run_Arc_Left"))).skeleton
    ckpt = retargeting.load_real()  # notebook 03's network on the course data
    for name in ("encoder_start", "contact_weight", "foot_weight", "theta_directions"):
        print(f"03 {name:19s} {ex.EXPERIMENTS[name].reference(source, target, ckpt):.2f}")
    _notebook_03_more(source, demo.trim_frozen(bvh.load(data.clip_path("mixamo", "Mousey_m", "Run_Arc_Left"))), ckpt)
    from motionlab import synthetic
    from motionlab.core import humanoid

    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=120, fps=30.0, seed=0)
    print(f"04 ex1 shorter_legs    {ex.shorter_legs.reference(walk):.2f}")
    styles = ("normal", "elderly", "feminine")
    root = data.data_root() / "bandai_namco" / "sessions" / "walk"
    motions = [
        clips.prepare(bvh.load(p), 30.0).copy(name=p.stem)
        for s in styles
        for p in sorted(root.glob(f"dataset-2_walk_{s}_*.bvh"))[:3]
    ]
    request = [("walk", s, 150) for s in styles]
    print(f"05 ex2 style_change    dwell {ex.style_change.reference(motions, request):.0f}")
    print(f"05 ex3 vanishing_thr.  {ex.vanishing_threshold.reference(motions, 'elderly'):.0f} cm")
    req = "idle:normal:60,walk:catwalk:120"
    print(
        f"05 ex4 transition_clip {ex.transition_clip.reference(clips.mixamo_aj(), req, 'idle_normal_to_walk_catwalk'):.0f} cm"
    )
    behaviours, _ = demo.behaviours()
    walk6, _ = demo.walk_clip()
    pwalk, _ = demo.paper_walk()
    print(f"06 ex1 held_out_q      q = {ex.held_out_q.reference(behaviours)}")
    print(f"06 ex2 walk_spacing    {ex.walk_spacing.reference(pwalk):.0f} frames")
    print(f"06 ex3 smallest_gap    {ex.smallest_gap.reference(walk6)} frames")
    print(f"06 ex4 key_frames      {ex.key_frames.reference(behaviours):.2f}")
    _notebook_07(ckpt)


def _notebook_02(held_out_path) -> None:
    """02's two experiments on the network notebook 02 saved (quick mode) and its held-out clip."""
    saved = Path(tempfile.gettempdir()) / "motionlab_notebooks" / "02_aj_quick.pt"
    if not saved.is_file():
        print(f"02 (skipped: run notebook 02 in quick mode first; it saves {saved})")
        return
    loaded = retargeting.load(saved, "cpu")
    held_out = demo.trim_frozen(bvh.load(held_out_path))
    print(f"02 ex1 q_delta_legs    {ex.q_delta_legs.reference(loaded, held_out):.3f} deg")
    print(f"02 ex2 no_correction   {ex.no_correction.reference(loaded, held_out):.2f} cm")


def _notebook_03_more(source, target_clip, ckpt) -> None:
    """The other numbers 03's experiments ask to print, measured as section 5 measures them."""
    from motionlab.core import humanoid, metrics
    from motionlab.exercises.retargeting import PAPER
    from motionlab.retargeting import pipeline, plots
    from motionlab.retargeting.solver import SolverConfig

    feet = [humanoid.JOINTS.index(n) for n in humanoid.FEET]
    src = preprocess.prepare(source, ckpt.fps, stand=True)
    gt_pos = preprocess.prepare(target_clip, ckpt.fps).global_positions()
    height = pipeline.target_skeleton(target_clip.skeleton).height()
    planted = pipeline.source_contacts(src)
    for label, cfg in (
        ("ex2 encoder start", SolverConfig(init="encoder")),
        ("ex3 contact 0.1", SolverConfig(lambda_contact=0.1)),
        ("ex4 paper-like, foot 5", SolverConfig(**dict(PAPER, lambda_foot=5.0))),
        ("ex5 theta directions", SolverConfig(theta="directions")),
    ):
        run = retargeting.retarget(source, target_clip.skeleton, ckpt, "full", cfg)
        pos, n = run.positions, min(len(run.positions), len(gt_pos), len(planted))
        pose = metrics.mse(pos[:n] - pos[:n, :1], gt_pos[:n] - gt_pos[:n, :1], height=height)
        print(f"03 {label:23s} angle {plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean():.2f} deg, "
              f"slide {100 * metrics.planted_slide(pos[:n], feet, planted[:n], ckpt.fps):.2f} cm/s, "
              f"below ground {100 * metrics.foot_penetration(pos, feet):.2f} cm, pose MSE/h2 {pose:.2e}, "
              f"{run.steps} steps ({run.stop_reason})")  # fmt: skip


def _notebook_07(ckpt) -> None:
    """07's experiment on the notebook's inputs: Jumping without its frozen tail, 20 steps (quick)."""
    from motionlab.retargeting.solver import SolverConfig

    jumping = demo.trim_frozen(bvh.load(data.clip_path("mixamo", "Aj", "Jumping")))
    with tempfile.TemporaryDirectory() as folder:
        clip_path = bvh.save(Path(folder) / "Jumping.bvh", jumping)
        lowest = ex.arm_length.reference(str(clip_path), ckpt, SolverConfig(max_steps=20))
        long_arms = humanoid.scale_bones(humanoid.canonical_skeleton(), arms=1.35)  # the `long_arms` preset
        preset = retargeting.retarget(
            bvh.load(clip_path), long_arms, ckpt, solver=SolverConfig(max_steps=20)
        ).plausibility
    print(
        f"07 ex1 arm_length      {lowest:.3f} of the leg (long_arms, x 1.35: {preset.lowest:.3f}, failed {preset.failed})"
    )


if __name__ == "__main__":
    main()
