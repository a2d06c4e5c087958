"""Expand a motion database: many clips onto many characters in one batched, resumable job.

The retargeting paper's stated purpose is to *expand motion databases*: one performer's
library, generated for every new character (Wang, Li, Xie and Jia 2023, skeletal motion data generation for humanoid character animation, DOI 10.3969/j.issn.1003-5060.2023.01.006, abstract). :func:`expand` takes
source clips × target characters and writes ``OUT/<character>/<clip>.bvh`` (or ``.glb``, glTF 2.0,
with ``output_format="glb"``) plus ``OUT/manifest.csv``, one row per (clip, character)::

    job = expand(["Aj/*.bvh"], characters("Kaya/Running.bvh", "long_legs"), "out/")
    print(job.summary())

* **Batched.** The network is loaded once; on the CPU pairs of equal length are solved together
  (:mod:`motionlab.retargeting.batching`), each output bit-for-bit what ``motionlab retarget``
  writes for that pair. On a GPU pairs of any length share a batch (padded, ``pad``) and worker
  processes read the clips and finish and encode the outputs while the GPU solves
  (:mod:`motionlab.retargeting.host`, ``host_workers``).
* **Resumable and safe.** Every BVH is written to a temporary file; the manifest (rewritten
  atomically) records a batch's rows *before* its files are renamed into place. A rerun keeps
  an output only when its file exists and its row's SHA-256 of the source file
  (``source_sha256``), of the character (``character_sha256``: the file's bytes, or a preset's
  factors) and of every option that changes the result (``options_sha256``: the checkpoint's
  weights, the solver settings, the root rule, the output frame rate and motionlab's own code,
  :data:`RESULT_CODE`: another version may write other outputs) are those of this run;
  everything else is redone and :attr:`ExpandResult.redone` says why. A kill at any moment loses
  at most the batch in flight. An output that exists but is not in the manifest is someone else's file and is
  only replaced with ``force=True``. A clip that cannot be read or mapped is recorded as an
  ``error`` row with its message, and the job goes on.
* **Quality flags.** A row is flagged when its mean foot penetration exceeds
  ``max_penetration_cm`` (default 1 cm: about a shoe sole) or, ``skating``, when its planted
  feet slide: on the frames where the source's feet are planted, B's feet move faster than the
  contact detector's speed limit on B (:attr:`plausibility.Plausibility.skating`) and faster
  than ``skate_ratio`` (default 2) times the source's own planted feet scaled by the root's ground
  ratio ``r_xz`` (a longer-legged character moves its feet faster by that ratio; sliding beyond
  twice that is new sliding the retargeting added). A low swinging foot is not a planted one.
  Both rules are set by these principles, not fitted to any clip. Every output also goes through the plausibility tests of
  :mod:`motionlab.retargeting.plausibility` (feet on the floor, hip height, bone lengths); a
  failed test adds ``implausible_<test>`` to ``flag``.
* **Frame rate.** Outputs are at each source's frame rate unless ``fps`` is given; the network
  runs at the checkpoint's, and every resample is listed in :attr:`ExpandResult.resampled`.
* **Beyond one machine.** ``backend="ray"`` sends the same batches to Ray actors
  (:mod:`motionlab.retargeting.cluster`), each loading the checkpoint once; this process
  still writes every file and the manifest, so both backends give the same outputs.

Taught in ``notebooks/07_expanding_a_database.ipynb``.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import functools
import glob
import hashlib
import io
import json
import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from motionlab.core import bvh, files, humanoid, metrics, motion_files, rest_pose
from motionlab.core.motion import resampled_frames
from motionlab.core.skeleton import Skeleton
from motionlab.core.threads import batch_threads, torch_threads
from motionlab.retargeting import host, terms
from motionlab.retargeting.batching import (
    Pair,
    PairResult,
    batch_frames,
    finish_job,
    plan_batches,
    quality,
    solve_jobs,
)
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.pipeline import at_rate, prepare_pair, prepare_source, target_skeleton
from motionlab.retargeting.solver import PROJECT_DAMPING, SolverConfig

__all__ = [
    "PRESETS",
    "MANIFEST",
    "COLUMNS",
    "columns",
    "FORMATS",
    "Character",
    "characters",
    "find_sources",
    "check_output_layout",
    "read_manifest",
    "options_digest",
    "code_digest",
    "RESULT_CODE",
    "ExpandResult",
    "expand",
    "prepare_clip",
]

PRESETS: dict[str, dict[str, float]] = {
    "long_legs": {"legs": 1.3},
    "short_legs": {"legs": 0.75},
    "long_arms": {"arms": 1.35},
    "stocky": {"legs": 0.8, "arms": 0.85, "spine": 0.85, "neck": 0.8},
    "tall": {"overall": 1.2},
    "child": {"legs": 0.85, "arms": 0.85, "spine": 0.9, "neck": 1.1, "overall": 0.7},
}
"""Synthetic characters: :func:`humanoid.scale_bones` factors applied to the canonical T-pose
(:func:`humanoid.canonical_skeleton`, 1.75 m). ``NAME:legs=1.2,arms=0.9`` makes a custom one."""

MANIFEST = "manifest.csv"
_HEAD = ("clip", "character", "status", "output", "source", "character_file", "frames", "steps", "stop_reason", "loss")
_TAIL = (
    "penetration_cm", "skating_cm_s", "source_skating_cm_s", "seconds", "batch_size",
    "flag", "error", "fps", "source_sha256", "character_sha256", "options_sha256",
)  # fmt: skip


def columns() -> tuple[str, ...]:
    """The manifest's columns: :data:`COLUMNS` with one column per registered loss term (:mod:`.terms`) after ``loss``.

    Raises
    ------
    ValueError when a registered term is named like one of the other columns (its value would
    take that column's place: the output's file name, its status...).
    """
    clash = [t.name for t in terms.registered() if t.name in _HEAD + _TAIL]
    if clash:
        raise ValueError(
            f"the loss term(s) {clash} are named like columns of expand's manifest; register them under other names "
            f"(the manifest's own columns: {', '.join(_HEAD + _TAIL)})"
        )
    return _HEAD + tuple(t.name for t in terms.registered()) + _TAIL


COLUMNS = columns()
"""Manifest columns (with the built-in loss terms; :func:`columns` follows the registry): ``status``
is ``ok`` or ``error``; ``loss`` the returned (best) iterate's L_iter, then each term's value there
(``angle`` L_angle, ``foot`` L_foot in metres, ``contact`` L_contact in m/s, ``floor`` L_floor in
metres, …; lengths of B at the network's character's scale, :data:`~motionlab.retargeting.terms.LENGTH_SCALE`); ``seconds`` the pair's share of its batch's wall time;
``flag`` lists the quality thresholds exceeded (``penetration``, ``skating``) and the failed
plausibility tests (``implausible_foot``, ``_floor``, ``_hips``, ``_bones``), empty if none; ``fps`` the
output's frame rate; the ``*_sha256`` columns key resumption (module docstring)."""
_OLD_COLUMNS = COLUMNS[: COLUMNS.index("fps")]  # manifests written before the content keys: all redone


