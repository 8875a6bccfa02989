//! `formation plot power`: the power reduction of every bird of one shape (a shape file, a key
//! shape or a frame of an animation) as bars at the birds' lateral positions (wingspans), with each
//! bird's feasible range of ξ drawn as a whisker when it is known (steady flight, §5 eq. 2).

use plotters::coord::Shift;
use plotters::prelude::*;

use std::path::Path;

use super::{Chart, DrawResult, FONT_FAMILY};
use crate::aero::power_reduction;
use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::shape::Shape;

/// Which quantity the bars show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PowerMetric {
    /// Relative power reduction ξ_i = e_i / E.
    #[default]
    Xi,
    /// Power reduction e_i (Hummel's model without the drag ratio).
    E,
}

/// Bars of e_i or ξ_i per bird.
#[derive(Debug, Clone)]
pub struct PowerChart {
    /// Chart title.
    pub title: String,
    /// Lateral position of each bird, wingspans (bar positions).
    pub x: Vec<f64>,
    /// Value per bird (same order as `x`).
    pub values: Vec<f64>,
    /// What `values` are.
    pub metric: PowerMetric,
    /// Feasible range [lo, hi] per bird, drawn as whiskers (ξ only).
    pub ranges: Option<Vec<[f64; 2]>>,
    /// Index of the leader, drawn in a distinct colour.
    pub leader: Option<usize>,
    /// Distance of each bird behind the leader, wingspans (same order as `x`): the bars are
    /// coloured by rank, front to back ([`super::bird_colour`]); empty for one colour.
    pub behind: Vec<f64>,
}

/// What part of an animation a [`PowerChart`] shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PowerOf {
    /// Key shape `k` (index into `key_shapes`), with the feasible ranges.
    Key(usize),
    /// Frame `k`, in the formation frame of its leader (any heading): bars at the birds'
    /// offsets to the right of the leader's heading.
    Frame(usize),
}

/// The file name of `origin`, for titles.
pub(crate) fn file_name(origin: &Path) -> String {
    origin
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

impl PowerChart {
    /// The chart of one key shape or frame of `anim`, read from `origin` (named in the title and
    /// in messages). A frame without stored e and ξ gets them from Hummel's model. Errors name
    /// `plot.key` or `plot.frame`.
    pub fn from_animation(
        anim: &Animation,
        origin: &Path,
        of: PowerOf,
        metric: PowerMetric,
    ) -> Result<PowerChart> {
        let name = file_name(origin);
        let (x, behind, e, xi, what) = match of {
            PowerOf::Frame(k) => {
                let fr = anim.frames.get(k).ok_or_else(|| {
                    Error::parameter(
                        "plot.frame",
                        format!(
                            "{k}: {} has {} frames (0..{})",
                            origin.display(),
                            anim.frames.len(),
                            anim.frames.len().saturating_sub(1)
                        ),
                    )
                })?;
                // The formation frame of docs/formats.md §2 at this frame, whatever the heading: lateral
                // offsets to the right of the leader's heading, distances behind it along it.
                let rel = anim.relative(k);
                let lateral: Vec<f64> = rel.iter().map(|r| r.lateral).collect();
                let behind: Vec<f64> = rel.iter().map(|r| r.behind).collect();
                let (e, xi) = match (&fr.e, &fr.xi) {
                    (Some(e), Some(xi)) => (e.clone(), xi.clone()),
                    _ => {
                        let p = power_reduction(&lateral, &behind)?;
                        (p.e, p.xi)
                    }
                };
                (lateral, behind, e, xi, format!("frame {k}"))
            }
            PowerOf::Key(k) => {
                let ks = anim.key_shapes.get(k).ok_or_else(|| {
                Error::parameter(
                    "plot.key",
                    format!(
                        "{k}: {} has {} key shape(s); use plot.frame for an animation without key shapes",
                        origin.display(),
                        anim.key_shapes.len()
                    ),
                )
            })?;
                let x: Vec<f64> = ks.birds.iter().map(|b| b.x).collect();
                let y: Vec<f64> = ks.birds.iter().map(|b| b.y).collect();
                let p = power_reduction(&x, &y)?;
                (
                    x,
                    y,
                    p.e,
                    p.xi,
                    format!("key shape {k} (frame {})", ks.frame),
                )
            }
        };
        // The front-most bird (a frame's distances are behind its leader: the one at 0).
        let leader = behind
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i);
        Ok(PowerChart {
            title: format!("{name}: {what}"),
            values: match metric {
                PowerMetric::Xi => xi,
                PowerMetric::E => e,
            },
            x,
            metric,
            // Ranges belong to slots: a key shape's birds that changed places take their
            // slot's.
            ranges: anim.xi_ranges.as_ref().map(|r| match of {
                PowerOf::Key(k) => anim.key_shapes.get(k).map_or(r.clone(), |ks| {
                    ks.birds
                        .iter()
                        .enumerate()
                        .map(|(i, b)| r.get(b.slot.unwrap_or(i)).copied().unwrap_or([0.0, 1.0]))
                        .collect()
                }),
                _ => r.clone(),
            }),
            leader,
            behind,
        })
    }

    /// The chart of the file at `path`: a shape file (docs/formats.md §4.3), or formation `formation` of an
    /// animation file and its key shape or frame `of` (default: key shape 0), told apart by
    /// content ([`crate::sniff`]). Errors name `plot.formation`, `plot.key` or `plot.frame`.
    pub fn from_file(
        path: &Path,
        formation: Option<usize>,
        of: Option<PowerOf>,
        metric: PowerMetric,
    ) -> Result<PowerChart> {
        if crate::sniff::path_kind(path)? == crate::sniff::Kind::Animation {
            let (anim, which) = super::one_formation(Animation::read(path)?, formation, path)?;
            let of = of.unwrap_or(PowerOf::Key(0));
            let mut chart = PowerChart::from_animation(&anim, path, of, metric)?;
            chart.title.push_str(which.as_deref().unwrap_or(""));
            return Ok(chart);
        }
        let refuse = |option: &str, what: &str| {
            Err(Error::parameter(
                option,
                format!("{} is a shape file, which has no {what}", path.display()),
            ))
        };
        if formation.is_some() {
            return refuse("plot.formation", "formations");
        }
        if of.is_some() {
            return refuse("plot.key/plot.frame", "key shapes or frames");
        }
        let shape: Shape = crate::io::read_json(path)?;
        shape.validate(path, 2)?;
        PowerChart::from_shape(&shape, path, metric)
    }

    /// The chart of a shape file's shape (already validated), read from `origin`.
    pub fn from_shape(shape: &Shape, origin: &Path, metric: PowerMetric) -> Result<PowerChart> {
        let name = file_name(origin);
        let p = power_reduction(&shape.xs(), &shape.ys())?;
        Ok(PowerChart {
            title: format!("{name}: E = {:.4}", p.total),
            x: shape.xs(),
            values: match metric {
                PowerMetric::Xi => p.xi,
                PowerMetric::E => p.e,
            },
            metric,
            ranges: None,
            leader: shape.leader(),
            behind: shape.ys(),
        })
    }
}

