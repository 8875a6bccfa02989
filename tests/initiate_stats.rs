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
    let seeds: u64 = std::env::var("SEEDS").ok().and_then(|s| s.parse().ok()).unwrap_or(20);
    let opts = InitiateOptions::default();
    for n in [9usize, 14, 41] {
        let s = if n == 41 { seeds / 2 } else { seeds };
        rate(&format!("V{n}"), &initiate_support::v_shape(n, 1.0, 0.6), s, &opts);
    }
}
