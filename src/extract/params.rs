//! The formation-parameters file (docs/formats.md §4.2): what `extract` learns from each annotated frame and
//! `steady` consumes. Formation frame (leader at the origin, `x` right of the flight direction,
//! `y` behind the leader), wingspans.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::error::{Error, Result};

pub use crate::sniff::PARAMS_FORMAT;

/// Parameters of a whole annotated movie.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FormationParams {
    /// Always [`PARAMS_FORMAT`].
    pub format: String,
    /// Free text from the annotations (`source`).
    pub source: String,
    /// Number of distinct birds in the movie (N̂).
    pub birds: usize,
    /// One entry per annotated frame, in file order.
    pub frames: Vec<FrameParams>,
    /// The movie's geometry over all frames and the warnings of the extraction;
    /// absent in files written before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub summary: Option<Box<ParamsSummary>>,
    /// The birds' position keeping measured in the footage (needs frame times); absent when
    /// the footage has no timing (the steady flight then uses the field-data default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<PositionKeeping>,
    /// 95 % bootstrap intervals of the apex angle, the nearest bird ahead, the depth and the
    /// wingtip spacing; absent in files written before them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ci: Option<Box<Intervals>>,
    /// The birds' heights measured in 3-D tracks; absent for image annotations (the steady
    /// flight then draws heights with the field-data defaults).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heights: Option<MeasuredHeights>,
}

/// Heights measured in 3-D tracks (the params' `"heights"`), wingspans, upward.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeasuredHeights {
    /// Frames measured.
    pub frames: usize,
    /// Standard deviation of the birds' heights within a frame, root mean square over the
    /// frames (what `steady.heights.spread` draws).
    pub spread: f64,
    /// Root-mean-square height difference of lateral neighbours (what
    /// `steady.heights.neighbour` draws).
    pub neighbour: f64,
    /// Mean height of a bird above the bird ahead of it (its lateral neighbour toward the
    /// leader), over every bird but the leader of every frame.
    pub ahead_mean: f64,
    /// Standard deviation of the height above the bird ahead.
    pub ahead_sd: f64,
}

/// What `extract` reports about the whole movie besides the per-frame parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamsSummary {
    /// Wingspan of one bird, metres, when given (the spacings in metres use it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingspan_m: Option<f64>,
    /// Apex angle, arm angles, depth and wingtip spacing over the frames.
    pub geometry: GeometrySummary,
    /// Suspicious input found while extracting (empty when none).
    #[serde(default)]
    pub warnings: Vec<Warning>,
}

/// §4 steps 1 and 2 for one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameParams {
    /// Frame index from the annotations.
    pub index: i64,
    /// Bird ids ordered by lateral position, left to right.
    pub order: Vec<usize>,
    /// Id of the front-most bird.
    pub leader: usize,
    /// Mean lateral distance between lateral neighbours, wingspans.
    pub mu_x: f64,
    /// Standard deviation of the lateral neighbour distances, wingspans.
    pub sigma_x: f64,
    /// Mean deviation of the inliers from the fitted curve (y − curve(x)), wingspans.
    pub mu_y: f64,
    /// Standard deviation of the inliers' deviations from the curve, wingspans.
    pub sigma_y: f64,
    /// The fitted curve.
    pub shape: ShapeModel,
    /// Ids of the birds the curve explains.
    pub inliers: Vec<usize>,
    /// Ids of the birds RANSAC rejects.
    pub outliers: Vec<usize>,
    /// Every marked bird of the frame in the formation frame (leader at the origin), with its
    /// deviation from the curve; in `order`.
    #[serde(default)]
    pub positions: Vec<BirdPosition>,
    /// Apex angle per arm, depth, width and wingtip spacing; absent in files
    /// written before it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry: Option<FrameGeometry>,
}

