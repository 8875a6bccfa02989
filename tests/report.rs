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

/// The page's text as a reader sees it: tags, styles and charts removed, entities decoded,
/// whitespace collapsed.
fn visible_text(page: &str) -> String {
    let mut rest = page.to_string();
    for tag in ["style", "script", "svg"] {
        let (open, close) = (format!("<{tag}"), format!("</{tag}>"));
        let mut kept = String::new();
        let mut r = rest.as_str();
        while let Some(a) = r.find(&open) {
            kept.push_str(&r[..a]);
            r = r[a..]
                .find(&close)
                .map_or("", |b| &r[a + b + close.len()..]);
        }
        kept.push_str(r);
        rest = kept;
    }
    let mut text = String::new();
    let mut in_tag = false;
    for c in rest.chars() {
        match c {
            '<' => in_tag = true,
            '>' => {
                in_tag = false;
                text.push(' ');
            }
            _ if !in_tag => text.push(c),
            _ => {}
        }
    }
    let text = text
        .replace("&amp;", "&")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'");
    text.split_whitespace().collect::<Vec<_>>().join(" ")
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
        [
            "geometry",
            "fit-0",
            "fit-10",
            "fit-19",
            "intervals",
            "saving-band",
            "footage-savings"
        ],
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
    assert_eq!(charts(&page), ["saving-band", "savings", "xi", "paths"]);
    for needle in [
        "flock saving in steady flight",
        "Take-off (§6)",
        "closest approach of two birds",
        "flock saving at the hand-over",
        "#C81E1E",
        // The 3-D player, in a frame of its own.
        "<h2 id=\"player\">",
        "<iframe class=\"player\"",
        "srcdoc=\"&lt;!DOCTYPE html&gt;",
    ] {
        assert!(page.contains(needle), "missing {needle:?}");
    }
    // The range over the modelling choices leads the table, induced and total, and holds the
    // chosen model's value.
    let text = visible_text(&page);
    let row = text
        .split("range over models, wakes and cores (model estimates)")
        .nth(1)
        .expect("no range row");
    let pcts: Vec<f64> = row
        .split(" %")
        .take(4)
        .map(|p| p.rsplit(' ').next().unwrap().parse().unwrap())
        .collect();
    let point: f64 = text
        .split("flock saving in steady flight (of induced power,")
        .nth(1)
        .and_then(|r| r.split(" %").next())
        .and_then(|r| r.rsplit(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        pcts[0] <= point && point <= pcts[1] && pcts[2] < pcts[0] && pcts[3] < pcts[1],
        "range row {pcts:?}, point {point}"
    );
    assert!(
        row[..200.min(row.len())].contains("of total power"),
        "{row}"
    );
    // Clean numbers: no negative zeros, no empty lists.
    for bad in ["[]", "NaN"] {
        assert!(!text.contains(bad), "the page shows {bad:?}");
    }
    let negative_zero = text.split_whitespace().find(|w| {
        let w = w.trim_matches(|c: char| !(c.is_ascii_digit() || c == '-' || c == '.'));
        w.starts_with('-') && w.parse::<f64>() == Ok(0.0)
    });
    assert_eq!(negative_zero, None, "the page shows a negative zero");
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
    // The savings flags: the animation's savings recomputed with another model, named on the
    // page; the band holds both models.
    let other = report(
        s(&json),
        &dir.join("c.html"),
        &["--aero-model", "lissaman", "--wake", "3d", "--mass-kg", "3"],
    );
    self_contained(&other);
    assert!(other.contains("Lissaman &amp; Shollenberger-type lifting lines, 3d wake, no core"));
    assert!(!page.contains("Lissaman &amp; Shollenberger-type lifting lines, 3d wake"));
    assert!(other.contains("3.00 kg"));
    for label in ["hummel, planar, core 0.04", "lissaman, planar"] {
        assert!(other.contains(label), "band lacks {label}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn error_bars_come_from_the_params_intervals() {
    let dir = scratch("report-ci");
    let p = dir.join("p.json");
    assert_eq!(
        code(&run(&[
            "extract",
            &example_arg("barnacle_geese_v.json"),
            "-o",
            s(&p),
            "-q"
        ])),
        0
    );
    let params: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let ci = &params["ci"];
    let page = report(s(&p), &dir.join("p.html"), &[]);
    let fig = page
        .split("data-chart=\"intervals\"")
        .nth(1)
        .and_then(|r| r.split("</figure>").next())
        .expect("an intervals figure");
    // Every interval's ends are printed on its error bar (two decimals; degrees with one).
    for (key, prec, unit) in [
        ("apex_deg", 1, "°"),
        ("lateral", 2, ""),
        ("behind", 2, ""),
        ("depth", 2, ""),
        ("wts", 2, ""),
    ] {
        let iv = ci[key].as_array().unwrap_or_else(|| panic!("ci.{key}"));
        for end in iv {
            let text = format!(">{:.*}{unit}<", prec, end.as_f64().unwrap());
            assert!(fig.contains(&text), "ci.{key}: {text} not drawn");
        }
    }
    // Five error bars: three lines each (bar and two caps).
    assert_eq!(fig.matches("stroke=\"#1f5fa8\"").count(), 15);
    let _ = std::fs::remove_dir_all(&dir);
}
