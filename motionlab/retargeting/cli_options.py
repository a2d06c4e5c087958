"""Options and helpers shared by the retargeting commands (``retarget``, ``evaluate``, ``expand``):
the latent-iteration options, the solver configuration they give, the checkpoint loader.

Its own module so that ``retargeting.cli`` and ``retargeting.expand_cli`` both import it and not
each other.
"""

from __future__ import annotations

import argparse

from motionlab.cli_args import CLIError, non_negative, non_negative_int, positive, renamed
from motionlab.retargeting.pipeline import METHODS, ROOT_MODES  # the choices come from the library

__all__ = ["METHODS", "ROOT_MODES", "load_checkpoint", "solver_config", "add_solver_args"]


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


def solver_config(args):
    from motionlab.retargeting.solver import SolverConfig

    rounds = SolverConfig().project_iters
    for option, value, ok, expected in (
        ("--steps", args.steps, args.steps >= 0, ">= 0"),
        ("--lr", args.lr, args.lr > 0, "> 0"),
        ("--stop-loss", args.stop_loss, args.stop_loss >= 0, ">= 0"),
        ("--contact-weight", args.contact_weight, args.contact_weight >= 0, ">= 0"),
        ("--exact-rounds", args.exact_rounds, 0 <= args.exact_rounds <= rounds, f"between 0 and {rounds}"),
    ):
        if not ok:  # also refuses nan
            raise CLIError(f"{option} must be {expected}, got {value}")
    return SolverConfig(
        max_steps=args.steps,
        lr=args.lr,
        threshold=args.stop_loss,
        lambda_contact=args.contact_weight,
        init=args.init,
        project_exact=args.exact_rounds,
    )


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
    g.add_argument(
        "--contact-weight",
        type=non_negative,
        default=0.5,
        metavar="W",
        help="weight of the foot-contact term (motionlab's addition; 0 = the paper's two losses; default 0.5)",
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
