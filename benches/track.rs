//! Benchmark of `formation track` (criterion). Results: docs/performance.md, section "Tracking
//! footage".
//!
//! - `track_1080p_frames`: detection and tracking of 10 consecutive 1920×1080 grey frames of the
//!   synthetic 14-bird flock drawn by the renderer (sky, clouds, follow camera at the default
//!   minimum bird size), the frames already decoded (throughput in frames per second). The
//!   decoding by ffmpeg runs in its own process beside it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use formation::export::raster::{Canvas, Mask};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::export::{Film, RenderOptions};
use formation::track::detect::Gray;
use formation::track::{TrackOptions, Tracking};

fn track(c: &mut Criterion) {
    let mut anim = synthetic_flock(&mut formation::rng::seeded(0), &SyntheticParams::default());
    anim.frames.truncate(200);
    anim.stages.clear();
    let opts = RenderOptions {
        width: 1920,
        height: 1080,
        min_bird_px: 30.0,
        ..RenderOptions::default()
    };
    let film = Film::with_options(&anim, 25.0, &opts);
    let mut mask = Mask::new();
    let frames: Vec<Gray> = (0..10)
        .map(|k| {
            let mut canvas = Canvas::new(1920, 1080);
            film.draw(k, &mut canvas, &mut mask, false);
            Gray::from_rgba(1920, 1080, &canvas.straight_rgba())
        })
        .collect();
    let mut g = c.benchmark_group("track");
    g.sample_size(10);
    g.throughput(Throughput::Elements(frames.len() as u64));
    g.bench_function("track_1080p_frames", |b| {
        b.iter(|| {
            let mut t = Tracking::new(&TrackOptions::default()).unwrap();
            for (k, f) in frames.iter().enumerate() {
                t.push(k, None, f, std::path::Path::new("bench")).unwrap();
            }
            t.finish("bench", Some(25.0)).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, track);
criterion_main!(benches);
