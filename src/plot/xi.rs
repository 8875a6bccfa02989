//! `formation plot xi`: the relative power reduction ξ_i of every bird over time (seconds) in an
//! animation, one line per bird coloured from the leftmost (blue) to the rightmost bird (red), with
//! the key-shape instants as dashed vertical lines. Gaps in a series (frames where ξ is undefined)
//! are left blank.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use std::path::Path;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::aero::power_reduction;
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
    /// Lateral position of each bird, wingspans (colour order; legend for few birds).
    pub lateral: Vec<f64>,
    /// Times of the key shapes, seconds.
    pub key_times: Vec<f64>,
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
            let values = match &fr.xi {
                Some(v) => Some(v.clone()),
                None => {
                    let back: Vec<f64> = fr.y.iter().map(|v| -v).collect();
                    power_reduction(&fr.x, &back).ok().map(|p| p.xi)
                }
            };
            any |= values.is_some();
            for (i, series) in xi.iter_mut().enumerate() {
                series.push(
                    values
                        .as_ref()
                        .and_then(|v| v.get(i).copied())
                        .unwrap_or(f64::NAN),
                );
            }
        }
        if !any {
            return Err(Error::format(
                origin,
                "no frame has a defined ξ (every frame has two birds wing to wing)",
            ));
        }
        let lateral = anim
            .key_shapes
            .first()
            .map(|k| k.birds.iter().map(|b| b.x).collect())
            .or_else(|| anim.frames.first().map(|f| f.x.clone()))
            .unwrap_or_default();
        let name = origin
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Ok(XiChart {
            title: format!("{name}: ξ of {n} birds over time"),
            t: anim.frames.iter().map(|f| f.t).collect(),
            xi,
            lateral,
            key_times: anim
                .key_shapes
                .iter()
                .filter_map(|k| anim.frames.get(k.frame).map(|f| f.t))
                .collect(),
        })
    }
}

/// Blue → cyan → green → orange → red by hue, `s` in [0, 1].
fn ramp(s: f64) -> HSLColor {
    let s = s.clamp(0.0, 1.0);
    HSLColor((240.0 - 240.0 * s) / 360.0, 0.8, 0.42)
}

impl Chart for XiChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let t0 = self.t.first().copied().unwrap_or(0.0);
        let t1 = self.t.last().copied().unwrap_or(1.0).max(t0 + 1e-6);
        let top = self
            .xi
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let top = if top > 0.0 { top * 1.1 } else { 1.0 };
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, 0.0..top)?;
        chart
            .configure_mesh()
            .x_desc("time (s)   ·   colour: lateral position, leftmost blue → rightmost red   ·   dashed: key shapes")
            .y_desc("relative power reduction ξ")
            .label_style((FONT_FAMILY, 14))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
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
        order.sort_by(|&a, &b| {
            let xa = self.lateral.get(a).copied().unwrap_or(0.0);
            let xb = self.lateral.get(b).copied().unwrap_or(0.0);
            xa.total_cmp(&xb)
        });
        let n = order.len().max(2) - 1;
        for (rank, &i) in order.iter().enumerate() {
            let color = ramp(rank as f64 / n as f64);
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
            let style = ShapeStyle::from(&color).stroke_width(2);
            for (j, run) in runs.into_iter().filter(|r| !r.is_empty()).enumerate() {
                let s = chart.draw_series(LineSeries::new(run, style))?;
                if j == 0 && self.xi.len() <= 12 {
                    let x = self.lateral.get(i).copied().unwrap_or(0.0);
                    s.label(format!("bird {i} (x = {x:.2})"))
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
                }
            }
        }
        if self.xi.len() <= 12 {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font((FONT_FAMILY, 13))
                .position(SeriesLabelPosition::UpperRight)
                .draw()?;
        }
        Ok(())
    }
}
