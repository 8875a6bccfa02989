//! The figures the README and the docs quote from the tool's own runs are the runs' figures: the
//! README job is run as the README gives it and its summary, durations and file sizes are held
//! against README.md, docs/usage.md and docs/export.md (sizes within 10 %, the summary exactly),
//! the .glb's last frame against the Blender steps of usage.md and export.md, and the CSV's
//! columns against usage.md's list; the large-flock sentence of docs/usage.md against a
//! 1000-bird run; usage.md's studio shot (frames, numbering, sizes) and its staged pipeline
//! (`extract`, `steady`, `initiate`, `render` against `animate`, within the bounds it states);
//! docs/performance.md's README-job GIF size.

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

    // The .glb's last frame (its scene extras' `frame_end`) where usage.md and export.md give it.
    let frame_end = glb_frame_end(&dir.join("flock.glb"));
    // usage.md's flock is animated from the extracted parameters without `--species`.
    let out = bin()
        .current_dir(&dir)
        .args(["animate"])
        .arg(repo_file("examples_data/barnacle_geese_v.json"))
        .args(["--birds", "14", "--quiet", "-o", "usage.glb"])
        .output()
        .unwrap();
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let usage_end = glb_frame_end(&dir.join("usage.glb"));
    let usage_says = |before: &str| number_after(&usage, before, "usage frame_end");
    assert_eq!(
        usage_says("in the file's scene extras: ") as u64,
        usage_end,
        "docs/usage.md frame_end"
    );
    assert_eq!(
        usage_says("bird playing frames 0–") as u64,
        usage_end,
        "docs/usage.md frames played"
    );
    let export_doc = doc("docs/export.md");
    assert_eq!(
        number_after(&export_doc, "(the README job: 0 and ", "export frame_end") as u64,
        frame_end,
        "docs/export.md frame_end"
    );
    assert_eq!(
        number_after(
            &export_doc,
            "one action per bird playing frames 0–",
            "export"
        ) as u64,
        frame_end,
        "docs/export.md frames played"
    );

    // usage.md names every column of the CSV.
    let header = std::fs::read_to_string(dir.join("flock.csv")).unwrap();
    let header = header.lines().next().unwrap().to_string();
    let para = &usage[usage
        .find("`flock.csv` has one row per frame and bird")
        .unwrap()..];
    let para = &para[..para.find("formats.md").unwrap()];
    let named: Vec<&str> = para
        .split('`')
        .skip(1)
        .step_by(2)
        .flat_map(|t| t.split(','))
        .collect();
    for column in header.split(',') {
        assert!(
            named.contains(&column),
            "docs/usage.md's CSV paragraph does not name the column `{column}` ({header})"
        );
    }

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

/// The scene extras' `frame_end` of a .glb (its JSON chunk).
fn glb_frame_end(path: &Path) -> u64 {
    let glb = std::fs::read(path).unwrap();
    let chunk = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + chunk]).unwrap();
    json["scenes"][0]["extras"]["frame_end"].as_u64().unwrap()
}

/// Columns of a CSV file: the header and the rows as text fields.
fn csv_table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

#[test]
fn the_studio_shot_is_as_usage_md_says() {
    let usage = doc("docs/usage.md");
    let command = "formation animate examples_data/barnacle_geese_v.json --birds 14 --fps 24 --shot-seconds 40 \\ --start-frame 1001 --subframes 4 --units m --up y --path-out layout.json \\ -o shot.glb -o shot.usda -o shot.csv";
    assert!(
        usage.contains(command),
        "docs/usage.md: the shot's command changed; update this test"
    );
    let dir = scratch("docs-figures-shot");
    let out = bin()
        .current_dir(&dir)
        .arg("animate")
        .arg(repo_file("examples_data/barnacle_geese_v.json"))
        .args([
            "--birds",
            "14",
            "--fps",
            "24",
            "--shot-seconds",
            "40",
            "--start-frame",
            "1001",
            "--subframes",
            "4",
            "--units",
            "m",
            "--up",
            "y",
            "--path-out",
            "layout.json",
            "-o",
            "shot.glb",
            "-o",
            "shot.usda",
            "-o",
            "shot.csv",
            "--quiet",
        ])
        .output()
        .unwrap();
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let (_, rows) = csv_table(&dir.join("shot.csv"));
    let first: u64 = rows.first().unwrap()[0].parse().unwrap();
    let last: u64 = rows.last().unwrap()[0].parse().unwrap();
    let frames = number_after(&usage, "gives exactly ", "usage shot") as u64;
    assert_eq!(
        last - first + 1,
        frames,
        "docs/usage.md: frames of the shot"
    );
    assert_eq!(first, 1001);
    assert_eq!(
        number_after(&usage, "numbered 1001–", "usage shot") as u64,
        last,
        "docs/usage.md: the shot's last frame"
    );
    let sizes = &usage[usage.find("This takes about ").unwrap()..];
    close(
        "usage shot .glb",
        number_after(sizes, "writes a ", "usage"),
        mb(&dir.join("shot.glb")),
        0.1,
    );
    close(
        "usage shot .usda",
        number_after(sizes, "`.glb`, a ", "usage"),
        mb(&dir.join("shot.usda")),
        0.1,
    );
    close(
        "usage shot .csv",
        number_after(sizes, "`.usda` and a ", "usage"),
        mb(&dir.join("shot.csv")),
        0.1,
    );
}

