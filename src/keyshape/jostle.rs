//! Position keeping: each bird's small, frequent moves about its slot in steady flight
//! (docs/jostle.md). The key shapes and their interpolation give the slow, energy-consistent
//! placement; on top of it every bird carries a smooth stationary deviation, lateral and fore-aft,
//! whose statistics are the footage's (`extract::motion`, or the field-data default).
//!
//! The deviation is defined in continuous time, so the same seed gives the same motion at any
//! frame rate: a sum of M cosines with frequencies drawn from N(0, 1/ℓ²) and uniform phases,
//! u(t) = s·√(2/M)·Σ cos(ω_m t + φ_m) (random Fourier features of a Gaussian-kernel process:
//! standard deviation s, autocorrelation exp(−τ²/(2ℓ²))). It is bounded smoothly,
//! d = u/(1 + (u/A)⁴)^(1/4) (close to the identity well inside A, never beyond it), where A is
//! the smaller of `limit` and the bird's room among its neighbours ([`rooms`]: while every bird
//! stays inside its room, no two birds' wings or bodies meet), and faded in
//! over the first `ramp_s` seconds with a smoothstep (the steady flight starts where the
//! take-off hands over, at the first key shape, at rest in the flock's frame). Velocity and
//! acceleration are analytic and bounded: |ü| ≤ s·√(2/M)·Σ ω_m².

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::extract::motion::{AxisKeeping, PositionKeeping};
use crate::extract::params::FormationParams;

/// Options of the position-keeping motion (`steady.jostle`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct JostleOptions {
    /// S, scale of the footage's position keeping: 1 = as measured, 0 = key-shape
    /// interpolation only; in [0, 10].
    pub scale: f64,
    /// M, cosines per bird and axis, in [4, 256].
    pub components: usize,
    /// Fade-in at the start of the steady flight, seconds, in [0, 60].
    pub ramp_s: f64,
    /// A, smooth bound of a bird's deviation on each axis, wingspans, in (0, 1].
    pub limit: f64,
}

impl Default for JostleOptions {
    fn default() -> Self {
        JostleOptions {
            // The footage's position keeping (scale 0: key-shape interpolation only).
            scale: 1.0,
            components: 24,
            ramp_s: 2.0,
            limit: 0.5,
        }
    }
}

impl JostleOptions {
    /// Checks ranges; errors name the option path (`steady.jostle.scale`).
    pub fn validate(&self) -> Result<()> {
        if !(self.scale.is_finite() && (0.0..=10.0).contains(&self.scale)) {
            return Err(Error::parameter(
                "steady.jostle.scale",
                format!(
                    "{}: must be in [0, 10] (1 = the footage's position keeping, 0 = none)",
                    self.scale
                ),
            ));
        }
        if !(4..=256).contains(&self.components) {
            return Err(Error::parameter(
                "steady.jostle.components",
                format!("{}: must be in [4, 256]", self.components),
            ));
        }
        if !(self.ramp_s.is_finite() && (0.0..=60.0).contains(&self.ramp_s)) {
            return Err(Error::parameter(
                "steady.jostle.ramp_s",
                format!("{}: must be in [0, 60] seconds", self.ramp_s),
            ));
        }
        if !(self.limit.is_finite() && self.limit > 0.0 && self.limit <= 1.0) {
            return Err(Error::parameter(
                "steady.jostle.limit",
                format!("{}: must be in (0, 1] wingspans", self.limit),
            ));
        }
        Ok(())
    }
}

/// Φ(x), the standard normal distribution function (Abramowitz & Stegun 7.1.26 through erf,
/// |error| < 1.5e-7).
fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    0.5 * (1.0 + erf.copysign(x))
}

