"""Loss terms as named objects (issue 44 item 1), L_floor (issue 41 item 1) and the reported loss
being the returned iterate's (issue 41 item 5).

The change test registers a term from this file, touching no file of the package, and checks that
the iteration sums it, that the report (history, ``RetargetResult.losses``, the plot), ``expand``'s
manifest and the command-line weight options use it.
"""

from __future__ import annotations

import csv
import re

import numpy as np
import pytest
import torch

from motionlab import retargeting, synthetic
from motionlab.cli import build_parser, main
from motionlab.core import bvh, humanoid, rest_pose
from motionlab.retargeting import expand as ex
from motionlab.retargeting import losses, plots, solver, terms
from motionlab.retargeting.model import Decoded
from motionlab.retargeting.solver import SolverConfig

FAST = SolverConfig(max_steps=4)
HIGH_HANDS = ("LeftHand", "RightHand")


def _hands_low(decoded, inputs):
    """A student's term: the hands' mean height below 1 m above the floor, metres."""
    idx = [humanoid.JOINTS.index(n) for n in HIGH_HANDS]
    y = decoded.positions[..., idx, 1] + inputs.root_height[..., None]
    return torch.relu(1.0 - y).mean()


@pytest.fixture
def hands_term():
    term = terms.register(terms.Term("hands", 0.2, _hands_low, "m", (), "the hands above 1 m"))
    yield term
    terms.unregister("hands")


@pytest.fixture(scope="module")
def ckpt():
    return retargeting.load_default("cpu")


@pytest.fixture(scope="module")
def clip():
    return synthetic.dataset(1, seed=1, num_frames=60)[0]


def _target(clip):
    return humanoid.scale_bones(clip.skeleton, legs=1.3)


def test_a_term_registered_outside_the_package_is_iterated_reported_and_written(hands_term, ckpt, clip, tmp_path):
    result = retargeting.retarget(clip, _target(clip), ckpt, "full", FAST)
    h = result.history
    assert "hands" in h and len(h["hands"]) == len(h["loss"]) and h["hands"][0] > 0
    cfg = FAST
    at_start = sum(cfg.weight(t.name) * h[t.name][0] for t in terms.registered())
    assert h["loss"][0] == pytest.approx(at_start, rel=1e-12)  # L_iter is the weighted sum, this term included
    assert result.losses["hands"] == h["hands"][result.best_step]
    heavier = retargeting.retarget(clip, _target(clip), ckpt, "full", SolverConfig(max_steps=4, weights={"hands": 2.0}))
    assert heavier.history["loss"][0] - h["loss"][0] == pytest.approx(1.8 * h["hands"][0], rel=1e-9)

    axes = plots.plot_iteration(h, config=cfg)
    assert any("hands" in ax.get_title() for ax in axes)
    assert "0.2 L_{hands}" in axes[0].get_legend().get_texts()[1].get_text()

    bvh.save(tmp_path / "walk.bvh", clip)
    job = ex.expand([str(tmp_path / "walk.bvh")], ex.characters(presets=["long_legs"]), tmp_path / "out", ckpt, FAST)
    assert job.failed == 0
    with open(tmp_path / "out" / ex.MANIFEST, newline="") as f:
        rows = list(csv.DictReader(f))
    assert "hands" in rows[0] and float(rows[0]["hands"]) > 0

    options = build_parser().parse_args(["retarget", "a.bvh", "-o", "b.bvh", "--hands-weight", "0.7"])
    from motionlab.retargeting.cli_options import solver_config

    assert solver_config(options).weight("hands") == 0.7


def test_a_manifest_written_with_other_terms_is_still_read(hands_term, ckpt, clip, tmp_path):
    bvh.save(tmp_path / "walk.bvh", clip)
    chars = ex.characters(presets=["long_legs"])
    ex.expand([str(tmp_path / "walk.bvh")], chars, tmp_path / "out", ckpt, FAST)
    terms.unregister("hands")
    try:
        again = ex.expand([str(tmp_path / "walk.bvh")], chars, tmp_path / "out", ckpt, FAST)
        assert again.done == 1  # another set of terms: other options, redone
    finally:
        terms.register(hands_term)


