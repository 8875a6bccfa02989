//! §5 step 2: Hummel's power-reduction model, as printed in Klotsman & Tal (after Hummel 1983),
//! defined for every lateral distance: overlapping wingtips, line astern, and a vortex core.
//!
//! Takes lateral and longitudinal distances between birds in wingspans (docs/formats.md §2–3) and gives the
//! pair function g(x, y), its partial derivatives, each bird's saving e_i, the total E and the
//! relative values ξ_i = e_i / E. Pure functions; the drag ratio C of eq. (1) is dropped.
//!
//! **What g is.** Each bird is a horseshoe vortex of span a = π/4 wingspans (elliptic loading):
//! a bound vortex across the wing and two trailing vortices from its ends downstream. g_ij is the
//! upwash of bird j integrated along bird i's bound vortex, divided by the solo induced drag of
//! an elliptic wing of the same lift: **the fraction of bird i's solo induced power that bird j
//! saves it** (negative where i sits in j's downwash). The derivation is in `docs/model.md`;
//! `tests/aero.rs` checks g against an independent numerical Biot–Savart integration.
//!
//! With r_c = √(c² + y²) for the three lateral offsets c ∈ {x + a, x − a, x} (weights w = 1, 1,
//! −2), the printed formula reads
//!
//! ```math
//! \tfrac{\pi^2}{2} g(x,y) = \underbrace{-\sum_c w_c \ln(r_c - y)}_{\text{trailing vortices}}
//!   \;\underbrace{-\;\frac{1}{y}\sum_c w_c\, r_c}_{\text{bound vortex}}
//! ```
//!
//! which is the printed one term by term (ln((c − y + r)/(c + y + r)) = ln(c/(r + y)) and
//! ln|c| − ln(|c|/(r − y))…; see `docs/model.md`). For x < a (wingtips overlapping) the integral
//! is a Cauchy principal value and equals the printed formula with absolute values inside its
//! logarithms, which is exactly this form. Two lines are singular: x = a and x = 0, where one of
//! j's trailing vortices meets the end of i's wing and ln(r_c − y) → −∞ for y > 0. A **vortex
//! core** of radius δ ([`AeroOptions::core_radius`]) replaces the squared distance c² from a
//! trailing vortex by ρ_c² = c² + δ²·exp(−c²/δ²) inside the logarithm (r̃_c = √(ρ_c² + y²)): the
//! trailing vortex's velocity (1 + y/r̃)·c(1 − e^{−c²/δ²})/ρ_c² is a regularised core, not a true
//! Lamb–Oseen core: it follows Lamb–Oseen's profile (1 − e^{−c²/δ²})/c a few core radii out but
//! is weaker inside the core (it divides by ρ_c², not c²); finite at the vortex, and equal to the ideal one to
//! within e^{−c²/δ²} a few core radii away. The bound-vortex term is kept exact: its only
//! singularity, a 1/y pole for x < a at y = 0, is two wings overlapping side by side, which is a
//! collision ([`AeroOptions::collision_chord`]) and an error.
//!
//! **Stable form** (details in `docs/model.md`): with Y = |y| and D(Y) = (π²/2)·g(x, −Y) the
//! saving of the bird in front, Munk's stagger theorem gives (π²/2)·g(x, y) = 2Ã − D(Y) for
//! y > 0, where Ã = ln(ρ_x² / (ρ_{x−a} ρ_{x+a})) = (π²/2)·g(x, 0) (for δ = 0 and x > a,
//! −ln1p(−a²/x²)). D is evaluated without cancellation:
//!
//! ```math
//! D(Y) = -\operatorname{ln1p}\!\Bigl(\frac{\tilde\Sigma}{q} + \frac{\tilde\delta_+\tilde\delta_-}{q^2}\Bigr) + \frac{\Sigma}{Y},
//! \quad q = Y + \tilde r_x,\quad \tilde\delta_\pm = \frac{\rho_{x\pm a}^2 - \rho_x^2}{\tilde r_{x\pm a} + \tilde r_x}
//! ```
//!
//! with Σ = Σ_c w_c r_c (Σ̃ the same with r̃), computed for Y < x as K + Y²·Σ_c w_c/(r_c + |c|)
//! where K = Σ_c w_c|c| = 2·max(a − x, 0), and for Y ≥ x as δ₊ + δ₋. The derivative in y is
//! (π²/2)·∂g/∂y = Σ/Y² + Σ_c w_c(1/r̃_c − 1/r_c), even in y and positive: g increases with y on
//! each side of a collision, so e(y) is the gradient of a convex potential.
//!
//! **Heights.** `wake3d` extends g to birds at different heights, g₃(x, y, z) with
//! g₃(x, y, 0) = g(x, y) ([`AeroOptions::g3`], [`AeroOptions::power_reduction_3d`], chosen by
//! [`AeroOptions::wake`]); everything else in this module is planar.
//!
//! Symbols → code: x → `x` (lateral distance), y → `y` (how far the affected bird is behind
//! the other), a → [`VORTEX_SPAN`], δ → [`AeroOptions::core_radius`], e_i →
//! [`PowerReduction::e`], ξ_i → [`PowerReduction::xi`], E → [`PowerReduction::total`].

use serde::{Deserialize, Serialize};

pub mod band;
mod far;
mod field;
pub mod flapping;
pub mod flight;
pub mod lissaman;
pub mod species;
mod tree;
mod wake3d;
pub use field::{ApproxField, Field};
pub use tree::TreeOptions;
pub use wake3d::Wake;

use crate::animation::Animation;
use crate::error::{Error, Result};

