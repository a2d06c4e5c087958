"""Argument checks shared by every ``motionlab`` sub-command.

Numbers: argparse ``type=`` functions (:func:`positive`, :func:`non_negative`,
:func:`positive_int`, :func:`non_negative_int`) refuse a bad value with argparse's own message,
which names the option (``argument --workers: expected 1 or more, got '0'``).

Outputs: :func:`check_outputs` and :func:`check_output_folder` are called *before* a command does
any work, so a refused output costs nothing and leaves nothing behind. Every message names the
option as the user typed it (``-o``, ``--report``) and says what would be accepted.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Sequence
from pathlib import Path

__all__ = [
    "positive",
    "non_negative",
    "positive_int",
    "non_negative_int",
    "check_outputs",
    "check_output_folder",
    "add_rate_and_plausibility_args",
]


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None


def _whole(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None


def positive(text: str) -> float:
    """argparse type: a finite number > 0 (``0``, ``-1.7``, ``nan`` refused)."""
    value = _number(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def non_negative(text: str) -> float:
    """argparse type: a finite number >= 0 (``-1``, ``nan`` refused)."""
    value = _number(text)
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected 0 or a positive number, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1 (``0``, ``-5``, ``2.5`` refused)."""
    value = _whole(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number of 1 or more, got {text!r}")
    return value


def non_negative_int(text: str) -> int:
    """argparse type: a whole number >= 0."""
    value = _whole(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number of 0 or more, got {text!r}")
    return value


def _error(message: str) -> Exception:
    from motionlab.cli import CLIError

    return CLIError(message)


def _check_folder(option: str, path: Path, folder: Path) -> None:
    """``folder`` (where ``path`` goes) exists and takes new files."""
    if folder.exists() and not folder.is_dir():
        raise _error(f"{option} {path}: {folder} is a file, not a folder; choose a file name in a folder")
    if not folder.is_dir():
        raise _error(f"{option} {path}: the folder {folder} does not exist; create it or choose another folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise _error(
            f"{option} {path}: cannot write into the folder {folder.resolve()} (permission denied); "
            "choose a folder you can write to"
        )


def check_outputs(
    outputs: Sequence[tuple[str, str | os.PathLike | None]],
    force: bool,
    inputs: Sequence[tuple[str, str | os.PathLike | None]] = (),
) -> list[Path | None]:
    """Check every output file of a command before it starts work.

    Parameters
    ----------
    outputs : ``(option, path)`` pairs, e.g. ``[("-o", "walk.mlgraph"), ("--report", "r.json")]``;
        a ``None`` path (option not given) is skipped
    force : the command's ``--force``: an existing file may be replaced
    inputs : ``(what, path)`` pairs of the files the command reads; no output may be one of them

    Returns
    -------
    list of Path (``None`` where the path was ``None``), in the order of ``outputs``

    Raises
    ------
    CLIError
        An output is a folder, exists without ``force``, lies in a missing or unwritable folder,
        is named by two options, or is an input file; the message names the option.
    """
    seen: dict[Path, str] = {}
    read = {Path(p).resolve(): what for what, p in inputs if p is not None}
    checked: list[Path | None] = []
    for option, given in outputs:
        if given is None:
            checked.append(None)
            continue
        path = Path(given)
        key = path.resolve()
        if key in seen:
            raise _error(f"{seen[key]} and {option} both name {path}; give each output its own file")
        if key in read:
            raise _error(f"{option} {path} is the {read[key]} file; write the output to another file")
        if path.is_dir():
            raise _error(f"{option} {path} is a folder; expected the name of a file to write")
        if path.exists() and not force:
            raise _error(f"{option} {path} exists; add --force to replace it, or choose another file name")
        _check_folder(option, path, path.parent)
        seen[key] = option
        checked.append(path)
    return checked


def check_output_folder(option: str, given: str | os.PathLike) -> Path:
    """Check an output *folder* (made if missing) before a command starts work.

    Raises
    ------
    CLIError
        ``given`` is a file, or neither it nor its nearest existing parent folder takes new files.
    """
    path = Path(given)
    if path.exists() and not path.is_dir():
        raise _error(f"{option} {path} is a file; expected a folder (it is made if it does not exist)")
    folder = path
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        raise _error(f"{option} {path}: {folder} is a file, so the folder cannot be made; choose another folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise _error(
            f"{option} {path}: cannot write into the folder {folder.resolve()} (permission denied); "
            "choose a folder you can write to"
        )
    return path


def add_rate_and_plausibility_args(p: argparse.ArgumentParser) -> None:
    """``--fps`` (output frame rate) and ``--keep-implausible``, shared by ``retarget`` and ``expand``."""
    p.add_argument(
        "--fps",
        type=positive,
        metavar="FPS",
        help="frame rate of the output (default: the source's; a resample is always reported)",
    )
    p.add_argument(
        "--keep-implausible",
        action="store_true",
        help="write outputs that fail the plausibility check (feet on the floor, hip height, bone lengths) "
        "instead of refusing them",
    )
