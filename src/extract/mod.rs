//! §4 parameter extraction: per-frame ordering, lateral spacing statistics, leader, and the RANSAC
//! shape fit.
//!
//! Takes [`Annotations`] (birds in wingspans along and across the flight direction, stable ids)
//! and gives [`FormationParams`] (docs/formats.md §4.2), one [`FrameParams`] per frame, formation frame with
//! the leader at the origin, wingspans.
//!
//! **Step 1** (per frame): the leader is the front-most bird; `order` lists the ids by lateral
//! position, left to right; μ_x, σ_x are the mean and sample standard deviation of the gaps
//! between lateral neighbours.
//!
//! **Step 2** (per frame): three families are fitted robustly ([`ransac`]): a line (line /
//! echelon), two arms meeting on the leader's line of flight (V: the apex depth and two slopes,
//! [`ransac::Vee`]), and a parabola opening backward (U or J). The family is chosen by a GRIC/BIC-like criterion (Torr's geometric
//! robust information criterion with all models being curves, so only the residual and
//! parameter-count terms differ):
//!
//! ```math
//! S(M) = \sum_i \min\!\left(\frac{r_i^2}{\sigma^2},\ \frac{T^2}{\sigma^2}\right) + k_M \ln n,
//! \qquad \sigma = T / 2
//! ```
//!
//! with r_i = (y_i − curve(x_i)) / √(1 + curve'(x_i)²) the first-order distance of bird i
//! from the curve (so that image noise on a steep arm is not taken for an outlier), T the inlier threshold (`ExtractOptions::inlier_threshold`,
//! wingspans), n the birds in the frame and k_M the parameter count (line 2, parabola 3, V 3).
//! A bad point costs at most (T/σ)² = 4, so an outlier cannot pull the choice; a more complex
//! model must buy its extra parameters with a residual drop of ln n each. The lowest S wins;
//! equal scores (within a relative 1e-6, e.g. three birds, which a V and a parabola both fit
//! exactly) go to the V, then the line, then the parabola: three birds are a V unless the data
//! say otherwise. The paper is silent on the choice; this criterion is ours.
//!
//! After the frames, [`checks`] looks for suspicious input (a formation opening forward, a
//! heading off by 90°, an implausible scale, few frames, 3-bird frames) and [`geometry`]
//! measures each frame's apex angle per arm, depth and wingtip spacing; both go into
//! [`FormationParams::summary`]. A
//! parabola is a **J** when its vertex x_v = −b/(2a) lies more than `j_offset` half-widths from
//! the centre of the inliers' lateral extent (one arm clearly longer), else a **U**. Birds with
//! |r| ≤ T are inliers; μ_y, σ_y are the mean and sample standard deviation of the inliers'
//! vertical deviations dy = y − curve(x) (the paper's y-deviations).

pub mod bootstrap;
pub mod checks;
pub mod geometry;
pub mod heights;
pub mod motion;
pub mod params;
pub mod ransac;
pub mod screen;

use rand::Rng;
use serde::{Deserialize, Serialize};

pub use checks::{Warning, WarningKind};
pub use params::{
    BirdPosition, FormationParams, FrameParams, LineCoef, ParamsSummary, ShapeModel, PARAMS_FORMAT,
};

use crate::annotations::{AnnotatedFrame, Annotations};
use crate::error::{Error, Result};
use crate::progress::Progress;
use ransac::{Line, Model, Parabola, RansacOptions, Vee};

/// Relative gap under which two criterion values count as equal (exact fits of a few birds).
const TIE: f64 = 1e-6;

pub use crate::shape::ShapeKind;

impl ShapeKind {
    /// The kind of a fitted model.
    pub fn of(m: &ShapeModel) -> ShapeKind {
        match m {
            ShapeModel::V { .. } => ShapeKind::V,
            ShapeModel::U { .. } => ShapeKind::U,
            ShapeModel::J { .. } => ShapeKind::J,
            ShapeModel::Line { .. } => ShapeKind::Line,
        }
    }
}

