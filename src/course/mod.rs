//! The course: where in the world the flock flies. Every earlier stage works in the
//! *course frame*, a straight flight along +y at constant altitude (docs/formats.md §2's world frame before
//! this step); this stage maps it onto the user's path. A point at along-track distance `s`,
//! lateral offset `d` (right of the track) and height `h` goes to
//! ```math
//! P(s) + d\,N(s) + h\,\hat z, \qquad N(s) = (\cos\theta(s), -\sin\theta(s), 0),
//! ```
//! with P the path at arc length s and θ its heading. Birds therefore keep their slots in the
//! formation frame that turns with the track, and in a turn of radius R a bird d wingspans
//! outward of the leader's track flies at v = V (R + d)/R. Velocities follow from the chain rule
//! (`∂/∂s = (cos γ − d θ′) T_h + sin γ ẑ`, `∂/∂d = N`, `∂/∂h = ẑ`, γ the climb angle), so a
//! bird at rest stays at rest and headings are exact, not finite differences. Each bird banks for
//! its own turn, tan φ = v ω / g (coordinated turn, g in wingspans/s² from `wingspan_m`), reached
//! with a limited roll rate; it pitches with its climb, tan ϑ = ż / v.
//!
//! A turn tighter than the flock can fly (an inner bird below `min_speed`, an outer one above
//! `max_speed`, or a bank beyond `max_bank`) is widened by local smoothing of the path
//! ([`spline::widen`]) and reported once, with the place on the path ([`CourseReport::widened`]).
//! A turn that widening cannot make flyable (still too tight, or the course pulled far off the
//! drawn path: [`spline::unflown`]) is an error naming the place and the radius to give it.
//!
//! Without a path the course frame is the world frame; only the cruise altitude of a flight
//! without a take-off is added, and pitch is filled in.

pub mod file;
pub mod spline;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::animation::{Animation, Frame, PathRecord};
use crate::error::{Error, Result};

pub use file::{PathPoints, PathUnits};
pub use spline::{Course, CourseAt};

/// Gravity, metres per second squared.
const GRAVITY_M_S2: f64 = 9.81;

/// Options of the course (the `course` section of [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CourseOptions {
    /// The leader's path, a JSON or CSV file of control points (world frame); `None`: straight
    /// north.
    pub path: Option<PathBuf>,
    /// Units of the path's coordinates (`None`: the file's `units`, or wingspans).
    pub units: Option<PathUnits>,
    /// Height of a flight without a take-off and without a path, wingspans (`None`: 0, the
    /// course frame's own; a take-off climbs to `initiate.cruise_altitude` instead).
    pub cruise_altitude: Option<f64>,
    /// Largest bank of any bird in a turn, radians.
    pub max_bank: f64,
    /// Largest roll rate, radians per second.
    pub max_roll_rate: f64,
    /// Time constant of the bank following the coordinated-turn bank, seconds.
    pub roll_lag: f64,
    /// Slowest a bird may fly on the inside of a turn, as a fraction of the cruise speed.
    pub min_speed: f64,
    /// Fastest a bird may fly on the outside of a turn, as a fraction of the cruise speed.
    pub max_speed: f64,
}

impl Default for CourseOptions {
    fn default() -> Self {
        CourseOptions {
            path: None,
            units: None,
            cruise_altitude: None,
            max_bank: 40f64.to_radians(),
            max_roll_rate: 90f64.to_radians(),
            roll_lag: 0.25,
            min_speed: 0.6,
            max_speed: 1.4,
        }
    }
}

