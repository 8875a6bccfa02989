//! Several `--bird-model`s across one flock: the models shared out over the birds at random
//! (seeded, every model on the same number of birds to one), each model's mesh and skin data
//! written once and reused by its birds, the assignment recorded in the metadata, and the USD
//! rig and crowd holding one class or one set of prototypes per model.

mod support;

use formation::export::bird::{model_assignment, BirdAsset};
use formation::export::bird_model;
use formation::export::crowd;
use formation::export::gltf::{glb_bytes_with, SceneOptions};
use formation::export::usd::write_usda;
use formation::wingbeat::Species;
use formation::Animation;
use serde_json::{json, Value};
use std::path::Path;
use support::glb::{join, json};
use support::{bin, code, data, s, scratch, stderr};

fn flock() -> Animation {
    let text = std::fs::read_to_string(data("flock_small.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A static "bird": one flat diamond, 4 units across X.
fn static_bird() -> Vec<u8> {
    let pos: [f32; 12] = [-2.0, 0.0, 0.0, 0.0, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0, 0.0, -0.5];
    let idx: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let mut b: Vec<u8> = pos.iter().flat_map(|v| v.to_le_bytes()).collect();
    b.extend(idx.iter().flat_map(|v| v.to_le_bytes()));
    join(
        &json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [-2.0, 0.0, -0.5], "max": [2.0, 0.0, 0.5]},
                {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}
            ],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 48},
                {"buffer": 0, "byteOffset": 48, "byteLength": 24}
            ],
            "buffers": [{"byteLength": 72}]
        }),
        &b,
    )
}

fn two_models() -> SceneOptions {
    let still = bird_model::parse(Path::new("still.glb"), &static_bird(), Species::Goose).unwrap();
    assert!(!still.wingbeat);
    SceneOptions {
        assets: vec![BirdAsset::builtin(Species::Goose), still],
        ..SceneOptions::default()
    }
}

