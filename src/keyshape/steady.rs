//! §5 Algorithm 1, the whole steady flight: from the formation parameters of an N̂-bird movie
//! (docs/formats.md §4.2) to an F-frame animation of N birds (docs/formats.md §4.4) whose key shapes keep the movie's
//! energy-savings pattern. Lengths in wingspans, times in seconds, speeds in wingspans per second.
//!
//! 1. [`initial`](crate::keyshape::initial): correspondence and one N-bird shape per movie frame.
//! 2. [`ranges`](crate::keyshape::ranges): ξ of every bird in every initial shape, evaluated at the
//!    key shapes' lateral positions, and the ranges [p_i, P_i].
//! 3. [`keys`](crate::keyshape::keys): key shapes by eq. (2) and the solve of eq. (4).
//! 4. [`interpolate`](crate::keyshape::interpolate): C¹ monotone cubic of each bird's `y` between
//!    keys, the flock cruising along +y.
//!
//! The lateral positions are drawn once: gaps from N(d̄, σ̄_x) with
//! d̄ uniform in the movie's range of mean gaps [min_f μ_xf, max_f μ_xf] and σ̄_x the mean of σ_xf,
//! redrawn only at or below a body's width (`min_gap`; overlapping wingtips are kept); each gap
//! then drifts slowly around its drawn value from key to key (`lateral_drift`), so
//! every key shape has its own x. Munk's theorem fixes E = Σ_{i≠j} g(|x_i − x_j|, 0) of each
//! key shape (`aero::munk_total`), which makes eq. (3) exact instead of an estimate from a
//! constant-gap flock. Heights differ slightly between birds (`height_spread`,
//! `height_neighbour`). This is the course frame: the leader at (0, speed·t, 0) and every bird
//! at (x_i(t), speed·t − y_i(t), z_i(t)); the course step (`crate::course`) maps it onto a path.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::aero::AeroOptions;
use crate::animation::{Animation, Frame, KeyBird, KeyShapeRecord, Stage};
use crate::error::{Error, Result};
use crate::extract::params::FormationParams;
use crate::keyshape::heights::{heights, heights_for, HeightOptions};
use crate::keyshape::initial::{
    correspondence_split, curve_y, initial_shapes_scaled, lateral_gaps, positions_from_gaps,
    proportional_left, side_scales, Correspondence, InitialOptions,
};
use crate::keyshape::interpolate::Track;
use crate::keyshape::jostle::{
    keeping_for, key_spread, residual_keeping, rooms, slow_drift, Jostle, JostleOptions, Placement,
    Room,
};
use crate::keyshape::keys::{
    key_shapes, KeyContext, KeyOptions, KeyPlan, KeyShape, KeyStats, LateralKey, Structure,
};
use crate::keyshape::lateral::{lateral_plan, LateralBounds, LateralOptions};
use crate::keyshape::ranges::{power_at, xi_ranges, XiRanges};
use crate::keyshape::reorganise::{Plan, ReorganiseOptions, SlotState};
pub use crate::keyshape::separate::separate;
use crate::keyshape::spacing;
use crate::progress::Progress;
use crate::rng::{Scope, Stream};

/// Options of the steady flight (the `steady` section of [`crate::pipeline::Config`]). Each
/// step's options are their own section (`steady.keys`, `steady.initial`, …), defined once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SteadyOptions {
    /// N, birds to animate, count (≥ 2).
    pub birds: usize,
    /// F, frames to produce, count (≥ 1).
    pub frames: usize,
    /// Frames per second, in [1, 1000].
    pub fps: f64,
    /// Cruise speed of the flock along +y, wingspans per second, in (0, 1000].
    pub speed: f64,
    /// Wingspan of one bird, metres, in (0, 100] (recorded in the file for exports).
    pub wingspan_m: f64,
    /// Seed recorded in the animation file (the generator itself is passed in).
    pub seed: u64,
    /// Step 3: eq. (2)'s draws, the key interval and the acceptance of key shapes.
    pub keys: KeyOptions,
    /// Step 1: the lateral gaps' physical bound and the initial shapes' redraws.
    pub initial: InitialOptions,
    /// The lateral positions' slow drift between key shapes.
    pub lateral: LateralOptions,
    /// Small per-bird altitude differences.
    pub heights: HeightOptions,
    /// The aerodynamic model's vortex core and collision distance.
    pub aero: AeroOptions,
    /// Each bird's position-keeping motion about its slot (`keyshape::jostle`); none in a
    /// loop.
    pub jostle: JostleOptions,
    /// Leader changes and neighbour swaps (`keyshape::reorganise`); none in a loop.
    pub reorganise: ReorganiseOptions,
    /// The birds' mass and airspeed for their power curve (savings of total power), recorded in
    /// the animation.
    pub flight: crate::animation::FlightSettings,
    /// A seamless cycle: the last key shape is the first, placed one frame after the last
    /// frame, so the frame after the last is the first again (in the flock's moving frame).
    #[serde(rename = "loop")]
    pub looped: bool,
    /// The arms of a formation the birds already fly (a start file's, `initiate::Joining`):
    /// the key shapes are solved with its birds left of the leader and its observed lateral
    /// gaps. Not a config option: set from the start file.
    #[serde(skip)]
    pub given: Option<crate::keyshape::given::GivenArms>,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        SteadyOptions {
            birds: 9,
            frames: 300,
            fps: 30.0,
            speed: 10.0,
            wingspan_m: 1.5,
            seed: 0,
            keys: KeyOptions::default(),
            initial: InitialOptions::default(),
            lateral: LateralOptions::default(),
            heights: HeightOptions::default(),
            aero: AeroOptions::default(),
            jostle: JostleOptions::default(),
            reorganise: ReorganiseOptions::default(),
            flight: crate::animation::FlightSettings::default(),
            looped: false,
            given: None,
        }
    }
}

