"""Every sub-command's parser driven with random option values and paths (Hypothesis).

Whatever the arguments, ``motionlab`` ends with exit status 0 or 2 and no traceback; a command
that refuses (2) leaves every file as it was, and no command replaces a file without ``--force``
or leaves a temporary file behind. Output names are drawn with every suffix, as a folder's name
(``new_dir/``), and as a named pipe or a symbolic link, which are never replaced, ``--force`` or
not; numbers are drawn huge and tiny (``1e300``, ``1e-300``) for every numeric option. The long-running work (training, solving, building, rendering)
is replaced by a stand-in that stops the command where its work would begin, so a valid argument
list costs milliseconds and the check "nothing written before the work starts" holds too.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from motionlab import cli, synthetic
from motionlab.core import bvh, humanoid

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)


class WorkBegan(Exception):
    """Raised by the stand-ins: the command accepted its arguments and started its work."""


def _stop(*args, **kwargs):
    raise WorkBegan


_WORK = (  # where each command's long work begins
    "motionlab.retargeting.cli_options.load_checkpoint",
    "motionlab.retargeting.cli_options.network_checkpoint",
    "motionlab.retargeting.real.trained",
    "motionlab.retargeting.pipeline.retarget",
    "motionlab.retargeting.train.training_set",
    "motionlab.retargeting.train.train",
    "motionlab.retargeting.evaluate.evaluate",
    "motionlab.retargeting.expand.expand",
    "motionlab.synthetic.dataset",
    "motionlab.synthetic.generate",
    "motionlab.synthetic.sequence",
    "motionlab.core.motion.Motion.resample",
    "motionlab.demo.run_demo",
    "motionlab.motion_graphs.clips.load_folder",
    "motionlab.interpolation.detect.detect",
    "motionlab.interpolation.gaps.fill",
    "motionlab.viz.export.save_movie",
)

PARSER = cli.build_parser()
COMMANDS = PARSER._subparsers._group_actions[0].choices
NAMES = ["in.bvh", "dir", "notes.txt", "old.bvh", "g.mlgraph", "missing.bvh", "nowhere/x.bvh", "", ".",
         "walk:normal:30", "walk:normal:10,run:normal:10", "walk:normal:10,,run:normal:10"]  # fmt: skip
OUTPUTS = ["out.bvh", "out.mlgraph", "r.json", "out.gif", "out.mp4", "out.npz", "out.pt", "new_dir", "old.bvh",
           "in.bvh", "dir", "nowhere/x.bvh",
           # every suffix a user may try, a folder's name, and names that are no plain file (made by _sandbox)
           "out.glb", "out.gltf", "out.fbx", "out.txt", "out.csv", "out", "new_dir/", "dir/", "pipe.bvh", "link.bvh"]  # fmt: skip
NUMBERS = ["0", "-1", "-5", "0.5", "nan", "inf", "-inf", "1e9", "abc", "2.5",
           "1e300", "-1e300", "1e6", "1e-9", "1e-300", "100000x100000", "4294967296"]  # huge and tiny  # fmt: skip
RANDOM = st.one_of(
    st.sampled_from(NAMES),
    st.sampled_from(NUMBERS),
    st.integers(-10, 10**6).map(str),
    st.text("abcxyz019:,._=-", max_size=12),  # no "/": a path never leaves the sandbox
)
FLOAT_TYPES = ("float", "positive", "non_negative", "in_range", "frame_rate", "factor")
GOOD_INTS = st.sampled_from(["1", "2", "3", "10"])
GOOD_FLOATS = st.sampled_from(["0.5", "1", "0.03", "30", "1.2"])


def _values(action: argparse.Action):
    """Values for ``action``: mostly ones of the right kind (so that commands get past the parser),
    the rest anything at all."""
    if action.choices:
        good = st.sampled_from(list(action.choices))
    elif action.dest in ("output", "out", "report", "csv", "npz"):
        good = st.sampled_from(OUTPUTS)
    elif getattr(action.type, "__name__", "") in ("int", "positive_int", "non_negative_int", "seed"):
        good = GOOD_INTS
    elif getattr(action.type, "__name__", "") in FLOAT_TYPES:
        good = GOOD_FLOATS
    else:
        good = st.sampled_from(NAMES)
    return st.one_of(good, good, RANDOM)


def _sandbox(folder: Path, text: str, graph: bytes) -> None:
    """The files an argument may name: a valid clip ``text``, a folder of clips, a motion graph,
    text, an existing output."""
    (folder / "g.mlgraph").write_bytes(graph)
    (folder / "in.bvh").write_text(text)
    (folder / "dir").mkdir()
    (folder / "dir" / "walk_normal.bvh").write_text(text)
    (folder / "notes.txt").write_text("not a motion\n")
    (folder / "old.bvh").write_text("a file that must survive\n")
    os.mkfifo(folder / "pipe.bvh")  # a special file: never replaced, --force or not
    (folder / "link.bvh").symlink_to("old.bvh")  # a link: never replaced, nor what it points to


def _state(p: Path) -> str:
    """What ``p`` is and holds: a link's target, a named pipe, a folder, or a file's hash."""
    if p.is_symlink():
        return f"link to {os.readlink(p)}"
    if p.is_fifo():
        return "named pipe"
    return hashlib.sha1(p.read_bytes()).hexdigest() if p.is_file() else "folder"


def _snapshot(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): _state(p) for p in sorted(folder.rglob("*"))}


def _resolve(dotted: str):
    """The module (not a same-named function in its package) or class that ``dotted`` names."""
    try:
        return importlib.import_module(dotted)
    except ModuleNotFoundError:
        module, name = dotted.rsplit(".", 1)
        return getattr(importlib.import_module(module), name)


BASE = {  # (inputs, options) each command accepts, to which random options are added
    "info": (["in.bvh"], []),
    "convert": (["in.bvh"], ["-o", "out.bvh"]),
    "synth": (["walk"], ["-o", "out.bvh"]),
    "demo": ([], ["-o", "new_dir"]),
    "expand": (["in.bvh"], ["--preset", "child", "-o", "new_dir"]),
    "retarget": (["in.bvh"], ["--scale-legs", "1.2", "-o", "out.bvh"]),
    "train": (["in.bvh"], ["-o", "out.pt"]),
    "evaluate": ([], ["--data", "dir", "--animations", "walk_normal", "--checkpoint", "out.pt"]),
    "graph-build": ([], ["--synthetic", "-o", "out.mlgraph"]),
    "graph-search": (["g.mlgraph"], ["--request", "walk:normal:30", "-o", "out.bvh"]),
    "graph-info": (["g.mlgraph"], []),
    "fill-gaps": (["in.bvh"], ["-o", "out.bvh"]),
    "view": (["in.bvh"], ["-o", "out.gif"]),
}

EXAMPLES = {  # the cases of issue 34 that once wrote what they should not have
    "graph-build": [([], ["--synthetic", "-o", "out.mlgraph", "--report", "out.mlgraph"])],
    "graph-search": [(["g.mlgraph"], ["--request", "walk:normal:30", "-o", "g.mlgraph", "--force"])],
}


def _option(draw, action: argparse.Action) -> list[str]:
    """``action``'s option string and random values for it."""
    if action.nargs == 0:  # a flag
        return [action.option_strings[0]]
    n = {"*": draw(st.integers(1, 2)), "+": draw(st.integers(1, 2))}.get(action.nargs, 1)
    return [draw(st.sampled_from(action.option_strings))] + [draw(_values(action)) for _ in range(n)]


