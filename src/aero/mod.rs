//! §5 step 2: Hummel's power-reduction model, as printed in Klotsman & Tal (after Hummel 1983).
//!
//! Takes lateral and longitudinal distances between birds in wingspans (SPEC §2–3) and gives the
//! pair function g(x, y), its partial derivatives, each bird's power reduction e_i, the total E and
//! the relative values ξ_i = e_i / E. Pure functions; the drag ratio C of eq. (1) is dropped.
//!
//! The printed formula is, with a = π/4 (the vortex span of an elliptically loaded wing),
//! r₀ = √(x² + y²) and r± = √((x ± a)² + y²):
//!
//! ```math
//! \tfrac{\pi^2}{2} g(x,y) = \ln\frac{x^2}{(x-a)(x+a)}
//!   + 2\ln\frac{x-y+r_0}{x+y+r_0}
//!   - \ln\frac{x-a-y+r_-}{x-a+y+r_-}
//!   - \ln\frac{x+a-y+r_+}{x+a+y+r_+}
//!   + \frac{1}{y}\left[2r_0 - r_+ - r_-\right]
//! ```
//!
//! Evaluated literally it loses every digit for |y| ≫ 1 (the log ratios and the bracket are
//! differences of nearly equal numbers) and divides 0 by 0 at y = 0. [`g`] uses the stable form
//! derived in `docs/model.md`:
//!
//! ```math
//! \tfrac{\pi^2}{2} g(x,y) = \begin{cases} D(|y|) & y \le 0 \\ 2A - D(|y|) & y > 0 \end{cases},
//! \quad A = -\operatorname{ln1p}(-a^2/x^2),
//! \quad D(Y) = -\operatorname{ln1p}\frac{\delta_-}{Y+r_0} - \operatorname{ln1p}\frac{\delta_+}{Y+r_0} + \frac{\Sigma}{Y}
//! ```
//!
//! where δ± = r± − r₀ = ±a(2x ± a)/(r± + r₀) and Σ = δ₊ + δ₋ (for Y < x computed as
//! Y²[1/(r₊+x+a) + 1/(r₋+x−a) − 2/(r₀+x)]). D(Y) = (π²/2)·g(x, −Y) is the savings of the bird
//! in front, which decays like a²/(2Y²); writing g through it makes Munk's stagger theorem
//! g(x, y) + g(x, −y) = 2g(x, 0) hold to rounding, and keeps ~1e-13 relative accuracy everywhere
//! (tested against 50-digit references in `tests/aero.rs`). The derivative has a closed form:
//! (π²/2)·∂g/∂y = Σ / y², even in y and positive.
//!
//! Symbols → code: x → `x` (lateral distance, > a), y → `y` (how far the affected bird is behind
//! the other), a → [`VORTEX_SPAN`], e_i → [`PowerReduction::e`], ξ_i → [`PowerReduction::xi`],
//! E → [`PowerReduction::total`].

use crate::error::{Error, Result};

/// Vortex span of an elliptically loaded wing, a = π/4 wingspans. Lateral distances at or below
/// it are inside the other bird's downwash, where the model is undefined.
pub const VORTEX_SPAN: f64 = std::f64::consts::FRAC_PI_4;

const A: f64 = VORTEX_SPAN;
/// 2/π², the factor between the bracket of the printed formula and g.
const TWO_OVER_PI2: f64 = 2.0 / (std::f64::consts::PI * std::f64::consts::PI);

/// e_i, ξ_i and E of a shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerReduction {
    /// Power reduction e_i of each bird (eq. 1 without C), input order.
    pub e: Vec<f64>,
    /// Relative power reduction ξ_i = e_i / E.
    pub xi: Vec<f64>,
    /// Total power reduction E = Σ e_i.
    pub total: f64,
}

/// The pieces shared by g and ∂g/∂y for one pair: A and D(|y|), both in units of 2/π².
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// A = ln(x²/(x² − a²)): (π²/2)·g(x, 0).
    a_term: f64,
    /// D(|y|) = (π²/2)·g(x, −|y|).
    d_term: f64,
    /// Σ/Y² = (π²/2)·∂g/∂y.
    slope: f64,
}

