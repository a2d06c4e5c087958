"""Foundation commands: ``motionlab info``, ``motionlab convert``, ``motionlab synth``, ``motionlab demo``."""

from __future__ import annotations

import argparse
import contextlib
import io
from pathlib import Path

from motionlab import cli_args
from motionlab.cli_args import check_output_folder, check_outputs, positive, positive_int, rig_error

__all__ = ["register", "positive"]


def _load(path: str, what: str = "input"):
    from motionlab.core import bvh, files

    return bvh.load(files.check_input(path, what))


def _rest_line(m, path) -> None:
    from motionlab.core import humanoid, rest_pose

    try:
        stand, pose = rest_pose.standing(humanoid.to_canonical(m), path, humanoid.family(m.skeleton))
        print(f"rest      {pose.describe()}; standing height {stand.skeleton.height():.4f} m")
    except rest_pose.RestPoseError as e:
        print(f"rest      {e}")


def _info(args) -> int:
    """describe a BVH file: skeleton, frames, fps, 22-joint mapping

    Print a BVH file's skeleton, frame count, frame rate, rest height and whether (and by which rig profile) it maps
    onto the canonical 22-joint humanoid.
    """
    from motionlab.core import humanoid, motion_files

    m = _load(args.file)
    unit = motion_files.file_unit(m.skeleton)
    m = motion_files.in_metres(m, unit)
    sk = m.skeleton
    print(f"file      {args.file}")
    if unit != motion_files.CM:
        print(f"unit      {unit:.6g} m per file unit (its rig profile's; other files are read as centimetres)")
    print(f"frames    {m.num_frames} at {m.fps:g} fps ({m.duration:.2f} s)")
    print(f"joints    {sk.num_joints} (root {sk.names[0]!r}, {len(sk.end_sites)} end sites)")
    print(f"height    {sk.height():.4f} m (rest pose, all joints)")
    try:
        mapping = humanoid.find_mapping(sk)
        canon = humanoid.to_canonical_skeleton(sk)
        print(
            f"humanoid  maps onto the 22 joints (profile {mapping.profile!r}); 22-joint height {canon.height():.4f} m, "
            f"leg length {humanoid.leg_length(canon):.4f} m"
        )
    except humanoid.RigMappingError as e:
        print(f"humanoid  does not map: {e.reason}")
    else:
        if m.num_frames == 0:
            print("rest      no frames to read the standing pose from")
        else:
            _rest_line(m, args.file)
    if args.joints:
        depth = sk.depth()
        for j, name in enumerate(sk.names):
            chans = " ".join(sk.channels[j]) if sk.channels else ""
            print(f"  {'  ' * depth[j]}{name}  [{chans}]")
    return 0


def _canonical(m, args):
    """``m`` on the 22 joints, their rest the rig's standing pose (as retargeting reads it: a rig
    whose rest offsets lie flat, Bandai Namco's, stands in its T-pose), every joint where it was;
    the file's own rest where the rig has no standing pose, said unless ``--quiet``."""
    from motionlab.core import humanoid, rest_pose

    try:
        reduced = humanoid.to_canonical(m)
    except humanoid.RigMappingError as e:
        raise rig_error(e, "input", args.input) from None
    try:
        return rest_pose.standing(reduced, family=humanoid.family(m.skeleton))[0]
    except rest_pose.RestPoseError as e:
        if not args.quiet:
            print(f"{args.input}: rest pose kept as the file's ({e})")
        return reduced


def _convert(args) -> int:
    """reduce a BVH file to the 22-joint humanoid and/or resample it; write BVH or glTF (.glb)

    Read a BVH file, optionally reduce it to the canonical 22 joints on their standing rest pose (--canonical) and
    resample it (--fps), and write it as BVH (OUTPUT ending in .bvh, in the input's length unit) or binary glTF 2.0
    (.glb, in metres; docs/gltf.md).
    """
    from motionlab.core import motion_files

    cli_args.motion_output("-o", args.output)
    (out,) = check_outputs([("-o", args.output)], args.force, inputs=[("input", args.input)])
    m = _load(args.input)
    unit = motion_files.file_unit(m.skeleton)
    if args.fps is not None:
        cli_args.check_size(
            f"--fps {args.fps:g} over {m.duration:g} s", m.duration * args.fps + 1, m.skeleton.num_joints
        )
    if args.canonical:  # the 22 joints' names read back as centimetres: write them in centimetres
        m, unit = motion_files.in_metres(m, unit), motion_files.CM
        m = _canonical(m, args)
    if args.fps is not None:
        m = m.resample(args.fps)
    motion_files.save(out, m, overwrite=args.force, unit=unit)
    if not args.quiet:
        print(f"wrote {out}: {m.num_frames} frames at {m.fps:g} fps, {m.skeleton.num_joints} joints")
    return 0


