"""Tests for motionlab.core.bvh: reading, writing, error reporting and round trips."""

from __future__ import annotations

import csv
import os
import pickle
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from motionlab import synthetic
from motionlab.core import bvh, humanoid, quat
from motionlab.core.bvh import BVHError
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

DATA = os.environ.get("MOTIONLAB_DATA")
NO_DATA = "set MOTIONLAB_DATA=/path/to/shared/data to run tests on real mocap"
REAL_FILES = sorted(Path(DATA).rglob("*.bvh")) if DATA and Path(DATA).is_dir() else []

AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def rot(axes: str, degrees) -> np.ndarray:
    """R = R_axes[0] @ R_axes[1] @ ... built from single-axis quaternions (independent of bvh)."""
    q = quat.IDENTITY
    for axis, angle in zip(axes, np.atleast_1d(degrees)):
        q = quat.mul(q, quat.from_axis_angle(AXES[axis], np.radians(angle)))
    return q


def assert_rot_close(a, b, tol=1e-5):
    """Same rotations (q and -q alike) within ``tol`` radians; the chord keeps small angles exact."""
    a, b = np.asarray(a), np.asarray(b)
    chord = np.minimum(np.linalg.norm(a - b, axis=-1), np.linalg.norm(a + b, axis=-1))
    angle = 4.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0))
    assert np.all(angle < tol), f"rotations differ by up to {np.max(angle)} rad"


def bvh_text(hierarchy: str, frames: list[str], frame_time: str = "0.04") -> str:
    return f"HIERARCHY\n{hierarchy.strip()}\nMOTION\nFrames: {len(frames)}\nFrame Time: {frame_time}\n" + "".join(
        f + "\n" for f in frames
    )


# One joint of every kind: 6 channels on the root, different Euler orders per joint, no channels,
# two and one rotation channels, a non-root joint with interleaved position channels.
MIXED = bvh_text(
    """
ROOT mixamorig:Hips
{
  OFFSET 0 90 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT mixamorig:Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    JOINT Fixed
    {
      OFFSET 0 5 0
      CHANNELS 0
      JOINT Neck
      {
        OFFSET 0 3 1
        CHANNELS 3 Yrotation Zrotation Xrotation
        End Site
        {
          OFFSET 0 8 0
        }
      }
    }
  }
  JOINT newVegas:LeftLeg
  {
    OFFSET 10 -40 0
    CHANNELS 2 Zrotation Xrotation
    JOINT Foot
    {
      OFFSET 0 -40 0
      CHANNELS 1 Yrotation
      End Site
      {
        OFFSET 0 0 12
      }
    }
  }
  JOINT Prop
  {
    OFFSET -10 0 0
    CHANNELS 6 Zrotation Xposition Yrotation Yposition Xrotation Zposition
  }
}
""",
    [
        "1 91 2   10 20 30   5 -6 7   -30 40 50   11 12   13   14 -3 15 4 16 5",
        "-1 89 -2   0 0 0   0 0 0   0 0 0   0 0   0   0 7 0 8 0 9",
    ],
)
MIXED_NAMES = ("mixamorig:Hips", "mixamorig:Spine", "Fixed", "Neck", "newVegas:LeftLeg", "Foot", "Prop")


# ------------------------------------------------------------------------------ reading
def test_mixed_layout_reads_every_joint_kind():
    m = bvh.loads(MIXED)
    sk = m.skeleton
    assert sk.names == MIXED_NAMES
    np.testing.assert_array_equal(sk.parents, [-1, 0, 1, 2, 0, 4, 0])
    np.testing.assert_allclose(sk.offsets[4], [0.1, -0.4, 0.0])
    assert sk.channels == (
        ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation"),
        ("Xrotation", "Yrotation", "Zrotation"),
        (),
        ("Yrotation", "Zrotation", "Xrotation"),
        ("Zrotation", "Xrotation"),
        ("Yrotation",),
        ("Zrotation", "Xposition", "Yrotation", "Yposition", "Xrotation", "Zposition"),
    )
    assert set(sk.end_sites) == {3, 5}
    np.testing.assert_allclose(sk.end_sites[5], [0.0, 0.0, 0.12])
    assert m.num_frames == 2 and m.fps == pytest.approx(25.0)
    np.testing.assert_allclose(m.root_pos, [[0.01, 0.91, 0.02], [-0.01, 0.89, -0.02]])
    r = m.local_rot[0]
    assert_rot_close(r[0], rot("zyx", [10, 20, 30]), 1e-12)
    assert_rot_close(r[1], rot("xyz", [5, -6, 7]), 1e-12)
    assert_rot_close(r[2], quat.IDENTITY, 1e-12)
    assert_rot_close(r[3], rot("yzx", [-30, 40, 50]), 1e-12)
    assert_rot_close(r[4], rot("zx", [11, 12]), 1e-12)
    assert_rot_close(r[5], rot("y", [13]), 1e-12)
    assert_rot_close(r[6], rot("zyx", [14, 15, 16]), 1e-12)
    assert_rot_close(m.local_rot[1], np.tile(quat.IDENTITY, (7, 1)), 1e-12)
    # position channels replace the offset of the non-root joint; the others keep their offsets
    assert m.local_pos is not None and m.local_pos.shape == (2, 7, 3)
    np.testing.assert_allclose(m.local_pos[:, 6], [[-0.03, 0.04, 0.05], [0.07, 0.08, 0.09]])
    np.testing.assert_allclose(m.local_pos[:, 1:6], np.broadcast_to(sk.offsets[1:6], (2, 5, 3)))


