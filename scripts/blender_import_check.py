# Imports a .glb written by `formation` into Blender (headless) and checks what arrived: one
# armature per bird with the documented bones, one action per clip and bird, the wing bones turning
# and the birds moving while the clips play. Prints a summary; exits 1 when a check fails.
# Usage: blender -b --python scripts/blender_import_check.py -- flock.glb [FPS|-] [flock.csv]
# FPS (default: the file's own, from the scene's extras) is set on the scene BEFORE the import,
# as docs/export.md advises, so that the importer turns the file's seconds into frames at the
# animation's own rate. With the CSV of the same animation, bird positions are checked.
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

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[-1:]
path = args[0]
csv_path = args[2] if len(args) > 2 else None
import json as _json, struct as _struct
with open(path, "rb") as fh:
    _head = fh.read(20)
    _doc = _json.loads(fh.read(_struct.unpack("<I", _head[12:16])[0]))
_extras = _doc["scenes"][0].get("extras", {})
wingspan = float(_extras.get("wingspan_m", 1.0))
fps = int(args[1]) if len(args) > 1 and args[1] != "-" else int(round(_extras.get("fps", 30)))
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.fps = fps
bpy.ops.import_scene.gltf(filepath=path)
objs = bpy.data.objects
arms = sorted((o for o in objs if o.type == 'ARMATURE'), key=lambda o: o.name)
meshes = [o for o in objs if o.type == 'MESH']
print("OBJECTS", len(objs), "ARMATURES", len(arms), "MESHES", len(meshes))
bones = [b.name for b in arms[0].data.bones]
print("BONES", bones)
clips = sorted({t.name for a in arms if a.animation_data for t in a.animation_data.nla_tracks})
print("CLIPS", clips, "ACTIONS", len(bpy.data.actions))
failed = []
want = ["body", "neck", "tail", "upper_arm.L", "hand.L", "upper_arm.R", "hand.R", "leg.L", "leg.R"]
if bones != want:
    failed.append("bones %s" % bones)
names = [a.name for a in arms]
if names != sorted(names) or not all(n.startswith("bird_") for n in names):
    failed.append("armature names %s" % names[:5])
for a in arms:
    if not any(m.parent == a for m in meshes):
        failed.append("%s has no skinned mesh" % a.name)
        break
# The default .glb has one clip per bird over the whole flight: it must play on import, with no
# NLA change. With a CSV of the same animation: every bird at 10 frames across the flight where
# the CSV puts it (within 1 mm); the wings flap and the birds move over a second of steady flight.
def _actions(a):
    ad = a.animation_data
    if ad is None:
        return []
    acts = [ad.action] if ad.action else []
    return acts + [s.action for t in ad.nla_tracks for s in t.strips if s.action]


# The bird watched for the wingbeat: the first whose wing bones are animated (with several bird
# models, the first bird may wear a static one).
a0 = next((a for a in arms if any('"upper_arm.L"' in fc.data_path for act in _actions(a)
                                  for fc in act.fcurves)), arms[0])
if "flight" in clips:
    for a in arms:
        ad = a.animation_data
        playing = ad is not None and (ad.action is not None or any(not t.mute for t in ad.nla_tracks))
        if not playing:
            failed.append("%s: nothing plays on import" % a.name)
            break
    # The first key sits on the file's first frame (0, or the --start-frame it was written with).
    start = int(_extras.get("frame_start", 0))
    first = min(act.frame_range[0] for act in bpy.data.actions)
    print("FIRST KEY", round(first, 4), "frame_start", start)
    if abs(first - start) > 0.01:
        failed.append("first key at frame %.4f, expected %d" % (first, start))
    lo = start
    hi = int(round(max(act.frame_range[1] for act in bpy.data.actions)))
    mid = (lo + hi) // 2
    wing, pos = [], []
    for f in range(mid, mid + fps + 1):
        sc.frame_set(f)
        wing.append(round(a0.pose.bones["upper_arm.L"].matrix.to_euler()[2], 4))
        pos.append(tuple(round(v, 3) for v in a0.matrix_world.translation))
    print("CLIP flight frames", lo, hi, "wing angles", len(set(wing)), "positions", len(set(pos)))
    if len(set(wing)) < 10:
        failed.append("flight: upper_arm.L does not flap")
    if len(set(pos)) < 10:
        failed.append("flight: %s does not move" % a0.name)
    if csv_path:
        import csv as _csv
        rows = {}
        with open(csv_path) as fh:
            for r in _csv.DictReader(fh):
                rows[(int(r["frame"]), int(r["bird"]))] = (float(r["x"]), float(r["y"]), float(r["z"]))
        frames = sorted({k[0] for k in rows})
        picks = [frames[round(i * (len(frames) - 1) / 9)] for i in range(10)]
        worst = 0.0
        for f in picks:
            sc.frame_set(f)
            for b, a in enumerate(arms):
                want = [v * wingspan for v in rows[(f, b)]]
                got = a.matrix_world.translation
                worst = max(worst, max(abs(got[i] - want[i]) for i in range(3)))
        print("POSITIONS 10 frames %d..%d, %d birds: worst %.6f m" % (picks[0], picks[-1], len(arms), worst))
        if worst > 0.001:
            failed.append("positions off the CSV by %.4f m" % worst)
else:
    # Per-stage clips (--clips stages): play each alone on the first armature.
    for clip in clips:
        act = bpy.data.actions.get("%s_%s" % (clip, a0.name))
        if act is None:
            failed.append("no action for clip %s" % clip)
            continue
        for t in a0.animation_data.nla_tracks:
            t.mute = True
        a0.animation_data.action = act
        lo, hi = int(act.frame_range[0]), int(act.frame_range[1])
        wing, pos = [], []
        for f in range(lo, min(hi, lo + 60) + 1):
            sc.frame_set(f)
            wing.append(round(a0.pose.bones["upper_arm.L"].matrix.to_euler()[2], 4))
            pos.append(tuple(round(v, 3) for v in a0.matrix_world.translation))
        print("CLIP", clip, "frames", lo, hi, "wing angles", len(set(wing)), "positions", len(set(pos)),
              "start", pos[0], "after 60 frames", pos[-1])
        if len(set(wing)) < 10 and clip != "initiation":
            failed.append("%s: upper_arm.L does not flap" % clip)
        if len(set(pos)) < 10 and clip != "initiation":
            failed.append("%s: %s does not move" % (clip, a0.name))
print("SCENE fps", sc.render.fps, "range", sc.frame_start, sc.frame_end)
if failed:
    print("FAILED", "; ".join(failed))
    sys.exit(1)
print("OK")
