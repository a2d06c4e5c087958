"""The ``motionlab`` command line.

Each part of the package registers its own sub-commands through a ``register(subparsers)``
function in its ``cli`` module; this file only gathers them, so ``motionlab --help`` lists
everything and a part that fails to import does not break the others.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from motionlab.cli_args import CLIError, HelpFormatter, rig_error

__all__ = ["main", "build_parser", "CLIError", "rig_error"]

_PARTS = (
    "motionlab.commands.foundation",
    "motionlab.retargeting.cli",
    "motionlab.motion_graphs.cli",
    "motionlab.interpolation.cli",
    "motionlab.viz.cli",
)

_HEAVY = ("motionlab.retargeting.cli",)
"""Parts whose import loads torch (seconds): looked in last when a single command is wanted."""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``motionlab`` parser with every part's sub-commands; with ``command``, the parts are
    imported (light ones first) only until one registers it, so a command of one part does not pay
    for another part's imports (torch, for the retargeting commands); an unknown ``command``
    imports them all."""
    parser = argparse.ArgumentParser(
        prog="motionlab",
        description="Skeletal character animation: BVH tools, retargeting by latent iteration, "
        "motion graphs, key-pose in-betweening and 3D playback.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    parts = _PARTS if command is None else sorted(_PARTS, key=lambda name: name in _HEAVY)
    for name in parts:
        if command is not None and command in sub.choices:
            break
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as e:
            if e.name == name:
                continue  # that part has no commands (yet)
            raise
        module.register(sub)
    if command is not None and command not in sub.choices:
        return build_parser()  # an unknown command: the full parser, in its order, says which exist
    for each in sub.choices.values():  # every option's default in its --help
        each.formatter_class = HelpFormatter
    return parser


def _os_message(e: OSError) -> str:
    """``[Errno 13] Permission denied: 'x.bvh'`` as ``x.bvh: permission denied``; our own messages unchanged."""
    if e.strerror and e.filename is not None:
        where = f"{e.filename} -> {e.filename2}" if e.filename2 else str(e.filename)
        return f"{where}: {e.strerror[0].lower()}{e.strerror[1:]}"
    return str(e) or type(e).__name__


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    command = argv[0] if argv and not argv[0].startswith("-") else None
    parser = build_parser(command)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except CLIError as e:
        print(f"motionlab: error: {e}", file=sys.stderr)
        return 2
    except ValueError as e:
        print(f"motionlab: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # unreadable input, unwritable folder, a folder where a file was expected, ...
        print(f"motionlab: error: {_os_message(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("motionlab: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # `python -m motionlab.cli`: use the imported module so CLIError is one class
    from motionlab.cli import main as _main

    sys.exit(_main())
