"""``motionlab fill-gaps``: fills dropped frames, reports them, never overwrites without --force."""

import re

import numpy as np
import pytest

from motionlab.cli import main
from motionlab.core import bvh
from tests.conftest import require_data

from .conftest import toy_motion


@pytest.fixture
def dropped(tmp_path):
    m = toy_motion(120)
    keep = np.r_[0:50, 58:120]
    path = tmp_path / "dropped.bvh"
    bvh.save(path, m[keep])
    return path


def test_fill_gaps_writes_filled_file(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "filled 1 gap(s)" in text and "frames 50-" in text
    filled = bvh.load(out)
    assert filled.num_frames > 112
    assert np.all(np.isfinite(filled.local_rot))


def test_fill_gaps_refuses_to_overwrite(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    out.write_text("keep me")
    assert main(["fill-gaps", str(dropped), "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "keep me"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--method", "hermite"]) == 0


def test_fill_gaps_user_errors(dropped, tmp_path, capsys):
    assert main(["fill-gaps", str(tmp_path / "nope.bvh"), "-o", str(tmp_path / "o.bvh")]) == 2
    assert main(["fill-gaps", str(dropped), "-o", str(tmp_path / "o.bvh"), "--method", "graph"]) == 2
    assert "--action" in capsys.readouterr().err


def test_fill_gaps_with_graph(dropped, tmp_path, capsys):
    clip = tmp_path / "walk.bvh"
    bvh.save(clip, toy_motion(80, phase=0.7))
    out = tmp_path / "g.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--method", "graph", "--action", f"walk={clip}"]) == 0
    assert "via walk" in capsys.readouterr().out


@pytest.mark.parametrize("flag", ["--threshold", "--delta", "--factor"])
@pytest.mark.parametrize("value", ["-1", "0", "nan"])
def test_fill_gaps_refuses_nonsense_delta(dropped, tmp_path, capsys, flag, value):
    out = tmp_path / "o.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), flag, value]) == 2
    assert "--delta must be a finite number above 1" in capsys.readouterr().err
    assert not out.exists()


