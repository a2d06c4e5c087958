"""Off-screen decisions, headless OpenGL selection, Jupyter backend choice, lazy imports."""

from __future__ import annotations

import subprocess
import sys

import pytest

from motionlab.viz import backend


def test_resolve_off_screen(monkeypatch):
    assert backend.resolve_off_screen(True) is True
    assert backend.resolve_off_screen(False) is False
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    assert backend.resolve_off_screen(None) is True
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "false")
    assert backend.resolve_off_screen(None) is False
    monkeypatch.delenv("PYVISTA_OFF_SCREEN")
    monkeypatch.setattr(backend.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert backend.resolve_off_screen(None) is True
    monkeypatch.setenv("DISPLAY", ":0")
    assert backend.resolve_off_screen(None) is False
    with pytest.raises(ValueError, match="off_screen must be"):
        backend.resolve_off_screen("yes")


def test_jupyter_backend(monkeypatch):
    monkeypatch.delenv("PYVISTA_JUPYTER_BACKEND", raising=False)
    assert backend.jupyter_backend() == "static"
    monkeypatch.setenv("PYVISTA_JUPYTER_BACKEND", "static")
    assert backend.jupyter_backend() == "static"
    assert backend.jupyter_backend("trame") in ("trame", "static")  # static when trame is missing
    with pytest.raises(ValueError, match="unknown Jupyter backend"):
        backend.jupyter_backend("vr")


def test_headless_without_gl_libraries_raises_instead_of_crashing(monkeypatch):
    monkeypatch.setattr(backend.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.setattr(backend.ctypes.util, "find_library", lambda name: None)
    with pytest.raises(backend.RenderingUnavailable, match="libegl1 libgl1-mesa-dri"):
        backend.import_pyvista()


def test_headless_picks_egl(monkeypatch):
    monkeypatch.setattr(backend.sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.setattr(backend.ctypes.util, "find_library", lambda name: "libEGL.so.1" if name == "EGL" else None)
    backend._choose_headless_window()
    assert backend.os.environ["VTK_DEFAULT_OPENGL_WINDOW"] == "vtkEGLRenderWindow"


def test_importing_motionlab_does_not_import_pyvista():
    code = (
        "import sys, motionlab, motionlab.viz, motionlab.viz.cli\n"
        "heavy = [m for m in ('pyvista', 'vtk', 'vtkmodules', 'ipywidgets') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
