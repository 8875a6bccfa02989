//! Landing: the stage after the steady flight that brings the flock down to the ground or onto
//! water, in the course frame (straight along +y, before the course step maps it onto a path).
//!
//! The paper has no landing; the model here is ours (docs/landing.md). It is a kinematic plan,
//! not a simulation, built so that no two birds come closer than they were in the formation
//! (times a factor) without any pairwise checks:
//!
//! 1. *Loosen and slow down.* Every bird slows from the cruise speed V to the approach speed
//!    V_a over [`LandingOptions::slow_seconds`], all with the same along-track speed, so the
//!    formation's along-track gaps are kept; the lateral offsets from the formation's middle grow
//!    by the factor [`LandingOptions::loosen`] (one common blend: lateral gaps only grow; in a
//!    flock of several formations each loosens about its own middle, as much as its neighbours
//!    side by side leave room for).
//! 2. *Glide.* Each bird descends on the glide slope (sink rate V_a tan γ in the world, ramped in
//!    over a second) so that it reaches the ground at its touch-down time.
//! 3. *Flare.* Over [`LandingOptions::flare_seconds`] before touch-down the sink rate and the
//!    speed fall smoothly to the touch-down speed, the body pitched up, wings spread.
//! 4. *Touch down and stop.* Birds touch down front first, bird i at
//!    T_i = T_0 + β (y_front − y_i) / V_a with β = [`LandingOptions::stagger`]: a bird behind
//!    flies on at V_a a little longer, so an along-track gap g shrinks to (1 − β) g at rest but
//!    never below it. On the ground a few running steps take the speed to zero at
//!    [`LandingOptions::run_decel_ms2`]; on water the feet ski and the body settles at the
//!    waterline, stopping at [`LandingOptions::water_decel_ms2`].
//!
//! Every profile is a smoothstep blend of speeds (continuous velocity, bounded acceleration), and
//! all times are seconds, so the same plan comes out at any frame rate. Each bird's velocity at
//! the end of the flight is blended into the plan over the first second.

use serde::{Deserialize, Serialize};

pub use crate::animation::landing::{LandingRecord, Surface, FLOAT_HEIGHT};
use crate::animation::{Animation, Frame, Stage, StageName};
use crate::error::{Error, Result};

/// Nose-up pitch of a bird at touch-down, radians (26°; our choice, from photographs of geese
/// and swans landing, body steeply up with the wings spread as air brakes).
pub const FLARE_PITCH: f64 = 0.45;

/// Options of the landing (the `landing` section of [`crate::pipeline::Config`]). Every number
/// is our choice where docs/landing.md does not give a source.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LandingOptions {
    /// Where the flock lands.
    pub surface: Surface,
    /// Glide-slope angle below the horizontal in the world, radians.
    pub glide_angle: f64,
    /// Approach speed, fraction of the cruise speed.
    pub approach_speed: f64,
    /// Speed at touch-down (end of the flare), metres per second (at most 0.8 of the approach
    /// speed).
    pub touchdown_speed_ms: f64,
    /// Time over which the flock slows from the cruise to the approach speed, seconds.
    pub slow_seconds: f64,
    /// Length of the flare, seconds.
    pub flare_seconds: f64,
    /// Factor by which the lateral offsets from the formation's middle grow, ≥ 1.
    pub loosen: f64,
    /// Fraction β of an along-track gap used up by the later touch-down, in [0, 0.8].
    pub stagger: f64,
    /// Deceleration of the running steps on the ground, metres per second squared.
    pub run_decel_ms2: f64,
    /// Deceleration on water (feet skiing, then the body), metres per second squared.
    pub water_decel_ms2: f64,
    /// Time the flock sits at rest after the last bird stops, seconds.
    pub rest_seconds: f64,
}

impl Default for LandingOptions {
    fn default() -> Self {
        LandingOptions {
            surface: Surface::Ground,
            glide_angle: 12f64.to_radians(),
            approach_speed: 0.5,
            touchdown_speed_ms: 3.5,
            slow_seconds: 3.0,
            flare_seconds: 1.2,
            loosen: 1.25,
            stagger: 0.5,
            run_decel_ms2: 3.0,
            water_decel_ms2: 6.0,
            rest_seconds: 1.5,
        }
    }
}

