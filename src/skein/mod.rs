//! Large flocks fly as several formations (skeins), as real ones do: a flock of N birds is split
//! into K formations of about the footage's size ([`sizes`]), each a full Klotsman–Tal flock
//! (its own correspondence, leader, key shapes and steady flight by §5 Algorithm 1 from the same
//! formation parameters, its own random streams), optionally taking off by §6 on its own, and the
//! formations are arranged loosely so that birds of different formations never come within the
//! clearance ([`layout`]). The result is one [`Animation`] whose `formations` record each
//! formation's birds, leader and key shapes.
//!
//! Lengths in wingspans, times in seconds, the course frame (the world frame of a flock cruising
//! north, docs/formats.md §2); the take-off's own start region is centred on each formation's place.
//!
//! - Formation k draws every one of its own numbers from `rng::Scope::Formation(k)` (the streams
//!   `rng::formation_stream(seed, Stream::Steady | SteadyLateral | SteadyHeight | Initiate |
//!   Skein, k)`), so formations of equal size do not share their lateral drift or heights; a
//!   retry `t` from `rng::Scope::Retry` (`rng::retry_stream`). The sizes and the arrangement
//!   come from `rng::stream(seed, Stream::SkeinSizes | SkeinLayout)`.
//! - Each formation's steady flight starts from a different movie frame: the params' frames are
//!   rotated by a random number of places, so with footage of several kinds (V, J, echelon) the
//!   formations start in different kinds and shapes.
//! - Take-off: every formation takes off from its own patch of the ground (the flock's resting
//!   area is partitioned, a patch per formation, placed under the formation's place in the
//!   arrangement; a bird joins the formation of the patch it rests in). A formation's take-off is
//!   simulated with the §6 rules among its own birds only; formations whose take-off is shorter
//!   leave the ground later, so that every formation hands over into its steady flight at the same
//!   frame (large flocks leave a field in waves). The arrangement is computed from the finished
//!   motion, so the clearance holds in every frame of the take-off too.
//! - Aerodynamics: savings (e, ξ) are computed within each formation (ξ = e / E of its own
//!   formation); formations do not interact beyond the clearance (Hummel's g at 5 wingspans is
//!   given in `docs/large-flocks.md`).

mod join;
pub mod layout;
pub mod natural;
pub mod sizes;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::extract::params::FormationParams;
use crate::initiate::{self, InitiateOptions, InitiateStats, InitiationRun};
use crate::keyshape::{steady_flight_in, SteadyOptions, SteadyReport};
use crate::progress::{Progress, Silent};
use crate::rng::{stream, Scope, Stream};

pub use layout::{Drift, Envelope, Placement};
pub use natural::SkeinLayout;
pub use sizes::{formation_count, formation_sizes};

/// Options of flocks of several formations (the `skein` section of
/// [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkeinOptions {
    /// K, the number of formations (`None`: from the footage's formation size, see [`sizes`]).
    pub formations: Option<usize>,
    /// M, the typical number of birds of a formation (`None`: the footage's); K = round(N / M).
    pub formation_size: Option<usize>,
    /// Smallest distance between two birds of different formations, in every frame, wingspans.
    pub clearance: f64,
    /// Looseness of the arrangement: extra gap between neighbouring formations, up to this
    /// factor times the median formation width (across) or depth (along), dimensionless.
    pub spread: f64,
    /// Largest heading difference of a formation's drift from the course, degrees (`None`: the
    /// layout's, [`SkeinLayout::max_heading_deg`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_heading_deg: Option<f64>,
    /// Largest speed difference of a formation's drift, as a fraction of the cruise speed.
    pub max_speed_diff: f64,
    /// How the formations are arranged: natural (the default), grid or compound.
    pub layout: SkeinLayout,
}

impl Default for SkeinOptions {
    fn default() -> Self {
        SkeinOptions {
            formations: None,
            formation_size: None,
            clearance: 5.0,
            spread: 0.5,
            max_heading_deg: None,
            max_speed_diff: 0.02,
            layout: SkeinLayout::default(),
        }
    }
}

