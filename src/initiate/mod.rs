//! §6 flock initiation, as a take-off: birds leave the ground (or start scattered in the air)
//! and, each following its own perception, drives and actions, converge into the first key shape
//! of a steady-flight animation while they climb to the cruise altitude; the result is that
//! animation with an `initiation` stage in front.
//!
//! Takes a [`crate::Animation`] (docs/formats.md §4.4) whose `key_shapes[0]` (formation frame, wingspans) is
//! the target and whose frames are the steady flight (world frame, wingspans, wingspans per
//! second, headings radians clockwise from +y). Gives the combined animation: frames `0..k` of
//! initiation, then the steady frames translated in space (to the cruise altitude) and time so
//! that position, heading, speed and bank continue without a jump.
//!
//! Behaviour is in seconds: the simulation runs with a fixed internal step (see [`sim`]) and the
//! output frames are samples of it, so the same seed gives the same take-off at any frame rate.
//!
//! - [`perception`]: visual field, Hidden Point Removal or exact disc occlusion, reference bird.
//! - [`hull`]: the robust orientation predicate and convex hull HPR needs.
//! - [`target`]: the target shape as a tree of slots (leader, left and right arms).
//! - [`sim`]: drives and actions (eqs. 5–6, separation, collision avoidance), flight dynamics.
//!
//! The rules as implemented and every choice the paper leaves open: `docs/initiation.md`.

pub mod hull;
pub mod perception;
pub mod sim;
pub mod target;

use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec2, DVec3};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::animation::{Animation, Frame, Stage};
use crate::error::{Error, Result};
use crate::progress::Progress;

pub use perception::{PerceptionMode, PerceptionParams, HPR_GAMMA_DEFAULT};
pub use sim::{Phase, Simulation, StepParams, Tolerances};
pub use target::{Side, TargetShape};

/// Margin between the largest bearing of a reference slot and the edge of the visual field when
/// the field is widened for the target shape, radians (15°).
pub const FIELD_MARGIN: f64 = 15.0 * PI / 180.0;

/// Draws of a start heading and speed per bird before the one with the largest predicted miss
/// distance is kept ([`random_start`]).
pub const START_DRAWS: usize = 100;

/// Largest accepted frame limit of the initiation.
pub const MAX_STEPS_LIMIT: usize = 1_000_000;

/// Largest accepted width or depth of the random start region, wingspans.
pub const MAX_START_EXTENT: f64 = 1e6;

/// Width over depth of the automatic take-off area (before [`GROUND_MAX_DEPTH`] makes it wider).
pub const GROUND_ASPECT: f64 = 3.0;

/// Largest depth of the automatic take-off area, wingspans: a deeper one leaves the birds at its
/// back (whose slots are near the apex of the V) more than 30 wingspans from every slot when the
/// last of them lifts off.
pub const GROUND_MAX_DEPTH: f64 = 22.0;

/// Smallest automatic width of the paper's airborne start region, wingspans.
pub const AIR_MIN_WIDTH: f64 = 20.0;

/// Automatic width of the airborne start region per square root of the flock's bird count,
/// wingspans (used when it exceeds [`AIR_MIN_WIDTH`]).
pub const AIR_WIDTH_PER_ROOT_BIRD: f64 = 4.5;

/// Automatic depth of the airborne start region: half its width, within these bounds,
/// wingspans. Shallow and wide like the V the birds fly into: a deeper region leaves the birds
/// at its back far from every slot (in a 30 × 30 region they began 24 wingspans from the
/// nearest one).
pub const AIR_DEPTH_RANGE: (f64, f64) = (10.0, 15.0);

/// Half-height of the band the airborne start scatters the birds in around the cruise altitude,
/// wingspans.
pub const AIR_HEIGHT_BAND: f64 = 1.5;

/// The airborne start's headings: no two birds predicted (flying straight) to come closer than
/// this within [`START_HORIZON`], wingspans (redrawn up to [`START_DRAWS`] times).
pub const START_MISS: f64 = 1.0;

/// The airborne start's heading draws look this far ahead, seconds.
pub const START_HORIZON: f64 = 1.5;

/// Gravity, metres per second squared.
pub const GRAVITY_M_S2: f64 = 9.81;

/// Parameters of the initiation. Every rule is in seconds (rates per second), independent of the
/// output frame rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitiateOptions {
    /// Perception model: visual field, reference cone, occlusion mode.
    pub perception: PerceptionParams,
    /// Widen the visual field per eye, where the target shape needs it, to the largest bearing
    /// at which a bird in its slot sees its reference bird plus [`FIELD_MARGIN`] (the paper:
    /// "90° per eye, though it may be wider for real birds"); never narrows it.
    pub widen_field: bool,
    /// Visual range: flockmates farther away are not perceived, wingspans.
    pub visual_range: f64,
    /// α of eq. (6), dimensionless (paper: 0.2).
    pub alpha: f64,
    /// |K| of eq. (5), per √wingspan (paper: 0.06).
    pub k: f64,
    /// Reaction time: a bird decides once per this many seconds (the paper's time step), seconds.
    pub reaction_time: f64,
    /// Internal integration steps per reaction time (dimensionless).
    pub substeps: u32,
    /// Maximum turn rate, radians per second.
    pub max_turn_rate: f64,
    /// Maximum change of the turn rate, radians per second squared.
    pub max_turn_accel: f64,
    /// Time constant of the turn rate following the bird's request, seconds.
    pub turn_lag: f64,
    /// Maximum rate of change of the turn rate's change, radians per second cubed.
    pub max_turn_jerk: f64,
    /// Maximum change of speed (acceleration), wingspans per second squared.
    pub max_accel: f64,
    /// Maximum change of the acceleration (jerk), wingspans per second cubed.
    pub max_jerk: f64,
    /// Time constant of the speed following the bird's request, seconds.
    pub speed_lag: f64,
    /// Minimum flight speed (also the lift-off speed), as a fraction of the cruise speed.
    pub min_speed: f64,
    /// Maximum flight speed, as a fraction of the cruise speed.
    pub max_speed: f64,
    /// Maximum roll rate of the bank, radians per second.
    pub max_roll_rate: f64,
    /// Time constant of the bank following the coordinated-turn bank, seconds.
    pub roll_lag: f64,
    /// Maximum roll acceleration, radians per second squared.
    pub max_roll_accel: f64,
    /// Cruise altitude: `z` of the steady flight above the ground, wingspans (the steady flight's
    /// own `z` is added to it).
    pub cruise_altitude: f64,
    /// Largest climb rate, wingspans per second.
    pub climb_rate: f64,
    /// Largest vertical acceleration, wingspans per second squared.
    pub vertical_accel: f64,
    /// Acceleration of the take-off run on the ground, wingspans per second squared.
    pub run_accel: f64,
    /// Wanted take-off duration, seconds (`None`: the natural one of the flock size, see
    /// [`TakeoffPlan::natural_seconds`]). The take-off plan scales the start area, the departure
    /// stagger and how hard the birds drive (accelerations, climb, approach) to it
    /// ([`TakeoffPlan::drive`]); the simulation is never cut.
    pub takeoff: Option<f64>,
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
    /// Eq. (5)'s √|r − v_j τ| is replaced by its chord within this distance of the fixed point,
    /// wingspans.
    pub linear_zone: f64,
    /// Beyond this distance from its fixed point, eq. (5)'s √|r − v_j τ| grows linearly, so a bird
    /// far behind catches up in seconds, wingspans.
    pub catchup_distance: f64,
    /// Eq. (5) on the longitudinal gap to the target (along the reference's heading) instead of
    /// the whole distance r: lateral errors are eq. (6)'s (docs/initiation.md).
    pub gap_speed: bool,
    /// Speed of the leader while flockmates are still on the ground or running, as a fraction
    /// of the cruise speed (at least the minimum speed).
    pub gather_speed: f64,
    /// Slots assigned once at the start, in the order of the birds' positions across the cruise
    /// heading (no sideways crossings; the departures follow the slots' depth), instead of the
    /// paper's §6.2.1 correspondence through reference birds, re-evaluated at every decision
    /// (docs/initiation.md).
    pub assign_slots: bool,
    /// Final approach: within this distance of its slot a bird steers by the formation-frame
    /// controller (slot error and the leader's velocity) instead of eqs. (5)–(6); blended out to
    /// twice it, wingspans.
    pub approach_distance: f64,
    /// Final approach: time constant of the sideways slot error, seconds (along the heading
    /// 0.7 of it).
    pub approach_time: f64,
    /// Final approach: deceleration that brakes the closing speed on the slot, wingspans per
    /// second squared.
    pub approach_brake: f64,
    /// Convergence: distance of every bird from its slot and from the cruise altitude, wingspans.
    pub tolerance: f64,
    /// Convergence: heading difference from the cruise heading, radians.
    pub heading_tolerance: f64,
    /// Convergence: speed difference from the cruise speed, fraction of it.
    pub speed_tolerance: f64,
    /// Convergence: how long the flock must stay in formation, seconds. The hand-over blend
    /// to the exact steady-flight state uses the same window.
    pub hold: f64,
    /// Time limit of the simulation, seconds; no convergence within it is
    /// [`Error::NotConverged`].
    pub max_time: f64,
    /// Frame limit of the initiation at the output frame rate (bounds memory); the time limit is
    /// the smaller of `max_time` and `max_steps / fps`.
    pub max_steps: usize,
    /// Where and how the birds start.
    pub start: Start,
    /// The seed recorded in the output file (the pipeline sets it from `Config::seed`).
    pub seed: u64,
}

