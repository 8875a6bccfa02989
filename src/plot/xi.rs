//! `formation plot xi`: the relative power reduction ξ_i of every bird over time (seconds) in an
//! animation, one line per bird coloured by its rank in its formation (the perceptual map of
//! [`super::bird_colour`], front dark), the leader in red and thicker, the take-off shaded, the
//! key-shape instants as dashed vertical lines. Exactly the ξ the file records (the CSV's `xi`
//! column) is drawn: frames without it are gaps, never recomputed.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use std::path::Path;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::animation::Animation;
use crate::error::{Error, Result};

/// ξ of every bird over time.
#[derive(Debug, Clone)]
pub struct XiChart {
    /// Chart title.
    pub title: String,
    /// Time of each sample, seconds.
    pub t: Vec<f64>,
    /// Per bird, ξ at each time (`NaN` where undefined).
    pub xi: Vec<Vec<f64>>,
    /// Rank of each bird in its formation (colour order), 0 = front.
    pub rank: Vec<usize>,
    /// The formations' leaders.
    pub leaders: Vec<usize>,
    /// Times of the key shapes, seconds.
    pub key_times: Vec<f64>,
    /// Start and end of the take-off, seconds, when the file has one.
    pub takeoff: Option<(f64, f64)>,
}

impl XiChart {
    /// ξ of every bird of `anim` (read from `origin`, named in the title and in messages) over
    /// time; frames without stored ξ get it from Hummel's model, and frames where it is undefined
    /// (birds inside each other's downwash) are gaps.
    pub fn from_animation(anim: &Animation, origin: &Path) -> Result<XiChart> {
        let n = anim.birds;
        let mut xi = vec![Vec::with_capacity(anim.frames.len()); n];
        let mut any = false;
        for fr in &anim.frames {
            any |= fr.xi.is_some();
            for (i, series) in xi.iter_mut().enumerate() {
                series.push(
                    fr.xi
                        .as_ref()
                        .and_then(|v| v.get(i).copied())
                        .unwrap_or(f64::NAN),
                );
            }
        }
        if !any {
            return Err(Error::format(
                origin,
                "no frame records ξ (`xi`); write the file with `formation steady` or `formation animate`",
            ));
        }
        // Ranks at the first steady frame (the formation the flock flies), else the last frame.
        let k = anim
            .stage("steady")
            .filter(|s| s.end > s.start)
            .map_or(anim.frames.len() - 1, |s| s.start);
        let rank = anim.relative(k).iter().map(|r| r.rank).collect();
        let takeoff = super::takeoff_span(anim);
        let name = super::power::file_name(origin);
        Ok(XiChart {
            title: format!(
                "{name}: ξ of {n} birds over time ({})",
                super::stages_title(anim)
            ),
            t: anim.frames.iter().map(|f| f.t).collect(),
            xi,
            rank,
            leaders: anim.leaders(),
            key_times: anim
                .key_shapes
                .iter()
                .filter_map(|k| anim.frames.get(k.frame).map(|f| f.t))
                .collect(),
            takeoff,
        })
    }
}

impl Chart for XiChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let t0 = self.t.first().copied().unwrap_or(0.0);
        let t1 = self.t.last().copied().unwrap_or(1.0).max(t0 + 1e-6);
        // The axis spans the steady flight's ξ (after the take-off): while the birds are still
        // scattered E is near 0 and ξ = e/E is huge; those spikes are cut at the top.
        let after = self.takeoff.map_or(f64::NEG_INFINITY, |(_, b)| b);
        let top = self
            .xi
            .iter()
            .flat_map(|s| s.iter().zip(&self.t))
            .filter(|(v, &t)| v.is_finite() && t >= after)
            .map(|(v, _)| *v)
            .fold(0.0, f64::max);
        let top = if top > 0.0 { top * 1.25 } else { 1.0 };
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, 0.0..top)?;
        chart
            .configure_mesh()
            .x_desc("time (s)   ·   colour: rank in the formation, front dark → back green; red: leader   ·   dashed: key shapes")
            .y_desc("relative power reduction ξ")
            .label_style((FONT_FAMILY, 14))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        if let Some((a, b)) = self.takeoff {
            let c = RGBColor(150, 150, 150);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, 0.0), (b, top)],
                    c.mix(0.15).filled(),
                )))?
                .label(format!("take-off ({:.1} s)", b - a))
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.mix(0.4).filled())
                });
        }
        let grey = RGBColor(170, 170, 170);
        for &k in &self.key_times {
            chart.draw_series(std::iter::once(DashedPathElement::new(
                vec![(k, 0.0), (k, top)],
                6,
                4,
                ShapeStyle::from(&grey).stroke_width(1),
            )))?;
        }
        let mut order: Vec<usize> = (0..self.xi.len()).collect();
        // Back to front, so that the leader and the front birds are drawn on top.
        order.sort_by_key(|&i| std::cmp::Reverse(self.rank.get(i).copied().unwrap_or(0)));
        let n = order.len();
        let labelled = super::legend_ranks(n);
        for &i in &order {
            let rank = self.rank.get(i).copied().unwrap_or(0);
            let leader = self.leaders.contains(&i);
            let (color, width) = if leader {
                (super::LEADER, 3)
            } else {
                (super::bird_colour(rank, n), 2)
            };
            let series = &self.xi[i];
            // Split into runs of finite values.
            let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for (&t, &v) in self.t.iter().zip(series) {
                if v.is_finite() {
                    if let Some(r) = runs.last_mut() {
                        r.push((t, v));
                    }
                } else if runs.last().is_some_and(|r| !r.is_empty()) {
                    runs.push(Vec::new());
                }
            }
            let style = ShapeStyle::from(&color).stroke_width(width);
            for (j, run) in runs.into_iter().filter(|r| !r.is_empty()).enumerate() {
                let s = chart.draw_series(LineSeries::new(run, style))?;
                if j == 0 && (leader || labelled.contains(&rank)) {
                    let label = if leader {
                        format!("leader (bird {i})")
                    } else {
                        format!("rank {rank} (bird {i})")
                    };
                    s.label(label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
                }
            }
        }
        {
            super::draw_legend(&mut chart, 13, SeriesLabelPosition::UpperRight)?;
        }
        Ok(())
    }
}
