//! §5 step 2: e_i and ξ_i of every bird in every initial shape, and each bird's range
//! [p_i, P_i] of ξ over the shapes. Takes shapes in the formation frame (wingspans); gives
//! dimensionless relative power reductions.
//!
//! The values are computed at the key shapes' lateral positions `x_key` (with each initial shape's
//! own `y`): key shapes keep `x` fixed and only move birds fore and aft, so only the spread of ξ
//! that comes from the longitudinal placement can be reproduced. Ranges taken at the initial
//! shapes' own, noisy lateral gaps would be dominated by lateral noise and mostly unreachable.

use serde::{Deserialize, Serialize};

use crate::aero::{AeroOptions, PowerReduction};
use crate::error::{Error, Result};
use crate::shape::Shape;

/// Per-bird range of ξ over the initial shapes, [p_i, P_i].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct XiRanges {
    /// p_i, the smallest ξ_i.
    pub min: Vec<f64>,
    /// P_i, the largest ξ_i.
    pub max: Vec<f64>,
}

impl XiRanges {
    /// The feasible range of eq. (2), [(1 − ε) p_i, (1 + ε) P_i], widened outward for negative
    /// values too (a bird in downwash has ξ < 0): [p_i − ε|p_i|, P_i + ε|P_i|].
    pub fn widened(&self, epsilon: f64) -> XiRanges {
        XiRanges {
            min: self.min.iter().map(|p| p - epsilon * p.abs()).collect(),
            max: self.max.iter().map(|p| p + epsilon * p.abs()).collect(),
        }
    }

    /// Number of birds.
    pub fn len(&self) -> usize {
        self.min.len()
    }

    /// True for zero birds.
    pub fn is_empty(&self) -> bool {
        self.min.is_empty()
    }

    /// The ranges extended, bird by bird, to contain `xi`.
    pub fn including(&self, xi: &[f64]) -> XiRanges {
        XiRanges {
            min: self.min.iter().zip(xi).map(|(a, v)| a.min(*v)).collect(),
            max: self.max.iter().zip(xi).map(|(a, v)| a.max(*v)).collect(),
        }
    }

    /// The union of two ranges, bird by bird (the smallest range containing both).
    pub fn union(&self, other: &XiRanges) -> XiRanges {
        XiRanges {
            min: self
                .min
                .iter()
                .zip(&other.min)
                .map(|(a, b)| a.min(*b))
                .collect(),
            max: self
                .max
                .iter()
                .zip(&other.max)
                .map(|(a, b)| a.max(*b))
                .collect(),
        }
    }

    /// Clips `xi` into the ranges, bird by bird.
    pub fn clip(&self, xi: &mut [f64]) {
        for ((v, lo), hi) in xi.iter_mut().zip(&self.min).zip(&self.max) {
            *v = v.clamp(*lo, hi.max(*lo));
        }
    }

    /// Largest amount by which `xi` leaves the ranges (0 when inside).
    pub fn excess(&self, xi: &[f64]) -> f64 {
        xi.iter()
            .zip(&self.min)
            .zip(&self.max)
            .map(|((v, lo), hi)| (lo - v).max(v - hi).max(0.0))
            .fold(0.0, f64::max)
    }
}

/// e_i, ξ_i of every initial shape's longitudinal positions at the lateral positions `x_key`,
/// leaving out the shapes in which two birds' wings would collide there (their ξ is not a
/// placement the key shapes can take). Fails when every shape collides.
pub fn power_at(
    x_key: &[f64],
    shapes: &[Shape],
    aero: &AeroOptions,
) -> Result<Vec<PowerReduction>> {
    let mut out = Vec::with_capacity(shapes.len());
    let mut last = None;
    for s in shapes {
        if s.len() != x_key.len() {
            return Err(Error::Internal(format!(
                "initial shape of {} birds for {} lateral positions",
                s.len(),
                x_key.len()
            )));
        }
        match aero.power_reduction(x_key, &s.ys()) {
            Ok(p) => out.push(p),
            Err(e @ Error::Collision { .. }) => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    if out.is_empty() {
        return Err(Error::parameter(
            "params",
            format!(
                "every frame's shape collides at the drawn lateral gaps ({}); try another seed",
                last.map(|e| e.to_string()).unwrap_or_default()
            ),
        ));
    }
    Ok(out)
}

/// [p_i, P_i] over the ξ vectors of step 2.
pub fn xi_ranges(values: &[PowerReduction]) -> Result<XiRanges> {
    let first = values
        .first()
        .ok_or_else(|| Error::Internal("no initial shapes".into()))?;
    let mut r = XiRanges {
        min: first.xi.clone(),
        max: first.xi.clone(),
    };
    for v in &values[1..] {
        for (i, &x) in v.xi.iter().enumerate() {
            if let (Some(lo), Some(hi)) = (r.min.get_mut(i), r.max.get_mut(i)) {
                *lo = lo.min(x);
                *hi = hi.max(x);
            }
        }
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pr(xi: Vec<f64>) -> PowerReduction {
        PowerReduction {
            e: xi.clone(),
            total: xi.iter().sum(),
            xi,
        }
    }

    #[test]
    fn ranges_are_min_and_max_and_widen() {
        let r = xi_ranges(&[pr(vec![0.2, 0.8]), pr(vec![0.4, 0.6])]).unwrap();
        assert_eq!(r.min, vec![0.2, 0.6]);
        assert_eq!(r.max, vec![0.4, 0.8]);
        let w = r.widened(0.1);
        assert!((w.min[0] - 0.18).abs() < 1e-15 && (w.max[1] - 0.88).abs() < 1e-15);
        let mut v = vec![0.1, 0.9];
        w.clip(&mut v);
        assert!((v[0] - 0.18).abs() < 1e-15 && (v[1] - 0.88).abs() < 1e-15);
        assert_eq!(w.excess(&v), 0.0);
        assert!((w.excess(&[0.1, 0.5]) - 0.08).abs() < 1e-12);
    }
}