impl SteadyOptions {
    /// Checks every option; the error names the option path (`steady.fps`, `steady.keys.c1`).
    pub fn validate(&self) -> Result<()> {
        let p = |name: &str, msg: String| Error::parameter(name, msg);
        if self.birds < 2 {
            return Err(p(
                "steady.birds",
                format!("{}: a formation needs at least 2 birds", self.birds),
            ));
        }
        if self.birds > crate::limits::MAX_BIRDS {
            return Err(p(
                "steady.birds",
                format!("{}: at most {} birds", self.birds, crate::limits::MAX_BIRDS),
            ));
        }
        if self.birds > crate::limits::MAX_FORMATION_BIRDS {
            return Err(p(
                "steady.birds",
                format!(
                    "{}: at most {} birds fly as one formation (the steady flight's cost grows with the square of a formation's birds)",
                    self.birds,
                    crate::limits::MAX_FORMATION_BIRDS
                ),
            ));
        }
        if self.frames == 0 {
            return Err(p("steady.frames", "0: at least 1 frame is needed".into()));
        }
        crate::limits::check_animation_size("steady.frames", self.birds, self.frames)?;
        // At least one frame a second: a vanishing rate (5e-324) made every frame time infinite.
        if !(self.fps.is_finite() && self.fps >= 1.0 && self.fps <= 1000.0) {
            return Err(p(
                "steady.fps",
                format!("{}: must be in [1, 1000] frames per second", self.fps),
            ));
        }
        if !(self.speed.is_finite() && self.speed > 0.0 && self.speed <= 1000.0) {
            return Err(p(
                "steady.speed",
                format!("{}: must be in (0, 1000] wingspans per second", self.speed),
            ));
        }
        if !(self.wingspan_m.is_finite()
            && self.wingspan_m >= crate::limits::MIN_WINGSPAN_M
            && self.wingspan_m <= 100.0)
        {
            return Err(p(
                "steady.wingspan_m",
                format!(
                    "{}: must be in [{}, 100] metres",
                    self.wingspan_m,
                    crate::limits::MIN_WINGSPAN_M
                ),
            ));
        }
        self.keys.validate()?;
        self.initial.validate()?;
        self.lateral.validate()?;
        self.heights.validate()?;
        self.aero.validate()?;
        self.jostle.validate()?;
        self.reorganise.validate()?;
        if self.looped {
            let (l, sw) = (
                self.reorganise.leader_changes.unwrap_or(0.0),
                self.reorganise.swaps.unwrap_or(0.0),
            );
            if l > 0.0 || sw > 0.0 {
                return Err(p(
                    if l > 0.0 {
                        "steady.reorganise.leader_changes"
                    } else {
                        "steady.reorganise.swaps"
                    },
                    "a loop cannot reorganise: the birds would not be back in their slots when it comes round; give 0 or set steady.loop to false".into(),
                ));
            }
        }
        crate::aero::flight::validate_settings(&self.flight)?;
        let seconds = self.frames as f64 / self.fps;
        let joiners = self.reorganise.joiners;
        if joiners > 0 {
            let name = "steady.reorganise.joiners";
            if joiners >= self.birds {
                return Err(p(
                    name,
                    format!(
                        "{joiners}: more late birds than the formation can take; give at most {} (the formation has {} birds, at least one of them in formation from the start)",
                        self.birds - 1,
                        self.birds
                    ),
                ));
            }
            if self.looped {
                return Err(p(
                    name,
                    "a loop cannot have late birds: they would not be back where they came from when it comes round; give 0 or set steady.loop to false".into(),
                ));
            }
            let end =
                crate::keyshape::reorganise::Join::plan(&[vec![], vec![]], 0, 0, self.speed).end();
            if seconds < end {
                return Err(p(
                    name,
                    format!(
                        "late birds need a steady flight of at least {end:.1} s to join (this one lasts {seconds:.1} s); make it longer"
                    ),
                ));
            }
        }
        if self.looped && seconds < self.keys.key_every_s {
            return Err(p(
                "steady.loop",
                format!(
                    "a loop of {seconds:.2} s is shorter than one key interval (steady.keys.key_every_s = {} s); make the flight longer or the key interval shorter",
                    self.keys.key_every_s
                ),
            ));
        }
        Ok(())
    }

