//! A synthetic flock for tests, benchmarks and demos of the outputs: birds take off in a loose
//! random cluster, converge into a V during an "initiation" stage, then cruise north in the V
//! with small oscillations and a gentle meander. It is **not** the paper's model (positions are
//! scripted, `e`/`xi` come from a simple stand-in for Hummel's function); it only gives the
//! renderers realistic, deterministic input without running the other stages.

use std::f64::consts::TAU;

use rand::Rng;

use crate::animation::{Animation, Frame, KeyBird, KeyShapeRecord, Stage};

/// Shape of the synthetic flock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticParams {
    /// Number of birds.
    pub birds: usize,
    /// Length of the animation, seconds.
    pub seconds: f64,
    /// Frames per second.
    pub fps: f64,
    /// Length of the initiation stage, seconds (at most a third of the animation).
    pub initiation_s: f64,
    /// Cruise speed, wingspans per second.
    pub speed: f64,
    /// Lateral spacing between neighbouring ranks of the V, wingspans.
    pub spacing_x: f64,
    /// Longitudinal spacing between neighbouring ranks of the V, wingspans.
    pub spacing_y: f64,
}

impl Default for SyntheticParams {
    fn default() -> Self {
        SyntheticParams {
            birds: 14,
            seconds: 20.0,
            fps: 30.0,
            initiation_s: 10.0 / 3.0,
            speed: 12.0,
            spacing_x: 0.9,
            spacing_y: 0.8,
        }
    }
}

fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Builds the synthetic animation; all randomness comes from `rng`.
pub fn synthetic_flock(rng: &mut impl Rng, p: &SyntheticParams) -> Animation {
    let n = p.birds.max(1);
    let frames = ((p.seconds * p.fps).round() as usize).max(3);
    let n_init = ((p.initiation_s * p.fps).round() as usize).min(frames / 3);
    let mut anim = Animation::new(0, p.fps, 1.5, n);
    anim.species = Some("goose".into());
    // Key shape (formation frame): leader at the apex, ranks alternating right and left.
    let key: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let r = k.div_ceil(2) as f64;
            let side = if k % 2 == 1 { 1.0 } else { -1.0 };
            let jitter = if k == 0 {
                0.0
            } else {
                rng.random_range(-0.12..0.12)
            };
            (side * r * p.spacing_x, r * p.spacing_y + jitter)
        })
        .collect();
    let start: Vec<(f64, f64, f64)> = (0..n)
        .map(|_| {
            let a = rng.random_range(0.0..TAU);
            let d = 2.0 + 5.0 * rng.random::<f64>().sqrt();
            (d * a.cos(), 3.0 + d * a.sin(), rng.random_range(0.0..2.0))
        })
        .collect();
    let delay: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..0.3)).collect();
    let osc: Vec<(f64, f64, f64)> = (0..n)
        .map(|_| {
            (
                rng.random_range(0.0..TAU),
                rng.random_range(0.0..TAU),
                rng.random_range(0.25..0.45),
            )
        })
        .collect();
    let flap: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..TAU)).collect();
    let t_init = n_init as f64 / p.fps;
    let pos = |t: f64| -> Vec<(f64, f64, f64)> {
        // Leader path: cruise north with a slow meander; climb during initiation.
        let lx = 1.5 * (0.21 * t).sin() + 0.8 * (0.07 * t).sin();
        let ly = p.speed * t;
        let climb = 30.0 * smoothstep(t / (t_init.max(1e-9) * 1.5));
        (0..n)
            .map(|i| {
                let (kx, ky) = key[i];
                let (ph1, ph2, f) = osc[i];
                let amp = if i == 0 { 0.0 } else { 1.0 };
                let fx = kx + amp * 0.06 * (TAU * f * t + ph1).sin();
                let fy = ky + amp * 0.15 * (TAU * f * 0.7 * t + ph2).sin();
                let s = if t_init > 0.0 {
                    smoothstep((t / t_init - delay[i]) / (1.0 - 0.3))
                } else {
                    1.0
                };
                let (sx, sy, sz) = start[i];
                let weave = (1.0 - s) * 1.2 * (1.3 * t + ph1).sin();
                let x = sx + (fx - sx) * s + weave;
                let y = sy + (fy - sy) * s;
                (lx + x, ly - y, climb + sz * (1.0 - s))
            })
            .collect()
    };
    let dt = 1.0 / p.fps;
    for k in 0..frames {
        let t = k as f64 * dt;
        let here = pos(t);
        let (a, b) = (pos(t - 0.5 * dt), pos(t + 0.5 * dt));
        let mut f = Frame {
            t,
            ..Default::default()
        };
        for i in 0..n {
            f.x.push(here[i].0);
            f.y.push(here[i].1);
            f.z.push(here[i].2);
            let (vx, vy, vz) = (
                (b[i].0 - a[i].0) / dt,
                (b[i].1 - a[i].1) / dt,
                (b[i].2 - a[i].2) / dt,
            );
            f.heading.push(vx.atan2(vy).rem_euclid(TAU));
            f.speed.push((vx * vx + vy * vy + vz * vz).sqrt());
        }
        f.wing_phase = Some(
            (0..n)
                .map(|i| (TAU * 2.8 * t + flap[i]).rem_euclid(TAU))
                .collect(),
        );
        if k >= n_init {
            // Stand-in for Hummel's g: upwash from birds ahead, peaking about one wingspan aside.
            let e: Vec<f64> = (0..n)
                .map(|i| {
                    (0..n)
                        .filter(|&j| j != i)
                        .map(|j| {
                            let dx = (here[i].0 - here[j].0).abs();
                            let dy = here[j].1 - here[i].1;
                            let lat = (-(dx - 0.9).powi(2) / 0.08).exp();
                            lat * 0.06 * (1.0 + (dy / 2.0).tanh())
                        })
                        .sum()
                })
                .collect();
            let total: f64 = e.iter().sum::<f64>().max(1e-12);
            f.xi = Some(e.iter().map(|v| v / total).collect());
            f.e = Some(e);
        }
        anim.frames.push(f);
    }
    anim.stages = vec![
        Stage {
            name: "initiation".into(),
            start: 0,
            end: n_init,
        },
        Stage {
            name: "steady".into(),
            start: n_init,
            end: frames,
        },
    ];
    let xi0 = anim.frames[n_init]
        .xi
        .clone()
        .unwrap_or_else(|| vec![1.0 / n as f64; n]);
    anim.key_shapes = vec![KeyShapeRecord {
        frame: n_init,
        birds: key
            .iter()
            .zip(&xi0)
            .map(|(&(x, y), &xi)| KeyBird {
                x,
                y,
                xi,
                slot: None,
            })
            .collect(),
    }];
    anim
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_flock_is_valid_and_deterministic() {
        let p = SyntheticParams {
            seconds: 4.0,
            ..Default::default()
        };
        let a = synthetic_flock(&mut crate::rng::seeded(3), &p);
        a.validate(std::path::Path::new("synthetic")).unwrap();
        assert_eq!(a.frames.len(), 120);
        assert_eq!(a, synthetic_flock(&mut crate::rng::seeded(3), &p));
        let steady = a.stage("steady").unwrap();
        assert!(a.frames[steady.start].xi.is_some() && a.frames[0].xi.is_none());
    }
}
