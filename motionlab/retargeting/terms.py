"""The loss terms of the latent iteration, as named objects in one registry.

Contract
--------
A term is a :class:`Term`: a ``name`` (a Python identifier), a default ``weight`` (>= 0), and a
``function(decoded, inputs) -> Tensor`` giving the term's value for ONE sequence: ``decoded`` is
the decoder's output on B (:class:`~motionlab.retargeting.model.Decoded`, tensors (1, T, 22, ·))
and ``inputs`` a :class:`TermInputs` of the same sequence. The function returns a 0-d tensor,
differentiable in ``decoded``; it must work under ``torch.func.vmap`` (no ``.item()``, no
branching on tensor values), since :func:`motionlab.retargeting.solver.solve_many` maps it over
the sequences of a batch. ``needs`` names the inputs it cannot do without (``"planted"``…); where
one is missing the term is not evaluated and its value is 0.

On a GPU the whole step of the iteration is recorded once as a CUDA graph and replayed
(:mod:`.graphs`): the function runs while the step is recorded, not at every step. Its value may
depend on its arguments alone: a Python number it changes or reads (a call counter, an annealed
weight) keeps its recorded value, and a tensor it reads from elsewhere must be updated in place,
never replaced. ``tests/retargeting/replay.py`` replays a step on the CPU as a graph does
(``test_a_loss_term_that_keeps_python_state_is_not_replayed``).

The iteration (:mod:`motionlab.retargeting.solver`) sums ``weight × value`` over the registered
terms, in registration order: ``L_iter = Σ_k w_k · L_k``. A term's weight comes from
``SolverConfig.weights[name]`` when given, else (for the three terms the paper and motionlab
started with) ``SolverConfig.lambda_angle`` / ``lambda_foot`` / ``lambda_contact``, else
``Term.weight``. Everything else follows the registry: the solver's history and callback (one
entry per term name, beside ``"loss"`` = L_iter), :func:`motionlab.retargeting.plots.plot_iteration`,
``expand``'s manifest columns (one per term, after ``loss``), ``options_sha256`` and the
``--NAME-weight`` options of ``retarget``, ``evaluate`` and ``expand``.

Adding a term is one function and one :func:`register` call (``tests/retargeting/test_terms.py``
does it from outside the package). Per-sequence data a term needs beyond the built-in inputs
travel in ``TermInputs.extra`` (``solve(..., inputs={"name": tensor (N, T, ...)})``).

Sequences of different lengths share a batch by padding (``solve_many(..., lengths=)``, which is
how ``expand`` fills a GPU): each term then sees ``TermInputs.frames``, the real frames, and must
average over those alone (:func:`losses.frame_mean`). A term declares that it does with
``padded=True``; while a registered term does not, batches keep to one length (:func:`unpadded`).

The built-in terms, in order:

==============  =======================================================================  ======  ======
name            value                                                                    unit    weight
==============  =======================================================================  ======  ======
``angle``       L_angle (eq. 16): A's joint angles vs B's (:func:`losses.angle_loss`)    —       0.3
``foot``        L_foot (eq. 17): the feet below the ground (:func:`losses.foot_loss`)    m       0.5
``contact``     L_contact (motionlab): speed of A's planted feet on B                    m/s     0.5
``floor``       L_floor (motionlab): the other 18 joints below the floor, beyond the     m       0 (off)
                source's own depth scaled to B (:func:`losses.floor_loss`)
``clearance``   L_clear (motionlab): B's feet below A's (scaled) while A's foot swings   m       0.5
                (:func:`losses.clearance_loss`; input ``extra["clearance"]``)
==============  =======================================================================  ======  ======

L_floor is off by default (:data:`losses.FLOOR_DEFAULT`); switched on, its weight is
λ_foot × 18 / 4 = 2.25 (:data:`losses.LAMBDA_FLOOR`, ``--floor-weight 2.25``): L_foot is a mean over
the 4 foot joints, L_floor over the other 18, so a joint under the floor costs exactly what a foot
under the ground costs in the paper's L_foot (the feet stay L_foot's alone). Where no joint goes under its allowed depth L_floor and its gradient are exactly 0, so
the iteration's numbers are those without it.

L_clear keeps B's swinging feet at least as far off the floor as A's, scaled to B (why:
``docs/results_retargeting.md``). Its weight is λ_foot's, by the same measure: a mean depth over
the four foot joints. Where A's foot is planted, L_foot and L_contact rule alone.

The four length-valued terms measure B **at the scale of the network's own character** when the
solver is given ``inputs[LENGTH_SCALE]`` (that character's leg length / B's, from the checkpoint's
skeleton; :func:`motionlab.retargeting.pipeline.retarget` and ``expand`` give it): a depth or a
slide of B costs what the same fraction of the leg costs on the character the weights were set
for, so a small character's feet are held as firmly as a large one's, as the plausibility check
(which measures in B's leg lengths) asks, whatever the unit of the source's or the target's file.
On a target of that character's size the numbers are the paper's. This is motionlab's choice;
the paper states L_foot (eq. 17) without a unit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from motionlab.retargeting import devices, losses

__all__ = [
    "Term",
    "TermInputs",
    "register",
    "unregister",
    "registered",
    "get",
    "unpadded",
    "PAPER_TERMS",
    "LENGTH_SCALE",
    "at_training_scale",
]

PAPER_TERMS = ("angle", "foot")
"""The two terms of the paper (eqs. 15–17); the others are motionlab's additions."""

