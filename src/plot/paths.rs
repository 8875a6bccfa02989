//! `formation plot paths`: top view of the birds' trajectories during initiation. Takes an
//! animation file with an `initiation` stage (world frame, wingspans); draws two panels:
//! the world (x east, y north, equal scales) and the same paths seen from a frame that moves with
//! the cruise velocity of the steady flight (p − v_c t), turned so that the flight direction is
//! up whatever the heading, where the birds can be seen gathering into the key shape. Starts are open circles, hand-over positions filled dots. Birds are
//! coloured by their rank at the hand-over (the perceptual map of [`super::bird_colour`], front
//! dark), the leader's path red and thicker, with a legend. A file without a take-off is drawn
//! whole and says so in its title.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::animation::Animation;
use crate::error::{Error, Result};

/// Trajectories of every bird during initiation.
#[derive(Debug, Clone)]
pub struct PathsChart {
    /// World-frame paths, one per bird: (x, y) per frame, wingspans.
    pub world: Vec<Vec<(f64, f64)>>,
    /// The same paths minus the cruise motion, across (right) and along the cruise direction,
    /// from the leader's hand-over position, wingspans: the same at any heading.
    pub relative: Vec<Vec<(f64, f64)>>,
    /// Index of the leader (front-most bird at hand-over).
    pub leader: usize,
    /// Each bird's rank in its formation at the hand-over (colour order).
    pub rank: Vec<usize>,
    /// Title line.
    pub title: String,
}

impl PathsChart {
    /// Builds the chart from an animation's `initiation` stage (the whole file if it has none).
    /// Long paths are thinned to at most ~600 points per bird.
    pub fn from_animation(a: &Animation) -> Result<PathsChart> {
        let (start, end) = match a.stage("initiation") {
            Some(s) => (s.start, s.end),
            None => (0, a.frames.len()),
        };
        if end <= start || end > a.frames.len() {
            return Err(Error::parameter(
                "stages",
                "the initiation stage has no frames; nothing to plot",
            ));
        }
        let n = a.birds;
        let last = &a.frames[end - 1];
        // Cruise velocity: the mean velocity of the flock at hand-over (wingspans per second).
        let (mut vx, mut vy) = (0.0, 0.0);
        for i in 0..n {
            let (s, c) = last.heading[i].sin_cos();
            vx += last.speed[i] * s / n as f64;
            vy += last.speed[i] * c / n as f64;
        }
        // The moving panel turns with the flock: across and along its cruise direction φ
        // (clockwise from north), from the leader's hand-over position, so that it shows the
        // same at any heading.
        let (sin_phi, cos_phi) = vx.atan2(vy).sin_cos();
        let t0 = a.frames[start].t;
        let stride = ((end - start) / 600).max(1);
        let mut idx: Vec<usize> = (start..end).step_by(stride).collect();
        if idx.last() != Some(&(end - 1)) {
            idx.push(end - 1);
        }
        let leader = (0..n)
            .max_by(|&i, &j| {
                let pi = last.x[i] * vx + last.y[i] * vy;
                let pj = last.x[j] * vx + last.y[j] * vy;
                pi.total_cmp(&pj)
            })
            .unwrap_or(0);
        let t_end = last.t - t0;
        let (ox, oy) = (last.x[leader] - vx * t_end, last.y[leader] - vy * t_end);
        let mut world = vec![Vec::with_capacity(idx.len()); n];
        let mut relative = vec![Vec::with_capacity(idx.len()); n];
        for &k in &idx {
            let f = &a.frames[k];
            let dt = f.t - t0;
            for i in 0..n {
                world[i].push((f.x[i], f.y[i]));
                let (qx, qy) = (f.x[i] - vx * dt - ox, f.y[i] - vy * dt - oy);
                relative[i].push((qx * cos_phi - qy * sin_phi, qx * sin_phi + qy * cos_phi));
            }
        }
        let secs = (end - start) as f64 / a.fps;
        let what = if a.stage("initiation").is_some() {
            "Take-off".to_string()
        } else {
            format!(
                "No take-off in this file ({}): paths",
                super::stages_title(a)
            )
        };
        Ok(PathsChart {
            world,
            relative,
            leader,
            rank: a.relative(end - 1).iter().map(|r| r.rank).collect(),
            title: format!(
                "{what} of {n} birds: {} frames ({secs:.1} s at {} fps)",
                end - start,
                a.fps
            ),
        })
    }
}