def test_euler_channels_compose_intrinsically_in_listed_order():
    text = bvh_text(
        "ROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n}",
        ["30 -45 60"],
    )
    m = bvh.loads(text)
    a = np.radians([30.0, -45.0, 60.0])
    c, s = np.cos(a), np.sin(a)
    rz = np.array([[c[0], -s[0], 0], [s[0], c[0], 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, c[1], -s[1]], [0, s[1], c[1]]])
    ry = np.array([[c[2], 0, s[2]], [0, 1, 0], [-s[2], 0, c[2]]])
    np.testing.assert_allclose(quat.to_matrix(m.local_rot[0, 0]), rz @ rx @ ry, atol=1e-12)
    assert_rot_close(m.local_rot[0, 0], quat.from_euler(a, "zxy"), 1e-12)


def test_fk_known_answer_90_degrees_about_z():
    """+90 degrees about z at the root turns the child's +y offset into -x."""
    text = bvh_text(
        """
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
""",
        ["100 200 300 90 0 0 0 0 0", "0 0 0 0 90 0 0 0 0"],
    )
    pos = bvh.loads(text).global_positions()
    np.testing.assert_allclose(pos[0], [[1.0, 2.0, 3.0], [0.9, 2.0, 3.0]], atol=1e-12)
    # +90 about x at the root tips the +y bone onto +z
    np.testing.assert_allclose(pos[1], [[0.0, 0.0, 0.0], [0.0, 0.0, 0.1]], atol=1e-12)


@pytest.mark.parametrize("channels", ["CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 0", ""])
def test_root_without_position_channels_stays_at_its_offset(channels):
    n = len(channels.split()) - 2 if channels else 0
    text = bvh_text(
        f"ROOT Hips\n{{\nOFFSET 1 2 3\n{channels}\nJOINT Leg\n{{\nOFFSET 0 -5 0\nCHANNELS 1 Xrotation\n}}\n}}",
        [" ".join(["45"] * (n + 1))] * 3,
    )
    m = bvh.loads(text)
    np.testing.assert_allclose(m.root_pos, np.tile([0.01, 0.02, 0.03], (3, 1)))
    assert m.local_pos is None
    assert m.skeleton.channels[0] == tuple(channels.split()[2:])
    back = bvh.loads(bvh.dumps(m))
    np.testing.assert_allclose(back.root_pos, m.root_pos)
    assert_rot_close(back.local_rot, m.local_rot)


def test_root_position_channels_replace_the_offset():
    text = bvh_text("ROOT Hips\n{\nOFFSET 50 50 50\nCHANNELS 3 Xposition Yposition Zposition\n}", ["1 2 3"])
    np.testing.assert_allclose(bvh.loads(text).root_pos, [[0.01, 0.02, 0.03]])


def test_partial_position_channels_keep_the_other_offset_components():
    text = bvh_text("ROOT Hips\n{\nOFFSET 5 6 7\nCHANNELS 2 Yposition Yrotation\n}", ["100 90"])
    m = bvh.loads(text)
    np.testing.assert_allclose(m.root_pos, [[0.05, 1.0, 0.07]])
    assert_rot_close(m.local_rot[0, 0], rot("y", [90]), 1e-12)


def test_crlf_tabs_scientific_notation_prefixes_and_blank_lines():
    text = (
        "\r\n  HIERARCHY  \r\n"
        "ROOT\tmixamorig7:Hips {\r\n"
        "\t\tOFFSET\t1.0E+1 -2.5e-1 +.5 \r\n"
        "\tCHANNELS 6 XPOSITION Yposition Zposition Zrotation Xrotation Yrotation\t\r\n"
        "\tJOINT newVegas:Head\r\n\t{\r\n\t\tOFFSET 0 1e1 0\r\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\r\n"
        "\t\tEnd Site\r\n\t\t{\r\n\t\t\tOFFSET 0 5. 0\r\n\t\t}\r\n\t}\r\n}\r\n"
        "MOTION\r\nFrames:\t2\r\nFrame Time:\t3.3333333e-2\r\n"
        "1e2\t-2E+1  3.5e0 0 0 0 9.0e1 0 0\r\n"
        "\r\n"
        "-1.5 .5 5. 0 0 0 0 0 0\r\n"
        "\r\n\r\n\t\r\n"
    )
    m = bvh.loads(text)
    assert m.skeleton.names == ("mixamorig7:Hips", "newVegas:Head")
    assert m.skeleton.channels[0][0] == "XPOSITION"
    np.testing.assert_allclose(m.skeleton.offsets, [[0.1, -0.0025, 0.005], [0.0, 0.1, 0.0]])
    np.testing.assert_allclose(m.root_pos, [[1.0, -0.2, 0.035], [-0.015, 0.005, 0.05]])
    assert_rot_close(m.local_rot[0, 1], rot("z", [90]), 1e-12)
    assert bvh.frame_time(m) == 3.3333333e-2
    assert bvh.loads(text.encode("utf-8")).skeleton.names == m.skeleton.names
    assert bvh.loads("\ufeff" + text).num_frames == 2


def test_frame_time_is_kept_exactly_and_written_back():
    text = bvh_text("ROOT A\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}", ["0"], frame_time="0.016667")
    m = bvh.loads(text)
    assert m.fps == 1 / 0.016667
    assert bvh.frame_time(m) == 0.016667
    assert "Frame Time: 0.016667\n" in bvh.dumps(m)


