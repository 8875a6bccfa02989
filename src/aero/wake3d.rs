//! The 3-D wake: Hummel's horseshoe model with a vertical offset between the two birds.
//!
//! Takes lateral, fore-aft and vertical distances between birds in wingspans and gives the pair
//! function g₃(x, y, z), and the shape-level savings e_i, ξ_i, E of birds at different heights.
//! Pure functions.
//!
//! **What g₃ is.** The same horseshoe as [`AeroOptions::g`] (bound vortex of span a = π/4
//! wingspans, two straight trailing vortices from its ends, parallel to the flight direction and
//! level unless [`AeroOptions::wake_descent`] makes them sink; they do not follow the wingbeat),
//! but bird i's bound vortex lies z
//! wingspans **above** bird j's plane (up positive). g₃ is the vertical velocity that j's
//! horseshoe induces along i's bound vortex, integrated along i's span, over the solo induced
//! drag of an elliptic wing of the same lift: the fraction of i's solo induced power that j
//! saves it. A trailing vortex at lateral offset c and vertical offset z (squared radial distance
//! h² = c² + z²) induces the vertical velocity (Γ/4π)·c/h²·(1 + y/√(h² + y²)) at a point y behind
//! its start; the bound vortex induces −(Γ/4π)·y/(y² + z²)·(cos θ₁ − cos θ₂). Both integrate
//! along i's span in closed form (the trailing term's antiderivative in c is ln(R − y),
//! R = √(c² + z² + y²); the bound term's is R): with the three lateral offsets
//! c ∈ {x + a, x − a, x} (weights w = 1, 1, −2) of [`super`],
//!
//! ```math
//! \tfrac{\pi^2}{2} g_3(x,y,z) = -\sum_c w_c \ln(\tilde R_c - y) \;-\; \frac{y}{y^2+z^2}\sum_c w_c R_c,
//! \qquad R_c = \sqrt{c^2+z^2+y^2},\quad \tilde R_c = \sqrt{\rho_c^2 + y^2}
//! ```
//!
//! with the planar model's vortex core applied to the squared radial distance from the trailing
//! vortex: ρ_c² = h_c² + δ²·exp(−h_c²/δ²), h_c² = c² + z². At z = 0 this is the planar formula
//! term by term (tested to 10⁻¹² against [`AeroOptions::g`], with and without core); it depends on
//! z through z² only (a bird above sees the same as a bird below), and is continuous in z.
//! Munk's stagger theorem still holds at every height: the bound term is odd in y and the two
//! trailing sums add up to −Σ_c w_c ln ρ_c², so g₃(x, y, z) + g₃(x, −y, z) = 2g₃(x, 0, z) with
//!
//! ```math
//! \tfrac{\pi^2}{2} g_3(x,0,z) = \tilde A(z) = \tfrac12 \ln\frac{\rho_x^4}{\rho_{x+a}^2\,\rho_{x-a}^2}
//! ```
//!
//! which is how it is evaluated (the bird in front by the stable form of [`super`], the bird
//! behind as 2Ã − D). Off the plane the two singular lines of the ideal model (x = a and x = 0,
//! behind) are finite even without a core.
//!
//! **Shape level.** [`AeroOptions::power_reduction_3d`] takes each bird's height. It sums pair by
//! pair (O(N²), no far-field expansion and no [`super::Field`]), so it is meant for measured
//! flocks and the tool's shapes, not for the big-flock fast paths. The collision rule stays the
//! planar one (two wings overlapping side by side collide at any height: the wingbeat's vertical
//! sweep is larger than the height differences of real flocks). The key-shape solve works in the
//! plane (z = 0), where both wakes agree, so it keeps using the planar sums whatever the wake.
//!
//! **A sinking wake** (slope σ = tan β > 0): the trailing vortices' share is the level one, times
//! cos β, evaluated at the offsets along and across the tilted vortex, y′ = y cos β − z sin β and
//! z′ = y sin β + z cos β; the bound vortex's share is unchanged. Munk's theorem then fails, so
//! both birds of each pair are evaluated.
//!
//! Symbols → code: z → `z` (how far the affected bird is above the other, wingspans), the
//! choice of wake → [`Wake`] in [`AeroOptions::wake`].

use serde::{Deserialize, Serialize};

