//! The pictures of docs/steady-flight.md: the lateral position of three birds over a minute of
//! steady flight, with key-shape interpolation only and with the living flight (position
//! keeping, leader changes and swaps); and a leader change seen from above in the flock's frame
//! and from the side.
//!
//! ```text
//! formation steady examples_data/barnacle_geese_v.json --birds 9 --seconds 60 --jostle 0 -o still.json
//! formation steady examples_data/barnacle_geese_v.json --birds 9 --seconds 60 -o living.json
//! cargo run --release --example steady_figures -- still.json living.json docs/images
//! ```

use std::path::Path;

use formation::animation::{Animation, EventKind};
use formation::plot::{bird_colour, draw_mesh, save, Chart, DrawResult, FONT_FAMILY, LEADER};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Each bird's (time, value) series.
type Series = Vec<Vec<(f64, f64)>>;

/// Lateral positions (wingspans) over time of three birds in two flights.
struct Lateral {
    panels: Vec<(String, Series)>,
    birds: Vec<usize>,
}

impl Chart for Lateral {
    fn size(&self) -> (u32, u32) {
        (1100, 700)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (lo, hi) = self
            .panels
            .iter()
            .flat_map(|(_, s)| s.iter().flatten())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        let t_end = self
            .panels
            .iter()
            .flat_map(|(_, s)| s.iter().flatten())
            .fold(0.0f64, |a, p| a.max(p.0));
        let areas = root.split_evenly((self.panels.len(), 1));
        for (area, (title, series)) in areas.iter().zip(&self.panels) {
            let mut chart = ChartBuilder::on(area)
                .caption(title, (FONT_FAMILY, 20))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t_end, (lo - 0.2)..(hi + 0.2))?;
            draw_mesh(&mut chart, "time, s", "lateral position, wingspans", 15)?;
            for (k, s) in series.iter().enumerate() {
                let colour = bird_colour(2 * k + 1, 2 * self.birds.len() + 1);
                chart
                    .draw_series(LineSeries::new(s.iter().copied(), colour.stroke_width(2)))?
                    .label(format!("bird {}", self.birds[k]))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                    });
            }
            formation::plot::draw_legend(&mut chart, 14, SeriesLabelPosition::UpperRight)?;
        }
        Ok(())
    }
}

/// A leader change from above, in the flock's frame (x across, distance ahead = y − v t).
struct LeaderChange {
    title: String,
    /// Every bird's path during the manoeuvre.
    paths: Vec<Vec<(f64, f64)>>,
    /// The old and the new leader.
    pair: (usize, usize),
}