/// A marked bird in the formation frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BirdPosition {
    /// Bird id.
    pub id: usize,
    /// Lateral offset from the leader, wingspans.
    pub x: f64,
    /// Distance behind the leader, wingspans.
    pub y: f64,
    /// Deviation from the fitted curve, `y − curve(x)`, wingspans.
    pub dy: f64,
}

/// A straight line `y = intercept + slope·x` in the formation frame (wingspans).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineCoef {
    /// `y` at `x = 0`, wingspans.
    pub intercept: f64,
    /// dy/dx.
    pub slope: f64,
}

impl LineCoef {
    /// `y` at lateral offset `x`.
    pub fn y_at(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }
}

/// The curve fitted to one frame (§4 step 2), formation frame, wingspans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ShapeModel {
    /// Two lines meeting near the leader: `left` for x < 0, `right` for x ≥ 0.
    V {
        /// Arm to the left of the leader.
        left: LineCoef,
        /// Arm to the right of the leader.
        right: LineCoef,
    },
    /// One line (echelon or line abreast).
    Line {
        /// `y` at `x = 0`.
        intercept: f64,
        /// dy/dx.
        slope: f64,
    },
    /// Symmetric-ish parabola `y = a·x² + b·x + c`, vertex near the flock's centre.
    U {
        /// Quadratic coefficient.
        a: f64,
        /// Linear coefficient.
        b: f64,
        /// Constant.
        c: f64,
    },
    /// Parabola whose vertex is well off the flock's centre (one arm longer).
    J {
        /// Quadratic coefficient.
        a: f64,
        /// Linear coefficient.
        b: f64,
        /// Constant.
        c: f64,
    },
}

impl ShapeModel {
    /// The curve's `y` (distance behind the leader) at lateral offset `x`, wingspans.
    pub fn y_at(&self, x: f64) -> f64 {
        match *self {
            ShapeModel::V { left, right } => {
                if x < 0.0 {
                    left.y_at(x)
                } else {
                    right.y_at(x)
                }
            }
            ShapeModel::Line { intercept, slope } => intercept + slope * x,
            ShapeModel::U { a, b, c } | ShapeModel::J { a, b, c } => (a * x + b) * x + c,
        }
    }

    /// `"v"`, `"line"`, `"u"` or `"j"`.
    pub fn kind(&self) -> &'static str {
        match self {
            ShapeModel::V { .. } => "v",
            ShapeModel::Line { .. } => "line",
            ShapeModel::U { .. } => "u",
            ShapeModel::J { .. } => "j",
        }
    }
}

impl std::fmt::Display for ShapeModel {
    /// The fitted curve as an equation in the formation frame (wingspans, y behind the leader):
    /// `V: y = 0.12 - 0.83·x (x < 0), y = 0.10 + 0.79·x (x ≥ 0)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = f.precision().unwrap_or(2);
        let line = |c: f64, m: f64| {
            let sign = if m < 0.0 { '-' } else { '+' };
            format!("y = {c:.p$} {sign} {:.p$}·x", m.abs())
        };
        let para = |a: f64, b: f64, c: f64| {
            let sb = if b < 0.0 { '-' } else { '+' };
            let sc = if c < 0.0 { '-' } else { '+' };
            format!("y = {a:.p$}·x² {sb} {:.p$}·x {sc} {:.p$}", b.abs(), c.abs())
        };
        match *self {
            ShapeModel::V { left, right } => write!(
                f,
                "V: {} (x < 0), {} (x ≥ 0)",
                line(left.intercept, left.slope),
                line(right.intercept, right.slope)
            ),
            ShapeModel::Line { intercept, slope } => write!(f, "line: {}", line(intercept, slope)),
            ShapeModel::U { a, b, c } => write!(f, "U: {}", para(a, b, c)),
            ShapeModel::J { a, b, c } => write!(f, "J: {}", para(a, b, c)),
        }
    }
}

