//! The wingbeat parameterisation of Wu & Popović (SIGGRAPH 2003, §4.1–4.3): the composite
//! functions g1 and g2, the phase transformation h with downstroke fractions u_α and u_β, the
//! stroke-midpoint alignment of the g2 DOFs, and the C1 blending weight used between wingbeats.
//!
//! Everything here is a pure function of a phase (radians, 0 = start of the downstroke, 2π = end of
//! the upstroke) and of stroke parameters given directly as joint angles (radians) or, for the
//! wing spread, as a fraction (0 = folded, 1 = fully extended). The paper writes
//! q* = q_min + (q_max − q_min)·g(u^d, u^u, φ) with normalised u ∈ [0, 1]; since g is affine in
//! (u^d, u^u) we fold the joint-limit map into the parameters and store angles.

use std::f64::consts::{PI, TAU};

use super::WingPose;

/// Composite function g1 (Wu & Popović §4.1), used for the arm dihedral, the hand dihedral and the
/// tail bend: a cosine that starts at the upstroke value and reaches the downstroke value at
/// φ = π.
///
/// ```math
/// g_1(u^d, u^u, \varphi) = (u^u - u^d)\,\frac{1 + \cos\varphi}{2} + u^d
/// ```
/// Symbols: `down` = u^d, `up` = u^u, `phi` = φ (radians, already transformed by h).
pub fn g1(down: f64, up: f64, phi: f64) -> f64 {
    (up - down) * g1_basis(phi) + down
}

/// The shape factor (1 + cos φ)/2 of [`g1`]: 1 at the top of the stroke, 0 at the bottom.
#[inline]
pub fn g1_basis(phi: f64) -> f64 {
    0.5 * (1.0 + phi.cos())
}

/// Reduces an angle into [0, 2π), cheaply when it already is or is one period off.
#[inline]
fn wrap(phi: f64) -> f64 {
    if (0.0..TAU).contains(&phi) {
        phi
    } else if (-TAU..0.0).contains(&phi) && phi + TAU < TAU {
        phi + TAU
    } else {
        phi.rem_euclid(TAU)
    }
}

/// Composite function g2 (Wu & Popović §4.1), used for the arm sweep, arm and hand (forearm)
/// twist and the wing spread: held at the downstroke value for the whole downstroke, then a
/// raised cosine that reaches the upstroke value at mid-upstroke and returns by its end.
///
/// ```math
/// g_2(u^d, u^u, \varphi) = \begin{cases} u^d & 0 \le \varphi < \pi \\
///   (u^u - u^d)\,\frac{1 - \cos 2\varphi}{2} + u^d & \pi \le \varphi < 2\pi \end{cases}
/// ```
/// `phi` is reduced modulo 2π first. The function is C1: value and slope are continuous at π and 2π.
pub fn g2(down: f64, up: f64, phi: f64) -> f64 {
    (up - down) * g2_basis(phi) + down
}

/// The shape factor of [`g2`]: 0 on the downstroke, 1 at mid-upstroke.
#[inline]
pub fn g2_basis(phi: f64) -> f64 {
    let p = wrap(phi);
    if p < PI {
        0.0
    } else {
        0.5 * (1.0 - (2.0 * p).cos())
    }
}

/// The phase transformation h of Wu & Popović §4.2 for a downstroke fraction `u` (u_α or u_β).
///
/// The paper only states the conditions h(0) = 0, h(2uπ) = π, h(2π) = 2π, h'(0) = h'(2π) = 1.
/// We use the piecewise cubic Hermite interpolant through the knots (0, 0), (2uπ, π), (2π, 2π),
/// all with slope 1:
///
/// ```math
/// h(\varphi) = y_0 + (y_1 - y_0)(3t^2 - 2t^3) + L\,(2t^3 - 3t^2 + t),\quad
/// t = \frac{\varphi - x_0}{L},\; L = x_1 - x_0
/// ```
/// on each of the two pieces [x_0, x_1] = [0, 2uπ] (y: 0 → π) and [2uπ, 2π] (y: π → 2π).
/// Its slope is h' = 1 + 6t(1 − t)(S − 1) with S = (y_1 − y_0)/L the piece's secant, whose minimum
/// over t is (3S − 1)/2 when S < 1. The secants are 1/(2u) and 1/(2(1 − u)), both above 1/3 for
/// every u ∈ (0, 1), so h is strictly increasing for every admissible u. Equal end slopes make each
/// piece point-symmetric about its midpoint, so h(uπ) = π/2 and h((1 + u)π) = 3π/2: the stroke
/// midpoints sit where a piecewise-linear h would put them, which lets one phase offset align the
/// g2 DOFs with the g1 DOFs (see [`Timing::g2_offset`]). Slope 1 at the middle knot (h' = 1 at
/// the stroke reversal) keeps the turn-around of the wing as in the symmetric wingbeat and moves
/// the asymmetry into mid-stroke, where it is least visible as a jerk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseMap {
    /// Downstroke fraction u ∈ (0, 1) of the wingbeat period.
    u: f64,
}

