//! Legends sit off the data: in the charts that draw their legend over the plot (the wingbeat of
//! each species, the power bars), no point of a data curve (a polyline of more than a legend
//! sample's two points) and no bar falls inside the legend's box. Read from the SVG the chart
//! writes, so the test sees exactly where each was drawn. (The ξ and savings charts put their
//! legends beside the plot.)

mod support;

use support::{example, run, s, scratch};

/// A rectangle `(x0, y0, x1, y1)` in the SVG's pixels.
type Rect = (f64, f64, f64, f64);

fn attr(tag: &str, name: &str) -> Option<f64> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    tag[at..].split('"').next()?.parse().ok()
}

/// The legend boxes: the half-opaque white rectangles plotters fills behind a series legend.
fn legends(svg: &str) -> Vec<Rect> {
    svg.split("<rect")
        .skip(1)
        .filter(|t| {
            let t = t.split('>').next().unwrap_or("");
            t.contains("fill=\"#FFFFFF\"") && t.contains("opacity=\"0.85\"")
        })
        .filter_map(|t| {
            let (x, y) = (attr(t, "x")?, attr(t, "y")?);
            Some((x, y, x + attr(t, "width")?, y + attr(t, "height")?))
        })
        .collect()
}

/// Points of the data curves: polylines of more than two points (a legend's sample line has two).
fn curve_points(svg: &str) -> Vec<(f64, f64)> {
    let mut v = Vec::new();
    for t in svg.split("<polyline").skip(1) {
        let Some(at) = t.find("points=\"") else {
            continue;
        };
        let pts: Vec<(f64, f64)> = t[at + 8..]
            .split('"')
            .next()
            .unwrap_or("")
            .split_whitespace()
            .filter_map(|p| {
                let (x, y) = p.split_once(',')?;
                Some((x.parse().ok()?, y.parse().ok()?))
            })
            .collect();
        if pts.len() > 2 {
            v.extend(pts);
        }
    }
    v
}

fn inside(r: Rect, p: (f64, f64)) -> bool {
    p.0 > r.0 && p.0 < r.2 && p.1 > r.1 && p.1 < r.3
}

fn plot_svg(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = args[args.iter().position(|a| *a == "-o").unwrap() + 1];
    std::fs::read_to_string(svg).unwrap()
}

fn assert_legend_off_the_data(what: &str, svg: &str) {
    let boxes = legends(svg);
    assert!(!boxes.is_empty(), "{what}: no legend found");
    let pts = curve_points(svg);
    assert!(pts.len() > 50, "{what}: only {} curve points", pts.len());
    for r in boxes {
        let hit: Vec<_> = pts.iter().filter(|&&p| inside(r, p)).collect();
        assert!(
            hit.is_empty(),
            "{what}: {} curve points under the legend {r:?}, e.g. {:?}",
            hit.len(),
            hit.first()
        );
    }
}

#[test]
fn wingbeat_legends_cover_no_curve() {
    let d = scratch("legend-wingbeat");
    for species in ["goose", "crane", "pelican"] {
        let svg = d.join(format!("{species}.svg"));
        let text = plot_svg(&[
            "plot",
            "wingbeat",
            "--species",
            species,
            "-o",
            s(&svg),
            "--quiet",
        ]);
        assert_legend_off_the_data(&format!("wingbeat of {species}"), &text);
    }
}

/// The bars of a bar chart: opaque filled rectangles other than the background and the legend's
/// swatches (which sit inside the legend box).
fn bars(svg: &str, legends: &[Rect]) -> Vec<Rect> {
    svg.split("<rect")
        .skip(1)
        .filter_map(|t| {
            let t = t.split('>').next()?;
            if !t.contains("opacity=\"1\"")
                || t.contains("fill=\"#FFFFFF\"")
                || t.contains("fill=\"none\"")
            {
                return None;
            }
            let (x, y) = (attr(t, "x")?, attr(t, "y")?);
            let r = (x, y, x + attr(t, "width")?, y + attr(t, "height")?);
            let swatch = legends
                .iter()
                .any(|l| r.0 >= l.0 && r.2 <= l.2 && r.1 >= l.1 && r.3 <= l.3);
            (!swatch).then_some(r)
        })
        .collect()
}

#[test]
fn power_chart_legend_covers_no_bar() {
    let d = scratch("legend-power");
    let anim = d.join("flock.json");
    let out = run(&[
        "animate",
        s(&example("barnacle_geese_v.json")),
        "--birds",
        "9",
        "--seconds",
        "6",
        "-o",
        s(&anim),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = d.join("power.svg");
    let text = plot_svg(&["plot", "power", s(&anim), "-o", s(&svg), "--quiet"]);
    let boxes = legends(&text);
    assert_eq!(boxes.len(), 1, "power chart legends {boxes:?}");
    let bars = bars(&text, &boxes);
    assert!(bars.len() >= 9, "only {} bars", bars.len());
    let l = boxes[0];
    for b in bars {
        let overlap = b.0 < l.2 && l.0 < b.2 && b.1 < l.3 && l.1 < b.3;
        assert!(!overlap, "bar {b:?} under the legend {l:?}");
    }
}
