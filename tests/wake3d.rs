//! The 3-D wake: g₃(x, y, z) against an independent numerical Biot–Savart integration (vector
//! segment law, integrated along the affected bird's span) at random offsets; at z = 0 it is the
//! planar g (ideal and cored); mirror symmetry in x and z, continuity in z, Munk's stagger
//! theorem at every height; the shape-level savings with heights; and `formation power` /
//! `formation solve` with `--wake`.

mod support;

use formation::aero::{self, AeroOptions, Wake, VORTEX_SPAN};
use support::{assert_usage_error, code, example, run, s, scratch, stderr, stdout};

const A: f64 = VORTEX_SPAN;
const S: f64 = VORTEX_SPAN / 2.0;
const TWO_OVER_PI2: f64 = 2.0 / (std::f64::consts::PI * std::f64::consts::PI);

fn ideal() -> AeroOptions {
    AeroOptions {
        core_radius: 0.0,
        ..AeroOptions::default()
    }
}

fn three_d(core: f64) -> AeroOptions {
    AeroOptions {
        core_radius: core,
        wake: Wake::ThreeD,
        ..AeroOptions::default()
    }
}

/// A small deterministic generator (SplitMix64) for the random offsets and flocks.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

// ---------------------------------------------------------------------------------------------
// Independent reference. Bird j's horseshoe vortex (Γ/4π = 1) as three straight segments in
// (lateral X, downstream Y, up Z): from far downstream along X = +s to the wing, across the wing
// to X = −s, and back downstream (the orientation that gives downwash behind a lifting wing).
// The vertical velocity of each segment comes from the vector Biot–Savart law of a straight
// segment; bird i's bound vortex spans [x − s, x + s] at (Y, Z) = (y, z), and the upwash is
// integrated along it numerically. (π²/2)·g₃ = ∫ w dX, the normalisation of the planar model
// (checked here too at z = 0, against the planar g).
// ---------------------------------------------------------------------------------------------

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// Velocity at `p` of a straight vortex segment from `a` to `b` with Γ = 4π:
/// (r₁ × r₂)/|r₁ × r₂|² · r₀·(r₁/|r₁| − r₂/|r₂|).
fn segment(p: V3, a: V3, b: V3) -> V3 {
    let (r1, r2, r0) = (sub(p, a), sub(p, b), sub(b, a));
    let c = cross(r1, r2);
    let c2 = dot(c, c);
    let (n1, n2) = (norm(r1), norm(r2));
    let k = (dot(r0, r1) / n1 - dot(r0, r2) / n2) / c2;
    [c[0] * k, c[1] * k, c[2] * k]
}

/// Vertical velocity of bird j's horseshoe at `p` (trailing vortices 10⁷ wingspans long: the
/// rest changes the velocity by less than 10⁻¹⁴).
fn upwash(p: V3) -> f64 {
    const FAR: f64 = 1e7;
    let segs = [
        ([S, FAR, 0.0], [S, 0.0, 0.0]),
        ([S, 0.0, 0.0], [-S, 0.0, 0.0]),
        ([-S, 0.0, 0.0], [-S, FAR, 0.0]),
    ];
    segs.iter().map(|&(a, b)| segment(p, a, b)[2]).sum()
}

/// Vertical velocity at `p` of bird j's horseshoe whose trailing vortices sink at slope `sigma`
/// (the segments from the wingtips run along (0, cos β, −sin β), tan β = σ).
fn upwash_descending(p: V3, sigma: f64) -> f64 {
    const FAR: f64 = 1e7;
    let cb = 1.0 / (1.0 + sigma * sigma).sqrt();
    let (fy, fz) = (FAR * cb, -FAR * sigma * cb);
    let segs = [
        ([S, fy, fz], [S, 0.0, 0.0]),
        ([S, 0.0, 0.0], [-S, 0.0, 0.0]),
        ([-S, 0.0, 0.0], [-S, fy, fz]),
    ];
    segs.iter().map(|&(a, b)| segment(p, a, b)[2]).sum()
}

