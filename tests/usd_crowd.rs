//! The point-instanced crowd of the `.usda` (`--usd-mode instancer`, the default from 200 birds):
//! one instance per bird at the animation's positions, posed prototypes, every frame sampled.

mod support;

use formation::export::{crowd, write_outputs, RenderOptions, UsdMode};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;
use formation::Animation;
use support::{example, scratch};

fn flock(birds: usize, seconds: f64) -> Animation {
    let mut c = Config {
        seed: 2,
        seconds: Some(seconds),
        ..Config::default()
    };
    c.steady.birds = birds;
    Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap()
        .0
}

/// The arrays of `name.timeSamples` in the text, one per time sample, as their item texts.
fn samples(text: &str, name: &str) -> Vec<(f64, Vec<String>)> {
    let start = text.find(&format!("{name}.timeSamples = {{")).unwrap();
    text[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('}'))
        .map(|l| {
            let (code, rest) = l.trim().split_once(": ").unwrap();
            let body = rest
                .trim_end_matches(',')
                .trim_start_matches('[')
                .trim_end_matches(']');
            let items = if body.contains('(') {
                body.split("),(")
                    .map(|s| s.trim_matches(|c| c == '(' || c == ')').to_string())
                    .collect()
            } else {
                body.split(',').map(String::from).collect()
            };
            (code.parse().unwrap(), items)
        })
        .collect()
}

#[test]
fn instances_follow_the_birds_and_flap_through_the_prototypes() {
    let dir = scratch("usd-crowd");
    let a = flock(14, 4.0);
    let usda = dir.join("c.usda");
    // Birds of one size: an instance's position is then the bird's own (sizes shift it, see
    // tests/size_variation.rs).
    let opts = RenderOptions {
        usd_mode: Some(UsdMode::Instancer),
        size_variation: Some(0.0),
        ..RenderOptions::default()
    };
    write_outputs(&a, std::slice::from_ref(&usda), &opts, &Silent).unwrap();
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.contains("def PointInstancer \"crowd\""));
    assert!(!text.contains("float3[] scales"));
    assert!(!text.contains("SkelRoot"));
    let protos = text.matches("def Mesh \"pose_").count();
    assert!((2..=crowd::MAX_PROTOTYPES).contains(&protos), "{protos}");
    let pos = samples(&text, "positions");
    // Positions are metres about the crowd's translation (the flock's centre), no scale.
    assert!(!text.contains("xformOp:scale"));
    // The prototypes meet the default pose error in every stage, worst under 2.4x.
    let (_, note) = crowd::recorded_pose_error(&usda).unwrap();
    for part in note.split(", ") {
        let w: Vec<&str> = part.split_whitespace().collect();
        let mean: f64 = w[2].trim_end_matches('°').parse().unwrap();
        let worst: f64 = w[4].trim_end_matches('°').parse().unwrap();
        assert!(mean <= crowd::DEFAULT_POSE_ERROR_DEG + 0.05, "{note}");
        assert!(
            worst <= crowd::DEFAULT_POSE_ERROR_DEG * crowd::WORST_FACTOR + 0.05,
            "{note}"
        );
    }
    // Motion blur and per-instance primvars.
    let vel = samples(&text, "velocities");
    let ang = samples(&text, "angularVelocities");
    assert_eq!(vel.len(), a.frames.len());
    assert_eq!(ang.len(), a.frames.len());
    assert!(text.contains("int[] primvars:bird_id = [0,1,2,"));
    assert!(text.contains("float[] primvars:size = ["));
    let centre = samples(&text, "xformOp:translate");
    assert_eq!(centre.len(), a.frames.len());
    let rot = samples(&text, "orientations");
    let idx = samples(&text, "protoIndices");
    assert_eq!(pos.len(), a.frames.len());
    assert_eq!(rot.len(), a.frames.len());
    assert_eq!(idx.len(), a.frames.len());
    let ws = a.wingspan_m;
    let mut worst: f64 = 0.0;
    for (k, (code, items)) in pos.iter().enumerate() {
        assert_eq!(*code, k as f64);
        assert_eq!(items.len(), a.birds);
        let f = &a.frames[k];
        let c: Vec<f64> = centre[k].1[0]
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        for (b, item) in items.iter().enumerate() {
            let v: Vec<f64> = item
                .split(',')
                .zip(&c)
                .map(|(x, c)| c + x.parse::<f64>().unwrap())
                .collect();
            let want = [f.x[b] * ws, f.z[b] * ws, -f.y[b] * ws];
            let d = (0..3).map(|i| (v[i] - want[i]).powi(2)).sum::<f64>().sqrt();
            worst = worst.max(d);
        }
    }
    assert!(worst <= 1e-3, "{worst} m");
    for (_, items) in &rot {
        for q in items {
            let v: Vec<f64> = q.split(',').map(|x| x.parse().unwrap()).collect();
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((norm - 1.0).abs() < 3e-3, "{q}");
        }
    }
    // Bird 0 changes prototype as it flaps: over the steady flight it shows many poses.
    let steady = a.stage("steady").unwrap().start;
    let shown: std::collections::BTreeSet<&String> =
        idx[steady..].iter().map(|(_, i)| &i[0]).collect();
    assert!(shown.len() > 6, "{}", shown.len());
    assert!(idx
        .iter()
        .all(|(_, i)| i.iter().all(|v| v.parse::<usize>().unwrap() < protos)));
}

#[test]
fn large_flocks_get_the_instancer_by_default_and_small_ones_the_rig() {
    let dir = scratch("usd-crowd-default");
    let small = flock(9, 1.0);
    let big = flock(crowd::INSTANCER_FROM, 1.0);
    for (a, name, instancer) in [(&small, "s.usda", false), (&big, "b.usda", true)] {
        let p = dir.join(name);
        write_outputs(
            a,
            std::slice::from_ref(&p),
            &RenderOptions::default(),
            &Silent,
        )
        .unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(text.contains("def PointInstancer"), instancer, "{name}");
        assert_eq!(text.contains("def SkelRoot"), !instancer, "{name}");
    }
    // Asked for, the rig is written whatever the size.
    let p = dir.join("r.usda");
    let opts = RenderOptions {
        usd_mode: Some(UsdMode::Skel),
        ..RenderOptions::default()
    };
    write_outputs(&big, std::slice::from_ref(&p), &opts, &Silent).unwrap();
    assert!(std::fs::read_to_string(&p)
        .unwrap()
        .contains("def SkelRoot"));
}