impl SkeinOptions {
    /// Checks the options for a flock of `n` birds; errors name the option path
    /// (`skein.formations`).
    pub fn validate(&self, n: usize) -> Result<()> {
        let p = |name: &str, msg: String| Err(Error::parameter(name, msg));
        if let Some(k) = self.formations {
            if k == 0 {
                return p("skein.formations", "0: give at least 1 formation".into());
            }
            if k > 1 && 2 * k > n {
                return p(
                    "skein.formations",
                    format!(
                        "{k} formations of {n} birds: a formation needs at least 2 birds, so at most {}",
                        n / 2
                    ),
                );
            }
            let biggest = sizes::size_bounds(n, k).1;
            if k > 1 && biggest > crate::limits::MAX_FORMATION_BIRDS {
                return p(
                    "skein.formations",
                    format!("{k} formations of {n} birds have up to {biggest} birds each; at most {} birds fly as one formation: give more formations", crate::limits::MAX_FORMATION_BIRDS),
                );
            }
        }
        if let Some(m) = self.formation_size {
            if m < 2 {
                return p(
                    "skein.formation_size",
                    format!("{m}: a formation needs at least 2 birds"),
                );
            }
            if m > crate::limits::MAX_FORMATION_BIRDS / 2 {
                return p(
                    "skein.formation_size",
                    format!(
                        "{m}: at most {} (formations grow to twice the typical size, and at most {} birds fly as one formation)",
                        crate::limits::MAX_FORMATION_BIRDS / 2,
                        crate::limits::MAX_FORMATION_BIRDS
                    ),
                );
            }
            if let Some(k) = self.formations {
                let want = formation_count(n, m, None, Some(m));
                if want != k {
                    return p(
                        "skein.formations/skein.formation_size",
                        format!("{k} formations and formations of about {m} birds conflict: {n} birds in formations of about {m} are {want} formations; give one of the two"),
                    );
                }
            }
        }
        if !(self.clearance.is_finite() && (0.0..=1000.0).contains(&self.clearance)) {
            return p(
                "skein.clearance",
                format!(
                    "{}: must be a distance in [0, 1000] wingspans",
                    self.clearance
                ),
            );
        }
        if !(self.spread.is_finite() && (0.0..=100.0).contains(&self.spread)) {
            return p(
                "skein.spread",
                format!("{}: must be in [0, 100]", self.spread),
            );
        }
        let h = self.heading_deg();
        if !(h.is_finite() && (0.0..=10.0).contains(&h)) {
            return p(
                "skein.max_heading_deg",
                format!("{h}: must be in [0, 10] degrees"),
            );
        }
        if !(self.max_speed_diff.is_finite() && (0.0..=0.2).contains(&self.max_speed_diff)) {
            return p(
                "skein.max_speed_diff",
                format!(
                    "{}: must be in [0, 0.2] of the cruise speed",
                    self.max_speed_diff
                ),
            );
        }
        Ok(())
    }

    /// Largest heading difference of a formation's drift from the course, degrees: the given
    /// one or the layout's.
    pub fn heading_deg(&self) -> f64 {
        self.max_heading_deg
            .unwrap_or_else(|| self.layout.max_heading_deg())
    }

    /// The sizes of the formations of `n` birds when the footage's formation has `n_hat` birds,
    /// drawn from the seed's `skein/sizes` stream (one entry: one formation).
    pub fn sizes(&self, n: usize, n_hat: usize, seed: u64) -> Result<Vec<usize>> {
        self.validate(n)?;
        let k = formation_count(n, n_hat, self.formations, self.formation_size);
        formation_sizes(n, k, &mut stream(seed, Stream::SkeinSizes))
    }
}

/// What each formation of a flock did, and how they were arranged.
#[derive(Debug, Clone, Serialize)]
pub struct SkeinReport {
    /// Birds of each formation.
    pub sizes: Vec<usize>,
    /// Number of lanes of the arrangement.
    pub lanes: usize,
    /// The clearance asked for, wingspans.
    pub clearance: f64,
    /// Smallest distance between birds of different formations over every frame, wingspans.
    pub min_separation: f64,
    /// One entry per formation.
    pub formations: Vec<FormationReport>,
}

