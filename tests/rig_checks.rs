//! A user's bird model whose joints are named otherwise: refused with the missing joints and the
//! convention's names, or mapped by `--joint-map` (then it flaps exactly as the convention's own
//! names do); a model with no skin flies without flapping and says so (an error with `--strict`).

mod support;

use formation::export::bird_model;
use formation::export::gltf::{glb_bytes, glb_bytes_with, SceneOptions};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::wingbeat::{assign_phases, Species, WingbeatOptions};
use formation::Animation;
use serde_json::Value;
use support::glb::{join, split};
use support::{bin, code, s, scratch, stderr};

fn flock() -> Animation {
    let p = SyntheticParams {
        seconds: 2.0,
        fps: 20.0,
        initiation_s: 0.7,
        ..SyntheticParams::default()
    };
    let mut a = synthetic_flock(&mut formation::rng::seeded(3), &p);
    assign_phases(&mut a, &WingbeatOptions::default()).unwrap();
    a
}

/// Our own exported bird with its joints renamed as a rig from another tool would name them.
const RENAMES: [(&str, &str); 7] = [
    ("body", "Spine"),
    ("neck", "Neck"),
    ("tail", "Tail"),
    ("upper_arm.L", "UpperArm.L"),
    ("hand.L", "Forearm.L"),
    ("upper_arm.R", "UpperArm.R"),
    ("hand.R", "Forearm.R"),
];

fn renamed(anim: &Animation) -> Vec<u8> {
    let (mut json, bin) = split(&glb_bytes(anim, 1.5).unwrap());
    for n in json["nodes"].as_array_mut().unwrap() {
        if let Some(name) = n["name"].as_str() {
            if let Some((_, to)) = RENAMES.iter().find(|(from, _)| *from == name) {
                n["name"] = Value::from(*to);
            }
        }
    }
    join(&json, &bin)
}

