//! Text USD (`.usda`) export with UsdSkel: the flock as a stage that opens in
//! usdview, Houdini Solaris, Blender and Omniverse.
//!
//! Stage metadata: `metersPerUnit = 1`, `upAxis = "Y"` (the same axes and numbers as the `.glb`:
//! world east `x` → `+X`, up `z` → `+Y`, north `y` → `−Z`, metres), `timeCodesPerSecond` and
//! `framesPerSecond` equal to the animation's fps, time code k = frame k (`t·fps`),
//! `startTimeCode` and `endTimeCode` the first and last frame; the animation's metadata
//! (fps, wingspan_m, seed, species, birds, stages, bird model) in `customLayerData.formation`.
//!
//! Prims: the bird is written once, as the class `/_bird` (a `SkelRoot` holding the `Skeleton`
//! `rig` with the joints of [`bird::JOINTS`] as paths `body/upper_arm_L/hand_L`, their bind and
//! rest transforms, and the skinned `Mesh` `mesh` with `primvars:skel:jointIndices` /
//! `jointWeights`, four influences a vertex, and per-face `displayColor`). Every bird
//! `/flock/bird_000` … is a `SkelRoot` that references `/_bird`, carries the flight as
//! time-sampled `xformOp:translate` and `xformOp:orient`, and binds its own `SkelAnimation`
//! `anim` (time-sampled joint `rotations`, constant `translations` and `scales`) to its `rig`
//! through `skel:animationSource`. With several bird models, model m > 0 is the class
//! `/_bird_m` and each bird references its own model's class (`customData` `bird_model`).
//!
//! An animation that followed a path also gets `/flock/flown_path`, a linear `BasisCurves` (purpose
//! `guide`, so renders leave it out) through the course as flown, turns widened.
//!
//! `render.keys` = reduced thins the flight samples within the tolerances of [`keys`] (the joint
//! rotations, one array per time sample, keep every frame: the wingbeat needs nearly all of them).

use std::fmt::Write as _;
use std::io::Write;

use glam::{Mat4, Quat, Vec3};

use super::bird::{self, BirdAsset};
use super::gltf::{bird_digits, bird_track, metadata, SceneOptions};
use super::keys::{self, Curve};
use crate::animation::Animation;
use crate::wingbeat::Flapper;

/// Shortest text of an f32 that reads back to the same value.
pub(super) fn f(v: f32) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v}")
    }
}

pub(super) fn vec3(v: Vec3) -> String {
    format!("({}, {}, {})", f(v.x), f(v.y), f(v.z))
}

/// USD writes quaternions real part first: `(w, x, y, z)`.
fn quat(q: Quat) -> String {
    format!("({}, {}, {}, {})", f(q.w), f(q.x), f(q.y), f(q.z))
}

/// A matrix as USD's rows (row vectors: translation in the last row), i.e. glam's columns.
fn matrix(m: Mat4) -> String {
    let c = m.to_cols_array_2d();
    let row = |r: [f32; 4]| format!("({}, {}, {}, {})", f(r[0]), f(r[1]), f(r[2]), f(r[3]));
    format!(
        "({}, {}, {}, {})",
        row(c[0]),
        row(c[1]),
        row(c[2]),
        row(c[3])
    )
}

