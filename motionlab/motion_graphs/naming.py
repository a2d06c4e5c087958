"""Clip names → behaviour, style and transition labels.

The structured motion graph (paper B) files every clip under a *behaviour* (walk, run …) and a
*style* of that behaviour (normal, angry …). Clip names carry the labels:

==========================================  =========================================
name                                        label
==========================================  =========================================
``Walk_creepingly``                         basic clip: behaviour ``walk``, style ``creepingly``
``Walk_happily_to_Run_fast``                transition clip from walk/happily to run/fast
``Transition_Walk_normal_Run_slowly``       the same, in the paper's other spelling
``dataset-2_walk_angry_001``                Bandai Namco: walk/angry, take ``001``
``dataset-2_walk_angry_017``                the same style, take ``017`` (pooled with take 001)
``Walk_angry_3``                            walk/angry, take ``3``
``run/angry_13_000`` (behaviour folders)    Xia et al.: run/angry, take ``13-000``
==========================================  =========================================

A take number never creates a style: a recording session delivers many takes of one behaviour
in one style, and the structured graph pools them (every take of ``walk/angry`` is material of
that one style). So a style is never a number: ``Idle_1``, CMU's ``131_03`` and Xia et al.'s
``angry_13_000`` give no label by their names alone. Xia et al. file each behaviour in a folder
of its own (``run/angry_13_000.bvh``: style, then numbers); read with ``behaviour=`` the folder's
name (``graph-build --behaviour-folders``), a name is then the style up to its first number and
the take from there, unless it names that behaviour itself (``walk/Walk_happily``), a
transition, or is a Bandai Namco name (which names its behaviour in any folder).

Labels are lower case. Names that fit none of these forms (most Mixamo clips) are looked up in a
*name map* ``{clip stem: "behaviour_style[_take]" or "b1_s1_to_b2_s2"}``, or passed through a
callable ``name_map(stem) -> label text | ClipLabel | None`` for other naming schemes;
:data:`MIXAMO_AJ` maps the Mixamo Aj clips of the shared data.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

__all__ = ["ClipLabel", "NamingError", "NameMap", "parse_name", "MIXAMO_AJ", "label_name"]


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
    take : the take's name within its style (``"001"``), ``None`` when the name has none; never
        part of :attr:`key`, so takes of one style share a key
    """

    kind: str
    behaviour: str
    style: str
    to_behaviour: str | None = None
    to_style: str | None = None
    take: str | None = None

    @property
    def key(self) -> tuple[str, str]:
        """``(behaviour, style)`` of a basic clip (the source for a transition)."""
        return (self.behaviour, self.style)

    @property
    def to_key(self) -> tuple[str, str] | None:
        return None if self.to_behaviour is None else (self.to_behaviour, self.to_style)


MIXAMO_AJ: dict[str, str] = {
    "Ready_Idle": "idle_normal",
    "Catwalk_Walk": "walk_catwalk",
    "Catwalk_Idle_To_Walk_Forward": "idle_normal_to_walk_catwalk",
    "Running": "dive-roll_normal",
    "Jumping": "jump_normal",
    "Standing_Land_To_Standing_Idle": "jump_normal_to_idle_normal",
}
"""Mixamo Aj clips of the shared data as behaviour/style names (land → idle, idle → walk), named
by what they show rather than by their file names: ``Running`` is a run into a dive roll (the hips
drop to a tenth of their standing height) and ``Idle`` a crouch, so the standing idle that the two
transition clips start and end in is ``Ready_Idle``."""

_BANDAI = re.compile(r"^dataset-\d+_(?P<b>[a-z0-9-]+)_(?P<s>[a-z0-9-]+)_(?P<take>\d+)$", re.IGNORECASE)
_TOKEN = r"[A-Za-z0-9-]+"
_TO = re.compile(rf"^(?P<b1>{_TOKEN})_(?P<s1>{_TOKEN})_to_(?P<b2>{_TOKEN})_(?P<s2>{_TOKEN})$", re.IGNORECASE)
_TRANSITION = re.compile(
    rf"^transition[_ ](?P<b1>{_TOKEN})_(?P<s1>{_TOKEN})[_ ](?P<b2>{_TOKEN})_(?P<s2>{_TOKEN})$", re.IGNORECASE
)
_BASIC = re.compile(rf"^(?P<b>{_TOKEN})_(?P<s>{_TOKEN})$")
_TAKE = re.compile(rf"^(?P<b>{_TOKEN})_(?P<s>{_TOKEN})_(?P<take>\d+(?:-\d+)*)$")


