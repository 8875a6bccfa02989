//! The §6 simulation in physical time. The paper's rules are decisions a bird takes once per
//! *reaction time* τ (a fixed number of seconds, independent of the output frame rate); between
//! decisions the bird's motion is integrated with a fixed internal step `dt` (τ = `substeps` · dt).
//! Output frames are samples of this one simulation, so the same seed gives the same take-off at
//! any output frame rate.
//!
//! With assigned slots (the default, [`super::InitiateOptions::assign_slots`]) every bird has its slot from
//! the start ([`assign_slots`]) and flies the final approach in the formation frame
//! (`Simulation::settle`); the paper's correspondence below applies otherwise.
//!
//! Each decision: every departed bird perceives the departed flock as it was (Jacobi update), in
//! the horizontal plane; it chooses its reference bird and side, derives its target position
//! from the correspondence with the target shape and asks for a turn rate (eq. 6 as a rate,
//! ω = α Δd / (max(r, 1) τ)) and a speed (eq. 5, with the predicted reference position
//! P_j + v_j τ d_j). Short-range collision avoidance, in 3-D, may override the turn.
//!
//! Between decisions every bird *flies* what it asked for, smoothly:
//! - turn rate ω follows the request with a lag, ω̇ = clamp((ω* − ω)/τ_ω, ±ω̇_max), |ω| ≤ ω_max;
//! - acceleration a follows (v* − v)/τ_v (within ±a_max) with a bounded jerk, so speed never
//!   flips between speeding up and slowing down from one frame to the next;
//! - bank is the coordinated turn, tan φ* = v ω / g (g in wingspans/s²), reached with a lag and
//!   a bounded roll rate;
//! - climb rate w follows min(w_max, √(2 a_z Δz)) towards the cruise altitude with |ẇ| ≤ a_z.
//!
//! A bird on the ground waits for its departure time, then runs straight ahead, accelerating
//! (with the same jerk limit) to its lift-off speed; only then is it airborne and do the paper's
//! rules act on it. Waiting birds are not part of the flock (not perceived, not followed).
//!
//! Units: wingspans, seconds, radians (speeds wingspans/s, turn rates rad/s). Neighbour queries go
//! through a uniform grid ([`Grid`]): perception within the visual range, avoidance within its
//! range. Decisions of large flocks are computed in parallel; every decision reads only the
//! previous state, so the result does not depend on the number of threads.

use glam::{DVec2, DVec3};

use super::perception::{bearing, choose_reference, direction, right_of, Perceiver};
use super::target::{Side, TargetShape};

/// Collision avoidance ignores flockmates whose speed relative to the bird is below this
/// fraction of the cruise speed (unless they are already closer than the avoidance distance).
pub const AVOID_MIN_RELATIVE_SPEED: f64 = 0.08;

/// Collision avoidance scores a candidate turn rate by the heading it gives after this long,
/// seconds.
pub const AVOID_COMMIT: f64 = 0.3;

/// Parameters of the drives, actions and flight dynamics of one run: the options themselves
/// (every pass-through value is read from [`Self::opts`]) and the values derived from them for a
/// cruise and a take-off plan (built by [`super::InitiateOptions::plan_params`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StepParams {
    /// The options of the initiation, as given but for the visual field, widened to the shape's
    /// when [`super::InitiateOptions::widen_field`] (shared: a step copies its parameters
    /// cheaply).
    pub opts: std::sync::Arc<super::InitiateOptions>,
    /// |K| of eq. (5), per √wingspan (the take-off plan's).
    pub k: f64,
    /// Minimum flight speed (lift-off speed), wingspans per second.
    pub min_speed: f64,
    /// Maximum flight speed, wingspans per second.
    pub max_speed: f64,
    /// Cruise heading, radians clockwise from +y.
    pub cruise_heading: f64,
    /// Cruise speed, wingspans per second.
    pub cruise_speed: f64,
    /// Largest climb (and descent) rate, scaled by the plan's drive, wingspans per second.
    pub climb_rate: f64,
    /// Largest vertical acceleration, scaled by the plan's drive, wingspans per second squared.
    pub vertical_accel: f64,
    /// Gravity, wingspans per second squared (9.81 m/s² / wingspan in metres).
    pub gravity: f64,
    /// Acceleration of the take-off run, scaled by the plan's drive, wingspans per second
    /// squared.
    pub run_accel: f64,
    /// A kept reference hidden for at most this many decisions is kept all the same.
    pub reference_memory: u32,
    /// Beyond this distance eq. (5)'s √|r − v_j τ| grows linearly (catch-up), wingspans (the
    /// take-off plan's).
    pub catchup_distance: f64,
    /// Speed of the leader while flockmates are still on the ground, wingspans per second.
    pub gather_speed: f64,
    /// Final approach: time constant of the slot error across the formation, divided by the
    /// plan's drive, seconds.
    pub approach_time: f64,
    /// Final approach: deceleration the closing speed on the slot is braked with, scaled by the
    /// plan's drive, wingspans per second squared.
    pub approach_brake: f64,
}

impl StepParams {
    /// The integration step, seconds: τ / substeps.
    pub fn dt(&self) -> f64 {
        self.opts.reaction_time / self.opts.substeps.max(1) as f64
    }
}

/// A bird claims a slot already held by a visible bird only when it is nearer the slot's target
/// by this much, wingspans.
pub const SLOT_CLAIM_MARGIN: f64 = 1.0;

/// A bird this close to its target holds its slot against a claimant at any distance, wingspans
/// (the separation drive's distance threshold only lets birds far apart share a reference while
/// neither is in the slot yet).
pub const SETTLED_DISTANCE: f64 = 1.0;

/// Collision avoidance yields to the shape's geometry between two birds both closer than this
/// to their own slots, wingspans: their threshold is [`YIELD_FRACTION`] of their slots' distance
/// (at least [`YIELD_FLOOR`]) when that is below the avoidance distance.
pub const YIELD_DISTANCE: f64 = 3.0;

/// Fraction of two slots' distance that two birds settling into them keep apart.
pub const YIELD_FRACTION: f64 = 0.5;

/// Least avoidance threshold between two birds settling into their slots, wingspans.
pub const YIELD_FLOOR: f64 = 0.35;

/// The final approach's funnel: a bird `FUNNEL_SLOPE` times its sideways error (beyond
/// [`FUNNEL_WIDTH`]) behind or ahead of its slot closes along the heading no farther.
pub const FUNNEL_SLOPE: f64 = 1.5;

/// The funnel's largest distance behind or ahead of the slot, wingspans.
pub const FUNNEL_MAX: f64 = 2.0;

/// Sideways error within which a bird closes on its slot along the heading freely, wingspans.
pub const FUNNEL_WIDTH: f64 = 0.25;

/// Separation drive: two birds predicted to come closer than this (3-D) are pushed apart,
/// wingspans.
pub const SEPARATION_DISTANCE: f64 = 0.5;

/// Separation drive between two birds with slots: at most this fraction of their slots' distance.
pub const SEPARATION_FRACTION: f64 = 0.7;

/// Separation drive: look-ahead of the predicted closest approach, seconds.
pub const SEPARATION_HORIZON: f64 = 1.0;

/// Separation drive: sideways speed away from a bird at contact, wingspans per second.
pub const SEPARATION_SPEED: f64 = 4.0;

/// Heading error from which a bird asks for less speed (so it turns tighter), radians (45°).
pub const TURN_SLOW_FROM: f64 = std::f64::consts::FRAC_PI_4;

/// Heading error at which a bird asks for the minimum speed, radians (135°).
pub const TURN_SLOW_TO: f64 = 3.0 * std::f64::consts::FRAC_PI_4;

/// Height between the two layers of birds away from their slots, wingspans.
pub const LAYER_HEIGHT: f64 = 0.6;

/// Birds closer to their slots than this fly at the cruise altitude; from twice it on in their
/// layer (smoothstep in between), wingspans.
pub const LAYER_MERGE: f64 = 1.0;

/// Height offset, wingspans, of a bird in layer `layer` (in units of [`LAYER_HEIGHT`]) that is
/// `slot_err` wingspans from its slot: none within [`LAYER_MERGE`], all of it from twice that,
/// a smoothstep in between.
fn layer_offset(layer: f64, slot_err: f64) -> f64 {
    let u = ((slot_err - LAYER_MERGE) / LAYER_MERGE).clamp(0.0, 1.0);
    layer * LAYER_HEIGHT * u * u * (3.0 - 2.0 * u)
}

/// Width of a take-off run's lane: a bird on the ground leaves only after every bird ahead of it
/// closer than this across the heading, wingspans.
pub const RUN_LANE: f64 = 1.5;

/// Least time between the departures of two birds in one run lane, seconds.
pub const RUN_GAP: f64 = 0.2;

/// An airborne start's gathering leader flies at the gathering speed while a flockmate's heading
/// is more than this far off the cruise heading (still turning round), radians (90°).
pub const AIR_GATHER_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

/// An airborne start's leader is at most this far across the cruise heading from the flock's
/// middle bird, wingspans. The middle half of a 300-bird start region is 39 wingspans wide, and a
/// leader 17 wingspans off the middle left the birds on the far side 56 wingspans across from it,
/// level with it, and 24 wingspans from every slot before they had moved (docs/initiation.md).
pub const AIR_LEADER_OFFSET: f64 = 8.0;

/// An airborne start's vertical separation: the altitude offset a bird asks for, away from a
/// flockmate predicted to come closer than the separation distance, at contact, wingspans.
pub const VERTICAL_SEPARATION: f64 = 1.0;

/// How far ahead an airborne start's heights are checked against a dry run of the turns, s.
pub const AIR_PREDICT_SECONDS: f64 = 4.5;

/// Birds of an airborne start that the dry run brings this close horizontally are put at
/// different heights, wingspans.
pub const AIR_PREDICT_MISS: f64 = 1.0;

/// The height difference an airborne start asks between birds whose turns cross, wingspans.
pub const AIR_LAYER_GAP: f64 = 0.8;

/// Draws of a bird's start height before the best is kept.
pub const AIR_HEIGHT_DRAWS: usize = 40;

/// Samples of the predicted arcs over the separation horizon (airborne starts).
pub const ARC_SAMPLES: usize = 20;

