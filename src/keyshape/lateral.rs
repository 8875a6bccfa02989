//! Living lateral spacing (issue 19): the lateral positions of every key shape. The gaps between
//! lateral neighbours are drawn once for the flight (§5 step 1's N(μ_x, σ_x), see
//! [`crate::keyshape::steady`]) and each drifts slowly around its drawn value from key shape to
//! key shape, so the V breathes sideways as well as fore and aft. Wingspans.

use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::keyshape::initial::positions_from_gaps;
use crate::keyshape::steady::SteadyOptions;

/// Options of the lateral drift (the `steady.lateral` section of [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LateralOptions {
    /// Standard deviation of each lateral gap's drift around its drawn value, wingspans, in
    /// [0, 1] (0: lateral positions fixed for the whole flight).
    pub drift: f64,
    /// Correlation of a gap's drift from one key shape to the next, dimensionless, in [0, 1)
    /// (an AR(1) process: larger is slower).
    pub correlation: f64,
}

impl Default for LateralOptions {
    fn default() -> Self {
        LateralOptions {
            drift: 0.03,
            correlation: 0.7,
        }
    }
}

impl LateralOptions {
    /// Checks every option; the error names the option path (`steady.lateral.drift`).
    pub fn validate(&self) -> Result<()> {
        if !(self.drift >= 0.0 && self.drift <= 1.0) {
            return Err(Error::parameter(
                "steady.lateral.drift",
                format!("{}: must be in [0, 1] wingspans", self.drift),
            ));
        }
        if !(self.correlation >= 0.0 && self.correlation < 1.0) {
            return Err(Error::parameter(
                "steady.lateral.correlation",
                format!("{}: must be in [0, 1)", self.correlation),
            ));
        }
        Ok(())
    }
}

/// Lateral positions of every key shape (the first the drawn `x` from `gaps`): each gap drifts
/// around its drawn value as an AR(1) process from key to key (`opts.lateral`), never at or
/// below `opts.initial.min_gap`, no bird moving more than `opts.keys.max_jump` between keys; a
/// loop's drift tapers to 0 at its last key (= the first).
pub fn lateral_plan(
    gaps: &[f64],
    leader: usize,
    keys: usize,
    opts: &SteadyOptions,
    rng: &mut impl Rng,
) -> Vec<Vec<f64>> {
    let rho = opts.lateral.correlation;
    let sd = opts.lateral.drift;
    let min_gap = opts.initial.min_gap;
    let mut dev = vec![0.0; gaps.len()];
    let mut prev = positions_from_gaps(gaps, leader);
    let mut out = vec![prev.clone()];
    for k in 1..keys {
        for d in dev.iter_mut() {
            let z: f64 = StandardNormal.sample(rng);
            *d = rho * *d + (1.0 - rho * rho).sqrt() * sd * z;
        }
        let taper = if opts.looped {
            1.0 - (k as f64 / (keys - 1).max(1) as f64).powi(2)
        } else {
            1.0
        };
        let g: Vec<f64> = gaps
            .iter()
            .zip(&dev)
            .map(|(&g, &d)| (g + taper * d).max((min_gap + 0.02).min(g)))
            .collect();
        let mut xk = positions_from_gaps(&g, leader);
        let jump = crate::keyshape::keys::max_jump(&prev, &xk);
        if jump > opts.keys.max_jump {
            let f = opts.keys.max_jump / jump;
            for (a, b) in xk.iter_mut().zip(&prev) {
                *a = b + f * (*a - b);
            }
        }
        prev = xk.clone();
        out.push(xk);
    }
    out
}
