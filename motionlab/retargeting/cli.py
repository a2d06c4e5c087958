"""``motionlab retarget``, ``motionlab train`` and ``motionlab evaluate``.

Examples::

    motionlab retarget Aj/Running.bvh --target BigVegas/Running.bvh -o running_bigvegas.bvh
    motionlab retarget Aj/Running.bvh --scale-legs 1.2 -o long_legs.bvh --method full
    motionlab train $MOTIONLAB_DATA/mixamo/Aj/*.bvh -o /tmp/motionlab_aj.pt
    motionlab train --synthetic 300 --seed 0 -o motionlab/assets/retarget_default.pt --force
    motionlab evaluate --data $MOTIONLAB_DATA/mixamo --checkpoint /tmp/motionlab_aj.pt
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

from motionlab import cli_args
from motionlab.cli_args import (
    CLIError,
    check_outputs,
    non_negative,
    non_negative_int,
    positive,
    positive_int,
    rig_error,
)
from motionlab.retargeting import cli_options
from motionlab.retargeting.cli_options import ROOT_MODES

__all__ = ["register"]


def _load_bvh(path: str, what: str):
    from motionlab.core import bvh, files

    return bvh.load(files.check_input(path, what))


# ---------------------------------------------------------------------------- retarget
def _check_result(args, result):
    """Print a resample (always, also under -q); refuse an implausible output unless --keep-implausible."""
    if result.resampled:
        print(f"{args.source}: {result.resampled}", file=sys.stderr)
    check = result.plausibility
    if not check.ok and not args.keep_implausible:
        raise CLIError(
            f"{args.source} -> {args.target or 'scaled source'}: {check.describe()}; nothing written "
            "(--keep-implausible writes it anyway)"
        )
    return check


def _cmd_retarget(args) -> int:
    """retarget a BVH clip onto another character (latent iteration)

    Generate TARGET's version of SOURCE.bvh. The target character is defined by the rest skeleton of --target (its
    motion is ignored) and/or --scale-* factors; the output is the motion on the 22-joint canonical skeleton,
    written as BVH (OUTPUT ending in .bvh) or binary glTF 2.0 (.glb).
    """
    from motionlab.core import files, humanoid, motion_files, rest_pose
    from motionlab.retargeting import real
    from motionlab.retargeting.pipeline import retarget, target_skeleton

    cli_options.check_device(args.device)
    out = Path(args.output)
    suffix = cli_args.motion_output("-o", args.output)
    npz = Path(args.npz) if args.npz else None
    if npz is not None and npz.suffix.lower() != ".npz":  # np.savez would silently add '.npz' to another name
        raise CLIError(f"--npz {npz} must end in .npz")
    inputs = [("source", args.source), ("--target", args.target), ("--checkpoint", args.checkpoint)]
    check_outputs([("-o", out), ("--npz", npz)], args.force, inputs=inputs)  # before any work
    source = _load_bvh(args.source, "source")
    if args.fps is not None:
        cli_args.check_size(f"--fps {args.fps:g} over {source.duration:g} s", source.duration * args.fps + 1, 22)
    try:
        humanoid.find_mapping(source.skeleton)
    except humanoid.RigMappingError as e:
        raise rig_error(e, "source", args.source) from None
    base = _load_bvh(args.target, "target") if args.target else source
    reference = cli_options.rest_from(args)
    try:
        source = rest_pose.on_reference(source, reference, args.source)
        base = rest_pose.on_reference(base, reference, args.target or args.source)
        target = target_skeleton(base, f"target file {args.target or args.source}")
    except humanoid.RigMappingError as e:
        raise rig_error(e, "target", args.target) from None
    scales = dict(
        legs=args.scale_legs, arms=args.scale_arms, spine=args.scale_spine, neck=args.scale_neck, overall=args.scale
    )
    if any(v != 1.0 for v in scales.values()):
        target = humanoid.scale_bones(target, **scales)
    if not args.target and all(v == 1.0 for v in scales.values()):
        raise CLIError("give --target TARGET.bvh and/or a --scale-* factor: otherwise the target is the source itself")
    solver = cli_options.solver_config(args)  # refused before a network is trained or loaded
    ckpt = None if args.method == "copy" else cli_options.network_checkpoint(args, real.is_real_rig(source.skeleton))
    result = retarget(source, target, ckpt, args.method, solver, args.root, progress=not args.quiet, fps=args.fps)
    check = _check_result(args, result)
    unit = motion_files.file_unit(base.skeleton)  # the target's file was read as centimetres
    metres, motion = unit / motion_files.CM, motion_files.in_metres(result.motion, unit)
    data = motion_files.encode(motion, suffix)  # 22 joints: centimetres in BVH; errors before writing
    outputs = [(out, lambda f: f.write(data), True, "output")]
    if npz is not None:  # both files or neither
        arrays = dict(
            local_rot=motion.local_rot,
            root_pos=motion.root_pos,
            positions=metres * result.positions,
            offsets=motion.skeleton.offsets,
            parents=result.motion.skeleton.parents,
            fps=result.motion.fps,
        )
        outputs.append((npz, lambda f: np.savez(f, **arrays), True, "--npz file"))
    files.atomic_write_all(outputs, overwrite=args.force)
    if not args.quiet:
        msg = f"wrote {out} ({result.motion.num_frames} frames @ {result.motion.fps:g} fps, method {result.method}"
        if result.method == "full":
            start, kept = (
                result.history["loss"][0],
                result.losses["loss"],
            )  # the returned iterate's, not the last step's
            msg += (
                f"; L_iter {start:.4g} -> {kept:.4g} (step {result.best_step} of {result.steps}, {result.stop_reason})"
            )
        print(msg + f", {result.seconds:.2f} s)")
    if not check.ok:
        print(f"warning: {out}: {check.describe()}", file=sys.stderr)
    return 0


# ---------------------------------------------------------------------------- train
def _cmd_train(args) -> int:
    """train the retargeting network on one character

    Train the retargeting network on the clips of ONE character (L_recon) and save a checkpoint.
    """
    from motionlab.retargeting import checkpoint as ck
    from motionlab.retargeting.model import ModelConfig
    from motionlab.retargeting.train import TrainConfig, train, training_set

    cli_options.check_device(args.device)
    (out,) = check_outputs([("-o", args.output)], args.force, inputs=[("clip", c) for c in args.clips])
    if not 0.0 <= args.pose_augment <= 0.5:  # also refuses nan; skeleton augmentation takes the other half
        raise CLIError(f"--pose-augment must be between 0 and 0.5, got {args.pose_augment}")
    if args.synthetic:
        if args.clips:
            raise CLIError("give BVH clips or --synthetic N, not both")
        from motionlab import synthetic

        motions = synthetic.dataset(args.synthetic, seed=args.seed)
    else:
        if not args.clips:
            raise CLIError("give the BVH clips of ONE character to train on (or --synthetic N)")
        motions = [_load_bvh(p, "training") for p in args.clips]
    try:
        data = training_set(motions, progress=not args.quiet)
    except ValueError as e:
        raise CLIError(str(e)) from None
    cfg = TrainConfig(
        steps=args.train_steps,
        batch_size=args.batch_size,
        lr=args.train_lr,
        seed=args.seed,
        device=args.device,
        pose_augment=args.pose_augment,
    )
    mcfg = ModelConfig(latent=args.latent, hidden=args.hidden)
    ckpt, history = train(data, cfg, mcfg, progress=not args.quiet)
    ckpt.info["source"] = "synthetic" if args.synthetic else [Path(p).name for p in args.clips]
    ck.save(out, ckpt, overwrite=args.force)
    if not args.quiet:
        print(
            f"wrote {out}: {len(data)} windows, final loss {history[-1]['loss']:.4g} after {cfg.steps} steps ({ckpt.info['seconds']:.0f} s)"
        )
    return 0


# ---------------------------------------------------------------------------- evaluate
def _fold_path(path: Path, k: int, folds: int) -> Path:
    """The checkpoint of fold ``k`` (0-based) of ``folds``: ``path`` itself when there is one fold."""
    return path if folds == 1 else path.with_name(f"{path.stem}_fold{k + 1}of{folds}{path.suffix}")


def _animations(args, folder: Path) -> list[str]:
    """The animations ``evaluate`` runs: --animations, every shared one (--all-animations) or the default 10."""
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, shared_animations

    if args.animations:
        return list(args.animations)
    if args.all_animations:
        try:
            return shared_animations(folder, args.source, args.targets)
        except (FileNotFoundError, ValueError) as e:
            raise CLIError(str(e)) from None
    return list(DEFAULT_ANIMATIONS)


def _check_characters_and_animations(args, folder: Path, animations: list[str]) -> None:
    """Before any training: every character folder exists, and every animation has the source's clip and
    at least one target's (a pair without its clips is skipped; an animation without any pair is refused)."""
    for option, name in [("--source", args.source)] + [("--targets", t) for t in args.targets]:
        if not (folder / name).is_dir():
            have = sorted(p.name for p in folder.iterdir() if p.is_dir())
            raise CLIError(f"{option} {name}: no folder {folder / name} (characters in {folder}: {', '.join(have)})")
    for anim in animations:
        if not (folder / args.source / f"{anim}.bvh").is_file():
            raise CLIError(f"--animations {anim}: the source has no clip {folder / args.source / (anim + '.bvh')}")
        if not any((folder / t / f"{anim}.bvh").is_file() for t in args.targets):
            raise CLIError(f"--animations {anim}: none of the targets {', '.join(args.targets)} has {anim}.bvh")


