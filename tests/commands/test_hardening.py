"""Issue 34: the newer commands (``fill-gaps``, ``graph-build``, ``graph-search``, ``expand``) with bad
input: no silent wrong result, nothing half-written, every output checked before any work, and
refusals that name the option or file in the user's words and say what would be accepted."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from motionlab import cli, synthetic
from motionlab.core import bvh, humanoid


def _run(capsys, *argv):
    """``(exit status, stdout, stderr)``; argparse's refusals (SystemExit) count as their status."""
    try:
        code = cli.main([str(a) for a in argv])
    except SystemExit as e:
        code = e.code
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """A 30-frame walk at 30 fps on the canonical skeleton."""
    motion = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=30, fps=30, seed=0)
    return bvh.save(tmp_path_factory.mktemp("hardening") / "walk.bvh", motion)


@pytest.fixture(scope="module")
def odd_rig(walk):
    """The walk on a rig whose legs have names no profile knows."""
    path = walk.with_name("odd.bvh")
    path.write_text(walk.read_text().replace("LeftUpLeg", "Thigh_L").replace("RightUpLeg", "Thigh_R"))
    return path


def _times(path, times):
    path.write_text("\n".join(f"{t:.6f}" for t in times) + "\n")
    return path


def _deny_writing(monkeypatch, folder):
    """``os.access`` says ``folder`` takes no new files (the tests may run as root, who can write anywhere)."""
    real = os.access
    folder = os.path.realpath(folder)

    def access(path, mode, *args, **kwargs):
        return False if os.path.realpath(path) == folder else real(path, mode, *args, **kwargs)

    monkeypatch.setattr(os, "access", access)


# ---------------------------------------------------------------------------- 1. fill-gaps --times
@pytest.mark.parametrize(("unit", "factor"), [("milliseconds", 1e3), ("microseconds", 1e6)])
def test_fill_gaps_refuses_times_in_another_unit(walk, tmp_path, capsys, unit, factor):
    times = _times(tmp_path / "t.txt", np.arange(30) / 30.0 * factor)
    out = tmp_path / "out.bvh"
    code, _, err = _run(capsys, "fill-gaps", walk, "-o", out, "--times", times)
    assert code == 2
    assert "--times" in err and "in seconds" in err and unit in err and "Frame Time" in err
    assert not out.exists()


def test_fill_gaps_refuses_a_time_that_would_grow_the_clip_beyond_reason(walk, tmp_path, capsys):
    t = np.arange(30) / 30.0
    t[-1] = 1000.0  # one wrong time: 30000 frames "missing"
    out = tmp_path / "out.bvh"
    code, _, err = _run(capsys, "fill-gaps", walk, "-o", out, "--times", _times(tmp_path / "t.txt", t))
    assert code == 2 and "--times" in err and "seconds" in err
    assert not out.exists()


def test_fill_gaps_times_in_seconds_still_fill(walk, tmp_path, capsys):
    keep = np.r_[0:10, 14:30]
    clip = tmp_path / "dropped.bvh"
    bvh.save(clip, bvh.load(walk)[keep])
    out = tmp_path / "out.bvh"
    code, stdout, err = _run(capsys, "fill-gaps", clip, "-o", out, "--times", _times(tmp_path / "t.txt", keep / 30))
    assert code == 0, err
    assert bvh.load(out).num_frames == 30


# ---------------------------------------------------------------------------- 2. graph-build: two outputs
@pytest.mark.parametrize("force", [[], ["--force"]])
def test_graph_build_refuses_one_file_for_graph_and_report(tmp_path, capsys, force):
    g = tmp_path / "g.mlgraph"
    code, _, err = _run(capsys, "graph-build", "--synthetic", "-o", g, "--report", g, *force)
    assert code == 2 and "-o and --report both name" in err
    assert "overwrite=True" not in err
    assert list(tmp_path.iterdir()) == []


def test_graph_build_writes_no_graph_when_the_report_fails(tmp_path, capsys, monkeypatch):
    real = json.dumps

    def full_disk(obj, *args, **kwargs):  # the report (not the graph's metadata) cannot be written
        if isinstance(obj, dict) and "rows" in obj:
            raise OSError(28, "No space left on device")
        return real(obj, *args, **kwargs)

    monkeypatch.setattr(json, "dumps", full_disk)
    code, _, err = _run(capsys, "graph-build", "--synthetic", "-o", tmp_path / "g", "--report", tmp_path / "r.json")
    assert code == 2 and "space" in err
    assert [p for p in tmp_path.iterdir()] == []  # neither file, and no temporary left