LENGTH_SCALE = "length_scale"
"""Key of :attr:`TermInputs.extra` holding the network's character's leg length / B's, (1, T)
(every frame the same). The length-valued built-in terms (L_foot, L_contact, L_floor, L_clear)
multiply their value by it, so they measure B at that character's scale: a motion of B and the
same motion scaled by s (on B scaled by s) cost the same, and on a target of that character's
size the values are metres. Without it they measure in metres of B."""


@dataclass(frozen=True)
class TermInputs:
    """What a term sees of one sequence besides the decoded motion (tensors with a leading 1).

    Attributes
    ----------
    source : Tensor (1, T, 22, 4) or (1, T, 22, 3)   θ(A): A's local rotations (``theta="rotations"``)
        or A's root-relative heading-frame positions (``"directions"``)
    theta : str                    ``"rotations"`` or ``"directions"``
    root_height : Tensor (1, T)    B's root height above the ground, metres
    root_world : Tensor (1, T, 3) or None   B's root in the world (contact inputs), metres
    yaw : Tensor (1, T) or None    A's (= B's) heading, radians
    planted : Tensor (1, T, 4) of bool or None   A's foot contacts
    fps : Tensor () or None        frame rate
    extra : dict of Tensor         per-sequence inputs of other terms, e.g. ``"floor"`` (1, T, 22):
                                   the lowest height each joint of B may reach, metres (<= 0)
    frames : Tensor (1, T) of bool or None   the sequence's real frames when it was padded to a
                                   batch's length (:func:`motionlab.retargeting.solver.solve_many`
                                   with ``lengths``); None: every frame is real. A term that honours
                                   it (:attr:`Term.padded`) averages over these frames alone
                                   (:func:`losses.frame_mean`)
    """

    source: Any
    theta: str
    root_height: Any
    root_world: Any = None
    yaw: Any = None
    planted: Any = None
    fps: Any = None
    extra: dict = field(default_factory=dict)
    frames: Any = None

    def has(self, name: str) -> bool:
        """Whether input ``name`` (a field or a key of ``extra``) is given."""
        if name in self.extra:
            return True
        return getattr(self, name, None) is not None


@dataclass(frozen=True)
class Term:
    """A loss term of the latent iteration (module docstring: the contract).

    Attributes
    ----------
    name : str           identifier: history key, manifest column, ``--NAME-weight`` option
    weight : float       default weight (finite, >= 0)
    function : callable  ``function(decoded, inputs: TermInputs) -> Tensor ()``
    unit : str           unit of the value ("" for none), for reports
    needs : tuple of str inputs the term cannot be evaluated without (fields or ``extra`` keys)
    description : str    one line for ``--help`` and the docs
    padded : bool        the function honours :attr:`TermInputs.frames` (padded frames change
                         neither its value nor its gradient), so sequences of other lengths can
                         share a batch; a term without it keeps batches to one length
    """

    name: str
    weight: float
    function: Callable
    unit: str = ""
    needs: tuple[str, ...] = ()
    description: str = ""
    padded: bool = False

    def __post_init__(self) -> None:
        if not self.name.isidentifier() or self.name == "loss":
            raise ValueError(f"a term's name must be a Python identifier other than 'loss', got {self.name!r}")
        if not (np.isfinite(self.weight) and self.weight >= 0):
            raise ValueError(f"term {self.name!r}: weight must be a finite number >= 0, got {self.weight}")
        if not callable(self.function):
            raise ValueError(f"term {self.name!r}: function must be callable")


