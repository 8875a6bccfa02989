//! Actions and their integration (§6 "actions"): what a bird flies between two decisions. Turn
//! rate, speed, bank and climb follow the requests with lags and bounded rates ([`fly`],
//! [`fly_at`]); a bird on the ground runs to its lift-off speed ([`run`]).

use super::*;

/// Parameters of the drives, actions and flight dynamics of one run: the options themselves
/// (every pass-through value is read from [`Self::opts`]) and the values derived from them for a
/// cruise and a take-off plan (built by [`crate::initiate::InitiateOptions::plan_params`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StepParams {
    /// The options of the initiation, as given but for the visual field, widened to the shape's
    /// when [`crate::initiate::InitiateOptions::widen_field`] (shared: a step copies its parameters
    /// cheaply).
    pub opts: std::sync::Arc<crate::initiate::InitiateOptions>,
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
pub(super) fn approach(x: f64, target: f64, max_step: f64) -> f64 {
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
    let w_t = (2.0 * p.vertical_accel * dz.abs())
        .sqrt()
        .min(climb_limit(p.climb_rate, s.z))
        * dz.signum();
    n.climb = approach(s.climb, w_t, p.vertical_accel * dt);
    n.z = s.z + 0.5 * (s.climb + n.climb) * dt;
    n.pos = s.pos + direction(n.heading) * (0.5 * (s.speed + n.speed) * dt);
    n
}

/// Burst climb just after lift-off, wingspans per second: near the ground a bird may climb at up
/// to this rate, tapering linearly to its sustained climb rate at [`LIFTOFF_BURST_HEIGHT`] (our
/// choice; the run's speed at lift-off, about 8 m/s for a goose, buys ½ v²/g ≈ 3 m, two
/// wingspans, of height). It lifts the birds clear of the ground before they bank into their
/// turns: at the sustained climb of a crane (0.31 wingspans/s) a bird banked 38° at 0.1
/// wingspans put a wingtip under the ground.
pub const LIFTOFF_BURST_CLIMB: f64 = 2.5;

/// Height over which the burst climb tapers off, wingspans (see [`LIFTOFF_BURST_CLIMB`]).
pub const LIFTOFF_BURST_HEIGHT: f64 = 2.0;

/// The climb-rate limit at altitude `z` (wingspans) of a bird whose sustained climb is
/// `climb_rate`: the burst climb near the ground, the sustained one from
/// [`LIFTOFF_BURST_HEIGHT`] up (never less than `climb_rate`).
pub fn climb_limit(climb_rate: f64, z: f64) -> f64 {
    let u = (1.0 - z / LIFTOFF_BURST_HEIGHT).clamp(0.0, 1.0);
    climb_rate.max(climb_rate + (LIFTOFF_BURST_CLIMB - climb_rate) * u)
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