#[test]
fn the_staged_pipeline_is_animate_s_within_the_files_precision() {
    let dir = scratch("docs-figures-staged");
    let example = repo_file("examples_data/barnacle_geese_v.json");
    let ex = example.to_str().unwrap();
    for args in [
        vec!["animate", ex, "--birds", "14", "-o", "animate.csv"],
        vec!["extract", ex, "-o", "params.json"],
        vec![
            "steady",
            "params.json",
            "--birds",
            "14",
            "--seconds",
            "20",
            "-o",
            "steady.json",
        ],
        vec!["initiate", "steady.json", "-o", "flight.json"],
        vec!["render", "flight.json", "-o", "flock.csv"],
    ] {
        let out = bin()
            .current_dir(&dir)
            .args(&args)
            .arg("--quiet")
            .output()
            .unwrap();
        assert_eq!(code(&out), 0, "{args:?}: {}", stderr(&out));
    }
    let (ha, a) = csv_table(&dir.join("animate.csv"));
    let (hb, b) = csv_table(&dir.join("flock.csv"));
    assert_eq!(ha, hb);
    assert_eq!(a.len(), b.len(), "rows");
    let bound = |column: &str| -> f64 {
        match column {
            "frame" | "t" | "bird" | "stage" | "formation" | "rank" | "leader" => 0.0,
            "x" | "y" | "z" | "lateral" | "behind" | "speed" => 2e-5,
            "e" | "xi" | "saving_total" => 5e-5,
            // Angles: heading, bank, pitch, wing phase and the quaternion.
            _ => 6e-5,
        }
    };
    let mut differ = 0;
    for (ra, rb) in a.iter().zip(&b) {
        differ += usize::from(ra != rb);
        for ((column, va), vb) in ha.iter().zip(ra).zip(rb) {
            if va == vb {
                continue;
            }
            let d = match (va.parse::<f64>(), vb.parse::<f64>()) {
                (Ok(x), Ok(y)) => (x - y).abs(),
                _ => f64::INFINITY,
            };
            assert!(
                d <= bound(column) + 1e-12,
                "frame {} bird {}: {column} {va} (animate) against {vb} (staged), over {}",
                ra[0],
                ra[2],
                bound(column)
            );
        }
    }
    let usage = doc("docs/usage.md");
    let said = number_after(&usage, "On the README job ", "usage staged");
    let tail = &usage[usage.find("On the README job ").unwrap()..];
    let tail = &tail[tail.find(" of the ").unwrap() + " of the ".len()..];
    // The row count is written with a space between thousands ("18 047").
    let digits: String = tail
        .chars()
        .take_while(|c| c.is_ascii_digit() || c.is_whitespace())
        .filter(char::is_ascii_digit)
        .collect();
    assert_eq!(
        digits.parse::<usize>().unwrap(),
        a.len(),
        "docs/usage.md: rows of the CSV"
    );
    assert!(
        (said - differ as f64).abs() <= 0.1 * differ as f64,
        "docs/usage.md says {said} rows differ, the run gives {differ}"
    );
}

#[test]
fn the_performance_page_s_readme_job_gif_is_the_run_s() {
    let dir = scratch("docs-figures-perf-gif");
    let out = bin()
        .current_dir(&dir)
        .arg("animate")
        .arg(repo_file("examples_data/barnacle_geese_v.json"))
        .args(["--birds", "14", "-o", "flock.gif", "--quiet"])
        .output()
        .unwrap();
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let perf = doc("docs/performance.md");
    let row = &perf[perf
        .find("| GIF size | 42.2 MB | 9.18 MB")
        .expect("the README job's table")..];
    close(
        "docs/performance.md README job GIF (re-measured column)",
        number_after(row, "| **", "performance"),
        mb(&dir.join("flock.gif")),
        0.1,
    );
}