impl PhaseMap {
    /// h for downstroke fraction `u`, clamped into [0.05, 0.95] (outside that range the wingbeat is
    /// no longer a wingbeat).
    pub fn new(u: f64) -> PhaseMap {
        let u = if u.is_finite() {
            u.clamp(0.05, 0.95)
        } else {
            0.5
        };
        PhaseMap { u }
    }

    /// The downstroke fraction u.
    pub fn fraction(&self) -> f64 {
        self.u
    }

    /// Knot and piece of φ ∈ [0, 2π): (x0, y0, L, ΔY).
    #[inline]
    fn piece(&self, phi: f64) -> (f64, f64, f64, f64) {
        let knot = TAU * self.u;
        if phi < knot {
            (0.0, 0.0, knot, PI)
        } else {
            (knot, PI, TAU - knot, PI)
        }
    }

    /// h(φ); φ is reduced modulo 2π, the result lies in [0, 2π).
    #[inline]
    pub fn eval(&self, phi: f64) -> f64 {
        let p = wrap(phi);
        let (x0, y0, l, dy) = self.piece(p);
        let t = (p - x0) / l;
        let t2 = t * t;
        let t3 = t2 * t;
        y0 + dy * (3.0 * t2 - 2.0 * t3) + l * (2.0 * t3 - 3.0 * t2 + t)
    }

    /// h'(φ), dimensionless.
    pub fn derivative(&self, phi: f64) -> f64 {
        let p = phi.rem_euclid(TAU);
        let (x0, _, l, dy) = self.piece(p);
        let t = (p - x0) / l;
        1.0 + 6.0 * t * (1.0 - t) * (dy / l - 1.0)
    }
}

/// One DOF's pair of stroke parameters: u^d (downstroke) and u^u (upstroke), radians (or a
/// fraction for the spread).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Stroke {
    /// Value of the DOF at the bottom of the downstroke (g1) or held through the downstroke (g2).
    pub down: f64,
    /// Value at the top of the upstroke (g1, reached at φ = 0) or at mid-upstroke (g2).
    pub up: f64,
}

impl Stroke {
    /// A stroke from its two values.
    pub const fn new(down: f64, up: f64) -> Stroke {
        Stroke { down, up }
    }

    /// A DOF held at `v` (no motion, e.g. in a glide).
    pub const fn hold(v: f64) -> Stroke {
        Stroke { down: v, up: v }
    }

    /// Linear blend `(1 − w)·a + w·b` of both values.
    pub fn lerp(a: Stroke, b: Stroke, w: f64) -> Stroke {
        Stroke {
            down: a.down + w * (b.down - a.down),
            up: a.up + w * (b.up - a.up),
        }
    }
}

/// The stroke parameters of one wingbeat, one [`Stroke`] per DOF (Wu & Popović Table 1, u1–u6,
/// plus the hand dihedral that a renderer needs).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Strokes {
    /// Arm dihedral (u1, g1), radians, up positive.
    pub dihedral: Stroke,
    /// Hand dihedral relative to the arm (g1, lagged by [`Timing::hand_lag`]), radians, up positive.
    pub hand_dihedral: Stroke,
    /// Tail bend (u6, g1), radians, up positive.
    pub tail_bend: Stroke,
    /// Arm sweep (u2, g2), radians, forward positive.
    pub sweep: Stroke,
    /// Arm twist (u3, g2), radians, leading edge up positive.
    pub arm_twist: Stroke,
    /// Forearm/hand twist (u4, g2), radians, leading edge up positive.
    pub hand_twist: Stroke,
    /// Wing spread (u5, g2), fraction: 1 = fully extended.
    pub spread: Stroke,
}

impl Strokes {
    /// Linear blend of every DOF.
    pub fn lerp(a: &Strokes, b: &Strokes, w: f64) -> Strokes {
        Strokes {
            dihedral: Stroke::lerp(a.dihedral, b.dihedral, w),
            hand_dihedral: Stroke::lerp(a.hand_dihedral, b.hand_dihedral, w),
            tail_bend: Stroke::lerp(a.tail_bend, b.tail_bend, w),
            sweep: Stroke::lerp(a.sweep, b.sweep, w),
            arm_twist: Stroke::lerp(a.arm_twist, b.arm_twist, w),
            hand_twist: Stroke::lerp(a.hand_twist, b.hand_twist, w),
            spread: Stroke::lerp(a.spread, b.spread, w),
        }
    }
}