def _label(text: str) -> ClipLabel | None:
    m = _TRANSITION.match(text) or _TO.match(text)
    if m and not (m["s1"].isdigit() or m["s2"].isdigit()):
        return ClipLabel("transition", m["b1"].lower(), m["s1"].lower(), m["b2"].lower(), m["s2"].lower())
    m = _TAKE.match(text) or _BASIC.match(text)
    if m and m["b"].lower() not in ("to", "transition") and not m["s"].isdigit():
        return ClipLabel("basic", m["b"].lower(), m["s"].lower(), take=m.groupdict().get("take"))
    return None


def _in_folder(stem: str, behaviour: str) -> ClipLabel | None:
    """``stem`` read as ``<style>[_<number>…]`` of ``behaviour`` (the style's words joined by
    ``-``, the numbers the take); ``None`` when it is not of that form."""
    words = stem.split("_")
    k = next((i for i, w in enumerate(words) if w.isdigit()), len(words))
    style, numbers = "-".join(words[:k]), words[k:]
    if not re.fullmatch(_TOKEN, style) or style.isdigit() or not all(w.isdigit() for w in numbers):
        return None
    return ClipLabel("basic", behaviour.lower(), style.lower(), take="-".join(numbers) or None)


NameMap = Mapping[str, str] | Callable[[str], "str | ClipLabel | None"]
"""A name map: ``{stem: label text}`` or a callable ``stem -> label text | ClipLabel | None``."""


def _mapped(stem: str, name_map: NameMap) -> ClipLabel | None:
    if callable(name_map):
        text = name_map(stem)
    elif stem in name_map:
        text = name_map[stem]
    else:
        return None
    if text is None or isinstance(text, ClipLabel):
        return text
    label = _label(str(text))
    if label is None:
        raise NamingError(
            f"name map gives {text!r} for {stem!r}, which is not 'behaviour_style', "
            "'behaviour_style_take' or 'b1_s1_to_b2_s2'"
        )
    return label


def parse_name(name: str, name_map: NameMap | None = None, behaviour: str | None = None) -> ClipLabel:
    """The label a clip name stands for.

    Parameters
    ----------
    name : clip name or file stem (a ``.bvh`` suffix and folders are ignored)
    name_map : optional ``{stem: label text}`` (exact stem) or a callable that takes the stem
        and returns label text, a ``ClipLabel`` or ``None``; consulted first, ``None`` / a missing
        stem falls back to the built-in forms
    behaviour : optional behaviour of the clip's folder (module docstring): a basic clip whose
        name does not name this behaviour is read as ``<style>[_<number>…]`` of it

    Raises
    ------
    NamingError naming the accepted forms.
    """
    stem = re.split(r"[\\/]", str(name))[-1]
    if stem.lower().endswith(".bvh"):
        stem = stem[:-4]
    if name_map is not None:
        label = _mapped(stem, name_map)
        if label is not None:
            return label
    m = _BANDAI.match(stem)
    if m:  # the studio's own labels, in any folder
        return ClipLabel("basic", m["b"].lower(), m["s"].lower(), take=m["take"])
    label = _label(stem)
    if behaviour is not None and (label is None or label.kind == "basic" and label.behaviour != behaviour.lower()):
        if not re.fullmatch(_TOKEN, behaviour):
            raise NamingError(f"folder name {behaviour!r} is not a behaviour name (letters, digits and '-' only)")
        label = _in_folder(stem, behaviour)
        if label is None:
            raise NamingError(
                f"cannot read a style from clip name {stem!r} in behaviour folder {behaviour!r}: expected "
                "'<style>' or '<style>_<number>…' (angry_13_000), or an entry in the name map"
            )
    if label is None:
        raise NamingError(
            f"cannot read behaviour and style from clip name {stem!r}: expected 'Behaviour_style' "
            "(Walk_creepingly), 'Behaviour_style_take' (Walk_creepingly_2), 'B1_s1_to_B2_s2' or 'Transition_B1_s1_B2_s2' for transition clips, "
            "'dataset-1_<behaviour>_<style>_<take>' (Bandai Namco), or an entry in the name map; a style is not a "
            "number (where each folder holds one behaviour, as Xia et al.'s run/angry_13_000.bvh, the folders name "
            "the behaviours: graph-build --behaviour-folders)"
        )
    return label


def label_name(label: ClipLabel) -> str:
    """Canonical text of a label: ``walk_angry``, ``walk_angry_001`` (with a take) or
    ``walk_angry_to_run_normal``; :func:`parse_name` reads it back to the same label."""
    if label.kind == "transition":
        return f"{label.behaviour}_{label.style}_to_{label.to_behaviour}_{label.to_style}"
    if label.take is not None:
        return f"{label.behaviour}_{label.style}_{label.take}"
    return f"{label.behaviour}_{label.style}"