#[test]
fn renamed_joints_are_refused_naming_them_and_mapped_by_a_joint_map() {
    let d = scratch("rig-map");
    let anim = flock();
    let model = d.join("other.glb");
    std::fs::write(&model, renamed(&anim)).unwrap();
    let e = bird_model::load(&model, Species::Goose).unwrap_err();
    let msg = e.to_string();
    assert_eq!(e.exit_code(), 2);
    assert!(!msg.contains('\n'), "{msg}");
    for needle in [
        "body",
        "upper_arm.L",
        "hand.R",
        "UpperArm.L",
        "Forearm.L",
        "render.joint_map",
    ] {
        assert!(msg.contains(needle), "{needle}: {msg}");
    }
    // With the map, the model flaps exactly as our own (conventionally named) bird does.
    let map = d.join("map.json");
    let entries: serde_json::Map<String, Value> = RENAMES
        .iter()
        .map(|(to, from)| (from.to_string(), Value::from(*to)))
        .collect();
    std::fs::write(&map, serde_json::to_vec(&entries).unwrap()).unwrap();
    let mapped = bird_model::load_with(&model, Species::Goose, Some(&map)).unwrap();
    assert!(mapped.wingbeat);
    let ours_path = d.join("ours.glb");
    std::fs::write(&ours_path, glb_bytes(&anim, 1.5).unwrap()).unwrap();
    let ours = bird_model::load(&ours_path, Species::Goose).unwrap();
    let write = |asset| {
        let opts = SceneOptions {
            assets: vec![asset],
            ..SceneOptions::default()
        };
        split(&glb_bytes_with(&anim, 1.5, &opts).unwrap())
    };
    let (ja, ba) = write(mapped);
    let (jb, bb) = write(ours);
    assert_eq!(ja["animations"], jb["animations"]);
    assert_eq!(ba, bb, "the animation data differ");
    // Bad maps: one line naming the file and the entry.
    for (text, needle) in [
        (
            r#"{"UpperArm.L": "wing"}"#,
            "\"wing\" is not a joint of the convention",
        ),
        (
            r#"{"UpperArm.L": "upper_arm.L", "UpperArm.R": "upper_arm.L"}"#,
            "both map to upper_arm.L",
        ),
        (r#"["body"]"#, "expected a JSON object"),
        (
            r#"{"Wing.L": "upper_arm.L"}"#,
            "\"Wing.L\" is not a joint of",
        ),
    ] {
        std::fs::write(&map, text).unwrap();
        let e = bird_model::load_with(&model, Species::Goose, Some(&map)).unwrap_err();
        let m = e.to_string();
        assert_eq!(e.exit_code(), 2);
        assert!(m.contains("map.json") && m.contains(needle), "{m}");
    }
}

#[test]
fn on_the_command_line() {
    let d = scratch("rig-cli");
    let anim = flock();
    let json = d.join("a.json");
    std::fs::write(&json, serde_json::to_vec(&anim).unwrap()).unwrap();
    let model = d.join("other.glb");
    std::fs::write(&model, renamed(&anim)).unwrap();
    let out = d.join("r.glb");
    let run = |extra: &[&str]| {
        let mut args = vec!["render", s(&json), "-o", s(&out), "--bird-model", s(&model)];
        args.extend_from_slice(extra);
        bin().args(&args).output().unwrap()
    };
    let o = run(&[]);
    assert_eq!(code(&o), 2);
    let err = stderr(&o);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("--bird-model") && err.contains("--joint-map"),
        "{err}"
    );
    assert!(!out.exists());
    let map = d.join("map.json");
    let entries: serde_json::Map<String, Value> = RENAMES
        .iter()
        .map(|(to, from)| (from.to_string(), Value::from(*to)))
        .collect();
    std::fs::write(&map, serde_json::to_vec(&entries).unwrap()).unwrap();
    let o = run(&["--joint-map", s(&map), "--quiet"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(out.exists());
    // A model without a skin: a warning, an error with --strict.
    let (mut j, bin_chunk) = split(&renamed(&anim));
    for n in j["nodes"].as_array_mut().unwrap() {
        if let Some(o) = n.as_object_mut() {
            o.remove("skin");
        }
    }
    j.as_object_mut().unwrap().remove("skins");
    let stat = d.join("static.glb");
    std::fs::write(&stat, join(&j, &bin_chunk)).unwrap();
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args([
            "render",
            s(&json),
            "-o",
            s(&out),
            "--bird-model",
            s(&stat),
            "--quiet",
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no animatable joints"),
        "{}",
        stderr(&o)
    );
    let _ = std::fs::remove_file(&out);
    let o = bin()
        .args([
            "--strict",
            "render",
            s(&json),
            "-o",
            s(&out),
            "--bird-model",
            s(&stat),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("no animatable joints"));
    assert!(!out.exists());
}

/// A change to a valid model: what it breaks, the change, and what the refusal must name.
type Edit = (&'static str, Box<dyn Fn(&mut Value)>, &'static str);

/// Models that break the glTF rules in ways a reader could miss (found by probing): each is
/// refused with one line naming the accessor, view, joint or extension, before any animation.
#[test]
fn models_breaking_the_gltf_rules_are_refused_naming_the_part() {
    let d = scratch("rig-rules");
    let anim = flock();
    let (json, bin) = split(&glb_bytes(&anim, 1.5).unwrap());
    let prim = json["meshes"][0]["primitives"][0].clone();
    let pos = prim["attributes"]["POSITION"].as_u64().unwrap() as usize;
    let idx = prim["indices"].as_u64().unwrap() as usize;
    let pos_view = json["accessors"][pos]["bufferView"].as_u64().unwrap() as usize;
    let node_of = |name: &str| {
        json["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .position(|n| n["name"] == name)
            .unwrap()
    };
    let edits: Vec<Edit> = vec![
        (
            "a required extension",
            Box::new(|j| {
                j["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"])
            }),
            "requires the glTF extension KHR_draco_mesh_compression",
        ),
        (
            "a stride shorter than the element",
            Box::new(move |j| j["bufferViews"][pos_view]["byteStride"] = Value::from(4)),
            "byteStride of 4 bytes, less than one element (12 bytes)",
        ),
        (
            "byte positions",
            Box::new(move |j| j["accessors"][pos]["componentType"] = Value::from(5121)),
            "POSITION accessor",
        ),
        (
            "float indices",
            Box::new(move |j| j["accessors"][idx]["componentType"] = Value::from(5126)),
            "index accessor",
        ),
        (
            "a joint past the nodes",
            Box::new(|j| j["skins"][0]["joints"][0] = Value::from(99_999)),
            "skin: joint 0 is node 99999",
        ),
        (
            "two joints named alike",
            {
                let arm = node_of("upper_arm.L");
                Box::new(move |j| j["nodes"][arm]["name"] = Value::from("Hand_L"))
            },
            "both stand for the convention's joint \"hand.L\"",
        ),
    ];
    for (what, edit, needle) in edits {
        let mut j = json.clone();
        edit(&mut j);
        let model = d.join("bad.glb");
        std::fs::write(&model, join(&j, &bin)).unwrap();
        let e = bird_model::load(&model, Species::Goose).unwrap_err();
        let msg = e.to_string();
        assert_eq!(e.exit_code(), 2, "{what}: {msg}");
        assert!(!msg.contains('\n'), "{what}: {msg}");
        assert!(msg.contains(needle), "{what}: {msg}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A model without leg joints (the built-in crane's `leg.L`/`leg.R` renamed to names outside
/// the convention, so its legs are skinned to the nearest convention joint above them, `body`)
/// loads, flaps, and exports with no error; its legs move with the body, with no animation of
/// the convention's leg joints. The built-in crane's do move in the same take-off.
#[test]
fn a_model_without_leg_joints_flies_with_its_legs_as_modelled() {
    use formation::export::bird::{leg_joint, BirdAsset, JOINTS};
    use formation::export::rig::Side;
    let d = scratch("rig-legless");
    let anim = flock();
    let crane = |asset: BirdAsset| SceneOptions {
        assets: vec![asset],
        ..SceneOptions::default()
    };
    let builtin = BirdAsset::builtin(Species::Crane);
    assert!(builtin.has_legs());
    let ours = glb_bytes_with(&anim, 1.5, &crane(builtin)).unwrap();
    let (mut json, chunk) = split(&ours);
    for n in json["nodes"].as_array_mut().unwrap() {
        match n["name"].as_str() {
            Some("leg.L") => n["name"] = Value::from("Shin.L"),
            Some("leg.R") => n["name"] = Value::from("Shin.R"),
            _ => {}
        }
    }
    let model = d.join("legless.glb");
    std::fs::write(&model, join(&json, &chunk)).unwrap();
    let asset = bird_model::load(&model, Species::Crane).expect("a model without legs loads");
    assert!(asset.wingbeat && !asset.has_legs());
    let legs = Side::BOTH.map(leg_joint);
    assert!(asset
        .mesh
        .joints
        .iter()
        .zip(&asset.mesh.weights)
        .all(|(j, w)| (0..4).all(|k| w[k] == 0.0 || !legs.contains(&(j[k] as usize)))));
    // Channels on the leg joints: the built-in crane's legs swing in the take-off, the legless
    // model's joints stay at rest.
    let leg_channels = |bytes: &[u8]| {
        let (j, _) = split(bytes);
        let leg_nodes: Vec<u64> = j["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .filter(|(_, n)| {
                n["name"]
                    .as_str()
                    .is_some_and(|s| legs.iter().any(|&l| s.ends_with(JOINTS[l])))
            })
            .map(|(i, _)| i as u64)
            .collect();
        j["animations"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|a| a["channels"].as_array().unwrap().clone())
            .filter(|c| leg_nodes.contains(&c["target"]["node"].as_u64().unwrap()))
            .count()
    };
    assert!(leg_channels(&ours) > 0);
    let out = glb_bytes_with(&anim, 1.5, &crane(asset)).unwrap();
    assert_eq!(leg_channels(&out), 0);
    // And on the command line, to a .glb and a .usda.
    let anim_path = d.join("flock.json");
    std::fs::write(&anim_path, serde_json::to_vec(&anim).unwrap()).unwrap();
    let (glb, usda) = (d.join("r.glb"), d.join("r.usda"));
    let o = bin()
        .args([
            "render",
            s(&anim_path),
            "--bird-model",
            s(&model),
            "--quiet",
        ])
        .args(["-o", s(&glb), "-o", s(&usda)])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(glb.exists() && usda.exists());
}
