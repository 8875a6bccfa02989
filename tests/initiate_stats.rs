//! Measurements behind docs/initiation.md (ignored by default; run with
//! `cargo test --release --test initiate_stats -- --ignored --nocapture`).

mod initiate_support;

use formation::initiate::{self, InitiateOptions, TargetShape};
use formation::progress::Silent;
use formation::rng;
use glam::DVec2;

fn target(shape: &[(f64, f64)]) -> TargetShape {
    let pts: Vec<DVec2> = shape.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
    TargetShape::new(&pts).unwrap()
}

fn rate(label: &str, shape: &[(f64, f64)], seeds: u64, opts: &InitiateOptions) {
    let t = target(shape);
    let mut ok = 0;
    let mut steps = Vec::new();
    let mut mind = f64::INFINITY;
    let mut fails = Vec::new();
    let mut minds = Vec::new();
    for seed in 0..seeds {
        let mut r = rng::seeded(seed);
        let run = initiate::simulate(&t, 30.0, 0.0, 10.0, opts, &mut r, &Silent).unwrap();
        if run.stats.converged {
            ok += 1;
            steps.push(run.stats.steps);
        } else {
            fails.push((seed, run.stats.birds_in_slot));
        }
        mind = mind.min(run.stats.min_distance);
        minds.push(run.stats.min_distance);
    }
    steps.sort_unstable();
    minds.sort_by(f64::total_cmp);
    let med = steps.get(steps.len() / 2).copied().unwrap_or(0);
    let below = minds.iter().filter(|d| **d < 0.25).count();
    println!(
        "{label}: {ok}/{seeds} converged, median steps {med}, max {:?}, min distance {mind:.3} ({below} runs < 0.25), fails {:?}",
        steps.last(),
        &fails[..fails.len().min(8)]
    );
}

#[test]
#[ignore]
fn convergence_rates() {
    let seeds: u64 = std::env::var("SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let opts = InitiateOptions::default();
    for n in [9usize, 14, 41] {
        let s = if n == 41 { seeds / 2 } else { seeds };
        rate(
            &format!("V{n}"),
            &initiate_support::v_shape(n, 1.0, 0.6),
            s,
            &opts,
        );
    }
}

#[test]
#[ignore]
fn diagnose() {
    let n: usize = std::env::var("N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(41);
    let seed: u64 = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let opts = InitiateOptions::default();
    let t = target(&initiate_support::v_shape(n, 1.0, 0.6));
    let params = opts.step_params(30.0, 0.0, 10.0);
    let mut r = rng::seeded(seed);
    let region = match &opts.start {
        initiate::Start::Random(r) => *r,
        _ => unreachable!(),
    };
    let (p, h, v) = initiate::random_start(n, &region, &params, &mut r).unwrap();
    let mut sim = initiate::Simulation::new(t, params, p, h, v);
    for step in 0..9000 {
        sim.step();
        if step % 500 == 0 || sim.min_distance() < 0.3 {
            let slots = sim.slot_positions();
            let f = &sim.flock;
            let matched = f.slot.iter().filter(|s| s.is_some()).count();
            let mut errs: Vec<(usize, f64)> = (0..n)
                .filter_map(|i| f.slot[i].map(|s| (i, (f.pos[i] - slots[s]).length())))
                .collect();
            errs.sort_by(|a, b| b.1.total_cmp(&a.1));
            let hd = f.heading.iter().map(|h| h.abs()).fold(0.0, f64::max);
            let sd = f
                .speed
                .iter()
                .map(|v| (v / params.cruise_speed - 1.0).abs())
                .fold(0.0, f64::max);
            let lost = f.reference.iter().filter(|r| r.is_none()).count();
            println!(
                "step {step}: in slot {} matched {matched} lost {lost} leader {} mind {:.3} maxhd {:.3} maxsd {:.3} worst {:?}",
                sim.birds_in_slot(0.1), f.leader, sim.min_distance(), hd, sd, &errs[..errs.len().min(4)]
            );
        }
    }
}
