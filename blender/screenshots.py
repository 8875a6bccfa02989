# Pictures of the add-on for docs/blender.md, taken in Blender's real window under Xvfb:
#   blender -b --factory-startup --python-expr "import bpy; bpy.ops.wm.save_as_mainfile(filepath='/tmp/x/empty.blend')"
#   xvfb-run -s "-screen 0 1600x900x24" blender --factory-startup /tmp/x/empty.blend \
#       --python blender/screenshots.py -- formation_flock.zip OUTDIR
# (opening a file skips the splash; installs the add-on, draws a path, generates a flock, shows
# the sidebar's Formation tab alone, then captures the window and the 3D view)
import os
import sys

import bpy

zip_path, out = sys.argv[sys.argv.index("--") + 1:][:2]
os.makedirs(out, exist_ok=True)
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="formation_flock")

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene = bpy.context.scene
cu = bpy.data.curves.new("flight path", "CURVE")
cu.dimensions = "3D"
sp = cu.splines.new("BEZIER")
sp.bezier_points.add(3)
for bp, co in zip(sp.bezier_points, [(0, 0, 30), (0, 150, 30), (60, 260, 36), (170, 320, 40)]):
    bp.co = co
    bp.handle_left_type = bp.handle_right_type = "AUTO"
path_obj = bpy.data.objects.new("flight path", cu)
scene.collection.objects.link(path_obj)
s = scene.formation_flock
s.birds, s.seconds, s.seed, s.path = 14, 12.0, 3, path_obj


def view3d():
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                region = next(r for r in area.regions if r.type == "WINDOW")
                return window, area, region
    raise RuntimeError("no 3D view")


def step1():
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.formation.generate()
    space = area.spaces.active
    space.show_region_ui = True
    space.overlay.show_floor = True
    space.shading.type = "SOLID"
    space.clip_end = 10000
    return None


def step2():
    window, area, region = view3d()
    # Show the sidebar's Formation tab: a click on it (xdotool, under Xvfb), found from the
    # sidebar region's place on the screen (its tabs are a column at the region's right edge).
    ui = next(r for r in area.regions if r.type == "UI")
    tab_x = ui.x + ui.width - 10
    tab_y_from_top = window.height - (ui.y + ui.height) + 160
    import subprocess
    subprocess.run(["xdotool", "mousemove", str(tab_x), str(tab_y_from_top), "click", "1"], check=False)
    area.spaces.active.overlay.show_relationship_lines = False
    for o in bpy.data.objects:
        o.select_set(False)
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    scene.frame_set((scene.frame_start + scene.frame_end) * 2 // 3)
    ps = [a.matrix_world.translation for a in arms]
    c = sum(ps, ps[0] * 0) / len(ps)
    ext = max((p - c).length for p in ps)
    r3d = area.spaces.active.region_3d
    r3d.view_location = c
    r3d.view_distance = max(ext * 2.2, 20.0)
    from mathutils import Euler
    r3d.view_rotation = Euler((0.55, 0.0, 3.4)).to_quaternion()
    bpy.app.timers.register(step3, first_interval=1.5)
    return None


def step3():
    window, area, region = view3d()
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=os.path.join(out, "blender-panel.png"))
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screenshot_area(filepath=os.path.join(out, "blender-flock.png"))
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(step1, first_interval=1.0)
bpy.app.timers.register(step2, first_interval=3.0)