/// Settings of [`extract`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExtractOptions {
    /// Inlier threshold T: a bird farther than this from the curve (along y) is an outlier,
    /// wingspans.
    pub inlier_threshold: f64,
    /// Most RANSAC minimal samples per model and frame; below this count of subsets, all are
    /// tried (exhaustive and seed-independent).
    pub max_samples: usize,
    /// Rounds of least-squares refinement on the inliers.
    pub refine_rounds: usize,
    /// A parabola is a J when its vertex is more than this many half-widths of the flock from
    /// the flock's lateral centre (dimensionless, 0–1).
    pub j_offset: f64,
    /// Fit only this family (U and J both mean "parabola", labelled as given).
    pub kind: Option<ShapeKind>,
    /// Wingspan of one bird, metres, when known: the wingtip spacings are also given in metres.
    pub wingspan_m: Option<f64>,
    /// Frames per second of the footage (overrides the annotations' `fps`): frame times for
    /// the position-keeping statistics.
    pub footage_fps: Option<f64>,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions {
            inlier_threshold: 0.5,
            max_samples: 2000,
            refine_rounds: 5,
            j_offset: 0.5,
            kind: None,
            wingspan_m: None,
            footage_fps: None,
        }
    }
}

impl ExtractOptions {
    /// Checks ranges; errors name the option path (`extract.j_offset`).
    pub fn validate(&self) -> Result<()> {
        if !(self.inlier_threshold.is_finite() && self.inlier_threshold > 0.0) {
            return Err(Error::parameter(
                "extract.inlier_threshold",
                format!(
                    "must be a positive number of wingspans, got {}",
                    self.inlier_threshold
                ),
            ));
        }
        if !(1..=crate::limits::MAX_RANSAC_SAMPLES).contains(&self.max_samples) {
            return Err(Error::parameter(
                "extract.max_samples",
                format!(
                    "must be between 1 and {} (each sample costs a pass over the frame's birds), got {}",
                    crate::limits::MAX_RANSAC_SAMPLES,
                    self.max_samples
                ),
            ));
        }
        if !(self.j_offset.is_finite() && (0.0..=1.0).contains(&self.j_offset)) {
            return Err(Error::parameter(
                "extract.j_offset",
                format!("must be between 0 and 1, got {}", self.j_offset),
            ));
        }
        if let Some(m) = self.wingspan_m {
            if !(m.is_finite() && m > 0.0 && m <= crate::limits::MAX_WINGSPAN_M) {
                return Err(Error::parameter(
                    "extract.wingspan_m",
                    format!(
                        "must be a positive number of metres, at most {}, got {m}",
                        crate::limits::MAX_WINGSPAN_M
                    ),
                ));
            }
        }
        if let Some(f) = self.footage_fps {
            if !(f.is_finite() && f > 0.0 && f <= 100_000.0) {
                return Err(Error::parameter(
                    "extract.footage_fps",
                    format!(
                        "must be a positive number of frames per second, at most 100000, got {f}"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Criterion value of every family tried on one frame (lower is better).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameReport {
    /// Frame index.
    pub index: i64,
    /// `(kind, S)` for each family fitted; the parabola appears under the kind it was labelled.
    pub scores: Vec<(ShapeKind, f64)>,
}

impl FrameReport {
    /// The best and second-best families with their criterion gap `S₂ − S₁`.
    pub fn margin(&self) -> Option<(ShapeKind, f64)> {
        let mut s = self.scores.clone();
        s.sort_by(|a, b| a.1.total_cmp(&b.1));
        match s.as_slice() {
            [a, b, ..] => Some((b.0, b.1 - a.1)),
            _ => None,
        }
    }
}

/// Formation parameters from `path`, whatever it holds: a params file written by `extract` is
/// read and validated; anything else is read as annotations (with `read`) and extracted (with
/// `opts` and `rng`). This is what `formation animate INPUT` needs.
pub fn params_from_path(
    path: &std::path::Path,
    read: &crate::annotations::ReadOptions,
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> Result<FormationParams> {
    if let Some(p) = FormationParams::read_if_params(path)? {
        return Ok(p);
    }
    let ann = crate::annotations::read(path, read)?;
    extract(&ann, opts, rng)
}

/// §4 steps 1 and 2 over every frame.
pub fn extract(
    ann: &Annotations,
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> Result<FormationParams> {
    extract_with_report(ann, opts, rng, &crate::progress::Silent).map(|(p, _)| p)
}

/// [`extract`], also returning the model-selection scores of every frame, and reporting
/// progress (one unit per frame).
pub fn extract_with_report(
    ann: &Annotations,
    opts: &ExtractOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<(FormationParams, Vec<FrameReport>)> {
    opts.validate()?;
    if ann.frames.is_empty() {
        return Err(Error::format(&ann.path, "no frames to extract from"));
    }
    let mut frames = Vec::with_capacity(ann.frames.len());
    let mut reports = Vec::with_capacity(ann.frames.len());
    progress.start("extract", ann.frames.len() as u64);
    for f in &ann.frames {
        let (p, r) = extract_frame(f, opts, rng)
            .map_err(|m| Error::format(&ann.path, format!("frame {}: {m}", f.index)))?;
        frames.push(p);
        reports.push(r);
        progress.advance(1);
    }
    progress.finish();
    for f in &mut frames {
        f.geometry = Some(geometry::frame_geometry(f, opts.wingspan_m));
    }
    let geometry =
        geometry::summarise(&frames.iter().filter_map(|f| f.geometry).collect::<Vec<_>>());
    let mut params = FormationParams {
        format: PARAMS_FORMAT.to_string(),
        source: ann.source.clone(),
        birds: ann.bird_count(),
        frames,
        summary: None,
        motion: None,
        ci: None,
        heights: None,
    };
    params.ci = Some(Box::new(bootstrap::intervals(&params.frames)));
    params.heights = heights::measure(ann, &params.frames);
    params.motion = opts
        .footage_fps
        .or(ann.fps)
        .and_then(|fps| motion::footage_keeping(&params.frames, fps));
    let warnings = checks::check(ann, &params, &reports, opts, rng);
    params.summary = Some(Box::new(ParamsSummary {
        wingspan_m: opts.wingspan_m,
        geometry,
        warnings,
    }));
    Ok((params, reports))
}

/// Slope dy/dx of a fitted curve at x (a V uses the arm of x's side).
pub fn slope_at(m: &ShapeModel, x: f64) -> f64 {
    match *m {
        ShapeModel::V { left, right } => {
            if x < 0.0 {
                left.slope
            } else {
                right.slope
            }
        }
        ShapeModel::Line { slope, .. } => slope,
        ShapeModel::U { a, b, .. } | ShapeModel::J { a, b, .. } => 2.0 * a * x + b,
    }
}

/// Squared first-order (Sampson) distance of (x, y) from the curve, wingspans²:
/// r² / (1 + y'(x)²) with r = y − curve(x).
pub fn dist2(m: &ShapeModel, x: f64, y: f64) -> f64 {
    let r = y - m.y_at(x);
    let s = slope_at(m, x);
    r * r / (1.0 + s * s)
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (m, 0.0);
    }
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// One frame: step 1 statistics and the chosen step 2 model. Errors are messages without the
/// file name (the caller adds it).
pub fn extract_frame(
    f: &AnnotatedFrame,
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> std::result::Result<(FrameParams, FrameReport), String> {
    let n = f.birds.len();
    if n < 3 {
        return Err(format!(
            "{n} bird(s) marked, a line formation needs at least 3"
        ));
    }
    if let Some(b) = f
        .birds
        .iter()
        .find(|b| !(b.lateral.is_finite() && b.forward.is_finite()))
    {
        return Err(format!("bird {}: position is not a finite number", b.id));
    }
    let lead = crate::annotations::front_most(&f.birds);
    let (l0, f0) = (f.birds[lead].lateral, f.birds[lead].forward);
    let leader = f.birds[lead].id;
    // Formation frame: x right of the flight direction, y behind the leader.
    let mut pos: Vec<(usize, f64, f64)> = f
        .birds
        .iter()
        .map(|b| (b.id, b.lateral - l0, f0 - b.forward))
        .collect();
    pos.sort_by(|a, b| {
        a.1.total_cmp(&b.1)
            .then(a.2.total_cmp(&b.2))
            .then(a.0.cmp(&b.0))
    });
    let order: Vec<usize> = pos.iter().map(|p| p.0).collect();
    let gaps: Vec<f64> = pos.windows(2).map(|w| w[1].1 - w[0].1).collect();
    let (mu_x, sigma_x) = mean_sd(&gaps);
    let pts: Vec<(f64, f64)> = pos.iter().map(|p| (p.1, p.2)).collect();
    let (shape, scores) = choose_model(&pts, opts, rng).ok_or_else(|| {
        "no curve fits these birds (are they all at one lateral position?)".to_string()
    })?;
    let t = opts.inlier_threshold;
    let mut positions = Vec::with_capacity(n);
    let (mut inliers, mut outliers, mut dys) = (Vec::new(), Vec::new(), Vec::new());
    for &(id, x, y) in &pos {
        let dy = y - shape.y_at(x);
        positions.push(BirdPosition { id, x, y, dy });
        if dist2(&shape, x, y) <= t * t {
            inliers.push(id);
            dys.push(dy);
        } else {
            outliers.push(id);
        }
    }
    let (mu_y, sigma_y) = mean_sd(&dys);
    Ok((
        FrameParams {
            index: f.index,
            order,
            leader,
            mu_x,
            sigma_x,
            mu_y,
            sigma_y,
            shape,
            inliers,
            outliers,
            positions,
            geometry: None,
        },
        FrameReport {
            index: f.index,
            scores,
        },
    ))
}

/// Fits the families and picks the one with the lowest criterion (module docs). `pts` are sorted
/// by x, leader at the origin.
fn choose_model(
    pts: &[(f64, f64)],
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> Option<(ShapeModel, Vec<(ShapeKind, f64)>)> {
    let t = opts.inlier_threshold;
    let t2 = t * t;
    let sigma2 = t2 / 4.0;
    let ro = RansacOptions {
        threshold: t,
        max_samples: opts.max_samples,
        refine_rounds: opts.refine_rounds,
    };
    let n = pts.len();
    let ln_n = (n as f64).ln();
    let want = |k: ShapeKind| match opts.kind {
        None => true,
        Some(ShapeKind::U) | Some(ShapeKind::J) => matches!(k, ShapeKind::U | ShapeKind::J),
        Some(w) => w == k,
    };
    let cost_of = |m: &ShapeModel| -> f64 {
        pts.iter()
            .map(|&(x, y)| dist2(m, x, y).min(t2))
            .sum::<f64>()
    };
    let mut cands: Vec<(ShapeModel, f64)> = Vec::new();
    if want(ShapeKind::Line) {
        if let Some((l, _)) = ransac::ransac::<Line>(pts, &ro, rng) {
            let m = ShapeModel::Line {
                intercept: l.c,
                slope: l.s,
            };
            cands.push((m, cost_of(&m) / sigma2 + 2.0 * ln_n));
        }
    }
    if want(ShapeKind::U) {
        if let Some((p, _)) = ransac::ransac::<Parabola>(pts, &ro, rng) {
            // J or U by where the vertex lies within the inliers' lateral extent.
            let inl: Vec<f64> = pts
                .iter()
                .filter(|&&(x, y)| p.dist2(x, y) <= t2)
                .map(|p| p.0)
                .collect();
            let (lo, hi) = inl
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                    (lo.min(x), hi.max(x))
                });
            let half = ((hi - lo) / 2.0).max(1e-9);
            let vertex = -p.b / (2.0 * p.a);
            let off = (vertex - (lo + hi) / 2.0).abs() / half;
            let is_j = match opts.kind {
                Some(ShapeKind::U) => false,
                Some(ShapeKind::J) => true,
                _ => off > opts.j_offset,
            };
            let m = if is_j {
                ShapeModel::J {
                    a: p.a,
                    b: p.b,
                    c: p.c,
                }
            } else {
                ShapeModel::U {
                    a: p.a,
                    b: p.b,
                    c: p.c,
                }
            };
            cands.push((m, cost_of(&m) / sigma2 + 3.0 * ln_n));
        }
    }
    if want(ShapeKind::V) {
        // Two arms meeting at the leader's lateral position (needs a bird on each side).
        if let Some((v, _)) = ransac::ransac::<Vee>(pts, &ro, rng) {
            let m = ShapeModel::V {
                left: LineCoef {
                    intercept: v.c,
                    slope: v.sl,
                },
                right: LineCoef {
                    intercept: v.c,
                    slope: v.sr,
                },
            };
            cands.push((m, cost_of(&m) / sigma2 + 3.0 * ln_n));
        }
    }
    // Lowest S; among scores equal to rounding (three birds fit a V and a parabola exactly) the
    // V, then the line, then the parabola.
    let lowest = cands.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let preference = |m: &ShapeModel| match m {
        ShapeModel::V { .. } => 0,
        ShapeModel::Line { .. } => 1,
        _ => 2,
    };
    let best = cands
        .iter()
        .filter(|c| c.1 <= lowest + TIE * (1.0 + lowest.abs()))
        .min_by_key(|c| preference(&c.0))
        .map(|c| c.0)?;
    let scores = cands.iter().map(|(m, s)| (ShapeKind::of(m), *s)).collect();
    Some((best, scores))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_parse() {
        assert_eq!("V".parse::<ShapeKind>(), Ok(ShapeKind::V));
        assert_eq!("echelon".parse::<ShapeKind>(), Ok(ShapeKind::Line));
        assert!("w".parse::<ShapeKind>().is_err());
    }
}
