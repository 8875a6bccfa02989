//! The key-shape solve (eq. 4): round trips shape → ξ → solved shape → same ξ, Hummel's
//! equal-savings U, and unreachable targets named.

use formation::aero::power_reduction;
use formation::keyshape::{solve, SolveOptions};
use formation::Error;
use proptest::prelude::*;

/// A V: leader at x = 0, `left` birds to the left and `right` to the right, lateral gaps and
/// per-bird depth increments given.
fn v_shape(
    gaps_l: &[f64],
    gaps_r: &[f64],
    depth_l: &[f64],
    depth_r: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut y) = (vec![0.0], vec![0.0]);
    let (mut ax, mut ay) = (0.0, 0.0);
    for (g, d) in gaps_l.iter().zip(depth_l) {
        ax -= g;
        ay += d;
        x.push(ax);
        y.push(ay);
    }
    let (mut ax, mut ay) = (0.0, 0.0);
    for (g, d) in gaps_r.iter().zip(depth_r) {
        ax += g;
        ay += d;
        x.push(ax);
        y.push(ay);
    }
    (x, y)
}

fn v_strategy() -> impl Strategy<Value = (Vec<f64>, Vec<f64>, Vec<f64>)> {
    (1usize..12, 1usize..12).prop_flat_map(|(l, r)| {
        (
            prop::collection::vec(0.6f64..1.6, l),
            prop::collection::vec(0.6f64..1.6, r),
            prop::collection::vec(0.3f64..1.5, l),
            prop::collection::vec(0.3f64..1.5, r),
            prop::collection::vec(-0.1f64..0.1, l + r + 1),
        )
            .prop_map(|(gl, gr, dl, dr, noise)| {
                let (x, y) = v_shape(&gl, &gr, &dl, &dr);
                let guess: Vec<f64> = y.iter().zip(&noise).map(|(a, b)| a + b).collect();
                (x, y, guess)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random V (lateral gaps 0.6–1.6 wingspans: wingtips often overlapping) → ξ → solve from a
    /// perturbed guess (same fore-aft order) → the same ξ (and the same shape).
    #[test]
    fn round_trip((x, y, guess) in v_strategy()) {
        // The noise can bring two overlapping neighbours of the guess closer fore and aft than
        // the collision distance; the solver rightly refuses such a start (Error::Collision),
        // so it is no valid input here.
        prop_assume!(power_reduction(&x, &guess).is_ok());
        let xi = power_reduction(&x, &y).unwrap().xi;
        let rep = solve(&x, &xi, Some(&guess), &SolveOptions::default()).unwrap();
        prop_assert!(rep.converged, "residual {}", rep.residual);
        let again = power_reduction(&x, &rep.y).unwrap().xi;
        for (a, b) in again.iter().zip(&xi) {
            prop_assert!((a - b).abs() < 1e-8);
        }
        // Unique up to a shift: the same positions (leader at 0 in both).
        for (a, b) in rep.y.iter().zip(&y) {
            prop_assert!((a - b).abs() < 1e-5, "{} vs {}", a, b);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Real spacing (the stereo-filmed geese: nearest bird ahead 0.62–0.88 wingspans to the
    /// side, 1.06–1.49 behind): round trip from the solver's own start and from a perturbed one.
    #[test]
    fn round_trip_at_real_spacing(
        (gl, gr) in (1usize..10, 1usize..10).prop_flat_map(|(l, r)| (
            prop::collection::vec((0.6f64..0.8, 1.06f64..1.49), l),
            prop::collection::vec((0.6f64..0.8, 1.06f64..1.49), r),
        )),
        noise in prop::collection::vec(-0.2f64..0.2, 19),
    ) {
        let gaps_l: Vec<f64> = gl.iter().map(|p| p.0).collect();
        let depth_l: Vec<f64> = gl.iter().map(|p| p.1).collect();
        let gaps_r: Vec<f64> = gr.iter().map(|p| p.0).collect();
        let depth_r: Vec<f64> = gr.iter().map(|p| p.1).collect();
        let (x, y) = v_shape(&gaps_l, &gaps_r, &depth_l, &depth_r);
        let xi = power_reduction(&x, &y).unwrap().xi;
        let guess: Vec<f64> = y.iter().zip(&noise).map(|(a, b)| a + b).collect();
        for start in [Some(&guess[..]), None] {
            let rep = solve(&x, &xi, start, &SolveOptions::default()).unwrap();
            prop_assert!(rep.converged, "residual {}", rep.residual);
            for (a, b) in rep.y.iter().zip(&y) {
                prop_assert!((a - b).abs() < 1e-5, "{} vs {}", a, b);
            }
        }
    }
}

#[test]
fn round_trip_from_the_neutral_start_for_large_flocks() {
    for n_side in [5usize, 20, 150] {
        let gaps = vec![1.05; n_side];
        let depth: Vec<f64> = (0..n_side).map(|k| 0.5 + 0.02 * k as f64).collect();
        let (x, y) = v_shape(&gaps, &gaps, &depth, &depth);
        let xi = power_reduction(&x, &y).unwrap().xi;
        let rep = solve(&x, &xi, None, &SolveOptions::default()).unwrap();
        assert!(rep.converged, "N = {}: residual {}", x.len(), rep.residual);
    }
}

/// Large flocks (the Newton–conjugate-gradient solve beyond `dense_limit`) at real spacing:
/// lateral gaps around 0.77 wingspans (overlapping wingtips), 1.24 back per rank, from a
/// perturbed start and from the solver's own start; the shape comes back to 10⁻⁶ wingspans.
#[test]
fn large_flocks_at_real_spacing_round_trip() {
    for n_side in [200usize, 450] {
        let gaps: Vec<f64> = (0..n_side)
            .map(|k| 0.77 + 0.08 * (k as f64 * 0.9).sin())
            .collect();
        let depth: Vec<f64> = (0..n_side)
            .map(|k| 1.24 + 0.15 * (k as f64 * 1.3).cos())
            .collect();
        let (x, y) = v_shape(&gaps, &gaps, &depth, &depth);
        let xi = power_reduction(&x, &y).unwrap().xi;
        let guess: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(k, v)| v + 0.2 * (k as f64 * 2.3).cos())
            .collect();
        for start in [Some(guess.as_slice()), None] {
            let rep = solve(&x, &xi, start, &SolveOptions::default()).unwrap();
            assert!(rep.converged, "N = {}: {rep:?}", x.len());
            for (a, b) in rep.y.iter().zip(&y) {
                assert!((a - b).abs() < 1e-6, "N = {}: {a} vs {b}", x.len());
            }
        }
    }
}

/// From `SolveOptions::interpolate_from` birds the iteration runs on interpolated far sums and
/// its result is checked with the exact ones: the same shape as the all-exact iteration (to
/// 10⁻⁸ of the depth), an exact residual within the tolerance, from a perturbed start at real
/// spacing; with the correction rounds forced (a crude interpolation, order 3) it still converges.
#[test]
fn interpolated_iterations_are_checked_exactly() {
    let n_side = 1100;
    let gaps: Vec<f64> = (0..n_side)
        .map(|k| 0.77 + 0.08 * (k as f64 * 0.9).sin())
        .collect();
    let depth: Vec<f64> = (0..n_side)
        .map(|k| 0.53 + 0.15 * (k as f64 * 1.3).cos())
        .collect();
    let (x, y) = v_shape(&gaps, &gaps, &depth, &depth);
    let xi = power_reduction(&x, &y).unwrap().xi;
    let guess: Vec<f64> = y
        .iter()
        .enumerate()
        .map(|(k, v)| v + 0.05 * (k as f64 * 2.3).cos())
        .collect();
    let fast = SolveOptions::default();
    assert!(x.len() >= fast.interpolate_from);
    let exact = SolveOptions {
        interpolate_from: usize::MAX,
        ..SolveOptions::default()
    };
    let crude = SolveOptions {
        interpolation: formation::aero::TreeOptions {
            order: 3,
            ..Default::default()
        },
        ..SolveOptions::default()
    };
    let reference = solve(&x, &xi, Some(&guess), &exact).unwrap();
    assert!(reference.converged, "{reference:?}");
    for opts in [fast, crude] {
        let rep = solve(&x, &xi, Some(&guess), &opts).unwrap();
        assert!(rep.converged, "{}", rep.termination);
        assert!(
            rep.termination.contains("interpolated"),
            "{}",
            rep.termination
        );
        // The reported residual is the exact one.
        let e = power_reduction(&x, &rep.y).unwrap();
        let r: f64 =
            e.xi.iter()
                .zip(&rep.target)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
        assert!(r <= opts.tolerance, "exact residual {r:e}");
        assert!(
            (r - rep.residual).abs() < 1e-12,
            "{r:e} vs {:e}",
            rep.residual
        );
        // Both are within the tolerance of the same solution: 10⁻⁸ of the depth (up to 224
        // wingspans here).
        for (a, b) in rep.y.iter().zip(&reference.y) {
            assert!((a - b).abs() < 1e-8 * b.abs().max(100.0), "{a} vs {b}");
        }
    }
}

/// Equal targets ξ_i = 1/N give Hummel's equal-savings formation: a mirror-symmetric U whose
/// outer birds fly farthest behind.
#[test]
fn equal_targets_give_a_symmetric_u() {
    for n in [5usize, 9, 15] {
        let x: Vec<f64> = (0..n).map(|i| i as f64 - (n as f64 - 1.0) / 2.0).collect();
        let rep = solve(&x, &vec![1.0; n], None, &SolveOptions::default()).unwrap();
        assert!(rep.converged);
        let mid = n / 2;
        assert!(rep.y[mid].abs() < 1e-9, "the middle bird leads");
        for i in 0..n {
            assert!(
                (rep.y[i] - rep.y[n - 1 - i]).abs() < 1e-7,
                "mirror symmetric"
            );
        }
        for i in mid..n - 1 {
            assert!(rep.y[i + 1] > rep.y[i], "further out is further back");
        }
        // U, not V: depth grows faster than linearly towards the tips.
        let d1 = rep.y[mid + 1] - rep.y[mid];
        let d_last = rep.y[n - 1] - rep.y[n - 2];
        assert!(
            d_last > 2.0 * d1,
            "U: {d1} at the centre, {d_last} at the tip"
        );
        for v in &rep.xi {
            assert!((v - 1.0 / n as f64).abs() < 1e-9);
        }
    }
}

#[test]
fn targets_are_renormalised() {
    let (x, y) = v_shape(&[1.0, 1.1], &[1.0, 1.2], &[0.5, 0.6], &[0.4, 0.7]);
    let xi = power_reduction(&x, &y).unwrap().xi;
    let scaled: Vec<f64> = xi.iter().map(|v| v * 7.5).collect();
    let rep = solve(&x, &scaled, None, &SolveOptions::default()).unwrap();
    assert!(rep.converged);
    assert!((rep.target.iter().sum::<f64>() - 1.0).abs() < 1e-15);
}

#[test]
fn unreachable_targets_name_the_birds() {
    // The leader of a 5-bird line abreast asking for 60 % of the savings: only possible if the
    // others flew infinitely far ahead, and more than that is impossible.
    let x = [-2.0, -1.0, 0.0, 1.0, 2.0];
    let err = solve(
        &x,
        &[0.1, 0.1, 0.6, 0.1, 0.1],
        None,
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(err, Error::Unreachable(_)), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("bird 2") || msg.contains("birds 2"), "{msg}");
    assert_eq!(err.exit_code(), 2);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let o = SolveOptions::default();
    assert!(solve(&[0.0], &[1.0], None, &o).is_err());
    assert!(solve(&[0.0, 1.0], &[1.0], None, &o).is_err());
    assert!(solve(&[0.0, 1.0], &[1.0, -0.5], None, &o).is_err());
    assert!(solve(&[0.0, 1.0], &[0.0, 0.0], None, &o).is_err());
    assert!(solve(&[0.0, 1.0], &[f64::NAN, 0.5], None, &o).is_err());
    // Overlapping wingtips asking for equal shares: only abreast, which is a collision.
    assert!(matches!(
        solve(&[0.0, 0.5], &[0.5, 0.5], None, &o),
        Err(Error::Unreachable(_))
    ));
    // A guess with colliding birds names them.
    let err = solve(
        &[0.0, 0.7, 2.0],
        &[0.3, 0.4, 0.3],
        Some(&[0.0, 0.05, 1.0]),
        &o,
    )
    .unwrap_err();
    assert!(err.to_string().contains("birds 0 and 1 collide"), "{err}");
    // Negative targets are allowed (a bird in downwash), but not a non-positive total.
    assert!(solve(&[0.0, 1.0], &[-0.5, 0.2], None, &o).is_err());
    assert!(solve(&[0.0, 1.0], &[0.5, 0.5], Some(&[0.0]), &o).is_err());
}

/// A bird in downwash (negative ξ, deep wingtip overlap behind the flock) is reachable: from a
/// guess with the original fore-aft order the solve finds the original shape; from its own
/// starts it finds a shape with the same ξ (possibly in another order of the overlapping pairs,
/// each of which has its own solution).
#[test]
fn negative_savings_round_trip() {
    let x = [0.0, 0.77, 1.54, -0.77, -1.54, 0.3];
    let y = [0.0, 1.24, 2.48, 1.24, 2.48, 4.0];
    let p = power_reduction(&x, &y).unwrap();
    assert!(p.xi[5] < 0.0, "bird 5 flies in downwash: {:?}", p.xi);
    let guess: Vec<f64> = y.iter().map(|v| v + 0.1).collect();
    let rep = solve(&x, &p.xi, Some(&guess), &SolveOptions::default()).unwrap();
    assert!(rep.converged);
    for (a, b) in rep.y.iter().zip(&y) {
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
    let own = solve(&x, &p.xi, None, &SolveOptions::default()).unwrap();
    assert!(own.converged, "{own:?}");
    let again = power_reduction(&x, &own.y).unwrap();
    for (a, b) in again.xi.iter().zip(&p.xi) {
        assert!((a - b).abs() < 1e-8);
    }
}