/// One formation of a [`SkeinReport`].
#[derive(Debug, Clone, Serialize)]
pub struct FormationReport {
    /// Its place in the arrangement.
    pub placement: Placement,
    /// Its drift about that place (`None`: from a steady-flight file).
    pub drift: Option<Drift>,
    /// Places the movie's frames were rotated by for its steady flight (`None`: from a file).
    pub frame_rotation: Option<usize>,
    /// Time it waited on the ground before its take-off, seconds (0 without take-off).
    pub takeoff_delay_s: f64,
    /// Take-offs flown until one converged (0 without take-off; see [`TAKEOFF_TRIES`]).
    pub takeoff_tries: usize,
    /// Algorithm 1's report of its steady flight (`None`: from a steady-flight file).
    pub steady: Option<SteadyReport>,
    /// Its take-off's statistics (`None` without take-off).
    pub initiate: Option<InitiateStats>,
}

/// Everything a flock of several formations is made from: the stage options (with their derived
/// fields set) and the seed.
#[derive(Debug, Clone)]
pub struct FlockOptions<'a> {
    /// The steady flight of every formation (`birds` is replaced by each formation's size).
    pub steady: &'a SteadyOptions,
    /// The take-off of every formation; `None`: the steady flight alone.
    pub initiate: Option<&'a InitiateOptions>,
    /// The flock's own options.
    pub skein: &'a SkeinOptions,
    /// The run's seed.
    pub seed: u64,
}

/// The flock of formations of `sizes` birds from `params`: steady flight (and take-off when
/// asked), arranged and joined into one animation (birds numbered formation by formation).
pub fn fly(
    params: &FormationParams,
    sizes: &[usize],
    o: &FlockOptions,
    progress: &dyn Progress,
) -> Result<(Animation, SkeinReport)> {
    o.skein.validate(sizes.iter().sum())?;
    let k = sizes.len();
    progress.start("formations: steady flight", k as u64);
    let steadies = par_map(k, |f| {
        let r = steady_of(params, sizes[f], f, 0, o);
        progress.advance(1);
        r
    })?;
    progress.finish();
    let (anims, reports): (Vec<Animation>, Vec<FormationReport>) = steadies.into_iter().unzip();
    let redo = |f: usize, t: usize| steady_of(params, sizes[f], f, t, o);
    finish(anims, reports, o, Some(&redo), progress)
}

/// §6 take-off of a flock of several formations whose steady flight is `steady` (a file written
/// by `steady` or [`fly`] without take-off): every formation takes off into its own first key
/// shape and the formations are arranged anew around the finished motion.
/// The steady flight is taken apart into its formations as it is read (never held twice).
pub fn initiate_flock(
    steady: Animation,
    o: &FlockOptions,
    progress: &dyn Progress,
) -> Result<(Animation, SkeinReport)> {
    let k = steady.formation_count();
    let anims = steady.into_formations();
    if anims.len() != k {
        return Err(Error::Internal(format!("no formation {}", anims.len())));
    }
    let mut reports = Vec::with_capacity(k);
    for _ in 0..k {
        reports.push(FormationReport {
            placement: Placement::default(),
            drift: None,
            frame_rotation: None,
            takeoff_delay_s: 0.0,
            takeoff_tries: 0,
            steady: None,
            initiate: None,
        });
    }
    finish(anims, reports, o, None, progress)
}

/// Freed memory, bytes, between two returns of it to the system while a flock is joined.
const RELEASE_BYTES: usize = 8 << 20;

/// About what joining frees for a bird-frame of a formation: its frames (11 values in vectors of
/// a few birds, about 100 bytes) and, after a take-off, the run it was made from (5 values).
const FREED_BYTES_PER_BIRD_FRAME: usize = 140;

/// A formation's take-off: the run, the tries it took, and the steady flight drawn afresh (with
/// its report) when a later try needed one.
type TakeoffRun = (InitiationRun, usize, Option<(Animation, FormationReport)>);

/// Formation `f`'s steady flight drawn afresh for try `t` of its take-off.
type Redo<'a> = &'a (dyn Fn(usize, usize) -> Result<(Animation, FormationReport)> + Sync);