#[test]
fn each_bird_wears_its_assigned_model_in_gltf_and_usd() {
    let a = flock();
    assert!(a.birds >= 4, "{}", a.birds);
    let opts = two_models();
    let bytes = glb_bytes_with(&a, a.wingspan_m, &opts).unwrap();
    assert_eq!(bytes, glb_bytes_with(&a, a.wingspan_m, &opts).unwrap());
    let j = json(&bytes);
    let want = model_assignment(a.seed, a.birds, 2);
    let ones = want.iter().filter(|&&m| m == 1).count();
    assert!(
        ones == a.birds / 2 || ones == a.birds.div_ceil(2),
        "{want:?}"
    );
    // The assignment in the scene's extras and on every bird root.
    let e = &j["scenes"][0]["extras"];
    assert_eq!(e["bird_model"], json!(["built-in goose", "still.glb"]));
    assert_eq!(e["bird_model_of"], json!(want));
    // One mesh per model, reused: each bird's mesh node shows its model's mesh.
    let meshes: Vec<&str> = j["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(meshes, ["bird_model_0", "bird_model_1"]);
    let nodes = j["nodes"].as_array().unwrap();
    let node = |name: &str| nodes.iter().position(|n| n["name"] == name).unwrap();
    // Which nodes the clip turns.
    let turned: Vec<usize> = j["animations"][0]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["target"]["path"] == "rotation")
        .map(|c| c["target"]["node"].as_u64().unwrap() as usize)
        .collect();
    for (b, &m) in want.iter().enumerate() {
        let root = &nodes[node(&format!("bird_{b:03}"))];
        assert_eq!(root["extras"]["bird_model"], json!(m), "bird {b}");
        let mesh_node = &nodes[node(&format!("bird_{b:03}_mesh"))];
        assert_eq!(mesh_node["mesh"], json!(m), "bird {b}");
        // The skinned goose flaps (its left hand turns), the static model does not.
        let skin = &j["skins"][mesh_node["skin"].as_u64().unwrap() as usize];
        let hand = skin["joints"][4].as_u64().unwrap() as usize;
        assert_eq!(nodes[hand]["name"], "hand.L");
        assert_eq!(turned.contains(&hand), m == 0, "bird {b}");
        // Each model's inverse bind matrices, shared by its birds.
        let ibm = skin["inverseBindMatrices"].as_u64().unwrap();
        let first = want.iter().position(|&x| x == m).unwrap();
        let first_skin = &j["skins"][nodes[node(&format!("bird_{first:03}_mesh"))]["skin"]
            .as_u64()
            .unwrap() as usize];
        assert_eq!(first_skin["inverseBindMatrices"].as_u64().unwrap(), ibm);
    }

    // USD, the rig: one class per model, each bird referencing its own.
    let mut text = Vec::new();
    write_usda(&a, a.wingspan_m, &opts, &mut text).unwrap();
    let text = String::from_utf8(text).unwrap();
    assert!(text.contains("class SkelRoot \"_bird\""));
    assert!(text.contains("class SkelRoot \"_bird_1\""));
    assert!(text.contains("rel skel:skeleton = </_bird_1/rig>"));
    for (b, &m) in want.iter().enumerate() {
        let at = text.find(&format!("def SkelRoot \"bird_{b:03}\"")).unwrap();
        let class = if m == 0 { "_bird" } else { "_bird_1" };
        assert!(
            text[at..].starts_with(&format!(
                "def SkelRoot \"bird_{b:03}\" (\n        prepend references = </{class}>"
            )),
            "bird {b}"
        );
    }
    assert!(text.contains("string[] bird_model = [\"built-in goose\", \"still.glb\"]"));

    // USD, the crowd: the goose's 24 poses, then the static model's one.
    let mut c = Vec::new();
    crowd::write_usda_instancer(&a, a.wingspan_m, &opts, &mut c).unwrap();
    let c = String::from_utf8(c).unwrap();
    // The goose's prototypes (as many as the pose error needs), then the static bird's one.
    let protos = c.matches("def Mesh \"model_0_pose_").count();
    assert!((2..=crowd::MAX_PROTOTYPES).contains(&protos), "{protos}");
    assert_eq!(c.matches("def Mesh \"model_1_pose_").count(), 1);
    let start = c.find("protoIndices.timeSamples = {").unwrap();
    let mut flapped = std::collections::BTreeSet::new();
    for line in c[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('}'))
    {
        let body = line.split_once(": [").unwrap().1.trim_end_matches("],");
        let idx: Vec<usize> = body.split(',').map(|x| x.parse().unwrap()).collect();
        for (b, &m) in want.iter().enumerate() {
            if m == 1 {
                assert_eq!(idx[b], protos, "static bird {b}");
            } else {
                assert!(idx[b] < protos, "goose {b}: {}", idx[b]);
                flapped.insert(idx[b]);
            }
        }
    }
    assert!(flapped.len() > 3, "{flapped:?}");
}

#[test]
fn one_model_keeps_the_single_model_layout() {
    let a = flock();
    let still = bird_model::parse(Path::new("still.glb"), &static_bird(), Species::Goose).unwrap();
    let opts = SceneOptions {
        assets: vec![still],
        ..SceneOptions::default()
    };
    let j = json(&glb_bytes_with(&a, a.wingspan_m, &opts).unwrap());
    assert_eq!(j["scenes"][0]["extras"]["bird_model"], "still.glb");
    assert!(j["scenes"][0]["extras"].get("bird_model_of").is_none());
    assert_eq!(j["meshes"][0]["name"], "bird");
    assert_eq!(j["meshes"].as_array().unwrap().len(), 1);
}

