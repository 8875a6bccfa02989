//! Living lateral spacing: the lateral positions of every key shape. The gaps between
//! lateral neighbours are drawn once for the flight (§5 step 1's N(μ_x, σ_x), see
//! [`crate::keyshape::steady`]) and each drifts slowly around its drawn value from key shape to
//! key shape, so the V breathes sideways as well as fore and aft. Wingspans.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use std::collections::BTreeMap;

use crate::error::{Error, Result};
use crate::extract::params::FormationParams;
use crate::keyshape::initial::positions_from_gaps;

/// Drift of the lateral gaps when the footage gives no measure of its own (no per-bird
/// positions): the median of the four example flocks' (0.06–0.09), wingspans.
pub const DEFAULT_DRIFT: f64 = 0.085;

/// Options of the lateral drift (the `steady.lateral` section of [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LateralOptions {
    /// Standard deviation of each lateral gap's drift around its drawn value, wingspans, in
    /// [0, 1] (0: lateral positions fixed for the whole flight). `None` (the default): the
    /// footage's, [`footage_drift`] (how much each pair of lateral neighbours' gap varies over
    /// the frames), or [`DEFAULT_DRIFT`] when the footage has no per-bird positions.
    pub drift: Option<f64>,
    /// Correlation of a gap's drift from one key shape to the next, dimensionless, in [0, 1)
    /// (an AR(1) process: larger is slower).
    pub correlation: f64,
}

impl Default for LateralOptions {
    fn default() -> Self {
        LateralOptions {
            drift: None,
            correlation: 0.7,
        }
    }
}

impl LateralOptions {
    /// Checks every option; the error names the option path (`steady.lateral.drift`).
    pub fn validate(&self) -> Result<()> {
        if let Some(d) = self.drift {
            if !(0.0..=1.0).contains(&d) {
                return Err(Error::parameter(
                    "steady.lateral.drift",
                    format!("{d}: must be in [0, 1] wingspans"),
                ));
            }
        }
        if !(self.correlation >= 0.0 && self.correlation < 1.0) {
            return Err(Error::parameter(
                "steady.lateral.correlation",
                format!("{}: must be in [0, 1)", self.correlation),
            ));
        }
        Ok(())
    }

    /// The drift to use with this footage, wingspans.
    pub fn drift_for(&self, params: &FormationParams) -> f64 {
        self.drift
            .or_else(|| footage_drift(params))
            .unwrap_or(DEFAULT_DRIFT)
    }
}

/// How much the footage's lateral gaps vary over its frames, wingspans: for every pair of birds
/// that are lateral neighbours (by id) in at least half of the frames (and at least 3), the
/// standard deviation of their gap over those frames; the median over the pairs, at most 0.25.
/// `None` with fewer than 3 frames of positions or no such pair. The figure includes the
/// annotation's own noise.
pub fn footage_drift(params: &FormationParams) -> Option<f64> {
    let frames: Vec<&crate::extract::params::FrameParams> = params
        .frames
        .iter()
        .filter(|f| f.positions.len() >= 2)
        .collect();
    if frames.len() < 3 {
        return None;
    }
    let mut series: BTreeMap<(usize, usize), Vec<f64>> = BTreeMap::new();
    for f in &frames {
        let mut b: Vec<(f64, usize)> = f.positions.iter().map(|p| (p.x, p.id)).collect();
        b.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        for w in b.windows(2) {
            series
                .entry((w[0].1, w[1].1))
                .or_default()
                .push(w[1].0 - w[0].0);
        }
    }
    let need = (frames.len().div_ceil(2)).max(3);
    let sds: Vec<f64> = series
        .values()
        .filter(|v| v.len() >= need)
        .map(|v| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|g| (g - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        })
        .filter(|s| s.is_finite())
        .collect();
    let m = crate::keyshape::spacing::median(sds);
    m.is_finite().then_some(m.min(0.25))
}

/// What bounds the drift of [`lateral_plan`] (from the steady flight's options).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LateralBounds {
    /// Correlation of a gap's deviation from one key to the next (`steady.lateral.correlation`).
    pub correlation: f64,
    /// No gap at or below this, wingspans (`steady.initial.min_gap`).
    pub min_gap: f64,
    /// No bird moves more than this between keys, wingspans (`steady.keys.max_jump`).
    pub max_jump: f64,
    /// A seamless loop.
    pub looped: bool,
}

