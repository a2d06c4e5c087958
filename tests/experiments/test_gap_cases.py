"""The hard cases of docs/results_interpolation.md: every case runs and its checks hold."""

import pytest

from experiments.interpolation import gap_cases
from motionlab import data


def test_every_case_runs_and_holds(capsys):
    if not data.has_data("bandai_namco"):
        pytest.skip(f"needs real mocap: {data.HOW_TO}")
    assert gap_cases.main([]) == 0
    out = capsys.readouterr().out
    assert all(f"{name}:" in out for name in gap_cases.CASES)


def test_an_unknown_case_is_refused():
    with pytest.raises(SystemExit):
        gap_cases.main(["no-such-case"])
