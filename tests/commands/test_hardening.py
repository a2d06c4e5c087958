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

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)


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


# ============================================================================ issue 39
# ---------------------------------------------------------------------------- every -o: its suffix's format
def _graph_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("graph") / "g.mlgraph"
    assert cli.main(["graph-build", "--synthetic", "-o", str(path), "-q"]) == 0
    return path


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    return _graph_file(tmp_path_factory)


def _motion_command(name, walk, graph, out):
    return {
        "convert": ["convert", walk, "-o", out],
        "synth": ["synth", "walk", "--seconds", "0.5", "-o", out],
        "fill-gaps": ["fill-gaps", walk, "-o", out],
        "graph-search": ["graph-search", graph, "--request", "walk:normal:30", "-o", out],
        "retarget": ["retarget", walk, "--scale-legs", "1.2", "--method", "copy", "--keep-implausible", "-o", out],
    }[name]


MOTION_COMMANDS = ["convert", "synth", "fill-gaps", "graph-search", "retarget"]


@pytest.mark.parametrize("command", MOTION_COMMANDS)
def test_a_glb_name_gets_gltf_and_a_bvh_name_bvh(walk, graph, tmp_path, capsys, command):
    for name, magic in (("x.glb", b"glTF"), ("x.BVH", b"HIER")):
        out = tmp_path / name
        code, _, err = _run(capsys, *_motion_command(command, walk, graph, out))
        assert code == 0, err
        assert out.read_bytes()[:4] == magic


@pytest.mark.parametrize("command", MOTION_COMMANDS)
@pytest.mark.parametrize("name", ["x.gltf", "x.fbx", "x.txt", "x"])
def test_a_suffix_no_motion_writer_has_is_refused_and_nothing_written(walk, graph, tmp_path, capsys, command, name):
    folder = tmp_path / "out"
    folder.mkdir()
    code, _, err = _run(capsys, *_motion_command(command, walk, graph, folder / name))
    assert code == 2 and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and ".glb" in err and ".bvh" in err
    assert not list(folder.iterdir())


def test_the_suffix_rule_has_one_home():
    from motionlab.core import motion_files

    assert motion_files.output_suffix("a/B.GLB") == ".glb"
    with pytest.raises(ValueError, match="--npz x.gltf ends in .gltf"):
        motion_files.output_suffix("x.gltf", "--npz")


# ---------------------------------------------------------------------------- glTF: finite, float32, metres
def _edited(walk, tmp_path, name, edit):
    lines = walk.read_text().split("\n")
    i = next(k for k, line in enumerate(lines) if line.startswith("Frame Time"))
    edit(lines, i)
    path = tmp_path / name
    path.write_text("\n".join(lines))
    return path


def test_convert_refuses_values_beyond_float32_for_gltf(walk, tmp_path, capsys):
    def huge(lines, i):
        lines[i + 1] = " ".join(["1e300"] + lines[i + 1].split()[1:])

    def slow(lines, i):
        lines[i] = "Frame Time: 1e300"

    for edit in (huge, slow):
        source = _edited(walk, tmp_path, f"{edit.__name__}.bvh", edit)
        code, _, err = _run(capsys, "convert", source, "-o", tmp_path / "x.glb")
        assert code == 2 and "float32" in err and len(err.strip().splitlines()) == 1
        assert not (tmp_path / "x.glb").exists()


def test_gltf_dumps_never_writes_json_that_is_not_json(walk):
    from motionlab.core import gltf

    motion = bvh.load(walk)
    for bad in (motion.copy(fps=1e-300), motion.copy(root_pos=motion.root_pos * 1e300)):
        with pytest.raises(ValueError, match="float32"):
            gltf.dumps(bad)


def _gltf_height(path) -> float:
    """Height (metres) of the bone mesh's rest pose in a GLB file."""
    import struct

    data = path.read_bytes()
    doc = json.loads(data[20 : 20 + struct.unpack("<I", data[12:16])[0]])
    bounds = [a for a in doc["accessors"] if "min" in a and a["type"] == "VEC3"][0]
    return bounds["max"][1] - bounds["min"][1]