impl Default for InitiateOptions {
    fn default() -> Self {
        InitiateOptions {
            perception: PerceptionParams::default(),
            widen_field: true,
            visual_range: 60.0,
            alpha: 0.2,
            k: 0.06,
            reaction_time: 1.0 / 30.0,
            substeps: 4,
            max_turn_rate: PI / 2.0,
            max_turn_accel: 540f64.to_radians(),
            turn_lag: 0.1,
            max_turn_jerk: 6000f64.to_radians(),
            max_accel: 4.0,
            max_jerk: 40.0,
            speed_lag: 0.1,
            min_speed: 0.5,
            max_speed: 1.6,
            max_roll_rate: 180f64.to_radians(),
            roll_lag: 0.2,
            max_roll_accel: 400f64.to_radians(),
            cruise_altitude: 10.0,
            climb_rate: 2.5,
            vertical_accel: 2.0,
            run_accel: 3.0,
            takeoff: None,
            separation_distance: 10.0,
            lookahead: 4.0,
            avoid_distance: 0.3,
            avoid_range: 6.0,
            avoid_horizon: 2.0,
            lost_speed_factor: 0.9,
            leader_hysteresis: 1.0,
            sticky_reference: true,
            reference_memory: None,
            turn_distance_cap: 5.0,
            linear_zone: 0.25,
            catchup_distance: 1.5,
            gap_speed: true,
            gather_speed: 0.5,
            assign_slots: true,
            approach_distance: 5.0,
            approach_time: 1.2,
            approach_brake: 2.0,
            tolerance: 0.1,
            heading_tolerance: 2f64.to_radians(),
            speed_tolerance: 0.02,
            hold: 1.0,
            max_time: 300.0,
            max_steps: 9000,
            start: Start::Ground(GroundStart::default()),
            seed: 0,
        }
    }
}

/// Where the birds start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Start {
    /// At rest on the ground (or water) in a take-off area, leaving in a staggered order.
    Ground(GroundStart),
    /// The paper's start: scattered in the air, random positions, headings and speeds in a
    /// region, at the cruise altitude.
    Random(StartRegion),
    /// Given positions (and optionally headings and speeds), in the air at the cruise altitude.
    Given(StartState),
}

/// A take-off from the ground: birds at rest in a rectangle centred on the origin (its width
/// across and its depth along the cruise heading), at least `min_spacing` apart, facing within
/// `heading_spread` of the cruise heading; they leave front to back over the stagger window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundStart {
    /// Width across the cruise heading, wingspans (`None`: from the take-off plan).
    pub width: Option<f64>,
    /// Depth along the cruise heading, wingspans (`None`: from the take-off plan).
    pub depth: Option<f64>,
    /// Half-width of the heading distribution around the cruise heading, radians.
    pub heading_spread: f64,
    /// Minimum distance between two birds on the ground, wingspans.
    pub min_spacing: f64,
    /// Time between the first and the last departure, seconds (`None`: from the take-off plan).
    pub stagger: Option<f64>,
}

impl Default for GroundStart {
    fn default() -> Self {
        GroundStart {
            width: None,
            depth: None,
            heading_spread: 5f64.to_radians(),
            min_spacing: 2.0,
            stagger: None,
        }
    }
}

/// What the take-off duration sets: the start area, the departure stagger and the drive gain.
/// Derived by [`TakeoffPlan::new`] from the flock size and [`InitiateOptions::takeoff`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TakeoffPlan {
    /// The take-off duration aimed at, seconds.
    pub seconds: f64,
    /// Width of the start area across the cruise heading, wingspans.
    pub width: f64,
    /// Depth of the start area along the cruise heading, wingspans.
    pub depth: f64,
    /// Time between the first and the last departure (ground start), seconds.
    pub stagger: f64,
    /// |K| of eq. (5) used, per √wingspan.
    pub k: f64,
    /// Catch-up distance of eq. (5) used, wingspans.
    pub catchup_distance: f64,
    /// How hard the birds drive: the natural duration over the wanted one, within
    /// [[`TakeoffPlan::MIN_DRIVE`], [`TakeoffPlan::MAX_DRIVE`]]. The run and vertical
    /// accelerations and the climb rate are multiplied by it, the approach time divided by it
    /// (by at most [`TakeoffPlan::MAX_APPROACH_DRIVE`]);
    /// the departure stagger is 1 s over it; below 1 the take-off area also grows by 1/drive.
    pub drive: f64,
}

impl TakeoffPlan {
    /// The weakest drive: a take-off at most about twice the natural one.
    pub const MIN_DRIVE: f64 = 0.45;
    /// The strongest drive: a take-off down to about 0.7 of the natural one (the climb to the
    /// cruise altitude bounds it).
    pub const MAX_DRIVE: f64 = 1.6;
    /// The strongest drive of the final approach to the slots: a short take-off runs, climbs
    /// and departs faster, but no bird closes on its slot harder than in the natural take-off.
    /// Driven 1.6 times as hard, birds of neighbouring slots came 0.29 wingspans close (100
    /// birds, `initiate.takeoff` 8 s, 2 of 21 seeds) and 0.22 (300 birds, 10 seeds); at 1 they
    /// keep 0.36 and 0.34, and the take-off lasts 0.4–1.1 s longer (docs/initiation.md).
    pub const MAX_APPROACH_DRIVE: f64 = 1.0;