def _fold_checkpoint(args, folder: Path, fpath: Path | None, left_out: list[str]):
    """The network of one fold: without --checkpoint (``fpath`` None) the cached network trained on the
    source's clips but ``left_out`` (:func:`motionlab.retargeting.real.trained`); else loaded from
    ``fpath``, or trained and saved there."""
    from motionlab.core import bvh
    from motionlab.retargeting import checkpoint as ck
    from motionlab.retargeting import real
    from motionlab.retargeting.evaluate import training_clips
    from motionlab.retargeting.train import train

    if fpath is not None and fpath.is_file() and not args.retrain:
        ckpt = cli_options.load_checkpoint(str(fpath), args.device)
        if not args.quiet:
            print(f"using checkpoint {fpath}")
        return ckpt
    try:
        clips = training_clips(folder, args.source, left_out)
    except FileNotFoundError as e:
        raise CLIError(str(e)) from None
    cfg = real.train_config(steps=args.train_steps, seed=args.seed)  # on the CPU: one network on every machine
    if fpath is None:
        try:
            return real.trained(clips, cfg, device=args.device, progress=not args.quiet, name=args.source)
        except ck.CheckpointError as e:
            raise CLIError(str(e)) from None
    if not args.quiet:
        print(f"training on {len(clips)} clips of {args.source} (none of the {len(left_out)} evaluated) -> {fpath}")
    ckpt, _ = train([bvh.load(p) for p in clips], dataclasses.replace(cfg, device=args.device), progress=not args.quiet)
    ck.save(fpath, ckpt)
    return ckpt