@pytest.mark.parametrize("fps", [24.0, 25.0, 29.97, 30.0, 60.0, 120.0, 1 / 0.0333333, 1 / 0.008333, 7.3e-3, 1e4])
def test_fps_round_trips(fps):
    """fps -> Frame Time -> fps: exact when a float frame time inverts to fps, else within 1 ulp"""
    m = Motion(Skeleton(["A"], [-1], [[0, 0, 0]]), np.tile(quat.IDENTITY, (2, 1, 1)), np.zeros((2, 3)), fps)
    back = bvh.loads(bvh.dumps(m)).fps
    assert abs(back - fps) <= np.spacing(fps)
    if fps in (24.0, 25.0, 30.0, 60.0, 120.0, 1 / 0.0333333, 1 / 0.008333):
        assert back == fps


def test_scale_and_names():
    text = bvh_text("ROOT A\n{\nOFFSET 1 2 3\nCHANNELS 3 Xposition Yposition Zposition\n}", ["4 5 6"])
    m = bvh.loads(text, scale=1.0, name="clip")
    np.testing.assert_allclose(m.root_pos, [[4, 5, 6]])
    np.testing.assert_allclose(m.skeleton.offsets, [[1, 2, 3]])
    assert m.name == "clip"
    assert "OFFSET 1.000000 2.000000 3.000000" in bvh.dumps(m, scale=1.0)
    with pytest.raises(ValueError, match="scale"):
        bvh.loads(text, scale=0.0)
    with pytest.raises(ValueError, match="precision"):
        bvh.dumps(m, precision=-1)


def test_zero_frames_and_zero_channels():
    m = bvh.loads(bvh_text("ROOT A\n{\nOFFSET 0 0 0\nCHANNELS 3 Xrotation Yrotation Zrotation\n}", []))
    assert m.local_rot.shape == (0, 1, 4) and m.root_pos.shape == (0, 3)
    # read, but never written: Blender cannot import a 0-frame file
    with pytest.raises(ValueError, match="0 frames"):
        bvh.dumps(m)
    m = bvh.loads(bvh_text("ROOT A\n{\nOFFSET 1 0 0\nCHANNELS 0\n}", ["", "", ""]))
    assert m.num_frames == 3
    back = bvh.loads(bvh.dumps(m))
    assert back.num_frames == 3 and back.skeleton.channels == (("Zrotation", "Yrotation", "Xrotation"),)


def test_load_uses_file_stem_and_names_the_file_in_errors(tmp_path):
    good = tmp_path / "walk_01.bvh"
    good.write_text(MIXED)
    m = bvh.load(good)
    assert m.name == "walk_01" and m.num_frames == 2
    bad = tmp_path / "broken.bvh"
    text = MIXED.replace("-1 89 -2", "-1 89")
    bad.write_text(text)
    line = next(i + 1 for i, s in enumerate(text.split("\n")) if s.startswith("-1 89"))
    with pytest.raises(BVHError, match=re.escape(f"{bad}, line {line}: expected 21 values")) as info:
        bvh.load(bad)
    assert info.value.line == line and info.value.source == str(bad)


def test_error_pickles():
    with pytest.raises(BVHError) as info:
        bvh.loads("")
    copy = pickle.loads(pickle.dumps(info.value))
    assert str(copy) == str(info.value) and copy.line == info.value.line


# ------------------------------------------------------------------------------ malformed input
SMALL = (
    "HIERARCHY\n"  # 1
    "ROOT Hips\n"  # 2
    "{\n"  # 3
    "  OFFSET 0 0 0\n"  # 4
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"  # 5
    "  JOINT Spine\n"  # 6
    "  {\n"  # 7
    "    OFFSET 0 10 0\n"  # 8
    "    CHANNELS 3 Zrotation Xrotation Yrotation\n"  # 9
    "    End Site\n"  # 10
    "    {\n"  # 11
    "      OFFSET 0 5 0\n"  # 12
    "    }\n"  # 13
    "  }\n"  # 14
    "}\n"  # 15
    "MOTION\n"  # 16
    "Frames: 3\n"  # 17
    "Frame Time: 0.0333333\n"  # 18
    "0 90 0 0 0 0 0 0 0\n"  # 19
    "1 90 0 0 0 0 0 0 0\n"  # 20
    "2 90 0 0 0 0 0 0 0\n"  # 21
)


def _edit(line: int, new: str | None) -> str:
    lines = SMALL.split("\n")
    if new is None:
        del lines[line - 1]
    else:
        lines[line - 1] = new
    return "\n".join(lines)


