"""``motionlab expand``: many clips onto many characters (:mod:`motionlab.retargeting.expand`).

Examples::

    motionlab expand $MOTIONLAB_DATA/mixamo/Aj --characters Kaya=$MOTIONLAB_DATA/mixamo/Kaya/Running.bvh \\
        --preset long_legs --preset child -o expanded/
    motionlab expand "clips/*.bvh" --characters rigs/*.bvh -o out/ --backend ray --address auto
"""

from __future__ import annotations

import sys

from motionlab import cli_args
from motionlab.cli_args import CLIError, check_output_folder, non_negative, non_negative_int, positive, positive_int
from motionlab.retargeting import cli_options
from motionlab.retargeting.cli_options import ROOT_MODES

__all__ = ["register"]


def _cmd_expand(args) -> int:
    """retarget many clips onto many characters (batched, resumable; local or Ray)

    Expand a motion database: every SOURCE clip onto every character, written as OUT/<character>/<clip>.bvh (or .glb
    with --format glb) with OUT/manifest.csv (one row per output). Rerunning the same command redoes only what is
    missing. Exit status 1 when some pair failed (see the manifest's error column).
    """
    from motionlab.retargeting import expand as ex
    from motionlab.retargeting import real

    cli_options.check_device(args.device)
    if args.backend == "ray":
        from motionlab.retargeting.cluster import INSTALL_HINT

        try:
            import ray  # noqa: F401
        except ImportError:
            raise CLIError(INSTALL_HINT) from None
    if not args.characters and not args.preset:
        raise CLIError("give target characters: --characters FILE.bvh ... and/or --preset NAME ...")
    check_output_folder("-o", args.output)  # before any work
    try:
        reference = cli_options.rest_from(args)
        targets = ex.characters(*args.characters, presets=args.preset, rest_from=reference)
        ex.check_output_layout(args.output, ex.find_sources(args.sources), targets, "." + args.format)
    except ValueError as e:
        raise CLIError(str(e)) from None
    solver = cli_options.solver_config(args)  # refused before a network is trained or loaded
    real_source = real.any_real_file([p for _, p in ex.find_sources(args.sources)])
    ckpt = cli_options.network_checkpoint(args, real_source)
    job = ex.expand(
        args.sources,
        targets,
        args.output,
        ckpt,
        solver,
        root_mode=args.root,
        force=args.force,
        max_frames=args.batch_frames,
        backend=args.backend,
        address=args.address,
        workers=args.workers,
        max_penetration_cm=args.max_penetration,
        skate_ratio=args.skate_ratio,
        progress=not args.quiet,
        threads=args.threads or None,
        output_format=args.format,
        fps=args.fps,
        rest_from=reference,
    )
    for line in job.resampled:  # always shown, also under -q
        print(line, file=sys.stderr)
    if not args.quiet:
        print(job.summary())
        _print_failures(job)
    if job.implausible and not args.keep_implausible:
        print(
            f"{job.implausible} output(s) failed the plausibility check (flag implausible_* in {job.out / ex.MANIFEST}); "
            "--keep-implausible accepts them",
            file=sys.stderr,
        )
        return 1
    return 1 if job.failed else 0


def _print_failures(job, most: int = 10) -> None:
    """Why pairs failed: one line per ``error`` row of the manifest (the first ``most``)."""
    failed = [r for r in job.rows if r["status"] == "error"]
    for r in failed[:most]:
        print(f"failed {r['character']}/{r['clip']}: {r['error']}")
    if len(failed) > most:
        print(f"... and {len(failed) - most} more failed pairs: see the error column of {job.out / 'manifest.csv'}")


def register(subparsers) -> None:
    """Add ``expand`` to the ``motionlab`` command."""
    with cli_args.command(
        subparsers,
        "expand",
        _cmd_expand,
        epilog="presets: long_legs, short_legs, long_arms, stocky, tall, child, or NAME:legs=1.2,arms=0.9,...",
        quiet=False,
    ) as p:
        p.add_argument("sources", nargs="+", help="source BVH files, folders (their *.bvh) or glob patterns")
        p.add_argument(
            "--characters",
            nargs="+",
            default=[],
            metavar="CHARACTER",
            help="BVH files whose rest skeletons define the targets, as FILE.bvh or NAME=FILE.bvh",
        )
        p.add_argument("--preset", action="append", default=[], help="a synthetic character (repeatable)")
        cli_args.add_output(p, "output folder")
        p.add_argument(
            "--format", choices=("bvh", "glb"), default="bvh", help="output files: bvh (default) or glb (glTF 2.0)"
        )
        cli_options.add_network(p, "sources")
        p.add_argument("--root", choices=ROOT_MODES, default="stride", help="root trajectory rule (as in retarget)")
        p.add_argument("--batch-frames", type=positive_int, help="frames per solver batch (default: from free memory)")
        p.add_argument(
            "--backend",
            choices=("local", "ray"),
            default="local",
            help='local: batches in this process; ray: the same batches on Ray actors (pip install "motionlab[cluster]")',
        )
        p.add_argument("--address", help="Ray cluster address (default: $RAY_ADDRESS, else a local Ray instance)")
        p.add_argument("--workers", type=positive_int, default=2, help="Ray actors (default 2)")
        p.add_argument(
            "--threads",
            type=non_negative_int,
            default=0,
            help="torch threads during the job (default 0: 1 on the CPU, which keeps a long job fast when the "
            "machine turns busy; torch's own count on a GPU)",
        )
        p.add_argument(
            "--max-penetration", type=non_negative, default=1.0, metavar="CM", help="flag above this (default 1 cm)"
        )
        p.add_argument(
            "--skate-ratio",
            type=positive,
            default=2.0,
            help="flag skating when the planted feet slide faster than the contact speed limit and this times the "
            "source's own planted feet (scaled by the root ratio; default 2)",
        )
        cli_options.add_run_options(p, "redo every pair and replace existing outputs")
