//! Reorganisations of a steady flight (docs/steady-flight.md): leader changes and neighbour
//! swaps. The key shapes are a formation of *slots*, solved once by Algorithm 1 and therefore
//! energy-consistent whoever occupies them; a reorganisation changes which bird flies in which
//! slot. Two birds exchange slots in a smooth manoeuvre of a few seconds: each moves along the
//! line between the two slots (as the slots themselves move with the key shapes) with a
//! smootherstep profile, and passes the other on a side bump perpendicular to that line, so the
//! pair never meets. A leader change is the leader exchanging slots with the first bird of one
//! arm: the leader drops back along that arm and the follower takes the lead (the turn-taking
//! of pairs Voelkl et al. 2015 measured in ibis). A swap is two neighbours along one arm
//! exchanging slots.
//!
//! Everything is in seconds from the start of the steady flight, drawn from the run's
//! `steady.events` stream, so the same seed gives the same reorganisations at any frame rate.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::animation::{Event, EventKind};
use crate::error::{Error, Result};

/// Options of the reorganisations (`steady.reorganise`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReorganiseOptions {
    /// Leader changes per minute of steady flight, in [0, 30] (0 = the leader leads
    /// throughout); unset: [`DEFAULT_LEADER_CHANGES`] with position keeping on
    /// (`steady.jostle.scale` > 0), else 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leader_changes: Option<f64>,
    /// Swaps of two neighbours along an arm per minute of steady flight, in [0, 30]; unset:
    /// [`DEFAULT_SWAPS`] with position keeping on, else 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub swaps: Option<f64>,
    /// Shortest manoeuvre, seconds, in [1, 60].
    pub min_duration_s: f64,
    /// Largest acceleration of a manoeuvring bird relative to the formation, wingspans/s², in
    /// (0, 10]: sets the duration of a long exchange.
    pub max_accel: f64,
    /// Half the lateral distance at which the two birds pass each other, wingspans, in
    /// [0.2, 2].
    pub pass_offset: f64,
    /// Late birds: this many birds fly in from one side and join at the free end of an arm
    /// (0 = none; fewer than the formation's birds).
    #[serde(skip_serializing_if = "is_zero")]
    pub joiners: usize,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

impl Default for ReorganiseOptions {
    fn default() -> Self {
        ReorganiseOptions {
            leader_changes: None,
            swaps: None,
            min_duration_s: 4.0,
            max_accel: 0.5,
            pass_offset: 0.35,
            joiners: 0,
        }
    }
}

/// Leader changes per minute when position keeping is on and no rate is given. No measured
/// rate is published for geese; Voelkl et al. (2015) report frequent, reciprocated turn-taking in
/// ibis: one a minute is this project's choice (docs/steady-flight.md).
pub const DEFAULT_LEADER_CHANGES: f64 = 1.0;

/// Neighbour swaps per minute when position keeping is on and no rate is given (a choice, as
/// [`DEFAULT_LEADER_CHANGES`]).
pub const DEFAULT_SWAPS: f64 = 2.0;

impl ReorganiseOptions {
    /// No reorganisation at all (the behaviour before reorganisations existed).
    pub fn none() -> Self {
        ReorganiseOptions {
            leader_changes: Some(0.0),
            swaps: Some(0.0),
            ..ReorganiseOptions::default()
        }
    }

    /// The rates in effect, (leader changes, swaps) per minute, with position keeping on
    /// (`living`) or off.
    pub fn rates(&self, living: bool) -> (f64, f64) {
        let d = |v: Option<f64>, def: f64| v.unwrap_or(if living { def } else { 0.0 });
        (
            d(self.leader_changes, DEFAULT_LEADER_CHANGES),
            d(self.swaps, DEFAULT_SWAPS),
        )
    }

