//! Byte-identity regression: `formation extract` and `formation animate` on every shipped example
//! (and a few flag combinations) with a fixed seed must write exactly the bytes recorded in
//! `tests/data/golden.sha256` (SHA-256 of each output, `sha256sum` format). It was recorded with
//! the binary of main before issue 11's refactor, to prove that moving the pipeline into the
//! library changed no output.
//!
//! A change that is *meant* to change outputs (a new model, a new field) regenerates the digests:
//!
//! ```text
//! FORMATION_BLESS=1 cargo test --release --test golden
//! ```
//!
//! then review `git diff tests/data/golden.sha256` (only the cases you expected should differ)
//! and commit it with the change that explains it.

mod support;

use std::collections::BTreeMap;

use support::{bin, example_arg, repo_file, s, scratch, sha256_hex};

const DIGESTS: &str = "tests/data/golden.sha256";

/// (case name, output file name, arguments before `-o`).
fn cases() -> Vec<(&'static str, &'static str, Vec<String>)> {
    let ex = example_arg;
    let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let cranes = [ex("cranes_v_dltdv.csv")];
    let cranes_read = v(&["--wingspan-px", "22", "--heading", "300"]);
    let mut out = Vec::new();
    for (name, input, read) in [
        ("geese", ex("barnacle_geese_v.json"), vec![]),
        ("snow", ex("snow_geese_j.csv"), vec![]),
        ("cranes", cranes[0].clone(), cranes_read.clone()),
        ("pelicans", ex("pelicans_u_labelme"), vec![]),
    ] {
        let mut extract = vec!["extract".to_string(), input.clone()];
        extract.extend(read.iter().cloned());
        out.push((leak(format!("extract-{name}")), "params.json", extract));
        let mut animate = vec!["animate".to_string(), input];
        animate.extend(read);
        animate.extend(v(&["--birds", "12", "--seconds", "3"]));
        out.push((leak(format!("animate-{name}")), "anim.json", animate));
    }
    let params = support::data("steady_v9_params.json")
        .to_string_lossy()
        .into_owned();
    out.push((
        "animate-params-v9",
        "anim.json",
        v(&["animate", &params, "--birds", "14", "--seconds", "2"]),
    ));
    out.push((
        "animate-geese-csv",
        "anim.csv",
        v(&[
            "animate",
            &ex("barnacle_geese_v.json"),
            "--birds",
            "7",
            "--seconds",
            "2",
        ]),
    ));
    out.push((
        "animate-geese-steady-crane",
        "anim.json",
        v(&[
            "animate",
            &ex("barnacle_geese_v.json"),
            "--birds",
            "5",
            "--seconds",
            "4",
            "--no-initiation",
            "--species",
            "crane",
            "--phase",
            "independent",
            "--glide",
            "bouts",
            "--fps",
            "24",
            "--key-every",
            "2",
            "--speed",
            "8",
        ]),
    ));
    out.push((
        "animate-snow-exact",
        "anim.json",
        v(&[
            "animate",
            &ex("snow_geese_j.csv"),
            "--birds",
            "8",
            "--seconds",
            "2",
            "--perception",
            "exact",
            "--max-turn-rate",
            "120",
            "--start-width",
            "20",
            "--heading-spread",
            "90",
        ]),
    ));
    // `--jostle 0` (key-shape interpolation only) must keep reproducing the flights from
    // before the position-keeping motion became the default: these digests are those outputs'.
    let still: Vec<_> = out
        .iter()
        .filter(|(name, _, _)| name.starts_with("animate-"))
        .map(|(name, file, args)| {
            let mut args = args.clone();
            args.extend(v(&["--jostle", "0"]));
            (leak(format!("{name}-jostle0")), *file, args)
        })
        .collect();
    out.extend(still);
    out
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

fn recorded() -> BTreeMap<String, String> {
    let path = repo_file(DIGESTS);
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let (hash, name) = l.split_once("  ").expect("`HASH  NAME` lines");
            (name.trim().to_string(), hash.to_string())
        })
        .collect()
}

#[test]
fn outputs_match_the_recorded_digests() {
    let dir = scratch("golden");
    let mut got = BTreeMap::new();
    for (name, file, args) in cases() {
        let out_path = dir.join(format!("{name}-{file}"));
        let out = bin()
            .args(&args)
            .args(["--seed", "7", "--quiet", "-o", s(&out_path)])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&out_path).unwrap();
        got.insert(name.to_string(), sha256_hex(&bytes));
    }
    if std::env::var_os("FORMATION_BLESS").is_some() {
        let mut text = String::from(
            "# SHA-256 of tests/golden.rs's outputs (seed 7); regenerate with\n# FORMATION_BLESS=1 cargo test --release --test golden\n",
        );
        for (name, hash) in &got {
            text.push_str(&format!("{hash}  {name}\n"));
        }
        let path = repo_file(DIGESTS);
        std::fs::write(path, text).unwrap();
        return;
    }
    let want = recorded();
    let mut diffs = Vec::new();
    for (name, hash) in &got {
        match want.get(name) {
            Some(w) if w == hash => {}
            Some(w) => diffs.push(format!("{name}: recorded {w}, now {hash}")),
            None => diffs.push(format!("{name}: no recorded digest")),
        }
    }
    for name in want.keys().filter(|n| !got.contains_key(*n)) {
        diffs.push(format!("{name}: recorded but no longer produced"));
    }
    assert!(
        diffs.is_empty(),
        "outputs differ from {DIGESTS} (if intended, FORMATION_BLESS=1 cargo test --release --test golden):\n{}",
        diffs.join("\n")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sha256_matches_the_standard_vectors() {
    assert_eq!(
        sha256_hex(b""),
        "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
    );
    assert_eq!(
        sha256_hex(b"abc"),
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    );
    let long = vec![b'a'; 1000];
    assert_eq!(
        sha256_hex(&long),
        "41edece42d63e8d9bf515a9ba6932e1c20cbc9f5a5d134645adb5db1b9737ea3"
    );
}
