//! Numerical safety of the whole pipeline (issue 8): random valid inputs — synthetic annotated
//! movies of every shape family with random size, noise, heading and scale, random output flock
//! sizes and lengths — go through extract → steady → initiate → wingbeats → every file writer,
//! and every number in every output file must be finite (no `null` smuggled into JSON, no
//! `NaN`/`inf` in CSV). Few small cases, so that it takes seconds under `cargo test --release`.

use std::path::Path;

use formation::annotations::synth::{generate, SynthSpec};
use formation::annotations::{parse_str, ReadOptions};
use formation::export::{write_outputs, RenderOptions};
use formation::extract::ShapeKind;
use formation::pipeline::{extract_stage, initiate_stage, steady_stage, Config};
use formation::progress::Silent;
use formation::rng::seeded;
use formation::{Animation, Error};
use proptest::prelude::*;

mod support;

use support::scratch;

/// Every number of a JSON document is finite and nothing is `null` (serde_json writes a
/// non-finite `f64` as `null`).
fn assert_json_finite(path: &Path) {
    fn walk(v: &serde_json::Value, at: &str, path: &Path) {
        match v {
            serde_json::Value::Null => panic!("{}: null at {at}", path.display()),
            serde_json::Value::Number(n) => {
                let f = n.as_f64().unwrap();
                assert!(f.is_finite(), "{}: {f} at {at}", path.display());
            }
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, &format!("{at}[{i}]"), path);
                }
            }
            serde_json::Value::Object(o) => {
                for (k, x) in o {
                    walk(x, &format!("{at}.{k}"), path);
                }
            }
            _ => {}
        }
    }
    let text = std::fs::read_to_string(path).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    walk(&v, "", path);
}

/// Every field of the long CSV is a finite number (or empty, for `e`, `xi`, `wing_phase`), or a
/// stage name in `stage`.
fn assert_csv_finite(path: &Path, birds: usize, frames: usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut rows = 0;
    for (r, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), header.len(), "row {r}: {line}");
        for (name, f) in header.iter().zip(&fields) {
            if f.is_empty() && matches!(*name, "e" | "xi" | "wing_phase" | "saving_total") {
                continue;
            }
            // The one word column (docs/formats.md).
            if *name == "stage" {
                assert!(
                    matches!(*f, "initiation" | "steady" | "none"),
                    "row {r}: {f:?}"
                );
                continue;
            }
            let v: f64 = f
                .parse()
                .unwrap_or_else(|_| panic!("row {r}, {name}: {f:?}"));
            assert!(v.is_finite(), "row {r}, {name}: {f}");
        }
        rows += 1;
    }
    assert_eq!(rows, birds * frames);
}

fn assert_animation_finite(a: &Animation) {
    assert!(a.fps.is_finite() && a.wingspan_m.is_finite());
    for (k, f) in a.frames.iter().enumerate() {
        assert!(f.t.is_finite(), "frames[{k}].t");
        for (name, v) in [
            ("x", Some(&f.x)),
            ("y", Some(&f.y)),
            ("z", Some(&f.z)),
            ("heading", Some(&f.heading)),
            ("speed", Some(&f.speed)),
            ("e", f.e.as_ref()),
            ("xi", f.xi.as_ref()),
            ("wing_phase", f.wing_phase.as_ref()),
        ] {
            if let Some(v) = v {
                assert_eq!(v.len(), a.birds);
                assert!(v.iter().all(|x| x.is_finite()), "frames[{k}].{name}: {v:?}");
            }
        }
    }
    for ks in &a.key_shapes {
        for b in &ks.birds {
            assert!(b.x.is_finite() && b.y.is_finite() && b.xi.is_finite());
        }
    }
}

fn kind() -> impl Strategy<Value = ShapeKind> {
    prop_oneof![
        Just(ShapeKind::V),
        Just(ShapeKind::U),
        Just(ShapeKind::J),
        Just(ShapeKind::Line),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    #[test]
    fn every_output_of_the_pipeline_is_finite(
        kind in kind(),
        movie_birds in 5usize..12,
        movie_frames in 3usize..7,
        noise in 0.0f64..0.08,
        heading_deg in 0.0f64..360.0,
        wingspan_px in 12.0f64..80.0,
        birds in 3usize..9,
        frames in 10usize..60,
        seed in any::<u64>(),
    ) {
        let spec = SynthSpec {
            kind,
            birds: movie_birds,
            frames: movie_frames,
            noise,
            heading_deg,
            wingspan_px,
            ..SynthSpec::default()
        };
        let flock = generate(&spec, &mut seeded(seed));
        let text = flock.native_json("property test", seed % 2 == 0, &mut seeded(seed ^ 1));
        let ann = parse_str(Path::new("movie.json"), &text, &ReadOptions::default()).unwrap();
        let dir = scratch(&format!("pipeline-props-{seed}"));

        // The stages one by one, as `formation animate` runs them (each stage's result is
        // checked on its own).
        let mut config = Config { seed, seconds: None, ..Config::default() };
        config.steady.birds = birds;
        config.steady.frames = frames;
        config.initiate.max_steps = 4000;

        // extract → params file.
        let params = extract_stage(&ann, &config, &Silent).unwrap().0;
        let params_path = dir.join("params.json");
        formation::io::write_json_atomic(&params_path, &params).unwrap();
        assert_json_finite(&params_path);

        // steady → animation (may refuse a flock it cannot arrange, but only with a clean error).
        let steady = match steady_stage(&params, &config, &Silent) {
            Ok((a, _)) => a,
            Err(e @ (Error::Unreachable(_) | Error::NotConverged(_))) => {
                eprintln!("steady refused: {e}");
                let _ = std::fs::remove_dir_all(&dir);
                return Ok(());
            }
            Err(e) => panic!("steady failed on a valid input: {e}"),
        };
        assert_animation_finite(&steady);

        // initiate → the combined animation, then wingbeats.
        let mut anim = match initiate_stage(steady.clone(), &config, &Silent) {
            Ok((a, _)) => a,
            Err(Error::NotConverged(e)) => {
                eprintln!("initiation did not converge: {e}");
                steady
            }
            Err(e) => panic!("initiate failed on a valid input: {e}"),
        };
        formation::wingbeat::assign_phases(&mut anim, &config.wingbeat).unwrap();
        assert_animation_finite(&anim);

        // Every file writer.
        let outs = ["a.json", "a.csv", "a.glb"].map(|n| dir.join(n));
        write_outputs(&anim, &outs, &RenderOptions::default(), &Silent).unwrap();
        assert_json_finite(&outs[0]);
        assert_csv_finite(&outs[1], anim.birds, anim.frames.len());
        let back = Animation::read(&outs[0]).unwrap();
        assert_animation_finite(&back);
        prop_assert!(std::fs::metadata(&outs[2]).unwrap().len() > 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