/// The take-off (when asked) of every formation of `anims` (steady flights in their own
/// coordinates), then the arrangement and the joined animation. `redo` draws a formation's
/// steady flight afresh when its take-off does not converge (see [`takeoff_run`]).
fn finish(
    mut anims: Vec<Animation>,
    mut reports: Vec<FormationReport>,
    o: &FlockOptions,
    redo: Option<Redo>,
    progress: &dyn Progress,
) -> Result<(Animation, SkeinReport)> {
    let k = anims.len();
    let sizes: Vec<usize> = anims.iter().map(|a| a.birds).collect();
    let mut takeoffs: Vec<TakeoffRun> = Vec::new();
    // Frames of the longest take-off: the others wait on the ground to hand over with it.
    let mut takeoff_frames = 0;
    if let Some(init) = o.initiate {
        if matches!(init.start, initiate::Start::Given(_)) {
            // From formation parameters the flock can be flown as one formation; a steady
            // flight read from a file has its formations already.
            let one = if redo.is_some() {
                "fly the flock as one formation (skein.formations 1)"
            } else {
                "give a steady flight of one formation (skein.formations 1)"
            };
            return Err(Error::parameter(
                "initiate.start",
                format!("a start file places the birds of one formation; a flock of {k} formations takes off from the ground or starts in the air (initiate.start ground or air), or {one}"),
            ));
        }
        progress.start("formations: take-off", k as u64);
        let runs = par_map(k, |f| {
            let r = takeoff_run(&anims[f], init, o.seed, f, redo);
            progress.advance(1);
            r
        })?;
        progress.finish();
        takeoff_frames = runs.iter().map(|(r, _, _)| r.pos.len()).max().unwrap_or(1);
        takeoffs = runs;
    }
    // Each formation is finished (its take-off handed over) and joined in turn, so its frames
    // are dropped before the next one's are made.
    let mut joiner = join::Joiner::new(sizes.iter().sum());
    let mut env: Vec<Envelope> = Vec::with_capacity(k);
    let mut freed = 0;
    let mut takeoffs = takeoffs.into_iter();
    for f in 0..k {
        if let (Some(init), Some((run, tries, fresh))) = (o.initiate, takeoffs.next()) {
            if let Some((a, r)) = fresh {
                anims[f] = a;
                reports[f] = r;
            }
            reports[f].takeoff_tries = tries;
            let wait = takeoff_frames - run.pos.len();
            reports[f].takeoff_delay_s = wait as f64 / anims[f].fps;
            let run = delayed(run, wait);
            // The formation's steady frames move into its take-off's animation (no copy).
            let steady = std::mem::replace(&mut anims[f], Animation::new(0, 1.0, 1.0, 0));
            let (mut a, stats) = initiate::hand_over_owned(steady, &run, init)
                .map_err(|e| in_formation(e, f, sizes[f]))?;
            drop(run);
            crate::aero::fill_frame_savings(&mut a, &o.steady.aero);
            anims[f] = a;
            reports[f].initiate = Some(stats);
        }
        env.push(Envelope::of(&anims[f]));
        joiner.push(&mut anims[f])?;
        // The formation's small vectors, freed, cannot hold the flock's large ones: give them
        // back every few tens of megabytes (crate::memory).
        freed += sizes[f] * joiner.frames() * FREED_BYTES_PER_BIRD_FRAME;
        if freed >= RELEASE_BYTES {
            crate::memory::release_free();
            freed = 0;
        }
    }
    crate::memory::release_free();
    let departures: Vec<f64> = reports.iter().map(|r| r.takeoff_delay_s).collect();
    let mut rng = stream(o.seed, Stream::SkeinLayout);
    let (c, s) = (o.skein.clearance, o.skein.spread);
    let mut placements = match o.skein.layout {
        SkeinLayout::Grid => layout::arrange(&env, &departures, c, s, &mut rng),
        SkeinLayout::Natural => natural::arrange_natural(&env, c, s, &mut rng),
        SkeinLayout::Compound => natural::arrange_compound(&env, c, s, &mut rng),
    };
    for (p, h) in placements
        .iter_mut()
        .zip(natural::heights(o.skein.layout, k, &mut rng))
    {
        p.height = h;
    }
    let lanes = match o.skein.layout {
        SkeinLayout::Grid => placements.iter().map(|p| p.lane + 1).max().unwrap_or(1),
        _ => 0,
    };
    let centre = centre_of(&env, &placements, o.initiate.is_some());
    for (r, p) in reports.iter_mut().zip(&placements) {
        r.placement = Placement {
            offset: [p.offset[0] - centre[0], p.offset[1] - centre[1]],
            ..p.clone()
        };
    }
    let anim = joiner.finish(&reports)?;
    let min_separation = min_separation(&anim);
    if min_separation < o.skein.clearance - 1e-9 {
        return Err(Error::Internal(format!(
            "formations came within {min_separation:.3} wingspans of each other, under the clearance of {}",
            o.skein.clearance
        )));
    }
    Ok((
        anim,
        SkeinReport {
            sizes,
            lanes,
            clearance: o.skein.clearance,
            min_separation,
            formations: reports,
        },
    ))
}

