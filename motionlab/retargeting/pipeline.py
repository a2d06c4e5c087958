"""Retarget a Motion onto a target skeleton, end to end.

::

    ckpt = retargeting.load_default()                       # or checkpoint.load("aj.pt")
    result = retarget(source_motion, target_skeleton, ckpt)  # method="full" | "network" | "copy"
    bvh.save("out.bvh", result.motion)

Steps: the source is reduced to the 22 canonical joints, brought to its canonical standing
rest pose (:mod:`motionlab.core.rest_pose`) and resampled to the checkpoint's frame rate; the
target rig is reduced to its canonical standing skeleton (:func:`target_skeleton`: B's rest
offsets, or a frame of B's motion when its rest pose does not stand). The output is resampled
back to the source's frame rate unless another is asked for (:func:`at_rate`), and every output
is checked for plausibility (:mod:`motionlab.retargeting.plausibility`).

**Whole clips, no seams (our choice).** The encoder is fully convolutional and φ is a latent
per frame, so a clip of any length goes through the network as *one* sequence and the latent
solver optimises all its frames together. There are no windows to stitch, hence no seams;
the 120-frame window is only the training unit.

**Root motion of B (our choice, the paper leaves it open).** A's root trajectory is scaled
about the world origin, with one ratio for the ground plane and one for the height
(``root_mode="stride"``, the default):

* horizontally by ``r_xz`` = B's / A's **leg chain**, the summed bone lengths from the Hips
  down to the toe (Hips→UpLeg→Leg→Foot→ToeBase, :func:`leg_chain`): with the same joint
  angles, a longer leg takes a longer stride, and the hip offset and the foot count too;
* vertically by ``r_y`` = B's / A's **hip height** (height of the Hips above the lowest joint in
  the canonical standing rest pose, :func:`hip_height`, :mod:`motionlab.core.rest_pose`), so a
  standing pose keeps its feet on the ground whatever rest pose each studio rigged; and raised by
  ``d = s_B − r_y s_A``, ``s`` being each rig's *sole*, the height of its toe joints above the
  floor when they stand on it: a sole does not grow with the leg, so B's planted toe stands on
  B's own sole, not on A's scaled. Each rig's sole is read from its rest root offset
  (:func:`motionlab.core.rest_pose.sole_height`) where that places the rig on the floor;
  otherwise from a take (:func:`motionlab.core.rest_pose.take_sole`: where its toes stand while
  planted), A's from the source clip (:func:`source_sole`) and B's from the target's take
  (:func:`target_skeleton`; 0 when B is a bare skeleton), so a clip copied onto its own rig keeps
  its root where it was;
* the heading (facing direction) of every frame is A's: the network's root rotation, expressed
  in A's heading frame, is turned back by A's heading.

``root_mode="contacts"`` replaces the ground-plane ratio by the one that keeps A's planted feet
still on B's legs (:func:`contact_stride`; the leg chain when the clip has no steps).
``root_mode="hips"`` scales all three axes by the hip height and ``"legs"`` by thigh + shin
(:func:`humanoid.leg_length`, the plain baseline of the data notes). The default is the rule
closest to Mixamo's own root paths; how it was chosen and how it holds with each character left
out is on the results page, docs/results_retargeting.md (``experiments/retargeting/root_rules.py``,
``experiments/retargeting/root_rules_loco.py``). All three methods (copy-rotation, network without
iteration, full method) use the same root trajectory, so the comparison is on poses.

Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import torch

from motionlab.core import humanoid, preprocess, quat, rest_pose, threads
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import contacts, plausibility
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.features import ClipFeatures, check_motion, clip_features
from motionlab.retargeting.losses import FOOT_JOINTS
from motionlab.retargeting.solver import SolverConfig, solve
from motionlab.retargeting.terms import LENGTH_SCALE

__all__ = [
    "METHODS",
    "ROOT_MODES",
    "RetargetResult",
    "hip_height",
    "leg_chain",
    "root_scale",
    "target_skeleton",
    "PreparedSource",
    "PreparedPair",
    "prepare_source",
    "prepare_pair",
    "finish",
    "solve_pair",
    "term_inputs",
    "source_contacts",
    "source_sole",
    "target_sole",
    "sole_lift",
    "contact_stride",
    "at_rate",
    "retarget",
]

METHODS = ("full", "network", "copy")
"""``full``: network + latent iteration; ``network``: no iteration; ``copy``: copy local rotations."""
ROOT_MODES = ("stride", "hips", "legs", "contacts")
"""How the root trajectory is scaled: see the module docstring."""


@dataclass
class RetargetResult:
    """A retargeted clip.

    Attributes
    ----------
    motion : Motion           on B's canonical 22-joint standing skeleton, world space, at the
                              checkpoint's fps (:func:`finish`) or the one :func:`at_rate` chose
    positions : ndarray (T, 22, 3)   world joint positions (FK of ``motion``), metres
    method : str              one of :data:`METHODS`
    root_scale : (float, float)  ``(r_xz, r_y)`` that scaled A's root trajectory
    history : dict            solver history (``loss`` and each loss term per step); empty otherwise
    stop_reason : str         why the solver stopped ("" without iteration)
    steps : int               solver steps
    best_step : int           the step whose iterate is the result (the lowest L_iter; Adam may
                              overshoot after it): :attr:`losses` are the values there
    seconds : float           wall time of the method itself (network + solver), seconds
    plausibility : Plausibility or None   the output's plausibility tests (:mod:`.plausibility`)
    resampled : str           how the frame rate changed on the way ("" when it did not)
    """

    motion: Motion
    positions: np.ndarray
    method: str
    root_scale: tuple[float, float]
    history: dict = field(default_factory=dict)
    stop_reason: str = ""
    steps: int = 0
    seconds: float = 0.0
    plausibility: plausibility.Plausibility | None = None
    resampled: str = ""
    best_step: int = 0

    @property
    def losses(self) -> dict[str, float]:
        """L_iter (``loss``) and each term's value at the returned iterate (step ``best_step``);
        empty without iteration. The numbers to report: the history's last entry may be an
        overshoot that was not kept."""
        return {k: float(v[self.best_step]) for k, v in self.history.items() if len(v) > self.best_step}


def hip_height(skeleton: Skeleton) -> float:
    """Rest-pose height of the root above the lowest joint (metres) of a canonical skeleton.

    A standing height only for a skeleton in its canonical standing rest pose
    (:func:`target_skeleton`, :func:`motionlab.core.rest_pose.standing_skeleton`).
    """
    rest = skeleton.rest_positions()
    return float(rest[0, 1] - rest[:, 1].min())


def leg_chain(skeleton: Skeleton, joints: tuple[str, ...] = ("UpLeg", "Leg", "Foot", "ToeBase")) -> float:
    """Summed lengths of the bones into ``joints`` of each leg (metres), averaged over both legs.

    By default Hips→UpLeg→Leg→Foot→ToeBase: the length of the whole leg stretched out, hip
    offset and foot included. ``skeleton`` is a canonical or mappable rig.
    """
    sk = skeleton if humanoid.is_canonical(skeleton) else humanoid.to_canonical_skeleton(skeleton)
    lengths = sk.bone_lengths()
    return float(np.mean([sum(lengths[sk.index(side + j)] for j in joints) for side in ("Left", "Right")]))


_MEASURES = {  # root mode -> (ground-plane measure, height measure)
    "stride": (leg_chain, hip_height),
    "hips": (hip_height, hip_height),
    "legs": (humanoid.leg_length, humanoid.leg_length),
}


def contact_stride(source: Motion, target: Skeleton, min_planted: float = 0.05) -> float | None:
    """The ground-plane root ratio that keeps A's planted feet still on B's legs, or None.

    While a foot is planted, the root moves by minus the foot's motion relative to the root.
    With A's joint rotations on B's skeleton, B's planted foot sweeps ``u_B`` where A's sweeps
    ``u_A`` (horizontal velocities relative to the root, on A's contact frames); the ratio is
    the least-squares ``r = Σ⟨u_A, u_B⟩ / Σ‖u_A‖²``. It uses A's motion and B's skeleton only.
    None when fewer than ``min_planted`` of the frames have a planted foot that moves
    relative to the root (a clip standing still says nothing about strides).

    Parameters
    ----------
    source : canonical 22-joint Motion of A
    target : B's canonical skeleton
    """
    labels = source_contacts(source)
    planted = labels[:-1] & labels[1:]  # (T-1, 4): planted in both frames
    zero = np.zeros_like(source.root_pos)
    rel = {}
    for key, sk in (("a", source.skeleton), ("b", target)):
        pos = Motion(sk, source.local_rot, zero, source.fps).global_positions()[:, list(contacts.CONTACT_JOINTS)]
        rel[key] = np.diff(pos[..., [0, 2]], axis=0)  # (T-1, 4, 2)
    moving = planted & (np.linalg.norm(rel["a"], axis=-1) * source.fps > 0.05 * source.skeleton.height())
    if moving.any(axis=1).mean() < min_planted:
        return None
    ua, ub = rel["a"][moving], rel["b"][moving]
    return float((ua * ub).sum() / (ua * ua).sum())


def root_scale(source: Skeleton, target: Skeleton, mode: str = "stride") -> tuple[float, float]:
    """``(r_xz, r_y)``: how much B's root moves per unit of A's, on the ground and up (module doc).

    ``mode="contacts"`` depends on the motion (:func:`contact_stride`); here it gives the
    skeleton-only fallback, the ``"stride"`` ratios.

    Raises
    ------
    ValueError for an unknown ``mode`` or a root measure of (nearly) zero.
    """
    if mode == "contacts":
        mode = "stride"
    if mode not in _MEASURES:
        raise ValueError(f"root_mode must be one of {ROOT_MODES}, got {mode!r}")
    ratios = []
    for measure in _MEASURES[mode]:
        a, b = measure(source), measure(target)
        if not (a > 1e-9 and b > 1e-9):
            raise ValueError(f"cannot scale the root: {measure.__name__} {a:.4g} m (source) / {b:.4g} m (target)")
        ratios.append(b / a)
    return ratios[0], ratios[1]


def source_contacts(source: Motion) -> np.ndarray:
    """A's planted feet (T, 4) for the contact term, from a canonical motion (:mod:`.contacts`)."""
    return contacts.of_motion(source)


def source_sole(source: Motion, canonical: Motion) -> float:
    """A's sole (metres): the height of its toe joints above the floor when they stand on it
    (B's is :func:`target_sole`).

    From the rig's rest root offset when that places the rig on the floor
    (:func:`motionlab.core.rest_pose.sole_height`); otherwise the median height of the toe joints
    over the frames where the clip plants them (:func:`rest_pose.take_sole`); 0 when it plants none.

    Parameters
    ----------
    source : the source Motion on its own rig (its rest offsets as the file has them)
    canonical : the same motion on the canonical 22 joints (:func:`preprocess.prepare`)
    """
    sole = rest_pose.sole_height(humanoid.to_canonical_skeleton(source.skeleton))
    return sole if sole is not None else rest_pose.take_sole(canonical)


def target_sole(target: Skeleton) -> float:
    """B's sole (metres) from B's canonical standing skeleton (:func:`target_skeleton`): the
    height its lowest rest joint stands at (:func:`rest_pose.sole_height`), 0 when that says nothing."""
    return rest_pose.sole_height(target) or 0.0


def sole_lift(source: PreparedSource, target: Skeleton, r_y: float) -> float:
    """``d = s_B − r_y s_A`` (metres): how far B's root is raised above A's scaled root so that B
    stands on its own sole (module docstring); ``target`` is B's canonical standing skeleton."""
    return target_sole(target) - r_y * source.sole


def target_skeleton(target: Skeleton | Motion, what: str = "target") -> Skeleton:
    """B's canonical 22-joint skeleton in its standing rest pose (:func:`rest_pose.standing_skeleton`),
    its lowest joint at B's sole (:func:`rest_pose.sole_height`, read by :func:`sole_lift`).

    ``target`` is a rig (Skeleton) or a Motion on it. The motion is used when the rest offsets do
    not stand, and when they do not say where the floor is: the sole is then where the take's
    toes stand while planted (:func:`rest_pose.take_sole`; below 0 for a take planted under its
    floor), as B's own takes stand. A bare Skeleton's is 0. A canonical skeleton is returned as
    it is.

    Raises :class:`humanoid.RigMappingError` naming the joints that cannot be mapped and
    :class:`rest_pose.RestPoseError` (naming ``what``) when no standing pose can be found.
    """
    sk = target.skeleton if isinstance(target, Motion) else target
    if not isinstance(sk, Skeleton):
        raise ValueError(f"expected a target Skeleton or Motion, got {type(target).__name__}")
    out = rest_pose.standing_skeleton(target, what)[0]
    if out.height() <= 1e-6:
        raise ValueError("the target skeleton has zero height")
    take = isinstance(target, Motion) and target.num_frames > 1
    if take and rest_pose.sole_height(humanoid.to_canonical_skeleton(sk)) is None:
        out = rest_pose.on_sole(out, rest_pose.take_sole(preprocess.prepare(target, None, stand=True)))
    return out


def _to_world(local_rot: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Turn heading-frame root rotations (T, 22, 4) back into world ones by the heading ``yaw`` (T,)."""
    out = quat.normalize(np.asarray(local_rot, dtype=np.float64))
    out[:, 0] = quat.mul(quat.from_yaw(yaw), out[:, 0])
    return quat.normalize(out)


def _network_inputs(ckpt: Checkpoint, feats: ClipFeatures, theta: str) -> tuple[torch.Tensor, torch.Tensor]:
    """A's normalised features (1, T, 70) and θ(A): rotations (1, T, 22, 4) or positions (1, T, 22, 3)."""
    device, dtype = ckpt.device, ckpt.dtype
    x = ckpt.stats.normalize(feats.x)
    source = feats.local_rot if theta == "rotations" else feats.positions
    return (
        torch.as_tensor(x, dtype=dtype, device=device)[None],
        torch.as_tensor(source, dtype=dtype, device=device)[None],
    )


@dataclass
class PreparedSource:
    """The source side of a retargeting job, shared by every target character.

    Attributes
    ----------
    name : str                   the source motion's name
    motion : Motion              A on the canonical 22 joints, resampled to the checkpoint's fps
    features : ClipFeatures or None   network-side features (None for ``method="copy"``)
    x : Tensor (1, T, 70) or None      A's normalised features on the checkpoint's device
    theta : Tensor (1, T, 22, 4) or (1, T, 22, 3) or None   θ(A) for the solver's ``theta``
    yaw : Tensor (1, T) or None        A's heading, radians (the contact term's world frame)
    planted : Tensor (1, T, 4) of bool or None   A's foot contacts (:func:`source_contacts`)
    sole : float                 A's sole, metres (:func:`source_sole`)
    """

    name: str
    motion: Motion
    features: ClipFeatures | None = None
    x: torch.Tensor | None = None
    theta: torch.Tensor | None = None
    yaw: torch.Tensor | None = None
    planted: torch.Tensor | None = None
    sole: float = 0.0


@dataclass
class PreparedPair:
    """One (source, target) job, ready for the network: what :func:`solver.solve` needs and what
    turns its answer into B's Motion (:func:`finish`).

    Attributes
    ----------
    source : PreparedSource
    target : Skeleton           B's canonical skeleton
    root_scale : (float, float)
    root_pos : ndarray (T, 3)   B's root trajectory, metres
    offsets : Tensor (22, 3) or None   B's bone offsets on the checkpoint's device
    root_height : Tensor (1, T) or None   B's root height, metres
    root_xz : Tensor (1, T, 2) or None    B's root on the ground plane, metres (contact term)
    floor : Tensor (1, T, 22) or None     the lowest height each joint of B may reach (L_floor,
        :mod:`.terms`): A's own joint heights scaled as the root (``r_y``, then raised by ``d``,
        module docstring) where that is under the floor, else 0; metres
    clearance : Tensor (1, T, 4) or None  the lowest height of each foot joint of B (L_clear,
        :mod:`.terms`): A's own foot heights scaled as the root (at least 0) while A's foot is
        not planted, 0 where it is; metres
    """

    source: PreparedSource
    target: Skeleton
    root_scale: tuple[float, float]
    root_pos: np.ndarray
    offsets: torch.Tensor | None = None
    root_height: torch.Tensor | None = None
    root_xz: torch.Tensor | None = None
    floor: torch.Tensor | None = None
    clearance: torch.Tensor | None = None


def prepare_source(
    source: Motion, checkpoint: Checkpoint | None, method: str = "full", solver: SolverConfig | None = None
) -> PreparedSource:
    """A's side of :func:`retarget`: canonical joints, the checkpoint's fps, features.

    Raises
    ------
    ValueError for an unknown ``method``.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    check_motion(source, "source motion")
    fps = checkpoint.fps if checkpoint is not None else source.fps
    src = preprocess.prepare(source, fps, stand=True)
    check_motion(src, "source motion")
    sole = source_sole(source, src)
    if method == "copy":
        return PreparedSource(source.name, src, sole=sole)
    feats = clip_features(src)
    x, theta = _network_inputs(checkpoint, feats, (solver or SolverConfig()).theta)
    yaw = torch.as_tensor(feats.yaw, dtype=x.dtype, device=x.device)[None]
    planted = torch.as_tensor(source_contacts(src), device=x.device)[None]
    return PreparedSource(source.name, src, feats, x, theta, yaw, planted, sole)


def prepare_pair(source: PreparedSource, target: Skeleton | Motion, root_mode: str = "stride") -> PreparedPair:
    """B's side of :func:`retarget`: canonical target skeleton and root trajectory."""
    tgt = target_skeleton(target)
    src = source.motion
    r = root_scale(src.skeleton, tgt, root_mode)
    if root_mode == "contacts":
        stride = contact_stride(src, tgt)
        r = (stride, r[1]) if stride is not None else r
    lift = sole_lift(source, tgt, r[1])
    root_pos = src.root_pos * np.array([r[0], r[1], r[0]]) + np.array([0.0, lift, 0.0])
    if source.x is None:
        return PreparedPair(source, tgt, r, root_pos)
    device, dtype = source.x.device, source.x.dtype
    offsets = torch.tensor(tgt.offsets, dtype=dtype, device=device)
    height = torch.as_tensor(root_pos[:, 1], dtype=dtype, device=device)[None]
    root_xz = torch.as_tensor(root_pos[:, [0, 2]], dtype=dtype, device=device)[None]
    heights = r[1] * src.global_positions()[..., 1] + lift  # A's joint heights, scaled to B (as the root)
    floor = torch.as_tensor(np.minimum(0.0, heights), dtype=dtype, device=device)[None]  # A's depth under the floor
    swing = ~source.planted[0].cpu().numpy()  # (T, 4): A's foot joints off the ground
    clearance = np.where(swing, np.maximum(heights[:, list(FOOT_JOINTS)], 0.0), 0.0)
    clearance = torch.as_tensor(clearance, dtype=dtype, device=device)[None]
    return PreparedPair(source, tgt, r, root_pos, offsets, height, root_xz, floor, clearance)


def finish(
    pair: PreparedPair,
    heading_rot: np.ndarray | None,
    method: str,
    history: dict | None = None,
    stop_reason: str = "",
    steps: int = 0,
    seconds: float = 0.0,
    best_step: int = 0,
) -> RetargetResult:
    """B's Motion from the network's heading-frame rotations (T, 22, 4) (``None`` for "copy");
    ``best_step`` the solver step whose iterate ``heading_rot`` is."""
    src = pair.source
    if method == "copy":
        local_rot = src.motion.local_rot.copy()
    else:
        local_rot = _to_world(heading_rot, src.features.yaw)
    name = f"{src.name}_on_target" if src.name else "retargeted"
    motion = Motion(pair.target, local_rot, pair.root_pos, src.motion.fps, None, name)
    positions = motion.global_positions()
    planted = None if src.planted is None else src.planted[0].cpu().numpy()
    check = plausibility.check(positions, pair.target, src.motion, planted, (src.sole, target_sole(pair.target)))
    return RetargetResult(
        motion, positions, method, pair.root_scale, history or {}, stop_reason, steps, seconds, check, "", best_step
    )


def _same_rate(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-4 * max(a, b)


def at_rate(result: RetargetResult, fps: float, source_fps: float, source_frames: int | None = None) -> RetargetResult:
    """``result`` resampled to ``fps`` (frames per second), with ``resampled`` saying what happened.

    ``source_fps`` is the source file's rate; the text names every rate the clip went through
    (source, network, output) whenever one differs from another, so callers can always print it.
    Rates within 1e-4 (relative) are the same. At the source's rate the output has the source's
    ``source_frames`` (where given): a frame the network's rate fell short of holds the last pose.
    Plausibility stays that of the solved rate.
    """
    solved = result.motion.fps
    if _same_rate(fps, solved) and _same_rate(source_fps, solved):
        return result
    note = f"resampled: source {source_fps:g} fps -> network {solved:g} fps -> output {fps:g} fps"
    if _same_rate(fps, solved):
        return replace(result, resampled=note)
    frames = source_frames if _same_rate(fps, source_fps) else None
    motion = result.motion.resample(fps, frames)
    return replace(result, motion=motion, positions=motion.global_positions(), resampled=note)


def term_inputs(checkpoint: Checkpoint, pair: PreparedPair) -> dict[str, torch.Tensor]:
    """The pair's inputs of the registered terms (:attr:`.terms.TermInputs.extra`), each (1, T, ...):
    ``floor``, ``clearance`` and :data:`.terms.LENGTH_SCALE` (the network's character's leg
    length / B's on every frame)."""
    scale = humanoid.leg_length(checkpoint.skeleton) / humanoid.leg_length(pair.target)
    return {"floor": pair.floor, "clearance": pair.clearance, LENGTH_SCALE: torch.full_like(pair.root_height, scale)}


def solve_pair(checkpoint, pair: PreparedPair, solver: SolverConfig | None = None, callback=None, progress=None):
    """The latent iteration of the full method on one prepared pair: :func:`solver.solve` with the
    pair's source features, target offsets, root height and ground path, A's heading and contacts.

    Returns :class:`solver.SolverResult` (``local_rot`` of shape (1, T, 22, 4), heading-relative).
    """
    src = pair.source
    return solve(
        checkpoint.model,
        src.x,
        src.theta,
        pair.offsets,
        pair.root_height,
        solver or SolverConfig(),
        callback=callback,
        progress=progress,
        root_xz=pair.root_xz,
        yaw=src.yaw,
        planted=src.planted,
        fps=src.motion.fps,
        inputs=term_inputs(checkpoint, pair),
    )


def retarget(
    source: Motion,
    target: Skeleton | Motion,
    checkpoint: Checkpoint | None = None,
    method: str = "full",
    solver: SolverConfig | None = None,
    root_mode: str = "stride",
    progress: bool = False,
    callback=None,
    fps: float | None = None,
) -> RetargetResult:
    """Generate B's version of ``source``.

    Parameters
    ----------
    source : Motion of character A on any rig :func:`humanoid.find_mapping` recognises
    target : B's rig (Skeleton) or a Motion on it; only its rest pose is used
    checkpoint : trained network (default: :func:`motionlab.retargeting.real.for_source`'s choice:
        the network trained on real mocap for a recorded source when the course data is there,
        else the shipped one); not needed for ``method="copy"``
    method : ``"full"`` (latent iteration), ``"network"`` (no iteration) or ``"copy"``
    solver : settings of the latent iteration
    root_mode : ``"stride"`` (default), ``"hips"`` or ``"legs"``: how A's root trajectory is scaled
    progress : tqdm bar for the iteration
    callback : passed to :func:`solver.solve` (per-step ``loss``, ``angle``, ``foot``)
    fps : frame rate of the output (default: the source's); the network runs at the
        checkpoint's rate and :func:`at_rate` converts

    Returns
    -------
    RetargetResult; ``result.motion`` is a proper Motion (local rotations + root positions) on
    B's canonical standing skeleton, so bone lengths are exact; ``result.plausibility`` says
    whether it passed the plausibility tests, ``result.resampled`` how the rate changed.

    Raises
    ------
    ValueError (and its subclasses :class:`humanoid.RigMappingError`,
    :class:`rest_pose.RestPoseError`) for a source or target that cannot be used.

    Notes
    -----
    The steps are :func:`prepare_source`, :func:`prepare_pair`, the solver and :func:`finish`;
    :mod:`motionlab.retargeting.expand` runs the same steps for many pairs, solving them in
    batches with :func:`solver.solve_many` (for one pair the same computation as here).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    check_motion(source, "source motion")
    target = target_skeleton(target)  # a bad target fails before any work
    if method != "copy" and checkpoint is None:
        from motionlab.retargeting import real

        checkpoint, _ = real.for_source(real.is_real_rig(source.skeleton))
    solver = solver or SolverConfig()
    pair = prepare_pair(prepare_source(source, checkpoint, method, solver), target, root_mode)
    history: dict = {}
    reason, steps, heading_rot, best = "", 0, None, 0
    start = time.perf_counter()
    if method == "network":
        with torch.no_grad(), threads.torch_threads(threads.threads_for(pair.source.x.shape[1])):
            heading_rot = checkpoint.model(pair.source.x, pair.offsets).local_rot[0].cpu().numpy()
    elif method == "full":
        res = solve_pair(checkpoint, pair, solver, callback=callback, progress=progress)
        heading_rot, history, reason, steps, best = (
            res.local_rot[0],
            res.history,
            res.stop_reason,
            res.steps,
            res.best_step,
        )
    result = finish(pair, heading_rot, method, history, reason, steps, time.perf_counter() - start, best)
    return at_rate(result, fps or source.fps, source.fps, source.num_frames)