MALFORMED = {
    "too few values": (_edit(20, "1 90 0 0 0 0 0 0"), 20, "expected 9 values on frame line 2.*found 8"),
    "too many values": (_edit(19, "0 90 0 0 0 0 0 0 0 0"), 19, "expected 9 values.*found 10"),
    "missing Frames": (_edit(17, None), 17, "expected 'Frames:'"),
    "missing Frame Time": (_edit(18, None), 18, "expected 'Frame Time:'"),
    "zero frame time": (_edit(18, "Frame Time: 0"), 18, "positive frame time"),
    "negative frame time": (_edit(18, "Frame Time: -0.1"), 18, "positive frame time"),
    "text frame time": (_edit(18, "Frame Time: fast"), 18, "positive frame time"),
    "bad frame count": (_edit(17, "Frames: 2.5"), 17, "whole number of frames"),
    "missing closing brace": (_edit(14, None), 15, "unbalanced braces"),
    "extra closing brace": (_edit(15, "}\n}"), 16, "unbalanced braces"),
    "missing opening brace": (_edit(7, None), 7, r"expected '\{' to open joint 'Spine'"),
    "duplicate joint name": (_edit(6, "  JOINT Hips"), 6, "unique joint name.*'Hips'.*line 2"),
    "truncated motion": (_edit(21, None), 21, "expected 3 frame lines.*found only 2.*truncated"),
    "extra frame line": (SMALL + "3 90 0 0 0 0 0 0 0\n", 22, "no more frame lines.*Frames: 3.*extra"),
    "non-numeric value": (
        _edit(20, "1 90 0 0 abc 0 0 0 0"),
        20,
        "expected a number for value 5 of frame 2, found 'abc'",
    ),
    "malformed number": (_edit(20, "1 90 0 0 1.2.3 0 0 0 0"), 20, "expected a number for value 5.*'1.2.3'"),
    "nan value": (_edit(21, "2 nan 0 0 0 0 0 0 0"), 21, "finite number for value 2 of frame 3"),
    "inf value": (_edit(19, "0 90 0 0 0 0 0 0 -inf"), 19, "finite number for value 9"),
    "overflowing value": (_edit(19, "0 90 0 0 0 1e999 0 0 0"), 19, "finite number for value 6"),
    "non-ascii value": (_edit(19, "0 90 0 0 0 ٣ 0 0 0"), 19, "found the character"),
    "missing HIERARCHY": (SMALL.replace("HIERARCHY\n", "\n"), 2, "expected 'HIERARCHY'"),
    "missing ROOT": (_edit(2, "JOINT Hips"), 2, "expected 'ROOT'"),
    "missing MOTION": (_edit(16, None), 16, "expected 'MOTION'.*found 'Frames:'"),
    "root name missing": (_edit(2, "ROOT"), 2, "expected a joint name after ROOT, found end of line"),
    "joint name missing": (_edit(6, "  JOINT {"), 6, "expected a joint name after JOINT"),
    "channel count too high": (_edit(9, "CHANNELS 7 Zrotation"), 9, "channel count from 0 to 6"),
    "channel count not a number": (_edit(9, "CHANNELS x Zrotation"), 9, "channel count from 0 to 6"),
    "channel count too low": (
        _edit(9, "CHANNELS 2 Zrotation Xrotation Yrotation"),
        9,
        "CHANNELS 2, but more channel names",
    ),
    "channel count too high for names": (
        _edit(9, "CHANNELS 4 Zrotation Xrotation Yrotation"),
        10,
        "channel name 4 of 4.*found 'End'",
    ),
    "unknown channel": (_edit(9, "CHANNELS 3 Zrotation Wrotation Yrotation"), 9, "channel name 2 of 3.*'Wrotation'"),
    "repeated channel": (
        _edit(9, "CHANNELS 3 Zrotation Zrotation Yrotation"),
        9,
        "distinct channels.*'Zrotation' twice",
    ),
    "missing offset": (_edit(8, None), 9, "expected OFFSET for joint 'Spine'"),
    "short offset": (_edit(8, "OFFSET 0 10"), 9, "number for z of the OFFSET of joint 'Spine'.*'CHANNELS'"),
    "nan offset": (_edit(8, "OFFSET 0 nan 0"), 8, "finite number for y of the OFFSET"),
    "second offset": (_edit(9, "OFFSET 1 1 1"), 9, "second or misplaced OFFSET"),
    "End without Site": (_edit(10, "    End"), 11, "expected 'Site' after 'End'"),
    "End Site without offset": (_edit(12, None), 12, "OFFSET in the End Site"),
    "second root": (SMALL.replace("MOTION", "ROOT B\n{\nOFFSET 0 0 0\n}\nMOTION"), 16, "only one ROOT"),
    "text after MOTION": (_edit(16, "MOTION now"), 16, "nothing after MOTION"),
    "frames on the next line": (_edit(17, "Frames:\n3"), 17, "value after 'Frames:' on the same line"),
    "data on the Frame Time line": (_edit(18, "Frame Time: 0.1 0"), 18, "only one value after 'Frame Time:'"),
    "garbage before hierarchy": ("hello\n" + SMALL, 1, "expected 'HIERARCHY'.*found 'hello'"),
    "only a hierarchy": (SMALL[: SMALL.index("MOTION")], 15, "expected 'MOTION'.*end of file"),
    "empty file": ("", 1, "expected 'HIERARCHY'.*end of file"),
    "only whitespace": ("\n\n  \n", 3, "expected 'HIERARCHY'.*end of file"),
}


@pytest.mark.parametrize("case", list(MALFORMED), ids=list(MALFORMED))
def test_malformed_input_names_source_line_and_expectation(case):
    text, line, pattern = MALFORMED[case]
    with pytest.raises(BVHError, match=rf"^<string>, line {line}: (.|\n)*?{pattern}") as info:
        bvh.loads(text)
    assert info.value.line == line
    assert "expected" in str(info.value)


def test_non_utf8_bytes():
    data = SMALL.replace("Spine", "Sp\xefne").encode("latin-1")
    with pytest.raises(BVHError, match=r"^<string>, line 6: expected UTF-8 text, found the byte 0xef"):
        bvh.loads(data)


def test_trailing_blank_lines_and_missing_final_newline_are_fine():
    assert bvh.loads(SMALL + "\n\n   \n\t\n").num_frames == 3
    assert bvh.loads(SMALL.rstrip("\n")).num_frames == 3


def test_first_bad_line_is_reported():
    text = _edit(20, "1 2 3").replace("2 90 0 0 0 0 0 0 0", "x")
    with pytest.raises(BVHError, match="line 20:"):
        bvh.loads(text)