_REGISTRY: dict[str, Term] = {}


def register(term: Term, replace: bool = False) -> Term:
    """Add ``term`` to the iteration (after the terms already there); returns it.

    Raises ``ValueError`` when a term of that name is registered and ``replace`` is False.
    """
    if not isinstance(term, Term):
        raise ValueError(f"expected a Term, got {type(term).__name__}")
    if term.name in _REGISTRY and not replace:
        raise ValueError(f"a loss term named {term.name!r} is already registered (replace=True replaces it)")
    _REGISTRY[term.name] = term
    return term


def unregister(name: str) -> Term:
    """Remove the term ``name`` and return it.

    Raises
    ------
    KeyError naming the registered terms if there is none called ``name``.
    """
    return _REGISTRY.pop(get(name).name)


def registered() -> tuple[Term, ...]:
    """The registered terms, in the order the iteration sums them."""
    return tuple(_REGISTRY.values())


def get(name: str) -> Term:
    """The registered term ``name``.

    Raises
    ------
    KeyError naming the registered terms if there is none called ``name``.
    """
    if name not in _REGISTRY:
        raise KeyError(f"no loss term {name!r}; registered: {list(_REGISTRY)}")
    return _REGISTRY[name]


def unpadded() -> tuple[str, ...]:
    """Names of the registered terms that do not honour padded frames (:attr:`Term.padded` False)."""
    return tuple(t.name for t in _REGISTRY.values() if not t.padded)


# ---------------------------------------------------------------------------- built-in terms
def _angle(decoded, inputs: TermInputs):
    if inputs.theta == "rotations":
        return losses.angle_loss(inputs.source, decoded.local_rot, inputs.frames)
    return losses.direction_loss(inputs.source, decoded.positions, inputs.frames)


def at_training_scale(value, inputs: TermInputs):
    """A length-valued term's ``value`` at the network's character's scale: × ``inputs.extra[LENGTH_SCALE]``
    (unchanged without it)."""
    scale = inputs.extra.get(LENGTH_SCALE)
    return value if scale is None else value * scale[0, 0]


def _foot(decoded, inputs: TermInputs):
    value = losses.foot_loss(decoded.positions[..., 1] + inputs.root_height[..., None], inputs.frames)
    return at_training_scale(value, inputs)


def _contact(decoded, inputs: TermInputs):
    feet = losses.feet_in_world(decoded.positions, inputs.root_world, inputs.yaw)
    planted = inputs.planted if inputs.frames is None else inputs.planted & inputs.frames[..., None]
    return at_training_scale(losses.contact_loss(feet, planted, inputs.fps), inputs)


def _clearance(decoded, inputs: TermInputs):
    feet = (
        decoded.positions[..., 1].index_select(-1, devices.index(losses.FOOT_JOINTS, decoded.positions.device))
        + inputs.root_height[..., None]
    )
    return at_training_scale(losses.clearance_loss(feet, inputs.extra["clearance"], inputs.frames), inputs)


def _floor(decoded, inputs: TermInputs):
    heights = decoded.positions[..., 1] + inputs.root_height[..., None]
    return at_training_scale(losses.floor_loss(heights, inputs.extra.get("floor"), inputs.frames), inputs)


register(
    Term("angle", losses.LAMBDA_ANGLE, _angle, "", (), "L_angle: the source's joint angles kept (paper, eq. 16)", True)
)
register(Term("foot", losses.LAMBDA_FOOT, _foot, "m", (), "L_foot: feet above the ground (paper, eq. 17)", True))
register(
    Term(
        "contact",
        losses.LAMBDA_CONTACT,
        _contact,
        "m/s",
        ("root_world", "yaw", "planted", "fps"),
        "L_contact: the source's planted feet stay still (motionlab's addition)",
        True,
    )
)
register(
    Term(
        "floor",
        losses.FLOOR_DEFAULT,
        _floor,
        "m",
        (),
        "L_floor: every joint at or above the floor, or no deeper than the source's own (motionlab's addition)",
        True,
    )
)
register(
    Term(
        "clearance",
        losses.LAMBDA_CLEARANCE,
        _clearance,
        "m",
        ("clearance",),
        "L_clear: swinging feet as high as the source's, scaled (motionlab's addition)",
        True,
    )
)
