//! §6 flock initiation: birds take off from random positions (or a start file) and, each
//! following its own perception, drives and actions, converge into the first key shape of a
//! steady-flight animation; the result is that animation with an `initiation` stage in front.
//!
//! Takes a [`crate::Animation`] (SPEC §4.4) whose `key_shapes[0]` (formation frame, wingspans) is
//! the target and whose frames are the steady flight (world frame, wingspans, wingspans per
//! second, headings radians clockwise from +y). Gives the combined animation: frames `0..k` of
//! initiation, then the steady frames translated in space and time so that position, heading and
//! speed continue without a jump. One simulation step is one animation frame (1/fps s).
//!
//! - [`perception`]: visual field, Hidden Point Removal or exact disc occlusion, reference bird.
//! - [`hull`]: the robust orientation predicate and convex hull HPR needs.
//! - [`target`]: the target shape as a tree of slots (leader, left and right arms).
//! - [`sim`]: drives and actions (eqs. 5–6, separation, collision avoidance), the step loop.
//!
//! The rules as implemented and every choice the paper leaves open: `docs/initiation.md`.

pub mod hull;
pub mod perception;
pub mod sim;
pub mod target;

use std::f64::consts::PI;
use std::path::Path;

use glam::DVec2;
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::animation::{Animation, Frame, Stage};
use crate::error::{Error, Result};
use crate::progress::Progress;

pub use perception::{PerceptionMode, PerceptionParams, HPR_GAMMA_DEFAULT};
pub use sim::{Simulation, StepParams};
pub use target::{Side, TargetShape};

/// Margin between the largest bearing of a reference slot and the edge of the visual field when
/// the field is widened for the target shape, radians (15°).
pub const FIELD_MARGIN: f64 = 15.0 * PI / 180.0;

/// Draws of a start heading and speed per bird before the one with the largest predicted miss
/// distance is kept ([`random_start`]).
pub const START_DRAWS: usize = 100;

/// Largest accepted step limit (9¼ hours of flight at 30 fps).
pub const MAX_STEPS_LIMIT: usize = 1_000_000;

/// Largest accepted width or depth of the random start region, wingspans.
pub const MAX_START_EXTENT: f64 = 1e6;

/// Parameters of the initiation (units per second; converted to per-step values at the file's fps).
#[derive(Debug, Clone, PartialEq)]
pub struct InitiateOptions {
    /// Perception model: visual field, reference cone, occlusion mode.
    pub perception: PerceptionParams,
    /// Widen the visual field per eye, where the target shape needs it, to the largest bearing
    /// at which a bird in its slot sees its reference bird plus [`FIELD_MARGIN`] (the paper:
    /// "90° per eye, though it may be wider for real birds"); never narrows it.
    pub widen_field: bool,
    /// α of eq. (6), dimensionless (paper: 0.2).
    pub alpha: f64,
    /// |K| of eq. (5), per √wingspan (paper: 0.06).
    pub k: f64,
    /// Maximum turn rate, radians per second.
    pub max_turn_rate: f64,
    /// Maximum change of speed, wingspans per second squared.
    pub max_accel: f64,
    /// Minimum flight speed, as a fraction of the cruise speed.
    pub min_speed: f64,
    /// Maximum flight speed, as a fraction of the cruise speed.
    pub max_speed: f64,
    /// Separation drive threshold, wingspans (paper: 10).
    pub separation_distance: f64,
    /// Look-ahead of a bird near or ahead of its target, wingspans.
    pub lookahead: f64,
    /// Collision avoidance: predicted closest approach that triggers evasion, wingspans.
    pub avoid_distance: f64,
    /// Collision avoidance: range within which flockmates are checked, wingspans.
    pub avoid_range: f64,
    /// Collision avoidance: prediction horizon, seconds.
    pub avoid_horizon: f64,
    /// Speed of a bird that sees no flockmate, as a fraction of the cruise speed.
    pub lost_speed_factor: f64,
    /// Distance by which a bird must be ahead of the leader to replace it, wingspans.
    pub leader_hysteresis: f64,
    /// Keep the current reference bird while it is visible and acceptable.
    pub sticky_reference: bool,
    /// A kept reference bird hidden (occluded or out of the field) for at most this long is kept
    /// all the same, seconds (0: only while visible; `None`: 0.5 s with HPR, 2 s with exact
    /// occlusion, whose discs hide birds for longer).
    pub reference_memory: Option<f64>,
    /// Upper bound of the distance divisor max(r, 1) of eq. (6), wingspans.
    pub turn_distance_cap: f64,
    /// Eq. (5)'s √|r − v_j| is replaced by its chord within this distance of the fixed point,
    /// wingspans.
    pub linear_zone: f64,
    /// Convergence: distance of every bird from its slot, wingspans.
    pub tolerance: f64,
    /// Convergence: heading difference from the cruise heading, radians.
    pub heading_tolerance: f64,
    /// Convergence: speed difference from the cruise speed, fraction of it.
    pub speed_tolerance: f64,
    /// Convergence: how long the flock must stay in formation, seconds. The hand-over blend
    /// to the exact steady-flight state uses the same window.
    pub hold: f64,
    /// Step limit; no convergence within it is [`Error::NotConverged`].
    pub max_steps: usize,
    /// Where and how the birds start.
    pub start: Start,
    /// The `--seed` recorded in the output file.
    pub seed: u64,
}