/// Φ⁻¹(p) for p in (0, 1) (Acklam's rational approximation, relative error < 1.2e-9).
fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.024_25 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.024_25 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The wing envelope of the clash test: two flying birds clash when, in the heading frame,
/// they are under this far apart laterally, fore and aft and vertically (wingspans).
pub const WING_ENVELOPE: [f64; 3] = [1.0, 0.15, 0.08];
/// The body test: any one coordinate this far apart keeps two bodies apart (wingspans).
pub const BODY_ENVELOPE: f64 = 0.3;
/// What the position keeping leaves of each envelope on each axis, wingspans: the lateral and
/// fore-aft margins cover the turn of a bird's heading frame by its own small moves (a few
/// degrees over a wingspan's distance).
const MARGIN: [f64; 3] = [0.04, 0.06, 0.02];
/// How strongly an axis that does not keep a pair apart is freed, per wingspan of the other
/// axis's lead (dimensionless).
const RELEASE: f64 = 1.0;
/// Width over which the release sets in, wingspans (it is C¹: the bounds change without kinks).
const RELEASE_WIDTH: f64 = 0.05;
/// Pairs farther apart than this on either horizontal axis do not bound each other (their
/// bounds would be above 1.5 wingspans, a term under 10⁻⁴ of the limit's in the soft minimum).
const NEIGHBOURHOOD: f64 = 4.0;
/// Smallest pair bound, wingspans (a placement that already clashes leaves the birds still).
const FLOOR: f64 = 1e-3;
/// Room (a bound) below which the motion on that axis is scaled down rather than only clipped,
/// so its acceleration stays bounded, wingspans.
pub const FULL_ROOM: f64 = 0.25;

/// The birds' placement before position keeping (key shapes and manoeuvres): lateral, depth
/// behind the leader and height, and their rates, one entry a bird.
#[derive(Debug, Clone, Copy)]
pub struct Placement<'a> {
    /// Lateral positions, wingspans.
    pub x: &'a [f64],
    /// Depths (positive behind), wingspans.
    pub y: &'a [f64],
    /// Heights, wingspans.
    pub z: &'a [f64],
    /// d x / d t, wingspans per second.
    pub vx: &'a [f64],
    /// d y / d t.
    pub vy: &'a [f64],
    /// d z / d t.
    pub vz: &'a [f64],
}

/// How far one bird may deviate on each horizontal axis without meeting a neighbour, and how
/// fast that changes: (lateral, its rate, fore-aft, its rate), wingspans and wingspans per
/// second. Infinite with no neighbour near.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Room {
    /// Lateral bound.
    pub x: f64,
    /// Its rate.
    pub dx: f64,
    /// Fore-aft bound.
    pub y: f64,
    /// Its rate.
    pub dy: f64,
    /// Share of its position keeping the bird flies (0 while it manoeuvres, 1 else).
    pub keep: f64,
    /// Its rate.
    pub dkeep: f64,
}

impl Room {
    /// No neighbour near.
    pub const FREE: Room = Room {
        x: f64::INFINITY,
        dx: 0.0,
        y: f64::INFINITY,
        dy: 0.0,
        keep: 1.0,
        dkeep: 0.0,
    };
}

/// max(0, d) with its corner rounded over [`RELEASE_WIDTH`] (C¹), and its derivative.
fn release(d: f64) -> (f64, f64) {
    let w = RELEASE_WIDTH;
    if d <= 0.0 {
        (0.0, 0.0)
    } else if d < w {
        (d * d / (2.0 * w), d / w)
    } else {
        (d - w / 2.0, 1.0)
    }
}

/// One pair's bounds on the two horizontal axes from one envelope: the slack s_a on each axis
/// (distance beyond the envelope and its margin) and its rate. The axis with the most slack
/// keeps the pair apart: each bird may use half of it. An axis that does not is freed by
/// [`RELEASE`] times the others' lead over it, so a bird moves freely sideways behind a
/// neighbour it is well clear of fore and aft, and the other way round; at a tie both are held
/// to half their slack; an axis without slack frees nothing. (bound, rate) on x and y.
fn pair_bounds(s: [(f64, f64); 3]) -> [(f64, f64); 2] {
    let mut out = [(0.0, 0.0); 2];
    for (a, o) in out.iter_mut().enumerate() {
        let (mut b, mut db) = (0.5 * s[a].0, 0.5 * s[a].1);
        for (c, &(sc, dsc)) in s.iter().enumerate() {
            if c != a {
                // Only an axis that keeps the pair apart itself (positive slack) frees another:
                // its lead over the other, or its whole slack when the other has none.
                let (lead, dlead) = if sc - s[a].0 <= sc {
                    (sc - s[a].0, dsc - s[a].1)
                } else {
                    (sc, dsc)
                };
                let (r, dr) = release(lead);
                b += RELEASE * r;
                db += RELEASE * dr * dlead;
            }
        }
        *o = if b > FLOOR { (b, db) } else { (FLOOR, 0.0) };
    }
    out
}

