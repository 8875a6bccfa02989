//! Benchmarks of Hummel's model: one g evaluation, and e_i of whole flocks (N = 40, 1000).
//! Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use formation::aero;
use std::hint::black_box;

/// A V of `n` birds: lateral gap 1.05 wingspans, 0.6 wingspans back per rank.
pub fn v_flock(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0];
    let mut y = vec![0.0];
    for k in 1..n {
        let rank = k.div_ceil(2) as f64;
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        x.push(side * rank * 1.05);
        y.push(rank * 0.6 + 0.05 * (k as f64 * 1.7).sin());
    }
    (x, y)
}

fn bench_g(c: &mut Criterion) {
    c.bench_function("g(x, y)", |b| {
        b.iter(|| aero::g(black_box(1.13), black_box(0.71)))
    });
    c.bench_function("dg_dy(x, y)", |b| {
        b.iter(|| aero::dg_dy(black_box(1.13), black_box(0.71)))
    });
}

fn bench_power(c: &mut Criterion) {
    let mut group = c.benchmark_group("power_reduction");
    for n in [40usize, 1000] {
        let (x, y) = v_flock(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| aero::power_reduction(black_box(&x), black_box(&y)).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_g, bench_power);
criterion_main!(benches);
