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
        Ok(SavingsChart {
            title: format!(
                "{name}: savings of {} birds ({}), {}",
                anim.birds,
                stages_title(anim),
                anim.savings_model
                    .as_ref()
                    .map_or("Hummel's model".to_string(), |m| m.to_string())
            ),
            stats,
            takeoff,
            time_label: "time (s)".into(),
        })
    }
}

/// Shades the span of flock savings that field studies estimated by applying lifting-line models
/// to the spacings they measured (not measured savings) across `x`.
fn band<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    x: (f64, f64),
) -> DrawResult<DB> {
    let (lo, hi) = field::FLOCK_SAVING_SPAN;
    let c = RGBColor(120, 170, 120);
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [(x.0, 100.0 * lo), (x.1, 100.0 * hi)],
            c.mix(0.18).filled(),
        )))?
        .label("models applied to measured spacings of geese: 14–36 % of induced power")
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.mix(0.4).filled()));
    Ok(())
}

impl Chart for SavingsChart {
    fn size(&self) -> (u32, u32) {
        (1200, 560)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let root = root.titled(&self.title, (FONT_FAMILY, 22))?;
        let (w, _) = root.dim_in_pixel();
        let (left, right) = root.split_horizontally(w / 2);
        let s = &self.stats;
        let top = s
            .birds
            .iter()
            .map(|b| b.saving)
            .chain(s.saving_over_time.iter().map(|p| p.1))
            .fold(field::FLOCK_SAVING_SPAN.1, f64::max)
            * 110.0;
        let bottom = s
            .birds
            .iter()
            .map(|b| b.saving)
            .chain(s.saving_over_time.iter().map(|p| p.1))
            .fold(0.0, f64::min)
            * 110.0;
        // Left: saving against rank.
        let max_rank = s.birds.iter().map(|b| b.rank).fold(1.0, f64::max);
        let mut chart = ChartBuilder::on(&left)
            .caption(
                "each bird in steady flight, by place in its formation",
                (FONT_FAMILY, 16),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(-0.5..max_rank + 0.5, bottom..top)?;
        super::draw_mesh(
            &mut chart,
            "rank (0 = leader, counted from the front)",
            "saving, % of solo induced power",
            13,
        )?;
        band(&mut chart, (-0.5, max_rank + 0.5))?;
        let n = s.birds.len();
        let mut by_rank: Vec<&crate::animation::stats::BirdStats> = s.birds.iter().collect();
        by_rank.sort_by(|a, b| a.rank.total_cmp(&b.rank));
        for (r, b) in by_rank.iter().enumerate() {
            let p = (b.rank, 100.0 * b.saving);
            if b.leader {
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        vec![
                            (p.0, p.1 + 0.04 * (top - bottom)),
                            (p.0 + 0.25, p.1),
                            (p.0, p.1 - 0.04 * (top - bottom)),
                            (p.0 - 0.25, p.1),
                        ],
                        LEADER.filled(),
                    )))?
                    .label(format!("leader (bird {})", b.bird))
                    .legend(|(x, y)| Circle::new((x + 7, y), 5, LEADER.filled()));
            } else {
                let c = bird_colour(r, n);
                chart.draw_series(std::iter::once(Circle::new(p, 5, c.filled())))?;
            }
        }
        let flock = s
            .steady_saving
            .unwrap_or_else(|| s.birds.iter().map(|b| b.saving).sum::<f64>() / n.max(1) as f64);
        let grey = RGBColor(90, 90, 90);
        chart
            .draw_series(std::iter::once(DashedPathElement::new(
                vec![(-0.5, 100.0 * flock), (max_rank + 0.5, 100.0 * flock)],
                6,
                4,
                grey.stroke_width(1),
            )))?
            .label(format!("this flock's mean: {:.1} %", 100.0 * flock))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], grey));
        super::draw_legend(&mut chart, 12, SeriesLabelPosition::LowerRight)?;
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
        band(&mut chart, (t0, t1))?;
        if let Some((a, b)) = self.takeoff {
            let c = RGBColor(150, 150, 150);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(a, bottom), (b, top)],
                    c.mix(0.15).filled(),
                )))?
                .label(format!("take-off ({:.1} s)", b - a))
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.mix(0.4).filled())
                });
        }
        let line = RGBColor(40, 60, 140);
        chart
            .draw_series(LineSeries::new(
                s.saving_over_time.iter().map(|&(t, e)| (t, 100.0 * e)),
                line.stroke_width(2),
            ))?
            .label("flock saving")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 14, y)], line.stroke_width(2))
            });
        super::draw_legend(&mut chart, 12, SeriesLabelPosition::LowerRight)?;
        Ok(())
    }
}