#[inline]
fn pair(x: f64, y: f64) -> Pair {
    let yy = y.abs();
    let y2 = yy * yy;
    let r0 = (x * x + y2).sqrt();
    let xp = x + A;
    let xm = x - A;
    let rp = (xp * xp + y2).sqrt();
    let rm = (xm * xm + y2).sqrt();
    // δ± = r± − r₀ without cancellation.
    let dp = A * (2.0 * x + A) / (rp + r0);
    let dm = -A * (2.0 * x - A) / (rm + r0);
    // Σ = r₊ + r₋ − 2r₀ ≥ 0 (convexity of r in x): for small Y as Y²·bracket (each r − c is
    // Y²/(r + c)), for large Y as δ₊ + δ₋.
    let sigma_over_y2 = if yy < x {
        1.0 / (rp + xp) + 1.0 / (rm + xm) - 2.0 / (r0 + x)
    } else {
        (dp + dm) / y2
    };
    let sigma = sigma_over_y2 * y2;
    let q = yy + r0;
    // −ln1p(δ₋/q) − ln1p(δ₊/q) as one logarithm: −ln1p((δ₊ + δ₋)/q + δ₊δ₋/q²), with δ₊ + δ₋ = Σ
    // taken from its cancellation-free form.
    let d_term = -(sigma / q + dp * dm / (q * q)).ln_1p() + sigma_over_y2 * yy;
    let a_term = -(-(A / x) * (A / x)).ln_1p();
    Pair {
        a_term,
        d_term,
        slope: sigma_over_y2,
    }
}

/// Hummel's g(x, y): the power reduction that a bird gains from one other bird at lateral
/// distance `x` (wingspans, must exceed a = π/4) when it flies `y` wingspans behind it
/// (negative: ahead). Returns NaN for x ≤ a; use [`try_g`] for a checked version.
///
/// Limits: g → 0 as y → −∞, g(x, 0) = (2/π²)·ln(x²/(x² − a²)), g → 2g(x, 0) as y → +∞.
#[inline]
pub fn g(x: f64, y: f64) -> f64 {
    if !(x > A) {
        return f64::NAN;
    }
    let p = pair(x, y);
    let scaled = if y > 0.0 {
        2.0 * p.a_term - p.d_term
    } else {
        p.d_term
    };
    TWO_OVER_PI2 * scaled
}

/// [`g`] with the downwash reported as an error (birds named 0 and 1).
pub fn try_g(x: f64, y: f64) -> Result<f64> {
    if !(x > A) || !y.is_finite() {
        return Err(Error::Downwash { i: 0, j: 1, dx: x });
    }
    Ok(g(x, y))
}

/// g(x, 0) = (2/π²)·ln(x²/(x² − a²)), half of what the pair (i, j) saves together; by Munk's
/// theorem the pair's total 2·g(x, 0) does not depend on the stagger.
#[inline]
pub fn g0(x: f64) -> f64 {
    if !(x > A) {
        return f64::NAN;
    }
    TWO_OVER_PI2 * -(-(A / x) * (A / x)).ln_1p()
}

/// ∂g/∂y = (2/π²)·(r₊ + r₋ − 2r₀)/y²: positive and even in y (so that g(x,y) + g(x,−y) is
/// constant), (2/π²)·a²/(x(x² − a²)) at y = 0.
#[inline]
pub fn dg_dy(x: f64, y: f64) -> f64 {
    if !(x > A) {
        return f64::NAN;
    }
    TWO_OVER_PI2 * pair(x, y).slope
}