impl Default for InitiateOptions {
    fn default() -> Self {
        InitiateOptions {
            perception: PerceptionParams::default(),
            widen_field: true,
            alpha: 0.2,
            k: 0.06,
            max_turn_rate: PI / 2.0,
            max_accel: 4.0,
            min_speed: 0.5,
            max_speed: 1.6,
            separation_distance: 10.0,
            lookahead: 4.0,
            avoid_distance: 0.6,
            avoid_range: 6.0,
            avoid_horizon: 2.0,
            lost_speed_factor: 0.9,
            leader_hysteresis: 1.0,
            sticky_reference: true,
            reference_memory: None,
            turn_distance_cap: 5.0,
            linear_zone: 0.25,
            tolerance: 0.1,
            heading_tolerance: 2f64.to_radians(),
            speed_tolerance: 0.02,
            hold: 1.0,
            max_steps: 9000,
            start: Start::Random(StartRegion::default()),
            seed: 0,
        }
    }
}

/// Where the birds start.
#[derive(Debug, Clone, PartialEq)]
pub enum Start {
    /// Random positions, headings and speeds in a region.
    Random(StartRegion),
    /// Given positions (and optionally headings and speeds).
    Given(StartState),
}

/// A random take-off: positions uniform in a rectangle centred on the origin, its width across
/// and its depth along the cruise heading, at least `min_spacing` apart; headings uniform within
/// `heading_spread` of the cruise heading; speeds uniform between the minimum and the cruise speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartRegion {
    /// Width across the cruise heading, wingspans (`None`: 30, or 6√N for large flocks).
    pub width: Option<f64>,
    /// Depth along the cruise heading, wingspans (`None`: as the width).
    pub depth: Option<f64>,
    /// Half-width of the heading distribution around the cruise heading, radians (π: any heading).
    pub heading_spread: f64,
    /// Minimum distance between two birds at the start, wingspans.
    pub min_spacing: f64,
}

impl Default for StartRegion {
    fn default() -> Self {
        StartRegion {
            width: None,
            depth: None,
            heading_spread: PI,
            min_spacing: 1.5,
        }
    }
}

impl StartRegion {
    /// Width and depth for `n` birds, wingspans.
    pub fn size(&self, n: usize) -> (f64, f64) {
        let auto = (6.0 * (n as f64).sqrt()).max(30.0);
        let w = self.width.unwrap_or(auto);
        (w, self.depth.unwrap_or(w))
    }
}

/// A start file: world-frame positions (wingspans), optional headings (radians clockwise from +y)
/// and speeds (wingspans per second), one entry per bird.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartState {
    /// East, wingspans.
    pub x: Vec<f64>,
    /// North, wingspans.
    pub y: Vec<f64>,
    /// Headings, radians clockwise from +y (default: the cruise heading).
    #[serde(default)]
    pub heading: Option<Vec<f64>>,
    /// Speeds, wingspans per second (default: the minimum speed).
    #[serde(default)]
    pub speed: Option<Vec<f64>>,
}

