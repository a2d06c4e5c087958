"""Argument checks shared by every ``motionlab`` sub-command.

Numbers: argparse ``type=`` functions (:func:`positive`, :func:`non_negative`,
:func:`positive_int`, :func:`non_negative_int`) refuse a bad value with argparse's own message,
which names the option (``argument --workers: expected 1 or more, got '0'``).

Outputs: :func:`check_outputs` and :func:`check_output_folder` are called *before* a command does
any work, so a refused output costs nothing and leaves nothing behind. Every message names the
option as the user typed it (``-o``, ``--report``) and says what would be accepted.

Vocabulary: one option name has one meaning across sub-commands (``tests/commands/
test_cli_vocabulary.py`` checks it). :func:`command` registers a sub-command (its parser, its
``-q/--quiet`` and the function it runs); :func:`add_output`, :func:`add_force` and :func:`add_quiet`
add the options every writing command shares (``-o/--output``, ``--force``, ``-q/--quiet``); :func:`renamed` keeps
an option's old spelling working as a hidden, deprecated alias that prints a note;
:class:`HelpFormatter` shows every option's default in ``--help``; :class:`Stages` is the progress
bar of a command that runs in a few long stages.
"""

from __future__ import annotations

import argparse
import contextlib
import inspect
import math
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from motionlab.core import files