use super::{AeroOptions, PowerReduction, A, COLLISION_SPAN, TWO_OVER_PI2};
use crate::error::{Error, Result};

/// Which wake gives the savings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Wake {
    /// Hummel's planar model: every bird in one horizontal plane; heights are ignored.
    #[default]
    #[serde(rename = "planar")]
    Planar,
    /// The same horseshoe vortices with each bird's height (`z`) taken into account.
    #[serde(rename = "3d")]
    ThreeD,
}

impl Wake {
    /// `"planar"` or `"3d"`, as in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Wake::Planar => "planar",
            Wake::ThreeD => "3d",
        }
    }

    /// True for [`Wake::Planar`] (the default, left out of serialised options).
    pub fn is_planar(&self) -> bool {
        *self == Wake::Planar
    }
}

impl std::fmt::Display for Wake {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Wake {
    type Err = Error;

    fn from_str(s: &str) -> Result<Wake> {
        match s {
            "planar" => Ok(Wake::Planar),
            "3d" => Ok(Wake::ThreeD),
            other => Err(Error::parameter(
                "aero.wake",
                format!("{other:?}: the wake is \"planar\" or \"3d\""),
            )),
        }
    }
}

/// `num / den`, with 0 when `num` is 0 (a point exactly on an ideal vortex line, where the
/// quotient is 0/0 but the term it stands for, ρ − |c|, is 0).
#[inline]
fn lift(num: f64, den: f64) -> f64 {
    if num == 0.0 {
        0.0
    } else {
        num / den
    }
}

impl AeroOptions {
    /// δ²·exp(−h²/δ²) for the squared radial distance `h2` from a trailing vortex (the planar
    /// model's core excess, with h² in place of c²).
    #[inline]
    fn core_excess2(&self, h2: f64) -> f64 {
        let d2 = self.core_radius * self.core_radius;
        if d2 == 0.0 {
            return 0.0;
        }
        let u = h2 / d2;
        if u > 40.0 {
            0.0
        } else {
            d2 * (-u).exp()
        }
    }

    /// (Ã, D(|y|)) of a pair at lateral distance `x`, fore-aft `y` and vertical `z`, in units of
    /// 2/π²: Ã = (π²/2)·g₃(x, 0, z), D = (π²/2)·g₃(x, −|y|, z) (the front bird's share).
    #[inline]
    fn pair3(&self, x: f64, y: f64, z: f64) -> (f64, f64) {
        let (a_term, log_term, bound) = self.parts3(x, y, z);
        (a_term, log_term + bound)
    }