#[test]
fn the_cli_takes_several_models_and_refuses_mismatched_maps() {
    let dir = scratch("bird-models");
    let still = dir.join("still.glb");
    std::fs::write(&still, static_bird()).unwrap();
    let other = dir.join("other.glb");
    std::fs::write(&other, static_bird()).unwrap();
    let map = dir.join("map.json");
    std::fs::write(&map, "{}").unwrap();
    let anim = s(&data("flock_small.json")).to_string();
    let out = dir.join("f.glb");
    let run = |extra: &[&str]| {
        let mut args = vec!["render", anim.as_str(), "-o", s(&out), "--quiet"];
        args.extend_from_slice(extra);
        bin().args(&args).output().unwrap()
    };
    let o = run(&["--bird-model", s(&still), "--bird-model", s(&other)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let j = json(&std::fs::read(&out).unwrap());
    assert_eq!(j["meshes"].as_array().unwrap().len(), 2);
    std::fs::remove_file(&out).unwrap();
    // Two maps for three models.
    let o = run(&[
        "--bird-model",
        s(&still),
        "--bird-model",
        s(&other),
        "--bird-model",
        s(&still),
        "--joint-map",
        s(&map),
        "--joint-map",
        s(&map),
    ]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("--joint-map") && err.contains("2 joint maps for 3 bird models"),
        "{err}"
    );
    assert!(!out.exists());
    // Too many models.
    let many: Vec<&str> = (0..=bird_model::MAX_MODELS)
        .flat_map(|_| ["--bird-model", s(&still)])
        .collect();
    let o = run(&many);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(
        err.contains("--bird-model") && err.contains("at most 16"),
        "{err}"
    );
    // A bad second model is named.
    let bad = dir.join("bad.glb");
    std::fs::write(&bad, b"not a glb").unwrap();
    let o = run(&["--bird-model", s(&still), "--bird-model", s(&bad)]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(err.contains("bad.glb"), "{err}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The floats of accessor `i` of a `.glb`.
fn floats(bytes: &[u8], j: &Value, i: &Value) -> Vec<f32> {
    let acc = &j["accessors"][i.as_u64().unwrap() as usize];
    let view = &j["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = &bytes[20 + jlen + 8..];
    let o = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let l = view["byteLength"].as_u64().unwrap() as usize;
    bin[o..o + l]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

#[test]
fn the_built_in_bird_is_one_primitive_coloured_by_its_vertices() {
    let a = flock();
    let bytes = glb_bytes_with(&a, a.wingspan_m, &SceneOptions::default()).unwrap();
    let j = json(&bytes);
    let goose = BirdAsset::builtin(Species::Goose);
    assert_eq!(j["meshes"].as_array().unwrap().len(), 1);
    let prims = j["meshes"][0]["primitives"].as_array().unwrap();
    assert_eq!(prims.len(), 1, "one draw call a bird");
    assert_eq!(j["materials"].as_array().unwrap().len(), 1);
    let p = &prims[0];
    let triangles: usize = goose.mesh.parts.iter().map(|(_, i)| i.len()).sum();
    assert_eq!(
        j["accessors"][p["indices"].as_u64().unwrap() as usize]["count"],
        json!(triangles)
    );
    let pos = floats(&bytes, &j, &p["attributes"]["POSITION"]);
    let col = floats(&bytes, &j, &p["attributes"]["COLOR_0"]);
    assert_eq!(pos.len(), col.len());
    assert!(pos.len() / 3 >= goose.mesh.positions.len());
    // The colours are the parts' own, and each part's triangles show its colour.
    let mut seen: Vec<[f32; 3]> = col.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    seen.sort_by(|x, y| x.partial_cmp(y).unwrap());
    seen.dedup();
    let mut want = goose.mesh.colours.clone();
    want.sort_by(|x, y| x.partial_cmp(y).unwrap());
    want.dedup();
    assert_eq!(seen, want);
    let acc = &j["accessors"][p["indices"].as_u64().unwrap() as usize];
    assert_eq!(acc["componentType"], 5123, "u16 indices");
    let view = &j["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let o = 20 + jlen + 8 + view["byteOffset"].as_u64().unwrap() as usize;
    let idx: Vec<usize> = bytes[o..o + 2 * triangles]
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]) as usize)
        .collect();
    let mut k = 0;
    for ((_, part), rgb) in goose.mesh.parts.iter().zip(&goose.mesh.colours) {
        for _ in 0..part.len() {
            let v = idx[k];
            assert_eq!(&col[3 * v..3 * v + 3], rgb, "index {k}");
            k += 1;
        }
    }
}
