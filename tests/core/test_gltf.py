"""glTF export: every file is read back by an independent reader (pygltflib + the tests' own TRS
composition in ``tests/gltf_reader.py``) and must put the joints where motionlab's FK does."""

from __future__ import annotations

import functools
import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.core import bvh, gltf, humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from tests.conftest import require_data
from tests.gltf_reader import accessor, assert_glb_matches, read


@pytest.fixture(scope="module")
def walk() -> Motion:
    skeleton = humanoid.scale_bones(humanoid.canonical_skeleton(1.75), legs=1.2)
    motion = synthetic.generate("walk", skeleton, num_frames=45, fps=30, seed=0)
    motion.name = "walk"
    return motion


def test_convention_pin_quaternions_are_written_xyzw():
    """+90 degrees about z, (w, x, y, z) = (c, 0, 0, s), is stored as (0, 0, s, c)."""
    sk = Skeleton(("root", "tip"), [-1, 0], [[0, 0, 0], [1, 0, 0]])
    rot = np.tile(quat.IDENTITY, (1, 2, 1))
    rot[0, 0] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    motion = Motion(sk, rot, np.zeros((1, 3)), fps=24)
    g = assert_glb_matches(gltf.dumps(motion), motion)
    root_rotation = next(c for c in g.animations[0].channels if c.target.node == 0 and c.target.path == "rotation")
    stored = accessor(g, g.animations[0].samplers[root_rotation.sampler].output)[0]
    np.testing.assert_allclose(stored, [0, 0, np.sqrt(0.5), np.sqrt(0.5)], atol=1e-7)
    # the tip, 1 m along x at rest, is at +y after the turn (right-handed, Y up)
    np.testing.assert_allclose(motion.global_positions()[0, 1], [0, 1, 0], atol=1e-12)


def test_synthetic_walk_matches_fk(walk, tmp_path):
    path = gltf.save(tmp_path / "walk.glb", walk)
    g = assert_glb_matches(path, walk, frames=range(0, walk.num_frames, 4))
    assert g.asset.version == "2.0"
    assert [n.name for n in g.nodes[: walk.skeleton.num_joints]] == list(walk.skeleton.names)
    assert g.animations[0].name == "walk"
    paths = [(c.target.node, c.target.path) for c in g.animations[0].channels]
    assert paths.count((0, "translation")) == 1
    assert sum(p == "rotation" for _, p in paths) == walk.skeleton.num_joints


def test_glb_layout(walk):
    """12-byte header (magic, version 2, total length), a JSON chunk, then a BIN chunk, all 4-byte aligned."""
    data = gltf.dumps(walk)
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_length, json_type = struct.unpack_from("<I4s", data, 12)
    bin_length, bin_type = struct.unpack_from("<I4s", data, 20 + json_length)
    assert (json_type, bin_type) == (b"JSON", b"BIN\0")
    assert json_length % 4 == 0 and bin_length % 4 == 0
    assert 28 + json_length + bin_length == len(data)


def test_local_pos_gives_every_joint_a_translation_channel():
    sk = Skeleton(("hips", "spine", "head"), [-1, 0, 1], [[0, 1, 0], [0, 0.2, 0], [0, 0.3, 0]])
    rng = np.random.default_rng(0)
    T = 6
    rot = quat.normalize(rng.normal(size=(T, 3, 4)))
    local_pos = np.broadcast_to(sk.offsets, (T, 3, 3)).copy()
    local_pos[:, 1, 1] += np.linspace(0, 0.1, T)  # a stretching spine
    motion = Motion(sk, rot, rng.normal(size=(T, 3)), fps=50, local_pos=local_pos)
    g = assert_glb_matches(gltf.dumps(motion), motion, frames=range(T))
    assert sum(c.target.path == "translation" for c in g.animations[0].channels) == 3


def test_one_frame_and_root_only():
    """a -> b edge cases: a one-frame clip and a skeleton with a single joint."""
    sk = Skeleton(("root",), [-1], [[0, 0, 0]])
    motion = Motion(sk, quat.IDENTITY[None, None], [[1.0, 2.0, 3.0]], fps=30)
    assert_glb_matches(gltf.dumps(motion), motion)


def test_inputs_unchanged(walk):
    before = (walk.local_rot.copy(), walk.root_pos.copy())
    gltf.dumps(walk)
    np.testing.assert_array_equal(walk.local_rot, before[0])
    np.testing.assert_array_equal(walk.root_pos, before[1])


def test_bad_input_is_refused_by_name(walk):
    with pytest.raises(TypeError, match="expected a motionlab Motion, got ndarray"):
        gltf.dumps(walk.local_rot)
    rot = walk.local_rot.copy()
    rot[3, 5] = np.nan
    with pytest.raises(ValueError, match="local_rot is not finite at frame 3"):
        gltf.dumps(walk.copy(local_rot=rot))
    zero = walk.copy()
    zero.local_rot[3, 5] = 0.0  # set in place: a Motion refuses it when made
    with pytest.raises(ValueError, match=f"joint {walk.skeleton.names[5]!r} at frame 3 is a zero quaternion"):
        gltf.dumps(zero)
    with pytest.raises(ValueError, match="no frames"):
        gltf.dumps(walk[0:0])


