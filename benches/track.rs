//! Benchmark of `formation track` (criterion). Results: docs/performance.md, section "Tracking
//! footage".
//!
//! - `track_1080p_frames`: detection and tracking of 10 consecutive 1920×1080 grey frames of the
//!   synthetic 14-bird flock drawn by the renderer (sky, clouds, follow camera at the default
//!   minimum bird size), the frames already decoded (throughput in frames per second). The
//!   decoding by ffmpeg runs in its own process beside it.
//! - `track_1000_birds`: 3 frames of 1000 dark discs 24 px apart (1000 × 640 px) moving 9.8 px a
//!   frame: the flock-shift vote and the assignment at the most birds a frame may hold.

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
    let grid: Vec<Gray> = (0..3)
        .map(|k| grid_frame(40, 25, (9.0 * k as f64, 4.0 * k as f64)))
        .collect();
    g.throughput(Throughput::Elements(grid.len() as u64));
    g.bench_function("track_1000_birds", |b| {
        b.iter(|| {
            let mut t = Tracking::new(&TrackOptions::default()).unwrap();
            for (k, f) in grid.iter().enumerate() {
                t.push(k, None, f, std::path::Path::new("bench")).unwrap();
            }
            t.finish("bench", None).unwrap()
        })
    });
    g.finish();
}

/// A sky with `cols × rows` dark discs 24 px apart, all shifted by `shift`.
fn grid_frame(cols: usize, rows: usize, shift: (f64, f64)) -> Gray {
    let (w, h) = (cols * 24 + 40, rows * 24 + 40);
    let mut data = vec![200u8; w * h];
    for r in 0..rows {
        for c in 0..cols {
            let cx = 20.0 + 24.0 * c as f64 + shift.0 + 3.0 * ((r * 7 + c * 3) % 5) as f64 / 5.0;
            let cy = 20.0 + 24.0 * r as f64 + shift.1;
            for y in (cy as usize).saturating_sub(5)..(cy as usize + 6).min(h) {
                for x in (cx as usize).saturating_sub(5)..(cx as usize + 6).min(w) {
                    if (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) < 3.5 {
                        data[y * w + x] = 40;
                    }
                }
            }
        }
    }
    Gray {
        width: w,
        height: h,
        data,
    }
}

criterion_group!(benches, track);
criterion_main!(benches);