/// Formation `f`'s steady flight (local coordinates: its leader starts at the origin) with its
/// drift applied, and the start of its report; try `t` > 0 draws it from fresh streams.
fn steady_of(
    params: &FormationParams,
    n: usize,
    f: usize,
    t: usize,
    o: &FlockOptions,
) -> Result<(Animation, FormationReport)> {
    use rand::Rng;
    let scope = Scope::formation(f, t);
    let mut own = scope.stream(o.seed, Stream::Skein);
    let mut steady_rng = scope.stream(o.seed, Stream::Steady);
    let rotation = own.random_range(0..params.frames.len().max(1));
    let mut p = params.clone();
    p.frames.rotate_left(rotation);
    let opts = SteadyOptions {
        birds: n,
        ..o.steady.clone()
    };
    let (mut anim, steady) = steady_flight_in(&p, &opts, scope, &mut steady_rng, &Silent)
        .map_err(|e| in_formation(e, f, n))?;
    let drift = Drift::draw(
        opts.speed,
        o.skein.heading_deg(),
        o.skein.max_speed_diff,
        &mut own,
    );
    drift.apply(&mut anim, 0);
    Ok((
        anim,
        FormationReport {
            placement: Placement::default(),
            drift: Some(drift),
            frame_rotation: Some(rotation),
            takeoff_delay_s: 0.0,
            takeoff_tries: 0,
            steady: Some(steady),
            initiate: None,
        },
    ))
}

/// Take-offs a formation may fly before the flock's run fails: one from its own stream, then
/// from fresh random starts.
pub const TAKEOFF_TRIES: usize = 4;

/// Closest two birds of a formation should come during its take-off, wingspans: a converged
/// take-off that brought two birds closer is flown again like one that did not converge (and
/// kept only if no try does better).
pub const MIN_TAKEOFF_DISTANCE: f64 = 0.3;

/// Formation `f`'s take-off into the first key shape of its steady flight `steady` (not yet
/// handed over), from its own start drawn around the origin; the number of tries it took, and
/// the formation's new steady flight if it was drawn afresh. A take-off that does not converge
/// within the time limit is flown again, up to [`TAKEOFF_TRIES`] in all, from a fresh random start
/// (stream `initiate/formation/f/try/t`) into a fresh steady flight (`redo`, when the flock was
/// made from formation parameters; its first key shape is what the take-off failed to reach):
/// now and then the §6 rules leave a bird or two of a formation short of their slots,
/// and a flock of a hundred formations should not fail for one of them.
#[allow(clippy::type_complexity)]
fn takeoff_run(
    steady: &Animation,
    opts: &InitiateOptions,
    seed: u64,
    f: usize,
    redo: Option<Redo>,
) -> Result<TakeoffRun> {
    let n = steady.birds;
    let mut last = None;
    let mut close: Option<TakeoffRun> = None;
    let mut fresh: Option<(Animation, FormationReport)> = None;
    for t in 0..TAKEOFF_TRIES {
        if t > 0 {
            if let Some(redo) = redo {
                fresh = Some(redo(f, t)?);
            }
        }
        let steady = fresh.as_ref().map_or(steady, |(a, _)| a);
        let name = format!("formation {f}");
        initiate::check_steady(steady, std::path::Path::new(&name))
            .map_err(|e| in_formation(e, f, n))?;
        let (target, cruise) =
            initiate::steady_target(steady).map_err(|e| in_formation(e, f, n))?;
        let mut rng = Scope::formation(f, t).stream(seed, Stream::Initiate);
        let run = initiate::simulate(&target, steady.fps, &cruise, opts, &mut rng, &Silent)
            .map_err(|e| in_formation(e, f, n))?;
        if run.stats.converged && run.stats.min_distance >= MIN_TAKEOFF_DISTANCE {
            return Ok((run, t + 1, fresh));
        }
        if run.stats.converged {
            // Converged, but two birds came closer than wanted: keep the best such run in case
            // no try does better.
            let better = match &close {
                None => true,
                Some((r, _, _)) => run.stats.min_distance > r.stats.min_distance,
            };
            if better {
                close = Some((run, t + 1, fresh.clone()));
            }
            continue;
        }
        last = Some(run.stats);
    }
    if let Some(c) = close {
        return Ok(c);
    }
    let stats = last.expect("at least one try");
    Err(Error::NotConverged(format!(
        "formation {f} ({n} birds) did not converge into its key shape in {TAKEOFF_TRIES} take-offs of up to {:.0} s of flight (last: {} of {n} birds within {} wingspans of their slots, last lift-off at {:.1} s); the time limit is the smaller of initiate.max_time and initiate.max_steps / fps",
        opts.time_limit(steady.fps),
        stats.birds_in_slot,
        opts.tolerance,
        stats.last_liftoff
    )))
}

