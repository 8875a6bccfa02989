//! Benchmarks of the steady stage (criterion): Algorithm 1 end to end with one frame per key shape
//! (fps = 1, a key every second), so the time is that of steps 1–3 plus a few frames.
//! Results: docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion};
use formation::keyshape::{steady_flight_report, KeyOptions, SteadyOptions};
use formation::progress::Silent;
use formation::rng::seeded;
use std::sync::Once;

#[path = "../tests/steady_support/mod.rs"]
mod steady_support;

fn opts(birds: usize, keys: usize) -> SteadyOptions {
    SteadyOptions {
        birds,
        frames: keys,
        fps: 1.0,
        keys: KeyOptions {
            key_every_s: 1.0,
            ..KeyOptions::default()
        },
        ..SteadyOptions::default()
    }
}

fn bench(c: &mut Criterion) {
    let v9 = steady_support::v9();
    let o = opts(40, 20);
    // The solve statistics are printed from the first timed run (recorded in docs/performance.md).
    let once = Once::new();
    c.bench_function("steady N=40 20 keys (v9 movie)", |b| {
        b.iter(|| {
            let r = steady_flight_report(&v9, &o, &mut seeded(0), &Silent).unwrap();
            once.call_once(|| eprintln!("N = 40, 20 keys: {:?}", r.1.keys));
            r
        })
    });

    let mut g = c.benchmark_group("steady large");
    g.sample_size(10);
    let o = opts(1000, 5);
    let once = Once::new();
    g.bench_function("steady N=1000 5 keys (v9 movie)", |b| {
        b.iter(|| {
            let r = steady_flight_report(&v9, &o, &mut seeded(0), &Silent).unwrap();
            once.call_once(|| eprintln!("N = 1000, 5 keys: {:?}", r.1.keys));
            r
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
