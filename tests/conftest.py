"""Shared pytest fixtures: real data through MOTIONLAB_DATA, skipping with a how-to otherwise."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import data


def require_data(*parts: str):
    """Skip the calling test unless MOTIONLAB_DATA (and the sub-path ``parts``) exists."""
    if not data.has_data(*parts):
        where = "/".join(parts) or "the data folder"
        pytest.skip(f"needs real mocap ({where}): {data.HOW_TO}")
    return data.data_root().joinpath(*parts)


@pytest.fixture
def data_root():
    """The MOTIONLAB_DATA folder (test skipped when unset)."""
    return require_data()


@pytest.fixture
def rng():
    return np.random.default_rng(0)