/// Flocks at least this large decide in parallel (one thread per core).
pub const PARALLEL_MIN_BIRDS: usize = 128;

/// Where a bird is in its take-off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// At rest on the ground, waiting for its departure time.
    Waiting,
    /// Running along the ground to lift-off speed.
    Running,
    /// Airborne: the paper's rules act on it.
    Airborne,
}

/// What one bird asks for until the next decision.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Decision {
    /// Requested turn rate, radians per second.
    turn_rate: f64,
    /// Requested speed, wingspans per second.
    speed: f64,
    /// Requested altitude offset, wingspans.
    alt_offset: f64,
    reference: Option<usize>,
    side: Option<Side>,
    branch: Option<usize>,
    unseen: u32,
}

/// The state of every bird (world frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Flock {
    /// Horizontal positions, wingspans.
    pub pos: Vec<DVec2>,
    /// Altitudes above the ground (`z`), wingspans.
    pub z: Vec<f64>,
    /// Climb rates, wingspans per second.
    pub climb: Vec<f64>,
    /// Headings, radians clockwise from +y.
    pub heading: Vec<f64>,
    /// Turn rates, radians per second (positive: turning right).
    pub turn_rate: Vec<f64>,
    /// Rates of change of the turn rates, radians per second squared.
    pub turn_accel: Vec<f64>,
    /// Horizontal speeds, wingspans per second.
    pub speed: Vec<f64>,
    /// Accelerations, wingspans per second squared.
    pub accel: Vec<f64>,
    /// Bank angles, radians (right wing down positive).
    pub bank: Vec<f64>,
    /// Roll rates, radians per second.
    pub roll_rate: Vec<f64>,
    /// Take-off phase of each bird.
    pub phase: Vec<Phase>,
    /// Departure time of each bird, seconds.
    pub depart: Vec<f64>,
    /// Requested turn rate (rad/s) and speed (wingspans/s) of each bird, from its last decision.
    pub request: Vec<(f64, f64)>,
    /// Requested altitude offset from the cruise altitude (collision avoidance), wingspans.
    pub alt_offset: Vec<f64>,
    /// Reference bird of each bird (`None` for the leader and for lost birds).
    pub reference: Vec<Option<usize>>,
    /// Side of each bird relative to its reference bird.
    pub side: Vec<Option<Side>>,
    /// The follower slot of its reference's slot each bird aims for (where the target tree
    /// branches, a reference slot has several).
    pub branch: Vec<Option<usize>>,
    /// Decisions since each bird last saw its reference bird (0: visible now).
    pub unseen: Vec<u32>,
    /// Slot of the target shape each bird corresponds to (§6.2.1), if matched.
    pub slot: Vec<Option<usize>>,
    /// The leader: the front-most departed bird along the cruise heading.
    pub leader: usize,
}

/// A uniform grid of square cells over the horizontal plane, for neighbour queries.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    cell: f64,
    origin: DVec2,
    nx: usize,
    ny: usize,
    /// Start of each cell's run in `items` (prefix sums; length nx·ny + 1).
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Grid {
    /// Rebuilds the grid over the points `pos[i]` for the `members` (cells of `cell` wingspans).
    pub fn build(&mut self, pos: &[DVec2], members: &[usize], cell: f64) {
        self.cell = cell.max(1e-6);
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &i in members {
            lo = lo.min(pos[i]);
            hi = hi.max(pos[i]);
        }
        if members.is_empty() {
            lo = DVec2::ZERO;
            hi = DVec2::ZERO;
        }
        self.origin = lo;
        // Cap the cell count so a bird far away cannot make the grid huge.
        let span = (hi - lo) / self.cell;
        let cap = (4 * members.len()).max(16) as f64;
        let scale = ((span.x + 1.0) * (span.y + 1.0) / cap).max(1.0).sqrt();
        self.cell *= scale;
        self.nx = ((hi.x - lo.x) / self.cell).floor() as usize + 1;
        self.ny = ((hi.y - lo.y) / self.cell).floor() as usize + 1;
        let cells = self.nx * self.ny;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &i in members {
            let c = self.cell_of(pos[i]);
            self.start[c + 1] += 1;
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(members.len(), 0);
        let mut fill = self.start.clone();
        for &i in members {
            let c = self.cell_of(pos[i]);
            self.items[fill[c]] = i;
            fill[c] += 1;
        }
    }

    fn cell_of(&self, p: DVec2) -> usize {
        let cx = (((p.x - self.origin.x) / self.cell).floor().max(0.0) as usize).min(self.nx - 1);
        let cy = (((p.y - self.origin.y) / self.cell).floor().max(0.0) as usize).min(self.ny - 1);
        cy * self.nx + cx
    }

    /// Members within `radius` of `p` (horizontal distance), in increasing index order.
    pub fn within(&self, pos: &[DVec2], p: DVec2, radius: f64, out: &mut Vec<usize>) {
        out.clear();
        if self.nx == 0 {
            return;
        }
        let r2 = radius * radius;
        let lo = ((p - DVec2::splat(radius) - self.origin) / self.cell).floor();
        let hi = ((p + DVec2::splat(radius) - self.origin) / self.cell).floor();
        if hi.x < 0.0 || hi.y < 0.0 || lo.x >= self.nx as f64 || lo.y >= self.ny as f64 {
            return;
        }
        let x0 = lo.x.max(0.0) as usize;
        let y0 = lo.y.max(0.0) as usize;
        let x1 = (hi.x as usize).min(self.nx - 1);
        let y1 = (hi.y as usize).min(self.ny - 1);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let c = cy * self.nx + cx;
                for &i in &self.items[self.start[c]..self.start[c + 1]] {
                    if (pos[i] - p).length_squared() <= r2 {
                        out.push(i);
                    }
                }
            }
        }
        out.sort_unstable();
    }
}

/// The simulation: target shape, parameters, flock and scratch buffers.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Target shape (slot tree).
    pub target: TargetShape,
    /// Parameters.
    pub params: StepParams,
    /// Current state.
    pub flock: Flock,
    /// Integration steps done so far.
    pub steps: usize,
    /// Simulated time, seconds.
    pub time: f64,
    /// Number of times the leader changed.
    pub leader_changes: usize,
    /// Birds that have left their place on the ground (running or airborne), in index order.
    departed: Vec<usize>,
    /// Birds by the slot they take, for this decision: slot `s` holds
    /// `holders[holder_start[s]..holder_start[s + 1]]` (increasing bird index).
    holders: Vec<usize>,
    holder_start: Vec<usize>,
    perceiver: Perceiver,
    visible: Vec<usize>,
    near: Vec<usize>,
    grid: Grid,
    vel: Vec<DVec3>,
    dir: Vec<DVec2>,
    decisions: Vec<Decision>,
    /// Slot positions (leader frame, cruise heading) for the current decision.
    slot_pos: Vec<DVec2>,
    /// Horizontal velocity of the leader for the current decision, wingspans per second.
    lead_vel: DVec2,
    /// Distance of each bird from its slot for the current decision (∞ when unmatched).
    slot_err: Vec<f64>,
    /// With assigned slots, the bird of every slot.
    bird_of_slot: Vec<usize>,
    /// With assigned slots, each bird's layer while away from its slot: +½ or −½, alternating
    /// across the formation.
    layer: Vec<f64>,
    next_reference: Vec<Option<usize>>,
    next_side: Vec<Option<Side>>,
    next_branch: Vec<Option<usize>>,
    next_unseen: Vec<u32>,
}

/// The state of a bird a flight dynamics step starts from and gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BirdState {
    /// Horizontal position, wingspans.
    pub pos: DVec2,
    /// Altitude, wingspans.
    pub z: f64,
    /// Climb rate, wingspans per second.
    pub climb: f64,
    /// Heading, radians.
    pub heading: f64,
    /// Turn rate, radians per second.
    pub turn_rate: f64,
    /// Rate of change of the turn rate, radians per second squared.
    pub turn_accel: f64,
    /// Speed, wingspans per second.
    pub speed: f64,
    /// Acceleration, wingspans per second squared.
    pub accel: f64,
    /// Bank, radians.
    pub bank: f64,
    /// Roll rate, radians per second.
    pub roll_rate: f64,
}

/// `x` moved towards `target` by at most `max_step`.
fn approach(x: f64, target: f64, max_step: f64) -> f64 {
    x + (target - x).clamp(-max_step, max_step)
}

/// One integration step of `dt` seconds of an airborne bird asking for turn rate `want_turn`
/// (rad/s) and speed `want_speed` (wingspans/s), climbing towards the cruise altitude. The
/// limits of [`StepParams`] hold by construction: |Δω| ≤ ω̇_max dt, |Δa| ≤ j_max dt,
/// |a| ≤ a_max, |Δφ| ≤ p_max dt, |Δw| ≤ a_z dt.
pub fn fly(s: &BirdState, want_turn: f64, want_speed: f64, p: &StepParams, dt: f64) -> BirdState {
    fly_at(s, want_turn, want_speed, p.opts.cruise_altitude, p, dt)
}

