//! Issue 18's take-off: time-based (the same at any frame rate), smooth (turn-rate, speed and
//! roll limits in every frame), short and settable (`takeoff`), from the ground, for any flock
//! size. Long statistics are `#[ignore]`d: `cargo test --release --test takeoff -- --ignored`.

mod initiate_support;

use formation::initiate::{self, Cruise, InitiateOptions, InitiateStats, Start, TargetShape};
use formation::progress::Silent;
use formation::rng;
use glam::DVec2;
use initiate_support::v_shape;

fn target(n: usize) -> TargetShape {
    let pts: Vec<DVec2> = v_shape(n, 1.0, 0.6)
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
    TargetShape::new(&pts).unwrap()
}

fn env_u(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

fn run_stats(n: usize, seed: u64, opts: &InitiateOptions) -> InitiateStats {
    let t = target(n);
    let mut r = rng::seeded(seed);
    initiate::simulate(&t, 30.0, &Cruise::new(0.0, 10.0), opts, &mut r, &Silent)
        .unwrap()
        .stats
}

/// Durations over seeds and sizes: `SEEDS=20 SIZES=9,14,41,100 TAKEOFF=... cargo test --release
/// --test takeoff table -- --ignored --nocapture`.
#[test]
#[ignore]
fn table() {
    let seeds = env_u("SEEDS").unwrap_or(10);
    let sizes: Vec<usize> = std::env::var("SIZES")
        .unwrap_or_else(|_| "9,14,41,100".into())
        .split(',')
        .filter_map(|s| s.parse().ok())
        .collect();
    let mut opts = InitiateOptions::default();
    if let Ok(t) = std::env::var("TAKEOFF") {
        opts.takeoff = t.parse().ok();
    }
    if let Some(k) = std::env::var("K").ok().and_then(|v| v.parse().ok()) {
        opts.k = k;
    }
    if let Some(k) = std::env::var("CATCHUP").ok().and_then(|v| v.parse().ok()) {
        opts.catchup_distance = k;
    }
    if let Some(k) = std::env::var("LAG").ok().and_then(|v| v.parse().ok()) {
        opts.speed_lag = k;
    }
    if let Some(k) = std::env::var("JERK").ok().and_then(|v| v.parse().ok()) {
        opts.max_jerk = k;
    }
    if let Some(w) = std::env::var("STAGGER").ok().and_then(|v| v.parse().ok()) {
        if let Start::Ground(g) = &mut opts.start {
            g.stagger = Some(w);
        }
    }
    if std::env::var("NOGAP").is_ok() {
        opts.gap_speed = false;
    }
    if let Some(k) = std::env::var("GATHER").ok().and_then(|v| v.parse().ok()) {
        opts.gather_speed = k;
    }
    if let Some(k) = std::env::var("TOL").ok().and_then(|v| v.parse().ok()) {
        opts.tolerance = k;
    }
    if let Some(k) = std::env::var("CLIMB").ok().and_then(|v| v.parse().ok()) {
        opts.climb_rate = k;
        opts.vertical_accel = k;
    }
    if let Some(k) = std::env::var("ALT").ok().and_then(|v| v.parse().ok()) {
        opts.cruise_altitude = k;
    }
    if std::env::var("AIR").is_ok() {
        opts.start = Start::Random(Default::default());
    }
    for n in sizes {
        let mut secs = Vec::new();
        let (mut ok, mut mind, mut stray, mut lift) = (0, f64::INFINITY, 0.0f64, 0.0f64);
        let mut planned = 0.0;
        for seed in 0..seeds {
            let s = run_stats(n, seed, &opts);
            planned = s.planned_seconds;
            if s.converged {
                ok += 1;
                secs.push(s.seconds);
            }
            mind = mind.min(s.min_distance);
            stray = stray.max(s.max_stray);
            lift = lift.max(s.last_liftoff);
        }
        secs.sort_by(f64::total_cmp);
        let med = secs.get(secs.len() / 2).copied().unwrap_or(f64::NAN);
        let max = secs.last().copied().unwrap_or(f64::NAN);
        println!(
            "N={n:4} planned {planned:5.1} s converged {ok}/{seeds} median {med:5.1} s max {max:5.1} s closest {mind:.3} stray {stray:.1} last lift-off {lift:.1}"
        );
    }
}

/// Per-second progress of one take-off: `N=14 SEED=0 cargo test --release --test takeoff trace
/// -- --ignored --nocapture`.
#[test]
#[ignore]
fn trace() {
    let n = env_u("N").unwrap_or(14) as usize;
    let seed = env_u("SEED").unwrap_or(0);
    let mut opts = InitiateOptions::default();
    if let Ok(t) = std::env::var("TAKEOFF") {
        opts.takeoff = t.parse().ok();
    }
    if let Some(k) = std::env::var("K").ok().and_then(|v| v.parse().ok()) {
        opts.k = k;
    }
    let t = target(n);
    let mut r = rng::seeded(seed);
    let (mut sim, plan) =
        initiate::start_simulation(&t, &Cruise::new(0.0, 10.0), &opts, &mut r).unwrap();
    println!("{plan:?}");
    let tol = opts.tolerances();
    let per_s = (1.0 / sim.params.dt()).round() as usize;
    for sec in 0..40 {
        for _ in 0..per_s {
            sim.step();
        }
        let slots = sim.slot_positions();
        let f = &sim.flock;
        let mut errs: Vec<(f64, usize)> = (0..n)
            .map(|i| match f.slot[i] {
                Some(s) => ((f.pos[i] - slots[s]).length(), i),
                None => (f64::INFINITY, i),
            })
            .collect();
        errs.sort_by(|a, b| b.0.total_cmp(&a.0));
        let worst: Vec<String> = errs[..4.min(n)]
            .iter()
            .map(|(e, i)| {
                format!(
                    "b{i} e{e:.2} v{:.1} z{:.1} ref{:?} slot{:?}",
                    f.speed[*i], f.z[*i], f.reference[*i], f.slot[*i]
                )
            })
            .collect();
        println!(
            "t={:3} in_slot {:2} leader {} v_lead {:.1} form {} stray {:.1} | {}",
            sec + 1,
            sim.birds_in_slot(opts.tolerance),
            f.leader,
            f.speed[f.leader],
            sim.in_formation(&tol),
            sim.stray_distance(),
            worst.join(" | ")
        );
    }
}
