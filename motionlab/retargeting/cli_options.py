"""Options and helpers shared by the retargeting commands (``retarget``, ``evaluate``, ``expand``):
the latent-iteration options, the solver configuration they give, the checkpoint loader.

Its own module so that ``retargeting.cli`` and ``retargeting.expand_cli`` both import it and not
each other.
"""

from __future__ import annotations

import argparse

from motionlab import cli_args
from motionlab.cli_args import CLIError, non_negative, non_negative_int, positive, renamed
from motionlab.retargeting import terms
from motionlab.retargeting.pipeline import METHODS, ROOT_MODES  # the choices come from the library

__all__ = [
    "METHODS",
    "ROOT_MODES",
    "check_device",
    "load_checkpoint",
    "add_network",
    "network_checkpoint",
    "solver_config",
    "add_solver_args",
    "add_rest_from",
    "rest_from",
    "add_device",
    "add_run_options",
]


def check_device(device: str | None) -> None:
    """Refuse a ``--device`` this machine does not have (:func:`devices.pick`), or without one a
    default that ``MOTIONLAB_DEVICE`` names and this machine does not have, before a command does
    any work.

    Raises
    ------
    CLIError naming ``--device`` (or ``MOTIONLAB_DEVICE``) and the devices this machine has.
    """
    from motionlab.retargeting import devices

    try:
        devices.pick(device)
    except ValueError as e:
        raise CLIError(f"--device: {e}" if device is not None else str(e)) from None


def load_checkpoint(path: str | None, device: str | None):
    """The ``--checkpoint`` network (default: the shipped one) on ``device``.

    Raises
    ------
    CLIError
        the file is missing or not a checkpoint written by ``motionlab train``.
    """
    import zipfile

    from motionlab import retargeting
    from motionlab.core import files

    check_device(device)
    if path:
        try:
            files.check_input(path, "--checkpoint")
        except OSError as e:
            raise CLIError(str(e)) from None
        if not zipfile.is_zipfile(path):  # torch.save writes a zip archive; text or BVH is refused here
            raise CLIError(
                f"--checkpoint {path} is not a network checkpoint (a .pt file written by `motionlab train`, "
                "which is a zip archive)"
            )
    try:
        return retargeting.load(path, device) if path else retargeting.load_default(device)
    except retargeting.CheckpointError as e:
        raise CLIError(str(e)) from None


def add_network(p, what: str) -> None:
    """``--checkpoint PATH`` and ``--network {auto,real,synthetic}`` (:func:`network_checkpoint`)."""
    from motionlab.retargeting.real import NETWORKS

    p.add_argument("--checkpoint", help="trained network file (default: chosen by --network)")
    p.add_argument(
        "--network",
        choices=NETWORKS,
        default="auto",
        help="without --checkpoint: real (trained on Aj's clips of MOTIONLAB_DATA on first use, then cached), "
        f"synthetic (the shipped network), or auto (default): real for {what} on a recorded rig when the course "
        "data is there, else synthetic (docs/rigs.md)",
    )


def network_checkpoint(args, real_source: bool):
    """The network of ``--checkpoint`` or ``--network`` (:func:`.real.for_source`) on ``--device``;
    prints which one unless ``--quiet``.

    Raises
    ------
    CLIError for both options at once, a bad checkpoint file, or ``--network real`` without the course data.
    """
    from motionlab import data
    from motionlab.retargeting import real
    from motionlab.retargeting.checkpoint import CheckpointError

    if args.checkpoint:
        if args.network != "auto":
            raise CLIError(f"give --checkpoint or --network {args.network}, not both")
        return load_checkpoint(args.checkpoint, args.device)
    check_device(args.device)
    try:
        ckpt, line = real.for_source(real_source, args.network, args.device, progress=not args.quiet)
    except data.DataNotFound as e:
        raise CLIError(f"--network {args.network}: {e}") from None
    except CheckpointError as e:
        raise CLIError(str(e)) from None
    if not args.quiet:
        print(line)
    return ckpt


