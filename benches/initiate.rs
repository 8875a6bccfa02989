//! Benchmarks of the initiate stage (criterion). Results: docs/performance.md.
//!
//! - perception of one bird among 1000 (HPR and exact occlusion);
//! - one simulation step of 1000 birds;
//! - a whole 41-bird initiation from a random start to convergence.

use criterion::{criterion_group, criterion_main, Criterion};
use formation::initiate::{
    self, perception::Perceiver, InitiateOptions, PerceptionMode, PerceptionParams, Simulation,
    StartRegion, TargetShape,
};
use formation::progress::Silent;
use formation::rng;
use glam::DVec2;
use std::hint::black_box;

fn v_shape(n: usize) -> Vec<DVec2> {
    let mut pts = vec![DVec2::ZERO];
    for k in 1..n {
        let rank = k.div_ceil(2) as f64;
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        pts.push(DVec2::new(side * rank, 0.6 * rank));
    }
    pts
}

fn flock(n: usize, seed: u64) -> (Vec<DVec2>, Vec<f64>, Vec<f64>, initiate::StepParams) {
    let opts = InitiateOptions::default();
    let params = opts.step_params(30.0, 0.0, 10.0);
    let mut r = rng::seeded(seed);
    let (p, h, v) =
        initiate::random_start(n, &StartRegion::default(), &params, &mut r).expect("start");
    (p, h, v, params)
}

fn perception(c: &mut Criterion) {
    let (pos, heading, _, _) = flock(1000, 1);
    let mut perceiver = Perceiver::new();
    let mut out = Vec::new();
    for (name, mode) in [
        (
            "hpr",
            PerceptionMode::Hpr {
                gamma: initiate::HPR_GAMMA_DEFAULT,
            },
        ),
        ("exact", PerceptionMode::Exact),
    ] {
        let params = PerceptionParams {
            mode,
            ..Default::default()
        };
        c.bench_function(&format!("perception_1_of_1000_{name}"), |b| {
            let mut i = 0;
            b.iter(|| {
                i = (i + 1) % pos.len();
                perceiver.visible(i, black_box(&pos), heading[i], &params, &mut out);
                out.len()
            })
        });
    }
}

fn step_1000(c: &mut Criterion) {
    let (pos, heading, speed, params) = flock(1000, 2);
    let target = TargetShape::new(&v_shape(1000)).expect("shape");
    let mut sim = Simulation::new(target, params, pos, heading, speed);
    // Let references and slots form first, so the step is a typical one.
    for _ in 0..30 {
        sim.step();
    }
    c.bench_function("step_1000_birds", |b| b.iter(|| sim.step()));
}

fn whole_41(c: &mut Criterion) {
    let target = TargetShape::new(&v_shape(41)).expect("shape");
    let opts = InitiateOptions::default();
    let mut group = c.benchmark_group("initiation");
    group.sample_size(20);
    group.bench_function("whole_41_birds", |b| {
        let mut seed = 0;
        b.iter(|| {
            seed += 1;
            let mut r = rng::seeded(seed % 10);
            let run =
                initiate::simulate(&target, 30.0, 0.0, 10.0, &opts, &mut r, &Silent).expect("run");
            assert!(run.stats.converged);
            run.stats.steps
        })
    });
    group.finish();
}

criterion_group!(benches, perception, step_1000, whole_41);
criterion_main!(benches);