def test_unknown_weights_and_bad_terms_are_refused(ckpt, clip):
    with pytest.raises(ValueError, match="not registered loss terms"):
        retargeting.retarget(clip, _target(clip), ckpt, "full", SolverConfig(max_steps=1, weights={"nope": 1.0}))
    with pytest.raises(ValueError, match="already registered"):
        terms.register(terms.Term("angle", 1.0, _hands_low))
    with pytest.raises(ValueError, match="identifier"):
        terms.Term("two words", 1.0, _hands_low)
    with pytest.raises(ValueError, match=">= 0"):
        SolverConfig(weights={"floor": -1.0})


def test_the_built_in_terms_keep_the_papers_weights():
    assert [t.name for t in terms.registered()][:4] == ["angle", "foot", "contact", "floor"]
    assert terms.get("angle").weight == losses.LAMBDA_ANGLE == SolverConfig().weight("angle") == 0.3
    assert terms.get("foot").weight == losses.LAMBDA_FOOT == 0.5
    assert terms.get("floor").weight == losses.FLOOR_DEFAULT == 0.0  # motionlab's addition: opt-in
    assert losses.LAMBDA_FLOOR == losses.LAMBDA_FOOT * 18 / 4  # its weight when switched on


# ----------------------------------------------------------------------------- L_floor
def test_floor_loss_is_a_hinge_on_the_joints_other_than_the_feet():
    y = torch.full((1, 3, 22), 0.5, dtype=torch.float64, requires_grad=True)
    assert losses.floor_loss(y).item() == 0.0
    y2 = y.detach().clone()
    hand = humanoid.JOINTS.index("LeftHand")
    y2[0, 1, hand] = -0.18  # 18 cm under the floor in one of 3 frames
    y2[0, :, humanoid.JOINTS.index("LeftFoot")] = -1.0  # feet are L_foot's, not L_floor's
    assert losses.floor_loss(y2).item() == pytest.approx(0.18 / (3 * 18))
    allowed = torch.zeros_like(y2)
    allowed[0, 1, hand] = -0.2  # the source's own hand went 20 cm deep there: allowed
    assert losses.floor_loss(y2, allowed).item() == 0.0
    (grad,) = torch.autograd.grad(losses.floor_loss(y), y)
    assert torch.count_nonzero(grad) == 0


def test_floor_changes_nothing_where_no_joint_goes_under(ckpt, clip):
    """Zero loss and zero gradient there: bit-identical results with and without the term."""
    on = SolverConfig(max_steps=12, weights={"floor": losses.LAMBDA_FLOOR})
    with_floor = retargeting.retarget(clip, _target(clip), ckpt, "full", on)
    assert max(with_floor.history["floor"]) == 0.0
    floor = terms.unregister("floor")
    try:
        without = retargeting.retarget(clip, _target(clip), ckpt, "full", SolverConfig(max_steps=12))
    finally:
        terms.register(floor)
    assert np.array_equal(with_floor.positions, without.positions)
    assert with_floor.history["loss"] == without.history["loss"]


def test_the_length_terms_give_a_target_twice_as_large_the_same_values():
    """The length-valued terms measure B at the network's character's scale (``terms.LENGTH_SCALE``):
    B's motion at twice the size, with half the scale, costs the same; without it, twice as much."""
    g = torch.Generator().manual_seed(0)
    T = 12
    rot = torch.nn.functional.normalize(torch.randn(1, T, 22, 4, generator=g, dtype=torch.float64), dim=-1)
    pos = 0.3 * torch.randn(1, T, 22, 3, generator=g, dtype=torch.float64)
    height = 0.2 + 0.05 * torch.rand(1, T, generator=g, dtype=torch.float64)
    world = torch.randn(1, T, 3, generator=g, dtype=torch.float64)
    yaw = torch.rand(1, T, generator=g, dtype=torch.float64)
    planted = torch.rand(1, T, 4, generator=g) < 0.5
    floor = -0.05 * torch.rand(1, T, 22, generator=g, dtype=torch.float64)
    cfg = SolverConfig(weights={"floor": 1.0})

    def values(k, scale):
        extra = (
            {"floor": k * floor}
            if scale is None
            else {"floor": k * floor, terms.LENGTH_SCALE: torch.full((1, T), scale, dtype=torch.float64)}
        )
        out = Decoded(rot, k * pos, rot, rot)
        _, v = solver.sequence_terms(
            rot, out, k * height, cfg, k * world, yaw, planted, torch.tensor([30.0], dtype=torch.float64), extra
        )
        return {name: float(v[name][0]) for name in ("foot", "contact", "floor")}

    one, two = values(1.0, 0.8), values(2.0, 0.4)
    assert min(one.values()) > 0  # every length term is compared, none is trivially 0
    assert two == pytest.approx(one, rel=1e-12)
    assert values(2.0, None) == pytest.approx({k: 2 * v / 0.8 for k, v in one.items()}, rel=1e-12)


