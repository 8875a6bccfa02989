//! What the commands write and say: the CSV's numbers in their shortest form (no `-0`, no float
//! noise), `--quiet` silent on success, `render --fps` stating the frames and rate it wrote.

mod support;

use support::{run, s, scratch};

const GEESE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples_data/barnacle_geese_v.json"
);

/// Digits after the decimal point of a CSV number.
fn decimals(v: &str) -> usize {
    v.split_once('.').map(|(_, f)| f.len()).unwrap_or(0)
}

#[test]
fn csv_numbers_are_short_and_never_negative_zero_and_quiet_commands_say_nothing() {
    let d = scratch("numbers");
    let json = d.join("flock.json");
    let csv = d.join("flock.csv");
    let out = run(&[
        "animate",
        GEESE,
        "--birds",
        "6",
        "--seconds",
        "3",
        "-o",
        s(&json),
        "-o",
        s(&csv),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.stdout.is_empty() && out.stderr.is_empty(),
        "animate --quiet printed something"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut cells = 0;
    for line in text.lines().skip(1) {
        for v in line.split(',') {
            if v.parse::<f64>().is_err() {
                continue;
            }
            cells += 1;
            assert!(!v.contains('e') && !v.contains('E'), "exponent: {v}");
            assert!(decimals(v) <= 6, "float noise: {v} in {line}");
            assert!(!(v.contains('.') && v.ends_with('0')), "trailing zero: {v}");
            assert!(
                v.parse::<f64>().unwrap() != 0.0 || v == "0",
                "zero written as {v}"
            );
        }
    }
    assert!(cells > 1000, "{cells}");

    // extract --quiet: nothing on stdout or stderr.
    let params = d.join("p.json");
    let out = run(&["extract", GEESE, "-o", s(&params), "--quiet"]);
    assert!(out.status.success());
    assert!(
        out.stdout.is_empty() && out.stderr.is_empty(),
        "extract --quiet: {}",
        String::from_utf8_lossy(&out.stdout)
    );

    // render --fps 24: the summary names what was written.
    let r = d.join("r.json");
    let out = run(&["render", s(&json), "--fps", "24", "-o", s(&r)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
    let n = written["frames"].as_array().unwrap().len();
    assert!(
        said.contains(&format!("{n} frames at 24 fps")),
        "{said} (wrote {n} frames)"
    );
    let out = run(&["render", s(&json), "--fps", "24", "-o", s(&r), "--quiet"]);
    assert!(out.status.success() && out.stdout.is_empty() && out.stderr.is_empty());
}
