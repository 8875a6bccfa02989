//! Small command-line rough edges, each with the message a user can act on: `animate --loop`
//! names `--no-initiation`; `--start` takes its words in any case and refuses a misspelt one
//! with the words to use (not as a missing file); help and version on a full stdout are exit 2
//! naming stdout, on a closed pipe exit 0; a start file for a flock of several formations names
//! a flag that exists (`--formations 1` of `animate`, of `formation steady` for `initiate`).

mod support;

use std::path::Path;
use std::process::Stdio;

use support::{assert_refused, assert_usage_error_in, bin, data, example_arg, run, s, scratch};

#[test]
fn a_loop_with_the_take_off_names_the_flag_that_turns_it_off() {
    let dir = scratch("cli-loop");
    let out = dir.join("l.json");
    let geese = example_arg("barnacle_geese_v.json");
    let args = [
        "animate",
        geese.as_str(),
        "--birds",
        "9",
        "--seconds",
        "3",
        "--loop",
        "-q",
        "-o",
        s(&out),
    ];
    let o = run(&args);
    assert_usage_error_in("--loop", &o, &["--loop", "--no-initiation"]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("initiation off"));
    assert!(!out.exists());
    // What the message says works.
    let o = run(&[&args[..], &["--no-initiation"]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
}

#[test]
fn start_words_are_read_in_any_case_and_misspelt_ones_refused() {
    let dir = scratch("cli-start");
    let geese = example_arg("barnacle_geese_v.json");
    let animate = |start: &str, name: &str| {
        let out = dir.join(name);
        let o = run(&[
            "animate",
            &geese,
            "--birds",
            "9",
            "--seconds",
            "1",
            "--start",
            start,
            "-q",
            "-o",
            s(&out),
        ]);
        (o, out)
    };
    for (word, same) in [("GROUND", "ground"), ("Air", "air")] {
        let (o, a) = animate(word, &format!("{word}.json"));
        assert!(
            o.status.success(),
            "{word}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let (o, b) = animate(same, &format!("{same}.json"));
        assert!(
            o.status.success(),
            "{same}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
            "--start {word} is not --start {same}"
        );
    }
    for bad in ["grund", "GRUND", "sky"] {
        let (o, out) = animate(bad, "bad.json");
        assert_usage_error_in(bad, &o, &["--start", bad, "ground, air or a start file"]);
        assert!(!String::from_utf8_lossy(&o.stderr).contains("No such file"));
        assert!(!out.exists());
    }
    // A missing start file is still named as a file; `initiate` reads `--start` the same way.
    let (o, _) = animate("nowhere/s.json", "bad.json");
    assert_refused(&o, "nowhere/s.json", "a missing start file");
    let steady = data("initiate_steady_v9.json");
    let o = run(&[
        "initiate",
        s(&steady),
        "--start",
        "Grund",
        "-q",
        "-o",
        s(&dir.join("i.json")),
    ]);
    assert_usage_error_in("initiate --start Grund", &o, &["--start", "ground, air"]);
    let o = run(&[
        "initiate",
        s(&steady),
        "--start",
        "AIR",
        "--max-seconds",
        "2",
        "-q",
        "-o",
        s(&dir.join("i.json")),
    ]);
    // Read as the air start: the take-off is flown (two seconds of flight do not converge; one
    // second is refused up front, as no longer than the one-second hold).
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("did not converge"));
}

/// `formation ARGS` with stdout on `/dev/full`.
fn to_full(args: &[&str]) -> std::process::Output {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    bin().args(args).stdout(full).output().unwrap()
}

#[test]
fn help_and_version_on_a_full_stdout_are_exit_2_naming_stdout() {
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    for args in [
        &["--help"][..],
        &["-h"],
        &["--version"],
        &["animate", "--help"],
        &["help", "steady"],
        &["plot", "power", "--help"],
    ] {
        let what = args.join(" ");
        assert_refused(&to_full(args), "stdout: No space left on device", &what);
    }
    // Help asked for on the way to a usage error goes to stderr: exit 2 as before.
    let o = to_full(&[]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn help_on_a_closed_pipe_or_a_terminal_like_stdout_is_exit_0() {
    // The reader is gone before (or while) the help is written: a quiet end, as for tables.
    let mut child = bin()
        .args(["animate", "--help"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = run(&["--help"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stdout).contains("Usage: formation"));
    assert!(o.stderr.is_empty());
}

#[test]
fn a_start_file_for_several_formations_names_a_flag_that_exists() {
    let dir = scratch("cli-start-flock");
    let (steady, start) = (dir.join("s.json"), dir.join("start.json"));
    let params = data("steady_v9_params.json");
    let o = run(&[
        "steady",
        s(&params),
        "--birds",
        "30",
        "--frames",
        "30",
        "-q",
        "-o",
        s(&steady),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xs: Vec<String> = (0..30).map(|i| format!("{}.0", 3 * i)).collect();
    let ys = vec!["0.0"; 30];
    std::fs::write(
        &start,
        format!(r#"{{"x": [{}], "y": [{}]}}"#, xs.join(", "), ys.join(", ")),
    )
    .unwrap();
    let o = run(&[
        "initiate",
        s(&steady),
        "--start",
        s(&start),
        "-q",
        "-o",
        s(&dir.join("i.json")),
    ]);
    assert_usage_error_in(
        "initiate",
        &o,
        &[
            "--start ground or air",
            "`formation steady` with --formations 1",
        ],
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("skein."));
    let geese = example_arg("barnacle_geese_v.json");
    let o = run(&[
        "animate",
        &geese,
        "--birds",
        "30",
        "--start",
        s(&start),
        "-q",
        "-o",
        s(&dir.join("a.json")),
    ]);
    assert_usage_error_in(
        "animate",
        &o,
        &["--start ground or air", "as one formation (--formations 1)"],
    );
    // What the message says works: one formation of 30 from that start file.
    let o = run(&[
        "animate",
        &geese,
        "--birds",
        "30",
        "--formations",
        "1",
        "--start",
        s(&start),
        "--seconds",
        "1",
        "-q",
        "-o",
        s(&dir.join("a.json")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
