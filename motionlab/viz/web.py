"""An animated 3D player for web pages: skeletons drawn by three.js in the browser.

:func:`player` returns an HTML output holding the joint positions of one or more motions (as
JSON) and a small script (``web_player.js``): play/pause, a time slider, orbit (drag) and zoom
(wheel), skeletons overlaid or side by side in the notebooks' colours
(:data:`motionlab.viz.scene.PALETTE`). It draws with three.js when the page has it as
``window.THREE``, and otherwise, after waiting two seconds for it, on the browser's own 2D canvas
(the same camera and controls; bones as flat strokes, far ones first), so a player shows the
motion wherever its script runs. three.js comes from:

* the documentation site does: ``scripts/build_docs.sh`` vendors three.js from npm into the site
  (``scripts/vendor_three.sh`` writes ``build/web/three.min.js``), so a page with a player works
  from ``file://`` with no server and no network;
* in JupyterLab or VS Code, :func:`player` embeds that vendored file by itself (``three_js="auto"``,
  the default there) in the first player it shows in a kernel, about 0.5 MB; later players of the
  same page wait for it. ``three_js=True`` (or a path to a three.js build) embeds it in every output,
  which then works anywhere; ``MOTIONLAB_WEB_EMBED=0`` turns the automatic embedding off (for
  outputs stored for the documentation site, which has three.js already).

A notebook reopened from disk is *not trusted*, and JupyterLab runs no script of its outputs: the
player then shows a line saying so instead of an empty box (run the cell again, or trust the
notebook).

PyVista (:mod:`motionlab.viz.player`) stays the notebooks' interactive player; this one is for
pages read without a kernel. Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

import base64
import hashlib
import html
import itertools
import json
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from motionlab.core.motion import Motion
from motionlab.viz.scene import PALETTE

__all__ = ["THREE_JS_ENV", "EMBED_ENV", "vendored_three_js", "player_data", "player_html", "player"]

THREE_JS_ENV = "MOTIONLAB_THREE_JS"
"""Environment variable naming a three.js build (a classic script defining ``THREE``) for ``three_js=True``."""

EMBED_ENV = "MOTIONLAB_WEB_EMBED"
"""Environment variable: ``0`` stops :func:`player` from embedding three.js by itself (``three_js="auto"``)."""

_TEMPLATE = Path(__file__).with_name("web_player.js")
_EMBEDDED: dict = {"done": False}  # three.js already embedded in an output of this kernel ("auto")
_COUNTER = itertools.count(1)  # with the data's hash, an element id that is unique on a page and the same in every run


def vendored_three_js() -> Path:
    """The three.js build to embed: ``$MOTIONLAB_THREE_JS``, else ``build/web/three.min.js`` of this checkout.

    Raises
    ------
    FileNotFoundError
        Neither exists; the message says how to make one (``bash scripts/vendor_three.sh``).
    """
    named = os.environ.get(THREE_JS_ENV)
    candidates = [Path(named)] if named else []
    candidates.append(Path(__file__).resolve().parents[2] / "build" / "web" / "three.min.js")
    for path in candidates:
        if path.is_file():
            return path
    raise FileNotFoundError(
        f"no three.js build found (looked at {', '.join(str(p) for p in candidates)}): run "
        f"`bash scripts/vendor_three.sh` in the repository (needs npm), or set {THREE_JS_ENV} to a three.js file"
    )


def _as_list(motions) -> list[Motion]:
    items = [motions] if isinstance(motions, Motion) else list(motions)
    if not items:
        raise ValueError("expected at least one Motion to play, got none")
    for i, m in enumerate(items):
        if not isinstance(m, Motion):
            raise TypeError(f"expected Motion objects, got {type(m).__name__} at position {i}")
        if m.num_frames < 1:
            raise ValueError(f"motion {i} ({m.name!r}) has no frames")
    return items


def player_data(
    motions: Motion | Sequence[Motion],
    colors: Sequence[str] | None = None,
    names: Sequence[str] | None = None,
    spacing: float | None = None,
    max_frames: int = 900,
) -> dict:
    """The JSON-ready description of a player: every motion's joint positions over time.

    Parameters
    ----------
    motions : Motion or sequence of Motion     any skeletons, lengths and frame rates
    colors : sequence of str, optional         CSS colours, one per motion (default: ``PALETTE``)
    names : sequence of str, optional          legend labels (default: each motion's ``name``)
    spacing : float, optional                  side by side: motion ``i`` moved ``i * spacing`` metres
                                               along +x; ``None`` draws them where they are (overlaid)
    max_frames : int                           longer motions keep every ``s``-th frame (``fps / s``)

    Returns
    -------
    dict
        ``skeletons``: one dict per motion with ``name``, ``color``, ``parents`` (J,), ``fps``,
        ``radius`` (bone radius, metres), ``root``: the root's world positions (T, 3) flattened, in
        whole millimetres, and ``joints``: every joint's position relative to the root (T, J, 3),
        whole millimetres as little-endian int16, base64 (about 2.7 characters a number);
        ``fps`` (the highest), ``duration`` (seconds, the longest), ``height`` (metres: the largest
        vertical extent of one frame's joints, over every frame of every motion, at least 0.2 m;
        measured on the motion, so a rig whose rest pose is folded up is framed as it moves), ``middle``
        (metres: halfway between the lowest and the highest joint, where the camera looks) and
        ``distance`` (metres, for the camera), ``grid`` (floor size, metres).

    Raises
    ------
    TypeError, ValueError
        Not Motions, no motions, a motion without frames, ``colors``/``names`` of the wrong length,
        or a joint more than 32 m from its root.
    """
    items = _as_list(motions)
    colors = list(colors) if colors is not None else [PALETTE[i % len(PALETTE)] for i in range(len(items))]
    names = list(names) if names is not None else [m.name or f"motion {i}" for i, m in enumerate(items)]
    for label, values in (("colors", colors), ("names", names)):
        if len(values) != len(items):
            raise ValueError(f"expected {len(items)} {label} (one per motion), got {len(values)}")
    if not (isinstance(max_frames, int) and max_frames >= 1):
        raise ValueError(f"max_frames must be a whole number >= 1, got {max_frames!r}")
    skeletons, lows, highs, extents = [], [], [], []
    for i, m in enumerate(items):
        step = -(-m.num_frames // max_frames)
        m = m[::step] if step > 1 else m
        pos = m.global_positions()
        if spacing is not None:
            pos = pos + np.array([i * float(spacing), 0.0, 0.0])
        if not np.all(np.isfinite(pos)):
            raise ValueError(f"motion {i} ({names[i]!r}) has non-finite joint positions")
        lows.append(pos.min(axis=(0, 1)))
        highs.append(pos.max(axis=(0, 1)))
        extents.append(max(float(np.ptp(pos[..., 1], axis=-1).max()), 0.2))  # as it moves, not its rest pose
        skeletons.append(_skeleton_entry(m, pos, f"motion {i} ({names[i]!r})", names[i], colors[i], extents[-1]))
    height = max(extents)
    spread = float(np.max(np.max(highs, axis=0) - np.min(lows, axis=0)))
    return {
        "skeletons": skeletons,
        "fps": max(s["fps"] for s in skeletons),
        "duration": max(m.duration for m in items),
        "height": height,
        "middle": float(0.5 * (np.min(lows, axis=0)[1] + np.max(highs, axis=0)[1])),
        "distance": 2.2 * height + 0.6 * min(spread, 6.0 * height),
        "grid": float(np.ceil(spread + 4.0 * height)),
    }


def _skeleton_entry(m: Motion, pos: np.ndarray, label: str, name, color, extent: float) -> dict:
    """One skeleton of :func:`player_data`: the root path and the joints relative to it in
    millimetres (int16, base64); ``label`` names the motion in the error."""
    root = np.rint(pos[:, 0] * 1000.0).astype(np.int64)
    rel = np.rint((pos - pos[:, :1]) * 1000.0)
    if np.abs(rel).max() > np.iinfo(np.int16).max:
        raise ValueError(f"{label} has a joint more than 32 m from its root")
    return {
        "name": str(name),
        "color": str(color),
        "parents": [int(p) for p in m.skeleton.parents],
        "fps": m.fps,
        "radius": 0.016 * extent,
        "root": root.ravel().tolist(),
        "joints": base64.b64encode(rel.astype("<i2").tobytes()).decode("ascii"),
    }


def _legend(data: dict) -> str:
    items = [
        f'<span style="white-space:nowrap;margin-right:1em"><span style="display:inline-block;width:0.8em;'
        f'height:0.8em;border-radius:50%;background:{html.escape(s["color"])};margin-right:0.3em"></span>'
        f"{html.escape(s['name'])}</span>"
        for s in data["skeletons"]
    ]
    return "".join(items)


# Intended twin: the same first parameters as player_data, which it wraps.
def player_html(
    motions: Motion | Sequence[Motion],
    colors: Sequence[str] | None = None,
    names: Sequence[str] | None = None,
    spacing: float | None = None,
    height: int = 380,
    autoplay: bool = False,
    three_js: bool | str | os.PathLike | None = None,
    max_frames: int = 900,
) -> str:
    """The player as one HTML fragment (a ``<div>`` with its data and script); see :func:`player_data`.

    Parameters
    ----------
    height : int                    canvas height in CSS pixels (the width follows the page)
    autoplay : bool                 start playing when shown
    three_js : bool, path or None   ``None``: use the page's ``window.THREE``; ``True``: embed
                                    :func:`vendored_three_js`; a path: embed that file;
                                    ``"auto"``: embed the vendored file if there is one, in the
                                    first such output of this process only (unless ``$MOTIONLAB_WEB_EMBED`` is ``0``)
    motions, colors, names, spacing, max_frames : as for :func:`player_data`

    Raises
    ------
    FileNotFoundError
        ``three_js`` asks for a file that does not exist.
    """
    data = player_data(motions, colors, names, spacing, max_frames)
    data["autoplay"] = bool(autoplay)
    if not (isinstance(height, int) and 50 <= height <= 4000):
        raise ValueError(f"height must be a whole number of pixels in [50, 4000], got {height!r}")
    payload = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    player_id = f"motionlab-player-{hashlib.sha1(payload.encode()).hexdigest()[:10]}-{next(_COUNTER)}"
    library = ""
    if isinstance(three_js, str) and three_js == "auto":
        three_js = _auto_three_js()
    if three_js is not None and three_js is not False:
        path = vendored_three_js() if three_js is True else Path(three_js)
        if not path.is_file():
            raise FileNotFoundError(f"three.js file {path} not found")
        library = f"<script>if (!window.THREE) {{\n{path.read_text(encoding='utf-8')}\n}}</script>\n"
    script = _compact(_TEMPLATE.read_text(encoding="utf-8")).replace("__PLAYER_ID__", player_id)
    button = "padding:0.15em 0.8em;border:1px solid #aab;border-radius:4px;background:#fff;cursor:pointer"
    return (
        f'<div class="motionlab-player" id="{player_id}" style="max-width:900px;font:13px sans-serif">\n'
        f'<canvas style="width:100%;height:{height}px;display:block;border-radius:6px;touch-action:none"></canvas>\n'
        f'<div style="display:flex;align-items:center;gap:0.6em;margin-top:0.3em">'
        f'<button class="motionlab-play" type="button" style="{button}">play</button>'
        f'<input class="motionlab-time" type="range" min="0" value="0" style="flex:1">'
        f'<span class="motionlab-label" style="min-width:9em"></span></div>\n'
        f'<div style="margin-top:0.2em;color:#444">{_legend(data)}'
        f'<span style="color:#888">drag to orbit, wheel to zoom</span></div>\n'
        f'<div class="motionlab-message" style="color:#a33">The 3D player has not started: this output\'s script '
        f"did not run (a notebook reopened from disk is not trusted: run the cell again, or trust the notebook)."
        f"</div>\n"
        f'<script type="application/json" class="motionlab-data">{payload}</script>\n'
        f"{library}<script>\n{script}</script>\n</div>"
    )


def _compact(script: str) -> str:
    """``script`` without indentation, blank lines and whole-line ``//`` comments (the player's
    source keeps no string or comment spanning lines, so its meaning is unchanged)."""
    lines = (line.strip() for line in script.splitlines())
    return "\n".join(line for line in lines if line and not line.startswith("//"))


def _auto_three_js() -> Path | None:
    """The vendored three.js for ``three_js="auto"``: once per process, if there is one and
    ``$MOTIONLAB_WEB_EMBED`` is not ``0``; else None (the page must provide ``window.THREE``)."""
    if _EMBEDDED["done"] or os.environ.get(EMBED_ENV, "1") == "0":
        return None
    try:
        path = vendored_three_js()
    except FileNotFoundError:
        return None
    _EMBEDDED["done"] = True
    return path


def player(motions: Motion | Sequence[Motion], **options):
    """The web player as a notebook output (``IPython.display.HTML``); options as for :func:`player_html`,
    with ``three_js="auto"`` unless given (three.js embedded once per kernel when vendored).

    In a notebook, ``web.player([source, result], names=["source", "retargeted"], spacing=1.0)``
    shows both skeletons side by side; on the documentation site the stored output plays as is.
    """
    from IPython.display import HTML

    options.setdefault("three_js", "auto")
    return HTML(player_html(motions, **options))