def _without_terms(names) -> tuple:
    """Column names with the loss-term columns (between ``loss`` and ``penetration_cm``) left out:
    manifests written with other registered terms are still this format (their options key differs)."""
    names = tuple(names)
    if "loss" not in names or _TAIL[0] not in names:
        return names
    return names[: names.index("loss") + 1] + names[names.index(_TAIL[0]) :]


FORMATS = ("bvh", "glb")
"""Output formats of :func:`expand`: BVH text or binary glTF 2.0 (:mod:`motionlab.core.gltf`)."""


_ERRORS = (
    ValueError,
    OSError,
    KeyError,
    IndexError,
)  # what a bad input file raises (BVHError, RigMappingError ⊂ ValueError)


@dataclass
class Character:
    """A target character: a name (the output folder) and its rest skeleton.

    Attributes
    ----------
    name : str
    skeleton : Skeleton or None     ``None`` when the file could not be read (``error`` says why)
    origin : str                    the BVH path or ``preset:NAME``
    error : str                     why the character cannot be used ("" if it can)
    digest : str                    SHA-256 of the file's bytes, or of a preset's factors
    unit : float                    metres per length unit of the file (:func:`motion_files.file_unit`):
                                    a ``.glb`` output is written in metres from it
    """

    name: str
    skeleton: Skeleton | None
    origin: str
    error: str = ""
    digest: str = ""
    unit: float = motion_files.CM


def _preset(spec: str) -> tuple[str, dict[str, float]]:
    name, _, rest = spec.partition(":")
    if not rest:
        if name not in PRESETS:
            raise ValueError(f"unknown character preset {name!r}; presets: {', '.join(PRESETS)} (or NAME:legs=1.2,...)")
        return name, PRESETS[name]
    factors = {}
    for item in rest.split(","):
        key, _, value = item.partition("=")
        if key not in ("legs", "arms", "spine", "neck", "overall"):
            raise ValueError(f"preset {spec!r}: unknown bone group {key!r}; expected legs, arms, spine, neck, overall")
        try:
            factors[key] = float(value)
        except ValueError:
            raise ValueError(f"preset {spec!r}: {key}={value!r} is not a number") from None
    return name, factors


def characters(*specs: str, presets: Iterable[str] = (), rest_from=None) -> list[Character]:
    """Target characters from ``FILE.bvh``, ``NAME=FILE.bvh`` and preset names.

    ``rest_from``: a Motion whose standing pose serves every file on its rig
    (:func:`rest_pose.on_reference`, ``--rest-from``).

    A file's character is named after its stem; stems shared by several files are made unique
    with the parent folder (``Kaya/Jumping.bvh`` → ``Kaya_Jumping``). A file that cannot be read
    or mapped gives a :class:`Character` with ``error`` set (its pairs are recorded as errors).
    Raises ``ValueError`` for a name used twice, a missing file or an unknown preset.
    """
    entries = []
    for spec in specs:
        name, sep, path = str(spec).partition("=")
        if not sep:
            name, path = "", spec
        p = Path(path)
        if not p.is_file():
            raise ValueError(f"character file {p} not found")
        entries.append([name, p])
    stems = [p.stem for n, p in entries if not n]
    for e in entries:
        if not e[0]:
            e[0] = e[1].stem if stems.count(e[1].stem) == 1 else f"{e[1].parent.name}_{e[1].stem}"
    out = []
    for name, p in entries:
        digest = _sha256(p)
        try:
            rig = rest_pose.on_reference(bvh.load(p), rest_from, f"character file {p}")
            sk = target_skeleton(rig, f"character file {p}")
            out.append(Character(name, sk, str(p), digest=digest, unit=motion_files.file_unit(rig.skeleton)))
        except _ERRORS as err:
            out.append(Character(name, None, str(p), _why(err, "character", p), digest))
    for spec in presets:
        name, factors = _preset(spec)
        sk = humanoid.scale_bones(humanoid.canonical_skeleton(), **factors)
        digest = hashlib.sha256(json.dumps(factors, sort_keys=True).encode()).hexdigest()
        out.append(Character(name, sk, f"preset:{spec}", digest=digest))
    names = [c.name for c in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"character name(s) {dup} used twice; name them with NAME=FILE.bvh")
    for n in names:
        _check_name(n, "character")
    return out


