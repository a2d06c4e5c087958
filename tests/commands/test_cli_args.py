"""``motionlab.cli_args``: the argument and output checks every sub-command shares."""

from __future__ import annotations

import argparse
import os
import re

import pytest

from motionlab.cli import CLIError
from motionlab.cli_args import (
    check_output_folder,
    check_outputs,
    non_negative,
    non_negative_int,
    positive,
    positive_int,
)


@pytest.mark.parametrize(
    ("check", "good", "bad"),
    [
        (positive, ["0.5", "3", "1e-9"], ["0", "-1", "nan", "inf", "x", ""]),
        (non_negative, ["0", "0.5"], ["-1", "-1e-9", "nan", "-inf", "x"]),
        (positive_int, ["1", "30"], ["0", "-5", "2.5", "nan", "x"]),
        (non_negative_int, ["0", "4"], ["-1", "1.5", "x"]),
    ],
)
def test_number_types_accept_and_refuse(check, good, bad):
    for text in good:
        assert check(text) == float(text)
    for text in bad:
        with pytest.raises(argparse.ArgumentTypeError, match="expected"):
            check(text)


def test_check_outputs_passes_new_files_and_skips_options_not_given(tmp_path):
    a, b = tmp_path / "a.bvh", tmp_path / "b.json"
    assert check_outputs([("-o", a), ("--report", None), ("--csv", b)], force=False) == [a, None, b]


@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("folder", "-o {p} is a folder; expected the name of a file"),
        ("exists", "-o {p} exists; add --force"),
        ("missing_folder", "the folder {d} does not exist"),
        ("parent_is_a_file", "{d} is a file, not a folder"),
    ],
)
def test_check_outputs_refuses_by_option(tmp_path, case, message):
    p, d = tmp_path / "out.bvh", tmp_path
    if case == "folder":
        p.mkdir()
    elif case == "exists":
        p.write_text("mine")
    elif case == "missing_folder":
        d = tmp_path / "nowhere"
        p = d / "out.bvh"
    else:
        d = tmp_path / "file.txt"
        d.write_text("")
        p = d / "out.bvh"
    with pytest.raises(CLIError, match=re.escape(message.format(p=p, d=d))) as e:
        check_outputs([("-o", p)], force=False)
    assert str(e.value).startswith(f"-o {p}")


def test_force_allows_an_existing_file_but_not_a_folder(tmp_path):
    (tmp_path / "old.bvh").write_text("x")
    assert check_outputs([("-o", tmp_path / "old.bvh")], force=True) == [tmp_path / "old.bvh"]
    with pytest.raises(CLIError, match="is a folder"):
        check_outputs([("-o", tmp_path)], force=True)


def test_one_path_for_two_outputs_or_an_input_is_refused_even_with_force(tmp_path):
    g = tmp_path / "g.mlgraph"
    with pytest.raises(CLIError, match="-o and --report both name"):
        check_outputs([("-o", g), ("--report", g)], force=True)
    src = tmp_path / "in.bvh"
    src.write_text("x")
    with pytest.raises(CLIError, match="-o .*in.bvh is the input file"):
        check_outputs([("-o", src)], force=True, inputs=[("input", src)])


def test_unwritable_folder_is_named(tmp_path, monkeypatch):
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m, *a, **k: False if str(p) == str(tmp_path) else real(p, m))
    with pytest.raises(CLIError, match=f"cannot write into the folder {tmp_path.resolve()}"):
        check_outputs([("--csv", tmp_path / "r.csv")], force=False)
    with pytest.raises(CLIError, match=f"-o {tmp_path / 'new'}: cannot write into the folder"):
        check_output_folder("-o", tmp_path / "new")


def test_check_output_folder(tmp_path):
    assert check_output_folder("-o", tmp_path / "a" / "b") == tmp_path / "a" / "b"  # made later
    (tmp_path / "f.txt").write_text("")
    with pytest.raises(CLIError, match="is a file; expected a folder"):
        check_output_folder("-o", tmp_path / "f.txt")
    with pytest.raises(CLIError, match="is a file, so the folder cannot be made"):
        check_output_folder("-o", tmp_path / "f.txt" / "sub")
    assert not (tmp_path / "a").exists()  # checking makes nothing


def test_command_takes_its_help_from_the_docstring_and_adds_quiet_last():
    from motionlab import cli_args

    def run(args):
        """do the thing

        Do the thing to a file,
        carefully.

        Exit status 1 when it fails.
        """

    sub = argparse.ArgumentParser(prog="motionlab").add_subparsers()
    with cli_args.command(sub, "thing", run) as p:
        p.add_argument("file")
        cli_args.add_output(p, "where to write")
        cli_args.add_force(p, "replace the output")
    args = p.parse_args(["a.bvh", "-o", "b.bvh", "--force", "-q"])
    assert args.func is run and args.output == "b.bvh" and args.force and args.quiet
    assert p.description == "Do the thing to a file, carefully.\n\nExit status 1 when it fails."
    assert [a.dest for a in p._actions][-1] == "quiet"
    assert sub._choices_actions[0].help == "do the thing"
    with pytest.raises(SystemExit):
        p.parse_args(["a.bvh"])  # -o is required