/// ∂g/∂x from the printed formula:
///
/// ```math
/// \tfrac{\pi^2}{2}\,\partial_x g = -\frac{2a^2}{x(x^2-a^2)}
///   + y\left[\frac{2}{x(r_0+x)} - \frac{1}{(x-a)(r_-+x-a)} - \frac{1}{(x+a)(r_++x+a)}\right]
/// ```
///
/// (from (1/y)[2r₀/x − r₋/(x−a) − r₊/(x+a)] with r/c = 1 + y²/(c(r + c))). Accurate to ~1e-12
/// absolute relative to the size of g₀'(x); its relative accuracy degrades where it tends to 0
/// (y → −∞). Only g and ∂g/∂y enter the key-shape solve.
pub fn dg_dx(x: f64, y: f64) -> f64 {
    if !(x > A) {
        return f64::NAN;
    }
    let y2 = y * y;
    let r0 = (x * x + y2).sqrt();
    let rp = ((x + A) * (x + A) + y2).sqrt();
    let rm = ((x - A) * (x - A) + y2).sqrt();
    let da = -2.0 * A * A / (x * (x * x - A * A));
    let bracket =
        2.0 / (x * (r0 + x)) - 1.0 / ((x - A) * (rm + x - A)) - 1.0 / ((x + A) * (rp + x + A));
    TWO_OVER_PI2 * (da + y * bracket)
}

/// Checks that no two birds are within the downwash (lateral distance ≤ π/4) and that every
/// coordinate is finite. Runs in O(N log N).
pub fn check_lateral(x: &[f64]) -> Result<()> {
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(Error::parameter(
            format!("x[{i}]"),
            "lateral position is not a finite number",
        ));
    }
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    for w in idx.windows(2) {
        let dx = x[w[1]] - x[w[0]];
        if !(dx > A) {
            let (i, j) = (w[0].min(w[1]), w[0].max(w[1]));
            return Err(Error::Downwash { i, j, dx });
        }
    }
    Ok(())
}

/// e_i, ξ_i and E for birds at lateral positions `x` and longitudinal positions `y` (distance
/// behind the leader), wingspans, in input order. Fails with [`Error::Downwash`] naming the two
/// birds when a pair is within π/4 laterally, and with [`Error::Parameter`] for non-finite or
/// mismatched input. One evaluation per pair serves both birds (Munk: the bird in front gets
/// D, the one behind 2A − D).
pub fn power_reduction(x: &[f64], y: &[f64]) -> Result<PowerReduction> {
    if x.len() != y.len() {
        return Err(Error::parameter(
            "y",
            format!("{} longitudinal positions for {} birds", y.len(), x.len()),
        ));
    }
    if x.len() < 2 {
        return Err(Error::parameter(
            "birds",
            format!("{} bird(s) given, at least 2 needed", x.len()),
        ));
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(Error::parameter(
            format!("y[{i}]"),
            "longitudinal position is not a finite number",
        ));
    }
    check_lateral(x)?;
    let e = power_unchecked(x, y);
    let total: f64 = e.iter().sum();
    let xi = e.iter().map(|v| v / total).collect();
    Ok(PowerReduction { e, xi, total })
}

/// e_i without validation (the caller guarantees N ≥ 2, finite values, no downwash pair).
pub fn power_unchecked(x: &[f64], y: &[f64]) -> Vec<f64> {
    let mut e = vec![0.0; x.len()];
    accumulate(x, y, &mut e, None);
    e
}

/// e_i and the Jacobian ∂e_i/∂y_k (row-major N×N, see [`power_jacobian_unchecked`]) in one pass
/// over the pairs, which share their square roots. No validation.
pub fn power_and_jacobian_unchecked(x: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let mut e = vec![0.0; n];
    let mut jac = vec![0.0; n * n];
    accumulate(x, y, &mut e, Some(&mut jac));
    (e, jac)
}

fn accumulate(x: &[f64], y: &[f64], e: &mut [f64], mut jac: Option<&mut [f64]>) {
    let n = x.len();
    for i in 0..n {
        for j in (i + 1)..n {
            let dx = (x[i] - x[j]).abs();
            // Distance of i behind j.
            let dy = y[i] - y[j];
            let p = pair(dx, dy);
            let (front, back) = (p.d_term, 2.0 * p.a_term - p.d_term);
            if dy > 0.0 {
                e[i] += back;
                e[j] += front;
            } else {
                e[i] += front;
                e[j] += back;
            }
            if let Some(jac) = jac.as_deref_mut() {
                scatter_slope(jac, n, i, j, TWO_OVER_PI2 * p.slope);
            }
        }
    }
    for v in e.iter_mut() {
        *v *= TWO_OVER_PI2;
    }
}

