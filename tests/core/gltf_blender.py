"""World joint positions of a .glb as Blender imports it, for tests/core/test_gltf.py.

Run by Blender, not by pytest::

    blender -b --factory-startup --python gltf_blender.py -- FILE.glb FPS OUT.json FRAME ...

Sets the scene's frame rate to FPS, imports the file with Blender's own glTF importer, and writes
JSON ``{"blender", "names", "positions"}``: each pose bone's head in world space (Blender's Z-up
axes), per requested frame counted from the action's first frame.
"""

import json
import sys

import bpy
import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Debian 12's Blender 3.4 importer still uses np.bool, gone since numpy 1.24

args = sys.argv[sys.argv.index("--") + 1 :]
path, fps, out, frames = args[0], float(args[1]), args[2], [int(f) for f in args[3:]]
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene = bpy.context.scene
scene.render.fps = round(fps)
scene.render.fps_base = round(fps) / fps
bpy.ops.import_scene.gltf(filepath=path)
armature = next(o for o in bpy.data.objects if o.type == "ARMATURE")
first = int(armature.animation_data.action.frame_range[0])
positions = []
for k in frames:
    scene.frame_set(first + k)
    positions.append([list(armature.matrix_world @ bone.head) for bone in armature.pose.bones])
names = [bone.name for bone in armature.pose.bones]
with open(out, "w") as f:
    json.dump({"blender": bpy.app.version_string, "names": names, "positions": positions}, f)
