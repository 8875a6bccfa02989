//! `--bird-model FILE.glb` (issue 14): a static model is placed on every bird, scaled to the
//! wingspan by its bounding box and bound to `body`; a skinned model following the joint
//! convention gets the wingbeat; bad files are refused with exit code 2 and the reason.

use std::path::Path;

use formation::export::bird_model::{self, MAX_VERTICES};
use formation::export::gltf::{glb_bytes, glb_bytes_with, SceneOptions};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::wingbeat::{assign_phases, Species, WingbeatOptions};
use formation::Animation;
use serde_json::json;

mod support;

use support::glb::{join, json};
use support::scratch;

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

/// A static "bird" of `n` vertices (a fan of triangles) 4 units across X and 1 along Z, under a
/// node that moves it by (10, 0, 0) and scales it by 2.
fn static_bird(n: usize) -> Vec<u8> {
    let mut pos = Vec::new();
    for i in 0..n {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        pos.extend_from_slice(&[2.0 * a.cos(), 0.1 * (3.0 * a).sin(), 0.5 * a.sin()]);
    }
    let idx: Vec<u32> = (1..n as u32 - 1).flat_map(|i| [0, i, i + 1]).collect();
    let mut bin: Vec<u8> = pos.iter().flat_map(|v| v.to_le_bytes()).collect();
    let ioff = bin.len();
    bin.extend(idx.iter().flat_map(|v| v.to_le_bytes()));
    let (lo, hi) = ([-2.0, -0.1, -0.5], [2.0, 0.1, 0.5]);
    join(
        &json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1.0]}}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi},
                {"bufferView": 1, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}
            ],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": ioff},
                {"buffer": 0, "byteOffset": ioff, "byteLength": idx.len() * 4}
            ],
            "buffers": [{"byteLength": bin.len()}]
        }),
        &bin,
    )
}

#[test]
fn a_static_model_is_scaled_to_the_wingspan_and_bound_to_the_body() {
    let d = scratch("static");
    let path = d.join("bird.glb");
    std::fs::write(&path, static_bird(40)).unwrap();
    let asset = bird_model::load(&path, Species::Goose).unwrap();
    assert!(!asset.wingbeat);
    let xs: Vec<f32> = asset.mesh.positions.iter().map(|p| p.x).collect();
    let w =
        xs.iter().cloned().fold(f32::MIN, f32::max) - xs.iter().cloned().fold(f32::MAX, f32::min);
    assert!((w - 1.0).abs() < 1e-5, "span {w} wingspans");
    assert!(asset.mesh.joints.iter().all(|j| j[0] == 0));
    let anim = flock();
    let opts = SceneOptions {
        assets: vec![asset],
        ..SceneOptions::default()
    };
    let bytes = glb_bytes_with(&anim, 1.5, &opts).unwrap();
    let g = json(&bytes);
    let pos = &g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize];
    let span = pos["max"][0].as_f64().unwrap() - pos["min"][0].as_f64().unwrap();
    assert!((span - 1.5).abs() < 1e-4, "{span} m");
    // Flight and bank only: per bird root translation, rotation and body rotation.
    for a in g["animations"].as_array().unwrap() {
        assert_eq!(a["channels"].as_array().unwrap().len(), 3 * anim.birds);
    }
    // The model's colour as the vertices' COLOR_0 under one white material (one draw call).
    assert_eq!(g["materials"].as_array().unwrap().len(), 1);
    assert_eq!(
        g["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"],
        json!([1.0, 1.0, 1.0, 1.0])
    );
    let acc = &g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"]
        .as_u64()
        .unwrap() as usize];
    let view = &g["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = &bytes[20 + jlen + 8..];
    let o = view["byteOffset"].as_u64().unwrap() as usize;
    let rgb: Vec<f32> = bin[o..o + 12]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(rgb, [0.8, 0.1, 0.1]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_skinned_model_with_the_convention_flaps_like_the_built_in_bird() {
    let d = scratch("skinned");
    let anim = flock();
    let path = d.join("ours.glb");
    std::fs::write(&path, glb_bytes(&anim, 1.5).unwrap()).unwrap();
    let asset = bird_model::load(&path, Species::Goose).unwrap();
    assert!(asset.wingbeat);
    let opts = SceneOptions {
        assets: vec![asset],
        ..SceneOptions::default()
    };
    let theirs = json(&glb_bytes_with(&anim, 1.5, &opts).unwrap());
    let ours = json(&glb_bytes(&anim, 1.5).unwrap());
    // Same channels (wing and tail joints included) as the built-in bird.
    for (a, b) in theirs["animations"]
        .as_array()
        .unwrap()
        .iter()
        .zip(ours["animations"].as_array().unwrap())
    {
        assert_eq!(
            a["channels"].as_array().unwrap().len(),
            b["channels"].as_array().unwrap().len()
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}

fn refused(path: &Path, needle: &str) {
    let e = bird_model::load(path, Species::Goose).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "{msg}");
    assert!(
        msg.contains("render.bird_model") && msg.contains(needle),
        "{msg}"
    );
}

#[test]
fn bad_models_are_refused_with_the_reason() {
    let d = scratch("bad");
    let p = d.join("x.glb");
    std::fs::write(&p, b"{\"asset\": {\"version\": \"2.0\"}}").unwrap();
    refused(&p, "not a binary .glb");
    std::fs::write(&p, b"PK\x03\x04 a zip file").unwrap();
    refused(&p, "not a glTF binary");
    std::fs::write(
        &p,
        join(
            &json!({"asset": {"version": "2.0"}, "nodes": [{"name": "empty"}]}),
            &[],
        ),
    )
    .unwrap();
    refused(&p, "no triangle mesh");
    std::fs::write(&p, static_bird(MAX_VERTICES + 10)).unwrap();
    refused(&p, "vertices");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(bird_model::MAX_BYTES + 1).unwrap();
    refused(&p, "byte limit");
    let mut trunc = static_bird(40);
    trunc.truncate(trunc.len() - 100);
    std::fs::write(&p, trunc).unwrap();
    refused(&p, "truncated");
    refused(&d.join("missing.glb"), "cannot read");
    std::fs::remove_dir_all(&d).unwrap();
}