    /// Checks ranges; errors name the option path (`steady.reorganise.swaps`).
    pub fn validate(&self) -> Result<()> {
        let rate = |name: &str, v: f64| {
            if v.is_finite() && (0.0..=MAX_RATE).contains(&v) {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!(
                        "{v}: must be in [0, {MAX_RATE}] per minute of steady flight (0 = never)"
                    ),
                ))
            }
        };
        if let Some(v) = self.leader_changes {
            rate("steady.reorganise.leader_changes", v)?;
        }
        if let Some(v) = self.swaps {
            rate("steady.reorganise.swaps", v)?;
        }
        if !(self.min_duration_s.is_finite() && (1.0..=60.0).contains(&self.min_duration_s)) {
            return Err(Error::parameter(
                "steady.reorganise.min_duration_s",
                format!("{}: must be in [1, 60] seconds", self.min_duration_s),
            ));
        }
        if !(self.max_accel.is_finite() && self.max_accel > 0.0 && self.max_accel <= 10.0) {
            return Err(Error::parameter(
                "steady.reorganise.max_accel",
                format!("{}: must be in (0, 10] wingspans/s²", self.max_accel),
            ));
        }
        if !(self.pass_offset.is_finite() && (0.2..=2.0).contains(&self.pass_offset)) {
            return Err(Error::parameter(
                "steady.reorganise.pass_offset",
                format!("{}: must be in [0.2, 2] wingspans", self.pass_offset),
            ));
        }
        Ok(())
    }

    /// Whether any reorganisation can happen, with position keeping on (`living`) or off.
    pub fn any(&self, living: bool) -> bool {
        let (l, s) = self.rates(living);
        l > 0.0 || s > 0.0 || self.joiners > 0
    }
}

/// Highest rate of either kind, per minute: one every two seconds is already more than a
/// manoeuvre of a few seconds allows.
pub const MAX_RATE: f64 = 30.0;

/// Seconds after the start of the steady flight before the first reorganisation (the take-off
/// hands over into the first key shape; the birds settle first).
const SETTLE_S: f64 = 3.0;

/// Seconds between the end of one manoeuvre and the start of the next.
const GAP_S: f64 = 1.0;

/// The gap late birds close, wingspans to the side of their slots, and the time they take
/// (field data: a stereo-filmed wild V of white-fronted geese, where birds about 30 wingspans
/// to the side joined in about 5.5 s).
pub const JOIN_GAP: f64 = 30.0;
/// See [`JOIN_GAP`].
pub const JOIN_SECONDS: f64 = 5.5;
/// The last seconds of a join, in which the sideways speed falls smoothly to the formation's.
pub const JOIN_BRAKE_S: f64 = 2.0;
/// The sideways speed of a join is at most this fraction of the cruise speed (a heading at
/// most 39° off the formation's).
pub const JOIN_MAX_SIDEWAYS: f64 = 0.8;
/// Seconds into the steady flight at which the joiners are [`JOIN_GAP`] aside.
pub const JOIN_FROM_S: f64 = 1.0;

/// Late birds flying in from one side to the free end of an arm. Before `t0` they fly in at a
/// constant sideways speed from farther out; from `t0` they close the last [`JOIN_GAP`]
/// wingspans, braking smoothly over the last `brake` seconds, and reach their slots at
/// `t0 + duration`.
#[derive(Debug, Clone, PartialEq)]
pub struct Join {
    /// When the joiners are [`JOIN_GAP`] aside, seconds from the start of the steady flight.
    pub t0: f64,
    /// Seconds from `t0` until they are in their slots.
    pub duration: f64,
    /// The joining birds (the slots they join: the free end of one arm, innermost first).
    pub birds: Vec<usize>,
    /// The side they come from: +1 right, −1 left (the arm's side).
    pub side: f64,
    /// Sideways speed before braking, wingspans per second.
    pub speed: f64,
    /// Braking time, seconds.
    pub brake: f64,
}

