//! Measurements behind docs/initiation.md (ignored by default; run with
//! `cargo test --release --test initiate_stats -- --ignored --nocapture`).
#![allow(clippy::needless_range_loop)]

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
        let heading = env_f("HEADING").unwrap_or(0.0).to_radians();
        let run = initiate::simulate(
            &t,
            30.0,
            &initiate::Cruise::new(heading, 10.0),
            opts,
            &mut r,
            &Silent,
        )
        .unwrap();
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

/// A simulation of an airborne start (the paper's) at the cruise altitude.
fn air_sim(
    t: TargetShape,
    params: initiate::StepParams,
    p: Vec<DVec2>,
    h: Vec<f64>,
    v: Vec<f64>,
) -> initiate::Simulation {
    let n = p.len();
    let z = vec![params.opts.cruise_altitude; n];
    initiate::Simulation::new(t, params, p, z, h, v, vec![0.0; n])
}

fn env_f(name: &str) -> Option<f64> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

/// Defaults, overridden by environment variables for parameter sweeps.
fn env_opts() -> InitiateOptions {
    let mut o = InitiateOptions::default();
    // The paper's airborne start unless GROUND is set.
    if std::env::var("GROUND").is_err() {
        o.start = initiate::Start::Random(Default::default());
    }
    if let Some(v) = env_f("AVOID") {
        o.avoid_distance = v;
    }
    if let Some(v) = env_f("RANGE") {
        o.avoid_range = v;
    }
    if let Some(v) = env_f("HORIZON") {
        o.avoid_horizon = v;
    }
    if let Some(v) = env_f("TURN") {
        o.max_turn_rate = v.to_radians();
    }
    if let Some(v) = env_f("ACCEL") {
        o.max_accel = v;
    }
    if let Some(v) = env_f("GAMMA") {
        o.perception.mode = initiate::PerceptionMode::Hpr { gamma: v };
    }
    if std::env::var("EXACT").is_ok() {
        o.perception.mode = initiate::PerceptionMode::Exact;
    }
    if let Some(v) = env_f("K") {
        o.k = v;
    }
    if let Some(v) = env_f("MEMORY") {
        o.reference_memory = Some(v);
    }
    if let Some(v) = env_f("SPREAD") {
        if let initiate::Start::Random(r) = &mut o.start {
            r.heading_spread = v.to_radians();
        }
    }
    o
}

