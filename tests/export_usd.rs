//! The `.usda` export (issue 14), read back as text: stage metadata, one SkelRoot, Skeleton and
//! SkelAnimation per bird, and the birds' time samples equal to the animation file's positions.
//! (CI also opens the file with Pixar's usd-core and runs its validators: `.ci/check_usd.py`.)

use formation::export::gltf::SceneOptions;
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::export::usd::write_usda;
use formation::wingbeat::{assign_phases, WingbeatOptions};

#[test]
fn usda_has_the_stage_metadata_and_the_flight_of_every_bird() {
    let p = SyntheticParams {
        seconds: 3.0,
        fps: 24.0,
        initiation_s: 1.0,
        ..SyntheticParams::default()
    };
    let mut anim = synthetic_flock(&mut formation::rng::seeded(5), &p);
    assign_phases(&mut anim, &WingbeatOptions::default()).unwrap();
    let mut out = Vec::new();
    write_usda(&anim, 1.5, &SceneOptions::default(), &mut out).unwrap();
    let mut again = Vec::new();
    write_usda(&anim, 1.5, &SceneOptions::default(), &mut again).unwrap();
    assert!(out == again, "equal inputs give byte-identical .usda");
    let text = String::from_utf8(out).unwrap();
    assert!(text.starts_with("#usda 1.0\n"));
    let n = anim.frames.len();
    for line in [
        "metersPerUnit = 1".to_string(),
        "upAxis = \"Y\"".into(),
        "timeCodesPerSecond = 24".into(),
        "framesPerSecond = 24".into(),
        "startTimeCode = 0".into(),
        format!("endTimeCode = {}", n - 1),
        "defaultPrim = \"flock\"".into(),
    ] {
        assert!(text.contains(&line), "missing {line}");
    }
    assert_eq!(text.matches("def SkelRoot \"bird_").count(), anim.birds);
    assert_eq!(
        text.matches("def SkelAnimation \"anim\"").count(),
        anim.birds
    );
    assert_eq!(
        text.matches("def Skeleton \"rig\"").count(),
        1,
        "one shared skeleton class"
    );
    // bird_003's translate samples: one per frame, equal to (x, z, −y) × wingspan.
    let start = text.find("def SkelRoot \"bird_003\"").unwrap();
    let block = &text[start..];
    let ts = block.find("xformOp:translate.timeSamples = {").unwrap();
    let end = block[ts..].find('}').unwrap();
    let samples: Vec<(usize, [f64; 3])> = block[ts..ts + end]
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let (k, v) = l.trim().trim_end_matches(',').split_once(": ").unwrap();
            let v: Vec<f64> = v
                .trim_matches(|c| c == '(' || c == ')')
                .split(", ")
                .map(|x| x.parse().unwrap())
                .collect();
            (k.parse().unwrap(), [v[0], v[1], v[2]])
        })
        .collect();
    assert_eq!(samples.len(), n);
    for (k, v) in samples {
        let f = &anim.frames[k];
        let want = [f.x[3] * 1.5, f.z[3] * 1.5, -f.y[3] * 1.5];
        for c in 0..3 {
            assert!(
                (v[c] - want[c]).abs() < 1e-5,
                "frame {k}: {v:?} vs {want:?}"
            );
        }
    }
}