impl CourseOptions {
    /// Checks every option; errors name `course.*`.
    pub fn validate(&self) -> Result<()> {
        let p = |name: &str, msg: String| Err(Error::parameter(name, msg));
        if let Some(a) = self.cruise_altitude {
            if !(a.is_finite() && (0.0..=1e5).contains(&a)) {
                return p(
                    "course.cruise_altitude",
                    format!(
                        "{a}: must be a number of wingspans at or above the ground, at most 1e5"
                    ),
                );
            }
        }
        if !(self.max_bank > 0.0 && self.max_bank <= 80f64.to_radians()) {
            return p(
                "course.max_bank",
                format!("{}: must be in (0, 80°] (radians)", self.max_bank),
            );
        }
        if !(self.max_roll_rate > 0.0 && self.max_roll_rate.is_finite()) {
            return p(
                "course.max_roll_rate",
                "must be a positive number of radians per second".into(),
            );
        }
        if !(self.roll_lag >= 0.0 && self.roll_lag <= 10.0) {
            return p("course.roll_lag", "must be in [0, 10] seconds".into());
        }
        if !(self.min_speed > 0.0 && self.min_speed < 1.0) {
            return p(
                "course.min_speed",
                format!("{}: must be in (0, 1)", self.min_speed),
            );
        }
        if !(self.max_speed > 1.0 && self.max_speed <= 10.0) {
            return p(
                "course.max_speed",
                format!("{}: must be in (1, 10]", self.max_speed),
            );
        }
        Ok(())
    }

    /// Reads and checks the path file, if any (points in wingspans for birds `wingspan_m` wide).
    pub fn load(&self, wingspan_m: f64) -> Result<Option<PathPoints>> {
        match &self.path {
            None => Ok(None),
            Some(p) => file::read(p, self.units, wingspan_m).map(Some),
        }
    }
}

/// A turn the flock could not fly as drawn.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Widened {
    /// The control point nearest to the tightest place.
    pub point: usize,
    /// Arc length of the tightest place from the first point, wingspans.
    pub s: f64,
    /// Radius there as drawn, wingspans.
    pub radius: f64,
    /// The smallest radius the flock can fly, wingspans.
    pub needed: f64,
}

/// What the course step did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CourseReport {
    /// Length of the flown course, wingspans (0 without a path).
    pub length: f64,
    /// Turns widened (empty when every turn could be flown as drawn).
    pub widened: Vec<Widened>,
    /// Laps of a closed path flown by a loop (0 otherwise).
    pub laps: usize,
    /// Factor applied to the cruise speed so a loop closes on a closed path (1 otherwise).
    pub speed_factor: f64,
    /// One-line warnings for the user (turns widened, the flight running past the path's end).
    pub warnings: Vec<String>,
}

/// Smallest radius at which birds from `d_lo` to `d_hi` wingspans right of the track (d_lo ≤ 0 ≤
/// d_hi) fly a turn within the speed and bank limits at cruise speed `v` (g in wingspans/s²);
/// returns the radius and the binding limit.
pub fn min_radius(
    d_lo: f64,
    d_hi: f64,
    v: f64,
    g: f64,
    opts: &CourseOptions,
) -> (f64, &'static str) {
    let inner = d_hi.max(-d_lo).max(0.0);
    let outer = inner;
    let c = g * opts.max_bank.tan() / (v * v);
    // Outer bird: V²(1 + κd)κ/g ≤ tan φ_max.
    let k_bank = if outer > 1e-9 {
        (-1.0 + (1.0 + 4.0 * outer * c).sqrt()) / (2.0 * outer)
    } else {
        c
    };
    let k_slow = if inner > 1e-9 {
        (1.0 - opts.min_speed) / inner
    } else {
        f64::INFINITY
    };
    let k_fast = if outer > 1e-9 {
        (opts.max_speed - 1.0) / outer
    } else {
        f64::INFINITY
    };
    let mut best = (k_bank, "an outer bird would bank beyond the bank limit");
    if k_slow < best.0 {
        best = (
            k_slow,
            "the inner birds would fly below their minimum speed",
        );
    }
    if k_fast < best.0 {
        best = (
            k_fast,
            "the outer birds would fly above their maximum speed",
        );
    }
    (1.0 / best.0, best.1)
}

/// What the course step needs of the flight before it: the cruise speed (wingspans per second),
/// the take-off's cruise altitude when a take-off was flown, and whether the flight loops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flight {
    /// Cruise speed of the course frame, wingspans per second.
    pub speed: f64,
    /// `Some(altitude)` when the animation begins with a take-off from the ground climbing to
    /// this altitude (wingspans), `None` for a steady flight alone.
    pub takeoff_altitude: Option<f64>,
    /// The steady flight cycles (`steady.loop`).
    pub looped: bool,
}

