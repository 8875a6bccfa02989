//! A second model of the savings, of the kind Lissaman & Shollenberger (1970) introduced and
//! Hainsworth (1987) and Cutts & Speakman (1994) applied to measured spacings: every bird an
//! **elliptically loaded lifting line** with a continuous, flat trailing vortex sheet.
//!
//! Takes lateral, fore-aft and vertical distances between birds in wingspans and gives the
//! fraction of a bird's solo induced power that another bird saves it, and the shape-level e_i.
//! Pure functions. Written from the lifting-line equations below, without any of Hummel's
//! closed form ([`super::AeroOptions::g`]): the two models share only their conventions.
//!
//! **The model.** Span b = 1, semi-span s = ½, circulation Γ(ξ) = Γ₀√(1 − ξ²/s²) along each
//! wing (the elliptic loading of least induced drag), shed as a sheet of trailing vortices of
//! strength γ = −dΓ/dξ that run straight downstream (+y, level). Bird i's interference drag in
//! the field of bird j is −ρ∫Γ_i u_j dη (u_j: j's upwash along i's lifting line), and its solo
//! induced drag ρ∫Γ_i w₀ dη with w₀ = Γ₀/(2b); the saving is their ratio,
//! e = (8/π)·∫Γ_i u_j dη for Γ₀ = 1. An element dξ of j's sheet at lateral offset d and height z
//! from a point y behind j's line induces the upwash (γ dξ/4π)·d/(d² + z²)·(1 + y/R), and an
//! element of j's bound vortex −(Γ dξ/4π)·y/R³ (R² = d² + y² + z²). Writing 1 + y/R =
//! (1 + sgn y) + (y/R − sgn y) splits j's upwash into
//!
//! * the Trefftz-plane field of the sheet, (1 + sgn y)/2 times the upwash far behind,
//!   u_∞ = (Γ₀/b)·Re(ζ/√(ζ² − s²) − 1) at ζ = η + iz (closed form; −Γ₀/b on the sheet itself,
//!   infinite only at its edges, where it is integrable), and
//! * a smooth remainder, (1/4π)∫[−sgn(y)·γ·d/(R(R + |y|)) − Γ·y/R³] dξ, evaluated by
//!   Gauss–Legendre quadrature in the angle τ (ξ = s cos τ, which absorbs the sheet's inverse
//!   square-root edges).
//!
//! The outer integral along i's span is split at j's wingtips (where u_∞ is singular) and each
//! piece is mapped by a smoothstep so that the square-root ends become smooth; Gauss–Legendre
//! again. There is no vortex core: the continuous sheet is finite off its edges, so the model's
//! numbers do not depend on `aero.core_radius`. Pairs whose wings overlap side by side collide, as in
//! Hummel's model.
//!
//! **Properties** (tested in `tests/lissaman.rs`): mirror symmetry in x; 0 for a lone bird;
//! savings that fall with distance; Munk's stagger theorem e_ij + e_ji = 2e_ij(y = 0) (the
//! remainder is odd under exchanging the two birds; to the quadrature's accuracy, about 10⁻⁶);
//! and, far apart, Hummel's model: both wings' far fields are that of a dipole of moment
//! Γ₀·πb/4, so the two models agree to leading order in 1/x² (the next order differs, as the
//! elliptic and the horseshoe's uniform loadings differ in their second moments).
//!
//! Symbols → code: x → `x` (how far the affected bird is to the side), y → `y` (how far it is
//! behind, negative: ahead), z → `z` (how far it is above), s → `S`.

use std::f64::consts::PI;
use std::sync::OnceLock;

