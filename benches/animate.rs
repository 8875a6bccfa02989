//! The main job end to end: what `formation animate examples_data/barnacle_geese_v.json
//! --birds 14 -o flock.gif` does (read and extract the 9-goose annotations, 20 s of steady flight
//! at 30 fps for 14 birds, the take-off before it, wingbeats, the 960×540 GIF), and the same
//! without the GIF (the simulation alone). Issue 13: a flock of 1000 geese (about 111 formations)
//! taking off and flying 20 s of steady flight, written as JSON and CSV, and 10 000 geese in
//! steady flight only (20 s, the animation in memory). Results: docs/performance.md.

use std::path::{Path, PathBuf};

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use formation::export::{write_outputs, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;
use formation::Animation;

fn simulate() -> Animation {
    simulate_on(None)
}

fn simulate_on(path: Option<PathBuf>) -> Animation {
    flock_on(14, true, path)
}

/// `birds` geese from the 9-goose example, 20 s of steady flight, with or without the take-off.
fn flock(birds: usize, takeoff: bool) -> Animation {
    flock_on(birds, takeoff, None)
}

/// [`flock`] along a path, if given.
fn flock_on(birds: usize, takeoff: bool, path: Option<PathBuf>) -> Animation {
    flock_with(birds, takeoff, path, true)
}

/// [`flock_on`], with the living steady flight (position keeping, leader changes, swaps: the
/// default) or without it (`--jostle 0`: the key shapes interpolated, as before it existed), to
/// hold what it costs side by side.
fn flock_with(birds: usize, takeoff: bool, path: Option<PathBuf>, living: bool) -> Animation {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    let mut config = Config::default();
    if !living {
        config.steady.jostle.scale = 0.0;
    }
    config.steady.birds = birds;
    config.seconds = Some(20.0);
    config.course.path = path;
    config.initiation = takeoff;
    Pipeline::from_path(input).run(&config).unwrap().0
}

/// Issue 19's test path, `tests/data/path_turn_climb.json`: 200 wingspans north, a 90° right
/// turn of radius 150, 300 east climbing 20 wingspans (the take-off joins it at its first point,
/// at the default cruise altitude of 10 wingspans, so both runs fly the same take-off).
fn turn_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/path_turn_climb.json")
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("animate");
    g.sample_size(10);
    g.bench_function("geese_14_birds_20s_simulation", |b| b.iter(simulate));
    let dir = std::env::temp_dir().join(format!("formation-bench-animate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = turn_path();
    g.bench_function("geese_14_birds_20s_simulation_on_a_path", |b| {
        b.iter(|| simulate_on(Some(path.clone())))
    });
    // Paired: straight and path runs alternate within every sample, so that the load of the
    // shared machine hits both alike; the ratio of their summed times is printed at the end.
    let sums = std::cell::Cell::new((Duration::ZERO, Duration::ZERO, 0u32));
    g.bench_function("geese_14_birds_20s_straight_then_path_paired", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let t = Instant::now();
                black_box(simulate());
                let straight = t.elapsed();
                let t = Instant::now();
                black_box(simulate_on(Some(path.clone())));
                let on_path = t.elapsed();
                let (s, p, n) = sums.get();
                sums.set((s + straight, p + on_path, n + 1));
                total += straight + on_path;
            }
            total
        })
    });
    let (s, p, n) = sums.get();
    if n > 0 {
        eprintln!(
            "paired ({n} runs each): straight {:.2} ms, on the path {:.2} ms per run: path following adds {:+.1} %",
            s.as_secs_f64() * 1e3 / n as f64,
            p.as_secs_f64() * 1e3 / n as f64,
            100.0 * (p.as_secs_f64() / s.as_secs_f64() - 1.0)
        );
    }
    // The course step alone (reading the path, the spline, the mapping, banks and pitches) on
    // the course-frame flight of the first benchmark.
    {
        let mut config = Config::default();
        config.steady.birds = 14;
        config.course.path = Some(path.clone());
        let straight = simulate();
        // The same step without the path (pitch and banks only, as every flight has): the
        // difference of the two is what following the path costs.
        let mut unbanked = straight.clone();
        for f in &mut unbanked.frames {
            f.bank = None;
        }
        for (name, config) in [
            ("geese_14_birds_20s_course_step", config.clone()),
            (
                "geese_14_birds_20s_course_step_without_path",
                Config::default(),
            ),
        ] {
            g.bench_function(name, |b| {
                b.iter(|| {
                    let points = config.course.load(config.steady.wingspan_m).unwrap();
                    let mut a = unbanked.clone();
                    formation::pipeline::course_stage(&mut a, points.as_ref(), &config).unwrap();
                    a
                })
            });
        }
    }
    let gif: PathBuf = dir.join("flock.gif");
    let anim = simulate();
    eprintln!(
        "animation: {} frames ({} s) of which {} take-off",
        anim.frames.len(),
        anim.frames.len() as f64 / anim.fps,
        anim.stage("initiation").map_or(0, |s| s.end - s.start)
    );
    g.bench_function("geese_14_birds_20s_with_gif_960x540", |b| {
        b.iter(|| {
            let anim = simulate();
            write_outputs(
                &anim,
                std::slice::from_ref(&gif),
                &RenderOptions::default(),
                &Silent,
            )
            .unwrap()
        })
    });
    g.bench_function("geese_14_birds_20s_with_gif_960x540_jostle0", |b| {
        b.iter(|| {
            let anim = flock_with(14, true, None, false);
            write_outputs(
                &anim,
                std::slice::from_ref(&gif),
                &RenderOptions::default(),
                &Silent,
            )
            .unwrap()
        })
    });
    let files: Vec<PathBuf> = vec![dir.join("flock.json"), dir.join("flock.csv")];
    g.bench_function("geese_1000_birds_takeoff_20s_json_csv", |b| {
        b.iter(|| {
            let anim = flock(1000, true);
            write_outputs(&anim, &files, &RenderOptions::default(), &Silent).unwrap()
        })
    });
    g.bench_function("geese_1000_birds_takeoff_20s_json_csv_jostle0", |b| {
        b.iter(|| {
            let anim = flock_with(1000, true, None, false);
            write_outputs(&anim, &files, &RenderOptions::default(), &Silent).unwrap()
        })
    });
    g.bench_function("geese_10000_birds_steady_20s", |b| {
        b.iter(|| flock(10_000, false))
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
