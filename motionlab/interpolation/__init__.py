"""System C: key-pose-constrained interpolation and gap filling (algorithms.md §C).

Modules, one concept each:

* :mod:`.slerp`        α(k) curves, SLERP paths, Euler interpolation for contrast
* :mod:`.inbetween`    batched in-betweening (SLERP / Hermite rotations, linear / Hermite root)
* :mod:`.alignment`    root alignment, eq. 3 (yaw about +Y and a floor translation)
* :mod:`.ppca`         probabilistic PCA (closed form and EM) and plain PCA
* :mod:`.features`     pose features and the inter-frame distance
* :mod:`.keyposes`     segmentation into action nodes and key-frame extraction
* :mod:`.action_graph` the finite-state action graph, best transition frames, paths
* :mod:`.library`      key-pose-guided in-betweening from recorded clips
* :mod:`.gaps`         missing-frame detection and filling
* :mod:`.benchmark`    LaFAN1-style benchmark (L2Q, L2P, NPSS)
* :mod:`.plots`        figures (matplotlib imported lazily)

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from motionlab.interpolation import alignment, features, gaps, inbetween, keyposes, ppca, slerp
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
    "ActionGraph",
    "MotionLibrary",
    "PCA",
    "PPCA",
]
