# Imports a large flock's .glb written with one skeleton for the flock (`--gltf-mode flock`, the
# default from 200 birds) into Blender (headless) and checks what arrived: one armature per part
# of 64 birds holding its birds' bones, with the part's skinned mesh, the import's CPU time under a
# budget, the birds where the CSV of the same animation puts them (10 frames, within 1 mm) and the
# wings flapping. Prints a summary; exits 1 when a check fails.
# Usage: blender -b --python scripts/blender_flock_check.py -- flock.glb flock.csv [BUDGET_S]
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
import csv, json, math, struct, time
import bpy

args = sys.argv[sys.argv.index("--") + 1:]
path, csv_path = args[0], args[1]
budget = float(args[2]) if len(args) > 2 else 60.0
with open(path, "rb") as fh:
    head = fh.read(20)
    doc = json.loads(fh.read(struct.unpack("<I", head[12:16])[0]))
extras = doc["scenes"][0].get("extras", {})
wingspan = float(extras["wingspan_m"])
fps = int(round(extras.get("fps", 30)))
birds = int(extras["birds"])
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.fps = fps
t = time.process_time()
bpy.ops.import_scene.gltf(filepath=path)
cpu = time.process_time() - t
failed = []
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
meshes = [o for o in bpy.data.objects if o.type == "MESH"]
parts = math.ceil(birds / 64)
print("IMPORT %d birds: %.1f s CPU, %d armature(s), %d meshes" % (birds, cpu, len(arms), len(meshes)))
if cpu > budget:
    failed.append("import took %.1f s of CPU (budget %.0f s)" % (cpu, budget))
if len(arms) != parts:
    failed.append("%d armatures, expected %d (one a part of 64 birds)" % (len(arms), parts))
if len(meshes) != parts:
    failed.append("%d meshes, expected %d" % (len(meshes), parts))
# Each bird: its root and the rig's nine joints (body, neck, tail, four wing joints, two legs).
BONES_PER_BIRD = 10
nbones = sum(len(a.pose.bones) for a in arms)
if nbones != BONES_PER_BIRD * birds:
    failed.append("%d bones, expected %d" % (nbones, BONES_PER_BIRD * birds))
# Every bone's armature, by name (bird_000, bird_000.upper_arm.L, ...).
arm_of = {b.name: a for a in arms for b in a.pose.bones}
for m in meshes:
    bound = [md.object for md in m.modifiers if md.type == "ARMATURE" and md.object in arms]
    if len(bound) != 1:
        failed.append("%s is not bound to one of the armatures" % m.name)
        break
    # Its vertex groups are its part's bones: all of one armature.
    if any(arm_of.get(g.name) is not bound[0] for g in m.vertex_groups):
        failed.append("%s has vertex groups outside its armature" % m.name)
        break
digits = len(str(birds - 1))
name = lambda b: "bird_%0*d" % (digits, b)
# The CSV at 10 frames across the flight.
frames = set()
with open(csv_path) as fh:
    for r in csv.DictReader(fh):
        frames.add(int(r["frame"]))
frames = sorted(frames)
picks = {frames[round(i * (len(frames) - 1) / 9)] for i in range(10)}
rows = {}
with open(csv_path) as fh:
    for r in csv.DictReader(fh):
        f = int(r["frame"])
        if f in picks:
            rows[(f, int(r["bird"]))] = (float(r["x"]), float(r["y"]), float(r["z"]))
worst, at = 0.0, None
for f in sorted(picks):
    sc.frame_set(f)
    for b in range(birds):
        arm = arm_of[name(b)]
        got = (arm.matrix_world @ arm.pose.bones[name(b)].matrix).translation
        want = [v * wingspan for v in rows[(f, b)]]
        err = max(abs(got[i] - want[i]) for i in range(3))
        if err > worst:
            worst, at = err, (f, b, tuple(round(v, 4) for v in got), tuple(round(v, 4) for v in want))
print("POSITIONS 10 frames %d..%d, %d birds: worst %.6f m (frame, bird, Blender, CSV: %s)"
      % (min(picks), max(picks), birds, worst, at))
if worst > 0.001:
    failed.append("positions off the CSV by %.4f m" % worst)
# The first bird's wing over a second: it flaps, and the mesh follows (evaluated vertices move).
mid = frames[len(frames) // 2]
wing = set()
deps = bpy.context.evaluated_depsgraph_get()
first = sorted(meshes, key=lambda m: m.name)[0]
spans = set()
for f in range(mid, mid + fps + 1):
    sc.frame_set(f)
    wing.add(round(arm_of[name(0)].pose.bones[name(0) + ".upper_arm.L"].matrix.to_euler()[2], 4))
    ev = first.evaluated_get(bpy.context.evaluated_depsgraph_get())
    zs = [v.co.z for v in ev.data.vertices[:400]]
    spans.add(round(max(zs) - min(zs), 4))
print("WING upper_arm.L angles over a second: %d; first bird's mesh heights: %d" % (len(wing), len(spans)))
if len(wing) < 10:
    failed.append("upper_arm.L does not flap")
if len(spans) < 10:
    failed.append("the skinned mesh does not follow the wings")
if failed:
    print("FAILED", "; ".join(failed))
    sys.exit(1)
print("OK")