impl StartState {
    /// Reads and checks a start file for `birds` birds.
    pub fn read(path: &Path, birds: usize) -> Result<StartState> {
        let s: StartState = crate::io::read_json(path)?;
        let mut arrays: Vec<(&str, &Vec<f64>)> = vec![("x", &s.x), ("y", &s.y)];
        if let Some(h) = &s.heading {
            arrays.push(("heading", h));
        }
        if let Some(v) = &s.speed {
            arrays.push(("speed", v));
        }
        for (name, a) in arrays {
            if a.len() != birds {
                return Err(Error::format(
                    path,
                    format!(
                        "{name}: {} values, but the steady flight has {birds} birds",
                        a.len()
                    ),
                ));
            }
            if let Some(i) = a.iter().position(|v| !v.is_finite()) {
                return Err(Error::format(
                    path,
                    format!("{name}[{i}]: not a finite number"),
                ));
            }
        }
        if let Some(v) = &s.speed {
            if let Some(i) = v.iter().position(|v| *v <= 0.0) {
                return Err(Error::format(path, format!("speed[{i}]: must be positive")));
            }
        }
        for i in 0..birds {
            for j in 0..i {
                if s.x[i] == s.x[j] && s.y[i] == s.y[j] {
                    return Err(Error::format(
                        path,
                        format!("birds {j} and {i} start at the same position"),
                    ));
                }
            }
        }
        Ok(s)
    }
}

/// What happened during an initiation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InitiateStats {
    /// Number of birds.
    pub birds: usize,
    /// Simulation steps until convergence (or the step limit).
    pub steps: usize,
    /// Whether the flock converged.
    pub converged: bool,
    /// Smallest distance between two birds over the whole initiation (start included), wingspans.
    pub min_distance: f64,
    /// Largest heading change of a bird in one step, radians per second.
    pub max_turn_rate: f64,
    /// How often the leader changed.
    pub leader_changes: usize,
    /// Birds within the tolerance of a slot of their own at the end.
    pub birds_in_slot: usize,
    /// Visual field per eye used, radians (the option's, or wider if the target shape needs it).
    pub field_per_eye: f64,
}

/// The simulated initiation before the hand-over: per-step states in simulation bird order.
#[derive(Debug, Clone)]
pub struct InitiationRun {
    /// Positions of every step (index 0 = start), wingspans.
    pub pos: Vec<Vec<DVec2>>,
    /// Headings of every step, radians.
    pub heading: Vec<Vec<f64>>,
    /// Speeds of every step, wingspans per step.
    pub speed: Vec<Vec<f64>>,
    /// Slot of every bird at the end (meaningful when converged: a permutation).
    pub slot: Vec<Option<usize>>,
    /// Statistics.
    pub stats: InitiateStats,
}