# ---------------------------------------------------------------------------- 3. outputs checked before work
def _no_work(monkeypatch):
    from motionlab.motion_graphs import clips

    def started(*args, **kwargs):
        raise AssertionError("the command started work before checking its outputs")

    monkeypatch.setattr(clips, "synthetic_library", started)


@pytest.mark.parametrize(
    ("where", "option"),
    [("report_missing_folder", "--report"), ("report_folder", "--report"), ("graph_read_only", "-o")],
)
def test_graph_build_checks_every_output_before_building(tmp_path, capsys, monkeypatch, where, option):
    graph, report = tmp_path / "g.mlgraph", tmp_path / "r.json"
    if where == "report_missing_folder":
        report = tmp_path / "nowhere" / "r.json"
    elif where == "report_folder":
        report.mkdir()
    else:
        locked = tmp_path / "locked"
        locked.mkdir()
        graph = locked / "g.mlgraph"
        _deny_writing(monkeypatch, locked)
    _no_work(monkeypatch)
    code, _, err = _run(capsys, "graph-build", "--synthetic", "-o", graph, "--report", report)
    assert code == 2 and option in err and "Traceback" not in err
    assert "pass --force" not in err  # a folder or a missing folder is not cured by --force
    assert not graph.exists() and not (report.is_file())


def test_read_only_output_folder_names_the_real_folder(walk, tmp_path, capsys, monkeypatch):
    out = tmp_path / "expanded"
    out.mkdir()
    _deny_writing(monkeypatch, out)
    code, _, err = _run(capsys, "expand", walk, "--preset", "child", "-o", out, "-q")
    assert code == 2 and "-o" in err and str(out.resolve()) in err and "permission denied" in err
    assert ".manifest" not in err and ".tmp" not in err
    assert list(out.iterdir()) == []


@pytest.mark.parametrize(
    ("in_the_way", "expected"),
    [
        ("child", "expected the folder of character 'child'"),  # OUT/<character> is a file
        ("manifest.csv/", "expected the job's manifest file"),  # OUT/manifest.csv is a folder
        ("child/walk.bvh/", "expected the output file of clip 'walk'"),  # OUT/<character>/<clip>.bvh is a folder
    ],
)
def test_expand_output_location_of_the_wrong_kind_is_refused_before_any_work(
    walk, tmp_path, capsys, monkeypatch, in_the_way, expected
):
    """An output location that is a file where a folder goes (or the reverse): refused up front (exit 2),
    naming the path, with nothing written and no work started."""
    from motionlab.retargeting import cli_options

    out = tmp_path / "expanded"
    path = out / in_the_way.rstrip("/")
    path.parent.mkdir(parents=True)
    path.mkdir() if in_the_way.endswith("/") else path.write_text("mine")
    before = sorted(p.relative_to(out) for p in out.rglob("*"))

    def started(*args, **kwargs):
        raise AssertionError("expand started work before checking its outputs")

    monkeypatch.setattr(cli_options, "load_checkpoint", started)
    code, _, err = _run(capsys, "expand", walk, "--preset", "child", "-o", out, "-q")
    assert code == 2 and str(path) in err and expected in err and "Traceback" not in err
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == before


@pytest.mark.parametrize("command", ["convert", "fill-gaps", "graph-search"])
def test_an_output_that_is_the_input_is_refused(walk, tmp_path, capsys, command):
    before = walk.read_bytes()
    argv = {"convert": ["convert", walk], "fill-gaps": ["fill-gaps", walk], "graph-search": ["graph-search", walk]}
    extra = ["--request", "walk:normal:30"] if command == "graph-search" else []
    code, _, err = _run(capsys, *argv[command], "-o", walk, "--force", *extra)
    assert code == 2 and (f"-o {walk} is the input file" in err or f"-o {walk} is the graph file" in err)
    assert walk.read_bytes() == before


# ---------------------------------------------------------------------------- 4. messages in the user's words
def test_expand_output_that_is_a_file(walk, tmp_path, capsys):
    target = tmp_path / "out.txt"
    target.write_text("mine")
    code, _, err = _run(capsys, "expand", walk, "--preset", "child", "-o", target, "-q")
    assert code == 2 and f"-o {target} is a file; expected a folder" in err and "isfile" not in err
    assert target.read_text() == "mine"


def test_expand_batch_frames_named_as_the_option(walk, tmp_path, capsys):
    code, _, err = _run(capsys, "expand", walk, "--preset", "child", "-o", tmp_path / "x", "--batch-frames", "-5")
    assert code == 2 and "--batch-frames" in err and "1 or more" in err and "max_frames" not in err
    assert not (tmp_path / "x").exists()


