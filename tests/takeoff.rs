//! Issue 18's take-off: time-based (the same at any frame rate), smooth (turn-rate, speed and
//! roll limits in every frame), short and settable (`takeoff`), from the ground, for any flock
//! size. Long statistics are `#[ignore]`d: `cargo test --release --test takeoff -- --ignored`.

mod initiate_support;

use formation::initiate::{self, Cruise, InitiateOptions, InitiateStats, Start, TargetShape};
use formation::progress::Silent;
use formation::rng;
use glam::DVec2;
use initiate_support::v_shape;

/// The V of `n` birds `gap` wingspans across and `back` behind per rank, as a target shape.
fn shape_target(n: usize, gap: f64, back: f64) -> TargetShape {
    let pts: Vec<DVec2> = v_shape(n, gap, back)
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
    TargetShape::new(&pts).unwrap()
}

/// The V's spacing of the diagnostic runs: `GAP` across and `BACK` behind per rank (default 1
/// and 0.6 wingspans).
fn env_shape() -> (f64, f64) {
    let f = |name: &str, default: f64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    (f("GAP", 1.0), f("BACK", 0.6))
}

/// The air start's region from `AIRW`, `AIRD` and `AIRSPACING` (wingspans), when set.
fn env_air(opts: &mut InitiateOptions) {
    if let Start::Random(r) = &mut opts.start {
        r.width = std::env::var("AIRW").ok().and_then(|v| v.parse().ok());
        r.depth = std::env::var("AIRD").ok().and_then(|v| v.parse().ok());
        if let Some(k) = std::env::var("AIRSPACING")
            .ok()
            .and_then(|v| v.parse().ok())
        {
            r.min_spacing = k;
        }
    }
}

/// The options of the forming tests: the fast climb of the take-off before the power-limited
/// default (2.5 wingspans/s, five times a goose's), so that how long the flock takes to form, and
/// what a `takeoff` duration does to it, is not hidden behind a climb of 20 s (and the sweeps
/// stay cheap). The default climb is tested in `the_default_climb_is_the_species_power_limited_climb`
/// and `ground_take_offs_at_the_default_climb_converge_over_seeds_and_flock_sizes`.
fn fast_climb() -> InitiateOptions {
    InitiateOptions {
        climb_rate: Some(FAST_CLIMB),
        ..Default::default()
    }
}

/// The fast climb of [`fast_climb`], wingspans per second.
const FAST_CLIMB: f64 = 2.5;

