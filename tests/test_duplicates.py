"""``duplicates`` on ``motionlab/`` lists only the intended twins that CONTRIBUTING.md names.

The ``duplicates`` command is a developer tool outside the package: the test is skipped where it
is not installed.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

ROOT = Path(__file__).resolve().parents[1]
ROW = re.compile(r"^D\d+ (\S+?):\d+-\d+ ~ (\S+?):\d+-\d+")


def intended_twins(contributing: str) -> set[frozenset[str]]:
    """The file pairs of the section "Intended twins": ```a.py` ~ `b.py``` and ``within `a.py```."""
    section = contributing.split("## Intended twins", 1)[1].split("\n## ", 1)[0]
    pairs = {frozenset(p) for p in re.findall(r"`([\w/.]+\.py)`\s+~\s+`([\w/.]+\.py)`", section)}
    return pairs | {frozenset([f]) for f in re.findall(r"within\s+`([\w/.]+\.py)`", section)}


def listed_pairs(output: str) -> set[frozenset[str]]:
    """The file pairs of the rows ``duplicates`` prints."""
    return {frozenset(m.groups()) for m in map(ROW.match, output.splitlines()) if m}


def test_the_contributing_section_parses():
    twins = intended_twins((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8"))
    assert frozenset(["core/quat.py", "core/quat_torch.py"]) in twins
    assert frozenset(["exercises/basics.py"]) in twins
    assert listed_pairs("D1 a.py:1-9 ~ b.py:3-11 shape\nD2 a.py:1-6 ~ a.py:8-13\n") == {
        frozenset(["a.py", "b.py"]),
        frozenset(["a.py"]),
    }


@pytest.mark.skipif(shutil.which("duplicates") is None, reason="the duplicates command is not installed")
def test_only_intended_twins_repeat():
    run = subprocess.run(
        ["duplicates", "--repo", "motionlab", "--most", "200", "--seconds", "120"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    assert "incomplete:" not in run.stdout, run.stdout
    unnamed = listed_pairs(run.stdout) - intended_twins((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8"))
    assert not unnamed, (
        "repeated code outside the intended twins of CONTRIBUTING.md: give it one home (a shared helper) "
        f"or name the pair there with the reason:\n{run.stdout}"
    )