    /// The natural take-off of `n` birds from the ground at the default options, seconds:
    /// measured medians (docs/initiation.md) about 9.5 s for 9–14 birds, 10.7 s for 41, 12.7 s
    /// for 100, 23 s for 300 (the lift-off and climb to 10 wingspans take about 7 s; the rest
    /// grows with the width of the V).
    pub fn natural_seconds(n: usize) -> f64 {
        9.0 + 0.045 * n.max(1) as f64
    }

    /// The automatic take-off duration of `n` birds, seconds: the natural one.
    pub fn auto_seconds(n: usize) -> f64 {
        Self::natural_seconds(n)
    }

    /// The shortest take-off of `n` birds from the ground at the strongest drive, seconds:
    /// measured medians 7.9 s for 9 birds, 8.3 for 14, 9.2 for 41, 11.7 for 100, 22.4 for 300
    /// (`initiate.takeoff` 5 s, docs/initiation.md); fitted 8.1, 8.4, 9.7, 12.6 and 22.4. The
    /// run, lift-off and climb to the cruise altitude take about 7 s at the strongest drive
    /// (climb rate and accelerations bounded), and the outer birds of a wider V have farther to
    /// fly to their slots at bounded speeds.
    pub fn shortest_seconds(n: usize) -> f64 {
        7.7 + 0.049 * n.max(1) as f64
    }

    /// A warning when the take-off duration of `opts` cannot be met within 25 % for `n` birds:
    /// shorter than [`Self::shortest_seconds`] allows, or longer than twice the natural
    /// duration; it names `initiate.takeoff`, the duration the take-off will have and why.
    pub fn warning(n: usize, opts: &InitiateOptions) -> Option<String> {
        let t = opts.takeoff?;
        if !matches!(opts.start, Start::Ground(_)) {
            return None;
        }
        let shortest = Self::shortest_seconds(n);
        let longest = 2.0 * Self::natural_seconds(n);
        if t * 1.25 < shortest {
            Some(format!(
                "initiate.takeoff {t} s: {n} birds cannot take off in less than about {shortest:.0} s (the run and the climb to the cruise altitude take about 7 s at the strongest drive, and the outer birds of a wide V need longer to reach their slots); the take-off will last about {shortest:.0} s"
            ))
        } else if t > 1.25 * longest {
            Some(format!(
                "initiate.takeoff {t} s: {n} birds form in at most about {longest:.0} s with these rules (the drive is at its weakest); the take-off will last about {longest:.0} s"
            ))
        } else {
            None
        }
    }

    /// The plan for `n` birds under `opts` (its `takeoff`, or the automatic duration): the
    /// drive is the natural duration over the wanted one (bounded), which scales the departure
    /// stagger, the accelerations, the climb rate, the approach and (for a longer take-off) the
    /// take-off area, so that every part of the take-off takes about `seconds / natural` times
    /// as long. The simulation itself is never cut.
    pub fn new(n: usize, opts: &InitiateOptions) -> TakeoffPlan {
        let natural = Self::natural_seconds(n);
        let seconds = opts.takeoff.unwrap_or(natural);
        let drive = (natural / seconds).clamp(Self::MIN_DRIVE, Self::MAX_DRIVE);
        let root = (n.max(1) as f64).sqrt();
        let (width, depth, stagger) = match &opts.start {
            Start::Ground(g) => {
                // About 6.8 square wingspans per bird (1.1 times what random packing of birds
                // `min_spacing` = 2 apart needs), more for a slow take-off; three times as wide
                // as deep, at most GROUND_MAX_DEPTH deep (wider instead).
                let base =
                    (1.3 * g.min_spacing * root).max(4.0 * g.min_spacing) / drive.min(1.0).sqrt();
                let aspect = GROUND_ASPECT;
                let depth = (base / aspect.sqrt()).min(GROUND_MAX_DEPTH);
                (
                    g.width.unwrap_or(base * base / depth),
                    g.depth.unwrap_or(depth),
                    g.stagger.unwrap_or(1.0 / drive),
                )
            }
            Start::Random(r) => {
                let (w, d) = r.size(n);
                (w, d, 0.0)
            }
            Start::Given(_) => (0.0, 0.0, 0.0),
        };
        TakeoffPlan {
            seconds,
            width,
            depth,
            stagger,
            k: opts.k,
            catchup_distance: opts.catchup_distance,
            drive,
        }
    }
}

/// An angle in radians as degrees for a message or a flag's default, rounded to 10⁻⁹° so that
/// a value given in degrees and converted to radians reads back as given.
pub fn display_degrees(rad: f64) -> f64 {
    let d = rad.to_degrees();
    let r = (d * 1e9).round() / 1e9;
    if r.is_finite() {
        r
    } else {
        d
    }
}

/// A random take-off: positions uniform in a rectangle centred on the origin, its width across
/// and its depth along the cruise heading, at least `min_spacing` apart; headings uniform within
/// `heading_spread` of the cruise heading; speeds uniform between the minimum and the cruise speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StartRegion {
    /// Width across the cruise heading, wingspans (`None`: 20, or 4.5√N for more than 19 birds).
    pub width: Option<f64>,
    /// Depth along the cruise heading, wingspans (`None`: half the width, 10 to 15).
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

/// A start chosen by name, as a command line or a config file gives it: the kind (`ground`,
/// `air` for the paper's scattered start, or else the path of a start file) and optional
/// overrides of the start's region. Angles are in degrees, as people give them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StartChoice {
    /// `ground`, `air`, or the path of a start file.
    pub kind: String,
    /// Width of the take-off area or start region across the cruise heading, wingspans.
    pub width: Option<f64>,
    /// Depth of the take-off area or start region along the cruise heading, wingspans.
    pub depth: Option<f64>,
    /// Half-width of the start headings around the cruise heading, degrees.
    pub heading_spread_deg: Option<f64>,
}

impl Start {
    /// The word that names this kind of start: `ground`, `air` or `file`.
    pub fn word(&self) -> &'static str {
        match self {
            Start::Ground(_) => "ground",
            Start::Random(_) => "air",
            Start::Given(_) => "file",
        }
    }

    /// The start `choice` names for a flock of `birds`: a start file is read (and checked
    /// against the flock); the region overrides apply to `ground` and `air` only, and giving one
    /// with a start file is an error naming it (`initiate.start.width`, `.depth`,
    /// `.heading_spread`). A heading spread equal to the default's display in degrees is the
    /// default exactly.
    pub fn from_choice(choice: &StartChoice, birds: usize) -> Result<Start> {
        let spread = |default: f64| {
            choice.heading_spread_deg.map_or(default, |h| {
                if h == display_degrees(default) {
                    default
                } else {
                    h.to_radians()
                }
            })
        };
        Ok(match choice.kind.as_str() {
            "ground" => {
                let g = GroundStart::default();
                Start::Ground(GroundStart {
                    width: choice.width,
                    depth: choice.depth,
                    heading_spread: spread(g.heading_spread),
                    ..g
                })
            }
            "air" => {
                let r = StartRegion::default();
                Start::Random(StartRegion {
                    width: choice.width,
                    depth: choice.depth,
                    heading_spread: spread(r.heading_spread),
                    ..r
                })
            }
            path => {
                for (name, given) in [
                    ("initiate.start.width", choice.width.is_some()),
                    ("initiate.start.depth", choice.depth.is_some()),
                    (
                        "initiate.start.heading_spread",
                        choice.heading_spread_deg.is_some(),
                    ),
                ] {
                    if given {
                        return Err(Error::parameter(
                            name,
                            "does not apply to a start file (initiate.start FILE); give initiate.start ground or air",
                        ));
                    }
                }
                Start::Given(StartState::read(std::path::Path::new(path), birds)?)
            }
        })
    }
}