/// The height of the path's first point, which a take-off climbs to (wingspans); an error when
/// a take-off from the ground could not reach it.
pub fn takeoff_altitude(points: &PathPoints, origin: &Path) -> Result<f64> {
    let z = points.points[0][2];
    if !(z >= 1.0) {
        return Err(Error::format(
            origin,
            format!(
                "point 0: at height {z:.2} wingspans; a take-off from the ground needs the path to start at least 1 wingspan up (raise the path, or fly without the take-off)"
            ),
        ));
    }
    Ok(z)
}

/// The bird whose track the path is: the leader of a flock of one formation; for a flock of
/// several formations the leader nearest the middle of the flock across the course (the median
/// of the leaders' lateral positions at the start of the steady flight), so that the path runs
/// through the middle of the sky of formations rather than along its edge.
fn reference_leader(leaders: &[usize], f: &Frame) -> usize {
    let mut xs: Vec<f64> = leaders
        .iter()
        .filter(|&&l| l < f.x.len())
        .map(|&l| f.x[l])
        .collect();
    if xs.is_empty() {
        return 0;
    }
    xs.sort_by(f64::total_cmp);
    let mid = xs[xs.len() / 2];
    leaders
        .iter()
        .copied()
        .filter(|&l| l < f.x.len())
        .min_by(|&a, &b| (f.x[a] - mid).abs().total_cmp(&(f.x[b] - mid).abs()))
        .unwrap_or(0)
}