/// Vortex span of an elliptically loaded wing, a = π/4 wingspans: a bird's trailing vortices are
/// a wingspans apart.
pub const VORTEX_SPAN: f64 = std::f64::consts::FRAC_PI_4;

/// Default vortex core radius δ, wingspans (4 % of the wingspan, about 6 cm for a goose). It
/// changes g by less than 1.3·10⁻⁴ wherever |x − π/4| ≥ 0.1 and x ≥ 0.1 (tested).
pub const DEFAULT_CORE_RADIUS: f64 = 0.04;

/// Default fore-aft collision distance, wingspans: the mean chord of a wing of aspect ratio 8
/// (a goose's), 1/8 of the wingspan.
pub const DEFAULT_COLLISION_CHORD: f64 = 0.125;

/// Birds laterally closer than this (one wingspan) have wings that overlap side by side when
/// they fly abreast.
pub const COLLISION_SPAN: f64 = 1.0;

const A: f64 = VORTEX_SPAN;

/// Pairs at least this far apart laterally (wingspans) are evaluated, inside the shape-level
/// sums ([`AeroOptions::power_unchecked`] and the Jacobian), by the far-field expansion of
/// `far_pair` instead of the closed form: relative error below 3·10⁻⁸, absolute below 10⁻¹²
/// (tested), and about a fifth of the cost, which is what makes flocks of thousands of birds fast.
pub const FAR_FIELD: f64 = 60.0;
/// Flocks of at least this many birds are summed by [`Field`] in [`AeroOptions::power_unchecked`]
/// and [`AeroOptions::munk_total_unchecked`] (smaller ones pair by pair in input order).
pub const FIELD_MIN: usize = 256;
/// 2/π², the factor between the bracket of the printed formula and g.
const TWO_OVER_PI2: f64 = 2.0 / (std::f64::consts::PI * std::f64::consts::PI);

/// The model's two physical lengths. Every function of this module that has no options argument
/// uses [`AeroOptions::default`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AeroOptions {
    /// Vortex core radius δ, wingspans (≥ 0; 0 = ideal line vortices, where g is infinite on
    /// the lines x = π/4 and x = 0 for birds behind).
    pub core_radius: f64,
    /// Fore-aft collision distance, wingspans (≥ 0): two birds less than
    /// [`COLLISION_SPAN`] apart laterally and less than this apart fore and aft have wings that
    /// overlap side by side. Coincident birds always collide.
    pub collision_chord: f64,
    /// Which wake gives the savings of shapes whose birds fly at different heights
    /// ([`AeroOptions::power_reduction_3d`]): [`Wake::Planar`] (the default, heights ignored) or
    /// [`Wake::ThreeD`]. Functions without heights (g, the key-shape solve's sums, the frames'
    /// savings) are planar whatever it says. Left out of serialised options when planar.
    #[serde(skip_serializing_if = "Wake::is_planar")]
    pub wake: Wake,
    /// Slope at which the 3-D wake's trailing vortices sink behind the bird, wingspans of descent
    /// per wingspan downstream (≥ 0, at most [`MAX_WAKE_DESCENT`]; 0, the default, keeps them
    /// level). Only [`Wake::ThreeD`] uses it. Left out of serialised options when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub wake_descent: f64,
    /// Which model gives the reported savings ([`AeroModel::Hummel`], the default, or
    /// [`AeroModel::Lissaman`]). Only the shape-level savings of [`AeroOptions::power_reduction_3d`]
    /// and [`AeroOptions::power_lenient_3d`] (what `power`, the frames of an animation and the
    /// report show) follow it; the key-shape solve, g and every planar sum are Hummel's, which
    /// is what Klotsman & Tal's method is built on. Left out of serialised options when Hummel.
    #[serde(skip_serializing_if = "AeroModel::is_hummel")]
    pub model: AeroModel,
}

/// The aerodynamic model that turns positions into savings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum AeroModel {
    /// Hummel's horseshoe vortices (span π/4, a vortex core), as printed in Klotsman & Tal.
    #[default]
    #[serde(rename = "hummel")]
    Hummel,
    /// Elliptically loaded lifting lines with continuous trailing sheets, of the kind Lissaman &
    /// Shollenberger introduced and the field studies used ([`lissaman`]).
    #[serde(rename = "lissaman")]
    Lissaman,
}

impl AeroModel {
    /// `"hummel"` or `"lissaman"`, as in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            AeroModel::Hummel => "hummel",
            AeroModel::Lissaman => "lissaman",
        }
    }

    /// True for [`AeroModel::Hummel`] (the default, left out of serialised options).
    pub fn is_hummel(&self) -> bool {
        *self == AeroModel::Hummel
    }

    /// How the model is named in summaries and the report.
    pub fn describe(self) -> &'static str {
        match self {
            AeroModel::Hummel => "Hummel's horseshoe model",
            AeroModel::Lissaman => "Lissaman & Shollenberger-type lifting lines",
        }
    }
}

impl std::str::FromStr for AeroModel {
    type Err = Error;

    fn from_str(s: &str) -> Result<AeroModel> {
        match s {
            "hummel" => Ok(AeroModel::Hummel),
            "lissaman" => Ok(AeroModel::Lissaman),
            other => Err(Error::parameter(
                "aero.model",
                format!("{other:?}: the model is \"hummel\" or \"lissaman\""),
            )),
        }
    }
}

/// Largest accepted [`AeroOptions::wake_descent`]: a slope of 0.2, far beyond a bird's wake
/// (about 0.01).
pub const MAX_WAKE_DESCENT: f64 = 0.2;

