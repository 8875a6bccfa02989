//! `formation steady`, `plot power` and `plot xi` through the built binary: outputs, determinism,
//! and one-line exit-2 errors for bad input.

mod support;

use support::{assert_usage_error, data, example, run, scratch};

use std::path::Path;

#[test]
fn writes_json_and_csv_and_plots() {
    let dir = scratch("writes_json_and_csv_and_plots");
    let params = data("steady_v9_params.json");
    let (json, csv) = (dir.join("a.json"), dir.join("a.csv"));
    let out = run(&[
        "steady",
        params.to_str().unwrap(),
        "--birds",
        "14",
        "--frames",
        "90",
        "--key-every",
        "1",
        "-q",
        "-o",
        json.to_str().unwrap(),
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let anim = formation::Animation::read(&json).unwrap();
    assert_eq!(anim.birds, 14);
    assert_eq!(anim.frames.len(), 90);
    assert_eq!(
        anim.stage("steady").map(|s| (s.start, s.end)),
        Some((0, 90))
    );
    assert!(anim.key_shapes.len() >= 3);
    assert!(anim.frames.iter().all(|f| f.xi.is_some() && f.e.is_some()));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    // SPEC §4.4's ten columns first, then the analysis columns (docs/formats.md).
    assert_eq!(lines.next(), Some("frame,t,bird,x,y,z,heading,speed,e,xi,stage,formation,rank,leader,lateral,behind,wing_phase,bank,saving_total,qx,qy,qz,qw,pitch"));
    assert_eq!(lines.count(), 90 * 14);

    // Same seed, same bytes; another seed, other bytes.
    let json2 = dir.join("b.json");
    let json3 = dir.join("c.json");
    for (p, seed) in [(&json2, "0"), (&json3, "5")] {
        let out = run(&[
            "steady",
            params.to_str().unwrap(),
            "--birds",
            "14",
            "--frames",
            "90",
            "--key-every",
            "1",
            "-q",
            "--seed",
            seed,
            "-o",
            p.to_str().unwrap(),
        ]);
        assert!(out.status.success());
    }
    assert_eq!(
        std::fs::read(&json).unwrap(),
        std::fs::read(&json2).unwrap()
    );
    assert_ne!(
        std::fs::read(&json).unwrap(),
        std::fs::read(&json3).unwrap()
    );

    // Charts.
    let png = dir.join("power.png");
    let out = run(&[
        "plot",
        "power",
        json.to_str().unwrap(),
        "--key",
        "1",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let svg = dir.join("power.svg");
    let out = run(&[
        "plot",
        "power",
        json.to_str().unwrap(),
        "--frame",
        "45",
        "--metric",
        "e",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let xi = dir.join("xi.png");
    let out = run(&[
        "plot",
        "xi",
        json.to_str().unwrap(),
        "-o",
        xi.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&xi).unwrap().len() > 1000);

    let out = run(&[
        "plot",
        "power",
        json.to_str().unwrap(),
        "--key",
        "99",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_usage_error(&out, &["--key"]);
}

#[test]
fn bad_input_is_one_line_exit_2_and_leaves_no_file() {
    let dir = scratch("bad_input_is_one_line_exit_2_and_leaves_no_file");
    let params = data("steady_v9_params.json");
    let p = params.to_str().unwrap();
    let o = dir.join("bad.json");
    let os = o.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--birds", "0", "--frames", "10"], "--birds"),
        (&["--birds", "1", "--frames", "10"], "--birds"),
        (&["--birds", "9", "--frames", "0"], "--frames"),
        (
            &["--birds", "9", "--frames", "10", "--epsilon", "0.9"],
            "--epsilon",
        ),
        (
            &["--birds", "9", "--frames", "10", "--epsilon", "-0.1"],
            "--epsilon",
        ),
        (&["--birds", "9", "--frames", "10", "--c1", "1.3"], "--c1"),
        (&["--birds", "9", "--frames", "10", "--c2", "0.5"], "--c2"),
        (&["--birds", "9", "--frames", "10", "--c2", "NaN"], "--c2"),
        (&["--birds", "9", "--frames", "10", "--fps", "0"], "--fps"),
        (
            &["--birds", "9", "--frames", "10", "--key-every", "0"],
            "--key-every",
        ),
        (
            &["--birds", "9", "--frames", "10", "--speed", "-1"],
            "--speed",
        ),
        (
            &["--birds", "9", "--frames", "10", "--wingspan-m", "0"],
            "--wingspan-m",
        ),
    ];
    for (args, needle) in cases {
        let mut a = vec!["steady", p];
        a.extend_from_slice(args);
        a.extend_from_slice(&["-o", os]);
        let out = run(&a);
        assert_usage_error(&out, &[needle]);
        assert!(!o.exists());
    }
    // A params file of the wrong format: an animation, a shape, broken JSON, a missing file.
    let shape = example("v9_shape.json");
    let broken = dir.join("broken.json");
    std::fs::write(
        &broken,
        "{\"format\": \"formation-params/1\", \"frames\": [",
    )
    .unwrap();
    let wrong = dir.join("wrong.json");
    std::fs::write(&wrong, "{\"format\": \"formation-animation/1\"}").unwrap();
    for (f, needle) in [
        (shape.as_path(), "v9_shape.json"),
        (broken.as_path(), "broken.json"),
        (wrong.as_path(), "wrong.json"),
        (Path::new("/nonexistent/params.json"), "params.json"),
    ] {
        let out = run(&[
            "steady",
            f.to_str().unwrap(),
            "--birds",
            "9",
            "--frames",
            "10",
            "-o",
            os,
        ]);
        assert_usage_error(&out, &[needle]);
        assert!(!o.exists());
    }
    let out = run(&[
        "steady",
        p,
        "--birds",
        "9",
        "--frames",
        "10",
        "-o",
        dir.join("x.txt").to_str().unwrap(),
    ]);
    assert_usage_error(&out, &["-o"]);
}
