//! The take-off's options ([`InitiateOptions`]): the paper's §6 constants, the flight limits and
//! the start, with their checks, and the cruise the flock converges to ([`Cruise`]).

use super::*;

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
    /// Largest climb rate, wingspans per second (`None`: the birds' power-limited climb, the
    /// cruise's [`Cruise::climb_rate`]: goose 0.51, crane 0.31, pelican 0.23 wingspans/s; see
    /// [`InitiateOptions::climb_rate_for`]).
    pub climb_rate: Option<f64>,
    /// Largest vertical acceleration, wingspans per second squared.
    pub vertical_accel: f64,
    /// Acceleration of the take-off run on the ground, wingspans per second squared.
    pub run_accel: f64,
    /// Wanted time until the V has formed, seconds from the start of the take-off, the sitting
    /// included (`None`: the natural one of the flock size, see
    /// [`TakeoffPlan::natural_form_seconds`]). The take-off plan scales the start area, the
    /// departure stagger and how hard the birds drive (run, approach; the climb only harder) to
    /// it ([`TakeoffPlan::drive`]); the simulation is never cut.
    pub takeoff: Option<f64>,
    /// Time the birds sit on the ground before the first one starts its run, seconds (a ground
    /// start only).
    pub ground_seconds: f64,
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
            climb_rate: None,
            vertical_accel: 2.0,
            run_accel: 3.0,
            takeoff: None,
            ground_seconds: 1.0,
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

/// The steady flight the flock converges into: the leader's cruise heading (radians) and speed
/// (wingspans per second), the wingspan in metres (for gravity in wingspans/s²) and the birds'
/// power-limited climb rate (the take-off's climb when [`InitiateOptions::climb_rate`] is `None`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cruise {
    /// Cruise heading, radians clockwise from +y.
    pub heading: f64,
    /// Cruise speed, wingspans per second.
    pub speed: f64,
    /// Wingspan, metres.
    pub wingspan_m: f64,
    /// The birds' best power-limited climb rate, wingspans per second
    /// ([`crate::aero::flight::PowerCurve::best_climb_rate`] over the wingspan; see
    /// [`Cruise::power_climb`]).
    pub climb_rate: f64,
}

impl Cruise {
    /// A cruise along `heading` (radians) at `speed` (wingspans per second) of geese with a
    /// wingspan of 1.5 m (climbing at most 0.51 wingspans/s).
    pub fn new(heading: f64, speed: f64) -> Cruise {
        Cruise::of_birds(heading, speed, Species::Goose, 1.5, None)
    }

    /// A cruise of birds of `species` with a wingspan of `wingspan_m` metres (the species'
    /// typical bird scaled to it) and, when given, a body mass of `mass_kg`: their climb rate is
    /// [`Cruise::power_climb`]'s.
    pub fn of_birds(
        heading: f64,
        speed: f64,
        species: Species,
        wingspan_m: f64,
        mass_kg: Option<f64>,
    ) -> Cruise {
        Cruise {
            heading,
            speed,
            wingspan_m,
            climb_rate: Cruise::power_climb(species, wingspan_m, mass_kg),
        }
    }

    /// The best power-limited climb rate of birds of `species` with a wingspan of `wingspan_m`
    /// metres (and a mass of `mass_kg`, default the species' typical mass scaled to the
    /// wingspan), wingspans per second: goose 0.51 (1.5 m), crane 0.31 (2.2 m), pelican 0.23
    /// (2.9 m). The power left over from flight at the minimum-power speed over the weight
    /// ([`crate::aero::flight::PowerCurve::best_climb_rate`]); docs/initiation.md.
    pub fn power_climb(species: Species, wingspan_m: f64, mass_kg: Option<f64>) -> f64 {
        let curve =
            crate::aero::flight::animation_curve_with(Some(species.name()), wingspan_m, mass_kg);
        let span = if wingspan_m.is_finite() && wingspan_m > 0.0 {
            wingspan_m
        } else {
            curve.bird.span_m
        };
        curve.best_climb_rate() / span
    }

    /// Gravity in wingspans per second squared.
    pub fn gravity(&self) -> f64 {
        GRAVITY_M_S2 / self.wingspan_m
    }
}

/// Largest climb rate of birds starting in the air (`Start::Random`, `Start::Given`), wingspans per
/// second: they start within a few wingspans of the cruise altitude and only change layers, so
/// they keep the take-off's fast climb from before the power-limited default (our choice).
pub const AIR_CLIMB_RATE: f64 = 2.5;

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
        if let Some(w) = self.climb_rate {
            pos("initiate.climb_rate", w)?;
        }
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
        if !(self.ground_seconds.is_finite() && (0.0..=600.0).contains(&self.ground_seconds)) {
            return Err(Error::parameter(
                "initiate.ground_seconds",
                format!(
                    "must be a number of seconds from 0 to 600, got {}",
                    self.ground_seconds
                ),
            ));
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

    /// The largest climb rate at the natural drive for birds of `cruise`, wingspans per second:
    /// the option, or for a take-off from the ground the birds' power-limited climb
    /// ([`Cruise::climb_rate`]); birds starting in the air, at the cruise altitude, change
    /// height by a few wingspans only, at up to [`AIR_CLIMB_RATE`].
    pub fn climb_rate_for(&self, cruise: &Cruise) -> f64 {
        self.climb_rate.unwrap_or(match self.start {
            Start::Ground(_) => cruise.climb_rate,
            _ => AIR_CLIMB_RATE,
        })
    }

    /// How long a bird of `cruise` takes to climb from the ground to the cruise altitude and level
    /// off at the natural drive, seconds: h/w + w/a (the climb rate w reached and shed at the
    /// vertical acceleration a), less what the burst climb after lift-off saves
    /// ([`sim::LIFTOFF_BURST_CLIMB`]).
    pub fn climb_seconds(&self, cruise: &Cruise) -> f64 {
        let w = self.climb_rate_for(cruise);
        let (b, h, alt) = (
            sim::LIFTOFF_BURST_CLIMB,
            sim::LIFTOFF_BURST_HEIGHT,
            self.cruise_altitude,
        );
        // The burst after lift-off: dz/dt = w + (b − w)(1 − z/h) over the lowest h wingspans
        // takes h/(b − w) ln(b/w).
        let burst = if w < b && alt > h {
            h / (b - w) * (b / w).ln() - h / w
        } else {
            0.0
        };
        alt / w + burst + w / self.vertical_accel
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
        let mut p = self.derive_params(cruise, plan.k, plan.catchup_distance, plan.drive);
        // The climb at the plan's climb drive (not slowed with a slow formation).
        p.climb_rate = self.climb_rate_for(cruise) * plan.climb_drive;
        p.vertical_accel = self.vertical_accel * plan.climb_drive;
        p
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
            climb_rate: self.climb_rate_for(cruise) * drive,
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
