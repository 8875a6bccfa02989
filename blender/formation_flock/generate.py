"""The work behind the Generate button: run formation, then bring the flock into the scene.

Two ways to run formation, chosen in this order:

1. the ``formation`` Python package, when Blender's Python can import it (the 4.2+ extension
   installs the wheel bundled in its zip; a Blender whose Python is the system's may also see a
   ``pip install``-ed package);
2. the ``formation`` command line: the path set in the add-on's preferences, else the program
   bundled in the zip (``bin/formation``), else ``formation`` on the PATH.

Both are the same Rust library, so the same settings and seed give the same flock. The flock
is written as a .glb into a temporary folder and imported with Blender's own glTF importer.
"""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import tempfile

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
COLLECTION = "formation flock"
BUNDLED_EXAMPLE = os.path.join(HERE, "examples", "barnacle_geese_v.json")


class FlockError(Exception):
    """A problem the user can fix; its text is one line shown as a Blender report."""


# ---------------------------------------------------------------------------------------------
# Running formation


def find_cli(preferred: str = "") -> str | None:
    """The command line to run: the preference, the bundled program, or the PATH's."""
    bundled = os.path.join(HERE, "bin", "formation")
    if os.path.isfile(bundled) and not os.access(bundled, os.X_OK):
        try:  # installing from a zip does not keep the executable bit
            os.chmod(bundled, 0o755)
        except OSError:
            pass
    for cand in (bpy.path.abspath(preferred) if preferred else "", bundled):
        if cand and os.path.isfile(cand) and os.access(cand, os.X_OK):
            return cand
    return shutil.which("formation")


def python_package():
    """The formation Python package when it can be imported here and has what we need."""
    if os.environ.get("FORMATION_BLENDER_BACKEND", "") == "cli":
        return None
    try:
        import formation  # noqa: F401  (the wheel, when installed)
    except Exception:  # an ImportError, or a wheel built for another Python
        return None
    if not hasattr(formation, "animate"):
        return None
    return formation


def backend(preferred_cli: str = "") -> str:
    """What Generate runs, as the panel shows it."""
    if python_package() is not None:
        return "the Python package"
    cli = find_cli(preferred_cli)
    if cli is None:
        return "nothing found (see preferences)"
    if cli == os.path.join(HERE, "bin", "formation"):
        return "the bundled command line"
    return cli


def cli_arguments(req: dict, glb: str, path_file: str | None) -> list[str]:
    """The `formation animate` arguments for a request (the panel's settings)."""
    args = [
        "animate", req["input"],
        "--birds", str(req["birds"]),
        "--seconds", repr(float(req["seconds"])),
        "--seed", str(req["seed"]),
        "--species", req["species"],
        "--fps", repr(float(req["fps"])),
    ]
    if req.get("wingspan_m", 0.0) > 0.0:
        args += ["--wingspan-m", repr(float(req["wingspan_m"]))]
    if not req.get("takeoff", True):
        args.append("--no-initiation")
    if path_file:
        args += ["--path", path_file]
    args += ["-o", glb, "--quiet"]
    return args


def run_formation(req: dict, workdir: str, path_file: str | None, preferred_cli: str = "") -> str:
    """Writes the flock as a .glb into workdir and returns its path; FlockError on failure."""
    glb = os.path.join(workdir, "flock.glb")
    pkg = python_package()
    if pkg is not None:
        options = {"steady.fps": float(req["fps"]), "wingbeat.species": req["species"]}
        if req.get("wingspan_m", 0.0) > 0.0:
            options["steady.wingspan_m"] = float(req["wingspan_m"])
        try:
            anim = pkg.animate(
                req["input"], birds=int(req["birds"]), seconds=float(req["seconds"]),
                seed=int(req["seed"]), path=path_file, initiation=bool(req.get("takeoff", True)),
                **options,
            )
            anim.write(glb)
        except (ValueError, OSError) as e:
            raise FlockError(one_line(str(e))) from None
        return glb
    cli = find_cli(preferred_cli)
    if cli is None:
        raise FlockError(
            "formation's command line was not found: set its path in the add-on's preferences "
            "or put `formation` on the PATH (cargo install --path . in the repository)"
        )
    try:
        proc = subprocess.run([cli] + cli_arguments(req, glb, path_file), capture_output=True, text=True)
    except OSError as e:
        raise FlockError(f"{cli}: cannot run it: {e.strerror or e}") from None
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and not ln.startswith("warning")]
        raise FlockError(one_line(lines[-1] if lines else f"formation ended with exit {proc.returncode}"))
    if not os.path.isfile(glb):
        raise FlockError(f"formation wrote no {glb}")
    return glb


