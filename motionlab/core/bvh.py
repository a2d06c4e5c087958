"""Read and write BVH motion-capture files.

A BVH file has two parts. ``HIERARCHY`` describes the skeleton: nested ``ROOT``/``JOINT``
blocks with a rest ``OFFSET`` and a ``CHANNELS`` list each, and ``End Site`` blocks marking
the tips of chains. ``MOTION`` gives ``Frames:``, ``Frame Time:`` (seconds per frame) and then
one line per frame holding one number per channel, in the order the channels were declared.

How channels are read (the same convention is used to write):

* rotation channels are degrees and compose **intrinsically in the listed order**:
  ``Zrotation Xrotation Yrotation`` means ``R = Rz @ Rx @ Ry``; a joint may list 0 to 3
  rotation axes, and every joint may use its own order;
* position channels **replace** the joint's ``OFFSET`` (they are not added to it): the root's
  position channels are its world position, and a non-root joint with position channels is
  translated per frame (``Motion.local_pos``). A root without position channels stays at its
  ``OFFSET``;
* lengths are multiplied by ``scale`` (default 0.01: centimetres in the file, metres inside).

The parser reads the header token by token (it is small) and converts the whole motion block
in one NumPy call; line-by-line scanning only happens to locate the first bad line of a file
that failed the vectorised checks. Every problem with the input raises :class:`BVHError`,
whose message names the file, the 1-based line and what was expected.

Taught in ``notebooks/01_preprocessing.ipynb``.
"""

from __future__ import annotations

import io
import math
import os
import re
from pathlib import Path

import numpy as np

from motionlab.core import files, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = [
    "BVHError",
    "CHANNEL_NAMES",
    "DEFAULT_SCALE",
    "header",
    "load",
    "loads",
    "save",
    "dumps",
    "frame_time",
]

DEFAULT_SCALE = 0.01
"""Default ``load`` scale: BVH centimetres to metres (``save`` uses ``1 / DEFAULT_SCALE``)."""

CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
"""The six BVH channel names (matched case-insensitively when reading)."""

_POSITION = {"xposition": 0, "yposition": 1, "zposition": 2}
_ROTATION = {"xrotation": "x", "yrotation": "y", "zrotation": "z"}
_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
_ROOT_LAYOUT = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
_JOINT_LAYOUT = ("Zrotation", "Yrotation", "Xrotation")
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_COUNT = re.compile(r"[0-9]+")
_ROT_TOL = 1e-6  # radians: rotation a channel layout cannot express before save refuses

# the bytes a motion block may hold: number characters and the whitespace bytes.split() uses
_NUMERIC_BYTES = b"0123456789+-.eE \t\n\r\x0b\x0c"


class BVHError(ValueError):
    """A malformed BVH file; the message names the file, the line and what was expected.

    Attributes
    ----------
    source : str   file path, or ``"<string>"`` for :func:`loads`
    line : int     1-based line number of the problem
    """

    def __init__(self, source: str, line: int, message: str) -> None:
        super().__init__(f"{source}, line {line}: {message}")
        self.source = source
        self.line = line

    def __reduce__(self):
        return (_rebuild_error, (self.args[0], self.source, self.line))


def _rebuild_error(text: str, source: str, line: int) -> BVHError:
    err = BVHError.__new__(BVHError)
    ValueError.__init__(err, text)
    err.source, err.line = source, line
    return err


def _show(token: str | None) -> str:
    """How a found token appears in messages."""
    if token is None:
        return "end of file"
    return repr(token if len(token) <= 40 else token[:37] + "...")


# ---------------------------------------------------------------------------------- header
class _NeedMore(Exception):
    """The header goes on past the part of the file read so far."""


class _Tokens:
    """Whitespace-separated tokens of the header, read lazily line by line.

    Lines are only read when a token is needed, so after the last header token ``pos`` points
    at the first line of the motion block.
    """

    def __init__(self, text: str, source: str, complete: bool = True) -> None:
        self.text = text
        self.source = source
        self.complete = complete  # False: ``text`` is the start of a longer file
        self.pos = 0  # start of the next unread line
        self.line = 0  # number of the line the buffered tokens come from
        self.buf: list[str] = []
        self.i = 0

    def _fill(self) -> bool:
        while self.i >= len(self.buf):
            if self.pos > len(self.text) or (self.pos == len(self.text) and self.line > 0):
                if not self.complete:
                    raise _NeedMore
                return False
            end = self.text.find("\n", self.pos)
            if end < 0:
                end = len(self.text)
            self.buf = self.text[self.pos : end].split()
            self.i = 0
            self.pos = end + 1
            self.line += 1
        return True

    def take(self) -> str | None:
        if self.i >= len(self.buf) and not self._fill():
            return None
        self.i += 1
        return self.buf[self.i - 1]

    def rest_of_line(self) -> list[str]:
        """Tokens left on the current line (without reading a new line)."""
        return self.buf[self.i :]

    def skip(self, n: int) -> None:
        self.i += n

    def error(self, message: str, line: int | None = None) -> BVHError:
        return BVHError(self.source, max(1, self.line if line is None else line), message)

    def expect(self, keyword: str, context: str = "") -> None:
        tok = self.take()
        if tok is None or tok.upper() != keyword.upper():
            raise self.error(f"expected {keyword!r}{context}, found {_show(tok)}")

    def number(self, what: str) -> float:
        tok = self.take()
        problem = "a number" if tok is None else _number_problem(tok)
        if problem:
            raise self.error(f"expected {problem} for {what}, found {_show(tok)}")
        return float(tok)

    def same_line_value(self, keyword: str) -> str:
        """The single token after ``keyword`` on the keyword's own line."""
        rest = self.rest_of_line()
        if not rest:
            raise self.error(f"expected a value after {keyword!r} on the same line, found end of line")
        if len(rest) > 1:
            raise self.error(f"expected only one value after {keyword!r}, found {_show(' '.join(rest))}")
        self.skip(1)
        return rest[0]


class _Joint:
    __slots__ = ("index", "line", "has_offset", "has_channels", "has_children", "has_end_site")

    def __init__(self, index: int, line: int) -> None:
        self.index = index
        self.line = line
        self.has_offset = False
        self.has_channels = False
        self.has_children = False
        self.has_end_site = False