@st.composite
def _argv(draw, command: str) -> tuple[list[str], list[str]]:
    """``(argv, inputs)``: a random argument list for ``command`` and its positional arguments (the
    files it reads). Half the time an accepted list with up to three random options added, else
    every positional and a random subset of options, all random."""
    actions = [a for a in COMMANDS[command]._actions if not isinstance(a, argparse._HelpAction)]
    options = [a for a in actions if a.option_strings]
    if command in BASE and draw(st.booleans()):
        inputs, argv = BASE[command][0], [command, *BASE[command][0], *BASE[command][1]]
        for _ in range(draw(st.integers(1 if options else 0, 3 if options else 0))):
            argv += _option(draw, draw(st.sampled_from(options)))
        return argv, inputs
    argv, inputs = [command], []
    for action in actions:
        if action.option_strings:
            if action.required or draw(st.integers(0, 3)) == 0:
                argv += _option(draw, action)
            continue
        n = {None: 1, "?": draw(st.integers(0, 1)), "*": draw(st.integers(0, 2)), "+": draw(st.integers(1, 2))}
        inputs += [draw(_values(action)) for _ in range(n.get(action.nargs, 1))]
    return argv[:1] + inputs + argv[1:], inputs


@pytest.fixture(scope="module")
def graph_parts(tmp_path_factory) -> tuple[bytes, list]:
    """A small motion graph file and the synthetic clips it was built from (30 fps)."""
    from motionlab.motion_graphs import clips

    path = tmp_path_factory.mktemp("fuzz") / "g.mlgraph"
    assert cli.main(["graph-build", "--synthetic", "-o", str(path)]) == 0
    return path.read_bytes(), clips.synthetic_library(fps=30.0)


