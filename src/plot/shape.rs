//! `formation plot shape`: one frame of a params file in the formation frame (wingspans, equal
//! axis scales, flight direction up, so the leader is at the top): inlier birds, outliers with
//! their deviation from the curve, the leader, the fitted curve, and bird ids.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::error::{Error, Result};
use crate::extract::{slope_at, FormationParams, FrameParams, ShapeModel};

/// The chart of one frame's fit.
#[derive(Debug, Clone)]
pub struct ShapeChart {
    /// The frame to draw.
    pub frame: FrameParams,
    /// Source text of the params file, for the title.
    pub source: String,
    /// Inlier threshold, wingspans, when known: drawn as a band around the curve.
    pub threshold: Option<f64>,
}

impl ShapeChart {
    /// The chart of the frame with index `frame` (the first frame when `None`) of `params`, read
    /// from `origin` (named in messages); `threshold` is the inlier band, wingspans, when known.
    /// A frame that is not there is an error naming `plot.frame`.
    pub fn from_params(
        params: &FormationParams,
        frame: Option<i64>,
        threshold: Option<f64>,
        origin: &std::path::Path,
    ) -> Result<ShapeChart> {
        let found = match frame {
            None => params.frames.first(),
            Some(k) => params.frames.iter().find(|f| f.index == k),
        }
        .ok_or_else(|| {
            let lo = params.frames.first().map(|f| f.index).unwrap_or(0);
            let hi = params.frames.last().map(|f| f.index).unwrap_or(0);
            Error::parameter(
                "plot.frame",
                format!(
                    "no frame {} in {} (frames {lo}..={hi})",
                    frame.unwrap_or(0),
                    origin.display()
                ),
            )
        })?;
        Ok(ShapeChart {
            frame: found.clone(),
            source: params.source.clone(),
            threshold,
        })
    }
}

/// Outliers are drawn grey (red is the leader's colour in every chart).
const OUTLIER: RGBColor = RGBColor(110, 110, 110);
const LEADER: RGBColor = super::LEADER;
const CURVE: RGBColor = RGBColor(60, 60, 60);

impl ShapeChart {
    /// Curve segments to draw (a V is drawn as its two arms meeting at x = 0), shifted by
    /// `offset` wingspans along the curve's normal to first order (vertically
    /// offset·√(1 + y'²)), which is how far the inlier test reaches.
    fn curve_pieces(&self, x0: f64, x1: f64, offset: f64) -> Vec<Vec<(f64, f64)>> {
        let m = self.frame.shape;
        let y = |x: f64, s: f64| m.y_at(x) + offset * (1.0 + s * s).sqrt();
        let sample = |a: f64, b: f64| -> Vec<(f64, f64)> {
            (0..=200)
                .map(|i| {
                    let x = a + (b - a) * i as f64 / 200.0;
                    (x, y(x, slope_at(&m, x)))
                })
                .collect()
        };
        match m {
            ShapeModel::V { left, right } => {
                let (a, b) = (x0.min(0.0), x1.max(0.0));
                let l = |x: f64| left.y_at(x) + offset * (1.0 + left.slope.powi(2)).sqrt();
                let r = |x: f64| right.y_at(x) + offset * (1.0 + right.slope.powi(2)).sqrt();
                vec![
                    vec![(a, l(a)), (0.0, l(0.0))],
                    vec![(0.0, r(0.0)), (b, r(b))],
                ]
            }
            _ => vec![sample(x0, x1)],
        }
    }
}