impl StartRegion {
    /// Width and depth for `n` birds, wingspans: by default 4.5√N wide (at least 20) and half
    /// as deep, 10 to 15 wingspans, wider where random packing needs it (more than about 300
    /// birds 1.5 apart).
    pub fn size(&self, n: usize) -> (f64, f64) {
        let auto = (AIR_WIDTH_PER_ROOT_BIRD * (n as f64).sqrt()).max(AIR_MIN_WIDTH);
        let (lo, hi) = AIR_DEPTH_RANGE;
        let depth = self
            .depth
            .unwrap_or((0.5 * self.width.unwrap_or(auto)).clamp(lo, hi));
        // Wide enough for random packing (about half the area) with a tenth to spare, as the
        // take-off area: 1000 birds 1.5 apart need 259 × 15 wingspans.
        let packing = 1.1 * n as f64 * PI / 4.0 * self.min_spacing * self.min_spacing / 0.5;
        let w = self
            .width
            .unwrap_or_else(|| auto.max(packing / depth.max(1e-9)));
        (w, depth)
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
        // Where an animation file may hold a bird: one 10¹² wingspans away made the take-off's
        // neighbour grid crawl (75 s), one at 10³⁰⁰ overflowed it (a panic).
        let bound = crate::limits::MAX_COORDINATE;
        for (name, a) in [("x", &s.x), ("y", &s.y)] {
            if let Some(i) = a.iter().position(|v| v.abs() > bound) {
                return Err(Error::format(
                    path,
                    format!(
                        "{name}[{i}]: {:e} wingspans; a start position must be within ±{bound:e} wingspans",
                        a[i]
                    ),
                ));
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
    /// Output frame intervals of the initiation (frames − 1).
    pub steps: usize,
    /// Simulated time until convergence (or the time limit), seconds.
    pub seconds: f64,
    /// The take-off duration aimed at, seconds ([`TakeoffPlan`]).
    pub planned_seconds: f64,
    /// Whether the flock converged.
    pub converged: bool,
    /// Smallest 3-D distance between two birds over the whole initiation (start included),
    /// wingspans.
    pub min_distance: f64,
    /// Largest turn rate of a bird, radians per second.
    pub max_turn_rate: f64,
    /// Largest change of a bird's turn rate, radians per second squared.
    pub max_turn_accel: f64,
    /// Largest change of a bird's speed, wingspans per second squared.
    pub max_accel: f64,
    /// Largest bank of a bird, radians.
    pub max_bank: f64,
    /// Largest distance of a bird from the nearest slot of the formed flock, once every bird
    /// is airborne, wingspans.
    pub max_stray: f64,
    /// Time at which the last bird left the ground, seconds (0 for an airborne start).
    pub last_liftoff: f64,
    /// How often the leader changed.
    pub leader_changes: usize,
    /// Birds within the tolerance of a slot of their own at the end.
    pub birds_in_slot: usize,
    /// Visual field per eye used, radians (the option's, or wider if the target shape needs it).
    pub field_per_eye: f64,
}

/// The simulated initiation before the hand-over: states sampled at the output frame rate, in
/// simulation bird order.
#[derive(Debug, Clone)]
pub struct InitiationRun {
    /// Output frame rate of the samples, frames per second.
    pub fps: f64,
    /// Horizontal positions of every frame (index 0 = start), wingspans.
    pub pos: Vec<Vec<DVec2>>,
    /// Altitudes of every frame, wingspans.
    pub z: Vec<Vec<f64>>,
    /// Headings of every frame, radians.
    pub heading: Vec<Vec<f64>>,
    /// Speeds of every frame, wingspans per second.
    pub speed: Vec<Vec<f64>>,
    /// Bank angles of every frame, radians (right wing down positive).
    pub bank: Vec<Vec<f64>>,
    /// Slot of every bird at the end (meaningful when converged: a permutation).
    pub slot: Vec<Option<usize>>,
    /// Statistics.
    pub stats: InitiateStats,
}

/// The steady flight the flock converges into: the leader's cruise heading (radians) and speed
/// (wingspans per second), and the wingspan in metres (for gravity in wingspans/s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cruise {
    /// Cruise heading, radians clockwise from +y.
    pub heading: f64,
    /// Cruise speed, wingspans per second.
    pub speed: f64,
    /// Wingspan, metres.
    pub wingspan_m: f64,
}

impl Cruise {
    /// A cruise along `heading` (radians) at `speed` (wingspans per second) of birds with a
    /// wingspan of 1.5 m.
    pub fn new(heading: f64, speed: f64) -> Cruise {
        Cruise {
            heading,
            speed,
            wingspan_m: 1.5,
        }
    }

    /// Gravity in wingspans per second squared.
    pub fn gravity(&self) -> f64 {
        GRAVITY_M_S2 / self.wingspan_m
    }
}

impl InitiateOptions {
    /// Checks every parameter; errors name the option path (`initiate.alpha`).
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
                "initiate.perception.fov_per_eye",
                format!(
                    "visual field per eye must be in (0, 180] degrees, got {:.3}",
                    fov.to_degrees()
                ),
            ));
        }
        let cone = self.perception.reference_cone;
        if !(cone.is_finite() && cone > 0.0 && cone <= PI) {
            return Err(Error::parameter(
                "initiate.perception.reference_cone",
                format!("must be in (0, 180] degrees, got {:.3}", cone.to_degrees()),
            ));
        }
        if let PerceptionMode::Hpr { gamma } = self.perception.mode {
            if !(gamma.is_finite() && (0.0..=8.0).contains(&gamma)) {
                return Err(Error::parameter(
                    "initiate.perception.mode.hpr.gamma",
                    format!("must be in [0, 8], got {gamma}"),
                ));
            }
        }
        pos(
            "initiate.perception.bird_radius",
            self.perception.bird_radius,
        )?;
        if !(self.alpha.is_finite() && self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(Error::parameter(
                "initiate.alpha",
                format!("must be in (0, 1], got {}", self.alpha),
            ));
        }
        pos("initiate.k", self.k)?;
        let pos_deg = |name: &str, v: f64, unit: &str| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!(
                        "must be a positive number of {unit}, got {}",
                        display_degrees(v)
                    ),
                ))
            }
        };
        pos_deg(
            "initiate.max_turn_rate",
            self.max_turn_rate,
            "degrees per second",
        )?;
        pos("initiate.max_accel", self.max_accel)?;
        pos_deg(
            "initiate.max_turn_accel",
            self.max_turn_accel,
            "degrees per second squared",
        )?;
        pos("initiate.max_jerk", self.max_jerk)?;
        pos_deg(
            "initiate.max_turn_jerk",
            self.max_turn_jerk,
            "degrees per second cubed",
        )?;
        pos_deg(
            "initiate.max_roll_rate",
            self.max_roll_rate,
            "degrees per second",
        )?;
        pos_deg(
            "initiate.max_roll_accel",
            self.max_roll_accel,
            "degrees per second squared",
        )?;
        pos("initiate.climb_rate", self.climb_rate)?;
        pos("initiate.vertical_accel", self.vertical_accel)?;
        pos("initiate.run_accel", self.run_accel)?;
        pos("initiate.visual_range", self.visual_range)?;
        for (name, v) in [
            ("initiate.turn_lag", self.turn_lag),
            ("initiate.speed_lag", self.speed_lag),
            ("initiate.roll_lag", self.roll_lag),
        ] {
            if !(v.is_finite() && (0.001..=10.0).contains(&v)) {
                return Err(Error::parameter(
                    name,
                    format!("must be between 0.001 and 10 seconds, got {v}"),
                ));
            }
        }
        if !(self.reaction_time.is_finite() && (0.001..=1.0).contains(&self.reaction_time)) {
            return Err(Error::parameter(
                "initiate.reaction_time",
                format!(
                    "must be between 0.001 and 1 second, got {}",
                    self.reaction_time
                ),
            ));
        }
        if !(1..=64).contains(&self.substeps) {
            return Err(Error::parameter(
                "initiate.substeps",
                format!("must be between 1 and 64, got {}", self.substeps),
            ));
        }
        if let Some(t) = self.takeoff {
            if !(t.is_finite() && t > 0.0) {
                return Err(Error::parameter(
                    "initiate.takeoff",
                    format!("must be a positive number of seconds, got {t}"),
                ));
            }
            if t > self.max_time {
                return Err(Error::parameter(
                    "initiate.takeoff",
                    format!("{t} s is longer than the time limit of {} s", self.max_time),
                ));
            }
        }
        if !(self.cruise_altitude.is_finite() && self.cruise_altitude >= 0.0) {
            return Err(Error::parameter(
                "initiate.cruise_altitude",
                format!(
                    "must be a number of wingspans at or above the ground (0), got {}",
                    self.cruise_altitude
                ),
            ));
        }
        if self.cruise_altitude > 1e5 {
            return Err(Error::parameter(
                "initiate.cruise_altitude",
                format!("at most 1e5 wingspans, got {:e}", self.cruise_altitude),
            ));
        }
        if !(self.max_time.is_finite() && self.max_time > 0.0) {
            return Err(Error::parameter(
                "initiate.max_time",
                format!(
                    "must be a positive number of seconds, got {}",
                    self.max_time
                ),
            ));
        }
        pos("initiate.min_speed", self.min_speed)?;
        pos("initiate.max_speed", self.max_speed)?;
        if self.min_speed >= 1.0 || self.max_speed <= 1.0 {
            return Err(Error::parameter(
                "initiate.min_speed/initiate.max_speed",
                format!(
                    "the cruise speed must lie between them (min < 1 < max), got {} and {}",
                    self.min_speed, self.max_speed
                ),
            ));
        }
        pos("initiate.separation_distance", self.separation_distance)?;
        pos("initiate.lookahead", self.lookahead)?;
        pos("initiate.avoid_distance", self.avoid_distance)?;
        pos("initiate.avoid_range", self.avoid_range)?;
        pos("initiate.avoid_horizon", self.avoid_horizon)?;
        pos("initiate.lost_speed_factor", self.lost_speed_factor)?;
        pos("initiate.turn_distance_cap", self.turn_distance_cap)?;
        pos("initiate.linear_zone", self.linear_zone)?;
        pos("initiate.catchup_distance", self.catchup_distance)?;
        pos("initiate.gather_speed", self.gather_speed)?;
        pos("initiate.approach_distance", self.approach_distance)?;
        pos("initiate.approach_time", self.approach_time)?;
        pos("initiate.approach_brake", self.approach_brake)?;
        let memory = self.reference_memory();
        if !(memory.is_finite() && (0.0..=60.0).contains(&memory)) {
            return Err(Error::parameter(
                "initiate.reference_memory",
                format!("must be in [0, 60] seconds, got {memory}"),
            ));
        }
        if !(self.leader_hysteresis.is_finite() && self.leader_hysteresis >= 0.0) {
            return Err(Error::parameter(
                "initiate.leader_hysteresis",
                "must be a non-negative number",
            ));
        }
        pos("initiate.tolerance", self.tolerance)?;
        if self.tolerance < 1e-6 {
            return Err(Error::parameter(
                "initiate.tolerance",
                format!(
                    "{:e} wingspans cannot be met in floating point; use at least 1e-6",
                    self.tolerance
                ),
            ));
        }
        pos("initiate.heading_tolerance", self.heading_tolerance)?;
        pos("initiate.speed_tolerance", self.speed_tolerance)?;
        if !(self.hold.is_finite() && self.hold >= 0.0) {
            return Err(Error::parameter(
                "initiate.hold",
                format!(
                    "must be a non-negative number of seconds, got {}",
                    self.hold
                ),
            ));
        }
        if self.max_steps == 0 {
            return Err(Error::parameter(
                "initiate.max_steps",
                "must be at least 1 (the initiation needs at least one step)",
            ));
        }
        if self.max_steps > MAX_STEPS_LIMIT {
            return Err(Error::parameter(
                "initiate.max_steps",
                format!(
                    "at most {MAX_STEPS_LIMIT} (every step is kept in memory for the output), got {}",
                    self.max_steps
                ),
            ));
        }
        if let Start::Ground(g) = &self.start {
            for (name, v) in [
                ("initiate.start.ground.width", g.width),
                ("initiate.start.ground.depth", g.depth),
            ] {
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
            if let Some(w) = g.stagger {
                if !(w.is_finite() && w >= 0.0 && w <= self.max_time) {
                    return Err(Error::parameter(
                        "initiate.start.ground.stagger",
                        format!(
                            "must be a number of seconds between 0 and the time limit, got {w}"
                        ),
                    ));
                }
            }
            if !(g.heading_spread.is_finite() && (0.0..=PI).contains(&g.heading_spread)) {
                return Err(Error::parameter(
                    "initiate.start.ground.heading_spread",
                    format!(
                        "must be in [0, 180] degrees, got {}",
                        display_degrees(g.heading_spread)
                    ),
                ));
            }
            if !(g.min_spacing.is_finite() && g.min_spacing > 0.0) {
                return Err(Error::parameter(
                    "initiate.start.ground.min_spacing",
                    "must be a positive number of wingspans",
                ));
            }
        }
        if let Start::Random(r) = &self.start {
            for (name, v) in [
                ("initiate.start.random.width", r.width),
                ("initiate.start.random.depth", r.depth),
            ] {
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
                    "initiate.start.random.heading_spread",
                    format!(
                        "must be in [0, 180] degrees, got {}",
                        display_degrees(r.heading_spread)
                    ),
                ));
            }
            if !(r.min_spacing.is_finite() && r.min_spacing >= 0.0) {
                return Err(Error::parameter(
                    "initiate.start.random.min_spacing",
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

    /// The simulation's parameters for a cruise (heading, speed, wingspan) without a take-off
    /// plan: the options' own gain and catch-up distance, at the natural drive (1).
    pub fn step_params(&self, cruise: &Cruise) -> StepParams {
        self.derive_params(cruise, self.k, self.catchup_distance, 1.0)
    }

    /// The simulation's parameters for a cruise under a take-off plan: the plan's gain,
    /// catch-up distance and drive (accelerations of the run and the climb, the climb rate and,
    /// up to [`TakeoffPlan::MAX_APPROACH_DRIVE`], the approach scaled by it).
    pub fn plan_params(&self, cruise: &Cruise, plan: &TakeoffPlan) -> StepParams {
        self.derive_params(cruise, plan.k, plan.catchup_distance, plan.drive)
    }

    /// The options and the values derived from them: the speeds in wingspans per second from
    /// their factors of the cruise speed, gravity, the reference memory in decisions, and the
    /// drive-scaled take-off values.
    fn derive_params(&self, cruise: &Cruise, k: f64, catchup: f64, drive: f64) -> StepParams {
        let vc = cruise.speed;
        let approach = drive.min(TakeoffPlan::MAX_APPROACH_DRIVE);
        StepParams {
            opts: std::sync::Arc::new(self.clone()),
            k,
            min_speed: self.min_speed * vc,
            max_speed: self.max_speed * vc,
            cruise_heading: cruise.heading,
            cruise_speed: vc,
            climb_rate: self.climb_rate * drive,
            vertical_accel: self.vertical_accel * drive,
            gravity: cruise.gravity(),
            run_accel: self.run_accel * drive,
            reference_memory: (self.reference_memory() / self.reaction_time).round() as u32,
            catchup_distance: catchup,
            gather_speed: self.gather_speed * vc,
            approach_time: self.approach_time / approach,
            approach_brake: self.approach_brake * approach,
        }
    }

    /// The convergence tolerances: the options' distance, heading and speed, and steady flight
    /// (turn rate ≤ 2°/s, acceleration ≤ 0.2 wingspans/s², climb rate ≤ 0.1 wingspans/s).
    pub fn tolerances(&self) -> Tolerances {
        Tolerances {
            distance: self.tolerance,
            heading: self.heading_tolerance,
            speed: self.speed_tolerance,
            turn_rate: 2f64.to_radians(),
            accel: 0.2,
            climb: 0.1,
        }
    }

    /// The time limit at `fps`: the smaller of `max_time` and `max_steps / fps`, seconds.
    pub fn time_limit(&self, fps: f64) -> f64 {
        self.max_time.min(self.max_steps as f64 / fps)
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

/// Random start positions, headings and speeds (wingspans, radians, wingspans per second):
/// positions uniform in the region at least `min_spacing` apart; headings uniform within the
/// spread and speeds between the minimum and the cruise speed, redrawn while two birds would,
/// flying straight, come closer than [`START_MISS`] within [`START_HORIZON`] (no start on a
/// collision course: the birds turn round at once, and a pair that close has no room to).
pub fn random_start(
    n: usize,
    region: &StartRegion,
    params: &StepParams,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    scatter(n, region, params, START_MISS, START_HORIZON, rng)
}

/// [`random_start`] with the predicted miss distance (wingspans) a start heading must keep from
/// the birds drawn before it within `horizon` seconds (the ground start's positions are drawn
/// with the avoidance distance and a quarter turn's time).
fn scatter(
    n: usize,
    region: &StartRegion,
    params: &StepParams,
    miss: f64,
    horizon: f64,
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
                "initiate.start.random.width/initiate.start.random.depth",
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
    let want_miss = params.opts.avoid_distance.max(miss);
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
            if miss >= want_miss {
                break;
            }
        }
        heading.push(best.1);
        speed.push(best.2);
    }
    Ok((pos, heading, speed))
}

/// A take-off area: positions uniform in the plan's rectangle at least `min_spacing` apart, at
/// rest (speed 0, z = 0), facing within the spread of the cruise heading, with departure times
/// front to back over the stagger window (the front-most bird leaves at 0 and leads; a small
/// random jitter of a tenth of the window mixes neighbours). With assigned slots the simulation
/// hands these times out again by slot depth ([`Simulation::new`]). An area too small for the
/// flock is an error naming the option paths.
pub fn ground_start(
    n: usize,
    g: &GroundStart,
    plan: &TakeoffPlan,
    params: &StepParams,
    rng: &mut impl Rng,
) -> Result<(Vec<DVec2>, Vec<f64>, Vec<f64>)> {
    let (w, d) = (plan.width, plan.depth);
    // Random packing of discs reaches about half the area (random sequential adsorption: 0.547).
    let capacity = 0.5 * w * d / (PI / 4.0 * g.min_spacing * g.min_spacing);
    if (n as f64) > capacity.max(1.0) {
        let need = (n as f64 * PI / 4.0 * g.min_spacing * g.min_spacing / 0.5).sqrt();
        return Err(Error::parameter(
            "initiate.start.ground.width/initiate.start.ground.depth",
            format!(
                "a take-off area of {w:.1} × {d:.1} wingspans is too small for {n} birds {} wingspans apart; give at least about {need:.0} × {need:.0}",
                g.min_spacing
            ),
        ));
    }
    let region = StartRegion {
        width: Some(w),
        depth: Some(d),
        heading_spread: 0.0,
        min_spacing: g.min_spacing,
    };
    let quarter_turn = std::f64::consts::FRAC_PI_2 / params.opts.max_turn_rate;
    let (pos, _, _) = scatter(
        n,
        &region,
        params,
        params.opts.avoid_distance,
        quarter_turn,
        rng,
    )?;
    let heading: Vec<f64> = (0..n)
        .map(|_| {
            let h = if g.heading_spread > 0.0 {
                rng.random_range(-g.heading_spread..=g.heading_spread)
            } else {
                0.0
            };
            sim::wrap_angle(params.cruise_heading + h)
        })
        .collect();
    let dc = perception::direction(params.cruise_heading);
    let along: Vec<f64> = pos.iter().map(|p| p.dot(dc)).collect();
    let front = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = (front - along.iter().copied().fold(f64::INFINITY, f64::min)).max(1e-9);
    let w = plan.stagger;
    let depart: Vec<f64> = along
        .iter()
        .map(|&a| {
            let jitter: f64 = rng.random_range(0.0..1.0);
            if a >= front {
                0.0
            } else {
                w * (0.9 * (front - a) / span + 0.1 * jitter)
            }
        })
        .collect();
    Ok((pos, heading, depart))
}

/// The simulation at its first instant: parameters for the cruise, the visual field widened for
/// `target` if asked, and the start (random ones drawn from `rng`). Also gives the take-off plan.
pub fn start_simulation(
    target: &TargetShape,
    cruise: &Cruise,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
) -> Result<(Simulation, TakeoffPlan)> {
    opts.validate()?;
    if !(cruise.speed.is_finite() && cruise.speed > 0.0 && cruise.heading.is_finite()) {
        return Err(Error::parameter(
            "cruise speed",
            "the leader's speed must be a positive number",
        ));
    }
    if !(cruise.wingspan_m.is_finite() && cruise.wingspan_m > 0.0) {
        return Err(Error::parameter(
            "wingspan_m",
            "must be a positive number of metres",
        ));
    }
    let n = target.len();
    let plan = TakeoffPlan::new(n, opts);
    let mut params = opts.plan_params(cruise, &plan);
    if opts.widen_field {
        let field = &mut std::sync::Arc::make_mut(&mut params.opts)
            .perception
            .fov_per_eye;
        *field = field.max(target.required_field(FIELD_MARGIN));
    }
    if matches!(opts.start, Start::Ground(_)) {
        let reach = reachable_altitude(params.climb_rate, params.vertical_accel, opts.max_time);
        if opts.cruise_altitude > reach {
            return Err(Error::parameter(
                "initiate.cruise_altitude",
                format!(
                    "{} wingspans cannot be reached: climbing at most {:.3} wingspans/s (initiate.climb_rate, times the take-off's drive {:.2}) the birds reach at most about {:.0} wingspans within the time limit of {} s (initiate.max_time)",
                    opts.cruise_altitude,
                    params.climb_rate,
                    plan.drive,
                    reach.floor(),
                    opts.max_time
                ),
            ));
        }
    }
    let alt = opts.cruise_altitude;
    let (pos, z, heading, speed, depart) = match &opts.start {
        Start::Ground(g) => {
            let (pos, heading, depart) = ground_start(n, g, &plan, &params, rng)?;
            (pos, vec![0.0; n], heading, vec![0.0; n], depart)
        }
        Start::Random(region) => {
            let (pos, heading, speed) = random_start(n, region, &params, rng)?;
            (pos, vec![alt; n], heading, speed, vec![0.0; n])
        }
        Start::Given(s) => {
            if s.x.len() != n || s.y.len() != n {
                return Err(Error::parameter(
                    "initiate.start",
                    format!("{} start positions for {n} birds", s.x.len()),
                ));
            }
            let pos =
                s.x.iter()
                    .zip(&s.y)
                    .map(|(&x, &y)| DVec2::new(x, y))
                    .collect();
            let heading = s.heading.clone().unwrap_or_else(|| vec![cruise.heading; n]);
            let speed = match &s.speed {
                Some(v) => v
                    .iter()
                    .map(|v| v.clamp(params.min_speed, params.max_speed))
                    .collect(),
                None => vec![params.min_speed; n],
            };
            (pos, vec![alt; n], heading, speed, vec![0.0; n])
        }
    };
    let mut sim = Simulation::new(target.clone(), params, pos, z, heading, speed, depart);
    if matches!(opts.start, Start::Random(_)) {
        sim.scatter_heights(AIR_HEIGHT_BAND, rng);
        sim.separate_heights(AIR_HEIGHT_BAND, rng);
    }
    Ok((sim, plan))
}

/// The highest altitude a bird climbing from the ground at most `climb_rate` (wingspans per
/// second, reached and shed at `vertical_accel`, wingspans per second squared) can reach and
/// level off at within `seconds`: w (T − w/a), or a T²/4 when it never reaches the full rate.
pub fn reachable_altitude(climb_rate: f64, vertical_accel: f64, seconds: f64) -> f64 {
    let (w, a, t) = (climb_rate, vertical_accel, seconds);
    if t >= 2.0 * w / a {
        w * (t - w / a)
    } else {
        a * t * t / 4.0
    }
}

/// Runs the simulation until convergence or the time limit, without the hand-over, sampling the
/// state at `fps` frames per second (frame k at k/fps s, linear interpolation between internal
/// steps). The flock's target is `target`, the steady flight's cruise `cruise`.
pub fn simulate(
    target: &TargetShape,
    fps: f64,
    cruise: &Cruise,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<InitiationRun> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::parameter("fps", "must be a positive number"));
    }
    let (mut sim, plan) = start_simulation(target, cruise, opts, rng)?;
    let n = target.len();
    let params = sim.params.clone();
    let dt = params.dt();
    let limit = opts.time_limit(fps);
    let tol = opts.tolerances();
    let mut run = InitiationRun {
        fps,
        pos: Vec::new(),
        z: Vec::new(),
        heading: Vec::new(),
        speed: Vec::new(),
        bank: Vec::new(),
        slot: Vec::new(),
        stats: InitiateStats {
            birds: n,
            steps: 0,
            seconds: 0.0,
            planned_seconds: plan.seconds,
            converged: false,
            min_distance: sim.min_distance(),
            max_turn_rate: 0.0,
            max_turn_accel: 0.0,
            max_accel: 0.0,
            max_bank: 0.0,
            max_stray: 0.0,
            last_liftoff: 0.0,
            leader_changes: 0,
            birds_in_slot: 0,
            field_per_eye: params.opts.perception.fov_per_eye,
        },
    };
    let mut prev: Vec<sim::BirdState> = (0..n).map(|i| sim.bird(i)).collect();
    let push = |run: &mut InitiationRun, a: &[sim::BirdState], b: &[sim::BirdState], u: f64| {
        run.pos
            .push(a.iter().zip(b).map(|(a, b)| a.pos.lerp(b.pos, u)).collect());
        run.z.push(
            a.iter()
                .zip(b)
                .map(|(a, b)| a.z + u * (b.z - a.z))
                .collect(),
        );
        run.heading.push(
            a.iter()
                .zip(b)
                .map(|(a, b)| {
                    sim::wrap_angle(a.heading + u * sim::wrap_angle(b.heading - a.heading))
                })
                .collect(),
        );
        run.speed.push(
            a.iter()
                .zip(b)
                .map(|(a, b)| a.speed + u * (b.speed - a.speed))
                .collect(),
        );
        run.bank.push(
            a.iter()
                .zip(b)
                .map(|(a, b)| a.bank + u * (b.bank - a.bank))
                .collect(),
        );
    };
    push(&mut run, &prev, &prev, 0.0);
    let total = (limit / dt).ceil() as u64;
    progress.start("initiate", total);
    let mut in_formation_since: Option<f64> = None;
    let mut converged = false;
    let mut liftoff_done = sim.all_airborne();
    let mut cur: Vec<sim::BirdState> = prev.clone();
    while sim.time < limit {
        sim.step();
        for (i, c) in cur.iter_mut().enumerate() {
            *c = sim.bird(i);
        }
        // Limits of the motion, per internal step.
        for (a, b) in prev.iter().zip(&cur) {
            let s = &mut run.stats;
            s.max_turn_rate = s.max_turn_rate.max(b.turn_rate.abs());
            s.max_turn_accel = s.max_turn_accel.max((b.turn_rate - a.turn_rate).abs() / dt);
            s.max_accel = s.max_accel.max((b.speed - a.speed).abs() / dt);
            s.max_bank = s.max_bank.max(b.bank.abs());
        }
        // Output samples between the previous and this internal step.
        let t0 = sim.time - dt;
        loop {
            let k = run.pos.len();
            let tk = k as f64 / fps;
            if tk > sim.time + 1e-9 {
                break;
            }
            let u = ((tk - t0) / dt).clamp(0.0, 1.0);
            push(&mut run, &prev, &cur, u);
        }
        std::mem::swap(&mut prev, &mut cur);
        if sim.steps % params.opts.substeps as usize != 0 {
            continue;
        }
        run.stats.min_distance = run.stats.min_distance.min(sim.min_distance());
        if !liftoff_done && sim.all_airborne() {
            liftoff_done = true;
            run.stats.last_liftoff = sim.time;
        }
        if liftoff_done && sim.steps % (8 * params.opts.substeps as usize) == 0 {
            run.stats.max_stray = run.stats.max_stray.max(sim.stray_distance());
        }
        if sim.in_formation(&tol) {
            let since = *in_formation_since.get_or_insert(sim.time);
            if sim.time - since >= opts.hold - 1e-9 {
                converged = true;
            }
        } else {
            in_formation_since = None;
        }
        if sim.steps % 256 == 0 {
            progress.advance(256 * params.opts.substeps as u64);
        }
        if converged {
            break;
        }
    }
    progress.finish();
    run.slot = sim.flock.slot.clone();
    run.stats.steps = run.pos.len() - 1;
    run.stats.seconds = sim.time;
    run.stats.converged = converged;
    run.stats.leader_changes = sim.leader_changes;
    run.stats.birds_in_slot = sim.birds_in_slot(opts.tolerance);
    Ok(run)
}

