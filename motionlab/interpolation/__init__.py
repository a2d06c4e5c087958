"""System C: key-pose-constrained interpolation and gap filling (Yang, Su, Yan, Li and Liu 2019, key-pose-constrained interpolation of human motion sequences).

Modules, one concept each:

* :mod:`.slerp`        α(k) curves, SLERP paths, Euler interpolation for contrast
* :mod:`.inbetween`    batched in-betweening (SLERP / Hermite rotations, linear / Hermite root)
* :mod:`.alignment`    root alignment, eq. 3 (yaw about +Y and a floor translation)
* :mod:`.ppca`         probabilistic PCA (closed form and EM) and plain PCA
* :mod:`.features`     pose features and the inter-frame distance
* :mod:`.keyposes`     segmentation into action nodes and key-frame extraction
* :mod:`.action_graph` the finite-state action graph, best transition frames, paths
* :mod:`.library`      key-pose-guided in-betweening from recorded clips
* :mod:`.labels`       does a clip show what its action label says (hip height, speed, flight)
* :mod:`.detect`       dropped-frame detection (stream vs graph, stream vs itself) and counts
* :mod:`.recorded`     missing counts read off other recordings of the action
* :mod:`.gaps`         inserting and filling missing frames
* :mod:`.stride`       gaps in a gait filled from the recorded strides on both sides
* :mod:`.plots`        figures (matplotlib imported lazily)
* :mod:`.demo`         the clips notebook 06 uses (real mocap or synthetic) and the paper's Fig. 8 set-up

Taught in ``notebooks/06_keypose_interpolation.ipynb``. The studies that measure it (gap
evaluation, the paper's experiments, a LaFAN1-style benchmark) are in ``experiments/interpolation/``.
"""

from motionlab.interpolation import (
    alignment,
    detect,
    features,
    gaps,
    inbetween,
    keyposes,
    labels,
    ppca,
    recorded,
    slerp,
    stride,
)
from motionlab.interpolation.action_graph import ActionGraph
from motionlab.interpolation.library import MotionLibrary
from motionlab.interpolation.ppca import PCA, PPCA

__all__ = [
    "slerp",
    "inbetween",
    "alignment",
    "ppca",
    "features",
    "keyposes",
    "gaps",
    "stride",
    "detect",
    "recorded",
    "labels",
    "ActionGraph",
    "MotionLibrary",
    "PCA",
    "PPCA",
]