/// Maps `anim` (course frame) onto its course: positions, headings, speeds, banks and pitches.
/// `points` is the loaded path (or `None`), `flight` what the earlier stages did.
pub fn apply(
    anim: &mut Animation,
    points: Option<&PathPoints>,
    opts: &CourseOptions,
    flight: Flight,
) -> Result<CourseReport> {
    opts.validate()?;
    let mut report = CourseReport {
        speed_factor: 1.0,
        ..CourseReport::default()
    };
    if anim.frames.is_empty() {
        return Ok(report);
    }
    let g = GRAVITY_M_S2 / anim.wingspan_m;
    let Some(points) = points else {
        if flight.takeoff_altitude.is_none() {
            let alt = opts.cruise_altitude.unwrap_or(0.0);
            for f in &mut anim.frames {
                for z in &mut f.z {
                    *z += alt;
                }
            }
        }
        fill_pitch(anim, flight.looped);
        if anim.frames.iter().any(|f| f.bank.is_none()) {
            let bank = banks(anim, g, opts, flight.looped);
            for (f, b) in anim.frames.iter_mut().zip(bank) {
                f.bank = Some(b);
            }
        }
        return Ok(report);
    };
    let origin = opts.path.clone().unwrap_or_else(|| PathBuf::from("path"));
    let n = anim.birds;
    let steady = anim
        .stage("steady")
        .map(|s| s.start..s.end)
        .unwrap_or(0..anim.frames.len());
    let f_ref = &anim.frames[steady.start.min(anim.frames.len() - 1)];
    let leader = reference_leader(&anim.leaders(), f_ref);
    let x_ref = f_ref.x[leader];
    let s0 = start_along(anim, flight.takeoff_altitude.is_some());
    // The flock's lateral extent and the formation's length (course frame).
    let (mut d_lo, mut d_hi, mut depth) = (0.0f64, 0.0f64, 1.0f64);
    for f in &anim.frames[steady.clone()] {
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for i in 0..n {
            d_lo = d_lo.min(f.x[i] - x_ref);
            d_hi = d_hi.max(f.x[i] - x_ref);
            lo = lo.min(f.y[i]);
            hi = hi.max(f.y[i]);
        }
        depth = depth.max(hi - lo);
    }
    check_above_ground(points, &origin)?;
    check_steepness(points, &origin)?;
    check_backwards(points, depth, &origin)?;
    let (r_min, why) = min_radius(d_lo, d_hi, flight.speed, g, opts);
    let dense = spline::spline_points(&points.points, points.closed);
    if points.closed {
        check_loop_size(&dense, r_min, &origin)?;
    }
    let (drawn, ds_drawn) = spline::resample(&dense, spline::SAMPLE_SPACING);
    let (pts, ds, tight) = spline::widen(
        drawn.clone(),
        ds_drawn,
        points.closed,
        1.0 / r_min,
        spline::SAMPLE_SPACING,
    );
    let cannot = || {
        Error::format(
            &origin,
            format!(
                "the path cannot be widened to the flock's smallest turn radius of {r_min:.0} wingspans ({why}); draw it with wider turns"
            ),
        )
    };
    if pts.len() < 2 {
        return Err(cannot());
    }
    let course = Course::from_samples(pts, ds, points.closed);
    if !(course.length() > 0.0 && course.length().is_finite()) {
        return Err(cannot());
    }
    let nearest_point = |p: [f64; 3]| {
        (0..points.points.len())
            .min_by(|&a, &b| {
                file::dist(points.points[a], p).total_cmp(&file::dist(points.points[b], p))
            })
            .unwrap_or(0)
    };
    if !tight.is_empty() {
        if let Some(u) = spline::unflown(&drawn, ds_drawn, &course, 1.0 / r_min) {
            let point = nearest_point(u.p);
            let what = match u.kind {
                spline::UnflownKind::Tight(r) => format!(
                    "is tighter than the flock can fly even after widening (it still turns at a radius of {r:.1} wingspans)"
                ),
                spline::UnflownKind::Away(d) => format!(
                    "cannot be widened without taking the flock {d:.0} wingspans off the drawn path (its legs are too close together for the turn)"
                ),
            };
            return Err(Error::format(
                &origin,
                format!(
                    "the turn near point {point} ({}), {:.0} wingspans along the path, {what}; give that turn a radius of at least {r_min:.0} wingspans (in a tighter turn {why})",
                    file::show(points.points[point]),
                    u.s
                ),
            ));
        }
    }
    // A reversal at one point (a spike) that the widening let through: no turn of any radius
    // follows both legs, and the widened course would be flown straight through it.
    if let Some((i, deg, along)) = reversal(points) {
        return Err(Error::format(
            &origin,
            format!(
                "the turn near point {i} ({}), {along:.0} wingspans along the path, turns back by {deg:.0}° at one point and cannot be widened into a turn the flock can fly; give that turn a radius of at least {r_min:.0} wingspans, drawn with two or more points",
                file::show(points.points[i]),
            ),
        ));
    }
    report.length = course.length();
    for t in &tight {
        let point = nearest_point(t.p);
        report.widened.push(Widened {
            point,
            s: t.s,
            radius: t.radius,
            needed: r_min,
        });
    }
    if let Some(w) = report
        .widened
        .iter()
        .min_by(|a, b| a.radius.total_cmp(&b.radius))
    {
        report.warnings.push(format!(
            "{}: {} turn(s) too tight for the flock, widened to a radius of {:.0} wingspans; the tightest near point {} ({}), {:.0} wingspans along the path, has a radius of {:.1} wingspans ({}); draw wider turns or slow the flock to fly them as drawn",
            origin.display(),
            report.widened.len(),
            w.needed,
            w.point,
            file::show(points.points[w.point]),
            w.s,
            w.radius,
            why
        ));
    }
    // A loop on a closed path: a whole number of laps over the loop's duration.
    let period = anim.frames.len() as f64 / anim.fps;
    let mut drift = 0.0;
    if flight.looped && points.closed {
        let flown = flight.speed * period;
        let laps = (flown / course.length()).round().max(1.0);
        drift = (laps * course.length() - flown) / period;
        report.laps = laps as usize;
        report.speed_factor = 1.0 + drift / flight.speed;
        if !(opts.min_speed..=opts.max_speed).contains(&report.speed_factor) {
            return Err(Error::format(
                &origin,
                format!(
                    "a loop of {period:.1} s cannot close on this closed path ({:.0} wingspans, {:.1} s a lap at cruise speed) without flying at {:.0} % of the cruise speed; give a duration near a whole number of laps",
                    course.length(),
                    course.length() / flight.speed,
                    100.0 * report.speed_factor
                ),
            ));
        }
        if (report.speed_factor - 1.0).abs() > 0.1 {
            report.warnings.push(format!(
                "{}: a loop of {period:.1} s flies {laps:.0} lap(s) of the closed path ({:.0} wingspans) at {:.0} % of the cruise speed; give a duration near a whole number of laps ({:.1} s a lap) to keep the speed",
                origin.display(),
                course.length(),
                100.0 * report.speed_factor,
                course.length() / flight.speed
            ));
        }
    }
    let z0 = points.points[0][2];
    let alt = flight.takeoff_altitude;
    // In a landing the course-frame height maps linearly onto the height of the path above
    // the ground (the smoothstep of the take-off would not be monotonic for a path that ends
    // far below where it starts), blended in over the landing's first LANDING_BLEND_S.
    let landing_t0 = anim
        .stage("landing")
        .and_then(|s| anim.frames.get(s.start))
        .map(|f| f.t);
    let mut s_max = f64::MIN;
    for f in anim.frames.iter_mut() {
        for i in 0..n {
            let s = f.y[i] - s0 + drift * f.t;
            s_max = s_max.max(s);
            let d = f.x[i] - x_ref;
            let c = course.at(s);
            let (sh, ch) = c.sin_cos;
            let zc = f.z[i];
            let z = match alt {
                Some(a) => {
                    let u = (zc / a).clamp(0.0, 1.0);
                    let mut w = u * u * (3.0 - 2.0 * u);
                    if let Some(t0) = landing_t0 {
                        let b = ((f.t - t0) / LANDING_BLEND_S).clamp(0.0, 1.0);
                        w += b * b * (3.0 - 2.0 * b) * (u - w);
                    }
                    zc + w * (c.p[2] - z0)
                }
                None => c.p[2] + zc,
            };
            // Course-frame velocity (right, along, up).
            let (uh, uv) = (f.heading[i], f.speed[i]);
            let (su, cu) = (uh.sin(), uh.cos());
            let (ux, uy) = (uv * su, uv * cu + drift);
            // The along-track axis is stretched by k (faster outside a turn, slower in a climb).
            let k = c.cos_climb - d * c.turn;
            let along = uy * k;
            let vx = along * sh + ux * ch;
            let vy = along * ch - ux * sh;
            f.x[i] = c.p[0] + d * ch;
            f.y[i] = c.p[1] - d * sh;
            f.z[i] = z;
            f.heading[i] = if drift == 0.0 && uv > 0.0 && k > 0.0 {
                world_heading(c.heading, uh, su, cu, k)
            } else {
                // atan2 is already in [−π, π].
                vx.atan2(vy)
            };
            f.speed[i] = (vx * vx + vy * vy).sqrt();
        }
    }
    let len = course.length();
    if !points.closed && s_max > len + 1.0 {
        report.warnings.push(format!(
            "{}: the flight runs {:.0} wingspans past the path's last point ({:.1} s at cruise speed); it flies straight on there — make the path longer or the flight shorter",
            origin.display(),
            s_max - len,
            (s_max - len) / flight.speed
        ));
    }
    fill_pitch(anim, flight.looped && points.closed);
    let bank = banks(anim, g, opts, flight.looped && points.closed);
    for (f, b) in anim.frames.iter_mut().zip(bank) {
        f.bank = Some(b);
    }
    anim.path = Some(PathRecord {
        source: origin.display().to_string(),
        points: points.points.clone(),
        closed: points.closed,
        length: len,
        widened: !report.widened.is_empty(),
        flown: course.points(1.0, FLOWN_POINTS),
    });
    Ok(report)
}