def _check(argv, inputs, code, err, before, after) -> None:
    """The contract of every command, whatever its arguments."""
    assert "Traceback" not in err
    assert code in (0, 2, None), (argv, code, err)
    if code in (2, None):  # refused, or work began: every output was checked and nothing written yet
        assert after == before, (argv, err)
    if "--force" not in argv:
        assert all(after.get(k) == v for k, v in before.items()), argv  # nothing replaced
    assert [after.get(k) for k in ("pipe.bvh", "link.bvh")] == [before[k] for k in ("pipe.bvh", "link.bvh")], argv
    if "old.bvh" not in argv:  # nothing written through the link either
        assert after.get("old.bvh") == before["old.bvh"], argv
    changed = [k for k in inputs if k in before and after.get(k) != before[k]]
    assert not changed, (argv, changed)  # a file the command reads is never written, --force or not
    assert not [k for k in after if k.endswith((".tmp", ".motionlab-tmp"))], argv


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_ends_cleanly_on_random_arguments(command, graph_parts, monkeypatch, capsys):
    clip = bvh.dumps(synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=12, fps=30, seed=0))
    graph, library = graph_parts
    for target in _WORK:
        owner, attr = target.rsplit(".", 1)
        monkeypatch.setattr(_resolve(owner), attr, _stop)
    # graph-build builds for real, from the small library whatever --fps says
    monkeypatch.setattr("motionlab.motion_graphs.clips.synthetic_library", lambda **kwargs: list(library))
    monkeypatch.setattr("motionlab.viz.backend.has_display", lambda: False)
    here = os.getcwd()

    @settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(case=_argv(command))
    def run(case):
        argv, inputs = case
        with tempfile.TemporaryDirectory() as name:
            folder = Path(name)
            _sandbox(folder, clip, graph)
            before = _snapshot(folder)
            os.chdir(folder)
            try:
                code = cli.main(argv)
            except SystemExit as e:  # argparse's refusal
                code = e.code
            except WorkBegan:
                code = None
            finally:
                os.chdir(here)
            err = capsys.readouterr().err
            event({0: "exit 0", 2: "refused (exit 2)", None: "work began"}.get(code, f"exit {code}"))
            _check(argv, inputs, code, err, before, _snapshot(folder))

    for inputs, options in EXAMPLES.get(command, []):
        run = example(case=([command, *inputs, *options], inputs))(run)
    run()


WRITERS = {  # commands that write a motion, with arguments that make them write one quickly
    "convert": ["convert", "in.bvh"],
    "synth": ["synth", "walk", "--seconds", "0.2"],
    "fill-gaps": ["fill-gaps", "in.bvh"],
    "graph-search": ["graph-search", "g.mlgraph", "--request", "walk:normal:10"],
    "retarget": ["retarget", "in.bvh", "--scale-legs", "1.2", "--method", "copy", "--keep-implausible"],
}
MAGIC = {".bvh": b"HIERARCHY", ".glb": b"glTF"}


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    command=st.sampled_from(sorted(WRITERS)),
    output=st.sampled_from(OUTPUTS),
    force=st.booleans(),
)
def test_every_motion_writer_writes_what_its_output_name_says(graph_parts, capsys, command, output, force):
    """For real (no stand-ins): exit 0 writes the format the name's suffix says; else exit 2 and
    nothing changed. A named pipe or a link is never replaced."""
    clip = bvh.dumps(synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=12, fps=30, seed=0))
    here = os.getcwd()
    argv = [*WRITERS[command], "-o", output, "-q"] + (["--force"] if force else [])
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        _sandbox(folder, clip, graph_parts[0])
        before = _snapshot(folder)
        os.chdir(folder)
        try:
            code = cli.main(argv)
        except SystemExit as e:
            code = e.code
        finally:
            os.chdir(here)
        after = _snapshot(folder)
        _check(argv, WRITERS[command][1:2], code, capsys.readouterr().err, before, after)
        if code == 0:
            magic = MAGIC.get(Path(output).suffix.lower(), b"(refused: no writer for this suffix)")
            assert (folder / output).read_bytes().startswith(magic), argv