/// Each bird's [`Room`] in the placement `p`: the soft minimum (Σ b⁻⁸)^(−1/8) ≤ min b over the
/// bounds b its neighbours set on each axis by the wing envelope (under [`WING_ENVELOPE`] on
/// every axis is a clash) and the body envelope (a clash needs every axis under
/// [`BODY_ENVELOPE`]), each with its margin. While every bird stays within its bounds no pair
/// can meet: for each pair, on the axis with the most slack, the two birds together use less
/// than it (the height is not moved by the position keeping). Smooth in the placement, so the
/// bounds change without kinks as neighbours move.
pub fn rooms(p: &Placement) -> Vec<Room> {
    let n = p.x.len();
    if crate::keyshape::separate::bench_without_clearance() {
        return vec![Room::FREE; n];
    }
    // Σ b⁻⁸ and Σ −8 b⁻⁹ b′ per bird and axis.
    let mut acc = vec![[(0.0f64, 0.0f64); 2]; n];
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| p.x[a].total_cmp(&p.x[b]).then(a.cmp(&b)));
    for (k, &i) in idx.iter().enumerate() {
        for &j in &idx[k + 1..] {
            if !(p.x[j] - p.x[i] < NEIGHBOURHOOD) {
                break;
            }
            let dy = p.y[i] - p.y[j];
            if !(dy.abs() < NEIGHBOURHOOD) {
                continue;
            }
            let d = [p.x[i] - p.x[j], dy, p.z[i] - p.z[j]];
            let v = [p.vx[i] - p.vx[j], p.vy[i] - p.vy[j], p.vz[i] - p.vz[j]];
            let abs = |a: usize| (d[a].abs(), if d[a] < 0.0 { -v[a] } else { v[a] });
            let slack = |env: [f64; 3]| -> [(f64, f64); 3] {
                std::array::from_fn(|a| {
                    let (m, dm) = abs(a);
                    (m - env[a] - MARGIN[a], dm)
                })
            };
            let body = [BODY_ENVELOPE; 3];
            for bounds in [pair_bounds(slack(WING_ENVELOPE)), pair_bounds(slack(body))] {
                for (a, &(b, db)) in bounds.iter().enumerate() {
                    let w = b.powi(-8);
                    let dw = -8.0 * w / b * db;
                    for q in [i, j] {
                        acc[q][a].0 += w;
                        acc[q][a].1 += dw;
                    }
                }
            }
        }
    }
    acc.iter()
        .map(|[(sx, dsx), (sy, dsy)]| {
            // R = S^(−1/8), R′ = −S′ R / (8 S).
            let axis = |s: f64, ds: f64| {
                if s > 0.0 {
                    let r = s.powf(-0.125);
                    (r, -ds * r / (8.0 * s))
                } else {
                    (f64::INFINITY, 0.0)
                }
            };
            let (x, dx) = axis(*sx, *dsx);
            let (y, dy) = axis(*sy, *dsy);
            Room {
                x,
                dx,
                y,
                dy,
                ..Room::FREE
            }
        })
        .collect()
}

/// Highest frequency of the deviation, in units of 1/ℓ.
pub const BAND: f64 = 2.5;