# ------------------------------------------------------------------------------ writing
def test_dumps_loads_round_trip_of_mixed_layout():
    m = bvh.loads(MIXED)
    back = bvh.loads(bvh.dumps(m))
    assert_same_motion(m, back)


def assert_same_motion(a: Motion, b: Motion, atol: float = 1e-8):
    sa, sb = a.skeleton, b.skeleton
    assert sa.names == sb.names
    np.testing.assert_array_equal(sa.parents, sb.parents)
    np.testing.assert_allclose(sa.offsets, sb.offsets, atol=atol)
    assert_written_layouts(sa.channels, sb.channels)
    assert sa.end_sites.keys() == sb.end_sites.keys()
    for j in sa.end_sites:
        np.testing.assert_allclose(sa.end_sites[j], sb.end_sites[j], atol=atol)
    assert abs(b.fps - a.fps) <= np.spacing(a.fps)  # exact whenever some frame time inverts to fps
    assert a.num_frames == b.num_frames
    if a.num_frames:
        assert_rot_close(a.local_rot, b.local_rot)
    np.testing.assert_allclose(a.root_pos, b.root_pos, atol=atol)
    assert (a.local_pos is None) == (b.local_pos is None)
    if a.local_pos is not None:
        np.testing.assert_allclose(a.local_pos, b.local_pos, atol=atol)


def assert_written_layouts(original, written):
    """``written`` is ``original`` with the missing rotation axes added (three per joint, for Blender)."""
    if original is None:
        return
    assert len(original) == len(written)
    for a, b in zip(original, written):
        assert [c for c in b if c in a] == list(a), (a, b)  # the original channels, in their order
        assert sorted(c[0] for c in b if c.endswith("rotation")) == ["X", "Y", "Z"], b
        assert [c for c in b if c.endswith("position")] == [c for c in a if c.endswith("position")]


def test_written_files_have_three_rotation_channels_per_joint():
    """Blender's importer fails on joints with one or two rotation channels: they get all three."""
    m = bvh.loads(MIXED)
    assert any(0 < sum(c.endswith("rotation") for c in layout) < 3 for layout in m.skeleton.channels)
    text = bvh.dumps(m)
    for line in text.splitlines():
        if line.strip().startswith("CHANNELS"):
            assert sum(w.endswith("rotation") for w in line.split()) == 3, line
    assert "CHANNELS 2 Zrotation Xrotation" not in text
    assert_same_motion(m, bvh.loads(text))


def test_save_load_round_trip(tmp_path):
    m = bvh.loads(MIXED, name="mixed")
    path = bvh.save(tmp_path / "out.bvh", m)
    assert path == tmp_path / "out.bvh"
    back = bvh.load(path)
    assert_same_motion(m, back)
    assert back.name == "out"


def _frame_rows(text: str) -> np.ndarray:
    """The MOTION block's numbers, (T, channels)."""
    lines = text.split("Frame Time:")[1].strip().splitlines()[1:]
    return np.array([[float(v) for v in line.split()] for line in lines])


def test_written_euler_curves_have_no_jumps():
    """A joint that spins (three turns about Y) and one that pitches through 90 degrees about its
    middle axis are written as smooth curves: each frame on the triple nearer the frame before's,
    whole turns added, every frame's rotation kept. Each frame written on its own wrapped the
    spin at 180 (a 360-degree jump in the file) and swapped triples where the pitch passed 90."""
    sk = Skeleton(("Hips", "Spine"), np.array([-1, 0]), np.array([[0.0, 1.0, 0.0], [0.0, 0.3, 0.0]]))
    t = np.linspace(0.0, 1.0, 121)[:, None]
    spin = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), 6 * np.pi * t[:, 0])
    tilt = quat.mul(quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(150.0) * t[:, 0]),
                    quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.radians(20.0) * t[:, 0]))  # fmt: skip
    m = Motion(sk, np.stack([spin, tilt], axis=1), np.zeros((121, 3)) + [0.0, 1.0, 0.0], 30.0)
    text = bvh.dumps(m)
    rows = _frame_rows(text)
    assert np.abs(np.diff(rows, axis=0)).max() < 10.0  # 9 degrees a frame at most, in every channel
    assert np.abs(rows[0]).max() <= 180.0  # frame 0 as each frame was written before
    back = bvh.loads(text)
    assert quat.angle_between(back.local_rot, m.local_rot).max() < 1e-6
    assert bvh.dumps(back) == text


def test_save_refuses_to_overwrite(tmp_path):
    m = bvh.loads(MIXED)
    path = tmp_path / "clip.bvh"
    bvh.save(path, m)
    before = path.read_text()
    with pytest.raises(FileExistsError, match="overwrite=True"):
        bvh.save(path, m[:1])
    assert path.read_text() == before
    bvh.save(path, m[:1], overwrite=True)
    assert bvh.load(path).num_frames == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.bvh"]


def test_failed_save_leaves_no_file(tmp_path):
    m = bvh.loads(MIXED)
    bad = m.copy()
    bad.root_pos[1, 2] = np.nan
    with pytest.raises(ValueError, match="root position|positions of joint 'mixamorig:Hips' at frame 1"):
        bvh.save(tmp_path / "nan.bvh", bad)
    assert list(tmp_path.iterdir()) == []
    # overwriting with a bad motion keeps the old file intact
    path = bvh.save(tmp_path / "keep.bvh", m)
    before = path.read_bytes()
    with pytest.raises(ValueError, match="not finite"):
        bvh.save(path, bad, overwrite=True)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["keep.bvh"]


