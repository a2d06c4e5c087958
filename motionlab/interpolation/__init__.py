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
* :mod:`.gap_eval`     measuring detection and filling on clips with frames removed
* :mod:`.paper`        the paper's experiments (§4: Fig. 6/7 walk, Fig. 8 run → squat)
* :mod:`.benchmark`    LaFAN1-style benchmark (L2Q, L2P, NPSS)
* :mod:`.plots`        figures (matplotlib imported lazily)

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from motionlab.interpolation import (
    alignment,
    detect,
    features,
    gap_eval,
    gaps,
    inbetween,
    keyposes,
    labels,
    paper,
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
    "gap_eval",
    "paper",
    "ActionGraph",
    "MotionLibrary",
    "PCA",
    "PPCA",
]
