"""Every study of experiments/interpolation runs as a module and answers --help (no data needed)."""

import importlib

import pytest

STUDIES = ["bench_gap_rigs", "bench_inbetween", "check_gaps", "check_tracking_pose", "compare_counts", "compare_feet",
           "compare_stride_root", "gap_cases", "reproduce_keypose_paper"]  # fmt: skip


@pytest.mark.parametrize("name", STUDIES)
def test_the_study_answers_help(name, capsys):
    module = importlib.import_module(f"experiments.interpolation.{name}")
    with pytest.raises(SystemExit) as stop:
        module.main(["--help"])
    assert stop.value.code == 0
    assert "usage:" in capsys.readouterr().out