/// USD string literal of `s` (JSON escaping is a subset of USD's).
fn string(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

/// Time code of sample `k`: the shot's frame number (fractional for a sub-frame sample).
pub(super) fn time_code(anim: &Animation, opts: &SceneOptions, k: usize) -> String {
    let tc = opts.frame_of(anim, k);
    let r = (tc * 1e6).round() / 1e6;
    if r == r.round() {
        format!("{}", r as i64)
    } else {
        format!("{r}")
    }
}

/// `customLayerData` value of a JSON value (dictionaries, numbers, strings, arrays of strings
/// or numbers).
fn dict_entries(v: &serde_json::Value, indent: &str, out: &mut String) {
    if let Some(map) = v.as_object() {
        for (k, val) in map {
            match val {
                serde_json::Value::String(s) => {
                    let _ = writeln!(out, "{indent}string {k} = {}", string(s));
                }
                serde_json::Value::Number(n) if n.is_u64() || n.is_i64() => {
                    let _ = writeln!(out, "{indent}int64 {k} = {n}");
                }
                serde_json::Value::Number(n) => {
                    let _ = writeln!(out, "{indent}double {k} = {n}");
                }
                serde_json::Value::Array(a) if a.iter().all(|x| x.is_string()) => {
                    let items: Vec<String> =
                        a.iter().map(|x| string(x.as_str().unwrap_or(""))).collect();
                    let _ = writeln!(out, "{indent}string[] {k} = [{}]", items.join(", "));
                }
                serde_json::Value::Array(a) if !a.is_empty() && a.iter().all(|x| x.is_number()) => {
                    let items: Vec<String> = a.iter().map(|x| x.to_string()).collect();
                    let _ = writeln!(out, "{indent}double[] {k} = [{}]", items.join(", "));
                }
                // Anything else (e.g. the stages) as its JSON text.
                other => {
                    let _ = writeln!(out, "{indent}string {k} = {}", string(&other.to_string()));
                }
            }
        }
    }
}

/// The stage's header: metadata (with `extra`'s entries) and the timeline.
pub(super) fn stage_head(
    anim: &Animation,
    wingspan_m: f64,
    assets: &[BirdAsset],
    opts: &SceneOptions,
    extra: &serde_json::Value,
) -> String {
    let mut head = String::new();
    let _ = writeln!(head, "#usda 1.0\n(");
    let _ = writeln!(
        head,
        "    customLayerData = {{\n        dictionary formation = {{"
    );
    let mut meta = metadata(anim, wingspan_m, assets, opts);
    if let (Some(m), Some(e)) = (meta.as_object_mut(), extra.as_object()) {
        for (k, v) in e {
            m.insert(k.clone(), v.clone());
        }
    }
    dict_entries(&meta, "            ", &mut head);
    let _ = writeln!(head, "        }}\n    }}");
    let _ = writeln!(head, "    defaultPrim = \"flock\"");
    let _ = writeln!(
        head,
        "    doc = \"Flock animation written by formation {}\"",
        env!("CARGO_PKG_VERSION")
    );
    // A loop's closing frame (the first again) is past the end: cycling the range shows each
    // frame once.
    let _ = writeln!(head, "    endTimeCode = {}", opts.frame_end(anim));
    let _ = writeln!(head, "    framesPerSecond = {}", opts.rate(anim));
    let _ = writeln!(head, "    metersPerUnit = 1");
    let _ = writeln!(head, "    startTimeCode = {}", opts.start_frame);
    let _ = writeln!(head, "    timeCodesPerSecond = {}", opts.rate(anim));
    let _ = writeln!(head, "    upAxis = \"Y\"\n)\n");
    head
}

/// Writes the `.usda` text of `anim` with birds `wingspan_m` metres wide to `out`.
pub fn write_usda(
    anim: &Animation,
    wingspan_m: f64,
    opts: &SceneOptions,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let ws = wingspan_m as f32;
    let assets = opts.models(anim);
    let model_of = opts.model_of(anim);
    let n = anim.frames.len();
    let io = |e: std::io::Error| e;
    let head = stage_head(anim, wingspan_m, &assets, opts, &serde_json::json!({}));
    out.write_all(head.as_bytes()).map_err(io)?;
    for (m, asset) in assets.iter().enumerate() {
        out.write_all(prototype(asset, ws, &class_name(m)).as_bytes())
            .map_err(io)?;
    }

    let paths = bird::usd_joint_paths();
    let joints_tokens = paths
        .iter()
        .map(|p| string(p))
        .collect::<Vec<_>>()
        .join(", ");
    let flapper = Flapper::from_animation(anim);
    let digits = bird_digits(anim.birds);
    let scales = bird::bird_scales(anim.seed, anim.birds, opts.size_variation);
    let species = crate::wingbeat::WingbeatOptions::for_animation(anim).species;
    let times: Vec<f32> = anim
        .frames
        .iter()
        .map(|fr| (fr.t - anim.frames[0].t) as f32)
        .collect();
    out.write_all(b"def Xform \"flock\" (\n    kind = \"assembly\"\n)\n{\n")
        .map_err(io)?;
    for (b, &scale) in scales.iter().enumerate() {
        let asset = &assets[model_of[b]];
        let track = bird_track(anim, &flapper, asset, b, wingspan_m);
        let name = format!("bird_{b:0digits$}");
        let mut s = String::new();
        let _ = writeln!(
            s,
            "    def SkelRoot \"{name}\" (\n        prepend references = </{}>\n        customData = {{\n            int bird = {b}{}{}\n        }}\n    )\n    {{",
            class_name(model_of[b]),
            if assets.len() > 1 {
                format!("\n            int bird_model = {}", model_of[b])
            } else {
                String::new()
            },
            if scale != 1.0 {
                format!("\n            double scale = {}", f(scale))
            } else {
                String::new()
            }
        );
        let tol = opts.tolerance;
        let kt = keys::keep(
            opts.keys,
            &times,
            &[Curve::Vec3(&track.flight.translation, tol.position_m)],
        );
        let kq = keys::keep(
            opts.keys,
            &times,
            &[Curve::Quat(&track.flight.yaw, tol.rotation_rad)],
        );
        let _ = writeln!(s, "        float3 xformOp:translate.timeSamples = {{");
        for &k in &kt {
            let _ = writeln!(
                s,
                "            {}: {},",
                time_code(anim, opts, k),
                vec3(track.flight.translation[k])
            );
        }
        let _ = writeln!(
            s,
            "        }}\n        quatf xformOp:orient.timeSamples = {{"
        );
        for &k in &kq {
            let _ = writeln!(
                s,
                "            {}: {},",
                time_code(anim, opts, k),
                quat(track.flight.yaw[k])
            );
        }
        // The bird's size scales it about its root, after the flight (a scale of exactly 1 is
        // left out).
        if scale != 1.0 {
            let sc = f(scale);
            let _ = writeln!(s, "        }}\n        float3 xformOp:scale = ({sc}, {sc}, {sc})\n        uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:orient\", \"xformOp:scale\"]\n");
        } else {
            let _ = writeln!(s, "        }}\n        uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:orient\"]\n");
        }
        let _ = writeln!(
            s,
            "        over \"rig\"\n        {{\n            rel skel:animationSource = </flock/{name}/anim>\n        }}\n"
        );
        let _ = writeln!(s, "        def SkelAnimation \"anim\"\n        {{\n            uniform token[] joints = [{joints_tokens}]");
        let rest: Vec<String> = (0..bird::JOINTS.len())
            .map(|j| {
                let mut t = asset.skeleton.rest_translation(j);
                if j == bird::BODY && scale != 1.0 {
                    t += bird::size_pivot(species, scale);
                }
                vec3(t * ws)
            })
            .collect();
        let _ = writeln!(
            s,
            "            float3[] translations = [{}]",
            rest.join(", ")
        );
        let _ = writeln!(
            s,
            "            half3[] scales = [{}]",
            vec!["(1, 1, 1)"; bird::JOINTS.len()].join(", ")
        );
        let _ = writeln!(s, "            quatf[] rotations.timeSamples = {{");
        out.write_all(s.as_bytes()).map_err(io)?;
        for k in 0..n {
            let q: Vec<String> = track.joints[k].iter().map(|&q| quat(q)).collect();
            writeln!(
                out,
                "                {}: [{}],",
                time_code(anim, opts, k),
                q.join(", ")
            )
            .map_err(io)?;
        }
        out.write_all(b"            }\n        }\n    }\n\n")
            .map_err(io)?;
    }
    out.write_all(flown_path_prim(anim, wingspan_m).as_bytes())
        .map_err(io)?;
    out.write_all(b"}\n").map_err(io)?;
    Ok(())
}

/// Per-vertex interpolation of a mesh attribute.
const VERTEX: &str = "interpolation = \"vertex\"";

/// One array attribute of the bird's mesh: `decl = [values]`, with its metadata lines in
/// parentheses when there are any.
fn mesh_attr<T: AsRef<str>>(s: &mut String, decl: &str, values: &[T], meta: &[&str]) {
    let values: Vec<&str> = values.iter().map(AsRef::as_ref).collect();
    let _ = write!(s, "        {decl} = [{}]", values.join(", "));
    if !meta.is_empty() {
        let _ = writeln!(s, " (");
        for m in meta {
            let _ = writeln!(s, "            {m}");
        }
        let _ = write!(s, "        )");
    }
    let _ = writeln!(s);
}

/// The mesh's triangles as USD values: `faceVertexCounts` (all 3), `faceVertexIndices` and the
/// per-face `displayColor` of each triangle's part.
pub(super) fn topology(m: &bird::SkinnedMesh) -> (Vec<&'static str>, Vec<String>, Vec<String>) {
    let mut counts = Vec::new();
    let mut indices = Vec::new();
    let mut colours = Vec::new();
    for ((_, idx), rgb) in m.parts.iter().zip(&m.colours) {
        for t in idx.chunks_exact(3) {
            counts.push("3");
            indices.extend(t.iter().map(|i| i.to_string()));
            colours.push(format!("({}, {}, {})", f(rgb[0]), f(rgb[1]), f(rgb[2])));
        }
    }
    (counts, indices, colours)
}

/// The class of bird model `m`: `_bird` for the first (or only) model, `_bird_1`, `_bird_2`, …
/// for the others.
fn class_name(m: usize) -> String {
    if m == 0 {
        "_bird".into()
    } else {
        format!("_bird_{m}")
    }
}

/// The class `/_bird` (or `class`): skeleton and skinned mesh, shared by reference.
fn prototype(asset: &BirdAsset, ws: f32, class: &str) -> String {
    let skel = &asset.skeleton;
    let paths = bird::usd_joint_paths();
    let joints = paths
        .iter()
        .map(|p| string(p))
        .collect::<Vec<_>>()
        .join(", ");
    let bind: Vec<String> = (0..bird::JOINTS.len())
        .map(|j| {
            matrix(Mat4::from_rotation_translation(
                skel.bind_rot[j],
                skel.bind_pos[j] * ws,
            ))
        })
        .collect();
    let rest: Vec<String> = (0..bird::JOINTS.len())
        .map(|j| {
            matrix(Mat4::from_rotation_translation(
                skel.rest_rotation(j),
                skel.rest_translation(j) * ws,
            ))
        })
        .collect();
    let m = &asset.mesh;
    let (counts, indices, colours) = topology(m);
    let points: Vec<String> = m.positions.iter().map(|&p| vec3(p * ws)).collect();
    let normals: Vec<String> = m.normals.iter().map(|&p| vec3(p)).collect();
    let (lo, hi) = m.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), &p| (a.min(p * ws), b.max(p * ws)),
    );
    let ji: Vec<String> = m.joints.iter().flatten().map(|j| j.to_string()).collect();
    let jw: Vec<String> = m.weights.iter().flatten().map(|&w| f(w)).collect();
    let mut s = String::new();
    let _ = writeln!(s, "class SkelRoot \"{class}\"\n{{");
    let _ = writeln!(
        s,
        "    def Skeleton \"rig\" (\n        prepend apiSchemas = [\"SkelBindingAPI\"]\n    )\n    {{"
    );
    let _ = writeln!(
        s,
        "        uniform matrix4d[] bindTransforms = [{}]",
        bind.join(", ")
    );
    let _ = writeln!(s, "        uniform token[] joints = [{joints}]");
    let _ = writeln!(
        s,
        "        uniform matrix4d[] restTransforms = [{}]\n    }}\n",
        rest.join(", ")
    );
    let _ = writeln!(
        s,
        "    def Mesh \"mesh\" (\n        prepend apiSchemas = [\"SkelBindingAPI\"]\n    )\n    {{"
    );
    let _ = writeln!(s, "        uniform bool doubleSided = 1");
    let _ = writeln!(s, "        float3[] extent = [{}, {}]", vec3(lo), vec3(hi));
    mesh_attr(&mut s, "int[] faceVertexCounts", &counts, &[]);
    mesh_attr(&mut s, "int[] faceVertexIndices", &indices, &[]);
    mesh_attr(&mut s, "normal3f[] normals", &normals, &[VERTEX]);
    mesh_attr(&mut s, "point3f[] points", &points, &[]);
    mesh_attr(
        &mut s,
        "color3f[] primvars:displayColor",
        &colours,
        &["interpolation = \"uniform\""],
    );
    let _ = writeln!(
        s,
        "        matrix4d primvars:skel:geomBindTransform = ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))"
    );
    mesh_attr(
        &mut s,
        "int[] primvars:skel:jointIndices",
        &ji,
        &["elementSize = 4", VERTEX],
    );
    mesh_attr(
        &mut s,
        "float[] primvars:skel:jointWeights",
        &jw,
        &["elementSize = 4", VERTEX],
    );
    let _ = writeln!(s, "        rel skel:skeleton = </{class}/rig>");
    let _ = writeln!(
        s,
        "        uniform token subdivisionScheme = \"none\"\n    }}\n}}\n"
    );
    s
}

/// The course as flown (turns widened), for layout: `/flock/flown_path`, a linear guide curve in
/// the flock's space (empty without a path).
pub(super) fn flown_path_prim(anim: &Animation, wingspan_m: f64) -> String {
    let ws = wingspan_m as f32;
    let mut c = String::new();
    if let Some(path) = anim.path.as_ref().filter(|p| !p.flown.is_empty()) {
        let pts: Vec<String> = path
            .flown
            .iter()
            .map(|p| {
                vec3(Vec3::new(
                    (p[0] * wingspan_m) as f32,
                    (p[2] * wingspan_m) as f32,
                    -(p[1] * wingspan_m) as f32,
                ))
            })
            .collect();
        let _ = writeln!(
            c,
            "    def BasisCurves \"flown_path\"\n    {{\n        uniform token type = \"linear\"\n        int[] curveVertexCounts = [{}]\n        point3f[] points = [{}]\n        float[] widths = [{}] (\n            interpolation = \"constant\"\n        )\n        uniform token purpose = \"guide\"\n    }}",
            pts.len(),
            pts.join(", "),
            f(ws * 0.1)
        );
    }
    c
}