/// Adaptive Simpson quadrature of `f` over [a, b] to absolute tolerance `tol`.
fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    /// One panel [a, b] with f at a, the midpoint and b, and its Simpson value `whole`.
    fn rec(
        f: &dyn Fn(f64) -> f64,
        ab: (f64, f64),
        fv: [f64; 3],
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let (a, b) = ab;
        let [fa, fm, fb] = fv;
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        let delta = left + right - whole;
        if depth == 0 || delta.abs() <= 15.0 * tol {
            left + right + delta / 15.0
        } else {
            rec(f, (a, m), [fa, flm, fm], left, 0.5 * tol, depth - 1)
                + rec(f, (m, b), [fm, frm, fb], right, 0.5 * tol, depth - 1)
        }
    }
    let m = 0.5 * (a + b);
    let fv = [f(a), f(m), f(b)];
    let whole = (b - a) / 6.0 * (fv[0] + 4.0 * fv[1] + fv[2]);
    rec(f, (a, b), fv, whole, tol, 50)
}

/// g₃ by numerical Biot–Savart integration (ideal vortices), split where the integrand varies
/// fastest: over j's trailing vortices and its centre line.
fn g3_biot_savart(x: f64, y: f64, z: f64) -> f64 {
    let (lo, hi) = (x - S, x + S);
    let mut cuts = vec![lo, hi];
    for c in [-S, 0.0, S] {
        if lo < c && c < hi {
            cuts.push(c);
        }
    }
    cuts.sort_by(f64::total_cmp);
    let f = |xi: f64| upwash([xi, y, z]);
    let integral: f64 = cuts
        .windows(2)
        .map(|w| simpson(&f, w[0], w[1], 1e-11))
        .sum();
    TWO_OVER_PI2 * integral
}

#[test]
fn g3_matches_numerical_biot_savart_at_random_offsets() {
    let o = ideal();
    let mut rng = Rng(7);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    while checked < 300 {
        let x = rng.range(-3.0, 3.0);
        let y = rng.range(-4.0, 4.0);
        let z = rng.range(-1.5, 1.5);
        // Ideal vortices: stay off the lines where i's wingtip or centre meets j's vortex.
        let near_line = [x.abs() - A, x.abs(), x.abs() - 2.0 * S]
            .iter()
            .any(|d| d.abs() < 0.03);
        if z.abs() < 0.03 && (near_line || y.abs() < 0.1) {
            continue;
        }
        let (got, want) = (o.g3(x, y, z), g3_biot_savart(x, y, z));
        let err = (got - want).abs();
        worst = worst.max(err);
        assert!(
            err < 1e-6,
            "x={x} y={y} z={z}: g3 {got}, Biot–Savart {want}"
        );
        checked += 1;
    }
    // The reference itself agrees with the planar model in the plane, away from its lines.
    for &(x, y) in &[(1.2, 0.6), (0.9, -0.8), (2.0, 3.0), (1.6, 1.5), (1.0, -0.4)] {
        let (got, want) = (o.g(x, y), g3_biot_savart(x, y, 0.0));
        assert!((got - want).abs() < 1e-6, "x={x} y={y}: g {got} vs {want}");
    }
    eprintln!("worst |g3 − Biot–Savart| over {checked} offsets: {worst:e}");
}

/// Vertical velocity of a cored trailing vortex (Γ/4π = 1) starting at the wing, at lateral
/// offset `c`, vertical offset `z`, `y` behind its start: the ideal semi-infinite vortex's
/// (c/h²)(1 + y/√(h² + y²)), h² = c² + z², with the model's core on the radial distance
/// (h² → ρ² = h² + δ²e^{−h²/δ²} and the circulation inside radius h scaled by 1 − e^{−h²/δ²}).
fn cored_trailing(c: f64, y: f64, z: f64, core: f64) -> f64 {
    let h2 = c * c + z * z;
    let e = (-h2 / (core * core)).exp();
    let rho2 = h2 + core * core * e;
    c * (1.0 - e) / rho2 * (1.0 + y / (rho2 + y * y).sqrt())
}

