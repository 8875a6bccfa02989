//! The `.glb` of a large flock as one skeleton (`render.gltf_mode` = flock): the same birds as
//! the one-skin-per-bird file, read back from the bytes. Every bird's nodes carry the same
//! transforms and the same animation; each part of the flock is one mesh holding a copy of the
//! bird per bird, bound to that bird's own joints (its root first, bound to nothing, its bind at
//! the origin); colours and weights are normalised bytes whose weights sum to exactly 255.

mod support;

use formation::export::bird::JOINTS;
use formation::export::gltf::{bird_digits, glb_bytes_with, SceneOptions, FLOCK_PART};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::wingbeat::{assign_phases, WingbeatOptions};
use formation::Animation;
use serde_json::Value;
use support::glb::split;

fn flock(birds: usize) -> Animation {
    let p = SyntheticParams {
        birds,
        seconds: 2.0,
        fps: 30.0,
        initiation_s: 0.5,
        ..SyntheticParams::default()
    };
    let mut a = synthetic_flock(&mut formation::rng::seeded(11), &p);
    assign_phases(&mut a, &WingbeatOptions::default()).unwrap();
    a
}

/// The raw bytes of accessor `i` and its component type.
fn raw<'a>(json: &Value, bin: &'a [u8], i: &Value) -> (&'a [u8], u64) {
    let a = &json["accessors"][i.as_u64().unwrap() as usize];
    let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = v["byteLength"].as_u64().unwrap() as usize;
    (&bin[off..off + len], a["componentType"].as_u64().unwrap())
}

fn floats(json: &Value, bin: &[u8], i: &Value) -> Vec<f32> {
    let (data, ct) = raw(json, bin, i);
    assert_eq!(ct, 5126);
    data.chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

/// Unsigned integers of any width (bytes, shorts, ints).
fn uints(json: &Value, bin: &[u8], i: &Value) -> Vec<u32> {
    let (data, ct) = raw(json, bin, i);
    match ct {
        5121 => data.iter().map(|&b| u32::from(b)).collect(),
        5123 => data
            .chunks_exact(2)
            .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]])))
            .collect(),
        5125 => data
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect(),
        c => panic!("component type {c}"),
    }
}

fn node_index(json: &Value, name: &str) -> usize {
    json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n["name"] == name)
        .unwrap_or_else(|| panic!("no node {name}"))
}