/// The target shape and cruise of a steady flight (the leader's heading and speed in the first
/// frame, the file's wingspan).
pub fn steady_target(steady: &Animation) -> Result<(TargetShape, Cruise)> {
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
    Ok((
        target,
        Cruise {
            heading,
            speed,
            wingspan_m: steady.wingspan_m,
        },
    ))
}

/// §6 initiation into the first key shape of `steady`: the combined animation (an `initiation`
/// stage, then the steady frames moved to the cruise altitude and translated so the hand-over
/// has no jump) and its statistics. A flock that does not converge within the time limit is
/// [`Error::NotConverged`].
pub fn initiate(
    steady: &Animation,
    opts: &InitiateOptions,
    rng: &mut impl Rng,
    progress: &dyn Progress,
) -> Result<(Animation, InitiateStats)> {
    check_steady(steady, Path::new("steady flight"))?;
    opts.validate()?;
    let frames_limit = ((opts.time_limit(steady.fps) * steady.fps).ceil() as usize).max(1);
    check_size(steady.birds, steady.frames.len(), frames_limit)?;
    let (target, cruise) = steady_target(steady)?;
    let run = simulate(&target, steady.fps, &cruise, opts, rng, progress)?;
    if !run.stats.converged {
        return Err(Error::NotConverged(format!(
            "the flock did not converge into the key shape within {:.0} s of flight ({} of {} birds within {} wingspans of their slots, last lift-off at {:.1} s); the time limit is the smaller of initiate.max_time and initiate.max_steps / fps",
            opts.time_limit(steady.fps),
            run.stats.birds_in_slot,
            run.stats.birds,
            opts.tolerance,
            run.stats.last_liftoff
        )));
    }
    hand_over(steady, &run, opts)
}