impl InitiateOptions {
    /// Checks every parameter (names are the command-line flags).
    pub fn validate(&self) -> Result<()> {
        let pos = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!("must be a positive number, got {v}"),
                ))
            }
        };
        let fov = self.perception.fov_per_eye;
        if !(fov.is_finite() && fov > 0.0 && fov <= PI) {
            return Err(Error::parameter(
                "--fov",
                format!(
                    "visual field per eye must be in (0, 180] degrees, got {:.3}",
                    fov.to_degrees()
                ),
            ));
        }
        let cone = self.perception.reference_cone;
        if !(cone.is_finite() && cone > 0.0 && cone <= PI) {
            return Err(Error::parameter(
                "--reference-cone",
                format!("must be in (0, 180] degrees, got {:.3}", cone.to_degrees()),
            ));
        }
        if let PerceptionMode::Hpr { gamma } = self.perception.mode {
            if !(gamma.is_finite() && (0.0..=8.0).contains(&gamma)) {
                return Err(Error::parameter(
                    "--hpr-gamma",
                    format!("must be in [0, 8], got {gamma}"),
                ));
            }
        }
        pos("bird radius", self.perception.bird_radius)?;
        if !(self.alpha.is_finite() && self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(Error::parameter(
                "--alpha",
                format!("must be in (0, 1], got {}", self.alpha),
            ));
        }
        pos("--k", self.k)?;
        pos("--max-turn-rate", self.max_turn_rate)?;
        pos("--max-accel", self.max_accel)?;
        pos("--min-speed", self.min_speed)?;
        pos("--max-speed", self.max_speed)?;
        if self.min_speed >= 1.0 || self.max_speed <= 1.0 {
            return Err(Error::parameter(
                "--min-speed/--max-speed",
                format!(
                    "the cruise speed must lie between them (min < 1 < max), got {} and {}",
                    self.min_speed, self.max_speed
                ),
            ));
        }
        pos("--separation", self.separation_distance)?;
        pos("--lookahead", self.lookahead)?;
        pos("--avoid-distance", self.avoid_distance)?;
        pos("--avoid-range", self.avoid_range)?;
        pos("--avoid-horizon", self.avoid_horizon)?;
        pos("lost speed factor", self.lost_speed_factor)?;
        pos("--turn-distance-cap", self.turn_distance_cap)?;
        pos("--linear-zone", self.linear_zone)?;
        let memory = self.reference_memory();
        if !(memory.is_finite() && (0.0..=60.0).contains(&memory)) {
            return Err(Error::parameter(
                "reference memory",
                format!("must be in [0, 60] seconds, got {memory}"),
            ));
        }
        if !(self.leader_hysteresis.is_finite() && self.leader_hysteresis >= 0.0) {
            return Err(Error::parameter(
                "leader hysteresis",
                "must be a non-negative number",
            ));
        }
        pos("--tolerance", self.tolerance)?;
        if self.tolerance < 1e-6 {
            return Err(Error::parameter(
                "--tolerance",
                format!(
                    "{:e} wingspans cannot be met in floating point; use at least 1e-6",
                    self.tolerance
                ),
            ));
        }
        pos("--heading-tolerance", self.heading_tolerance)?;
        pos("--speed-tolerance", self.speed_tolerance)?;
        if !(self.hold.is_finite() && self.hold >= 0.0) {
            return Err(Error::parameter(
                "--hold",
                format!(
                    "must be a non-negative number of seconds, got {}",
                    self.hold
                ),
            ));
        }
        if self.max_steps == 0 {
            return Err(Error::parameter(
                "--max-steps",
                "must be at least 1 (the initiation needs at least one step)",
            ));
        }
        if self.max_steps > MAX_STEPS_LIMIT {
            return Err(Error::parameter(
                "--max-steps",
                format!(
                    "at most {MAX_STEPS_LIMIT} (every step is kept in memory for the output), got {}",
                    self.max_steps
                ),
            ));
        }
        if let Start::Random(r) = &self.start {
            for (name, v) in [("--start-width", r.width), ("--start-depth", r.depth)] {
                if let Some(v) = v {
                    pos(name, v)?;
                    if v > MAX_START_EXTENT {
                        return Err(Error::parameter(
                            name,
                            format!("at most {MAX_START_EXTENT} wingspans, got {v:e}"),
                        ));
                    }
                }
            }
            if !(r.heading_spread.is_finite() && (0.0..=PI).contains(&r.heading_spread)) {
                return Err(Error::parameter(
                    "--heading-spread",
                    "must be in [0, 180] degrees",
                ));
            }
            if !(r.min_spacing.is_finite() && r.min_spacing >= 0.0) {
                return Err(Error::parameter(
                    "--min-spacing",
                    "must be a non-negative number of wingspans",
                ));
            }
        }
        Ok(())
    }

    /// The reference memory in seconds (the option, or the default of the perception mode).
    pub fn reference_memory(&self) -> f64 {
        self.reference_memory.unwrap_or(match self.perception.mode {
            PerceptionMode::Hpr { .. } => 0.5,
            PerceptionMode::Exact => 2.0,
        })
    }

    /// Per-step parameters at `fps` for a cruise heading (radians) and speed (wingspans per second).
    pub fn step_params(&self, fps: f64, cruise_heading: f64, cruise_speed: f64) -> StepParams {
        let vc = cruise_speed / fps;
        StepParams {
            perception: self.perception,
            alpha: self.alpha,
            k: self.k,
            max_turn: self.max_turn_rate / fps,
            max_dv: self.max_accel / fps / fps,
            min_speed: self.min_speed * vc,
            max_speed: self.max_speed * vc,
            cruise_heading,
            cruise_speed: vc,
            separation_distance: self.separation_distance,
            lookahead: self.lookahead,
            avoid_distance: self.avoid_distance,
            avoid_range: self.avoid_range,
            avoid_horizon: self.avoid_horizon * fps,
            lost_speed_factor: self.lost_speed_factor,
            leader_hysteresis: self.leader_hysteresis,
            sticky_reference: self.sticky_reference,
            reference_memory: (self.reference_memory() * fps).round() as u32,
            turn_distance_cap: self.turn_distance_cap,
            linear_zone: self.linear_zone,
        }
    }
}