/// E from the lateral positions only (Munk's stagger theorem): Σ over pairs of 2·g(|Δx|, 0).
/// Fails like [`power_reduction`] on downwash or non-finite input.
pub fn munk_total(x: &[f64]) -> Result<f64> {
    check_lateral(x)?;
    Ok(munk_total_unchecked(x))
}

/// [`munk_total`] without validation.
pub fn munk_total_unchecked(x: &[f64]) -> f64 {
    let n = x.len();
    let mut total = 0.0;
    for i in 0..n {
        for j in (i + 1)..n {
            total += 2.0 * g0((x[i] - x[j]).abs());
        }
    }
    total
}

/// The Jacobian of e with respect to y, row-major N×N: ∂e_i/∂y_k. Diagonal entries are
/// Σ_{j≠i} ∂g/∂y(x_ij, y_i − y_j), off-diagonal ones −∂g/∂y(x_ik, y_i − y_k). The matrix is
/// symmetric (∂g/∂y is even in y): e is the gradient of a convex potential, which is why the
/// key-shape system has a unique solution up to a shift when it has one at all.
pub fn power_jacobian_unchecked(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut jac = vec![0.0; n * n];
    for i in 0..n {
        for k in (i + 1)..n {
            scatter_slope(&mut jac, n, i, k, dg_dy((x[i] - x[k]).abs(), y[i] - y[k]));
        }
    }
    jac
}

/// Adds pair (i, j)'s ∂g/∂y = `s` to the row-major N×N Jacobian of e: +s on both diagonal
/// entries, −s on the two off-diagonal ones (a weighted graph Laplacian).
#[inline]
fn scatter_slope(jac: &mut [f64], n: usize, i: usize, j: usize, s: f64) {
    jac[i * n + j] = -s;
    jac[j * n + i] = -s;
    jac[i * n + i] += s;
    jac[j * n + j] += s;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The formula exactly as printed, evaluated literally (only valid for moderate y ≠ 0).
    fn g_printed(x: f64, y: f64) -> f64 {
        let r0 = (x * x + y * y).sqrt();
        let rm = ((x - A) * (x - A) + y * y).sqrt();
        let rp = ((x + A) * (x + A) + y * y).sqrt();
        let t = (x * x / ((x - A) * (x + A))).ln() + 2.0 * ((x - y + r0) / (x + y + r0)).ln()
            - ((x - A - y + rm) / (x - A + y + rm)).ln()
            - ((x + A - y + rp) / (x + A + y + rp)).ln()
            + (2.0 * r0 - rp - rm) / y;
        TWO_OVER_PI2 * t
    }

    #[test]
    fn matches_printed_formula_where_it_is_well_conditioned() {
        for &x in &[0.8, 0.9, 1.0, 1.3, 2.0, 5.0] {
            for &y in &[-5.0, -2.0, -0.7, -0.1, 0.05, 0.3, 1.0, 3.0, 8.0] {
                let a = g(x, y);
                let b = g_printed(x, y);
                assert!(
                    ((a - b) / b).abs() < 1e-11,
                    "x={x} y={y}: stable {a} printed {b}"
                );
            }
        }
    }

    #[test]
    fn munk_symmetry_and_limits() {
        for &x in &[0.786, 0.9, 1.2, 3.0, 40.0] {
            let g0 = g0(x);
            assert!(((g(x, 0.0) - g0) / g0).abs() < 1e-14);
            for &y in &[1e-9, 0.3, 2.0, 1e3, 1e6] {
                let s = g(x, y) + g(x, -y);
                assert!(((s - 2.0 * g0) / g0).abs() < 1e-13, "x={x} y={y}");
            }
            assert!(g(x, -1e9) / g0 < 1e-15);
            assert!(((g(x, 1e9) - 2.0 * g0) / g0).abs() < 1e-14);
        }
    }

    #[test]
    fn downwash_is_nan_or_error() {
        assert!(g(A, 1.0).is_nan());
        assert!(g(0.5, 1.0).is_nan());
        assert!(try_g(0.7, 0.0).is_err());
        let err = power_reduction(&[0.0, 0.5, 2.0], &[0.0, 1.0, 2.0]).unwrap_err();
        assert!(matches!(err, Error::Downwash { i: 0, j: 1, .. }), "{err}");
    }
}