def one_line(text: str) -> str:
    text = " ".join(text.split())
    return text[len("error: "):] if text.startswith("error: ") else text


# ---------------------------------------------------------------------------------------------
# The path from a curve


def curve_points(obj, depsgraph=None) -> list[list[float]]:
    """A curve object's first spline as points in world metres, in order, as drawn.

    The curve is evaluated as Blender draws it (its resolution), so a Bézier or NURBS curve gives
    a dense polyline that formation follows as drawn. Points closer than 5 cm to the one before
    are dropped (formation refuses a point repeating the one before); a cyclic spline ends on
    its first point again, which closes the path.
    """
    if obj is None or obj.type != "CURVE":
        raise FlockError("the path must be a curve object")
    if not obj.data.splines:
        raise FlockError(f"curve {obj.name}: it has no spline")
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        verts = [obj.matrix_world @ v.co for v in mesh.vertices]
        order = spline_order(mesh)
    finally:
        ev.to_mesh_clear()
    pts: list[list[float]] = []
    for i in order:
        p = verts[i]
        if pts and sum((a - b) ** 2 for a, b in zip(pts[-1], p)) < 0.05**2:
            continue
        pts.append([round(p.x, 4), round(p.y, 4), round(p.z, 4)])
    if obj.data.splines[0].use_cyclic_u and len(pts) > 2:
        pts.append(list(pts[0]))
    if len(pts) < 2:
        raise FlockError(f"curve {obj.name}: fewer than two points")
    return pts


def spline_order(mesh) -> list[int]:
    """Vertex indices of the evaluated curve's first connected chain, end to end."""
    n = len(mesh.vertices)
    if not mesh.edges:
        return list(range(n))
    nbr: dict[int, list[int]] = {}
    for e in mesh.edges:
        a, b = e.vertices
        nbr.setdefault(a, []).append(b)
        nbr.setdefault(b, []).append(a)
    start = min((v for v in nbr if len(nbr[v]) == 1), default=min(nbr))
    order, prev, cur = [start], None, start
    while True:
        nxt = [v for v in nbr[cur] if v != prev and v not in order[-2:]]
        if not nxt or nxt[0] == start:
            break
        prev, cur = cur, nxt[0]
        order.append(cur)
    return order


def write_path(points: list[list[float]], file: str) -> None:
    with open(file, "w") as f:
        json.dump({"units": "m", "points": points}, f)


# ---------------------------------------------------------------------------------------------
# The .glb's time range


def glb_json(path: str) -> dict:
    with open(path, "rb") as f:
        head = f.read(20)
        if len(head) < 20 or head[:4] != b"glTF":
            raise FlockError(f"{path}: not a binary glTF file")
        length, kind = struct.unpack("<II", head[12:20])
        if kind != 0x4E4F534A:
            raise FlockError(f"{path}: the first chunk is not JSON")
        return json.loads(f.read(length))


def time_range(doc: dict) -> tuple[float, float]:
    """First and last key time, seconds, over every animation of a glTF document."""
    lo, hi = None, None
    for anim in doc.get("animations", []):
        for s in anim.get("samplers", []):
            acc = doc["accessors"][s["input"]]
            a, b = acc.get("min", [0.0])[0], acc.get("max", [0.0])[0]
            lo = a if lo is None else min(lo, a)
            hi = b if hi is None else max(hi, b)
    if lo is None:
        raise FlockError("the generated flock has no animation")
    return lo, hi


# ---------------------------------------------------------------------------------------------
# Into the scene


