"""Property-based fuzzing of the BVH reader and writer (Hypothesis).

Three generators:

* ``bvh_files``: BVH text written here, independently of ``bvh.dumps``: random trees (chains up
  to 12 deep, any branching), any 0-6 channels in any order, names with punctuation, keywords and
  non-ASCII letters, numbers in many spellings (``1``, ``-0.5``, ``+.5``, ``1e-3``, ``12.``), line
  ends LF / CRLF / CR, a BOM, tabs, blank lines;
* the writer's own output for those files;
* ``mutated``: those files with tokens deleted, doubled or replaced, lines dropped or doubled,
  bytes inserted, or the text cut short.

Properties: a generated file loads to exactly the numbers written in it; what loads is written
by ``save`` in a form that loads back to the same motion and is written again byte for byte the
same (``dumps`` is idempotent); a mutated file either loads (and then round-trips the same way)
or raises ``BVHError`` naming the line; no other exception, ever. The chunk size of the streamed
reader is drawn too (7 bytes to 1 MiB), so chunk borders fall everywhere.

Examples per test: 300 (CI), or ``MOTIONLAB_FUZZ=thorough`` for 5000 (by hand, a few minutes),
or ``MOTIONLAB_FUZZ=<number>``.
"""

from __future__ import annotations

import os
import re
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import motionlab.core.bvh as bvh_module
from motionlab.core import bvh, quat
from motionlab.core.bvh import BVHError

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

_LEVEL = os.environ.get("MOTIONLAB_FUZZ", "ci").strip().lower()
EXAMPLES = 5000 if _LEVEL == "thorough" else int(_LEVEL) if _LEVEL.isdigit() else 300
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

POSITION = ("Xposition", "Yposition", "Zposition")
ROTATION = ("Xrotation", "Yrotation", "Zrotation")
NAME_CHARS = "abcXYZ019_:-.|é日"
KEYWORDS = ["End", "Site", "JOINT", "ROOT", "MOTION", "OFFSET", "CHANNELS", "Frames:", "Xrotation"]


@contextmanager
def chunk_size(n: int):
    old = bvh_module.CHUNK
    bvh_module.CHUNK = n
    try:
        yield
    finally:
        bvh_module.CHUNK = old


# ------------------------------------------------------------------------------ generators
def _number_text(value: float, style: int) -> str:
    """One of several spellings readers meet in the wild."""
    if style == 0:
        return f"{value:.6f}"
    if style == 1:
        return f"{value:g}"
    if style == 2:
        return f"{value:.4e}"
    if style == 3:
        return f"{round(value)}"
    if style == 4:
        text = f"{value:.3f}"
        return text.replace("0.", ".", 1) if text.startswith("0.") else "+" + text if value >= 0 else text
    return f"{value:.0f}."  # "12."


