//! Algorithm 1 invariants (issue 4): for N = N̂, N > N̂ and N < N̂, every key shape is solved,
//! inside the feasible ranges, with no two birds wing to wing, and the motion between frames is
//! smooth; equal seeds give equal bytes. These are invariants of the key-shape interpolation, so
//! the flights here are flown without position keeping (`--jostle 0`, [`still`]); the jostled
//! motion's own invariants (spacing, smoothness) are checked by
//! `jostled_flights_keep_apart_and_smooth`.

mod steady_support;

use formation::aero::power_reduction;
use formation::extract::params::FormationParams;
use formation::keyshape::{
    steady_flight, steady_flight_report, JostleOptions, KeyOptions, SteadyOptions, SteadyReport,
};
use formation::progress::Silent;
use formation::rng::seeded;
use formation::Animation;

/// The default options without position keeping: key-shape interpolation only.
fn still() -> SteadyOptions {
    SteadyOptions {
        jostle: JostleOptions {
            scale: 0.0,
            ..JostleOptions::default()
        },
        ..SteadyOptions::default()
    }
}

fn run(
    params: &FormationParams,
    birds: usize,
    frames: usize,
    seed: u64,
) -> (Animation, SteadyReport) {
    let opts = SteadyOptions {
        birds,
        frames,
        seed,
        ..still()
    };
    steady_flight_report(params, &opts, &mut seeded(seed), &Silent).expect("steady flight")
}

/// Every invariant the issue asks for, on one run.
fn check(anim: &Animation, rep: &SteadyReport, opts: &SteadyOptions) {
    let n = opts.birds;
    assert_eq!(anim.birds, n);
    assert_eq!(anim.frames.len(), opts.frames);
    assert_eq!(
        anim.stage("steady").map(|s| (s.start, s.end)),
        Some((0, opts.frames))
    );
    assert_eq!(anim.key_shapes.len(), rep.key_frames.len());
    assert!(anim.key_shapes.len() >= 2);
    let ranges = anim.xi_ranges.as_ref().expect("xi_ranges");
    assert_eq!(ranges.len(), n);

    // Every key shape solved (residual bound), its ξ consistent with its positions and inside the
    // feasible ranges; no two birds colliding.
    assert!(
        rep.keys.max_residual <= 1e-6,
        "max residual {}",
        rep.keys.max_residual
    );
    for (k, ks) in anim.key_shapes.iter().enumerate() {
        let x: Vec<f64> = ks.birds.iter().map(|b| b.x).collect();
        let y: Vec<f64> = ks.birds.iter().map(|b| b.y).collect();
        let p = power_reduction(&x, &y).expect("key shape without collisions");
        for (i, b) in ks.birds.iter().enumerate() {
            assert!(
                (p.xi[i] - b.xi).abs() < 1e-9,
                "key {k} bird {i}: stored ξ differs"
            );
            let [lo, hi] = ranges[i];
            assert!(
                b.xi >= lo - 1e-6 && b.xi <= hi + 1e-6,
                "key {k} bird {i}: ξ {} outside [{lo}, {hi}]",
                b.xi
            );
        }
        // No two birds wing to wing (lateral gaps under π/4 are allowed: overlapping wingtips).
        assert_eq!(
            formation::aero::AeroOptions::default().first_collision(&x, &y),
            None,
            "key {k}: colliding pair"
        );
        // Leader front-most.
        let lead = rep.leader;
        assert!(
            y.iter().enumerate().all(|(i, &v)| i == lead || v > y[lead]),
            "key {k}"
        );
    }

    // Motion relative to the flock (formation-frame y = leader's north − bird's north) is smooth:
    // bounded step per frame and bounded change of step.
    let spacing = (rep.key_frames[1] - rep.key_frames[0]) as f64;
    let step_bound = 3.0 * opts.keys.max_jump / spacing + 1e-9;
    let accel_bound = 20.0 * opts.keys.max_jump / (spacing * spacing) + 1e-9;
    let rel = |f: usize| -> Vec<f64> {
        let fr = &anim.frames[f];
        let lead_n = fr.y[rep.leader];
        fr.y.iter().map(|v| lead_n - v).collect()
    };
    let mut prev_step: Option<Vec<f64>> = None;
    for f in 1..anim.frames.len() {
        let (a, b) = (rel(f - 1), rel(f));
        let step: Vec<f64> = a.iter().zip(&b).map(|(p, q)| q - p).collect();
        for (i, s) in step.iter().enumerate() {
            assert!(
                s.abs() <= step_bound,
                "frame {f} bird {i}: step {s} > {step_bound}"
            );
        }
        if let Some(ps) = &prev_step {
            for (i, (s, p)) in step.iter().zip(ps).enumerate() {
                assert!(
                    (s - p).abs() <= accel_bound,
                    "frame {f} bird {i}: change of step {} > {accel_bound}",
                    (s - p).abs()
                );
            }
        }
        prev_step = Some(step);
        // Lateral positions drift only between keys (issue 19), between the two keys' values
        // (monotone interpolation), never by more than the jump bound per key.
        let k = rep
            .key_frames
            .partition_point(|&kf| kf <= f)
            .clamp(1, rep.key_frames.len() - 1);
        let (ka, kb) = (&anim.key_shapes[k - 1], &anim.key_shapes[k]);
        for i in 0..n {
            let (lo, hi) = (
                ka.birds[i].x.min(kb.birds[i].x),
                ka.birds[i].x.max(kb.birds[i].x),
            );
            let xf = anim.frames[f].x[i];
            assert!(
                xf >= lo - 1e-9 && xf <= hi + 1e-9,
                "frame {f} bird {i}: x {xf} outside [{lo}, {hi}]"
            );
            assert!(hi - lo <= opts.keys.max_jump + 1e-9);
        }
    }
    // Speeds are continuous too (C¹ interpolation: no velocity kink at key frames).
    for f in 1..anim.frames.len() {
        for i in 0..n {
            let dv = (anim.frames[f].speed[i] - anim.frames[f - 1].speed[i]).abs();
            assert!(
                dv <= accel_bound * opts.fps * opts.fps / opts.fps + 1e-6,
                "frame {f} bird {i}: speed jump {dv}"
            );
        }
    }
}