@pytest.mark.parametrize("clip", ["cmu/131/131_01.bvh", "xia/walk/neutral_01_000.bvh", "mixamo/Aj/Running.bvh"])
def test_gltf_from_every_rig_family_is_a_figure_in_metres(tmp_path, capsys, clip):
    from tests.conftest import require_data

    source = require_data(*clip.split("/"))
    out = tmp_path / "x.glb"
    code, _, err = _run(capsys, "convert", source, "-o", out, "-q")
    assert code == 0, err
    assert 1.2 < _gltf_height(out) < 2.1  # people, not 24 cm figures
    code, _, err = _run(capsys, "convert", source, "-o", tmp_path / "x.bvh", "-q")  # BVH keeps the file's unit
    assert bvh.load(tmp_path / "x.bvh").skeleton.height() == pytest.approx(bvh.load(source).skeleton.height(), 1e-5)


def test_file_unit_of_the_cmu_skeleton_is_the_asf_unit():
    from motionlab.core import motion_files

    canonical = humanoid.canonical_skeleton()
    assert motion_files.file_unit(canonical) == motion_files.CM
    cmu = canonical.renamed([{"Spine": "LowerBack", "Spine1": "Spine", "Spine2": "Spine1", "Neck": "Neck",
                              "Head": "Neck1"}.get(n, n) for n in canonical.names])  # fmt: skip
    assert humanoid.find_mapping(cmu).profile == "cmu"
    assert motion_files.file_unit(cmu) == pytest.approx(0.0254 / 0.45)


# ---------------------------------------------------------------------------- special files, folders
@pytest.mark.parametrize("kind", ["fifo", "symlink"])
@pytest.mark.parametrize("command", ["convert", "synth", "fill-gaps", "graph-search"])
def test_force_never_replaces_a_special_file_or_a_link(walk, graph, tmp_path, capsys, kind, command):
    target = tmp_path / "target.bvh"
    target.write_text("kept\n")
    out = tmp_path / "out.bvh"
    if kind == "fifo":
        os.mkfifo(out)
    else:
        out.symlink_to(target)
    code, _, err = _run(capsys, *_motion_command(command, walk, graph, out), "--force")
    assert code == 2 and ("named pipe" in err if kind == "fifo" else "symbolic link" in err)
    assert out.is_fifo() if kind == "fifo" else out.is_symlink()
    assert target.read_text() == "kept\n"


def test_the_library_writer_refuses_special_files_too(tmp_path, walk):
    from motionlab.core import files

    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(FileExistsError, match="named pipe"):
        files.atomic_write(tmp_path / "pipe", lambda f: f.write("x"), overwrite=True)
    assert (tmp_path / "pipe").is_fifo()


@pytest.mark.parametrize(
    "argv",
    [["convert", "{walk}", "-o", "{dir}/newdir/"], ["synth", "walk", "-o", "{dir}/newdir/"],
     ["graph-build", "--synthetic", "-o", "{dir}/newdir/"], ["view", "{walk}", "-o", "{dir}/newdir/"]],
)  # fmt: skip
def test_a_name_ending_in_a_slash_writes_no_file(walk, tmp_path, capsys, argv):
    code, _, err = _run(capsys, *(a.format(walk=walk, dir=tmp_path) for a in argv))
    assert code == 2 and "Traceback" not in err
    assert not [p for p in tmp_path.iterdir() if p.name.startswith("newdir")]


def test_one_wording_for_the_overwrite_refusal(walk, tmp_path, capsys):
    from motionlab.core import files

    out = tmp_path / "x.bvh"
    out.write_text("old\n")
    code, _, err = _run(capsys, "convert", walk, "-o", out)
    with pytest.raises(FileExistsError) as library:
        files.check_output(out, what="-o")
    assert code == 2 and err.strip() == f"motionlab: error: {library.value}"


# ---------------------------------------------------------------------------- expand into one folder twice
def test_two_expand_runs_into_one_folder_keep_both_runs_rows(tmp_path):
    """The second run starts while the first is between batches; both runs' rows stay, and the first
    command then runs again cleanly (everything kept)."""
    from motionlab import retargeting
    from motionlab.retargeting import expand as ex
    from motionlab.retargeting.solver import SolverConfig

    ckpt, fast = retargeting.load_default("cpu"), SolverConfig(max_steps=2)
    for name, seed in (("a", 1), ("b", 2), ("c", 3)):
        bvh.save(tmp_path / f"{name}.bvh", synthetic.dataset(1, seed=seed, num_frames=24)[0])
    out = tmp_path / "out"
    child, tall = ex.characters(presets=["child"]), ex.characters(presets=["tall"])

    def second_run(index, rows):
        if index == 0:
            ex.expand([str(tmp_path / "c.bvh")], tall, out, ckpt, fast)

    first = ([str(tmp_path / "a.bvh"), str(tmp_path / "b.bvh")], child, out, ckpt, fast)
    ex.expand(*first, max_frames=24, on_batch=second_run)  # one clip per batch: two batches
    rows = {(r["character"], r["clip"]): r["status"] for r in ex.read_manifest(out)}
    assert rows == {("child", "a"): "ok", ("child", "b"): "ok", ("tall", "c"): "ok"}
    again = ex.expand(*first)
    assert again.failed == 0 and again.skipped == 2
    assert ex.expand([str(tmp_path / "c.bvh")], tall, out, ckpt, fast).skipped == 1