def test_rotation_outside_the_read_channels_is_written():
    """Written layouts have all three rotation axes, so rotations outside the read channels survive."""
    m = bvh.loads(MIXED)
    fixed = MIXED_NAMES.index("Fixed")
    turned = m.copy()
    turned.local_rot[0, fixed] = rot("x", [10])
    assert_rot_close(bvh.loads(bvh.dumps(turned)).local_rot[0, fixed], turned.local_rot[0, fixed])
    leg = MIXED_NAMES.index("newVegas:LeftLeg")
    turned.local_rot[1, leg] = rot("y", [5])  # the leg only has Zrotation Xrotation in the file
    assert_rot_close(bvh.loads(bvh.dumps(turned)).local_rot[1, leg], turned.local_rot[1, leg])


def test_translation_without_position_channels_is_refused():
    m = bvh.loads(MIXED)
    moved = m.copy()
    moved.local_pos[1, 1] += [0.0, 0.01, 0.0]
    with pytest.raises(ValueError, match="'mixamorig:Spine'.*moves.*along y"):
        bvh.dumps(moved)


def test_default_layout_without_channels():
    sk = Skeleton(["Root", "A", "B"], [-1, 0, 1], [[0, 1, 0], [0, 0.5, 0], [0.2, 0, 0]], {2: [0.1, 0, 0]})
    rng = np.random.default_rng(0)
    local_rot = quat.normalize(rng.normal(size=(4, 3, 4)))
    m = Motion(sk, local_rot, rng.normal(size=(4, 3)), 30.0)
    text = bvh.dumps(m)
    assert "CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation" in text
    assert text.count("CHANNELS 3 Zrotation Yrotation Xrotation") == 2
    back = bvh.loads(text)
    assert_rot_close(back.local_rot, m.local_rot)
    np.testing.assert_allclose(back.global_positions(), m.global_positions(), atol=1e-7)
    # a non-root joint that translates gets position channels
    local_pos = np.broadcast_to(sk.offsets, (4, 3, 3)).copy()
    local_pos[:, 2, 0] = [0.1, 0.2, 0.3, 0.4]
    back = bvh.loads(bvh.dumps(m.copy(local_pos=local_pos)))
    assert back.skeleton.channels[2][:3] == ("Xposition", "Yposition", "Zposition")
    np.testing.assert_allclose(back.local_pos[:, 2, 0], [0.1, 0.2, 0.3, 0.4], atol=1e-8)