def _write_csv(args, result) -> None:
    import csv

    from motionlab.core import files

    def write(f):
        w = csv.DictWriter(f, fieldnames=list(result.records[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(result.records)

    files.atomic_write(args.csv, write, overwrite=args.force, what="--csv file")
    if not args.quiet:
        print(f"wrote {args.csv}")


def _cmd_evaluate(args) -> int:
    """reproduce Table 1 (retargeting vs real clips) on a <Character>/<Animation>.bvh folder

    Retarget SOURCE's clips onto each target's T-pose skeleton and compare with the targets' real clips:
    copy-rotation baseline, network without iteration, full method. The network is trained on SOURCE's other clips
    once and cached (without --checkpoint), or loaded from --checkpoint (trained and saved there if missing).
    """
    from motionlab import data as mdata
    from motionlab.retargeting.evaluate import Evaluation, evaluate, rows_with_root

    cli_options.check_device(args.device)
    folder = Path(args.data) if args.data else mdata.data_root() / "mixamo"
    check_outputs([("--csv", args.csv)], args.force)  # refuse before hours of work, not after
    if not folder.is_dir():
        raise CLIError(f"data folder {folder} not found")
    if args.folds < 1:
        raise CLIError(f"--folds must be >= 1, got {args.folds}")
    if args.retrain and not args.checkpoint:
        raise CLIError("--retrain needs --checkpoint: without it the network is cached under its clips and settings")
    animations = _animations(args, folder)
    _check_characters_and_animations(args, folder, animations)
    if args.folds > len(animations):
        raise CLIError(f"--folds {args.folds} is more than the {len(animations)} animations evaluated")
    # leave animations out: fold k is evaluated by a network trained without the fold's animations
    folds = [animations[k :: args.folds] for k in range(args.folds)]
    path = Path(args.checkpoint) if args.checkpoint else None
    fold_paths = [_fold_path(path, k, args.folds) if path else None for k in range(args.folds)]
    trained = [("--checkpoint", p) for p in fold_paths if p and (args.retrain or not p.is_file())]
    check_outputs(trained, force=True, inputs=[("--csv", args.csv)])  # a checkpoint to train is written later
    solver = cli_options.solver_config(args)  # refused before a network is trained
    result = Evaluation(rows=[])
    for fold, fpath in zip(folds, fold_paths):
        ckpt = _fold_checkpoint(args, folder, fpath, fold if args.folds > 1 else animations)
        part = evaluate(
            folder,
            ckpt,
            source=args.source,
            targets=args.targets,
            animations=fold,
            rows=rows_with_root(args.root, ablations=not args.no_ablations),
            solver=solver,
            progress=not args.quiet,
        )
        result.rows = part.rows
        result.records += part.records
        result.ground_truth += part.ground_truth
    if args.folds > 1:
        print(f"leave-animations-out: {args.folds} folds, each evaluated by a network trained without its animations")
    print(result.table())
    print()
    print(result.breakdown("mse_h2"))
    print()
    print(result.breakdown("pose_mse_h2"))
    if args.csv:
        _write_csv(args, result)
    return 0


def register(subparsers) -> None:
    """Add ``retarget``, ``train``, ``evaluate`` and ``expand`` to the ``motionlab`` command."""
    from motionlab.retargeting import expand_cli

    expand_cli.register(subparsers)
    _add_retarget(subparsers)
    _add_train(subparsers)
    _add_evaluate(subparsers)


def _add_retarget(subparsers) -> None:
    with cli_args.command(subparsers, "retarget", _cmd_retarget, quiet=False) as p:
        p.add_argument("source", help="source motion (BVH, any rig that maps onto the 22 canonical joints)")
        p.add_argument("--target", help="BVH whose rest skeleton defines the target character")
        cli_args.add_output(p, "output file: .bvh, or .glb for glTF 2.0")
        p.add_argument("--npz", help="also write arrays (local_rot, root_pos, positions, offsets) to this .npz")
        p.add_argument(
            "--method",
            choices=cli_options.METHODS,
            default="full",
            help="full = latent iteration (default); network = no iteration; copy = copy rotations",
        )
        cli_options.add_network(p, "a source")
        p.add_argument(
            "--root",
            choices=ROOT_MODES,
            default="stride",
            help="how A's root path is scaled: stride = leg chain on the ground, hip height up (default); contacts = "
            "the ratio that keeps A's planted feet still on B's legs; "
            "hips / legs = one ratio for all axes",
        )
        for name in ("legs", "arms", "spine", "neck"):
            p.add_argument(
                f"--scale-{name}",
                type=cli_args.factor,
                default=1.0,
                metavar="F",
                help=f"scale the target's {name} bones by F (0.1 to 10)",
            )
        p.add_argument(
            "--scale", type=cli_args.factor, default=1.0, metavar="F", help="scale the whole target by F (0.1 to 10)"
        )
        cli_options.add_run_options(p, "overwrite existing output files")


def _add_train(subparsers) -> None:
    with cli_args.command(subparsers, "train", _cmd_train) as p:
        p.add_argument("clips", nargs="*", help="BVH clips of one character")
        p.add_argument(
            "--synthetic",
            type=non_negative_int,
            default=0,
            metavar="N",
            help="train on N built-in synthetic clips instead",
        )
        cli_args.add_output(p, "checkpoint file to write (.pt)")
        cli_args.renamed(
            p,
            "--steps",
            p.add_argument("--train-steps", type=positive_int, default=1500, help="Adam steps (default 1500)"),
        )
        p.add_argument("--batch-size", type=positive_int, default=32, help="windows per Adam step")
        p.add_argument(
            "--pose-augment",
            type=non_negative,
            default=0.0,
            metavar="F",
            help="fraction of each batch with joints turned at random (up to 0.3 rad; 0..0.5, default 0 = off)",
        )
        cli_args.renamed(
            p,
            "--lr",
            p.add_argument("--train-lr", type=positive, default=2e-3, help="Adam learning rate of the training"),
        )
        p.add_argument("--latent", type=positive_int, default=128, help="latent channels D per frame")
        p.add_argument("--hidden", type=positive_int, default=96, help="hidden channels")
        p.add_argument("--seed", type=cli_args.seed, default=0, help="random seed")
        cli_options.add_device(p)
        cli_args.add_force(p, "overwrite an existing checkpoint")


def _add_evaluate(subparsers) -> None:
    with cli_args.command(subparsers, "evaluate", _cmd_evaluate, quiet=False) as p:
        p.add_argument(
            "--data", help="folder laid out as <Character>/<Animation>.bvh (default: $MOTIONLAB_DATA/mixamo)"
        )
        p.add_argument(
            "--source", default="Aj", help="the character trained on and retargeted from (a folder of --data)"
        )
        p.add_argument(
            "--targets",
            nargs="+",
            default=["BigVegas", "Kaya", "SportyGranny", "Goblin_m", "Mousey_m", "Vampire_m"],
            help="the characters retargeted onto (folders of --data)",
        )
        p.add_argument("--animations", nargs="+", help="clip stems (default: the 10 retarget_gt animations)")
        p.add_argument("--all-animations", action="store_true", help="use every animation shared by source and targets")
        p.add_argument(
            "--checkpoint",
            help="checkpoint to use, trained there if missing (default: the network trained on the source's other "
            "clips, cached: $MOTIONLAB_CACHE or ~/.cache/motionlab)",
        )
        p.add_argument("--retrain", action="store_true", help="train even if the --checkpoint file exists")
        p.add_argument(
            "--folds",
            type=positive_int,
            default=1,
            metavar="K",
            help="leave animations out: split the evaluated animations into K folds and evaluate each with a network "
            "trained on the source's other clips (checkpoints <checkpoint>_fold<k>of<K>.pt); default 1",
        )
        p.add_argument(
            "--train-steps",
            type=positive_int,
            default=1500,
            help="Adam steps when the network is trained (default 1500)",
        )
        p.add_argument("--seed", type=cli_args.seed, default=0, help="random seed")
        p.add_argument("--csv", help="write the per-clip records to this CSV")
        cli_args.add_force(p, "overwrite an existing --csv file")
        p.add_argument(
            "--no-ablations", action="store_true", help="skip the ablation rows (full method without one of its parts)"
        )
        p.add_argument(
            "--root",
            choices=ROOT_MODES,
            default="stride",
            help="root trajectory of every row but the plain baseline (default stride, as in `motionlab retarget`)",
        )
        cli_options.add_device(p)
        cli_args.add_quiet(p)
        cli_options.add_solver_args(p)
