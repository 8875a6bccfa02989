//! `formation plot savings`: how much each bird saves against its place in the formation, and how
//! much the flock saves over time through the take-off, with the field studies' flock savings
//! drawn for comparison.
//!
//! Takes an animation with savings (`e` in its frames); savings are percentages of solo induced
//! power (docs/formats.md §3). Left panel: each bird's mean saving over the steady flight against its mean
//! rank (0 = its formation's leader, drawn as a red diamond), birds coloured by rank with the
//! map of [`super::bird_colour`]. Right panel: the flock's saving E/N at every frame, the take-off
//! shaded. Both panels shade the span of [`super::field::FLOCK_SAVING`].

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use std::path::Path;

use super::{bird_colour, field, stages_title, Chart, DrawResult, FONT_FAMILY, LEADER};
use crate::animation::stats::AnimationStats;
use crate::animation::Animation;
use crate::error::{Error, Result};

/// Per-bird and over-time savings of an animation.
#[derive(Debug, Clone)]
pub struct SavingsChart {
    /// Title line.
    pub title: String,
    /// The statistics drawn.
    pub stats: AnimationStats,
    /// Start and end of the take-off, seconds, when the file has one.
    pub takeoff: Option<(f64, f64)>,
    /// Label of the right panel's horizontal axis.
    pub time_label: String,
    /// The flock saving's range over the modelling choices (models, wakes, cores: the band of
    /// `formation report`), fractions of induced power, when computed; drawn as a band and
    /// stated first, the chosen model's value after it.
    pub range: Option<(f64, f64)>,
    /// The chosen model, for the legend ("Hummel's model, planar wake, core 0.04 wingspans").
    pub model: String,
}

impl SavingsChart {
    /// The chart of `anim`, read from `origin` (named in the title and in messages).
    pub fn from_animation(anim: &Animation, origin: &Path) -> Result<SavingsChart> {
        let stats = AnimationStats::of(anim);
        if stats.birds.is_empty() || stats.saving_over_time.is_empty() {
            return Err(Error::format(
                origin,
                "no frame records the savings `e`; write the file with `formation steady` or `formation animate`",
            ));
        }
        let takeoff = super::takeoff_span(anim);
        let name = super::power::file_name(origin);
        let model = anim
            .savings_model
            .as_ref()
            .map_or("Hummel's model".to_string(), |m| m.to_string());
        let range = range_of(
            &crate::aero::band::animation_band(anim),
            stats.steady_saving,
        );
        Ok(SavingsChart {
            title: format!(
                "{name}: savings of {} birds ({})",
                anim.birds,
                stages_title(anim),
            ),
            stats,
            takeoff,
            time_label: "time (s)".into(),
            range,
            model,
        })
    }
}

/// The least and the largest of a band's savings and the point value `point` (the range
/// contains the value stated beside it), or `None` for an empty band.
pub fn range_of(band: &[crate::aero::band::BandEntry], point: Option<f64>) -> Option<(f64, f64)> {
    if band.is_empty() {
        return None;
    }
    Some(
        band.iter()
            .map(|b| b.saving)
            .chain(point)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(v), h.max(v))
            }),
    )
}

/// Colour of the band of this flock's saving over the modelling choices.
const RANGE: RGBColor = RGBColor(70, 110, 200);

/// Shades the span of flock savings that field studies estimated by applying lifting-line models
/// to the spacings they measured (not measured savings) across `x`.
fn band<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, super::Cartesian64>,
    x: (f64, f64),
    range: Option<(f64, f64)>,
) -> DrawResult<DB> {
    if let Some((lo, hi)) = range {
        chart.draw_series(std::iter::once(Rectangle::new(
            [(x.0, 100.0 * lo), (x.1, 100.0 * hi)],
            RANGE.mix(0.12).filled(),
        )))?;
        for v in [lo, hi] {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(x.0, 100.0 * v), (x.1, 100.0 * v)],
                RANGE.mix(0.5).stroke_width(1),
            )))?;
        }
    }
    let (lo, hi) = field::FLOCK_SAVING_SPAN;
    let c = RGBColor(120, 170, 120);
    chart.draw_series(std::iter::once(Rectangle::new(
        [(x.0, 100.0 * lo), (x.1, 100.0 * hi)],
        c.mix(0.18).filled(),
    )))?;
    Ok(())
}

