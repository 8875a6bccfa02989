//! What keeping birds clear of each other costs (criterion): the steady flight's clearance
//! machinery (the key shapes' fore-aft step, `keyshape::separate`; the position keeping bounded
//! by each bird's room, `keyshape::jostle::rooms`) switched on and off by a benchmark-only switch
//! (`keyshape::separate::BENCH_WITHOUT_CLEARANCE`), on the README job's simulation (14 barnacle geese
//! from the 9-goose example, take-off and 20 s of steady flight at 30 fps) and on 1000 geese (take-off
//! and 20 s). Runs with and without alternate within every sample, so that the load of the shared
//! machine hits both alike; the ratio of their summed times is printed at the end, with the
//! clashes of each run (`animation::clearance`). Results: docs/performance.md.

use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use formation::animation::clearance::Clearance;
use formation::keyshape::separate::BENCH_WITHOUT_CLEARANCE;
use formation::pipeline::{Config, Pipeline};
use formation::Animation;

/// `birds` geese from the 9-goose example: take-off and 20 s of steady flight, with or without
/// the clearance machinery.
fn flock(birds: usize, clearance: bool) -> Animation {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    let mut config = Config::default();
    config.steady.birds = birds;
    config.seconds = Some(20.0);
    // The README job's `--species barnacle-goose`: its span and cruise speed.
    if let Some(b) = formation::aero::species::lookup("barnacle-goose") {
        config.steady.wingspan_m = b.span_m;
        config.steady.speed = b.cruise_wingspans_s();
    }
    BENCH_WITHOUT_CLEARANCE.store(!clearance, Ordering::Relaxed);
    let a = Pipeline::from_path(input).run(&config).unwrap().0;
    BENCH_WITHOUT_CLEARANCE.store(false, Ordering::Relaxed);
    a
}

fn paired(c: &mut Criterion, name: &str, birds: usize) {
    let mut g = c.benchmark_group("clearance");
    g.sample_size(10);
    let sums = std::cell::Cell::new((Duration::ZERO, Duration::ZERO, 0u32));
    g.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t = Instant::now();
                black_box(flock(birds, true));
                let with = t.elapsed();
                let t = Instant::now();
                black_box(flock(birds, false));
                let without = t.elapsed();
                let (w, o, n) = sums.get();
                sums.set((w + with, o + without, n + 1));
                total += with + without;
            }
            total
        })
    });
    g.finish();
    let (w, o, n) = sums.get();
    if n > 0 {
        let clash = |a: &Animation| {
            let steady = a
                .stage("steady")
                .map_or(0..a.frames.len(), |s| s.start..s.end);
            let s = Clearance::of_frames(&a.frames, steady);
            let all = Clearance::of(a);
            format!(
                "{} clashes in the steady flight ({} in all), closest {:.2} wingspans",
                s.clashes(),
                all.clashes(),
                all.closest.map_or(f64::NAN, |c| c.distance)
            )
        };
        eprintln!(
            "{name}, paired ({n} runs each): with clearance {:.1} ms ({}), without {:.1} ms ({}) per run: clearance adds {:+.1} %",
            w.as_secs_f64() * 1e3 / n as f64,
            clash(&flock(birds, true)),
            o.as_secs_f64() * 1e3 / n as f64,
            clash(&flock(birds, false)),
            100.0 * (w.as_secs_f64() / o.as_secs_f64() - 1.0)
        );
    }
}

fn bench(c: &mut Criterion) {
    paired(c, "readme_job_14_birds_with_then_without", 14);
    paired(c, "geese_1000_birds_with_then_without", 1000);
}

criterion_group!(benches, bench);
criterion_main!(benches);
