//! Small per-bird altitude differences, as in real flocks: heights about the
//! leader's at every key shape, wingspans. A stereo-filmed V of white-fronted geese had a
//! height spread of about 0.14 wingspans, lateral neighbours about 0.06 apart.

use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Options of the heights (the `steady.heights` section of [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HeightOptions {
    /// Standard deviation of the birds' heights about the leader's, wingspans, in [0, 10]
    /// (a stereo-filmed V of white-fronted geese: 0.14).
    pub spread: f64,
    /// Root-mean-square height difference of lateral neighbours, wingspans (the same V: 0.06);
    /// at most `spread` · √2.
    pub neighbour: f64,
    /// Correlation of the height field from one key shape to the next, dimensionless, in [0, 1).
    pub correlation: f64,
}

impl Default for HeightOptions {
    fn default() -> Self {
        HeightOptions {
            spread: 0.14,
            neighbour: 0.06,
            correlation: 0.7,
        }
    }
}

impl HeightOptions {
    /// Checks every option; the error names the option path (`steady.heights.spread`).
    pub fn validate(&self) -> Result<()> {
        if !(self.spread >= 0.0 && self.spread <= 10.0) {
            return Err(Error::parameter(
                "steady.heights.spread",
                format!("{}: must be in [0, 10] wingspans", self.spread),
            ));
        }
        let most = self.spread * std::f64::consts::SQRT_2;
        if !(self.neighbour >= 0.0 && self.neighbour <= most + 1e-12) {
            return Err(Error::parameter(
                "steady.heights.neighbour",
                format!(
                    "{}: must be in [0, √2 · steady.heights.spread = {most:.3}] wingspans",
                    self.neighbour
                ),
            ));
        }
        if !(self.correlation >= 0.0 && self.correlation < 1.0) {
            return Err(Error::parameter(
                "steady.heights.correlation",
                format!("{}: must be in [0, 1)", self.correlation),
            ));
        }
        Ok(())
    }
}

/// Heights of every bird at every key shape, wingspans, the leader at 0: a random walk along
/// the lateral order (step `neighbour`) plus a tilt across the flock that brings the expected
/// spread to `spread` (one arm a little higher than the other, as in the footage), both
/// evolving from key to key as AR(1) processes (`correlation`). A loop's last key repeats the
/// first. Drawn from `rng` (the flight's `steady.height` stream, see
/// [`crate::keyshape::steady_flight_in`]).
pub fn heights(
    n: usize,
    x: &[f64],
    leader: usize,
    keys: usize,
    h: &HeightOptions,
    looped: bool,
    rng: &mut crate::rng::FlockRng,
) -> Vec<Vec<f64>> {
    let rho = h.correlation;
    let nf = n as f64;
    let walk_var = h.neighbour.powi(2) * (nf * nf - 1.0) / (6.0 * nf);
    let mean_x = x.iter().sum::<f64>() / nf;
    let var_x = x.iter().map(|v| (v - mean_x).powi(2)).sum::<f64>() / nf;
    let tilt_sd = if var_x > 1e-12 {
        ((h.spread.powi(2) - walk_var).max(0.0) / var_x).sqrt()
    } else {
        0.0
    };
    let draw = |rng: &mut crate::rng::FlockRng| -> Vec<f64> {
        let tilt: f64 = StandardNormal.sample(rng);
        let mut out = Vec::with_capacity(n);
        let mut walk = 0.0;
        for &xi in x {
            let z: f64 = StandardNormal.sample(rng);
            walk += h.neighbour * z;
            out.push(walk + tilt_sd * tilt * (xi - mean_x));
        }
        out
    };
    let mut field = draw(rng);
    let mut out = Vec::with_capacity(keys);
    for k in 0..keys {
        if k > 0 {
            let fresh = draw(rng);
            for (f, g) in field.iter_mut().zip(fresh) {
                *f = rho * *f + (1.0 - rho * rho).sqrt() * g;
            }
        }
        let lead = field[leader];
        out.push(field.iter().map(|v| v - lead).collect::<Vec<f64>>());
    }
    if looped && keys > 1 {
        out[keys - 1] = out[0].clone();
    }
    out
}

/// The height options of a steady flight from `params`: the heights measured in 3-D tracks
/// (the params' `heights`: spread and neighbour difference, the neighbour capped at
/// √2 · spread as [`HeightOptions::validate`] requires) when the config leaves
/// `steady.heights` at its defaults, else `opts`. The key-to-key correlation is not measured
/// (a few seconds of tracks do not show it) and stays `opts.correlation`.
pub fn heights_for(
    params: &crate::extract::params::FormationParams,
    opts: &HeightOptions,
) -> HeightOptions {
    match &params.heights {
        Some(m) if *opts == HeightOptions::default() => {
            let spread = m.spread.clamp(0.0, 10.0);
            HeightOptions {
                spread,
                neighbour: m.neighbour.clamp(0.0, spread * std::f64::consts::SQRT_2),
                correlation: opts.correlation,
            }
        }
        _ => opts.clone(),
    }
}