/// Seconds over which a landing's height mapping turns from the take-off's smoothstep to linear.
const LANDING_BLEND_S: f64 = 1.0;

/// The course-frame along-track position that the path's start is mapped to: the flock's mean
/// at the first frame when it takes off (or lands) from the ground, else the reference leader's.
pub fn start_along(anim: &Animation, grounded: bool) -> f64 {
    let Some(f0) = anim.frames.first() else {
        return 0.0;
    };
    let n = anim.birds.max(1);
    if grounded {
        return f0.y.iter().sum::<f64>() / n as f64;
    }
    let steady = anim
        .stage("steady")
        .map(|s| s.start)
        .unwrap_or(0)
        .min(anim.frames.len() - 1);
    let leader = reference_leader(&anim.leaders(), &anim.frames[steady]);
    f0.y.get(leader).copied().unwrap_or(0.0)
}

/// Largest number of points of the recorded flown course ([`PathRecord::flown`]).
pub const FLOWN_POINTS: usize = 20_000;

/// Refuses a closed path too small for the flock's turns: seen from above, a closed curve whose
/// turns have radii of at least `r_min` is at least 2π `r_min` long (its heading turns through at
/// least a full turn, Fenchel's theorem), so widening a shorter one to `r_min` would shrink it
/// to nothing. `dense` is the spline through the path.
fn check_loop_size(dense: &[[f64; 3]], r_min: f64, origin: &Path) -> Result<()> {
    let around: f64 = dense
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum();
    let needed = 2.0 * std::f64::consts::PI * r_min;
    if around < needed {
        return Err(Error::format(
            origin,
            format!(
                "the closed path is {around:.0} wingspans around (seen from above), too small for the flock: its turns need a radius of at least {r_min:.0} wingspans, so a closed path at least {needed:.0} wingspans around; draw it larger, or slow the flock"
            ),
        ));
    }
    Ok(())
}