fn env_u(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

fn run_stats(n: usize, seed: u64, opts: &InitiateOptions) -> InitiateStats {
    run_stats_shape(n, 1.0, 0.6, seed, opts)
}

fn run_stats_shape(
    n: usize,
    gap: f64,
    back: f64,
    seed: u64,
    opts: &InitiateOptions,
) -> InitiateStats {
    let t = shape_target(n, gap, back);
    let mut r = rng::seeded(seed);
    initiate::simulate(&t, 30.0, &Cruise::new(0.0, 10.0), opts, &mut r, &Silent)
        .unwrap()
        .stats
}

/// What `seeds` take-offs of `n` birds into the real-spacing V (0.7 across, 0.35 back) did, over
/// all seeds: runs converged, the converged runs' durations (sorted), the closest approach and
/// the largest stray (wingspans), and the largest turn and speed accelerations.
struct Sweep {
    converged: u64,
    secs: Vec<f64>,
    closest: f64,
    stray: f64,
    max_turn_accel: f64,
    max_accel: f64,
}

fn sweep(n: usize, seeds: u64, opts: &InitiateOptions) -> Sweep {
    let mut w = Sweep {
        converged: 0,
        secs: Vec::new(),
        closest: f64::INFINITY,
        stray: 0.0,
        max_turn_accel: 0.0,
        max_accel: 0.0,
    };
    for seed in 0..seeds {
        let s = run_stats_shape(n, 0.7, 0.35, seed, opts);
        if s.converged {
            w.converged += 1;
            w.secs.push(s.seconds);
        }
        w.closest = w.closest.min(s.min_distance);
        w.stray = w.stray.max(s.max_stray);
        w.max_turn_accel = w.max_turn_accel.max(s.max_turn_accel);
        w.max_accel = w.max_accel.max(s.max_accel);
    }
    w.secs.sort_by(f64::total_cmp);
    w
}

/// Durations over seeds and sizes: `SEEDS=20 SIZES=9,14,41,100 TAKEOFF=... cargo test --release
/// --test takeoff table -- --ignored --nocapture` (`PERSEED=1`: a line per seed as well).
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
        opts.climb_rate = Some(k);
        opts.vertical_accel = k;
    }
    if let Some(k) = std::env::var("ALT").ok().and_then(|v| v.parse().ok()) {
        opts.cruise_altitude = k;
    }
    if std::env::var("AIR").is_ok() {
        opts.start = Start::Random(Default::default());
    }
    env_air(&mut opts);
    for (name, field) in [
        ("APPROACH", &mut opts.approach_distance),
        ("APPTIME", &mut opts.approach_time),
        ("BRAKE", &mut opts.approach_brake),
        ("AVOID", &mut opts.avoid_distance),
        ("AVOIDRANGE", &mut opts.avoid_range),
        ("HORIZON", &mut opts.avoid_horizon),
    ] {
        if let Some(k) = std::env::var(name).ok().and_then(|v| v.parse().ok()) {
            *field = k;
        }
    }
    let (gap, back) = env_shape();
    for n in sizes {
        let mut secs = Vec::new();
        let (mut ok, mut mind, mut stray, mut lift) = (0, f64::INFINITY, 0.0f64, 0.0f64);
        let mut planned = 0.0;
        for seed in 0..seeds {
            let s = run_stats_shape(n, gap, back, seed, &opts);
            if std::env::var("PERSEED").is_ok() {
                println!(
                    "  N={n} seed {seed}: converged {} {:.1} s closest {:.3} stray {:.1}",
                    s.converged, s.seconds, s.min_distance, s.max_stray
                );
            }
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
    let (gap, back) = env_shape();
    let t = shape_target(n, gap, back);
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
                    "b{i} e{e:.2} v{:.2} z{:.2} h{:.1} w{:.1} ref{:?} slot{:?}",
                    f.speed[*i],
                    f.z[*i],
                    f.heading[*i].to_degrees(),
                    f.turn_rate[*i].to_degrees(),
                    f.reference[*i],
                    f.slot[*i]
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

use formation::animation::Animation;
use formation::initiate::sim::{self, BirdState};
use initiate_support::steady;
use std::f64::consts::PI;

fn wrap(a: f64) -> f64 {
    (a + PI).rem_euclid(2.0 * PI) - PI
}

/// The smoothness limits of issue 18, checked in every frame of `a` (initiation and steady
/// flight, hand-over included): turn-rate change ≤ 600°/s², speed change ≤ 5 wingspans/s², roll
/// rate ≤ 200°/s, and no one-frame reversal (a rate whose sign flips and flips back on the next
/// frame, each of the three rates above a visible size: 2°/s of turn, 10°/s of roll, 1
/// wingspan/s² of acceleration) of heading, bank or speed. Returns the largest turn-rate change
/// (rad/s²).
fn check_limits(a: &Animation, label: &str) -> f64 {
    let fps = a.fps;
    let fr = &a.frames;
    let mut largest = 0.0f64;
    for b in 0..a.birds {
        let rate = |k: usize, f: &dyn Fn(&formation::animation::Frame) -> f64, ang: bool| {
            let d = f(&fr[k + 1]) - f(&fr[k]);
            (if ang { wrap(d) } else { d }) / (fr[k + 1].t - fr[k].t)
        };
        let heading = |f: &formation::animation::Frame| f.heading[b];
        let speed = |f: &formation::animation::Frame| f.speed[b];
        let bank = |f: &formation::animation::Frame| f.bank.as_ref().map_or(0.0, |v| v[b]);
        let w: Vec<f64> = (0..fr.len() - 1).map(|k| rate(k, &heading, true)).collect();
        let acc: Vec<f64> = (0..fr.len() - 1).map(|k| rate(k, &speed, false)).collect();
        let roll: Vec<f64> = (0..fr.len() - 1).map(|k| rate(k, &bank, false)).collect();
        for k in 0..w.len() {
            assert!(
                acc[k].abs() <= 5.0,
                "{label}: bird {b} frame {k}: speed changes at {:.2} wingspans/s²",
                acc[k]
            );
            assert!(
                roll[k].abs() <= 200f64.to_radians(),
                "{label}: bird {b} frame {k}: rolls at {:.0}°/s",
                roll[k].to_degrees()
            );
            if k + 1 < w.len() {
                let dw = (w[k + 1] - w[k]) * fps;
                largest = largest.max(dw.abs());
                assert!(
                    dw.abs() <= 600f64.to_radians(),
                    "{label}: bird {b} frame {k}: turn rate {:.1} → {:.1}°/s ({:.0}°/s²)",
                    w[k].to_degrees(),
                    w[k + 1].to_degrees(),
                    dw.to_degrees()
                );
            }
            if k + 2 < w.len() {
                // One-frame reversal: up, down, up (or down, up, down) with rates that matter.
                for (name, r, floor) in [
                    ("heading", &w, 2f64.to_radians()),
                    ("bank", &roll, 10f64.to_radians()),
                    ("speed", &acc, 1.0),
                ] {
                    let flips = r[k] * r[k + 1] < 0.0 && r[k + 1] * r[k + 2] < 0.0;
                    let big =
                        r[k].abs() > floor && r[k + 1].abs() > floor && r[k + 2].abs() > floor;
                    assert!(
                        !(flips && big),
                        "{label}: bird {b} frames {k}..{}: {name} reverses for one frame ({:.3}, {:.3}, {:.3})",
                        k + 3,
                        r[k],
                        r[k + 1],
                        r[k + 2]
                    );
                }
            }
        }
    }
    largest
}

fn init(st: &Animation, opts: &InitiateOptions, seed: u64) -> (Animation, InitiateStats) {
    let opts = InitiateOptions {
        seed,
        ..opts.clone()
    };
    initiate::initiate(st, &opts, &mut rng::seeded(seed), &Silent).unwrap()
}

fn stage_seconds(a: &Animation) -> f64 {
    a.stage("initiation").unwrap().end as f64 / a.fps
}

#[test]
fn the_same_take_off_at_24_30_and_60_fps() {
    let shape = v_shape(9, 1.0, 0.6);
    for (seed, start) in [
        (0, Start::Ground(Default::default())),
        (1, Start::Random(Default::default())),
    ] {
        let opts = InitiateOptions {
            start,
            ..Default::default()
        };
        let runs: Vec<(f64, Animation)> = [24.0, 30.0, 60.0]
            .iter()
            .map(|&fps| (fps, init(&steady(&shape, 30, fps, 10.0), &opts, seed).0))
            .collect();
        let d30 = stage_seconds(&runs[1].1);
        for (fps, a) in &runs {
            let d = stage_seconds(a);
            assert!(
                (d - d30).abs() <= 0.05 * d30,
                "seed {seed}: {d:.2} s at {fps} fps, {d30:.2} s at 30 fps"
            );
            // Paths: every whole second of the take-off, the same positions.
            for sec in 0..(d30 as usize).min(d as usize) {
                let f = &a.frames[(sec as f64 * fps).round() as usize];
                let g = &runs[1].1.frames[sec * 30];
                for b in 0..a.birds {
                    let dp = ((f.x[b] - g.x[b]).powi(2)
                        + (f.y[b] - g.y[b]).powi(2)
                        + (f.z[b] - g.z[b]).powi(2))
                    .sqrt();
                    assert!(
                        dp < 0.05,
                        "seed {seed}, {fps} fps, t = {sec} s, bird {b}: {dp:.3} wingspans from 30 fps"
                    );
                }
            }
            check_limits(a, &format!("seed {seed} at {fps} fps"));
        }
    }
}

#[test]
fn smoothness_limits_hold_in_every_frame() {
    for n in [9usize, 14] {
        for seed in 0..3 {
            for (fps, start) in [
                (30.0, Start::Ground(Default::default())),
                (24.0, Start::Random(Default::default())),
            ] {
                let opts = InitiateOptions {
                    start,
                    ..Default::default()
                };
                let (a, _) = init(&steady(&v_shape(n, 1.0, 0.6), 60, fps, 10.0), &opts, seed);
                let largest = check_limits(&a, &format!("{n} birds, seed {seed}, {fps} fps"));
                // The birds do turn: the limits are reached, not avoided by flying straight.
                assert!(largest > 100f64.to_radians(), "{largest}");
            }
        }
    }
}

#[test]
fn bank_is_the_coordinated_turn_in_a_steady_turn() {
    let opts = InitiateOptions::default();
    let cruise = Cruise::new(0.0, 10.0);
    let p = opts.step_params(&cruise);
    let dt = p.dt();
    for (turn_deg, v) in [(20.0f64, 10.0), (-45.0, 8.0), (60.0, 12.0)] {
        let mut s = BirdState {
            pos: DVec2::ZERO,
            z: p.opts.cruise_altitude,
            climb: 0.0,
            heading: 0.0,
            turn_rate: 0.0,
            turn_accel: 0.0,
            speed: v,
            accel: 0.0,
            bank: 0.0,
            roll_rate: 0.0,
        };
        let mut prev = s;
        for _ in 0..(5.0 / dt) as usize {
            s = sim::fly(&s, turn_deg.to_radians(), v, &p, dt);
            assert!(
                (s.turn_rate - prev.turn_rate).abs() <= p.opts.max_turn_accel * dt * (1.0 + 1e-9)
            );
            assert!((s.bank - prev.bank).abs() <= p.opts.max_roll_rate * dt * (1.0 + 1e-9));
            prev = s;
        }
        let g = 9.81 / 1.5;
        let want = (s.speed * s.turn_rate / g).atan();
        assert!((s.turn_rate - turn_deg.to_radians()).abs() < 1e-9);
        assert!(
            (s.bank - want).abs() < 1e-6,
            "{turn_deg}°/s at {v}: bank {:.4}, V·ω/g gives {want:.4}",
            s.bank
        );
        // Right turn, right wing down.
        assert_eq!(s.bank > 0.0, turn_deg > 0.0);
    }
    // Straight and level: no bank at all.
    let (a, _) = init(
        &steady(&v_shape(9, 1.0, 0.6), 30, 30.0, 10.0),
        &InitiateOptions::default(),
        2,
    );
    let k = a.stage("initiation").unwrap().end;
    for f in &a.frames[k..] {
        assert!(f.bank.as_ref().unwrap().iter().all(|&b| b == 0.0));
    }
}

#[test]
fn ground_birds_start_at_rest_and_end_at_the_cruise_altitude() {
    for alt in [10.0, 25.0] {
        let opts = InitiateOptions {
            cruise_altitude: alt,
            ground_seconds: 0.0,
            ..Default::default()
        };
        let st = steady(&v_shape(14, 1.0, 0.6), 30, 30.0, 10.0);
        let (a, stats) = init(&st, &opts, 4);
        let f0 = &a.frames[0];
        assert!(f0.z.iter().all(|&z| z == 0.0), "{:?}", f0.z);
        assert!(f0.speed.iter().all(|&v| v == 0.0), "{:?}", f0.speed);
        // Staggered: some birds are still at rest a moment later.
        let f1 = &a.frames[15];
        assert!(f1.speed.contains(&0.0) && f1.speed.iter().any(|&v| v > 0.0));
        assert!(stats.last_liftoff > 0.5);
        let k = a.stage("initiation").unwrap().end;
        for f in &a.frames[k - 1..] {
            for b in 0..a.birds {
                assert!((f.z[b] - alt).abs() < 0.1, "frame z {} at {alt}", f.z[b]);
            }
        }
        // The climb rate is plausible: at most the goose's power-limited climb (0.51
        // wingspans/s; the steady flight names no species, a goose of its 1.5 m wingspan).
        let w_max = opts.climb_rate_for(&Cruise::new(0.0, 10.0));
        assert!((w_max - 0.51).abs() < 0.01, "{w_max}");
        // Near the ground the burst climb after lift-off (at most 2.5 wingspans/s, tapering
        // off by 2 wingspans up).
        for w in a.frames.windows(2) {
            for b in 0..a.birds {
                let climb = (w[1].z[b] - w[0].z[b]) / (w[1].t - w[0].t);
                let limit = initiate::sim::climb_limit(w_max, w[0].z[b]);
                // (0.01: the climb rate sheds the burst at the bounded vertical acceleration.)
                assert!(climb <= limit + 0.01, "{climb} at {}", w[0].z[b]);
                assert!(limit <= initiate::sim::LIFTOFF_BURST_CLIMB);
            }
        }
    }
    // The airborne start is at the cruise altitude from the first frame.
    let opts = InitiateOptions {
        start: Start::Random(Default::default()),
        ..Default::default()
    };
    let (a, _) = init(&steady(&v_shape(9, 1.0, 0.6), 30, 30.0, 10.0), &opts, 4);
    // Scattered in height within the band around the cruise altitude.
    let band = initiate::AIR_HEIGHT_BAND + 1e-9;
    assert!(a.frames[0]
        .z
        .iter()
        .all(|&z| (z - opts.cruise_altitude).abs() <= band));
    assert!(a.frames[0].z.iter().any(|&z| z != opts.cruise_altitude));
    assert!(a.frames[0].speed.iter().all(|&v| v > 0.0));
}

#[test]
fn ground_take_offs_converge_without_collisions() {
    let opts = InitiateOptions::default();
    for n in [9usize, 14] {
        let seeds = if cfg!(debug_assertions) { 2 } else { 10 };
        for seed in 0..seeds {
            let s = run_stats(n, seed, &opts);
            assert!(s.converged, "{n} birds, seed {seed}: {s:?}");
            assert!(
                s.min_distance >= 0.3,
                "{n} birds, seed {seed}: two birds came {:.3} wingspans close (3-D)",
                s.min_distance
            );
            assert!(s.max_turn_accel <= opts.max_turn_accel * (1.0 + 1e-9));
            assert!(s.max_accel <= opts.max_accel * (1.0 + 1e-9));
        }
    }
}

/// The V forms when `takeoff` asks (median over seeds within 25 %, from the start of the
/// take-off, the sitting included) at real spacing (lateral gaps of 0.7 wingspans, wingtips
/// overlapping), and by default the take-off lasts at most 12 s for 9–14 birds at a fast climb.
#[test]
fn takeoff_8_and_20_seconds_are_met_and_the_default_is_short() {
    let seeds = if cfg!(debug_assertions) { 3 } else { 11 };
    for n in [9usize, 14] {
        for want in [None, Some(8.0), Some(20.0)] {
            let opts = InitiateOptions {
                takeoff: want,
                ..fast_climb()
            };
            let mut secs: Vec<f64> = (0..seeds)
                .map(|seed| {
                    let s = run_stats_shape(n, 0.7, 0.35, seed, &opts);
                    assert!(s.converged, "{n} birds, seed {seed}, --takeoff {want:?}");
                    match want {
                        Some(_) => s.formed_seconds.expect("the V formed"),
                        None => s.seconds,
                    }
                })
                .collect();
            secs.sort_by(f64::total_cmp);
            let med = secs[secs.len() / 2];
            match want {
                Some(want) => assert!(
                    (med - want).abs() <= 0.25 * want,
                    "{n} birds, --takeoff {want}: V formed after a median {med:.1} s ({secs:?})"
                ),
                None => assert!(med <= 12.0, "{n} birds: median {med:.1} s ({secs:?})"),
            }
        }
    }
}

/// At the goose's power-limited climb (the README job's), `--takeoff` 8, 12 and 20 form the V
/// in about that time (median of 5 seeds within 25 %), 14 birds at real spacing; the climb to the
/// cruise altitude goes on at the birds' own pace, and the stats say when each ended. The V
/// formed after 8.2–10.0 s whatever `--takeoff` said before it set the formation's drive alone
/// (`--takeoff 20`: 8.5 s).
#[test]
fn takeoff_8_12_and_20_form_the_v_in_about_that_time_at_the_default_climb() {
    let seeds = if cfg!(debug_assertions) { 1 } else { 5 };
    let n = 14;
    for want in [8.0, 12.0, 20.0] {
        let opts = InitiateOptions {
            takeoff: Some(want),
            ..Default::default()
        };
        assert!(
            initiate::TakeoffPlan::warning(n, &opts, &Cruise::new(0.0, 10.0)).is_none(),
            "--takeoff {want} is within reach"
        );
        let mut formed = Vec::new();
        for seed in 0..seeds {
            let s = run_stats_shape(n, 0.7, 0.35, seed, &opts);
            assert!(s.converged, "--takeoff {want}, seed {seed}");
            let f = s.formed_seconds.expect("the V formed");
            let high = s
                .cruise_height_seconds
                .expect("the flock reached its height");
            // Formed and at the cruise height before (or when) the take-off converged, the
            // first lift-off after the sitting.
            assert!(f <= s.seconds && high <= s.seconds, "{s:?}");
            assert!(s.first_liftoff >= opts.ground_seconds - 1e-9, "{s:?}");
            assert!(s.first_liftoff <= s.last_liftoff, "{s:?}");
            assert!(s.min_distance >= 0.3, "--takeoff {want}: {s:?}");
            formed.push(f);
        }
        formed.sort_by(f64::total_cmp);
        let med = formed[formed.len() / 2];
        assert!(
            (med - want).abs() <= 0.25 * want,
            "--takeoff {want}: the V formed after a median {med:.1} s ({formed:?})"
        );
    }
}

/// Issue 18: ground take-offs into a V at real spacing (0.7 wingspans across, wingtips
/// overlapping) converge in at least 99 % of 100 seeds for 9, 14, 41 and 100 birds and in all of
/// 10 seeds for 300, within the durations (median ≤ 12 s for 9–14, ≤ 30 s for 100, every
/// 300-bird run ≤ 45 s), no bird straying more than 30 wingspans beyond the formed flock, closest
/// approach ≥ 0.3 wingspans (3-D) in every decision and written frame. Measured
/// (docs/initiation.md): 100/100 each, 10/10; closest 0.417/0.382/0.393/0.375, 300 birds 0.320;
/// strays 11.0/11.6/14.3/20.9, 300 birds 28.9.
#[test]
fn convergence_over_seeds_and_flock_sizes() {
    let opts = fast_climb();
    let (many, few) = if cfg!(debug_assertions) {
        (2, 1)
    } else {
        (100, 10)
    };
    for (n, seeds, median_max) in [
        (9usize, many, 12.0),
        (14, many, 12.0),
        (41, many, 30.0),
        (100, many, 30.0),
        (300, few, 45.0),
    ] {
        let Sweep {
            converged: ok,
            secs,
            closest,
            stray,
            ..
        } = sweep(n, seeds, &opts);
        assert!(ok * 100 >= 99 * seeds, "{n} birds: {ok}/{seeds} converged");
        let median = secs[secs.len() / 2];
        assert!(median <= median_max, "{n} birds: median {median:.1} s");
        if n == 300 {
            assert!(secs.iter().all(|&s| s <= 45.0), "300 birds: {secs:?}");
        }
        assert!(closest >= 0.3, "{n} birds: closest approach {closest:.3}");
        assert!(
            stray <= 30.0,
            "{n} birds: a bird strayed {stray:.1} wingspans"
        );
    }
}

/// The paper's airborne start (`--start air`: scattered, any heading) converges in at least 99 %
/// of the runs for 9, 14, 41 and 100 birds (100 seeds) and 300 birds (10 seeds), within the
/// smoothness limits, no bird strays more than 30 wingspans beyond the formed flock, and the
/// closest approach (3-D) is at least 0.3 wingspans for every size (since the start heights are
/// checked against a dry run of the turns; before: 0.178/0.099/0.134 for 41/100/300 birds).
/// 300 birds strayed up to 33.6 wingspans while the leader could be 17 wingspans off the
/// middle of the start region; it is now within `AIR_LEADER_OFFSET` (8) of the middle bird.
/// Measured (docs/initiation.md): closest 0.378/0.344/0.346/0.313/0.346, strays
/// 23.9/25.8/25.7/28.8/28.3 wingspans.
#[test]
fn air_start_converges_over_seeds_and_flock_sizes() {
    let opts = InitiateOptions {
        start: Start::Random(Default::default()),
        ..Default::default()
    };
    let (many, few) = if cfg!(debug_assertions) {
        (2, 1)
    } else {
        (100, 10)
    };
    for (n, seeds) in [
        (9usize, many),
        (14, many),
        (41, many),
        (100, many),
        (300, few),
    ] {
        let w = sweep(n, seeds, &opts);
        assert!(w.max_turn_accel <= opts.max_turn_accel * (1.0 + 1e-9));
        assert!(w.max_accel <= opts.max_accel * (1.0 + 1e-9));
        let (ok, closest, stray) = (w.converged, w.closest, w.stray);
        println!("{n} birds from the air: {ok}/{seeds} converged, closest {closest:.4}, stray {stray:.1}");
        assert!(
            ok * 100 >= 99 * seeds,
            "{n} birds from the air: {ok}/{seeds} converged"
        );
        assert!(
            stray <= 30.0,
            "{n} birds from the air: a bird strayed {stray:.1} wingspans"
        );
        assert!(
            closest >= 0.3,
            "{n} birds from the air: closest approach {closest:.3}"
        );
    }
}

/// Take-offs of other lengths keep the limits too: `--takeoff 8` (9, 14, 41 birds; 100 and 300
/// cannot take off that fast and are warned about, but fly at the strongest drive) and
/// `--takeoff 20` (9, 14, 41, 100 birds), 21 seeds each (5 for 300) at real spacing: every run
/// converges, the closest approach (3-D) is at least 0.3 wingspans and no bird strays more than
/// 30 wingspans. Before, `--takeoff 20` widened the take-off area by 1/drive (41 birds: 53 × 18
/// wingspans) and 41 birds came 0.20 close and strayed 35 wingspans; the area now grows by
/// 1/√drive. The final approach was driven as hard as the rest of a short take-off, and 100
/// birds at `--takeoff 8` came 0.293 close (300 birds: 0.220); it is now driven at most as hard
/// as in the natural take-off (`TakeoffPlan::MAX_APPROACH_DRIVE`). Measured (docs/initiation.md):
/// `--takeoff 8` closest 0.601/0.414/0.430/0.360/0.344, strays 10.5/11.0/13.5/19.8/28.4;
/// `--takeoff 20` closest 0.569/0.586/0.442/0.336, strays 19.7/19.1/21.8/23.5.
#[test]
fn takeoff_8_and_20_keep_apart_and_close_in() {
    let (many, few) = if cfg!(debug_assertions) {
        (2, 1)
    } else {
        (21, 5)
    };
    for (want, sizes) in [
        (
            8.0,
            &[
                (9usize, many),
                (14, many),
                (41, many),
                (100, many),
                (300, few),
            ][..],
        ),
        (20.0, &[(9, many), (14, many), (41, many), (100, many)][..]),
    ] {
        let opts = InitiateOptions {
            takeoff: Some(want),
            ..fast_climb()
        };
        for &(n, seeds) in sizes {
            for seed in 0..seeds {
                let s = run_stats_shape(n, 0.7, 0.35, seed, &opts);
                let label = format!("--takeoff {want}, {n} birds, seed {seed}");
                assert!(s.converged, "{label}: did not converge");
                assert!(
                    s.min_distance >= 0.3,
                    "{label}: two birds came {:.3} wingspans close (3-D)",
                    s.min_distance
                );
                assert!(
                    s.max_stray <= 30.0,
                    "{label}: a bird strayed {:.1} wingspans",
                    s.max_stray
                );
            }
        }
    }
}

/// `--takeoff 8` forms the V within 25 % up to 41 birds at real spacing (median of 11 seeds);
/// for 100 birds, which cannot form that fast, the take-off plan warns with the range it can, and
/// the V forms after about the shortest time (within 25 %).
#[test]
fn takeoff_8_for_larger_flocks_is_met_or_warned_about() {
    let seeds = if cfg!(debug_assertions) { 1 } else { 11 };
    for n in [41usize, 100] {
        let opts = InitiateOptions {
            takeoff: Some(8.0),
            ..fast_climb()
        };
        let mut secs: Vec<f64> = (0..seeds)
            .map(|seed| {
                let s = run_stats_shape(n, 0.7, 0.35, seed, &opts);
                assert!(s.converged, "{n} birds, seed {seed}");
                s.formed_seconds.expect("the V formed")
            })
            .collect();
        secs.sort_by(f64::total_cmp);
        let med = secs[secs.len() / 2];
        let cruise = Cruise::new(0.0, 10.0);
        let warning = initiate::TakeoffPlan::warning(n, &opts, &cruise);
        if n <= 41 {
            assert!(warning.is_none(), "{warning:?}");
            assert!((med - 8.0).abs() <= 2.0, "{n} birds: median {med:.1} s");
        } else {
            let w = warning.expect("100 birds cannot form in 8 s: a warning");
            let shortest = initiate::TakeoffPlan::shortest_form_seconds(n, &opts);
            let longest = initiate::TakeoffPlan::longest_form_seconds(n, &opts);
            assert!(
                w.contains("initiate.takeoff")
                    && w.contains(&format!("about {shortest:.0} to {longest:.0} s")),
                "{w}"
            );
            assert!(
                (med - shortest).abs() <= 0.25 * shortest,
                "{n} birds: median {med:.1} s, warned {shortest:.1}"
            );
        }
    }
    // Within reach: no warning, also at the goose's power-limited climb (the climb to the cruise
    // altitude goes on after the V has formed).
    let cruise = Cruise::new(0.0, 10.0);
    for opts in [fast_climb(), InitiateOptions::default()] {
        for t in [8.0, 10.0, 20.0] {
            let opts = InitiateOptions {
                takeoff: Some(t),
                ..opts.clone()
            };
            assert!(initiate::TakeoffPlan::warning(14, &opts, &cruise).is_none());
        }
    }
    // Out of reach both ways: the warning gives the range.
    for t in [4.0, 60.0] {
        let opts = InitiateOptions {
            takeoff: Some(t),
            ..Default::default()
        };
        let w = initiate::TakeoffPlan::warning(9, &opts, &cruise).expect("a warning");
        let shortest = initiate::TakeoffPlan::shortest_form_seconds(9, &opts);
        let longest = initiate::TakeoffPlan::longest_form_seconds(9, &opts);
        assert!((7.0..9.0).contains(&shortest), "{shortest}");
        assert!(
            w.contains(&format!("about {shortest:.0} to {longest:.0} s")),
            "{w}"
        );
    }
}

#[test]
#[ignore]
fn dump() {
    let seed = env_u("SEED").unwrap_or(1);
    let fps = env_u("FPS").unwrap_or(24) as f64;
    let b = env_u("BIRD").unwrap_or(4) as usize;
    let from = env_u("FROM").unwrap_or(365) as usize;
    let opts = InitiateOptions {
        start: Start::Random(Default::default()),
        ..Default::default()
    };
    let (a, _) = init(&steady(&v_shape(9, 1.0, 0.6), 60, fps, 10.0), &opts, seed);
    println!("initiation ends at {}", a.stage("initiation").unwrap().end);
    for k in from..from + 14 {
        let f = &a.frames[k];
        println!(
            "{k} t {:.3} h {:.4} bank {:.4} v {:.3}",
            f.t,
            f.heading[b].to_degrees(),
            f.bank.as_ref().unwrap()[b].to_degrees(),
            f.speed[b]
        );
    }
}

#[test]
#[ignore]
fn closest() {
    let n = env_u("N").unwrap_or(41) as usize;
    let seeds: Vec<u64> = match std::env::var("SEEDLIST") {
        Ok(l) => l.split(',').filter_map(|s| s.trim().parse().ok()).collect(),
        Err(_) => (env_u("SEED0").unwrap_or(0)..env_u("SEEDS").unwrap_or(10)).collect(),
    };
    let until = env_u("TMAX").unwrap_or(80) as f64;
    for seed in seeds {
        let mut opts = InitiateOptions::default();
        if std::env::var("AIR").is_ok() {
            opts.start = Start::Random(Default::default());
        }
        env_air(&mut opts);
        if let Ok(t) = std::env::var("TAKEOFF") {
            opts.takeoff = t.parse().ok();
        }
        let (gap, back) = env_shape();
        let t = shape_target(n, gap, back);
        let (mut sim, _) =
            initiate::start_simulation(&t, &Cruise::new(0.0, 10.0), &opts, &mut rng::seeded(seed))
                .unwrap();
        let mut best = (f64::INFINITY, 0.0, String::new());
        while sim.time < until {
            sim.step();
            let f = &sim.flock;
            for a in 0..n {
                for b in a + 1..n {
                    let d =
                        ((f.pos[a] - f.pos[b]).length_squared() + (f.z[a] - f.z[b]).powi(2)).sqrt();
                    if d < best.0 {
                        let sp = sim.slot_positions();
                        let e =
                            |i: usize| f.slot[i].map_or(f64::NAN, |s| (f.pos[i] - sp[s]).length());
                        best = (d, sim.time, format!(
                            "{a}:{:?} z{:.2} v{:.1} h{:.0} slot{:?} e{:.2} | {b}:{:?} z{:.2} v{:.1} h{:.0} slot{:?} e{:.2}",
                            f.phase[a], f.z[a], f.speed[a], f.heading[a].to_degrees(), f.slot[a], e(a),
                            f.phase[b], f.z[b], f.speed[b], f.heading[b].to_degrees(), f.slot[b], e(b)));
                    }
                }
            }
        }
        println!("seed {seed}: {:.3} at {:.2} s: {}", best.0, best.1, best.2);
    }
}

/// Two birds of one take-off in the formation frame (x right, y behind the leader, wingspans):
/// `N=100 SEED=44 A=60 B=70 FROM=6 TO=10 cargo test --release --test takeoff pair -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn pair() {
    let n = env_u("N").unwrap_or(100) as usize;
    let seed = env_u("SEED").unwrap_or(44);
    let (a, b) = (
        env_u("A").unwrap_or(60) as usize,
        env_u("B").unwrap_or(70) as usize,
    );
    let from = env_u("FROM").unwrap_or(0) as f64;
    let to = env_u("TO").unwrap_or(20) as f64;
    let mut opts = InitiateOptions::default();
    if std::env::var("AIR").is_ok() {
        opts.start = Start::Random(Default::default());
    }
    env_air(&mut opts);
    let (gap, back) = env_shape();
    let t = shape_target(n, gap, back);
    let (mut sim, _) =
        initiate::start_simulation(&t, &Cruise::new(0.0, 10.0), &opts, &mut rng::seeded(seed))
            .unwrap();
    let mut next = from;
    while sim.time < to {
        sim.step();
        if sim.time + 1e-9 < next {
            continue;
        }
        next += 0.1;
        let f = &sim.flock;
        let l = f.pos[f.leader];
        let sp = sim.slot_positions();
        let row = |i: usize| {
            let r = f.pos[i] - l;
            let s = sp[f.slot[i].unwrap()] - l;
            format!(
                "{i}:{:?} x{:6.2} y{:6.2} sx{:6.2} sy{:6.2} z{:5.2} v{:5.2} h{:5.0} w{:5.0}",
                f.phase[i],
                r.x,
                -r.y,
                s.x,
                -s.y,
                f.z[i],
                f.speed[i],
                f.heading[i].to_degrees(),
                f.turn_rate[i].to_degrees()
            )
        };
        let d = ((f.pos[a] - f.pos[b]).length_squared() + (f.z[a] - f.z[b]).powi(2)).sqrt();
        println!("t{:5.2} d{d:.2} | {} | {}", sim.time, row(a), row(b));
    }
}

/// The bird farthest from every slot, each half second once all are airborne: `N=300 SEED=0
/// cargo test --release --test takeoff strays -- --ignored --nocapture`.
#[test]
#[ignore]
fn strays() {
    let n = env_u("N").unwrap_or(300) as usize;
    let seed = env_u("SEED").unwrap_or(0);
    let mut opts = InitiateOptions::default();
    if std::env::var("AIR").is_ok() {
        opts.start = Start::Random(Default::default());
    }
    env_air(&mut opts);
    let (gap, back) = env_shape();
    let t = shape_target(n, gap, back);
    let (mut sim, plan) =
        initiate::start_simulation(&t, &Cruise::new(0.0, 10.0), &opts, &mut rng::seeded(seed))
            .unwrap();
    println!("{plan:?}");
    let f = &sim.flock;
    let l0 = f.pos[f.leader];
    println!("leader start x{:.1} y{:.1}", l0.x, l0.y);
    let mut next = 0.0;
    while sim.time < 30.0 {
        sim.step();
        if sim.time + 1e-9 < next {
            continue;
        }
        next += 0.5;
        let f = &sim.flock;
        let l = f.pos[f.leader];
        let sp = sim.slot_positions();
        let (d, i) = (0..n)
            .map(|i| {
                let d = sp
                    .iter()
                    .map(|s| (*s - f.pos[i]).length())
                    .fold(f64::INFINITY, f64::min);
                (d, i)
            })
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        let r = f.pos[i] - l;
        let s = sp[f.slot[i].unwrap()] - l;
        let start = f.pos[i] - l0;
        println!(
            "t{:5.2} air {} stray {d:5.1} bird {i} {:?} x{:6.1} y{:6.1} slot x{:6.1} y{:6.1} z{:4.1} v{:4.1} h{:4.0} depart {:.2} | lead v{:.1} y{:.1}",
            sim.time,
            sim.all_airborne(),
            f.phase[i],
            r.x,
            -r.y,
            s.x,
            -s.y,
            f.z[i],
            f.speed[i],
            f.heading[i].to_degrees(),
            f.depart[i],
            f.speed[f.leader],
            (l - l0).y
        );
        let _ = start;
    }
}

/// The take-off climbs at the species' power-limited climb by default (goose 0.51, crane 0.31,
/// pelican 0.23 wingspans/s at their typical wingspans): above the burst climb after lift-off
/// (the lowest 2 wingspans) no frame climbs faster, the climb
/// reaches that rate, and the take-off lasts what the plan expects of it (the climb to 10
/// wingspans dominating: about 21, 32 and 41 s from the first run), within 10 %.
#[test]
fn the_default_climb_is_the_species_power_limited_climb() {
    use formation::aero::flight::Morphology;
    use formation::animation::wing::Species;
    for (sp, want) in [
        (Species::Goose, 0.51),
        (Species::Crane, 0.31),
        (Species::Pelican, 0.23),
    ] {
        let span = Morphology::of(sp).span_m;
        let mut st = steady(&v_shape(14, 1.0, 0.6), 30, 30.0, 10.0);
        st.species = Some(sp.name().into());
        st.wingspan_m = span;
        let (_, cruise) = initiate::steady_target(&st).unwrap();
        assert!(
            (cruise.climb_rate - want).abs() < 0.01,
            "{sp:?}: {}",
            cruise.climb_rate
        );
        let opts = InitiateOptions::default();
        let (a, stats) = init(&st, &opts, 3);
        assert!(stats.converged);
        assert!(stats.min_distance >= 0.3, "{sp:?}: {}", stats.min_distance);
        // A wingspan above the burst climb's height (2 wingspans), the burst shed.
        let mut fastest = 0.0f64;
        for w in a.frames.windows(2) {
            for b in 0..a.birds {
                if w[0].z[b] >= initiate::sim::LIFTOFF_BURST_HEIGHT + 1.0 {
                    fastest = fastest.max((w[1].z[b] - w[0].z[b]) / (w[1].t - w[0].t));
                }
            }
        }
        assert!(fastest <= cruise.climb_rate + 1e-9, "{sp:?}: {fastest}");
        assert!(fastest >= 0.95 * cruise.climb_rate, "{sp:?}: {fastest}");
        let planned = initiate::TakeoffPlan::natural_seconds(14, &opts, &cruise);
        let took = stage_seconds(&a) - opts.ground_seconds;
        assert!(
            (took - planned).abs() <= 0.1 * planned,
            "{sp:?}: {took:.1} s, planned {planned:.1} s"
        );
    }
}

/// Ground take-offs at the default (power-limited) climb into a V at real spacing converge for
/// 9, 14, 41 and 100 birds (5 seeds each), closest approach ≥ 0.3 wingspans (3-D), no bird
/// straying more than 30 wingspans, and last about the goose's climb (23.7 s from the first run)
/// plus at most 15 %.
#[test]
fn ground_take_offs_at_the_default_climb_converge_over_seeds_and_flock_sizes() {
    let opts = InitiateOptions::default();
    let seeds = if cfg!(debug_assertions) { 1 } else { 5 };
    let planned = initiate::TakeoffPlan::natural_seconds(9, &opts, &Cruise::new(0.0, 10.0));
    for n in [9usize, 14, 41, 100] {
        let w = sweep(n, seeds, &opts);
        let label = format!("{n} birds at the default climb");
        assert_eq!(w.converged, seeds, "{label}");
        assert!(w.closest >= 0.3, "{label}: closest {:.3}", w.closest);
        assert!(w.stray <= 30.0, "{label}: strayed {:.1}", w.stray);
        let slowest = w.secs[w.secs.len() - 1] - opts.ground_seconds;
        assert!(
            slowest <= 1.15 * planned,
            "{label}: {slowest:.1} s, planned {planned:.1}"
        );
        println!(
            "{label}: {:?} s, closest {:.3}, stray {:.1}",
            w.secs, w.closest, w.stray
        );
    }
}
