//! `formation initiate` and `formation plot paths` through the binary: outputs, exit codes,
//! one-line messages, nothing written on failure, byte-identical reruns.

mod support;

use support::{assert_usage_error_in, data, run, run_full, scratch};

#[test]
fn initiate_writes_an_animation_and_the_paths_chart() {
    let dir = scratch("initiate-writes");
    let steady = data("initiate_steady_v9.json");
    let out = dir.join("init9.json");
    let csv = dir.join("init9.csv");
    let (code, _, err) = run_full(&[
        "initiate",
        steady.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-o",
        csv.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let a = formation::Animation::read(&out).unwrap();
    assert_eq!(a.stages[0].name, "initiation");
    assert_eq!(a.stages[1].name, "steady");
    assert_eq!(a.stages[1].end, a.frames.len());
    let text = std::fs::read_to_string(&csv).unwrap();
    // SPEC §4.4's ten columns first, then the analysis columns (docs/formats.md).
    assert!(text.starts_with("frame,t,bird,x,y,z,heading,speed,e,xi,stage,"));
    assert_eq!(text.lines().count(), 1 + a.frames.len() * a.birds);
    let png = dir.join("paths.png");
    let (code, _, err) = run_full(&[
        "plot",
        "paths",
        out.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"));
}

#[test]
fn same_seed_gives_byte_identical_files() {
    let dir = scratch("initiate-same-seed");
    let steady = data("initiate_steady_v9.json");
    let (a, b, c) = (
        dir.join("s1.json"),
        dir.join("s2.json"),
        dir.join("s3.json"),
    );
    for (p, seed) in [(&a, "4"), (&b, "4"), (&c, "5")] {
        let (code, _, err) = run_full(&[
            "initiate",
            steady.to_str().unwrap(),
            "-o",
            p.to_str().unwrap(),
            "--seed",
            seed,
        ]);
        assert_eq!(code, 0, "{err}");
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());
}

#[test]
fn bad_input_is_exit_2_with_one_line() {
    let steady = data("initiate_steady_v9.json");
    let dir = scratch("initiate-bad-input");
    let s = steady.to_str().unwrap();
    let no_ks = data("initiate_steady_no_keyshape.json");
    let out = dir.join("bad.json");
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["initiate", no_ks.to_str().unwrap(), "-o", o],
            "key_shapes",
        ),
        (
            vec!["initiate", s, "-o", o, "--max-steps", "0"],
            "--max-steps",
        ),
        (vec!["initiate", s, "-o", o, "--alpha=-1"], "--alpha"),
        (vec!["initiate", s, "-o", o, "--alpha", "-1"], "-1"),
        (vec!["initiate", s, "-o", o, "--fov", "0"], "--fov"),
        (vec!["initiate", s, "-o", o, "--fov", "200"], "--fov"),
        (
            vec!["initiate", s, "-o", o, "--start-width=-3"],
            "--start-width",
        ),
        (
            vec!["initiate", s, "-o", o, "--start-width", "2"],
            "--start-width/--start-depth: a take-off area of 2.0",
        ),
        (
            vec![
                "initiate",
                s,
                "-o",
                o,
                "--start",
                "air",
                "--start-width",
                "2",
                "--start-depth",
                "2",
            ],
            "region",
        ),
        (vec!["initiate", s, "-o", o, "--takeoff", "0"], "--takeoff"),
        (vec!["initiate", s, "-o", o, "--takeoff", "-4"], "--takeoff"),
        (
            vec!["initiate", s, "-o", o, "--takeoff", "NaN"],
            "--takeoff",
        ),
        (
            vec!["initiate", s, "-o", o, "--takeoff", "inf"],
            "--takeoff",
        ),
        (vec!["initiate", s, "-o", o, "--hold", "NaN"], "--hold"),
        (vec!["initiate", s, "-o", o, "--hold=-1"], "--hold"),
        (
            vec!["initiate", s, "-o", o, "--cruise-altitude", "-2"],
            "--cruise-altitude",
        ),
        (
            vec!["initiate", s, "-o", o, "--climb-rate", "0"],
            "--climb-rate",
        ),
        // Higher than the birds can climb within the time limit (0.51 wingspans/s, 300 s): the
        // highest reachable altitude is given, up front (before: 300 s of simulation, then
        // "did not converge").
        (
            vec!["initiate", s, "-o", o, "--cruise-altitude", "10000"],
            "--cruise-altitude: 10000 wingspans cannot be reached",
        ),
        (
            vec!["initiate", s, "-o", o, "--cruise-altitude", "10000"],
            "at most about 136 wingspans",
        ),
        (
            vec![
                "initiate",
                s,
                "-o",
                o,
                "--cruise-altitude",
                "300",
                "--max-seconds",
                "100",
            ],
            "at most about 44 wingspans",
        ),
        (
            vec![
                "initiate",
                s,
                "-o",
                o,
                "--start",
                "air",
                "--heading-spread",
                "200",
            ],
            "--heading-spread",
        ),
        (
            vec!["initiate", s, "-o", o, "--start-width", "1e300"],
            "--start-width",
        ),
        (
            vec!["initiate", s, "-o", o, "--tolerance", "1e-300"],
            "--tolerance",
        ),
        (
            vec!["initiate", s, "-o", o, "--max-steps", "99999999"],
            "--max-steps",
        ),
        (
            vec!["initiate", s, "-o", o, "--hpr-gamma", "1e9"],
            "--hpr-gamma",
        ),
        (
            vec!["initiate", s, "-o", o, "--perception", "psychic"],
            "psychic",
        ),
        (vec!["initiate", s, "-o", "out.xyz"], "out.xyz"),
        (
            vec!["initiate", "/nonexistent/steady.json", "-o", o],
            "/nonexistent/steady.json",
        ),
        (
            vec!["initiate", s, "-o", o, "--start", s],
            "unexpected JSON structure",
        ),
        // A start file fixes every position: the region flags do not apply, and the message
        // names the flag given and the flag to use instead.
        (
            vec!["initiate", s, "-o", o, "--start", s, "--start-width", "9"],
            "--start-width: does not apply to a start file (--start FILE); give --start ground or air",
        ),
        (
            vec!["initiate", s, "-o", o, "--start", s, "--start-depth", "9"],
            "--start-depth: does not apply",
        ),
        (
            vec!["initiate", s, "-o", o, "--start", s, "--heading-spread", "9"],
            "--heading-spread: does not apply",
        ),
    ];
    for (args, needle) in cases {
        assert_usage_error_in(&format!("{args:?}"), &run(&args), &[needle]);
        assert!(!out.exists(), "{args:?} wrote a file");
    }
}

#[test]
fn no_convergence_is_exit_1_and_writes_nothing() {
    let dir = scratch("initiate-no-convergence");
    let steady = data("initiate_steady_v9.json");
    let out = dir.join("nc.json");
    std::fs::write(&out, b"previous").unwrap();
    let (code, _, err) = run_full(&[
        "initiate",
        steady.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--max-steps",
        "40",
    ]);
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("did not converge"), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");
    let fresh = dir.join("nc-fresh.json");
    let (code, _, _) = run_full(&[
        "initiate",
        steady.to_str().unwrap(),
        "-o",
        fresh.to_str().unwrap(),
        "--max-steps",
        "40",
    ]);
    assert_eq!(code, 1);
    assert!(!fresh.exists());
}