/// The statistics the deviation itself must have so that, added to the key shapes' own slow
/// motion (per-bird spread `base` = (lateral, fore-aft) about the mean slot, wingspans), a flock
/// of `birds` birds measured relative to its centroid shows `keep`: the spreads add in
/// quadrature (the deviation supplies the missing variance, at least a quarter of the target's
/// spread), the 0.5 s moves are the deviation's (the key shapes move a bird about 0.01 wingspans
/// in 0.5 s), and the centroid's own share (1/N of the variance) is put back.
pub fn residual_keeping(keep: &PositionKeeping, base: (f64, f64), birds: usize) -> PositionKeeping {
    let centroid = (1.0 - 1.0 / birds.max(2) as f64).sqrt();
    let axis = |a: &AxisKeeping, b: f64| {
        let spread = (a.spread * a.spread - b * b)
            .max((0.25 * a.spread).powi(2))
            .sqrt();
        AxisKeeping::fitted(
            a.move_median / centroid,
            a.move_p90 / centroid,
            a.move_long_median.map(|m| m / centroid),
            spread / centroid,
        )
    };
    PositionKeeping {
        lateral: axis(&keep.lateral, base.0),
        fore_aft: axis(&keep.fore_aft, base.1),
        ..*keep
    }
}

/// The key shapes' slow lateral drift when the birds also keep position: the footage's gap
/// variation `footage_drift` (the standard deviation of a pair of neighbours' gap over the
/// frames) already holds the position keeping of both birds, 2·(S·s)² of its variance for
/// scale S and per-bird spread s; only the rest is left to the key shapes.
pub fn slow_drift(footage_drift: f64, keep: &PositionKeeping, scale: f64) -> f64 {
    let fast = scale * keep.lateral.spread;
    (footage_drift * footage_drift - 2.0 * fast * fast)
        .max(0.0)
        .sqrt()
}

/// Per-bird spread of the key shapes about each bird's mean slot, relative to each key's
/// centroid, median over the birds: (lateral, fore-aft), wingspans.
pub fn key_spread(xs: &[&[f64]], ys: &[&[f64]]) -> (f64, f64) {
    let k = xs.len();
    if k < 2 {
        return (0.0, 0.0);
    }
    let n = xs[0].len();
    let per_bird = |v: &[&[f64]]| {
        let cent: Vec<f64> = v.iter().map(|r| r.iter().sum::<f64>() / n as f64).collect();
        let mut sds: Vec<f64> = (0..n)
            .map(|i| {
                let d: Vec<f64> = (0..k).map(|j| v[j][i] - cent[j]).collect();
                let m = d.iter().sum::<f64>() / k as f64;
                (d.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (k - 1) as f64).sqrt()
            })
            .collect();
        sds.sort_by(f64::total_cmp);
        sds[n / 2]
    };
    (per_bird(xs), per_bird(ys))
}

/// One axis of one bird: amplitude per cosine and (ω, φ) of each.
#[derive(Debug, Clone)]
struct Axis {
    amp: f64,
    waves: Vec<(f64, f64)>,
}

impl Axis {
    fn draw(keep: &AxisKeeping, scale: f64, m: usize, rng: &mut impl Rng) -> Axis {
        let l = keep.time_scale.max(1e-3);
        // Stratified frequencies: one from each of M equal-probability slices of the normal
        // N(0, 1/ℓ²) truncated at |ω| ≤ BAND/ℓ (band-limited, so no rare fast wave makes a bird
        // jerk), so that every bird's spectrum is close to the target's, not only the average.
        let lo = normal_cdf(-BAND);
        let width = 1.0 - 2.0 * lo;
        let waves = (0..m)
            .map(|k| {
                let u: f64 = rng.random();
                let phase: f64 = rng.random::<f64>() * std::f64::consts::TAU;
                let p = lo + width * (k as f64 + u) / m as f64;
                (normal_quantile(p) / l, phase)
            })
            .collect();
        Axis {
            amp: scale * keep.spread * (2.0 / m as f64).sqrt(),
            waves,
        }
    }

    /// u(t), u'(t).
    fn eval(&self, t: f64) -> (f64, f64) {
        let (mut u, mut du) = (0.0, 0.0);
        for &(w, p) in &self.waves {
            let (s, c) = (w * t + p).sin_cos();
            u += c;
            du -= w * s;
        }
        (self.amp * u, self.amp * du)
    }