/// The source text wrapped at word boundaries into lines of at most `width` characters (a
/// word longer than that gets a line of its own); "flock" when empty.
fn wrapped_source(s: &str, width: usize) -> Vec<String> {
    let s = s.trim();
    if s.is_empty() {
        return vec!["flock".into()];
    }
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for w in s.split_whitespace() {
        if !cur.is_empty() && cur.chars().count() + 1 + w.chars().count() > width {
            lines.push(std::mem::take(&mut cur));
        }
        if !cur.is_empty() {
            cur.push(' ');
        }
        cur.push_str(w);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

/// Characters of the source per title line (16 px text on a 1000 px chart).
const SOURCE_LINE_CHARS: usize = 100;

impl Chart for ShapeChart {
    fn size(&self) -> (u32, u32) {
        (1000, 720)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let f = &self.frame;
        let pos = &f.positions;
        let (mut xmin, mut xmax, mut ymin, mut ymax) = (-1.0f64, 1.0f64, -0.5f64, 1.0f64);
        for p in pos {
            xmin = xmin.min(p.x);
            xmax = xmax.max(p.x);
            ymin = ymin.min(p.y);
            ymax = ymax.max(p.y);
        }
        let (cx0, cx1) = (xmin - 0.3, xmax + 0.3);
        for i in 0..=20 {
            let x = cx0 + (cx1 - cx0) * i as f64 / 20.0;
            let y = f.shape.y_at(x);
            if y.is_finite() {
                ymin = ymin.min(y);
                ymax = ymax.max(y);
            }
        }
        // Margins, then widen one axis so that a wingspan is as long across as along.
        let (mut x0, mut x1) = (xmin - 1.0, xmax + 1.0);
        let (mut y0, mut y1) = (ymin - 1.0, ymax + 1.0);
        let (w, h) = self.size();
        let (pw, ph) = (w as f64 - 110.0, h as f64 - 130.0);
        let (sx, sy) = ((x1 - x0) / pw, (y1 - y0) / ph);
        if sx > sy {
            let extra = (sx * ph - (y1 - y0)) / 2.0;
            y0 -= extra;
            y1 += extra;
        } else {
            let extra = (sy * pw - (x1 - x0)) / 2.0;
            x0 -= extra;
            x1 += extra;
        }
        let n_out = f.outliers.len();
        // The whole source above the chart, wrapped rather than cut.
        let source = wrapped_source(&self.source, SOURCE_LINE_CHARS);
        let line_px = 20;
        let (head, root) = root.split_vertically(8 + line_px * source.len() as u32);
        for (i, line) in source.iter().enumerate() {
            head.draw(&Text::new(
                line.clone(),
                (14, 6 + line_px as i32 * i as i32),
                (FONT_FAMILY, 16).into_font().color(&RGBColor(60, 60, 60)),
            ))?;
        }
        let root = &root;
        let caption = format!(
            "frame {}: {} birds, kind {}, {} outlier{}",
            f.index,
            f.order.len(),
            f.shape.kind().to_uppercase(),
            n_out,
            if n_out == 1 { "" } else { "s" }
        );
        let mut chart = ChartBuilder::on(root)
            .caption(caption, (FONT_FAMILY, 22))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(56)
            // y grows downward: behind the leader is lower on the page, flight is up.
            .build_cartesian_2d(x0..x1, y1..y0)?;
        super::draw_mesh(
            &mut chart,
            "x: lateral offset right of the flight direction (wingspans)",
            "y: distance behind the leader (wingspans)",
            14,
        )?;

        if let Some(t) = self.threshold {
            let mut labelled = false;
            for off in [-t, t] {
                for piece in self.curve_pieces(cx0, cx1, off) {
                    let s = chart
                        .draw_series(LineSeries::new(piece, CURVE.mix(0.35).stroke_width(1)))?;
                    if !labelled {
                        s.label(format!("inlier band (±{t} wingspans from the curve)"))
                            .legend(|(x, y)| {
                                PathElement::new(vec![(x, y), (x + 18, y)], CURVE.mix(0.35))
                            });
                        labelled = true;
                    }
                }
            }
        }
        let mut first = true;
        for piece in self.curve_pieces(cx0, cx1, 0.0) {
            let s = chart.draw_series(LineSeries::new(piece, CURVE.stroke_width(2)))?;
            if first {
                let label = match f.shape {
                    ShapeModel::V { left, right } => format!(
                        "V: left y = {} {}x, right y = {} {}x",
                        num(left.intercept, 2),
                        signed(left.slope, 2),
                        num(right.intercept, 2),
                        signed(right.slope, 2)
                    ),
                    ShapeModel::Line { intercept, slope } => {
                        format!("line: y = {} {}x", num(intercept, 2), signed(slope, 2))
                    }
                    ShapeModel::U { a, b, c } | ShapeModel::J { a, b, c } => format!(
                        "{}: y = {}x² {}x {}",
                        f.shape.kind().to_uppercase(),
                        num(a, 3),
                        signed(b, 3),
                        signed(c, 2)
                    ),
                };
                s.label(label).legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], CURVE.stroke_width(2))
                });
                first = false;
            }
        }
        // Outliers' deviations from the curve.
        for p in pos.iter().filter(|p| f.outliers.contains(&p.id)) {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(p.x, p.y), (p.x, p.y - p.dy)],
                OUTLIER.mix(0.6).stroke_width(1),
            )))?;
        }
        // Rank: how far behind the leader (the leader is rank 0), the colour of every bird chart.
        let mut by_depth: Vec<(f64, usize)> = pos.iter().map(|p| (p.y, p.id)).collect();
        by_depth.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let n_birds = by_depth.len();
        let rank = |id: usize| by_depth.iter().position(|b| b.1 == id).unwrap_or(0);
        let mid = super::bird_colour(n_birds / 2, n_birds);
        chart
            .draw_series(
                pos.iter()
                    .filter(|p| f.inliers.contains(&p.id) && p.id != f.leader)
                    .map(|p| {
                        Circle::new(
                            (p.x, p.y),
                            6,
                            super::bird_colour(rank(p.id), n_birds).filled(),
                        )
                    }),
            )?
            .label(format!(
                "inliers ({}), coloured by rank: front dark, back green",
                f.inliers.len()
            ))
            .legend(move |(x, y)| Circle::new((x + 9, y), 5, mid.filled()));
        chart
            .draw_series(
                pos.iter()
                    .filter(|p| f.outliers.contains(&p.id))
                    .map(|p| Cross::new((p.x, p.y), 7, OUTLIER.stroke_width(3))),
            )?
            .label(format!("outliers ({n_out}), line = deviation from curve"))
            .legend(|(x, y)| Cross::new((x + 9, y), 5, OUTLIER.stroke_width(3)));
        chart
            .draw_series(
                pos.iter()
                    .filter(|p| p.id == f.leader)
                    .map(|p| TriangleMarker::new((p.x, p.y), 11, LEADER.filled())),
            )?
            .label(format!("leader (bird {})", f.leader))
            .legend(|(x, y)| TriangleMarker::new((x + 9, y), 6, LEADER.filled()));
        chart.draw_series(pos.iter().map(|p| {
            EmptyElement::at((p.x, p.y))
                + Text::new(
                    p.id.to_string(),
                    (7, 2),
                    (FONT_FAMILY, 12).into_font().color(&RGBColor(40, 40, 40)),
                )
        }))?;
        // The legend goes in the corner with the fewest birds.
        let (mx, my) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let corners = [
            (SeriesLabelPosition::UpperRight, true, false),
            (SeriesLabelPosition::UpperLeft, false, false),
            (SeriesLabelPosition::LowerRight, true, true),
            (SeriesLabelPosition::LowerLeft, false, true),
        ];
        let crowd = |right: bool, low: bool| {
            pos.iter()
                .filter(|p| (p.x > mx) == right && (p.y > my) == low)
                .count()
        };
        let corner = corners
            .iter()
            .min_by_key(|c| crowd(c.1, c.2))
            .map(|c| c.0.clone())
            .unwrap_or(SeriesLabelPosition::LowerRight);
        chart
            .configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font((FONT_FAMILY, 14))
            .draw()?;
        let stats = format!(
            "μx = {}  σx = {}  μy = {}  σy = {} (wingspans)   ↑ flight direction",
            num(f.mu_x, 3),
            num(f.sigma_x, 3),
            num(f.mu_y, 3),
            num(f.sigma_y, 3)
        );
        root.draw(&Text::new(
            stats,
            (70, 40),
            (FONT_FAMILY, 15).into_font().color(&RGBColor(80, 80, 80)),
        ))?;
        Ok(())
    }
}

