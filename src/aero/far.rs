//! Far-field expansions of Hummel's pair function shared by the exact sums ([`super::Field`])
//! and the tree approximation (`tree`), and when the sums run on several threads. Kept apart
//! so that both depend on this module and neither on the other.

use super::A;

/// a², the vortex span squared.
pub(super) const A2: f64 = A * A;
/// a⁴/12.
pub(super) const A4_12: f64 = A * A * A * A / 12.0;

/// The far pair's stagger-dependent share (`field::far_odd`) without its term sign(y)·H₀ (H₀ = u³(1/3 + u/4) < 1.7·10⁻¹² for X ≥
/// [`super::FAR_FIELD`], a remainder of the expansion's truncation): smooth in y, for interpolation.
#[inline(always)]
pub(super) fn far_odd_smooth(x2: f64, y: f64) -> f64 {
    far_parts(x2, y).1
}

/// (H₀, y·Q(X, r)) of a far pair, `x2` = X².
#[inline(always)]
pub(super) fn far_parts(x2: f64, y: f64) -> (f64, f64) {
    let r = (x2 + y * y).sqrt();
    let d = 1.0 / (r * x2);
    let inv_r = x2 * d;
    let inv_x2 = r * d;
    let inv_r2 = inv_r * inv_r;
    let u = A2 * inv_x2;
    let h0 = u * u * u * (1.0 / 3.0 + 0.25 * u);
    let q = inv_r
        * (A2 * inv_x2
            + A4_12 * (6.0 * inv_x2 * inv_x2 + 3.0 * inv_x2 * inv_r2 + 3.0 * inv_r2 * inv_r2));
    (h0, y * q)
}

/// ∂g/∂y of a far pair in units of 2/π² (as [`super::far_pair`]'s slope). `x2` = X².
#[inline(always)]
pub(super) fn far_slope(x2: f64, y: f64) -> f64 {
    let r2 = x2 + y * y;
    let inv_r = 1.0 / r2.sqrt();
    let inv_r2 = inv_r * inv_r;
    let inv_r3 = inv_r2 * inv_r;
    let inv_r5 = inv_r3 * inv_r2;
    A2 * inv_r3 + A4_12 * (15.0 * x2 * inv_r5 * inv_r2 - 3.0 * inv_r5)
}

/// Flocks of at least this many birds have their exact sums (`Field::power`, the far part of
/// `Field::new`) split into fixed chunks that run on several threads.
pub const PARALLEL_MIN: usize = 2000;

/// Whether the machine has more than one core.
pub(super) fn parallel() -> bool {
    std::thread::available_parallelism().is_ok_and(|v| v.get() > 1)
}