def test_non_depth_first_skeleton_is_written_depth_first():
    # joint order 0, 1, 2, 3 with 3 a child of 1: the file lists Root, A, C, B
    sk = Skeleton(["Root", "A", "B", "C"], [-1, 0, 0, 1], [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    rng = np.random.default_rng(1)
    m = Motion(sk, quat.normalize(rng.normal(size=(3, 4, 4))), rng.normal(size=(3, 3)), 60.0)
    back = bvh.loads(bvh.dumps(m))
    assert back.skeleton.names == ("Root", "A", "C", "B")
    order = [sk.index(n) for n in back.skeleton.names]
    np.testing.assert_allclose(back.global_positions(), m.global_positions()[:, order], atol=1e-7)


def test_unwritable_names_are_refused():
    for name in ["two  spaces", " lead", "br{ace", ""]:
        sk = Skeleton(["Root", name or "x"], [-1, 0], np.zeros((2, 3)))
        if not name:
            sk = sk.renamed(["Root", ""])
        m = Motion(sk, np.tile(quat.IDENTITY, (1, 2, 1)), np.zeros((1, 3)), 30.0)
        with pytest.raises(ValueError, match="cannot write joint name"):
            bvh.dumps(m)


def test_names_with_single_spaces_round_trip():
    sk = Skeleton(["Root", "Left Arm"], [-1, 0], [[0, 0, 0], [1, 0, 0]])
    m = Motion(sk, np.tile(quat.IDENTITY, (1, 2, 1)), np.zeros((1, 3)), 30.0)
    assert bvh.loads(bvh.dumps(m)).skeleton.names == ("Root", "Left Arm")


def test_dumps_does_not_modify_the_motion():
    m = bvh.loads(MIXED)
    before = [m.local_rot.copy(), m.root_pos.copy(), m.local_pos.copy()]
    bvh.dumps(m, scale=50.0, precision=3)
    for a, b in zip(before, [m.local_rot, m.root_pos, m.local_pos]):
        np.testing.assert_array_equal(a, b)


# ------------------------------------------------------------------------------ properties
POSITIONS = ("Xposition", "Yposition", "Zposition")


@st.composite
def random_motions(draw):
    """A random depth-first tree with random channel layouts, offsets, end sites and values."""
    n_joints = draw(st.integers(1, 7))
    parents, path = [-1], [0]
    for j in range(1, n_joints):
        depth = draw(st.integers(0, len(path) - 1))
        path = path[: depth + 1]
        parents.append(path[-1])
        path.append(j)
    layouts = []
    for _ in range(n_joints):
        n_rot = draw(st.sampled_from([0, 1, 2, 3, 3, 3]))
        layout = [f"{a.upper()}rotation" for a in draw(st.permutations("xyz"))[:n_rot]]
        n_pos = draw(st.sampled_from([0, 0, 3, 3, 1, 2]))
        for name in draw(st.permutations(POSITIONS))[:n_pos]:
            layout.insert(draw(st.integers(0, len(layout))), name)
        layouts.append(tuple(layout))
    prefix = draw(st.sampled_from(["", "mixamorig:", "newVegas:", "mixamorig7:"]))
    names = draw(
        st.lists(st.text("abcXYZ_019:-.", min_size=1, max_size=6), min_size=n_joints, max_size=n_joints, unique=True)
    )
    names = [prefix + n for n in names]
    n_frames = draw(st.integers(1, 4))
    fps = draw(st.sampled_from([30.0, 60.0, 120.0, 1 / 0.016667, 1 / 0.0333333]) | st.floats(0.5, 1000.0))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    offsets = rng.uniform(-0.5, 0.5, size=(n_joints, 3))
    end_sites = {j: rng.uniform(-0.2, 0.2, size=3) for j in range(n_joints) if rng.random() < 0.4}
    local_rot = np.empty((n_frames, n_joints, 4))
    translations = np.broadcast_to(offsets, (n_frames, n_joints, 3)).copy()
    for j, layout in enumerate(layouts):
        axes = "".join(c[0].lower() for c in layout if c.endswith("rotation"))
        angles = rng.uniform(-180.0, 180.0, size=(n_frames, len(axes)))
        local_rot[:, j] = [rot(axes, a) for a in angles] if n_frames else np.empty((0, 4))
        for c in layout:
            if c.endswith("position"):
                translations[:, j, POSITIONS.index(c)] = rng.uniform(-2.0, 2.0, size=n_frames)
    moving = any(c.endswith("position") for layout in layouts[1:] for c in layout)
    skeleton = Skeleton(names, parents, offsets, end_sites, layouts)
    return Motion(skeleton, local_rot, translations[:, 0].copy(), fps, translations if moving else None)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_motions())
def test_random_hierarchies_round_trip(m):
    """motion -> dumps -> loads -> same motion (to print precision)"""
    back = bvh.loads(bvh.dumps(m))
    assert_same_motion(m, back, atol=1e-8)


REPLACEMENTS = [
    b"", b"{", b"}", b"JOINT", b"ROOT", b"End", b"Site", b"MOTION", b"CHANNELS", b"OFFSET", b"HIERARCHY",
    b"Frames:", b"Frame", b"Time:", b"Xrotation", b"Yposition", b"0", b"7", b"-1", b"nan", b"inf", b"1e999",
    b"1.2.3", b"1_0", b"0x10", b"--1", b"\x00", b"\xff", b"\xc3\xa9", b"\xe2\x80\xa8", b"\x1c", b"\r", b"\n",
    b"99999999999999999999", b"1e-400", b"+.5", b"6",
]  # fmt: skip


@st.composite
def corrupted(draw):
    base = draw(st.sampled_from([SMALL, MIXED, SMALL.replace("\n", "\r\n")])).encode()
    for _ in range(draw(st.integers(1, 3))):
        tokens = [t.span() for t in re.finditer(rb"\S+", base)] or [(0, 0)]
        lines = base.split(b"\n")
        op = draw(st.sampled_from(["del_tok", "dup_tok", "swap_tok", "del_line", "dup_line", "cut", "insert"]))
        if op in ("del_tok", "dup_tok", "swap_tok"):
            a, b = draw(st.sampled_from(tokens))
            new = {
                "del_tok": b"",
                "dup_tok": base[a:b] + b" " + base[a:b],
                "swap_tok": draw(st.sampled_from(REPLACEMENTS) | st.binary(max_size=4)),
            }[op]
            base = base[:a] + new + base[b:]
        elif op in ("del_line", "dup_line"):
            i = draw(st.integers(0, len(lines) - 1))
            lines[i : i + 1] = [] if op == "del_line" else [lines[i], lines[i]]
            base = b"\n".join(lines)
        elif op == "cut":
            base = base[: draw(st.integers(0, len(base)))]
        else:
            i = draw(st.integers(0, len(base)))
            base = base[:i] + draw(st.binary(min_size=1, max_size=8)) + base[i:]
    return base


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(corrupted())
def test_corrupted_files_parse_or_raise_bvh_error(data):
    try:
        m = bvh.loads(data)
    except BVHError as err:
        assert re.match(r"<string>, line \d+: ", str(err)), str(err)
        assert err.line >= 1
        return
    assert np.isfinite(m.local_rot).all() and np.isfinite(m.root_pos).all()
    assert m.local_rot.shape == (m.num_frames, m.skeleton.num_joints, 4)


# ------------------------------------------------------------------------------ real mocap
def _manifest() -> dict[str, dict[str, str]]:
    path = Path(DATA or "") / "manifest.csv"
    if not DATA or not path.is_file():
        return {}
    with path.open(newline="") as f:
        return {row["path"]: row for row in csv.DictReader(f)}


@pytest.mark.realdata
def _real_file_params() -> list:
    """Every real file; all but the first of each folder marked ``slow`` (a folder holds one
    source's files, so the fast loop, ``-m "not slow"``, still reads every source's format)."""
    folders: set[Path] = set()
    out = []
    for p in REAL_FILES:
        out.append(pytest.param(p, id=str(p.relative_to(DATA)), marks=pytest.mark.slow if p.parent in folders else ()))
        folders.add(p.parent)
    return out or [pytest.param(None, id="no-data")]


@pytest.mark.backend_free  # the reader and writer on every real file; FK within 1e-6 of the size
@pytest.mark.parametrize("path", _real_file_params())
def test_real_file_loads_and_round_trips(path, tmp_path):
    """file -> load -> save -> load: same skeleton, frame time and global positions; the header
    alone (``bvh.header``) gives load's frame count and rate"""
    if path is None:
        pytest.skip(NO_DATA)
    m = bvh.load(path)
    assert bvh.header(path) == (m.num_frames, m.fps)
    row = _manifest().get(path.relative_to(DATA).as_posix())
    if row:
        assert m.num_frames == int(row["frames"])
        assert m.skeleton.num_joints == int(row["joints"])
        assert sum(len(c) for c in m.skeleton.channels) == int(row["channels"])
        assert bvh.frame_time(m) == float(row["frame_time"])
    pos = m.global_positions()
    assert np.isfinite(pos).all()
    back = bvh.load(bvh.save(tmp_path / path.name, m))
    assert back.skeleton.names == m.skeleton.names
    assert_written_layouts(m.skeleton.channels, back.skeleton.channels)
    np.testing.assert_array_equal(back.skeleton.parents, m.skeleton.parents)
    np.testing.assert_allclose(back.skeleton.offsets, m.skeleton.offsets, atol=1e-8)
    assert back.fps == m.fps
    size = max(1.0, float(np.abs(pos).max()))
    np.testing.assert_allclose(back.global_positions(), pos, rtol=0, atol=1e-6 * size)


# ------------------------------------------------------------------------------ line ends, memory
def test_cr_only_line_ends_read_like_lf():
    """Old Mac files end lines with CR alone; they used to fail on 'line 1'."""
    lf = bvh.loads(MIXED)
    cr = bvh.loads(MIXED.replace("\n", "\r"))
    assert_identical(lf, cr)
    bad = MIXED.replace("-1 89 -2", "-1 89").replace("\n", "\r")
    line = next(i + 1 for i, s in enumerate(MIXED.split("\n")) if s.startswith("-1 89"))
    with pytest.raises(BVHError, match=rf"line {line}: expected 21 values"):
        bvh.loads(bad)


def test_load_streams_with_memory_below_three_times_the_file(tmp_path):
    import tracemalloc

    from motionlab import synthetic

    motion = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=6000, fps=60, seed=0)
    path = bvh.save(tmp_path / "long.bvh", motion)
    size = path.stat().st_size
    import motionlab.core.bvh as module

    old = module.CHUNK
    module.CHUNK = 1 << 16  # a file many chunks long (as a 200 MB file is with the default)
    tracemalloc.start()
    try:
        back = bvh.load(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        module.CHUNK = old
    assert back.num_frames == 6000
    assert peak <= 3 * size, f"peak {peak / 1e6:.1f} MB for a {size / 1e6:.1f} MB file"
    # the streamed reader gives exactly what reading the text in one piece gives, across chunk borders
    module.CHUNK = 1000  # borders inside lines
    try:
        assert_identical(back, bvh.loads(path.read_bytes(), name=back.name))
        assert_identical(back, bvh.load(path))
    finally:
        module.CHUNK = old


def assert_identical(a: Motion, b: Motion):
    assert a.skeleton.names == b.skeleton.names and a.skeleton.channels == b.skeleton.channels
    np.testing.assert_array_equal(a.skeleton.offsets, b.skeleton.offsets)
    np.testing.assert_array_equal(a.local_rot, b.local_rot)
    np.testing.assert_array_equal(a.root_pos, b.root_pos)
    assert (a.local_pos is None) == (b.local_pos is None) and a.fps == b.fps


@pytest.mark.parametrize("order", ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx"])
def test_closed_form_euler_matches_quat_from_euler(order):
    angles = np.random.default_rng(0).uniform(-400, 400, size=(50, 3, 3))
    out = np.empty((50, 3, 4))
    bvh._euler_into(out, angles, order)
    assert_rot_close(out, quat.from_euler(np.radians(angles), order), tol=1e-14)
    small = angles[np.abs(angles).max(axis=(1, 2)) < 360]  # below a full turn: the same quaternion
    bvh._euler_into(out[: len(small)], small, order)
    np.testing.assert_allclose(out[: len(small)], quat.from_euler(np.radians(small), order), atol=1e-15)


def test_a_file_ending_on_the_frame_time_line_names_that_line():
    text = SMALL[: SMALL.index("Frame Time: 0.0333333") + len("Frame Time: 0.0333333")]
    with pytest.raises(BVHError, match="line 18: expected 3 frame lines"):
        bvh.loads(text)


def test_header_reads_no_motion_block_and_names_the_file_and_line_of_a_bad_header(tmp_path):
    good = bvh.dumps(
        Motion(
            Skeleton(("Hips",), np.array([-1]), np.zeros((1, 3))),
            np.tile(quat.IDENTITY, (3, 1, 1)),
            np.zeros((3, 3)),
            30.0,
        )
    )
    broken_block = tmp_path / "block.bvh"
    broken_block.write_text(good.replace(good.splitlines()[-1], "1 2 x"))
    assert bvh.header(broken_block) == (3, pytest.approx(30.0))
    with pytest.raises(BVHError, match="block.bvh"):
        bvh.load(broken_block)
    bad = tmp_path / "bad.bvh"
    bad.write_text(good.replace("Frame Time:", "Frame Tme:"))
    with pytest.raises(BVHError, match=r"bad\.bvh.*line \d+.*Frame Time"):
        bvh.header(bad)


def test_a_glb_file_is_named_as_glb(tmp_path):
    from motionlab.core import gltf

    path = tmp_path / "walk.glb"
    path.write_bytes(gltf.dumps(synthetic.generate("walk", num_frames=5, fps=30)))
    with pytest.raises(bvh.BVHError, match=r"walk.glb, line 1: a binary glTF \(.glb\) file, not BVH text"):
        bvh.load(path)
