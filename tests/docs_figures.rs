//! The figures the README and the docs quote from the tool's own runs are the runs' figures: the
//! README job is run as the README gives it and its summary, durations and file sizes are held
//! against README.md, docs/usage.md and docs/export.md (sizes within 10 %, the summary exactly);
//! the large-flock sentence of docs/usage.md against a 1000-bird run.

mod support;

use std::path::Path;

use support::{bin, code, repo_file, scratch, stderr};

/// A document's text with every run of whitespace made one space (sentences wrap).
fn doc(rel: &str) -> String {
    let text = std::fs::read_to_string(repo_file(rel)).unwrap();
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The number right after `before` in `text` (e.g. `about 4.6` after "flock.gif` is about ").
fn number_after(text: &str, before: &str, what: &str) -> f64 {
    let at = text
        .find(before)
        .unwrap_or_else(|| panic!("{what}: no {before:?}"))
        + before.len();
    let digits: String = text[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    digits
        .trim_end_matches('.')
        .parse()
        .unwrap_or_else(|_| panic!("{what}: no number after {before:?}"))
}

/// Megabytes of a file, as the summaries print them.
fn mb(path: &Path) -> f64 {
    std::fs::metadata(path).unwrap().len() as f64 / 1e6
}

fn close(what: &str, doc: f64, real: f64, rel: f64) {
    assert!(
        (doc - real).abs() <= rel * real,
        "{what}: the docs say {doc}, the run gives {real:.2}"
    );
}

#[test]
fn the_readme_job_s_figures_are_the_run_s() {
    let dir = scratch("docs-figures");
    // The README's command, as given (without --quiet: its summary is quoted in the docs).
    let out = bin()
        .current_dir(&dir)
        .args(["animate"])
        .arg(repo_file("examples_data/barnacle_geese_v.json"))
        .args([
            "--birds",
            "14",
            "--species",
            "barnacle-goose",
            "-o",
            "flock.gif",
            "-o",
            "flock.glb",
            "-o",
            "flock.csv",
        ])
        .output()
        .unwrap();
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let summary = stderr(&out);
    let summary = summary.trim_end();
    let takeoff = number_after(summary, "take-off ", "summary");
    let steady = number_after(summary, "steady flight ", "summary");
    let (gif, glb, csv) = (
        mb(&dir.join("flock.gif")),
        mb(&dir.join("flock.glb")),
        mb(&dir.join("flock.csv")),
    );

    // docs/usage.md quotes the summary word for word.
    let usage_raw = std::fs::read_to_string(repo_file("docs/usage.md")).unwrap();
    assert!(
        usage_raw.contains(summary),
        "docs/usage.md should quote the README job's summary:\n{summary}"
    );
    let usage = doc("docs/usage.md");
    close(
        "docs/usage.md GIF size",
        number_after(&usage, "This 14-bird GIF is about ", "usage"),
        gif,
        0.1,
    );

    // README.md: duration, take-off, steady flight and the three sizes.
    let readme = doc("README.md");
    let total = number_after(&readme, "25 fps, about ", "README");
    let readme = &readme[readme.find("25 fps, about ").unwrap()..];
    assert!(
        (total - (takeoff + steady)).abs() <= 0.5,
        "README: about {total} s, the run {takeoff} + {steady} s"
    );
    close(
        "README take-off",
        number_after(readme, "s: a ", "README"),
        takeoff,
        0.01,
    );
    close(
        "README steady",
        number_after(readme, "ground take-off, then ", "README"),
        steady,
        0.01,
    );
    close(
        "README GIF",
        number_after(readme, "of steady flight; about ", "README"),
        gif,
        0.1,
    );
    close(
        "README .glb",
        number_after(readme, "`flock.glb` about ", "README"),
        glb,
        0.1,
    );
    close(
        "README .csv",
        number_after(readme, "`flock.csv` about ", "README"),
        csv,
        0.1,
    );

    // docs/export.md: the GIF's length and size.
    let export = doc("docs/export.md");
    let marker = "The README job's GIF (14 birds, 960×540, ";
    close(
        "docs/export.md duration",
        number_after(&export, marker, "export"),
        takeoff + steady,
        0.01,
    );
    close(
        "docs/export.md GIF size",
        number_after(&export, "at 25 fps) is about ", "export"),
        gif,
        0.1,
    );
}

#[test]
fn the_large_flock_sentence_is_the_run_s() {
    let dir = scratch("docs-figures-skeins");
    let out = bin()
        .current_dir(&dir)
        .args(["animate"])
        .arg(repo_file("examples_data/barnacle_geese_v.json"))
        .args([
            "--birds",
            "1000",
            "--seconds",
            "1",
            "--no-initiation",
            "-o",
            "x.json",
        ])
        .output()
        .unwrap();
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let err = stderr(&out);
    let lo = number_after(&err, "formations of ", "summary");
    let hi = number_after(&err, &format!("formations of {lo} to "), "summary");
    let usage = doc("docs/usage.md");
    let want = format!("the 9-goose example gives formations of {lo} to {hi} geese");
    assert!(
        usage.contains(&want),
        "docs/usage.md should say {want:?} ({err})"
    );
}