def _sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


RESULT_CODE = ("core", "retargeting")
"""The package's folders whose Python source is part of :func:`options_digest`: a run with another
motionlab (an upgrade, an edit) redoes the rows an older one wrote instead of keeping them."""


@functools.cache
def code_digest() -> bytes:
    """SHA-256 of every module under :data:`RESULT_CODE`: each path (relative to the package) and its bytes."""
    h = hashlib.sha256()
    package = Path(__file__).resolve().parent.parent
    for folder in RESULT_CODE:
        for path in sorted((package / folder).rglob("*.py")):
            h.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    return h.digest()


def options_digest(
    checkpoint: Checkpoint, solver: SolverConfig, root_mode: str, fps: float | None, rest_from=None, flags=None
) -> str:
    """SHA-256 of everything besides source and character that changes an output or its row: the
    checkpoint's weights, normalisation and frame rate, the solver settings, the registered loss
    terms and their weights, the root rule, the output rate, the ``rest_from`` motion (its rest
    offsets and rotations; nothing when None), ``flags``, the thresholds the row's ``flag``
    is set by, and motionlab's code (:func:`code_digest`)."""
    h = hashlib.sha256(code_digest())
    for name, tensor in sorted(checkpoint.model.state_dict().items()):
        h.update(name.encode())
        h.update(tensor.detach().cpu().double().numpy().tobytes())
    h.update(np.asarray(checkpoint.stats.mean, dtype=np.float64).tobytes())
    h.update(np.asarray(checkpoint.stats.std, dtype=np.float64).tobytes())
    settings = {"solver": dataclasses.asdict(solver), "root": root_mode, "fps": fps, "ckpt_fps": checkpoint.fps}
    if flags is not None:
        settings["flags"] = flags
    settings["terms"] = [[t.name, solver.weight(t.name)] for t in terms.registered()]  # what L_iter sums
    dtype = next(checkpoint.model.parameters()).dtype
    settings["damping"] = solver.project_damping or PROJECT_DAMPING.get(dtype, 1e-3)  # the one project_latent uses
    h.update(json.dumps(settings, sort_keys=True, default=str).encode())
    if rest_from is not None:
        h.update(np.asarray(rest_from.skeleton.offsets, dtype=np.float64).tobytes())
        h.update(np.asarray(rest_from.local_rot, dtype=np.float64).tobytes())
    return h.hexdigest()


def _why(err: Exception, role: str, path) -> str:
    """What went wrong with the ``role`` (character, source) file ``path``, in words a command-line user can act on."""
    if isinstance(err, humanoid.RigMappingError):  # its Python hint (profile=...) has no command-line form
        return f"{type(err).__name__}: {err.for_file(role, path)}"
    return f"{type(err).__name__}: {err}"


def _check_name(name: str, what: str) -> None:
    if not name or name in (".", "..") or "/" in name or "\\" in name or name.startswith("."):
        raise ValueError(f"{what} name {name!r} cannot be a folder or file name")
    if what == "character" and name == MANIFEST:
        raise ValueError(f"character name {name!r} is the job's manifest file's; name the character otherwise")


def find_sources(specs: Sequence[str]) -> list[tuple[str, Path]]:
    """``(clip name, path)`` for BVH files, folders (their BVH files, sorted) and glob patterns; a
    file named twice (by any path) counts once.

    Clip names are file stems; where stems repeat, the folders above them are put in front
    (``take_Run``, then ``a_take_Run``) until every name is unique.
    Raises ``ValueError`` when a spec matches nothing.
    """
    paths: dict[Path, Path] = {}
    for spec in specs:
        p = Path(spec)
        if p.is_dir():
            found = files.bvh_files(p)
        elif p.is_file():
            found = [p]
        else:
            found = sorted(Path(f) for f in glob.glob(str(spec), recursive=True) if f.lower().endswith(".bvh"))
        if not found:
            raise ValueError(f"source {spec!r} matches no BVH file")
        for f in found:
            paths.setdefault(f.resolve(), f)
    return list(zip(_unique_names([Path(os.path.abspath(f)) for f in paths.values()]), paths.values()))


def _unique_names(paths: list[Path]) -> list[str]:
    """A name per distinct absolute path: its stem, with as many folders above it in front as make
    it unique."""
    depth = [0] * len(paths)
    while True:
        names = ["_".join([*p.parent.parts[max(0, len(p.parent.parts) - d) :], p.stem]) for p, d in zip(paths, depth)]
        repeated = {n for n in names if names.count(n) > 1}
        if not repeated:
            return names
        for k, n in enumerate(names):
            if n in repeated:
                depth[k] += 1