    /// What bounds the lateral positions' drift ([`lateral_plan`]).
    pub fn lateral_bounds(&self) -> LateralBounds {
        LateralBounds {
            correlation: self.lateral.correlation,
            min_gap: self.initial.min_gap,
            max_jump: self.keys.max_jump,
            looped: self.looped,
        }
    }

    /// A living flight: position keeping or reorganisations on (never in a loop). Its key
    /// shapes come at fixed times in seconds ([`SteadyOptions::key_times`]), so the same seed
    /// gives the same motion at any frame rate.
    pub fn living(&self) -> bool {
        !self.looped && (self.jostle.scale > 0.0 || self.reorganise.any(self.jostle.scale > 0.0))
    }

    /// The time of every key shape, seconds. A living flight ([`SteadyOptions::living`]): every
    /// `keys.key_every_s` seconds from 0 until one at or after the flight's length F/fps (the
    /// same times at any frame rate); otherwise at [`SteadyOptions::key_frames`].
    pub fn key_times(&self) -> Vec<f64> {
        if !self.living() {
            return self
                .key_frames()
                .iter()
                .map(|&f| f as f64 / self.fps)
                .collect();
        }
        let every = self.keys.key_every_s;
        let length = self.frames as f64 / self.fps;
        let k = ((length / every - 1e-9).ceil() as usize).max(1);
        (0..=k).map(|i| i as f64 * every).collect()
    }

    /// Number of key shapes and the frame of each (evenly spread, first at 0, last at F − 1; for
    /// a loop the last at F, one frame after the last, where the first key comes round again).
    pub fn key_frames(&self) -> Vec<usize> {
        let f = self.frames + usize::from(self.looped);
        if f <= 1 {
            return vec![0];
        }
        let spacing = (self.keys.key_every_s * self.fps).round().max(1.0);
        let k = (((f - 1) as f64 / spacing).round() as usize).max(1) + 1;
        (0..k)
            .map(|i| ((i as f64) * ((f - 1) as f64) / ((k - 1) as f64)).round() as usize)
            .collect()
    }
}

/// What Algorithm 1 did, for reports and tests.
#[derive(Debug, Clone, Serialize)]
pub struct SteadyReport {
    /// Step 1's correspondence (animated birds left to right).
    pub correspondence: Vec<Option<usize>>,
    /// Animated leader index.
    pub leader: usize,
    /// Movie birds dropped (N < N̂).
    pub dropped: Vec<usize>,
    /// Mean lateral gap d̄ drawn for the key shapes, wingspans.
    pub mean_gap: f64,
    /// Lateral positions of the key shapes, wingspans.
    pub x: Vec<f64>,
    /// E of every key shape (Munk), dimensionless.
    pub total: f64,
    /// Raw ranges [p_i, P_i] of step 2.
    pub ranges: XiRanges,
    /// Feasible ranges [(1 − ε) p_i, (1 + ε) P_i].
    pub feasible: XiRanges,
    /// Movie frame (position in the params file) whose initial shape is the first key shape;
    /// `None` when none qualified and the first frame's noise-free curve was used.
    pub first_key_from: Option<usize>,
    /// Frame index of each key shape.
    pub key_frames: Vec<usize>,
    /// Step 3 counts.
    pub keys: KeyStats,
    /// The footage's median (lateral, longitudinal) distance to the nearest bird ahead,
    /// wingspans (`None` without positions in the params).
    pub footage_spacing: Option<(f64, f64)>,
    /// Factor on the U and J curves' rank scale that gives the initial shapes the footage's
    /// longitudinal spacing (1 for V and line frames, or without positions).
    pub depth_scale: f64,
    /// Band of every key shape's median longitudinal distance to the nearest bird ahead,
    /// wingspans.
    pub spacing_band: Option<(f64, f64)>,
    /// Standard deviation of the lateral gaps' drift between key shapes, wingspans (the
    /// footage's unless `steady.lateral.drift` is set).
    pub lateral_drift: f64,
    /// Frames where some bird's ξ leaves its feasible range.
    pub frames_outside_range: usize,
    /// Largest amount by which a frame's ξ leaves the feasible range.
    pub max_frame_excess: f64,
}

/// The shapes' depths with every collision at lateral positions `x` resolved by [`separate`]
/// (each shape keeps its own lateral positions).
fn separated_at(
    x: &[f64],
    shapes: &[crate::shape::Shape],
    aero: &AeroOptions,
) -> Vec<crate::shape::Shape> {
    shapes
        .iter()
        .map(|s| crate::shape::Shape::from_xy(&s.xs(), &separate(x, &s.ys(), aero)))
        .collect()
}

/// Largest factor (and smallest, its inverse) [`depth_scale`] applies to the U and J curves.
const DEPTH_SCALE_LIMIT: f64 = 3.0;

