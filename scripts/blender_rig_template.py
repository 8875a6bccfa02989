# Exports the rig of one bird of a .glb written by `formation` as a template for your own bird
# (Blender headless): the armature `bird_000` (bones body, neck, tail, upper_arm.L, hand.L,
# upper_arm.R, hand.R, leg.L, leg.R, bound with Blender's own bone orientations) and its skinned mesh, at the
# origin, unanimated. Model your bird on it, keep the bone names, export as .glb and give it to
# `--bird-model`. Also a check that a Blender-made rig works: `formation render ... --bird-model`
# on this file gives the same birds as the built-in one.
# Usage: blender -b --python scripts/blender_rig_template.py -- flock.glb rig_template.glb
# Blender's glTF add-on needs numpy (Debian's Blender: `apt install python3-numpy`); Debian's
# Blender 3.4 add-on also uses `numpy.bool`, which numpy 1.24-1.26 lack (numpy 2 has it again):
# the alias is restored when missing, with whatever numpy Blender's Python imports (numpy 1 or 2;
# no path changes and no second import, which numpy 2 refuses).
import sys
try:
    import numpy
except ImportError:
    print("FAILED Blender's glTF add-on needs numpy, which this Blender's Python cannot import"
          " (Debian/Ubuntu: apt install python3-numpy; another Blender: its bundled Python's"
          " `python -m pip install numpy`)", file=sys.stderr)
    print("FAILED numpy missing")
    sys.exit(1)
import warnings
with warnings.catch_warnings():  # numpy 1.24-1.26 warn on the attribute's lookup
    warnings.simplefilter("ignore")
    if not hasattr(numpy, "bool"):
        numpy.bool = numpy.bool_
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