/// Rank of each bird (0 = front) from its distance behind the leader; ties keep index order.
/// Empty when `behind` is.
fn ranks_of(behind: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..behind.len()).collect();
    order.sort_by(|&a, &b| behind[a].total_cmp(&behind[b]).then(a.cmp(&b)));
    let mut rank = vec![0; behind.len()];
    for (r, i) in order.into_iter().enumerate() {
        rank[i] = r;
    }
    rank
}

impl Chart for PowerChart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (xmin, xmax) = self
            .x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let (xmin, xmax) = if xmin.is_finite() {
            (xmin - 0.8, xmax + 0.8)
        } else {
            (-1.0, 1.0)
        };
        let mut top = self.values.iter().copied().fold(0.0, f64::max);
        let mut bottom = self.values.iter().copied().fold(0.0, f64::min);
        if let Some(r) = &self.ranges {
            for [lo, hi] in r {
                top = top.max(*hi);
                bottom = bottom.min(*lo);
            }
        }
        // Headroom above the tallest bar or whisker for the legend's box (two lines), so it
        // covers no bar.
        let top = if top > 0.0 {
            top + 0.3 * (top - bottom)
        } else {
            1.0
        };
        let ylabel = match self.metric {
            PowerMetric::Xi => "relative power reduction ξ",
            PowerMetric::E => "power reduction e",
        };
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(xmin..xmax, bottom..top)?;
        chart
            .configure_mesh()
            .x_desc("lateral position x (wingspans, right of the flight direction)")
            .y_desc(ylabel)
            .label_style((FONT_FAMILY, 14))
            .x_label_formatter(&super::tick_label)
            .y_label_formatter(&super::tick_label)
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        let lead = super::LEADER;
        let ranks = ranks_of(&self.behind);
        let n = self.x.len();
        let bar = super::bird_colour(n / 2, n);
        let half = 0.25;
        chart
            .draw_series(
                self.x
                    .iter()
                    .zip(&self.values)
                    .enumerate()
                    .map(|(i, (&x, &v))| {
                        let c = if Some(i) == self.leader {
                            lead
                        } else {
                            ranks.get(i).map_or(bar, |&r| super::bird_colour(r, n))
                        };
                        Rectangle::new([(x - half, 0.0), (x + half, v)], c.filled())
                    }),
            )?
            .label(match (self.leader.is_some(), ranks.is_empty()) {
                (true, false) => "bird by rank: leader red, then front dark to back green",
                (true, true) => "bird (red: leader)",
                (false, false) => "bird by rank: front dark to back green",
                (false, true) => "bird",
            })
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], bar.filled()));
        if let (Some(r), PowerMetric::Xi) = (&self.ranges, self.metric) {
            let style = ShapeStyle::from(&BLACK).stroke_width(2);
            let cap = half * 0.6;
            chart
                .draw_series(
                    self.x
                        .iter()
                        .zip(r)
                        .map(|(&x, [lo, hi])| PathElement::new(vec![(x, *lo), (x, *hi)], style)),
                )?
                .label("feasible range [(1−ε)p, (1+ε)P]")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
            for (&x, [lo, hi]) in self.x.iter().zip(r) {
                chart.draw_series(
                    [*lo, *hi]
                        .into_iter()
                        .map(|v| PathElement::new(vec![(x - cap, v), (x + cap, v)], style)),
                )?;
            }
        }
        super::draw_legend(&mut chart, 14, SeriesLabelPosition::UpperRight)?;
        Ok(())
    }
}