fn case(params: &FormationParams, birds: usize) {
    let opts = SteadyOptions {
        birds,
        frames: 181,
        fps: 30.0,
        keys: KeyOptions {
            key_every_s: 1.0,
            ..KeyOptions::default()
        },
        ..still()
    };
    let (anim, rep) = steady_flight_report(params, &opts, &mut seeded(7), &Silent).unwrap();
    eprintln!("{birds} birds: {:?}", rep.keys);
    assert_eq!(rep.keys.held, 0, "a key shape was held instead of solved");
    eprintln!(
        "  frames outside range {} max excess {:.2e}",
        rep.frames_outside_range, rep.max_frame_excess
    );
    // Between keys both x (the lateral drift) and y are interpolated and ξ is recomputed: it
    // may leave the ranges slightly (measured up to 4.1e-3 for 9 birds with the key shapes'
    // fore-aft step between birds near each other laterally).
    assert!(
        rep.max_frame_excess <= 5e-3,
        "frame ξ leaves the ranges by {}",
        rep.max_frame_excess
    );
    check(&anim, &rep, &opts);
}

#[test]
fn v9_same_number_of_birds() {
    case(&steady_support::v9(), 9);
}

#[test]
fn v9_to_14_birds() {
    case(&steady_support::v9(), 14);
}

#[test]
fn j16_to_28_birds() {
    case(&steady_support::j16(), 28);
}

#[test]
fn j16_to_16_birds() {
    case(&steady_support::j16(), 16);
}

#[test]
fn fewer_birds_than_the_movie() {
    case(&steady_support::j16(), 7);
    case(&steady_support::v9(), 5);
}

#[test]
fn same_seed_same_bytes() {
    let p = steady_support::v9();
    let a = serde_json::to_vec(&run(&p, 12, 60, 3).0).unwrap();
    let b = serde_json::to_vec(&run(&p, 12, 60, 3).0).unwrap();
    let c = serde_json::to_vec(&run(&p, 12, 60, 4).0).unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn steady_flight_matches_report_variant() {
    let p = steady_support::v9();
    let opts = SteadyOptions {
        birds: 9,
        frames: 40,
        ..still()
    };
    let a = steady_flight(&p, &opts, &mut seeded(1), &Silent).unwrap();
    let b = steady_flight_report(&p, &opts, &mut seeded(1), &Silent)
        .unwrap()
        .0;
    assert_eq!(a, b);
}

/// Writes the fixtures under tests/data/ (run explicitly with `--ignored`).
#[test]
#[ignore]
fn write_fixtures() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for (name, p) in [
        ("steady_v9_params.json", steady_support::v9()),
        ("steady_j16_params.json", steady_support::j16()),
    ] {
        formation::io::write_json_atomic(&dir.join(name), &p).unwrap();
    }
}