/// Semi-span, wingspans.
const S: f64 = 0.5;

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n from Chebyshev guesses).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let mut x = (PI * (k as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for m in 2..=n {
                let p2 = ((2 * m - 1) as f64 * x * p1 - (m - 1) as f64 * p0) / m as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// A rule of `panels` equal panels of `per` nodes on [a, b].
fn composite(a: f64, b: f64, panels: usize, per: usize) -> Vec<(f64, f64)> {
    let gl = gauss_legendre(per);
    let h = (b - a) / panels as f64;
    let mut out = Vec::with_capacity(panels * per);
    for p in 0..panels {
        let lo = a + p as f64 * h;
        for &(t, w) in &gl {
            out.push((lo + 0.5 * h * (t + 1.0), 0.5 * h * w));
        }
    }
    out
}

/// The quadrature rules, built once: (inner rule over τ ∈ [0, π] as (cos τ, s·sin²τ·w, cos τ·w)
/// triples folded into weights, outer rule on [0, 1]), near and far.
struct Rules {
    inner_near: Vec<(f64, f64, f64)>,
    inner_far: Vec<(f64, f64, f64)>,
    outer_near: Vec<(f64, f64)>,
    outer_far: Vec<(f64, f64)>,
}

fn inner(panels: usize, per: usize) -> Vec<(f64, f64, f64)> {
    composite(0.0, PI, panels, per)
        .into_iter()
        .map(|(t, w)| {
            let (st, ct) = t.sin_cos();
            // (source position ξ, weight of the trailing term γ dξ, weight of the bound Γ dξ)
            (S * ct, ct * w, S * st * st * w)
        })
        .collect()
}

fn rules() -> &'static Rules {
    static R: OnceLock<Rules> = OnceLock::new();
    R.get_or_init(|| Rules {
        inner_near: inner(12, 8),
        inner_far: inner(2, 8),
        outer_near: composite(0.0, 1.0, 3, 8),
        outer_far: composite(0.0, 1.0, 1, 8),
    })
}

/// Upwash far behind an elliptically loaded sheet of semi-span S and Γ₀ = 1 (b = 1) at lateral
/// `p` and height `z` from its centre: Re(ζ/√(ζ² − s²) − 1), ζ = p + iz (principal roots of
/// ζ − s and ζ + s, so that the branch cut is the sheet).
fn trefftz(p: f64, z: f64) -> f64 {
    // √(ζ − s)·√(ζ + s) with principal complex square roots.
    let (ar, ai) = csqrt(p - S, z);
    let (br, bi) = csqrt(p + S, z);
    let (qr, qi) = (ar * br - ai * bi, ar * bi + ai * br);
    let den = qr * qr + qi * qi;
    if den == 0.0 {
        return f64::INFINITY;
    }
    // Re(ζ / q) − 1.
    (p * qr + z * qi) / den - 1.0
}

/// Principal square root of re + i·im.
fn csqrt(re: f64, im: f64) -> (f64, f64) {
    let m = re.hypot(im);
    let r = (0.5 * (m + re)).max(0.0).sqrt();
    let i = (0.5 * (m - re)).max(0.0).sqrt();
    if im < 0.0 {
        (r, -i)
    } else {
        (r, i)
    }
}

/// The smooth remainder of j's upwash at lateral `p` (from j's centre), `y` behind and `z`
/// above j's lifting line, Γ₀ = 1.
fn remainder(p: f64, y: f64, z: f64, rule: &[(f64, f64, f64)]) -> f64 {
    let sy = if y > 0.0 {
        1.0
    } else if y < 0.0 {
        -1.0
    } else {
        0.0
    };
    let ay = y.abs();
    let yz2 = y * y + z * z;
    let mut acc = 0.0;
    for &(xi, wt, wb) in rule {
        let d = p - xi;
        let r2 = d * d + yz2;
        let r = r2.sqrt();
        acc += -sy * wt * d / (r * (r + ay)) - wb * y / (r2 * r);
    }
    acc / (4.0 * PI)
}

/// The fraction of its solo induced power that a bird saves in the field of one other bird when
/// it flies `x` wingspans to the side of it (any sign), `y` behind it (negative: ahead) and `z`
/// above it (negative: below). NaN for non-finite input; infinite (or meaningless) where the
/// wings overlap side by side (|x| < 1 at y = z = 0), which callers refuse as a collision.
pub fn saving(x: f64, y: f64, z: f64) -> f64 {
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        return f64::NAN;
    }
    let x = x.abs();
    // Far (smooth integrands): at least 3 wingspans aside and 6 away.
    let near = x < 3.0 || x.hypot(y).hypot(z) < 6.0;
    let r = rules();
    if near {
        saving_with(x, y, z, &r.inner_near, &r.outer_near)
    } else {
        saving_with(x, y, z, &r.inner_far, &r.outer_far)
    }
}

/// [`saving`] for x ≥ 0 with the given rules.
fn saving_with(x: f64, y: f64, z: f64, inner: &[(f64, f64, f64)], outer: &[(f64, f64)]) -> f64 {
    let half = if y > 0.0 {
        1.0
    } else if y < 0.0 {
        0.0
    } else {
        0.5
    };
    // The receiving span [x − s, x + s], split at the source's wingtips ±s.
    let (lo, hi) = (x - S, x + S);
    let mut cuts = vec![lo];
    for t in [-S, S] {
        if t > lo && t < hi {
            cuts.push(t);
        }
    }
    cuts.push(hi);
    let mut total = 0.0;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        for &(v, wv) in outer.iter() {
            // Smoothstep: p = a + (b − a)(3v² − 2v³), dp = 6(b − a)v(1 − v) dv.
            let p = a + (b - a) * v * v * (3.0 - 2.0 * v);
            let jac = 6.0 * (b - a) * v * (1.0 - v);
            let eta = (p - x) / S;
            let gamma_i = (1.0 - eta * eta).max(0.0).sqrt();
            if gamma_i == 0.0 || jac == 0.0 {
                continue;
            }
            let mut u = remainder(p, y, z, inner);
            if half > 0.0 {
                u += half * trefftz(p, z);
            }
            total += wv * jac * gamma_i * u;
        }
    }
    8.0 / PI * total
}

