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

mod decide;
mod drives;
mod flight;
mod grid;
mod reference;
mod separation;
use separation::envelope_altitude;
mod slots;

pub use flight::*;
pub use grid::*;
pub use slots::*;

/// Collision avoidance ignores flockmates whose speed relative to the bird is below this
/// fraction of the cruise speed (unless they are already closer than the avoidance distance).
pub const AVOID_MIN_RELATIVE_SPEED: f64 = 0.08;

/// Collision avoidance scores a candidate turn rate by the heading it gives after this long,
/// seconds.
pub const AVOID_COMMIT: f64 = 0.3;

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
    /// Least and greatest altitude of the wing envelope (below and above a flockmate within
    /// reach of the wings), wingspans (±∞: none).
    alt_floor: f64,
    alt_ceiling: f64,
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
    /// Each bird's wing-envelope altitude bounds from its last decision (see
    /// [`Simulation::wing_envelope`]), wingspans.
    alt_floor: Vec<f64>,
    alt_ceiling: Vec<f64>,
    next_reference: Vec<Option<usize>>,
    next_side: Vec<Option<Side>>,
    next_branch: Vec<Option<usize>>,
    next_unseen: Vec<u32>,
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
            alt_floor: vec![f64::NEG_INFINITY; n],
            alt_ceiling: vec![f64::INFINITY; n],
            next_reference: vec![None; n],
            next_side: vec![None; n],
            next_branch: vec![None; n],
            next_unseen: vec![0; n],
        };
        if sim.params.opts.assign_slots && n > 0 {
            let offset = sim.airborne_start().then_some(AIR_LEADER_OFFSET);
            let given = sim.params.opts.start.given_slots(
                &sim.target,
                &sim.flock.pos,
                sim.params.cruise_heading,
            );
            let (slot, leader) = given.unwrap_or_else(|| {
                assign_slots(
                    &sim.target,
                    &sim.flock.pos,
                    sim.params.cruise_heading,
                    offset,
                )
            });
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

    /// Whether any bird has left the ground.
    pub fn any_airborne(&self) -> bool {
        self.flock.phase.contains(&Phase::Airborne)
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
                    let z = envelope_altitude(
                        p.opts.cruise_altitude + self.flock.alt_offset[i],
                        self.alt_floor[i],
                        self.alt_ceiling[i],
                    );
                    fly_at(&s, w, v, z, &p, dt)
                }
            };
            self.set_bird(i, &next);
        }
        self.steps += 1;
        self.time = self.steps as f64 * dt;
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