/// Checks that `steady` can be initiated into: at least one key shape, a first frame, a positive
/// cruise speed. `origin` names the file in messages.
pub fn check_steady(steady: &Animation, origin: &Path) -> Result<()> {
    let Some(ks) = steady.key_shapes.first() else {
        return Err(Error::format(
            origin,
            "key_shapes: none; initiation needs the first key shape as its target (give a file written by `formation steady`)",
        ));
    };
    if ks.birds.len() != steady.birds {
        return Err(Error::format(
            origin,
            format!(
                "key_shapes[0].birds: {} birds, expected {}",
                ks.birds.len(),
                steady.birds
            ),
        ));
    }
    if steady.stage("initiation").is_some() {
        return Err(Error::format(
            origin,
            "stages: already has an initiation stage; give the steady-flight file instead",
        ));
    }
    let Some(f0) = steady.frames.first() else {
        return Err(Error::format(origin, "frames: no frames"));
    };
    let n = steady.birds;
    if f0.x.len() != n || f0.speed.len() != n || f0.heading.len() != n {
        return Err(Error::format(
            origin,
            "frames[0]: one value per bird expected",
        ));
    }
    let pts: Vec<DVec2> = ks.birds.iter().map(|b| DVec2::new(b.x, b.y)).collect();
    let t =
        TargetShape::new(&pts).map_err(|e| Error::format(origin, format!("key_shapes[0]: {e}")))?;
    let vc = f0.speed[t.leader];
    if !(vc.is_finite() && vc > 0.0) {
        return Err(Error::format(
            origin,
            format!(
                "frames[0].speed[{}]: the leader's cruise speed must be positive, got {vc}",
                t.leader
            ),
        ));
    }
    Ok(())
}

/// Random start positions, headings and speeds (wingspans, radians, wingspans per step):
/// positions uniform in the region at least `min_spacing` apart; headings uniform within the
/// spread and speeds between the minimum and the cruise speed, redrawn while two birds would,
/// flying straight, come closer than the avoidance distance within the time a quarter turn takes
/// (no take-off on a collision course that no turn could avoid).
pub fn random_start(
    n: usize,
    region: &StartRegion,
    params: &StepParams,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    let (w, d) = region.size(n);
    let dc = perception::direction(params.cruise_heading);
    let rc = perception::right_of(params.cruise_heading);
    let mut pos: Vec<DVec2> = Vec::with_capacity(n);
    let attempts = 2000 * n.max(1);
    let mut tries = 0;
    // Rejection sampling on a grid of cells of the minimum spacing keeps this O(n).
    let cell = region.min_spacing.max(1e-9);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> =
        std::collections::HashMap::new();
    let key = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    while pos.len() < n {
        tries += 1;
        if tries > attempts {
            return Err(Error::parameter(
                "--start-width/--start-depth",
                format!(
                    "cannot place {n} birds {} wingspans apart in a {w:.1} × {d:.1} wingspan region; make it larger",
                    region.min_spacing
                ),
            ));
        }
        let a: f64 = rng.random_range(-0.5..0.5);
        let b: f64 = rng.random_range(-0.5..0.5);
        let p = rc * (a * w) + dc * (b * d);
        let (kx, ky) = key(p);
        let clash = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                grid.get(&(kx.saturating_add(dx), ky.saturating_add(dy)))
                    .is_some_and(|v| {
                        v.iter()
                            .any(|&j| (pos[j] - p).length() < region.min_spacing)
                    })
            })
        });
        if clash {
            continue;
        }
        grid.entry((kx, ky)).or_default().push(pos.len());
        pos.push(p);
    }
    // Headings and speeds: no two birds start on a course that brings them closer than the
    // avoidance distance before they could turn a quarter circle away (straight-line
    // prediction); a draw that does is redrawn, up to START_DRAWS times (then the safest is kept).
    let horizon = std::f64::consts::FRAC_PI_2 / params.max_turn;
    let mut heading: Vec<f64> = Vec::with_capacity(n);
    let mut speed: Vec<f64> = Vec::with_capacity(n);
    for i in 0..n {
        let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
        for _ in 0..START_DRAWS {
            let h = if region.heading_spread > 0.0 {
                rng.random_range(-region.heading_spread..=region.heading_spread)
            } else {
                0.0
            };
            let h = sim::wrap_angle(params.cruise_heading + h);
            let v = rng.random_range(params.min_speed..=params.cruise_speed);
            let vel = perception::direction(h) * v;
            let miss = (0..i)
                .map(|j| {
                    let dp = pos[j] - pos[i];
                    let dv = perception::direction(heading[j]) * speed[j] - vel;
                    let vv = dv.length_squared();
                    let tau = if vv > 0.0 {
                        (-dp.dot(dv) / vv).clamp(0.0, horizon)
                    } else {
                        0.0
                    };
                    (dp + dv * tau).length()
                })
                .fold(f64::INFINITY, f64::min);
            if miss > best.0 {
                best = (miss, h, v);
            }
            if miss >= params.avoid_distance {
                break;
            }
        }
        heading.push(best.1);
        speed.push(best.2);
    }
    Ok((pos, heading, speed))
}