/// The factor on the U and J curves' rank scale ([`side_scales`]) that gives the initial shapes,
/// at the key shapes' lateral positions `x`, the footage's median longitudinal distance to the
/// nearest bird ahead. The plain rank scale keeps each bird's step behind its
/// neighbour at the same relative place on the arm, but a median of the few steps of a small
/// flock, or of the many of a large one, is not the footage's median of its own count (a
/// parabola's steps grow along the arm), and the noise of the deviations adds to it. The
/// shapes are drawn from a generator seeded from `rng` (one draw), so the flight stays
/// deterministic. 1 when no frame is a U or J, or without positions.
fn depth_scale(
    params: &FormationParams,
    corr: &Correspondence,
    x: &[f64],
    footage: Option<(f64, f64)>,
    init: &InitialOptions,
    rng: &mut impl Rng,
    at_key_x: &dyn Fn(Vec<crate::shape::Shape>) -> Vec<crate::shape::Shape>,
) -> f64 {
    use crate::extract::params::ShapeModel;
    let curved = params
        .frames
        .iter()
        .any(|f| matches!(f.shape, ShapeModel::U { .. } | ShapeModel::J { .. }));
    let Some((_, target)) = footage.filter(|_| curved) else {
        return 1.0;
    };
    let seed: u64 = rng.random();
    let (sl, sr) = side_scales(params, corr);
    spacing::depth_scale(target, DEPTH_SCALE_LIMIT, |t| {
        let mut r = crate::rng::seeded(seed);
        let shapes = at_key_x(initial_shapes_scaled(
            params,
            corr,
            (sl * t, sr * t),
            &mut r,
            init,
        ));
        let ys: Vec<Vec<f64>> = shapes.iter().map(|s| s.ys()).collect();
        spacing::spacing(ys.iter().map(|y| (x, y.as_slice()))).1
    })
}