/// As [`fly`], climbing towards altitude `want_z` (wingspans) instead of the cruise altitude.
pub fn fly_at(
    s: &BirdState,
    want_turn: f64,
    want_speed: f64,
    want_z: f64,
    p: &StepParams,
    dt: f64,
) -> BirdState {
    let mut n = *s;
    // Turn rate: it follows the request with a lag, (ω* − ω)/τ_ω, its change bounded and
    // itself changing at a bounded rate (so the turn rate cannot flip sign from one frame to the
    // next); near the request the change is the braking one, ω̇² = 2 j |ω* − ω|, so it arrives
    // without overshoot.
    let w_req = want_turn.clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate);
    let err = w_req - s.turn_rate;
    let brake = (2.0 * p.opts.max_turn_jerk * err.abs()).sqrt();
    let a_turn = (err / p.opts.turn_lag)
        .clamp(-p.opts.max_turn_accel, p.opts.max_turn_accel)
        .clamp(-brake, brake);
    n.turn_accel = approach(s.turn_accel, a_turn, p.opts.max_turn_jerk * dt);
    n.turn_rate =
        (s.turn_rate + n.turn_accel * dt).clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate);
    // Speed: the acceleration follows (v* − v)/τ_v with bounded jerk. Near the speed limits the
    // wanted acceleration is the braking one (a² = 2 j Δv), so the bound is met without a kink.
    let v_req = want_speed.clamp(p.min_speed, p.max_speed);
    let a_lag = (v_req - s.speed) / p.opts.speed_lag;
    let room_up = (p.max_speed - s.speed).max(0.0);
    let room_down = (s.speed - p.min_speed).max(0.0);
    let a_want = a_lag
        .clamp(-p.opts.max_accel, p.opts.max_accel)
        .min((2.0 * p.opts.max_jerk * room_up).sqrt())
        .max(-(2.0 * p.opts.max_jerk * room_down).sqrt());
    n.accel =
        approach(s.accel, a_want, p.opts.max_jerk * dt).clamp(-p.opts.max_accel, p.opts.max_accel);
    n.speed = (s.speed + n.accel * dt).clamp(p.min_speed.min(s.speed), p.max_speed.max(s.speed));
    n.heading = wrap_angle(s.heading + n.turn_rate * dt);
    // Coordinated turn: tan φ = v ω / g.
    // The roll rate follows (φ* − φ)/τ_φ with a bounded roll acceleration, braking near φ*, so
    // the bank cannot swing back and forth from frame to frame.
    let phi_t = (n.speed * n.turn_rate / p.gravity).atan();
    let e = phi_t - s.bank;
    let brake = (2.0 * p.opts.max_roll_accel * e.abs()).sqrt();
    let p_want = (e / p.opts.roll_lag)
        .clamp(-p.opts.max_roll_rate, p.opts.max_roll_rate)
        .clamp(-brake, brake);
    n.roll_rate = approach(s.roll_rate, p_want, p.opts.max_roll_accel * dt);
    n.bank = s.bank + n.roll_rate * dt;
    // Climb: towards the cruise altitude, arriving with zero climb rate.
    let dz = want_z - s.z;
    let w_t = (2.0 * p.vertical_accel * dz.abs()).sqrt().min(p.climb_rate) * dz.signum();
    n.climb = approach(s.climb, w_t, p.vertical_accel * dt);
    n.z = s.z + 0.5 * (s.climb + n.climb) * dt;
    n.pos = s.pos + direction(n.heading) * (0.5 * (s.speed + n.speed) * dt);
    n
}

/// One integration step of a bird on its take-off run: straight ahead, level, accelerating at
/// the run acceleration (bounded jerk) until the lift-off speed.
pub fn run(s: &BirdState, p: &StepParams, dt: f64) -> BirdState {
    let mut n = *s;
    n.accel = approach(s.accel, p.run_accel, p.opts.max_jerk * dt);
    n.speed = s.speed + n.accel * dt;
    n.pos = s.pos + direction(s.heading) * (0.5 * (s.speed + n.speed) * dt);
    n
}