#[test]
#[ignore]
fn convergence_rates() {
    let seeds: u64 = std::env::var("SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let opts = env_opts();
    let shape = std::env::var("SHAPE").unwrap_or_else(|_| "v".into());
    for n in [9usize, 14, 41] {
        let s = if n == 41 { seeds / 2 } else { seeds };
        let pts = match shape.as_str() {
            "u" => initiate_support::u_shape(n),
            "e" => initiate_support::echelon(n),
            "vwide" => initiate_support::v_shape(n, 1.2, 1.0),
            _ => initiate_support::v_shape(n, 1.0, 0.6),
        };
        rate(&format!("{shape}{n}"), &pts, s, &opts);
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
    let opts = env_opts();
    let t = target(&if std::env::var("SHAPE").is_ok() {
        initiate_support::u_shape(n)
    } else {
        initiate_support::v_shape(n, 1.0, 0.6)
    });
    let params = opts.step_params(&initiate::Cruise::new(0.0, 10.0));
    let mut r = rng::seeded(seed);
    let region = match &opts.start {
        initiate::Start::Random(r) => *r,
        _ => initiate::StartRegion::default(),
    };
    let (p, h, v) = initiate::random_start(n, &region, &params, &mut r).unwrap();
    let mut sim = air_sim(t, params.clone(), p, h, v);
    let steps: usize = std::env::var("STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(9000);
    for step in 0..steps {
        sim.step();
        if step + 1 == steps {
            let f = &sim.flock;
            let slots = sim.slot_positions();
            for i in 0..n {
                let err = f.slot[i].map(|s| f.pos[i] - slots[s]);
                println!(
                    "  bird {i}: pos ({:.2},{:.2}) hd {:.1}° v {:.3} ref {:?} side {:?} slot {:?} err {:?}",
                    f.pos[i].x, f.pos[i].y, f.heading[i].to_degrees(), f.speed[i], f.reference[i], f.side[i], f.slot[i], err
                );
            }
        }
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

#[test]
#[ignore]
fn near_misses() {
    let n: usize = std::env::var("N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(41);
    let seeds: u64 = std::env::var("SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let opts = env_opts();
    let t = target(&initiate_support::v_shape(n, 1.0, 0.6));
    let params = opts.step_params(&initiate::Cruise::new(0.0, 10.0));
    let region = match &opts.start {
        initiate::Start::Random(r) => *r,
        _ => initiate::StartRegion::default(),
    };
    for seed in 0..seeds {
        let mut r = rng::seeded(seed);
        let (p, h, v) = initiate::random_start(n, &region, &params, &mut r).unwrap();
        let mut sim = air_sim(t.clone(), params.clone(), p, h, v);
        let mut prev: Option<initiate::sim::Flock> = None;
        for step in 0..2500 {
            sim.step();
            let f = &sim.flock;
            let mut best = (f64::INFINITY, 0, 0);
            for a in 0..n {
                for b in a + 1..n {
                    let d = (f.pos[a] - f.pos[b]).length();
                    if d < best.0 {
                        best = (d, a, b);
                    }
                }
            }
            if best.0 < 0.25 {
                let (_, a, b) = best;
                let pf = prev.as_ref().unwrap();
                println!(
                    "seed {seed} step {step}: birds {a},{b} d={:.3} leader {}",
                    best.0, f.leader
                );
                for i in [a, b] {
                    println!(
                        "  bird {i}: pos ({:.2},{:.2}) hd {:.1}° v {:.3} ref {:?} side {:?} slot {:?}; prev hd {:.1}° ref {:?}",
                        f.pos[i].x, f.pos[i].y, f.heading[i].to_degrees(), f.speed[i], f.reference[i], f.side[i], f.slot[i],
                        pf.heading[i].to_degrees(), pf.reference[i]
                    );
                }
                break;
            }
            prev = Some(sim.flock.clone());
        }
    }
}

/// HPR with an absolute flipping radius (the paper's literal "R = half a wingspan").
fn hpr_absolute(viewer: usize, pos: &[DVec2], heading: f64, r_flip: f64) -> Vec<usize> {
    use formation::initiate::perception::in_field_of_view;
    let p = pos[viewer];
    let cand: Vec<usize> = (0..pos.len())
        .filter(|&j| {
            j != viewer && in_field_of_view(heading, pos[j] - p, std::f64::consts::FRAC_PI_2)
        })
        .collect();
    let mut pts = vec![DVec2::ZERO];
    for &j in &cand {
        let q = pos[j] - p;
        pts.push(q * (2.0 * r_flip / q.length() - 1.0));
    }
    let (mut sorted, mut hull) = (Vec::new(), Vec::new());
    initiate::hull::convex_hull(&pts, &mut sorted, &mut hull);
    let mut out: Vec<usize> = hull
        .iter()
        .filter(|&&h| h > 0)
        .map(|&h| cand[h - 1])
        .collect();
    out.sort_unstable();
    out
}

#[test]
#[ignore]
fn hpr_agreement() {
    use formation::initiate::perception::{choose_reference, Perceiver};
    use formation::initiate::{PerceptionMode, PerceptionParams};
    let flocks: u64 = std::env::var("FLOCKS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let opts = InitiateOptions::default();
    let params = opts.step_params(&initiate::Cruise::new(0.0, 10.0));
    let cone = 0.35 * std::f64::consts::PI;
    for n in [9usize, 14, 41] {
        // Configurations: random take-off clusters, and the flock 5 s and 20 s into an initiation.
        let mut configs: Vec<(Vec<DVec2>, Vec<f64>)> = Vec::new();
        for seed in 0..flocks {
            let mut r = rng::seeded(1000 + seed);
            let (p, h, v) =
                initiate::random_start(n, &initiate::StartRegion::default(), &params, &mut r)
                    .unwrap();
            configs.push((p.clone(), h.clone()));
            let t = target(&initiate_support::v_shape(n, 1.0, 0.6));
            let mut sim = air_sim(t, params.clone(), p, h, v);
            for step in 1..=2400 {
                sim.step();
                if step == 600 || step == 2400 {
                    configs.push((sim.flock.pos.clone(), sim.flock.heading.clone()));
                }
            }
        }
        let exact = PerceptionParams {
            mode: PerceptionMode::Exact,
            ..Default::default()
        };
        let mut perceiver = Perceiver::new();
        let variants: Vec<(String, Option<f64>)> = vec![
            ("R = 0.5 wingspan".into(), None),
            ("γ = 0.5".into(), Some(0.5)),
            ("γ = 1".into(), Some(1.0)),
            ("γ = 1.5".into(), Some(1.5)),
            ("γ = 2".into(), Some(2.0)),
            ("γ = 3".into(), Some(3.0)),
        ];
        for (label, gamma) in variants {
            let (mut views, mut same_set, mut same_ref, mut jac, mut refs) =
                (0usize, 0usize, 0usize, 0.0, 0usize);
            for (pos, heading) in &configs {
                for i in 0..n {
                    let mut ve = Vec::new();
                    perceiver.visible(i, pos, heading[i], &exact, &mut ve);
                    let vh = match gamma {
                        None => hpr_absolute(i, pos, heading[i], 0.5),
                        Some(g) => {
                            let hp = PerceptionParams {
                                mode: PerceptionMode::Hpr { gamma: g },
                                ..Default::default()
                            };
                            let mut v = Vec::new();
                            perceiver.visible(i, pos, heading[i], &hp, &mut v);
                            v
                        }
                    };
                    views += 1;
                    if ve == vh {
                        same_set += 1;
                    }
                    let inter = ve.iter().filter(|j| vh.contains(j)).count() as f64;
                    let uni = (ve.len() + vh.len()) as f64 - inter;
                    jac += if uni > 0.0 { inter / uni } else { 1.0 };
                    let re = choose_reference(i, &ve, pos, heading[i], cone, |_| true);
                    let rh = choose_reference(i, &vh, pos, heading[i], cone, |_| true);
                    if re.is_some() || rh.is_some() {
                        refs += 1;
                        if re == rh {
                            same_ref += 1;
                        }
                    }
                }
            }
            println!(
                "N={n} {label}: views {views}, identical visible sets {:.1}%, mean Jaccard {:.3}, same reference bird {:.1}%",
                100.0 * same_set as f64 / views as f64,
                jac / views as f64,
                100.0 * same_ref as f64 / refs.max(1) as f64
            );
        }
    }
}
