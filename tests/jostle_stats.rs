//! Position keeping learnt from footage: a synthetic footage whose birds fluctuate about their
//! slots by a known process (an Ornstein–Uhlenbeck deviation per bird and axis) is measured as
//! `extract` measures footage, and steady flights of N = N̂ and N = 2N̂ birds generated from it
//! reproduce its 0.5 s lateral move median (0.6–1.6×) and per-bird lateral spread (0.5–2×), for
//! three seeds. The footage's spread, 0.12 wingspans, is one a V's spacing leaves room for: the
//! generated birds never cross a neighbour's wing, which an unbounded process twice as wide would.

mod steady_support;

use formation::extract::motion::footage_keeping;
use formation::extract::params::FrameParams;
use formation::keyshape::jostle::measure_animation;
use formation::keyshape::{steady_flight_report, ReorganiseOptions, SteadyOptions};
use formation::progress::Silent;
use formation::rng::seeded;
use rand_distr::{Distribution, Normal};

/// `frames` frames at `fps` of the fixture's first frame with every bird displaced by its own
/// OU deviation (standard deviation `sigma` wingspans, correlation time `tau` seconds).
fn ou_footage(
    base: &FrameParams,
    frames: usize,
    fps: f64,
    sigma: f64,
    tau: f64,
    seed: u64,
) -> Vec<FrameParams> {
    let mut rng = seeded(seed);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let a = (-1.0 / (fps * tau)).exp();
    let kick = sigma * (1.0 - a * a).sqrt();
    let n = base.positions.len();
    let mut dev: Vec<(f64, f64)> = (0..n)
        .map(|_| (sigma * unit.sample(&mut rng), sigma * unit.sample(&mut rng)))
        .collect();
    (0..frames)
        .map(|f| {
            let mut fr = base.clone();
            fr.index = f as i64;
            for (b, d) in fr.positions.iter_mut().zip(&mut dev) {
                b.x += d.0;
                b.y += d.1;
                b.dy += d.1;
                d.0 = a * d.0 + kick * unit.sample(&mut rng);
                d.1 = a * d.1 + kick * unit.sample(&mut rng);
            }
            fr
        })
        .collect()
}

#[test]
fn flights_reproduce_the_footage_s_position_keeping() {
    let (sigma, tau, fps) = (0.12, 1.2, 30.0);
    let mut params = steady_support::v9();
    let n_hat = params.frames[0].positions.len();
    let footage = ou_footage(&params.frames[0], 1800, fps, sigma, tau, 11);
    let keep = footage_keeping(&footage, fps).expect("footage with timing");
    // The measurement finds the known process (relative to the centroid: a share 1 − 1/N̂ of
    // the variance; the 0.5 s move of a Gaussian process is 0.6745·√(2σ²(1 − ρ))).
    let share = (1.0 - 1.0 / n_hat as f64).sqrt();
    let spread = sigma * share;
    let move_median = 0.6745 * (2.0 * (1.0 - (-0.5 / tau).exp())).sqrt() * sigma * share;
    let lat = keep.lateral;
    eprintln!(
        "footage: move {:.4} (process {move_median:.4}), spread {:.4} (process {spread:.4})",
        lat.move_median, lat.spread
    );
    assert!((lat.move_median / move_median - 1.0).abs() < 0.15);
    assert!((lat.spread / spread - 1.0).abs() < 0.15);
    params.motion = Some(keep);
    for birds in [n_hat, 2 * n_hat] {
        for seed in 1..=3 {
            // Position keeping alone: a bird that changes places (leader changes, swaps) moves
            // its mean slot, which the footage's birds, measured between reorganisations, do not.
            let opts = SteadyOptions {
                birds,
                frames: 2701,
                fps,
                seed,
                reorganise: ReorganiseOptions::none(),
                ..SteadyOptions::default()
            };
            let (anim, _) =
                steady_flight_report(&params, &opts, &mut seeded(seed), &Silent).unwrap();
            // With the default reorganisations the short moves are still the footage's.
            let (lively, _) = steady_flight_report(
                &params,
                &SteadyOptions {
                    reorganise: ReorganiseOptions::default(),
                    ..opts.clone()
                },
                &mut seeded(seed),
                &Silent,
            )
            .unwrap();
            let (got, _) = measure_animation(&anim, 5.0).expect("long enough");
            eprintln!(
                "N {birds} seed {seed}: move {:.4} vs {:.4}, spread {:.4} vs {:.4}",
                got.move_median, lat.move_median, got.spread, lat.spread
            );
            assert!(!lively.events.is_empty());
            let (moves, _) = measure_animation(&lively, 5.0).expect("long enough");
            eprintln!(
                "N {birds} seed {seed}: with reorganisations, move {:.4} vs {:.4}",
                moves.move_median, lat.move_median
            );
            assert!(
                (0.6..=1.6).contains(&(moves.move_median / lat.move_median)),
                "N {birds} seed {seed}: with reorganisations, 0.5 s move {} vs the footage's {}",
                moves.move_median,
                lat.move_median
            );
            assert!(
                (0.6..=1.6).contains(&(got.move_median / lat.move_median)),
                "N {birds} seed {seed}: 0.5 s move {} vs the footage's {}",
                got.move_median,
                lat.move_median
            );
            assert!(
                (0.5..=2.0).contains(&(got.spread / lat.spread)),
                "N {birds} seed {seed}: spread {} vs the footage's {}",
                got.spread,
                lat.spread
            );
        }
    }
}