    /// The three pieces of [`AeroOptions::pair3`], units of 2/π²: Ã, the trailing vortices'
    /// share of the front bird −Σ_c w_c ln(R̃_c + |y|), and the bound vortex's
    /// |y|/(y² + z²)·Σ_c w_c R_c.
    fn parts3(&self, x: f64, y: f64, z: f64) -> (f64, f64, f64) {
        let x = x.abs();
        let yy = y.abs();
        let y2 = yy * yy;
        let z2 = z * z;
        let b2 = y2 + z2;
        let cp = x + A;
        let cm = x - A;
        let acm = cm.abs();
        // Squared radial distances from j's three vortex lines (the middle one counted twice).
        let h0 = x * x + z2;
        let hp = cp * cp + z2;
        let hm = cm * cm + z2;
        let r0 = (h0 + y2).sqrt();
        let rp = (hp + y2).sqrt();
        let rm = (hm + y2).sqrt();
        // K = Σ w|c|: 2(a − x) for overlapping wingtips, 0 otherwise.
        let k = 2.0 * (A - x).max(0.0);
        // R± − R₀ without cancellation: R±² − R₀² = (x ± a)² − x², whatever z.
        let dp = A * (2.0 * x + A) / (rp + r0);
        let dm = -A * (2.0 * x - A) / (rm + r0);
        // Σ_c w R_c = K + b²·Σ_c w/(R_c + |c|) (b² = y² + z²) while b < x, else δ₊ + δ₋.
        let small = b2.sqrt() < x;
        let bracket = if small {
            1.0 / (rp + cp) + 1.0 / (rm + acm) - 2.0 / (r0 + x)
        } else {
            0.0
        };
        // The bound vortex's share of the front bird is |y|/b²·Σ_c w R_c; |y|/b² is scaled so
        // that b² cannot underflow (exactly 1/|y| at z = 0, as in the planar model).
        let m = yy.max(z.abs());
        let over = if m > 0.0 {
            let (u, v) = (yy / m, z.abs() / m);
            u / (m * (u * u + v * v))
        } else {
            1.0 / yy
        };
        let bound = if small {
            (if k > 0.0 { k * over } else { 0.0 }) + yy * bracket
        } else {
            (dp + dm) * over
        };
        // Trailing vortices with the core on the radial distance: ρ_c² = h_c² + ε_c.
        let (e0, ep, em) = (
            self.core_excess2(h0),
            self.core_excess2(hp),
            self.core_excess2(hm),
        );
        let q0 = h0 + e0;
        let qp = hp + ep;
        let qm = hm + em;
        let (s0, sp, sm) = (q0.sqrt(), qp.sqrt(), qm.sqrt());
        let t0 = (q0 + y2).sqrt();
        let tp = (qp + y2).sqrt();
        let tm = (qm + y2).sqrt();
        // R̃± − R̃₀, from ρ±² − ρ₀² = (x ± a)² − x² + ε± − ε₀.
        let dtp = (A * (2.0 * x + A) + (ep - e0)) / (tp + t0);
        let dtm = (-A * (2.0 * x - A) + (em - e0)) / (tm + t0);
        let sigma_t = if small {
            // R̃ − |c| = y²/(R̃ + ρ) + (z² + ε)/(ρ + |c|).
            let base =
                k + lift(z2 + ep, sp + cp) + lift(z2 + em, sm + acm) - 2.0 * lift(z2 + e0, s0 + x);
            base + y2 * (1.0 / (tp + sp) + 1.0 / (tm + sm) - 2.0 / (t0 + s0))
        } else {
            dtp + dtm
        };
        let q = yy + t0;
        let log_term = -(sigma_t / q + dtp * dtm / (q * q)).ln_1p();
        // Ã = ½ln(ρ₀⁴/(ρ₊²ρ₋²)); ρ₊²ρ₋² − ρ₀⁴ = a²(a² + 2z² − 2x²) + the core's share, exactly.
        let excess = A * A * (A * A + 2.0 * z2 - 2.0 * x * x) + ep * hm + em * hp + ep * em
            - 2.0 * e0 * h0
            - e0 * e0;
        let u = excess / (q0 * q0);
        let a_term = if u.abs() < 0.5 {
            -0.5 * u.ln_1p()
        } else {
            0.5 * ((q0 / qp) * (q0 / qm)).ln()
        };
        (a_term, log_term, bound)
    }

    /// What bird i saves thanks to bird j (units of 2/π²) when j's trailing vortices sink at
    /// slope σ = [`AeroOptions::wake_descent`] (direction (0, cos β, −sin β), tan β = σ): the
    /// trailing vortices' share is the level one, times cos β, at the offsets along and across
    /// the tilted vortices, y′ = y cos β − z sin β and z′ = y sin β + z cos β (R_c is the same
    /// in both frames); the bound vortex's share is unchanged. Munk's theorem does not hold for
    /// a tilted wake, so both birds of a pair are evaluated.
    fn descending(&self, x: f64, y: f64, z: f64) -> f64 {
        let sigma = self.wake_descent;
        let cb = 1.0 / (1.0 + sigma * sigma).sqrt();
        let sb = sigma * cb;
        let (yt, zt) = (y * cb - z * sb, y * sb + z * cb);
        let (a_t, log_t, _) = self.parts3(x, yt, zt);
        // −Σ w ln(R̃ − y′) = 2Ã(z′) − (−Σ w ln(R̃ + y′)) behind, since R̃² − y′² = ρ².
        let trailing = if yt > 0.0 { 2.0 * a_t - log_t } else { log_t };
        let (_, _, bound) = self.parts3(x, y, z);
        cb * trailing + if y > 0.0 { -bound } else { bound }
    }