/// The world heading of a bird flying at course-frame heading `uh` (sine `su`, cosine `cu`)
/// where the course heads `course` and its along-track axis is stretched by `k` > 0: the heading
/// of (sin uh, k cos uh) turned by `course`, i.e. `course + atan2(sin uh, k cos uh)`, written as
/// `course + uh + δ` with tan δ = sin uh cos uh (1 − k) / (k cos² uh + sin² uh). δ is small
/// (k is within a few percent of 1 and birds fly nearly along the track), so it costs a few
/// multiplications instead of an atan2; wrapped into (−π, π] like atan2's result.
fn world_heading(course: f64, uh: f64, su: f64, cu: f64, k: f64) -> f64 {
    let t = su * cu * (1.0 - k) / (k * cu * cu + su * su);
    let h = course + uh + atan_small(t);
    if h > -PI && h <= PI {
        h
    } else {
        spline::wrap(h)
    }
}

/// atan t, by its series below |t| = 0.01 (the first term left out, t¹¹/11, is below 10⁻²⁰ of
/// t), by libm above.
fn atan_small(t: f64) -> f64 {
    if t.abs() < 0.01 {
        let t2 = t * t;
        t * (1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 / 9.0))))
    } else {
        t.atan()
    }
}

/// Refuses a path with a point below the ground (z < 0): the flock would fly underground.
fn check_above_ground(points: &PathPoints, origin: &Path) -> Result<()> {
    match points.points.iter().position(|p| p[2] < 0.0) {
        Some(i) => Err(Error::format(
            origin,
            format!(
                "point {i} ({}): below the ground (z = {:.2} wingspans); a path is flown at or above z = 0",
                file::show(points.points[i]),
                points.points[i][2]
            ),
        )),
        None => Ok(()),
    }
}

/// Steepest climb or descent of a leg between two control points, degrees: a formation of large
/// birds climbs out at a few degrees and glides down at less than ten; past this a leg is
/// a wall the flock cannot follow (our choice of a generous bound, so that stylised shots keep
/// their steep climbs).
pub const MAX_LEG_SLOPE_DEG: f64 = 45.0;