def test_refusing_writes_nothing(walk, tmp_path):
    with pytest.raises(ValueError, match=r"must end in \.glb, got 'walk.gltf'"):
        gltf.save(tmp_path / "walk.gltf", walk)
    bad = walk.copy(root_pos=np.full_like(walk.root_pos, np.inf))
    with pytest.raises(ValueError, match="root_pos is not finite"):
        gltf.save(tmp_path / "walk.glb", bad)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        gltf.save(tmp_path / "missing" / "walk.glb", walk)
    assert list(tmp_path.iterdir()) == []
    path = gltf.save(tmp_path / "walk.glb", walk)
    before = path.read_bytes()
    with pytest.raises(FileExistsError, match="exists; add --force"):
        gltf.save(path, walk[:10])
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["walk.glb"]
    gltf.save(path, walk[:10], overwrite=True)
    assert_glb_matches(path, walk[:10])


@pytest.mark.realdata
def test_real_mixamo_clip_matches_fk(tmp_path):
    folder = require_data("mixamo", "Aj")
    motion = bvh.load(sorted(folder.glob("*.bvh"))[0])
    assert_glb_matches(gltf.save(tmp_path / "aj.glb", motion), motion)


@pytest.mark.realdata
def test_real_bandai_namco_clip_matches_fk(tmp_path):
    folder = require_data("bandai_namco")
    path = sorted(folder.rglob("*.bvh"))[0]
    motion = bvh.load(path)
    assert motion.local_pos is not None  # this set animates every joint's position: one channel each
    g = assert_glb_matches(gltf.save(tmp_path / "bn.glb", motion), motion)
    assert read(tmp_path / "bn.glb").animations[0].extras["fps"] == pytest.approx(motion.fps)
    assert sum(c.target.path == "translation" for c in g.animations[0].channels) == motion.skeleton.num_joints


THREE_PACKAGE = Path(__file__).resolve().parents[2] / "build" / "web-npm" / "node_modules" / "three"


def _threejs_positions(path: Path, times) -> np.ndarray:
    """World joint positions (len(times), J, 3) that three.js's GLTFLoader and AnimationMixer compute."""
    if shutil.which("node") is None or not (THREE_PACKAGE / "package.json").is_file():
        pytest.skip("needs node and three.js from npm: bash scripts/vendor_three.sh (the docs build runs it)")
    script = Path(__file__).with_name("gltf_threejs.mjs")
    run = subprocess.run(
        ["node", str(script), str(THREE_PACKAGE), str(path), *(repr(float(t)) for t in times)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    return np.array(json.loads(run.stdout)["positions"])


@pytest.mark.parametrize("source", ["synthetic", "mixamo", "bandai_namco"])
def test_threejs_puts_the_joints_where_fk_does(walk, tmp_path, source):
    if source == "mixamo":
        motion = bvh.load(sorted(require_data("mixamo", "Aj").glob("*.bvh"))[0])
    elif source == "bandai_namco":
        motion = bvh.load(sorted(require_data("bandai_namco").rglob("*.bvh"))[0])
    else:
        motion = walk
    path = gltf.save(tmp_path / "clip.glb", motion)
    frames = sorted({0, motion.num_frames // 2, motion.num_frames - 1})
    got = _threejs_positions(path, [k / motion.fps for k in frames])
    err = np.abs(got - motion.global_positions()[frames]).max()
    assert err <= 1e-4 * motion.skeleton.height(), f"three.js joints {err:.3g} m from FK"


@functools.cache
def _blender_has_numpy() -> bool:
    """Whether the Python inside Blender imports numpy (Debian's ``blender`` without ``python3-numpy`` does not)."""
    run = subprocess.run(
        ["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", "import numpy"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    return run.returncode == 0


@pytest.mark.parametrize("source", ["synthetic", "bandai_namco"])
def test_blender_imports_the_joints_where_fk_does(walk, tmp_path, source):
    """Blender's own glTF importer (skipped where Blender is not installed; Z-up inside Blender)."""
    if shutil.which("blender") is None:
        pytest.skip("needs Blender on PATH (Debian: apt-get install blender python3-numpy)")
    if not _blender_has_numpy():
        pytest.skip(
            "Blender's Python has no numpy, which its glTF importer needs (Debian: apt-get install python3-numpy)"
        )
    motion = walk if source == "synthetic" else bvh.load(sorted(require_data("bandai_namco").rglob("*.bvh"))[0])
    path = gltf.save(tmp_path / "clip.glb", motion)
    frames = sorted({0, motion.num_frames // 2, motion.num_frames - 1})
    script, out = Path(__file__).with_name("gltf_blender.py"), tmp_path / "blender.json"
    run = subprocess.run(
        ["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python", str(script), "--",
         str(path), repr(motion.fps), str(out), *map(str, frames)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    result = json.loads(out.read_text())
    z_up = np.array(result["positions"])
    got = np.stack([z_up[..., 0], z_up[..., 2], -z_up[..., 1]], axis=-1)  # Blender (x, y, z) = glTF (x, -z, y)
    order = [motion.skeleton.names.index(n) for n in result["names"]]
    err = np.abs(got - motion.global_positions()[frames][:, order]).max()
    assert err <= 1e-4 * motion.skeleton.height(), f"Blender {result['blender']}: joints {err:.3g} m from FK"


@pytest.mark.parametrize(("status", "has"), [(0, True), (1, False)])
def test_blender_without_numpy_is_told_apart(tmp_path, monkeypatch, status, has):
    """The Blender test skips, with the reason, where Blender's Python cannot import numpy."""
    fake = tmp_path / "blender"
    fake.write_text(f"#!/bin/sh\nexit {status}\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{tmp_path}:/usr/bin:/bin")
    _blender_has_numpy.cache_clear()
    try:
        assert _blender_has_numpy() is has
    finally:
        _blender_has_numpy.cache_clear()
