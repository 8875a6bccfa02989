//! Position keeping: each bird's small, frequent moves about its slot in steady flight
//! (docs/jostle.md). The key shapes and their interpolation give the slow, energy-consistent
//! placement; on top of it every bird carries a smooth stationary deviation, lateral and fore-aft,
//! whose statistics are the footage's (`extract::motion`, or the field-data default).
//!
//! The deviation is defined in continuous time, so the same seed gives the same motion at any
//! frame rate: a sum of M cosines with frequencies drawn from N(0, 1/ℓ²) and uniform phases,
//! u(t) = s·√(2/M)·Σ cos(ω_m t + φ_m) (random Fourier features of a Gaussian-kernel process:
//! standard deviation s, autocorrelation exp(−τ²/(2ℓ²))). It is bounded smoothly,
//! d = u/(1 + (u/A)⁸)^(1/8) (the identity well inside A = `limit`, never beyond it, so no bird
//! strays far enough to meet a neighbour), and faded in
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

/// Closest two birds may come by their deviations, wingspans.
pub const CLEARANCE: f64 = 0.45;
/// Smallest room, wingspans.
const MIN_BOUND: f64 = 0.02;
/// Room (half the clearance left by the nearest neighbour) at which a bird keeps position fully,
/// wingspans.
pub const FULL_ROOM: f64 = 0.25;

/// Each bird's distance to its nearest neighbour, as the smooth minimum
/// D = (Σ_j d_j⁻⁸)^(−1/8) ≤ min_j d_j over the other birds (wingspans), and its rate of change
/// (wingspans per second), from positions `x`, `y` and velocities `vx`, `vy`. Smooth, so the
/// bound it sets changes without kinks when the nearest neighbour changes.
pub fn nearest(x: &[f64], y: &[f64], vx: &[f64], vy: &[f64]) -> Vec<(f64, f64)> {
    let n = x.len();
    (0..n)
        .map(|i| {
            let (mut sum, mut dsum) = (0.0, 0.0);
            for j in (0..n).filter(|&j| j != i) {
                let (dx, dy) = (x[i] - x[j], y[i] - y[j]);
                let d = dx.hypot(dy).max(1e-9);
                let rate = (dx * (vx[i] - vx[j]) + dy * (vy[i] - vy[j])) / d;
                let w = d.powi(-8);
                sum += w;
                dsum += -8.0 * w / d * rate;
            }
            if sum == 0.0 {
                return (f64::INFINITY, 0.0);
            }
            let big = sum.powf(-1.0 / 8.0);
            (big, -big / (8.0 * sum) * dsum)
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

    /// Bird `i`'s deviation at the current frame (see [`Jostle::at`]).
    pub fn at(&self, i: usize, nearest: f64, nearest_rate: f64) -> Deviation {
        let t = self.frame.unwrap_or(0) as f64 / self.fps;
        let [(cx, _), (cy, _)] = &self.state[i];
        let [ax, ay] = &self.jostle.birds[i];
        self.jostle
            .shape(t, nearest, nearest_rate, ax.eval_from(cx), ay.eval_from(cy))
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

    /// Bird `i`'s deviation at `t` seconds from the start of the steady flight, with the
    /// bird's nearest neighbour `nearest` wingspans away in the key-shape placement and that
    /// distance changing at `nearest_rate` wingspans per second ([`nearest`]). Each axis is
    /// bounded by `limit`, and the whole motion is scaled by softmin(1, room/FULL_ROOM) with
    /// room = 0.02 + (nearest − CLEARANCE)/2, so a bird crowded by a neighbour keeps still (the
    /// tests check every frame's closest pair).
    pub fn at(&self, i: usize, t: f64, nearest: f64, nearest_rate: f64) -> Deviation {
        let [ax, ay] = &self.birds[i];
        self.shape(t, nearest, nearest_rate, ax.eval(t), ay.eval(t))
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

    /// The deviation from the raw axis motions (u, u′) of both axes: the ramp, the room scaling
    /// and the bound of [`Jostle::at`].
    fn shape(
        &self,
        t: f64,
        nearest: f64,
        nearest_rate: f64,
        ux: (f64, f64),
        uy: (f64, f64),
    ) -> Deviation {
        let (e, de) = if self.ramp > 0.0 && t < self.ramp {
            let s = (t / self.ramp).max(0.0);
            (s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / self.ramp)
        } else {
            (1.0, 0.0)
        };
        // The motion is scaled down, g = softmin(1, room/FULL_ROOM) = (1 + (room/FULL_ROOM)⁻⁸)^(−1/8),
        // where the key-shape placement leaves a bird little room: scaling (not clipping harder)
        // keeps the acceleration bounded.
        let (room, droom) = if nearest > CLEARANCE {
            (MIN_BOUND + (nearest - CLEARANCE) / 2.0, nearest_rate / 2.0)
        } else {
            (MIN_BOUND, 0.0)
        };
        let q = room / FULL_ROOM;
        let g = (1.0 + q.powi(-8)).powf(-1.0 / 8.0);
        let dg = (g / q).powi(9) * droom / FULL_ROOM;
        let a = self.limit;
        let bound = |(u, du): (f64, f64)| {
            // f(u) = u / (1 + (u/A)⁸)^(1/8): the identity well inside A, never beyond it.
            let r = (u / a).powi(8);
            let f = u * (1.0 + r).powf(-1.0 / 8.0);
            let df = (1.0 + r).powf(-9.0 / 8.0) * du;
            (e * g * f, (de * g + e * dg) * f + e * g * df)
        };
        let (x, vx) = bound(ux);
        let (y, vy) = bound(uy);
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
            // A neighbour closing in at 0.2 wingspans per second, tightening the bound.
            let near = |t: f64| 0.6 - 0.2 * (t - 5.0);
            let at = |t: f64| j.at(1, t, near(t), -0.2);
            let (a, b, d) = (at(t - h), at(t + h), at(t));
            assert!(((b.x - a.x) / (2.0 * h) - d.vx).abs() < 1e-6);
            assert!(((b.y - a.y) / (2.0 * h) - d.vy).abs() < 1e-6);
        }
        assert_eq!(j.at(2, 0.0, 2.0, 0.0), Deviation::default());
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
                    let (a, b) = (clock.at(i, 1.0, 0.1), j.at(i, t, 1.0, 0.1));
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
            assert!(worst < 1e-12, "{fps} fps: {worst}");
        }
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