def test_expand_prints_why_pairs_failed_without_nan_or_python_advice(walk, odd_rig, tmp_path, capsys):
    code, out, err = _run(capsys, "expand", walk, "--characters", odd_rig, "-o", tmp_path / "x")
    assert code == 1
    assert "nan" not in out
    assert "failed odd/walk: RigMappingError" in out and f"motionlab info {odd_rig} --joints" in out
    assert "profile=" not in out
    rows = (tmp_path / "x" / "manifest.csv").read_text()
    assert "profile=" not in rows and "motionlab info" in rows


@pytest.mark.parametrize("command", ["graph-build", "graph-search", "fill-gaps"])
def test_an_output_that_is_a_folder_is_named_as_such(walk, tmp_path, capsys, command):
    folder = tmp_path / "folder"
    folder.mkdir()
    argv = {
        "graph-build": ["graph-build", "--synthetic", "-o", folder],
        "graph-search": ["graph-search", walk, "--request", "walk:normal:30", "-o", folder],
        "fill-gaps": ["fill-gaps", walk, "-o", folder],
    }[command]
    code, _, err = _run(capsys, *argv)
    assert code == 2 and f"-o {folder} is a folder" in err and "--force" not in err
    assert list(folder.iterdir()) == [] and sorted(p.name for p in tmp_path.iterdir()) == ["folder"]


def test_fill_gaps_takes_on_another_rig_names_the_file(walk, tmp_path, capsys):
    other = tmp_path / "other_rig.bvh"
    other.write_text(walk.read_text().replace("Hips", "Pelvis"))
    out = tmp_path / "out.bvh"
    code, _, err = _run(capsys, "fill-gaps", walk, "-o", out, "--takes", other)
    assert code == 2 and f"--takes {other}" in err and "rig" in err
    assert not out.exists()


def test_fill_gaps_action_on_another_rig_and_takes_at_another_rate_name_the_file(walk, tmp_path, capsys):
    other = tmp_path / "other_rig.bvh"
    other.write_text(walk.read_text().replace("Hips", "Pelvis"))
    out = tmp_path / "out.bvh"
    code, _, err = _run(capsys, "fill-gaps", walk, "-o", out, "--method", "graph", "--action", f"walk={other}")
    assert code == 2 and f"--action walk={other}" in err and "rig" in err
    fast = tmp_path / "fast.bvh"
    bvh.save(fast, bvh.load(walk).resample(60))
    code, _, err = _run(capsys, "fill-gaps", walk, "-o", out, "--takes", fast)
    assert code == 2 and f"--takes {fast} is at 60 fps" in err and f"motionlab convert {fast}" in err
    assert not out.exists()


def test_graph_search_frame_limit_in_command_line_words(tmp_path, capsys):
    g = tmp_path / "g.mlgraph"
    assert _run(capsys, "graph-build", "--synthetic", "-o", g)[0] == 0
    code, _, err = _run(capsys, "graph-search", g, "--request", "walk:normal:200000", "-o", tmp_path / "x.bvh")
    assert code == 2 and "--request" in err and "at most 100000 frames" in err and "MAX_FRAMES" not in err
    assert not (tmp_path / "x.bvh").exists()


# ---------------------------------------------------------------------------- 5. nonsense refused
@pytest.mark.parametrize(
    ("option", "value"),
    [("--max-penetration", "-1"), ("--batch-frames", "0"), ("--workers", "0"), ("--skate-ratio", "nan")],
)
def test_expand_refuses_nonsense_numbers(walk, tmp_path, capsys, option, value):
    code, _, err = _run(capsys, "expand", walk, "--preset", "child", "-o", tmp_path / "x", option, value)
    assert code == 2 and option in err and value in err
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("request_text", ["walk:normal:10,,run:normal:10", "walk:normal:10,", ",walk:normal:10"])
def test_graph_search_refuses_an_empty_request_segment(tmp_path, capsys, request_text):
    g = tmp_path / "g.mlgraph"
    assert _run(capsys, "graph-build", "--synthetic", "-o", g)[0] == 0
    out = tmp_path / "x.bvh"
    code, _, err = _run(capsys, "graph-search", g, "--request", request_text, "-o", out)
    assert code == 2 and "--request" in err and "is empty" in err and "walk:angry:300" in err
    assert not out.exists()


# ---------------------------------------------------------------------------- 6. figures in the option's unit
def test_graph_report_threshold_in_metres_as_the_option(tmp_path, capsys):
    report = tmp_path / "r.json"
    code, _, err = _run(
        capsys, "graph-build", "--synthetic", "-o", tmp_path / "g", "--report", report, "--threshold", "0.03"
    )
    assert code == 0, err
    assert json.loads(report.read_text())["info"]["threshold"] == pytest.approx(0.03)