    /// u, u′ from each wave's (cos, sin) of its angle ω t + φ.
    fn eval_from(&self, cs: &[(f64, f64)]) -> (f64, f64) {
        let (mut u, mut du) = (0.0, 0.0);
        for (&(w, _), &(c, s)) in self.waves.iter().zip(cs) {
            u += c;
            du -= w * s;
        }
        (self.amp * u, self.amp * du)
    }
}

/// Frames between two exact evaluations of a [`JostleClock`]: in between, each wave's angle is
/// advanced by a rotation, whose rounding stays below 10⁻¹⁴ wingspans over this many frames.
const CLOCK_ANCHOR: usize = 64;

/// [`Jostle::at`] for the frames t = k / fps, k = 0, 1, 2, … in order: every wave's cos and sin
/// advance by one rotation a frame (four multiplications instead of a sine and a cosine),
/// recomputed exactly every 64 frames (`CLOCK_ANCHOR`).
#[derive(Debug, Clone)]
pub struct JostleClock<'a> {
    jostle: &'a Jostle,
    fps: f64,
    frame: Option<usize>,
    /// Per bird and axis, each wave's (cos, sin) of its angle at the current frame, then its
    /// rotation per frame (cos ω dt, sin ω dt).
    state: Vec<[WaveState; 2]>,
}

/// One axis's waves in a [`JostleClock`]: (cos, sin) of each angle, and of each step.
type WaveState = (Vec<(f64, f64)>, Vec<(f64, f64)>);

impl<'a> JostleClock<'a> {
    /// Moves to frame `k` (t = k / fps): one step from the previous frame, else exactly.
    pub fn seek(&mut self, k: usize) {
        let t = k as f64 / self.fps;
        let step = self.frame.is_some_and(|f| f + 1 == k) && k % CLOCK_ANCHOR != 0;
        for (b, axes) in self.jostle.birds.iter().zip(self.state.iter_mut()) {
            for (axis, (cs, rot)) in b.iter().zip(axes.iter_mut()) {
                if step {
                    for ((c, s), &(rc, rs)) in cs.iter_mut().zip(rot.iter()) {
                        let (c0, s0) = (*c, *s);
                        *c = c0 * rc - s0 * rs;
                        *s = s0 * rc + c0 * rs;
                    }
                } else {
                    for ((c, s), &(w, p)) in cs.iter_mut().zip(&axis.waves) {
                        let (sn, cn) = (w * t + p).sin_cos();
                        *c = cn;
                        *s = sn;
                    }
                }
            }
        }
        self.frame = Some(k);
    }

    /// Bird `i`'s deviation at the current frame with its room `room` (see [`Jostle::at`]).
    pub fn at(&self, i: usize, room: Room) -> Deviation {
        let t = self.frame.unwrap_or(0) as f64 / self.fps;
        let [(cx, _), (cy, _)] = &self.state[i];
        let [ax, ay] = &self.jostle.birds[i];
        self.jostle
            .shape(t, room, ax.eval_from(cx), ay.eval_from(cy))
    }
}

/// The drawn motion of a flock.
#[derive(Debug, Clone)]
pub struct Jostle {
    birds: Vec<[Axis; 2]>,
    ramp: f64,
    limit: f64,
}

/// A bird's deviation at one time: lateral and fore-aft (positive behind), wingspans, and their
/// rates, wingspans per second.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// Lateral (right of the flight direction).
    pub x: f64,
    /// Fore-aft, positive behind (as the formation frame's y).
    pub y: f64,
    /// d x / d t.
    pub vx: f64,
    /// d y / d t.
    pub vy: f64,
}

/// The statistics the motion reproduces: the footage's, else the field-data default.
pub fn keeping_for(params: &FormationParams) -> PositionKeeping {
    params.motion.unwrap_or_else(PositionKeeping::field_default)
}

