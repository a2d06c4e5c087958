"""Clip names → behaviour, style and transition labels.

The structured motion graph (paper B) files every clip under a *behaviour* (walk, run …) and a
*style* of that behaviour (normal, angry …). Clip names carry the labels:

==========================================  =========================================
name                                        label
==========================================  =========================================
``Walk_creepingly``                         basic clip: behaviour ``walk``, style ``creepingly``
``Walk_happily_to_Run_fast``                transition clip from walk/happily to run/fast
``Transition_Walk_normal_Run_slowly``       the same, in the paper's other spelling
``dataset-1_walk_angry_001``                Bandai Namco dataset-1: walk/angry (take 1)
``dataset-1_walk_normal_002``               a second take becomes style ``normal-2``
==========================================  =========================================

Labels are lower case. Names that fit none of these forms (most Mixamo clips) are looked up in
a small *name map* ``{clip stem: "behaviour_style" or "b1_s1_to_b2_s2"}``; :data:`MIXAMO_AJ`
maps the Mixamo Aj clips of the shared data that the experiments use.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["ClipLabel", "NamingError", "parse_name", "MIXAMO_AJ", "label_name"]


class NamingError(ValueError):
    """A clip name that says neither behaviour/style nor a transition."""


@dataclass(frozen=True)
class ClipLabel:
    """What a clip is.

    Attributes
    ----------
    kind : ``"basic"`` (one behaviour in one style) or ``"transition"`` (a recorded change)
    behaviour, style : labels of the clip (the *source* for a transition clip)
    to_behaviour, to_style : the target of a transition clip (``None`` for basic clips)
    """

    kind: str
    behaviour: str
    style: str
    to_behaviour: str | None = None
    to_style: str | None = None

    @property
    def key(self) -> tuple[str, str]:
        """``(behaviour, style)`` of a basic clip (the source for a transition)."""
        return (self.behaviour, self.style)

    @property
    def to_key(self) -> tuple[str, str] | None:
        return None if self.to_behaviour is None else (self.to_behaviour, self.to_style)


MIXAMO_AJ: dict[str, str] = {
    "Idle": "idle_normal",
    "Catwalk_Walk": "walk_catwalk",
    "Catwalk_Idle_To_Walk_Forward": "idle_normal_to_walk_catwalk",
    "Running": "run_normal",
    "Jumping": "jump_normal",
    "Standing_Land_To_Standing_Idle": "jump_normal_to_idle_normal",
}
"""Mixamo Aj clips of the shared data as behaviour/style names (land → idle, idle → walk)."""

_BANDAI = re.compile(r"^dataset-\d+_(?P<b>[a-z0-9-]+)_(?P<s>[a-z0-9-]+)_(?P<take>\d+)$", re.IGNORECASE)
_TOKEN = r"[A-Za-z0-9-]+"
_TO = re.compile(rf"^(?P<b1>{_TOKEN})_(?P<s1>{_TOKEN})_to_(?P<b2>{_TOKEN})_(?P<s2>{_TOKEN})$", re.IGNORECASE)
_TRANSITION = re.compile(
    rf"^transition[_ ](?P<b1>{_TOKEN})_(?P<s1>{_TOKEN})[_ ](?P<b2>{_TOKEN})_(?P<s2>{_TOKEN})$", re.IGNORECASE
)
_BASIC = re.compile(rf"^(?P<b>{_TOKEN})_(?P<s>{_TOKEN})$")


def _label(text: str) -> ClipLabel | None:
    m = _TRANSITION.match(text) or _TO.match(text)
    if m:
        return ClipLabel("transition", m["b1"].lower(), m["s1"].lower(), m["b2"].lower(), m["s2"].lower())
    m = _BASIC.match(text)
    if m and m["b"].lower() not in ("to", "transition"):
        return ClipLabel("basic", m["b"].lower(), m["s"].lower())
    return None


def parse_name(name: str, name_map: Mapping[str, str] | None = None) -> ClipLabel:
    """The label a clip name stands for.

    Parameters
    ----------
    name : clip name or file stem (a ``.bvh`` suffix and folders are ignored)
    name_map : optional ``{stem: label text}``; looked up first (exact stem)

    Raises
    ------
    NamingError naming the accepted forms.
    """
    stem = re.split(r"[\\/]", str(name))[-1]
    if stem.lower().endswith(".bvh"):
        stem = stem[:-4]
    if name_map and stem in name_map:
        label = _label(name_map[stem])
        if label is None:
            raise NamingError(
                f"name map gives {name_map[stem]!r} for {stem!r}, which is not 'behaviour_style' or 'b1_s1_to_b2_s2'"
            )
        return label
    m = _BANDAI.match(stem)
    if m:
        take = int(m["take"])
        style = m["s"].lower() if take == 1 else f"{m['s'].lower()}-{take}"
        return ClipLabel("basic", m["b"].lower(), style)
    label = _label(stem)
    if label is None:
        raise NamingError(
            f"cannot read behaviour and style from clip name {stem!r}: expected 'Behaviour_style' "
            "(Walk_creepingly), 'B1_s1_to_B2_s2' or 'Transition_B1_s1_B2_s2' for transition clips, "
            "'dataset-1_<behaviour>_<style>_<take>' (Bandai Namco), or an entry in the name map"
        )
    return label


def label_name(label: ClipLabel) -> str:
    """Canonical text of a label: ``walk_angry`` or ``walk_angry_to_run_normal``."""
    if label.kind == "transition":
        return f"{label.behaviour}_{label.style}_to_{label.to_behaviour}_{label.to_style}"
    return f"{label.behaviour}_{label.style}"
