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
//! The files follow the paper's §6:
//!
//! - `options.rs`: the options (§6's constants, flight limits) and the cruise ([`InitiateOptions`],
//!   [`Cruise`]); `takeoff.rs`: how long the take-off lasts ([`TakeoffPlan`]).
//! - `start.rs`: where the birds start, on the ground or in the air ([`Start`], [`StartState`]).
//! - [`perception`]: visual field, Hidden Point Removal or exact disc occlusion, reference bird;
//!   [`hull`]: the robust orientation predicate and convex hull HPR needs.
//! - [`target`]: the target shape as a tree of slots (leader, left and right arms).
//! - [`sim`]: the simulation: its decisions (`decide.rs`), the reference bird and side
//!   (`reference.rs`), the target-reaching drive (`drives.rs`, eqs. 5–6), the separation drive and
//!   collision avoidance (`separation.rs`), the actions and their integration (`flight.rs`),
//!   slots and formation measures (`slots.rs`), neighbour queries (`grid.rs`).
//! - this file: the take-off run ([`simulate`], [`initiate`]); `handover.rs`: the steady flight
//!   joined on without a jump ([`hand_over`]).
//!
//! The rules as implemented and every choice the paper leaves open: `docs/initiation.md`.

mod handover;
pub mod hull;
pub mod landing;
mod options;
pub mod perception;
mod rows;
pub mod sim;
mod start;
mod takeoff;
pub mod target;

use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec2, DVec3};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::animation::wing::Species;
use crate::animation::{Animation, Frame, Stage};
use crate::error::{Error, Result};
use crate::progress::Progress;

pub use perception::{PerceptionMode, PerceptionParams, HPR_GAMMA_DEFAULT};
pub use rows::Rows;
pub use sim::{Phase, Simulation, StepParams, Tolerances};
pub use target::{Side, TargetShape};

pub use handover::*;
pub use options::*;
pub use start::*;
pub use takeoff::*;

/// Margin between the largest bearing of a reference slot and the edge of the visual field when
/// the field is widened for the target shape, radians (15°).
pub const FIELD_MARGIN: f64 = 15.0 * PI / 180.0;

/// Largest accepted frame limit of the initiation.
pub const MAX_STEPS_LIMIT: usize = 1_000_000;