#[test]
fn the_flock_as_one_skeleton_is_the_same_birds_as_one_skin_each() {
    let birds = FLOCK_PART + 6;
    let a = flock(birds);
    let base = SceneOptions {
        size_variation: 0.05,
        ..SceneOptions::default()
    };
    let one = SceneOptions {
        one_skin: true,
        ..base.clone()
    };
    let (bj, bb) = split(&glb_bytes_with(&a, 1.5, &base).unwrap());
    let (fj, fb) = split(&glb_bytes_with(&a, 1.5, &one).unwrap());
    let digits = bird_digits(birds);
    let name = |b: usize| format!("bird_{b:0digits$}");

    // Nodes: every bird's root and joints with the same transforms (names carry the bird).
    for b in [0, 1, FLOCK_PART, birds - 1] {
        let root_b = &bj["nodes"][node_index(&bj, &name(b))];
        let root_f = &fj["nodes"][node_index(&fj, &name(b))];
        for key in ["translation", "rotation", "scale"] {
            assert_eq!(root_b[key], root_f[key], "bird {b} {key}");
        }
    }
    // Skins and meshes: one per part, JOINTS.len() + 1 joints a bird (root first).
    let per = JOINTS.len() + 1;
    let parts = birds.div_ceil(FLOCK_PART);
    assert_eq!(fj["skins"].as_array().unwrap().len(), parts);
    assert_eq!(fj["meshes"].as_array().unwrap().len(), parts);
    let bird_skin = &bj["skins"][0];
    let bird_ibm = floats(&bj, &bb, &bird_skin["inverseBindMatrices"]);
    let bird_prim = &bj["meshes"][bird_skin_mesh(&bj)]["primitives"][0];
    let bird_pos = floats(&bj, &bb, &bird_prim["attributes"]["POSITION"]);
    let bird_joints = uints(&bj, &bb, &bird_prim["attributes"]["JOINTS_0"]);
    let bird_weights = floats(&bj, &bb, &bird_prim["attributes"]["WEIGHTS_0"]);
    let bird_idx = uints(&bj, &bb, &bird_prim["indices"]);
    let verts = bird_pos.len() / 3;
    let identity: Vec<f32> = glam::Mat4::IDENTITY.to_cols_array().to_vec();
    for p in 0..parts {
        let first = p * FLOCK_PART;
        let n = (birds - first).min(FLOCK_PART);
        let skin = &fj["skins"][p];
        let joints = skin["joints"].as_array().unwrap();
        assert_eq!(joints.len(), per * n);
        for i in 0..n {
            assert_eq!(
                fj["nodes"][joints[per * i].as_u64().unwrap() as usize]["name"],
                name(first + i).as_str()
            );
            for (j, joint) in JOINTS.iter().enumerate() {
                assert_eq!(
                    fj["nodes"][joints[per * i + 1 + j].as_u64().unwrap() as usize]["name"],
                    format!("{}.{joint}", name(first + i)).as_str()
                );
            }
        }
        // The part's skeleton: a node of its own (one armature a part in Blender) holding
        // exactly the part's birds, under the flock node.
        let part = skin["skeleton"].as_u64().unwrap() as usize;
        let part_node = &fj["nodes"][part];
        assert_eq!(
            part_node["name"],
            format!("flock_{p:0width$}", width = bird_digits(parts)).as_str()
        );
        let roots: Vec<&Value> = (0..n).map(|i| &joints[per * i]).collect();
        assert_eq!(
            part_node["children"]
                .as_array()
                .unwrap()
                .iter()
                .collect::<Vec<_>>(),
            roots
        );
        assert!(fj["nodes"][node_index(&fj, "flock")]["children"]
            .as_array()
            .unwrap()
            .contains(&Value::from(part)));
        let ibm = floats(&fj, &fb, &skin["inverseBindMatrices"]);
        assert_eq!(ibm.len(), 16 * per * n);
        for i in 0..n {
            assert_eq!(
                &ibm[16 * per * i..16 * per * i + 16],
                &identity[..],
                "root bind"
            );
            assert_eq!(&ibm[16 * per * i + 16..16 * per * (i + 1)], &bird_ibm[..]);
        }
        let prim = &fj["meshes"][mesh_of_skin(&fj, p)]["primitives"][0];
        let pos = floats(&fj, &fb, &prim["attributes"]["POSITION"]);
        assert_eq!(pos.len(), 3 * verts * n);
        let jw = uints(&fj, &fb, &prim["attributes"]["JOINTS_0"]);
        let (wb, ct) = raw(&fj, &fb, &prim["attributes"]["WEIGHTS_0"]);
        assert_eq!(ct, 5121);
        let idx = uints(&fj, &fb, &prim["indices"]);
        assert_eq!(idx.len(), bird_idx.len() * n);
        for i in 0..n {
            // Each bird's copy: the same positions, triangles and weights, its own joints.
            assert_eq!(&pos[3 * verts * i..3 * verts * (i + 1)], &bird_pos[..]);
            for (t, &v) in bird_idx.iter().enumerate() {
                assert_eq!(idx[bird_idx.len() * i + t], v + (verts * i) as u32);
            }
            for v in 0..verts {
                let w = &wb[4 * (verts * i + v)..4 * (verts * i + v + 1)];
                assert_eq!(w.iter().map(|&x| u32::from(x)).sum::<u32>(), 255);
                for k in 0..4 {
                    let (fw, bw) = (f32::from(w[k]) / 255.0, bird_weights[4 * v + k]);
                    assert!((fw - bw).abs() <= 1.0 / 255.0 + 1e-6, "weight {fw} vs {bw}");
                    let j = jw[4 * (verts * i + v) + k] as usize;
                    if w[k] > 0 {
                        assert_eq!(j, per * i + 1 + bird_joints[4 * v + k] as usize);
                    } else {
                        assert_eq!(j, 0, "an unused slot names joint 0");
                    }
                }
            }
        }
    }
    // Animation: the same channels on the same-named nodes with the same keys.
    let names = |json: &Value| -> Vec<String> {
        json["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n["name"].as_str().unwrap_or("").to_string())
            .collect()
    };
    let (bn, fnames) = (names(&bj), names(&fj));
    let channels_b = bj["animations"][0]["channels"].as_array().unwrap();
    let channels_f = fj["animations"][0]["channels"].as_array().unwrap();
    assert_eq!(channels_b.len(), channels_f.len());
    let mut bird_nodes_b: Vec<String> = Vec::new();
    for (cb, cf) in channels_b.iter().zip(channels_f) {
        assert_eq!(cb["target"]["path"], cf["target"]["path"]);
        let nb = cb["target"]["node"].as_u64().unwrap() as usize;
        let nf = cf["target"]["node"].as_u64().unwrap() as usize;
        // The per-bird file names joints alone ("upper_arm.L"), after their bird's root channel.
        let full = fnames[nf].clone();
        if bn[nb].starts_with("bird_") {
            bird_nodes_b.push(bn[nb].clone());
            assert_eq!(bn[nb], full);
        } else {
            let owner = bird_nodes_b
                .last()
                .expect("a bird's root channel comes first");
            assert_eq!(format!("{owner}.{}", bn[nb]), full);
        }
        let sb = &bj["animations"][0]["samplers"][cb["sampler"].as_u64().unwrap() as usize];
        let sf = &fj["animations"][0]["samplers"][cf["sampler"].as_u64().unwrap() as usize];
        for key in ["input", "output"] {
            assert_eq!(
                raw(&bj, &bb, &sb[key]).0,
                raw(&fj, &fb, &sf[key]).0,
                "{full} {key}"
            );
        }
    }
}

/// The mesh of the per-bird file's first skinned node.
fn bird_skin_mesh(json: &Value) -> usize {
    json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["skin"] == 0)
        .unwrap()["mesh"]
        .as_u64()
        .unwrap() as usize
}

