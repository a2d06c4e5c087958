"""System A: retargeting by latent-space iteration (Wang, Li, Xie and Jia 2023).

Train a network on ONE character's motion, then generate the motion of a character with other
proportions by optimising the network's latent code (weights frozen) so that joint directions
match the source and the feet stay above the ground.

* :mod:`.model` — F_enc, F_qlinear, F_skel, F_Δ, Hamilton correction and FK;
* :mod:`.losses` — L_recon, L_angle, L_foot, L_contact, L_floor, L_clear; :mod:`.terms` — the latent
  iteration's loss terms as named objects (the registry a new term joins);
* :mod:`.devices` — the default torch device and its checks;
* :mod:`.train` — training on one character; :mod:`.checkpoint` — save / load;
  :mod:`.real` — the network trained on real motion, trained on first use and cached;
* :mod:`.solver` — the latent iteration; :mod:`.baselines` — copy-rotation;
* :mod:`.pipeline` — a Motion onto a target skeleton, end to end;
* :mod:`.evaluate` — Table 1 on real data; :mod:`.cli` — ``motionlab retarget/train/evaluate``.
* :mod:`.expand` — many clips onto many characters, batched and resumable (``motionlab expand``).

``load_default()`` returns the small network shipped in ``motionlab/assets`` (trained by this
package on its own synthetic data), so retargeting works without training first. Re-create it
with::

    motionlab train --synthetic 300 --seed 0 -o motionlab/assets/retarget_default.pt --force

``load_real()`` returns the network trained on real motion (Aj's Mixamo clips but Table 1's 10,
the network ``motionlab evaluate`` uses), trained from ``MOTIONLAB_DATA`` on first use and cached
(:mod:`.real`: the data's licences do not allow shipping it). Paper A trains on the source
character's own motion, so :func:`retarget` without a checkpoint uses it for a recorded source
when the course data is there, and the shipped network for motionlab's synthetic rig or without
the data (:func:`.real.for_source`).

Taught in ``notebooks/02_training_autoencoder.ipynb`` and ``03_latent_iteration.ipynb``.
"""

from __future__ import annotations

from pathlib import Path

from motionlab.retargeting.baselines import copy_rotation
from motionlab.retargeting.checkpoint import Checkpoint, CheckpointError, load, save
from motionlab.retargeting.model import ModelConfig, RetargetNet
from motionlab.retargeting.pipeline import RetargetResult, retarget
from motionlab.retargeting.real import load_real
from motionlab.retargeting.solver import SolverConfig, SolverResult, solve
from motionlab.retargeting.train import TrainConfig, train, training_set

__all__ = [
    "DEFAULT_CHECKPOINT",
    "load_default",
    "load_real",
    "Checkpoint",
    "CheckpointError",
    "load",
    "save",
    "ModelConfig",
    "RetargetNet",
    "TrainConfig",
    "train",
    "training_set",
    "SolverConfig",
    "SolverResult",
    "solve",
    "RetargetResult",
    "retarget",
    "copy_rotation",
]

DEFAULT_CHECKPOINT = Path(__file__).resolve().parent.parent / "assets" / "retarget_default.pt"
"""The shipped checkpoint (trained on ``motionlab.synthetic`` data; see the module docstring)."""


def load_default(device=None, dtype: str = "float64") -> Checkpoint:
    """The shipped pretrained network on ``device`` (default: CUDA when available, else CPU),
    computing in ``dtype`` (:func:`checkpoint.load`).

    Raises
    ------
    FileNotFoundError when the shipped checkpoint is missing; ValueError for a device that is not there.
    """
    if not DEFAULT_CHECKPOINT.is_file():
        raise FileNotFoundError(
            f"the default retargeting checkpoint {DEFAULT_CHECKPOINT} is missing; re-create it with "
            "`motionlab train --synthetic 300 --seed 0 -o motionlab/assets/retarget_default.pt --force`"
        )
    return load(DEFAULT_CHECKPOINT, device, dtype)