#[test]
fn descending_wake_matches_numerical_biot_savart() {
    let mut rng = Rng(17);
    let mut checked = 0;
    while checked < 200 {
        let sigma = rng.range(0.0, aero::MAX_WAKE_DESCENT);
        let o = AeroOptions {
            core_radius: 0.0,
            wake: Wake::ThreeD,
            wake_descent: sigma,
            ..AeroOptions::default()
        };
        let (x, y, z) = (
            rng.range(-3.0, 3.0),
            rng.range(-4.0, 4.0),
            rng.range(-1.0, 1.0),
        );
        // Height above the sunk trailing vortex: stay off the ideal vortices' lines.
        let cb = 1.0 / (1.0 + sigma * sigma).sqrt();
        let above = (y * sigma + z) * cb;
        let near_line = [x.abs() - A, x.abs(), x.abs() - 2.0 * S]
            .iter()
            .any(|d| d.abs() < 0.03);
        if (above.abs() < 0.03 && (near_line || y.abs() < 0.1)) || (z.abs() < 0.03 && y.abs() < 0.1)
        {
            continue;
        }
        let (lo, hi) = (x - S, x + S);
        let mut cuts = vec![lo, hi];
        for c in [-S, 0.0, S] {
            if lo < c && c < hi {
                cuts.push(c);
            }
        }
        cuts.sort_by(f64::total_cmp);
        let f = |xi: f64| upwash_descending([xi, y, z], sigma);
        let want = TWO_OVER_PI2
            * cuts
                .windows(2)
                .map(|w| simpson(&f, w[0], w[1], 1e-11))
                .sum::<f64>();
        let got = o.g3(x, y, z);
        assert!(
            (got - want).abs() < 1e-6,
            "σ={sigma} x={x} y={y} z={z}: g3 {got}, Biot–Savart {want}"
        );
        checked += 1;
    }
}

#[test]
fn descending_wake_in_shapes_and_its_limits() {
    let level = three_d(0.04);
    let sunk = AeroOptions {
        wake_descent: 0.01,
        ..level
    };
    // A follower level with the leader sits above the sunk vortex: it saves less than with a
    // level wake; one that sits where the vortex has sunk to saves about the level peak.
    let (x, y) = (0.77, 1.24);
    assert!(sunk.g3(x, y, 0.0) < level.g3(x, y, 0.0));
    assert!((sunk.g3(x, y, -0.01 * y) - level.g3(x, y, 0.0)).abs() < 0.01);
    // Ahead of the other bird the trailing vortices barely matter.
    assert!((sunk.g3(x, -1.0, 0.0) - level.g3(x, -1.0, 0.0)).abs() < 1e-3);
    let mut rng = Rng(3);
    for _ in 0..20 {
        let n = 6;
        let (x, y, z) = flock(&mut rng, n);
        let e = sunk.power_reduction_3d(&x, &y, &z).unwrap();
        for i in 0..n {
            let sum: f64 = (0..n)
                .filter(|&j| j != i)
                .map(|j| sunk.g3(x[i] - x[j], y[i] - y[j], z[i] - z[j]))
                .sum();
            assert!((sum - e.e[i]).abs() < 1e-12 * sum.abs().max(1.0));
        }
    }
    for (bad, wake) in [
        (-0.01, Wake::ThreeD),
        (f64::NAN, Wake::ThreeD),
        (0.5, Wake::ThreeD),
        (0.01, Wake::Planar),
    ] {
        let o = AeroOptions {
            wake,
            wake_descent: bad,
            ..AeroOptions::default()
        };
        let err = o.validate().unwrap_err().to_string();
        assert!(err.contains("aero.wake_descent"), "{err}");
    }
}