/// `run` with `wait` frames in front: before its start every bird kept its start state, at rest
/// on the ground (speed 0) or flying straight at its start heading and speed.
fn delayed(mut run: InitiationRun, wait: usize) -> InitiationRun {
    if wait == 0 || run.pos.is_empty() {
        return run;
    }
    let fps = run.fps;
    let p0 = run.pos[0].to_vec();
    let (h0, v0) = (run.heading[0].to_vec(), run.speed[0].to_vec());
    run.pos.prepend(wait, |j| {
        let back = (wait - j) as f64 / fps;
        p0.iter()
            .zip(&h0)
            .zip(&v0)
            .map(|((p, &h), &v)| *p - DVec2::new(h.sin(), h.cos()) * (v * back))
            .collect::<Vec<_>>()
    });
    for rows in [&mut run.z, &mut run.heading, &mut run.speed, &mut run.bank] {
        let first = rows[0].to_vec();
        rows.prepend(wait, |_| first.iter().copied());
    }
    run.stats.steps = run.pos.len() - 1;
    run
}

/// The point subtracted from every placement: the middle of the flock across the course, and
/// along it the middle of the start (take-off) or the front-most bird (steady flight, whose
/// leader starts at the origin for one formation).
fn centre_of(env: &[Envelope], p: &[Placement], takeoff: bool) -> [f64; 2] {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (e, p) in env.iter().zip(p) {
        x0 = x0.min(e.x[0] + p.offset[0]);
        x1 = x1.max(e.x[1] + p.offset[0]);
        if let (Some(r), Some(f)) = (e.rear.first(), e.front.first()) {
            y0 = y0.min(r + p.offset[1]);
            y1 = y1.max(f + p.offset[1]);
        }
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return [0.0, 0.0];
    }
    [0.5 * (x0 + x1), if takeoff { 0.5 * (y0 + y1) } else { y1 }]
}

/// Smallest 3-D distance between two birds of different formations over every frame of `anim`,
/// wingspans (infinite for one formation). In each frame the formations' boxes are swept west to
/// east, and only pairs whose boxes are closer than the best distance so far are compared bird
/// by bird.
pub fn min_separation(anim: &Animation) -> f64 {
    let Some(fs) = &anim.formations else {
        return f64::INFINITY;
    };
    let mut best = f64::INFINITY;
    let mut order: Vec<usize> = (0..fs.len()).collect();
    for f in &anim.frames {
        let boxes: Vec<[f64; 4]> = fs
            .iter()
            .map(|fm| {
                fm.birds.iter().fold(
                    [
                        f64::INFINITY,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                        f64::NEG_INFINITY,
                    ],
                    |b, &i| {
                        [
                            b[0].min(f.x[i]),
                            b[1].min(f.y[i]),
                            b[2].max(f.x[i]),
                            b[3].max(f.y[i]),
                        ]
                    },
                )
            })
            .collect();
        order.sort_by(|&a, &b| boxes[a][0].total_cmp(&boxes[b][0]).then(a.cmp(&b)));
        for (p, &a) in order.iter().enumerate() {
            for &b in &order[p + 1..] {
                // Sorted by west edge: every later box starts at least this far east.
                if boxes[b][0] - boxes[a][2] >= best {
                    break;
                }
                let gx = (boxes[a][0] - boxes[b][2])
                    .max(boxes[b][0] - boxes[a][2])
                    .max(0.0);
                let gy = (boxes[a][1] - boxes[b][3])
                    .max(boxes[b][1] - boxes[a][3])
                    .max(0.0);
                if gx.hypot(gy) >= best {
                    continue;
                }
                for &i in &fs[a].birds {
                    let p = DVec3::new(f.x[i], f.y[i], f.z[i]);
                    for &j in &fs[b].birds {
                        best = best.min(p.distance(DVec3::new(f.x[j], f.y[j], f.z[j])));
                    }
                }
            }
        }
    }
    best
}

