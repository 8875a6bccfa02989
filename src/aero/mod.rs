//! §5 step 2: Hummel's power-reduction model (issue 2; being written — signatures are final).

use crate::error::Result;

/// Vortex span of an elliptically loaded wing, a = π/4 wingspans.
pub const VORTEX_SPAN: f64 = std::f64::consts::FRAC_PI_4;

/// e_i, ξ_i and E of a shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerReduction {
    /// e_i per bird (input order).
    pub e: Vec<f64>,
    /// ξ_i = e_i / E.
    pub xi: Vec<f64>,
    /// E = Σ e_i.
    pub total: f64,
}

/// Hummel's g(x, y) for lateral distance `x` (> a) and longitudinal distance `y` of the bird
/// behind the other, wingspans.
pub fn g(x: f64, y: f64) -> f64 {
    let _ = (x, y);
    unimplemented!("issue 2")
}

/// e_i, ξ_i, E for birds at lateral `x` and longitudinal `y` (behind the leader) positions.
/// Fails with `Error::Downwash` naming the birds when a pair is within π/4 laterally.
pub fn power_reduction(x: &[f64], y: &[f64]) -> Result<PowerReduction> {
    let _ = (x, y);
    unimplemented!("issue 2")
}

/// E from the lateral positions only (Munk's stagger theorem): Σ over pairs of 2·g(|Δx|, 0).
pub fn munk_total(x: &[f64]) -> Result<f64> {
    let _ = x;
    unimplemented!("issue 2")
}