/// Refuses a leg climbing or descending more steeply than [`MAX_LEG_SLOPE_DEG`], naming its
/// points (the spline through such a leg folds back on itself, which the course used to report
/// as a turn too tight to fly).
fn check_steepness(points: &PathPoints, origin: &Path) -> Result<()> {
    let p = &points.points;
    let n = p.len();
    let legs = if points.closed { n } else { n - 1 };
    for i in 0..legs {
        let (a, b) = (p[i], p[(i + 1) % n]);
        let rise = b[2] - a[2];
        let run = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let slope = rise.abs().atan2(run).to_degrees();
        if slope > MAX_LEG_SLOPE_DEG {
            let need = rise.abs() / MAX_LEG_SLOPE_DEG.to_radians().tan();
            return Err(Error::format(
                origin,
                format!(
                    "points {i} ({}) to {} ({}): the path {} {:.1} wingspans over {:.1} wingspans of ground ({slope:.0}°), steeper than the {MAX_LEG_SLOPE_DEG:.0}° a flock can follow; spread the height change over at least {need:.0} wingspans",
                    file::show(a),
                    (i + 1) % n,
                    file::show(b),
                    if rise > 0.0 { "climbs" } else { "descends" },
                    rise.abs(),
                    run
                ),
            ));
        }
    }
    Ok(())
}

/// The first control point where the path turns back by more than 150° (its index, the turn in
/// degrees and its distance along the control polygon, wingspans).
fn reversal(points: &PathPoints) -> Option<(usize, f64, f64)> {
    let p = &points.points;
    let n = p.len();
    let mut along = 0.0;
    for i in 1..n.saturating_sub(1) {
        let (a, b, c) = (p[i - 1], p[i], p[i + 1]);
        along += file::dist(a, b);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - b[0], c[1] - b[1], c[2] - b[2]];
        let cos = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (file::dist(a, b) * file::dist(b, c));
        if cos < REVERSAL_COS {
            return Some((i, cos.clamp(-1.0, 1.0).acos().to_degrees(), along));
        }
    }
    None
}

/// Cosine of the largest turn at one control point that can be widened (150°).
const REVERSAL_COS: f64 = -0.866_025_403_784_438_6;

/// Refuses a path that turns back on itself (more than 90° at a control point) with a segment
/// shorter than the formation's length `depth` (wingspans): the formation would fly into itself.
fn check_backwards(points: &PathPoints, depth: f64, origin: &Path) -> Result<()> {
    let p = &points.points;
    let n = p.len();
    let inner: Vec<usize> = if points.closed {
        (0..n).collect()
    } else {
        (1..n.saturating_sub(1)).collect()
    };
    for i in inner {
        let a = p[(i + n - 1) % n];
        let b = p[i];
        let c = p[(i + 1) % n];
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - b[0], c[1] - b[1], c[2] - b[2]];
        let (lu, lv) = (file::dist(a, b), file::dist(b, c));
        let cos = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (lu * lv);
        if cos < 0.0 && lu.min(lv) < depth {
            return Err(Error::format(
                origin,
                format!(
                    "point {i} ({}): the path turns back on itself by {:.0}° within one formation length ({depth:.1} wingspans); move the point, or make the legs at least that long",
                    file::show(b),
                    cos.clamp(-1.0, 1.0).acos().to_degrees()
                ),
            ));
        }
    }
    Ok(())
}

/// Fills `pitch`: tan ϑ = ż / v from the height change over neighbouring frames (`cyclic`: the
/// last frame's neighbour is the first).
fn fill_pitch(anim: &mut Animation, cyclic: bool) {
    let nf = anim.frames.len();
    let n = anim.birds;
    let period = nf as f64 / anim.fps;
    let mut out = vec![vec![0.0; n]; nf];
    for (k, row) in out.iter_mut().enumerate() {
        let (a, b, dt) = neighbours(anim, k, cyclic, period);
        if !(dt > 0.0) {
            continue;
        }
        for (i, v) in row.iter_mut().enumerate() {
            let vz = (anim.frames[b].z[i] - anim.frames[a].z[i]) / dt;
            *v = vz.atan2(anim.frames[k].speed[i].max(1e-9));
            if anim.frames[k].speed[i] < 1e-6 && vz.abs() < 1e-6 {
                *v = 0.0;
            }
        }
    }
    for (f, p) in anim.frames.iter_mut().zip(out) {
        f.pitch = Some(p);
    }
}