def test_fill_gaps_on_a_clean_clip_writes_an_unchanged_copy(tmp_path, capsys):
    clean = tmp_path / "clean.bvh"
    bvh.save(clean, toy_motion(120))
    out = tmp_path / "copy.bvh"
    assert main(["fill-gaps", str(clean), "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert "unchanged copy" in said
    assert "Δ = 2.5 nowhere" in said and "one dropped frame" in said  # what the default cannot see, and how to
    assert out.read_bytes() == clean.read_bytes()


def test_fill_gaps_continues_the_strides_by_default(tmp_path, capsys):
    m = toy_motion(240)  # one stride a second, 1.5 strides known on both sides of the cut
    path = tmp_path / "walk.bvh"
    bvh.save(path, m[np.r_[0:100, 112:240]])
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(path), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "(method: stride)" in text and ": stride" in text
    assert abs(bvh.load(out).num_frames - m.num_frames) <= 1  # 12 frames missing, counted to one


def test_fill_gaps_with_other_takes(dropped, tmp_path, capsys):
    other = tmp_path / "other.bvh"
    bvh.save(other, toy_motion(150, phase=0.7, speed=1.1))
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--takes", str(other)]) == 0
    assert "filled 1 gap(s)" in capsys.readouterr().out
    assert abs(bvh.load(out).num_frames - 120) <= 1
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--takes", str(dropped)]) == 2
    assert "the input itself" in capsys.readouterr().err
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--takes", str(tmp_path / "no.bvh")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_fill_gaps_takes_from_a_folder(dropped, tmp_path, capsys, monkeypatch):
    """``--takes FOLDER`` reads every BVH file in it but the input, each once; the same result as
    naming them."""
    from motionlab.interpolation import recorded

    seen = []

    class Spy(recorded.RecordedTakes):
        def __init__(self, motions, mirror=True):
            seen.append(sorted(m.name for m in motions))
            super().__init__(motions, mirror)

    monkeypatch.setattr(recorded, "RecordedTakes", Spy)
    session = tmp_path / "session"
    session.mkdir()
    for i, (phase, speed) in enumerate([(0.7, 1.1), (0.3, 0.9)]):
        bvh.save(session / f"take_{i}.bvh", toy_motion(150, phase=phase, speed=speed))
    stream = session / "stream.bvh"
    stream.write_bytes(dropped.read_bytes())
    by_folder, by_name = tmp_path / "a.bvh", tmp_path / "b.bvh"
    assert main(["fill-gaps", str(stream), "-o", str(by_folder), "--takes", str(session)]) == 0
    names = [a for f in sorted(session.glob("take_*.bvh")) for a in ("--takes", str(f))]
    assert main(["fill-gaps", str(stream), "-o", str(by_name), *names, "--takes", str(session)]) == 0
    assert by_folder.read_bytes() == by_name.read_bytes()
    assert seen == [["take_0", "take_1"], ["take_0", "take_1"]]  # the input left out, no take twice
    capsys.readouterr()
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["fill-gaps", str(stream), "-o", str(tmp_path / "c.bvh"), "--takes", str(empty)]) == 2
    assert "a folder without BVH files" in capsys.readouterr().err
    alone = tmp_path / "alone"
    alone.mkdir()
    (alone / "stream.bvh").write_bytes(dropped.read_bytes())
    assert main(["fill-gaps", str(alone / "stream.bvh"), "-o", str(tmp_path / "d.bvh"), "--takes", str(alone)]) == 2
    assert "other than the input" in capsys.readouterr().err


def _times_file(path, times, header="# frame times (s)"):
    path.write_text(header + "\n" + "\n".join(f"{t:.6f}" for t in times) + "\n")
    return path


def test_fill_gaps_reads_the_counts_from_frame_times(dropped, tmp_path, capsys):
    """``dropped`` is the toy walk (30 fps) without frames 50 … 57: its capture times say so exactly."""
    keep = np.r_[0:50, 58:120]
    times = _times_file(tmp_path / "times.txt", 0.25 + keep / 30.0)  # a clock that does not start at 0
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(times)]) == 0
    assert "filled 1 gap(s), 8 frame(s)" in capsys.readouterr().out
    assert bvh.load(out).num_frames == 120
    clean = tmp_path / "clean.bvh"
    bvh.save(clean, toy_motion(40))
    regular = _times_file(tmp_path / "regular.txt", np.arange(40) / 30.0)
    copy = tmp_path / "copy.bvh"
    assert main(["fill-gaps", str(clean), "-o", str(copy), "--times", str(regular)]) == 0
    assert "no dropped frames in the times of" in capsys.readouterr().out
    assert copy.read_bytes() == clean.read_bytes()
    capsys.readouterr()
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(times), "--force"]) == 0
    assert "estimated" not in capsys.readouterr().err  # counts from the times are exact


def test_fill_gaps_says_an_estimated_count_is_one(tmp_path, capsys):
    """Issue 39: a real walk without frames 40-45 (6 frames), filled without ``--times``. The
    motion alone counts 7 there (the stride count 6.1, the local count 6.9, and the rehearsal
    picks the local one); the command must not pass that off as exact: a warning gives the range
    the count is likely in, which holds the true 6, and points to ``--times``."""
    walk = bvh.load(require_data("bandai_namco", "dataset-1", "walk", "dataset-1_walk_normal_001.bvh"))
    gap, out = tmp_path / "gap.bvh", tmp_path / "out.bvh"
    bvh.save(gap, walk[np.r_[0:40, 46 : walk.num_frames]])
    assert main(["fill-gaps", str(gap), "-o", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    found = re.search(
        r"warning: .*gap\.bvh: .*estimated.* (\d+) frames after frame 39 \(likely (\d+) to (\d+)\).*--times", err
    )
    assert found, err
    count, low, high = map(int, found.groups())
    assert low <= 6 <= high and low <= count <= high
    assert bvh.load(out).num_frames == walk.num_frames - 6 + count


def test_fill_gaps_says_which_gap_sizes_its_range_could_not_try(tmp_path, capsys):
    """A Xia punch take of 105 frames at 120 fps without frames 50-69: beside the gap a cut keeps
    12 frames on each side, so too few cuts of 25 frames or more fit to try them as the true size;
    the warning says so after the range."""
    punch = bvh.load(require_data("xia", "punch", "depressed_18_000.bvh"))
    gap, out = tmp_path / "gap.bvh", tmp_path / "out.bvh"
    bvh.save(gap, punch[np.r_[0:50, 70 : punch.num_frames]])
    assert main(["fill-gaps", str(gap), "-o", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert re.search(
        r"after frame 49 \(likely \d+ to \d+; gaps of 25 or more frames could not be tried beside it\)", err
    ), err


def test_the_warning_counts_the_unlisted_gaps_whose_sizes_were_not_all_tried(capsys):
    """Past the gaps it lists, the warning says how many more there are and how many of those have
    sizes their range could not try."""
    from motionlab.interpolation.cli import SHOWN_RANGES, _warn_estimated
    from motionlab.interpolation.detect import MissingCount

    open_above = [None] * SHOWN_RANGES + [12, None, 30]
    _warn_estimated("x.bvh", [(10 * i, MissingCount(3, 2, 4, u)) for i, u in enumerate(open_above)])
    err = capsys.readouterr().err
    assert "after frame 40 (likely 2 to 4)," in err and "after frame 50" not in err
    assert "and 3 more gaps (2 with sizes that could not be tried);" in err


def test_fill_gaps_refuses_frame_times_that_do_not_fit(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    keep = np.r_[0:50, 58:120]
    cases = {
        "short.txt": (keep[:-1] / 30.0, r"short.txt: 111 frame times for 112 frames"),
        "word.txt": (list(keep[:2] / 30.0) + ["abc"], r"word.txt line 4: expected one time in seconds, found 'abc'"),
        "back.txt": ([0.0, 0.1, 0.05], r"back.txt line 4: 0.05 s is not after 0.1 s \(line 3\)"),
    }
    for name, (times, message) in cases.items():
        path = tmp_path / name
        path.write_text("# times\n" + "\n".join(str(t) for t in times) + "\n")
        assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(path)]) == 2
        assert re.search(message, capsys.readouterr().err), name
        assert not out.exists()
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(tmp_path / "none.txt")]) == 2
    assert "--times" in capsys.readouterr().err
    times = _times_file(tmp_path / "t.txt", keep / 30.0)
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(times), "--takes", str(dropped)]) == 2
    assert "--times gives the gaps" in capsys.readouterr().err


