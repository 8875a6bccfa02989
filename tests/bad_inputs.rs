//! The bad-input corpus (issue 8): every case of `tests/data/bad/cases.json` runs the binary from
//! `tests/data/bad/` (so messages name files by short relative paths) and must exit with the
//! expected code (2: bad input or usage), print exactly the expected first line on stderr (`$OUT`
//! stands for the case's output directory), print no panic or backtrace, and create nothing in
//! its output directory (no output, no temporary, not even an empty file).
//!
//! The manifest covers every command: extract (each annotation format), power, solve, steady,
//! initiate, render, plot power|xi|shape|paths|wingbeat and animate, including the size limits
//! of `formation::limits` (10⁶ birds, 10⁷ frames, a 10-GB GIF).

use std::path::PathBuf;

use serde::Deserialize;

mod support;

use support::{data, run_in, scratch};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    /// `command: what is wrong`.
    name: String,
    /// Arguments after `formation --quiet`; `$OUT` is replaced by a fresh empty directory.
    args: Vec<String>,
    /// Expected exit code.
    exit: i32,
    /// Expected first line of stderr (with `$OUT` for the output directory).
    message: String,
}

fn bad_dir() -> PathBuf {
    data("bad")
}

fn cases() -> Vec<Case> {
    let text = std::fs::read_to_string(bad_dir().join("cases.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn manifest_covers_every_command_and_every_file() {
    let cases = cases();
    let commands = [
        "extract",
        "power",
        "solve",
        "steady",
        "initiate",
        "render",
        "plot power",
        "plot xi",
        "plot shape",
        "plot paths",
        "plot wingbeat",
        "animate",
    ];
    for c in commands {
        assert!(
            cases.iter().any(|k| k.name.starts_with(&format!("{c}:"))),
            "no bad-input case for `{c}`"
        );
    }
    // Every file of the corpus is used by some case.
    for entry in std::fs::read_dir(bad_dir()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name == "cases.json" {
            continue;
        }
        assert!(
            cases.iter().any(|c| c.args.iter().any(|a| a == &name)),
            "tests/data/bad/{name} is used by no case"
        );
    }
}

#[test]
fn every_bad_input_fails_cleanly_and_writes_nothing() {
    let base = scratch("bad-inputs");
    let mut failures = Vec::new();
    for (k, case) in cases().iter().enumerate() {
        let out = base.join(format!("case{k}"));
        std::fs::create_dir_all(&out).unwrap();
        let out_s = out.to_string_lossy().into_owned();
        let args: Vec<String> = case
            .args
            .iter()
            .map(|a| a.replace("$OUT", &out_s))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let r = run_in(&bad_dir(), &args);
        let stderr = String::from_utf8_lossy(&r.stderr);
        let first = stderr.lines().next().unwrap_or("").replace(&out_s, "$OUT");
        let left: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        let mut why = Vec::new();
        if r.status.code() != Some(case.exit) {
            why.push(format!(
                "exit {:?}, expected {}",
                r.status.code(),
                case.exit
            ));
        }
        if first != case.message {
            why.push(format!(
                "first line\n      {first}\n    expected\n      {}",
                case.message
            ));
        }
        if stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
            why.push(format!("panic: {stderr}"));
        }
        if stderr.lines().count() != 1 {
            why.push(format!(
                "{} lines on stderr, expected 1",
                stderr.lines().count()
            ));
        }
        if !left.is_empty() {
            why.push(format!("left files behind: {left:?}"));
        }
        if !why.is_empty() {
            failures.push(format!("{}: {}", case.name, why.join("; ")));
        }
    }
    let _ = std::fs::remove_dir_all(&base);
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