# ---------------------------------------------------------------------------- evaluate checks first
@pytest.mark.parametrize(("option", "value"), [("--targets", "Nobody"), ("--animations", "NoSuchClip")])
def test_evaluate_refuses_a_missing_character_or_animation_before_training(
    tmp_path, capsys, monkeypatch, option, value
):
    from tests.conftest import require_data

    def no_training(*args, **kwargs):
        raise AssertionError("trained before checking the inputs")

    import importlib

    monkeypatch.setattr(importlib.import_module("motionlab.retargeting.train"), "train", no_training)
    folder = require_data("mixamo")
    ckpt = tmp_path / "never.pt"
    code, _, err = _run(capsys, "evaluate", "--data", folder, "--checkpoint", ckpt, option, value)
    assert code == 2 and value in err and len(err.strip().splitlines()) == 1
    assert not ckpt.exists()


# ---------------------------------------------------------------------------- numbers: bounds and ranges
@pytest.mark.parametrize(
    "argv",
    [
        ["convert", "{walk}", "-o", "{out}", "--fps", "1e9"],
        ["convert", "{walk}", "-o", "{out}", "--fps", "1e-9"],
        ["synth", "walk", "-o", "{out}", "--seconds", "1e9"],
        ["synth", "walk", "-o", "{out}", "--seconds", "1e5", "--fps", "1000"],
        ["retarget", "{walk}", "--scale-legs", "1.2", "-o", "{out}", "--fps", "1e6"],
        ["retarget", "{walk}", "--scale", "1e6", "-o", "{out}"],
        ["graph-build", "--synthetic", "-o", "{out}", "--fps", "1e6"],
        ["view", "{walk}", "-o", "{movie}", "--size", "100000x100000"],
        ["view", "{walk}", "-o", "{movie}", "--stop", "-1"],
    ],
)
def test_numbers_beyond_reason_are_refused_with_their_range(walk, tmp_path, capsys, argv):
    argv = [a.format(walk=walk, out=tmp_path / "x.bvh", movie=tmp_path / "x.gif") for a in argv]
    code, _, err = _run(capsys, *argv)
    assert code == 2 and "Traceback" not in err
    assert argv[-2] in err or "asks for" in err  # names the option, or the size it would make
    assert " to " in err or "at most" in err or "or more" in err  # states the range or the bound
    assert [p.name for p in tmp_path.iterdir()] == []


def test_synth_seed_refusal_names_the_option(tmp_path, capsys):
    code, _, err = _run(capsys, "synth", "walk", "-o", tmp_path / "x.bvh", "--seed", "-1")
    assert code == 2 and "--seed" in err


def test_view_start_past_the_end_says_how_many_frames(walk, tmp_path, capsys):
    code, _, err = _run(capsys, "view", walk, "-o", tmp_path / "x.gif", "--start", "1000")
    assert code == 2 and "None" not in err and "30 frames" in err


def test_info_on_a_file_without_frames(walk, tmp_path, capsys):
    def no_frames(lines, i):
        lines[i - 1] = "Frames: 0"
        del lines[i + 1 :]

    path = _edited(walk, tmp_path, "empty.bvh", no_frames)
    code, out, err = _run(capsys, "info", path)
    assert code == 0 and "frames    0" in out and "no frames" in out, err


def test_a_checkpoint_that_is_not_one_is_named_without_torch_text(walk, tmp_path, capsys):
    code, _, err = _run(capsys, "retarget", walk, "--scale-legs", "1.2", "-o", tmp_path / "x.bvh", "--checkpoint", walk)
    assert code == 2 and "--checkpoint" in err and "torch" not in err and len(err.strip().splitlines()) == 1


def test_graph_build_refuses_a_folder_and_synthetic_together(walk, tmp_path, capsys):
    code, _, err = _run(capsys, "graph-build", walk.parent, "--synthetic", "-o", tmp_path / "g.mlgraph")
    assert code == 2 and "not both" in err and not (tmp_path / "g.mlgraph").exists()