/// The frames before and after `k` and the time between them.
fn neighbours(anim: &Animation, k: usize, cyclic: bool, period: f64) -> (usize, usize, f64) {
    let nf = anim.frames.len();
    if cyclic && nf > 2 {
        let (a, b) = ((k + nf - 1) % nf, (k + 1) % nf);
        return (a, b, 2.0 * period / nf as f64);
    }
    let (a, b) = (k.saturating_sub(1), (k + 1).min(nf - 1));
    (a, b, anim.frames[b].t - anim.frames[a].t)
}

/// Coordinated-turn banks tan φ* = v ω / g (ω from neighbouring headings), followed with the
/// roll lag and the roll-rate limit, within ±`max_bank` (`cyclic`: run twice round the loop so
/// the last frame leads into the first).
fn banks(anim: &Animation, g: f64, opts: &CourseOptions, cyclic: bool) -> Vec<Vec<f64>> {
    let nf = anim.frames.len();
    let n = anim.birds;
    let period = nf as f64 / anim.fps;
    // Targets of every frame and bird (frame-major, one allocation).
    let mut target = vec![0.0; nf * n];
    for k in 0..nf {
        let (a, b, dt) = neighbours(anim, k, cyclic, period);
        if !(dt > 0.0) {
            continue;
        }
        let (fa, fb, fk) = (&anim.frames[a], &anim.frames[b], &anim.frames[k]);
        for i in 0..n {
            let w = spline::wrap(fb.heading[i] - fa.heading[i]) / dt;
            target[k * n + i] = (fk.speed[i] * w / g)
                .atan()
                .clamp(-opts.max_bank, opts.max_bank);
        }
    }
    let h = 1.0 / anim.fps;
    let mut phi = target[..n].to_vec();
    let mut out = vec![Vec::new(); nf];
    let passes = if cyclic { 2 } else { 1 };
    for pass in 0..passes {
        for k in 0..nf {
            if k > 0 || pass > 0 {
                for (p, &t) in phi.iter_mut().zip(&target[k * n..(k + 1) * n]) {
                    let rate = if opts.roll_lag > 0.0 {
                        (t - *p) / opts.roll_lag
                    } else {
                        (t - *p) / h
                    };
                    let rate = rate.clamp(-opts.max_roll_rate, opts.max_roll_rate);
                    let next = *p + rate * h;
                    *p = if (next - t) * (*p - t) < 0.0 { t } else { next };
                }
            }
            out[k] = phi.clone();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The heading without atan2 is the atan2 of the turned, stretched velocity, in (−π, π],
    /// across headings, stretches and course headings of several turns.
    #[test]
    fn world_heading_is_the_turned_velocity_heading() {
        let mut worst = 0.0f64;
        for a in 0..73 {
            let uh = -PI + a as f64 * (2.0 * PI / 72.0) + 1e-3;
            for &k in &[0.3, 0.6, 0.93, 0.999, 1.0, 1.001, 1.07, 1.4, 2.5] {
                for c in -9..=9 {
                    let course = c as f64 * 0.77;
                    let (su, cu) = (uh.sin(), uh.cos());
                    let (sh, ch) = course.sin_cos();
                    let (vx, vy) = (k * cu * sh + su * ch, k * cu * ch - su * sh);
                    let reference = vx.atan2(vy);
                    let h = world_heading(course, uh, su, cu, k);
                    assert!(h > -PI && h <= PI, "{h}");
                    worst = worst.max(spline::wrap(h - reference).abs());
                }
            }
        }
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn small_atan_matches_libm() {
        for k in -2000..=2000 {
            let t = k as f64 * 1.3e-5;
            let (a, b) = (atan_small(t), t.atan());
            assert!(
                (a - b).abs() <= 2.0 * f64::EPSILON * b.abs(),
                "{t}: {a} {b}"
            );
        }
    }
}
