# Installs the add-on from its zip into a headless Blender and checks it as a user would:
# a 14-bird flock from the bundled example along a Bezier curve; the scene's rate and range; the
# birds where the command line puts them for the same seed and path (5 frames, within 0.5 m);
# generating again replaces the flock; bad input ends in a report, not a traceback.
# Usage: blender -b --factory-startup --python-exit-code 1 --python blender/check_addon.py -- \
#            formation_flock.zip path/to/formation OUTDIR
import json
import math
import os
import subprocess
import sys

import bpy

zip_path, cli, out = sys.argv[sys.argv.index("--") + 1:][:3]
os.makedirs(out, exist_ok=True)
failed = []


def check(ok, what):
    print(("ok      " if ok else "FAILED  ") + what)
    if not ok:
        failed.append(what)


bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="formation_flock")
import formation_flock.generate as gen  # noqa: E402  (importable once enabled)

os.environ["FORMATION_BLENDER_BACKEND"] = "cli"  # the bundled program, as in Blender 3.4
scene = bpy.context.scene
scene.render.fps = 24  # not formation's default: the flock must follow the scene's rate

cu = bpy.data.curves.new("flight path", "CURVE")
cu.dimensions = "3D"
sp = cu.splines.new("BEZIER")
sp.bezier_points.add(3)
for bp, co in zip(sp.bezier_points, [(0, 0, 30), (0, 450, 30), (180, 780, 36), (510, 960, 40)]):
    bp.co = co
    bp.handle_left_type = bp.handle_right_type = "AUTO"
path_obj = bpy.data.objects.new("flight path", cu)
scene.collection.objects.link(path_obj)

s = scene.formation_flock
s.birds, s.seconds, s.seed, s.path = 14, 12.0, 3, path_obj
print("backend:", gen.backend())
res = bpy.ops.formation.generate()
check(res == {"FINISHED"}, f"Generate finished ({res})")
coll = bpy.data.collections.get(gen.COLLECTION)
arms = sorted((o for o in coll.all_objects if o.type == "ARMATURE"), key=lambda o: o.name) if coll else []
check(len(arms) == 14, f"14 armatures in the collection ({len(arms)})")
check(scene.render.fps == 24 and scene.render.fps_base == 1.0, f"scene at 24 fps ({scene.render.fps}/{scene.render.fps_base})")

# The command line on the same path file and settings.
path_file = os.path.join(out, "path.json")
gen.write_path(gen.curve_points(path_obj), path_file)
req = {"input": gen.BUNDLED_EXAMPLE, "birds": 14, "seconds": 12.0, "species": "goose", "seed": 3, "fps": 24.0}
anim_json = os.path.join(out, "cli.json")
args = gen.cli_arguments(req, os.path.join(out, "cli.glb"), path_file) + ["-o", anim_json]
proc = subprocess.run([cli] + args, capture_output=True, text=True)
check(proc.returncode == 0, "the command line ran: " + proc.stderr.strip()[-200:])
anim = json.load(open(anim_json))
frames, span = anim["frames"], anim["wingspan_m"]
check((scene.frame_start, scene.frame_end) == (0, len(frames) - 1),
      f"frame range {scene.frame_start}-{scene.frame_end} = the animation's 0-{len(frames) - 1}")
worst = 0.0
for f in [round(i * (len(frames) - 1) / 4) for i in range(5)]:
    scene.frame_set(f)
    fr = frames[f]
    for b, arm in enumerate(arms):
        want = (fr["x"][b] * span, fr["y"][b] * span, fr["z"][b] * span)
        got = arm.matrix_world.translation
        worst = max(worst, math.dist(want, got))
check(worst < 0.5, f"birds where the command line puts them at 5 frames (worst {worst:.4f} m)")

# Along the curve: the flock's centre in the last frame is near the drawn path.
scene.frame_set(scene.frame_end)
c = [sum(a.matrix_world.translation[i] for a in arms) / len(arms) for i in range(3)]
pts = gen.curve_points(path_obj)


def seg_dist(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]
    t = max(0.0, min(1.0, sum((p[i] - a[i]) * ab[i] for i in range(3)) / max(sum(v * v for v in ab), 1e-12)))
    return math.dist(p, [a[i] + t * ab[i] for i in range(3)])


d = min(seg_dist(c, pts[i], pts[i + 1]) for i in range(len(pts) - 1))
check(d < 15.0, f"the flock's centre at the end is {d:.1f} m from the curve")
scene.render.filepath = os.path.join(out, "")

# Generating again replaces the flock.
actions_before = len(bpy.data.actions)
s.birds = 9
res = bpy.ops.formation.generate()
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
check(res == {"FINISHED"} and len(arms) == 9, f"regenerated: 9 armatures in the file ({len(arms)})")
check(len(bpy.data.actions) <= actions_before, f"no actions left behind ({actions_before} -> {len(bpy.data.actions)})")

# Bad input: a report with formation's one line, the flock left as it was.
for setup, expect in [
    (lambda: setattr(s, "input", "/nonexistent/annotations.json"), "no such file"),
    (lambda: (setattr(s, "input", ""), [setattr(p, "co", (p.co.x, p.co.y, -5.0)) for p in sp.bezier_points]), "path"),
]:
    setup()
    try:
        res = bpy.ops.formation.generate()
        check(False, f"bad input was refused (got {res})")
    except RuntimeError as e:  # how an operator's error report reaches a script
        msg = str(e)
        check(expect in msg and "Traceback" not in msg, f"bad input reported in one line: {msg.strip()}")
    n = len([o for o in bpy.data.objects if o.type == "ARMATURE"])
    check(n == 9, f"the flock before is kept ({n} armatures)")

print("FAILED: " + "; ".join(failed) if failed else "OK")
sys.exit(1 if failed else 0)