/// A number for the chart's text: [`super::clean_number`] (no `-0`, no trailing zeros).
fn num(v: f64, decimals: usize) -> String {
    super::clean_number(v, decimals)
}

/// A term after another in a formula: `+ 0.6`, `- 0.6`, `+ 0` (never `-0`).
fn signed(v: f64, decimals: usize) -> String {
    let t = num(v, decimals);
    match t.strip_prefix('-') {
        Some(abs) => format!("- {abs}"),
        None => format!("+ {t}"),
    }
}

#[cfg(test)]
mod wrap_tests {
    #[test]
    fn formula_terms_never_read_minus_zero() {
        assert_eq!(super::signed(-0.0001, 2), "+ 0");
        assert_eq!(super::signed(-0.6, 2), "- 0.6");
        assert_eq!(super::signed(0.67, 2), "+ 0.67");
        assert_eq!(super::num(-0.0004, 3), "0");
    }

    #[test]
    fn long_sources_wrap_at_words_and_keep_every_word() {
        let s = "synthetic: 9 barnacle geese in a V (generated by examples/make_examples.rs) filmed from below";
        let lines = super::wrapped_source(s, 40);
        assert!(lines.len() >= 3 && lines.iter().all(|l| l.chars().count() <= 40));
        assert_eq!(lines.join(" "), s);
        assert_eq!(super::wrapped_source("  ", 40), ["flock"]);
    }
}