impl LandingOptions {
    /// Checks every option; errors name `landing.*`.
    pub fn validate(&self) -> Result<()> {
        let check = |name: &str, v: f64, lo: f64, hi: f64, what: &str| {
            if v.is_finite() && v >= lo && v <= hi {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!("{v}: must be {what} in [{lo}, {hi}]"),
                ))
            }
        };
        check(
            "landing.glide_angle",
            self.glide_angle,
            1f64.to_radians(),
            45f64.to_radians(),
            "an angle (radians)",
        )?;
        check(
            "landing.approach_speed",
            self.approach_speed,
            0.2,
            1.0,
            "a fraction of the cruise speed",
        )?;
        check(
            "landing.touchdown_speed_ms",
            self.touchdown_speed_ms,
            0.6,
            30.0,
            "a speed (m/s)",
        )?;
        check(
            "landing.slow_seconds",
            self.slow_seconds,
            0.5,
            60.0,
            "a time (s)",
        )?;
        check(
            "landing.flare_seconds",
            self.flare_seconds,
            0.2,
            5.0,
            "a time (s)",
        )?;
        check("landing.loosen", self.loosen, 1.0, 3.0, "a factor")?;
        check("landing.stagger", self.stagger, 0.0, 0.8, "a fraction")?;
        check(
            "landing.run_decel_ms2",
            self.run_decel_ms2,
            0.5,
            20.0,
            "a deceleration (m/s²)",
        )?;
        check(
            "landing.water_decel_ms2",
            self.water_decel_ms2,
            0.5,
            30.0,
            "a deceleration (m/s²)",
        )?;
        check(
            "landing.rest_seconds",
            self.rest_seconds,
            0.0,
            600.0,
            "a time (s)",
        )
    }
}

/// Where the landing goes, in the course frame, and how high the flock is in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Cruise speed, wingspans per second.
    pub speed: f64,
    /// The flock's cruise altitude in the course frame, wingspans (the ground is z = 0).
    pub altitude: f64,
    /// Height of the flock above the ground in the world where it lands, wingspans (the
    /// course-frame descent is scaled so that the world glide slope is the option's).
    pub world_height: f64,
    /// Least ratio of a world along-track distance to its course-frame one where the flock
    /// flies at its cruise width (1 on a straight course; on a path, the inside of a turn: the
    /// slowest a bird flies in a turn as a fraction of the cruise speed, 0.6 by default). The
    /// landing keeps its along-track gaps clear of the clash test after the course is bent.
    pub along_scale: f64,
}