#[test]
fn cored_g3_matches_numerical_integration_of_the_cored_field() {
    let mut rng = Rng(5);
    for core in [0.04, 0.16] {
        let o = three_d(core);
        for _ in 0..100 {
            let (x, y, z) = (
                rng.range(-3.0, 3.0),
                rng.range(-4.0, 4.0),
                rng.range(-1.0, 1.0),
            );
            if y.abs() < 0.05 && x.abs() < 1.0 {
                continue;
            }
            let bound = |xi: f64| segment([xi, y, z], [S, 0.0, 0.0], [-S, 0.0, 0.0])[2];
            let f = |xi: f64| {
                cored_trailing(xi - S, y, z, core) - cored_trailing(xi + S, y, z, core) + bound(xi)
            };
            let (lo, hi) = (x - S, x + S);
            let mut cuts = vec![lo, hi];
            for c in [-S, 0.0, S] {
                if lo < c && c < hi {
                    cuts.push(c);
                }
            }
            cuts.sort_by(f64::total_cmp);
            let want = TWO_OVER_PI2
                * cuts
                    .windows(2)
                    .map(|w| simpson(&f, w[0], w[1], 1e-11))
                    .sum::<f64>();
            let got = o.g3(x, y, z);
            assert!(
                (got - want).abs() < 1e-6 * want.abs().max(1.0),
                "δ={core} x={x} y={y} z={z}: g3 {got}, integral {want}"
            );
        }
    }
}

#[test]
fn at_zero_height_g3_is_the_planar_g_with_and_without_core() {
    let mut rng = Rng(11);
    for core in [0.0, 0.01, 0.04, 0.16, 0.35] {
        let o = AeroOptions {
            core_radius: core,
            ..AeroOptions::default()
        };
        let mut compared = 0;
        for _ in 0..4000 {
            let x = rng.range(-8.0, 8.0) * rng.next();
            let y = rng.range(-10.0, 10.0) * rng.next();
            let (a, b) = (o.g3(x, y, 0.0), o.g(x, y));
            if !b.is_finite() {
                assert!(core == 0.0 || y == 0.0, "x={x} y={y} δ={core}");
                continue;
            }
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                "δ={core} x={x} y={y}: g3 {a} g {b}"
            );
            compared += 1;
        }
        assert!(compared > 3900, "δ={core}: {compared}");
        // And on a grid through both singular lines and the fore-aft axis.
        for i in 0..=120 {
            let x = i as f64 * 0.025;
            for k in -40..=40 {
                let y = k as f64 * 0.1;
                let b = o.g(x, y);
                if b.is_finite() {
                    let a = o.g3(x, y, 0.0);
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                        "δ={core} x={x} y={y}: g3 {a} g {b}"
                    );
                }
            }
        }
    }
}

#[test]
fn mirror_symmetric_even_in_height_and_munk_at_every_height() {
    let mut rng = Rng(23);
    for core in [0.0, 0.04] {
        let o = three_d(core);
        for _ in 0..2000 {
            let x = rng.range(0.0, 6.0);
            let y = rng.range(0.05, 8.0);
            let z = rng.range(0.02, 2.0);
            let g = o.g3(x, y, z);
            assert!(g.is_finite(), "x={x} y={y} z={z}");
            assert_eq!(g, o.g3(-x, y, z));
            assert_eq!(g, o.g3(x, y, -z));
            let sum = g + o.g3(x, -y, z);
            let g0 = o.g3_0(x, z);
            assert!(
                (sum - 2.0 * g0).abs() <= 1e-12 * g0.abs().max(1.0),
                "x={x} y={y} z={z}: {sum} vs {}",
                2.0 * g0
            );
            // The bird at y = 0 beside the other gets the mean of the two shares.
            assert!((o.g3(x, 0.0, z) - g0).abs() <= 1e-12 * g0.abs().max(1.0));
        }
        // Far above or below, no interaction.
        for &(x, y) in &[(0.0, 1.0), (1.0, 2.0), (0.5, -1.0)] {
            assert!(o.g3(x, y, 1e4).abs() < 1e-7, "x={x} y={y}");
        }
    }
}