/// The mesh of the node that wears skin `s`.
fn mesh_of_skin(json: &Value, s: usize) -> usize {
    json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["skin"] == s)
        .unwrap()["mesh"]
        .as_u64()
        .unwrap() as usize
}

#[test]
fn large_flocks_get_one_skeleton_by_default_and_small_ones_a_rig_each() {
    let dir = support::scratch("gltf_flock_default");
    for (birds, skins) in [(12usize, 12usize), (200, 200usize.div_ceil(FLOCK_PART))] {
        let json = dir.join(format!("f{birds}.json"));
        let glb = dir.join(format!("f{birds}.glb"));
        let out = support::bin()
            .args(["animate", "--birds", &birds.to_string(), "--seconds", "1"])
            .args(["--no-initiation", "--quiet"])
            .arg(support::example("barnacle_geese_v.json"))
            .arg("-o")
            .arg(&json)
            .arg("-o")
            .arg(&glb)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc = support::glb::json(&std::fs::read(&glb).unwrap());
        assert_eq!(
            doc["skins"].as_array().unwrap().len(),
            skins,
            "{birds} birds"
        );
        // Asked for, the other mode.
        let other = dir.join(format!("f{birds}_other.glb"));
        let mode = if birds < 200 { "flock" } else { "birds" };
        let out = support::bin()
            .args(["render", "--quiet", "--gltf-mode", mode])
            .arg(&json)
            .arg("-o")
            .arg(&other)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc = support::glb::json(&std::fs::read(&other).unwrap());
        let want = if birds < 200 { 1 } else { birds };
        assert_eq!(
            doc["skins"].as_array().unwrap().len(),
            want,
            "{birds} birds, {mode}"
        );
    }
}