/// The simulation at its first step: parameters at `fps` for the cruise heading (radians) and
/// speed (wingspans per second), the visual field widened for `target` if asked, and the start
/// positions, headings and speeds (random ones drawn from `rng`).
pub fn start_simulation(
    target: &TargetShape,
    fps: f64,
    cruise_heading: f64,
    cruise_speed: f64,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
) -> Result<Simulation> {
    opts.validate()?;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::parameter("fps", "must be a positive number"));
    }
    if !(cruise_speed.is_finite() && cruise_speed > 0.0 && cruise_heading.is_finite()) {
        return Err(Error::parameter(
            "cruise speed",
            "the leader's speed must be a positive number",
        ));
    }
    let n = target.len();
    let mut params = opts.step_params(fps, cruise_heading, cruise_speed);
    if opts.widen_field {
        let field = &mut params.perception.fov_per_eye;
        *field = field.max(target.required_field(FIELD_MARGIN));
    }
    let (pos, heading, speed) = match &opts.start {
        Start::Random(region) => random_start(n, region, &params, rng)?,
        Start::Given(s) => {
            if s.x.len() != n || s.y.len() != n {
                return Err(Error::parameter(
                    "--start",
                    format!("{} start positions for {n} birds", s.x.len()),
                ));
            }
            let pos =
                s.x.iter()
                    .zip(&s.y)
                    .map(|(&x, &y)| DVec2::new(x, y))
                    .collect();
            let heading = s.heading.clone().unwrap_or_else(|| vec![cruise_heading; n]);
            let speed = match &s.speed {
                Some(v) => v
                    .iter()
                    .map(|v| (v / fps).clamp(params.min_speed, params.max_speed))
                    .collect(),
                None => vec![params.min_speed; n],
            };
            (pos, heading, speed)
        }
    };
    Ok(Simulation::new(target.clone(), params, pos, heading, speed))
}