def _joint_name(tok: _Tokens, keyword: str) -> str:
    """Joint name: the rest of the keyword's line up to an optional ``{``."""
    rest = tok.rest_of_line()
    n = rest.index("{") if "{" in rest else len(rest)
    if n == 0:
        raise tok.error(f"expected a joint name after {keyword}, found {_show(rest[0]) if rest else 'end of line'}")
    name = " ".join(rest[:n])
    if "{" in name or "}" in name:  # a brace would end the name when written back
        raise tok.error(f"expected a joint name without braces after {keyword}, found {_show(name)}")
    tok.skip(n)
    return name


def _channels(tok: _Tokens, joint_name: str) -> tuple[str, ...]:
    line = tok.line
    count_tok = tok.take()
    if count_tok is None or not _COUNT.fullmatch(count_tok) or int(count_tok) > 6:
        raise tok.error(
            f"expected a channel count from 0 to 6 after CHANNELS of joint {joint_name!r}, found {_show(count_tok)}"
        )
    count = int(count_tok)
    names: list[str] = []
    for k in range(count):
        name = tok.take()
        key = None if name is None else name.lower()
        if key not in _POSITION and key not in _ROTATION:
            raise tok.error(
                f"expected channel name {k + 1} of {count} (CHANNELS {count} of joint {joint_name!r} at line {line}; "
                f"one of {', '.join(CHANNEL_NAMES)}), found {_show(name)}"
            )
        if any(n.lower() == key for n in names):
            raise tok.error(f"expected distinct channels for joint {joint_name!r}, found {name!r} twice")
        names.append(name)
    return tuple(names)


class _Hierarchy:
    """The joint tree read so far from a ``HIERARCHY`` block, in file order and file units."""

    def __init__(self, tok: _Tokens) -> None:
        self.tok = tok
        self.names: list[str] = []
        self.parents: list[int] = []
        self.offsets: list[tuple[float, float, float]] = []
        self.channels: list[tuple[str, ...]] = []
        self.end_sites: dict[int, tuple[float, float, float]] = {}
        self.seen: dict[str, int] = {}  # joint name -> line it was declared on

    def new_joint(self, keyword: str, parent: int) -> _Joint:
        """Read ``<name> {`` after ``ROOT``/``JOINT`` and add the joint."""
        tok = self.tok
        line = tok.line
        name = _joint_name(tok, keyword)
        if name in self.seen:
            raise tok.error(f"expected a unique joint name, found {name!r} again (first at line {self.seen[name]})")
        self.seen[name] = line
        self.names.append(name)
        self.parents.append(parent)
        self.offsets.append((0.0, 0.0, 0.0))
        self.channels.append(())
        tok.expect("{", f" to open joint {name!r}")
        return _Joint(len(self.names) - 1, line)

    def offset(self, what: str) -> tuple[float, float, float]:
        x, y, z = (self.tok.number(f"{axis} of the OFFSET of {what}") for axis in "xyz")
        return x, y, z

    def end_site_token(self, word: str | None, stack: list, pending):
        """One token inside ``End Site { OFFSET x y z }``; returns the offset read and not yet closed."""
        key = None if word is None else word.upper()
        owner = stack[-2]
        if key == "OFFSET" and pending is None:
            return self.offset(f"the End Site of joint {self.names[owner.index]!r}")
        if key == "}" and pending is not None:
            self.end_sites[owner.index] = pending
            stack.pop()
            return None
        wanted = "'}' to close the End Site" if pending is not None else "OFFSET in the End Site"
        raise self.tok.error(f"expected {wanted} of joint {self.names[owner.index]!r}, found {_show(word)}")

    def joint_token(self, word: str | None, top: _Joint, stack: list) -> None:
        """One token in the body of joint ``top``: OFFSET, CHANNELS, a child, an End Site or ``}``."""
        tok = self.tok
        key = None if word is None else word.upper()
        name = self.names[top.index]
        if key == "OFFSET" and not top.has_offset and not top.has_children:
            self.offsets[top.index] = self.offset(f"joint {name!r}")
            top.has_offset = True
        elif key == "CHANNELS" and not top.has_channels and not top.has_children:
            self.channels[top.index] = _channels(tok, name)
            top.has_channels = True
        elif key in ("JOINT", "END", "}") and not top.has_offset:
            raise tok.error(f"expected OFFSET for joint {name!r} (opened at line {top.line}), found {_show(word)}")
        elif key == "JOINT":
            top.has_children = True
            stack.append(self.new_joint("JOINT", top.index))
        elif key == "END":
            self.open_end_site(top, name)
            stack.append(None)
        elif key == "}":
            stack.pop()
        else:
            raise self.unexpected(word, top)

    def open_end_site(self, top: _Joint, name: str) -> None:
        """Read ``Site [name] {`` after ``End`` in joint ``top``."""
        tok = self.tok
        site = tok.take()
        if site is None or site.upper() != "SITE":
            raise tok.error(f"expected 'Site' after 'End' in joint {name!r}, found {_show(site)}")
        if top.has_end_site:
            raise tok.error(f"expected at most one End Site in joint {name!r}, found a second one")
        top.has_end_site = True
        top.has_children = True
        rest = tok.rest_of_line()  # some exporters name End Sites: skip up to '{'
        tok.skip(rest.index("{") if "{" in rest else len(rest))
        tok.expect("{", f" to open the End Site of joint {name!r}")

    def unexpected(self, word: str | None, top: _Joint) -> BVHError:
        """The error for a token that cannot come next in joint ``top``, with a hint at the likely cause."""
        key = None if word is None else word.upper()
        name = self.names[top.index]
        if word is not None and (word.lower() in _POSITION or word.lower() in _ROTATION):
            hint = f" (joint {name!r} declares CHANNELS {len(self.channels[top.index])}, but more channel names follow)"
        elif key in ("OFFSET", "CHANNELS"):
            hint = f" (a second or misplaced {word} in joint {name!r})"
        elif key == "MOTION" or word is None:
            hint = f" (unbalanced braces: joint {name!r} opened at line {top.line} is never closed)"
        else:
            hint = ""
        return self.tok.error(f"expected JOINT, End Site or '}}' in joint {name!r}, found {_show(word)}{hint}")


def _parse_joints(tok: _Tokens) -> _Hierarchy:
    """Parse ``HIERARCHY`` through the ``}`` that closes the root."""
    tok.expect("HIERARCHY", " at the start of the file")
    first = tok.take()
    if first is None or first.upper() != "ROOT":
        raise tok.error(f"expected 'ROOT' after HIERARCHY, found {_show(first)}")
    tree = _Hierarchy(tok)
    stack: list[_Joint | None] = [tree.new_joint("ROOT", -1)]  # None marks an open End Site block
    end_site_offset: tuple[float, float, float] | None = None
    while stack:
        top = stack[-1]
        word = tok.take()
        if top is None:
            end_site_offset = tree.end_site_token(word, stack, end_site_offset)
        else:
            tree.joint_token(word, top, stack)
    return tree