/// Lateral positions of every key shape (the first the drawn `x` from `gaps`): each gap drifts
/// around its drawn value as an AR(1) process from key to key (standard deviation `drift`,
/// correlation `opts.correlation`), never at or below `opts.min_gap`, no bird
/// moving more than `opts.max_jump` between keys. A loop's drift is 0 at its first and
/// last key (= the first) and averages to 0 over the loop (a sine bump times the mean is taken
/// off each gap's deviations), so that every bird covers the same distance along a path in
/// every lap and the loop closes.
pub fn lateral_plan(
    gaps: &[f64],
    leader: usize,
    keys: usize,
    drift: f64,
    opts: &LateralBounds,
    rng: &mut impl Rng,
) -> Vec<Vec<f64>> {
    let rho = opts.correlation;
    let min_gap = opts.min_gap;
    let mut dev = vec![0.0; gaps.len()];
    let mut devs: Vec<Vec<f64>> = vec![dev.clone()];
    for _ in 1..keys {
        for d in dev.iter_mut() {
            let z: f64 = StandardNormal.sample(rng);
            *d = rho * *d + (1.0 - rho * rho).sqrt() * drift * z;
        }
        devs.push(dev.clone());
    }
    if opts.looped && keys > 2 {
        let last = (keys - 1) as f64;
        let bump: Vec<f64> = (0..keys)
            .map(|k| (std::f64::consts::PI * k as f64 / last).sin())
            .collect();
        let taper: Vec<f64> = (0..keys).map(|k| 1.0 - (k as f64 / last).powi(2)).collect();
        let wsum: f64 = bump.iter().sum();
        #[allow(clippy::needless_range_loop)]
        for g in 0..gaps.len() {
            let mean: f64 = (0..keys).map(|k| taper[k] * devs[k][g]).sum::<f64>() / wsum;
            for (k, dev) in devs.iter_mut().enumerate() {
                dev[g] = taper[k] * dev[g] - mean * bump[k];
            }
        }
        devs[keys - 1].iter_mut().for_each(|d| *d = 0.0);
    }
    let mut prev = positions_from_gaps(gaps, leader);
    let mut out = vec![prev.clone()];
    for dev in devs.iter().skip(1) {
        let g: Vec<f64> = gaps
            .iter()
            .zip(dev)
            .map(|(&g, &d)| (g + d).max((min_gap + 0.02).min(g)))
            .collect();
        let mut xk = positions_from_gaps(&g, leader);
        let jump = crate::keyshape::keys::max_jump(&prev, &xk);
        if jump > opts.max_jump {
            let f = opts.max_jump / jump;
            for (a, b) in xk.iter_mut().zip(&prev) {
                *a = b + f * (*a - b);
            }
        }
        prev = xk.clone();
        out.push(xk);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drift_is_measured_from_the_footage() {
        use crate::extract::params::{BirdPosition, FrameParams, ShapeModel, PARAMS_FORMAT};
        let mut p = FormationParams {
            format: PARAMS_FORMAT.into(),
            source: String::new(),
            birds: 3,
            frames: vec![],
            summary: None,
            motion: None,
            ci: None,
            heights: None,
        };
        // The gap of (0, 1) alternates 0.8 and 1.0 (sd 0.1), that of (1, 2) stays 1: median
        // over the two pairs 0.05.
        for k in 0..6 {
            let g = if k % 2 == 0 { 0.8 } else { 1.0 };
            let pos = |id: usize, x: f64| BirdPosition {
                id,
                x,
                y: 0.5 * x,
                dy: 0.0,
            };
            p.frames.push(FrameParams {
                index: k,
                order: vec![0, 1, 2],
                leader: 0,
                mu_x: 0.9,
                sigma_x: 0.1,
                mu_y: 0.0,
                sigma_y: 0.0,
                shape: ShapeModel::Line {
                    intercept: 0.0,
                    slope: 0.5,
                },
                inliers: vec![0, 1, 2],
                outliers: vec![],
                positions: vec![pos(0, 0.0), pos(1, g), pos(2, g + 1.0)],
                geometry: None,
            });
        }
        let d = footage_drift(&p).unwrap();
        assert!((d - 0.05).abs() < 1e-12, "{d}");
        assert_eq!(LateralOptions::default().drift_for(&p), d);
        let set = LateralOptions {
            drift: Some(0.2),
            ..LateralOptions::default()
        };
        assert_eq!(set.drift_for(&p), 0.2);
        p.frames.truncate(2);
        assert_eq!(LateralOptions::default().drift_for(&p), DEFAULT_DRIFT);
    }
}
