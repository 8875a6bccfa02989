//! Benchmarks of the render stage (criterion). Results: docs/performance.md, section
//! "Rendering and export".
//!
//! - `gif_frames_960x540`: drawing, palette mapping, differencing and LZW of 50 GIF frames of the
//!   synthetic 14-bird flock (throughput in frames per second).
//! - `render_gif_14_birds_20s`: the whole GIF output of a 14-bird, 20 s, 30 fps animation
//!   (sampling, camera, 500 frames at 25 fps, file written), i.e. `formation render -o x.gif`
//!   after reading the file.
//! - `glb_14_birds_20s`, `csv_14_birds_20s`: the other exports of the same animation.
//! - `frame_960x540_14_birds`, `frame_960x540_1000_birds`: drawing one 960×540 picture (sky,
//!   clouds, birds) of the steady synthetic flock of 14 and of 1000 birds, follow camera.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::export::{pictures, write_outputs, Film, RenderOptions};
use formation::progress::Silent;

fn out(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("formation-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn render(c: &mut Criterion) {
    let anim = synthetic_flock(&mut formation::rng::seeded(0), &SyntheticParams::default());
    let mut g = c.benchmark_group("render");
    g.sample_size(10);

    // 50 frames from the steady part of the flight, 960×540.
    let mut short = anim.clone();
    short.frames.truncate(200);
    short.stages.clear();
    let film = Film::new(&short, 25.0, 960, 540);
    let frames = film.len() as u64;
    g.throughput(Throughput::Elements(frames));
    let gif = out("frames.gif");
    g.bench_function("gif_frames_960x540", |b| {
        b.iter(|| pictures::write_gif(&film, &gif, 0, &Silent).unwrap())
    });

    g.throughput(Throughput::Elements(1));
    let gif = out("flock.gif");
    let opts = RenderOptions::default();
    g.bench_function("render_gif_14_birds_20s", |b| {
        b.iter(|| write_outputs(&anim, std::slice::from_ref(&gif), &opts, &Silent).unwrap())
    });
    let glb = out("flock.glb");
    g.bench_function("glb_14_birds_20s", |b| {
        b.iter(|| write_outputs(&anim, std::slice::from_ref(&glb), &opts, &Silent).unwrap())
    });
    let csv = out("flock.csv");
    g.bench_function("csv_14_birds_20s", |b| {
        b.iter(|| write_outputs(&anim, std::slice::from_ref(&csv), &opts, &Silent).unwrap())
    });
    for birds in [14usize, 1000] {
        let p = SyntheticParams {
            birds,
            seconds: 6.0,
            ..SyntheticParams::default()
        };
        let a = synthetic_flock(&mut formation::rng::seeded(0), &p);
        let film = Film::new(&a, 25.0, 960, 540);
        let k = film.len() - 1;
        let mut canvas = formation::export::raster::Canvas::new(960, 540);
        let mut mask = formation::export::raster::Mask::new();
        g.bench_function(format!("frame_960x540_{birds}_birds"), |b| {
            b.iter(|| film.draw(k, &mut canvas, &mut mask, false))
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(gif.parent().unwrap());
}

criterion_group!(benches, render);
criterion_main!(benches);
