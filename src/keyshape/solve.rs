//! The key-shape solve of eq. (4) (issue 2; being written — signatures are final).

use crate::error::Result;

/// Options of [`solve`].
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Converged means ‖ξ − ξ̂‖₂ ≤ this.
    pub tolerance: f64,
    /// Budget of model evaluations.
    pub max_evaluations: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tolerance: 1e-9,
            max_evaluations: 2000,
        }
    }
}

/// Outcome of a solve: never an error for non-convergence; read `converged`.
#[derive(Debug, Clone)]
pub struct SolveReport {
    /// Longitudinal positions, leader (front-most) at 0, wingspans.
    pub y: Vec<f64>,
    /// ξ achieved.
    pub xi: Vec<f64>,
    /// ‖ξ − ξ̂‖₂ with ξ̂ renormalised.
    pub residual: f64,
    /// Model evaluations used.
    pub evaluations: usize,
    /// `residual <= tolerance`.
    pub converged: bool,
}

/// Solves eq. (4): y such that ξ(x, y) = ξ̂ (renormalised), starting from `y0` if given.
/// Errors: downwash pairs in `x`, bad targets, unreachable targets (naming the birds).
pub fn solve(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    opts: &SolveOptions,
) -> Result<SolveReport> {
    let _ = (x, xi_target, y0, opts);
    unimplemented!("issue 2")
}