__all__ = [
    "CLIError",
    "rig_error",
    "positive",
    "non_negative",
    "positive_int",
    "non_negative_int",
    "in_range",
    "frame_rate",
    "factor",
    "seed",
    "check_size",
    "motion_output",
    "check_replaceable",
    "check_outputs",
    "check_output_folder",
    "HelpFormatter",
    "DeprecatedAlias",
    "command",
    "add_output",
    "add_force",
    "add_quiet",
    "renamed",
    "Stages",
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


def _checked(text: str, parse, accepted, expected: str):
    """``parse(text)`` when ``accepted`` by the rule, else argparse's error ``expected EXPECTED, got 'TEXT'``."""
    value = parse(text)
    if not accepted(value):
        raise argparse.ArgumentTypeError(f"expected {expected}, got {text!r}")
    return value


def positive(text: str) -> float:
    """argparse type: a finite number > 0 (``0``, ``-1.7``, ``nan`` refused).

    Raises
    ------
    argparse.ArgumentTypeError for anything but a finite number > 0.
    """
    return _checked(text, _number, lambda v: math.isfinite(v) and v > 0, "a positive number")


def non_negative(text: str) -> float:
    """argparse type: a finite number >= 0 (``-1``, ``nan`` refused).

    Raises
    ------
    argparse.ArgumentTypeError for anything but a finite number >= 0.
    """
    return _checked(text, _number, lambda v: math.isfinite(v) and v >= 0, "0 or a positive number")


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1 (``0``, ``-5``, ``2.5`` refused).

    Raises
    ------
    argparse.ArgumentTypeError for anything but a whole number >= 1.
    """
    return _checked(text, _whole, lambda v: v >= 1, "a whole number of 1 or more")


def non_negative_int(text: str) -> int:
    """argparse type: a whole number >= 0.

    Raises
    ------
    argparse.ArgumentTypeError for anything but a whole number >= 0.
    """
    return _checked(text, _whole, lambda v: v >= 0, "a whole number of 0 or more")


def in_range(low: float, high: float, what: str = "a number", name: str = "in_range"):
    """argparse type named ``name``: a finite number from ``low`` to ``high`` (the message states the range)."""

    def check(text: str) -> float:
        return _checked(
            text, _number, lambda v: math.isfinite(v) and low <= v <= high, f"{what} from {low:g} to {high:g}"
        )

    check.__name__ = name
    return check


FPS_RANGE = (1.0, 1000.0)
"""Frame rates a command accepts: motion capture records at 24 to 480 fps; above 1000 fps a clip
only grows, below 1 fps it is no longer motion."""

frame_rate = in_range(*FPS_RANGE, "a frame rate in fps", "frame_rate")
"""argparse type of every ``--fps``."""

FACTOR_RANGE = (0.1, 10.0)
"""Bone-length factors a command accepts: a tenth to ten times the bone (a human figure stays one)."""

factor = in_range(*FACTOR_RANGE, "a length factor", "factor")
"""argparse type of every ``--scale*``, ``--legs``, ``--arms`` factor."""

SEED_MAX = 2**32 - 1


def seed(text: str) -> int:
    """argparse type of every ``--seed``: a whole number from 0 to 2**32 - 1 (what NumPy's generators take).

    Raises
    ------
    argparse.ArgumentTypeError for anything else.
    """
    return _checked(text, _whole, lambda v: 0 <= v <= SEED_MAX, f"a whole number from 0 to {SEED_MAX}")


MAX_OUTPUT_GB = 2.0
"""A command refuses, before any work, an output whose poses would take more than this many GB
of memory (``frames x joints x 7`` float64 numbers: a rotation and a position per joint)."""


def check_size(what: str, frames: float, joints: int) -> None:
    """Refuse a motion of ``frames`` frames of ``joints`` joints beyond :data:`MAX_OUTPUT_GB`;
    ``what`` names the options that asked for it (``--seconds 1e9 at --fps 60``).

    Raises
    ------
    CLIError naming ``what``, the size asked for and the limit.
    """
    gigabytes = frames * joints * 7 * 8 / 1e9
    if not gigabytes <= MAX_OUTPUT_GB:
        raise CLIError(
            f"{what} asks for {frames:.3g} frames of {joints} joints ({gigabytes:.3g} GB of poses); "
            f"at most {MAX_OUTPUT_GB:g} GB is made ({MAX_OUTPUT_GB * 1e9 / (joints * 56):.3g} frames): "
            "ask for fewer frames"
        )


def check_replaceable(option: str, given) -> None:
    """A :class:`CLIError` for an output name that is no file to write, ``--force`` or not: a name
    ending in ``/``, a symbolic link, a named pipe, a device (:func:`motionlab.core.files.check_replaceable`).

    Raises
    ------
    CLIError naming ``option`` and what the path is.
    """
    try:
        files.check_replaceable(given, option)
    except OSError as e:
        raise CLIError(str(e)) from None


def motion_output(option: str, given) -> str:
    """The suffix (``.bvh``, ``.glb``) of a motion output, or a :class:`CLIError` saying which are
    written (:func:`motionlab.core.motion_files.output_suffix`); first :func:`check_replaceable`.

    Raises
    ------
    CLIError for a name that is no file to write, a folder, or a suffix that is not written.
    """
    from motionlab.core import motion_files

    check_replaceable(option, given)
    if Path(given).is_dir():
        raise CLIError(f"{option} {given} is a folder; expected the name of a file to write")
    try:
        return motion_files.output_suffix(given, option)
    except ValueError as e:
        raise CLIError(str(e)) from None


class CLIError(Exception):
    """A user-facing error: printed as ``motionlab: error: …`` with exit status 2, no traceback.

    Defined here, beside the checks that raise it, and re-exported by :mod:`motionlab.cli`.
    """


def rig_error(error, role: str, path) -> CLIError:
    """A :class:`CLIError` saying which file (``role``: source, target, input) does not map onto the
    humanoid (a :class:`~motionlab.core.humanoid.RigMappingError` ``error``)."""
    return CLIError(error.for_file(role, path))


def _check_writable(option: str, path: Path, folder: Path) -> None:
    """Refuse ``path`` when the existing ``folder`` it goes into cannot be written."""
    if not os.access(folder, os.W_OK | os.X_OK):
        raise CLIError(
            f"{option} {path}: cannot write into the folder {folder.resolve()} (permission denied); "
            "choose a folder you can write to"
        )


def _check_folder(option: str, path: Path, folder: Path) -> None:
    """``folder`` (where ``path`` goes) exists and takes new files."""
    if folder.exists() and not folder.is_dir():
        raise CLIError(f"{option} {path}: {folder} is a file, not a folder; choose a file name in a folder")
    if not folder.is_dir():
        raise CLIError(f"{option} {path}: the folder {folder} does not exist; create it or choose another folder")
    _check_writable(option, path, folder)


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
        An output is a folder (or a name ending in ``/``), exists without ``force``, is a link, a
        named pipe or a device (``force`` or not), lies in a missing or unwritable folder, is named
        by two options, or is an input file; the message names the option.
    """
    seen: dict[Path, str] = {}
    read = {Path(p).resolve(): what for what, p in inputs if p is not None}
    checked: list[Path | None] = []
    for option, given in outputs:
        if given is None:
            checked.append(None)
            continue
        check_replaceable(option, given)
        path = Path(given)
        key = path.resolve()
        if key in seen:
            raise CLIError(f"{seen[key]} and {option} both name {path}; give each output its own file")
        if key in read:
            raise CLIError(f"{option} {path} is the {read[key]} file; write the output to another file")
        if path.is_dir():
            raise CLIError(f"{option} {path} is a folder; expected the name of a file to write")
        if path.exists() and not force:
            raise CLIError(files.exists_message(option, path))
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
        raise CLIError(f"{option} {path} is a file; expected a folder (it is made if it does not exist)")
    folder = path
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        raise CLIError(f"{option} {path}: {folder} is a file, so the folder cannot be made; choose another folder")
    _check_writable(option, path, folder)
    return path


def _shown(default) -> bool:
    """A default worth printing: not ``None``, a flag's ``False``, an empty list or SUPPRESS (0 is)."""
    return not (default is None or default is False or default is argparse.SUPPRESS or default == [])


class HelpFormatter(argparse.HelpFormatter):
    """``--help`` that ends every option's text with its default, unless the text already says it.

    No default is shown where there is none to show (``None``, a flag's ``False``, an empty list).
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if action.option_strings and "default" not in text and _shown(action.default):
            text += " (default: %(default)s)"
        return text


class DeprecatedAlias(argparse.Action):
    """An option's old spelling: stores its value as the new option does, and prints on stderr
    ``motionlab: note: OLD is deprecated; use NEW``. Hidden from ``--help``."""

    def __init__(self, option_strings, dest, new: str = "", **kwargs):
        super().__init__(option_strings, dest, **kwargs)
        self.new = new

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"motionlab: note: {option_string} is deprecated here; use {self.new}", file=sys.stderr)
        setattr(namespace, self.dest, True if self.nargs == 0 else values)


def renamed(parser, old: str, new: argparse.Action) -> argparse.Action:
    """Keep ``old`` working as a deprecated alias of the option ``new`` (the action that
    ``add_argument`` returned): same destination, type and choices, hidden from ``--help``."""
    return parser.add_argument(
        old,
        dest=new.dest,
        type=new.type,
        choices=new.choices,
        metavar=new.metavar,
        nargs=new.nargs,
        default=argparse.SUPPRESS,
        help=argparse.SUPPRESS,
        action=DeprecatedAlias,
        new=new.option_strings[-1],
    )


def _help_texts(run) -> tuple[str, str]:
    """``(summary, description)`` of a command from ``run``'s docstring: its first paragraph, then the
    others up to the first numpydoc section (``Raises`` over a line of dashes), each paragraph's lines
    joined by spaces, paragraphs by a blank line."""
    text = re.split(r"\n\S[^\n]*\n-{3,}\n", inspect.getdoc(run) or "")[0].strip()
    paragraphs = [" ".join(p.split("\n")) for p in text.split("\n\n")]
    return paragraphs[0], "\n\n".join(paragraphs[1:])


@contextlib.contextmanager
def command(subparsers, name: str, run, *, quiet: bool = True, **kwargs):
    """Register the sub-command ``name``, which runs ``run(args)``; yields its parser.

    ``run``'s docstring is the command's help: its first paragraph the line in ``motionlab --help``,
    the rest the text of ``motionlab NAME --help``. The ``with`` block adds the command's own
    arguments; on leaving it, ``-q/--quiet`` is added last (``quiet=False``: the block placed it
    itself) and ``run`` becomes the command's ``func``. ``kwargs`` go to ``add_parser`` (an epilog,
    a formatter class).
    """
    summary, description = _help_texts(run)
    parser = subparsers.add_parser(name, help=summary, description=description, **kwargs)
    yield parser
    if quiet:
        add_quiet(parser)
    parser.set_defaults(func=run)


def add_output(parser, text: str, *, required: bool = True, **kwargs) -> argparse.Action:
    """``-o/--output``: where the command writes (a file or a folder, as the help ``text`` says);
    ``kwargs`` (a ``default``, a ``metavar``) go to ``add_argument``."""
    return parser.add_argument("-o", "--output", required=required, help=text, **kwargs)


def add_force(parser, text: str) -> argparse.Action:
    """``--force``: replace what is in the way (the help ``text`` says what, for this command)."""
    return parser.add_argument("--force", action="store_true", help=text)


def add_quiet(parser) -> argparse.Action:
    """``-q/--quiet``: no progress bars and no status lines; results and errors still print."""
    return parser.add_argument(
        "-q", "--quiet", action="store_true", help="no progress bars or status lines; results and errors still print"
    )


class Stages:
    """A progress bar over a command's named stages, on stderr: it names the stage that runs, so a
    long job is never silent. Call :meth:`start` as each stage begins and :meth:`close` at the end.

    Parameters
    ----------
    names : the stages in order (their count is the bar's length)
    desc : the bar's label, e.g. the command's name
    disable : no bar (``--quiet``, or input too short to need one)
    """

    def __init__(self, names: Sequence[str], desc: str, disable: bool = False):
        from tqdm.auto import tqdm

        self._bar = tqdm(total=len(names), desc=desc, unit="stage", disable=disable, leave=False)
        self._started = False

    def start(self, name: str) -> None:
        """Mark the previous stage done and show ``name`` as running."""
        if self._started:
            self._bar.update(1)
        self._started = True
        self._bar.set_postfix_str(name, refresh=True)

    def close(self) -> None:
        self._bar.close()


def add_rate_and_plausibility_args(p: argparse.ArgumentParser) -> None:
    """``--fps`` (output frame rate) and ``--keep-implausible``, shared by ``retarget`` and ``expand``."""
    p.add_argument(
        "--fps",
        type=frame_rate,
        metavar="FPS",
        help="frame rate of the output (default: the source's; a resample is always reported)",
    )
    p.add_argument(
        "--keep-implausible",
        action="store_true",
        help="write outputs that fail the plausibility check (feet on the floor, hip height, bone lengths) "
        "instead of refusing them",
    )