@st.composite
def bvh_files(draw):
    """(text bytes, expected) where expected holds the tree and every number as written."""
    n_joints = draw(st.integers(1, 12))
    parents, path = [-1], [0]
    for j in range(1, n_joints):
        depth = draw(st.integers(0, len(path) - 1))
        path = path[: depth + 1]
        parents.append(path[-1])
        path.append(j)
    name_text = st.text(NAME_CHARS, min_size=1, max_size=5) | st.sampled_from(KEYWORDS)
    words = draw(st.lists(st.lists(name_text, min_size=1, max_size=2), min_size=n_joints, max_size=n_joints))
    names = [" ".join(w) for w in words]
    if len(set(names)) != n_joints:
        names = [f"{n}_{j}" for j, n in enumerate(names)]
    layouts = []
    for _ in range(n_joints):
        chosen = draw(st.lists(st.sampled_from(POSITION + ROTATION), unique=True, max_size=6))
        layouts.append(tuple(chosen))
    n_frames = draw(st.integers(1, 5))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    style = draw(st.integers(0, 5))
    n_channels = sum(len(c) for c in layouts)

    def numbers(size, scale):
        values = rng.uniform(-scale, scale, size=size)
        texts = [_number_text(v, style) for v in values.ravel()]
        return np.array([float(t) for t in texts]).reshape(size), texts

    offsets, offset_text = numbers((n_joints, 3), 50.0)
    ends = {j: numbers(3, 10.0) for j in range(n_joints) if j not in parents and rng.random() < 0.7}
    frames, frame_text = numbers((n_frames, n_channels), 180.0)
    indent = draw(st.sampled_from(["\t", "  ", ""]))
    children = [[c for c in range(n_joints) if parents[c] == j] for j in range(n_joints)]
    lines, order = ["HIERARCHY"], []

    def write(j, depth):
        pad = indent * depth
        order.append(j)
        lines.append(f"{pad}{'ROOT' if j == 0 else 'JOINT'} {names[j]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}{indent}OFFSET {' '.join(offset_text[3 * j : 3 * j + 3])}")
        lines.append(f"{pad}{indent}CHANNELS {len(layouts[j])}{''.join(' ' + c for c in layouts[j])}")
        for c in children[j]:
            write(c, depth + 1)
        if j in ends:
            lines.extend([f"{pad}{indent}End Site", f"{pad}{indent}{{"])
            lines.append(f"{pad}{indent * 2}OFFSET {' '.join(ends[j][1])}")
            lines.append(f"{pad}{indent}}}")
        lines.append(f"{pad}}}")

    write(0, 0)
    lines += ["MOTION", f"Frames: {n_frames}", "Frame Time: " + draw(st.sampled_from(["0.0333333", "0.008333", "1"]))]
    for t in range(n_frames):
        lines.append(" ".join(frame_text[t * n_channels : (t + 1) * n_channels]))
        if draw(st.integers(0, 9)) == 0:
            lines.append("")  # a blank line between frames
    newline = draw(st.sampled_from(["\n", "\n", "\r\n", "\r"]))
    text = newline.join(lines) + draw(st.sampled_from([newline, ""]))
    data = text.encode("utf-8")
    if draw(st.integers(0, 9)) == 0:
        data = b"\xef\xbb\xbf" + data
    # the file lists joints depth-first; `order` maps file order -> joint index (here: the same)
    assert order == sorted(order)
    expected = dict(names=names, parents=parents, layouts=layouts, offsets=offsets, frames=frames, ends=ends)
    return data, expected


# ------------------------------------------------------------------------------ properties
def _assert_round_trips(m):
    """save -> load gives the same motion, and writing that again gives the same bytes."""
    text = bvh.dumps(m)
    back = bvh.loads(text)
    assert back.skeleton.names == m.skeleton.names
    np.testing.assert_array_equal(back.skeleton.parents, m.skeleton.parents)
    np.testing.assert_allclose(back.skeleton.offsets, m.skeleton.offsets, atol=1e-8)
    assert back.fps == m.fps and back.num_frames == m.num_frames
    chord = np.minimum(
        np.linalg.norm(back.local_rot - m.local_rot, axis=-1), np.linalg.norm(back.local_rot + m.local_rot, axis=-1)
    )
    assert chord.max(initial=0.0) < 1e-6
    np.testing.assert_allclose(back.translations(), m.translations(), atol=1e-8)
    for layout in back.skeleton.channels:  # what Blender can import
        assert sum(c.endswith("rotation") for c in layout) == 3
    assert bvh.dumps(back) == text