impl Simulation {
    /// A simulation starting from `pos`, `z`, `heading`, `speed` (wingspans, radians, wingspans
    /// per second), each bird leaving at `depart[i]` seconds (a bird that starts with a speed of
    /// at least the minimum speed, or above the ground, is airborne from the start; one at rest
    /// on the ground waits, then runs to lift-off). The leader is the front-most departed bird.
    pub fn new(
        target: TargetShape,
        params: StepParams,
        pos: Vec<DVec2>,
        z: Vec<f64>,
        heading: Vec<f64>,
        speed: Vec<f64>,
        depart: Vec<f64>,
    ) -> Simulation {
        let n = pos.len();
        let phase: Vec<Phase> = (0..n)
            .map(|i| {
                if z[i] > 0.0 || speed[i] >= params.min_speed {
                    Phase::Airborne
                } else if depart[i] <= 0.0 {
                    Phase::Running
                } else {
                    Phase::Waiting
                }
            })
            .collect();
        let request = (0..n).map(|i| (0.0, speed[i])).collect();
        let mut sim = Simulation {
            target,
            params,
            flock: Flock {
                pos,
                z,
                climb: vec![0.0; n],
                heading,
                turn_rate: vec![0.0; n],
                turn_accel: vec![0.0; n],
                speed,
                accel: vec![0.0; n],
                bank: vec![0.0; n],
                roll_rate: vec![0.0; n],
                phase,
                depart,
                request,
                alt_offset: vec![0.0; n],
                reference: vec![None; n],
                side: vec![None; n],
                branch: vec![None; n],
                unseen: vec![0; n],
                slot: vec![None; n],
                leader: 0,
            },
            steps: 0,
            time: 0.0,
            leader_changes: 0,
            departed: Vec::new(),
            holders: Vec::new(),
            holder_start: Vec::new(),
            perceiver: Perceiver::new(),
            visible: Vec::new(),
            near: Vec::new(),
            grid: Grid::default(),
            vel: Vec::new(),
            dir: Vec::new(),
            decisions: Vec::new(),
            slot_pos: Vec::new(),
            lead_vel: DVec2::ZERO,
            slot_err: Vec::new(),
            bird_of_slot: Vec::new(),
            layer: Vec::new(),
            next_reference: vec![None; n],
            next_side: vec![None; n],
            next_branch: vec![None; n],
            next_unseen: vec![0; n],
        };
        if sim.params.opts.assign_slots && n > 0 {
            let offset = sim.airborne_start().then_some(AIR_LEADER_OFFSET);
            let (slot, leader) = assign_slots(
                &sim.target,
                &sim.flock.pos,
                sim.params.cruise_heading,
                offset,
            );
            sim.flock.leader = leader;
            // The departure times, earliest first, go to the birds by the depth of their slot
            // behind the leader's (the leader leaves first; the tails of the arms last).
            let mut times = sim.flock.depart.clone();
            times.sort_by(f64::total_cmp);
            let sl = sim.target.slots[sim.target.leader];
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| {
                let da = sim.target.slots[slot[a]] - sl;
                let db = sim.target.slots[slot[b]] - sl;
                (a != leader)
                    .cmp(&(b != leader))
                    .then(da.y.total_cmp(&db.y))
                    .then(da.x.abs().total_cmp(&db.x.abs()))
                    .then(a.cmp(&b))
            });
            for (k, &i) in order.iter().enumerate() {
                sim.flock.depart[i] = times[k];
            }
            // No bird runs into one still on the ground ahead of it: front to back, a bird leaves
            // after every bird ahead of it within a run lane (a wingspan and a half across).
            let mut front: Vec<usize> = (0..n).collect();
            let dc = direction(sim.params.cruise_heading);
            let rc = right_of(sim.params.cruise_heading);
            let f = &sim.flock;
            front.sort_by(|&a, &b| {
                f.pos[b]
                    .dot(dc)
                    .total_cmp(&f.pos[a].dot(dc))
                    .then(a.cmp(&b))
            });
            for (k, &i) in front.iter().enumerate() {
                if sim.flock.phase[i] == Phase::Airborne {
                    continue;
                }
                let f = &sim.flock;
                let after = front[..k]
                    .iter()
                    .filter(|&&a| {
                        f.phase[a] != Phase::Airborne
                            && (f.pos[a] - f.pos[i]).dot(rc).abs() < RUN_LANE
                    })
                    .map(|&a| f.depart[a] + RUN_GAP)
                    .fold(f.depart[i], f64::max);
                sim.flock.depart[i] = after;
            }
            for i in 0..n {
                let t = sim.flock.depart[i];
                if sim.flock.phase[i] != Phase::Airborne {
                    sim.flock.phase[i] = if t <= 0.0 {
                        Phase::Running
                    } else {
                        Phase::Waiting
                    };
                }
            }
            sim.bird_of_slot = vec![0; n];
            for (i, &s) in slot.iter().enumerate() {
                sim.bird_of_slot[s] = i;
            }
            let mut across: Vec<usize> = (0..n).collect();
            let ts = &sim.target.slots;
            across.sort_by(|&a, &b| ts[slot[a]].x.total_cmp(&ts[slot[b]].x).then(a.cmp(&b)));
            sim.layer = vec![0.0; n];
            for (k, &i) in across.iter().enumerate() {
                sim.layer[i] = if k % 2 == 0 { 0.5 } else { -0.5 };
            }
            sim.flock.slot = slot.iter().map(|&s| Some(s)).collect();
            sim.update_departed();
        } else {
            sim.update_departed();
            let dc = direction(sim.params.cruise_heading);
            sim.flock.leader = sim.front_most(dc).unwrap_or(0);
            sim.match_slots();
        }
        sim
    }

    /// An airborne start scattered in height: each bird's layer offset is drawn uniformly
    /// within ±`band` wingspans (instead of the two layers ±[`LAYER_HEIGHT`]/2) and the bird
    /// starts at it (merging into the cruise altitude near its slot, as the layers do).
    pub fn scatter_heights(&mut self, band: f64, rng: &mut impl rand::Rng) {
        if band <= 0.0 || self.layer.len() != self.len() {
            return;
        }
        let b = band / LAYER_HEIGHT;
        for l in self.layer.iter_mut() {
            *l = rng.random_range(-b..=b);
        }
        let slots = self.slot_positions();
        for i in 0..self.len() {
            let Some(s) = self.flock.slot[i] else {
                continue;
            };
            if self.flock.phase[i] != Phase::Airborne {
                continue;
            }
            let e = (self.flock.pos[i] - slots[s]).length();
            self.flock.z[i] += layer_offset(self.layer[i], e);
        }
    }

    /// An airborne start's heights checked against the turning paths: a dry run of the first
    /// [`AIR_PREDICT_SECONDS`] (the birds turning round on their own circles, which neither a
    /// straight-line nor a current-arc prediction foresees) finds the pairs that come within
    /// [`AIR_PREDICT_MISS`] wingspans horizontally; each bird's height within ±`band` wingspans
    /// is then redrawn (up to [`AIR_HEIGHT_DRAWS`] times, keeping the best) until it is at least
    /// [`AIR_LAYER_GAP`] wingspans from every such partner drawn before it, so that birds whose
    /// turns cross pass above and below each other from the start.
    pub fn separate_heights(&mut self, band: f64, rng: &mut impl rand::Rng) {
        let n = self.len();
        if band <= 0.0 || self.layer.len() != n || n < 2 {
            return;
        }
        let mut dry = self.clone();
        let mut partners: Vec<Vec<usize>> = vec![Vec::new(); n];
        let (mut grid, mut near) = (Grid::default(), Vec::new());
        let all: Vec<usize> = (0..n).collect();
        while dry.time < AIR_PREDICT_SECONDS {
            dry.step();
            let f = &dry.flock;
            grid.build(&f.pos, &all, AIR_PREDICT_MISS);
            for i in 0..n {
                grid.within(&f.pos, f.pos[i], AIR_PREDICT_MISS, &mut near);
                for &k in &near {
                    if k < i && !partners[i].contains(&k) {
                        partners[i].push(k);
                        partners[k].push(i);
                    }
                }
            }
        }
        let b = band / LAYER_HEIGHT;
        let gap = AIR_LAYER_GAP / LAYER_HEIGHT;
        let slots = self.slot_positions();
        for (i, mates) in partners.iter().enumerate() {
            let before: Vec<usize> = mates.iter().copied().filter(|&k| k < i).collect();
            if before.is_empty() {
                continue;
            }
            let clear = |l: f64| {
                before
                    .iter()
                    .map(|&k| (self.layer[k] - l).abs())
                    .fold(f64::INFINITY, f64::min)
            };
            let mut best = (clear(self.layer[i]), self.layer[i]);
            for _ in 0..AIR_HEIGHT_DRAWS {
                if best.0 >= gap {
                    break;
                }
                let l = rng.random_range(-b..=b);
                let c = clear(l);
                if c > best.0 {
                    best = (c, l);
                }
            }
            let (old, new) = (self.layer[i], best.1);
            self.layer[i] = new;
            if let Some(s) = self.flock.slot[i] {
                let e = (self.flock.pos[i] - slots[s]).length();
                self.flock.z[i] += layer_offset(new - old, e);
            }
        }
    }

    /// Number of birds.
    pub fn len(&self) -> usize {
        self.flock.pos.len()
    }

    /// True when there are no birds.
    pub fn is_empty(&self) -> bool {
        self.flock.pos.is_empty()
    }

    fn update_departed(&mut self) {
        self.departed.clear();
        self.departed
            .extend((0..self.len()).filter(|&i| self.flock.phase[i] != Phase::Waiting));
    }

    /// The departed bird farthest along `dir` (ties to the lower index).
    fn front_most(&self, dir: DVec2) -> Option<usize> {
        let mut best: Option<usize> = None;
        for &i in &self.departed {
            if best.map_or(true, |b| {
                self.flock.pos[i].dot(dir) > self.flock.pos[b].dot(dir)
            }) {
                best = Some(i);
            }
        }
        best
    }

    /// True when every bird is airborne.
    pub fn all_airborne(&self) -> bool {
        self.flock.phase.iter().all(|&p| p == Phase::Airborne)
    }

    /// The state of bird `i`.
    pub fn bird(&self, i: usize) -> BirdState {
        let f = &self.flock;
        BirdState {
            pos: f.pos[i],
            z: f.z[i],
            climb: f.climb[i],
            heading: f.heading[i],
            turn_rate: f.turn_rate[i],
            turn_accel: f.turn_accel[i],
            speed: f.speed[i],
            accel: f.accel[i],
            bank: f.bank[i],
            roll_rate: f.roll_rate[i],
        }
    }

    fn set_bird(&mut self, i: usize, s: &BirdState) {
        let f = &mut self.flock;
        f.pos[i] = s.pos;
        f.z[i] = s.z;
        f.climb[i] = s.climb;
        f.heading[i] = s.heading;
        f.turn_rate[i] = s.turn_rate;
        f.turn_accel[i] = s.turn_accel;
        f.speed[i] = s.speed;
        f.accel[i] = s.accel;
        f.bank[i] = s.bank;
        f.roll_rate[i] = s.roll_rate;
    }

    /// §6.2.1 correspondence: the leader takes the leader slot; a bird whose reference bird is
    /// matched takes the slot that follows its reference's slot on its side (the one it aims for
    /// where the tree branches, else the first). Birds in cycles, with unmatched references, or
    /// on a full arm stay unmatched. Several birds may share a slot.
    pub fn match_slots(&mut self) {
        let f = &mut self.flock;
        let n = f.pos.len();
        // 0 = unknown, 1 = on the current walk, 2 = resolved.
        let mut state = vec![0u8; n];
        for s in f.slot.iter_mut() {
            *s = None;
        }
        if n == 0 {
            return;
        }
        f.slot[f.leader] = Some(self.target.leader);
        state[f.leader] = 2;
        let mut path = Vec::new();
        for start in 0..n {
            path.clear();
            let mut i = start;
            // Walk up the reference chain until a resolved bird, a cycle, or no reference.
            let base = loop {
                if state[i] == 2 {
                    break f.slot[i];
                }
                if state[i] == 1 {
                    break None;
                }
                state[i] = 1;
                path.push(i);
                match f.reference[i] {
                    Some(j) if j < n => i = j,
                    _ => break None,
                }
            };
            // Assign back down the walk.
            let mut s = base;
            for &b in path.iter().rev() {
                s = match (s, f.side[b]) {
                    (Some(sj), Some(side)) if f.reference[b].is_some() => {
                        let fl = self.target.followers(sj, side);
                        match f.branch[b] {
                            Some(c) if fl.contains(&c) => Some(c),
                            _ => fl.first().copied(),
                        }
                    }
                    _ => None,
                };
                f.slot[b] = s;
                state[b] = 2;
            }
        }
    }

    /// The target position of a follower of bird `j` at formation-frame `offset` (Δx right,
    /// Δy behind), one reaction time ahead: T = P_j + v_j τ d_j + Δx r_j − Δy d_j.
    fn target_point(&self, j: usize, offset: DVec2) -> DVec2 {
        let f = &self.flock;
        let d = self.dir_of(j);
        // Right of d = (sin θ, cos θ) is (cos θ, −sin θ).
        let r = DVec2::new(d.y, -d.x);
        f.pos[j] + d * (f.speed[j] * self.params.opts.reaction_time) + r * offset.x - d * offset.y
    }

    /// Flight direction of bird `j` (cached for the current decision).
    fn dir_of(&self, j: usize) -> DVec2 {
        match self.dir.get(j) {
            Some(d) if self.dir.len() == self.flock.pos.len() => *d,
            _ => direction(self.flock.heading[j]),
        }
    }

    /// Which follower slot of `j` on `side` bird `i` may take, if any. `j` must be matched (an
    /// unmatched bird gives no consistent target, and birds following each other in a cycle
    /// never reach the flock) and its slot must have a follower slot on that side (capacity: the
    /// tail of an arm has none); a follower slot is refused when a visible bird that already takes
    /// it is within the separation distance and nearer its target (separation drive, §6.2.2).
    /// Among the free ones, the bird keeps the one it holds, else takes the one whose target is
    /// nearest.
    fn acceptable(&self, i: usize, j: usize, side: Side, visible: &[usize]) -> Option<usize> {
        let f = &self.flock;
        let sj = f.slot[j]?;
        let mut best: Option<(f64, usize)> = None;
        for &c in self.target.followers(sj, side) {
            let t = self.target_point(j, self.target.offset(sj, c));
            let my = (f.pos[i] - t).length();
            // A bird that does not take the slot yet must be nearer than a holder by a margin to
            // claim it, so that birds at the tail of an arm do not trade places forever.
            let holds =
                f.reference[i] == Some(j) && f.side[i] == Some(side) && f.slot[i] == Some(c);
            let margin = if holds { 0.0 } else { SLOT_CLAIM_MARGIN };
            // Birds that take slot `c` (a short list, from the per-decision table), of those
            // the visible ones (`visible` is sorted).
            let holders = &self.holders[self.holder_start[c]..self.holder_start[c + 1]];
            let taken = holders.iter().any(|&k| {
                k != i
                    && visible.binary_search(&k).is_ok()
                    && f.reference[k] == Some(j)
                    && f.side[k] == Some(side)
                    && f.slot[k] == Some(c)
                    && ((f.pos[k] - f.pos[i]).length() < self.params.opts.separation_distance
                        || (f.pos[k] - t).length() < SETTLED_DISTANCE)
                    && (f.pos[k] - t).length() < my + margin
            });
            if taken {
                continue;
            }
            let score = if holds { f64::NEG_INFINITY } else { my };
            if best.map_or(true, |b| score < b.0) {
                best = Some((score, c));
            }
        }
        best.map(|b| b.1)
    }

    /// Side rule of §6.2.1 for bird `i` following `j`: the reference's side if it has one (it is
    /// matched to an arm, or has chosen a side itself), else by relative position.
    fn sides_for(&self, i: usize, j: usize) -> [Option<Side>; 2] {
        let f = &self.flock;
        let dj = self.dir_of(j);
        let geometric = if (f.pos[i] - f.pos[j]).dot(DVec2::new(dj.y, -dj.x)) > 0.0 {
            Side::Right
        } else {
            Side::Left
        };
        if j == f.leader {
            return [Some(geometric), Some(geometric.other())];
        }
        let own = match f.slot[j] {
            Some(sj) => self.target.side_of(sj),
            None => f.side[j],
        };
        [Some(own.unwrap_or(geometric)), None]
    }

    /// Advances the flock by one integration step (`dt` seconds); every `substeps`-th step
    /// starts with a decision of every airborne bird.
    pub fn step(&mut self) {
        let n = self.len();
        if n == 0 {
            return;
        }
        let p = self.params.clone();
        let dt = p.dt();
        if self.steps % p.opts.substeps.max(1) as usize == 0 {
            self.decide_all();
        }
        for i in 0..n {
            let s = self.bird(i);
            let next = match self.flock.phase[i] {
                Phase::Waiting => {
                    if self.time + 0.5 * dt >= self.flock.depart[i] {
                        self.flock.phase[i] = Phase::Running;
                        run(&s, &p, dt)
                    } else {
                        s
                    }
                }
                Phase::Running => {
                    let r = run(&s, &p, dt);
                    if r.speed >= p.min_speed {
                        self.flock.phase[i] = Phase::Airborne;
                        self.flock.request[i] = (0.0, r.speed);
                    }
                    r
                }
                Phase::Airborne => {
                    let (w, v) = self.flock.request[i];
                    let z = p.opts.cruise_altitude + self.flock.alt_offset[i];
                    fly_at(&s, w, v, z, &p, dt)
                }
            };
            self.set_bird(i, &next);
        }
        self.steps += 1;
        self.time = self.steps as f64 * dt;
    }

    /// One decision of every bird from the current state (Jacobi: all read the same state).
    fn decide_all(&mut self) {
        let n = self.len();
        let p = self.params.clone();
        self.update_departed();
        if self.departed.is_empty() {
            return;
        }
        let dc = direction(p.cruise_heading);
        // The leader is the front-most departed bird (with hysteresis against flip-flopping);
        // with assigned slots it is the one of the leader slot throughout.
        let lead = self.flock.leader;
        if let Some(front) = self.front_most(dc).filter(|_| !p.opts.assign_slots) {
            let lead_gone = self.flock.phase[lead] == Phase::Waiting;
            if front != lead
                && (lead_gone
                    || (self.flock.pos[front] - self.flock.pos[lead]).dot(dc)
                        > p.opts.leader_hysteresis)
            {
                self.flock.leader = front;
                self.leader_changes += 1;
                self.match_slots();
            }
        }
        self.build_holders();
        self.slot_pos = self.slot_positions();
        let lead = self.flock.leader;
        self.lead_vel = direction(self.flock.heading[lead]) * self.flock.speed[lead];
        let mut err = std::mem::take(&mut self.slot_err);
        err.clear();
        err.extend((0..n).map(|i| match self.flock.slot[i] {
            Some(s) if s < self.slot_pos.len() => (self.flock.pos[i] - self.slot_pos[s]).length(),
            _ => f64::INFINITY,
        }));
        self.slot_err = err;
        let mut vel = std::mem::take(&mut self.vel);
        vel.clear();
        vel.extend((0..n).map(|i| {
            let h = direction(self.flock.heading[i]) * self.flock.speed[i];
            DVec3::new(h.x, h.y, self.flock.climb[i])
        }));
        self.vel = vel;
        let mut dir = std::mem::take(&mut self.dir);
        dir.clear();
        dir.extend(self.flock.heading.iter().map(|&h| direction(h)));
        self.dir = dir;
        // One grid for perception and avoidance: cells of the avoidance range, perception
        // queries cover as many cells as the visual range needs.
        let mut grid = std::mem::take(&mut self.grid);
        let all: Vec<usize> = (0..n).collect();
        grid.build(
            &self.flock.pos,
            &all,
            p.opts.avoid_range.max(p.opts.visual_range / 4.0),
        );
        self.grid = grid;
        let mut decisions = std::mem::take(&mut self.decisions);
        decisions.clear();
        decisions.resize(n, Decision::default());
        let threads = if self.departed.len() >= PARALLEL_MIN_BIRDS {
            std::thread::available_parallelism().map_or(1, |t| t.get().min(8))
        } else {
            1
        };
        if threads <= 1 {
            let mut perceiver = std::mem::take(&mut self.perceiver);
            let mut visible = std::mem::take(&mut self.visible);
            let mut near = std::mem::take(&mut self.near);
            for (i, d) in decisions.iter_mut().enumerate() {
                if self.flock.phase[i] == Phase::Airborne {
                    *d = self.decide(i, &mut perceiver, &mut visible, &mut near);
                }
            }
            self.perceiver = perceiver;
            self.visible = visible;
            self.near = near;
        } else {
            let chunk = n.div_ceil(threads);
            let this = &*self;
            std::thread::scope(|scope| {
                for (c, out) in decisions.chunks_mut(chunk).enumerate() {
                    scope.spawn(move || {
                        let mut perceiver = Perceiver::new();
                        let mut visible = Vec::new();
                        let mut near = Vec::new();
                        for (k, d) in out.iter_mut().enumerate() {
                            let i = c * chunk + k;
                            if this.flock.phase[i] == Phase::Airborne {
                                *d = this.decide(i, &mut perceiver, &mut visible, &mut near);
                            }
                        }
                    });
                }
            });
        }
        let f = &mut self.flock;
        for (i, d) in decisions.iter().enumerate() {
            if f.phase[i] != Phase::Airborne {
                continue;
            }
            f.request[i] = (d.turn_rate, d.speed);
            f.alt_offset[i] = d.alt_offset;
            self.next_reference[i] = d.reference;
            self.next_side[i] = d.side;
            self.next_branch[i] = d.branch;
            self.next_unseen[i] = d.unseen;
        }
        for i in 0..n {
            if f.phase[i] != Phase::Airborne {
                self.next_reference[i] = None;
                self.next_side[i] = None;
                self.next_branch[i] = None;
                self.next_unseen[i] = 0;
            }
        }
        self.decisions = decisions;
        std::mem::swap(&mut f.reference, &mut self.next_reference);
        std::mem::swap(&mut f.side, &mut self.next_side);
        std::mem::swap(&mut f.branch, &mut self.next_branch);
        std::mem::swap(&mut f.unseen, &mut self.next_unseen);
        if !p.opts.assign_slots {
            self.match_slots();
        }
    }

    /// The table of birds by slot the decisions read (counting sort, O(N)).
    fn build_holders(&mut self) {
        let slots = self.target.len();
        self.holder_start.clear();
        self.holder_start.resize(slots + 1, 0);
        for s in self.flock.slot.iter().flatten() {
            if *s < slots {
                self.holder_start[*s + 1] += 1;
            }
        }
        for s in 0..slots {
            self.holder_start[s + 1] += self.holder_start[s];
        }
        self.holders.clear();
        self.holders.resize(self.holder_start[slots], 0);
        let mut fill = self.holder_start.clone();
        for (i, s) in self.flock.slot.iter().enumerate() {
            if let Some(s) = *s {
                if s < slots {
                    self.holders[fill[s]] = i;
                    fill[s] += 1;
                }
            }
        }
    }

    /// The decision of airborne bird `i`, from the current state only.
    fn decide(
        &self,
        i: usize,
        perceiver: &mut Perceiver,
        visible: &mut Vec<usize>,
        near: &mut Vec<usize>,
    ) -> Decision {
        let p = &self.params;
        let f = &self.flock;
        let tau = p.opts.reaction_time;
        let mut unseen = 0;
        let (turn, want_speed, reference, side, branch) = if i == f.leader {
            let dd = wrap_angle(p.cruise_heading - f.heading[i]);
            // While flockmates are still on the ground the leader flies at the gathering speed
            // (a fraction of the cruise speed), so that the last to leave is not left far behind.
            // From the air, it also waits while a flockmate is still turning round (heading
            // more than 90° off the cruise heading): flown away at cruise speed, the leader left
            // those birds up to 50 wingspans behind every slot.
            let turning = self.airborne_start()
                && f.heading.iter().enumerate().any(|(k, &h)| {
                    k != i && wrap_angle(h - p.cruise_heading).abs() > AIR_GATHER_ANGLE
                });
            let v = if turning
                || self.departed.len() < f.pos.len()
                || f.phase.iter().any(|&ph| ph != Phase::Airborne)
            {
                p.gather_speed.max(p.min_speed)
            } else {
                p.cruise_speed
            };
            (p.opts.alpha * dd / tau, v, None, None, None)
        } else if let Some(c) = f.slot[i].filter(|_| p.opts.assign_slots) {
            // Assigned slot: the reference is the bird of the nearest airborne ancestor of the
            // slot (its reference slot, or farther up the tree while that bird is on the ground).
            let mut s = c;
            let j = loop {
                match self.target.parent[s] {
                    Some(ps) => {
                        let j = self.bird_of_slot[ps];
                        if f.phase[j] == Phase::Airborne || ps == self.target.leader {
                            break j;
                        }
                        s = ps;
                    }
                    None => break f.leader,
                }
            };
            // The whole way in the formation frame: eqs. (5)–(6) relative to a reference bird
            // that is itself still far from its slot would pass its lag down the arm.
            self.grid.within(&f.pos, f.pos[i], p.opts.avoid_range, near);
            let (w, v) = self.settle(i, c, near);
            (w, v, Some(j), self.target.side_of(c), Some(c))
        } else {
            // Perception: departed flockmates within the visual range.
            self.grid
                .within(&f.pos, f.pos[i], p.opts.visual_range, near);
            near.retain(|&j| f.phase[j] != Phase::Waiting);
            perceiver.visible_among(i, &f.pos, near, f.heading[i], &p.opts.perception, visible);
            match self.choose(i, visible) {
                Some((j, side, c, u)) => {
                    unseen = u;
                    let (w, v) = self.steer(i, j, c, near);
                    (w, v, Some(j), Some(side), Some(c))
                }
                None if near.is_empty() => {
                    // Nobody within the visual range: head for the flock, which is seen from
                    // much farther as a whole (its centroid), at cruise speed.
                    let c = self.departed.iter().map(|&j| f.pos[j]).sum::<DVec2>()
                        / self.departed.len().max(1) as f64;
                    let dd = bearing(f.heading[i], c - f.pos[i]);
                    (p.opts.alpha * dd / tau, p.max_speed, None, None, None)
                }
                None => {
                    let d = direction(f.heading[i]);
                    let nearest = visible
                        .iter()
                        .map(|&j| (f.pos[j] - f.pos[i], j))
                        .min_by(|a, b| a.0.length_squared().total_cmp(&b.0.length_squared()));
                    match nearest {
                        // Lost behind the flock (every visible bird ahead, the nearest farther
                        // than the separation distance): close on the nearest, a little faster
                        // than the cruise, instead of falling back ever farther.
                        Some((rel, _))
                            if rel.length() > p.opts.separation_distance
                                && visible.iter().all(|&j| (f.pos[j] - f.pos[i]).dot(d) > 0.0) =>
                        {
                            let dd = bearing(f.heading[i], rel);
                            let gain =
                                (0.02 * (rel.length() - p.opts.separation_distance)).min(0.3);
                            (
                                p.opts.alpha * dd / (p.opts.turn_distance_cap * tau),
                                p.cruise_speed * (1.0 + gain),
                                None,
                                None,
                                None,
                            )
                        }
                        _ => {
                            // Lost: turn toward the cruise heading and slow a little.
                            let dd = wrap_angle(p.cruise_heading - f.heading[i]);
                            (
                                p.opts.alpha * dd / tau,
                                p.opts.lost_speed_factor * p.cruise_speed,
                                None,
                                None,
                                None,
                            )
                        }
                    }
                }
            }
        };
        let (mut w, mut v) = (
            turn.clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate),
            want_speed,
        );
        self.grid.within(&f.pos, f.pos[i], p.opts.avoid_range, near);
        // With assigned slots, neighbours across the formation fly in two layers while they are
        // away from their slots (half a wingspan apart in height), merging as they settle, so
        // that two birds passing each other on the way are apart in 3-D.
        let mut alt_offset = match (self.layer.get(i), self.slot_err.get(i)) {
            (Some(&l), Some(&e)) if e.is_finite() => layer_offset(l, e),
            _ => 0.0,
        };
        if self.airborne_start() && f.slot[i].is_some() {
            alt_offset += self.vertical_separation(i, near);
        }
        if let Some((turn, slow, dz)) = self.avoidance(i, w, near) {
            w = turn;
            alt_offset = dz;
            if slow {
                v = v.min(f.speed[i] - p.opts.max_accel * p.opts.speed_lag);
            }
        }
        Decision {
            turn_rate: w.clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate),
            speed: v.clamp(p.min_speed, p.max_speed),
            alt_offset,
            reference,
            side,
            branch,
            unseen,
        }
    }

    /// Reference bird, side and follower slot of bird `i` among its `visible` flockmates, and
    /// the steps since the reference was last seen. The current reference is kept while it stays
    /// acceptable and is visible, or hidden for no more than the reference memory (a bird does not
    /// forget the bird it follows when another passes in front of it for a moment).
    fn choose(&self, i: usize, visible: &[usize]) -> Option<(usize, Side, usize, u32)> {
        let f = &self.flock;
        if self.params.opts.sticky_reference {
            if let (Some(j), Some(side)) = (f.reference[i], f.side[i]) {
                let seen = visible.contains(&j);
                let remembered = seen || f.unseen[i] < self.params.reference_memory;
                if remembered && self.sides_for(i, j).contains(&Some(side)) {
                    if let Some(c) = self.acceptable(i, j, side, visible) {
                        let unseen = if seen { 0 } else { f.unseen[i] + 1 };
                        return Some((j, side, c, unseen));
                    }
                }
            }
        }
        let mut chosen = None;
        let reference = choose_reference(
            i,
            visible,
            &f.pos,
            f.heading[i],
            self.params.opts.perception.reference_cone,
            |j| {
                for side in self.sides_for(i, j).into_iter().flatten() {
                    if let Some(c) = self.acceptable(i, j, side, visible) {
                        chosen = Some((side, c));
                        return true;
                    }
                }
                false
            },
        );
        reference.zip(chosen).map(|(j, (side, c))| (j, side, c, 0))
    }

    /// The request of bird `i` following `j` into slot `c`: eqs. (5)–(6) ([`Self::pursue`]) far
    /// from the slot, the formation-frame controller ([`Self::settle`]) within the approach
    /// distance of it, blended (smoothstep) in between, so the request never jumps.
    fn steer(&self, i: usize, j: usize, c: usize, near: &[usize]) -> (f64, f64) {
        let p = &self.params;
        let Some(&slot) = self.slot_pos.get(c) else {
            return self.pursue(i, j, c);
        };
        let r = (self.flock.pos[i] - slot).length();
        let others = near;
        let near = p.opts.approach_distance;
        if r >= 2.0 * near {
            return self.pursue(i, j, c);
        }
        let settle = self.settle(i, c, others);
        if r <= near {
            return settle;
        }
        let u = (2.0 * near - r) / near;
        let w = u * u * (3.0 - 2.0 * u);
        let far = self.pursue(i, j, c);
        (
            far.0 + w * (settle.0 - far.0),
            far.1 + w * (settle.1 - far.1),
        )
    }

    /// Final approach in the formation frame: the bird wants the formation's velocity (the
    /// leader's) plus a closing velocity on its slot (leader position plus the slot's offset
    /// along the cruise heading), linear in the slot error near it
    /// (time constant `approach_time`; across the formation the slower, since a sideways move
    /// needs a turn first) and braked (√(2 a e)) farther out, bounded so that the wanted
    /// velocity stays within the speed range and never points backwards. It is flown as a
    /// heading (turn rate = heading error / (3 τ_ω)) and a speed: a well-damped second-order
    /// approach whose time does not depend on where the reference bird is (no cascade down the
    /// arms). Requested turn rate (rad/s) and speed (wingspans/s).
    fn settle(&self, i: usize, c: usize, near: &[usize]) -> (f64, f64) {
        let p = &self.params;
        let f = &self.flock;
        let vf = self.lead_vel;
        let e = self.slot_pos[c] - f.pos[i];
        let dc = direction(p.cruise_heading);
        let rc = right_of(p.cruise_heading);
        let speed_f = vf.length().max(p.min_speed);
        let shape = |e: f64, t: f64, lo: f64, hi: f64| -> f64 {
            let mag = (e.abs() / t).min((2.0 * p.approach_brake * e.abs()).sqrt());
            (mag * e.signum()).clamp(lo, hi)
        };
        // The funnel: a bird still off its slot's line across the formation closes along it
        // only to a distance that grows with the sideways error, so it comes in on its own
        // lane from behind (or ahead) instead of cutting across its neighbours' slots.
        let (ea, ec) = (e.dot(dc), e.dot(rc));
        let room = (FUNNEL_SLOPE * (ec.abs() - FUNNEL_WIDTH).max(0.0)).min(FUNNEL_MAX);
        let ea = if ea > 0.0 {
            (ea - room).max(0.0)
        } else {
            (ea + room).min(0.0)
        };
        let ua = shape(
            ea,
            0.7 * p.approach_time,
            -0.8 * (speed_f - p.min_speed).max(0.0),
            0.8 * (p.max_speed - speed_f).max(0.0),
        );
        let lat = 0.5 * speed_f;
        let uc = shape(ec, p.approach_time, -lat, lat);
        let want = vf + dc * ua + rc * uc + self.separation(i, near);
        let h = want.x.atan2(want.y);
        let herr = wrap_angle(h - f.heading[i]);
        let w = herr / (3.0 * p.opts.turn_lag.max(0.05));
        // Facing away from where it wants to go, a bird slows down and turns tighter.
        let away =
            ((herr.abs() - TURN_SLOW_FROM) / (TURN_SLOW_TO - TURN_SLOW_FROM)).clamp(0.0, 1.0);
        let slow = 1.0 - away * away * (3.0 - 2.0 * away);
        let v = p.min_speed + (want.length() - p.min_speed).max(0.0) * slow;
        (w, v.min(want.length().max(p.min_speed)))
    }

    /// The separation drive of the final approach, in 3-D with a look-ahead: for every flockmate
    /// among `near` whose predicted closest approach (both flying straight, climb rates included)
    /// within [`SEPARATION_HORIZON`] falls below the pair's separation distance
    /// ([`SEPARATION_DISTANCE`], or [`SEPARATION_FRACTION`] of their slots' distance when that is
    /// less), a horizontal velocity away from the predicted position of the other bird, growing
    /// linearly to [`SEPARATION_SPEED`] at contact. Both birds of a pair take their half: the
    /// drive is symmetric. Wingspans per second.
    /// True for a start in the air (the paper's scattered start or a start file): the leader
    /// gathers while birds turn round, and the separation drive predicts turning paths and acts
    /// in height as well. The ground start keeps its straight-line separation.
    fn airborne_start(&self) -> bool {
        !matches!(self.params.opts.start, super::Start::Ground(_))
    }

    /// The closest predicted approach of birds `i` and `k` within `horizon` seconds, each flying
    /// on at its current speed, turn rate and climb rate (arcs, sampled [`ARC_SAMPLES`] times):
    /// the time and `k`'s position relative to `i` then (3-D, wingspans). Birds turning round
    /// after a scattered start are on arcs, which a straight-line prediction misses.
    fn arc_closest(&self, i: usize, k: usize, horizon: f64) -> (f64, DVec3) {
        let f = &self.flock;
        let at = |b: usize, t: f64| -> DVec3 {
            let (h, v, w) = (f.heading[b], f.speed[b], f.turn_rate[b]);
            let xy = if w.abs() * t < 1e-6 {
                direction(h) * (v * t)
            } else {
                let r = v / w;
                DVec2::new(h.cos() - (h + w * t).cos(), (h + w * t).sin() - h.sin()) * r
            };
            DVec3::new(
                f.pos[b].x + xy.x,
                f.pos[b].y + xy.y,
                f.z[b] + f.climb[b] * t,
            )
        };
        let steps = ARC_SAMPLES;
        let mut best = (0.0, at(k, 0.0) - at(i, 0.0));
        for s in 1..=steps {
            let t = horizon * s as f64 / steps as f64;
            let m = at(k, t) - at(i, t);
            if m.length_squared() < best.1.length_squared() {
                best = (t, m);
            }
        }
        best
    }

    /// The vertical part of an airborne start's separation drive: for the most pressing
    /// flockmate among `near` predicted on its arc ([`Self::arc_closest`]) to come closer than
    /// the pair's separation distance within [`SEPARATION_HORIZON`], an altitude offset away
    /// from it (the higher bird up, the lower down; by index when level), growing linearly to
    /// [`VERTICAL_SEPARATION`] at contact. Birds turning round at their largest turn rate have
    /// no sideways freedom left; they pass above and below. Wingspans.
    /// The distance below which birds `i` and `k` push apart: `dsep`, or less for two birds
    /// whose slots are closer than that (a fraction of their slots' distance).
    fn separation_limit(&self, i: usize, k: usize, dsep: f64) -> f64 {
        let f = &self.flock;
        match (f.slot[i], f.slot[k]) {
            (Some(a), Some(b)) => dsep
                .min(SEPARATION_FRACTION * (self.target.slots[a] - self.target.slots[b]).length()),
            _ => dsep,
        }
    }

    fn vertical_separation(&self, i: usize, near: &[usize]) -> f64 {
        let f = &self.flock;
        let horizon = SEPARATION_HORIZON;
        let dsep = SEPARATION_DISTANCE;
        let mut out = 0.0f64;
        for &k in near {
            if k == i || f.phase[k] != Phase::Airborne {
                continue;
            }
            let (t, m) = self.arc_closest(i, k, horizon);
            let d = m.length();
            let limit = self.separation_limit(i, k, dsep);
            if d >= limit {
                continue;
            }
            let dz = f.z[k] - f.z[i];
            let sign = if dz.abs() > 1e-9 {
                -dz.signum()
            } else if i < k {
                -1.0
            } else {
                1.0
            };
            let urgency = 1.0 - 0.5 * t / horizon.max(1e-9);
            let push = sign * VERTICAL_SEPARATION * (limit - d) / limit * urgency;
            if push.abs() > out.abs() {
                out = push;
            }
        }
        out
    }

    fn separation(&self, i: usize, near: &[usize]) -> DVec2 {
        let f = &self.flock;
        let pi = DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]);
        let vi = self.vel.get(i).copied().unwrap_or(DVec3::ZERO);
        let horizon = SEPARATION_HORIZON;
        let dsep = SEPARATION_DISTANCE;
        let gain = SEPARATION_SPEED;
        let mut out = DVec2::ZERO;
        for &k in near {
            if k == i || f.phase[k] == Phase::Waiting {
                continue;
            }
            let dp = DVec3::new(f.pos[k].x, f.pos[k].y, f.z[k]) - pi;
            if dp.truncate().length_squared() > 4.0 * dsep * dsep + 36.0 * horizon * horizon {
                continue;
            }
            let dv = self.vel.get(k).copied().unwrap_or(DVec3::ZERO) - vi;
            let vv = dv.length_squared();
            let (t, m) = if self.airborne_start() {
                self.arc_closest(i, k, horizon)
            } else {
                let t = if vv > 1e-12 {
                    (-dp.dot(dv) / vv).clamp(0.0, horizon)
                } else {
                    0.0
                };
                (t, dp + dv * t)
            };
            let d = m.length();
            let limit = self.separation_limit(i, k, dsep);
            if d >= limit {
                continue;
            }
            let away = -m.truncate();
            let away = if away.length_squared() > 1e-12 {
                away.normalize()
            } else if i < k {
                // Exactly above one another: apart across the cruise heading, by index.
                -right_of(self.params.cruise_heading)
            } else {
                right_of(self.params.cruise_heading)
            };
            // Nearer in time counts more: a closest approach now is pressing.
            let urgency = 1.0 - 0.5 * t / horizon.max(1e-9);
            out += away * (gain * (limit - d) / limit * urgency);
        }
        out
    }

    /// Eqs. (5) and (6) with the fixes of docs/initiation.md, in physical time: requested turn
    /// rate (rad/s) and speed (wingspans/s) of bird `i` following `j` into slot `c` (a follower
    /// slot of `j`'s slot). With τ the reaction time, eq. (6) θ' = θ + α Δd / max(r, 1) per step
    /// becomes ω = α Δd / (max(r, 1) τ), and eq. (5)'s v_j (a distance per step) is v_j τ.
    fn pursue(&self, i: usize, j: usize, c: usize) -> (f64, f64) {
        let p = &self.params;
        let f = &self.flock;
        let tau = p.opts.reaction_time;
        let offset = match f.slot[j] {
            Some(sj) => self.target.offset(sj, c),
            None => self.target.mean_offset,
        };
        let t = self.target_point(j, offset);
        let dj = self.dir_of(j);
        let to_t = t - f.pos[i];
        let r = to_t.length();
        // How far the bird is behind its target along the reference's flight direction.
        let behind = to_t.dot(dj);
        // Near or ahead of the target: steer at a point ahead on the target's line instead of
        // turning back toward it (turnaround fix).
        let aim = if behind >= p.opts.lookahead {
            t
        } else {
            t + dj * (p.opts.lookahead - behind)
        };
        let to_aim = aim - f.pos[i];
        let dd = bearing(f.heading[i], to_aim);
        let vj = f.speed[j];
        let step_j = vj * tau;
        // Eq. (5): K > 0 only when behind the target by more than one step of the reference, and
        // not while facing away from it (a far bird flying the wrong way must not speed up).
        let k = if behind <= step_j {
            -p.k
        } else if dd.abs() < std::f64::consts::FRAC_PI_2 {
            p.k
        } else {
            0.0
        };
        // √|u| has an infinite slope at the fixed point u = 0, which with a bounded acceleration
        // makes a speed limit cycle; within `linear_zone` use its chord |u|/√u₀ instead.
        // The distance is signed (negative ahead of the target): with |r − v_j τ| alone a bird one
        // step *ahead* of its target would sit at a second fixed point of eq. (5).
        let signed_r = if behind >= 0.0 { r } else { -r };
        // With `gap_speed`, the distance is the longitudinal gap alone: the lateral error is the
        // heading's business (eq. 6), and with the full distance K's sign flip at the target
        // (|u| ≈ the lateral error there) is a jump of 2 K φ v_j in the wanted speed.
        let (k, u) = if p.opts.gap_speed {
            let g = behind - step_j;
            let k = if g <= 0.0 {
                -p.k
            } else if dd.abs() < std::f64::consts::FRAC_PI_2 {
                p.k
            } else {
                0.0
            };
            (k, g.abs())
        } else {
            (k, (signed_r - step_j).abs())
        };
        let z = p.opts.linear_zone;
        // Far from the fixed point (beyond the catch-up distance u₁) the term grows linearly,
        // √u₁ · u/u₁, so that a bird far behind closes the gap in seconds, not tens of seconds
        // (eq. 5's √ alone closes 25 wingspans in 1/(v_j K) ≈ 17 s at 10 wingspans/s).
        let far = p.catchup_distance;
        let root = if u < z {
            u / z.sqrt()
        } else if u > far {
            u / far.sqrt()
        } else {
            u.sqrt()
        };
        let mut v = vj * (1.0 - dd.abs() / std::f64::consts::PI + k * root);
        // Braking distance: close on the target no faster than the speed that can still be shed
        // before reaching it, v ≤ v_j + √(2 a g) with g the longitudinal gap (no overshoot); the
        // speed lag adds a distance v τ_v, taken off the gap.
        let gap = (behind - step_j - (f.speed[i] - vj).max(0.0) * p.opts.speed_lag).max(0.0);
        v = v.min(vj + (2.0 * p.opts.max_accel * gap).sqrt());
        // Eq. (6) as a rate, the divisor capped so that a far bird can still turn to its target.
        let w = p.opts.alpha * dd / (r.clamp(1.0, p.opts.turn_distance_cap) * tau);
        (w, v)
    }

    /// Short-range collision avoidance in 3-D, all around (not limited to the visual field). A
    /// threat is a flockmate among `near` (within `avoid_range` horizontally) whose predicted
    /// closest approach (both flying straight, climb rates included) within the horizon is below
    /// `avoid_distance`, or one already that close. When there is a threat, the bird picks among
    /// its requested turn rate `want` and five across the turn-rate range the one that maximises
    /// the smallest predicted miss distance, its heading changed by that rate over one reaction
    /// time (the requested turn wins whenever it is safe, then the one nearest to it), and slows
    /// if the nearest threat is ahead. Birds flying in parallel (V neighbours) are no threat.
    /// Returns the turn rate (rad/s) and whether to slow.
    fn avoidance(&self, i: usize, want: f64, near: &[usize]) -> Option<(f64, bool, f64)> {
        let p = &self.params;
        let f = &self.flock;
        let pi = DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]);
        let vel = &self.vel;
        let vi = vel[i];
        let miss = |dp: DVec3, dv: DVec3| -> f64 {
            let vv = dv.length_squared();
            let tau = if vv > 1e-12 {
                (-dp.dot(dv) / vv).clamp(0.0, p.opts.avoid_horizon)
            } else {
                0.0
            };
            (dp + dv * tau).length()
        };
        let at = |k: usize| DVec3::new(f.pos[k].x, f.pos[k].y, f.z[k]);
        let mut threat: Option<(f64, DVec3, usize)> = None;
        for &k in near {
            if k == i {
                continue;
            }
            let dp = at(k) - pi;
            let dv = vel[k] - vi;
            let closing = dv.length() >= AVOID_MIN_RELATIVE_SPEED * p.cruise_speed;
            let m = miss(dp, dv);
            let d = dp.length();
            // Two birds near their own slots only keep their slots' distance apart: the
            // threshold yields to the shape's geometry (slots may overlap wingtips).
            let limit = match (f.slot[i], f.slot[k]) {
                (Some(a), Some(b))
                    if self.slot_err.get(i).is_some_and(|&e| e < YIELD_DISTANCE)
                        && self.slot_err.get(k).is_some_and(|&e| e < YIELD_DISTANCE) =>
                {
                    p.opts.avoid_distance.min(
                        (YIELD_FRACTION * (self.target.slots[a] - self.target.slots[b]).length())
                            .max(YIELD_FLOOR),
                    )
                }
                _ => p.opts.avoid_distance,
            };
            let is_threat = (closing && m < limit) || d < limit;
            if is_threat && threat.map_or(true, |t| d < t.0) {
                threat = Some((d, dp, k));
            }
        }
        let (_, nearest, other) = threat?;
        let score = |w: f64| -> f64 {
            // The heading after holding that turn rate for the avoidance commitment time (a
            // turn takes effect over a fraction of a second, not one reaction time).
            let h = direction(f.heading[i] + w * AVOID_COMMIT) * f.speed[i];
            let vnew = DVec3::new(h.x, h.y, vi.z);
            let mut worst = f64::INFINITY;
            for &k in near {
                if k != i {
                    worst = worst.min(miss(at(k) - pi, vel[k] - vnew));
                }
            }
            worst
        };
        let m = p.opts.max_turn_rate;
        let mut best = (score(want), want);
        if best.0 < p.opts.avoid_distance {
            for w in [-m, -0.5 * m, 0.0, 0.5 * m, m] {
                let sc = score(w);
                let better = sc > best.0 + 1e-9
                    || ((sc - best.0).abs() <= 1e-9 && (w - want).abs() < (best.1 - want).abs());
                if better {
                    best = (sc, w);
                }
            }
        }
        let ahead = nearest.truncate().dot(direction(f.heading[i])) > 0.0;
        // In 3-D a bird can also pass above or below: the higher of the two (the one with the
        // higher index when level) climbs, the other dives, by 1.5 avoidance distances, while the
        // threat lasts (airborne birds only; the hand-over needs the cruise altitude back).
        let above = f.z[i] > f.z[other] || (f.z[i] == f.z[other] && i > other);
        let dz = if f.phase[other] == Phase::Airborne && f.z[i] > 0.5 * p.opts.avoid_distance {
            if above {
                1.5 * p.opts.avoid_distance
            } else {
                -1.5 * p.opts.avoid_distance
            }
        } else {
            0.0
        };
        Some((best.1, ahead, dz))
    }

    /// Positions of the slots in the world if the leader were exactly in its slot and the flock
    /// flew along the cruise heading: S_s = P_L + (x_s − x_L) r_c − (y_s − y_L) d_c.
    pub fn slot_positions(&self) -> Vec<DVec2> {
        let p = &self.params;
        let dc = direction(p.cruise_heading);
        let rc = right_of(p.cruise_heading);
        let l = self.flock.pos[self.flock.leader];
        let sl = self.target.slots[self.target.leader];
        self.target
            .slots
            .iter()
            .map(|s| l + rc * (s.x - sl.x) - dc * (s.y - sl.y))
            .collect()
    }

    /// The convergence test at one instant: every bird is airborne, the matching is one-to-one
    /// and every bird is within `tol.distance` wingspans of its slot (and of the cruise
    /// altitude), within `tol.heading` radians of the cruise heading, within `tol.speed`
    /// (fraction) of the cruise speed, and flying steadily (turn rate, acceleration and climb
    /// rate small, so that the hand-over to the steady flight has no jerk).
    pub fn in_formation(&self, tol: &Tolerances) -> bool {
        let n = self.len();
        let f = &self.flock;
        if !self.all_airborne() {
            return false;
        }
        let mut taken = vec![false; n];
        for s in &f.slot {
            match s {
                Some(s) if *s < n && !taken[*s] => taken[*s] = true,
                _ => return false,
            }
        }
        let slots = self.slot_positions();
        let p = &self.params;
        (0..n).all(|i| {
            let s = f.slot[i].unwrap_or(0);
            (f.pos[i] - slots[s]).length() <= tol.distance
                && (f.z[i] - p.opts.cruise_altitude).abs() <= tol.distance
                && wrap_angle(f.heading[i] - p.cruise_heading).abs() <= tol.heading
                && (f.speed[i] - p.cruise_speed).abs() <= tol.speed * p.cruise_speed
                && f.turn_rate[i].abs() <= tol.turn_rate
                && f.accel[i].abs() <= tol.accel
                && f.climb[i].abs() <= tol.climb
        })
    }

    /// Number of birds within `tolerance` of their (uniquely held) slot.
    pub fn birds_in_slot(&self, tolerance: f64) -> usize {
        let slots = self.slot_positions();
        let f = &self.flock;
        let mut count = vec![0usize; self.len()];
        for s in f.slot.iter().flatten() {
            if let Some(c) = count.get_mut(*s) {
                *c += 1;
            }
        }
        (0..self.len())
            .filter(|&i| match f.slot[i] {
                Some(s) => count[s] == 1 && (f.pos[i] - slots[s]).length() <= tolerance,
                None => false,
            })
            .count()
    }

    /// Largest distance of a bird beyond the formed flock: its horizontal distance from the
    /// nearest slot position (slots placed behind the current leader), wingspans.
    pub fn stray_distance(&self) -> f64 {
        let slots = self.slot_positions();
        let mut grid = Grid::default();
        let all: Vec<usize> = (0..slots.len()).collect();
        grid.build(&slots, &all, 8.0);
        let mut out = Vec::new();
        let mut worst = 0.0f64;
        for &p in &self.flock.pos {
            // Slots within a growing radius; the first hit bounds the nearest.
            let mut r = 8.0;
            let d = loop {
                grid.within(&slots, p, r, &mut out);
                if let Some(d) = out
                    .iter()
                    .map(|&s| (slots[s] - p).length())
                    .reduce(f64::min)
                {
                    break d;
                }
                r *= 2.0;
                if r > 1e7 {
                    break r;
                }
            };
            worst = worst.max(d);
        }
        worst
    }

    /// Smallest 3-D distance between two birds now, wingspans (∞ for fewer than two birds).
    pub fn min_distance(&self) -> f64 {
        let f = &self.flock;
        let pts: Vec<DVec3> = (0..self.len())
            .map(|i| DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]))
            .collect();
        min_pair_distance(&pts)
    }
}