/// True for 0: an option left out of serialised options.
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Default for AeroOptions {
    fn default() -> Self {
        AeroOptions {
            core_radius: DEFAULT_CORE_RADIUS,
            collision_chord: DEFAULT_COLLISION_CHORD,
            wake: Wake::Planar,
            wake_descent: 0.0,
            model: AeroModel::Hummel,
        }
    }
}

/// e_i, ξ_i and E of a shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerReduction {
    /// Saving e_i of each bird: the fraction of its solo induced power that the others save it
    /// (eq. 1 without C), input order.
    pub e: Vec<f64>,
    /// Relative saving ξ_i = e_i / E.
    pub xi: Vec<f64>,
    /// Total saving E = Σ e_i.
    pub total: f64,
}

/// The pieces shared by g and ∂g/∂y for one pair, in units of 2/π².
#[derive(Debug, Clone, Copy)]
struct Pair {
    /// Ã = (π²/2)·g(x, 0) (the mean of the two birds' shares).
    a_term: f64,
    /// D(|y|) = (π²/2)·g(x, −|y|), the front bird's share.
    d_term: f64,
    /// (π²/2)·∂g/∂y at |y| (even in y).
    slope: f64,
}

/// The pair terms for lateral distance x ≥ [`FAR_FIELD`], from the expansion of the printed
/// formula in a/x (its three vortex offsets x + a, x − a, x enter as a second difference):
///
/// ```math
/// \tfrac{\pi^2}{2} g \approx a^2\psi + \tfrac{a^4}{12}\partial_x^2\psi, \qquad
/// \psi = \frac{1 + y/r}{x^2}, \quad
/// \partial_x^2\psi = \frac{6}{x^4}\Bigl(1+\frac{y}{r}\Bigr) + y\Bigl(\frac{3}{x^2r^3} + \frac{3}{r^5}\Bigr),
/// \quad \tfrac{\pi^2}{2}\partial_y g \approx \frac{a^2}{r^3} + \frac{a^4}{12}\Bigl(\frac{15x^2}{r^7} - \frac{3}{r^5}\Bigr)
/// ```
///
/// with r = √(x² + y²) (the core plays no role that far from the vortices), and
/// Ã = −ln(1 − a²/x²) by its series (exact to rounding there). Evaluated for the bird in front
/// (y = −Y) and completed by Munk's theorem like [`AeroOptions::g`].
#[inline]
fn far_pair(x: f64, y: f64) -> Pair {
    // Two divisions in all (this runs for most pairs of a large flock).
    let yy = y.abs();
    let x2 = x * x;
    let r2 = x2 + yy * yy;
    let r = r2.sqrt();
    let inv_x2 = 1.0 / x2;
    let inv_r = 1.0 / r;
    let inv_r2 = inv_r * inv_r;
    let inv_r3 = inv_r2 * inv_r;
    let inv_r5 = inv_r3 * inv_r2;
    // ψ = (1 − Y/r)/x² = 1/(r(r + Y)) without cancellation.
    let psi = 1.0 / (r * (r + yy));
    let psi2 = 6.0 * psi * inv_x2 - yy * 3.0 * (inv_x2 * inv_r3 + inv_r5);
    const A2: f64 = A * A;
    const A4_12: f64 = A * A * A * A / 12.0;
    let u = A2 * inv_x2;
    let a_term = u * (1.0 + u * (0.5 + u * (1.0 / 3.0 + u * 0.25)));
    Pair {
        a_term,
        d_term: A2 * psi + A4_12 * psi2,
        slope: A2 * inv_r3 + A4_12 * (15.0 * x2 * inv_r5 * inv_r2 - 3.0 * inv_r5),
    }
}