@pytest.mark.slow
@FUZZ
@given(bvh_files(), st.sampled_from([7, 64, 1000, 1 << 20]))
def test_generated_files_load_exactly_and_round_trip(file, chunk):
    data, exp = file
    with chunk_size(chunk):
        m = bvh.loads(data)
    sk = m.skeleton
    assert list(sk.names) == exp["names"]
    assert sk.parents.tolist() == exp["parents"]
    assert sk.channels == tuple(exp["layouts"])
    np.testing.assert_array_equal(sk.offsets, exp["offsets"] * 0.01)
    assert set(sk.end_sites) == set(exp["ends"])
    # every channel value as written: positions exactly, rotations as the product of axis turns
    column = 0
    for j, layout in enumerate(exp["layouts"]):
        q = quat.IDENTITY
        for c in layout:
            value = exp["frames"][:, column]
            if c in POSITION:
                got = m.root_pos[:, POSITION.index(c)] if j == 0 else m.local_pos[:, j, POSITION.index(c)]
                np.testing.assert_array_equal(got, value * 0.01)
            else:
                turn = np.zeros((len(value), 4))  # a turn about one axis, built by hand
                turn[:, 0] = np.cos(np.radians(value) / 2)
                turn[:, 1 + ROTATION.index(c)] = np.sin(np.radians(value) / 2)
                q = quat.mul(q, turn)
            column += 1
        q = np.broadcast_to(q, m.local_rot[:, j].shape)
        chord = np.minimum(
            np.linalg.norm(m.local_rot[:, j] - q, axis=-1), np.linalg.norm(m.local_rot[:, j] + q, axis=-1)
        )
        assert chord.max() < 1e-9
    _assert_round_trips(m)


REPLACEMENTS = [
    b"", b"{", b"}", b"JOINT", b"ROOT", b"End", b"Site", b"MOTION", b"CHANNELS", b"OFFSET", b"Frames:",
    b"Time:", b"Zrotation", b"Xposition", b"0", b"6", b"-1", b"nan", b"inf", b"1e999", b"1.2.3", b"--1",
    b"+", b".", b"e5", b"1e", b"\x00", b"\xff", b"\xc3\xa9", b"\r", b"\n", b"\t", b"99999999999999999999",
]  # fmt: skip


@st.composite
def mutated(draw):
    data, _ = draw(bvh_files())
    for _ in range(draw(st.integers(1, 3))):
        tokens = [t.span() for t in re.finditer(rb"\S+", data)] or [(0, 0)]
        op = draw(st.sampled_from(["del_tok", "dup_tok", "swap_tok", "del_line", "dup_line", "cut", "insert"]))
        if op in ("del_tok", "dup_tok", "swap_tok"):
            a, b = draw(st.sampled_from(tokens))
            new = {
                "del_tok": b"",
                "dup_tok": data[a:b] + b" " + data[a:b],
                "swap_tok": draw(st.sampled_from(REPLACEMENTS) | st.binary(max_size=4)),
            }[op]
            data = data[:a] + new + data[b:]
        elif op in ("del_line", "dup_line"):
            lines = data.split(b"\n")
            i = draw(st.integers(0, len(lines) - 1))
            lines[i : i + 1] = [] if op == "del_line" else [lines[i], lines[i]]
            data = b"\n".join(lines)
        elif op == "cut":
            data = data[: draw(st.integers(0, len(data)))]
        else:
            i = draw(st.integers(0, len(data)))
            data = data[:i] + draw(st.binary(min_size=1, max_size=8)) + data[i:]
    return data


@pytest.mark.slow
@FUZZ
@given(mutated(), st.sampled_from([7, 64, 1 << 20]))
def test_mutated_files_load_and_round_trip_or_name_a_line(data, chunk):
    try:
        with chunk_size(chunk):
            m = bvh.loads(data, source="fuzz.bvh")
    except BVHError as err:
        # what was expected at that line; a file that begins as binary glTF is named as one
        assert re.match(r"fuzz\.bvh, line \d+: (expected |a binary glTF)", str(err)), str(err)
        assert 1 <= err.line <= data.count(b"\n") + data.count(b"\r") + 1
        return
    assert np.isfinite(m.local_rot).all() and np.isfinite(m.root_pos).all()
    if m.num_frames == 0:
        with pytest.raises(ValueError, match="0 frames"):
            bvh.dumps(m)
        return
    _assert_round_trips(m)


@pytest.mark.slow
@FUZZ
@given(mutated())
def test_streamed_and_whole_reads_agree(data):
    """A file read in 7-byte chunks gives the same motion, or the same error, as one read whole."""
    results = []
    for chunk in (7, 1 << 20):
        with chunk_size(chunk):
            try:
                m = bvh.loads(data)
                results.append((m.skeleton.names, m.local_rot.tobytes(), m.root_pos.tobytes()))
            except BVHError as err:
                results.append(str(err))
    assert results[0] == results[1]
