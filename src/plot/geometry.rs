//! The extracted geometry over the annotated frames (for `formation report`): the V's
//! apex angle and each arm's angle per frame with the field studies' apex angles shaded, and the
//! mean wingtip spacing per frame. Takes [`FormationParams`] with geometry (written by
//! `formation extract`); angles in degrees, spacing in wingspans.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{field, Chart, DrawResult, FONT_FAMILY};
use crate::extract::FormationParams;

/// One frame: `(frame index, apex, left arm, right arm, wingtip spacing)`, degrees and
/// wingspans.
pub type GeometryRow = (i64, Option<f64>, Option<f64>, Option<f64>, f64);

/// Apex angle and wingtip spacing per frame.
#[derive(Debug, Clone)]
pub struct GeometryChart {
    /// Title line.
    pub title: String,
    /// `(frame index, apex, left arm, right arm, wingtip spacing)`.
    pub rows: Vec<GeometryRow>,
}

impl GeometryChart {
    /// The chart of `p`; `None` when no frame has geometry (a params file written before per-frame geometry existed).
    pub fn from_params(p: &FormationParams, title: &str) -> Option<GeometryChart> {
        let rows: Vec<_> = p
            .frames
            .iter()
            .filter_map(|f| {
                let g = f.geometry?;
                Some((
                    f.index,
                    g.apex_deg,
                    g.arm_left_deg,
                    g.arm_right_deg,
                    g.wingtip_spacing,
                ))
            })
            .collect();
        (!rows.is_empty()).then(|| GeometryChart {
            title: title.to_string(),
            rows,
        })
    }
}

impl Chart for GeometryChart {
    fn size(&self) -> (u32, u32) {
        (1200, 480)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let root = root.titled(&self.title, (FONT_FAMILY, 20))?;
        let (w, _) = root.dim_in_pixel();
        let (left, right) = root.split_horizontally(w * 3 / 5);
        let f0 = self.rows.first().map_or(0, |r| r.0) as f64 - 0.5;
        let f1 = self.rows.last().map_or(1, |r| r.0) as f64 + 0.5;
        let mut chart = ChartBuilder::on(&left)
            .caption(
                "angles per frame (from the flight axis behind the leader)",
                (FONT_FAMILY, 15),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(f0..f1, 0.0..180.0)?;
        super::draw_mesh(&mut chart, "annotated frame", "degrees", 13)?;
        let shades = [
            RGBColor(120, 170, 120),
            RGBColor(120, 140, 200),
            RGBColor(200, 160, 90),
        ];
        for (k, fr) in field::APEX_ANGLE.iter().take(3).enumerate() {
            let c = shades[k];
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(f0, fr.lo), (f1, fr.hi)],
                    c.mix(0.18).filled(),
                )))?
                .label(format!("apex, {}: {}–{}°", fr.source, fr.lo, fr.hi))
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.mix(0.4).filled())
                });
        }
        let series: [(&str, RGBColor, usize); 3] = [
            ("apex angle", RGBColor(20, 20, 20), 1),
            ("left arm", RGBColor(59, 82, 139), 2),
            ("right arm", RGBColor(33, 145, 140), 3),
        ];
        for (name, c, col) in series {
            let pts: Vec<(f64, f64)> = self
                .rows
                .iter()
                .filter_map(|r| {
                    let v = match col {
                        1 => r.1,
                        2 => r.2,
                        _ => r.3,
                    }?;
                    Some((r.0 as f64, v))
                })
                .collect();
            if pts.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 14, y)], c.stroke_width(2))
                });
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, c.filled())))?;
        }
        super::draw_legend(&mut chart, 11, SeriesLabelPosition::UpperRight)?;
        let (lo, hi) = self
            .rows
            .iter()
            .fold((-0.5f64, 0.5f64), |(a, b), r| (a.min(r.4), b.max(r.4)));
        let mut chart = ChartBuilder::on(&right)
            .caption("mean wingtip spacing per frame", (FONT_FAMILY, 15))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(f0..f1, (lo - 0.1)..(hi + 0.1))?;
        super::draw_mesh(
            &mut chart,
            "annotated frame",
            "wingspans (< 0: wingtips overlap)",
            13,
        )?;
        // Hummel's optimum: wingtip on the other's trailing vortex, π/4 − 1 wingspans.
        let opt = std::f64::consts::FRAC_PI_4 - 1.0;
        let red = RGBColor(200, 30, 30);
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(f0, opt), (f1, opt)],
                red.stroke_width(1),
            )))?
            .label("theory's optimum (π/4 − 1)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], red));
        let c = RGBColor(40, 60, 140);
        chart
            .draw_series(LineSeries::new(
                self.rows.iter().map(|r| (r.0 as f64, r.4)),
                c.stroke_width(2),
            ))?
            .label("this footage")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], c.stroke_width(2)));
        super::draw_legend(&mut chart, 11, SeriesLabelPosition::UpperRight)?;
        Ok(())
    }
}
