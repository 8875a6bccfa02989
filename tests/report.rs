//! `formation report` (issue 16): one self-contained page for annotations, a params file and an
//! animation, with the charts and sections each must have. (CI also opens the pages in headless
//! Chromium: `.ci/check_report.sh`.)

mod support;

use support::*;

fn report(input: &str, out: &std::path::Path, extra: &[&str]) -> String {
    let mut args = vec!["report", input, "-o", s(out), "-q"];
    args.extend(extra);
    let o = run(&args);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    std::fs::read_to_string(out).unwrap()
}

fn charts(page: &str) -> Vec<String> {
    page.split("<figure class=\"chart\" data-chart=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().to_string())
        .collect()
}

fn self_contained(page: &str) {
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(page.trim_end().ends_with("</html>"));
    for bad in [
        "src=\"http",
        "href=\"http",
        "src=\"//",
        "<link",
        "<img",
        "@import",
        "url(",
    ] {
        assert!(!page.contains(bad), "page fetches something: {bad}");
    }
    let n = charts(page).len();
    assert!(page.contains(&format!("<body data-charts=\"{n}\">")));
    assert_eq!(page.matches("<svg").count(), n, "one inline SVG per chart");
}

#[test]
fn the_page_of_annotations_has_parameters_fits_savings_and_the_field() {
    let dir = scratch("report-annotations");
    let page = report(
        &example_arg("barnacle_geese_v.json"),
        &dir.join("r.html"),
        &["--wingspan-m", "1.4"],
    );
    self_contained(&page);
    let c = charts(&page);
    assert_eq!(
        c,
        ["geometry", "fit-0", "fit-10", "fit-19", "footage-savings"],
        "{c:?}"
    );
    for needle in [
        "Extracted parameters (§4)",
        "Shapes fitted: V in 20 of 20",
        "apex angle",
        "mean wingtip spacing",
        " m (median;",
        "Savings in the footage",
        "Compared with real formations",
        "Gould &amp; Heppner 1974",
        "position (arm, place from the leader)",
        "<td>left 1</td>",
    ] {
        assert!(page.contains(needle), "missing {needle:?}");
    }
    // Every annotated frame has a row.
    assert!(page.matches("<tr><td>").count() >= 20);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_page_of_an_animation_has_savings_take_off_and_its_charts() {
    let dir = scratch("report-animation");
    let json = dir.join("flock.json");
    let o = run(&[
        "animate",
        &example_arg("barnacle_geese_v.json"),
        "--birds",
        "9",
        "--seconds",
        "2",
        "-o",
        s(&json),
        "-q",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let page = report(s(&json), &dir.join("a.html"), &[]);
    self_contained(&page);
    assert_eq!(charts(&page), ["savings", "xi", "paths"]);
    for needle in [
        "flock saving in steady flight",
        "Take-off (§6)",
        "closest approach of two birds",
        "flock saving at the hand-over",
        "#C81E1E",
    ] {
        assert!(page.contains(needle), "missing {needle:?}");
    }
    // Same input, same bytes.
    let again = report(s(&json), &dir.join("b.html"), &[]);
    assert_eq!(page, again);
    // A params file.
    let p = dir.join("p.json");
    assert_eq!(
        code(&run(&[
            "extract",
            &example_arg("snow_geese_j.csv"),
            "-o",
            s(&p),
            "-q"
        ])),
        0
    );
    let page = report(s(&p), &dir.join("p.html"), &[]);
    self_contained(&page);
    assert!(page.contains("J in 24 of 24"));
    let _ = std::fs::remove_dir_all(&dir);
}
