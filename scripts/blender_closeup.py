# Renders a close-up of the first birds of a .glb written by `formation` (Blender headless, Cycles
# on the CPU), for docs/export.md: the skinned bird, its wings mid-beat, as a studio would see it.
# Usage: blender -b --python scripts/blender_closeup.py -- flock.glb out.png [FRAME] [FPS] [CLIP]
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
import bpy, mathutils

args = sys.argv[sys.argv.index("--") + 1:]
path, out = args[0], args[1]
frame = int(args[2]) if len(args) > 2 else 40
fps = int(args[3]) if len(args) > 3 else 30
clip = args[4] if len(args) > 4 else "steady"
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.fps = fps
bpy.ops.import_scene.gltf(filepath=path)
arms = sorted((o for o in bpy.data.objects if o.type == 'ARMATURE'), key=lambda o: o.name)
for a in arms:
    act = bpy.data.actions.get("%s_%s" % (clip, a.name))
    if a.animation_data and act:
        for t in a.animation_data.nla_tracks:
            t.mute = True
        a.animation_data.action = act
sc.frame_set(frame - 1); p0 = [a.matrix_world.translation.copy() for a in arms]
sc.frame_set(frame + 1); p1 = [a.matrix_world.translation.copy() for a in arms]
sc.frame_set(frame)
fwd = sum((b - a for a, b in zip(p0, p1)), mathutils.Vector()); fwd.z = 0
fwd = fwd.normalized() if fwd.length > 1e-6 else mathutils.Vector((0, 1, 0))
# The subject is the bird furthest ahead, so that the rest of the flock is behind it.
lead = max(arms, key=lambda a: a.matrix_world.translation.dot(fwd))
p = lead.matrix_world.translation.copy()
right = fwd.cross(mathutils.Vector((0, 0, 1)))
span = max(a.dimensions.x for a in bpy.data.objects if a.type == 'MESH') or 1.5
cam_pos = p + fwd * 1.5 * span + right * 0.9 * span + mathutils.Vector((0, 0, 0.35 * span))
cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
sc.collection.objects.link(cam)
cam.location = cam_pos
cam.rotation_euler = (p - cam_pos).to_track_quat('-Z', 'Y').to_euler()
cam.data.lens = 40
sc.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN'))
sun.data.energy = 2.5
sun.rotation_euler = (0.7, 0.2, 0.8)
sc.collection.objects.link(sun)
world = bpy.data.worlds.new("sky"); sc.world = world
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.45, 0.62, 0.85, 1.0)
world.node_tree.nodes["Background"].inputs[1].default_value = 0.9
sc.render.engine = 'CYCLES'
sc.cycles.samples = 24
sc.cycles.use_denoising = False
sc.cycles.device = 'CPU'
sc.render.resolution_x, sc.render.resolution_y = 960, 540
sc.render.filepath = out
bpy.ops.render.render(write_still=True)
print("RENDERED", out)
