//! The skinned glTF export (issue 14), read back from the `.glb` bytes by an independent little
//! reader (JSON chunk + accessors): the skeleton follows the joint convention, the root follows the
//! animation file's positions to 1e-5 m, the wing joints turn with the wingbeat, the clips are the
//! stages, metadata is in `extras`, and `--keys reduced` stays within its tolerances.

use formation::export::bird::{self, JOINTS};
use formation::export::gltf::{glb_bytes, glb_bytes_with, SceneOptions};
use formation::export::keys::{ClipMode, KeyMode, Tolerance};
use formation::export::rig::{self, Side};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::wingbeat::{assign_phases, Flapper, WingbeatOptions};
use formation::Animation;
use glam::{Quat, Vec3};
use serde_json::Value;

const WS: f64 = 1.5;

fn flock(seconds: f64, fps: f64) -> Animation {
    let p = SyntheticParams {
        seconds,
        fps,
        initiation_s: seconds / 3.0,
        ..SyntheticParams::default()
    };
    let mut a = synthetic_flock(&mut formation::rng::seeded(7), &p);
    assign_phases(&mut a, &WingbeatOptions::default()).unwrap();
    a
}

/// A parsed `.glb`: its JSON and binary chunk.
struct Glb {
    json: Value,
    bin: Vec<u8>,
}

impl Glb {
    fn parse(bytes: &[u8]) -> Glb {
        assert_eq!(&bytes[0..4], b"glTF");
        let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json: Value = serde_json::from_slice(&bytes[20..20 + jlen]).unwrap();
        let bin = bytes[28 + jlen..].to_vec();
        Glb { json, bin }
    }

    /// Every element of accessor `i` as floats, normalised integers decoded as glTF says.
    fn floats(&self, i: u64) -> Vec<f32> {
        let a = &self.json["accessors"][i as usize];
        let v = &self.json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = v["byteLength"].as_u64().unwrap() as usize;
        let data = &self.bin[off..off + len];
        let norm = a["normalized"].as_bool().unwrap_or(false);
        match a["componentType"].as_u64().unwrap() {
            5126 => data
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                .collect(),
            5122 => data
                .chunks_exact(2)
                .map(|b| {
                    let v = i16::from_le_bytes(b.try_into().unwrap()) as f32;
                    if norm {
                        (v / 32767.0).max(-1.0)
                    } else {
                        v
                    }
                })
                .collect(),
            5120 => data
                .iter()
                .map(|&b| {
                    let v = b as i8 as f32;
                    if norm {
                        (v / 127.0).max(-1.0)
                    } else {
                        v
                    }
                })
                .collect(),
            5121 => data.iter().map(|&b| b as f32).collect(),
            c => panic!("component type {c}"),
        }
    }