/// smoothstep on [0, 1], clamped.
fn smooth(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// ∫₀ˣ smoothstep, for x in [0, 1]; ½ from x = 1 on: the distance covered by a unit blend.
fn smooth_int(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let x = x.min(1.0);
    x * x * x - 0.5 * x * x * x * x
}

/// Distance covered from time 0 by a speed that goes from `a` to `b` by a smoothstep over `dur`
/// seconds and stays at `b`.
fn blend_dist(a: f64, b: f64, dur: f64, t: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    let u = t / dur;
    let ramp = (a - b) * dur * (u.min(1.0) - smooth_int(u));
    b * t + ramp
}

/// Speed at time `t` of the blend of [`blend_dist`].
fn blend_speed(a: f64, b: f64, dur: f64, t: f64) -> f64 {
    a + (b - a) * smooth(t / dur)
}

/// One bird's landing, times from the landing's start (seconds), course frame.
#[derive(Debug, Clone, Copy)]
struct BirdPlan {
    x0: f64,
    y0: f64,
    z0: f64,
    /// Lateral position at rest.
    x1: f64,
    /// The part of `x1 − x0` that pulls apart two birds ending abreast, made over the first
    /// [`PULL_S`] (the rest over the loosening).
    pull: f64,
    /// Start of the descent, start of the flare, touch-down, rest.
    descend: f64,
    flare: f64,
    touchdown: f64,
    rest: f64,
    /// Sink rate of the glide, course frame, wingspans per second.
    sink: f64,
    /// Initial velocity minus the plan's (lateral, along).
    dvx: f64,
    dvy: f64,
}

/// The flock's plan: the common along-track profile and each bird's times.
#[derive(Debug, Clone)]
struct Plan {
    v: f64,
    va: f64,
    vtd: f64,
    slow: f64,
    flare: f64,
    run: f64,
    loosen_time: f64,
    ramp: f64,
    surface: Surface,
    birds: Vec<BirdPlan>,
}

/// Time over which each bird's initial velocity difference is blended out, seconds.
const BLEND_S: f64 = 1.0;

/// Time over which birds that would end the landing abreast are pulled apart, seconds: as short
/// as the blend of velocities, which can close their gap fore and aft.
const PULL_S: f64 = 0.5;
/// Time over which the sink rate ramps in, seconds.
const RAMP_S: f64 = 1.0;

impl Plan {
    /// The common along-track distance flown from the start until time `t` while cruising and
    /// slowing to the approach speed.
    fn common(&self, t: f64) -> f64 {
        blend_dist(self.v, self.va, self.slow, t)
    }

    fn common_speed(&self, t: f64) -> f64 {
        blend_speed(self.v, self.va, self.slow, t)
    }

    /// Along-track distance of bird `b` from its start, and its along speed, at time `t`.
    fn along(&self, b: &BirdPlan, t: f64) -> (f64, f64) {
        if t <= b.flare {
            return (self.common(t), self.common_speed(t));
        }
        let base = self.common(b.flare);
        let u = t - b.flare;
        if t <= b.touchdown {
            return (
                base + blend_dist(self.va, self.vtd, self.flare, u),
                blend_speed(self.va, self.vtd, self.flare, u),
            );
        }
        let base = base + blend_dist(self.va, self.vtd, self.flare, self.flare);
        let u = t - b.touchdown;
        (
            base + blend_dist(self.vtd, 0.0, self.run, u),
            blend_speed(self.vtd, 0.0, self.run, u),
        )
    }

    /// Height above the course-frame ground of bird `b` at time `t`: the integral of its sink
    /// rate, which ramps in over [`RAMP_S`] from `descend`, holds, and ramps out over the flare.
    fn height(&self, b: &BirdPlan, t: f64) -> f64 {
        if t <= b.descend {
            return b.z0;
        }
        if t >= b.touchdown {
            return 0.0;
        }
        let w = b.sink;
        let u = (t.min(b.flare) - b.descend).max(0.0);
        let mut z = b.z0 - w * (self.ramp * smooth_int(u / self.ramp) + (u - self.ramp).max(0.0));
        if t > b.flare {
            let v = t - b.flare;
            z -= w * (v - self.flare * smooth_int(v / self.flare));
        }
        z.max(0.0)
    }

    /// Lateral position and speed of bird `b` at time `t`.
    fn lateral(&self, b: &BirdPlan, t: f64) -> (f64, f64) {
        let u = t / self.loosen_time;
        let s = smooth(u);
        let ds = if (0.0..1.0).contains(&u) {
            6.0 * u * (1.0 - u) / self.loosen_time
        } else {
            0.0
        };
        let p = t / PULL_S;
        let dp = if (0.0..1.0).contains(&p) {
            6.0 * p * (1.0 - p) / PULL_S
        } else {
            0.0
        };
        let d = b.x1 - b.pull - b.x0;
        (b.x0 + d * s + b.pull * smooth(p), d * ds + b.pull * dp)
    }

    /// World-frame state (course frame) of bird `b` at `t`: x, y, z, vx, vy.
    fn state(&self, b: &BirdPlan, t: f64) -> [f64; 5] {
        let (s, vs) = self.along(b, t);
        let (x, vx) = self.lateral(b, t);
        let z = self.height(b, t);
        // The initial velocity difference, blended out over BLEND_S.
        let e = BLEND_S * (t.min(BLEND_S) / BLEND_S - smooth_int(t / BLEND_S));
        let de = 1.0 - smooth(t / BLEND_S);
        [
            x + b.dvx * e,
            b.y0 + s + b.dvy * e,
            z,
            vx + b.dvx * de,
            vs + b.dvy * de,
        ]
    }
}

/// What [`land`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LandingStats {
    /// Seconds from the landing's start to the first touch-down.
    pub first_touchdown_s: f64,
    /// Seconds from the first touch-down to the last.
    pub touchdown_spread_s: f64,
    /// Seconds from the landing's start until every bird is at rest.
    pub seconds: f64,
    /// Along-track distance from the front bird's position at the landing's start to its
    /// resting place, wingspans.
    pub front_distance: f64,
}

/// The plan of a landing that starts from frame `anim.frames.last()` advanced by one frame.
fn plan(anim: &Animation, opts: &LandingOptions, site: &Site) -> Result<(Plan, f64)> {
    let last = anim
        .frames
        .last()
        .ok_or_else(|| Error::Internal("a landing after no flight".into()))?;
    plan_from(anim, last, opts, site)
}