def _parse_frames_header(tok: _Tokens) -> tuple[int, int, float]:
    """Parse ``MOTION``, ``Frames: n`` and ``Frame Time: s``; returns (n, line of Frames:, s)."""
    word = tok.take()
    if word is None or word.upper() != "MOTION":
        if word == "}":
            hint = " (unbalanced braces: a '}' without a matching '{')"
        elif word is not None and word.upper() == "ROOT":
            hint = " (only one ROOT per file is supported)"
        else:
            hint = ""
        raise tok.error(f"expected 'MOTION' after the hierarchy, found {_show(word)}{hint}")
    if tok.rest_of_line():
        raise tok.error(f"expected nothing after MOTION on its line, found {_show(tok.rest_of_line()[0])}")
    word = tok.take()
    if word is None or word.upper() != "FRAMES:":
        raise tok.error(f"expected 'Frames:' after MOTION, found {_show(word)}")
    frames_line = tok.line
    value = tok.same_line_value("Frames:")
    if not _COUNT.fullmatch(value):
        raise tok.error(f"expected a non-negative whole number of frames after 'Frames:', found {_show(value)}")
    n_frames = int(value)
    word = tok.take()
    second = tok.take() if word is not None and word.upper() == "FRAME" else None
    if word is None or word.upper() != "FRAME" or second is None or second.upper() != "TIME:":
        found = word if second is None else f"{word} {second}"
        raise tok.error(f"expected 'Frame Time:' after the Frames: line, found {_show(found)}")
    value = tok.same_line_value("Frame Time:")
    ft = float(value) if _NUMBER.fullmatch(value) else math.nan
    if not (math.isfinite(ft) and ft > 0 and math.isfinite(1.0 / ft)):
        raise tok.error(f"expected a positive frame time in seconds after 'Frame Time:', found {_show(value)}")
    return n_frames, frames_line, ft


def _parse_hierarchy(tok: _Tokens):
    """Parse ``HIERARCHY`` up to and including the ``Frame Time:`` line."""
    tree = _parse_joints(tok)
    n_frames, frames_line, ft = _parse_frames_header(tok)
    return tree.names, tree.parents, tree.offsets, tree.channels, tree.end_sites, n_frames, frames_line, ft


# ---------------------------------------------------------------------------------- motion block
def _number_problem(token: str) -> str | None:
    """What is wrong with a numeric token, or None when it is a finite number."""
    if _NUMBER.fullmatch(token):
        return None if math.isfinite(float(token)) else "a finite number"
    try:
        value = float(token)
    except ValueError:
        return "a number"
    return "a number" if math.isfinite(value) else "a finite number"


def _scan_block(block: str, n_frames: int, n_channels: int, first_line: int, frames_line: int, source: str):
    """Slow line-by-line scan that reports the first bad line of a motion block."""
    lines = block.split("\n")
    frame = 0
    for k, line in enumerate(lines):
        number = first_line + k
        if not line.isascii():
            bad = next(ch for ch in line if not ch.isascii())
            raise BVHError(source, number, f"expected numbers on a frame line, found the character {bad!r}")
        values = [v.decode("ascii") for v in line.encode("ascii").split()]
        if not values:
            continue
        if len(values) != n_channels:
            raise BVHError(
                source,
                number,
                f"expected {n_channels} values on frame line {frame + 1} (one per channel), found {len(values)}",
            )
        for i, value in enumerate(values):
            problem = _number_problem(value)
            if problem:
                raise BVHError(
                    source, number, f"expected {problem} for value {i + 1} of frame {frame + 1}, found {_show(value)}"
                )
        if frame >= n_frames:
            raise BVHError(
                source,
                number,
                f"expected no more frame lines ('Frames: {n_frames}' at line {frames_line}), found an extra frame line",
            )
        frame += 1
    if frame < n_frames:
        raise BVHError(
            source,
            first_line + len(lines) - 1,
            f"expected {n_frames} frame lines ('Frames: {n_frames}' at line {frames_line}), found only {frame}: "
            "the motion block is truncated",
        )
    raise BVHError(source, first_line, "expected a valid motion block, found one that could not be converted")


def _read_block(
    block: str, n_frames: int, n_channels: int, first_line: int, frames_line: int, source: str
) -> np.ndarray:
    """The motion block as an array (T, C), checked with vectorised tests only."""

    def scan() -> np.ndarray:
        return _scan_block(block, n_frames, n_channels, first_line, frames_line, source)

    try:
        raw = block.encode("ascii")
    except UnicodeEncodeError:
        return scan()
    if raw.translate(None, _NUMERIC_BYTES):  # anything left is neither a digit, sign, dot, e nor space
        return scan()
    buf = np.frombuffer(raw, dtype=np.uint8)
    whitespace = buf <= 32  # the only bytes <= 32 that survived the check above are whitespace
    if n_channels == 0:
        if not whitespace.all():
            return scan()
        available = raw.count(b"\n") + 1
        if n_frames > available:
            raise BVHError(
                source,
                first_line + available - 1,
                f"expected {n_frames} (empty) frame lines ('Frames: {n_frames}' at line {frames_line}), "
                f"found only {available}: the motion block is truncated",
            )
        return np.zeros((n_frames, 0))
    starts = ~whitespace
    starts[1:] &= whitespace[:-1]
    newlines = np.flatnonzero(buf == 10)
    per_line = np.bincount(np.searchsorted(newlines, np.flatnonzero(starts)), minlength=newlines.size + 1)
    per_line = per_line[per_line > 0]
    if per_line.size != n_frames or np.any(per_line != n_channels):
        return scan()
    try:
        values = np.array(raw.split(), dtype=np.float64)
    except (ValueError, OverflowError):
        return scan()
    if values.size != n_frames * n_channels or not np.isfinite(values).all():
        return scan()
    return values.reshape(n_frames, n_channels)