#[test]
fn continuous_in_height_including_the_plane_and_the_branch_switch() {
    for core in [0.0, 0.04] {
        let o = three_d(core);
        for &x in &[0.0, 0.3, 0.6, 0.9, 1.0, 1.5, 3.0] {
            for &y in &[-2.0, -0.5, 0.3, 1.0, 4.0] {
                let at0 = o.g3(x, y, 0.0);
                if !at0.is_finite() {
                    continue;
                }
                for &dz in &[1e-9, 1e-7, 1e-5] {
                    let d = (o.g3(x, y, dz) - at0).abs();
                    assert!(d < 1e-3 * dz.sqrt(), "δ={core} x={x} y={y} dz={dz}: {d}");
                }
                // Across √(y² + z²) = x, where the evaluation changes form.
                if x * x > y * y {
                    let z = (x * x - y * y).sqrt();
                    let (lo, hi) = (o.g3(x, y, z * (1.0 - 1e-12)), o.g3(x, y, z * (1.0 + 1e-12)));
                    assert!(
                        (lo - hi).abs() < 1e-11,
                        "δ={core} x={x} y={y} z={z}: {lo} {hi}"
                    );
                }
            }
        }
    }
    // With the default core, small steps in z change g3 little everywhere, the plane included
    // (a Lipschitz bound of 50 per wingspan of height: no jump between the forms).
    let o = three_d(aero::DEFAULT_CORE_RADIUS);
    for i in 0..60 {
        let x = 0.05 * i as f64;
        for &y in &[-0.8, 0.8] {
            let mut prev = o.g3(x, y, 0.0);
            for k in 1..=500 {
                let g = o.g3(x, y, 0.002 * k as f64);
                assert!((g - prev).abs() < 0.1, "x={x} y={y} step {k}: {prev} → {g}");
                prev = g;
            }
        }
    }
}

#[test]
fn side_by_side_at_different_heights() {
    // Abreast (y = 0) the bound vortex induces nothing off its plane, and g3 tends to the planar
    // g(x, 0) as z → 0, also for tiny heights whose square underflows.
    for core in [0.0, 0.04] {
        let o = three_d(core);
        for &x in &[0.85, 1.0, 1.5, 4.0] {
            let g0 = o.g(x, 0.0);
            for &z in &[1e-300, 1e-150, 1e-20, 1e-8] {
                let g = o.g3(x, 0.0, z);
                assert!((g - g0).abs() < 1e-6, "δ={core} x={x} z={z}: {g} vs {g0}");
            }
            for &y in &[1e-200, -1e-200] {
                let g = o.g3(x, y, 1e-200);
                assert!(g.is_finite(), "δ={core} x={x} y={y}: {g}");
            }
        }
        // Overlapping wingtips abreast are a collision in the plane, finite off it: the mean
        // of the two shares (Munk).
        for &x in &[0.2, 0.5, 0.7] {
            for &z in &[1e-250, 0.01, 0.3] {
                let g = o.g3(x, 0.0, z);
                assert!((g - o.g3_0(x, z)).abs() < 1e-12, "δ={core} x={x} z={z}");
            }
        }
    }
}

#[test]
fn a_height_difference_costs_the_follower_on_the_vortex_line() {
    // On the line where the follower's wingtip meets the other's trailing vortex (x = a), height
    // detunes the upwash peak: the saving falls with |z| over the first half wingspan, with the
    // default core.
    let o = three_d(aero::DEFAULT_CORE_RADIUS);
    let mut prev = o.g3(A, 1.0, 0.0);
    for k in 1..=20 {
        let g = o.g3(A, 1.0, 0.025 * k as f64);
        assert!(g < prev, "z={}: {g} ≥ {prev}", 0.025 * k as f64);
        prev = g;
    }
}

