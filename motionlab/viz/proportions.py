"""Bone-proportion sliders: design a new character and watch the motion retargeted onto it.

Five sliders scale bone groups of the 22-joint humanoid through
:func:`motionlab.core.humanoid.scale_bones` -- legs, arms, spine, neck/head and overall size --
and a button resets them. When a slider is *released* (``continuous_update=False``), the new
skeleton goes to a solver, a callable ``solve(skeleton) -> Motion`` (or ``-> (Motion, history)``
with a loss history), and the view updates: the source character on the left, the new one on
the right, and a small plot of the feet's height over the clip (and the solver's loss).

A slow solver (the latent iteration) would leave the old character on
screen meanwhile; so, on a slider release, the editor first shows a *preview* -- the motion of
:func:`copy_rotation_solver` on the new skeleton, with the status line saying so -- and then the
solver's result replaces it. :meth:`ProportionEditor.update` (called from code) shows only the
solver's result.

The solver is injected, so ``viz`` imports none of the three systems: pass
:func:`motionlab.retargeting.proportions.proportion_solver` for the latent iteration. The default,
:func:`copy_rotation_solver`, is a dependency-free stand-in that copies the local rotations,
scales the root path by the hip-height ratio and lifts the clip so no foot goes below the ground.

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping

import numpy as np

from motionlab.core import humanoid
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.viz.compare import side_by_side_offsets
from motionlab.viz.scene import PALETTE, Scene

__all__ = [
    "GROUPS",
    "Solver",
    "canonical_source",
    "feet_height",
    "copy_rotation_solver",
    "ProportionEditor",
]

GROUPS: dict[str, str] = {
    "legs": "legs",
    "arms": "arms",
    "spine": "spine",
    "neck": "neck / head",
    "overall": "overall size",
}
"""Slider name (a :func:`humanoid.scale_bones` argument) -> label."""

Solver = Callable[[Skeleton], "Motion | tuple[Motion, Mapping | None]"]


def canonical_source(motion: Motion) -> Motion:
    """The motion on the 22-joint humanoid (unchanged when it already is).

    Raises
    ------
    ValueError for something other than a Motion.
    """
    if not isinstance(motion, Motion):
        raise ValueError(f"expected a Motion, got {type(motion).__name__}")
    return motion if humanoid.is_canonical(motion.skeleton) else humanoid.to_canonical(motion)


def feet_height(motion: Motion) -> np.ndarray:
    """Height (T, 2) of the lowest of foot and toe, left then right, metres (ground y = 0).

    Raises
    ------
    ValueError when the motion lacks the foot or toe joints of the 22-joint humanoid.
    """
    sk = motion.skeleton
    pos = motion.global_positions()
    out = []
    for side in ("Left", "Right"):
        idx = [sk.index(n) for n in (f"{side}Foot", f"{side}ToeBase") if n in sk.names]
        if not idx:
            raise ValueError(f"motion has no {side}Foot/{side}ToeBase joints; expected the 22-joint humanoid")
        out.append(pos[:, idx, 1].min(axis=1))
    return np.stack(out, axis=1)


def _hip_height(skeleton: Skeleton) -> float:
    rest = skeleton.rest_positions()
    return float(rest[0, 1] - rest[:, 1].min())


def copy_rotation_solver(source: Motion) -> Callable[[Skeleton], Motion]:
    """A stand-in solver: ``solve(skeleton)`` copies ``source``'s local rotations onto the new
    skeleton, scales the root path by the ratio of hip heights, and shifts the whole clip up or
    down so its lowest foot point is where the source's was (never below the ground).

    Works without torch or a trained network; feet may slide or float where the proportions
    change a lot (that is what the latent solver fixes). The returned function carries
    ``is_stand_in = True``, so :class:`ProportionEditor` shows no preview of it.
    """
    source = canonical_source(source)
    source_floor = max(float(feet_height(source).min()), 0.0)

    def solve(skeleton: Skeleton) -> Motion:
        target = skeleton if humanoid.is_canonical(skeleton) else humanoid.to_canonical_skeleton(skeleton)
        if tuple(target.names) != tuple(source.skeleton.names):
            raise ValueError("the new skeleton's joints do not match the source's 22-joint humanoid")
        ratio = _hip_height(target) / max(_hip_height(source.skeleton), 1e-9)
        root = source.root_pos * ratio
        moved = Motion(target, source.local_rot.copy(), root, source.fps, None, f"{source.name or 'motion'}_resized")
        lift = source_floor - float(feet_height(moved).min())
        root = root + np.array([0.0, lift, 0.0])
        return moved.copy(root_pos=root)

    solve.is_stand_in = True
    return solve


def _split(result) -> tuple[Motion, dict]:
    """A solver's result as (Motion, history dict)."""
    history: dict = {}
    if isinstance(result, tuple):
        if len(result) != 2:
            raise ValueError(f"a solver returns a Motion or (Motion, history), got a tuple of {len(result)}")
        result, hist = result
        if isinstance(hist, Mapping):
            history = {k: list(np.ravel(v)) for k, v in hist.items()}
        elif hist is not None:
            history = {"loss": list(np.ravel(hist))}
    if not isinstance(result, Motion):
        raise ValueError(f"the solver must return a Motion (or (Motion, history)), got {type(result).__name__}")
    return result, history