def solver_config(args):
    """The solver settings of the parsed options, each checked against its range.

    Raises
    ------
    CLIError naming the option whose value is out of range.
    """
    import dataclasses

    from motionlab.retargeting.solver import SolverConfig

    rounds = SolverConfig().project_iters
    for option, value, ok, expected in (
        ("--steps", args.steps, args.steps >= 0, ">= 0"),
        ("--lr", args.lr, args.lr > 0, "> 0"),
        ("--stop-loss", args.stop_loss, args.stop_loss >= 0, ">= 0"),
        *[
            (_weight_option(t.name), _weight(args, t.name), _weight(args, t.name) >= 0, ">= 0")
            for t in terms.registered()
        ],
        ("--exact-rounds", args.exact_rounds, 0 <= args.exact_rounds <= rounds, f"between 0 and {rounds}"),
    ):
        if not ok:  # also refuses nan
            raise CLIError(f"{option} must be {expected}, got {value}")
    return SolverConfig(
        max_steps=args.steps,
        lr=args.lr,
        threshold=args.stop_loss,
        init=args.init,
        project_exact=args.exact_rounds,
        **_weights(args, {f.name for f in dataclasses.fields(SolverConfig)}),
    )


def _weights(args, fields: set) -> dict:
    """The ``--NAME-weight`` values as SolverConfig arguments: ``lambda_NAME`` where that field
    exists (so an ablation's ``lambda_contact=0`` still applies), else ``weights[NAME]``."""
    named = {t.name: _weight(args, t.name) for t in terms.registered()}
    out = {f"lambda_{n}": w for n, w in named.items() if f"lambda_{n}" in fields}
    out["weights"] = {n: w for n, w in named.items() if f"lambda_{n}" not in fields}
    return out


def _weight_option(name: str) -> str:
    return f"--{name.replace('_', '-')}-weight"


def _weight(args, name: str) -> float:
    return getattr(args, f"{name}_weight")


def add_solver_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("latent iteration")
    g.add_argument(
        "--steps", type=non_negative_int, default=100, help="step limit of the latent iteration (default 100)"
    )
    g.add_argument(
        "--lr",
        type=positive,
        default=0.02,
        help="Adam step on the latent, relative to its spread std(φ₀) (default 0.02)",
    )
    renamed(
        g,
        "--threshold",
        g.add_argument(
            "--stop-loss",
            type=non_negative,
            default=2e-3,
            metavar="L",
            help="stop when L_iter drops below this (the paper's threshold; default 2e-3)",
        ),
    )
    for term in terms.registered():  # one --NAME-weight per registered loss term
        g.add_argument(
            _weight_option(term.name),
            type=non_negative,
            default=term.weight,
            metavar="W",
            help=f"weight of {term.description or term.name} (default {term.weight:g})",
        )
    g.add_argument(
        "--init",
        choices=("auto", "project", "encoder"),
        default="auto",
        help="start of the iteration: least-squares projection onto the source's rotations, the encoder's "
        "latent (the paper), or auto (default: projection)",
    )
    g.add_argument(
        "--exact-rounds",
        type=non_negative_int,
        default=4,
        metavar="K",
        help="of the projection's 8 Gauss-Newton rounds, how many last ones are not smoothed over time (default 4)",
    )


def add_device(p: argparse.ArgumentParser) -> None:
    """``--device``: the torch device of a command that runs the network."""
    p.add_argument(
        "--device", help="torch device (default: $MOTIONLAB_DEVICE if set, else cuda if available, else cpu)"
    )


def add_run_options(p: argparse.ArgumentParser, force_help: str) -> None:
    """The options that end a command retargeting clips (``retarget``, ``expand``): ``--device``,
    ``--rest-from``, ``--force`` (``force_help``), the frame-rate and plausibility options, ``-q``
    and the latent iteration's."""
    add_device(p)
    add_rest_from(p)
    cli_args.add_force(p, force_help)
    cli_args.add_rate_and_plausibility_args(p)
    cli_args.add_quiet(p)
    add_solver_args(p)


def add_rest_from(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--rest-from",
        metavar="FILE.bvh",
        help="take the standing pose of every source or target on FILE's rig from FILE (another take of the rig "
        "that stands), for a rig whose rest offsets lie flat and whose profile has no rule",
    )


def rest_from(args):
    """The ``--rest-from`` motion, checked (it must have a standing pose), or None.

    Raises
    ------
    CLIError naming ``--rest-from`` when the file cannot be read or does not stand.
    """
    if not args.rest_from:
        return None
    from motionlab.core import bvh, files, humanoid, rest_pose

    try:
        reference = bvh.load(files.check_input(args.rest_from, "--rest-from"))
        rest_pose.standing(humanoid.to_canonical(reference), f"--rest-from {args.rest_from}")
    except ValueError as e:  # also RigMappingError, RestPoseError, BVH errors
        raise CLIError(f"--rest-from {args.rest_from}: {e}") from None
    return reference