/// Sign with sign(0) = 0.
#[inline]
fn sign0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl AeroOptions {
    /// Checks both lengths; the error names the field (`aero.core_radius`,
    /// `aero.collision_chord`).
    pub fn validate(&self) -> Result<()> {
        if !(self.core_radius.is_finite() && self.core_radius >= 0.0 && self.core_radius <= 0.5) {
            return Err(Error::parameter(
                "aero.core_radius",
                format!(
                    "{}: the vortex core radius must be a number of wingspans in [0, 0.5] (default {DEFAULT_CORE_RADIUS})",
                    self.core_radius
                ),
            ));
        }
        if !(self.collision_chord.is_finite()
            && self.collision_chord >= 0.0
            && self.collision_chord <= 1.0)
        {
            return Err(Error::parameter(
                "aero.collision_chord",
                format!(
                    "{}: the collision distance must be a number of wingspans in [0, 1] (default {DEFAULT_COLLISION_CHORD})",
                    self.collision_chord
                ),
            ));
        }
        if !(self.wake_descent.is_finite()
            && self.wake_descent >= 0.0
            && self.wake_descent <= MAX_WAKE_DESCENT)
        {
            return Err(Error::parameter(
                "aero.wake_descent",
                format!(
                    "{}: the wake's descent must be a slope in [0, {MAX_WAKE_DESCENT}] (wingspans per wingspan; default 0)",
                    self.wake_descent
                ),
            ));
        }
        if self.wake_descent != 0.0 && self.wake == Wake::Planar {
            return Err(Error::parameter(
                "aero.wake_descent",
                format!(
                    "{}: only the 3-D wake descends; choose the wake \"3d\" or a descent of 0",
                    self.wake_descent
                ),
            ));
        }
        Ok(())
    }

    /// δ²·exp(−c²/δ²): how much the core adds to the squared distance c² from a trailing vortex.
    #[inline]
    fn core_excess(&self, c: f64) -> f64 {
        let d2 = self.core_radius * self.core_radius;
        if d2 == 0.0 {
            return 0.0;
        }
        let u = c * c / d2;
        // Beyond 40 core radii² the excess is below 10⁻¹⁹ of c²: exactly the ideal vortex.
        if u > 40.0 {
            0.0
        } else {
            d2 * (-u).exp()
        }
    }

    #[inline]
    fn pair(&self, x: f64, y: f64) -> Pair {
        let x = x.abs();
        let yy = y.abs();
        let y2 = yy * yy;
        let cp = x + A;
        let cm = x - A;
        let acm = cm.abs();
        let r0 = (x * x + y2).sqrt();
        let rp = (cp * cp + y2).sqrt();
        let rm = (cm * cm + y2).sqrt();
        // K = Σ w|c|: 2(a − x) for overlapping wingtips, 0 otherwise.
        let k = 2.0 * (A - x).max(0.0);
        // Exact distances: δ± = r± − r₀ without cancellation.
        let dp = A * (2.0 * x + A) / (rp + r0);
        let dm = -A * (2.0 * x - A) / (rm + r0);
        // Σ/Y² (bound vortex) and the bracket Σ_c w/(r + |c|).
        let small = yy < x;
        let bracket = if small {
            1.0 / (rp + cp) + 1.0 / (rm + acm) - 2.0 / (r0 + x)
        } else {
            0.0
        };
        let bound_over_y = if small {
            (if k > 0.0 { k / yy } else { 0.0 }) + yy * bracket
        } else {
            (dp + dm) / yy
        };
        let sigma_over_y2 = if small {
            (if k > 0.0 { k / y2 } else { 0.0 }) + bracket
        } else {
            (dp + dm) / y2
        };
        let (e0, ep, em) = (
            self.core_excess(x),
            self.core_excess(cp),
            self.core_excess(cm),
        );
        let (log_term, a_term, slope) = if e0 == 0.0 && ep == 0.0 && em == 0.0 {
            // Ideal vortices: the trailing part uses the same distances.
            let sigma = if small { k + y2 * bracket } else { dp + dm };
            let q = yy + r0;
            let log_term = -(sigma / q + dp * dm / (q * q)).ln_1p();
            let a_term = if x > A {
                -(-(A / x) * (A / x)).ln_1p()
            } else {
                -(((A - x) * (A + x)) / (x * x)).ln()
            };
            (log_term, a_term, sigma_over_y2)
        } else {
            let q0 = x * x + e0;
            let qp = cp * cp + ep;
            let qm = cm * cm + em;
            let (s0, sp, sm) = (q0.sqrt(), qp.sqrt(), qm.sqrt());
            let t0 = (q0 + y2).sqrt();
            let tp = (qp + y2).sqrt();
            let tm = (qm + y2).sqrt();
            let dtp = (qp - q0) / (tp + t0);
            let dtm = (qm - q0) / (tm + t0);
            let sigma_t = if small {
                let base = k + ep / (sp + cp) + em / (sm + acm) - 2.0 * e0 / (s0 + x);
                base + y2 * (1.0 / (tp + sp) + 1.0 / (tm + sm) - 2.0 / (t0 + s0))
            } else {
                dtp + dtm
            };
            let q = yy + t0;
            let log_term = -(sigma_t / q + dtp * dtm / (q * q)).ln_1p();
            let a_term = 0.5 * (q0 * q0 / (qm * qp)).ln();
            // Σ_c w(1/r̃ − 1/r) = −Σ_c w·ε_c/(r r̃ (r + r̃)), only where the core acts.
            let corr = |eps: f64, r: f64, t: f64| {
                if eps > 0.0 {
                    -eps / (r * t * (r + t))
                } else {
                    0.0
                }
            };
            let slope =
                sigma_over_y2 + corr(ep, rp, tp) + corr(em, rm, tm) - 2.0 * corr(e0, r0, t0);
            (log_term, a_term, slope)
        };
        Pair {
            a_term,
            d_term: log_term + bound_over_y,
            slope,
        }
    }

    /// g(x, y): the fraction of its solo induced power that a bird saves thanks to one other
    /// bird at lateral distance `x` (wingspans, any sign) when it flies `y` wingspans behind it
    /// (negative: ahead). Finite everywhere except where the two wings overlap side by side at
    /// y = 0 with |x| < π/4 (a collision: ±∞ there) and, for `core_radius` = 0, on the lines
    /// |x| = π/4 and x = 0 behind the other bird. NaN for non-finite input.
    ///
    /// Limits: g → 0 as y → −∞, g → 2g(x, 0) as y → +∞, g(x, y) + g(x, −y) = 2g(x, 0).
    #[inline]
    pub fn g(&self, x: f64, y: f64) -> f64 {
        if !(x.is_finite() && y.is_finite()) {
            return f64::NAN;
        }
        let p = self.pair(x, y);
        let scaled = if y > 0.0 {
            2.0 * p.a_term - p.d_term
        } else {
            p.d_term
        };
        TWO_OVER_PI2 * scaled
    }

    /// g(x, 0) = (2/π²)·ln(ρ_x²/(ρ_{x−a}ρ_{x+a})) (ideal: (2/π²)·ln(x²/|x² − a²|)): half of
    /// what the pair saves together, which by Munk's theorem does not depend on the stagger.
    /// Negative for |x| below about 0.555 (a/√2): heavily overlapping wings lose in total.
    #[inline]
    pub fn g0(&self, x: f64) -> f64 {
        if !x.is_finite() {
            return f64::NAN;
        }
        // The y-independent part of the pair (y = 1 is arbitrary and cheap).
        TWO_OVER_PI2 * self.pair(x, 1.0).a_term
    }

    /// ∂g/∂y = (2/π²)·[Σ/y² + Σ_c w_c(1/r̃_c − 1/r_c)]: positive and even in y.
    #[inline]
    pub fn dg_dy(&self, x: f64, y: f64) -> f64 {
        if !(x.is_finite() && y.is_finite()) {
            return f64::NAN;
        }
        TWO_OVER_PI2 * self.pair(x, y).slope
    }

    /// ∂g/∂x for x ≥ 0 (g is even in x). For the front bird (y = −Y ≤ 0)
    ///
    /// ```math
    /// \tfrac{\pi^2}{2}\partial_x g(x,-Y) = -\sum_c \frac{w_c\,c\,(1-e^{-c^2/\delta^2})}{\tilde r_c(\tilde r_c + Y)}
    ///   + \frac{K'}{Y} - Y\sum_c \frac{w_c \operatorname{sign} c}{r_c(r_c+|c|)},
    ///   \qquad K' = \sum_c w_c \operatorname{sign} c,
    /// ```
    ///
    /// and for y > 0, by Munk's theorem, 2Ã'(x) − ∂_x g(x, −y) with
    /// Ã' = −Σ_c w_c c(1 − e^{−c²/δ²})/ρ_c². Its relative accuracy degrades where it tends to 0
    /// (y → −∞). Only g and ∂g/∂y enter the key-shape solve.
    pub fn dg_dx(&self, x: f64, y: f64) -> f64 {
        if !(x.is_finite() && y.is_finite()) {
            return f64::NAN;
        }
        let x = x.abs();
        let yy = y.abs();
        let d2 = self.core_radius * self.core_radius;
        let mut front = 0.0;
        let mut a_prime = 0.0;
        let mut k_prime = 0.0;
        let mut tail = 0.0;
        for (c, w) in [(x + A, 1.0), (x - A, 1.0), (x, -2.0)] {
            let eps = self.core_excess(c);
            let damp = if d2 > 0.0 && eps > 0.0 {
                1.0 - eps / d2
            } else {
                1.0
            };
            let rho2 = c * c + eps;
            let t = (rho2 + yy * yy).sqrt();
            let r = (c * c + yy * yy).sqrt();
            if c != 0.0 {
                front -= w * c * damp / (t * (t + yy));
                a_prime -= w * c * damp / rho2;
                k_prime += w * sign0(c);
                tail += w * sign0(c) / (r * (r + c.abs()));
            }
        }
        let bound = if k_prime != 0.0 { k_prime / yy } else { 0.0 } - yy * tail;
        let front = front + bound;
        let v = if y > 0.0 {
            2.0 * a_prime - front
        } else {
            front
        };
        TWO_OVER_PI2 * v
    }

    /// The first pair of birds (i < j, input order) whose wings overlap side by side: lateral
    /// distance under [`COLLISION_SPAN`] and fore-aft distance under `collision_chord` (or
    /// coincident). O(N log N + collisions checked): sort by x, compare birds within one span.
    pub fn first_collision(&self, x: &[f64], y: &[f64]) -> Option<(usize, usize)> {
        let mut idx: Vec<usize> = (0..x.len()).collect();
        idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
        let mut best: Option<(usize, usize)> = None;
        for (k, &i) in idx.iter().enumerate() {
            for &j in &idx[k + 1..] {
                let dx = x[j] - x[i];
                if !(dx < COLLISION_SPAN) {
                    break;
                }
                if self.collides(dx, y[i] - y[j]) {
                    let p = (i.min(j), i.max(j));
                    if best.map_or(true, |b| p < b) {
                        best = Some(p);
                    }
                }
            }
        }
        best
    }

    /// Whether two birds `dx` apart laterally and `dy` fore and aft collide.
    #[inline]
    pub fn collides(&self, dx: f64, dy: f64) -> bool {
        let dx = dx.abs();
        let dy = dy.abs();
        dx < COLLISION_SPAN && (dy < self.collision_chord || (dy == 0.0 && (dx == 0.0 || dx < A)))
    }

    /// Checks a whole shape: finite coordinates, matching lengths, no collision
    /// ([`Error::Collision`] names the two birds).
    pub fn check_shape(&self, x: &[f64], y: &[f64]) -> Result<()> {
        if x.len() != y.len() {
            return Err(Error::parameter(
                "y",
                format!("{} longitudinal positions for {} birds", y.len(), x.len()),
            ));
        }
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(Error::parameter(
                format!("x[{i}]"),
                "lateral position is not a finite number",
            ));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::parameter(
                format!("y[{i}]"),
                "longitudinal position is not a finite number",
            ));
        }
        if let Some((i, j)) = self.first_collision(x, y) {
            return Err(Error::Collision {
                i,
                j,
                dx: (x[i] - x[j]).abs(),
                dy: (y[i] - y[j]).abs(),
                chord: self.collision_chord,
            });
        }
        Ok(())
    }

    /// e_i, ξ_i and E for birds at lateral positions `x` and longitudinal positions `y` (distance
    /// behind the leader), wingspans, in input order. Fails with [`Error::Collision`] naming the
    /// two birds when wings overlap side by side, with [`Error::Parameter`] for non-finite or
    /// mismatched input or fewer than two birds. One evaluation per pair serves both birds
    /// (Munk: the bird in front gets D, the one behind 2Ã − D).
    pub fn power_reduction(&self, x: &[f64], y: &[f64]) -> Result<PowerReduction> {
        self.validate()?;
        if x.len() < 2 {
            return Err(Error::parameter(
                "birds",
                format!("{} bird(s) given, at least 2 needed", x.len()),
            ));
        }
        self.check_shape(x, y)?;
        let e = self.power_unchecked(x, y);
        let total: f64 = e.iter().sum();
        let xi = e.iter().map(|v| v / total).collect();
        Ok(PowerReduction { e, xi, total })
    }

    /// e_i without validation (the caller guarantees N ≥ 2, finite values, no collision). Flocks
    /// of [`FIELD_MIN`] birds or more go through [`Field`] (sorted by x, far pairs by their
    /// expansion with the lateral part summed once).
    pub fn power_unchecked(&self, x: &[f64], y: &[f64]) -> Vec<f64> {
        if x.len() >= FIELD_MIN {
            return Field::new(self, x, 0.0).power(y);
        }
        let mut e = vec![0.0; x.len()];
        self.accumulate(x, y, &mut e, None);
        e
    }

    /// e_i and the Jacobian ∂e_i/∂y_k (row-major N×N, see [`AeroOptions::power_jacobian_unchecked`])
    /// in one pass over the pairs, which share their square roots. No validation.
    pub fn power_and_jacobian_unchecked(&self, x: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = x.len();
        let mut e = vec![0.0; n];
        let mut jac = vec![0.0; n * n];
        self.accumulate(x, y, &mut e, Some(&mut jac));
        (e, jac)
    }

    fn accumulate(&self, x: &[f64], y: &[f64], e: &mut [f64], mut jac: Option<&mut [f64]>) {
        let n = x.len();
        for i in 0..n {
            for j in (i + 1)..n {
                let dx = (x[i] - x[j]).abs();
                // Distance of i behind j.
                let dy = y[i] - y[j];
                let p = if dx >= FAR_FIELD {
                    far_pair(dx, dy)
                } else {
                    self.pair(dx, dy)
                };
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
    /// Fails on non-finite input, and when E is not finite (ideal vortices, `core_radius` = 0,
    /// with two birds exactly π/4 or 0 apart laterally).
    pub fn munk_total(&self, x: &[f64]) -> Result<f64> {
        self.validate()?;
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(Error::parameter(
                format!("x[{i}]"),
                "lateral position is not a finite number",
            ));
        }
        let total = self.munk_total_unchecked(x);
        if !total.is_finite() {
            return Err(Error::parameter(
                "aero.core_radius",
                "0: two birds sit exactly on the other's trailing vortex (lateral distance π/4 or 0), where ideal vortices give an infinite saving; give the vortex a core (default 0.04 wingspans)",
            ));
        }
        Ok(total)
    }

    /// [`AeroOptions::munk_total`] without validation.
    pub fn munk_total_unchecked(&self, x: &[f64]) -> f64 {
        if x.len() >= FIELD_MIN {
            return Field::new(self, x, 0.0).munk_total();
        }
        let n = x.len();
        let mut total = 0.0;
        for i in 0..n {
            for j in (i + 1)..n {
                total += 2.0 * self.g0((x[i] - x[j]).abs());
            }
        }
        total
    }

    /// The Jacobian of e with respect to y, row-major N×N: ∂e_i/∂y_k. Diagonal entries are
    /// Σ_{j≠i} ∂g/∂y(x_ij, y_i − y_j), off-diagonal ones −∂g/∂y(x_ik, y_i − y_k). The matrix is
    /// symmetric (∂g/∂y is even in y) and a weighted graph Laplacian with positive weights: e is
    /// the gradient of a convex potential, which is why the key-shape system has a unique
    /// solution up to a shift (for a given fore-aft order of overlapping pairs) when it has one.
    pub fn power_jacobian_unchecked(&self, x: &[f64], y: &[f64]) -> Vec<f64> {
        let n = x.len();
        let mut jac = vec![0.0; n * n];
        for i in 0..n {
            for k in (i + 1)..n {
                scatter_slope(
                    &mut jac,
                    n,
                    i,
                    k,
                    self.dg_dy((x[i] - x[k]).abs(), y[i] - y[k]),
                );
            }
        }
        jac
    }

    /// e_i of a shape that may contain colliding pairs (a take-off, birds on the ground): each
    /// pair laterally under one wingspan apart and fore-aft under `collision_chord` is evaluated
    /// as if it were exactly `collision_chord` apart fore and aft (keeping its order; coincident
    /// birds: the lower index in front), so every value is finite. For collision-free shapes this
    /// is [`AeroOptions::power_unchecked`].
    pub fn power_lenient(&self, x: &[f64], y: &[f64]) -> Vec<f64> {
        let n = x.len();
        let chord = self.collision_chord.max(1e-3);
        let mut e = vec![0.0; n];
        for i in 0..n {
            for j in (i + 1)..n {
                let dx = (x[i] - x[j]).abs();
                let mut dy = y[i] - y[j];
                if !(dx.is_finite() && dy.is_finite()) {
                    continue;
                }
                if self.collides(dx, dy) || (dx < COLLISION_SPAN && dy.abs() < chord) {
                    // i ahead when dy < 0; ties: i (lower index) in front.
                    dy = if dy > 0.0 { chord } else { -chord };
                }
                let p = self.pair(dx, dy);
                let (front, back) = (p.d_term, 2.0 * p.a_term - p.d_term);
                if dy > 0.0 {
                    e[i] += back;
                    e[j] += front;
                } else {
                    e[i] += front;
                    e[j] += back;
                }
            }
        }
        for v in e.iter_mut() {
            *v *= TWO_OVER_PI2;
        }
        e
    }
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

/// [`AeroOptions::g`] with the default core.
#[inline]
pub fn g(x: f64, y: f64) -> f64 {
    AeroOptions::default().g(x, y)
}

/// [`AeroOptions::g0`] with the default core.
#[inline]
pub fn g0(x: f64) -> f64 {
    AeroOptions::default().g0(x)
}

/// [`AeroOptions::dg_dy`] with the default core.
#[inline]
pub fn dg_dy(x: f64, y: f64) -> f64 {
    AeroOptions::default().dg_dy(x, y)
}

/// [`AeroOptions::dg_dx`] with the default core.
pub fn dg_dx(x: f64, y: f64) -> f64 {
    AeroOptions::default().dg_dx(x, y)
}

/// [`AeroOptions::power_reduction`] with the default options.
pub fn power_reduction(x: &[f64], y: &[f64]) -> Result<PowerReduction> {
    AeroOptions::default().power_reduction(x, y)
}

/// [`AeroOptions::power_unchecked`] with the default options.
pub fn power_unchecked(x: &[f64], y: &[f64]) -> Vec<f64> {
    AeroOptions::default().power_unchecked(x, y)
}

/// [`AeroOptions::power_and_jacobian_unchecked`] with the default options.
pub fn power_and_jacobian_unchecked(x: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
    AeroOptions::default().power_and_jacobian_unchecked(x, y)
}

/// [`AeroOptions::power_jacobian_unchecked`] with the default options.
pub fn power_jacobian_unchecked(x: &[f64], y: &[f64]) -> Vec<f64> {
    AeroOptions::default().power_jacobian_unchecked(x, y)
}

/// [`AeroOptions::munk_total`] with the default options.
pub fn munk_total(x: &[f64]) -> Result<f64> {
    AeroOptions::default().munk_total(x)
}

/// [`AeroOptions::munk_total_unchecked`] with the default options.
pub fn munk_total_unchecked(x: &[f64]) -> f64 {
    AeroOptions::default().munk_total_unchecked(x)
}

/// ξ_i = e_i/E, with ξ = 0 when E is 0 (so that every value is a number).
pub fn relative(e: &[f64]) -> (Vec<f64>, f64) {
    let total: f64 = e.iter().sum();
    let xi = if total != 0.0 && total.is_finite() {
        e.iter().map(|v| v / total).collect()
    } else {
        vec![0.0; e.len()]
    };
    (xi, total)
}

/// Fills `e` (the saving) and `xi` of every frame of `anim` that lacks them (the take-off),
/// from the frame's positions in the flock's course frame: without a path the world frame
/// (flight along +y), the frame the steady flight's own savings are computed in, so a
/// recomputation with the same model reproduces them; on a path, the formation frame of the
/// leader's heading (the leader is the front-most bird of the first key shape, bird 0 without
/// key shapes): x = offset to the right of the heading, y = distance behind along it. Pairs whose wings overlap side by side
/// (birds still on the ground, or crossing) are evaluated at the collision distance
/// ([`AeroOptions::power_lenient`]), so every cell is a finite number. Frames that already
/// carry e and ξ (the steady flight) are left as they are.
pub fn fill_frame_savings(anim: &mut Animation, opts: &AeroOptions) {
    let n = anim.birds;
    let leader = anim
        .key_shapes
        .first()
        .and_then(|k| {
            k.birds
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.y.total_cmp(&b.1.y))
                .map(|(i, _)| i)
        })
        .filter(|&i| i < n)
        .unwrap_or(0);
    let course_is_world = anim.path.is_none();
    for f in &mut anim.frames {
        if f.e.is_some() && f.xi.is_some() {
            continue;
        }
        if f.x.len() != n || f.y.len() != n || f.heading.len() != n || n < 2 {
            continue;
        }
        // The course frame: without a path it is the world frame (flight along +y, heading 0),
        // the frame the steady flight computed its own savings in; on a path, the leader's
        // heading stands for the path's (its small jostling turns included).
        let h = if course_is_world {
            0.0
        } else {
            f.heading[leader]
        };
        let (s, c) = h.sin_cos();
        // d = (sin θ, cos θ) is the flight direction, (cos θ, −sin θ) its right.
        let lx: Vec<f64> = (0..n).map(|i| f.x[i] * c - f.y[i] * s).collect();
        let ly: Vec<f64> = (0..n).map(|i| -(f.x[i] * s + f.y[i] * c)).collect();
        let e = opts.power_lenient_3d(&lx, &ly, &f.z);
        let (xi, _) = relative(&e);
        f.e = Some(e);
        f.xi = Some(xi);
    }
}

impl AeroOptions {
    /// The record of these options in an animation file (`savings_model`).
    pub fn record(&self) -> crate::animation::SavingsModel {
        crate::animation::SavingsModel {
            wake: self.wake.name().into(),
            core_radius: self.core_radius,
            model: self.model.name().into(),
        }
    }

    /// The options an animation's `savings_model` stands for (defaults for anything it does not
    /// say).
    pub fn from_record(m: &crate::animation::SavingsModel) -> AeroOptions {
        AeroOptions {
            core_radius: m.core_radius,
            wake: m.wake.parse().unwrap_or_default(),
            model: m.model.parse().unwrap_or_default(),
            ..AeroOptions::default()
        }
    }
}

/// Recomputes `e` and `xi` of every frame of `anim` with `opts` (another model, wake or core
/// than the one the animation was made with), as [`fill_frame_savings`] does for the take-off:
/// in the course frame. Records `opts` as the animation's savings
/// model.
pub fn recompute_frame_savings(anim: &mut Animation, opts: &AeroOptions) {
    for f in &mut anim.frames {
        f.e = None;
        f.xi = None;
    }
    fill_frame_savings(anim, opts);
    anim.savings_model = Some(opts.record());
}

#[cfg(test)]
mod tests {
    use super::*;

    const IDEAL: AeroOptions = AeroOptions {
        core_radius: 0.0,
        collision_chord: DEFAULT_COLLISION_CHORD,
        wake: Wake::Planar,
        wake_descent: 0.0,
        model: AeroModel::Hummel,
    };

    /// The formula exactly as printed, with absolute values inside the logarithms, evaluated
    /// literally (only valid for moderate y ≠ 0).
    fn g_printed(x: f64, y: f64) -> f64 {
        let r0 = (x * x + y * y).sqrt();
        let rm = ((x - A) * (x - A) + y * y).sqrt();
        let rp = ((x + A) * (x + A) + y * y).sqrt();
        let t = (x * x / ((x - A) * (x + A))).abs().ln()
            + 2.0 * ((x - y + r0) / (x + y + r0)).abs().ln()
            - ((x - A - y + rm) / (x - A + y + rm)).abs().ln()
            - ((x + A - y + rp) / (x + A + y + rp)).abs().ln()
            + (2.0 * r0 - rp - rm) / y;
        TWO_OVER_PI2 * t
    }

    #[test]
    fn matches_printed_formula_on_both_sides_of_the_vortex_span() {
        for &x in &[0.05, 0.2, 0.4, 0.6, 0.75, 0.8, 0.9, 1.0, 1.3, 2.0, 5.0] {
            for &y in &[-5.0, -2.0, -0.7, -0.1, 0.05, 0.3, 1.0, 3.0, 8.0] {
                let a = IDEAL.g(x, y);
                let b = g_printed(x, y);
                assert!(
                    ((a - b) / b).abs() < 1e-10,
                    "x={x} y={y}: stable {a} printed {b}"
                );
            }
        }
    }

    #[test]
    fn munk_symmetry_and_limits_with_and_without_core() {
        for opts in [IDEAL, AeroOptions::default()] {
            for &x in &[0.0, 0.1, 0.5, 0.7, A, 0.786, 0.9, 1.2, 3.0, 40.0] {
                let g0 = opts.g0(x);
                if !g0.is_finite() {
                    assert_eq!(opts.core_radius, 0.0, "x={x}");
                    continue;
                }
                for &y in &[0.2, 2.0, 1e3, 1e6] {
                    let s = opts.g(x, y) + opts.g(x, -y);
                    assert!(
                        (s - 2.0 * g0).abs() < 1e-12 * g0.abs().max(1.0),
                        "x={x} y={y}: {s} vs {}",
                        2.0 * g0
                    );
                }
                assert!(opts.g(x, -1e9).abs() < 1e-15);
                assert!((opts.g(x, 1e9) - 2.0 * g0).abs() < 1e-14 * g0.abs().max(1.0));
            }
        }
    }

    #[test]
    fn core_is_finite_on_the_singular_lines_and_negligible_away_from_them() {
        let core = AeroOptions::default();
        for &y in &[-3.0, -0.5, 0.2, 0.5, 3.0, 50.0] {
            assert!(
                core.g(A, y).is_finite() && core.g(0.0, y).is_finite(),
                "y={y}"
            );
            assert!(core.dg_dy(A, y).is_finite() && core.dg_dy(A, y) > 0.0);
        }
        // |x − a| ≥ 0.1 and x ≥ 0.1: the core changes g by less than 1e-3 (in fact < 1.3e-4).
        let mut worst: f64 = 0.0;
        for i in 0..=400 {
            let x = 0.1 + i as f64 * 0.01;
            if (x - A).abs() < 0.1 {
                continue;
            }
            for k in -60..=60 {
                let y = if k == 0 { 0.3 } else { k as f64 * 0.25 };
                worst = worst.max((core.g(x, y) - IDEAL.g(x, y)).abs());
            }
        }
        assert!(worst < 1.3e-4, "core changes g by {worst}");
    }

    #[test]
    fn far_field_expansion_matches_the_closed_form() {
        let o = AeroOptions::default();
        let mut worst: f64 = 0.0;
        for i in 0..200 {
            let x = FAR_FIELD * (1.0 + i as f64 * 0.1);
            for k in -40..=40 {
                let y = k as f64 * x / 8.0;
                let (exact, far) = (o.pair(x, y), far_pair(x, y));
                for (a, b) in [
                    (exact.d_term, far.d_term),
                    (exact.a_term, far.a_term),
                    (exact.slope, far.slope),
                ] {
                    let err = (a - b).abs();
                    assert!(err < 3e-8 * a.abs() + 1e-16, "x={x} y={y}: {a} vs {b}");
                    worst = worst.max(TWO_OVER_PI2 * err);
                }
            }
        }
        assert!(worst < 1e-12, "worst absolute error of g {worst:e}");
    }

    #[test]
    fn collisions_and_options() {
        let o = AeroOptions::default();
        assert!(o.collides(0.0, 0.0));
        assert!(o.collides(0.8, 0.1));
        assert!(!o.collides(0.8, 0.2));
        assert!(!o.collides(1.0, 0.0));
        let err = o
            .power_reduction(&[0.0, 0.5, 2.0], &[0.0, 0.05, 2.0])
            .unwrap_err();
        assert!(matches!(err, Error::Collision { i: 0, j: 1, .. }), "{err}");
        let bad = AeroOptions {
            core_radius: -0.1,
            ..o
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("aero.core_radius"));
        let nan = AeroOptions {
            core_radius: f64::NAN,
            ..o
        };
        assert!(nan.power_reduction(&[0.0, 1.0], &[0.0, 1.0]).is_err());
    }
}