impl Jostle {
    /// Draws `birds` birds' motion; `None` when the scale is 0 (nothing is drawn).
    pub fn draw(
        birds: usize,
        keep: &PositionKeeping,
        opts: &JostleOptions,
        rng: &mut impl Rng,
    ) -> Option<Jostle> {
        if opts.scale == 0.0 {
            return None;
        }
        let m = opts.components;
        let birds = (0..birds)
            .map(|_| {
                [
                    Axis::draw(&keep.lateral, opts.scale, m, rng),
                    Axis::draw(&keep.fore_aft, opts.scale, m, rng),
                ]
            })
            .collect();
        Some(Jostle {
            birds,
            ramp: opts.ramp_s,
            limit: opts.limit,
        })
    }

    /// Bird `i`'s deviation at `t` seconds from the start of the steady flight, with its room
    /// `room` among its neighbours ([`rooms`]). On each axis the deviation is bounded by
    /// A = softmin(`limit`, room) and, where A is under [`FULL_ROOM`], scaled down with it, so a
    /// crowded bird keeps still on that axis rather than pressing against its bound (the tests
    /// check every frame against the clash test).
    pub fn at(&self, i: usize, t: f64, room: Room) -> Deviation {
        let [ax, ay] = &self.birds[i];
        self.shape(t, room, ax.eval(t), ay.eval(t))
    }

    /// A clock for the frames t = k / fps in order ([`JostleClock`]).
    pub fn clock(&self, fps: f64) -> JostleClock<'_> {
        let dt = 1.0 / fps;
        let state = self
            .birds
            .iter()
            .map(|axes| {
                axes.clone().map(|a| {
                    let rot = a
                        .waves
                        .iter()
                        .map(|&(w, _)| {
                            let (s, c) = (w * dt).sin_cos();
                            (c, s)
                        })
                        .collect();
                    (vec![(1.0, 0.0); a.waves.len()], rot)
                })
            })
            .collect();
        JostleClock {
            jostle: self,
            fps,
            frame: None,
            state,
        }
    }

    /// The deviation from the raw axis motions (u, u′) of both axes: the ramp, and each axis's
    /// bound and scaling by its room ([`Jostle::at`]).
    fn shape(&self, t: f64, room: Room, ux: (f64, f64), uy: (f64, f64)) -> Deviation {
        let (e, de) = if self.ramp > 0.0 && t < self.ramp {
            let s = (t / self.ramp).max(0.0);
            (s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / self.ramp)
        } else {
            (1.0, 0.0)
        };
        // The fade-in and the share the bird keeps (0 while it manoeuvres).
        let (e, de) = (e * room.keep, de * room.keep + e * room.dkeep);
        let limit = self.limit;
        let axis = |(u, du): (f64, f64), r: f64, dr: f64| -> (f64, f64) {
            // A = (L⁻⁸ + R⁻⁸)^(−1/8) ≤ min(L, R), A′ = A⁹ R⁻⁹ R′.
            let (a, da) = if r.is_finite() {
                let q = (limit / r).powi(8);
                let a = limit * (1.0 + q).powf(-0.125);
                (a, (a / r).powi(9) * dr)
            } else {
                (limit, 0.0)
            };
            // g = softmin(1, A / FULL_ROOM): the motion scaled down where the room is small
            // (scaling, not clipping harder, keeps the acceleration bounded).
            let p = (FULL_ROOM / a).powi(8);
            let g = (1.0 + p).powf(-0.125);
            let dg = (1.0 + p).powf(-1.125) * p / a * da;
            // f(v) = v / (1 + (v/A)⁴)^(1/4): close to the identity inside A, never beyond it
            // (a fourth power, not a higher one, so a bird meeting its bound turns gently).
            let v = g * u;
            let dv = dg * u + g * du;
            let r4 = (v / a).powi(4);
            let f = v * (1.0 + r4).powf(-0.25);
            let df_dv = (1.0 + r4).powf(-1.25);
            let df_da = v * r4 / a * (1.0 + r4).powf(-1.25);
            (e * f, de * f + e * (df_dv * dv + df_da * da))
        };
        let (x, vx) = axis(ux, room.x, room.dx);
        let (y, vy) = axis(uy, room.y, room.dy);
        Deviation { x, y, vx, vy }
    }
}

