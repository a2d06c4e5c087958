"""Atomic writes: no partial file, no overwrite without asking, and no temporary files left behind,
not even by a writer killed with SIGKILL (the next write to the same file removes them)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from motionlab.core import bvh, files, humanoid

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)


def test_atomic_write_replaces_in_one_step_and_keeps_the_old_file_on_error(tmp_path):
    path = tmp_path / "a.txt"
    files.atomic_write(path, lambda f: f.write("one"))
    with pytest.raises(FileExistsError, match="a.txt exists"):
        files.atomic_write(path, lambda f: f.write("two"))

    def fail(f):
        f.write("half")
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError):
        files.atomic_write(path, fail, overwrite=True)
    assert path.read_text() == "one"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_checks_name_the_problem(tmp_path):
    with pytest.raises(IsADirectoryError, match="is a folder; expected a file name"):
        files.check_output(tmp_path, overwrite=True)
    with pytest.raises(FileNotFoundError, match="folder .*missing for the output x.bvh does not exist"):
        files.check_output(tmp_path / "missing" / "x.bvh")
    with pytest.raises(IsADirectoryError, match="is a folder; expected a file"):
        files.check_input(tmp_path, "BVH")
    with pytest.raises(FileNotFoundError, match="BVH file .*nope.bvh not found"):
        files.check_input(tmp_path / "nope.bvh", "BVH")


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temporary_files_of_dead_writers_are_removed(tmp_path):
    path = tmp_path / "clip.bvh"
    stale = tmp_path / f".clip.bvh.{_dead_pid()}.abc123{files.TMP_SUFFIX}"
    stale.write_text("half a file")
    alive = tmp_path / f".clip.bvh.{os.getppid()}.xyz{files.TMP_SUFFIX}"  # a running process: kept
    alive.write_text("someone is writing")
    other = tmp_path / f".other.bvh.{_dead_pid()}.abc{files.TMP_SUFFIX}"  # another destination: kept
    other.write_text("not ours")
    files.atomic_write(path, lambda f: f.write("whole"))
    assert path.read_text() == "whole"
    assert not stale.exists() and alive.exists() and other.exists()


def test_kill_9_during_a_write_then_the_next_write_cleans_up(tmp_path):
    path = tmp_path / "out.txt"
    code = (
        "import sys, time\n"
        "from motionlab.core import files\n"
        "def slow(f):\n"
        "    f.write('partial'); f.flush(); print('writing', flush=True); time.sleep(60)\n"
        f"files.atomic_write({str(path)!r}, slow)\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, env=env, text=True)
    try:
        assert proc.stdout.readline().strip() == "writing"
        temps = [p for p in tmp_path.iterdir() if p.name.endswith(files.TMP_SUFFIX)]
        assert len(temps) == 1 and not path.exists()
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    time.sleep(0.05)
    assert temps[0].exists()  # a killed writer cannot clean up after itself ...
    files.atomic_write(path, lambda f: f.write("complete"))
    assert path.read_text() == "complete"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]  # ... the next write does


def test_bvh_save_uses_the_same_rule(tmp_path):
    from motionlab import synthetic

    m = synthetic.generate("idle", humanoid.canonical_skeleton(), num_frames=3, seed=0)
    stale = tmp_path / f".idle.bvh.{_dead_pid()}.q{files.TMP_SUFFIX}"
    stale.write_text("HIERARCHY\nROOT")
    bvh.save(tmp_path / "idle.bvh", m)
    assert [p.name for p in tmp_path.iterdir()] == ["idle.bvh"]


def test_atomic_write_all_writes_every_file_or_none(tmp_path):
    old = tmp_path / "a.bvh"
    old.write_text("old a")

    def fail(f):
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        files.atomic_write_all(
            [(old, lambda f: f.write("new a"), False, "output"), (tmp_path / "b.npz", fail, True, "--npz file")],
            overwrite=True,
        )
    assert old.read_text() == "old a"  # the first file was not replaced either
    assert [p.name for p in tmp_path.iterdir()] == ["a.bvh"]
    files.atomic_write_all(
        [(old, lambda f: f.write("new a"), False, "output"), (tmp_path / "b.npz", lambda f: f.write(b"b"), True, "x")],
        overwrite=True,
    )
    assert old.read_text() == "new a" and (tmp_path / "b.npz").read_bytes() == b"b"


def test_nothing_changes_the_process_umask(tmp_path):
    """Importing the package and writing a file never set the umask (it is shared by every thread)."""
    code = (
        "import os\n"
        "def refuse(*args):\n"
        "    raise AssertionError('the umask was changed')\n"
        "os.umask = refuse\n"
        "import motionlab.retargeting.expand, motionlab.viz.export\n"
        "from motionlab.core import files\n"
        f"files.atomic_write({str(tmp_path / 'x.txt')!r}, lambda f: f.write('x'))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "x.txt").stat().st_mode & 0o777 == 0o666 & ~_current_umask()


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def test_a_writer_that_needs_a_name_gets_one_with_the_suffix(tmp_path):
    seen = []

    def fill(tmp):
        seen.append(tmp)
        tmp.write_bytes(b"GIF89a")

    path = files.atomic_write_file(tmp_path / "movie.gif", fill)
    assert path.read_bytes() == b"GIF89a" and seen[0].suffix == ".gif" and seen[0].parent == tmp_path
    assert [p.name for p in tmp_path.iterdir()] == ["movie.gif"]
    with pytest.raises(FileExistsError, match="add --force"):
        files.atomic_write_file(tmp_path / "movie.gif", fill)
