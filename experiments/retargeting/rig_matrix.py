"""Every ordered pair of rig families: one clip per family retargeted onto every other family.

The families are those of the shared data (``$MOTIONLAB_DATA/README.md``) and motionlab's
synthetic character; :data:`FAMILY_CLIPS` names the one clip of each. :func:`pair_matrix`
retargets every clip onto every other family's rig (the rig of that family's clip) and returns
the plausibility measures (:mod:`motionlab.retargeting.plausibility`) and skating per pair.
``experiments/retargeting/rigs.py`` prints the table; ``tests/experiments/test_rig_matrix.py`` requires
every pair to be plausible.
"""

from __future__ import annotations

from pathlib import Path

from motionlab.core import bvh, humanoid
from motionlab.core.motion import Motion

__all__ = ["FAMILY_CLIPS", "family_clips", "pair_matrix", "table"]

FAMILY_CLIPS: dict[str, str] = {
    "mixamo": "mixamo/Aj/Catwalk_Idle_To_Walk_Forward.bvh",
    "bandai": "bandai_namco/dataset-1/walk/dataset-1_walk_normal_001.bvh",
    "cmu": "cmu/131/131_01.bvh",
    "xia": "xia/walk/neutral_01_000.bvh",
}
"""One walking clip per real rig family, relative to the data folder."""


def family_clips(root: str | Path | None, seconds: float = 3.0) -> dict[str, Motion]:
    """The first ``seconds`` of each family's clip, plus a synthetic walk (``"synthetic"``).

    ``root`` is the data folder; ``None`` gives the synthetic character only. Raises
    ``FileNotFoundError`` naming a missing clip.
    """
    from motionlab import synthetic

    out: dict[str, Motion] = {}
    if root is not None:
        for family, rel in FAMILY_CLIPS.items():
            path = Path(root) / rel
            if not path.is_file():
                raise FileNotFoundError(f"{path} not found (the {family} clip of the rig matrix)")
            m = bvh.load(path)
            n = min(m.num_frames, max(2, int(round(seconds * m.fps))))
            out[family] = m.copy(
                local_rot=m.local_rot[:n],
                root_pos=m.root_pos[:n],
                local_pos=None if m.local_pos is None else m.local_pos[:n],
            )
    frames = int(seconds * 60)
    out["synthetic"] = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=frames, fps=60, seed=0)
    out["synthetic"].name = "synthetic_walk"
    return out


def pair_matrix(clips: dict[str, Motion], checkpoint, solver=None, pairs=None) -> list[dict]:
    """Retarget each clip onto each other family's rig (``pairs``: the ``(source, target)`` to run).

    Returns one dict per pair: ``source``, ``target``, ``ok``, ``failed``, ``root_scale_y`` (the
    vertical root scale B / A, standing hip heights), ``hip_ratio`` (B's median hip height / B's
    standing hip height), ``source_hip_ratio``, ``foot_cm`` (median height of planted feet above
    contact height, cm), ``foot_leg`` (the same / B's leg length), ``source_foot_leg`` (A's, / A's
    leg length), ``lowest_leg``, ``skating_cm_s`` (B's planted-foot slide on A's contact frames at
    the network's rate, :attr:`plausibility.Plausibility.slide`, × 100), ``source_skating_cm_s``
    (A's own), ``skating`` (the plausibility check's skating flag), ``fps`` (output) and ``source_fps``.
    """
    from motionlab.retargeting.pipeline import retarget

    rows = []
    names = list(clips)
    for a in names:
        for b in names:
            if a == b or (pairs is not None and (a, b) not in pairs):
                continue
            res = retarget(clips[a], clips[b], checkpoint, solver=solver)
            p = res.plausibility
            leg = humanoid.leg_length(res.motion.skeleton)
            rows.append(
                {
                    "source": a,
                    "target": b,
                    "ok": p.ok,
                    "failed": "+".join(p.failed),
                    "skating": p.skating,
                    "root_scale_y": res.root_scale[1],
                    "hip_ratio": p.hip_ratio,
                    "source_hip_ratio": p.source_hip_ratio,
                    "foot_leg": p.foot_height,
                    "source_foot_leg": p.source_foot_height,
                    "foot_cm": 100 * p.foot_height * leg,
                    "lowest_leg": p.lowest,
                    "skating_cm_s": 100 * p.slide,
                    "source_skating_cm_s": 100 * p.source_slide,
                    "fps": res.motion.fps,
                    "source_fps": clips[a].fps,
                }
            )
    return rows


def table(rows: list[dict]) -> str:
    """The rows of :func:`pair_matrix` as a fixed-width text table."""
    head = (
        f"{'source':<10} {'target':<10} {'r_y':>6} {'hip ratio':>9} {'(source)':>8} {'foot cm':>8} {'foot/leg':>8} {'(source)':>8} "
        f"{'skate cm/s':>10} {'(source)':>8} {'fps':>5}  verdict"
    )
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r['source']:<10} {r['target']:<10} {r['root_scale_y']:>6.3f} {r['hip_ratio']:>9.2f} {r['source_hip_ratio']:>8.2f} "
            f"{r['foot_cm']:>8.1f} {r['foot_leg']:>+8.3f} {r['source_foot_leg']:>+8.3f} {r['skating_cm_s']:>10.1f} {r['source_skating_cm_s']:>8.1f} "
            f"{r['fps']:>5.0f}  {'ok' if r['ok'] else 'IMPLAUSIBLE ' + r['failed']}{', skating' if r['skating'] else ''}"
        )
    return "\n".join(lines)