def remove_flock(name: str = COLLECTION) -> None:
    """Removes a flock made before: its collection, objects and the data only they used."""
    coll = bpy.data.collections.get(name)
    if coll is None:
        return
    data, actions, materials = [], [], []
    for obj in list(coll.all_objects):
        if obj.data is not None:
            data.append(obj.data)
            materials += [s.material for s in getattr(obj, "material_slots", []) if s.material]
        ad = obj.animation_data
        if ad is not None:
            if ad.action is not None:
                actions.append(ad.action)
            for t in ad.nla_tracks:
                actions += [s.action for s in t.strips if s.action is not None]
        bpy.data.objects.remove(obj, do_unlink=True)
    for c in list(coll.children_recursive):
        bpy.data.collections.remove(c)
    bpy.data.collections.remove(coll)
    for block in data + actions + materials:
        try:
            if block.users == 0:
                for coll_of in (bpy.data.meshes, bpy.data.armatures, bpy.data.actions, bpy.data.materials):
                    if block.name in coll_of and coll_of[block.name] == block:
                        coll_of.remove(block)
                        break
        except ReferenceError:  # already removed with its owner
            pass


def numpy_for_the_importer() -> None:
    """Debian's Blender 3.4 glTF importer uses numpy.bool, which numpy 1.24 removed."""
    import warnings

    try:
        import numpy
    except ImportError:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if not hasattr(numpy, "bool"):
            numpy.bool = bool


def import_flock(context, glb: str, fps: float, name: str = COLLECTION) -> tuple[int, int]:
    """Imports the .glb into a fresh collection, sets the scene's rate and range; returns it."""
    doc = glb_json(glb)
    t0, t1 = time_range(doc)
    scene = context.scene
    # The importer turns the file's seconds into frames at the scene's rate: set it first.
    set_fps(scene, fps)
    remove_flock(name)
    coll = bpy.data.collections.new(name)
    scene.collection.children.link(coll)
    layer = find_layer_collection(context.view_layer.layer_collection, name)
    if layer is not None:
        context.view_layer.active_layer_collection = layer
    numpy_for_the_importer()
    bpy.ops.import_scene.gltf(filepath=glb)
    for obj in list(context.selected_objects):
        if obj.name not in coll.objects and not obj.users_collection == [coll]:
            for c in obj.users_collection:
                c.objects.unlink(obj)
            coll.objects.link(obj)
    start, end = round(t0 * fps), round(t1 * fps)
    # The file's own range where it says it (a loop ends before its closing key).
    extras = (doc.get("scenes") or [{}])[0].get("extras") or {}
    if isinstance(extras.get("frame_end"), int) and isinstance(extras.get("frame_start"), int):
        start, end = extras["frame_start"], extras["frame_end"]
    scene.frame_start, scene.frame_end = start, end
    scene.frame_set(start)
    return start, end


def set_fps(scene, fps: float) -> None:
    whole = round(fps)
    if abs(fps - whole) < 1e-9:
        scene.render.fps, scene.render.fps_base = int(whole), 1.0
    else:  # e.g. 29.97: Blender's rate is fps / fps_base
        scene.render.fps = int(round(fps * 1001 / 1000))
        scene.render.fps_base = scene.render.fps / fps


def find_layer_collection(layer, name):
    if layer.name == name:
        return layer
    for child in layer.children:
        found = find_layer_collection(child, name)
        if found is not None:
            return found
    return None


def generate(context, req: dict, path_obj=None, preferred_cli: str = "") -> tuple[int, int, int]:
    """The whole Generate: checks, runs formation, imports; (birds, first frame, last frame)."""
    if not req["input"]:
        req["input"] = BUNDLED_EXAMPLE
    req["input"] = bpy.path.abspath(req["input"])
    if not os.path.exists(req["input"]):
        raise FlockError(f"{req['input']}: no such file (pick annotations or a params file)")
    scene = context.scene
    req["fps"] = scene.render.fps / scene.render.fps_base
    workdir = tempfile.mkdtemp(prefix="formation-flock-")
    try:
        path_file = None
        if path_obj is not None:
            path_file = os.path.join(workdir, "path.json")
            write_path(curve_points(path_obj, context.evaluated_depsgraph_get()), path_file)
        try:
            glb = run_formation(req, workdir, path_file, preferred_cli)
        except FlockError as e:
            if path_file is None:
                raise
            raise FlockError(str(e).replace(path_file, f"curve {path_obj.name}")) from None
        start, end = import_flock(context, glb, req["fps"])
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    return req["birds"], start, end
