"""The ``motionlab`` command line.

Each part of the package registers its own sub-commands through a ``register(subparsers)``
function in its ``cli`` module; this file only gathers them, so ``motionlab --help`` lists
everything and a part that fails to import does not break the others.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from motionlab.cli_args import CLIError, HelpFormatter, RawDescriptionHelpFormatter, rig_error

__all__ = ["main", "build_parser", "CLIError", "rig_error"]

_PARTS = (
    "motionlab.commands.foundation",
    "motionlab.retargeting.cli",
    "motionlab.motion_graphs.cli",
    "motionlab.interpolation.cli",
    "motionlab.viz.cli",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="motionlab",
        description="Skeletal character animation: BVH tools, retargeting by latent iteration, "
        "motion graphs, key-pose in-betweening and 3D playback.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _PARTS:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as e:
            if e.name == name:
                continue  # that part has no commands (yet)
            raise
        module.register(sub)
    for command in sub.choices.values():  # every option's default in its --help
        raw = issubclass(command.formatter_class, argparse.RawDescriptionHelpFormatter)
        command.formatter_class = RawDescriptionHelpFormatter if raw else HelpFormatter
    return parser


def _os_message(e: OSError) -> str:
    """``[Errno 13] Permission denied: 'x.bvh'`` as ``x.bvh: permission denied``; our own messages unchanged."""
    if e.strerror and e.filename is not None:
        where = f"{e.filename} -> {e.filename2}" if e.filename2 else str(e.filename)
        return f"{where}: {e.strerror[0].lower()}{e.strerror[1:]}"
    return str(e) or type(e).__name__


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
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