impl FormationParams {
    /// How many frames were fitted by each kind (`"v"`, `"line"`, …), most frequent first
    /// (ties in order of first appearance).
    pub fn kind_counts(&self) -> Vec<(&'static str, usize)> {
        let mut counts: Vec<(&'static str, usize)> = Vec::new();
        for f in &self.frames {
            let k = f.shape.kind();
            match counts.iter_mut().find(|c| c.0 == k) {
                Some(c) => c.1 += 1,
                None => counts.push((k, 1)),
            }
        }
        counts.sort_by_key(|c| std::cmp::Reverse(c.1));
        counts
    }

    /// Reads and validates a params file. Another of formation's files (an animation, a shape,
    /// annotations) is named for what it is ([`crate::sniff`]) before any field error.
    pub fn read(path: &Path) -> Result<FormationParams> {
        let text = crate::io::read_text(path)?;
        FormationParams::parse(path, &text)
    }

    /// The params file at `path` when it is one (told apart by content, [`crate::sniff`]),
    /// read and validated; `None` for a directory or any other file (annotations, say).
    pub fn read_if_params(path: &Path) -> Result<Option<FormationParams>> {
        if path.is_dir() {
            return Ok(None);
        }
        let text = crate::io::read_text(path)?;
        if !crate::sniff::is_params(&text) {
            return Ok(None);
        }
        FormationParams::parse(path, &text).map(Some)
    }

    /// [`FormationParams::read`] of a text already read from `path`.
    fn parse(path: &Path, text: &str) -> Result<FormationParams> {
        let value: serde_json::Value = crate::io::parse_json(path, text)?;
        let kind = crate::sniff::json_kind(&value);
        if kind != crate::sniff::Kind::Params {
            return Err(Error::format(
                path,
                format!(
                    "not a formation params file ({}, expected \"format\": \"{PARAMS_FORMAT}\"); write one with `formation extract ANNOTATIONS -o params.json`",
                    kind.describe(),
                ),
            ));
        }
        let p: FormationParams = crate::io::parse_json(path, text)?;
        p.validate(path)?;
        Ok(p)
    }

    /// Checks the format tag and that every number is finite and every id known.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        if self.format != PARAMS_FORMAT {
            return Err(Error::format(
                origin,
                format!(
                    "format: expected \"{PARAMS_FORMAT}\", found \"{}\" (is this a params file written by `formation extract`?)",
                    self.format
                ),
            ));
        }
        if self.frames.is_empty() {
            return Err(Error::format(origin, "frames: no frames"));
        }
        for (k, f) in self.frames.iter().enumerate() {
            let nums = [
                ("mu_x", f.mu_x),
                ("sigma_x", f.sigma_x),
                ("mu_y", f.mu_y),
                ("sigma_y", f.sigma_y),
            ];
            for (name, v) in nums {
                if !v.is_finite() {
                    return Err(Error::format(
                        origin,
                        format!("frames[{k}].{name}: not a finite number"),
                    ));
                }
            }
            // Found by fuzzing: huge finite values overflow the steady flight's ranges
            // to NaN. No formation has neighbours 100 wingspans apart.
            if let Some((name, v)) = nums
                .iter()
                .find(|(_, v)| v.abs() > crate::limits::MAX_PARAM_SPACING)
            {
                return Err(Error::format(
                    origin,
                    format!(
                        "frames[{k}].{name}: {v} wingspans is not a formation spacing (at most {} in magnitude)",
                        crate::limits::MAX_PARAM_SPACING
                    ),
                ));
            }
            if f.sigma_x < 0.0 || f.sigma_y < 0.0 {
                return Err(Error::format(
                    origin,
                    format!("frames[{k}]: standard deviations must not be negative"),
                ));
            }
            if f.order.len() < 2 {
                return Err(Error::format(
                    origin,
                    format!(
                        "frames[{k}].order: {} bird(s), at least 2 needed",
                        f.order.len()
                    ),
                ));
            }
            if !f.order.contains(&f.leader) {
                return Err(Error::format(
                    origin,
                    format!("frames[{k}].leader: bird {} is not in `order`", f.leader),
                ));
            }
            let coefs: Vec<f64> = match f.shape {
                ShapeModel::V { left, right } => {
                    vec![left.intercept, left.slope, right.intercept, right.slope]
                }
                ShapeModel::Line { intercept, slope } => vec![intercept, slope],
                ShapeModel::U { a, b, c } | ShapeModel::J { a, b, c } => vec![a, b, c],
            };
            if coefs
                .iter()
                .any(|v| !v.is_finite() || v.abs() > crate::limits::MAX_PARAM_COORDINATE)
            {
                return Err(Error::format(
                    origin,
                    format!(
                        "frames[{k}].shape: coefficients must be finite numbers of at most {:e} in magnitude",
                        crate::limits::MAX_PARAM_COORDINATE
                    ),
                ));
            }
            for (i, p) in f.positions.iter().enumerate() {
                let ok = |v: f64| v.is_finite() && v.abs() <= crate::limits::MAX_PARAM_COORDINATE;
                if !(ok(p.x) && ok(p.y) && ok(p.dy)) {
                    return Err(Error::format(
                        origin,
                        format!(
                            "frames[{k}].positions[{i}]: not a finite number of at most {:e} wingspans",
                            crate::limits::MAX_PARAM_COORDINATE
                        ),
                    ));
                }
            }
        }
        if let Some(h) = &self.heights {
            let fields = [
                ("spread", h.spread),
                ("neighbour", h.neighbour),
                ("ahead_mean", h.ahead_mean),
                ("ahead_sd", h.ahead_sd),
            ];
            for (name, v) in fields {
                // Heights feed `steady.heights.spread`, which allows at most 10 wingspans.
                let ok = v.is_finite() && v.abs() <= 10.0 && (name == "ahead_mean" || v >= 0.0);
                if !ok {
                    return Err(Error::format(
                        origin,
                        format!("heights.{name}: {v} is not a height of at most 10 wingspans (non-negative but for ahead_mean)"),
                    ));
                }
            }
        }
        Ok(())
    }
}