    /// g₃(x, y, z): the fraction of its solo induced power that a bird saves thanks to one
    /// other bird at lateral distance `x` (wingspans, any sign) when it flies `y` wingspans
    /// behind it (negative: ahead) and `z` wingspans above it (negative: below). Even in x and
    /// in z; equal to [`AeroOptions::g`] at z = 0. Ignores [`AeroOptions::wake`]; with a
    /// [`AeroOptions::wake_descent`] the trailing vortices sink (then g₃ is no longer even in z,
    /// nor equal to g at z = 0). NaN for non-finite input; infinite where the planar g is.
    pub fn g3(&self, x: f64, y: f64, z: f64) -> f64 {
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return f64::NAN;
        }
        if self.wake_descent != 0.0 {
            return TWO_OVER_PI2 * self.descending(x, y, z);
        }
        let (a_term, d_term) = self.pair3(x, y, z);
        let scaled = if y > 0.0 {
            2.0 * a_term - d_term
        } else {
            d_term
        };
        TWO_OVER_PI2 * scaled
    }

    /// g₃(x, 0, z): half of what two birds `x` apart laterally and `z` apart vertically save
    /// together, whatever their stagger (Munk's theorem; level vortices, the descent ignored).
    pub fn g3_0(&self, x: f64, z: f64) -> f64 {
        if !(x.is_finite() && z.is_finite()) {
            return f64::NAN;
        }
        TWO_OVER_PI2 * self.pair3(x, 1.0, z).0
    }

    /// e_i, ξ_i and E for birds at lateral positions `x`, longitudinal positions `y` (distance
    /// behind the leader) and heights `z` (up), wingspans, input order. With [`Wake::Planar`]
    /// this is [`AeroOptions::power_reduction`] and `z` is ignored (but must have one value per
    /// bird); with [`Wake::ThreeD`] each pair is g₃ at its vertical distance, summed directly
    /// (O(N²)). Errors as [`AeroOptions::power_reduction`]; a non-finite height is named `z[i]`.
    pub fn power_reduction_3d(&self, x: &[f64], y: &[f64], z: &[f64]) -> Result<PowerReduction> {
        if z.len() != x.len() {
            return Err(Error::parameter(
                "z",
                format!("{} heights for {} birds", z.len(), x.len()),
            ));
        }
        if let Some(i) = z.iter().position(|v| !v.is_finite()) {
            return Err(Error::parameter(
                format!("z[{i}]"),
                "height is not a finite number",
            ));
        }
        let lissaman = self.model == super::AeroModel::Lissaman;
        if !lissaman && self.wake == Wake::Planar {
            return self.power_reduction(x, y);
        }
        self.validate()?;
        if x.len() < 2 {
            return Err(Error::parameter(
                "birds",
                format!("{} bird(s) given, at least 2 needed", x.len()),
            ));
        }
        self.check_shape(x, y)?;
        let e = if lissaman {
            self.power_lenient_3d(x, y, z)
        } else {
            self.power_unchecked_3d(x, y, z)
        };
        let total: f64 = e.iter().sum();
        let xi = e.iter().map(|v| v / total).collect();
        Ok(PowerReduction { e, xi, total })
    }

