"""The MOTIONLAB_DATA setting."""

from __future__ import annotations

import pytest

from motionlab import data


def test_unset_gives_a_how_to(monkeypatch):
    monkeypatch.delenv(data.ENV_VAR, raising=False)
    assert data.data_root(required=False) is None
    assert not data.has_data()
    with pytest.raises(data.DataNotFound, match="MOTIONLAB_DATA"):
        data.data_root()


def test_missing_or_empty_folder(monkeypatch, tmp_path):
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path / "nope"))
    with pytest.raises(data.DataNotFound, match="not a folder"):
        data.data_root()
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path))
    with pytest.raises(data.DataNotFound, match="no .bvh files"):
        data.data_root()


def test_lists_characters_and_clips(monkeypatch, tmp_path):
    for char, clips in {"Aj": ["Run", "Walk"], "Kaya": ["Run"]}.items():
        (tmp_path / "mixamo" / char).mkdir(parents=True)
        for c in clips:
            (tmp_path / "mixamo" / char / f"{c}.bvh").write_text("HIERARCHY")
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path))
    assert data.list_characters() == {"Aj": ["Run", "Walk"], "Kaya": ["Run"]}
    assert len(data.list_clips("mixamo")) == 3
    assert data.clip_path("mixamo", "Aj", "Run").name == "Run.bvh"
    with pytest.raises(data.DataNotFound, match="Jump.bvh"):
        data.clip_path("mixamo", "Aj", "Jump")
