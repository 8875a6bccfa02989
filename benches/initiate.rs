//! Benchmarks of the initiate stage (criterion). Results: docs/performance.md.
//!
//! - perception of one bird among 1000 (HPR and exact occlusion);
//! - one simulation step of 1000 airborne birds: one decision of every bird (perception through
//!   the grid, drives, avoidance) and the integration steps up to the next decision, i.e. one
//!   reaction time (1/30 s) of flight;
//! - a whole ground take-off of 100 and of 300 birds, from rest to convergence (or the time
//!   limit), into a V at real spacing (0.7 wingspans across, 0.35 back);
//! - the landing of 100 birds flying a V at 10 wingspans up: the whole landing stage (glide,
//!   flare, touch-downs, running steps, 30 fps), then the birds put on the ground and the
//!   wingbeats assigned (fold and flare included).

use criterion::{criterion_group, criterion_main, Criterion};
use formation::initiate::{
    self, perception::Perceiver, Cruise, InitiateOptions, PerceptionMode, PerceptionParams,
    Simulation, StartRegion, TargetShape,
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
        pts.push(DVec2::new(side * 0.7 * rank, 0.35 * rank));
    }
    pts
}

fn flock(n: usize, seed: u64) -> (Vec<DVec2>, Vec<f64>, Vec<f64>, initiate::StepParams) {
    let opts = InitiateOptions::default();
    let params = opts.step_params(&Cruise::new(0.0, 10.0));
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
    let n = pos.len();
    let z = vec![params.opts.cruise_altitude; n];
    let mut sim = Simulation::new(target, params.clone(), pos, z, heading, speed, vec![0.0; n]);
    let per_decision = params.opts.substeps as usize;
    // Let references and slots form first (1 s), so the step is a typical one.
    for _ in 0..30 * per_decision {
        sim.step();
    }
    c.bench_function("step_1000_birds", |b| {
        b.iter(|| {
            for _ in 0..per_decision {
                sim.step();
            }
        })
    });
}

fn whole(c: &mut Criterion) {
    let mut group = c.benchmark_group("takeoff");
    group.sample_size(10);
    for n in [100usize, 300] {
        let target = TargetShape::new(&v_shape(n)).expect("shape");
        let opts = InitiateOptions::default();
        group.bench_function(format!("whole_{n}_birds"), |b| {
            b.iter(|| {
                let mut r = rng::seeded(0);
                let run = initiate::simulate(
                    &target,
                    30.0,
                    &Cruise::new(0.0, 10.0),
                    &opts,
                    &mut r,
                    &Silent,
                )
                .expect("run");
                run.stats.seconds
            })
        });
    }
    group.finish();
}

fn landing(c: &mut Criterion) {
    use formation::animation::{Animation, Frame, Stage, StageName};
    use formation::initiate::landing::{self, LandingOptions, Site};
    let n = 100;
    let shape = v_shape(n);
    let mut flight = Animation::new(0, 30.0, 1.5, n);
    for k in 0..30 {
        let t = k as f64 / 30.0;
        flight.frames.push(Frame {
            t,
            x: shape.iter().map(|p| p.x).collect(),
            y: shape.iter().map(|p| 10.0 * t - p.y).collect(),
            z: vec![10.0; n],
            heading: vec![0.0; n],
            speed: vec![10.0; n],
            ..Frame::default()
        });
    }
    flight.stages.push(Stage {
        name: StageName::Steady,
        start: 0,
        end: 30,
    });
    let site = Site {
        speed: 10.0,
        altitude: 10.0,
        world_height: 10.0,
        along_scale: 1.0,
    };
    let mut group = c.benchmark_group("landing");
    group.sample_size(10);
    group.bench_function("whole_100_birds", |b| {
        b.iter(|| {
            let mut a = flight.clone();
            landing::land(&mut a, &LandingOptions::default(), &site, None).expect("lands");
            formation::wingbeat::rest::stand_on_ground(&mut a, formation::wingbeat::Species::Goose);
            formation::wingbeat::assign_phases(&mut a, &Default::default()).expect("wingbeats");
            black_box(a.frames.len())
        })
    });
    group.finish();
}

criterion_group!(benches, perception, step_1000, whole, landing);
criterion_main!(benches);
