//! Benchmarks of the wingbeat stage (criterion). Results: docs/performance.md.
//!
//! - `poses/1000_birds_one_frame`: [`Flapper::pose`] for every bird of a 1000-bird flock at one
//!   frame (what a renderer does per frame; target well under 1 ms).
//! - `assign_phases/<n>_birds_<m>_frames`: phase integration with locking (bird-ahead search is
//!   O(n²) per frame).
//! - `from_animation/1000_birds_300_frames`: replaying the stored phases (renderer start-up).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use formation::animation::{Animation, Frame};
use formation::wingbeat::{assign_phases, Flapper, WingbeatOptions};

/// A V of `birds` flying north at 10 wingspans/s, accelerating during the first second.
fn flock(birds: usize, frames: usize) -> Animation {
    let fps = 30.0;
    let mut a = Animation::new(1, fps, 1.5, birds);
    for k in 0..frames {
        let t = k as f64 / fps;
        let speed = if t < 1.0 { 6.0 + 4.0 * t } else { 10.0 };
        let mut f = Frame {
            t,
            ..Frame::default()
        };
        for i in 0..birds {
            let rank = i.div_ceil(2) as f64;
            let side = if i % 2 == 1 { 1.0 } else { -1.0 };
            f.x.push(side * 0.85 * rank);
            f.y.push(10.0 * t - 0.6 * rank);
            f.z.push(0.0);
            f.heading.push(0.0);
            f.speed.push(speed);
        }
        a.frames.push(f);
    }
    a
}

fn poses(c: &mut Criterion) {
    let mut a = flock(1000, 300);
    assign_phases(&mut a, &WingbeatOptions::default()).expect("valid animation");
    let flapper = Flapper::from_animation(&a);
    let mut out = Vec::with_capacity(1000);
    let mut frame = 0;
    c.bench_function("poses/1000_birds_one_frame", |b| {
        b.iter(|| {
            frame = (frame + 37) % 300;
            flapper.poses_into(black_box(frame), &mut out);
            black_box(&out);
        })
    });
}

fn assign(c: &mut Criterion) {
    let mut g = c.benchmark_group("assign_phases");
    g.sample_size(10);
    for (birds, frames) in [(50, 600), (1000, 100)] {
        let a = flock(birds, frames);
        g.bench_function(format!("{birds}_birds_{frames}_frames"), |b| {
            b.iter(|| {
                let mut x = a.clone();
                assign_phases(&mut x, &WingbeatOptions::default()).expect("valid animation");
                black_box(x);
            })
        });
    }
    g.finish();
}

fn replay(c: &mut Criterion) {
    let mut a = flock(1000, 300);
    assign_phases(&mut a, &WingbeatOptions::default()).expect("valid animation");
    let mut g = c.benchmark_group("from_animation");
    g.sample_size(10);
    g.bench_function("1000_birds_300_frames", |b| {
        b.iter(|| black_box(Flapper::from_animation(black_box(&a))))
    });
    g.finish();
}

criterion_group!(benches, poses, assign, replay);
criterion_main!(benches);
