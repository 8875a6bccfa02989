//! Where the formations of a flock fly relative to one another, in the course frame (the world
//! frame of a flock cruising north, docs/formats.md §2): x east, y north, wingspans.
//!
//! **Drift.** Each formation wanders about its place on a slow Lissajous figure: a displacement
//! (A_x sin(ωt + φ_x), A_y sin(ωt + φ_y)) − its value at t = 0, with the period 2π/ω uniform in
//! [[`DRIFT_PERIOD_S`]] seconds, the phases uniform, and the amplitudes such that the velocity it
//! adds is at most `max_heading_deg` of heading and `max_speed_diff` of the cruise speed (each
//! amplitude uniform between half and all of that). Formations thus fly the same course with
//! small, smooth, bounded differences of speed and heading.
//!
//! **Arrangement.** Formations are dealt, in a random order, into L lanes side by side across the
//! course (L ≈ √(2K · pitch_y / pitch_x), so the flock is about twice as wide as deep) and, in
//! each lane, one behind the other. Each formation's *envelope* is measured over the whole
//! animation, take-off, drift and key-shape changes included: its lateral extent over all frames,
//! and its fore-aft extent frame by frame. With w̃ the median envelope width (of an even count,
//! the mean of the middle two: [`crate::keyshape::spacing::median`], the one median of the
//! library) and s = `spread`: a lane is s·w̃/2 wider than its widest envelope and each formation
//! sits at a random place across it; neighbouring lanes are the clearance plus s·u·w̃/2 apart
//! (u uniform in [0, 1], drawn per gap). Along a lane, each formation is placed behind the one ahead so that in *every frame*
//! its front-most bird is the clearance plus s·u·w̃ behind the rear-most bird of the one ahead
//! (line formations are wider than deep, so the width sets the scale of the gaps both ways); the
//! first formation of each lane is set back by a random fraction of a row (staggered rows). After
//! a take-off, the formations of a lane are ordered by the time they leave the ground, the first
//! to leave in front. Birds of different formations are therefore never within the clearance in
//! any frame: in different lanes they are that far apart across the course, in one lane along it.

use rand::Rng;
use serde::Serialize;

use crate::animation::Animation;
use crate::keyshape::spacing::median;

/// Range of the drift period, seconds.
pub const DRIFT_PERIOD_S: [f64; 2] = [60.0, 120.0];

/// Length of the windows of [`Envelope::windows`], seconds.
pub const WINDOW_S: f64 = 0.5;

/// Width : depth of the whole arrangement (wingspans over wingspans) the lane count aims at.
pub const ASPECT: f64 = 2.0;

/// A formation's slow wander about its place (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Drift {
    /// ω, radians per second.
    pub omega: f64,
    /// Amplitudes across and along the course, wingspans.
    pub amplitude: [f64; 2],
    /// Phases φ_x, φ_y, radians.
    pub phase: [f64; 2],
}

impl Drift {
    /// A drift drawn from `rng` for a cruise of `speed` wingspans per second.
    pub fn draw(
        speed: f64,
        max_heading_deg: f64,
        max_speed_diff: f64,
        rng: &mut impl Rng,
    ) -> Drift {
        let period = rng.random_range(DRIFT_PERIOD_S[0]..=DRIFT_PERIOD_S[1]);
        let omega = std::f64::consts::TAU / period;
        let ux: f64 = rng.random_range(0.5..=1.0);
        let uy: f64 = rng.random_range(0.5..=1.0);
        let px = rng.random_range(0.0..std::f64::consts::TAU);
        let py = rng.random_range(0.0..std::f64::consts::TAU);
        Drift {
            omega,
            amplitude: [
                ux * max_heading_deg.to_radians().tan() * speed / omega,
                uy * max_speed_diff * speed / omega,
            ],
            phase: [px, py],
        }
    }

    /// Displacement at `t` seconds (zero at t = 0), wingspans.
    pub fn offset(&self, t: f64) -> [f64; 2] {
        let d = |a: f64, p: f64| a * ((self.omega * t + p).sin() - p.sin());
        [
            d(self.amplitude[0], self.phase[0]),
            d(self.amplitude[1], self.phase[1]),
        ]
    }

