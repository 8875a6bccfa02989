# Imports a .glb written by `formation` into Blender (headless) and checks, on the evaluated
# (skinned) meshes, that no vertex of any bird is below the ground (z = 0) at 20 frames spread
# over the whole timeline and 12 in each stage: sitting, the take-off run, the flight and, with
# --land, the landing.
# Prints the lowest vertex per frame; exits 1 (with --python-exit-code 1) when one is below
# -TOL metres.
# Usage: blender -b --factory-startup --python-exit-code 1 --python scripts/blender_ground_check.py -- flock.glb
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
import json
import struct

import bpy

TOL = 0.001
path = sys.argv[sys.argv.index("--") + 1]
with open(path, "rb") as fh:
    head = fh.read(20)
    doc = json.loads(fh.read(struct.unpack("<I", head[12:16])[0]))
extras = doc["scenes"][0].get("extras", {})
fps = int(round(extras.get("fps", 30)))
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.fps = fps
bpy.ops.import_scene.gltf(filepath=path)
meshes = [o for o in bpy.data.objects if o.type == 'MESH']
# The file's own frame range (the importer leaves Blender's default 1-250).
start = int(extras.get("frame_start", sc.frame_start))
end = int(extras.get("frame_end", sc.frame_end))
sc.frame_start, sc.frame_end = start, end
frames = {round(start + (end - start) * k / 19) for k in range(20)} | {end}
# And 12 in each stage (the take-off's run and the landing's touch-downs are short).
for st in extras.get("stages") or []:
    a, b = start + st["start"], start + st["end"] - 1
    frames |= {round(a + (b - a) * k / 11) for k in range(12)}
frames = sorted(f for f in frames if start <= f <= end)
print("MESHES", len(meshes), "FRAMES", start, end, "STAGES", extras.get("stages"))
worst = float("inf")
failed = []
for f in frames:
    sc.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    low = float("inf")
    for o in meshes:
        ev = o.evaluated_get(dg)
        m = ev.to_mesh()
        mw = ev.matrix_world
        for v in m.vertices:
            z = (mw @ v.co).z
            if z < low:
                low = z
        ev.to_mesh_clear()
    worst = min(worst, low)
    print("FRAME", f, "LOWEST %.4f m" % low)
    if low < -TOL:
        failed.append("frame %d: a vertex at z = %.4f m" % (f, low))
print("LOWEST OVER ALL FRAMES %.4f m" % worst)
if failed:
    print("FAILED", "; ".join(failed))
    sys.exit(1)
print("OK")
