"""formation flock: generate a flock flying in line formation inside Blender.

A panel in the 3D view's sidebar (N, tab "Formation"): pick the footage's annotations or a
params file, the number of birds, seconds of steady flight, species and seed, optionally a curve
object as the leader's path, and press Generate. The flock appears as the collection
"formation flock" (one armature and skinned bird per bird; from 200 birds one armature and
one mesh for every 64 birds, which imports in a fraction of the time), the scene's frame rate and range are
set, and the flight plays at once. Generating again replaces the collection. Problems show as
reports (one line), not tracebacks.
"""

bl_info = {
    "name": "formation flock",
    "author": "formation developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Formation",
    "description": "Generate bird flocks flying in line formations (V, U, J, echelon)",
    "category": "Animation",
}

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import generate as gen


def _is_curve(_self, obj):
    return obj.type == "CURVE"


class FormationFlockSettings(bpy.types.PropertyGroup):
    input: StringProperty(
        name="Input",
        description="Annotations of the footage (any format formation reads) or a params file; "
        "empty: the bundled example (a V of barnacle geese)",
        subtype="FILE_PATH",
        default="",
    )
    birds: IntProperty(name="Birds", description="Number of birds", default=14, min=2, soft_max=1000)
    seconds: FloatProperty(
        name="Seconds", description="Length of the steady flight after the take-off, seconds",
        default=20.0, min=0.1, soft_max=600.0,
    )
    species: EnumProperty(
        name="Species",
        description="Species preset of the wingbeat",
        items=[("goose", "Goose", ""), ("crane", "Crane", ""), ("pelican", "Pelican", "")],
        default="goose",
    )
    seed: IntProperty(name="Seed", description="Equal seeds and settings give the same flock", default=0, min=0)
    takeoff: BoolProperty(
        name="Take-off", description="Start on the ground and take off (off: the steady flight alone)", default=True
    )
    wingspan_m: FloatProperty(
        name="Wingspan (m)", description="Wingspan of one bird in metres; 0: formation's default",
        default=0.0, min=0.0, soft_max=4.0,
    )
    path: PointerProperty(
        name="Path", description="A curve the leader follows (optional; world coordinates in metres)",
        type=bpy.types.Object, poll=_is_curve,
    )


class FORMATION_OT_generate(bpy.types.Operator):
    """Generate the flock (replaces the flock generated before)"""

    bl_idname = "formation.generate"
    bl_label = "Generate"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        s = context.scene.formation_flock
        req = {
            "input": s.input,
            "birds": s.birds,
            "seconds": s.seconds,
            "species": s.species,
            "seed": s.seed,
            "takeoff": s.takeoff,
            "wingspan_m": s.wingspan_m,
        }
        prefs = context.preferences.addons.get(__package__)
        cli = prefs.preferences.cli_path if prefs is not None else ""
        try:
            birds, start, end = gen.generate(context, req, s.path, cli)
        except gen.FlockError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except Exception as e:  # never a traceback in the user's face
            self.report({"ERROR"}, f"formation flock: {type(e).__name__}: {gen.one_line(str(e))}")
            return {"CANCELLED"}
        fps = context.scene.render.fps / context.scene.render.fps_base
        self.report({"INFO"}, f"{birds} birds, frames {start}-{end} at {fps:g} fps")
        return {"FINISHED"}


class FORMATION_PT_panel(bpy.types.Panel):
    bl_label = "Formation flock"
    bl_idname = "FORMATION_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Formation"

    def draw(self, context):
        s = context.scene.formation_flock
        col = self.layout.column()
        col.prop(s, "input")
        col.prop(s, "birds")
        col.prop(s, "seconds")
        col.prop(s, "species")
        col.prop(s, "seed")
        col.prop(s, "wingspan_m")
        col.prop(s, "takeoff")
        col.prop(s, "path")
        col.operator(FORMATION_OT_generate.bl_idname, icon="OUTLINER_OB_ARMATURE")
        prefs = context.preferences.addons.get(__package__)
        cli = prefs.preferences.cli_path if prefs is not None else ""
        col.label(text="Runs " + gen.backend(cli))


class FormationFlockPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    cli_path: StringProperty(
        name="formation command line",
        description="Path of the formation program; empty: the one bundled with the add-on, else the PATH's",
        subtype="FILE_PATH",
        default="",
    )

    def draw(self, context):
        self.layout.prop(self, "cli_path")
        self.layout.label(text="Generate runs " + gen.backend(self.cli_path))


CLASSES = (FormationFlockSettings, FORMATION_OT_generate, FORMATION_PT_panel, FormationFlockPreferences)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.formation_flock = PointerProperty(type=FormationFlockSettings)


def unregister():
    del bpy.types.Scene.formation_flock
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