/// The slot of every bird and the leader for start positions `pos` (wingspans) of a flock
/// flying along `heading`: the leader is the front-most bird of the middle half across the
/// heading, and with `max_offset` (wingspans) of those at most that far across from the middle
/// bird (the middle bird itself when none is); the other birds take the other slots in the order
/// of their positions across the heading (the leftmost bird the leftmost slot, ties along the
/// heading), so that no two birds cross sideways on their way to their slots.
pub fn assign_slots(
    target: &TargetShape,
    pos: &[DVec2],
    heading: f64,
    max_offset: Option<f64>,
) -> (Vec<usize>, usize) {
    let n = pos.len().min(target.len());
    let dc = direction(heading);
    let rc = right_of(heading);
    let across = |i: usize| pos[i].dot(rc);
    let along = |i: usize| pos[i].dot(dc);
    let mut by_x: Vec<usize> = (0..n).collect();
    by_x.sort_by(|&a, &b| across(a).total_cmp(&across(b)).then(a.cmp(&b)));
    let (lo, hi) = (n / 4, (n - n / 4).max(n / 4 + 1).min(n));
    let middle = by_x.get(n / 2).copied().unwrap_or(0);
    let near_middle = |i: usize| {
        i == middle
            || match max_offset {
                Some(m) => (across(i) - across(middle)).abs() <= m,
                None => true,
            }
    };
    let leader = by_x[lo..hi]
        .iter()
        .copied()
        .filter(|&i| near_middle(i))
        .max_by(|&a, &b| along(a).total_cmp(&along(b)).then(b.cmp(&a)))
        .unwrap_or(0);
    let mut slots: Vec<usize> = (0..target.len()).filter(|&s| s != target.leader).collect();
    slots.sort_by(|&a, &b| {
        let (pa, pb) = (target.slots[a], target.slots[b]);
        pa.x.total_cmp(&pb.x)
            .then(pa.y.total_cmp(&pb.y))
            .then(a.cmp(&b))
    });
    let mut slot = vec![target.leader; pos.len()];
    let others = by_x.iter().copied().filter(|&i| i != leader);
    for (i, s) in others.zip(slots) {
        slot[i] = s;
    }
    (slot, leader)
}