def _synth(args) -> int:
    """write synthetic motion (idle, walk, run, jump, squat or mix) as BVH or glTF (.glb)

    Generate procedural humanoid motion on a character of the given height and limb proportions and write it as BVH
    or, when OUTPUT ends in .glb, binary glTF 2.0 (mix: idle -> walk -> run -> jump -> walk -> squat).
    """
    from motionlab import synthetic
    from motionlab.core import humanoid, motion_files

    cli_args.motion_output("-o", args.output)
    (out,) = check_outputs([("-o", args.output)], args.force)
    joints = len(humanoid.JOINTS)
    frames = round(args.seconds * args.fps)
    if args.behaviour != "mix" and frames < 1:
        raise cli_args.CLIError(f"--seconds {args.seconds:g} at --fps {args.fps:g} is less than one frame")
    if args.behaviour != "mix":
        cli_args.check_size(f"--seconds {args.seconds:g} at --fps {args.fps:g}", args.seconds * args.fps, joints)
    skeleton = humanoid.canonical_skeleton(args.height)
    skeleton = humanoid.scale_bones(skeleton, legs=args.legs, arms=args.arms)
    if args.behaviour == "mix":
        at_60 = [("idle", 60), ("walk", 150), ("run", 120), ("jump", 70), ("walk", 90), ("squat", 100), ("idle", 60)]
        segments = [(behaviour, max(1, round(n * args.fps / 60))) for behaviour, n in at_60]  # the same seconds
        motion = synthetic.sequence(segments, skeleton, fps=args.fps, seed=args.seed)
    else:
        motion = synthetic.generate(args.behaviour, skeleton, num_frames=frames, fps=args.fps, seed=args.seed)
    motion.name = args.behaviour
    motion_files.save(out, motion, overwrite=args.force, unit=motion_files.CM)
    if not args.quiet:
        print(f"wrote {out}: {motion.num_frames} frames of {args.behaviour} at {motion.fps:g} fps")
    return 0


def _demo(args) -> int:
    """the main job on built-in data: retarget a synthetic performance onto new characters

    Make a synthetic performance, retarget it onto new synthetic characters with the shipped network (copy, network
    alone, full method), write BVH files, a figure and a table to the output folder, and print the table.
    """
    from motionlab.demo import run_demo

    check_output_folder("-o", args.output)
    out = Path(args.output)
    if not args.quiet:
        return run_demo(out_dir=out, characters=args.num_characters, seed=args.seed, force=args.force)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):  # no bar, no status
        code = run_demo(out_dir=out, characters=args.num_characters, seed=args.seed, force=args.force)
    print((out / "summary.md").read_text().removeprefix("# motionlab demo\n\n"), end="")  # the result: the table
    return code


def register(sub: argparse._SubParsersAction) -> None:
    with cli_args.command(sub, "info", _info) as p:
        p.add_argument("file", help="a .bvh file")
        p.add_argument("--joints", action="store_true", help="also print the joint tree with channels")

    with cli_args.command(sub, "convert", _convert) as p:
        p.add_argument("input", help="input .bvh")
        cli_args.add_output(p, "output file: .bvh writes BVH, .glb binary glTF 2.0 (Blender, web viewers, engines)")
        p.add_argument(
            "--canonical",
            action="store_true",
            help="reduce to the canonical 22 joints, their rest the rig's standing pose (a .bvh is then written in "
            "centimetres)",
        )
        p.add_argument(
            "--fps", type=cli_args.frame_rate, default=None, help="resample to this frame rate (frames per second)"
        )
        cli_args.add_force(p, "overwrite the output if it exists")

    with cli_args.command(sub, "synth", _synth) as p:
        p.add_argument("behaviour", choices=["idle", "walk", "run", "jump", "squat", "mix"], help="what the body does")
        cli_args.add_output(p, "output file: .bvh or .glb (binary glTF 2.0)")
        p.add_argument("--seconds", type=positive, default=4.0, help="length in seconds (ignored for mix)")
        p.add_argument("--fps", type=cli_args.frame_rate, default=60.0, help="frame rate (frames per second)")
        p.add_argument(
            "--height",
            type=cli_args.in_range(0.3, 3.0, "a height in metres"),
            default=1.75,
            help="character height, metres",
        )
        p.add_argument("--legs", type=cli_args.factor, default=1.0, help="leg length factor")
        p.add_argument("--arms", type=cli_args.factor, default=1.0, help="arm length factor")
        p.add_argument("--seed", type=cli_args.seed, default=0, help="random seed")
        cli_args.add_force(p, "overwrite the output if it exists")

    with cli_args.command(sub, "demo", _demo) as p:
        cli_args.renamed(p, "--out", cli_args.add_output(p, "output folder", required=False, default="outputs/demo"))
        cli_args.renamed(
            p,
            "--characters",
            p.add_argument(
                "--num-characters", type=positive_int, default=4, help="how many new characters (1 or more)"
            ),
        )
        p.add_argument("--seed", type=cli_args.seed, default=0, help="random seed")
        cli_args.add_force(
            p, "replace files in an output folder that an earlier demo did not write (a demo folder is always re-used)"
        )