    /// Velocity it adds at `t`, wingspans per second.
    pub fn velocity(&self, t: f64) -> [f64; 2] {
        let v = |a: f64, p: f64| a * self.omega * (self.omega * t + p).cos();
        [
            v(self.amplitude[0], self.phase[0]),
            v(self.amplitude[1], self.phase[1]),
        ]
    }

    /// Moves every bird of `anim` (frames from `from` on, time measured from that frame) by the
    /// drift and adds its velocity to their headings and speeds. The formation turns with its
    /// heading: each frame's positions are turned about the formation's centre by the angle the
    /// drift turns the mean flight direction, so the line formation stays set to the direction
    /// it flies (a V flying 3° off the course is a V seen 3° turned, not a V crabbing).
    pub fn apply(&self, anim: &mut Animation, from: usize) {
        let t0 = anim.frames.get(from).map_or(0.0, |f| f.t);
        for f in anim.frames.iter_mut().skip(from) {
            let n = f.x.len();
            if n == 0 {
                continue;
            }
            let t = f.t - t0;
            let [dx, dy] = self.offset(t);
            let [vx, vy] = self.velocity(t);
            // The flock's mean velocity before and after the drift's is added: the turn.
            let (mut sx, mut sy) = (0.0, 0.0);
            for i in 0..n {
                let (s, c) = f.heading[i].sin_cos();
                sx += f.speed[i] * s;
                sy += f.speed[i] * c;
            }
            let (sx, sy) = (sx / n as f64, sy / n as f64);
            let turn = if sx.hypot(sy) > 1e-9 {
                let a = (sx + vx).atan2(sy + vy) - sx.atan2(sy);
                (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
            } else {
                0.0
            };
            let (ts, tc) = turn.sin_cos();
            let cx = f.x.iter().sum::<f64>() / n as f64;
            let cy = f.y.iter().sum::<f64>() / n as f64;
            for i in 0..n {
                // Turned clockwise by `turn` (headings are clockwise from north) about the centre.
                let (rx, ry) = (f.x[i] - cx, f.y[i] - cy);
                f.x[i] = cx + rx * tc + ry * ts + dx;
                f.y[i] = cy - rx * ts + ry * tc + dy;
                let (s, c) = f.heading[i].sin_cos();
                let (ux, uy) = (f.speed[i] * s + vx, f.speed[i] * c + vy);
                f.heading[i] = ux.atan2(uy);
                f.speed[i] = ux.hypot(uy);
            }
        }
    }
}

/// Extent of one formation over an animation: across the course over all frames, along it per
/// frame, wingspans.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// Westmost and eastmost x over all frames.
    pub x: [f64; 2],
    /// Southmost (rear) y of each frame.
    pub rear: Vec<f64>,
    /// Northmost (front) y of each frame.
    pub front: Vec<f64>,
    /// Boxes [west, south, east, north] of the birds over consecutive windows of
    /// [`WINDOW_S`] seconds (the last one shorter), wingspans: what the natural and compound
    /// arrangements keep apart.
    pub windows: Vec<[f64; 4]>,
}

impl Envelope {
    /// The envelope of `anim`'s birds.
    pub fn of(anim: &Animation) -> Envelope {
        let mut x = [f64::INFINITY, f64::NEG_INFINITY];
        let mut rear = Vec::with_capacity(anim.frames.len());
        let mut front = Vec::with_capacity(anim.frames.len());
        let per = ((WINDOW_S * anim.fps).round() as usize).max(1);
        let mut windows = Vec::with_capacity(anim.frames.len() / per + 1);
        for (j, f) in anim.frames.iter().enumerate() {
            let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
            for &v in &f.x {
                (x0, x1) = (x0.min(v), x1.max(v));
            }
            x = [x[0].min(x0), x[1].max(x1)];
            let (lo, hi) =
                f.y.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
            rear.push(lo);
            front.push(hi);
            if j % per == 0 {
                windows.push([x0, lo, x1, hi]);
            } else if let Some(w) = windows.last_mut() {
                *w = [w[0].min(x0), w[1].min(lo), w[2].max(x1), w[3].max(hi)];
            }
        }
        Envelope {
            x,
            rear,
            front,
            windows,
        }
    }

