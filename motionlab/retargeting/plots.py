"""Figures (and two small measurements) for the retargeting notebooks; matplotlib is imported lazily.

* :func:`draw_architecture` — the network of paper A as a block diagram with tensor shapes;
* :class:`LiveLossPlot` — a ``callback(step, record)`` for :func:`~motionlab.retargeting.train.train`
  and :func:`~motionlab.retargeting.solver.solve` that redraws one figure in place while it runs
  (in a Jupyter kernel with an inline/widget backend), or only draws the final figure when it
  runs headless (CI), so a notebook never fills up with frames;
* :func:`plot_reconstruction` — true vs reconstructed joint coordinates over time;
* :func:`plot_iteration` — ``L_iter``, ``L_angle``, ``L_foot`` (and ``L_contact``) over the latent iteration;
* :func:`foot_heights` / :func:`plot_foot_heights` — lowest point of each foot over time;
* :func:`joint_angle_errors` / :func:`plot_joint_errors` — per-joint rotation differences;
* :func:`plot_summary` — bars of a few columns of :meth:`Evaluation.summary`.

Taught in ``notebooks/02_training_autoencoder.ipynb`` and ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence

import numpy as np

from motionlab.core import humanoid, quat

__all__ = [
    "draw_architecture",
    "LiveLossPlot",
    "plot_reconstruction",
    "plot_iteration",
    "foot_heights",
    "plot_foot_heights",
    "joint_angle_errors",
    "plot_joint_errors",
    "plot_summary",
]


def _plt():
    import matplotlib.pyplot as plt

    return plt


def _axes(ax, figsize):
    if ax is None:
        _, ax = _plt().subplots(figsize=figsize)
    return ax


# ----------------------------------------------------------------------------- architecture
class _Diagram:
    """Boxes, arrows and shape labels of :func:`draw_architecture` on one Axes."""

    W, H = 2.0, 0.85

    def __init__(self, ax):
        self.ax = ax

    def box(self, x, y, text, color, w=W):
        from matplotlib.patches import FancyBboxPatch

        H = self.H
        self.ax.add_patch(
            FancyBboxPatch(
                (x - w / 2, y - H / 2), w, H, boxstyle="round,pad=0.04", fc=color, ec="0.25", lw=1.2, zorder=2
            )
        )
        self.ax.text(x, y, text, ha="center", va="center", fontsize=10, zorder=3)

    def arrow(self, a, b, rad=0.0):
        from matplotlib.patches import FancyArrowPatch

        self.ax.add_patch(
            FancyArrowPatch(
                a, b, arrowstyle="-|>", mutation_scale=13, lw=1.2, color="0.3",
                connectionstyle=f"arc3,rad={rad}", zorder=1, shrinkA=0, shrinkB=0,
            )
        )  # fmt: skip

    def label(self, x, y, text, ha="center"):
        self.ax.text(x, y, text, ha=ha, va="center", fontsize=8.5, color="0.1", zorder=4,
                     bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.9})  # fmt: skip


def draw_architecture(config=None, frames: int = 120, ax=None):
    """Block diagram of :class:`~motionlab.retargeting.model.RetargetNet` with the shape of every tensor.

    Parameters
    ----------
    config : ModelConfig or None   sizes to print (D, E); default ``ModelConfig()``
    frames : int                   T shown in the shapes
    ax : matplotlib Axes or None

    Returns
    -------
    the Axes
    """
    from motionlab.retargeting.model import FEATURE_DIM, NUM_JOINTS, ModelConfig

    cfg = config or ModelConfig()
    T, J, D, E = frames, NUM_JOINTS, cfg.latent, cfg.skel_embed
    ax = _axes(ax, (14, 5.0))
    ax.set_xlim(-0.15, 15.35)
    ax.set_ylim(-0.55, 4.6)
    ax.axis("off")
    W, H = _Diagram.W, _Diagram.H
    d = _Diagram(ax)
    box, arrow, label = d.box, d.arrow, d.label

    net, data, op = "#cfe2f3", "#f4f4f4", "#fde9c9"
    top, mid, bot = 3.9, 2.35, 0.8
    xa, xenc, xq, xham, xfk, xp = 1.0, 4.2, 7.4, 10.1, 12.4, 14.5
    box(xa, top, "$X_A$: window of\n$p_t$ features", data)
    box(xenc, top, "$F_{enc}$\ntemporal 1-D convs", net)
    box(xq, top, "$F_{qlinear}$\nlinear, $/\\|\\cdot\\|$", net)
    box(xham, mid, "$q \\leftarrow q \\otimes q_\\Delta$\nHamilton product", op)
    box(xfk, mid, "FK$(q, \\bar S)$\nforward kinematics", op)
    box(xp, mid, "$P'$ joint\npositions", data, w=1.4)
    box(xa, bot, "$\\bar S$: T-pose\nbone offsets", data)
    box(xenc, bot, "$F_{skel}$\nMLP, $/\\|\\cdot\\|$", net)
    box(xq, bot + 0.35, "$F_\\Delta$\nMLP, $/\\|\\cdot\\|$", net)
    arrow((xa + W / 2, top), (xenc - W / 2, top))
    label((xa + xenc) / 2, top + 0.3, f"({T}, {FEATURE_DIM})")
    arrow((xenc + W / 2, top), (xq - W / 2, top))
    label((xenc + xq) / 2, top + 0.3, f"$\\varphi$  ({T}, {D})")
    arrow((xenc + 0.3, top - H / 2), (xq - W / 2, bot + 0.35 + 0.2))
    label(5.6, 2.35, f"$\\varphi$  ({T}, {D})")
    arrow((xa + W / 2, bot), (xenc - W / 2, bot))
    label((xa + xenc) / 2, bot + 0.3, f"({J}, 3)")
    arrow((xenc + W / 2, bot), (xq - W / 2, bot + 0.2))
    label(5.8, bot - 0.2, f"$\\bar S'$  ({E},)")
    arrow((xq + W / 2, top), (xham - 0.5, mid + H / 2))
    label(9.1, top - 0.15, f"$q$  ({T}, {J}, 4)")
    arrow((xq + W / 2, bot + 0.35), (xham - 0.5, mid - H / 2))
    label(9.1, bot + 0.3, f"$q_\\Delta$  ({T}, {J}, 4)")
    arrow((xham + W / 2, mid), (xfk - W / 2, mid))
    label((xham + xfk) / 2, mid + 0.62, f"({T}, {J}, 4)")
    arrow((xfk + W / 2, mid), (xp - 0.7, mid))
    label((xfk + xp) / 2 + 0.1, mid + 0.62, f"({T}, {J}, 3)")
    arrow((xa, bot - H / 2), (xfk, mid - H / 2), rad=0.18)
    label(9.3, -0.3, "the same $\\bar S$: FK puts the rotations on the skeleton")
    ax.set_title(
        f"RetargetNet: T = {T} frames, J = {J} joints, D = {D} latent channels per frame, E = {E} (blue: learned)",
        fontsize=11,
    )
    return ax


# ----------------------------------------------------------------------------- live plot
def _interactive_backend() -> bool:
    """True inside a running IPython kernel whose matplotlib backend shows figures inline/widgets."""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    if shell is None or not hasattr(shell, "kernel"):
        return False
    import matplotlib

    backend = matplotlib.get_backend().lower()
    return any(k in backend for k in ("inline", "ipympl", "widget", "nbagg"))


class LiveLossPlot:
    """A training / iteration callback that plots named values of each ``record`` against its step.

    Use as ``callback=live`` in :func:`~motionlab.retargeting.train.train` (records with ``recon``,
    ``rot``, ``loss``) or :func:`~motionlab.retargeting.solver.solve` (``loss``, ``angle``,
    ``foot``), then call :meth:`finish` once for the final figure.

    Parameters
    ----------
    keys : sequence of str       record entries to plot
    labels : mapping or None     legend / title text per key
    separate : bool              one panel per key (for values of different units) instead of one
    logy : bool                  logarithmic y axes
    xlabel : str
    title : str
    live : bool or None          redraw while running; None: only inside a Jupyter kernel with an
                                 inline or widget backend (never in headless CI runs)
    min_interval : float         seconds between two redraws (keeps the overhead small)
    """

    def __init__(
        self,
        keys: Sequence[str] = ("loss",),
        labels: Mapping[str, str] | None = None,
        separate: bool = False,
        logy: bool = True,
        xlabel: str = "step",
        title: str = "",
        live: bool | None = None,
        min_interval: float = 2.0,
    ) -> None:
        """A plot of the losses ``keys``, drawn as the steps come in.

        Raises
        ------
        ValueError when no key is given.
        """
        if not keys:
            raise ValueError("LiveLossPlot needs at least one key to plot")
        self.keys = tuple(keys)
        self.labels = dict(labels or {})
        self.separate = bool(separate)
        self.logy = bool(logy)
        self.xlabel = xlabel
        self.title = title
        self.live = _interactive_backend() if live is None else bool(live)
        self.min_interval = float(min_interval)
        self.steps: list[int] = []
        self.values: dict[str, list[float]] = {k: [] for k in self.keys}
        self.redraws = 0
        self._fig = None
        self._handle = None
        self._last = -np.inf

    def __call__(self, step: int, record: Mapping[str, float]) -> None:
        missing = [k for k in self.keys if k not in record]
        if missing:
            raise ValueError(f"LiveLossPlot: record at step {step} has no {missing}; it has {sorted(record)}")
        self.steps.append(int(step))
        for k in self.keys:
            self.values[k].append(float(record[k]))
        if self.live and time.perf_counter() - self._last >= self.min_interval:
            self._show()

    def _draw(self):
        plt = _plt()
        n = len(self.keys) if self.separate else 1
        if self._fig is None:
            self._fig, axes = plt.subplots(1, n, figsize=(5.5 * n if n > 1 else 7, 3.2), squeeze=False)
        fig = self._fig
        axes = fig.axes
        for ax in axes:
            ax.clear()
        for i, k in enumerate(self.keys):
            ax = axes[i] if self.separate else axes[0]
            y = np.asarray(self.values[k])
            ax.plot(self.steps, y, color=f"C{i}", label=self.labels.get(k, k))
            if self.logy and np.all(y[np.isfinite(y)] > 0) and len(y):
                ax.set_yscale("log")
            ax.set_xlabel(self.xlabel)
            ax.grid(alpha=0.3)
            if self.separate:
                ax.set_title(self.labels.get(k, k), fontsize=10)
        if not self.separate:
            axes[0].legend()
        if self.title:
            fig.suptitle(self.title, fontsize=11)
        fig.tight_layout()
        return fig

    def _show(self) -> None:
        from IPython.display import display

        fig = self._draw()
        if self._handle is None:
            self._handle = display(fig, display_id=True)
        else:
            self._handle.update(fig)
        self.redraws += 1
        self._last = time.perf_counter()

    def finish(self):
        """Draw the final figure and return it (live: update the shown figure and close it).

        Raises
        ------
        ValueError when nothing was recorded.
        """
        if not self.steps:
            raise ValueError("LiveLossPlot.finish: nothing was recorded (was it passed as callback=?)")
        if self.live:
            self._show()
            fig = self._fig
            _plt().close(fig)  # already displayed: keep the inline backend from showing it twice
            return fig
        return self._draw()


# ----------------------------------------------------------------------------- reconstruction
def plot_reconstruction(true_pos, pred_pos, joints: Sequence[str], fps: float | None = None, axes=None):
    """True (solid) vs reconstructed (dashed) x, y, z of a few joints over time.

    Parameters
    ----------
    true_pos, pred_pos : array (T, 22, 3)   canonical joint positions, metres
    joints : joint names (one panel each)
    fps : float or None                     x axis in seconds when given

    Raises
    ------
    ValueError unless both arrays are (T, 22, 3).
    """
    true_pos, pred_pos = np.asarray(true_pos), np.asarray(pred_pos)
    if true_pos.shape != pred_pos.shape or true_pos.shape[-2:] != (len(humanoid.JOINTS), 3):
        raise ValueError(f"expected two (T, 22, 3) arrays, got {true_pos.shape} and {pred_pos.shape}")
    if axes is None:
        _, axes = _plt().subplots(1, len(joints), figsize=(4.3 * len(joints), 3.2), squeeze=False)
        axes = axes[0]
    t = np.arange(len(true_pos)) / fps if fps else np.arange(len(true_pos))
    for ax, name in zip(axes, joints):
        j = humanoid.JOINTS.index(name)
        for c, axis in enumerate("xyz"):
            ax.plot(t, true_pos[:, j, c], color=f"C{c}", lw=1.8, label=f"{axis} true")
            ax.plot(t, pred_pos[:, j, c], color=f"C{c}", lw=1.4, ls="--", label=f"{axis} network")
        err = 100 * np.linalg.norm(true_pos[:, j] - pred_pos[:, j], axis=-1).mean()
        ax.set_title(f"{name} (mean error {err:.1f} cm)", fontsize=10)
        ax.set_xlabel("time (s)" if fps else "frame")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("m (root-relative, heading frame)")
    axes[0].legend(fontsize=7, ncol=3)
    return axes


# ----------------------------------------------------------------------------- latent iteration
_TITLES = {
    "contact": "contact loss: planted feet's speed (cm/s)",
    "floor": "floor loss: mean depth of the other joints below their limit (cm)",
    "clearance": "clearance loss: mean depth of the swinging feet below A's (cm)",
}
_CENTI = {"m": "cm", "m/s": "cm/s"}


def plot_iteration(history: Mapping[str, Sequence[float]], axes=None, title: str = "", config=None):
    """The latent iteration's losses over its steps, labelled from the terms that were actually used.

    Parameters
    ----------
    history : a solver history (:attr:`SolverResult.history`): ``loss`` (L_iter), ``angle``
        (L_angle), ``foot`` (L_foot, metres) and one list per other registered loss term
        (:mod:`motionlab.retargeting.terms`: ``contact`` in m/s, ``floor`` in metres, …; lengths
        of B at the network's character's scale where the solver had
        :data:`~motionlab.retargeting.terms.LENGTH_SCALE`)
    axes : two Axes, plus one per other term shown; None: a new figure
    title : suptitle
    config : the :class:`~motionlab.retargeting.solver.SolverConfig` of the run (default: the
        defaults). Its weights write the L_iter legend; its ``init`` names step 0 (the
        Gauss–Newton start for ``"project"``/``"auto"``, ``φ = F_enc(X_A)`` for ``"encoder"``).
        A term other than L_angle and L_foot is in the legend, and gets its own panel, when its
        weight is positive and the history holds a nonzero value of it.

    Returns
    -------
    the Axes

    Raises
    ------
    ValueError when the history lacks ``'loss'``, ``'angle'`` or ``'foot'``.
    """
    from motionlab.retargeting import terms
    from motionlab.retargeting.solver import SolverConfig

    for k in ("loss", "angle", "foot"):
        if k not in history or not len(history[k]):
            raise ValueError(f"plot_iteration needs a solver history with 'loss', 'angle' and 'foot'; {k!r} is missing")
    cfg = config or SolverConfig()
    registered = [t for t in terms.registered() if t.name in history]
    shown = [
        t
        for t in registered
        if t.name not in ("angle", "foot") and cfg.weight(t.name) > 0 and np.any(np.asarray(history[t.name]) != 0)
    ]
    legend = [f"{cfg.weight(t.name):g} L_{{{t.name}}}" for t in registered if t.name in ("angle", "foot")]
    legend += [f"{cfg.weight(t.name):g} L_{{{t.name}}}" for t in shown]
    uses_encoder = cfg.init == "encoder" or (cfg.init == "auto" and cfg.theta != "rotations")
    start = "$\\varphi = F_{enc}(X_A)$" if uses_encoder else "the Gauss–Newton start"
    if axes is None:
        _, axes = _plt().subplots(1, 2 + len(shown), figsize=(11 + 4 * len(shown), 3.2))
    steps = np.arange(len(history["loss"]))
    ax = axes[0]
    ax.plot(steps, history["angle"], color="C0", label="$L_{angle}$")
    ax.plot(steps, history["loss"], color="0.4", ls=":", label="$L_{iter} = " + " + ".join(legend) + "$")
    ax.set_title("joint-angle loss (unitless)", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.plot(steps, 100 * np.asarray(history["foot"]), color="C3", label="$L_{foot}$")
    ax.set_title("foot loss: mean depth below the ground (cm)", fontsize=10)
    for k, (ax, term) in enumerate(zip(axes[2:], shown)):
        scale = 100 if term.unit in _CENTI else 1
        unit = _CENTI.get(term.unit, term.unit)
        ax.plot(
            steps, scale * np.asarray(history[term.name], dtype=float), color=f"C{2 + k}", label=f"$L_{{{term.name}}}$"
        )
        ax.set_title(_TITLES.get(term.name, f"{term.name} loss" + (f" ({unit})" if unit else "")), fontsize=10)
    for ax in axes:
        ax.set_xlabel(f"iteration step (0 = {start})")
        ax.grid(alpha=0.3)
    if title:
        axes[0].figure.suptitle(title, fontsize=11)
        axes[0].figure.tight_layout()
    return axes


def foot_heights(positions) -> np.ndarray:
    """Lowest point of each foot, ``min(y_Foot, y_ToeBase)``, left and right: (T, 22, 3) → (T, 2), metres.

    Raises
    ------
    ValueError when ``pos`` is not (T, 22, 3).
    """
    pos = np.asarray(positions)
    if pos.ndim != 3 or pos.shape[1:] != (len(humanoid.JOINTS), 3):
        raise ValueError(f"expected canonical world positions (T, 22, 3), got {pos.shape}")
    idx = humanoid.JOINTS.index
    left = np.minimum(pos[:, idx("LeftFoot"), 1], pos[:, idx("LeftToeBase"), 1])
    right = np.minimum(pos[:, idx("RightFoot"), 1], pos[:, idx("RightToeBase"), 1])
    return np.stack([left, right], axis=-1)


def plot_foot_heights(results: Mapping[str, np.ndarray], fps: float | None = None, axes=None, title: str = ""):
    """Lowest point of the left and right foot over time for several motions (T, 22, 3), in cm.

    The region below the ground (y < 0: the foot sinks into the floor) is shaded.
    """
    if axes is None:
        _, axes = _plt().subplots(1, 2, figsize=(12, 3.2), sharey=True)
    styles = ["-", "--", "-", ":", "-."]
    for i, (name, pos) in enumerate(results.items()):
        h = 100 * foot_heights(pos)
        t = np.arange(len(h)) / fps if fps else np.arange(len(h))
        for side, ax in enumerate(axes):
            ax.plot(t, h[:, side], color=f"C{i}", ls=styles[i % len(styles)], lw=1.5, label=name)
    for side, ax in zip(("left", "right"), axes):
        lo = min(ax.get_ylim()[0], -1.0)
        ax.axhspan(lo, 0.0, color="0.85", zorder=0)
        ax.axhline(0.0, color="0.3", lw=0.8)
        ax.set_ylim(bottom=lo)
        ax.set_title(f"{side} foot: lowest of ankle and toe", fontsize=10)
        ax.set_xlabel("time (s)" if fps else "frame")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("height above ground (cm)")
    axes[0].legend(fontsize=8)
    if title:
        axes[0].figure.suptitle(title, fontsize=11)
        axes[0].figure.tight_layout()
    return axes


def joint_angle_errors(local_rot, reference_rot) -> np.ndarray:
    """Mean rotation angle between two sets of local rotations, per joint: (T, 22, 4) × 2 → (22,), degrees.

    Raises
    ------
    ValueError unless both arrays are (T, J, 4) of the same J, with T >= 1.
    """
    a, b = np.asarray(local_rot), np.asarray(reference_rot)
    n = min(len(a), len(b))
    if a.ndim != 3 or a.shape[1:] != b.shape[1:] or a.shape[-1] != 4 or n == 0:
        raise ValueError(f"expected two (T, J, 4) rotation arrays, got {a.shape} and {b.shape}")
    return np.degrees(quat.angle_between(a[:n], b[:n])).mean(axis=0)


def plot_joint_errors(
    errors: Mapping[str, np.ndarray], names: Sequence[str] = humanoid.JOINTS, ax=None, title: str = ""
):
    """Grouped bars: one group per joint, one bar per method (degrees)."""
    ax = _axes(ax, (13, 3.4))
    k = len(errors)
    width = 0.8 / max(k, 1)
    x = np.arange(len(names))
    for i, (label, err) in enumerate(errors.items()):
        err = np.asarray(err)
        ax.bar(x + (i - (k - 1) / 2) * width, err, width, color=f"C{i}", label=f"{label} (mean {err.mean():.1f}°)")
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("mean angle (deg)")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


# ----------------------------------------------------------------------------- Table 1
_SUMMARY_LABELS = {
    "mse": "MSE (cm²)",
    "mse_h2": "MSE / h²",
    "pose_mse_h2": "pose MSE / h²",
    "mpjpe": "MPJPE (cm)",
    "smooth": "smoothness (cm/frame²)",
    "pen": "foot penetration (% of h)",
    "skate": "foot skating (cm/s)",
    "time": "time (s / clip)",
}


def plot_summary(
    summary: Mapping[str, Mapping[str, float]], keys: Sequence[str] = ("pose_mse_h2", "smooth", "pen"), axes=None
):
    """Bars of a few columns of :meth:`~motionlab.retargeting.evaluate.Evaluation.summary`, one panel each.

    Rows missing a column (the ground truth has no MSE) are left out of that panel.
    """
    if axes is None:
        _, axes = _plt().subplots(1, len(keys), figsize=(4.6 * len(keys), 3.4), squeeze=False)
        axes = axes[0]
    rows = list(summary)
    for ax, key in zip(axes, keys):
        labels = [r for r in rows if key in summary[r]]
        values = [summary[r][key] for r in labels]
        colors = ["0.6" if r == "ground truth" else f"C{rows.index(r)}" for r in labels]
        ax.barh(np.arange(len(labels)), values, color=colors)
        ax.set_yticks(np.arange(len(labels)))
        ax.set_yticklabels(labels, fontsize=8)
        ax.invert_yaxis()
        ax.set_title(_SUMMARY_LABELS.get(key, key), fontsize=10)
        ax.grid(axis="x", alpha=0.3)
        for i, v in enumerate(values):
            ax.text(v, i, f" {v:.3g}", va="center", fontsize=8)
        top = max([v for v in values if np.isfinite(v)] + [0.0])
        if top > 0:
            ax.set_xlim(0, 1.3 * top)  # room for the value written after the longest bar
    return axes
