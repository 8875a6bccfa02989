//! Benchmarks of the key-shape solve (eq. 4) for N = 10, 40, 200, 1000, 10 000: targets are the ξ of a
//! V, the start is that V with every bird moved by up to ±0.3 wingspans (as when the steady
//! flight starts each key shape from the previous one). `benches/solve_scipy.py` times scipy's
//! MINPACK LM on the same problems. Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use formation::aero;
use formation::keyshape::{solve, SolveOptions};
use std::hint::black_box;

/// The V of `benches/aero.rs` and the perturbed start.
pub fn problem(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0];
    let mut y = vec![0.0];
    for k in 1..n {
        let rank = k.div_ceil(2) as f64;
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        x.push(side * rank * 1.05);
        y.push(rank * 0.6 + 0.05 * (k as f64 * 1.7).sin());
    }
    let xi = aero::power_reduction(&x, &y).unwrap().xi;
    let guess: Vec<f64> = y
        .iter()
        .enumerate()
        .map(|(k, v)| v + 0.3 * (k as f64 * 2.3).cos())
        .collect();
    (x, xi, guess)
}

fn bench_solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("solve");
    group.sample_size(10);
    let sizes: Vec<usize> = std::env::var("SOLVE_SIZES")
        .ok()
        .map(|v| v.split(',').filter_map(|s| s.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10, 40, 200, 1000, 10_000]);
    for n in sizes {
        let (x, xi, guess) = problem(n);
        let opts = SolveOptions::default();
        let check = solve(&x, &xi, Some(&guess), &opts).unwrap();
        assert!(check.converged, "N = {n} did not converge");
        eprintln!(
            "N = {n}: {} evaluations, residual {:.2e} ({})",
            check.evaluations, check.residual, check.termination
        );
        group.bench_with_input(BenchmarkId::new("perturbed_start", n), &n, |b, _| {
            b.iter(|| solve(black_box(&x), black_box(&xi), Some(&guess), &opts).unwrap())
        });
        // The same problem with the 3-D wake (the birds in one plane: the same numbers through
        // the 3-D model's code).
        if n >= 1000 {
            let opts3 = SolveOptions {
                aero: aero::AeroOptions {
                    wake: aero::Wake::ThreeD,
                    ..aero::AeroOptions::default()
                },
                ..SolveOptions::default()
            };
            let check = solve(&x, &xi, Some(&guess), &opts3).unwrap();
            assert!(check.converged, "N = {n}, 3-D wake: did not converge");
            group.bench_with_input(BenchmarkId::new("perturbed_start_wake3d", n), &n, |b, _| {
                b.iter(|| solve(black_box(&x), black_box(&xi), Some(&guess), &opts3).unwrap())
            });
        }
        if n <= 1000 {
            group.bench_with_input(BenchmarkId::new("neutral_start", n), &n, |b, _| {
                b.iter(|| solve(black_box(&x), black_box(&xi), None, &opts).unwrap())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_solve);
criterion_main!(benches);
