//! The flapping check (docs/model.md, "A flapping check"): the stored output of
//! `scripts/flapping_check.py` (an unsteady vortex-lattice solver run on rigid and flapping
//! wings at the field's offsets) beside the tool's own follower savings at the same offsets.
//!
//! - the table in docs/model.md is generated here from the stored file and the tool's models, and
//!   must appear there verbatim (`cargo test --release --test flapping_check -- --nocapture`
//!   prints it);
//! - the stored savings and ratios are recomputed from the stored powers and lifts, so the file
//!   cannot say one thing in its numbers and another in its summary;
//! - the ratio the summaries print is the stored median: checked on `formation power`'s output
//!   and on the compiled-in copy of the file.

use formation::aero::flapping::{flapping_check, flapping_note, FLAPPING_CHECK_JSON};
use formation::aero::{AeroModel, AeroOptions, Wake};
use serde_json::Value;
use std::process::Command;

fn repo(p: &str) -> String {
    format!("{}/{p}", env!("CARGO_MANIFEST_DIR"))
}

fn stored() -> Value {
    let text = std::fs::read_to_string(repo("tests/data/flapping_check.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The last follower's saving with the tool's `model` and `wake` in the stored formation.
fn tool(positions: &[[f64; 3]], model: AeroModel, wake: Wake) -> f64 {
    let x: Vec<f64> = positions.iter().map(|p| p[0]).collect();
    let y: Vec<f64> = positions.iter().map(|p| p[1]).collect();
    let z: Vec<f64> = positions.iter().map(|p| p[2]).collect();
    let o = AeroOptions {
        model,
        wake,
        ..AeroOptions::default()
    };
    *o.power_reduction_3d(&x, &y, &z).unwrap().e.last().unwrap()
}

fn pct(v: f64) -> String {
    format!("{:.1}", 100.0 * v)
}

/// The rows of the table in docs/model.md.
fn rows() -> Vec<String> {
    let c = flapping_check().expect("the compiled-in flapping check parses");
    c.cases
        .iter()
        .map(|k| {
            let pos = &k.rigid.positions;
            let last = |r: &formation::aero::flapping::Run| r.birds.last().unwrap().saving;
            format!(
                "| {} | {} | {:.3}, {:.3}, {:.2} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} |",
                k.offset,
                k.birds,
                k.lateral,
                k.behind,
                k.above,
                pct(tool(pos, AeroModel::Hummel, Wake::Planar)),
                pct(tool(pos, AeroModel::Hummel, Wake::ThreeD)),
                pct(tool(pos, AeroModel::Lissaman, Wake::Planar)),
                pct(tool(pos, AeroModel::Lissaman, Wake::ThreeD)),
                pct(last(&k.rigid)),
                pct(last(&k.flapping)),
                k.ratio,
                k.ratio_watts,
            )
        })
        .collect()
}

#[test]
fn the_table_in_docs_matches_the_stored_runs_and_the_models() {
    let docs = std::fs::read_to_string(repo("docs/model.md")).unwrap();
    let mut missing = Vec::new();
    for r in rows() {
        println!("{r}");
        if !docs.contains(&r) {
            missing.push(r);
        }
    }
    assert!(
        missing.is_empty(),
        "docs/model.md lacks these rows of the flapping table (regenerate with --nocapture):\n{}",
        missing.join("\n")
    );
    let c = flapping_check().unwrap();
    let version = format!("pterasoftware {}", c.package_version);
    assert!(
        docs.contains(&version),
        "docs/model.md should name {version}"
    );
    let ratio = format!("{:.2}×", c.ratio_median);
    assert!(
        docs.contains(&ratio),
        "docs/model.md should give the ratio {ratio}"
    );
}

#[test]
fn the_compiled_in_copy_is_the_stored_file() {
    let text = std::fs::read_to_string(repo("tests/data/flapping_check.json")).unwrap();
    assert_eq!(FLAPPING_CHECK_JSON, text);
    assert!(flapping_check().is_some());
}

#[test]
fn stored_savings_and_ratios_follow_from_the_stored_powers() {
    let v = stored();
    let alone = |kind: &str| {
        let a = &v[format!("alone_{kind}")];
        (
            a["power_w"].as_f64().unwrap(),
            a["lift_n"].as_f64().unwrap(),
        )
    };
    let mut ratios = Vec::new();
    for case in v["cases"].as_array().unwrap() {
        let mut last = Vec::new();
        for kind in ["rigid", "flapping"] {
            let (p0, l0) = alone(kind);
            let birds = case[kind]["birds"].as_array().unwrap();
            for b in birds {
                let p = b["power_w"].as_f64().unwrap();
                let l = b["lift_n"].as_f64().unwrap();
                let want = 1.0 - p * (l0 / l).powi(2) / p0;
                let got = b["saving"].as_f64().unwrap();
                assert!((want - got).abs() < 1e-12, "{kind}: {got} vs {want}");
                let watts = p0 - p * (l0 / l).powi(2);
                assert!((watts - b["saved_w"].as_f64().unwrap()).abs() < 1e-12);
            }
            // The leader, in front, gains less than the followers (a little from their bound
            // vortices, more the closer they fly behind it).
            let leader = birds[0]["saving"].as_f64().unwrap();
            let follower = birds.last().unwrap()["saving"].as_f64().unwrap();
            assert!(
                follower > leader && leader.abs() < 0.2,
                "{kind} {case}: leader {leader}, follower {follower}"
            );
            last.push(follower);
        }
        let ratio = last[1] / last[0];
        assert!((ratio - case["ratio"].as_f64().unwrap()).abs() < 1e-12);
        if case["birds"].as_u64() == Some(2) {
            ratios.push(ratio);
        }
    }
    ratios.sort_by(f64::total_cmp);
    let n = ratios.len();
    assert!(n >= 4, "the check covers the field's offsets: {n}");
    let median = if n % 2 == 1 {
        ratios[n / 2]
    } else {
        0.5 * (ratios[n / 2 - 1] + ratios[n / 2])
    };
    let c = flapping_check().unwrap();
    assert!((c.ratio_median - median).abs() < 1e-12);
    assert_eq!(c.ratio_range, [ratios[0], ratios[n - 1]]);
    // What docs/model.md says of it: flapping keeps less than the rigid wake at every offset.
    assert!(ratios[n - 1] < 1.0, "{ratios:?}");
}

#[test]
fn the_summary_prints_the_stored_ratio() {
    let c = flapping_check().unwrap();
    let want = format!(
        "a flapping wake gives about {:.2}× this ({:.2}–{:.2}× at the field's offsets)",
        c.ratio_median, c.ratio_range[0], c.ratio_range[1]
    );
    assert_eq!(flapping_note(), want);
    let dir = tempfile::tempdir().unwrap();
    let shape = dir.path().join("v.json");
    std::fs::write(
        &shape,
        r#"{"birds": [{"x": 0, "y": 0}, {"x": -0.77, "y": 1.24}, {"x": 0.77, "y": 1.24}]}"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_formation"))
        .arg("power")
        .arg(&shape)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with("flock saving, a model estimate: ") && first.contains(&want),
        "{first}"
    );
}