/// Refuses an initiation that could hold more than [`crate::limits::MAX_BIRD_FRAMES`]
/// bird-frames in memory: `birds` × (`steady_frames` + `max_steps`), every step being kept for the
/// output (refused up front instead of exhausting memory).
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
                "initiate.max_steps",
                format!(
                    "{birds} birds × ({max_steps} steps{plus}) could be more than {} bird-frames in memory; lower initiate.max_steps to at most {}",
                    crate::limits::MAX_BIRD_FRAMES,
                    (crate::limits::MAX_BIRD_FRAMES / birds.max(1)).saturating_sub(steady_frames)
                ),
            ))
        }
    }
}

/// Joins a converged run to the steady flight: birds are renumbered by their final slot, the last
/// `hold` seconds of the initiation are blended (smoothstep) into the backward extrapolation of the
/// steady flight's first frame, and the steady frames are translated (horizontally, and up to the
/// cruise altitude) and delayed to follow on. Every frame gets a `bank`: the simulation's in the
/// initiation, the coordinated-turn bank of the steady flight's own turns after it.
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
    let alt = opts.cruise_altitude;
    let g = GRAVITY_M_S2 / steady.wingspan_m;
    let steady_bank = steady_banks(steady, g, opts.max_roll_rate, opts.roll_lag);
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
            bank: Some(vec![0.0; n]),
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
            let v = run.speed[t][b] * (1.0 - w) + f0.speed[s] * w;
            fr.x[s] = p.x;
            fr.y[s] = p.y;
            fr.z[s] = run.z[t][b] * (1.0 - w) + (f0.z[s] + alt) * w;
            fr.heading[s] = h;
            fr.speed[s] = v;
            if let Some(bank) = fr.bank.as_mut() {
                bank[s] = run.bank[t][b] * (1.0 - w) + steady_bank[0][s] * w;
            }
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
    for (f, bank) in steady.frames.iter().zip(steady_bank) {
        let mut g = f.clone();
        g.t = t_start + (f.t - t0);
        for s in 0..n {
            if let (Some(x), Some(y)) = (g.x.get_mut(s), g.y.get_mut(s)) {
                *x += shift.x;
                *y += shift.y;
            }
            if let Some(z) = g.z.get_mut(s) {
                *z += alt;
            }
        }
        g.bank = Some(bank);
        frames.push(g);
    }
    let mut out = Animation::new(opts.seed, fps, steady.wingspan_m, n);
    out.species = steady.species.clone();
    out.flight = steady.flight;
    out.savings_model = steady.savings_model.clone();
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
    // The steady flight's feasible ξ ranges stay with its key shapes (plot power draws them).
    out.xi_ranges = steady.xi_ranges.clone();
    out.frames = frames;
    // Closest approach (3-D) in the written initiation frames (after the blend).
    let mut stats = run.stats.clone();
    stats.min_distance = out.frames[..offset]
        .iter()
        .map(|f| {
            let pts: Vec<DVec3> = (0..n).map(|i| DVec3::new(f.x[i], f.y[i], f.z[i])).collect();
            sim::min_pair_distance(&pts)
        })
        .fold(stats.min_distance, f64::min);
    Ok((out, stats))
}

