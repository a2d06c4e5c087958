"""Where and how 3D views render: on screen or off, headless OpenGL, Jupyter backends.

pyvista (and VTK behind it) is imported lazily, only by the functions that draw, so that
``import motionlab`` never pays for it. This module decides three things:

* **off-screen or not** -- :func:`resolve_off_screen`: an explicit ``True``/``False`` wins;
  ``None`` means off-screen when ``PYVISTA_OFF_SCREEN`` is true, or on Linux when no
  ``DISPLAY``/``WAYLAND_DISPLAY`` exists.
* **which OpenGL window VTK opens headless** -- the VTK wheel needs EGL, OSMesa or X at render
  time and *segfaults* when none is there. :func:`import_pyvista` picks EGL
  (``libEGL`` + Mesa's DRI drivers) or OSMesa by setting ``VTK_DEFAULT_OPENGL_WINDOW`` unless
  the user already did, and raises :class:`RenderingUnavailable` (with the packages to
  install) instead of crashing when no display and neither library is present.
* **which Jupyter view the player uses** -- :func:`jupyter_backend`: ``"trame"`` when trame is
  installed and ``PYVISTA_JUPYTER_BACKEND`` (or pyvista's theme) asks for an interactive
  backend, otherwise ``"static"`` (rendered images pushed into an ``ipywidgets.Image``).

Headless Debian/Ubuntu::

    apt-get install -y libegl1 libgl1-mesa-dri        # EGL software rendering (llvmpipe)
    export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
    export PYVISTA_OFF_SCREEN=true PYVISTA_JUPYTER_BACKEND=static   # CI and nbval

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

import ctypes.util
import importlib.util
import os
import sys

__all__ = [
    "RenderingUnavailable",
    "has_display",
    "resolve_off_screen",
    "import_pyvista",
    "jupyter_backend",
    "HEADLESS_HELP",
]

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}

HEADLESS_HELP = (
    "headless 3D rendering needs EGL or OSMesa: on Debian/Ubuntu run "
    "`apt-get install -y libegl1 libgl1-mesa-dri` (and optionally "
    "`export VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow`), or `apt-get install -y libosmesa6` "
    "with `export VTK_DEFAULT_OPENGL_WINDOW=vtkOSOpenGLRenderWindow`, or run under `xvfb-run`"
)


class RenderingUnavailable(RuntimeError):
    """No display and no headless OpenGL library: VTK would crash on the first render."""


def has_display() -> bool:
    """True when a window could be opened: always on Windows/macOS, on Linux when ``DISPLAY``
    or ``WAYLAND_DISPLAY`` is set."""
    if sys.platform.startswith(("win", "darwin")):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def resolve_off_screen(off_screen: bool | None = None) -> bool:
    """Decide whether to render off-screen.

    Parameters
    ----------
    off_screen : bool or None
        ``True``/``False`` are returned as given. ``None`` reads ``PYVISTA_OFF_SCREEN`` (true/false)
        and otherwise renders off-screen exactly when :func:`has_display` is False.

    Raises
    ------
    ValueError for a value other than True, False or None.
    """
    if off_screen is not None:
        if not isinstance(off_screen, (bool, int)):
            raise ValueError(f"off_screen must be True, False or None, got {off_screen!r}")
        return bool(off_screen)
    env = os.environ.get("PYVISTA_OFF_SCREEN", "").strip().lower()
    if env in _TRUE:
        return True
    if env in _FALSE:
        return False
    return not has_display()


def _choose_headless_window() -> None:
    """Set ``VTK_DEFAULT_OPENGL_WINDOW`` for a display-less Linux machine, or raise."""
    if has_display() or sys.platform.startswith(("win", "darwin")):
        return
    if os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"):
        return  # the user chose
    if ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    elif ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"
    else:
        raise RenderingUnavailable(f"no display and no EGL/OSMesa library found; {HEADLESS_HELP}")


def import_pyvista():
    """Import and return :mod:`pyvista`, after making headless rendering safe.

    Raises
    ------
    RenderingUnavailable
        No display and neither ``libEGL`` nor ``libOSMesa`` is installed (VTK would segfault).
    ImportError
        pyvista is not installed.
    """
    _choose_headless_window()
    import pyvista

    return pyvista


def jupyter_backend(backend: str | None = None) -> str:
    """The view the Jupyter player uses: ``"static"`` or ``"trame"``.

    Parameters
    ----------
    backend : str or None
        ``"static"``: frames rendered off-screen and shown as images (works everywhere, CI too).
        ``"trame"``: an interactive pyvista/trame view (rotate, zoom) updated per frame; needs
        ``pip install 'pyvista[jupyter]'`` and a live Jupyter server. ``None``: read
        ``PYVISTA_JUPYTER_BACKEND`` (``trame``/``server``/``client`` -> trame when installed;
        anything else -> static).

    Raises
    ------
    ValueError for a backend other than ``'static'``, ``'trame'`` or None.
    """
    if backend is None:
        backend = os.environ.get("PYVISTA_JUPYTER_BACKEND", "").strip().lower() or None
    if backend is None:
        return "static"
    backend = backend.lower()
    if backend in ("trame", "server", "client"):
        return "trame" if importlib.util.find_spec("trame_pyvista") or importlib.util.find_spec("trame") else "static"
    if backend in ("static", "none", "html"):
        return "static"
    raise ValueError(f"unknown Jupyter backend {backend!r}; expected 'static', 'trame' or None")
