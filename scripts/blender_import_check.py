# Imports a .glb written by `formation` into Blender (headless) and prints what arrived: objects,
# meshes, actions, bird nodes, the actions' frame range, and a bird's position at three frames.
# Usage: blender -b --python scripts/blender_import_check.py -- flock.glb
# (Debian's Blender 3.4 glTF add-on still uses numpy.bool, which numpy 1.24 removed: the first
# lines put Debian's numpy first and restore the alias.)
import sys; sys.path.insert(0, "/usr/lib/python3/dist-packages"); [sys.modules.pop(m) for m in list(sys.modules) if m.startswith("numpy")]
import numpy; numpy.bool = bool
import bpy, sys
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=sys.argv[-1])
objs = bpy.data.objects
print("OBJECTS", len(objs))
print("MESHES", sum(1 for o in objs if o.type == 'MESH'))
print("ACTIONS", len(bpy.data.actions))
birds = [o for o in objs if o.name.startswith("bird_") and o.name.count("_") == 1]
print("BIRD NODES", len(birds))
sc = bpy.context.scene
print("FRAME RANGE", sc.frame_start, sc.frame_end, "fps", sc.render.fps)
b = birds[0]
for f in (sc.frame_start, (sc.frame_start + sc.frame_end)//2, sc.frame_end):
    sc.frame_set(f)
    print("frame", f, b.name, tuple(round(v, 3) for v in b.matrix_world.translation))
hand = objs.get("bird_00_hand_left")
if hand:
    angles = []
    for f in range(sc.frame_end - 30, sc.frame_end):
        sc.frame_set(f)
        angles.append(round(hand.matrix_world.to_euler()[1], 3))
    print("hand rotation varies:", len(set(angles)) > 5)
a = birds[0].animation_data.action if birds[0].animation_data else None
print("ACTION RANGE", a.name if a else None, tuple(a.frame_range) if a else None)
lo = min(x.frame_range[0] for x in bpy.data.actions); hi = max(x.frame_range[1] for x in bpy.data.actions)
print("ALL ACTIONS RANGE", lo, hi)