def check_output_layout(
    out: str | Path, clips: Sequence[tuple[str, Path]], targets: Sequence[Character], suffix: str
) -> None:
    """Refuse, before any work, an output location of the wrong kind under the folder ``out``.

    ``out/<character>`` must be a folder (or not exist yet); ``out/manifest.csv`` and every
    ``out/<character>/<clip><suffix>`` a file (or not exist yet). ``clips`` as from
    :func:`find_sources`, ``suffix`` the outputs' file suffix (``".bvh"`` or ``".glb"``).

    Raises
    ------
    ValueError
        naming the first path of the wrong kind and what was expected there.
    """
    out = Path(out)
    if (out / MANIFEST).is_dir():
        raise ValueError(
            f"{out / MANIFEST} is a folder; expected the job's manifest file (remove or rename the folder)"
        )
    for c in targets:
        folder = out / c.name
        if folder.exists() and not folder.is_dir():
            raise ValueError(
                f"{folder} is a file; expected the folder of character {c.name!r}'s outputs "
                "(remove or rename the file, or choose another output folder)"
            )
        for clip, _ in clips:
            if (folder / f"{clip}{suffix}").is_dir():
                raise ValueError(
                    f"{folder / f'{clip}{suffix}'} is a folder; expected the output file of clip {clip!r} "
                    "(remove or rename the folder)"
                )


# ---------------------------------------------------------------------------- manifest
def read_manifest(out: str | Path) -> list[dict]:
    """The rows of ``OUT/manifest.csv`` (empty when there is none). Raises ``ValueError`` naming the
    file when it is not a manifest of this format."""
    path = Path(out) / MANIFEST
    if not path.is_file():
        return []
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        cols = columns()
        if _without_terms(reader.fieldnames or ()) not in (_without_terms(cols), _without_terms(_OLD_COLUMNS)):
            raise ValueError(f"{path} is not an expand manifest (columns {reader.fieldnames}, expected {list(cols)})")
        return [{k: r.get(k, "") for k in cols} for r in reader]


