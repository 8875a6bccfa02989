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
        // scattered E is near 0 and ξ = e/E is huge or negative; those values are cut at the
        // frame's edge, and the legend says by how much.
        let after = self.takeoff.map_or(f64::NEG_INFINITY, |(_, b)| b);
        let steady = || {
            self.xi
                .iter()
                .flat_map(|s| s.iter().zip(&self.t))
                .filter(|(v, &t)| v.is_finite() && t >= after)
                .map(|(v, _)| *v)
        };
        let top = steady().fold(0.0, f64::max);
        let top = if top > 0.0 { top * 1.25 } else { 1.0 };
        let low = steady().fold(0.0, f64::min);
        let bottom = if low < 0.0 { low * 1.25 } else { 0.0 };
        // What the axis cuts: (least, largest) of the values outside it, in the take-off and
        // after it.
        let mut cut: [Option<(f64, f64)>; 2] = [None, None];
        for s in &self.xi {
            for (&v, &t) in s.iter().zip(&self.t) {
                if v.is_finite() && (v < bottom || v > top) {
                    let c = &mut cut[usize::from(t >= after)];
                    *c = Some(c.map_or((v, v), |(a, b)| (a.min(v), b.max(v))));
                }
            }
        }
        let root = root.titled(&self.title, (FONT_FAMILY, 22))?;
        let (w, _) = root.dim_in_pixel();
        let (plot_area, legend_area) = root.split_horizontally(w.saturating_sub(230));
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(16)
            .x_label_area_size(60)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, bottom..top)?;
        chart
            .configure_mesh()
            .x_desc("time (s)   ·   dashed: key shapes")
            .y_desc("relative power reduction ξ")
            .x_label_formatter(&super::tick_label)
            .y_label_formatter(&super::tick_label)
            .label_style((FONT_FAMILY, 14))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        let mut legend: Vec<(String, RGBColor, super::Key)> = Vec::new();
        if let Some((a, b)) = self.takeoff {
            let c = RGBColor(150, 150, 150);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(a, bottom), (b, top)],
                c.mix(0.15).filled(),
            )))?;
            legend.push((format!("take-off ({:.1} s)", b - a), c, super::Key::Box));
        }
        let grey = RGBColor(170, 170, 170);
        for &k in &self.key_times {
            chart.draw_series(std::iter::once(DashedPathElement::new(
                vec![(k, bottom), (k, top)],
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
        let mut entries: Vec<(usize, String, RGBColor, u32)> = Vec::new();
        for &i in &order {
            let rank = self.rank.get(i).copied().unwrap_or(0);
            let leader = self.leaders.contains(&i);
            let (color, width) = if leader {
                (super::LEADER, 3)
            } else {
                (super::bird_colour(rank, n), 2)
            };
            let points: Vec<(f64, f64)> = self
                .t
                .iter()
                .zip(&self.xi[i])
                .map(|(&t, &v)| (t, v))
                .collect();
            let style = ShapeStyle::from(&color).stroke_width(width);
            // A thick line's mitred corner at a sharp spike reaches far past the point (out of
            // the frame): a run is broken at every steep reversal, so no corner is that sharp.
            let steep = 0.05 * (top - bottom);
            for run in super::clip_to_band(&points, bottom, top) {
                let mut start = 0;
                for k in 1..run.len().saturating_sub(1) {
                    let (a, b) = (run[k].1 - run[k - 1].1, run[k + 1].1 - run[k].1);
                    if a * b < 0.0 && (a.abs() > steep || b.abs() > steep) {
                        chart.draw_series(LineSeries::new(run[start..=k].to_vec(), style))?;
                        start = k;
                    }
                }
                chart.draw_series(LineSeries::new(run[start..].to_vec(), style))?;
            }
            if leader {
                entries.push((0, format!("leader (bird {i})"), color, width));
            } else if labelled.contains(&rank) {
                entries.push((rank, format!("rank {rank} (bird {i})"), color, width));
            }
        }
        entries.sort_by_key(|e| e.0);
        legend.extend(
            entries
                .into_iter()
                .map(|(_, l, c, w)| (l, c, super::Key::Line(w))),
        );
        legend.push((
            "colour: rank in the formation,".into(),
            BLACK,
            super::Key::Note,
        ));
        legend.push(("front dark, back green".into(), BLACK, super::Key::Note));
        for (k, what) in ["in the take-off", "after it"].iter().enumerate() {
            if let Some((a, b)) = cut[k] {
                legend.push((
                    format!("ξ cut at the frame {what}:"),
                    BLACK,
                    super::Key::Note,
                ));
                legend.push((
                    format!(
                        "  {} to {}",
                        super::clean_number(a, 2),
                        super::clean_number(b, 2)
                    ),
                    BLACK,
                    super::Key::Note,
                ));
            }
        }
        let legend_area = legend_area.margin(60, 0, 0, 6);
        super::side_legend(&legend_area, &legend, 13)
    }
}
