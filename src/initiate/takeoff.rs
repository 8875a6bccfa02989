//! The take-off plan: how long the take-off lasts for a flock of a given size, and the drives
//! scaled to that length ([`TakeoffPlan`]).

use super::*;

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
    /// How hard the birds climb: the formation's [`Self::drive`] when it is above 1 (a flock
    /// pressed to form fast also climbs hard), else 1 (a flock forming slowly still climbs at
    /// its natural rate rather than lingering low). The climb rate and the vertical acceleration
    /// are multiplied by it.
    pub climb_drive: f64,
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

    /// Time a bird's take-off takes beside its climb at the natural drive, seconds: the departure
    /// stagger (1 s), the run to lift-off (about 1.7 s) and holding the formation (1 s); fitted to
    /// the README job's take-off at the goose's power-limited climb (24.7 s, 1 s of it sitting,
    /// for a climb of 20.0 s).
    pub const CLIMB_OVERHEAD: f64 = 3.7;

    /// [`Self::CLIMB_OVERHEAD`] at the strongest drive, seconds: the stagger and the run shortened
    /// by it, the hold not.
    pub const SHORTEST_CLIMB_OVERHEAD: f64 = 2.7;

    /// The natural take-off of `n` birds from the ground under `opts` (at their drive 1), seconds:
    /// the longer of the time the flock needs to form, measured at a fast climb (medians about
    /// 10.4 s for 9–14 birds with the wing envelope kept, 9.5 s before; 10.7 s for 41, 12.7 s for
    /// 100, 23 s for 300: 9.4 + 0.045 N, growing with the width of the V), and the time the last bird needs to leave, climb to the cruise
    /// altitude and hold the formation ([`Self::CLIMB_OVERHEAD`] +
    /// [`InitiateOptions::climb_seconds`]: 23.7 s for geese at their power-limited climb to
    /// 10 wingspans; docs/initiation.md).
    pub fn natural_seconds(n: usize, opts: &InitiateOptions, cruise: &Cruise) -> f64 {
        (9.4 + 0.045 * n.max(1) as f64).max(Self::CLIMB_OVERHEAD + opts.climb_seconds(cruise))
    }

    /// The natural time of `n` birds flying from their first run until the V has formed (at
    /// their drive 1), seconds: 8.4 + 0.045 N, the measured natural take-offs above less the
    /// second they hold the formed V (the V forms while they still climb: 9.0 s for 14 geese at
    /// their power-limited climb).
    pub fn natural_form_flying(n: usize) -> f64 {
        8.4 + 0.045 * n.max(1) as f64
    }

    /// The shortest time from the first run until the V has formed at the strongest drive,
    /// seconds: 6.7 + 0.049 N (the measured shortest take-offs above less the held second).
    pub fn shortest_form_flying(n: usize) -> f64 {
        6.7 + 0.049 * n.max(1) as f64
    }

    /// Seconds the birds sit before their first run under `opts` (0 for an airborne start):
    /// `initiate.takeoff` counts from the start of the take-off, the sitting included.
    fn sitting(opts: &InitiateOptions) -> f64 {
        match opts.start {
            Start::Ground(_) => opts.ground_seconds,
            _ => 0.0,
        }
    }

    /// The natural time until the V of `n` birds has formed under `opts`, seconds from the
    /// start of the take-off (the sitting included): what `initiate.takeoff` aims for by default.
    pub fn natural_form_seconds(n: usize, opts: &InitiateOptions) -> f64 {
        Self::sitting(opts) + Self::natural_form_flying(n)
    }

    /// The shortest time until the V of `n` birds can form under `opts` (the strongest drive),
    /// seconds from the start of the take-off.
    pub fn shortest_form_seconds(n: usize, opts: &InitiateOptions) -> f64 {
        Self::sitting(opts) + Self::shortest_form_flying(n)
    }

    /// The longest time the V of `n` birds takes to form under `opts` (the weakest drive:
    /// softer runs, a wider start area, a slower approach), seconds from the start of the
    /// take-off.
    pub fn longest_form_seconds(n: usize, opts: &InitiateOptions) -> f64 {
        Self::sitting(opts) + Self::natural_form_flying(n) / Self::MIN_DRIVE
    }

    /// The automatic take-off duration of `n` birds, seconds: the natural one.
    pub fn auto_seconds(n: usize, opts: &InitiateOptions, cruise: &Cruise) -> f64 {
        Self::natural_seconds(n, opts, cruise)
    }

    /// The shortest take-off of `n` birds from the ground at the strongest drive, seconds: the
    /// longer of the forming time, measured medians 7.9 s for 9 birds, 8.3 for 14, 9.2 for 41,
    /// 11.7 for 100, 22.4 for 300 (`initiate.takeoff` 5 s at a fast climb, docs/initiation.md;
    /// fitted 8.1, 8.4, 9.7, 12.6 and 22.4, the outer birds of a wider V having farther to fly to
    /// their slots at bounded speeds), and the run, lift-off and climb to the cruise altitude at
    /// the strongest drive ([`Self::climb_part_shortest`]).
    pub fn shortest_seconds(n: usize, opts: &InitiateOptions, cruise: &Cruise) -> f64 {
        (7.7 + 0.049 * n.max(1) as f64).max(Self::climb_part_shortest(opts, cruise))
    }

    /// The departure, run, climb to the cruise altitude and hold at the strongest drive
    /// ([`Self::MAX_DRIVE`]), seconds: [`Self::SHORTEST_CLIMB_OVERHEAD`] + h/(d w) + w/a (the climb
    /// rate and the vertical acceleration both scaled by the drive d).
    pub fn climb_part_shortest(opts: &InitiateOptions, cruise: &Cruise) -> f64 {
        let w = opts.climb_rate_for(cruise);
        Self::SHORTEST_CLIMB_OVERHEAD
            + opts.cruise_altitude / (Self::MAX_DRIVE * w)
            + w / opts.vertical_accel
    }

    /// A warning when the forming time of `opts` (`initiate.takeoff`) cannot be met within 25 %
    /// for `n` birds: shorter than [`Self::shortest_form_seconds`] allows, or longer than
    /// [`Self::longest_form_seconds`]; it names `initiate.takeoff`, the range the flock can fly
    /// and when the V will form.
    pub fn warning(n: usize, opts: &InitiateOptions, _cruise: &Cruise) -> Option<String> {
        let t = opts.takeoff?;
        let shortest = Self::shortest_form_seconds(n, opts);
        let longest = Self::longest_form_seconds(n, opts);
        let range = format!("{n} birds can form their V in about {shortest:.0} to {longest:.0} s");
        if t * 1.25 < shortest {
            Some(format!(
                "initiate.takeoff {t} s: {range} (the run, the lift-off and the flight of the outer birds to their slots bound it); the V will form after about {shortest:.0} s"
            ))
        } else if t > 1.25 * longest {
            Some(format!(
                "initiate.takeoff {t} s: {range} (the drive is at its weakest); the V will form after about {longest:.0} s"
            ))
        } else {
            None
        }
    }

    /// The plan for `n` birds of `cruise` under `opts` (its `takeoff`, or the automatic duration): the
    /// drive is the natural duration over the wanted one (bounded), which scales the departure
    /// stagger, the accelerations, the climb rate, the approach and (for a longer take-off) the
    /// take-off area, so that every part of the take-off takes about `seconds / natural` times
    /// as long. The simulation itself is never cut.
    pub fn new(n: usize, opts: &InitiateOptions, _cruise: &Cruise) -> TakeoffPlan {
        let natural = Self::natural_form_seconds(n, opts);
        let seconds = opts.takeoff.unwrap_or(natural);
        let sitting = Self::sitting(opts);
        let flying = (seconds - sitting).max(1e-3);
        // The natural take-off is driven at exactly 1 (no rounding of the sitting time).
        let drive = match opts.takeoff {
            None => 1.0,
            Some(_) => {
                (Self::natural_form_flying(n) / flying).clamp(Self::MIN_DRIVE, Self::MAX_DRIVE)
            }
        };
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
            climb_drive: drive.max(1.0),
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