/// Gravity, metres per second squared.
pub const GRAVITY_M_S2: f64 = 9.81;

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
    /// Time at which the first bird left the ground, seconds (0 for an airborne start).
    #[serde(default)]
    pub first_liftoff: f64,
    /// When the V formed, seconds from the start of the take-off: the start of the first
    /// stretch of at least `initiate.hold` seconds over which the convergence test holds in the
    /// horizontal (every bird in its own slot, at the cruise heading and speed, flying steadily;
    /// [`sim::Simulation::formed`]), whatever the height. `None` if it never did.
    #[serde(default)]
    pub formed_seconds: Option<f64>,
    /// When every bird reached the cruise altitude and levelled off, seconds from the start of
    /// the take-off (held for `initiate.hold` seconds, as `formed_seconds`). `None` if they never
    /// did.
    #[serde(default)]
    pub cruise_height_seconds: Option<f64>,
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
    /// Horizontal positions of every frame (row 0 = start), wingspans.
    pub pos: Rows<DVec2>,
    /// Altitudes of every frame, wingspans.
    pub z: Rows<f64>,
    /// Headings of every frame, radians.
    pub heading: Rows<f64>,
    /// Speeds of every frame, wingspans per second.
    pub speed: Rows<f64>,
    /// Bank angles of every frame, radians (right wing down positive).
    pub bank: Rows<f64>,
    /// Slot of every bird at the end (meaningful when converged: a permutation).
    pub slot: Vec<Option<usize>>,
    /// Statistics.
    pub stats: InitiateStats,
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
        pos: Rows::new(n),
        z: Rows::new(n),
        heading: Rows::new(n),
        speed: Rows::new(n),
        bank: Rows::new(n),
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
            first_liftoff: 0.0,
            formed_seconds: None,
            cruise_height_seconds: None,
            leader_changes: 0,
            birds_in_slot: 0,
            field_per_eye: params.opts.perception.fov_per_eye,
        },
    };
    let mut prev: Vec<sim::BirdState> = (0..n).map(|i| sim.bird(i)).collect();
    let push =
        |run: &mut InitiationRun, a: &[sim::BirdState], b: &[sim::BirdState], u: f64| {
            let ab = || a.iter().zip(b);
            run.pos.push_row(ab().map(|(a, b)| a.pos.lerp(b.pos, u)));
            run.z.push_row(ab().map(|(a, b)| a.z + u * (b.z - a.z)));
            run.heading.push_row(ab().map(|(a, b)| {
                sim::wrap_angle(a.heading + u * sim::wrap_angle(b.heading - a.heading))
            }));
            run.speed
                .push_row(ab().map(|(a, b)| a.speed + u * (b.speed - a.speed)));
            run.bank
                .push_row(ab().map(|(a, b)| a.bank + u * (b.bank - a.bank)));
        };
    push(&mut run, &prev, &prev, 0.0);
    let total = (limit / dt).ceil() as u64;
    progress.start("initiate", total);
    let mut in_formation_since: Option<f64> = None;
    let (mut formed_since, mut high_since): (Option<f64>, Option<f64>) = (None, None);
    let mut lifted = sim.all_airborne();
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
        if !lifted && sim.any_airborne() {
            lifted = true;
            run.stats.first_liftoff = sim.time;
        }
        let formed = sim.formed(&tol);
        let high = sim.at_cruise_height(&tol);
        for (holds, since, at) in [
            (formed, &mut formed_since, &mut run.stats.formed_seconds),
            (high, &mut high_since, &mut run.stats.cruise_height_seconds),
        ] {
            if at.is_some() {
                continue;
            }
            if holds {
                let t0 = *since.get_or_insert(sim.time);
                if sim.time - t0 >= opts.hold - 1e-9 {
                    *at = Some(t0);
                }
            } else {
                *since = None;
            }
        }
        if formed && high {
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
    run.pos.shrink_to_fit();
    for rows in [&mut run.z, &mut run.heading, &mut run.speed, &mut run.bank] {
        rows.shrink_to_fit();
    }
    run.stats.steps = run.pos.len() - 1;
    run.stats.seconds = sim.time;
    run.stats.converged = converged;
    run.stats.leader_changes = sim.leader_changes;
    run.stats.birds_in_slot = sim.birds_in_slot(opts.tolerance);
    Ok(run)
}

/// The target shape and cruise of a steady flight (the leader's heading and speed in the first
/// frame, the file's wingspan, and the climb of its species, a goose when it names none, and
/// mass).
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
    let species = steady
        .species
        .as_deref()
        .and_then(|s| s.parse::<Species>().ok())
        .unwrap_or_default();
    let mass = steady.flight.and_then(|f| f.mass_kg);
    Ok((
        target,
        Cruise::of_birds(heading, speed, species, steady.wingspan_m, mass),
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

/// Refuses, up front, an initiation that could not fit in the memory this process may use
/// ([`crate::limits::memory_budget`]): at its longest, `birds` × (`steady_frames` + `max_steps`)
/// bird-frames, each taking at most [`crate::limits::RUN_BYTES_PER_BIRD_FRAME`] while the run is
/// made. A take-off that converges sooner takes only what it used: the animation's own limit
/// ([`crate::limits::MAX_BIRD_FRAMES`]) is checked on the frames it really has.
pub fn check_size(birds: usize, steady_frames: usize, max_steps: usize) -> Result<()> {
    let frames = steady_frames.saturating_add(max_steps) as u64;
    let Some(budget) = crate::limits::memory_budget() else {
        return Ok(());
    };
    let per_frame = (birds as u64).saturating_mul(crate::limits::RUN_BYTES_PER_BIRD_FRAME);
    let need = per_frame.saturating_mul(frames);
    if need <= budget {
        return Ok(());
    }
    let plus = if steady_frames > 0 {
        format!(" + {steady_frames} steady frames")
    } else {
        String::new()
    };
    let fits = (budget / per_frame.max(1)).saturating_sub(steady_frames as u64);
    Err(Error::parameter(
        "initiate.max_steps",
        format!(
            "{birds} birds × ({max_steps} steps{plus}) could take {:.1} GB, more than the {:.1} GB of memory available; lower initiate.max_steps to at most {fits} or fly fewer birds",
            need as f64 / 1e9,
            budget as f64 / 1e9
        ),
    ))
}
