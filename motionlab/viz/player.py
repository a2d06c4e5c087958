"""Play/pause and a frame slider (ipywidgets) driving a 3D scene in JupyterLab.

Two views, chosen by ``backend`` (see :func:`motionlab.viz.backend.jupyter_backend`):

``"static"`` (default; CI, nbval, any Jupyter)
    The scene renders off-screen in the kernel; each frame is sent to an ``ipywidgets.Image``
    as a JPEG. Play, pause and scrub work wherever a kernel runs. The camera is fixed (framing
    the clip) or follows the characters, as the scene says. Where no widget can run at all (a
    notebook exported to HTML, GitHub's viewer) the output also carries a PNG of the current
    frame, and :func:`still` gives a film strip of the clip as a plain image.
``"trame"`` (``pip install 'pyvista[jupyter]'``, live Jupyter server)
    pyvista's trame view in an iframe: rotate and zoom with the mouse; the same Play/slider
    move the characters and push each frame to the view. pyvista's maintainers warn that trame
    is not built for animation, so expect a lower frame rate than the static view.

Playback keeps to real time by skipping frames when rendering is slower than the clip's frame
rate: the Play widget's step and interval are set from the measured render time.

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

import asyncio
import base64
import io
import threading
import time
import warnings
from collections.abc import Sequence

import numpy as np

from motionlab.core.motion import Motion
from motionlab.viz import backend as _backend
from motionlab.viz.scene import Scene, build_scene

__all__ = ["Player", "play", "still", "encode_image", "OwnerThread"]


class OwnerThread:
    """Runs callbacks on the thread that created it (the notebook's main thread).

    An OpenGL context belongs to one thread: VTK renders black images when called from another.
    ipykernel 7 may run widget callbacks (comm messages) outside the thread that executes cells,
    where the scene was created; so widget callbacks go through this, which hands them to the
    kernel's event loop when they arrive on a foreign thread.
    """

    def __init__(self) -> None:
        self.thread = threading.get_ident()
        try:
            self.loop = asyncio.get_running_loop()
        except RuntimeError:
            self.loop = None

    def __call__(self, function, *args) -> None:
        if threading.get_ident() == self.thread or self.loop is None or self.loop.is_closed():
            function(*args)
        else:
            self.loop.call_soon_threadsafe(function, *args)


def encode_image(image: np.ndarray, fmt: str = "jpeg", quality: int = 85) -> bytes:
    """Encode an image (H, W, 3) uint8 as JPEG or PNG bytes.

    Raises
    ------
    ValueError for a format other than ``'jpeg'`` or ``'png'``.
    """
    from PIL import Image

    if fmt not in ("jpeg", "png"):
        raise ValueError(f"fmt must be 'jpeg' or 'png', got {fmt!r}")
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image[..., :3])).save(
        buf, format=fmt.upper(), **({"quality": quality} if fmt == "jpeg" else {})
    )
    return buf.getvalue()


class Player:
    """An ipywidgets player for a :class:`~motionlab.viz.scene.Scene`.

    Parameters
    ----------
    motions : Motion, list of Motions, or a Scene (used as it is)
    backend : ``"static"``, ``"trame"`` or None (environment: ``PYVISTA_JUPYTER_BACKEND``)
    image_format : ``"jpeg"`` (fast, small) or ``"png"`` for the static view
    **scene_options : passed to :class:`Scene` when ``motions`` is not a Scene; the scene is
        rendered off-screen unless ``off_screen`` says otherwise

    Attributes
    ----------
    scene : the Scene being shown
    play, slider : the ``ipywidgets.Play`` and ``IntSlider`` (linked in the browser)
    view : the image (static) or trame iframe widget
    widget : the whole layout (displayed when the Player is the last expression of a cell)
    render_seconds : measured time to render and send one frame
    """

    def __init__(
        self,
        motions: Motion | Sequence[Motion] | Scene,
        backend: str | None = None,
        image_format: str = "jpeg",
        **scene_options,
    ) -> None:
        import ipywidgets as widgets

        self.backend = _backend.jupyter_backend(backend)
        if not isinstance(motions, Scene):
            scene_options.setdefault("off_screen", True)
        self.scene = build_scene(motions, **scene_options)
        self.image_format = image_format
        width, height = self.scene.plotter.window_size
        last = self.scene.num_frames - 1
        self.play = widgets.Play(value=0, min=0, max=last, step=1, interval=100, repeat=True, description="play")
        self.slider = widgets.IntSlider(
            value=0, min=0, max=last, description="frame", continuous_update=True, layout=widgets.Layout(width="55%")
        )
        self.label = widgets.Label()
        widgets.jslink((self.play, "value"), (self.slider, "value"))
        self.view = None
        if self.backend == "trame":
            try:
                self.view = self.scene.plotter.show(
                    jupyter_backend="server", return_viewer=True, jupyter_kwargs={"add_menu": False}
                )
            except Exception as e:  # no Jupyter server, trame missing pieces: fall back, say why
                warnings.warn(f"trame view unavailable ({e}); using the static view", RuntimeWarning, stacklevel=2)
                self.backend = "static"
        if self.view is None:
            self.view = widgets.Image(format=image_format, width=width, height=height)
        self._busy = False
        self._owner = OwnerThread()
        self.show_frame(0)  # the first render compiles shaders: not representative
        self.render_seconds = min(self._timed_show(min(1, self.scene.num_frames - 1)), self._timed_show(0))
        self._tune_playback()
        self.slider.observe(self._on_slider, names="value")
        self.widget = widgets.VBox([self.view, widgets.HBox([self.play, self.slider, self.label])])

    # -------------------------------------------------------------- frames
    def _timed_show(self, t: int) -> float:
        start = time.perf_counter()
        self.show_frame(t)
        return time.perf_counter() - start

    def _tune_playback(self) -> None:
        """Step and interval of the Play widget: real time, skipping frames if rendering is slow."""
        period = 1.0 / self.scene.fps
        step = max(1, int(np.ceil(1.25 * self.render_seconds / period)))
        self.play.step = step
        self.play.interval = max(int(round(1000 * step * period)), 15)

    def show_frame(self, t: int) -> None:
        """Render frame ``t`` into the view (and move the slider there)."""
        t = int(np.clip(t, 0, self.scene.num_frames - 1))
        self.scene.set_frame(t, render=False)
        if self.backend == "trame":
            self.scene.plotter.render()
            self.view.viewer.update()
        else:
            self.view.value = encode_image(self.scene.screenshot(), self.image_format)
        self.label.value = f"{t / self.scene.fps:5.2f} s"
        if self.slider.value != t:
            self.slider.value = t

    def _on_slider(self, change) -> None:
        self._owner(self._slider_moved, change["new"])

    def _slider_moved(self, t: int) -> None:
        if self._busy or t != self.slider.value:  # re-entry, or a newer position is queued
            return
        self._busy = True
        try:
            self.show_frame(t)
        finally:
            self._busy = False
        self._owner = OwnerThread()

    def refresh(self) -> None:
        """Re-draw after the scene changed (new motion, new length): slider range and view."""
        last = self.scene.num_frames - 1
        self.play.max = last
        self.slider.max = last
        frame = min(self.slider.value, last)
        self.render_seconds = self._timed_show(frame)
        self._tune_playback()

    def image(self) -> np.ndarray:
        """The current frame as an image (H, W, 3) uint8."""
        return self.scene.screenshot()

    # -------------------------------------------------------------- display
    def _repr_mimebundle_(self, **kwargs):
        bundle = self.widget._repr_mimebundle_(**kwargs)
        data = bundle[0] if isinstance(bundle, tuple) else bundle
        data = dict(data or {})
        # a still for front ends without widgets (exported HTML, GitHub); JupyterLab shows the widget
        data["image/png"] = base64.b64encode(encode_image(self.image(), "png")).decode("ascii")
        data["text/plain"] = repr(self)
        return data

    def __repr__(self) -> str:
        return f"Player({self.scene!r}, backend={self.backend!r})"

    def close(self) -> None:
        """Close the widgets and the scene's render window."""
        self.widget.close()
        self.scene.close()


def play(motions: Motion | Sequence[Motion] | Scene, backend: str | None = None, **scene_options) -> Player:
    """A :class:`Player` for ``motions``; display it as the last line of a cell.

    ``camera="follow"`` by default, so a walking character stays in view.
    """
    if not isinstance(motions, Scene):
        scene_options.setdefault("camera", "follow")
    return Player(motions, backend=backend, **scene_options)


def still(motions: Motion | Sequence[Motion] | Scene, num: int = 4, **scene_options):
    """A film strip of ``num`` frames as an ``IPython.display.Image``: the static fallback that
    shows the clip anywhere (CI logs, exported notebooks)."""
    from IPython.display import Image

    from motionlab.viz import export

    return Image(data=export.to_png(export.filmstrip(motions, num=num, **scene_options)), format="png")