// The types the extraction's summary and checks fill in live here, with the file they are part
// of, so that `geometry` and `checks` depend on this module and not the other way round.

/// Geometry of one extracted frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrameGeometry {
    /// Angle of the left arm from the flight axis behind the leader, degrees; `None` without a
    /// bird left of the leader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_left_deg: Option<f64>,
    /// Angle of the right arm, degrees; `None` without a bird right of the leader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_right_deg: Option<f64>,
    /// Apex angle, left + right arm, degrees; `None` unless both arms exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_deg: Option<f64>,
    /// Farthest inlier behind the leader, wingspans.
    pub depth: f64,
    /// Lateral extent of the inliers, wingspans.
    pub width: f64,
    /// Mean wingtip spacing of lateral neighbours (μ_x − 1), wingspans.
    pub wingtip_spacing: f64,
    /// The same in metres, when the wingspan in metres is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing_m: Option<f64>,
}

/// Median, mean and range of one quantity over the frames that have it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Frames that have the quantity.
    pub frames: usize,
    /// Median.
    pub median: f64,
    /// Mean.
    pub mean: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Stat {
    /// The statistics of `v`; `None` when empty.
    pub fn of(v: &[f64]) -> Option<Stat> {
        if v.is_empty() {
            return None;
        }
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        let n = s.len();
        let median = if n % 2 == 1 {
            s[n / 2]
        } else {
            (s[n / 2 - 1] + s[n / 2]) / 2.0
        };
        Some(Stat {
            frames: n,
            median,
            mean: s.iter().sum::<f64>() / n as f64,
            min: s[0],
            max: s[n - 1],
        })
    }
}