impl Join {
    /// Plans `k` joiners into the outermost slots of the arm `arm` (ordered from the leader
    /// outwards; when it is shorter than `k`, the other arm's outermost slots follow), for a
    /// formation flying at `cruise` wingspans per second.
    pub fn plan(arms: &[Vec<usize>; 2], arm: usize, k: usize, cruise: f64) -> Join {
        let mut birds: Vec<usize> = arms[arm].iter().rev().take(k).copied().collect();
        if birds.len() < k {
            let more = k - birds.len();
            birds.extend(arms[1 - arm].iter().rev().take(more));
        }
        birds.reverse();
        let brake = JOIN_BRAKE_S;
        // JOIN_GAP = v (T − brake) + v brake / 2.
        let speed = (JOIN_GAP / (JOIN_SECONDS - 0.5 * brake)).min(JOIN_MAX_SIDEWAYS * cruise);
        let duration = (JOIN_GAP - 0.5 * speed * brake) / speed + brake;
        Join {
            t0: JOIN_FROM_S,
            duration,
            birds,
            side: if arm == 1 { 1.0 } else { -1.0 },
            speed,
            brake,
        }
    }

    /// When the joiners are in their slots, seconds.
    pub fn end(&self) -> f64 {
        self.t0 + self.duration
    }

    /// A joiner's distance to the side of its slot (outwards, wingspans) at `t` and its rate:
    /// a constant closing speed, then a brake whose deceleration rises and falls smoothly
    /// (the speed follows 1 − smoothstep), so the acceleration is continuous.
    pub fn offset(&self, t: f64) -> (f64, f64) {
        let tb = self.end() - self.brake;
        let (v, b) = (self.speed, self.brake);
        if t >= self.end() {
            (0.0, 0.0)
        } else if t >= tb {
            let u = (t - tb) / b;
            let left = 0.5 - u + u * u * u - 0.5 * u * u * u * u;
            (v * b * left, -v * (1.0 - u * u * (3.0 - 2.0 * u)))
        } else {
            (0.5 * v * b + v * (tb - t), -v)
        }
    }

    /// The joiners' event.
    pub fn event(&self, offset: f64) -> Event {
        Event {
            t: offset + self.t0,
            kind: EventKind::Join,
            birds: self.birds.clone(),
            duration: self.duration,
        }
    }
}

/// One planned exchange of two slots.
#[derive(Debug, Clone, PartialEq)]
pub struct Exchange {
    /// Start, seconds from the start of the steady flight.
    pub t0: f64,
    /// Length, seconds.
    pub duration: f64,
    /// What it is.
    pub kind: EventKind,
    /// The two slots: the front one (the leader's for a leader change) and the one behind it.
    pub slots: (usize, usize),
    /// The birds in them when it starts, in the same order.
    pub birds: (usize, usize),
    /// Unit vector (lateral, fore-aft) on which the bird moving back passes; the other passes
    /// on the opposite side.
    pub side: (f64, f64),
    /// The other birds within [`NEAR`] of either slot: they hold still while the two pass.
    pub near: Vec<usize>,
}

/// Distance from either exchanged slot within which the other birds hold their position
/// keeping while two birds pass, wingspans (the passing birds' envelopes sweep past them
/// faster than a bird's small moves about its slot could give way).
pub const NEAR: f64 = 2.0;