/// The position keeping of a straight flight along +y (the course frame, `steady` without a
/// path), measured as `extract` measures footage: lateral is world x, fore-aft world y, both
/// relative to the flock's centroid, over the frames from `from_s` seconds on. `None` when the
/// flight is too short.
pub fn measure_animation(
    anim: &crate::animation::Animation,
    from_s: f64,
) -> Option<(AxisKeeping, AxisKeeping)> {
    let frames: Vec<&crate::animation::Frame> =
        anim.frames.iter().filter(|f| f.t >= from_s).collect();
    let times: Vec<f64> = frames.iter().map(|f| f.t).collect();
    let birds: Vec<Vec<(usize, f64, f64)>> = frames
        .iter()
        .map(|f| {
            f.x.iter()
                .zip(&f.y)
                .enumerate()
                .map(|(i, (&x, &y))| (i, x, y))
                .collect()
        })
        .collect();
    crate::extract::motion::measure(&crate::extract::motion::Tracks {
        times: &times,
        frames: &birds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;

    #[test]
    fn derivative_matches_finite_differences() {
        let keep = PositionKeeping::field_default();
        let opts = JostleOptions {
            scale: 1.0,
            ..JostleOptions::default()
        };
        let j = Jostle::draw(3, &keep, &opts, &mut stream(1, "t")).unwrap();
        for &t in &[0.3, 1.7, 5.0, 40.2] {
            let h = 1e-6;
            // Neighbours closing in, tightening both bounds.
            let room = |t: f64| Room {
                x: 0.3 - 0.005 * (t - 5.0),
                dx: -0.005,
                y: 0.08 + 0.001 * (t - 5.0),
                dy: 0.001,
                ..Room::FREE
            };
            let at = |t: f64| j.at(1, t, room(t));
            let (a, b, d) = (at(t - h), at(t + h), at(t));
            assert!(((b.x - a.x) / (2.0 * h) - d.vx).abs() < 1e-6);
            assert!(((b.y - a.y) / (2.0 * h) - d.vy).abs() < 1e-6);
            assert!(d.y.abs() < room(t).y && d.x.abs() < room(t).x);
        }
        assert_eq!(j.at(2, 0.0, Room::FREE), Deviation::default());
    }

    #[test]
    fn the_clock_gives_the_direct_evaluation() {
        let keep = PositionKeeping::field_default();
        let j = Jostle::draw(4, &keep, &JostleOptions::default(), &mut stream(2, "t")).unwrap();
        for fps in [24.0, 30.0, 60.0] {
            let mut clock = j.clock(fps);
            let mut worst: f64 = 0.0;
            // An hour of flight, with a jump (seek out of order) half way.
            let frames = (3600.0 * fps) as usize;
            for k in (0..frames / 2).chain(frames / 2 + 7..frames) {
                clock.seek(k);
                let t = k as f64 / fps;
                for i in 0..4 {
                    let room = Room {
                        x: 1.0,
                        dx: 0.1,
                        y: 0.2,
                        dy: -0.1,
                        ..Room::FREE
                    };
                    let (a, b) = (clock.at(i, room), j.at(i, t, room));
                    worst = worst
                        .max((a.x - b.x).abs())
                        .max((a.y - b.y).abs())
                        .max((a.vx - b.vx).abs())
                        .max((a.vy - b.vy).abs());
                    if k % CLOCK_ANCHOR == 0 {
                        assert_eq!(a, b, "anchor frame {k} at {fps} fps");
                    }
                }
            }
            assert!(worst < 1e-11, "{fps} fps: {worst}");
        }
    }

    /// A placement moving at constant rates: (x, y, z) at time t.
    fn moving(t: f64) -> [Vec<f64>; 3] {
        let x0 = [0.0, 0.8, -0.9, 1.7, 0.85, 2.5];
        let y0 = [0.0, 0.45, 0.5, 1.0, 0.9, 1.3];
        let z0 = [0.0, 0.05, -0.04, 0.02, 0.15, 0.0];
        let v = [0.05, -0.1, 0.02, 0.07, -0.03, 0.0];
        [
            x0.iter().zip(&v).map(|(a, b)| a + b * t).collect(),
            y0.iter().zip(&v).map(|(a, b)| a - 0.5 * b * t).collect(),
            z0.iter().zip(&v).map(|(a, b)| a + 0.2 * b * t).collect(),
        ]
    }

    #[test]
    fn rooms_change_at_the_rate_they_report() {
        let v = [0.05, -0.1, 0.02, 0.07, -0.03, 0.0];
        let vy: Vec<f64> = v.iter().map(|b| -0.5 * b).collect();
        let vz: Vec<f64> = v.iter().map(|b| 0.2 * b).collect();
        let at = |t: f64| {
            let [x, y, z] = moving(t);
            rooms(&Placement {
                x: &x,
                y: &y,
                z: &z,
                vx: &v,
                vy: &vy,
                vz: &vz,
            })
        };
        for t in [0.0, 0.7, 1.9, 3.3] {
            let h = 1e-6;
            let (a, b, r) = (at(t - h), at(t + h), at(t));
            for i in 0..6 {
                assert!(
                    ((b[i].x - a[i].x) / (2.0 * h) - r[i].dx).abs() < 1e-5,
                    "{t} {i}"
                );
                assert!(
                    ((b[i].y - a[i].y) / (2.0 * h) - r[i].dy).abs() < 1e-5,
                    "{t} {i}"
                );
                assert!(r[i].x > 0.0 && r[i].y > 0.0);
            }
        }
    }

    #[test]
    fn birds_inside_their_rooms_never_clash() {
        let mut rng = stream(7, "rooms");
        let mut checked = 0;
        for _ in 0..4000 {
            // Random placements of four birds near each other that do not clash.
            let n = 4;
            let x: Vec<f64> = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
            let y: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let z: Vec<f64> = (0..n).map(|_| rng.random_range(-0.15..0.15)).collect();
            let zero = vec![0.0; n];
            let clash = |x: &[f64], y: &[f64]| {
                (0..n).any(|i| {
                    (i + 1..n).any(|j| {
                        let d = [
                            (x[i] - x[j]).abs(),
                            (y[i] - y[j]).abs(),
                            (z[i] - z[j]).abs(),
                        ];
                        (d[0] < 1.0 && d[1] < 0.15 && d[2] < 0.08)
                            || d.iter().all(|&v| v < BODY_ENVELOPE)
                    })
                })
            };
            let r = rooms(&Placement {
                x: &x,
                y: &y,
                z: &z,
                vx: &zero,
                vy: &zero,
                vz: &zero,
            });
            let crowded = |r: &Room| r.x.min(r.y) <= 2.0 * FLOOR;
            if clash(&x, &y) || r.iter().any(crowded) {
                continue;
            }
            checked += 1;
            // Every bird at a corner of its room, in every direction.
            for _ in 0..8 {
                let mut xs = x.clone();
                let mut ys = y.clone();
                for i in 0..n {
                    let sx = if rng.random::<bool>() { 1.0 } else { -1.0 };
                    let sy = if rng.random::<bool>() { 1.0 } else { -1.0 };
                    xs[i] += sx * 0.999 * r[i].x.min(0.5);
                    ys[i] += sy * 0.999 * r[i].y.min(0.5);
                }
                assert!(!clash(&xs, &ys), "{x:?} {y:?} {z:?} -> {xs:?} {ys:?}");
            }
        }
        assert!(checked > 500, "{checked}");
    }

    #[test]
    fn normal_quantile_inverts_the_distribution() {
        for &x in &[-2.5, -1.0, -0.1, 0.0, 0.7, 2.2] {
            assert!((normal_quantile(normal_cdf(x)) - x).abs() < 2e-6, "{x}");
        }
    }

    #[test]
    fn zero_scale_draws_nothing() {
        let opts = JostleOptions {
            scale: 0.0,
            ..JostleOptions::default()
        };
        let keep = PositionKeeping::field_default();
        assert!(Jostle::draw(3, &keep, &opts, &mut stream(1, "t")).is_none());
        assert!(JostleOptions {
            scale: -1.0,
            ..opts.clone()
        }
        .validate()
        .is_err());
    }
}