    /// The box [west, south, east, north] of every window together, wingspans.
    pub fn bounds(&self) -> [f64; 4] {
        self.windows.iter().fold(
            [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ],
            |b, w| {
                [
                    b[0].min(w[0]),
                    b[1].min(w[1]),
                    b[2].max(w[2]),
                    b[3].max(w[3]),
                ]
            },
        )
    }

    /// Width across the course, wingspans.
    pub fn width(&self) -> f64 {
        self.x[1] - self.x[0]
    }

    /// Largest depth along the course over the frames, wingspans.
    pub fn depth(&self) -> f64 {
        self.rear
            .iter()
            .zip(&self.front)
            .map(|(r, f)| f - r)
            .fold(0.0, f64::max)
    }
}

/// Where each formation goes: its offset (added to its birds' x and y in every frame) and lane.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Placement {
    /// Offset east and north, wingspans.
    pub offset: [f64; 2],
    /// Lane index, west to east.
    pub lane: usize,
    /// Position in its lane, front to back.
    pub row: usize,
    /// Height offset from the flock's cruise height, wingspans (0 on the grid).
    pub height: f64,
}

/// w̃ and the median depth of `env`, wingspans: the library's one median
/// ([`crate::keyshape::spacing::median`], the mean of the middle two of an even count).
fn median_size(env: &[Envelope]) -> (f64, f64) {
    (
        median(env.iter().map(Envelope::width).collect()),
        median(env.iter().map(Envelope::depth).collect()),
    )
}