/// The plan of a landing that starts one frame after `last`, a frame of `anim`.
fn plan_from(
    anim: &Animation,
    last: &Frame,
    opts: &LandingOptions,
    site: &Site,
) -> Result<(Plan, f64)> {
    let n = anim.birds;
    let ws = anim.wingspan_m;
    let dt = 1.0 / anim.fps;
    let v = site.speed;
    let va = opts.approach_speed * v;
    let vtd = (opts.touchdown_speed_ms / ws).min(0.8 * va);
    let decel = match opts.surface {
        Surface::Ground => opts.run_decel_ms2,
        Surface::Water => opts.water_decel_ms2,
    } / ws;
    // A smoothstep stop from vtd averages vtd / run; its peak deceleration is 1.5 times that.
    let run = 1.5 * vtd / decel;
    let height = site.world_height.max(1e-3);
    let alt = site.altitude.max(1e-3);
    // Course-frame sink rate whose world image is V_a tan γ.
    let sink = va * opts.glide_angle.tan() * alt / height;
    let ramp = RAMP_S;
    let flare = opts.flare_seconds;
    let start: Vec<[f64; 5]> = (0..n)
        .map(|i| {
            let (h, sp) = (last.heading[i], last.speed[i]);
            let (vx, vy) = (sp * h.sin(), sp * h.cos());
            [
                last.x[i] + vx * dt,
                last.y[i] + vy * dt,
                last.z[i].max(0.0),
                vx,
                vy,
            ]
        })
        .collect();
    if start.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::Internal(
            "a landing from a frame that is not finite".into(),
        ));
    }
    let y_front = start.iter().map(|s| s[1]).fold(f64::MIN, f64::max);
    // Each bird's formation loosens about its own middle (a flock of one formation about the
    // flock's), by its own factor.
    let (x1, pull, loosen) = loosening(anim, &start, v, opts.loosen);
    // Length of the descent of a bird starting at height z (the area of its sink profile is z),
    // at least the ramp and the flare (a bird low down sinks more slowly).
    let descent_len = |z: f64| (z / sink + 0.5 * (ramp + flare)).max(ramp + flare);
    // On a bent course an along-track gap of the course frame shrinks by up to 1 − κ d on the
    // inside of a turn, and the loosened flock is wider by `loosen`.
    let bend = (1.0 - (1.0 - site.along_scale.clamp(0.0, 1.0)) * loosen).max(0.2);
    let beta = clear_stagger(&start, &x1, v, opts.stagger, bend);
    let lag = |y: f64| beta * (y_front - y) / va;
    // The front bird's touch-down: after the slowdown and the flare, and late enough that no
    // bird needs to start descending before the landing starts (at half the slowdown).
    let mut t_front = opts.slow_seconds + flare;
    for s in &start {
        t_front = t_front.max(0.5 * opts.slow_seconds + descent_len(s[2]) - lag(s[1]));
    }
    let birds: Vec<BirdPlan> = start
        .iter()
        .zip(x1.iter().zip(&pull))
        .map(|(s, (&x1, &pull))| {
            let touchdown = t_front + lag(s[1]);
            let len = descent_len(s[2]);
            BirdPlan {
                x0: s[0],
                y0: s[1],
                z0: s[2],
                x1,
                pull,
                descend: touchdown - len,
                sink: s[2] / (len - 0.5 * (ramp + flare)),
                flare: touchdown - flare,
                touchdown,
                rest: touchdown + run,
                dvx: s[3],
                dvy: s[4] - v,
            }
        })
        .collect();
    let p = Plan {
        v,
        va,
        vtd,
        slow: opts.slow_seconds,
        flare,
        run,
        loosen_time: t_front - flare,
        ramp,
        surface: opts.surface,
        birds,
    };
    Ok((p, last.t + dt))
}

