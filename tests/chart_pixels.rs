//! The charts read as the docs say, checked on their pixels: every bird chart colours birds by
//! rank with the leader in red, and the shape chart's outliers are not red.

use formation::plot::{bird_colour, LEADER};

mod support;

use support::{example, run, s, scratch};

fn plot(args: &[&str]) -> image::RgbImage {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = args[args.iter().position(|a| *a == "-o").unwrap() + 1];
    image::open(png).unwrap().to_rgb8()
}

fn has(img: &image::RgbImage, c: plotters::style::RGBColor) -> bool {
    img.pixels().any(|p| p.0 == [c.0, c.1, c.2])
}

/// How many of the rank colours `1..n` of `n` birds appear exactly.
fn rank_colours(img: &image::RgbImage, n: usize) -> usize {
    (1..n).filter(|&r| has(img, bird_colour(r, n))).count()
}

#[test]
fn shape_chart_colours_birds_by_rank_with_the_leader_red() {
    let d = scratch("chart-shape");
    let params = d.join("params.json");
    let out = run(&[
        "extract",
        s(&example("barnacle_geese_v.json")),
        "-o",
        s(&params),
        "--quiet",
    ]);
    assert!(out.status.success());
    let png = d.join("shape.png");
    let img = plot(&["plot", "shape", s(&params), "-o", s(&png), "--quiet"]);
    assert!(has(&img, LEADER), "no leader red in the shape chart");
    // 9 geese: the 8 behind the leader in at least 6 distinct rank colours (two may share a
    // depth and a colour step).
    let n = rank_colours(&img, 9);
    assert!(n >= 6, "only {n} rank colours in the shape chart");
    // The old one-colour inliers and green leader are gone.
    assert!(!has(&img, plotters::style::RGBColor(31, 119, 180)));
    assert!(!has(&img, plotters::style::RGBColor(44, 160, 44)));
}

#[test]
fn power_chart_colours_bars_by_rank_with_the_leader_red() {
    let d = scratch("chart-power");
    let anim = d.join("flock.json");
    let out = run(&[
        "animate",
        s(&example("barnacle_geese_v.json")),
        "--birds",
        "9",
        "--seconds",
        "3",
        "-o",
        s(&anim),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for extra in [&[][..], &["--frame", "0"][..]] {
        let png = d.join("power.png");
        let mut args = vec!["plot", "power", s(&anim), "-o", s(&png), "--quiet"];
        args.extend_from_slice(extra);
        let img = plot(&args);
        assert!(
            has(&img, LEADER),
            "{extra:?}: no leader red in the power chart"
        );
        let n = rank_colours(&img, 9);
        assert!(
            n >= 6,
            "{extra:?}: only {n} rank colours in the power chart"
        );
    }
}