/// Convergence tolerances of [`Simulation::in_formation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Distance from the slot and from the cruise altitude, wingspans.
    pub distance: f64,
    /// Heading difference, radians.
    pub heading: f64,
    /// Speed difference, fraction of the cruise speed.
    pub speed: f64,
    /// Turn rate, radians per second.
    pub turn_rate: f64,
    /// Acceleration, wingspans per second squared.
    pub accel: f64,
    /// Climb rate, wingspans per second.
    pub climb: f64,
}

/// Smallest distance between two points, wingspans (∞ for fewer than two). Sort-and-sweep on x.
pub fn min_pair_distance(pos: &[DVec3]) -> f64 {
    let mut order: Vec<usize> = (0..pos.len()).collect();
    order.sort_unstable_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x));
    let mut best = f64::INFINITY;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if pos[b].x - pos[a].x >= best {
                break;
            }
            best = best.min((pos[b] - pos[a]).length());
        }
    }
    best
}

/// An angle wrapped into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::PI;
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    } else if a <= -PI {
        a += 2.0 * PI;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A V of `n` birds 0.7 wingspans across and 0.35 behind per rank (y behind the leader).
    fn v(n: usize) -> TargetShape {
        let pts: Vec<DVec2> = (0..n)
            .map(|k| {
                let rank = k.div_ceil(2) as f64;
                let side = if k % 2 == 1 { 1.0 } else { -1.0 };
                DVec2::new(side * 0.7 * rank, 0.35 * rank)
            })
            .collect();
        TargetShape::new(&pts).unwrap()
    }

    /// 41 birds in a row across the heading (north), 2 wingspans apart, x = −40 … 40; the bird
    /// at x = 16 is 3 wingspans ahead of the rest and the one at x = −6 one wingspan ahead.
    fn row() -> Vec<DVec2> {
        (0..41)
            .map(|k| {
                let x = 2.0 * k as f64 - 40.0;
                let y = match x as i64 {
                    16 => 3.0,
                    -6 => 1.0,
                    _ => 0.0,
                };
                DVec2::new(x, y)
            })
            .collect()
    }

    #[test]
    fn the_leader_is_the_front_most_bird_of_the_middle_half() {
        let pos = row();
        let (_, leader) = assign_slots(&v(41), &pos, 0.0, None);
        assert_eq!(pos[leader], DVec2::new(16.0, 3.0));
    }

    #[test]
    fn an_airborne_leader_is_near_the_middle_bird_and_the_slots_stay_in_order() {
        let pos = row();
        let t = v(41);
        let (slot, leader) = assign_slots(&t, &pos, 0.0, Some(AIR_LEADER_OFFSET));
        // x = 16 is 16 wingspans from the middle bird (x = 0): beyond 8, so x = −6 leads.
        assert_eq!(pos[leader], DVec2::new(-6.0, 1.0));
        assert_eq!(slot[leader], t.leader);
        // The others keep their order across the heading in their slots' order.
        let mut others: Vec<usize> = (0..pos.len()).filter(|&i| i != leader).collect();
        others.sort_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x));
        for w in others.windows(2) {
            assert!(t.slots[slot[w[0]]].x <= t.slots[slot[w[1]]].x);
        }
        let mut seen = slot.clone();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), pos.len(), "one bird per slot");
        // No bird within the offset: the middle bird leads.
        let (_, leader) = assign_slots(&t, &pos, 0.0, Some(0.5));
        assert_eq!(pos[leader], DVec2::new(0.0, 0.0));
    }
}
