"""3D playback and widgets: pyvista scenes, a Jupyter player, side-by-side comparison, movie
export and bone-proportion sliders.

pyvista, VTK, ipywidgets and Pillow are imported only inside the functions that need them, so
``import motionlab.viz`` stays light. Headless machines render off-screen through EGL or OSMesa
(see :mod:`motionlab.viz.backend`).

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from motionlab.viz import backend, compare, export, player, proportions, scene
from motionlab.viz.compare import joint_errors, side_by_side
from motionlab.viz.export import filmstrip, save_gif, save_movie, save_mp4, snapshot
from motionlab.viz.player import Player, play, still
from motionlab.viz.proportions import ProportionEditor, copy_rotation_solver
from motionlab.viz.scene import Scene, build_scene, contact_labels, foot_joints

__all__ = [
    "backend",
    "compare",
    "export",
    "player",
    "proportions",
    "scene",
    "Scene",
    "build_scene",
    "contact_labels",
    "foot_joints",
    "Player",
    "play",
    "still",
    "side_by_side",
    "joint_errors",
    "save_gif",
    "save_mp4",
    "save_movie",
    "snapshot",
    "filmstrip",
    "ProportionEditor",
    "copy_rotation_solver",
]