/// The bank of every bird in every steady frame: the coordinated-turn bank tan φ = v ω / g of the
/// steady flight's own turns (ω from the headings of neighbouring frames, g in wingspans/s²),
/// followed with the roll lag and roll-rate limit from a level start. Straight flight gives 0.
pub fn steady_banks(
    steady: &Animation,
    g: f64,
    max_roll_rate: f64,
    roll_lag: f64,
) -> Vec<Vec<f64>> {
    let n = steady.birds;
    let fr = &steady.frames;
    let mut out = Vec::with_capacity(fr.len());
    let mut phi = vec![0.0; n];
    for k in 0..fr.len() {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(fr.len() - 1));
        let dt = fr[b].t - fr[a].t;
        for (s, phi) in phi.iter_mut().enumerate() {
            let w = if dt > 0.0 {
                sim::wrap_angle(fr[b].heading[s] - fr[a].heading[s]) / dt
            } else {
                0.0
            };
            let target = (fr[k].speed[s] * w / g).atan();
            if k == 0 {
                *phi = 0.0;
            } else {
                let h = fr[k].t - fr[k - 1].t;
                let rate = ((target - *phi) / roll_lag).clamp(-max_roll_rate, max_roll_rate);
                // An exact step to the target when the lag would overshoot it.
                let next = *phi + rate * h;
                *phi = if (next - target) * (*phi - target) < 0.0 {
                    target
                } else {
                    next
                };
            }
        }
        out.push(phi.clone());
    }
    out
}