/// Bounds of a set of paths, padded and widened so that both axes have the same scale on a
/// panel of `w × h` pixels.
fn equal_bounds(paths: &[Vec<(f64, f64)>], w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in paths.iter().flatten() {
        x0 = x0.min(p.0);
        x1 = x1.max(p.0);
        y0 = y0.min(p.1);
        y1 = y1.max(p.1);
    }
    if !x0.is_finite() {
        return ((-1.0, 1.0), (-1.0, 1.0));
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0).max(2.0);
    let (mut x0, mut x1, mut y0, mut y1) = (x0 - pad, x1 + pad, y0 - pad, y1 + pad);
    let sx = (x1 - x0) / w;
    let sy = (y1 - y0) / h;
    if sx < sy {
        let c = 0.5 * (x0 + x1);
        let half = 0.5 * sy * w;
        x0 = c - half;
        x1 = c + half;
    } else {
        let c = 0.5 * (y0 + y1);
        let half = 0.5 * sx * h;
        y0 = c - half;
        y1 = c + half;
    }
    ((x0, x1), (y0, y1))
}

impl PathsChart {
    fn rank_of(&self, i: usize) -> usize {
        self.rank.get(i).copied().unwrap_or(i)
    }

    #[allow(clippy::too_many_arguments)]
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        paths: &[Vec<(f64, f64)>],
        caption: &str,
        x_desc: &str,
        y_desc: &str,
        legend: bool,
    ) -> DrawResult<DB> {
        let (w, h) = area.dim_in_pixel();
        // Plot area excludes the label areas and margins.
        let (pw, ph) = ((w as f64 - 80.0).max(10.0), (h as f64 - 100.0).max(10.0));
        let ((x0, x1), (y0, y1)) = equal_bounds(paths, pw, ph);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT_FAMILY, 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        super::draw_mesh(&mut chart, x_desc, y_desc, 13)?;
        let n = paths.len();
        let labelled = super::legend_ranks(n);
        let mut order: Vec<usize> = (0..n).collect();
        // Back to front, the leader last (on top).
        order.sort_by_key(|&i| (i == self.leader, std::cmp::Reverse(self.rank_of(i))));
        for i in order {
            let p = &paths[i];
            let rank = self.rank_of(i);
            let (color, width) = if i == self.leader {
                (super::LEADER, 3)
            } else {
                (super::bird_colour(rank, n), 1)
            };
            let s = chart.draw_series(LineSeries::new(
                p.iter().copied(),
                color.stroke_width(width),
            ))?;
            if legend && (i == self.leader || labelled.contains(&rank)) {
                let style = color.stroke_width(width);
                let label = if i == self.leader {
                    format!("leader (bird {i})")
                } else {
                    format!("rank {rank} (bird {i})")
                };
                s.label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
            }
            if let (Some(&a), Some(&b)) = (p.first(), p.last()) {
                chart.draw_series(std::iter::once(Circle::new(a, 4, color.stroke_width(1))))?;
                chart.draw_series(std::iter::once(Circle::new(b, 4, color.filled())))?;
            }
        }
        if legend {
            super::draw_legend(&mut chart, 12, SeriesLabelPosition::UpperLeft)?;
        }
        Ok(())
    }
}

impl Chart for PathsChart {
    fn size(&self) -> (u32, u32) {
        (1200, 800)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let root = root.titled(&self.title, (FONT_FAMILY, 22))?;
        let (w, _) = root.dim_in_pixel();
        let (left, right) = root.split_horizontally(w * 2 / 5);
        self.panel(
            &left,
            &self.world,
            "world (top view)",
            "east, wingspans",
            "north, wingspans",
            false,
        )?;
        self.panel(
            &right,
            &self.relative,
            "moving with the cruise velocity, flight direction up (○ start, ● hand-over)",
            "across the flight, wingspans (leader at hand-over = 0)",
            "along the flight − V t, wingspans",
            true,
        )?;
        Ok(())
    }
}