/// The take-off statistics of the whole flock from its formations': sums of counts, extremes of
/// the rest; the smallest distance also counts birds of different formations.
pub fn flock_stats(report: &SkeinReport) -> Option<InitiateStats> {
    let all: Vec<&InitiateStats> = report
        .formations
        .iter()
        .map(|f| f.initiate.as_ref())
        .collect::<Option<Vec<_>>>()?;
    let first = (*all.first()?).clone();
    Some(all.iter().skip(1).fold(first, |mut s, o| {
        s.birds += o.birds;
        s.steps = s.steps.max(o.steps);
        s.seconds = s.seconds.max(o.seconds);
        s.planned_seconds = s.planned_seconds.max(o.planned_seconds);
        s.converged &= o.converged;
        s.min_distance = s.min_distance.min(o.min_distance);
        s.max_turn_rate = s.max_turn_rate.max(o.max_turn_rate);
        s.max_turn_accel = s.max_turn_accel.max(o.max_turn_accel);
        s.max_accel = s.max_accel.max(o.max_accel);
        s.max_bank = s.max_bank.max(o.max_bank);
        s.max_stray = s.max_stray.max(o.max_stray);
        s.last_liftoff = s.last_liftoff.max(o.last_liftoff);
        s.first_liftoff = s.first_liftoff.min(o.first_liftoff);
        s.formed_seconds = s
            .formed_seconds
            .zip(o.formed_seconds)
            .map(|(a, b)| a.max(b));
        s.cruise_height_seconds = s
            .cruise_height_seconds
            .zip(o.cruise_height_seconds)
            .map(|(a, b)| a.max(b));
        s.leader_changes += o.leader_changes;
        s.birds_in_slot += o.birds_in_slot;
        s.field_per_eye = s.field_per_eye.max(o.field_per_eye);
        s
    }))
    .map(|mut s| {
        s.min_distance = s.min_distance.min(report.min_separation);
        s
    })
}

/// An error of formation `f` (of `n` birds), saying which formation it was.
fn in_formation(e: Error, f: usize, n: usize) -> Error {
    let pre = format!("formation {f} ({n} birds)");
    match e {
        Error::Parameter { name, message } => Error::Parameter {
            name,
            message: format!("{pre}: {message}"),
        },
        Error::NotConverged(m) if !m.starts_with("formation ") => {
            Error::NotConverged(format!("{pre}: {m}"))
        }
        Error::Unreachable(m) => Error::Unreachable(format!("{pre}: {m}")),
        Error::Internal(m) => Error::Internal(format!("{pre}: {m}")),
        other => other,
    }
}

