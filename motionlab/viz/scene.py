"""A pyvista scene of one or more animated skeletons, updated in place frame by frame.

Each character is drawn from two small point sets whose coordinates change every frame:

* **bones** -- segments parent → child (and joint → BVH end site) fed through a VTK tube filter;
* **joints** -- one sphere glyph per joint, coloured per joint (foot contacts light up, or a
  per-frame scalar such as the joint error is mapped through a colour map).

Changing a frame replaces the point coordinates of those sets and re-renders: no actor is
rebuilt, so a 22-joint character renders at tens of frames per second on a CPU. A ground grid at
y = 0, optional trails (the root's path on the ground, the feet's paths) and a camera that
either frames the whole clip or follows the characters complete the view.

All motions share one timeline at the first motion's frame rate; a motion with another rate is
sampled at the nearest frame, and a shorter one holds its last pose.

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motionlab.core import contacts as _contacts
from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.viz import backend

__all__ = [
    "PALETTE",
    "CONTACT_COLOR",
    "BACKGROUND",
    "foot_joints",
    "contact_labels",
    "world_pose",
    "SkeletonActor",
    "Scene",
    "build_scene",
]

PALETTE: tuple[str, ...] = ("#3b6fb6", "#e08a2c", "#3f9e59", "#8a63b8", "#8c6d4f", "#d45f9e", "#5aa9b5")
"""Character colours, in order (blue, orange, green, purple, brown, pink, teal)."""

CONTACT_COLOR = "#e0202a"
"""Colour of a foot joint while it touches the ground."""

BACKGROUND = "#f4f4f2"
"""Background colour of every scene (a flat colour, so tests can tell the character apart)."""

_JOINT_TINT = 0.55  # joints are the bone colour mixed this much towards dark grey
_CAMERA_DIRECTION = np.array([0.55, 0.42, 1.0])  # from the target towards the camera: front-left, above
_VIEW_ANGLE = 30.0  # degrees, VTK's default vertical field of view


# ---------------------------------------------------------------------------- helpers
def _rgb(color) -> np.ndarray:
    """Any matplotlib colour -> float RGB (3,) in [0, 1]."""
    from matplotlib.colors import to_rgb

    return np.asarray(to_rgb(color), dtype=np.float64)


MAX_CLEARANCE = 0.1
"""Body heights a foot joint may stand above its rest height in every frame of a clip and still
touch the ground (a rig's foot joints need not sit at its sole); higher, the clip is in the air."""


def foot_joints(skeleton: Skeleton) -> list[int]:
    """Indices of the foot and toe joints of any humanoid rig.

    Uses the rig mapping of :mod:`motionlab.core.humanoid` when the rig is recognised (feet and
    toe bases), otherwise every joint whose name contains ``foot``, ``toe`` or ``ankle``.
    """
    try:
        mapping = humanoid.find_mapping(skeleton)
    except humanoid.RigMappingError:
        names = [humanoid.strip_prefix(n).lower() for n in skeleton.names]
        return [j for j, n in enumerate(names) if any(k in n for k in ("foot", "toe", "ankle")) and "end" not in n]
    out = [mapping.source[humanoid.JOINTS.index(n)] for n in humanoid.FEET]
    return sorted({int(j) for j in out if j >= 0})


def contact_labels(
    skeleton: Skeleton, positions: np.ndarray, fps: float, feet: Sequence[int] | None = None
) -> np.ndarray:
    """Foot-contact labels (T, J): True where a foot joint is near the ground and nearly still.

    A foot joint counts as touching when its height is below its own standing height (rest pose,
    relative to the lowest joint, plus the joint's own clearance: the least it stands above that in
    the clip, as :func:`motionlab.core.contacts.detect_contacts` reads it, up to
    :data:`MAX_CLEARANCE` body heights; a joint higher in every frame never touches) plus 2 % of
    the body height, and it moves slower than 0.3 body heights per second
    (:func:`motionlab.core.contacts.low_and_slow`, the package's contact rule).

    Parameters
    ----------
    skeleton : the rig (its rest pose sets how high each foot joint sits when standing)
    positions : ndarray, shape (T, J, 3)   world joint positions, metres, ground at y = 0
    fps : frames per second
    feet : foot joint indices; default :func:`foot_joints`

    Raises
    ------
    ValueError when ``positions`` is not (T, J, 3) for the skeleton's J.
    """
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[1:] != (skeleton.num_joints, 3):
        raise ValueError(f"expected positions of shape (T, {skeleton.num_joints}, 3), got {positions.shape}")
    feet = foot_joints(skeleton) if feet is None else [int(j) for j in feet]
    labels = np.zeros(positions.shape[:2], dtype=bool)
    if not feet:
        return labels
    rest_y = skeleton.rest_positions()[:, 1]
    rest = rest_y[feet] - rest_y.min()
    height = max(skeleton.height(), 1e-6)
    clearance = np.nanmin(positions[:, feet, 1] - rest, axis=0)  # each joint's own (CMU's ankles and toes)
    clearance = np.where(clearance <= MAX_CLEARANCE * height, np.maximum(clearance, 0.0), -np.inf)  # in the air
    labels[:, feet] = _contacts.low_and_slow(positions[:, feet], rest + clearance, 0.02 * height, 0.3 * height, fps)
    return labels


def world_pose(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Joint and end-site positions of every frame.

    Returns
    -------
    joints : ndarray, shape (T, J, 3)   world joint positions, metres
    ends   : ndarray, shape (T, E, 3)   world positions of the skeleton's end sites (sorted by joint)
    """
    rot, pos = motion.fk()
    sites = sorted(motion.skeleton.end_sites)
    if not sites:
        return pos, np.zeros((motion.num_frames, 0, 3))
    offsets = np.stack([motion.skeleton.end_sites[j] for j in sites])
    ends = pos[:, sites] + quat.rotate(rot[:, sites], offsets)
    return pos, ends


def _nice_step(length: float) -> float:
    """A 1-2-5 grid step close to ``length``."""
    exponent = np.floor(np.log10(max(length, 1e-9)))
    base = length / 10**exponent
    mantissa = 1.0 if base < 1.5 else 2.0 if base < 3.5 else 5.0
    return float(mantissa * 10**exponent)


def _add_pipeline(plotter, algorithm, color=None, scalars: str | None = None, cmap=None, clim=None):
    """Add a VTK filter's output as an actor, with a plain mapper.

    pyvista's ``add_mesh`` would insert Python-side filters (normals, wrappers) that re-run on
    every frame; the tube and glyph filters already give normals, so we wire them directly.
    ``scalars="rgb"``: colours straight from a (N, 3) uint8 point array; another name: a scalar
    point array mapped through ``cmap`` over ``clim``.
    """
    pv = backend.import_pyvista()
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(algorithm.GetOutputPort())
    if scalars is None:
        mapper.ScalarVisibilityOff()
    else:
        mapper.ScalarVisibilityOn()
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray(scalars)
        if scalars == "rgb":
            mapper.SetColorModeToDirectScalars()
        else:
            lut = pv.LookupTable(cmap=cmap)
            lut.scalar_range = clim
            lut.nan_color = "#9a9a9a"  # joints without a counterpart
            mapper.SetLookupTable(lut)
            mapper.SetColorModeToMapScalars()
            mapper.SetScalarRange(*clim)
            mapper.UseLookupTableScalarRangeOff()
    actor = vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    if color is not None:
        prop.SetColor(*color)
    prop.SetInterpolationToGouraud()
    prop.SetSpecular(0.25)
    prop.SetSpecularPower(20.0)
    plotter.add_actor(actor, reset_camera=False)
    return actor


# ---------------------------------------------------------------------------- one character
class SkeletonActor:
    """One animated character inside a pyvista plotter.

    Parameters
    ----------
    plotter : pyvista.Plotter
    motion : Motion to draw
    color : bone colour (any matplotlib colour)
    offset : ndarray (3,), world translation added to the character, metres
    contacts : True (detect foot contacts), False, or a bool array (T, J) of given labels
    trails : which trails to draw: any of ``"root"`` (the root's path on the ground) and ``"feet"``
    joint_values : ndarray (T, J), optional
        A scalar per joint and frame (e.g. the error against a reference, metres); joints are
        then coloured by ``cmap`` over ``clim`` instead of by contact.
    cmap, clim : colour map name and (low, high) range for ``joint_values``
    label : legend text
    end_sites : draw bones out to the BVH end sites (head top, finger and toe tips); None: only
        on the 22-joint humanoid (full rigs' end sites include hair, hats and props)
    """

    def __init__(
        self,
        plotter,
        motion: Motion,
        color="#3b6fb6",
        offset=(0.0, 0.0, 0.0),
        contacts: bool | np.ndarray = True,
        trails: Sequence[str] = ("root",),
        joint_values: np.ndarray | None = None,
        cmap: str = "inferno_r",
        clim: tuple[float, float] | None = None,
        value_title: str = "error (m)",
        label: str | None = None,
        end_sites: bool | None = None,
    ) -> None:
        """Check the motion and the trails asked for.

        Raises
        ------
        ValueError for something other than a Motion, or an unknown trail.
        """
        if not isinstance(motion, Motion):
            raise ValueError(f"expected a Motion, got {type(motion).__name__}")
        unknown = set(trails) - {"root", "feet"}
        if unknown:
            raise ValueError(f"unknown trail(s) {sorted(unknown)}; expected 'root' and/or 'feet'")
        pv = backend.import_pyvista()
        self.plotter = plotter
        self.color = _rgb(color)
        self.offset = np.asarray(offset, dtype=np.float64).reshape(3)
        self.label = label or None
        self.trails = tuple(trails)
        self._value_mode = joint_values is not None
        self._cmap, self._clim, self._value_title = cmap, clim, value_title
        self._contacts_arg = contacts
        self._end_sites_arg = end_sites
        self._set_data(motion, joint_values)

        # bones: segments through joints + end sites, swept into tubes; joints: sphere glyphs
        self._bone_points = pv.PolyData()
        self._joint_points = pv.PolyData()
        self._build_geometry()
        self._build_filters()
        self._add_actors()
        self._add_trails()
        self.frame = -1
        self.set_frame(0)

    def _build_filters(self) -> None:
        """The VTK filters: tubes along the bone segments, sphere glyphs at the joints."""
        from vtkmodules.vtkCommonDataModel import vtkDataObject
        from vtkmodules.vtkFiltersCore import vtkGlyph3D, vtkTubeFilter
        from vtkmodules.vtkFiltersSources import vtkSphereSource

        self._tube = vtkTubeFilter()
        self._tube.SetInputData(self._bone_points)
        self._tube.SetRadius(0.011 * self.size)
        self._tube.SetNumberOfSides(10)
        self._tube.CappingOn()
        sphere = vtkSphereSource()
        sphere.SetRadius(1.0)
        sphere.SetThetaResolution(14)
        sphere.SetPhiResolution(10)
        self._glyph = vtkGlyph3D()
        self._glyph.SetInputData(self._joint_points)
        self._glyph.SetSourceConnection(sphere.GetOutputPort())
        self._glyph.OrientOff()
        self._glyph.SetScaleModeToScaleByVector()
        self._glyph.SetScaleFactor(1.0)
        self._glyph.SetColorModeToColorByScalar()
        points = vtkDataObject.FIELD_ASSOCIATION_POINTS
        self._glyph.SetInputArrayToProcess(0, 0, 0, points, "value" if self._value_mode else "rgb")
        self._glyph.SetInputArrayToProcess(1, 0, 0, points, "scale")

    def _add_actors(self) -> None:
        """Bone and joint actors in the plotter (and a colour bar when joints show values)."""
        plotter = self.plotter
        self.bone_actor = _add_pipeline(plotter, self._tube, color=self.color)
        if not self._value_mode:
            self.joint_actor = _add_pipeline(plotter, self._glyph, scalars="rgb")
            return
        low, high = self._value_range()
        self.joint_actor = _add_pipeline(plotter, self._glyph, scalars="value", cmap=self._cmap, clim=(low, high))
        plotter.add_scalar_bar(
            self._value_title,
            mapper=self.joint_actor.GetMapper(),
            n_labels=3,
            fmt="%.2f",
            vertical=True,
            color="#333333",
            position_x=0.86,
            position_y=0.08,
            width=0.07,
            height=0.45,
            title_font_size=12,
            label_font_size=11,
        )

    def _add_trails(self) -> None:
        """One line mesh per requested trail, in a light tint of the bone colour."""
        self._trail_meshes: dict[str, object] = {}
        tint = 0.45 * self.color + 0.55
        for kind in self.trails:
            if self._paths[kind].size == 0:  # e.g. feet trails on a rig without feet
                continue
            mesh = self._trail_polydata(self._paths[kind])
            self.plotter.add_mesh(mesh, color=tint, line_width=3, lighting=False, reset_camera=False)
            self._trail_meshes[kind] = mesh

    # -------------------------------------------------------------- data
    def _build_geometry(self) -> None:
        """(Re)build the bone segments and joint points for the current skeleton, in place."""
        pv = backend.import_pyvista()
        skeleton = self.motion.skeleton
        J, E = skeleton.num_joints, self.ends.shape[1]
        sites = sorted(skeleton.end_sites)
        sites = sites if E else []
        segments = [(int(skeleton.parents[j]), j) for j in range(1, J)] + [(j, J + e) for e, j in enumerate(sites)]
        bones = pv.PolyData(np.zeros((J + E, 3)))
        if segments:
            bones.lines = np.array([(2, a, b) for a, b in segments], dtype=np.int64).ravel()
        self._bone_points.copy_from(bones)
        # sphere radius per joint: smaller on short bones (fingers), never below a minimum
        radius = np.full(J, 0.021 * self.size)
        lengths = skeleton.bone_lengths()
        for j in range(1, J):
            if lengths[j] > 1e-9:
                for k in (j, int(skeleton.parents[j])):
                    radius[k] = min(radius[k], 0.45 * lengths[j])
        radius = np.maximum(radius, 0.006 * self.size)
        joints = pv.PolyData(np.zeros((J, 3)))
        joints.point_data["scale"] = np.column_stack([radius, np.zeros(J), np.zeros(J)])
        joints.point_data["rgb"] = np.zeros((J, 3), dtype=np.uint8)
        joints.point_data["value"] = np.zeros(J)
        self._joint_points.copy_from(joints)

    def _set_data(self, motion: Motion, joint_values) -> None:
        self.motion = motion
        joints, ends = world_pose(motion)
        draw_ends = humanoid.is_canonical(motion.skeleton) if self._end_sites_arg is None else self._end_sites_arg
        if not draw_ends:
            ends = ends[:, :0]
        self.joints = joints + self.offset
        self.ends = ends + self.offset
        self.size = max(motion.skeleton.height(), float(np.ptp(joints[0], axis=0).max()), 1e-3)
        if joint_values is not None:
            joint_values = np.asarray(joint_values, dtype=np.float64)
            if joint_values.shape != joints.shape[:2]:
                raise ValueError(f"expected joint_values of shape {joints.shape[:2]} (T, J), got {joint_values.shape}")
        self.joint_values = joint_values
        contacts = self._contacts_arg
        if isinstance(contacts, np.ndarray):
            if contacts.shape != joints.shape[:2]:
                raise ValueError(f"expected contacts of shape {joints.shape[:2]} (T, J), got {contacts.shape}")
            self.contacts = contacts.astype(bool)
        elif contacts:
            self.contacts = contact_labels(motion.skeleton, joints, motion.fps)
        else:
            self.contacts = np.zeros(joints.shape[:2], dtype=bool)
        self._paths = {kind: self._trail_paths(kind) for kind in self.trails}
        base = (1 - _JOINT_TINT) * self.color + _JOINT_TINT * 0.15
        rgb = np.where(self.contacts[..., None], _rgb(CONTACT_COLOR), base)
        self._rgb = np.round(rgb * 255).astype(np.uint8)  # (T, J, 3)

    def _value_range(self) -> tuple[float, float]:
        if self._clim is not None:
            return float(self._clim[0]), float(self._clim[1])
        finite = self.joint_values[np.isfinite(self.joint_values)]
        high = float(finite.max()) if finite.size else 1.0
        return 0.0, high if high > 0 else 1.0

    def _trail_paths(self, kind: str) -> np.ndarray:
        if kind == "root":
            path = self.joints[:, 0].copy()
            path[:, 1] = 0.002 * self.size  # on the ground, just above the grid
            return path[None]
        feet = foot_joints(self.motion.skeleton)
        return np.transpose(self.joints[:, feet], (1, 0, 2))

    @staticmethod
    def _trail_polydata(paths: np.ndarray):
        """Polylines through ``paths`` (P, T, 3)."""
        pv = backend.import_pyvista()
        P, T = paths.shape[:2]
        lines = np.concatenate([np.r_[T, np.arange(T) + p * T] for p in range(P)]) if T > 1 and P else None
        return pv.PolyData(paths.reshape(-1, 3).copy(), lines=lines)

    @property
    def num_frames(self) -> int:
        """Number of frames T of this character's motion."""
        return self.motion.num_frames

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner (3,) of everything this character reaches over the clip."""
        everything = np.concatenate([self.joints, self.ends], axis=1).reshape(-1, 3)
        return everything.min(axis=0), everything.max(axis=0)

    def set_motion(self, motion: Motion, joint_values: np.ndarray | None = None) -> None:
        """Show another motion (any skeleton, e.g. a retargeted character with new bone lengths)
        with the same colour, trails and actors.

        Raises
        ------
        ValueError for something other than a Motion, or ``joint_values`` given to a character
        built without them (or missing for one built with them).
        """
        if not isinstance(motion, Motion):
            raise ValueError(f"expected a Motion, got {type(motion).__name__}")
        if self._value_mode != (joint_values is not None):
            need = "needs" if self._value_mode else "takes no"
            raise ValueError(f"this character {need} joint_values (it was built that way)")
        self._set_data(motion, joint_values)
        self._build_geometry()
        self._tube.SetRadius(0.011 * self.size)
        for kind, mesh in self._trail_meshes.items():
            if self._paths[kind].size:
                mesh.copy_from(self._trail_polydata(self._paths[kind]))
        if self._value_mode:
            self.joint_actor.GetMapper().SetScalarRange(*self._value_range())
        self.frame = -1
        self.set_frame(0)

    # -------------------------------------------------------------- per frame
    def set_frame(self, t: int) -> None:
        """Move the character to frame ``t`` (clamped to the clip); does not render."""
        t = int(np.clip(t, 0, self.num_frames - 1))
        if t == self.frame:
            return
        self.frame = t
        self._bone_points.points = np.concatenate([self.joints[t], self.ends[t]], axis=0)
        self._joint_points.points = self.joints[t].copy()
        self._joint_points.point_data["rgb"] = self._rgb[t]
        if self._value_mode:
            self._joint_points.point_data["value"] = self.joint_values[t]
        for kind, mesh in self._trail_meshes.items():
            paths = self._paths[kind]  # (P, T, 3)
            shown = paths.copy()
            shown[:, t + 1 :] = paths[:, t : t + 1]  # the rest of the path collapses onto "now"
            mesh.points = shown.reshape(-1, 3)


def _scene_args(motions, camera, colors, offsets, labels, joint_values, window_size):
    """:class:`Scene`'s arguments checked: the per-motion ones as lists of K (defaults filled in), and
    ``(width, height)``; raises ``ValueError`` on a wrong count, camera or size."""
    motions = [motions] if isinstance(motions, Motion) else list(motions)
    if not motions or not all(isinstance(m, Motion) for m in motions):
        raise ValueError(f"expected a Motion or a non-empty sequence of Motions, got {motions!r:.80}")
    if camera not in ("frame", "follow"):
        raise ValueError(f"camera must be 'frame' or 'follow', got {camera!r}")
    K = len(motions)
    colors = list(colors) if colors is not None else [PALETTE[k % len(PALETTE)] for k in range(K)]
    offsets = np.zeros((K, 3)) if offsets is None else np.asarray(offsets, dtype=np.float64)
    labels = list(labels) if labels is not None else [m.name or None for m in motions]
    joint_values = list(joint_values) if joint_values is not None else [None] * K
    for what, seq in (("colors", colors), ("labels", labels), ("joint_values", joint_values)):
        if len(seq) != K:
            raise ValueError(f"expected {K} {what} (one per motion), got {len(seq)}")
    if offsets.shape != (K, 3):
        raise ValueError(f"expected offsets of shape ({K}, 3), got {offsets.shape}")
    width, height = (int(v) for v in window_size)
    if width < 16 or height < 16:
        raise ValueError(f"window_size must be at least 16 x 16 pixels, got {window_size}")
    return motions, colors, offsets, labels, joint_values, (width, height)


# ---------------------------------------------------------------------------- the scene
class Scene:
    """Several characters, a ground grid and a camera, on one timeline.

    Parameters
    ----------
    motions : a Motion or a sequence of Motions
    colors : one colour per motion (default :data:`PALETTE`)
    offsets : ndarray (K, 3) or None, world translation of each motion, metres
    labels : legend text per motion (default: the motions' names; no legend when all empty)
    camera : ``"frame"`` (fixed, sees the whole clip) or ``"follow"`` (moves with the characters)
    contacts : highlight foot contacts (True/False)
    trails : trails to draw per character: any of ``"root"``, ``"feet"``
    end_sites : draw bones to the BVH end sites (None: on the 22-joint humanoid only)
    ground : draw the ground grid at y = 0
    joint_values : list (one per motion) of (T, J) arrays or None; see :class:`SkeletonActor`
    clim : shared colour range for the joint values (default 0 .. the largest value)
    window_size : (width, height) in pixels
    off_screen : True/False, or None to decide from the environment
        (:func:`motionlab.viz.backend.resolve_off_screen`)
    show_time : print the frame number and time in a corner
    anti_aliasing : smooth edges with 4x multisampling; None: only when rendering on screen
        (off-screen rendering is usually software OpenGL, where it multiplies the render time)
    plotter : draw into this existing pyvista Plotter instead of a new one
    """

    def __init__(
        self,
        motions: Motion | Sequence[Motion],
        colors: Sequence | None = None,
        offsets: np.ndarray | None = None,
        labels: Sequence[str | None] | None = None,
        camera: str = "frame",
        contacts: bool = True,
        trails: Sequence[str] = ("root",),
        end_sites: bool | None = None,
        ground: bool = True,
        joint_values: Sequence[np.ndarray | None] | None = None,
        clim: tuple[float, float] | None = None,
        value_title: str = "error (m)",
        window_size: tuple[int, int] = (640, 480),
        off_screen: bool | None = None,
        show_time: bool = True,
        anti_aliasing: bool | None = None,
        plotter=None,
    ) -> None:
        motions, colors, offsets, labels, joint_values, (width, height) = _scene_args(
            motions, camera, colors, offsets, labels, joint_values, window_size
        )
        self._open_plotter(plotter, off_screen, (width, height), anti_aliasing)
        self.camera_mode = camera
        self.fps = motions[0].fps
        self.actors: list[SkeletonActor] = []
        for k, m in enumerate(motions):
            self.actors.append(
                SkeletonActor(
                    self.plotter,
                    m,
                    color=colors[k],
                    offset=offsets[k],
                    contacts=contacts,
                    trails=trails,
                    joint_values=joint_values[k],
                    clim=clim,
                    value_title=value_title,
                    label=labels[k],
                    end_sites=end_sites,
                )
            )
        self.num_frames = max(int(np.floor(a.motion.duration * self.fps + 1e-6)) + 1 for a in self.actors)
        self._ground_mesh = self._add_ground() if ground else None
        self._add_text_rows(height, show_time)
        self._setup_camera()
        self.frame = -1
        self.set_frame(0, render=False)

    def _open_plotter(self, plotter, off_screen, window_size: tuple[int, int], anti_aliasing) -> None:
        """Use ``plotter``, or open a new one (multisampling per ``anti_aliasing``); set the background."""
        pv = backend.import_pyvista()
        self.off_screen = backend.resolve_off_screen(off_screen)
        self.plotter = (
            plotter if plotter is not None else pv.Plotter(off_screen=self.off_screen, window_size=window_size)
        )
        self.plotter.set_background(BACKGROUND)
        if plotter is None:
            smooth = (not self.off_screen) if anti_aliasing is None else bool(anti_aliasing)
            self.plotter.ren_win.SetMultiSamples(4 if smooth else 0)

    def _add_text_rows(self, height: int, show_time: bool) -> None:
        """Frame/time on top, then one coloured legend line per labelled character."""
        font = max(6, round(height / 44))
        line = 2.0 * font / height  # viewport units
        rows = [("", "#444444")] if show_time else []
        rows += [(f"\u2014 {a.label}", tuple(a.color)) for a in self.actors if a.label]
        texts = []
        for row, (text, color) in enumerate(rows):
            actor = self.plotter.add_text(
                text, position=(0.012, 0.99 - row * line), viewport=True, font_size=font, color=color
            )
            actor.GetTextProperty().SetVerticalJustificationToTop()
            texts.append(actor)
        # a plain text actor: pyvista's corner annotation re-fits its font every frame (slow)
        self._time_text = texts[0] if show_time else None

    # -------------------------------------------------------------- geometry of the whole clip
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest corner (3,) of everything any character reaches, ground included."""
        lows, highs = zip(*(a.bounds() for a in self.actors), strict=True)
        low, high = np.min(lows, axis=0), np.max(highs, axis=0)
        low[1] = min(low[1], 0.0)
        return low, high

    @property
    def size(self) -> float:
        """The tallest character's rest height, metres (sets tube radii, grid step, margins)."""
        return max(a.size for a in self.actors)

    def _add_ground(self):
        pv = backend.import_pyvista()
        low, high = self.bounds()
        step = _nice_step(self.size / 3.5)
        margin = 0.6 * self.size
        x0, x1 = np.floor((low[0] - margin) / step) * step, np.ceil((high[0] + margin) / step) * step
        z0, z1 = np.floor((low[2] - margin) / step) * step, np.ceil((high[2] + margin) / step) * step
        nx, nz = max(int(round((x1 - x0) / step)), 1), max(int(round((z1 - z0) / step)), 1)
        y = -0.001 * self.size  # just below the grid lines and trails
        corners = np.array([[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]])
        plane = pv.PolyData(corners, faces=[4, 0, 1, 2, 3])
        self.plotter.add_mesh(plane, color="#dcdcd4", lighting=False, reset_camera=False, name="ground")
        xs, zs = x0 + step * np.arange(nx + 1), z0 + step * np.arange(nz + 1)
        pts = np.concatenate(
            [np.stack([[x, 0.0, z0], [x, 0.0, z1]]) for x in xs] + [np.stack([[x0, 0.0, z], [x1, 0.0, z]]) for z in zs]
        )
        cells = np.column_stack(
            [np.full(len(pts) // 2, 2), np.arange(0, len(pts), 2), np.arange(1, len(pts), 2)]
        ).ravel()
        grid = pv.PolyData(pts, lines=cells)
        self.plotter.add_mesh(grid, color="#b4b4ac", line_width=1, lighting=False, reset_camera=False, name="grid")
        return plane

    def _frames_of(self, t: int) -> list[int]:
        """The frame of each character shown at scene frame ``t`` (same time, nearest frame)."""
        seconds = t / self.fps
        return [min(int(round(seconds * a.motion.fps)), a.num_frames - 1) for a in self.actors]

    def _setup_camera(self) -> None:
        direction = _CAMERA_DIRECTION / np.linalg.norm(_CAMERA_DIRECTION)
        right = np.cross(np.array([0.0, 1.0, 0.0]), direction)
        right /= np.linalg.norm(right)
        up = np.cross(direction, right)
        width, height = self.plotter.window_size
        tan_v = np.tan(np.radians(_VIEW_ANGLE / 2))
        tan_h = tan_v * width / height
        bar = any(a._value_mode for a in self.actors)  # keep the right 18 % free for the colour bar
        if bar:
            tan_h *= 0.82
        pts = np.stack(
            [
                np.concatenate(
                    [
                        np.concatenate([a.joints[f], a.ends[f]])
                        for a, f in zip(self.actors, self._frames_of(t), strict=True)
                    ]
                )
                for t in range(self.num_frames)
            ]
        )  # (T, N, 3): everything drawn at each frame
        if self.camera_mode == "frame":
            flat = pts.reshape(-1, 3)
            center = (flat.min(axis=0) + flat.max(axis=0)) / 2
            self._centers = np.broadcast_to(center, (self.num_frames, 3))
        else:
            center = (pts.min(axis=1) + pts.max(axis=1)) / 2
            k = max(int(round(0.5 * self.fps)), 1)  # smooth over half a second: no jitter
            kernel = np.ones(k) / k
            padded = np.pad(center, ((k // 2, k - 1 - k // 2), (0, 0)), mode="edge")
            center = np.stack([np.convolve(padded[:, i], kernel, mode="valid") for i in range(3)], axis=1)
            center[:, 1] = (min(0.0, pts[..., 1].min()) + pts[..., 1].max()) / 2
            self._centers = center
        # the nearest camera distance along `direction` that keeps every point in view
        rel = pts - np.asarray(self._centers)[:, None]
        along = rel @ direction
        need = along + np.maximum(np.abs(rel @ right) / tan_h, np.abs(rel @ up) / tan_v)
        distance = 1.1 * float(need.max()) + 0.05 * self.size
        self._camera_offset = direction * distance
        cam = self.plotter.camera
        cam.view_angle = _VIEW_ANGLE
        cam.SetWindowCenter(0.18 if bar else 0.0, 0.0)  # shifts the picture left, geometry unchanged
        span = float(np.abs(rel).max()) + 10 * self.size
        cam.clipping_range = (max(distance - span, 1e-3 * distance), distance + span)
        self._place_camera(0)

    def _place_camera(self, t: int) -> None:
        center = self._centers[min(t, len(self._centers) - 1)]
        cam = self.plotter.camera  # raw VTK setters: pyvista's would reset the clipping range each time
        cam.SetFocalPoint(*center)
        cam.SetPosition(*(center + self._camera_offset))
        cam.SetViewUp(0.0, 1.0, 0.0)

    # -------------------------------------------------------------- playback
    def set_frame(self, t: int, render: bool = True) -> None:
        """Show scene frame ``t`` (0 ≤ t < :attr:`num_frames`), moving the camera when following.

        Raises
        ------
        ValueError when ``t`` is outside 0 … num_frames - 1.
        """
        t = int(t)
        if not 0 <= t < self.num_frames:
            raise ValueError(f"frame {t} out of range: this scene has frames 0..{self.num_frames - 1}")
        for actor, f in zip(self.actors, self._frames_of(t), strict=True):
            actor.set_frame(f)
        if self.camera_mode == "follow":
            self._place_camera(t)
        if self._time_text is not None:
            self._time_text.SetInput(f"frame {t}/{self.num_frames - 1}   {t / self.fps:.2f} s")
        self.frame = t
        if render:
            self.plotter.render()

    def set_motion(self, index: int, motion: Motion, joint_values: np.ndarray | None = None) -> None:
        """Replace character ``index``'s motion (any skeleton), re-fit camera and ground, keep the frame."""
        self.actors[index].set_motion(motion, joint_values)
        if self._ground_mesh is not None:
            self._ground_mesh = self._add_ground()  # named actors: replaced, not added
        self.num_frames = max(int(np.floor(a.motion.duration * self.fps + 1e-6)) + 1 for a in self.actors)
        self._setup_camera()
        frame, self.frame = self.frame, -1
        self.set_frame(min(max(frame, 0), self.num_frames - 1))

    def screenshot(self, t: int | None = None) -> np.ndarray:
        """The rendered image (H, W, 3) uint8 of frame ``t`` (default: the current frame)."""
        if t is not None:
            self.set_frame(t, render=False)
        self.plotter.render()
        return np.asarray(self.plotter.screenshot(return_img=True))[..., :3].copy()

    def frames(self, frames: Sequence[int] | None = None):
        """Yield the rendered image (H, W, 3) of each frame in ``frames`` (default: all)."""
        for t in range(self.num_frames) if frames is None else frames:
            yield self.screenshot(int(t))

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (N, 2) as (column, row from the top) of world points (N, 3) in the
        current camera view; used by tests to look at where a joint is drawn."""
        from vtkmodules.vtkRenderingCore import vtkCoordinate

        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        coord = vtkCoordinate()
        coord.SetCoordinateSystemToWorld()
        renderer = self.plotter.renderer
        height = self.plotter.window_size[1]
        out = np.empty((len(points), 2))
        for i, p in enumerate(points):
            coord.SetValue(*p)
            x, y = coord.GetComputedDoubleDisplayValue(renderer)
            out[i] = (x, height - 1 - y)
        return out

    def show(self, **kwargs):
        """Open the interactive window (on-screen plotters), passing ``kwargs`` to pyvista's show."""
        return self.plotter.show(**kwargs)

    def close(self) -> None:
        """Release the render window."""
        self.plotter.close()

    def __enter__(self) -> Scene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return (
            f"Scene({len(self.actors)} character(s), {self.num_frames} frames @ {self.fps:g} fps, "
            f"camera={self.camera_mode!r}, off_screen={self.off_screen})"
        )


def build_scene(motions: Motion | Sequence[Motion] | Scene, **kwargs) -> Scene:
    """A :class:`Scene` of ``motions`` (a Scene passes through unchanged, ``kwargs`` must be empty).

    Raises
    ------
    ValueError for an existing Scene given with scene options.
    """
    if isinstance(motions, Scene):
        if kwargs:
            raise ValueError(f"got an existing Scene and scene options {sorted(kwargs)}; pass one or the other")
        return motions
    return Scene(motions, **kwargs)