/// Each bird's lateral place at the end of the loosening (course frame, wingspans), and the
/// widest ratio by which a formation widened.
///
/// A flock of one formation loosens about its middle by [`clear_loosen`]'s factor. In a flock of
/// several formations each formation loosens about its own middle (loosening a flock hundreds of
/// wingspans wide about its middle would move its outer formations sideways at tens of degrees
/// off the course), by a factor capped so that the formations flying side by side (their
/// along-track extents within [`SIDE_BY_SIDE`] of each other) keep more than a span and a margin
/// between them (each may grow towards a neighbour by at most half the gap beyond that), and
/// birds that would still end abreast within the wing envelope are pulled apart locally
/// ([`pulled_apart`]).
fn loosening(
    anim: &Animation,
    start: &[[f64; 5]],
    v: f64,
    loosen: f64,
) -> (Vec<f64>, Vec<f64>, f64) {
    use crate::animation::clearance::SPAN;
    let n = start.len();
    let of = anim.formation_of_birds();
    let k = of.iter().copied().max().map_or(1, |m| m + 1);
    // Each formation's extent at the start: [x_min, x_max, y_min, y_max].
    let mut ext = vec![[f64::MAX, f64::MIN, f64::MAX, f64::MIN]; k];
    for (s, &f) in start.iter().zip(&of) {
        let e = &mut ext[f];
        e[0] = e[0].min(s[0]);
        e[1] = e[1].max(s[0]);
        e[2] = e[2].min(s[1]);
        e[3] = e[3].max(s[1]);
    }
    let mids: Vec<f64> = ext.iter().map(|e| 0.5 * (e[0] + e[1])).collect();
    if k <= 1 {
        let f = clear_loosen(start, v, loosen);
        let m = mids[0];
        return (
            start.iter().map(|s| m + f * (s[0] - m)).collect(),
            vec![0.0; n],
            f,
        );
    }
    let mut x1 = vec![0.0; n];
    let mut pull = vec![0.0; n];
    let mut widest = 1.0f64;
    for f in 0..k {
        let members: Vec<usize> = (0..n).filter(|&i| of[i] == f).collect();
        let half = 0.5 * (ext[f][1] - ext[f][0]);
        let room = (0..k)
            .filter(|&g| g != f)
            .filter(|&g| {
                ext[g][2] - SIDE_BY_SIDE < ext[f][3] && ext[f][2] - SIDE_BY_SIDE < ext[g][3]
            })
            .map(|g| {
                let gap = (ext[g][0] - ext[f][1]).max(ext[f][0] - ext[g][1]);
                (0.5 * (gap - SPAN - STAGGER_MARGIN)).max(0.0)
            })
            .fold(f64::INFINITY, f64::min);
        let factor = if half > 1e-9 {
            loosen.min(1.0 + room / half).max(1.0)
        } else {
            loosen
        };
        let m = mids[f];
        let own = pulled_apart(start, &members, m, v, factor);
        for (&i, &(x, p)) in members.iter().zip(&own) {
            x1[i] = m + x;
            pull[i] = p;
        }
        if half > 1e-9 {
            let (lo, hi) = own
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &(x, _)| (a.min(x), b.max(x)));
            widest = widest.max((hi - lo) / (2.0 * half));
        }
    }
    (x1, pull, widest)
}

/// The loosened lateral offsets of `members` (birds of one formation) from their middle `m`:
/// every offset times `factor`, and the gaps between birds that would still fly abreast within
/// the wing envelope after the blend of their velocities (less than a span and a margin aside,
/// within a chord and a margin fore and aft) widened to a span and a margin, locally: the
/// widening is added to the gaps between those two birds only, so lateral gaps only grow and the
/// formation widens by the widenings, not by a larger factor everywhere.
///
/// Returns each member's (offset, the part of it that pulls apart), in the order of `members`.
fn pulled_apart(
    start: &[[f64; 5]],
    members: &[usize],
    m: f64,
    v: f64,
    factor: f64,
) -> Vec<(f64, f64)> {
    use crate::animation::clearance::{CHORD, SPAN};
    let span = SPAN + STAGGER_MARGIN;
    let drift = 0.5 * BLEND_S;
    // Positions in `members`, sorted by lateral place; `extra[r]` widens the gap between ranks
    // r − 1 and r.
    let base = |k: usize| factor * (start[members[k]][0] - m);
    let mut order: Vec<usize> = (0..members.len()).collect();
    order.sort_by(|&a, &b| {
        base(a)
            .total_cmp(&base(b))
            .then(members[a].cmp(&members[b]))
    });
    // Where the bird is when the blend of velocities is done, before any loosening: the pull,
    // made by then, must part the two birds a span on its own.
    let x = |k: usize| start[members[k]][0] + start[members[k]][3] * drift;
    let y = |k: usize| start[members[k]][1] + (start[members[k]][4] - v) * drift;
    let mut extra = vec![0.0f64; order.len()];
    for a in 0..order.len() {
        for b in a + 1..order.len() {
            let apart = x(order[b]) - x(order[a]);
            if apart >= span {
                break;
            }
            let dx = apart + extra[a + 1..=b].iter().sum::<f64>();
            if (y(order[a]) - y(order[b])).abs() < CHORD + STAGGER_MARGIN && dx < span {
                extra[b] += span - dx;
            }
        }
    }
    let total: f64 = extra.iter().sum();
    let mut out = vec![(0.0, 0.0); members.len()];
    let mut acc = 0.0;
    for (r, &k) in order.iter().enumerate() {
        acc += extra[r];
        out[k] = (base(k) + acc - 0.5 * total, acc - 0.5 * total);
    }
    out
}