    fn node_named(&self, name: &str) -> Vec<usize> {
        self.json["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .filter(|(_, n)| n["name"] == name)
            .map(|(i, _)| i)
            .collect()
    }

    /// (times, values) of the channel of clip `clip` on `node`/`path`.
    fn channel(&self, clip: &str, node: usize, path: &str) -> (Vec<f32>, Vec<f32>) {
        let anim = self.json["animations"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["name"] == clip)
            .unwrap_or_else(|| panic!("no clip {clip}"));
        let ch = anim["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["node"] == node && c["target"]["path"] == path)
            .unwrap_or_else(|| panic!("no {path} channel on node {node} in {clip}"));
        let s = &anim["samplers"][ch["sampler"].as_u64().unwrap() as usize];
        assert_eq!(s["interpolation"], "LINEAR");
        (
            self.floats(s["input"].as_u64().unwrap()),
            self.floats(s["output"].as_u64().unwrap()),
        )
    }
}

/// Linear interpolation of a keyed curve of `width` components at time `t` (the keys' own rule).
fn sample(times: &[f32], values: &[f32], width: usize, t: f32) -> Vec<f32> {
    let k = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
    let (a, b) = (k - 1, k);
    let u = ((t - times[a]) / (times[b] - times[a])).clamp(0.0, 1.0);
    (0..width)
        .map(|c| values[a * width + c] + u * (values[b * width + c] - values[a * width + c]))
        .collect()
}

fn quat(v: &[f32]) -> Quat {
    Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
}

/// The angle between two rotations, radians, from the chord between the quaternions (in f64:
/// `Quat::angle_between`'s acos of an f32 dot product near 1 is off by up to 1e-3 rad).
fn rotation_angle(a: Quat, b: Quat) -> f64 {
    let (a, b) = (a.to_array(), b.to_array());
    let chord = |s: f64| {
        (0..4)
            .map(|i| (a[i] as f64 - s * b[i] as f64).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    4.0 * (chord(1.0).min(chord(-1.0)) / 2.0).min(1.0).asin()
}

fn slerp_at(times: &[f32], values: &[f32], t: f32) -> Quat {
    let k = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
    let (a, b) = (k - 1, k);
    let u = ((t - times[a]) / (times[b] - times[a])).clamp(0.0, 1.0);
    quat(&values[a * 4..a * 4 + 4]).slerp(quat(&values[b * 4..b * 4 + 4]), u)
}

#[test]
fn skinned_rig_follows_the_convention_and_the_animation_file() {
    let anim = flock(3.0, 30.0);
    let stages = SceneOptions {
        clips: ClipMode::Stages,
        ..SceneOptions::default()
    };
    let g = Glb::parse(&glb_bytes_with(&anim, WS, &stages).unwrap());
    let j = &g.json;
    // One skin per bird, seven joints named by the convention, one inverse bind matrix each.
    let skins = j["skins"].as_array().unwrap();
    assert_eq!(skins.len(), anim.birds);
    for s in skins {
        let names: Vec<&str> = s["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| {
                j["nodes"][i.as_u64().unwrap() as usize]["name"]
                    .as_str()
                    .unwrap()
            })
            .collect();
        assert_eq!(names, JOINTS);
        let ibm = &j["accessors"][s["inverseBindMatrices"].as_u64().unwrap() as usize];
        assert_eq!(ibm["type"], "MAT4");
        assert_eq!(ibm["count"], JOINTS.len());
    }
    // One shared skinned mesh; weights are non-negative and sum to 1.
    assert_eq!(j["meshes"].as_array().unwrap().len(), 1);
    let prim = &j["meshes"][0]["primitives"][0];
    let w = g.floats(prim["attributes"]["WEIGHTS_0"].as_u64().unwrap());
    for v in w.chunks_exact(4) {
        assert!(v.iter().all(|&x| x >= 0.0));
        assert!((v.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }
    let joints = g.floats(prim["attributes"]["JOINTS_0"].as_u64().unwrap());
    assert!(joints.iter().all(|&x| x < JOINTS.len() as f32));
    // Zero-padded names that sort in bird order.
    let roots: Vec<String> = j["nodes"][g.node_named("flock")[0]]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            j["nodes"][i.as_u64().unwrap() as usize]["name"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let mut sorted = roots.clone();
    sorted.sort();
    assert_eq!(roots, sorted);
    assert_eq!(roots[0], "bird_000");
    assert_eq!(roots.len(), anim.birds);
    // Metadata.
    let x = &j["scenes"][0]["extras"];
    assert_eq!(x["fps"], 30.0);
    assert_eq!(x["wingspan_m"], WS);
    assert_eq!(x["seed"], anim.seed);
    assert_eq!(x["birds"], anim.birds);
    assert_eq!(x["species"], "goose");
    // One clip per stage, named after it, starting at 0, ending on the next stage's first frame.
    let clips: Vec<&str> = j["animations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    let stages: Vec<&str> = anim.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(clips, stages);

    let flapper = Flapper::from_animation(&anim);
    for bird in [0, 5, anim.birds - 1] {
        let root = g.node_named(&format!("bird_{bird:03}"))[0];
        let skin = &skins[bird];
        let arm_l = skin["joints"][3].as_u64().unwrap() as usize;
        let hand_r = skin["joints"][6].as_u64().unwrap() as usize;
        let mut phases_vs_lift = Vec::new();
        for st in &anim.stages {
            let (t, tr) = g.channel(&st.name, root, "translation");
            let last = st.end.min(anim.frames.len() - 1);
            assert_eq!(t.len(), last - st.start + 1);
            assert_eq!(t[0], 0.0);
            for (i, k) in (st.start..=last).enumerate() {
                let f = &anim.frames[k];
                let want = [f.x[bird] * WS, f.z[bird] * WS, -f.y[bird] * WS];
                for c in 0..3 {
                    let err = (tr[3 * i + c] as f64 - want[c]).abs();
                    assert!(err < 1e-5, "bird {bird} frame {k}: {err} m");
                }
            }
            // The wing joints carry the wingbeat pose of every frame.
            let (_, ql) = g.channel(&st.name, arm_l, "rotation");
            let (_, qr) = g.channel(&st.name, hand_r, "rotation");
            for (i, k) in (st.start..=last).enumerate() {
                let pose = flapper.pose(k, bird);
                let want_l = rig::wing_joints(&pose, Side::Left).shoulder_q;
                let want_r = rig::wing_joints(&pose, Side::Right).wrist_q;
                let (el, er) = (
                    rotation_angle(quat(&ql[4 * i..4 * i + 4]), want_l),
                    rotation_angle(quat(&qr[4 * i..4 * i + 4]), want_r),
                );
                assert!(
                    el < 1e-4 && er < 1e-4,
                    "bird {bird} frame {k}: {el}, {er} rad"
                );
                // Lift of the left arm's tip (the wing's span axis, +X, rotated).
                let lift = (quat(&ql[4 * i..4 * i + 4]) * Vec3::X).y as f64;
                let phase = anim.frames[k].wing_phase.as_ref().unwrap()[bird];
                phases_vs_lift.push((phase, lift));
            }
        }
        // The wings rotate with the wingbeat: lifted at the start of the downstroke (phase 0),
        // lowered half a beat later: the lift correlates with cos(phase).
        let n = phases_vs_lift.len() as f64;
        let mean = phases_vs_lift.iter().map(|p| p.1).sum::<f64>() / n;
        let cov: f64 = phases_vs_lift
            .iter()
            .map(|(ph, l)| ph.cos() * (l - mean))
            .sum::<f64>()
            / n;
        let sd = (phases_vs_lift
            .iter()
            .map(|p| (p.1 - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        let range = phases_vs_lift.iter().map(|p| p.1).fold(f64::MIN, f64::max)
            - phases_vs_lift.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert!(range > 0.5, "bird {bird}: the arm barely moves ({range})");
        let corr = cov / (sd * (0.5f64).sqrt());
        assert!(
            corr > 0.5,
            "bird {bird}: lift vs cos(phase) correlation {corr}"
        );
    }
}

#[test]
fn reduced_keys_stay_within_the_documented_tolerances_and_shrink_the_file() {
    let anim = flock(6.0, 30.0);
    let all = glb_bytes_with(
        &anim,
        WS,
        &SceneOptions {
            clips: ClipMode::Stages,
            ..SceneOptions::default()
        },
    )
    .unwrap();
    let opts = SceneOptions {
        keys: KeyMode::Reduced,
        clips: ClipMode::Stages,
        ..SceneOptions::default()
    };
    let red = glb_bytes_with(&anim, WS, &opts).unwrap();
    assert!(red.len() * 2 < all.len(), "{} vs {}", red.len(), all.len());
    let g = Glb::parse(&red);
    let tol = Tolerance::default();
    let skins = g.json["skins"].as_array().unwrap().clone();
    for (bird, skin) in skins.iter().enumerate() {
        let root = g.node_named(&format!("bird_{bird:03}"))[0];
        let body = skin["joints"][bird::BODY].as_u64().unwrap() as usize;
        let wing = skin["joints"][4].as_u64().unwrap() as usize;
        let exact = formation::export::gltf::bird_track(
            &anim,
            &Flapper::from_animation(&anim),
            &formation::export::bird::BirdAsset::builtin(Default::default()),
            bird,
            WS,
        );
        for st in &anim.stages {
            let (t, tr) = g.channel(&st.name, root, "translation");
            let (tq, yaw) = g.channel(&st.name, root, "rotation");
            let (tb, bank) = g.channel(&st.name, body, "rotation");
            let (tw, hand) = g.channel(&st.name, wing, "rotation");
            let t0 = anim.frames[st.start].t;
            for k in st.start..=st.end.min(anim.frames.len() - 1) {
                let f = &anim.frames[k];
                let tt = (f.t - t0) as f32;
                let p = sample(&t, &tr, 3, tt);
                let want = [f.x[bird] * WS, f.z[bird] * WS, -f.y[bird] * WS];
                let err = (0..3)
                    .map(|c| (p[c] as f64 - want[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(
                    err <= tol.position_m as f64 + 1e-4,
                    "bird {bird} frame {k}: {err} m"
                );
                let a = slerp_at(&tq, &yaw, tt).angle_between(exact.flight.yaw[k]);
                assert!(a <= tol.rotation_rad + 1e-4, "yaw {a}");
                let a = slerp_at(&tb, &bank, tt).angle_between(exact.joints[k][bird::BODY]);
                assert!(a <= tol.rotation_rad + 1e-4, "bank {a}");
                let a = slerp_at(&tw, &hand, tt).angle_between(exact.joints[k][4]);
                assert!(a <= tol.wing_rad + 2e-3, "hand {a}");
            }
        }
    }
}

/// The default: one clip, `flight`, over every stage, keyed at the animation's own times from its
/// first frame, so it plays on import; the stages as markers; the scene's timeline in `extras`.
#[test]
fn one_clip_covers_every_stage_at_the_animation_s_times() {
    let anim = flock(6.0, 30.0);
    assert!(anim.stages.len() >= 2, "a flock with stages");
    let g = Glb::parse(&glb_bytes(&anim, WS).unwrap());
    let clips: Vec<&str> = g.json["animations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert_eq!(clips, ["flight"]);
    let x = &g.json["scenes"][0]["extras"];
    assert_eq!(x["frame_start"], 0);
    assert_eq!(x["frame_end"], anim.frames.len() - 1);
    assert_eq!(x["clips"], "one");
    let markers = g.json["animations"][0]["extras"]["markers"]
        .as_array()
        .unwrap()
        .clone();
    assert_eq!(markers.len(), anim.stages.len());
    for (m, st) in markers.iter().zip(&anim.stages) {
        assert_eq!(m["name"], st.name.as_str());
        assert_eq!(m["frame"], st.start);
    }
    let t0 = anim.frames[0].t;
    for bird in [0, anim.birds - 1] {
        let root = g.node_named(&format!("bird_{bird:03}"))[0];
        let (t, tr) = g.channel("flight", root, "translation");
        assert_eq!(t.len(), anim.frames.len());
        for (k, f) in anim.frames.iter().enumerate() {
            assert!(
                (t[k] as f64 - (f.t - t0)).abs() < 1e-5,
                "frame {k}: key at {} s",
                t[k]
            );
            let want = [f.x[bird] * WS, f.z[bird] * WS, -f.y[bird] * WS];
            for c in 0..3 {
                assert!(
                    (tr[3 * k + c] as f64 - want[c]).abs() < 1e-5,
                    "bird {bird} frame {k}"
                );
            }
        }
    }
}
