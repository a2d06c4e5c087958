"""Synthesis continuity, save/load round trip, the CLI."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from motionlab.cli import main
from motionlab.motion_graphs import io, search, synthesis


@pytest.fixture(scope="module")
def result(sgraph):
    return search.search(sgraph, "walk:normal:120,walk:happy:120,run:normal:120")


def test_synthesis_is_continuous(sgraph, result):
    m = synthesis.synthesize(sgraph, result.pieces)
    assert m.num_frames == result.num_frames
    pos = m.global_positions()
    root_step = np.linalg.norm(np.diff(m.root_pos[:, [0, 2]], axis=0), axis=1)
    # the root never jumps: no step much larger than the clips' own fastest step
    own = max(
        np.linalg.norm(np.diff(sgraph.root_pos[c.start : c.stop, [0, 2]], axis=0), axis=1).max() for c in sgraph.clips
    )
    assert root_step.max() < 1.5 * own
    q = synthesis.transition_quality(m, result.transitions())
    assert np.isfinite(q["smoothness"]) and q["max_jump"] <= q["max_jump_all"] + 1e-12
    # without root alignment the character would teleport
    raw = np.concatenate(
        [sgraph.root_pos[sgraph.clips[c].start + a : sgraph.clips[c].start + b + 1] for c, a, b in result.pieces]
    )
    assert np.linalg.norm(np.diff(raw[:, [0, 2]], axis=0), axis=1).max() > root_step.max()
    assert np.all(np.isfinite(pos))


def test_blending_smooths_transitions(sgraph, result):
    hard = synthesis.synthesize(sgraph, result.pieces, blend=0, fix_feet=False)
    soft = synthesis.synthesize(sgraph, result.pieces, blend=8, fix_feet=False)
    t = result.transitions()
    assert (
        synthesis.transition_quality(soft, t)["smoothness"]
        <= synthesis.transition_quality(hard, t)["smoothness"] * 1.05
    )


def test_save_load_round_trip(sgraph, result, tmp_path):
    path = io.save(tmp_path / "g", sgraph)
    assert path.suffix == ".mlgraph"
    with pytest.raises(FileExistsError):
        io.save(path, sgraph)
    g2 = io.load(path)
    assert g2.summary() == sgraph.summary()
    assert g2.table == sgraph.table
    np.testing.assert_array_equal(g2.src, sgraph.src)
    np.testing.assert_allclose(g2.local_rot, sgraph.local_rot, atol=1e-6)
    assert search.search(g2, "walk:normal:120,walk:happy:120,run:normal:120").pieces == result.pieces
    bad = tmp_path / "bad.mlgraph"
    bad.write_bytes(b"not a graph")
    with pytest.raises(ValueError, match="not a motion graph"):
        io.load(bad)


def test_saved_arrays_map_aligned(sgraph, tmp_path):
    """Every array of a saved graph starts on an io.ALIGN-byte boundary of the file, so the
    mapped arrays are aligned (NumPy runs slow unaligned loops on the others); the file is still
    a plain .npz, and a format-3 file written by np.savez (the previous writer) still loads."""
    import zipfile

    path = io.save(tmp_path / "g", sgraph)
    g = io.load(path)
    for name in ("local_rot", "root_pos", "alive", "src", "dst", "cost", "kind"):
        a = getattr(g, name)
        assert isinstance(a, np.memmap) and a.flags["ALIGNED"] and a.ctypes.data % io.ALIGN == 0, name
    with zipfile.ZipFile(path) as z:
        assert z.testzip() is None
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    np.testing.assert_array_equal(arrays["src"], sgraph.src)
    plain = tmp_path / "plain.mlgraph"
    with open(plain, "wb") as fh:
        np.savez(fh, **arrays)
    g2 = io.load(plain)
    assert g2.table == sgraph.table
    for name in ("local_rot", "src", "dst", "cost", "alive"):
        np.testing.assert_array_equal(getattr(g2, name), getattr(g, name))


def test_cli_build_search(tmp_path, capsys):
    g = tmp_path / "s.mlgraph"
    assert main(["graph-build", "--synthetic", "-o", str(g)]) == 0
    assert main(["graph-build", "--synthetic", "-o", str(g)]) == 2  # no overwrite without --force
    out = tmp_path / "o.bvh"
    assert main(["graph-search", str(g), "--request", "walk:happy:90,run:tired:60", "-o", str(out)]) == 0
    assert out.is_file()
    assert main(["graph-search", str(g), "--request", "walk:zany:90", "-o", str(tmp_path / "x.bvh")]) == 2
    err = capsys.readouterr().err
    assert "no style 'zany'" in err
    assert main(["graph-info", str(g)]) == 0
    gs = tmp_path / "std.mlgraph"
    assert main(["graph-build", "--synthetic", "--standard", "-o", str(gs)]) == 0
    assert (
        main(["graph-search", str(gs), "--request", "walk:normal:60,walk:happy:60", "-o", str(tmp_path / "s.bvh")]) == 0
    )


def test_damaged_graph_files_are_named(sgraph, tmp_path, capsys):
    good = io.save(tmp_path / "g", sgraph)
    raw = good.read_bytes()
    cases = {
        "truncated.mlgraph": raw[: len(raw) // 3],
        "garbage.mlgraph": b"\x93NUMPY garbage that is no zip" * 10,
        "empty.mlgraph": b"",
    }
    for name, payload in cases.items():
        path = tmp_path / name
        path.write_bytes(payload)
        with pytest.raises(ValueError, match=name) as e:
            io.load(path)
        assert "allow_pickle" not in str(e.value)
        for argv in (["graph-info", str(path)], ["graph-search", str(path), "--request", "walk:normal:10",
                                                  "-o", str(tmp_path / "x.bvh")]):  # fmt: skip
            assert main(argv) == 2
            err = capsys.readouterr().err
            assert name in err and "Traceback" not in err and "allow_pickle" not in err
    assert not (tmp_path / "x.bvh").exists()


def test_cli_refuses_overlong_request(tmp_path, capsys):
    g = tmp_path / "s.mlgraph"
    assert main(["graph-build", "--synthetic", "-o", str(g)]) == 0
    capsys.readouterr()
    assert main(["graph-search", str(g), "--request", "walk:angry:100000000", "-o", str(tmp_path / "x.bvh")]) == 2
    err = capsys.readouterr().err
    assert "--request" in err and "at most 100000 frames" in err and "MAX_FRAMES" not in err
    assert not (tmp_path / "x.bvh").exists()


def test_info_counts_the_clips_built_from(tmp_path, capsys):
    g = tmp_path / "s.mlgraph"
    assert main(["graph-build", "--synthetic", "-o", str(g), "--report", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out
    n = int(out.split("using ")[1].split()[0])
    assert f"from {n} clips" in out
    assert "largest strongly connected component: " in out and "largest strongly connected component of walk: " in out
    assert main(["graph-info", str(g)]) == 0
    info = json.loads("{" + capsys.readouterr().out.split("\n{", 1)[1])
    assert info["clips"] == n and info["intermediate_clips"] > 0
    rep = json.loads((tmp_path / "r.json").read_text())
    assert set(rep["behaviours"]) == {"idle", "walk", "run"}


def test_interrupted_search_writes_nothing(tmp_path, capsys, monkeypatch):
    g = tmp_path / "s.mlgraph"
    assert main(["graph-build", "--synthetic", "-o", str(g)]) == 0

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(search, "search", interrupted)
    out = tmp_path / "x.bvh"
    assert main(["graph-search", str(g), "--request", "walk:normal:90", "-o", str(out)]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == [g]


def test_old_format_is_named(sgraph, tmp_path):
    path = io.save(tmp_path / "g", sgraph)
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(arrays["meta"].tobytes().decode("utf-8"))
    meta["format"] = "motionlab-graph-1"
    arrays["meta"] = np.array(json.dumps(meta))
    old = tmp_path / "old.mlgraph"
    with open(old, "wb") as fh:
        np.savez(fh, **arrays)
    with pytest.raises(ValueError, match="old.mlgraph.*motionlab-graph-1.*rebuild"):
        io.load(old)


def test_a_count_the_graph_cannot_meet_is_refused_by_name(sgraph, tmp_path, capsys):
    """walk:normal:4 before a run: the shortest route out of the walk is longer than 4 + 2 frames."""
    result = search.search(sgraph, "walk:normal:4,run:normal:60")
    assert result.misses == [0] and "outside the ±2 allowed" in result.report()
    assert search.search(sgraph, "walk:normal:120,run:normal:60").misses == []
    g, out = io.save(tmp_path / "g", sgraph), tmp_path / "o.bvh"
    argv = ["graph-search", str(g), "--request", "walk:normal:4,run:normal:60", "-o", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"walk:normal asks for 4 frames, and the nearest walk this graph has gives {result.achieved[0]}" in err
    assert "--keep-misses" in err and not out.exists()
    assert main([*argv, "--keep-misses"]) == 0
    assert "written as asked by --keep-misses" in capsys.readouterr().err and out.is_file()


@pytest.mark.parametrize("block", [None, 64])
def test_a_flipped_byte_in_an_array_is_named(sgraph, tmp_path, capsys, monkeypatch, block):
    """Also with the checksum read in many small blocks (``block``), as large arrays are."""
    if block:
        monkeypatch.setattr(io, "_CRC_BLOCK", block)
    path = io.save(tmp_path / "g", sgraph)
    io.load(path)  # the file as written passes
    raw = bytearray(path.read_bytes())
    with zipfile.ZipFile(path) as z:
        info = z.getinfo("root_pos.npy")
    raw[info.header_offset + 30 + len(info.filename) + len(info.extra) + 200] ^= 0xFF  # inside the array's data
    path.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match="'root_pos' array"):
        io.load(path)
    assert main(["graph-info", str(path)]) == 2 and "damaged" in capsys.readouterr().err
    io.load(path, verify=False)  # the check left to the caller ...
    with pytest.raises(ValueError, match=f"{path.name}.*'root_pos' array"):
        io.verify(path)  # ... which finds it
    out = tmp_path / "x.bvh"
    argv = ["graph-search", str(path), "--request", "walk:normal:60", "-o", str(out)]
    assert main(argv) == 2  # graph-search checks in a thread while it searches, and writes nothing
    assert "'root_pos' array" in capsys.readouterr().err and not out.exists()

    def garbled(*args, **kwargs):  # a search that the damaged bytes sent astray: the damage is named
        raise IndexError("index 10**9 is out of bounds")

    monkeypatch.setattr(search, "search", garbled)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "'root_pos' array" in err and "Traceback" not in err and not out.exists()


def test_the_structure_table_counts_the_graph_as_built(sgraph):
    """Every cell's alive frames, transitions and loops are the graph's, after the last stage."""
    live = sgraph.alive[sgraph.src] & sgraph.alive[sgraph.dst]
    for styles in sgraph.table["behaviours"].values():
        for cell in styles.values():
            st, sp = cell["start"], cell["start"] + cell["frames"]
            inside = live & (sgraph.src >= st) & (sgraph.src < sp) & (sgraph.dst >= st) & (sgraph.dst < sp)
            assert cell["alive"] == int(sgraph.alive[st:sp].sum())
            assert cell["transitions"] == int(inside.sum())
            assert sum(t["alive"] for t in cell["takes"]) == cell["alive"]


@pytest.mark.parametrize("name", ["g.bvh", "g.GLB", "g.json"])
def test_a_graph_is_not_written_under_a_motion_or_report_name(tmp_path, capsys, name):
    """A graph written as ``g.bvh`` was then skipped, with a warning, by the next build of its folder."""
    assert main(["graph-build", "--synthetic", "-o", str(tmp_path / name), "-q"]) == 2
    assert "a graph is written as .mlgraph" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_build_names_skipped_files_reads_any_case_and_protects_its_inputs(library, tmp_path, capsys):
    from motionlab.core import bvh

    folder = tmp_path / "clips"
    folder.mkdir()
    walks = [m for m in library if m.name.startswith("walk_normal")]
    bvh.save(folder / "walk_normal_001.BVH", walks[0])
    bvh.save(folder / "walk normal (copy).bvh", walks[0])
    out = tmp_path / "g.mlgraph"
    assert main(["graph-build", str(folder), "-o", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "skipped 1 of 2 BVH files" in err and "walk normal (copy).bvh" in err
    assert io.load(out).info["input_clips"] == 1
    clip = folder / "walk_normal_001.BVH"
    before = clip.read_bytes()
    assert main(["graph-build", str(folder), "-o", str(out), "--report", str(clip), "--force", "-q"]) == 2
    assert "is the input clip file" in capsys.readouterr().err and clip.read_bytes() == before


def test_build_refuses_a_clip_without_frames_and_a_graph_with_nothing_alive(library, tmp_path, capsys):
    from motionlab.core import bvh

    folder = tmp_path / "clips"
    folder.mkdir()
    walk = next(m for m in library if m.name.startswith("walk_normal"))
    bvh.save(folder / "walk_normal_001.bvh", walk)
    assert main(["graph-build", str(folder), "-o", str(tmp_path / "g"), "--fps", "1", "-q"]) == 2
    assert "none of the" in capsys.readouterr().err and not (tmp_path / "g.mlgraph").exists()
    header = bvh.dumps(walk[0:1]).split("Frames:")[0]
    (folder / "walk_normal_002.bvh").write_text(header + "Frames: 0\nFrame Time: 0.0333333\n")
    assert main(["graph-build", str(folder), "-o", str(tmp_path / "g"), "-q"]) == 2
    assert "walk_normal_002.bvh has no frames" in capsys.readouterr().err


def test_a_style_with_nothing_alive_is_named(sgraph, tmp_path):
    g = io.load(io.save(tmp_path / "g", sgraph))
    g.table["behaviours"]["run"]["normal"]["alive"] = 0
    with pytest.raises(search.SearchError, match="run/normal has no frame left alive"):
        search.search(g, "walk:normal:30,run:normal:30")


def test_build_reads_behaviour_folders(tmp_path, capsys):
    """Xia et al.'s layout, ``<behaviour>/<style>_<numbers>.bvh``: without ``--behaviour-folders``
    its files give no label and are skipped with the option named (they used to read as behaviour
    ``angry``, style ``13``); with it, every behaviour is its folder's."""
    from tests.conftest import require_data

    xia = require_data("xia")
    out = tmp_path / "xia.mlgraph"
    assert main(["graph-build", str(xia), "-o", str(out), "-q"]) == 0
    err = capsys.readouterr().err  # the two left: walk/normal_ganimator, proud_…
    assert "skipped 9 of 11 BVH files" in err and "The first: cannot read behaviour and style from clip name" in err
    assert main(["graph-build", str(xia), "-o", str(out), "-q", "--force", "--behaviour-folders"]) == 0
    table = io.load(out).table["behaviours"]
    assert {b: sorted(styles) for b, styles in table.items()} == {
        "jump": ["neutral"],
        "punch": ["depressed"],
        "run": ["angry", "depressed", "old"],
        "walk": ["neutral", "normal-ganimator", "proud-ganimator", "sexy", "strutting"],
    }
    assert len(table["walk"]["sexy"]["takes"]) == 2


