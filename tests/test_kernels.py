"""``scripts/kernels.py`` names the MKL code path torch computes with, not only the one asked for."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "kernels.py"


@pytest.mark.parametrize("asked, shown", [("COMPATIBLE", "COMPATIBLE"), ("", "off (MKL's own choice)")])
def test_the_mkl_code_path_in_effect_is_printed(asked, shown):
    env = dict(os.environ, MKL_CBWR=asked)
    out = subprocess.run([sys.executable, str(SCRIPT)], env=env, capture_output=True, text=True, check=True).stdout
    line = next(line for line in out.splitlines() if line.startswith("MKL in torch"))
    if "no MKL" in line:
        pytest.skip("this torch build has no MKL")
    assert line == f"MKL in torch: code path in effect {shown}"