/// The movie's geometry over all frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GeometrySummary {
    /// Apex angle, degrees (frames with two arms).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_deg: Option<Stat>,
    /// Left arm angle, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_left_deg: Option<Stat>,
    /// Right arm angle, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_right_deg: Option<Stat>,
    /// Depth, wingspans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<Stat>,
    /// Mean wingtip spacing, wingspans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing: Option<Stat>,
    /// Mean wingtip spacing, metres, when the wingspan in metres is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing_m: Option<Stat>,
}

/// What kind of suspicion a [`Warning`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// The formation opens forward (y axis or heading reversed).
    OpensForward,
    /// The formation fits far better with the heading turned 90°.
    Heading,
    /// Birds implausibly close or far for the given wingspan in pixels.
    Scale,
    /// Fewer than `extract::checks::MIN_FRAMES` frames.
    FewFrames,
    /// Frames of exactly 3 birds (V and U indistinguishable).
    ThreeBirds,
    /// Frames unlike the others (gaps, scatter or birds off the shape), left out of the spacing.
    OddFrame,
}

/// One warning: its kind and a one-line message naming the option that fixes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// What kind of suspicion.
    pub kind: WarningKind,
    /// One line: the file, what looks wrong, the likely cause, the option that fixes it.
    pub message: String,
}

/// One axis of position keeping, wingspans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AxisKeeping {
    /// Median of a bird's move over 0.5 s.
    pub move_median: f64,
    /// 90th percentile of a bird's move over 0.5 s.
    pub move_p90: f64,
    /// Median of a bird's move over 3 s (`None` when the footage is shorter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub move_long_median: Option<f64>,
    /// Per-bird standard deviation about its mean slot, median over the birds.
    pub spread: f64,
    /// Correlation time ℓ of the fitted process, seconds: its autocorrelation is
    /// exp(−τ²/(2ℓ²)).
    pub time_scale: f64,
}

/// Where the position-keeping statistics came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KeepingSource {
    /// Measured in the footage.
    Footage,
    /// The field-data default (wild white-fronted geese).
    FieldData,
}

/// The footage's position keeping (the params' `"motion"`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PositionKeeping {
    /// Measured or default.
    pub source: KeepingSource,
    /// Frames per second of the footage used for the frame times.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f64>,
    /// Across the flight direction.
    pub lateral: AxisKeeping,
    /// Along the flight direction.
    pub fore_aft: AxisKeeping,
}

/// 95 % intervals, `[lo, hi]`; a quantity the footage does not have (an apex without a V, too
/// few frames) is absent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Intervals {
    /// Apex angle, degrees (median over the frames with two arms).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_deg: Option<[f64; 2]>,
    /// Lateral offset of each bird from its nearest bird ahead, wingspans (median over every
    /// bird of every frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lateral: Option<[f64; 2]>,
    /// Distance behind its nearest bird ahead, wingspans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub behind: Option<[f64; 2]>,
    /// Depth (farthest inlier behind the leader), wingspans (median over the frames).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<[f64; 2]>,
    /// Mean wingtip spacing (μ_x − 1), wingspans (median over the frames).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wts: Option<[f64; 2]>,
}

#[cfg(test)]
mod tests {
    #[test]
    fn fitted_curves_print_as_equations() {
        use super::{LineCoef, ShapeModel};
        let v = ShapeModel::V {
            left: LineCoef {
                intercept: 0.12,
                slope: -0.83,
            },
            right: LineCoef {
                intercept: 0.1,
                slope: 0.79,
            },
        };
        assert_eq!(
            v.to_string(),
            "V: y = 0.12 - 0.83·x (x < 0), y = 0.10 + 0.79·x (x ≥ 0)"
        );
        let u = ShapeModel::U {
            a: 0.2,
            b: -0.01,
            c: 0.5,
        };
        assert_eq!(format!("{u:.1}"), "U: y = 0.2·x² - 0.0·x + 0.5");
    }
}