def test_graph_build_counts_recorded_frames_apart_from_made_ones(tmp_path, capsys):
    from motionlab.motion_graphs import io

    code, out, _ = _run(capsys, "graph-build", "--synthetic", "-o", tmp_path / "g.mlgraph", "-q")
    g = io.load(tmp_path / "g.mlgraph")
    recorded = sum(c.num_frames for c in g.clips if c.kind != "intermediate")
    assert code == 0 and f"of {recorded} recorded frames alive" in out


def test_expand_writes_a_cmu_character_in_metres_in_gltf():
    """A CMU-skeleton character's outputs carry its file's unit, which the .glb writer turns into metres."""
    from motionlab.core import motion_files
    from motionlab.retargeting import expand as ex
    from tests.conftest import require_data

    (cmu,) = ex.characters(str(require_data("cmu", "131", "131_01.bvh")))
    (mixamo,) = ex.characters(str(require_data("mixamo", "Kaya", "Running.bvh")))
    assert (cmu.unit, mixamo.unit) == (motion_files.ASF_UNIT, motion_files.CM)


def test_a_retargeted_cmu_character_reads_back_at_its_size(tmp_path, capsys):
    """The 22 joints are written in centimetres: a BVH that kept CMU's unit under canonical names
    read back as a 0.22 m figure (info, convert, view), where its .glb was 1.28 m. ``expand``'s
    files and manifest say the same size."""
    from motionlab.core import motion_files, rest_pose
    from tests.conftest import require_data

    source, target = require_data("mixamo", "Aj", "Run_Arc_Left.bvh"), require_data("cmu", "131", "131_02.bvh")
    out = tmp_path / "out.bvh"
    code, _, err = _run(capsys, "retarget", source, "--target", target, "--method", "copy", "-o", out, "-q")
    assert code == 0, err
    standing = rest_pose.standing(humanoid.to_canonical(motion_files.load_metres(target)))[0]
    assert bvh.load(out).skeleton.height() == pytest.approx(standing.skeleton.height(), rel=1e-4)  # 1.24 m
    code, _, err = _run(
        capsys, "expand", source, "--characters", f"CMU={target}", "--network", "synthetic", "--steps", "2",
        "-o", tmp_path / "x", "-q",
    )  # fmt: skip
    assert code == 0, err
    assert bvh.load(tmp_path / "x" / "CMU" / "Run_Arc_Left.bvh").skeleton.height() == pytest.approx(
        standing.skeleton.height(), rel=1e-4
    )


def test_manifest_quality_is_measured_in_metres_of_the_target():
    """Feet 2 units up in a CMU file (11 cm) do not touch the ground; read as centimetres they did."""
    from types import SimpleNamespace

    from motionlab.core import motion_files
    from motionlab.retargeting import batching

    pos = np.zeros((30, 22, 3))
    pos[:, :, 1] = 0.02  # as read: 2 file units
    pos[:, :, 0] = np.linspace(0.0, 0.3, 30)[:, None]  # sliding 0.3 units a second
    result = SimpleNamespace(positions=pos, motion=SimpleNamespace(fps=30.0))
    assert batching.quality(result)["skating_cm_s"] > 0  # centimetres: on the ground, sliding
    assert batching.quality(result, motion_files.ASF_UNIT)["skating_cm_s"] == 0.0  # 11 cm up: in the air


def test_an_input_that_is_a_named_pipe_is_refused_not_waited_on(tmp_path, capsys):
    os.mkfifo(tmp_path / "pipe.bvh")
    code, _, err = _run(capsys, "convert", tmp_path / "pipe.bvh", "-o", tmp_path / "x.bvh")
    assert code == 2 and "named pipe" in err and not (tmp_path / "x.bvh").exists()


def test_graph_build_refuses_a_folder_too_long_at_the_frame_rate_before_loading(tmp_path, capsys, monkeypatch):
    def no_loading(*args, **kwargs):
        raise AssertionError("loaded before checking the size")

    monkeypatch.setattr("motionlab.motion_graphs.clips.load_folder", no_loading)
    (tmp_path / "clips").mkdir()
    header = "HIERARCHY\nROOT Hips\n{\n}\nMOTION\nFrames: 100000000\nFrame Time: 0.0333333\n"
    (tmp_path / "clips" / "walk_normal.bvh").write_text(header)
    code, _, err = _run(capsys, "graph-build", tmp_path / "clips", "-o", tmp_path / "g.mlgraph", "--fps", "1000")
    assert code == 2 and "--fps 1000" in err and "at most" in err and not (tmp_path / "g.mlgraph").exists()
