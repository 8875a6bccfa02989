//! A formation given by the birds already flying it: a start file whose birds fly a formation
//! that late birds join (`initiate::Joining`). The key shapes are solved with its arms: the
//! birds left of the leader fixed, and the lateral gaps of the birds already in formation near
//! the observed ones (docs/initiation.md, "Joining").

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The arms a start file fixes for the key shapes.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GivenArms {
    /// Birds left of the leader (the key shapes' leader index).
    pub left: usize,
    /// Lateral gap between each pair of key-shape neighbours (left to right), wingspans:
    /// observed where both birds already fly in the formation, `None` where it is drawn.
    pub gaps: Vec<Option<f64>>,
}

/// A kept gap stays within this factor of the footage's mean gap, either way: the observed
/// formation's spacing is kept where it is within the range real V's span (neighbours from
/// wingtips overlapping to half a span apart), and a straggler's wider gap closes to it (the
/// paper is silent; docs/initiation.md).
pub const KEPT_GAP_FACTOR: f64 = 1.5;

impl GivenArms {
    /// Checks the arms against a formation of `n` birds.
    pub fn validate(&self, n: usize) -> Result<()> {
        if self.left >= n || self.gaps.len() + 1 != n {
            return Err(Error::parameter(
                "steady.birds",
                format!(
                    "{n} birds, but the start file's formation has {} (its leader with {} birds on its left)",
                    self.gaps.len() + 1,
                    self.left
                ),
            ));
        }
        Ok(())
    }

    /// Replaces the drawn `gaps` by the observed ones, each kept within [`KEPT_GAP_FACTOR`] of
    /// the footage's mean gap `mean` and above `min_gap`.
    pub fn fix_gaps(&self, gaps: &mut [f64], mean: f64, min_gap: f64) {
        let lo = (mean / KEPT_GAP_FACTOR).max(min_gap);
        let hi = (mean * KEPT_GAP_FACTOR).max(lo);
        for (g, kept) in gaps.iter_mut().zip(&self.gaps) {
            if let Some(k) = kept {
                *g = k.clamp(lo, hi);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn observed_gaps_are_kept_within_the_footage_s_range() {
        let given = GivenArms {
            left: 1,
            gaps: vec![Some(0.96), Some(0.47), Some(0.42), Some(2.71), None, None],
        };
        let mut gaps = vec![0.8; 6];
        given.fix_gaps(&mut gaps, 0.8, 0.1);
        let want = [0.96, 0.8 / 1.5, 0.8 / 1.5, 1.2, 0.8, 0.8];
        for (g, w) in gaps.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{gaps:?}");
        }
        assert!(given.validate(7).is_ok());
        assert!(given.validate(8).is_err());
    }
}