/// The arms of a formation of slots at lateral positions `x` and depths `y` (behind the
/// leader): each side's slots ordered from the leader outwards.
pub fn arms(x: &[f64], y: &[f64], leader: usize) -> [Vec<usize>; 2] {
    let mut left: Vec<usize> = (0..x.len())
        .filter(|&i| i != leader && x[i] < x[leader])
        .collect();
    let mut right: Vec<usize> = (0..x.len())
        .filter(|&i| i != leader && x[i] >= x[leader])
        .collect();
    let key = |i: &usize| ((x[*i] - x[leader]).abs(), y[*i]);
    left.sort_by(|a, b| {
        key(a)
            .partial_cmp(&key(b))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    right.sort_by(|a, b| {
        key(a)
            .partial_cmp(&key(b))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    [left, right]
}

/// Derivatives of the smootherstep s(u) = 6u⁵ − 15u⁴ + 10u³: (s, s′).
fn smootherstep(u: f64) -> (f64, f64) {
    let u = u.clamp(0.0, 1.0);
    (
        u * u * u * (u * (6.0 * u - 15.0) + 10.0),
        30.0 * u * u * (u - 1.0) * (u - 1.0),
    )
}

/// The side bump b(u) = 64 u³ (1 − u)³ (1 at the middle, value, slope and curvature 0 at both
/// ends) and its derivative.
fn bump(u: f64) -> (f64, f64) {
    let u = u.clamp(0.0, 1.0);
    let w = u * (1.0 - u);
    (64.0 * w * w * w, 192.0 * w * w * (1.0 - 2.0 * u))
}

/// Height by which each of two exchanging birds leaves its line while they pass, wingspans:
/// the one moving back sinks and the other rises, so they are 0.3 wingspans apart vertically
/// (the wing clash needs them within 0.08), about 22 cm each way for a goose, as birds changing
/// places slip past a little above or below one another. Enough also to clear the bird beside
/// the leader's slot, which a bird taking the lead passes within a wingspan.
pub const PASS_HEIGHT: f64 = 0.15;

/// Share of an exchange over which the vertical parting rises (and, at its end, falls) with a
/// smootherstep: the birds are fully parted from this share to one minus it, while they are
/// within [`crate::keyshape::separate::MIN_STEP`] fore and aft.
const PLATEAU_RAMP: f64 = 0.2;

/// The plateau p(u): 0 at both ends, 1 over [`PLATEAU_RAMP`] ≤ u ≤ 1 − it, smootherstep
/// ramps between (value, slope and curvature continuous), and its derivative.
fn plateau(u: f64) -> (f64, f64) {
    let r = PLATEAU_RAMP;
    if u <= 0.0 || u >= 1.0 {
        (0.0, 0.0)
    } else if u < r {
        let (s, ds) = smootherstep(u / r);
        (s, ds / r)
    } else if u > 1.0 - r {
        let (s, ds) = smootherstep((1.0 - u) / r);
        (s, -ds / r)
    } else {
        (1.0, 0.0)
    }
}

/// Softness of [`clear_of`]'s maximum, wingspans: a log-sum-exp this wide keeps the passing
/// bird's height smooth where the highest (or lowest) near bird changes.
const CLEAR_SOFTNESS: f64 = 0.02;

/// How far beyond the line between its slots a passing bird must go, in the direction `dir`
/// (+1 up, −1 down), to be as far past every near bird's height `near` (height, rate) as
/// [`PASS_HEIGHT`] takes it past the line: a smooth maximum (log-sum-exp, [`CLEAR_SOFTNESS`]) of
/// 0 and each near bird's height beyond the line (`line`, its rate `dline`), and its rate.
fn clear_of(near: &[(f64, f64)], line: f64, dline: f64, dir: f64) -> (f64, f64) {
    let tau = CLEAR_SOFTNESS;
    let beyond: Vec<(f64, f64)> = near
        .iter()
        .map(|&(z, vz)| (dir * (z - line), dir * (vz - dline)))
        .collect();
    let top = beyond.iter().map(|b| b.0).fold(0.0f64, f64::max);
    let mut sum = (-top / tau).exp();
    let mut rate = 0.0;
    for &(v, dv) in &beyond {
        let w = ((v - top) / tau).exp();
        sum += w;
        rate += w * dv;
    }
    (top + tau * sum.ln(), rate / sum)
}

/// Seconds over which a bird's position keeping fades out before a manoeuvre and back in after
/// it ([`Plan::keeping`]).
pub const CALM_S: f64 = 1.0;

/// The plan: exchanges in time order, never overlapping, and the slot of every bird after
/// each of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The late birds, if any; the exchanges come after they have joined.
    pub join: Option<Join>,
    /// The formed birds within [`NEAR`] of a joiner's slot: they hold still while the late
    /// birds close in.
    pub join_near: Vec<usize>,
    /// The exchanges.
    pub exchanges: Vec<Exchange>,
    /// `slot_of[k][b]`: bird b's slot after the first k exchanges (`slot_of[0]` is the identity).
    pub slot_of: Vec<Vec<usize>>,
}

/// A slot's state at one time: position (lateral, depth behind the leader, height) and the rate
/// of the first two.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlotState {
    /// Lateral position, wingspans.
    pub x: f64,
    /// Depth behind the leader's slot (the formation frame's y), wingspans.
    pub y: f64,
    /// Height, wingspans.
    pub z: f64,
    /// d x / d t.
    pub vx: f64,
    /// d y / d t.
    pub vy: f64,
    /// d z / d t.
    pub vz: f64,
}

impl Plan {
    /// Draws the exchanges of a steady flight of `seconds` over slots at lateral positions `x`
    /// and depths `y` (the first key shape) with the leader's slot `leader`. Each kind comes at
    /// intervals drawn uniformly between half and one and a half times its mean interval (60/R
    /// seconds), so a rate of R per minute gives close to R a minute, never a long drought;
    /// a manoeuvre starts at least `GAP_S` after the previous ends and only when it ends before
    /// the flight does.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        x: &[f64],
        y: &[f64],
        leader: usize,
        seconds: f64,
        cruise: f64,
        opts: &ReorganiseOptions,
        living: bool,
        rng: &mut impl Rng,
    ) -> Plan {
        let n = x.len();
        let mut plan = Plan {
            join: None,
            join_near: Vec::new(),
            exchanges: Vec::new(),
            slot_of: vec![(0..n).collect()],
        };
        if !opts.any(living) || n < 2 {
            return plan;
        }
        let arms = arms(x, y, leader);
        let mut free_from = SETTLE_S;
        if opts.joiners > 0 {
            // Late birds join the longer arm, so the formation they find is the more even one
            // (a V of five finding two more at the end of an arm, as in the footage); between
            // arms of one length the side is drawn (first, so it does not depend on the rates).
            let drawn = rng.random_range(0..2usize);
            let arm = match arms[0].len().cmp(&arms[1].len()) {
                std::cmp::Ordering::Less => 1,
                std::cmp::Ordering::Greater => 0,
                std::cmp::Ordering::Equal => drawn,
            };
            let join = Join::plan(&arms, arm, opts.joiners.min(n - 1), cruise);
            free_from = free_from.max(join.end() + GAP_S);
            plan.join_near = (0..n)
                .filter(|q| !join.birds.contains(q))
                .filter(|&q| {
                    join.birds
                        .iter()
                        .any(|&r| (x[q] - x[r]).hypot(y[q] - y[r]) < NEAR)
                })
                .collect();
            plan.join = Some(join);
        }
        let (leader_changes, swaps) = opts.rates(living);
        let mut times: Vec<(f64, EventKind)> = Vec::new();
        for (rate, kind) in [
            (leader_changes, EventKind::LeaderChange),
            (swaps, EventKind::Swap),
        ] {
            if rate <= 0.0 {
                continue;
            }
            let mean = 60.0 / rate;
            let mut t = SETTLE_S;
            loop {
                t += mean * rng.random_range(0.5..1.5);
                if t >= seconds {
                    break;
                }
                times.push((t, kind));
            }
        }
        times.sort_by(|a, b| a.0.total_cmp(&b.0));
        let pairs_of = |kind: EventKind| -> Vec<(usize, usize)> {
            match kind {
                EventKind::LeaderChange => arms
                    .iter()
                    .filter_map(|a| a.first().map(|&f| (leader, f)))
                    .collect(),
                _ => arms
                    .iter()
                    .flat_map(|a| a.windows(2).map(|w| (w[0], w[1])))
                    .collect(),
            }
        };
        for (t, kind) in times {
            let pairs = pairs_of(kind);
            if pairs.is_empty() {
                continue;
            }
            // Drawn even when the manoeuvre does not fit, so one event's fate does not shift
            // the choices of the next.
            let (sa, sb) = pairs[rng.random_range(0..pairs.len())];
            let t0 = t.max(free_from);
            let (dx, dy) = (x[sb] - x[sa], y[sb] - y[sa]);
            let d = dx.hypot(dy).max(1e-9);
            // Smootherstep's peak acceleration is 10/√3 · d / T².
            let duration = opts
                .min_duration_s
                .max((10.0 / 3f64.sqrt() * d / opts.max_accel).sqrt());
            if t0 + duration > seconds - 0.5 {
                continue;
            }
            // The bird moving back passes on the outside of the arm (ahead of the line between
            // the slots, away from the leader's side).
            let s = if dx >= 0.0 { 1.0 } else { -1.0 };
            let side = (s * dy / d, -s * dx / d);
            let current = plan.slot_of.last().cloned().unwrap_or_default();
            let bird_in = |slot: usize| current.iter().position(|&q| q == slot).unwrap_or(slot);
            let birds = (bird_in(sa), bird_in(sb));
            let mut next = current.clone();
            next[birds.0] = sb;
            next[birds.1] = sa;
            let near = (0..n)
                .filter(|&q| q != sa && q != sb)
                .filter(|&q| {
                    [sa, sb]
                        .iter()
                        .any(|&r| (x[q] - x[r]).hypot(y[q] - y[r]) < NEAR)
                })
                .map(&bird_in)
                .collect();
            plan.exchanges.push(Exchange {
                t0,
                duration,
                kind,
                slots: (sa, sb),
                birds,
                side,
                near,
            });
            plan.slot_of.push(next);
            free_from = t0 + duration + GAP_S;
        }
        plan
    }

    /// Number of exchanges finished by `t` (an exchange in progress is not finished).
    fn finished(&self, t: f64) -> usize {
        self.exchanges
            .iter()
            .take_while(|e| e.t0 + e.duration <= t)
            .count()
    }

    /// Each bird's state at `t` from the slots' states `slots` at `t`, and the pass offset `h`.
    pub fn birds_at(&self, t: f64, slots: &[SlotState], h: f64) -> Vec<SlotState> {
        let k = self.finished(t);
        let assign = &self.slot_of[k];
        let mut out: Vec<SlotState> = assign.iter().map(|&s| slots[s]).collect();
        if let Some(e) = self.exchanges.get(k).filter(|e| t > e.t0) {
            let u = (t - e.t0) / e.duration;
            let (s, ds) = smootherstep(u);
            let (b, db) = bump(u);
            let (ds, db) = (ds / e.duration, db / e.duration);
            let (pa, pb) = (slots[e.slots.0], slots[e.slots.1]);
            // The two birds also part vertically while they pass, the one moving back
            // sinking and the other rising, so they never fly wing over wing (a fixed side:
            // one chosen from the slots' heights would flip when those cross).
            let (p, dp) = plateau(u);
            let dp = dp / e.duration;
            let up = -1.0;
            // The birds near the exchange hold their slots (their position keeping fades out):
            // each passing bird parts from them as well as from its partner, the rising one
            // PASS_HEIGHT above the highest of them, the sinking one as far below the lowest
            // (a bird beside the leader's slot may fly higher than the line between the slots).
            let near: Vec<(f64, f64)> = e
                .near
                .iter()
                .filter_map(|&q| assign.get(q).and_then(|&sq| slots.get(sq)))
                .map(|st| (st.z, st.vz))
                .collect();
            // `from` → `to`, passing on `sign` · side.
            let blend = |from: SlotState, to: SlotState, sign: f64| {
                let dir = sign * up;
                let line = (1.0 - s) * from.z + s * to.z;
                let dline = (1.0 - s) * from.vz + s * to.vz + ds * (to.z - from.z);
                let (m, dm) = clear_of(&near, line, dline, dir);
                let (lift, dlift) = (PASS_HEIGHT + m, dm);
                SlotState {
                    x: (1.0 - s) * from.x + s * to.x + sign * h * b * e.side.0,
                    y: (1.0 - s) * from.y + s * to.y + sign * h * b * e.side.1,
                    z: line + dir * lift * p,
                    vz: dline + dir * (lift * dp + dlift * p),
                    vx: (1.0 - s) * from.vx
                        + s * to.vx
                        + ds * (to.x - from.x)
                        + sign * h * db * e.side.0,
                    vy: (1.0 - s) * from.vy
                        + s * to.vy
                        + ds * (to.y - from.y)
                        + sign * h * db * e.side.1,
                }
            };
            out[e.birds.0] = blend(pa, pb, 1.0);
            out[e.birds.1] = blend(pb, pa, -1.0);
        }
        if let Some(j) = &self.join {
            let (o, v) = j.offset(t);
            for &b in &j.birds {
                out[b].x += j.side * o;
                out[b].vx += j.side * v;
            }
        }
        out
    }

    /// The share of its position keeping bird `b` flies at `t`, and its rate: 0 while it
    /// exchanges places, two birds pass near it, or it flies in to join (the manoeuvre is the motion then; its neighbours'
    /// envelopes change too fast for the small moves about a slot), back to 1 over
    /// [`CALM_S`] before and after with a smootherstep.
    pub fn keeping(&self, b: usize, t: f64) -> (f64, f64) {
        let spans = self
            .exchanges
            .iter()
            .filter(|e| e.birds.0 == b || e.birds.1 == b || e.near.contains(&b))
            .map(|e| (e.t0, e.t0 + e.duration))
            .chain(
                self.join
                    .iter()
                    .filter(|j| j.birds.contains(&b))
                    .map(|j| (f64::NEG_INFINITY, j.end())),
            )
            .chain(
                self.join
                    .iter()
                    .filter(|_| self.join_near.contains(&b))
                    .map(|j| (j.end() - j.brake, j.end())),
            );
        let (mut k, mut dk) = (1.0, 0.0);
        for (a, z) in spans {
            // 1 − the fade: down over [a − CALM_S, a], 0 to z, up over [z, z + CALM_S].
            let (f, df) = if t <= a - CALM_S || t >= z + CALM_S {
                (1.0, 0.0)
            } else if t < a {
                let (s, ds) = smootherstep((a - t) / CALM_S);
                (s, -ds / CALM_S)
            } else if t > z {
                let (s, ds) = smootherstep((t - z) / CALM_S);
                (s, ds / CALM_S)
            } else {
                (0.0, 0.0)
            };
            dk = dk * f + k * df;
            k *= f;
        }
        (k, dk)
    }

    /// Whether bird `b` is still flying in to join at `t`.
    pub fn joining(&self, b: usize, t: f64) -> bool {
        self.join
            .as_ref()
            .is_some_and(|j| t < j.end() && j.birds.contains(&b))
    }

    /// The slot of every bird at `t`: before an exchange in progress ends, the one it started
    /// from.
    pub fn slots_at(&self, t: f64) -> &[usize] {
        &self.slot_of[self.finished(t)]
    }

    /// The exchanges as the animation file's events, at `offset` seconds plus their start.
    pub fn events(&self, offset: f64) -> Vec<Event> {
        let join = self.join.iter().map(|j| j.event(offset));
        join.chain(self.exchanges.iter().map(|e| Event {
            t: offset + e.t0,
            kind: e.kind,
            birds: vec![e.birds.0, e.birds.1],
            duration: e.duration,
        }))
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v9() -> (Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (0..9).map(|i| (i as f64 - 4.0) * 0.8).collect();
        let y: Vec<f64> = x.iter().map(|x| x.abs() * 1.5).collect();
        (x, y)
    }

    #[test]
    fn arms_run_outwards_from_the_leader() {
        let (x, y) = v9();
        let [l, r] = arms(&x, &y, 4);
        assert_eq!(l, vec![3, 2, 1, 0]);
        assert_eq!(r, vec![5, 6, 7, 8]);
    }

    #[test]
    fn profiles_match_finite_differences() {
        for u in [0.1, 0.3, 0.5, 0.77] {
            let h = 1e-6;
            let fd = (smootherstep(u + h).0 - smootherstep(u - h).0) / (2.0 * h);
            assert!((fd - smootherstep(u).1).abs() < 1e-6);
            let fd = (bump(u + h).0 - bump(u - h).0) / (2.0 * h);
            assert!((fd - bump(u).1).abs() < 1e-6);
        }
        assert_eq!(bump(0.5).0, 1.0);
        assert_eq!(smootherstep(1.0).0, 1.0);
    }

    #[test]
    fn rates_are_kept_and_exchanges_do_not_overlap() {
        let (x, y) = v9();
        let opts = ReorganiseOptions {
            leader_changes: Some(2.0),
            swaps: Some(2.0),
            ..ReorganiseOptions::default()
        };
        for seed in 0..20 {
            let plan = Plan::draw(
                &x,
                &y,
                4,
                120.0,
                10.0,
                &opts,
                true,
                &mut crate::rng::seeded(seed),
            );
            let leaders = plan
                .exchanges
                .iter()
                .filter(|e| e.kind == EventKind::LeaderChange)
                .count();
            assert!(leaders >= 2, "seed {seed}: {leaders} leader changes");
            for w in plan.exchanges.windows(2) {
                assert!(w[1].t0 >= w[0].t0 + w[0].duration + GAP_S - 1e-9);
            }
            let last = plan.exchanges.last().unwrap();
            assert!(last.t0 + last.duration <= 120.0);
            // Every assignment is a permutation.
            for a in &plan.slot_of {
                let mut s = a.clone();
                s.sort();
                assert_eq!(s, (0..9).collect::<Vec<_>>());
            }
        }
    }

    #[test]
    fn exchanging_birds_keep_apart_and_end_in_each_others_slot() {
        let (x, y) = v9();
        let opts = ReorganiseOptions {
            leader_changes: Some(3.0),
            swaps: Some(3.0),
            ..ReorganiseOptions::default()
        };
        let plan = Plan::draw(
            &x,
            &y,
            4,
            60.0,
            10.0,
            &opts,
            true,
            &mut crate::rng::seeded(7),
        );
        assert!(!plan.exchanges.is_empty());
        let slots: Vec<SlotState> = (0..9)
            .map(|i| SlotState {
                x: x[i],
                y: y[i],
                ..SlotState::default()
            })
            .collect();
        let mut t = 0.0;
        while t < 60.0 {
            let b = plan.birds_at(t, &slots, opts.pass_offset);
            for i in 0..9 {
                for j in i + 1..9 {
                    let d = (b[i].x - b[j].x).hypot(b[i].y - b[j].y);
                    assert!(d > 0.5, "t {t}: birds {i} and {j} {d:.3} apart");
                }
            }
            t += 0.01;
        }
        let e = &plan.exchanges[0];
        let after = plan.birds_at(e.t0 + e.duration, &slots, opts.pass_offset);
        assert!((after[e.birds.0].x - x[e.slots.1]).abs() < 1e-12);
        assert!((after[e.birds.1].y - y[e.slots.0]).abs() < 1e-12);
    }

    #[test]
    fn zero_rates_plan_nothing_and_bad_rates_name_the_option() {
        let (x, y) = v9();
        let p = Plan::draw(
            &x,
            &y,
            4,
            600.0,
            10.0,
            &ReorganiseOptions::none(),
            true,
            &mut crate::rng::seeded(1),
        );
        assert!(p.exchanges.is_empty());
        let p = Plan::draw(
            &x,
            &y,
            4,
            600.0,
            10.0,
            &ReorganiseOptions::default(),
            false,
            &mut crate::rng::seeded(1),
        );
        assert!(
            p.exchanges.is_empty(),
            "without position keeping the default is none"
        );
        for (o, name) in [
            (
                ReorganiseOptions {
                    leader_changes: Some(f64::NAN),
                    ..ReorganiseOptions::default()
                },
                "steady.reorganise.leader_changes",
            ),
            (
                ReorganiseOptions {
                    swaps: Some(1e9),
                    ..ReorganiseOptions::default()
                },
                "steady.reorganise.swaps",
            ),
        ] {
            assert!(o.validate().unwrap_err().to_string().starts_with(name));
        }
    }
}