/// `f(0..k)` on the machine's cores, results in index order; the error of the lowest index wins
/// (so a run fails the same way whatever the thread timing).
fn par_map<T: Send>(k: usize, f: impl Fn(usize) -> Result<T> + Sync) -> Result<Vec<T>> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(k.max(1));
    let mut slots: Vec<Option<Result<T>>> = (0..k).map(|_| None).collect();
    if threads <= 1 {
        for (i, s) in slots.iter_mut().enumerate() {
            *s = Some(f(i));
        }
    } else {
        let f = &f;
        let chunks: Vec<Vec<(usize, Result<T>)>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|t| scope.spawn(move || (t..k).step_by(threads).map(|i| (i, f(i))).collect()))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_default())
                .collect()
        });
        for (i, r) in chunks.into_iter().flatten() {
            slots[i] = Some(r);
        }
    }
    slots
        .into_iter()
        .map(|s| s.unwrap_or_else(|| Err(Error::Internal("a worker thread failed".into()))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers `docs/large-flocks.md` gives for Hummel's g at the default clearance.
    #[test]
    fn hummels_g_at_the_clearance_is_small() {
        let aero = crate::aero::AeroOptions::default();
        let side = aero.g(5.0, 0.0);
        let diag = aero.g(5.0, 5.0);
        let far = aero.g(0.5, 50.0);
        println!(
            "g(5,0) = {side:.5}, 2g(5,0) = {:.5}, g(5,5) = {diag:.5}, g(0.5,50) = {far:.5}",
            2.0 * side
        );
        assert!(side > 0.0 && side < 0.01);
        assert!(diag > side && diag < 2.0 * side);
        // Directly behind, the model's infinite trailing vortices still give downwash.
        assert!(far < 0.0);
    }

    #[test]
    fn option_errors_name_the_option() {
        let bad = [
            (
                SkeinOptions {
                    formations: Some(0),
                    ..SkeinOptions::default()
                },
                "skein.formations: ",
            ),
            (
                SkeinOptions {
                    formations: Some(6),
                    ..SkeinOptions::default()
                },
                "skein.formations: ",
            ),
            (
                SkeinOptions {
                    formation_size: Some(1),
                    ..SkeinOptions::default()
                },
                "skein.formation_size: ",
            ),
            (
                SkeinOptions {
                    formations: Some(3),
                    formation_size: Some(5),
                    ..SkeinOptions::default()
                },
                "skein.formations/skein.formation_size: ",
            ),
            (
                SkeinOptions {
                    clearance: f64::NAN,
                    ..SkeinOptions::default()
                },
                "skein.clearance: ",
            ),
            (
                SkeinOptions {
                    spread: -1.0,
                    ..SkeinOptions::default()
                },
                "skein.spread: ",
            ),
        ];
        for (o, want) in bad {
            let e = o.validate(10).unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
            assert_eq!(e.lines().count(), 1);
        }
        let ok = SkeinOptions {
            formations: Some(1),
            formation_size: Some(10),
            ..SkeinOptions::default()
        };
        assert!(ok.validate(10).is_ok());
        assert_eq!(SkeinOptions::default().sizes(14, 9, 0).unwrap(), vec![14]);
        assert_eq!(SkeinOptions::default().sizes(19, 9, 0).unwrap().len(), 2);
    }

    #[test]
    fn a_delayed_run_waits_at_its_start_state() {
        fn rows<T: Copy>(values: [T; 2]) -> initiate::Rows<T> {
            let mut r = initiate::Rows::new(1);
            values.into_iter().for_each(|v| r.push_row([v]));
            r
        }
        let run = InitiationRun {
            fps: 10.0,
            pos: rows([DVec2::new(1.0, 2.0), DVec2::new(1.0, 3.0)]),
            z: rows([0.0, 0.1]),
            heading: rows([0.0, 0.0]),
            speed: rows([10.0, 10.0]),
            bank: rows([0.0, 0.0]),
            slot: vec![Some(0)],
            stats: InitiateStats {
                birds: 1,
                steps: 1,
                seconds: 0.1,
                planned_seconds: 0.1,
                converged: true,
                min_distance: f64::INFINITY,
                max_turn_rate: 0.0,
                max_turn_accel: 0.0,
                max_accel: 0.0,
                max_bank: 0.0,
                max_stray: 0.0,
                last_liftoff: 0.0,
                first_liftoff: 0.0,
                formed_seconds: Some(0.0),
                cruise_height_seconds: Some(0.0),
                leader_changes: 0,
                birds_in_slot: 1,
                field_per_eye: 1.0,
            },
        };
        let d = delayed(run, 3);
        assert_eq!(d.pos.len(), 5);
        // Flying straight north at 10 wingspans/s before the start: one wingspan per frame.
        let ys: Vec<f64> = (0..d.pos.len()).map(|t| d.pos[t][0].y).collect();
        assert_eq!(ys, vec![-1.0, 0.0, 1.0, 2.0, 3.0]);
        let zs: Vec<f64> = (0..d.z.len()).map(|t| d.z[t][0]).collect();
        assert_eq!(zs, vec![0.0, 0.0, 0.0, 0.0, 0.1]);
        assert_eq!(d.stats.steps, 4);
    }
}
