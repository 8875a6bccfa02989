//! `formation power` and `formation solve` through the binary: outputs and every bad input
//! (exit 2, one line naming the file and field, no output file left behind).

mod support;

use support::{assert_usage_text, example_arg as example, run_full as run, scratch};

#[test]
fn power_table_and_json() {
    let (code, out, err) = run(&["power", &example("v9_shape.json")]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("leader"));
    assert!(out.contains("flock saving") && out.contains('%'), "{out}");
    assert!(
        out.contains("induced power"),
        "the table says what the saving is: {out}"
    );
    let (code, out, _) = run(&["power", &example("v9_shape.json"), "--json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let birds = v["birds"].as_array().unwrap();
    assert_eq!(birds.len(), 9);
    let total = v["total"].as_f64().unwrap();
    let sum_e: f64 = birds.iter().map(|b| b["e"].as_f64().unwrap()).sum();
    let sum_xi: f64 = birds.iter().map(|b| b["xi"].as_f64().unwrap()).sum();
    assert!((sum_e - total).abs() < 1e-12 * total);
    assert!((sum_xi - 1.0).abs() < 1e-12);
    assert_eq!(birds[4]["y"].as_f64().unwrap(), 0.0);
    // saving = e per bird, flock_saving = their mean.
    for b in birds {
        assert_eq!(b["saving"].as_f64().unwrap(), b["e"].as_f64().unwrap());
    }
    let flock = v["flock_saving"].as_f64().unwrap();
    assert!((flock - total / 9.0).abs() < 1e-15);
    assert!(flock > 0.0 && flock < 1.0);
}

#[test]
fn power_reports_savings_of_total_power_from_the_power_curve() {
    let shape = example("v9_shape.json");
    let json = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec!["power", shape.as_str(), "--json"];
        args.extend_from_slice(extra);
        let (code, out, err) = run(&args);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str(&out).unwrap()
    };
    let v = json(&[]);
    let f = &v["flight"];
    let share = f["induced_share"].as_f64().unwrap();
    // The library's curve for the same bird and speed gives the same share.
    let curve = formation::aero::flight::PowerCurve::new(formation::aero::flight::Morphology::of(
        formation::animation::wing::Species::Goose,
    ));
    assert_eq!(f["speed_ms"].as_f64().unwrap(), curve.minimum_power_speed());
    assert!((share - curve.induced_share(curve.minimum_power_speed())).abs() < 1e-15);
    assert!(share > 0.2 && share < 0.6, "{share}");
    for b in v["birds"].as_array().unwrap() {
        let (s, t) = (
            b["saving"].as_f64().unwrap(),
            b["saving_total"].as_f64().unwrap(),
        );
        assert!((t - s * share).abs() <= 1e-15 * s.abs().max(1.0));
    }
    let flock = v["flock_saving"].as_f64().unwrap();
    assert!((v["flock_saving_total"].as_f64().unwrap() - flock * share).abs() < 1e-15);
    // The sensitivity over the core radius holds the default's own number, and a wider core
    // (a more diffuse vortex) saves less.
    let sens = v["sensitivity"].as_array().unwrap();
    assert_eq!(sens.len(), 5);
    let at = |c: f64| {
        sens.iter()
            .find(|s| s["core_radius"].as_f64() == Some(c))
            .unwrap()["flock_saving"]
            .as_f64()
            .unwrap()
    };
    assert!((at(0.04) - flock).abs() < 1e-15);
    assert!(at(0.02) > at(0.04) && at(0.04) > at(0.16) && at(0.16) > at(0.32));
    // Faster flight: less of the power is induced, so the same positions save less of the total.
    let fast = json(&["--speed-ms", "25"]);
    assert!(fast["flight"]["induced_share"].as_f64().unwrap() < share);
    // A heavier bird of the same span: more of its power is induced at the same speed.
    let heavy = json(&["--mass-kg", "4", "--speed-ms", "16"]);
    let light = json(&["--mass-kg", "2", "--speed-ms", "16"]);
    assert!(
        heavy["flight"]["induced_share"].as_f64().unwrap()
            > light["flight"]["induced_share"].as_f64().unwrap()
    );
    // The table says which model, core and bird gave the numbers.
    let (_, out, _) = run(&["power", &shape, "--species", "crane"]);
    assert!(
        out.contains("of total power") && out.contains("core 0.04") && out.contains("crane"),
        "{out}"
    );
    // Bad values exit 2 with one line naming the flag.
    for (flag, value) in [
        ("--mass-kg", "0"),
        ("--speed-ms", "-3"),
        ("--species", "owl"),
        ("--core-radius", "nan"),
        ("--wingspan-m", "-1"),
    ] {
        let (code, out, err) = run(&["power", &shape, flag, value]);
        assert!(out.is_empty());
        assert_usage_text(&format!("{flag} {value}"), code, &err, &[flag]);
    }
}

#[test]
fn solve_writes_a_shape_that_power_reads_back() {
    let dir = scratch("solve");
    let out = dir.join("u.json");
    let (code, _, err) = run(&[
        "solve",
        &example("equal_savings_target.json"),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["converged"], true);
    assert!(v["residual"].as_f64().unwrap() < 1e-9);
    let ys: Vec<f64> = v["birds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["y"].as_f64().unwrap())
        .collect();
    assert_eq!(
        ys.iter().copied().fold(f64::INFINITY, f64::min),
        0.0,
        "leader at y = 0"
    );
    let (code, json, _) = run(&["power", out.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0);
    let p: serde_json::Value = serde_json::from_str(&json).unwrap();
    for b in p["birds"].as_array().unwrap() {
        assert!((b["xi"].as_f64().unwrap() - 1.0 / 9.0).abs() < 1e-9);
    }
}

/// Runs a command on a file with `content`, expects exit 2, one stderr line containing every
/// `needle`, and no output file.
fn bad(cmd: &str, content: &str, needles: &[&str]) {
    let dir = scratch(&format!(
        "bad-{cmd}-{}",
        needles
            .join("-")
            .replace(['/', ' ', '[', ']', '.', '"'], "_")
    ));
    let input = dir.join("input.json");
    std::fs::write(&input, content).unwrap();
    let out = dir.join("out.json");
    let mut args = vec![cmd, input.to_str().unwrap()];
    if cmd == "solve" {
        args.extend(["-o", out.to_str().unwrap()]);
    }
    let (code, _, err) = run(&args);
    assert_usage_text(&format!("{cmd} on {content:?}"), code, &err, needles);
    assert!(!out.exists(), "no output after a failure");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "no temporary files left behind");
}

#[test]
fn power_bad_inputs() {
    bad("power", "", &["input.json", "empty"]);
    bad(
        "power",
        "{\"birds\": [{\"x\": 0, \"y\": 0}, {\"x\": 1",
        &["input.json", "line 1", "truncated"],
    );
    bad(
        "power",
        "[1, 2]",
        &["input.json", "unexpected JSON structure"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": NaN, \"y\": 0}, {\"x\": 1, \"y\": 1}]}",
        &["input.json", "invalid JSON"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": 1e999, \"y\": 0}, {\"x\": 1, \"y\": 1}]}",
        &["input.json"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": 0, \"y\": 0}]}",
        &["input.json", "at least 2"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": 0, \"y\": 0}, {\"x\": 0.5, \"y\": 0.05}]}",
        &["input.json", "birds 0 and 1 collide"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": 0, \"y\": 1}, {\"x\": 2, \"y\": 0}, {\"x\": 0, \"y\": 1}]}",
        &["input.json", "birds 0 and 2 collide"],
    );
    bad(
        "power",
        "{\"birds\": [{\"x\": \"a\", \"y\": 0}, {\"x\": 1, \"y\": 1}]}",
        &["input.json", "line 1"],
    );
}

#[test]
fn solve_bad_inputs() {
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [1, 1]}",
        &["input.json", "xi", "2 targets for 3"],
    );
    bad(
        "solve",
        "{\"x\": [0], \"xi\": [1]}",
        &["input.json", "at least 2"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [1, -1, 1]}",
        &["input.json", "asks for"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [0, 0, 0]}",
        &["input.json", "sum to 0"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 1.5], \"xi\": [1, 1, 1]}",
        &["input.json", "bird 2", "overlap"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [1, 1, 1], \"y\": [0, 1]}",
        &["input.json", "initial positions"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [1, 1, 1], \"typo\": 1}",
        &["input.json", "unknown field"],
    );
    bad(
        "solve",
        "{\"x\": [-2, -1, 0, 1, 2], \"xi\": [0.1, 0.1, 0.6, 0.1, 0.1]}",
        &["input.json", "bird 2"],
    );
    bad(
        "solve",
        "{\"x\": [0, 1, 2], \"xi\": [1, 1e999, 1]}",
        &["input.json"],
    );
}

#[test]
fn core_radius_flag_is_checked() {
    let never = scratch("core-radius").join("never.json");
    let never_arg = never.display().to_string();
    for flag in ["-0.1", "NaN", "inf"] {
        for cmd in ["power", "solve"] {
            let mut args = vec![cmd.to_string()];
            args.push(if cmd == "power" {
                example("v9_shape.json")
            } else {
                example("equal_savings_target.json")
            });
            if cmd == "solve" {
                args.extend(["-o".into(), never_arg.clone()]);
            }
            args.extend(["--core-radius".into(), flag.into()]);
            let refs: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
            let (code, _, err) = run(&refs);
            assert_usage_text(
                &format!("{cmd} --core-radius {flag}"),
                code,
                &err,
                &["--core-radius"],
            );
        }
    }
    assert!(!never.exists());
    // A valid radius changes the numbers only slightly away from the vortex lines.
    let (code, a, _) = run(&[
        "power",
        &example("v9_shape.json"),
        "--json",
        "--core-radius",
        "0",
    ]);
    assert_eq!(code, 0);
    let (_, b, _) = run(&["power", &example("v9_shape.json"), "--json"]);
    let ta = serde_json::from_str::<serde_json::Value>(&a).unwrap()["total"]
        .as_f64()
        .unwrap();
    let tb = serde_json::from_str::<serde_json::Value>(&b).unwrap()["total"]
        .as_f64()
        .unwrap();
    assert!((ta - tb).abs() < 1e-3 * ta, "{ta} vs {tb}");
}

#[test]
fn usage_errors_and_missing_files() {
    let (code, _, err) = run(&["power", "/nonexistent/shape.json"]);
    assert_eq!(code, 2);
    assert!(err.contains("/nonexistent/shape.json"));
    let (code, _, err) = run(&[
        "solve",
        &example("equal_savings_target.json"),
        "-o",
        "/tmp/x.txt",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("x.txt"), "{err}");
    let (code, _, err) = run(&[
        "solve",
        &example("equal_savings_target.json"),
        "-o",
        "/nonexistent-dir/u.json",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("/nonexistent-dir/u.json"), "{err}");
    let (code, _, err) = run(&["power", "--bogus"]);
    assert_usage_text("power --bogus", code, &err, &["--bogus"]);
}