def test_without_the_scale_a_term_is_in_metres_of_b():
    """``at_training_scale`` multiplies by ``extra[LENGTH_SCALE]`` and leaves the value alone without it."""
    value = torch.tensor(0.25, dtype=torch.float64)
    plain = terms.TermInputs(None, "rotations", None)
    scaled = terms.TermInputs(None, "rotations", None, extra={terms.LENGTH_SCALE: torch.full((1, 5), 2.0)})
    assert float(terms.at_training_scale(value, plain)) == 0.25
    assert float(terms.at_training_scale(value, scaled)) == 0.5


# ----------------------------------------------------------------------------- the reported loss
def test_retarget_prints_the_returned_iterates_loss(ckpt, clip, tmp_path, capsys):
    """It printed the last step's L_iter, which Adam may have overshot to (issue 41 item 5)."""
    bvh.save(tmp_path / "walk.bvh", clip)
    loaded = bvh.load(tmp_path / "walk.bvh")
    for steps in range(1, 41):  # the first step limit whose last step is not kept (backtracking undoes it)
        direct = retargeting.retarget(loaded, _target(loaded), ckpt, "full", SolverConfig(max_steps=steps))
        if direct.history["loss"][-1] > direct.losses["loss"]:
            break
    assert direct.best_step < direct.steps and direct.history["loss"][-1] > direct.losses["loss"]  # an overshoot
    code = main(["retarget", str(tmp_path / "walk.bvh"), "--scale-legs", "1.3", "--steps", str(steps), "--device",
                 "cpu", "-o", str(tmp_path / "out.bvh")])  # fmt: skip
    assert code == 0
    printed = float(re.search(r"L_iter \S+ -> (\S+)", capsys.readouterr().out).group(1))
    assert printed == pytest.approx(direct.losses["loss"], rel=1e-3)
    assert printed != pytest.approx(direct.history["loss"][-1], rel=1e-3)


def test_expand_writes_the_returned_iterates_losses(ckpt, clip, tmp_path):
    bvh.save(tmp_path / "walk.bvh", clip)
    cfg = SolverConfig(max_steps=40)
    job = ex.expand([str(tmp_path / "walk.bvh")], ex.characters(presets=["long_legs"]), tmp_path / "out", ckpt, cfg)
    (row,) = job.rows
    direct = retargeting.retarget(bvh.load(tmp_path / "walk.bvh"), ex.characters(presets=["long_legs"])[0].skeleton,
                                  ckpt, "full", cfg)  # fmt: skip
    for name in ("loss", "angle", "foot", "floor"):
        assert float(row[name]) == pytest.approx(direct.losses[name], rel=1e-5, abs=1e-12), name


def test_the_papers_two_losses_row_switches_every_other_term_off(monkeypatch):
    """``evaluate``'s ablation row, with the solver settings the command line builds."""
    from motionlab.retargeting import evaluate
    from motionlab.retargeting.cli_options import solver_config

    used = {}
    monkeypatch.setattr(evaluate, "retarget", lambda *args, **kw: used.__setitem__("cfg", args[4]))
    cfg = solver_config(build_parser().parse_args(["evaluate", "--floor-weight", "3", "--angle-weight", "0.4"]))
    assert (cfg.weight("floor"), cfg.weight("angle"), cfg.weight("contact")) == (3.0, 0.4, 0.5)
    paper = next(r for r in evaluate.ABLATIONS if "paper" in r[0])
    evaluate._run_row(paper, None, None, None, cfg, 60.0)
    weights = {t.name: used["cfg"].weight(t.name) for t in terms.registered()}
    assert weights == {"angle": 0.4, "foot": 0.5, "contact": 0.0, "floor": 0.0, "clearance": 0.0}
    without = next(r for r in evaluate.ABLATIONS if "L_clear" in r[0])
    evaluate._run_row(without, None, None, None, cfg, 60.0)
    weights = {t.name: used["cfg"].weight(t.name) for t in terms.registered()}
    assert weights == {"angle": 0.4, "foot": 0.5, "contact": 0.5, "floor": 3.0, "clearance": 0.0}