/// A random collision-free flock of `n` birds (at least one wingspan apart laterally or at least
/// half a wingspan fore and aft), with heights.
fn flock(rng: &mut Rng, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    while x.len() < n {
        let (a, b) = (rng.range(-6.0, 6.0), rng.range(0.0, 8.0));
        if x.iter()
            .zip(&y)
            .all(|(&p, &q): (&f64, &f64)| (a - p).abs() >= 1.0 || (b - q).abs() >= 0.5)
        {
            x.push(a);
            y.push(b);
            z.push(rng.range(-0.3, 0.3));
        }
    }
    (x, y, z)
}

#[test]
fn shape_savings_with_heights() {
    let mut rng = Rng(31);
    for trial in 0..40 {
        let n = 2 + trial % 14;
        let (x, y, z) = flock(&mut rng, n);
        let zero = vec![0.0; n];
        for core in [0.0, 0.04] {
            let planar = AeroOptions {
                core_radius: core,
                ..AeroOptions::default()
            };
            let o = three_d(core);
            let flat = planar.power_reduction(&x, &y);
            let Ok(flat) = flat else { continue };
            // 3-D with every bird at one height: the planar savings.
            let same = o.power_reduction_3d(&x, &y, &zero).unwrap();
            for i in 0..n {
                assert!(
                    (same.e[i] - flat.e[i]).abs() <= 1e-12 * flat.e[i].abs().max(1.0),
                    "trial {trial} bird {i}: {} vs {}",
                    same.e[i],
                    flat.e[i]
                );
            }
            // The planar wake ignores heights.
            assert_eq!(planar.power_reduction_3d(&x, &y, &z).unwrap(), flat);
            // With heights: Munk's theorem (E independent of fore-aft moves), a common height
            // shift and a mirror change nothing, each bird's e is the sum of its pairs' g3.
            let e = o.power_reduction_3d(&x, &y, &z).unwrap();
            let munk = o.munk_total_3d_unchecked(&x, &z);
            assert!((e.total - munk).abs() < 1e-10 * munk.abs().max(1.0));
            let shifted: Vec<f64> = z.iter().map(|v| v + 0.37).collect();
            let mx: Vec<f64> = x.iter().map(|v| -v).collect();
            let mz: Vec<f64> = z.iter().map(|v| -v).collect();
            for other in [
                o.power_reduction_3d(&x, &y, &shifted).unwrap(),
                o.power_reduction_3d(&mx, &y, &z).unwrap(),
                o.power_reduction_3d(&x, &y, &mz).unwrap(),
            ] {
                for i in 0..n {
                    assert!((other.e[i] - e.e[i]).abs() < 1e-12 * e.e[i].abs().max(1.0));
                }
            }
            for i in 0..n {
                let sum: f64 = (0..n)
                    .filter(|&j| j != i)
                    .map(|j| o.g3(x[i] - x[j], y[i] - y[j], z[i] - z[j]))
                    .sum();
                assert!((sum - e.e[i]).abs() < 1e-12 * sum.abs().max(1.0));
            }
            let moved: Vec<f64> = y.iter().map(|v| v * 1.3 + 0.2).collect();
            if let Ok(m) = o.power_reduction_3d(&x, &moved, &z) {
                assert!((m.total - e.total).abs() < 1e-10 * e.total.abs().max(1.0));
            }
        }
    }
}

#[test]
fn bad_heights_are_named() {
    let o = three_d(0.04);
    let err = o
        .power_reduction_3d(&[0.0, 1.0], &[0.0, 1.0], &[0.0, f64::NAN])
        .unwrap_err();
    assert!(err.to_string().contains("z[1]"), "{err}");
    let err = o
        .power_reduction_3d(&[0.0, 1.0], &[0.0, 1.0], &[0.0])
        .unwrap_err();
    assert!(err.to_string().contains('z'), "{err}");
    // Side by side with overlapping wings collides at any height.
    assert!(o
        .power_reduction_3d(&[0.0, 0.5], &[0.0, 0.0], &[0.0, 0.2])
        .is_err());
}