impl Chart for SavingsChart {
    fn size(&self) -> (u32, u32) {
        (1200, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        use super::{clean_number, Key};
        let root = root.titled(&self.title, (FONT_FAMILY, 22))?;
        let s = &self.stats;
        let n = s.birds.len();
        let flock = s
            .steady_saving
            .unwrap_or_else(|| s.birds.iter().map(|b| b.saving).sum::<f64>() / n.max(1) as f64);
        let pc = |v: f64| clean_number(100.0 * v, 1);
        // The range first, then the chosen model's value.
        let lead = match self.range {
            Some((lo, hi)) => format!(
                "flock saving, a model estimate: {}–{} % of induced power over models, wakes and cores; by {}: {} %",
                pc(lo),
                pc(hi),
                self.model,
                pc(flock)
            ),
            None => format!(
                "flock saving, a model estimate by {}: {} % of induced power",
                self.model,
                pc(flock)
            ),
        };
        // Under the range, what a flapping wake gives of it (a second line: too long for one).
        let second = match self.range {
            Some(_) => crate::aero::flapping::flapping_note(),
            None => String::new(),
        };
        let (head, rest) = root.split_vertically(if second.is_empty() { 26 } else { 46 });
        head.draw(&Text::new(
            lead,
            (14, 2),
            (FONT_FAMILY, 15).into_font().color(&RGBColor(40, 40, 40)),
        ))?;
        if !second.is_empty() {
            head.draw(&Text::new(
                second,
                (14, 22),
                (FONT_FAMILY, 15).into_font().color(&RGBColor(40, 40, 40)),
            ))?;
        }
        let (_, h) = rest.dim_in_pixel();
        let (panels, legends) = rest.split_vertically(h.saturating_sub(96));
        let (w, _) = panels.dim_in_pixel();
        let (left, right) = panels.split_horizontally(w / 2);
        let (left_legend, right_legend) = legends.split_horizontally(w / 2);
        let values = || {
            s.birds
                .iter()
                .map(|b| b.saving)
                .chain(s.saving_over_time.iter().map(|p| p.1))
                .chain(self.range.map(|r| r.0))
                .chain(self.range.map(|r| r.1))
        };
        let hi = values().fold(field::FLOCK_SAVING_SPAN.1, f64::max);
        let lo = values().fold(0.0, f64::min);
        // 8 % of the span above and below: no marker is cut at the frame.
        let pad = 0.08 * (hi - lo).max(0.05);
        let (bottom, top) = (100.0 * (lo - pad), 100.0 * (hi + pad));
        // Left: saving against rank.
        let max_rank = s.birds.iter().map(|b| b.rank).fold(1.0, f64::max);
        let (r0, r1) = (-0.6, max_rank + 0.6);
        let mut chart = ChartBuilder::on(&left)
            .caption(
                "each bird in steady flight, by place in its formation",
                (FONT_FAMILY, 16),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(r0..r1, bottom..top)?;
        // Ranks are whole numbers: only whole ticks are labelled.
        let rank_label = |v: &f64| {
            if (v - v.round()).abs() < 1e-9 && *v >= 0.0 {
                format!("{}", v.round() as i64)
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .x_desc("mean rank (0 = leader, counted from the front)")
            .y_desc("saving, % of solo induced power")
            .x_label_formatter(&rank_label)
            .y_label_formatter(&super::tick_label)
            .label_style((FONT_FAMILY, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        band(&mut chart, (r0, r1), self.range)?;
        let mut by_rank: Vec<&crate::animation::stats::BirdStats> = s.birds.iter().collect();
        by_rank.sort_by(|a, b| a.rank.total_cmp(&b.rank));
        let mut leaders = Vec::new();
        for (r, b) in by_rank.iter().enumerate() {
            let p = (b.rank, 100.0 * b.saving);
            if b.leader {
                leaders.push(b.bird);
                // A diamond of fixed size in pixels, drawn inside the frame.
                chart.draw_series(std::iter::once(
                    EmptyElement::at(p)
                        + Polygon::new(vec![(0, -9), (7, 0), (0, 9), (-7, 0)], LEADER.filled()),
                ))?;
            } else {
                let c = bird_colour(r, n);
                chart.draw_series(std::iter::once(Circle::new(p, 5, c.filled())))?;
            }
        }
        let grey = RGBColor(90, 90, 90);
        chart.draw_series(std::iter::once(DashedPathElement::new(
            vec![(r0, 100.0 * flock), (r1, 100.0 * flock)],
            6,
            4,
            grey.stroke_width(1),
        )))?;
        let field_colour = RGBColor(120, 170, 120);
        let field_label = |what: &str| {
            format!(
                "{what}models applied to measured spacings of geese: {}–{} % of induced power",
                pc(field::FLOCK_SAVING_SPAN.0),
                pc(field::FLOCK_SAVING_SPAN.1)
            )
        };
        let mut legend = Vec::new();
        if let Some((lo, hi)) = self.range {
            legend.push((
                format!(
                    "this flock over models, wakes and cores: {}–{} %",
                    pc(lo),
                    pc(hi)
                ),
                RANGE,
                Key::Box,
            ));
        }
        legend.push((
            format!("this flock's mean by the chosen model: {} %", pc(flock)),
            grey,
            Key::Line(1),
        ));
        legend.push((field_label("field: "), field_colour, Key::Box));
        if !leaders.is_empty() {
            let ids: Vec<String> = leaders.iter().map(|b| b.to_string()).collect();
            legend.push((
                format!(
                    "leader (bird {}); other birds coloured by rank, front dark",
                    ids.join(", ")
                ),
                LEADER,
                Key::Diamond,
            ));
        }
        super::side_legend(&left_legend.margin(0, 0, 60, 0), &legend, 12)?;
        // Right: the flock's saving over time.
        let t0 = s.saving_over_time.first().map_or(0.0, |p| p.0);
        let t1 = s
            .saving_over_time
            .last()
            .map_or(1.0, |p| p.0)
            .max(t0 + 1e-6);
        let mut chart = ChartBuilder::on(&right)
            .caption("the flock over time (E/N)", (FONT_FAMILY, 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(t0..t1, bottom..top)?;
        super::draw_mesh(
            &mut chart,
            self.time_label.as_str(),
            "flock saving, % of solo induced power",
            13,
        )?;
        band(&mut chart, (t0, t1), self.range)?;
        let mut legend = Vec::new();
        if let Some((a, b)) = self.takeoff {
            let c = RGBColor(150, 150, 150);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(a, bottom), (b, top)],
                c.mix(0.15).filled(),
            )))?;
            legend.push((format!("take-off ({:.1} s)", b - a), c, Key::Box));
        }
        let line = RGBColor(40, 60, 140);
        let points: Vec<(f64, f64)> = s
            .saving_over_time
            .iter()
            .map(|&(t, e)| (t, 100.0 * e))
            .collect();
        for run in super::clip_to_band(&points, bottom, top) {
            chart.draw_series(LineSeries::new(run, line.stroke_width(2)))?;
        }
        legend.push((
            format!("flock saving by {}", self.model),
            line,
            Key::Line(2),
        ));
        if let Some((lo, hi)) = self.range {
            legend.push((
                format!(
                    "its steady-flight range over models, wakes and cores: {}–{} %",
                    pc(lo),
                    pc(hi)
                ),
                RANGE,
                Key::Box,
            ));
        }
        legend.push((field_label(""), field_colour, Key::Box));
        super::side_legend(&right_legend.margin(0, 0, 60, 0), &legend, 12)?;
        Ok(())
    }
}
