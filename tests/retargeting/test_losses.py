"""L_recon, L_angle, L_foot on hand-made cases with known answers."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motionlab.core import humanoid
from motionlab.retargeting import losses


def _rest(scale: float = 1.0) -> torch.Tensor:
    rest = humanoid.canonical_skeleton().rest_positions() * scale
    rest = rest - rest[:1]
    return torch.as_tensor(rest, dtype=torch.float64).expand(5, 22, 3).clone()


def test_recon_loss_known_value():
    a = torch.zeros(2, 4, 22, 3)
    b = a.clone()
    b[..., 0] = 3.0  # every joint 3 m off: λ/(3TJ) Σ 3 = 0.5 · 3 / 3
    assert float(losses.recon_loss(a, b)) == pytest.approx(0.5)
    assert float(losses.recon_loss(a, a)) == 0.0


def test_foot_loss_zero_when_all_feet_above_ground():
    y = torch.full((10, 22), 0.2)
    assert float(losses.foot_loss(y)) == 0.0
    y[:, list(losses.FOOT_JOINTS)] = 0.0  # touching is not penetrating
    assert float(losses.foot_loss(y)) == 0.0
    y[:, 0] = -1.0  # a non-foot joint below ground does not count
    assert float(losses.foot_loss(y)) == 0.0


def test_foot_loss_positive_below_ground_known_value():
    y = torch.full((10, 4), 0.1)
    y[3, 0] = -0.4  # one foot joint, one frame, 0.4 m deep: 0.4 / (4 · 10)
    assert float(losses.foot_loss(y)) == pytest.approx(0.01)
    y[:, 2] = -0.1  # a toe 0.1 m down in every frame adds 0.1 · 10 / 40
    assert float(losses.foot_loss(y)) == pytest.approx(0.01 + 0.025)


def test_angle_loss_zero_against_itself_and_scale_invariant():
    p = _rest()
    assert float(losses.direction_loss(p, p)) == pytest.approx(0.0, abs=1e-12)
    assert float(losses.direction_loss(p, _rest(1.7))) == pytest.approx(0.0, abs=1e-12)


def test_angle_loss_positive_for_a_bent_limb_known_value():
    p = _rest()
    q = p.clone()
    arm = humanoid.JOINTS.index("LeftArm")
    hand = humanoid.JOINTS.index("LeftHand")
    fore = humanoid.JOINTS.index("LeftForeArm")
    # swing the forearm+hand (pointing +x) to point +y: forearm and hand bone directions change by 90°
    length_fore = float((p[0, fore] - p[0, arm]).norm())
    length_hand = float((p[0, hand] - p[0, fore]).norm())
    q[:, fore] = p[:, arm] + torch.tensor([0.0, length_fore, 0.0], dtype=torch.float64)
    q[:, hand] = q[:, fore] + torch.tensor([0.0, length_hand, 0.0], dtype=torch.float64)
    expected = 2 * np.sqrt(2) / 22  # two bones, each ‖x̂ − ŷ‖ = √2, averaged over 22 joints
    assert float(losses.direction_loss(p, q)) == pytest.approx(expected, rel=1e-9)


def test_angle_loss_on_joint_rotations():
    g = torch.Generator().manual_seed(0)
    q = torch.nn.functional.normalize(torch.randn(7, 22, 4, generator=g), dim=-1)
    assert float(losses.angle_loss(q, q)) == pytest.approx(0.0, abs=1e-5)
    assert float(losses.angle_loss(q, -q)) == pytest.approx(0.0, abs=1e-5)  # same rotations
    r = q.clone()
    r[:, 3] = torch.tensor([np.cos(0.25), np.sin(0.25), 0.0, 0.0])  # another rotation at joint 3 only
    expected = torch.minimum((q[:, 3] - r[:, 3]).norm(dim=-1), (q[:, 3] + r[:, 3]).norm(dim=-1)).mean() / 22
    assert float(losses.angle_loss(q, r)) == pytest.approx(float(expected), rel=1e-4)


def test_rotation_loss_sign_agnostic():
    q = torch.nn.functional.normalize(torch.randn(6, 22, 4), dim=-1)
    assert float(losses.rotation_loss(q, -q)) == pytest.approx(0.0, abs=1e-6)
    assert float(losses.rotation_loss(q, q.roll(1, dims=0))) > 0.0


def test_bad_shapes_refused():
    with pytest.raises(ValueError, match="equal shape"):
        losses.recon_loss(torch.zeros(2, 22, 3), torch.zeros(3, 22, 3))
    with pytest.raises(ValueError, match="22"):
        losses.foot_loss(torch.zeros(5, 7))


def test_angle_loss_is_two_sines_of_a_quarter_angle():
    """‖q_A − q_B‖ for unit quaternions 2 sin(α/4) apart by a rotation of α (≈ α/2, not α)."""
    from motionlab.core import quat_torch as tq
    from motionlab.retargeting.losses import angle_loss

    alpha = torch.tensor(0.7)
    a = tq.IDENTITY.expand(1, 22, 4)
    b = tq.from_axis_angle(torch.tensor([0.0, 1.0, 0.0]), alpha).expand(1, 22, 4)
    assert float(angle_loss(a, b)) == pytest.approx(float(2 * torch.sin(alpha / 4)), rel=1e-5)
    assert float(angle_loss(a, -b)) == pytest.approx(float(2 * torch.sin(alpha / 4)), rel=1e-5)  # sign-blind


def test_clearance_loss_is_the_mean_depth_of_the_feet_below_their_allowed_heights():
    feet = torch.tensor([[[0.10, 0.00, 0.05, 0.20], [0.30, 0.30, 0.30, 0.30]]], dtype=torch.float64, requires_grad=True)
    allowed = torch.tensor([[[0.15, 0.00, 0.00, 0.10], [0.0, 0.0, 0.0, 0.5]]], dtype=torch.float64)
    value = losses.clearance_loss(feet, allowed)
    assert float(value.detach()) == pytest.approx((0.05 + 0.20) / 8)
    (grad,) = torch.autograd.grad(value, feet)
    assert torch.count_nonzero(grad) == 2  # only the two joints below their height pull
    above = losses.clearance_loss(feet.detach() + 1.0, allowed)
    assert float(above) == 0.0
    with pytest.raises(ValueError, match=r"\(\.\.\., T, 4\)"):
        losses.clearance_loss(feet[..., :3], allowed[..., :3])