class ProportionEditor:
    """Sliders for bone proportions driving a solver, with a 3D view and a feet/loss plot.

    Parameters
    ----------
    source : the motion to retarget (any rig :func:`humanoid.find_mapping` knows; reduced to the
        22-joint humanoid)
    solve : ``solve(skeleton) -> Motion`` or ``-> (Motion, history)``; default
        :func:`copy_rotation_solver`; the latent iteration is
        :func:`motionlab.retargeting.proportions.proportion_solver`
    backend : Jupyter view, ``"static"``/``"trame"``/None, see :class:`~motionlab.viz.player.Player`
    slider_range : (low, high) of the group sliders
    preview : on a slider release, show :func:`copy_rotation_solver`'s motion on the new skeleton
        before the solver's; default: True unless ``solve`` is None or is
        :func:`copy_rotation_solver`'s (marked ``solve.is_stand_in = True``)
    **scene_options : window_size, camera, trails, ... for the 3D view

    Attributes
    ----------
    skeleton, motion, history : the current new character, its motion and the solver history
    timings : seconds of the last update: ``solve``, ``view`` (3D + plot) and ``total``, and
        ``preview`` (from the release to the preview on screen) when a preview was shown
    widget : the layout to display
    """

    def __init__(
        self,
        source: Motion,
        solve: Solver | None = None,
        backend: str | None = None,
        slider_range: tuple[float, float] = (0.5, 1.6),
        preview: bool | None = None,
        **scene_options,
    ) -> None:
        """Check the solver and the slider range (the widgets are built on display).

        Raises
        ------
        ValueError when ``solve`` is not callable or ``slider_range`` is not 0 < low < 1 < high.
        """
        import ipywidgets as widgets

        from motionlab.viz.player import Player

        self.source = canonical_source(source)
        self.base = self.source.skeleton
        self.solve = solve if solve is not None else copy_rotation_solver(self.source)
        if preview is None:  # no preview of the stand-in by itself
            preview = solve is not None and not getattr(solve, "is_stand_in", False)
        self._preview = copy_rotation_solver(self.source) if preview else None
        if not callable(self.solve):
            raise ValueError(f"solve must be callable as solve(skeleton), got {type(self.solve).__name__}")
        low, high = (float(v) for v in slider_range)
        if not 0 < low < 1 < high:
            raise ValueError(f"slider_range must satisfy 0 < low < 1 < high, got {slider_range}")
        self.sliders = {
            name: widgets.FloatSlider(
                value=1.0,
                min=low,
                max=high,
                step=0.05,
                description=label,
                continuous_update=False,  # act on release only
                readout_format=".2f",
                style={"description_width": "90px"},
            )
            for name, label in GROUPS.items()
        }
        self.reset_button = widgets.Button(description="reset", icon="undo", layout=widgets.Layout(width="90px"))
        self.status = widgets.Label()
        self.plot = widgets.Image(format="png")
        self.timings: dict[str, float] = {}
        self.skeleton = self.base
        self.motion, self.history = _split(self.solve(self.base))

        size = 1.6 * max(self.base.height(), 1e-3)
        offsets = side_by_side_offsets([self.source, self.motion], spacing=max(0.75 * size, 0.5))
        scene_options = {"camera": "follow", "window_size": (560, 420), "off_screen": True, **scene_options}
        scene = Scene(
            [self.source, self.motion],
            offsets=offsets,
            labels=["source", "new character"],
            colors=["#9a9a9a", PALETTE[0]],
            **scene_options,
        )
        self.player = Player(scene, backend=backend)
        self._plot_feet()
        self._suspend = False
        self._queued = False
        self._owner = self.player._owner  # render on the thread that owns the OpenGL context
        for slider in self.sliders.values():
            slider.observe(self._on_release, names="value")
        self.reset_button.on_click(lambda _: self._owner(self.reset))
        controls = widgets.VBox([*self.sliders.values(), widgets.HBox([self.reset_button, self.status])])
        self.widget = widgets.VBox([widgets.HBox([self.player.widget, widgets.VBox([controls, self.plot])])])

    # -------------------------------------------------------------- state
    @property
    def factors(self) -> dict[str, float]:
        """Current slider values, ``{group: factor}``."""
        return {name: float(s.value) for name, s in self.sliders.items()}

    def update(self, **factors: float) -> Motion:
        """Set some sliders (without firing them one by one), solve once, refresh the view.

        Returns the new motion. Unknown names raise ValueError.

        Raises
        ------
        ValueError naming unknown proportions, or a value outside its slider's range (a slider
        would clamp it without a word); no slider changes then.
        """
        unknown = set(factors) - set(GROUPS)
        if unknown:
            raise ValueError(f"unknown proportion(s) {sorted(unknown)}; expected some of {list(GROUPS)}")
        for name, value in factors.items():
            low, high = self.sliders[name].min, self.sliders[name].max
            if not (np.isfinite(value) and low <= value <= high):
                raise ValueError(f"{name}={value!r} is outside its slider's range, {low:g} to {high:g}")
        self._suspend = True
        try:
            for name, value in factors.items():
                self.sliders[name].value = float(value)
        finally:
            self._suspend = False
        return self._apply()

    def reset(self) -> Motion:
        """All sliders back to 1 (the source's proportions), solved once."""
        return self.update(**dict.fromkeys(GROUPS, 1.0))

    def _on_release(self, change) -> None:
        if self._suspend or self._queued:
            return  # an update with the latest slider values is already on its way
        self._queued = True
        self._owner(self._apply_queued)

    def _apply_queued(self) -> None:
        self._queued = False
        self._apply(preview=self._preview is not None)

    def _apply(self, preview: bool = False) -> Motion:
        start = time.perf_counter()
        self.status.value = "solving..."
        skeleton = humanoid.scale_bones(self.base, **self.factors)
        shown = None
        if preview:  # the stand-in's motion on the new skeleton while the solver runs
            self.player.scene.set_motion(1, self._preview(skeleton))
            self.player.refresh()
            self.status.value = f"height {skeleton.height():.2f} m · preview (copied rotations) · solving..."
            shown = time.perf_counter() - start
        begin = time.perf_counter()
        motion, history = _split(self.solve(skeleton))
        solved = time.perf_counter()
        self.skeleton, self.motion, self.history = skeleton, motion, history
        self.player.scene.set_motion(1, motion)
        self.player.refresh()
        self._plot_feet()
        end = time.perf_counter()
        self.timings = {"solve": solved - begin, "view": end - solved, "total": end - start}
        if shown is not None:
            self.timings["preview"] = shown
        self.status.value = (
            f"height {skeleton.height():.2f} m · solved in {self.timings['solve']:.2f} s · "
            f"view in {self.timings['view']:.2f} s"
        )
        return motion

    # -------------------------------------------------------------- the small plot
    def figure(self):
        """A matplotlib Figure: feet height of source and new character, and the solver loss."""
        from matplotlib.figure import Figure

        has_loss = bool(self.history.get("loss"))
        fig = Figure(figsize=(4.2, 3.2 if has_loss else 1.9), dpi=90)  # fixed margins: layout engines cost 0.1 s
        axes = fig.subplots(2 if has_loss else 1, 1, squeeze=False)[:, 0]
        fig.subplots_adjust(left=0.17, right=0.97, top=0.95, bottom=0.14 if has_loss else 0.24, hspace=0.55)
        ax = axes[0]
        for motion, color, style, label in (
            (self.source, "#9a9a9a", "--", "source"),
            (self.motion, PALETTE[0], "-", "new"),
        ):
            h = feet_height(motion)
            t = np.arange(len(h)) / motion.fps
            ax.plot(t, h[:, 0], style, color=color, lw=1.2, label=f"{label} L")
            ax.plot(t, h[:, 1], style, color=color, lw=1.2, alpha=0.6, label=f"{label} R")
        ax.axhline(0.0, color="#c0392b", lw=0.8)
        ax.set_xlabel("time (s)", fontsize=8)
        ax.set_ylabel("feet height (m)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, ncol=2, loc="upper right")
        if has_loss:
            loss = np.asarray(self.history["loss"], dtype=float)
            axes[1].plot(np.arange(len(loss)), loss, color=PALETTE[1], lw=1.2)
            if np.all(loss > 0):
                axes[1].set_yscale("log")
            axes[1].set_xlabel("solver step", fontsize=8)
            axes[1].set_ylabel("loss", fontsize=8)
            axes[1].tick_params(labelsize=7)
        return fig

    def _plot_feet(self) -> None:
        import io

        buf = io.BytesIO()
        self.figure().savefig(buf, format="png")
        self.plot.value = buf.getvalue()

    # -------------------------------------------------------------- display
    def _repr_mimebundle_(self, **kwargs):
        bundle = self.widget._repr_mimebundle_(**kwargs)
        data = dict(bundle[0] if isinstance(bundle, tuple) else bundle)
        data["text/plain"] = repr(self)
        return data

    def __repr__(self) -> str:
        f = ", ".join(f"{k}={v:.2f}" for k, v in self.factors.items())
        return f"ProportionEditor({f})"

    def close(self) -> None:
        """Close the widgets and the render window."""
        self.widget.close()
        self.player.close()