# ---------------------------------------------------------------------------------- rotations
def _axis_quats(angles: np.ndarray, axes: str) -> np.ndarray:
    """``R = R_axes[0] @ R_axes[1] @ ...`` for 0 to 3 axes; angles (..., k) in radians."""
    if len(axes) == 3:
        return quat.from_euler(angles, axes)
    q = np.zeros(angles.shape[:-1] + (4,))
    q[..., 0] = 1.0
    for k, axis in enumerate(axes):
        step = np.zeros(angles.shape[:-1] + (4,))
        step[..., 0] = np.cos(0.5 * angles[..., k])
        step[..., 1 + _AXIS_INDEX[axis]] = np.sin(0.5 * angles[..., k])
        q = quat.mul(q, step)
    return q


def _euler_into(out: np.ndarray, degrees: np.ndarray, axes: str) -> None:
    """``out[...] = R_i(a) R_j(b) R_k(c)`` as quaternions (w, x, y, z) for three distinct axes ``ijk``.

    The product of the three half-angle quaternions written out (what ``quat.from_euler``
    computes, without its intermediate arrays); ``s`` is +1 for a cyclic order (xyz, yzx,
    zxy) and -1 otherwise. ``degrees`` (..., 3), ``out`` (..., 4). Angles of a full turn or
    more are wrapped first, so the result may be ``-q`` of ``quat.from_euler``'s (same rotation).
    """
    i, j, k = (_AXIS_INDEX[a] for a in axes)
    s = 1.0 if (j - i) % 3 == 1 else -1.0
    radians = np.radians(degrees)
    if np.abs(radians).max(initial=0.0) >= 2.0 * np.pi:  # one turn or more: wrap (q may flip to -q)
        radians = np.remainder(radians + np.pi, 2.0 * np.pi) - np.pi
    # cos and sin of the half angle from t = tan(angle / 4): one trig call instead of two
    t = np.tan(radians * 0.25)
    t2 = t * t
    inv = 1.0 / (1.0 + t2)
    c, n = (1.0 - t2) * inv, 2.0 * t * inv
    ca, cb, cc = c[..., 0], c[..., 1], c[..., 2]
    sa, sb, sc = n[..., 0], n[..., 1], n[..., 2]
    cbc, sbs, sbc, cbs = cb * cc, sb * sc, sb * cc, cb * sc
    out[..., 0] = ca * cbc - s * sa * sbs
    out[..., 1 + i] = sa * cbc + s * ca * sbs
    out[..., 1 + j] = ca * sbc - s * sa * cbs
    out[..., 1 + k] = ca * cbs + s * sa * sbc


def _split_axes(q: np.ndarray, axes: str) -> np.ndarray:
    """Angles (..., k) in radians with ``_axis_quats(angles, axes) == ±q`` when possible.

    For fewer than three axes the rotation may not be expressible; the caller checks.
    """
    if len(axes) == 3:
        return quat.to_euler(q, axes)
    if len(axes) == 0:
        return np.zeros(q.shape[:-1] + (0,))
    i = _AXIS_INDEX[axes[0]]
    if len(axes) == 1:
        return (2.0 * np.arctan2(q[..., 1 + i], q[..., 0]))[..., None]
    # R = R_i(a) R_j(b): column j of R is R_i(a) e_j, which lies in the (j, k) plane
    j = _AXIS_INDEX[axes[1]]
    k = 3 - i - j
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    column = quat.rotate(q, np.eye(3)[j])
    a = np.arctan2(sign * column[..., k], column[..., j])
    rest = quat.mul(quat.conj(_axis_quats(a[..., None], axes[0])), q)
    b = 2.0 * np.arctan2(rest[..., 1 + j], rest[..., 0])
    return np.stack([a, b], axis=-1)