/// Odd movies: an echelon (leader at the left end, a line), a 2-bird movie, two animated birds,
/// no positions, zero deviations, and mean gaps with overlapping wingtips (0.6, and 0.3: a
/// negative total saving for two birds).
#[test]
fn odd_movies_still_give_valid_flights() {
    use formation::extract::params::ShapeModel;
    let mut echelon = steady_support::v9();
    for f in &mut echelon.frames {
        f.leader = 0;
        f.shape = ShapeModel::Line {
            intercept: 0.0,
            slope: 0.6,
        };
        f.outliers.clear();
        f.inliers = (0..9).collect();
        f.positions.clear();
    }
    let mut two = steady_support::v9();
    for f in &mut two.frames {
        f.order = vec![3, 4];
        f.outliers.clear();
        f.inliers = vec![3, 4];
    }
    // Wingtips overlapping in every frame (0.6 wingspans apart, below π/4): kept, and flown.
    let mut close = steady_support::v9();
    for f in &mut close.frames {
        f.mu_x = 0.6;
        f.sigma_x = 0.0;
        f.sigma_y = 0.0;
    }
    // So close (0.3) that Hummel's model gives a pair or a trio a negative total saving:
    // refused with a message, not a wild flight; 17 birds get a positive total from their wider
    // pairs, some birds fly in downwash (ξ < 0), and the flight is made.
    let mut tiny = steady_support::v9();
    for f in &mut tiny.frames {
        f.mu_x = 0.3;
        f.sigma_x = 0.0;
        f.sigma_y = 0.0;
    }
    let opts = SteadyOptions {
        birds: 2,
        frames: 121,
        keys: KeyOptions {
            key_every_s: 1.0,
            ..KeyOptions::default()
        },
        ..still()
    };
    let err = steady_flight_report(&tiny, &opts, &mut seeded(2), &Silent).unwrap_err();
    assert!(err.to_string().contains("lateral gap"), "{err}");
    assert_eq!(err.exit_code(), 2);
    let opts = SteadyOptions { birds: 17, ..opts };
    let (anim, rep) = steady_flight_report(&tiny, &opts, &mut seeded(2), &Silent).unwrap();
    check(&anim, &rep, &opts);
    assert!(
        rep.feasible.min.iter().any(|&v| v < 0.0),
        "some birds in downwash"
    );
    for p in [&echelon, &two, &close] {
        for birds in [2, 3, 17] {
            let opts = SteadyOptions {
                birds,
                frames: 121,
                keys: KeyOptions {
                    key_every_s: 1.0,
                    ..KeyOptions::default()
                },
                ..still()
            };
            let (anim, rep) = steady_flight_report(p, &opts, &mut seeded(2), &Silent).unwrap();
            check(&anim, &rep, &opts);
        }
    }
}