impl Chart for LeaderChange {
    fn size(&self) -> (u32, u32) {
        (900, 800)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let pts = self.paths.iter().flatten();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in pts {
            x0 = x0.min(p.0);
            x1 = x1.max(p.0);
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
        // Equal scales: widen the narrower axis.
        let (w, h) = (x1 - x0 + 1.0, y1 - y0 + 1.0);
        let s = (w / 780.0).max(h / 680.0);
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let (hw, hh) = (0.5 * 780.0 * s, 0.5 * 680.0 * s);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((cx - hw)..(cx + hw), (cy - hh)..(cy + hh))?;
        draw_mesh(
            &mut chart,
            "across, wingspans",
            "ahead (flock frame), wingspans",
            15,
        )?;
        for (i, p) in self.paths.iter().enumerate() {
            if i == self.pair.0 || i == self.pair.1 {
                continue;
            }
            chart.draw_series(LineSeries::new(
                p.iter().copied(),
                RGBColor(150, 150, 150).stroke_width(1),
            ))?;
            if let (Some(&a), Some(&b)) = (p.first(), p.last()) {
                chart.draw_series([
                    Circle::new(a, 5, RGBColor(150, 150, 150).stroke_width(1)),
                    Circle::new(b, 5, RGBColor(150, 150, 150).filled()),
                ])?;
            }
        }
        for (who, colour, label) in [
            (self.pair.0, LEADER, "leader before: drops back"),
            (
                self.pair.1,
                RGBColor(33, 100, 180),
                "leader after: takes the lead",
            ),
        ] {
            let p = &self.paths[who];
            chart
                .draw_series(LineSeries::new(p.iter().copied(), colour.stroke_width(3)))?
                .label(format!("bird {who}, {label}"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            if let (Some(&a), Some(&b)) = (p.first(), p.last()) {
                chart.draw_series([
                    Circle::new(a, 6, colour.stroke_width(2)),
                    Circle::new(b, 6, colour.filled()),
                ])?;
            }
        }
        formation::plot::draw_legend(&mut chart, 14, SeriesLabelPosition::LowerRight)
    }
}

/// The same leader change seen from the side: fore-aft (ahead, flock frame) against height
/// over the other birds' mean height, and the pair's gaps on each axis over time against the
/// wing-clash test.
struct LeaderChangeSide {
    title: String,
    /// Every bird's (ahead, height) during the manoeuvre.
    side: Vec<Vec<(f64, f64)>>,
    /// The pair's gaps over time: (t, |across|, |ahead|, height of the one moving back over
    /// the other's).
    gaps: Vec<(f64, f64, f64, f64)>,
    /// The old and the new leader.
    pair: (usize, usize),
}

impl Chart for LeaderChangeSide {
    fn size(&self) -> (u32, u32) {
        (1000, 900)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        use formation::animation::clearance::{CHORD, SPAN, THICKNESS};
        let grey = RGBColor(150, 150, 150);
        let blue = RGBColor(33, 100, 180);
        let root = root.titled(&self.title, (FONT_FAMILY, 20))?;
        let (top, bottom) = root.split_vertically(470);
        // The side view: the pair's span fore and aft, a wingspan around.
        let pair_pts = || {
            self.side[self.pair.0]
                .iter()
                .chain(&self.side[self.pair.1])
                .copied()
        };
        let (a0, a1) = pair_pts().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
        let (a0, a1) = (a0 - 1.0, a1 + 1.0);
        let zmax = self
            .side
            .iter()
            .flatten()
            .filter(|p| p.0 >= a0 && p.0 <= a1)
            .fold(0.2f64, |m, p| m.max(p.1.abs()))
            * 1.25;
        let mut chart = ChartBuilder::on(&top)
            .caption(
                "From the side (flight to the right; height drawn about 10 times the fore-aft scale)",
                (FONT_FAMILY, 16),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(a0..a1, -zmax..zmax)?;
        draw_mesh(
            &mut chart,
            "ahead (flock frame), wingspans",
            "height over the others, wingspans",
            15,
        )?;
        for (i, p) in self.side.iter().enumerate() {
            if i == self.pair.0 || i == self.pair.1 {
                continue;
            }
            let p: Vec<(f64, f64)> = p
                .iter()
                .copied()
                .filter(|q| q.0 >= a0 && q.0 <= a1)
                .collect();
            chart.draw_series(LineSeries::new(p.iter().copied(), grey.stroke_width(1)))?;
            if let (Some(&a), Some(&b)) = (p.first(), p.last()) {
                chart.draw_series([
                    Circle::new(a, 5, grey.stroke_width(1)),
                    Circle::new(b, 5, grey.filled()),
                ])?;
            }
        }
        for (who, colour, label) in [
            (self.pair.0, LEADER, "leader before: dips and drops back"),
            (self.pair.1, blue, "leader after: lifts and moves up"),
        ] {
            let p = &self.side[who];
            chart
                .draw_series(LineSeries::new(p.iter().copied(), colour.stroke_width(3)))?
                .label(format!("bird {who}, {label}"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            if let (Some(&a), Some(&b)) = (p.first(), p.last()) {
                chart.draw_series([
                    Circle::new(a, 6, colour.stroke_width(2)),
                    Circle::new(b, 6, colour.filled()),
                ])?;
            }
        }
        formation::plot::draw_legend(&mut chart, 14, SeriesLabelPosition::UpperLeft)?;

        // The gaps over time against the clash test.
        let t0 = self.gaps.first().map_or(0.0, |g| g.0);
        let t1 = self.gaps.last().map_or(1.0, |g| g.0);
        let gmax = self
            .gaps
            .iter()
            .fold(1.2f64, |m, g| m.max(g.1.min(3.0)).max(g.2.min(3.0)));
        let mut chart = ChartBuilder::on(&bottom)
            .caption(
                "The pair's gaps: a wing clash needs all three under their dashed limits at once",
                (FONT_FAMILY, 16),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, -0.4..gmax * 1.05)?;
        draw_mesh(&mut chart, "time, s", "wingspans", 15)?;
        let green = RGBColor(40, 140, 60);
        for (colour, limit, label, pick) in [
            (
                blue,
                SPAN,
                "across",
                (|g: &(f64, f64, f64, f64)| g.1) as fn(&(f64, f64, f64, f64)) -> f64,
            ),
            (green, CHORD, "fore and aft", |g| g.2),
            (
                LEADER,
                THICKNESS,
                "height of the one moving back over the other",
                |g| g.3,
            ),
        ] {
            chart
                .draw_series(LineSeries::new(
                    self.gaps.iter().map(|g| (g.0, pick(g).min(gmax * 1.05))),
                    colour.stroke_width(2),
                ))?
                .label(format!("{label} (clash under {limit})"))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(3))
                });
            let mut dashes = Vec::new();
            let n = 60;
            for k in (0..n).step_by(2) {
                let a = t0 + (t1 - t0) * k as f64 / n as f64;
                let b = t0 + (t1 - t0) * (k + 1) as f64 / n as f64;
                dashes.push(PathElement::new(
                    vec![(a, limit), (b, limit)],
                    colour.stroke_width(1),
                ));
                if colour == LEADER {
                    dashes.push(PathElement::new(
                        vec![(a, -limit), (b, -limit)],
                        colour.stroke_width(1),
                    ));
                }
            }
            chart.draw_series(dashes)?;
        }
        formation::plot::draw_legend(&mut chart, 14, SeriesLabelPosition::UpperRight)
    }
}

/// The lateral position of `birds` over the whole flight.
fn lateral(a: &Animation, birds: &[usize]) -> Vec<Vec<(f64, f64)>> {
    birds
        .iter()
        .map(|&b| a.frames.iter().map(|f| (f.t, f.x[b])).collect())
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [still, living, out] = args.as_slice() else {
        return Err("usage: steady_figures STILL.json LIVING.json OUT_DIR".into());
    };
    let still = Animation::read(Path::new(still))?;
    let living = Animation::read(Path::new(living))?;
    let out = Path::new(out);
    // Three birds of one arm: the first, the middle and the last (in the first key shape).
    let arms = {
        let ks = &living.key_shapes[0].birds;
        let x: Vec<f64> = ks.iter().map(|b| b.x).collect();
        let y: Vec<f64> = ks.iter().map(|b| b.y).collect();
        let lead = living.leaders()[0];
        formation::keyshape::reorganise::arms(&x, &y, lead)
    };
    let arm = if arms[1].len() >= arms[0].len() {
        &arms[1]
    } else {
        &arms[0]
    };
    let birds = vec![arm[0], arm[arm.len() / 2], arm[arm.len() - 1]];
    let chart = Lateral {
        panels: vec![
            (
                "Key shapes interpolated (--jostle 0): lateral position of three birds".into(),
                lateral(&still, &birds),
            ),
            (
                "Living flight (default: position keeping, leader changes, swaps)".into(),
                lateral(&living, &birds),
            ),
        ],
        birds: birds.clone(),
    };
    save(&chart, &out.join("steady-lateral.png"))?;

    let e = living
        .events
        .iter()
        .find(|e| e.kind == EventKind::LeaderChange)
        .ok_or("the living flight has no leader change; give a longer flight")?;
    let speed = {
        let f = &living.frames[0];
        let lead = living.leaders()[0];
        f.speed[lead]
    };
    let (t0, t1) = (e.t - 0.5, e.t + e.duration + 0.5);
    let paths: Vec<Vec<(f64, f64)>> = (0..living.birds)
        .map(|b| {
            living
                .frames
                .iter()
                .filter(|f| f.t >= t0 && f.t <= t1)
                .map(|f| (f.x[b], f.y[b] - speed * f.t))
                .collect()
        })
        .collect();
    let chart = LeaderChange {
        title: format!(
            "A leader change from above, {:.1}–{:.1} s (open: start, filled: end)",
            t0, t1
        ),
        paths,
        pair: (e.birds[0], e.birds[1]),
    };
    save(&chart, &out.join("steady-leader-change.png"))?;

    // The same from the side: ahead in the flock's frame (along the flight), height over the
    // mean height of the birds not in the exchange.
    let (old, new) = (e.birds[0], e.birds[1]);
    let window: Vec<&formation::animation::Frame> = living
        .frames
        .iter()
        .filter(|f| f.t >= t0 && f.t <= t1)
        .collect();
    let base = |f: &formation::animation::Frame| {
        let others: Vec<f64> = (0..living.birds)
            .filter(|&b| b != old && b != new)
            .map(|b| f.z[b])
            .collect();
        others.iter().sum::<f64>() / others.len().max(1) as f64
    };
    let side: Vec<Vec<(f64, f64)>> = (0..living.birds)
        .map(|b| {
            window
                .iter()
                .map(|f| (f.y[b] - speed * f.t, f.z[b] - base(f)))
                .collect()
        })
        .collect();
    let gaps: Vec<(f64, f64, f64, f64)> = window
        .iter()
        .map(|f| {
            (
                f.t,
                (f.x[old] - f.x[new]).abs(),
                (f.y[old] - f.y[new]).abs(),
                f.z[old] - f.z[new],
            )
        })
        .collect();
    let level = gaps
        .iter()
        .filter(|g| g.1 < 1.0 && g.2 < 0.15)
        .map(|g| g.3.abs())
        .fold(f64::INFINITY, f64::min);
    let chart = LeaderChangeSide {
        title: format!(
            "The leader change of {:.1}–{:.1} s seen from the side (open: start, filled: end)",
            t0, t1
        ),
        side,
        gaps,
        pair: (old, new),
    };
    save(&chart, &out.join("steady-leader-change-side.png"))?;
    println!(
        "wrote steady-leader-change-side.png: while under a wingspan across and a chord fore and aft, the pair is at least {level:.3} wingspans apart in height"
    );
    println!(
        "wrote steady-lateral.png (birds {birds:?}) and steady-leader-change.png (birds {:?}, {:.1} s from {:.1} s)",
        e.birds, e.duration, e.t
    );
    Ok(())
}
