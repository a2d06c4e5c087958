"""Every study of experiments/ runs as a module and answers --help (no data needed)."""

import importlib
from pathlib import Path

import pytest

EXPERIMENTS = Path(__file__).resolve().parents[2] / "experiments"
STUDIES = sorted(
    f"{path.parent.name}.{path.stem}"
    for path in EXPERIMENTS.glob("*/*.py")
    if "\ndef main(" in path.read_text(encoding="utf-8")
)
"""Every module of experiments/<system>/ that has a ``main``: the command-line studies."""


def test_every_system_has_its_studies_here():
    assert {name.split(".")[0] for name in STUDIES} == {"interpolation", "motion_graphs", "retargeting"}


@pytest.mark.parametrize("name", STUDIES)
def test_the_study_answers_help(name, capsys):
    module = importlib.import_module(f"experiments.{name}")
    with pytest.raises(SystemExit) as stop:
        module.main(["--help"])
    assert stop.value.code == 0
    assert "usage:" in capsys.readouterr().out