/// e_i of every bird at lateral positions `x`, distances behind the leader `y` and heights `z`
/// (wingspans, input order): the sum over the other birds of [`saving`], each pair evaluated in
/// both directions. A pair whose wings overlap side by side closer than `chord` fore and aft is
/// evaluated `chord` apart (keeping its order; ties: the lower index in front), so every value
/// is finite; shapes checked for collisions are unaffected.
pub fn power(x: &[f64], y: &[f64], z: &[f64], chord: f64) -> Vec<f64> {
    let n = x.len();
    let mut e = vec![0.0; n];
    let chord = chord.max(1e-3);
    for i in 0..n {
        for j in (i + 1)..n {
            let dx = x[i] - x[j];
            let mut dy = y[i] - y[j];
            let dz = z.get(i).copied().unwrap_or(0.0) - z.get(j).copied().unwrap_or(0.0);
            if !(dx.is_finite() && dy.is_finite() && dz.is_finite()) {
                continue;
            }
            if dx.abs() < 1.0 && dy.abs() < chord {
                dy = if dy > 0.0 { chord } else { -chord };
            }
            e[i] += saving(dx, dy, dz);
            e[j] += saving(-dx, -dy, -dz);
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let gl = gauss_legendre(8);
        let s: f64 = gl.iter().map(|(x, w)| w * x.powi(14)).sum();
        assert!((s - 2.0 / 15.0).abs() < 1e-14, "{s}");
    }

    #[test]
    fn quadrature_is_converged() {
        // Against rules four times finer, over the region the tool evaluates (overlapping pairs
        // at least a collision chord apart fore and aft).
        let (fi, fo) = (inner(48, 8), composite(0.0, 1.0, 12, 8));
        let mut worst: f64 = 0.0;
        for &x in &[
            0.0, 0.3, 0.7, 0.95, 1.0, 1.02, 1.3, 2.0, 2.9, 3.1, 6.0, 20.0,
        ] {
            for &y in &[-8.0, -1.0, -0.13, 0.13, 0.5, 1.24, 6.0, 50.0] {
                for &z in &[0.0, 0.03, -0.14] {
                    let (a, b) = (saving(x, y, z), saving_with(x, y, z, &fi, &fo));
                    worst = worst.max((a - b).abs());
                }
            }
        }
        assert!(worst < 2e-4, "worst quadrature error {worst:e}");
    }

    #[test]
    fn trefftz_field_of_the_elliptic_sheet() {
        // Uniform downwash Γ₀/b on the sheet, 0 far away, s²/(2p²) outside far off.
        assert!((trefftz(0.2, 0.0) + 1.0).abs() < 1e-15);
        assert!((trefftz(-0.4, 0.0) + 1.0).abs() < 1e-15);
        let p = 50.0;
        assert!((trefftz(p, 0.0) - S * S / (2.0 * p * p)).abs() < 1e-8);
        assert!((trefftz(-p, 0.0) - S * S / (2.0 * p * p)).abs() < 1e-8);
        // Even in z.
        assert!((trefftz(0.7, 0.1) - trefftz(0.7, -0.1)).abs() < 1e-15);
    }
}