// --------------------------------------------------------------------------------------------
// Through the binary.
// --------------------------------------------------------------------------------------------

fn power_json(shape: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["power", s(shape), "--json"];
    args.extend_from_slice(extra);
    let out = run(&args);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    serde_json::from_str(&stdout(&out)).unwrap()
}

fn savings(v: &serde_json::Value) -> Vec<f64> {
    v["birds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["e"].as_f64().unwrap())
        .collect()
}

#[test]
fn power_with_the_3d_wake_uses_heights() {
    let dir = scratch("wake3d-power");
    let flat = dir.join("flat.json");
    let high = dir.join("high.json");
    let birds = [(0.0, 0.0), (0.8, 0.6), (-0.8, 0.6), (1.6, 1.2), (-1.6, 1.2)];
    let heights = [0.0, 0.08, -0.05, 0.15, 0.02];
    let doc = |zs: &[f64]| {
        let b: Vec<serde_json::Value> = birds
            .iter()
            .zip(zs)
            .map(|(&(x, y), &z)| {
                if z == 0.0 {
                    serde_json::json!({"x": x, "y": y})
                } else {
                    serde_json::json!({"x": x, "y": y, "z": z})
                }
            })
            .collect();
        serde_json::json!({ "birds": b }).to_string()
    };
    std::fs::write(&flat, doc(&[0.0; 5])).unwrap();
    std::fs::write(&high, doc(&heights)).unwrap();

    let planar_flat = power_json(&flat, &[]);
    let three_flat = power_json(&flat, &["--wake", "3d"]);
    let planar_high = power_json(&high, &["--wake", "planar"]);
    let three_high = power_json(&high, &["--wake", "3d"]);
    // All in one plane: the 3-D wake gives the planar savings.
    for (a, b) in savings(&planar_flat).iter().zip(savings(&three_flat)) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    // The planar wake ignores heights (same savings as the flat shape), and the output carries
    // each bird's height.
    assert_eq!(savings(&planar_high), savings(&planar_flat));
    assert_eq!(planar_high["birds"][3]["z"].as_f64(), Some(0.15));
    assert!(planar_flat["birds"][3].get("z").is_none());
    // With heights the 3-D wake changes the flock's saving, and each bird's is the library's.
    let (p, t) = (
        planar_high["flock_saving"].as_f64().unwrap(),
        three_high["flock_saving"].as_f64().unwrap(),
    );
    assert!((p - t).abs() > 1e-3, "planar {p} 3d {t}");
    let x: Vec<f64> = birds.iter().map(|b| b.0).collect();
    let y: Vec<f64> = birds.iter().map(|b| b.1).collect();
    let lib = three_d(aero::DEFAULT_CORE_RADIUS)
        .power_reduction_3d(&x, &y, &heights)
        .unwrap();
    for (a, b) in savings(&three_high).iter().zip(&lib.e) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    // The sensitivity over the core uses the same wake: its default-core entry is the saving.
    let default_entry = three_high["sensitivity"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["core_radius"].as_f64() == Some(aero::DEFAULT_CORE_RADIUS))
        .unwrap()["flock_saving"]
        .as_f64()
        .unwrap();
    assert_eq!(default_entry, t);
    // The table names the wake.
    let out = run(&["power", s(&high), "--wake", "3d"]);
    assert_eq!(code(&out), 0);
    assert!(stdout(&out).contains("in 3-D"), "{}", stdout(&out));
    // A sinking wake changes the followers' savings; it needs the 3-D wake.
    let sunk = power_json(&high, &["--wake", "3d", "--wake-descent", "0.01"]);
    assert!(savings(&sunk)
        .iter()
        .zip(savings(&three_high))
        .any(|(a, b)| (a - b).abs() > 1e-3));
    let out = run(&["power", s(&high), "--wake-descent", "0.01"]);
    assert_usage_error(&out, &["--wake-descent", "--wake 3d"]);
}

#[test]
fn unknown_wake_is_a_usage_error_naming_the_flag() {
    let dir = scratch("wake3d-bad");
    let shape = dir.join("s.json");
    std::fs::write(&shape, r#"{"birds": [{"x": 0, "y": 0}, {"x": 1, "y": 1}]}"#).unwrap();
    let target = example("equal_savings_target.json");
    let out_shape = dir.join("out.json");
    for args in [
        vec!["power", s(&shape), "--wake", "sideways"],
        vec![
            "solve",
            s(&target),
            "-o",
            s(&out_shape),
            "--wake",
            "sideways",
        ],
    ] {
        let out = run(&args);
        assert_usage_error(&out, &["--wake", "sideways"]);
        assert!(!out_shape.exists());
    }
    // A height that is not a number is refused naming the bird.
    std::fs::write(
        &shape,
        r#"{"birds": [{"x": 0, "y": 0}, {"x": 1, "y": 1, "z": "high"}]}"#,
    )
    .unwrap();
    let out = run(&["power", s(&shape), "--wake", "3d"]);
    assert_eq!(code(&out), 2, "{}", stderr(&out));
}

#[test]
fn solve_with_the_3d_wake_gives_the_planar_key_shape() {
    let dir = scratch("wake3d-solve");
    let target = example("equal_savings_target.json");
    let mut ys = Vec::new();
    for wake in ["planar", "3d"] {
        let out = dir.join(format!("{wake}.json"));
        let r = run(&[
            "solve",
            s(&target),
            "-o",
            s(&out),
            "--wake",
            wake,
            "--quiet",
        ]);
        assert_eq!(code(&r), 0, "{}", stderr(&r));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        assert_eq!(v["converged"], true);
        let y: Vec<f64> = v["birds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                assert!(b.get("z").is_none(), "{b}");
                b["y"].as_f64().unwrap()
            })
            .collect();
        // The solved shape, read back with the 3-D wake, has the target's equal savings.
        let p = power_json(&out, &["--wake", "3d"]);
        for b in p["birds"].as_array().unwrap() {
            assert!((b["xi"].as_f64().unwrap() - 1.0 / 9.0).abs() < 1e-9);
        }
        ys.push(y);
    }
    assert_eq!(ys[0], ys[1]);
}

#[test]
fn a_steady_flight_with_the_3d_wake_flies_the_same_and_saves_by_its_heights() {
    let dir = scratch("wake3d-steady");
    let params = support::repo_file("tests/data/steady_v9_params.json");
    let fly = |wake: &str| {
        let out = dir.join(format!("{wake}.json"));
        let o = run(&[
            "steady",
            s(&params),
            "--birds",
            "9",
            "--seconds",
            "6",
            "--wake",
            wake,
            "-o",
            s(&out),
        ]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        formation::Animation::read(&out).unwrap()
    };
    let (planar, three) = (fly("planar"), fly("3d"));
    assert_eq!(planar.savings_model.as_ref().unwrap().wake, "planar");
    assert_eq!(three.savings_model.as_ref().unwrap().wake, "3d");
    // The same motion: the key shapes are solved in the plane either way.
    let mut differ = 0;
    for (a, b) in planar.frames.iter().zip(&three.frames) {
        assert_eq!((&a.x, &a.y, &a.z), (&b.x, &b.y, &b.z));
        let (ea, eb) = (a.e.as_ref().unwrap(), b.e.as_ref().unwrap());
        // The birds fly at slightly different heights, which the 3-D wake sees.
        if ea.iter().zip(eb).any(|(p, q)| (p - q).abs() > 1e-9) {
            differ += 1;
        }
        // Every saving finite, the shares a partition of the flock's total.
        assert!(eb.iter().all(|v| v.is_finite()));
    }
    assert!(
        differ * 2 > three.frames.len(),
        "3-D savings differ in {differ} frames"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
