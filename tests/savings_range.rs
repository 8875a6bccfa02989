//! Savings stated as what they are: `power --json` leads with the range over the modelling
//! choices (which contains the chosen model's value), real species set the power curve and
//! cruise airspeed, unknown species and implausible masses are refused naming the flag or field.

mod support;

use support::{bin, example, scratch};

fn power_json(extra: &[&str]) -> serde_json::Value {
    let shape = example("v9_shape.json");
    let out = bin()
        .args(["power", shape.to_str().unwrap(), "--json"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_range_contains_the_point_value_induced_and_total() {
    for extra in [
        &[][..],
        &["--core-radius", "0.45"][..],
        &["--aero-model", "lissaman"][..],
        &["--species", "common-crane"][..],
    ] {
        let j = power_json(extra);
        let r = &j["saving_range"];
        let (lo, hi) = (
            r["induced"][0].as_f64().unwrap(),
            r["induced"][1].as_f64().unwrap(),
        );
        let point = j["flock_saving"].as_f64().unwrap();
        assert!(
            lo <= point && point <= hi && lo < hi,
            "{extra:?}: {lo} {point} {hi}"
        );
        let share = j["flight"]["induced_share"].as_f64().unwrap();
        assert!(share > 0.0 && share < 1.0);
        for k in 0..2 {
            let t = r["total"][k].as_f64().unwrap();
            let i = r["induced"][k].as_f64().unwrap();
            assert!((t - i * share).abs() < 1e-12);
        }
        let total = j["flock_saving_total"].as_f64().unwrap();
        assert!(
            r["total"][0].as_f64().unwrap() <= total && total <= r["total"][1].as_f64().unwrap()
        );
        // Every band entry lies inside the range.
        for b in j["band"].as_array().unwrap() {
            let v = b["flock_saving"].as_f64().unwrap();
            assert!(lo <= v && v <= hi);
        }
    }
}

#[test]
fn a_real_species_sets_its_morphology_and_cruise_airspeed() {
    let j = power_json(&["--species", "barnacle-goose"]);
    let f = &j["flight"];
    assert_eq!(f["species"], "barnacle-goose");
    assert_eq!(f["mass_kg"].as_f64().unwrap(), 1.8);
    assert_eq!(f["wingspan_m"].as_f64().unwrap(), 1.38);
    assert_eq!(f["wing_area_m2"].as_f64().unwrap(), 0.224);
    assert_eq!(f["speed_ms"].as_f64().unwrap(), 18.0);
    let share = f["induced_share"].as_f64().unwrap();
    assert!((0.26..0.37).contains(&share), "{share}");
    // --speed-ms still wins; a family keeps its minimum-power speed.
    let j = power_json(&["--species", "barnacle-goose", "--speed-ms", "12"]);
    assert_eq!(j["flight"]["speed_ms"].as_f64().unwrap(), 12.0);
    let j = power_json(&["--species", "goose"]);
    assert!((j["flight"]["speed_ms"].as_f64().unwrap() - 16.3).abs() < 0.1);
    for name in [
        "greylag-goose",
        "canada-goose",
        "white-fronted-goose",
        "pink-footed-goose",
        "common-crane",
        "white-pelican",
        "northern-bald-ibis",
        "crane",
        "pelican",
    ] {
        let j = power_json(&["--species", name]);
        assert_eq!(j["flight"]["species"], name);
    }
}

#[test]
fn an_unknown_species_is_refused_naming_the_flag_and_the_known_ones() {
    let shape = example("v9_shape.json");
    let out = bin()
        .args(["power", shape.to_str().unwrap(), "--species", "dodo"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--species")
            && err.contains("barnacle-goose")
            && err.contains("northern-bald-ibis"),
        "{err}"
    );
}

#[test]
fn implausible_masses_are_refused_naming_the_flag() {
    let shape = example("v9_shape.json");
    for m in ["1e-200", "1e-300", "0.0001"] {
        let out = bin()
            .args(["power", shape.to_str().unwrap(), "--mass-kg", m])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{m}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--mass-kg"));
    }
    let dir = scratch("savings_range_mass");
    let input = example("barnacle_geese_v.json");
    let gif = dir.join("a.json");
    let out = bin()
        .args([
            "animate",
            input.to_str().unwrap(),
            "--birds",
            "5",
            "--mass-kg",
            "1e-200",
        ])
        .args(["-o", gif.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--mass-kg"));
    assert!(!gif.exists());
}

#[test]
fn an_animation_with_an_implausible_mass_is_refused_on_reading() {
    let dir = scratch("savings_range_file");
    let input = example("barnacle_geese_v.json");
    let json = dir.join("a.json");
    let out = bin()
        .args([
            "animate",
            input.to_str().unwrap(),
            "--birds",
            "4",
            "--seconds",
            "2",
            "--no-initiation",
            "--quiet",
        ])
        .args(["-o", json.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&json).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    for m in [1e300, -3.0] {
        v["flight"] = serde_json::json!({ "mass_kg": m });
        let bad = dir.join("bad.json");
        std::fs::write(&bad, serde_json::to_string(&v).unwrap()).unwrap();
        let html = dir.join("r.html");
        let out = bin()
            .args([
                "report",
                bad.to_str().unwrap(),
                "-o",
                html.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{m}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("bad.json") && err.contains("flight.mass_kg"),
            "{err}"
        );
        assert!(!html.exists());
    }
    // report --mass-kg 1e-300 on the good file.
    let html = dir.join("r2.html");
    let out = bin()
        .args([
            "report",
            json.to_str().unwrap(),
            "--mass-kg",
            "1e-300",
            "-o",
            html.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--mass-kg"));
}