def test_the_clearance_input_is_the_sources_swinging_feet_scaled(ckpt, clip):
    """``prepare_pair``'s L_clear input: A's foot heights scaled as the root (r_y, then the soles'
    difference d, at least 0) where A's foot swings, 0 where it is planted; with it the iteration
    holds B's swinging feet up (``clearance`` falls)."""
    from motionlab.retargeting import pipeline

    src = pipeline.prepare_source(clip, ckpt, "full")
    pair = pipeline.prepare_pair(src, _target(clip))
    allowed = pair.clearance[0].numpy()
    planted = src.planted[0].numpy()
    lift = pair.root_pos[0, 1] - pair.root_scale[1] * src.motion.root_pos[0, 1]
    assert lift == pytest.approx(rest_pose.sole_height(pair.target) - pair.root_scale[1] * src.sole)
    heights = pair.root_scale[1] * src.motion.global_positions()[:, list(losses.FOOT_JOINTS), 1] + lift
    assert planted.any() and (~planted).any()
    assert np.all(allowed[planted] == 0.0)
    np.testing.assert_allclose(allowed[~planted], np.maximum(heights[~planted], 0.0))
    short = retargeting.retarget(
        clip, humanoid.scale_bones(clip.skeleton, legs=0.7), ckpt, "full", SolverConfig(max_steps=20)
    )
    history = short.history["clearance"]
    assert history[0] > 0 and history[short.best_step] < history[0]


@pytest.fixture
def broken_term(request):
    term = terms.register(terms.Term("broken", 1.0, request.param, padded=True))
    yield term
    terms.unregister("broken")


@pytest.mark.parametrize(
    ("broken_term", "message"),
    [
        (lambda d, i: d.positions.sum() * float("nan"), r"not finite at any step .*\['broken'\]"),
        (lambda d, i: d.positions[..., 0, 1].mean(dim=-1), "loss term 'broken' returned Tensor of shape"),
    ],
    indirect=["broken_term"],
)
def test_a_term_that_gives_no_number_is_named_not_returned_as_a_motion(broken_term, message, ckpt, clip):
    with pytest.raises(ValueError, match=message):
        retargeting.retarget(clip, _target(clip), ckpt, solver=FAST)


def test_weights_that_are_not_finite_or_negative_are_refused_when_made():
    for changes in (
        {"weights": {"floor": float("inf")}},
        {"lambda_angle": float("inf")},
        {"lambda_foot": -5.0},
        {"threshold": float("nan")},
        {"min_delta": -1.0},
    ):
        with pytest.raises(ValueError, match="finite number"):
            SolverConfig(**changes)
    with pytest.raises(ValueError, match="finite number >= 0"):
        terms.Term("big", float("inf"), _hands_low)


def test_a_term_named_like_a_manifest_column_is_refused_before_expand_works(ckpt, clip, tmp_path):
    terms.register(terms.Term("output", 0.1, _hands_low, padded=True))
    try:
        bvh.save(tmp_path / "walk.bvh", clip)
        with pytest.raises(ValueError, match=r"\['output'\] are named like columns"):
            ex.expand([str(tmp_path / "walk.bvh")], ex.characters(presets=["tall"]), tmp_path / "out", ckpt, FAST)
        assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.bvh"))
    finally:
        terms.unregister("output")


def test_expand_redoes_a_row_whose_flag_thresholds_changed(ckpt, clip, tmp_path):
    bvh.save(tmp_path / "walk.bvh", clip)
    chars = ex.characters(presets=["tall"])
    first = ex.expand([str(tmp_path / "walk.bvh")], chars, tmp_path / "out", ckpt, FAST, max_penetration_cm=1.0)
    again = ex.expand([str(tmp_path / "walk.bvh")], chars, tmp_path / "out", ckpt, FAST, max_penetration_cm=1.0)
    other = ex.expand([str(tmp_path / "walk.bvh")], chars, tmp_path / "out", ckpt, FAST, max_penetration_cm=2.0)
    assert (first.done, again.done, other.done) == (1, 0, 1)
