//! 95 % bootstrap intervals of what `extract` measures: the apex angle, the nearest bird ahead
//! (lateral and fore-aft), the depth and the wingtip spacing.
//!
//! The point estimates are medians: of the per-frame apex angle, depth and wingtip spacing over
//! the frames (the `summary.geometry` medians), and of the nearest-bird-ahead offsets pooled over
//! every bird of every frame. Birds of one frame are not independent (they share the frame's
//! shape and its errors), so the resampling unit is the frame: each of [`RESAMPLES`] replicates
//! draws the frames with replacement and, for the pooled offsets, each drawn frame's birds with
//! replacement (a two-stage bootstrap). The interval is the 2.5th to 97.5th percentile of the
//! replicates' medians. The generator is seeded from a fixed constant, so the same footage
//! always gives the same intervals (and the extraction's own random stream is untouched).

use rand::Rng;

use super::geometry::FrameGeometry;
use super::params::FrameParams;

/// Bootstrap replicates per interval.
pub const RESAMPLES: usize = 2000;

/// Seed of the bootstrap's generator.
const SEED: u64 = 0x626f_6f74_7374_7270;

/// Fewest frames an interval is computed from (fewer: no interval).
pub const MIN_FRAMES: usize = 3;

pub use super::params::Intervals;

/// Each inlier bird's offset from its nearest bird ahead in one frame: (|lateral|, behind),
/// wingspans. The bird ahead is the nearest (Euclidean) inlier with a smaller distance behind the
/// leader; the leader has none.
pub fn nearest_ahead(f: &FrameParams) -> Vec<(f64, f64)> {
    let inl: Vec<(f64, f64)> = f
        .positions
        .iter()
        .filter(|p| f.inliers.contains(&p.id))
        .map(|p| (p.x, p.y))
        .collect();
    inl.iter()
        .filter_map(|&(x, y)| {
            inl.iter()
                .filter(|q| q.1 < y)
                .map(|q| ((x - q.0).abs(), y - q.1))
                .min_by(|a, b| (a.0.hypot(a.1)).total_cmp(&b.0.hypot(b.1)))
        })
        .collect()
}

/// The median of `v` (sorted in place); `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The 2.5th and 97.5th percentiles of `reps` (linear interpolation between order statistics).
fn percentile_interval(reps: &mut [f64]) -> Option<[f64; 2]> {
    if reps.is_empty() {
        return None;
    }
    reps.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let h = p * (reps.len() - 1) as f64;
        let (i, t) = (h.floor() as usize, h - h.floor());
        let j = (i + 1).min(reps.len() - 1);
        reps[i] + t * (reps[j] - reps[i])
    };
    Some([q(0.025), q(0.975)])
}

/// Interval of the median over frames of a per-frame value (frames without it skipped).
fn frame_median_interval(values: &[f64], rng: &mut impl Rng) -> Option<[f64; 2]> {
    let n = values.len();
    if n < MIN_FRAMES {
        return None;
    }
    let mut buf = vec![0.0; n];
    let mut reps: Vec<f64> = (0..RESAMPLES)
        .map(|_| {
            for b in buf.iter_mut() {
                *b = values[rng.random_range(0..n)];
            }
            median(&mut buf).unwrap_or(f64::NAN)
        })
        .collect();
    percentile_interval(&mut reps)
}

/// Interval of the median of values pooled over frames, by the two-stage bootstrap.
fn pooled_median_interval(per_frame: &[Vec<f64>], rng: &mut impl Rng) -> Option<[f64; 2]> {
    let frames: Vec<&Vec<f64>> = per_frame.iter().filter(|v| !v.is_empty()).collect();
    let n = frames.len();
    if n < MIN_FRAMES {
        return None;
    }
    let mut pool = Vec::new();
    let mut reps: Vec<f64> = (0..RESAMPLES)
        .map(|_| {
            pool.clear();
            for _ in 0..n {
                let f = frames[rng.random_range(0..n)];
                for _ in 0..f.len() {
                    pool.push(f[rng.random_range(0..f.len())]);
                }
            }
            median(&mut pool).unwrap_or(f64::NAN)
        })
        .collect();
    percentile_interval(&mut reps)
}

/// The intervals of `frames` (each with its geometry computed).
pub fn intervals(frames: &[FrameParams]) -> Intervals {
    let mut rng = crate::rng::seeded(SEED);
    let geo: Vec<FrameGeometry> = frames.iter().filter_map(|f| f.geometry).collect();
    let ahead: Vec<Vec<(f64, f64)>> = frames.iter().map(nearest_ahead).collect();
    let col = |f: &dyn Fn(&FrameGeometry) -> Option<f64>| -> Vec<f64> {
        geo.iter().filter_map(f).filter(|v| v.is_finite()).collect()
    };
    let apex_deg = frame_median_interval(&col(&|g| g.apex_deg), &mut rng);
    let depth = frame_median_interval(&col(&|g| Some(g.depth)), &mut rng);
    let wts = frame_median_interval(&col(&|g| Some(g.wingtip_spacing)), &mut rng);
    let lateral = pooled_median_interval(
        &ahead
            .iter()
            .map(|v| v.iter().map(|p| p.0).collect())
            .collect::<Vec<_>>(),
        &mut rng,
    );
    let behind = pooled_median_interval(
        &ahead
            .iter()
            .map(|v| v.iter().map(|p| p.1).collect())
            .collect::<Vec<_>>(),
        &mut rng,
    );
    Intervals {
        apex_deg,
        lateral,
        behind,
        depth,
        wts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn frame_median_intervals_cover_the_true_median_in_most_seeds() {
        // 20 frames of a value drawn around 60 (sd 5): the interval covers 60 in about 95 % of
        // samples; at least 90 of 100 here.
        let d = Normal::new(60.0, 5.0).unwrap();
        let mut covered = 0;
        for seed in 0..100u64 {
            let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let v: Vec<f64> = (0..20).map(|_| d.sample(&mut r)).collect();
            let [lo, hi] = frame_median_interval(&v, &mut r).unwrap();
            assert!(lo <= hi);
            if lo <= 60.0 && 60.0 <= hi {
                covered += 1;
            }
        }
        assert!(covered >= 90, "covered {covered} of 100");
    }

    #[test]
    fn too_few_frames_give_no_interval() {
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        assert!(frame_median_interval(&[1.0, 2.0], &mut r).is_none());
        assert!(pooled_median_interval(&[vec![1.0], vec![], vec![2.0]], &mut r).is_none());
        let mut v = [3.0, 1.0, 2.0, 4.0];
        assert_eq!(median(&mut v), Some(2.5));
    }
}
