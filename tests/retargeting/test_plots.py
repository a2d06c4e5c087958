"""The retargeting notebooks' figures and small measurements (headless: no display is needed)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest

from motionlab.core import humanoid, quat
from motionlab.retargeting import plots
from motionlab.retargeting.model import ModelConfig


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _walk_positions(frames: int = 30) -> np.ndarray:
    rest = humanoid.canonical_skeleton().rest_positions()
    pos = np.repeat(rest[None], frames, axis=0)
    pos[:, :, 1] += 0.05 * np.sin(np.linspace(0, 2 * np.pi, frames))[:, None]
    return pos


def test_foot_heights_known_answer():
    pos = _walk_positions()
    pos[3, humanoid.JOINTS.index("LeftToeBase"), 1] = -0.02  # toe below the ankle and the floor
    h = plots.foot_heights(pos)
    assert h.shape == (30, 2)
    assert h[3, 0] == pytest.approx(-0.02)
    idx = humanoid.JOINTS.index
    np.testing.assert_allclose(h[:, 1], np.minimum(pos[:, idx("RightFoot"), 1], pos[:, idx("RightToeBase"), 1]))


def test_foot_heights_rejects_other_shapes():
    with pytest.raises(ValueError, match="expected canonical world positions"):
        plots.foot_heights(np.zeros((10, 21, 3)))


def test_joint_angle_errors_known_answer_and_sign_free():
    rng = np.random.default_rng(0)
    q = quat.normalize(rng.normal(size=(8, 22, 4)))
    turned = q.copy()
    turned[:, 5] = quat.mul(q[:, 5], quat.from_axis_angle([0.0, 1.0, 0.0], np.radians(30.0)))
    err = plots.joint_angle_errors(turned, -q)  # -q is the same rotation as q
    assert err.shape == (22,)
    assert err[5] == pytest.approx(30.0, abs=1e-6)
    np.testing.assert_allclose(np.delete(err, 5), 0.0, atol=1e-5)


def test_joint_angle_errors_rejects_mismatch():
    with pytest.raises(ValueError, match="rotation arrays"):
        plots.joint_angle_errors(np.zeros((5, 22, 4)), np.zeros((5, 21, 4)))


def test_live_loss_plot_headless_records_and_draws_once():
    live = plots.LiveLossPlot(("recon", "rot"), live=None)
    assert not live.live  # no IPython kernel here
    for step in range(1, 6):
        live(step, {"recon": 1.0 / step, "rot": 0.5 / step, "loss": 2.0})
    assert live.steps == [1, 2, 3, 4, 5] and live.redraws == 0
    fig = live.finish()
    assert len(fig.axes) == 1 and len(fig.axes[0].lines) == 2
    np.testing.assert_allclose(fig.axes[0].lines[0].get_ydata(), [1.0, 0.5, 1 / 3, 0.25, 0.2])


def test_live_loss_plot_errors():
    live = plots.LiveLossPlot(("angle", "foot"), separate=True)
    with pytest.raises(ValueError, match="has no"):
        live(0, {"angle": 1.0})
    with pytest.raises(ValueError, match="nothing was recorded"):
        plots.LiveLossPlot(("loss",)).finish()
    with pytest.raises(ValueError, match="at least one key"):
        plots.LiveLossPlot(())


def test_figures_draw():
    pos = _walk_positions()
    assert plots.draw_architecture(ModelConfig(latent=16, hidden=8, skel_embed=4)) is not None
    assert len(plots.plot_reconstruction(pos, pos + 0.01, ["Head", "LeftHand"], fps=60)) == 2
    axes = plots.plot_foot_heights({"a": pos, "b": pos - 0.02}, fps=60)
    assert axes[0].get_ylim()[0] <= -1.0  # the shaded below-ground band is visible
    history = {"loss": [0.3, 0.2, 0.1], "angle": [0.5, 0.4, 0.3], "foot": [0.01, 0.0, 0.0]}
    plots.plot_iteration(history)
    plots.plot_joint_errors({"x": np.ones(22), "y": np.zeros(22)})
    summary = {"copy": {"pose_mse_h2": 1e-4, "pen": 0.2}, "ground truth": {"pen": 0.0}}
    assert len(plots.plot_summary(summary, keys=("pose_mse_h2", "pen"))) == 2
    with pytest.raises(ValueError, match="solver history"):
        plots.plot_iteration({"loss": [1.0]})


def test_iteration_plot_is_labelled_from_the_terms_and_the_start():
    from motionlab.retargeting.solver import SolverConfig

    history = {"loss": [0.3, 0.2], "angle": [0.0, 0.1], "foot": [0.01, 0.0], "contact": [0.2, 0.1]}
    axes = plots.plot_iteration(history)  # defaults: Gauss-Newton start, contact term on
    assert len(axes) == 3
    assert "0.5 L_{contact}" in axes[0].get_legend().get_texts()[1].get_text()
    assert "Gauss–Newton" in axes[0].get_xlabel()
    paper = SolverConfig(init="encoder", lambda_contact=0.0)
    axes = plots.plot_iteration(dict(history, contact=[0.0, 0.0]), config=paper)
    assert len(axes) == 2
    label = axes[0].get_legend().get_texts()[1].get_text()
    assert "contact" not in label and "0.3 L_{angle} + 0.5 L_{foot}" in label
    assert "F_{enc}" in axes[0].get_xlabel()