def test_fill_gaps_refuses_frame_times_of_another_rate(dropped, tmp_path, capsys):
    """A log at 18 or 50 Hz beside a 30 fps file: every step would count as a gap, or none."""
    out, keep = tmp_path / "out.bvh", np.r_[0:50, 58:120]
    for rate in (18.0, 50.0):
        times = _times_file(tmp_path / f"t{rate:g}.txt", keep / rate)
        assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(times)]) == 2
        err = capsys.readouterr().err
        assert f"{rate:g} fps" in err and "within 1%" in err
        assert not out.exists()
    times = _times_file(tmp_path / "ntsc.txt", keep / 29.97)  # NTSC's rate: counted in its own frame period
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--times", str(times)]) == 0
    assert bvh.load(out).num_frames == 120


def test_frame_times_with_most_frames_dropped_are_read_in_their_one_frame_steps(tmp_path, capsys):
    """Every other frame dropped but for the first ten: the median step is two Frame Times, and
    the times were refused as another rate's; their steps of one Frame Time give the period."""
    m = toy_motion(120)
    keep = np.r_[0:10, 10:120:2]
    stream = tmp_path / "stream.bvh"
    bvh.save(stream, m[keep])
    out = tmp_path / "out.bvh"
    times = _times_file(tmp_path / "t.txt", keep / 30.0)
    assert main(["fill-gaps", str(stream), "-o", str(out), "--times", str(times)]) == 0
    assert bvh.load(out).num_frames == 119  # frames 0 … 118: nothing was dropped after the last kept one
    every_other = _times_file(tmp_path / "e.txt", np.arange(0, 120, 2) / 30.0)  # as a 15 fps log would be
    bvh.save(stream, m[::2].copy(fps=30.0), overwrite=True)  # a 30 fps file that lost every other frame
    assert main(["fill-gaps", str(stream), "-o", str(tmp_path / "e.bvh"), "--times", str(every_other)]) == 2
    assert "no two frames are one Frame Time apart" in capsys.readouterr().err


def test_fill_gaps_refuses_graph_options_it_would_not_use(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--allow", "walk -> run"]) == 2
    assert "--allow names transitions between --action clips" in capsys.readouterr().err
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--action", f"walk={tmp_path / 'none.bvh'}"]) == 2
    assert "no such file" in capsys.readouterr().err
    times = _times_file(tmp_path / "t.txt", np.r_[0:50, 58:120] / 30.0)
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--action", f"walk={dropped}", "--times", str(times)]) == 2
    assert "the graph would not be used" in capsys.readouterr().err and not out.exists()