/// Runs the simulation until convergence or the step limit, without the hand-over. The flock's
/// target is `target`; cruise heading (radians) and speed (wingspans per second) are those of the
/// steady flight's leader; `fps` sets the step length.
pub fn simulate(
    target: &TargetShape,
    fps: f64,
    cruise_heading: f64,
    cruise_speed: f64,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<InitiationRun> {
    let mut sim = start_simulation(target, fps, cruise_heading, cruise_speed, opts, rng)?;
    let n = target.len();
    let params = sim.params;
    let hold_steps = (opts.hold * fps).round() as usize;
    let mut run = InitiationRun {
        pos: vec![sim.flock.pos.clone()],
        heading: vec![sim.flock.heading.clone()],
        speed: vec![sim.flock.speed.clone()],
        slot: Vec::new(),
        stats: InitiateStats {
            birds: n,
            steps: 0,
            converged: false,
            min_distance: sim.min_distance(),
            max_turn_rate: 0.0,
            leader_changes: 0,
            birds_in_slot: 0,
            field_per_eye: params.perception.fov_per_eye,
        },
    };
    progress.start("initiate", opts.max_steps as u64);
    let mut in_formation = 0usize;
    let mut converged = false;
    while sim.steps < opts.max_steps {
        sim.step();
        run.pos.push(sim.flock.pos.clone());
        run.heading.push(sim.flock.heading.clone());
        run.speed.push(sim.flock.speed.clone());
        run.stats.min_distance = run.stats.min_distance.min(sim.min_distance());
        if sim.in_formation(opts.tolerance, opts.heading_tolerance, opts.speed_tolerance) {
            in_formation += 1;
        } else {
            in_formation = 0;
        }
        if sim.steps % 64 == 0 {
            progress.advance(64);
        }
        if in_formation > hold_steps {
            converged = true;
            break;
        }
    }
    progress.finish();
    run.slot = sim.flock.slot.clone();
    run.stats.steps = sim.steps;
    run.stats.converged = converged;
    run.stats.max_turn_rate = sim.max_heading_change * fps;
    run.stats.leader_changes = sim.leader_changes;
    run.stats.birds_in_slot = sim.birds_in_slot(opts.tolerance);
    Ok(run)
}

/// The target shape and cruise heading/speed (radians, wingspans per second) of a steady flight.
pub fn steady_target(steady: &Animation) -> Result<(TargetShape, f64, f64)> {
    let ks = steady.key_shapes.first().ok_or_else(|| {
        Error::parameter(
            "key_shapes",
            "the steady flight has no key shape; initiation needs the first one as its target",
        )
    })?;
    let pts: Vec<DVec2> = ks.birds.iter().map(|b| DVec2::new(b.x, b.y)).collect();
    let target = TargetShape::new(&pts)?;
    let f0 = steady
        .frames
        .first()
        .ok_or_else(|| Error::parameter("frames", "the steady flight has no frames"))?;
    let heading = f0.heading.get(target.leader).copied().unwrap_or(0.0);
    let speed = f0.speed.get(target.leader).copied().unwrap_or(0.0);
    Ok((target, heading, speed))
}

/// §6 initiation into the first key shape of `steady`: the combined animation (an `initiation`
/// stage, then the steady frames translated so the hand-over has no jump) and its statistics.
/// A flock that does not converge within `opts.max_steps` is [`Error::NotConverged`].
pub fn initiate(
    steady: &Animation,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<(Animation, InitiateStats)> {
    check_steady(steady, Path::new("steady flight"))?;
    check_size(steady.birds, steady.frames.len(), opts.max_steps)?;
    let (target, cruise_heading, cruise_speed) = steady_target(steady)?;
    let run = simulate(
        &target,
        steady.fps,
        cruise_heading,
        cruise_speed,
        opts,
        rng,
        progress,
    )?;
    if !run.stats.converged {
        return Err(Error::NotConverged(format!(
            "the flock did not converge into the key shape within {} steps ({} of {} birds within {} wingspans of their slots); raise --max-steps, or start from a smaller region",
            opts.max_steps, run.stats.birds_in_slot, run.stats.birds, opts.tolerance
        )));
    }
    hand_over(steady, &run, opts)
}

/// Refuses an initiation that could hold more than [`crate::limits::MAX_BIRD_FRAMES`]
/// bird-frames in memory: `birds` × (`steady_frames` + `max_steps`), every step being kept for the
/// output (issue 8: refused up front instead of exhausting memory).
pub fn check_size(birds: usize, steady_frames: usize, max_steps: usize) -> Result<()> {
    let frames = steady_frames.saturating_add(max_steps);
    match birds.checked_mul(frames) {
        Some(p) if p <= crate::limits::MAX_BIRD_FRAMES => Ok(()),
        _ => {
            let plus = if steady_frames > 0 {
                format!(" + {steady_frames} steady frames")
            } else {
                String::new()
            };
            Err(Error::parameter(
                "--max-steps",
                format!(
                    "{birds} birds × ({max_steps} steps{plus}) could be more than {} bird-frames in memory; lower --max-steps to at most {}",
                    crate::limits::MAX_BIRD_FRAMES,
                    (crate::limits::MAX_BIRD_FRAMES / birds.max(1)).saturating_sub(steady_frames)
                ),
            ))
        }
    }
}

/// Joins a converged run to the steady flight: birds are renumbered by their final slot, the last
/// `hold` seconds of the initiation are blended (smoothstep) into the backward extrapolation of the
/// steady flight's first frame, and the steady frames are translated and delayed to follow on.
pub fn hand_over(
    steady: &Animation,
    run: &InitiationRun,
    opts: &InitiateOptions,
) -> Result<(Animation, InitiateStats)> {
    let n = steady.birds;
    let fps = steady.fps;
    let f0 = steady
        .frames
        .first()
        .ok_or_else(|| Error::Internal("steady flight without frames".into()))?;
    // Bird b of the simulation becomes animation bird perm[b] (its slot = the key shape's bird).
    let mut perm = vec![usize::MAX; n];
    let mut used = vec![false; n];
    for (b, s) in run.slot.iter().enumerate() {
        match s {
            Some(s) if *s < n && !used[*s] => {
                perm[b] = *s;
                used[*s] = true;
            }
            _ => {
                return Err(Error::Internal(
                    "hand-over of a flock whose slots are not one-to-one".into(),
                ))
            }
        }
    }
    let last = run.pos.len() - 1;
    let step_of = |s: usize| perception::direction(f0.heading[s]) * (f0.speed[s] / fps);
    let s0 = |s: usize| DVec2::new(f0.x[s], f0.y[s]);
    // Translation of the steady flight: least squares over birds of the one-step continuation.
    let mut shift = DVec2::ZERO;
    for (b, &s) in perm.iter().enumerate() {
        shift += run.pos[last][b] + step_of(s) - s0(s);
    }
    shift /= n as f64;
    let window = ((opts.hold * fps).round() as usize).clamp(1, last.max(1));
    let mut frames: Vec<Frame> = Vec::with_capacity(run.pos.len() + steady.frames.len());
    let wing_rate: Option<Vec<f64>> = match (
        steady.frames.first().and_then(|f| f.wing_phase.as_ref()),
        steady.frames.get(1).and_then(|f| f.wing_phase.as_ref()),
    ) {
        (Some(a), Some(b)) => Some(
            a.iter()
                .zip(b)
                .map(|(a, b)| (b - a).rem_euclid(2.0 * PI))
                .collect(),
        ),
        _ => None,
    };
    for t in 0..=last {
        let mut fr = Frame {
            t: t as f64 / fps,
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            heading: vec![0.0; n],
            speed: vec![0.0; n],
            ..Default::default()
        };
        // Blend weight: 0 before the window, smoothstep up to 1 at the last initiation frame.
        let w = if t + window <= last {
            0.0
        } else {
            let u = (t + window - last) as f64 / window as f64;
            u * u * (3.0 - 2.0 * u)
        };
        for (b, &s) in perm.iter().enumerate() {
            let back = (last + 1 - t) as f64;
            let ideal = s0(s) + shift - step_of(s) * back;
            let p = run.pos[t][b].lerp(ideal, w);
            let h = run.heading[t][b];
            let h = sim::wrap_angle(h + w * sim::wrap_angle(f0.heading[s] - h));
            let v = run.speed[t][b] * fps * (1.0 - w) + f0.speed[s] * w;
            fr.x[s] = p.x;
            fr.y[s] = p.y;
            fr.z[s] = f0.z[s];
            fr.heading[s] = h;
            fr.speed[s] = v;
        }
        if let (Some(rate), Some(ph0)) = (&wing_rate, f0.wing_phase.as_ref()) {
            let back = (last + 1 - t) as f64;
            fr.wing_phase = Some(
                (0..n)
                    .map(|s| (ph0[s] - rate[s] * back).rem_euclid(2.0 * PI))
                    .collect(),
            );
        }
        frames.push(fr);
    }
    let offset = frames.len();
    let t_start = offset as f64 / fps;
    let t0 = f0.t;
    for f in &steady.frames {
        let mut g = f.clone();
        g.t = t_start + (f.t - t0);
        for s in 0..n {
            if let (Some(x), Some(y)) = (g.x.get_mut(s), g.y.get_mut(s)) {
                *x += shift.x;
                *y += shift.y;
            }
        }
        frames.push(g);
    }
    let mut out = Animation::new(opts.seed, fps, steady.wingspan_m, n);
    out.species = steady.species.clone();
    out.stages.push(Stage {
        name: "initiation".into(),
        start: 0,
        end: offset,
    });
    if steady.stages.is_empty() {
        out.stages.push(Stage {
            name: "steady".into(),
            start: offset,
            end: offset + steady.frames.len(),
        });
    }
    for st in &steady.stages {
        out.stages.push(Stage {
            name: st.name.clone(),
            start: st.start + offset,
            end: st.end + offset,
        });
    }
    out.key_shapes = steady
        .key_shapes
        .iter()
        .map(|k| {
            let mut k = k.clone();
            k.frame += offset;
            k
        })
        .collect();
    out.frames = frames;
    // Closest approach in the written initiation frames (after the blend).
    let mut stats = run.stats.clone();
    stats.min_distance = out.frames[..offset]
        .iter()
        .map(|f| {
            let pts: Vec<DVec2> =
                f.x.iter()
                    .zip(&f.y)
                    .map(|(&x, &y)| DVec2::new(x, y))
                    .collect();
            sim::min_pair_distance(&pts)
        })
        .fold(f64::INFINITY, f64::min);
    Ok((out, stats))
}