    /// e_i without validation (the caller guarantees N ≥ 2, matching lengths, finite values,
    /// no collision). [`Wake::Planar`]: [`AeroOptions::power_unchecked`] (z ignored, with its
    /// fast paths). [`Wake::ThreeD`]: the direct sum over pairs of g₃, one evaluation per pair
    /// serving both birds (the front bird gets D, the one behind 2Ã − D); with a
    /// [`AeroOptions::wake_descent`], both birds of each pair evaluated.
    pub fn power_unchecked_3d(&self, x: &[f64], y: &[f64], z: &[f64]) -> Vec<f64> {
        if self.wake == Wake::Planar {
            return self.power_unchecked(x, y);
        }
        let n = x.len();
        let mut e = vec![0.0; n];
        if self.wake_descent != 0.0 {
            for i in 0..n {
                for j in (i + 1)..n {
                    let (dx, dy, dz) = (x[i] - x[j], y[i] - y[j], z[i] - z[j]);
                    e[i] += self.descending(dx, dy, dz);
                    e[j] += self.descending(-dx, -dy, -dz);
                }
            }
            for v in e.iter_mut() {
                *v *= TWO_OVER_PI2;
            }
            return e;
        }
        for i in 0..n {
            for j in (i + 1)..n {
                let dy = y[i] - y[j];
                let (a_term, d_term) = self.pair3(x[i] - x[j], dy, z[i] - z[j]);
                let (front, back) = (d_term, 2.0 * a_term - d_term);
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

    /// [`AeroOptions::power_lenient`] with heights: every frame of an animation gets finite
    /// savings (a pair closer than a chord is evaluated at the collision distance). The planar
    /// wake ignores `z`.
    /// With [`super::AeroModel::Lissaman`], the lifting-line model's sums
    /// ([`super::lissaman::power`]; heights only with [`Wake::ThreeD`]).
    pub fn power_lenient_3d(&self, x: &[f64], y: &[f64], z: &[f64]) -> Vec<f64> {
        if self.model == super::AeroModel::Lissaman {
            let zs: &[f64] = if self.wake == Wake::ThreeD && z.len() == x.len() {
                z
            } else {
                &[]
            };
            return super::lissaman::power(x, y, zs, self.collision_chord);
        }
        if self.wake == Wake::Planar || z.len() != x.len() {
            return self.power_lenient(x, y);
        }
        let n = x.len();
        let chord = self.collision_chord.max(1e-3);
        // Pairs closer than a chord: the one behind is evaluated a chord behind (as the planar
        // lenient sum does).
        let mut e = vec![0.0; n];
        for i in 0..n {
            for j in (i + 1)..n {
                let dx = x[i] - x[j];
                let mut dy = y[i] - y[j];
                let dz = z[i] - z[j];
                if !(dx.is_finite() && dy.is_finite() && dz.is_finite()) {
                    continue;
                }
                if self.collides(dx.abs(), dy) || (dx.abs() < COLLISION_SPAN && dy.abs() < chord) {
                    dy = if dy > 0.0 { chord } else { -chord };
                }
                let pair = if self.wake_descent != 0.0 {
                    (self.descending(dx, dy, dz), self.descending(-dx, -dy, -dz))
                } else {
                    let (a_term, d_term) = self.pair3(dx, dy, dz);
                    let (front, back) = (d_term, 2.0 * a_term - d_term);
                    if dy > 0.0 {
                        (back, front)
                    } else {
                        (front, back)
                    }
                };
                e[i] += pair.0;
                e[j] += pair.1;
            }
        }
        for v in e.iter_mut() {
            *v *= TWO_OVER_PI2;
        }
        e
    }

    /// E from lateral positions and heights (Munk's theorem at every height): Σ over pairs of
    /// 2·g₃(|Δx|, 0, Δz), for level vortices ([`AeroOptions::wake_descent`] is ignored: a
    /// sinking wake's total depends on the stagger). With [`Wake::Planar`],
    /// [`AeroOptions::munk_total_unchecked`]. No validation.
    pub fn munk_total_3d_unchecked(&self, x: &[f64], z: &[f64]) -> f64 {
        if self.wake == Wake::Planar {
            return self.munk_total_unchecked(x);
        }
        let n = x.len();
        let mut total = 0.0;
        for i in 0..n {
            for j in (i + 1)..n {
                total += 2.0 * TWO_OVER_PI2 * self.pair3(x[i] - x[j], 1.0, z[i] - z[j]).0;
            }
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduces_to_the_planar_pair_terms_at_zero_height() {
        for core in [0.0, 0.04, 0.2] {
            let o = AeroOptions {
                core_radius: core,
                ..AeroOptions::default()
            };
            for &x in &[0.0, 0.1, 0.5, 0.7, 0.78, 0.79, 0.9, 1.0, 2.5, 10.0, 59.0] {
                for &y in &[-20.0, -1.0, -0.3, -0.01, 0.01, 0.3, 1.0, 20.0] {
                    let (a, b) = (o.g3(x, y, 0.0), o.g(x, y));
                    if b.is_finite() {
                        assert!(
                            (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                            "δ={core} x={x} y={y}: {a} vs {b}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn wake_names_round_trip() {
        for w in [Wake::Planar, Wake::ThreeD] {
            assert_eq!(w.name().parse::<Wake>().unwrap(), w);
            let json = serde_json::to_string(&w).unwrap();
            assert_eq!(json, format!("\"{}\"", w.name()));
        }
        assert!("sideways".parse::<Wake>().is_err());
    }
}
