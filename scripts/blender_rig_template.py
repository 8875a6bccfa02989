# Exports the rig of one bird of a .glb written by `formation` as a template for your own bird
# (Blender headless): the armature `bird_000` (bones body, neck, tail, upper_arm.L, hand.L,
# upper_arm.R, hand.R, leg.L, leg.R, bound with Blender's own bone orientations) and its skinned mesh, at the
# origin, unanimated. Model your bird on it, keep the bone names, export as .glb and give it to
# `--bird-model`. Also a check that a Blender-made rig works: `formation render ... --bird-model`
# on this file gives the same birds as the built-in one.
# Usage: blender -b --python scripts/blender_rig_template.py -- flock.glb rig_template.glb
import sys; sys.path.insert(0, "/usr/lib/python3/dist-packages"); [sys.modules.pop(m) for m in list(sys.modules) if m.startswith("numpy")]
import numpy; numpy.bool = bool
import bpy

src, out = sys.argv[-2], sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=src)
keep = bpy.data.objects["bird_000"]
for o in list(bpy.data.objects):
    if o != keep and o.parent != keep:
        bpy.data.objects.remove(o)
keep.animation_data_clear()
keep.location = (0, 0, 0)
keep.rotation_mode = "QUATERNION"
keep.rotation_quaternion = (1, 0, 0, 0)
for a in list(bpy.data.actions):
    bpy.data.actions.remove(a)
bpy.ops.export_scene.gltf(filepath=out, export_format='GLB', export_animations=False)
print("EXPORTED", out, [b.name for b in keep.data.bones])
