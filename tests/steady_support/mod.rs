//! Synthetic formation-parameter movies with known shape models, for the steady-flight tests and
//! the fixtures under `tests/data/` (`cargo test --test steady -- --ignored write_fixtures`).

#![allow(dead_code)]

use formation::extract::params::{
    BirdPosition, FormationParams, FrameParams, LineCoef, ShapeModel, PARAMS_FORMAT,
};
use rand::Rng;
use rand_distr::{Distribution, Normal};

/// Kind of synthetic movie.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// V with arm slopes ±0.7.
    V,
    /// J: parabola y = 0.05 x² with the leader near the left end.
    J,
}

/// A noisy `n_hat`-bird movie of `frames` frames; `leader_rank` birds left of the leader;
/// `outliers` = (bird rank, extra deviation in wingspans).
pub fn movie(
    kind: Kind,
    n_hat: usize,
    leader_rank: usize,
    frames: usize,
    outliers: &[(usize, f64)],
    seed: u64,
) -> FormationParams {
    let mut rng = formation::rng::seeded(seed);
    let gap = Normal::new(1.0, 0.12).unwrap();
    let dev = Normal::new(0.0, 0.08).unwrap();
    let mut out = Vec::new();
    for f in 0..frames {
        let gaps: Vec<f64> = (0..n_hat - 1)
            .map(|_| loop {
                let g: f64 = gap.sample(&mut rng);
                if g > 0.82 {
                    break g;
                }
            })
            .collect();
        let mut x = vec![0.0; n_hat];
        for i in (0..leader_rank).rev() {
            x[i] = x[i + 1] - gaps[i];
        }
        for i in leader_rank + 1..n_hat {
            x[i] = x[i - 1] + gaps[i - 1];
        }
        let shape = match kind {
            Kind::V => {
                let sl: f64 = 0.7 + rng.random_range(-0.05..0.05);
                let sr: f64 = 0.7 + rng.random_range(-0.05..0.05);
                ShapeModel::V {
                    left: LineCoef {
                        intercept: 0.0,
                        slope: -sl,
                    },
                    right: LineCoef {
                        intercept: 0.0,
                        slope: sr,
                    },
                }
            }
            Kind::J => ShapeModel::J {
                a: 0.05 + rng.random_range(-0.005..0.005),
                b: 0.0,
                c: 0.0,
            },
        };
        let mut positions = Vec::new();
        let mut inlier_dev = Vec::new();
        for (i, &xi) in x.iter().enumerate() {
            let mut d = if i == leader_rank {
                0.0
            } else {
                dev.sample(&mut rng)
            };
            if let Some(&(_, extra)) = outliers.iter().find(|(r, _)| *r == i) {
                d += extra;
            } else if i != leader_rank {
                inlier_dev.push(d);
            }
            let y = shape.y_at(xi) + d;
            positions.push(BirdPosition {
                id: i,
                x: xi,
                y,
                dy: d,
            });
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let sd = |v: &[f64]| {
            let m = mean(v);
            (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / v.len() as f64).sqrt()
        };
        out.push(FrameParams {
            index: f as i64,
            order: (0..n_hat).collect(),
            leader: leader_rank,
            mu_x: mean(&gaps),
            sigma_x: sd(&gaps),
            mu_y: mean(&inlier_dev),
            sigma_y: sd(&inlier_dev),
            shape,
            inliers: (0..n_hat)
                .filter(|i| !outliers.iter().any(|(r, _)| r == i))
                .collect(),
            outliers: outliers.iter().map(|(r, _)| *r).collect(),
            positions,
            geometry: None,
        });
    }
    FormationParams {
        format: PARAMS_FORMAT.into(),
        source: format!("synthetic {kind:?} movie, {n_hat} birds, seed {seed}"),
        birds: n_hat,
        frames: out,
        summary: None,
        motion: None,
        ci: None,
        heights: None,
    }
}

/// The 9-bird V fixture (leader 4th from the left, one outlier).
pub fn v9() -> FormationParams {
    movie(Kind::V, 9, 3, 15, &[(6, 0.45)], 9)
}

/// The 16-bird J fixture (leader 4th from the left, two outliers).
pub fn j16() -> FormationParams {
    movie(Kind::J, 16, 3, 12, &[(9, -0.3), (13, 0.5)], 16)
}