@contextlib.contextmanager
def _folder_lock(out: Path):
    """Hold an exclusive lock on the folder ``out`` (``flock`` on the folder itself, so no lock file
    is left in it); where ``flock`` does not exist (Windows), no lock."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    fd = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def _write_manifest(out: Path, rows: list[dict], outputs: Sequence[tuple[Path, bytes]] = ()) -> None:
    """Write ``rows`` as the manifest, merged by ``(character, clip)`` with the rows on disk for
    pairs not among ``rows`` (another run's, written meanwhile), under a lock on the folder: two runs
    into one folder keep both runs' rows. A kept row is checked again when a run reuses it.
    ``outputs`` (path, bytes) are written with it as one (:func:`motionlab.core.files.atomic_write_all`),
    renamed after the manifest: a kill in between leaves rows without files, which a rerun redoes."""
    mine = {(r["character"], r["clip"]): r for r in rows}
    with _folder_lock(out):
        merged = dict(mine)
        for r in read_manifest(out):
            merged.setdefault((r["character"], r["clip"]), r)
        buf = io.StringIO()
        cols = columns()
        w = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
        w.writeheader()
        for key in sorted(merged):
            w.writerow({k: merged[key].get(k, "") for k in cols})
        text = buf.getvalue()
        writes = [(out / MANIFEST, lambda f: f.write(text), False, "manifest")]
        writes += [(file, lambda f, data=data: f.write(data), True, "output") for file, data in outputs]
        files.atomic_write_all(writes, overwrite=True)


def _fmt(v: float) -> str:
    return f"{v:.6g}"


# ---------------------------------------------------------------------------- result
@dataclass
class ExpandResult:
    """What :func:`expand` did.

    Attributes
    ----------
    out : Path              the output folder
    rows : list of dict     the manifest rows (all of them, old and new), :data:`COLUMNS`
    done : int              pairs solved in this run
    skipped : int           pairs found complete (file + manifest row) and not redone
    failed : int            pairs recorded as ``error`` in this run
    source_frames : int     source frames (at the checkpoint's rate) solved in this run
    seconds : float         wall time of the run
    batches : int           latent-iteration batches run
    redone : dict           why outputs that existed were redone: reason -> count (``source changed``,
                            ``character changed``, ``options changed``: also motionlab's code,
                            ``file missing``)
    resampled : list of str   one line per source whose frame rate changed on the way
    implausible : int       outputs of this run that failed a plausibility test
    timings : dict          wall time, seconds: ``load`` (plan the batches, and read and prepare
                            the sources and pairs where a batch waits for them: a GPU solves
                            the first batches while host workers prepare the rest), ``solve``
                            (the latent iteration of the batches, and the outputs
                            finished, checked and encoded where no host workers do it),
                            ``finish`` (waiting for the host workers' outputs, with workers),
                            ``write`` (files and manifest)
    """

    out: Path
    rows: list = field(default_factory=list)
    done: int = 0
    skipped: int = 0
    failed: int = 0
    source_frames: int = 0
    seconds: float = 0.0
    batches: int = 0
    redone: dict = field(default_factory=dict)
    resampled: list = field(default_factory=list)
    implausible: int = 0
    timings: dict = field(default_factory=lambda: {"load": 0.0, "solve": 0.0, "write": 0.0})

    @property
    def throughput(self) -> float:
        """Source frames solved per second of wall time in this run."""
        return self.source_frames / self.seconds if self.seconds > 0 else 0.0

    def summary(self) -> str:
        """A fixed-width table: one line per character, then the run's totals."""
        head = f"{'character':<18} {'ok':>4} {'err':>4} {'flag':>4} {'steps':>6} {'L_iter':>8} {'pen cm':>7} {'skate cm/s':>10}"
        lines = [head, "-" * len(head)]
        for name in sorted({r["character"] for r in self.rows}):
            rs = [r for r in self.rows if r["character"] == name]
            ok = [r for r in rs if r["status"] == "ok"]

            def mean(key, width, digits, ok=ok):  # "-" where no pair succeeded: no mean to show
                return f"{np.mean([float(r[key]) for r in ok]):>{width}.{digits}f}" if ok else f"{'-':>{width}}"

            lines.append(
                f"{name:<18} {len(ok):>4} {len(rs) - len(ok):>4} {sum(1 for r in ok if r['flag']):>4} "
                f"{mean('steps', 6, 1)} {mean('loss', 8, 4)} {mean('penetration_cm', 7, 3)} {mean('skating_cm_s', 10, 2)}"
            )
        why = ", ".join(f"{n} {reason}" for reason, n in sorted(self.redone.items()))
        redone = sum(self.redone.values())
        lines.append(
            f"this run: {self.done} solved ({redone} redone{': ' + why if why else ''}; "
            f"{self.implausible} implausible), {self.skipped} already done, {self.failed} failed; "
            f"{self.source_frames} source frames in {self.seconds:.1f} s = {self.throughput:.0f} frames/s "
            f"({self.batches} batches); manifest {self.out / MANIFEST}"
        )
        return "\n".join(lines)


# ---------------------------------------------------------------------------- the job
def _row(pr: PairResult, src: _Source, char: Character, limits, suffix: str, out_motion, options: str) -> dict:
    res = pr.result
    h = res.history
    q = quality(res, char.unit)
    flags = []
    if q["penetration_cm"] > limits[0]:
        flags.append("penetration")
    check = res.plausibility  # planted-foot slide on A's stance frames (plausibility.Plausibility.skating)
    if check.skating and check.slide > limits[1] * check.source_slide * res.root_scale[0]:
        flags.append("skating")
    flags += [f"implausible_{t}" for t in res.plausibility.failed]
    source = src.path
    best = res.best_step  # the returned iterate's losses, not the last step's
    return {
        "clip": pr.clip,
        "character": pr.character,
        "status": "ok",
        "output": f"{pr.character}/{pr.clip}{suffix}",
        "source": source,
        "character_file": char.origin,
        "frames": str(out_motion.num_frames),
        "steps": str(res.steps),
        "stop_reason": res.stop_reason,
        "loss": _fmt(h["loss"][best]),
        **{t.name: _fmt(h[t.name][best]) if h.get(t.name) else "" for t in terms.registered()},
        "penetration_cm": _fmt(q["penetration_cm"]),
        "skating_cm_s": _fmt(q["skating_cm_s"]),
        "source_skating_cm_s": _fmt(src.skating),
        "seconds": _fmt(pr.seconds),
        "batch_size": str(pr.batch_size),
        "flag": "+".join(flags),
        "error": "",
        "fps": _fmt(out_motion.fps),
        "source_sha256": src.digest,
        "character_sha256": char.digest,
        "options_sha256": options,
    }


@dataclass
class _Source:
    """What the rows need of a source clip: its path, skating (cm/s), frame rate, frames and SHA-256."""

    path: str
    skating: float
    fps: float
    digest: str
    frames: int


def _reuse(old: dict | None, file: Path, expected: tuple[str, str, str], output: str) -> str:
    """``""`` when the old row's output can be kept, else why it must be redone (``"new"``: no output)."""
    if old is None or old["status"] != "ok" or old["output"] != output:
        return "new"
    if not file.is_file():
        return "file missing"
    for key, value, reason in zip(
        ("source_sha256", "character_sha256", "options_sha256"),
        expected,
        ("source changed", "character changed", "options changed"),
    ):
        if old.get(key, "") != value:
            return reason
    return ""


def _error_row(clip: str, character: str, source: str, origin: str, message: str, suffix: str = ".bvh") -> dict:
    return {
        "clip": clip,
        "character": character,
        "status": "error",
        "output": f"{character}/{clip}{suffix}",
        "source": source,
        "character_file": origin,
        "error": message.replace("\n", " "),
    }


def _clean_temporaries(folder: Path) -> None:
    """Remove what a killed run left: the temporary files of writers that no longer run
    (:func:`motionlab.core.files.remove_stale_in`), and ``.<name>.*.tmp`` files of older releases."""
    if folder.is_dir():
        files.remove_stale_in(folder)
        for t in folder.glob(".*.tmp"):
            t.unlink(missing_ok=True)


def expand(
    sources: Sequence[str],
    targets: Sequence[Character],
    out: str | Path,
    checkpoint: Checkpoint,
    solver: SolverConfig | None = None,
    root_mode: str = "stride",
    force: bool = False,
    max_frames: int | None = None,
    backend: str = "local",
    address: str | None = None,
    workers: int = 2,
    max_penetration_cm: float = 1.0,
    skate_ratio: float = 2.0,
    progress: bool = False,
    on_batch: Callable[[int, list[dict]], None] | None = None,
    threads: int | None = None,
    output_format: str = "bvh",
    fps: float | None = None,
    rest_from=None,
    host_workers: int | None = None,
    pad: bool | None = None,
) -> ExpandResult:
    """Retarget every source clip onto every character; see the module docstring.

    Parameters
    ----------
    sources : files, folders or glob patterns of BVH clips (:func:`find_sources`)
    targets : characters (:func:`characters`)
    out : output folder (created)
    checkpoint : the network (loaded once, used for every batch)
    solver, root_mode : as for ``motionlab retarget``
    force : redo and replace every output, including existing files not in the manifest
    max_frames : frames per batch (default :func:`batching.batch_frames` for the device)
    backend : ``"local"`` or ``"ray"``; ``address``: Ray cluster (default ``RAY_ADDRESS``, else a
        local Ray instance with ``workers`` CPUs); ``workers``: Ray actors
    max_penetration_cm, skate_ratio : quality-flag thresholds (module docstring)
    progress : tqdm bar over batches
    on_batch : called as ``on_batch(batch_index, rows)`` after each batch is on disk (tests use it
        to interrupt a run)
    threads : torch CPU threads during the job (restored afterwards); default
        :func:`motionlab.core.threads.batch_threads`: 1 on the CPU, unchanged on a GPU.
    output_format : ``"bvh"`` (default) or ``"glb"`` (glTF 2.0, :func:`motionlab.core.gltf.dumps`):
        the outputs' format and file suffix. A rerun in another format redoes every pair.
    fps : frame rate of every output (default: each source's own); the network runs at the
        checkpoint's rate
    rest_from : a Motion whose standing pose serves every source on its rig
        (:func:`rest_pose.on_reference`, ``--rest-from``; pass the same to :func:`characters`)
    host_workers : processes that read and prepare the clips and finish and encode the outputs
        while the network solves (:mod:`motionlab.retargeting.host`); default
        :func:`host.default_workers`: none on the CPU, every core but one on a GPU (at most 4)
    pad : let pairs of other lengths share a batch (:func:`batching.plan_batches`); default: on a
        GPU, when every registered term honours padding (:func:`terms.unpadded`)

    Returns
    -------
    ExpandResult

    Raises
    ------
    ValueError for an unknown ``backend`` or ``output_format``.
    """
    if backend not in ("local", "ray"):
        raise ValueError(f"backend must be 'local' or 'ray', got {backend!r}")
    if output_format not in FORMATS:
        raise ValueError(f"output_format must be one of {FORMATS}, got {output_format!r}")
    with torch_threads(batch_threads(checkpoint.device, threads)):
        return _expand(
            sources, targets, out, checkpoint, solver, root_mode, force, max_frames, backend, address, workers,
            max_penetration_cm, skate_ratio, progress, on_batch, "." + output_format, fps, rest_from,
            host_workers, pad,
        )  # fmt: skip


def _plan(clips, targets, out, known, force, suffix, options, result, rows):
    """Which pairs to solve: a kept output needs its file and unchanged content hashes."""
    todo: list[tuple[str, Path, Character, str]] = []
    digests: dict[Path, str] = {}
    for clip, path in clips:
        try:
            digests[path] = digests.get(path) or _sha256(path)
        except OSError:
            digests[path] = ""  # unreadable: preparing the clip records the error
        for c in targets:
            key, output = (c.name, clip), f"{c.name}/{clip}{suffix}"
            file = out / output
            old = known.get(key)
            why = _reuse(old, file, (digests[path], c.digest, options), output)
            if not force and not why:
                rows[key] = old
                result.skipped += 1
            elif file.exists() and not force and why == "new":
                message = f"{file} exists and is not an output of this job; pass --force to replace it"
                rows[key] = _error_row(clip, c.name, str(path), c.origin, message, suffix)
                result.failed += 1
            else:
                todo.append((clip, path, c, digests[path]))
                if why != "new" or force and file.exists():
                    reason = "forced" if force else why
                    result.redone[reason] = result.redone.get(reason, 0) + 1
    # rows of the old manifest for pairs outside this run stay while their files exist
    planned = {(c.name, clip) for clip, _, c, _ in todo}
    for key, r in known.items():
        if key not in rows and key not in planned and (r["status"] != "ok" or (out / r["output"]).is_file()):
            rows[key] = r
    return todo


def _expand(
    sources, targets, out, checkpoint, solver, root_mode, force, max_frames, backend, address, workers,
    max_penetration_cm, skate_ratio, progress, on_batch, suffix, fps, rest_from=None, host_workers=None, pad=None,
) -> ExpandResult:  # fmt: skip
    start = time.perf_counter()
    out = Path(out)
    solver = solver or SolverConfig()
    clips = find_sources(sources)
    for name, _ in clips:
        _check_name(name, "clip")
    if not targets:
        raise ValueError("no target characters given")
    check_output_layout(out, clips, targets, suffix)  # before any work: nothing is written on a refusal
    columns()  # refuses a loss term named like a manifest column, before any work too
    out.mkdir(parents=True, exist_ok=True)
    known = {(r["character"], r["clip"]): r for r in read_manifest(out)}
    for c in targets:
        _clean_temporaries(out / c.name)
    result = ExpandResult(out)
    rows: dict[tuple[str, str], dict] = {}
    flags = {"max_penetration_cm": max_penetration_cm, "skate_ratio": skate_ratio}
    options = options_digest(checkpoint, solver, root_mode, fps, rest_from, flags)
    todo = _plan(clips, targets, out, known, force, suffix, options, result, rows)
    gpu = checkpoint.device.type != "cpu"
    workers_here = host.default_workers(checkpoint.device) if host_workers is None else host_workers
    with host.pool(checkpoint, workers_here if todo else 0) as pool:
        loader = _Sources(todo, checkpoint, solver, rows, result, suffix, rest_from, root_mode, pool, fps)
        context = (
            loader.sources,
            {c.name: c for c in targets},
            (max_penetration_cm, skate_ratio),
            suffix,
            options,
            fps,
        )
        padding = (gpu and not terms.unpadded()) if pad is None else pad
        max_frames = max_frames or batch_frames(checkpoint.device)
        plan = loader.plan(max_frames, padding)
        planned = time.perf_counter() - start
        batches = loader.batches(plan, max_frames, padding)
        if backend == "ray":
            from motionlab.retargeting.cluster import solve_batches_ray

            stream = solve_batches_ray(checkpoint, list(batches), solver, root_mode, address=address, workers=workers)
            outputs = ([_output(pr, *context) for pr in solved] for solved in stream)
        else:
            outputs = _local_outputs(batches, checkpoint, solver, pool, context, result.timings)
        _write_all(outputs, len(plan), out, rows, result, progress, on_batch)
        _write_manifest(out, list(rows.values()))  # the error rows of clips no batch held
    result.timings["load"] = planned + loader.seconds
    result.timings["solve"] -= result.timings.get("finish", 0.0) + loader.seconds  # waits, not the solve
    result.rows = sorted(rows.values(), key=lambda r: (r["character"], r["clip"]))
    result.seconds = time.perf_counter() - start
    return result


def _write_all(outputs, count: int, out: Path, rows: dict, result: ExpandResult, progress: bool, on_batch) -> None:
    """Write each batch's outputs (rows, then files) as they come; time the waits as ``solve``."""
    from tqdm.auto import tqdm

    bar = tqdm(total=count, desc="expand", unit="batch", disable=not progress)
    clock = time.perf_counter()
    for index, batch in enumerate(outputs):
        result.timings["solve"] += time.perf_counter() - clock
        clock = time.perf_counter()
        for row, _, _, ok, frames in batch:
            rows[(row["character"], row["clip"])] = row
            result.implausible += not ok
            result.source_frames += frames
        staged = [(out / file, data) for _, file, data, _, _ in batch]
        for file, _ in staged:
            file.parent.mkdir(parents=True, exist_ok=True)
        _write_manifest(out, list(rows.values()), staged)
        result.timings["write"] += time.perf_counter() - clock
        result.done += len(batch)
        result.batches += 1
        bar.update(1)
        if on_batch is not None:
            on_batch(index, [b[0] for b in batch])
        clock = time.perf_counter()
    bar.total = bar.n  # fewer than planned when a planned batch's clips all failed
    bar.close()


def _local_outputs(batches, checkpoint, solver, pool, context, timings):
    """Each batch's outputs (:func:`_output`), in order. With a pool, a batch is finished and encoded
    there while the next one is solved; ``timings["finish"]`` is the time spent waiting for it."""
    timings.setdefault("finish", 0.0)
    pending = None
    for batch in batches:
        clock = time.perf_counter()
        jobs = [p.job for p in batch]
        solved = solve_jobs(checkpoint, jobs, solver)
        share = (time.perf_counter() - clock) / len(batch)
        args = [(p, j, r, len(batch), share, context) for p, j, r in zip(batch, jobs, solved)]
        if pool is None:
            yield [_finished_output(*a) for a in args]
            continue
        for a in args:  # host data only to the workers: no CUDA tensor, no CUDA call in their pipe's thread
            a[2].phi = a[2].phi.cpu()
        futures = [pool.submit(_finished_output, *a) for a in args]
        if pending is not None:
            yield _collect(pending, timings)
        pending = futures
    if pending is not None:
        yield _collect(pending, timings)


def _collect(futures, timings) -> list:
    clock = time.perf_counter()
    done = [f.result() for f in futures]
    timings["finish"] += time.perf_counter() - clock
    return done


def _finished_output(pair: Pair, job, solved, batch_size: int, seconds: float, context):
    """:func:`_output` of a solved pair (:func:`batching.finish_job` first); runs in a host worker."""
    return _output(finish_job(pair, job, solved, batch_size, seconds), *context)


def _output(pr: PairResult, sources_by_clip, chars, limits, suffix, options, fps):
    """``(row, file, bytes, plausible, source frames)`` of one retargeted pair, ready to write."""
    src = sources_by_clip[pr.clip]
    motion = at_rate(pr.result, fps or src.fps, src.fps, src.frames).motion
    char = chars[pr.character]
    row = _row(pr, src, char, limits, suffix, motion, options)
    data = motion_files.encode(motion_files.in_metres(motion, char.unit), suffix)  # 22 joints: centimetres in BVH
    return row, row["output"], data, pr.result.plausibility.ok, pr.result.motion.num_frames


def prepare_clip(path, rest_from, targets, root_mode, solver, checkpoint=None):
    """Read and prepare one source clip and its pairs, as :func:`expand` does.

    ``targets`` is a list of ``(character name, canonical Skeleton)``; ``rest_from`` as for
    :func:`expand`. Runs in a host worker (:func:`host.checkpoint`, the worker's CPU copy) or in
    this process with ``checkpoint`` given. Returns ``(motion, prepared, skating cm/s, {character:
    PreparedPair or error message})``; raises what reading or preparing the source raises
    (``ValueError``, ``OSError``, …).
    """
    checkpoint = checkpoint or host.checkpoint()
    motion = rest_pose.on_reference(bvh.load(path), rest_from, str(path))
    prepared = prepare_source(motion, checkpoint, "full", solver)
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    metres = motion_files.file_unit(motion.skeleton) / motion_files.CM  # the file was read as centimetres
    skating = 100.0 * metrics.foot_skating(metres * prepared.motion.global_positions(), feet, prepared.motion.fps)
    jobs = {}
    for name, skeleton in targets:
        try:
            jobs[name] = prepare_pair(prepared, skeleton, root_mode)
        except _ERRORS as err:
            jobs[name] = _why(err, "character", name)
    return motion, prepared, skating, jobs


def _header_frames(path, checkpoint: Checkpoint) -> int:
    """The frames a clip has once prepared (at the checkpoint's rate), from its BVH header alone;
    at least 1. A header that cannot be read counts as 1 frame (preparing the clip says why)."""
    try:
        frames, fps = bvh.header(path)
        return max(1, resampled_frames(frames, fps, checkpoint.fps))
    except _ERRORS:
        return 1


class _Sources:
    """The sources of an expansion, read and prepared in the order the batches need them, so that
    the first batch solves while the workers prepare the rest.

    The batches are planned from the BVH headers' frame counts (:meth:`plan`); :meth:`batches`
    prepares each planned batch's clips (in the host workers when there is a ``pool``; a clip no
    worker has started yet is prepared in this process rather than waited for) and yields its
    pairs, planned again from their prepared lengths (the same batch when the header was right).
    A clip or character that fails becomes ``error`` rows. ``seconds``: time spent preparing or
    waiting for clips.
    """

    def __init__(self, todo, checkpoint, solver, rows, result, suffix, rest_from, root_mode, pool, fps) -> None:
        self.checkpoint, self.rows, self.result, self.suffix, self.fps = checkpoint, rows, result, suffix, fps
        self.pool, self.cpu = pool, host.cpu_copy(checkpoint) if pool else checkpoint
        self.by_clip: dict[str, list] = {}
        for clip, path, c, digest in todo:
            self.by_clip.setdefault(clip, [path, [], digest])[1].append(c)
        self.args = {
            clip: (path, rest_from, [(c.name, c.skeleton) for c in chars if c.skeleton is not None], root_mode, solver)
            for clip, (path, chars, _) in self.by_clip.items()
        }
        self.tasks: dict[str, Future | None] = {}  # None: prepared here when taken (no pool)
        self.taken: set[str] = set()
        self.pairs: dict[tuple[str, str], Pair] = {}
        self.sources: dict[str, _Source] = {}
        self.seconds = 0.0

    def plan(self, max_frames: int, pad: bool) -> list[list[Pair]]:
        """The batches of every usable pair, their frames read from the headers (the planned pairs
        carry no source yet: ``source`` None); each clip's preparation is queued in the order the
        batches need it."""
        planned = [
            Pair(clip, name, None, skeleton, _header_frames(self.args[clip][0], self.checkpoint))
            for clip in self.by_clip
            for name, skeleton in self.args[clip][2]
        ]
        plan = plan_batches(planned, max_frames, pad)
        order = dict.fromkeys([p.clip for b in plan for p in b] + list(self.by_clip))
        for clip in order:
            self.tasks[clip] = self.pool.submit(prepare_clip, *self.args[clip]) if self.pool else None
        return plan

    def batches(self, plan: list[list[Pair]], max_frames: int, pad: bool) -> Iterator[list[Pair]]:
        """Each planned batch's prepared pairs, as batches; then the clips no batch holds."""
        for planned in plan:
            self._take(list(dict.fromkeys(p.clip for p in planned)))
            ready = [self.pairs[p.clip, p.character] for p in planned if (p.clip, p.character) in self.pairs]
            yield from plan_batches(ready, max_frames, pad)
        self._take(list(self.tasks))

    def _take(self, clips: list[str]) -> None:
        clock = time.perf_counter()
        clips = [c for c in clips if c not in self.taken]
        for clip in clips:  # first those no worker has started: prepared here rather than waited for
            task = self.tasks[clip]
            if task is None or task.cancel():
                self.tasks[clip] = task = Future()
                try:
                    task.set_result(prepare_clip(*self.args[clip], self.cpu))
                except _ERRORS as err:  # raised again by result(), as a worker's would be
                    task.set_exception(err)
        for clip in clips:
            self._record(clip, self.tasks[clip])
            self.taken.add(clip)
        self.seconds += time.perf_counter() - clock

    def _record(self, clip: str, task: Future) -> None:
        """The clip's pairs, or its error rows (``task``: :func:`prepare_clip`'s answer or error)."""
        path, chars, digest = self.by_clip[clip]
        try:
            motion, prepared, skating, jobs = task.result()
        except _ERRORS as err:
            for c in chars:
                self._error(clip, c, _why(err, "source", path))
            return
        self.sources[clip] = _Source(str(path), skating, motion.fps, digest, motion.num_frames)
        rates = (motion.fps, self.checkpoint.fps, self.fps or motion.fps)
        if max(rates) - min(rates) > 1e-4 * max(rates):
            self.result.resampled.append(
                f"{path}: resampled: source {rates[0]:g} fps -> network {rates[1]:g} fps -> output {rates[2]:g} fps"
            )
        for c in chars:
            job = jobs.get(c.name, c.error)
            if isinstance(job, str):
                self._error(clip, c, job)
            else:
                self.pairs[clip, c.name] = Pair(
                    clip, c.name, motion, c.skeleton, prepared.motion.num_frames, prepared, job
                )

    def _error(self, clip: str, c: Character, message: str) -> None:
        self.rows[(c.name, clip)] = _error_row(clip, c.name, str(self.by_clip[clip][0]), c.origin, message, self.suffix)
        self.result.failed += 1