/// Along-track distance within which two formations count as side by side for the landing's
/// loosening, wingspans.
const SIDE_BY_SIDE: f64 = 2.0;

/// Largest factor the landing loosens the formation by to bring birds abreast a span apart.
pub const MAX_CLEAR_LOOSEN: f64 = 2.0;

/// The loosening actually used: `loosen`, or more (up to [`MAX_CLEAR_LOOSEN`]), so that two
/// birds flying abreast within the wing envelope at the landing's start (after the blend of
/// their velocities, see [`clear_stagger`]) end it at least a span and a margin apart aside.
fn clear_loosen(start: &[[f64; 5]], v: f64, loosen: f64) -> f64 {
    use crate::animation::clearance::{CHORD, SPAN};
    let span = SPAN + STAGGER_MARGIN;
    let drift = 0.5 * BLEND_S;
    let x = |i: usize| start[i][0] + start[i][3] * drift;
    let y = |i: usize| start[i][1] + (start[i][4] - v) * drift;
    let mut order: Vec<usize> = (0..start.len()).collect();
    order.sort_by(|&a, &b| x(a).total_cmp(&x(b)));
    let mut out = loosen;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            let dx = x(b) - x(a);
            if dx >= span {
                break;
            }
            if (y(a) - y(b)).abs() < CHORD + STAGGER_MARGIN && dx > 1e-6 {
                out = out.max((span / dx).min(MAX_CLEAR_LOOSEN));
            }
        }
    }
    out
}

/// Margin kept beyond the clash test's span and chord by the landing's stagger, wingspans.
pub const STAGGER_MARGIN: f64 = 0.03;

/// The stagger actually used: `stagger`, or less, so that no two birds end the landing within
/// the wing envelope of the clash test (less than a span aside and a chord fore and aft) unless
/// they started it so. The landing's lateral offsets only grow (by `loosen`, done before the
/// first touch-down) and its along-track gaps only shrink (to (1 − β) of the start's, after the
/// first touch-down), so a pair clear at the start and at the end is clear throughout; a pair
/// abreast at the end (loosened offset under a span) keeps d1 − β d0 ≥ chord + margin (d1 its
/// along-track gap after the blend of velocities, d0 at the start: the touch-down lag is reckoned
/// from the start's places, so the gap closes by β d0, not β d1).
/// `start` holds each bird's [x, y, vx, vy] at the landing's start, `loosened` each bird's
/// lateral place at the end of the loosening ([`loosening`]),
/// `v` the flight speed: each bird's velocity difference from the plan is blended out over the
/// first [`BLEND_S`], moving it by half that difference times the blend, which counts here.
/// `bend` is the least ratio of a world along-track gap to its course-frame one (1 on a straight
/// course): the kept gap is the chord and margin over it.
fn clear_stagger(start: &[[f64; 5]], loosened: &[f64], v: f64, stagger: f64, bend: f64) -> f64 {
    use crate::animation::clearance::{BODY, CHORD, SPAN};
    let span = SPAN + STAGGER_MARGIN;
    let clear = CHORD + STAGGER_MARGIN;
    let mut order: Vec<usize> = (0..start.len()).collect();
    let drift = 0.5 * BLEND_S;
    let x1 = |i: usize| loosened[i] + start[i][3] * drift;
    let y1 = |i: usize| start[i][1] + (start[i][4] - v) * drift;
    order.sort_by(|&a, &b| x1(a).total_cmp(&x1(b)));
    let mut beta = stagger;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if x1(b) - x1(a) >= span {
                break;
            }
            // The gap after the blend, d1, shrinks by β times the gap at the start, d0 (the
            // touch-down lag is reckoned from the start's places), to d1 − β d0.
            let (mut d1, mut d0) = (y1(a) - y1(b), start[a][1] - start[b][1]);
            if d1 < 0.0 {
                (d1, d0) = (-d1, -d0);
            }
            // Birds at rest are held to the body test: a pair nearly in line must stop a body's
            // distance apart, not only a chord.
            let dx = x1(b) - x1(a);
            let body = BODY + STAGGER_MARGIN;
            let need = if dx < body {
                clear.max((body * body - dx * dx).sqrt())
            } else {
                clear
            };
            let bent = need / bend.clamp(0.2, 1.0);
            if d1 >= bent {
                if d0 > 0.0 {
                    beta = beta.min((d1 - bent) / d0);
                }
            } else if d1 >= clear || dx < body {
                // Clear now, but with no room to close up (on a bent course, or in line): no
                // stagger.
                beta = 0.0;
            }
        }
    }
    beta.max(0.0)
}