def test_a_cmu_skeleton_folder_is_read_in_metres(library, tmp_path, capsys):
    """A CMU-skeleton file's length unit is not the centimetre (``motion_files.ASF_UNIT``): its
    clips are read in metres, the unit of every threshold of a graph (they were read as
    centimetres, a walker 0.18 of its size, so the 0.04 m distance threshold let in poses about
    5.6 times further apart), and the search's output is the walker's size."""
    from motionlab.core import bvh, motion_files
    from motionlab.motion_graphs import clips

    cmu_names = {"Spine": "LowerBack", "Spine1": "Spine", "Spine2": "Spine1", "Head": "Neck1"}
    factor = motion_files.CM / motion_files.ASF_UNIT  # metres -> ASF units, as bvh.load reads them
    folder = tmp_path / "clips"
    folder.mkdir()
    walks = [m for m in library if m.name.startswith("walk_normal")]
    for i, m in enumerate(walks):
        sk = m.skeleton.renamed([cmu_names.get(n, n) for n in m.skeleton.names]).scaled(factor)
        bvh.save(folder / f"walk_normal_{i + 1:03d}.bvh", m.copy(skeleton=sk, root_pos=m.root_pos * factor))
    loaded = clips.load_folder(folder)
    assert [motion_files.file_unit(bvh.load(p).skeleton) for p in sorted(folder.iterdir())] == [
        motion_files.ASF_UNIT
    ] * len(walks)
    for got, want in zip(loaded, walks):
        np.testing.assert_allclose(got.root_pos, want.root_pos, atol=1e-5)
    graph, out = tmp_path / "g.mlgraph", tmp_path / "w.bvh"
    assert main(["graph-build", str(folder), "-o", str(graph), "-q"]) == 0
    assert main(["graph-search", str(graph), "--request", "walk:normal:60", "-o", str(out), "-q"]) == 0
    hips = bvh.load(out).root_pos[:, 1]  # a 22-joint output, written in centimetres
    assert np.median(hips) == pytest.approx(np.median(walks[0].root_pos[:, 1]), rel=0.05)