/// Living lateral spacing (issue 19): over a two-minute flight from the example footage the
/// lateral gaps between neighbours vary about as much as the footage's (standard deviation over
/// time within a factor of 2), at least 90 % of the key shapes take their drifted lateral
/// positions, every key is solved, and the motion stays smooth; equal seeds, equal bytes.
#[test]
fn lateral_gaps_breathe_like_the_footage() {
    use formation::annotations::{self, ReadOptions};
    use formation::extract::{self, ExtractOptions};
    use std::collections::BTreeMap;
    for (name, birds) in [("barnacle_geese_v.json", 9), ("snow_geese_j.csv", 16)] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples_data")
            .join(name);
        let ann = annotations::read(&path, &ReadOptions::default()).unwrap();
        let p = extract::extract(&ann, &ExtractOptions::default(), &mut seeded(0)).unwrap();
        // The footage's variation, measured here from the positions: the sd over the frames of
        // each pair of lateral neighbours' gap, median over the pairs.
        let mut series: BTreeMap<(usize, usize), Vec<f64>> = BTreeMap::new();
        for f in &p.frames {
            let mut b: Vec<(f64, usize)> = f.positions.iter().map(|q| (q.x, q.id)).collect();
            b.sort_by(|a, c| a.0.total_cmp(&c.0));
            for w in b.windows(2) {
                series
                    .entry((w[0].1, w[1].1))
                    .or_default()
                    .push(w[1].0 - w[0].0);
            }
        }
        let sd = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|g| (g - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let footage = median(
            series
                .values()
                .filter(|v| v.len() >= p.frames.len() / 2)
                .map(|v| sd(v))
                .collect(),
        );
        let opts = SteadyOptions {
            birds,
            frames: 3600,
            seed: 5,
            ..still()
        };
        let (anim, rep) = steady_flight_report(&p, &opts, &mut seeded(5), &Silent).unwrap();
        let keys = anim.key_shapes.len();
        eprintln!(
            "{name}: drift {:.3}, lateral_held {} of {} keys, {:?}",
            rep.lateral_drift,
            rep.keys.lateral_held,
            keys - 1,
            rep.keys
        );
        assert!(
            (rep.keys.lateral_held as f64) <= 0.1 * (keys - 1) as f64,
            "{name}: {} of {} keys kept the previous lateral positions",
            rep.keys.lateral_held,
            keys - 1
        );
        assert_eq!(rep.keys.held, 0, "{name}: a key was held");
        // Each gap's sd over the key shapes' lateral positions, median over the gaps.
        let gaps: Vec<f64> = (0..birds - 1)
            .map(|i| {
                let v: Vec<f64> = anim
                    .key_shapes
                    .iter()
                    .map(|k| k.birds[i + 1].x - k.birds[i].x)
                    .collect();
                sd(&v)
            })
            .collect();
        let generated = median(gaps);
        eprintln!("{name}: lateral gap sd {generated:.3} vs footage {footage:.3}");
        assert!(
            generated >= footage / 2.0 && generated <= footage * 2.0,
            "{name}: lateral gap sd {generated} vs the footage's {footage}"
        );
        check(&anim, &rep, &opts);
        // The frames' lateral positions move smoothly too.
        for f in 1..anim.frames.len() {
            for i in 0..birds {
                let dx = (anim.frames[f].x[i] - anim.frames[f - 1].x[i]).abs();
                assert!(dx < 0.05, "{name} frame {f} bird {i}: lateral step {dx}");
            }
        }
    }
}

/// With position keeping on (the default), every frame keeps the birds at least 0.3 wingspans
/// apart, and each bird's acceleration and turn rate stay bounded (finite differences of the
/// sampled positions at 30 fps), for both shapes and three seeds.
#[test]
fn jostled_flights_keep_apart_and_smooth() {
    for (name, p) in [("v9", steady_support::v9()), ("j16", steady_support::j16())] {
        for seed in 1..=3 {
            let opts = SteadyOptions {
                birds: 14,
                frames: 901,
                fps: 30.0,
                seed,
                ..SteadyOptions::default()
            };
            assert!(opts.jostle.scale == 1.0, "position keeping is the default");
            let (anim, _) = steady_flight_report(&p, &opts, &mut seeded(seed), &Silent).unwrap();
            let dt = 1.0 / anim.fps;
            let (mut closest, mut acc, mut turn) = (f64::INFINITY, 0.0f64, 0.0f64);
            let mut acc_at = (0, 0);
            for (f, fr) in anim.frames.iter().enumerate() {
                for i in 0..fr.x.len() {
                    for j in 0..i {
                        closest = closest.min((fr.x[i] - fr.x[j]).hypot(fr.y[i] - fr.y[j]));
                    }
                    if f >= 2 {
                        let (a, b) = (&anim.frames[f - 1], &anim.frames[f - 2]);
                        let ax = (fr.x[i] - 2.0 * a.x[i] + b.x[i]) / (dt * dt);
                        let ay = (fr.y[i] - 2.0 * a.y[i] + b.y[i]) / (dt * dt);
                        if ax.hypot(ay) > acc {
                            acc = ax.hypot(ay);
                            acc_at = (f, i);
                        }
                        turn = turn.max((fr.heading[i] - a.heading[i]).abs() / dt);
                    }
                }
            }
            eprintln!(
                "{name} seed {seed}: closest {closest:.3}, accel {acc:.2} (frame {}, bird {}), turn {turn:.3}",
                acc_at.0, acc_at.1
            );
            assert!(
                closest >= 0.3,
                "{name} seed {seed}: birds {closest} wingspans apart"
            );
            assert!(
                acc <= 4.0,
                "{name} seed {seed}: acceleration {acc} wingspans/s²"
            );
            assert!(
                turn <= 30f64.to_radians(),
                "{name} seed {seed}: turn rate {} °/s",
                turn.to_degrees()
            );
        }
    }
}