/// Along-track distance from the front bird's place at the end of the flight to the landed
/// flock's front (its farthest resting place), wingspans, for `anim` as it is: what a course
/// that must end where the flock lands needs.
pub fn front_distance(anim: &Animation, opts: &LandingOptions, site: &Site) -> Result<f64> {
    let last = anim
        .frames
        .last()
        .ok_or_else(|| Error::Internal("a landing after no flight".into()))?;
    front_distance_from(anim, last, opts, site)
}

/// [`front_distance`] for a landing that starts one frame after `last`, a frame of `anim`.
pub fn front_distance_from(
    anim: &Animation,
    last: &Frame,
    opts: &LandingOptions,
    site: &Site,
) -> Result<f64> {
    let (p, _) = plan_from(anim, last, opts, site)?;
    let y_front = p.birds.iter().map(|b| b.y0).fold(f64::MIN, f64::max);
    let far = p
        .birds
        .iter()
        .map(|b| p.state(b, b.rest + 1.0)[1])
        .fold(f64::MIN, f64::max);
    Ok(far - y_front)
}

/// Appends the landing stage to `anim` (course frame, after the steady flight): frames every
/// 1/fps from one frame after the last until every bird has been at rest for
/// [`LandingOptions::rest_seconds`] (or until `total_frames` frames in all, when given: an error
/// when the landing needs more). Records the touch-downs in `anim.landing`.
pub fn land(
    anim: &mut Animation,
    opts: &LandingOptions,
    site: &Site,
    total_frames: Option<usize>,
) -> Result<LandingStats> {
    opts.validate()?;
    if anim.looped {
        return Err(Error::parameter(
            "landing",
            "a loop cycles for ever and cannot end in a landing; fly it without the loop",
        ));
    }
    if !(site.speed.is_finite() && site.speed > 0.0) {
        return Err(Error::Internal(format!(
            "a landing at cruise speed {}",
            site.speed
        )));
    }
    let (p, t0) = plan(anim, opts, site)?;
    let n = anim.birds;
    let end_rest = p.birds.iter().map(|b| b.rest).fold(0.0, f64::max);
    let first_td = p.birds.iter().map(|b| b.touchdown).fold(f64::MAX, f64::min);
    let last_td = p.birds.iter().map(|b| b.touchdown).fold(f64::MIN, f64::max);
    let dt = 1.0 / anim.fps;
    let start = anim.frames.len();
    let needed = ((end_rest + opts.rest_seconds) / dt).ceil() as usize + 1;
    let count = match total_frames {
        Some(total) => {
            let room = total.saturating_sub(start);
            let least = (end_rest / dt).ceil() as usize + 1;
            if room < least {
                return Err(Error::parameter(
                    "shot_seconds",
                    format!(
                        "the shot ends {:.1} s into the landing, which needs {:.1} s until every bird is at rest; give a longer shot",
                        room as f64 * dt,
                        least as f64 * dt
                    ),
                ));
            }
            room
        }
        None => needed,
    };
    crate::limits::check_animation_size("landing", n, start + count)?;
    let ys: Vec<f64> = p.birds.iter().map(|b| b.y0).collect();
    let y_front = ys.iter().copied().fold(f64::MIN, f64::max);
    let mut headings: Vec<f64> = anim
        .frames
        .last()
        .map(|f| f.heading.clone())
        .unwrap_or_default();
    for j in 0..count {
        let t = j as f64 * dt;
        let mut f = Frame {
            t: t0 + t,
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            heading: Vec::with_capacity(n),
            speed: Vec::with_capacity(n),
            ..Frame::default()
        };
        for (i, b) in p.birds.iter().enumerate() {
            let [x, y, z, vx, vy] = p.state(b, t);
            let sp = vx.hypot(vy);
            // Keep the heading of a bird that has stopped.
            if sp > 1e-6 {
                headings[i] = vx.atan2(vy);
            }
            f.x.push(x);
            f.y.push(y);
            f.z.push(z);
            f.heading.push(headings[i]);
            f.speed.push(sp);
        }
        anim.frames.push(f);
    }
    anim.stages.push(Stage {
        name: StageName::Landing,
        start,
        end: start + count,
    });
    anim.landing = Some(LandingRecord {
        surface: p.surface,
        touchdown: p.birds.iter().map(|b| t0 + b.touchdown).collect(),
        rest: p.birds.iter().map(|b| t0 + b.rest).collect(),
        flare_seconds: p.flare,
    });
    let far = p
        .birds
        .iter()
        .map(|b| p.state(b, b.rest + 1.0)[1])
        .fold(f64::MIN, f64::max);
    Ok(LandingStats {
        first_touchdown_s: first_td,
        touchdown_spread_s: last_td - first_td,
        seconds: end_rest,
        front_distance: far - y_front,
    })
}