/// Timing of a wingbeat: the downstroke fractions of §4.2 and the hand's lag.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Timing {
    /// u_α: fraction of the period taken by the downstroke of the g1 DOFs.
    pub u_alpha: f64,
    /// u_β: fraction of the period taken by the downstroke (hold) of the g2 DOFs.
    pub u_beta: f64,
    /// Phase lag of the hand dihedral behind the arm dihedral, radians (the hand's inertia and the
    /// flexible primaries make the hand turn after the arm).
    pub hand_lag: f64,
    /// Depression of the hand as the wing folds (King & McLelland via Wu & Popović §4.1), radians
    /// per unit of lost spread: hand dihedral −= fold_droop · (1 − spread).
    pub fold_droop: f64,
}

impl Timing {
    /// Phase offset δ = (u_α − u_β)π of the g2 DOFs: evaluating them at h_β(φ − δ) puts the middle
    /// of their downstroke hold at φ = u_α π and their mid-upstroke at φ = (1 + u_α)π, exactly the
    /// stroke midpoints of the g1 DOFs (Wu & Popović §4.2, last paragraph).
    pub fn g2_offset(&self) -> f64 {
        (self.u_alpha - self.u_beta) * PI
    }

    /// Phase of mid-upstroke, (1 + u_α)π: where one wingbeat ends and the next begins (§4.3).
    pub fn mid_upstroke(&self) -> f64 {
        (1.0 + self.u_alpha) * PI
    }

    /// Half-width of the blending window around mid-upstroke, radians of phase: 10 % of the period,
    /// or less if the upstroke is short, so the window never reaches the downstroke.
    pub fn blend_half_width(&self) -> f64 {
        (0.2 * PI).min(0.5 * (1.0 - self.u_alpha) * PI)
    }
}

/// Evaluates the full wing pose of a wingbeat with `strokes` and `timing` at wingbeat phase `phi`
/// (radians, 0 = start of the downstroke; reduced modulo 2π).
#[inline]
pub fn pose(strokes: &Strokes, timing: &Timing, phi: f64) -> WingPose {
    let h_a = PhaseMap::new(timing.u_alpha);
    let h_b = PhaseMap::new(timing.u_beta);
    let c1 = g1_basis(h_a.eval(phi));
    let c1_hand = g1_basis(h_a.eval(phi - timing.hand_lag));
    let c2 = g2_basis(h_b.eval(phi - timing.g2_offset()));
    let lin = |s: Stroke, c: f64| s.down + (s.up - s.down) * c;
    let spread = lin(strokes.spread, c2).clamp(0.0, 1.0);
    WingPose {
        dihedral: lin(strokes.dihedral, c1),
        hand_dihedral: lin(strokes.hand_dihedral, c1_hand) - timing.fold_droop * (1.0 - spread),
        sweep: lin(strokes.sweep, c2),
        arm_twist: lin(strokes.arm_twist, c2),
        hand_twist: lin(strokes.hand_twist, c2),
        spread,
        tail_bend: lin(strokes.tail_bend, c1),
        legs: 0.0,
    }
}

/// C1 blending weight on x ∈ [0, 1]: the smoothstep 3x² − 2x³ (zero slope at both ends, so a
/// blend of two C1 curves with it is C1; Lee & Kim's blending in the sense of Wu & Popović §4.3).
#[inline]
pub fn blend_weight(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g2_is_c1_at_the_stroke_reversals() {
        let eps = 1e-6;
        for &p in &[PI, TAU] {
            let left = g2(0.2, 1.0, p - eps);
            let right = g2(0.2, 1.0, p + eps);
            assert!((left - right).abs() < 1e-9);
        }
    }

    #[test]
    fn h_derivative_matches_finite_differences() {
        for &u in &[0.2, 0.45, 0.5, 0.62, 0.8] {
            let h = PhaseMap::new(u);
            for k in 1..200 {
                let p = k as f64 * TAU / 200.0 + 1e-3;
                let fd = (h.eval(p + 1e-6) - h.eval(p - 1e-6)) / 2e-6;
                assert!((fd - h.derivative(p)).abs() < 1e-5, "u={u} p={p}");
            }
        }
    }
}
