//! Chart of one wingbeat: every joint angle of [`WingPose`] (degrees) and the wing spread over the
//! wingbeat phase (fraction of the period, 0 = start of the downstroke), for a species preset.
//! The downstroke of the g1 DOFs is shaded, the mid-upstroke wingbeat boundary and its blending
//! window (Wu & Popović §4.3) are marked.

use std::f64::consts::TAU;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::wingbeat::{wingbeat_curve, Species, Timing, WingPose};

/// One wingbeat of the average bird of a species.
#[derive(Debug, Clone)]
pub struct WingbeatChart {
    /// The species.
    pub species: Species,
    /// Its wingbeat frequency, Hz.
    pub frequency_hz: f64,
    /// Its timing (u_α, u_β, ...).
    pub timing: Timing,
    /// Poses at phases 0..2π, radians.
    pub samples: Vec<(f64, WingPose)>,
}

impl WingbeatChart {
    /// The chart of `species`' preset wingbeat.
    pub fn new(species: Species) -> WingbeatChart {
        let preset = species.preset();
        WingbeatChart {
            species,
            frequency_hz: preset.frequency_hz,
            timing: preset.timing,
            samples: wingbeat_curve(species, 361),
        }
    }
}

type Getter = fn(&WingPose) -> f64;

const ANGLES: [(&str, Getter, RGBColor); 6] = [
    ("arm dihedral (g1)", |p| p.dihedral, RGBColor(31, 119, 180)),
    (
        "hand dihedral (g1, lagged)",
        |p| p.hand_dihedral,
        RGBColor(174, 199, 232),
    ),
    ("tail bend (g1)", |p| p.tail_bend, RGBColor(140, 86, 75)),
    ("sweep (g2)", |p| p.sweep, RGBColor(214, 39, 40)),
    ("arm twist (g2)", |p| p.arm_twist, RGBColor(44, 160, 44)),
    ("hand twist (g2)", |p| p.hand_twist, RGBColor(255, 127, 14)),
];

/// Headroom above the joint-angle curves, as a fraction of their span: the legend's box sits
/// there.
const LEGEND_HEADROOM: f64 = 0.6;

impl Chart for WingbeatChart {
    fn size(&self) -> (u32, u32) {
        (960, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (top, bottom) = root.split_vertically(500);
        let deg = |r: f64| r.to_degrees();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (_, p) in &self.samples {
            for (_, get, _) in ANGLES {
                lo = lo.min(deg(get(p)));
                hi = hi.max(deg(get(p)));
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (-45.0, 45.0);
        }
        let pad = 0.08 * (hi - lo).max(1.0);
        // Headroom above the curves for the legend (six lines, about a third of the plot's
        // height), so it never covers a curve.
        let (lo, hi) = (lo - pad, hi + LEGEND_HEADROOM * (hi - lo).max(1.0));
        let ua = self.timing.u_alpha;
        let mid = self.timing.mid_upstroke() / TAU;
        let half = self.timing.blend_half_width() / TAU;

        let caption = format!(
            "One {} wingbeat: {:.1} Hz, downstroke fraction u_α = {:.2}, u_β = {:.2}",
            self.species, self.frequency_hz, self.timing.u_alpha, self.timing.u_beta
        );
        let mut chart = ChartBuilder::on(&top)
            .caption(caption, (FONT_FAMILY, 20))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, lo..hi)?;
        chart
            .configure_mesh()
            .x_desc("wingbeat phase φ / 2π (0 = start of downstroke)")
            .y_desc("joint angle, degrees")
            .label_style((FONT_FAMILY, 13))
            .x_label_formatter(&super::tick_label)
            .y_label_formatter(&super::tick_label)
            .max_light_lines(2)
            .draw()?;
        shade(&mut chart, ua, mid, half, lo, hi)?;
        for (name, get, color) in ANGLES {
            chart
                .draw_series(LineSeries::new(
                    self.samples.iter().map(|(phi, p)| (phi / TAU, deg(get(p)))),
                    color.stroke_width(2),
                ))?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                });
        }
        super::draw_legend(&mut chart, 13, SeriesLabelPosition::UpperRight)?;

        let mut spread = ChartBuilder::on(&bottom)
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, 0.0..1.1)?;
        spread
            .configure_mesh()
            .x_desc("wingbeat phase φ / 2π")
            .y_desc("wing spread")
            .label_style((FONT_FAMILY, 13))
            .x_label_formatter(&super::tick_label)
            .y_label_formatter(&super::tick_label)
            .max_light_lines(2)
            .draw()?;
        shade(&mut spread, ua, mid, half, 0.0, 1.1)?;
        let purple = RGBColor(148, 103, 189);
        spread
            .draw_series(LineSeries::new(
                self.samples.iter().map(|(phi, p)| (phi / TAU, p.spread)),
                purple.stroke_width(2),
            ))?
            .label("wing spread (g2), 1 = extended")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], purple.stroke_width(2))
            });
        spread
            .draw_series(std::iter::once(Text::new(
                "grey: downstroke (g1) · dashed: wingbeat boundary at mid-upstroke, band: blending window",
                (0.01, 0.08),
                (FONT_FAMILY, 12),
            )))?;
        super::draw_legend(&mut spread, 13, SeriesLabelPosition::LowerRight)?;
        Ok(())
    }
}

/// Shades the downstroke [0, u_α] and the blending window around mid-upstroke, and draws the
/// mid-upstroke boundary.
fn shade<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    ua: f64,
    mid: f64,
    half: f64,
    lo: f64,
    hi: f64,
) -> DrawResult<DB> {
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, lo), (ua, hi)],
        BLACK.mix(0.07).filled(),
    )))?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(mid - half, lo), (mid + half, hi)],
        RGBColor(31, 119, 180).mix(0.08).filled(),
    )))?;
    let steps = 24;
    chart.draw_series((0..steps).step_by(2).map(|k| {
        let y0 = lo + (hi - lo) * k as f64 / steps as f64;
        let y1 = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
        PathElement::new(vec![(mid, y0), (mid, y1)], BLACK.mix(0.6))
    }))?;
    Ok(())
}