/// Pitches each bird up in its flare (nose up by `pitch` radians at touch-down, blended with
/// [`LandingRecord::flare_weight`]); run after the course step, which sets the pitch of the
/// glide from the climb angle.
pub fn flare_pitch(anim: &mut Animation, pitch: f64) {
    let Some(rec) = anim.landing.clone() else {
        return;
    };
    for f in &mut anim.frames {
        let Some(p) = f.pitch.as_mut() else {
            continue;
        };
        for (i, v) in p.iter_mut().enumerate() {
            let w = rec.flare_weight(i, f.t);
            if w > 0.0 {
                *v += w * (pitch - *v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flight(n: usize, fps: f64) -> Animation {
        let mut a = Animation::new(0, fps, 1.5, n);
        let frames = (fps as usize).max(2);
        for k in 0..frames {
            let t = k as f64 / fps;
            a.frames.push(Frame {
                t,
                x: (0..n)
                    .map(|i| {
                        let r = i.div_ceil(2) as f64;
                        if i % 2 == 1 {
                            0.77 * r
                        } else {
                            -0.77 * r
                        }
                    })
                    .collect(),
                y: (0..n)
                    .map(|i| 10.0 * t - 1.24 * i.div_ceil(2) as f64)
                    .collect(),
                z: vec![10.0; n],
                heading: vec![0.0; n],
                speed: vec![10.0; n],
                ..Frame::default()
            });
        }
        a.stages.push(Stage {
            name: StageName::Steady,
            start: 0,
            end: frames,
        });
        a
    }

    fn site() -> Site {
        Site {
            speed: 10.0,
            altitude: 10.0,
            world_height: 10.0,
            along_scale: 1.0,
        }
    }

    #[test]
    fn every_bird_lands_front_first_and_stops_apart() {
        let mut a = flight(14, 30.0);
        let start = a.frames.len();
        let stats = land(&mut a, &LandingOptions::default(), &site(), None).unwrap();
        assert!(stats.touchdown_spread_s > 0.5, "{stats:?}");
        let last = a.frames.last().unwrap();
        assert!(last.z.iter().all(|&z| z == 0.0));
        assert!(last.speed.iter().all(|&v| v == 0.0));
        let rec = a.landing.clone().unwrap();
        let order = rec.arrival_order();
        assert_eq!(order[0], 0, "the leader lands first");
        for w in a.frames[start..].windows(2) {
            for i in 0..14 {
                // Bounded accelerations: speed changes < 6 m/s² · dt.
                let dv = (w[1].speed[i] - w[0].speed[i]).abs() * 1.5 * 30.0;
                assert!(dv < 6.0, "bird {i} at {}: {dv} m/s²", w[1].t);
                let dz = (w[1].z[i] - w[0].z[i]).abs() * 30.0;
                assert!(dz < 2.5, "bird {i}: sink {dz} wingspans/s");
                assert!(w[1].z[i] >= 0.0);
            }
            for i in 0..14 {
                for j in 0..i {
                    let d = (w[1].x[i] - w[1].x[j])
                        .hypot(w[1].y[i] - w[1].y[j])
                        .hypot(w[1].z[i] - w[1].z[j]);
                    assert!(d > 0.6, "birds {i}, {j} at {}: {d}", w[1].t);
                }
            }
        }
    }

    #[test]
    fn the_plan_is_the_same_at_any_frame_rate() {
        let mut a = flight(9, 24.0);
        let mut b = flight(9, 60.0);
        land(&mut a, &LandingOptions::default(), &site(), None).unwrap();
        land(&mut b, &LandingOptions::default(), &site(), None).unwrap();
        let (ra, rb) = (a.landing.unwrap(), b.landing.unwrap());
        for (x, y) in ra.touchdown.iter().zip(&rb.touchdown) {
            assert!((x - y).abs() < 1e-9);
        }
    }

    #[test]
    fn surfaces_parse_and_bad_ones_are_refused() {
        assert_eq!(Surface::parse("water").unwrap(), Surface::Water);
        let e = Surface::parse("lava").unwrap_err().to_string();
        assert!(e.contains("lava") && e.contains("ground or water"), "{e}");
    }
}