/// The steady flight of Algorithm 1 as an animation (one `steady` stage covering all frames).
pub fn steady_flight(
    params: &FormationParams,
    opts: &SteadyOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<Animation> {
    steady_flight_report(params, opts, rng, progress).map(|(a, _)| a)
}

/// [`steady_flight`] plus the report of what each step did. The slow drift of the lateral gaps
/// and the birds' heights draw from the run's own `steady.lateral` and `steady.height` streams of
/// `opts.seed` ([`Scope::Run`]); one formation of a flock of several is [`steady_flight_in`].
pub fn steady_flight_report(
    params: &FormationParams,
    opts: &SteadyOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<(Animation, SteadyReport)> {
    steady_flight_in(params, opts, Scope::Run, rng, progress)
}

/// [`steady_flight_report`] with the drift of the lateral gaps and the heights drawn from
/// `scope`'s `steady.lateral` and `steady.height` streams of `opts.seed`: each formation of a
/// flock of several ([`Scope::Formation`]) breathes sideways and steps in height on its own,
/// instead of every formation of one size repeating the same plan.
pub fn steady_flight_in(
    params: &FormationParams,
    opts: &SteadyOptions,
    scope: Scope,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<(Animation, SteadyReport)> {
    opts.validate()?;
    let first = params
        .frames
        .first()
        .ok_or_else(|| Error::parameter("params", "no frames"))?;
    let n = opts.birds;
    let init_opts = &opts.initial;

    // Step 1 (with a given formation's birds left of the leader).
    if let Some(g) = &opts.given {
        g.validate(n)?;
    }
    // Late birds joining in flight take the tail of one arm and the formed birds keep the
    // footage's split among themselves: the joiners lengthen the formed flock's longer arm
    // (its right one on a tie), which `reorganise::Plan` then gives them.
    let left = match &opts.given {
        Some(g) => Some(g.left),
        None if opts.living() && opts.reorganise.joiners > 0 => {
            let k = opts.reorganise.joiners.min(n - 1);
            let lf = proportional_left(first, n - k);
            let rf = n - k - 1 - lf;
            Some(if rf >= lf { lf } else { lf + k })
        }
        None => None,
    };
    let corr: Correspondence = correspondence_split(first, n, left)?;
    // The spacing is drawn from the frames that look like the others (an odd frame, e.g. a
    // half-tracked one, would widen every generated flock; `extract` warns about it).
    let spacing_frames = crate::extract::screen::spacing_frames(params);
    let (lo_mu, hi_mu) = spacing_frames
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), f| {
            (a.min(f.mu_x), b.max(f.mu_x))
        });
    let sigma_bar =
        spacing_frames.iter().map(|f| f.sigma_x).sum::<f64>() / spacing_frames.len().max(1) as f64;
    let u: f64 = rng.random();
    let mean_gap = (lo_mu + u * (hi_mu - lo_mu)).max(init_opts.min_gap);
    let mut gaps = lateral_gaps(rng, mean_gap, sigma_bar, n - 1, init_opts);
    if let Some(g) = &opts.given {
        g.fix_gaps(&mut gaps, mean_gap, init_opts.min_gap);
    }
    let x = positions_from_gaps(&gaps, corr.leader);
    // At the key shapes' lateral positions a movie frame's placement can put two birds wing to
    // wing; the bird behind is moved back to the collision distance (what a real bird does).
    let aero = &opts.aero;
    let at_key_x = |shapes: Vec<crate::shape::Shape>| separated_at(&x, &shapes, aero);
    let footage = spacing::footage_spacing(params);
    let depth_scale = depth_scale(params, &corr, &x, footage, init_opts, rng, &at_key_x);
    let (sl, sr) = side_scales(params, &corr);
    let scales = (sl * depth_scale, sr * depth_scale);
    let raw_shapes = initial_shapes_scaled(params, &corr, scales, rng, init_opts);
    let shapes = at_key_x(raw_shapes.clone());

    // Step 2, at the key shapes' lateral positions.
    let values = power_at(&x, &shapes, aero)?;
    let ranges = xi_ranges(&values)?;
    let feasible = ranges.widened(opts.keys.epsilon);
    let total = aero.munk_total(&x)?;
    if !(total > 0.0) {
        return Err(Error::parameter(
            "params",
            format!("the drawn lateral gaps give the flock no saving in total (E = {total:.4}): the footage's mean lateral gap is too small for Hummel's model; check the wingspan scale of the annotations"),
        ));
    }

    // The first key shape: the first initial shape whose leader is front-most.
    let deepest = shapes
        .iter()
        .map(|s| s.ys().iter().copied().fold(0.0, f64::max))
        .fold(0.0, f64::max);
    let max_depth = opts.keys.max_depth_factor * deepest + 1.0;
    let loose = Structure {
        leader: corr.leader,
        monotone_pairs: vec![],
        max_depth,
        monotone_tolerance: 0.0,
        spacing: None,
        min_step: 0.0,
    };
    let first_key_from = shapes
        .iter()
        .position(|s| loose.accepts(&x, &s.ys()) && aero.first_collision(&x, &s.ys()).is_none());
    let y0: Vec<f64> = match first_key_from {
        Some(i) => shapes[i].ys(),
        None => {
            let (sl, sr) = scales;
            let y: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(i, &xi)| {
                    if i == corr.leader {
                        0.0
                    } else {
                        curve_y(&first.shape, xi, sl, sr).max(init_opts.lead_margin)
                    }
                })
                .collect();
            separate(&x, &y, aero)
        }
    };
    let p0 = aero.power_reduction(&x, &y0).map_err(|e| match e {
        Error::Collision { .. } => Error::parameter(
            "params",
            format!("no frame's shape fits the drawn lateral gaps without two birds' wings colliding ({e}); try another seed"),
        ),
        other => other,
    })?;
    let key0 = KeyShape {
        x: x.clone(),
        y: y0.clone(),
        xi_target: p0.xi.clone(),
        xi: p0.xi,
        residual: 0.0,
        damping: 1.0,
        draws: 0,
    };
    // The key shapes' spacing stays inside the band the initial shapes span (as each bird's ξ
    // stays inside its range), widened by `keys.spacing_margin`.
    let spacing_band = shapes
        .iter()
        .map(|s| spacing::spacing([(x.as_slice(), s.ys().as_slice())]).1)
        .filter(|m| m.is_finite())
        .fold(None, |b: Option<(f64, f64)>, m| {
            Some(b.map_or((m, m), |(lo, hi)| (lo.min(m), hi.max(m))))
        })
        .map(|(lo, hi)| {
            let m0 = spacing::spacing([(x.as_slice(), y0.as_slice())]).1;
            let w = opts.keys.spacing_margin;
            (lo.min(m0) * (1.0 - w), hi.max(m0) * (1.0 + w))
        });
    let structure = Structure {
        spacing: spacing_band,
        min_step: crate::keyshape::separate::min_step(aero),
        ..Structure::of(&x, &y0, corr.leader, max_depth)
    };

    // Step 3.
    let key_times = opts.key_times();
    let key_frames: Vec<usize> = key_times
        .iter()
        .map(|&t| (t * opts.fps).round() as usize)
        .collect();
    let solve_opts = opts.keys.solve_options(&opts.aero);
    let nk = key_times.len();
    progress.start("steady: key shapes", nk as u64);
    let ctx = KeyContext {
        x: &x,
        feasible: &feasible,
        structure: &structure,
        opts: &opts.keys,
        solve: &solve_opts,
        total,
    };
    let mut lateral = Vec::with_capacity(nk);
    let mut lat_rng = scope.stream(opts.seed, Stream::SteadyLateral);
    let drawn = LateralKey {
        x: x.clone(),
        total,
        feasible: feasible.clone(),
    };
    let keeping = keeping_for(params);
    let jostling = !opts.looped && opts.jostle.scale > 0.0;
    let drift = match opts.lateral.drift {
        // The footage's gap variation, less the part the birds' position keeping makes.
        None if jostling => slow_drift(opts.lateral.drift_for(params), &keeping, opts.jostle.scale),
        _ => opts.lateral.drift_for(params),
    };
    // Each key's feasible ranges are the initial shapes' ξ at its own lateral positions (as
    // step 2 does at the drawn ones). A drift that leaves the flock no saving in total, or at
    // which every initial shape collides, is not taken.
    let lateral_at = |xk: &[f64]| -> Option<LateralKey> {
        let t = aero.munk_total(xk).ok().filter(|t| *t > 0.0)?;
        let values = power_at(xk, &separated_at(xk, &raw_shapes, aero), aero).ok()?;
        Some(LateralKey {
            x: xk.to_vec(),
            total: t,
            feasible: xi_ranges(&values).ok()?.widened(opts.keys.epsilon),
        })
    };
    for xk in lateral_plan(
        &gaps,
        corr.leader,
        nk,
        drift,
        &opts.lateral_bounds(),
        &mut lat_rng,
    ) {
        lateral.push(if xk == x {
            drawn.clone()
        } else {
            lateral_at(&xk).unwrap_or_else(|| drawn.clone())
        });
    }
    let plan = KeyPlan {
        lateral,
        home: opts.looped,
    };
    let solved = if opts.looped { nk - 1 } else { nk };
    let (mut keys, key_stats) = key_shapes(&ctx, &plan, key0, solved, &lateral_at, rng, || {
        progress.advance(1)
    })?;
    if opts.looped {
        keys.push(keys[0].clone());
        progress.advance(1);
    }
    progress.finish();
    // The published ranges: every key's own, extended (as its draws were) to the previous key's
    // placement at its lateral positions.
    let mut feasible = feasible;
    for (k, key) in keys.iter().enumerate().skip(1) {
        if let Some(l) = plan.lateral.iter().find(|l| l.x == key.x) {
            feasible = feasible.union(&l.feasible);
        } else if let Some(l) = lateral_at(&key.x) {
            feasible = feasible.union(&l.feasible);
        }
        if key.x != keys[k - 1].x {
            let t = aero.munk_total(&key.x).unwrap_or(total);
            let reference: Vec<f64> = aero
                .power_lenient(&key.x, &keys[k - 1].y)
                .iter()
                .map(|e| e / t)
                .collect();
            feasible = feasible.including(&reference);
        }
    }
    let height_opts = heights_for(params, &opts.heights);
    let heights = heights(
        n,
        &x,
        corr.leader,
        nk,
        &height_opts,
        opts.looped,
        &mut scope.stream(opts.seed, Stream::SteadyHeight),
    );

    // Each bird's position keeping about its slot (not in a loop: the motion does not cycle).
    let jostle = if !jostling {
        None
    } else {
        let xs: Vec<&[f64]> = keys.iter().map(|k| k.x.as_slice()).collect();
        let ys: Vec<&[f64]> = keys.iter().map(|k| k.y.as_slice()).collect();
        Jostle::draw(
            n,
            &residual_keeping(&keeping, key_spread(&xs, &ys), n),
            &opts.jostle,
            &mut scope.stream(opts.seed, Stream::SteadyJostle),
        )
    };

    // Leader changes and swaps: which bird flies in which slot, over time.
    let plan = if opts.living() {
        Plan::draw(
            &keys[0].x,
            &keys[0].y,
            corr.leader,
            opts.frames as f64 / opts.fps,
            opts.speed,
            &opts.reorganise,
            opts.jostle.scale > 0.0,
            &mut scope.stream(opts.seed, Stream::SteadyEvents),
        )
    } else {
        Plan::draw(
            &x,
            &y0,
            corr.leader,
            0.0,
            opts.speed,
            &ReorganiseOptions::none(),
            false,
            rng,
        )
    };
    let reorganised = !plan.exchanges.is_empty() || plan.join.is_some();

    // Step 4.
    progress.start("steady: frames", opts.frames as u64);
    let times = &key_times;
    let track = |v: &dyn Fn(usize) -> f64| {
        let v: Vec<f64> = (0..nk).map(v).collect();
        Track::pchip(times, &v)
    };
    let tracks: Vec<[Track; 3]> = (0..n)
        .map(|i| {
            [
                track(&|k| keys[k].y[i]),
                track(&|k| keys[k].x[i]),
                track(&|k| heights[k][i]),
            ]
        })
        .collect();
    let mut frames = Vec::with_capacity(opts.frames);
    let mut clock = jostle.as_ref().map(|j| j.clock(opts.fps));
    let mut frames_outside_range = 0;
    let mut max_frame_excess: f64 = 0.0;
    for j in 0..opts.frames {
        let t = j as f64 / opts.fps;
        let lead_y = opts.speed * t;
        let mut fr = Frame {
            t,
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            heading: Vec::with_capacity(n),
            speed: Vec::with_capacity(n),
            ..Frame::default()
        };
        // The key-shape placement, then each bird's position keeping about it.
        let mut ys = Vec::with_capacity(n);
        let (mut vxs, mut vys) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut vzs = Vec::with_capacity(n);
        if reorganised {
            let slots: Vec<SlotState> = tracks
                .iter()
                .map(|[ty, tx, tz]| {
                    let (y, vy) = ty.eval(t);
                    let (x, vx) = tx.eval(t);
                    let (z, vz) = tz.eval(t);
                    SlotState {
                        x,
                        y,
                        z,
                        vx,
                        vy,
                        vz,
                    }
                })
                .collect();
            for b in plan.birds_at(t, &slots, opts.reorganise.pass_offset) {
                ys.push(b.y);
                fr.x.push(b.x);
                fr.z.push(b.z);
                vxs.push(b.vx);
                vys.push(b.vy);
                vzs.push(b.vz);
            }
        } else {
            for [ty, tx, tz] in &tracks {
                let (y, dy) = ty.eval(t);
                let (xl, dx) = tx.eval(t);
                let (z, dz) = tz.eval(t);
                ys.push(y);
                fr.x.push(xl);
                fr.z.push(z);
                vxs.push(dx);
                vys.push(dy);
                vzs.push(dz);
            }
        }
        if let Some(clock) = &mut clock {
            clock.seek(j);
            let room = rooms(&Placement {
                x: &fr.x,
                y: &ys,
                z: &fr.z,
                vx: &vxs,
                vy: &vys,
                vz: &vzs,
            });
            for (i, &r) in room.iter().enumerate() {
                let (keep, dkeep) = plan.keeping(i, t);
                let dev = clock.at(i, Room { keep, dkeep, ..r });
                fr.x[i] += dev.x;
                ys[i] += dev.y;
                vxs[i] += dev.vx;
                vys[i] += dev.vy;
            }
        }
        for i in 0..n {
            fr.y.push(lead_y - ys[i]);
            // World velocity (dx/dt, speed − dy/dt): the flock frame moves at `speed` along +y.
            let (vx, vy) = (vxs[i], opts.speed - vys[i]);
            fr.heading.push(vx.atan2(vy));
            fr.speed.push(vx.hypot(vy));
        }
        // Between two collision-free keys a pair can pass within a chord: evaluated at the
        // collision distance there, so every frame has finite savings.
        let (e, total_t) = if !aero.model.is_hummel() {
            // Another model's savings: ξ against its own total (the ranges below stay
            // Hummel's, checked on Hummel's ξ).
            let e = aero.power_lenient_3d(&fr.x, &ys, &fr.z);
            let t: f64 = e.iter().sum();
            (e, if t.is_finite() && t > 0.0 { t } else { total })
        } else if aero.wake.is_planar() {
            let t = match aero.munk_total(&fr.x) {
                Ok(t) if t > 0.0 => t,
                _ => total,
            };
            (aero.power_lenient(&fr.x, &ys), t)
        } else {
            // The 3-D wake: the birds' own heights in this frame.
            let t = aero.munk_total_3d_unchecked(&fr.x, &fr.z);
            let t = if t.is_finite() && t > 0.0 { t } else { total };
            (aero.power_lenient_3d(&fr.x, &ys, &fr.z), t)
        };
        let xi: Vec<f64> = e.iter().map(|v| v / total_t).collect();
        // The feasible ranges are Hummel's: another model's ξ is checked as Hummel's.
        let hummel_xi: Option<Vec<f64>> = (!aero.model.is_hummel()).then(|| {
            let h = crate::aero::AeroOptions {
                model: crate::aero::AeroModel::Hummel,
                ..*aero
            };
            let t = match h.munk_total(&fr.x) {
                Ok(t) if t > 0.0 => t,
                _ => total,
            };
            h.power_lenient(&fr.x, &ys).iter().map(|v| v / t).collect()
        });
        let check = hummel_xi.as_ref().unwrap_or(&xi);
        // Ranges belong to slots: each bird's ξ against its slot's (the one it left, during an
        // exchange).
        let excess = if reorganised {
            let mut by_slot = vec![0.0; n];
            for (b, &s) in plan.slots_at(t).iter().enumerate() {
                // A bird still flying in is not in its slot: its ξ is not the slot's.
                by_slot[s] = if plan.joining(b, t) {
                    check[b].clamp(feasible.min[s], feasible.max[s])
                } else {
                    check[b]
                };
            }
            feasible.excess(&by_slot)
        } else {
            feasible.excess(check)
        };
        if excess > 1e-12 {
            frames_outside_range += 1;
        }
        max_frame_excess = max_frame_excess.max(excess);
        fr.e = Some(e);
        fr.xi = Some(xi);
        frames.push(fr);
        progress.advance(1);
    }
    progress.finish();

    let mut anim = Animation::new(opts.seed, opts.fps, opts.wingspan_m, n);
    anim.flight = (!opts.flight.is_empty()).then_some(opts.flight);
    anim.savings_model = Some(opts.aero.record());
    anim.stages.push(Stage {
        name: "steady".into(),
        start: 0,
        end: opts.frames,
    });
    anim.looped = opts.looped;
    anim.key_shapes = keys
        .iter()
        .zip(&key_frames)
        .zip(&key_times)
        .filter(|((_, &frame), _)| frame < opts.frames)
        .map(|((k, &frame), &t)| KeyShapeRecord {
            frame,
            // Each bird with the slot it flies in at this key.
            birds: plan
                .slots_at(t)
                .iter()
                .map(|&s| KeyBird {
                    x: k.x[s],
                    y: k.y[s],
                    xi: k.xi[s],
                    slot: reorganised.then_some(s),
                })
                .collect(),
        })
        .collect();
    anim.events = plan.events(0.0);
    anim.frames = frames;
    anim.xi_ranges = Some(
        feasible
            .min
            .iter()
            .zip(&feasible.max)
            .map(|(&a, &b)| [a, b])
            .collect(),
    );
    let report = SteadyReport {
        correspondence: corr.movie.clone(),
        leader: corr.leader,
        dropped: corr.dropped.clone(),
        mean_gap,
        x,
        total,
        ranges,
        feasible,
        first_key_from,
        key_frames,
        keys: key_stats,
        footage_spacing: footage,
        depth_scale,
        spacing_band,
        lateral_drift: drift,
        frames_outside_range,
        max_frame_excess,
    };
    Ok((anim, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_frames_are_spread_and_end_at_last_frame() {
        let o = SteadyOptions {
            frames: 301,
            fps: 30.0,
            keys: KeyOptions {
                key_every_s: 3.0,
                ..KeyOptions::default()
            },
            ..SteadyOptions::default()
        };
        assert_eq!(o.key_frames(), vec![0, 100, 200, 300]);
        let o = SteadyOptions {
            frames: 1,
            ..SteadyOptions::default()
        };
        assert_eq!(o.key_frames(), vec![0]);
        let o = SteadyOptions {
            frames: 5,
            keys: KeyOptions {
                key_every_s: 0.001,
                ..KeyOptions::default()
            },
            ..SteadyOptions::default()
        };
        assert_eq!(o.key_frames(), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn options_nest_and_round_trip_through_json() {
        let o: SteadyOptions = serde_json::from_str(
            r#"{"birds": 12, "keys": {"epsilon": 0.2}, "lateral": {"drift": 0.05}, "loop": true}"#,
        )
        .unwrap();
        assert_eq!(o.birds, 12);
        assert_eq!(o.keys.epsilon, 0.2);
        assert_eq!(
            o.keys.c1,
            KeyOptions::default().c1,
            "unset fields keep defaults"
        );
        assert_eq!(o.lateral.drift, Some(0.05));
        assert!(o.looped);
        let back: SteadyOptions =
            serde_json::from_str(&serde_json::to_string(&o).unwrap()).unwrap();
        assert_eq!(back, o);
        // An option is defined once: the old flat names are unknown fields.
        assert!(serde_json::from_str::<SteadyOptions>(r#"{"epsilon": 0.2}"#).is_err());
        assert!(serde_json::from_str::<SteadyOptions>(r#"{"keys": {"min_gap": 0.2}}"#).is_err());
        let bad = SteadyOptions {
            initial: InitialOptions {
                min_gap: 1.5,
                ..InitialOptions::default()
            },
            ..SteadyOptions::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("steady.initial.min_gap"));
        let bad = SteadyOptions {
            lateral: LateralOptions {
                drift: Some(-1.0),
                ..LateralOptions::default()
            },
            ..SteadyOptions::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("steady.lateral.drift"));
        let bad = SteadyOptions {
            heights: HeightOptions {
                neighbour: 1.0,
                ..HeightOptions::default()
            },
            ..SteadyOptions::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("steady.heights.neighbour"));
    }

    #[test]
    fn validation_names_the_flag() {
        let bad = [
            SteadyOptions {
                birds: 0,
                ..SteadyOptions::default()
            },
            SteadyOptions {
                frames: 0,
                ..SteadyOptions::default()
            },
            SteadyOptions {
                keys: KeyOptions {
                    epsilon: 0.9,
                    ..KeyOptions::default()
                },
                ..SteadyOptions::default()
            },
            SteadyOptions {
                keys: KeyOptions {
                    c1: 1.2,
                    ..KeyOptions::default()
                },
                ..SteadyOptions::default()
            },
            SteadyOptions {
                keys: KeyOptions {
                    c2: 0.9,
                    ..KeyOptions::default()
                },
                ..SteadyOptions::default()
            },
        ];
        let flags = [
            "steady.birds",
            "steady.frames",
            "steady.keys.epsilon",
            "steady.keys.c1",
            "steady.keys.c2",
        ];
        for (o, f) in bad.iter().zip(flags) {
            let e = o.validate().unwrap_err().to_string();
            assert!(e.starts_with(f), "{e}");
            assert_eq!(e.lines().count(), 1);
        }
        assert!(SteadyOptions::default().validate().is_ok());
    }
}