/// The arrangement of formations with envelopes `env` (all over the same frames), `clearance`
/// wingspans apart at least, loosened by `spread` (see the module doc). In each lane the
/// formations are ordered front to back by `first` (ascending; ties keep the dealt order): the
/// take-off passes each formation's departure time, so that the formations that leave first fly
/// ahead and no formation has to pass over another's patch.
pub fn arrange(
    env: &[Envelope],
    first: &[f64],
    clearance: f64,
    spread: f64,
    rng: &mut impl Rng,
) -> Vec<Placement> {
    let k = env.len();
    if k == 0 {
        return Vec::new();
    }
    let (w_med, d_med) = median_size(env);
    let pitch_x = w_med + clearance + spread * w_med;
    let pitch_y = d_med + clearance + 0.5 * spread * w_med;
    let lanes = ((ASPECT * k as f64 * pitch_y / pitch_x.max(1e-9))
        .sqrt()
        .round() as usize)
        .clamp(1, k.max(1));
    // A random order, dealt into lanes.
    let mut order: Vec<usize> = (0..k).collect();
    for i in (1..k).rev() {
        let j = rng.random_range(0..=i);
        order.swap(i, j);
    }
    let members: Vec<Vec<usize>> = (0..lanes)
        .map(|l| {
            let mut m: Vec<usize> = order.iter().copied().skip(l).step_by(lanes).collect();
            m.sort_by(|&a, &b| {
                let key = |f: usize| first.get(f).copied().unwrap_or(0.0);
                key(a).total_cmp(&key(b))
            });
            m
        })
        .collect();
    let mut out = vec![
        Placement {
            offset: [0.0, 0.0],
            lane: 0,
            row: 0,
            height: 0.0,
        };
        k
    ];
    let mut left = 0.0;
    for (l, m) in members.iter().enumerate() {
        let lane_w = m.iter().map(|&f| env[f].width()).fold(0.0, f64::max) + 0.5 * spread * w_med;
        let mut ahead: Option<(usize, f64)> = None;
        for (row, &f) in m.iter().enumerate() {
            let e = &env[f];
            let x = left + (lane_w - e.width()) * rng.random_range(0.0..=1.0) - e.x[0];
            let y = match ahead {
                None => -rng.random_range(0.0..=1.0) * pitch_y,
                Some((a, ya)) => {
                    let ea = &env[a];
                    let closest = ea
                        .rear
                        .iter()
                        .zip(&e.front)
                        .map(|(r, fr)| r - fr)
                        .fold(f64::INFINITY, f64::min);
                    ya + closest - clearance - spread * w_med * rng.random_range(0.0..=1.0)
                }
            };
            out[f] = Placement {
                offset: [x, y],
                lane: l,
                row,
                height: 0.0,
            };
            ahead = Some((f, y));
        }
        left += lane_w + clearance + 0.5 * spread * w_med * rng.random_range(0.0..=1.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::Frame;

    #[test]
    fn drift_velocity_is_the_derivative_and_bounded() {
        let mut rng = crate::rng::seeded(4);
        for _ in 0..20 {
            let d = Drift::draw(10.0, 1.0, 0.02, &mut rng);
            assert_eq!(d.offset(0.0), [0.0, 0.0]);
            for k in 0..200 {
                let t = k as f64 * 0.7;
                let h = 1e-5;
                let (a, b) = (d.offset(t + h), d.offset(t - h));
                let v = d.velocity(t);
                for c in 0..2 {
                    assert!(((a[c] - b[c]) / (2.0 * h) - v[c]).abs() < 1e-6);
                }
                assert!(v[0].abs() <= 10.0 * 1f64.to_radians().tan() + 1e-12);
                assert!(v[1].abs() <= 0.2 + 1e-12);
            }
        }
    }

    fn moving(n: usize, wobble: f64) -> Animation {
        let mut a = Animation::new(0, 10.0, 1.5, n);
        a.frames = (0..50)
            .map(|j| {
                let t = j as f64 / 10.0;
                Frame {
                    t,
                    x: (0..n)
                        .map(|i| i as f64 + wobble * (t + i as f64).sin())
                        .collect(),
                    y: (0..n)
                        .map(|i| 10.0 * t - 0.5 * i as f64 + wobble * (2.0 * t).cos())
                        .collect(),
                    z: vec![0.0; n],
                    heading: vec![0.0; n],
                    speed: vec![10.0; n],
                    ..Frame::default()
                }
            })
            .collect();
        a
    }

    #[test]
    fn the_typical_formation_size_is_the_libraries_median() {
        let env = |w: f64, d: f64| Envelope {
            x: [-w / 2.0, w / 2.0],
            rear: vec![-d, -0.5 * d],
            front: vec![0.0, 0.0],
            windows: vec![[-w / 2.0, -d, w / 2.0, 0.0]],
        };
        // An even count: the mean of the middle two (the upper one, 30 and 3, before).
        let four = [
            env(40.0, 4.0),
            env(10.0, 1.0),
            env(30.0, 3.0),
            env(20.0, 2.0),
        ];
        assert_eq!(median_size(&four), (25.0, 2.5));
        assert_eq!(median_size(&four[..3]), (30.0, 3.0));
        let widths: Vec<f64> = four.iter().map(Envelope::width).collect();
        assert_eq!(median_size(&four).0, median(widths));
        assert!(arrange(&[], &[], 5.0, 0.5, &mut crate::rng::seeded(0)).is_empty());
    }

    #[test]
    fn arranged_formations_keep_the_clearance_in_every_frame() {
        for seed in 0..20 {
            let anims: Vec<Animation> = (0..13)
                .map(|k| moving(3 + k % 5, 0.5 + k as f64 * 0.3))
                .collect();
            let env: Vec<Envelope> = anims.iter().map(Envelope::of).collect();
            let mut rng = crate::rng::seeded(seed);
            let first: Vec<f64> = (0..env.len()).map(|k| (k % 3) as f64).collect();
            let p = arrange(&env, &first, 5.0, 1.0, &mut rng);
            assert!(p.iter().map(|p| p.lane).max().unwrap() >= 1);
            for j in 0..50 {
                for a in 0..anims.len() {
                    for b in 0..a {
                        for i in 0..anims[a].birds {
                            for q in 0..anims[b].birds {
                                let fa = &anims[a].frames[j];
                                let fb = &anims[b].frames[j];
                                let dx = fa.x[i] + p[a].offset[0] - fb.x[q] - p[b].offset[0];
                                let dy = fa.y[i] + p[a].offset[1] - fb.y[q] - p[b].offset[1];
                                assert!(dx.hypot(dy) >= 5.0 - 1e-9, "seed {seed} frame {j}");
                            }
                        }
                    }
                }
            }
        }
    }
}