def _rotation_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (radians) between unit quaternions, accurate near zero (unlike an arccos of the dot)."""
    chord = np.minimum(np.linalg.norm(a - b, axis=-1), np.linalg.norm(a + b, axis=-1))
    return 4.0 * np.arcsin(np.clip(0.5 * chord, 0.0, 1.0))


# ---------------------------------------------------------------------------------- reading
def loads(text: str | bytes, scale: float = DEFAULT_SCALE, source: str = "<string>", name: str = "") -> Motion:
    """Parse BVH text into a :class:`~motionlab.core.motion.Motion`.

    Parameters
    ----------
    text : str or bytes   the file contents (bytes must be UTF-8)
    scale : float         factor from file length units to the package's (0.01: cm -> m)
    source : str          what error messages call the input
    name : str            the Motion's name

    Returns
    -------
    Motion
        ``skeleton.channels`` holds each joint's channel names as written in the file and
        ``skeleton.end_sites`` the End Site offsets (scaled); ``fps = 1 / Frame Time``
        (:func:`frame_time` gives the frame time back); ``local_pos`` (T, J, 3) is set only when
        a non-root joint has position channels.

    Raises
    ------
    BVHError
        For any malformed input, naming ``source``, the line and what was expected.
    """
    if isinstance(text, (bytes, bytearray, memoryview)):
        data = bytes(text)
    elif isinstance(text, str):
        data = text.encode("utf-8", "surrogatepass")  # a lone surrogate fails as bad UTF-8 below
    else:
        raise TypeError(f"expected BVH text as str or bytes, got {type(text).__name__}")
    return _read(io.BytesIO(data), len(data), scale, source, name)


def load(path: str | os.PathLike, scale: float = DEFAULT_SCALE, name: str | None = None) -> Motion:
    """Read a BVH file; see :func:`loads` for what the Motion holds.

    The file is streamed: the motion block is converted :data:`CHUNK` bytes at a time straight
    into the frame array, so memory stays near the size of the result (about the file's size)
    instead of several times the text.

    Parameters
    ----------
    path : str or PathLike
    scale : float      file length units -> metres (default 0.01, for centimetres)
    name : str, optional   the Motion's name (default: the file stem)

    Raises
    ------
    BVHError
        The file is malformed (the message names the file and line).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        return _read(f, size, scale, str(path), path.stem if name is None else name)


CHUNK = 1 << 20
"""Most bytes of motion text converted per step while streaming (1 MiB); a file smaller than
16 MiB uses 1/16 of its size (at least 64 KiB), so the step's temporary arrays stay small
beside the result for small files too."""

_HEADER_START = 1 << 16  # bytes read first for the header; doubled while the header goes on


def _decode(data: bytes, source: str, first_line: int = 1) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = first_line + data.count(b"\n", 0, exc.start)
        raise BVHError(source, line, f"expected UTF-8 text, found the byte {data[exc.start]:#04x}") from None


def header(path: str | os.PathLike) -> tuple[int, float]:
    """``(frames, fps)`` of a BVH file from its header alone (``Frames:`` and ``1 / Frame Time:``),
    without reading the motion block: what :func:`load` gives as ``num_frames`` and ``fps`` when
    the file is well formed. Raises :class:`BVHError` (naming the file and line) for a malformed
    header, ``OSError`` when the file cannot be read."""
    with open(path, "rb") as f:
        parsed = _read_header(f, os.fstat(f.fileno()).st_size, str(path))[0]
    return parsed[5], 1.0 / parsed[7]


def _read_header(f, size: int, source: str):
    """The parsed header of a binary stream of ``size`` bytes, the tokens and bytes read so far,
    the byte-order mark's length and whether lines end in CR alone."""
    head = f.read(min(size, _HEADER_START))
    if head.startswith(b"glTF"):
        raise BVHError(source, 1, "a binary glTF (.glb) file, not BVH text; motionlab reads motion from BVH")
    bom = 3 if head.startswith(b"\xef\xbb\xbf") else 0
    head, size = head[bom:], size - bom
    # Old Mac files end lines with CR alone: read every CR as a line end when the start has no LF
    cr_only = b"\r" in head and b"\n" not in head
    while True:
        if cr_only:
            head = head.replace(b"\r", b"\n")
        complete = len(head) >= size
        cut = len(head) if complete else head.rfind(b"\n") + 1
        tok = _Tokens(_decode(head[:cut], source), source, complete=complete)
        try:
            header = _parse_hierarchy(tok)
            break
        except _NeedMore:
            more = f.read(max(len(head), _HEADER_START))
            head += more
    return header, tok, head, bom, cr_only


def _read(f, size: int, scale: float, source: str, name: str) -> Motion:
    """Parse a binary stream of ``size`` bytes (header token by token, motion block in chunks)."""
    scale = _check_scale(scale)
    header, tok, head, bom, cr_only = _read_header(f, size, source)
    names, parents, offsets, channels, end_sites, n_frames, frames_line, ft = header
    if tok.pos <= len(tok.text):
        first_line = tok.line + 1
        start = len(tok.text[: tok.pos].encode("utf-8"))
    else:  # the file ends on the Frame Time line: a missing block is reported there, not past the end
        first_line = tok.line
        start = len(head)
    n_channels = sum(len(c) for c in channels)
    values = _read_stream(f, head[start:], bom + start, n_frames, n_channels, first_line, frames_line, source, cr_only)
    return _to_motion(names, parents, offsets, channels, end_sites, values, ft, scale, name)


def _chunk_values(raw: bytes, n_channels: int) -> np.ndarray | None:
    """Frame lines of one chunk (complete lines) as an array (k, C), or None if anything is off."""
    if raw.translate(None, _NUMERIC_BYTES):  # anything left is neither a digit, sign, dot, e nor space
        return None
    buf = np.frombuffer(raw, dtype=np.uint8)
    whitespace = buf <= 32  # the only bytes <= 32 that survived the check above are whitespace
    starts = ~whitespace
    starts[1:] &= whitespace[:-1]
    newlines = np.flatnonzero(buf == 10)
    first = np.flatnonzero(starts)  # first byte of each number
    # numbers per line: how many start before each line end (a search per line, not per number)
    before = np.searchsorted(first, np.append(newlines, buf.size))
    per_line = np.diff(before, prepend=0)
    per_line = per_line[per_line > 0]
    if np.any(per_line != n_channels):
        return None
    values = _fixed_decimals(raw, buf, whitespace, first)
    if values is None:
        try:
            values = np.fromstring(raw, dtype=np.float64, sep=" ")  # C parser; stops (ValueError) at bad text
        except ValueError:
            return None
    if values.size != per_line.size * n_channels or not np.isfinite(values).all():
        return None
    return values.reshape(per_line.size, n_channels)


_EXACT = 2**53  # integers below this, divided by 10**k (k <= 22), give the correctly rounded float


def _fixed_decimals(raw: bytes, buf: np.ndarray, whitespace: np.ndarray, first: np.ndarray) -> np.ndarray | None:
    """Fast path for numbers written with one fixed count of decimals (``-12.345678``), or None.

    Most BVH writers print every value with the same number of decimals ``k``. Then each
    number is an integer (its digits without the dot) divided by ``10**k``: the dots are
    dropped in one bytes call and the integers are read by NumPy's C integer parser, about five
    times faster than parsing floats. With fewer than 16 digits the division is exact to the
    last bit (the same float ``float(text)`` gives). Anything else returns None.
    """
    dots = np.flatnonzero(buf == 46)
    if dots.size != first.size or first.size == 0:
        return None
    ends = ~whitespace
    ends[:-1] &= whitespace[1:]
    last = np.flatnonzero(ends)  # last byte of each number
    decimals = last - dots
    k = int(decimals[0])
    if np.any(decimals != k) or np.any(dots < first) or k > 22:  # one dot inside each number, k decimals
        return None
    lead = buf[first]
    signed = (lead == 45) | (lead == 43)
    if np.any(last - first + 1 - signed < 2):
        return None  # a number without digits ('-.', '.')
    # Now every number has exactly one dot and a digit or letter besides sign and dot. A sign or
    # letter inside a number makes the integer parser fail or read one number too many: the
    # count check below catches both (no number can read as zero numbers to make up for it).
    try:
        whole = np.fromstring(raw.translate(None, b"."), dtype=np.int64, sep=" ")
    except ValueError:
        return None
    if whole.size != first.size or np.any(np.abs(whole) >= _EXACT):
        return None
    return whole / 10.0**k


def _pieces(f, head: bytes, cr_only: bool, size: int):
    """The rest of ``f`` after ``head`` in pieces of about :data:`CHUNK` bytes that end at line ends."""
    chunk = min(CHUNK, max(size // 16, 1 << 16))
    if not cr_only:  # readlines stops at the first line end after `chunk` bytes
        yield head + b"".join(f.readlines(chunk))
        while lines := f.readlines(chunk):
            yield b"".join(lines)
        return
    pending = head.replace(b"\r", b"\n")
    while more := f.read(chunk):
        pending += more.replace(b"\r", b"\n")
        cut = pending.rfind(b"\n") + 1
        if cut:
            yield pending[:cut]
            pending = pending[cut:]
    yield pending


def _read_stream(f, head: bytes, offset: int, n_frames, n_channels, first_line, frames_line, source, cr_only):
    """The motion block, starting at byte ``offset`` of ``f`` (``head``: its part read already), as (T, C)."""
    size = f.seek(0, io.SEEK_END) - offset  # bytes in the block
    f.seek(offset + len(head))

    def slow() -> np.ndarray:  # exact error with a line number: read the block again, whole
        f.seek(offset)
        block = f.read()
        if cr_only:
            block = block.replace(b"\r", b"\n")
        text = _decode(block, source, first_line)
        return _read_block(text, n_frames, n_channels, first_line, frames_line, source)

    # every frame line needs C numbers and C whitespace bytes: a file too short for the count is truncated
    if n_channels == 0 or n_frames > size // (2 * n_channels) + 1:
        return slow()
    values = np.empty((n_frames, n_channels))
    row = 0
    for piece in _pieces(f, head, cr_only, size):
        part = _chunk_values(piece, n_channels)
        if part is None or row + len(part) > n_frames:
            return slow()
        values[row : row + len(part)] = part
        row += len(part)
    if row != n_frames:
        return slow()
    return values


_ROTATIONS_PER_STEP = 1 << 14  # joint-frames converted to quaternions at a time (bounds the temporaries)


def _to_motion(names, parents, offsets, channels, end_sites, values, ft, scale, name) -> Motion:
    n_frames, n_joints = values.shape[0], len(names)
    offsets = np.asarray(offsets, dtype=np.float64) * scale
    local_rot = np.zeros((n_frames, n_joints, 4))
    local_rot[..., 0] = 1.0
    root_pos = np.broadcast_to(offsets[0], (n_frames, 3)).copy()
    # per-frame translations only when a non-root joint has position channels
    moving = any("position" in ch.lower() for layout in channels[1:] for ch in layout)
    translations = np.broadcast_to(offsets, (n_frames, n_joints, 3)).copy() if moving else None
    groups: dict[str, tuple[list[int], list[list[int]]]] = {}
    column = 0
    for j, layout in enumerate(channels):
        rot_cols, axes = [], ""
        for ch in layout:
            key = ch.lower()
            if key in _POSITION:
                target = root_pos if j == 0 else translations[:, j]
                target[:, _POSITION[key]] = values[:, column] * scale
            else:
                axes += _ROTATION[key]
                rot_cols.append(column)
            column += 1
        if axes:
            joints, cols = groups.setdefault(axes, ([], []))
            joints.append(j)
            cols.append(rot_cols)
    for axes, (joints, cols) in groups.items():
        cols = np.asarray(cols)
        contiguous = joints == list(range(joints[0], joints[-1] + 1))
        # a small file converts in smaller steps, so temporaries stay small beside the result
        per_step = min(_ROTATIONS_PER_STEP, max(1024, n_frames * n_joints // 16))
        step = max(1, per_step // len(joints))
        for t0 in range(0, n_frames, step):
            t1 = min(t0 + step, n_frames)
            if len(axes) == 3 and contiguous:  # straight into the result
                _euler_into(local_rot[t0:t1, joints[0] : joints[-1] + 1], values[t0:t1, cols], axes)
            elif len(axes) == 3:
                q = np.empty((t1 - t0, len(joints), 4))
                _euler_into(q, values[t0:t1, cols], axes)
                local_rot[t0:t1, joints] = q
            else:
                local_rot[t0:t1, joints] = _axis_quats(np.deg2rad(values[t0:t1, cols]), axes)
    if translations is not None:
        translations[:, 0] = root_pos
    skeleton = Skeleton(
        tuple(names),
        np.asarray(parents),
        offsets,
        {j: np.asarray(o) * scale for j, o in end_sites.items()},
        tuple(channels),
    )
    return Motion(skeleton, local_rot, root_pos, 1.0 / ft, translations, name)


# ---------------------------------------------------------------------------------- writing
def _check_scale(scale) -> float:
    try:
        scale = float(scale)
    except (TypeError, ValueError):
        raise ValueError(f"expected scale as a positive number, got {scale!r}") from None
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"expected scale as a positive number, got {scale}")
    return scale


def _format_frame_time(fps: float) -> str:
    """Decimal frame time ``s`` such that reading it back gives ``fps = 1 / float(s)``.

    The shortest ``s`` that gives ``fps`` exactly (a file's own ``Frame Time:`` digits for a
    loaded motion); when no float inverts exactly to ``fps`` (e.g. 93), the one that comes closest.
    """
    ft = 1.0 / fps
    for digits in range(1, 18):
        text = f"{ft:.{digits}g}"
        if 1.0 / float(text) == fps:
            return text
    candidates = [ft]
    for direction in (0.0, math.inf):
        value = ft
        for _ in range(4):
            value = math.nextafter(value, direction)
            candidates.append(value)
    best = min(candidates, key=lambda c: abs(1.0 / c - fps))
    return repr(best)


def frame_time(motion_or_fps: Motion | float) -> float:
    """The frame time (seconds) a BVH file of this motion states, ``1 / fps``.

    For a motion loaded from BVH this is exactly the file's ``Frame Time:`` value (e.g.
    0.016667 rather than 1/60); :func:`save` writes the same digits back.

    Raises
    ------
    ValueError when the motion's fps is not a finite positive number.
    """
    fps = motion_or_fps.fps if isinstance(motion_or_fps, Motion) else float(motion_or_fps)
    if not (math.isfinite(fps) and fps > 0):
        raise ValueError(f"expected a positive fps, got {fps}")
    return float(_format_frame_time(fps))


def _check_layout(skeleton: Skeleton, translations: np.ndarray, pos_tol: float) -> tuple[tuple[str, ...], ...]:
    """Each joint's channel names for writing (``skeleton.channels`` or the default layout)."""
    if skeleton.channels is not None:
        layouts = []
        for j, layout in enumerate(skeleton.channels):
            keys = [str(c).lower() for c in layout]
            if any(k not in _POSITION and k not in _ROTATION for k in keys) or len(set(keys)) != len(keys):
                raise ValueError(
                    f"joint {skeleton.names[j]!r} has channel layout {layout}; expected distinct names from {CHANNEL_NAMES}"
                )
            layouts.append(_three_rotations(tuple(layout)))
        return tuple(layouts)
    layouts = [_ROOT_LAYOUT]
    for j in range(1, skeleton.num_joints):
        moved = np.abs(translations[:, j] - skeleton.offsets[j]).max(initial=0.0) > pos_tol
        layouts.append(_ROOT_LAYOUT if moved else _JOINT_LAYOUT)
    return tuple(layouts)


def _three_rotations(layout: tuple[str, ...]) -> tuple[str, ...]:
    """``layout`` with exactly three rotation channels, as Blender's importer needs.

    Missing rotation axes follow the joint's last rotation channel (a joint without any gets
    ``Zrotation Yrotation Xrotation`` at the end); their angles are zero for motion that the
    original channels could express, so nothing else changes.
    """
    rotations = [c for c in layout if c.lower() in _ROTATION]
    if len(rotations) == 3:
        return layout
    have = {c[0].lower() for c in rotations}
    missing = [f"{a}rotation" for a in ("Z", "Y", "X") if a.lower() not in have]
    if not rotations:
        return layout + tuple(missing)
    last = max(i for i, c in enumerate(layout) if c.lower() in _ROTATION)
    return layout[: last + 1] + tuple(missing) + layout[last + 1 :]


def _check_name(name: str) -> None:
    if not name or " ".join(name.split()) != name or "{" in name or "}" in name:
        raise ValueError(
            f"cannot write joint name {name!r} to BVH: expected non-empty text without braces, "
            "line breaks or repeated/leading/trailing whitespace"
        )


def _no_negative_zero(values: np.ndarray, precision: int) -> np.ndarray:
    """Values that would print as ``-0.000…`` set to 0, so a rewrite gives the same text."""
    values = np.array(values, dtype=np.float64)
    values[np.abs(values) < 0.5 * 10.0**-precision] = 0.0
    return values


def _fmt(values, precision: int) -> str:
    return " ".join(f"{v:.{precision}f}" for v in _no_negative_zero(values, precision))


def _check_write_args(motion: Motion, scale, precision) -> tuple[float, int]:
    """``(scale, precision)`` checked for :func:`dumps`, after checking the motion can be named in BVH."""
    if not isinstance(motion, Motion):
        raise TypeError(f"expected a Motion, got {type(motion).__name__}")
    if motion.num_frames == 0:
        raise ValueError(
            f"cannot write motion {motion.name!r} with 0 frames as BVH: Blender and most importers need at least one frame"
        )
    scale = 1.0 / DEFAULT_SCALE if scale is None else _check_scale(scale)
    if isinstance(precision, bool) or not isinstance(precision, (int, np.integer)) or not 0 <= precision <= 17:
        raise ValueError(f"expected precision as a whole number of decimals from 0 to 17, got {precision!r}")
    for name in motion.skeleton.names:
        _check_name(name)
    return scale, int(precision)


def _finite_channels(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Normalised local rotations (T, J, 4) and translations (T, J, 3); raises on a non-finite value."""
    local_rot = motion.local_rot
    translations = motion.translations()
    for label, array in (("local_rot", local_rot), ("positions", translations)):
        bad = np.argwhere(~np.isfinite(array))
        if bad.size:
            t, j = int(bad[0, 0]), int(bad[0, 1])
            raise ValueError(
                f"cannot write BVH: {label} of joint {motion.skeleton.names[j]!r} at frame {t} is not finite"
            )
    return quat.normalize(local_rot, "local_rot"), translations


def _rotation_angles(local_rot: np.ndarray, layouts, names, precision: int) -> dict[int, np.ndarray]:
    """Each joint's rotation-channel angles (T, k) in degrees, in its layout's order.

    Joints sharing an axis order are split together; raises if a joint rotates outside its channels.
    """
    groups: dict[str, list[int]] = {}
    for j, layout in enumerate(layouts):
        axes = "".join(_ROTATION[c.lower()] for c in layout if c.lower() in _ROTATION)
        groups.setdefault(axes, []).append(j)
    angles: dict[int, np.ndarray] = {}
    for axes, joints in groups.items():
        q = local_rot[:, joints]
        split = _split_axes(q, axes)  # (T, n, k)
        error = _rotation_gap(_axis_quats(split, axes), q)
        if error.size and error.max() > _ROT_TOL:
            t, n = np.unravel_index(np.argmax(error), error.shape)
            have = " ".join(c for c in layouts[joints[n]] if c.lower() in _ROTATION) or "no rotation channels"
            raise ValueError(
                f"cannot write joint {names[joints[n]]!r}: its channels have {have}, but at frame {t} it rotates "
                f"{np.degrees(error[t, n]):.4g} degrees outside them; give it rotation channels in skeleton.channels"
            )
        # frame 0's angles lie in (-180, 180]: -180 and 180 (the same turn) must not flip between writes
        degrees = np.degrees(split)
        degrees[degrees <= -180.0 + 0.5 * 10.0**-precision] += 360.0
        degrees = _continuous(degrees, min(1.0, 50.0 * 10.0**-precision))  # far above the digits' rounding
        for n, j in enumerate(joints):
            angles[j] = degrees[:, n]
    return angles


def _continuous(degrees: np.ndarray, margin: float) -> np.ndarray:
    """Euler angles (T, n, k), degrees, each frame's own, as curves without jumps.

    With three axes a rotation has two triples, ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)``;
    each frame takes the other triple where it lies nearer the frame before's choice by more than
    ``margin`` (whether a frame swaps is the parity of the swaps up to it, so no loop over frames).
    Then whole turns are added where a channel steps by more than 180 + ``margin`` degrees. Frame
    0 keeps its values; every frame keeps its rotation. The margins keep a file read and written
    again on the same choices where a tie (a step of exactly 180) meets the printed digits' rounding.
    """
    if len(degrees) < 2:
        return degrees
    if degrees.shape[-1] == 3:
        other = degrees + np.array([180.0, 0.0, 180.0])
        other[..., 1] = 180.0 - degrees[..., 1]

        def apart(x, y):  # (T-1, n): summed turn between two triples, each channel modulo 360
            return np.abs((x - y + 180.0) % 360.0 - 180.0).sum(-1)

        swap = apart(other[1:], degrees[:-1]) + margin < apart(degrees[1:], degrees[:-1])
        odd = np.concatenate([np.zeros_like(swap[:1]), np.cumsum(swap, axis=0) % 2 == 1])
        degrees = np.where(odd[..., None], other, degrees)
    step = np.diff(degrees, axis=0)
    turns = -np.floor((step + 180.0 - margin) / 360.0)  # 0 for steps in [-180 + margin, 180 + margin)
    return degrees + 360.0 * np.concatenate([np.zeros_like(turns[:1]), np.cumsum(turns, axis=0)])


def _channel_columns(translations, angles, layouts, skeleton: Skeleton, scale: float, pos_tol: float) -> list:
    """One (T,) column per channel, in joint-index order, positions in file units.

    Raises if a joint's translation leaves its offset along an axis it has no position channel for.
    """
    names, rest = skeleton.names, skeleton.offsets
    columns: list[np.ndarray] = []
    for j, layout in enumerate(layouts):
        keys = [c.lower() for c in layout]
        for axis in range(3):
            if ("xposition", "yposition", "zposition")[axis] not in keys:
                drift = np.abs(translations[:, j, axis] - rest[j, axis]).max(initial=0.0)
                if drift > pos_tol:
                    what = "root position" if j == 0 else "local_pos"
                    raise ValueError(
                        f"cannot write joint {names[j]!r}: its {what} moves {drift:.4g} m along {'xyz'[axis]} "
                        f"away from its offset, but its channels {tuple(layout)} have no {'XYZ'[axis]}position"
                    )
        rot_index = 0
        for key in keys:
            if key in _POSITION:
                columns.append(translations[:, j, _POSITION[key]] * scale)
            else:
                columns.append(angles[j][:, rot_index])
                rot_index += 1
    return columns


def _hierarchy_lines(skeleton: Skeleton, layouts, scale: float, precision: int) -> tuple[list[str], list[int]]:
    """The ``HIERARCHY`` block's lines, and the depth-first joint order it lists (children by index)."""
    names = skeleton.names
    lines = ["HIERARCHY"]
    children: list[list[int]] = [[] for _ in names]
    for j in range(1, len(names)):
        children[int(skeleton.parents[j])].append(j)
    order: list[int] = []
    stack: list[tuple[int, int]] = [(0, 0)]  # (joint, depth); a negative joint closes joint ~j
    while stack:
        j, depth = stack.pop()
        pad = "\t" * depth
        if j < 0:
            j = ~j
            if j in skeleton.end_sites:
                inner = pad + "\t"
                end = skeleton.end_sites[j] * scale
                lines += [f"{inner}End Site", f"{inner}{{", f"{inner}\tOFFSET {_fmt(end, precision)}", f"{inner}}}"]
            lines.append(f"{pad}}}")
            continue
        order.append(j)
        layout = layouts[j]
        lines += [
            f"{pad}{'ROOT' if j == 0 else 'JOINT'} {names[j]}",
            f"{pad}{{",
            f"{pad}\tOFFSET {_fmt(skeleton.offsets[j] * scale, precision)}",
            f"{pad}\tCHANNELS {len(layout)}{''.join(' ' + c for c in layout)}",
        ]
        stack.append((~j, depth))
        stack.extend((c, depth + 1) for c in reversed(children[j]))
    return lines, order


def _frame_lines(columns, layouts, order: list[int], n_frames: int, precision: int) -> str:
    """The frame rows: ``columns`` (joint-index order) permuted to the file's depth-first ``order``."""
    starts = np.cumsum([0] + [len(layout) for layout in layouts])
    perm = [c for j in order for c in range(starts[j], starts[j + 1])]
    data = np.stack([columns[c] for c in perm], axis=1) if perm else np.zeros((n_frames, 0))
    data = _no_negative_zero(data, precision)
    if n_frames == 0:
        return ""
    if data.shape[1] == 0:
        return "\n" * n_frames
    row = " ".join([f"%.{precision}f"] * data.shape[1])
    return ("\n".join([row] * n_frames) % tuple(data.ravel().tolist())) + "\n"


def dumps(motion: Motion, scale: float | None = None, precision: int = 6) -> str:
    """BVH text of a motion.

    Parameters
    ----------
    motion : Motion
    scale : float, optional   metres -> file units; default ``1 / DEFAULT_SCALE`` (100, centimetres)
    precision : int           decimals written for offsets, positions and angles (degrees)

    Returns
    -------
    str
        Joints are written depth-first (children in index order) with ``skeleton.channels``
        when set, else positions + ``Zrotation Yrotation Xrotation`` for the root (and for
        non-root joints whose ``local_pos`` moves), ``Zrotation Yrotation Xrotation`` for the
        others. Every joint gets exactly three rotation channels, as Blender's importer needs:
        a layout with fewer is completed by the missing axes (zero angles where the original
        axes expressed the motion). ``Frame Time:`` has the fewest digits that give ``fps`` back
        exactly.

    Raises
    ------
    ValueError
        No frames (Blender cannot import a 0-frame file), non-finite values, names BVH cannot hold, or a joint whose channel layout cannot
        express its motion (rotation about an axis it has no channel for, or a translation
        away from its offset without position channels); the message names the joint.
    """
    scale, precision = _check_write_args(motion, scale, precision)
    skeleton = motion.skeleton
    local_rot, translations = _finite_channels(motion)
    # a length difference below half the last printed digit is invisible in the file
    pos_tol = 0.5 * 10.0**-precision / scale
    layouts = _check_layout(skeleton, translations, pos_tol)
    angles = _rotation_angles(local_rot, layouts, skeleton.names, precision)
    columns = _channel_columns(translations, angles, layouts, skeleton, scale, pos_tol)
    lines, order = _hierarchy_lines(skeleton, layouts, scale, precision)
    lines += ["MOTION", f"Frames: {motion.num_frames}", f"Frame Time: {_format_frame_time(motion.fps)}"]
    header = "\n".join(lines) + "\n"
    return header + _frame_lines(columns, layouts, order, motion.num_frames, precision)


def save(
    path: str | os.PathLike,
    motion: Motion,
    scale: float | None = None,
    precision: int = 6,
    overwrite: bool = False,
) -> Path:
    """Write a motion as a BVH file (see :func:`dumps` for the layout) and return ``Path(path)``.

    The text is built first and written through :func:`~motionlab.core.files.atomic_write`,
    which never leaves a partial file.

    Parameters
    ----------
    path : str or PathLike
    motion : Motion
    scale : float, optional   metres -> file units (default 100: centimetres)
    precision : int           decimals written
    overwrite : bool          replace an existing file (default: refuse)

    Raises
    ------
    ValueError
        the motion cannot be written (see :func:`dumps`).
    OSError
        as :func:`motionlab.core.files.check_output` says for ``path``.
    """
    text = dumps(motion, scale=scale, precision=precision)
    return files.atomic_write(path, lambda f: f.write(text), overwrite=overwrite, what="BVH file")
