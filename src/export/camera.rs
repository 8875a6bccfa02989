//! The camera of the image outputs: a top-down view, north up and east right, that follows the
//! flock and keeps every bird inside the picture with a margin.
//!
//! The path is computed offline over all output frames. The centre is the flock's bounding-box
//! centre smoothed by a Gaussian in time (odd reflection at both ends, so steady motion is not
//! biased). The zoom is then chosen in two steps that guarantee containment while staying smooth:
//! for each frame the largest scale `s_need(t)` (pixels per wingspan) that still fits every bird
//! around the smoothed centre, then an erosion (minimum over ±W frames) followed by a Gaussian
//! average over the same ±W in log scale:
//! ```math
//! \log s(t) = \sum_{|k|\le W} w_k \min_{|j|\le W} \log s_\text{need}(t+k+j) \le \log s_\text{need}(t)
//! ```
//! (every term of the average is a minimum over a window that contains `t`), so no bird ever
//! leaves the frame, and the zoom eases in and out instead of jumping.

use super::rig::BIRD_RADIUS;
use super::sample::BirdState;

/// Camera placement for one output frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// World point at the image centre, east, wingspans.
    pub cx: f64,
    /// World point at the image centre, north, wingspans.
    pub cy: f64,
    /// Pixels per wingspan.
    pub scale: f64,
}

impl View {
    /// Pixel coordinates `(column, row)` of a world point in a `width × height` image.
    pub fn to_pixel(&self, x: f64, y: f64, width: usize, height: usize) -> (f64, f64) {
        (
            0.5 * width as f64 + (x - self.cx) * self.scale,
            0.5 * height as f64 - (y - self.cy) * self.scale,
        )
    }
}

/// How the camera frames the flock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraParams {
    /// Empty border kept around the outermost birds, as a fraction of the shorter image side.
    pub margin: f64,
    /// Closest zoom: the image shows at least this many wingspans along its shorter side.
    pub min_extent: f64,
    /// Standard deviation of the Gaussian smoothing of the centre and the zoom, seconds.
    pub smoothing_s: f64,
}

impl Default for CameraParams {
    fn default() -> Self {
        CameraParams {
            margin: 0.07,
            min_extent: 7.0,
            smoothing_s: 0.6,
        }
    }
}

fn gaussian(sigma: f64, half: usize) -> Vec<f64> {
    let w: Vec<f64> = (0..=2 * half)
        .map(|k| {
            let d = k as f64 - half as f64;
            (-0.5 * d * d / (sigma * sigma).max(1e-12)).exp()
        })
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|v| v / s).collect()
}

/// Gaussian smoothing with odd reflection at the ends (`v(−k) = 2 v(0) − v(k)`).
fn smooth_odd(v: &[f64], kernel: &[f64]) -> Vec<f64> {
    let n = v.len() as isize;
    let half = (kernel.len() / 2) as isize;
    (0..n)
        .map(|i| {
            kernel
                .iter()
                .enumerate()
                .map(|(k, w)| {
                    let j = i + k as isize - half;
                    let val = if j < 0 {
                        2.0 * v[0] - v[(-j).min(n - 1) as usize]
                    } else if j >= n {
                        2.0 * v[(n - 1) as usize] - v[(2 * (n - 1) - j).max(0) as usize]
                    } else {
                        v[j as usize]
                    };
                    w * val
                })
                .sum()
        })
        .collect()
}

/// The camera path for the sampled frames `states` (one `Vec<BirdState>` per output frame) at
/// `fps`, for a `width × height` image.
pub fn track(
    states: &[Vec<BirdState>],
    fps: f64,
    width: usize,
    height: usize,
    p: &CameraParams,
) -> Vec<View> {
    let n = states.len();
    if n == 0 {
        return Vec::new();
    }
    let sigma = (p.smoothing_s * fps).max(0.5);
    let half = ((2.0 * sigma).ceil() as usize).min(n.max(1));
    let kernel = gaussian(sigma, half);
    let bbox: Vec<(f64, f64, f64, f64)> = states
        .iter()
        .map(|s| {
            s.iter().fold(
                (f64::MAX, f64::MAX, f64::MIN, f64::MIN),
                |(a, b, c, d), q| (a.min(q.x), b.min(q.y), c.max(q.x), d.max(q.y)),
            )
        })
        .collect();
    let cx = smooth_odd(
        &bbox.iter().map(|b| 0.5 * (b.0 + b.2)).collect::<Vec<_>>(),
        &kernel,
    );
    let cy = smooth_odd(
        &bbox.iter().map(|b| 0.5 * (b.1 + b.3)).collect::<Vec<_>>(),
        &kernel,
    );
    let (w, h) = (width as f64, height as f64);
    let m = p.margin * w.min(h);
    let (hw, hh) = ((0.5 * w - m).max(1.0), (0.5 * h - m).max(1.0));
    let s_max = w.min(h) / p.min_extent;
    let log_need: Vec<f64> = (0..n)
        .map(|i| {
            let mut s = s_max;
            for b in &states[i] {
                let dx = (b.x - cx[i]).abs() + BIRD_RADIUS;
                let dy = (b.y - cy[i]).abs() + BIRD_RADIUS;
                s = s.min(hw / dx).min(hh / dy);
            }
            s.ln()
        })
        .collect();
    let eroded: Vec<f64> = (0..n)
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half).min(n - 1);
            log_need[lo..=hi].iter().cloned().fold(f64::MAX, f64::min)
        })
        .collect();
    (0..n)
        .map(|i| {
            let mut acc = 0.0;
            let mut wsum = 0.0;
            for (k, wk) in kernel.iter().enumerate() {
                let j = i as isize + k as isize - half as isize;
                // Clamping at the ends keeps every term a minimum over a window containing i.
                let j = j.clamp(0, n as isize - 1) as usize;
                let j = if j.abs_diff(i) > half { i } else { j };
                acc += wk * eroded[j];
                wsum += wk;
            }
            View {
                cx: cx[i],
                cy: cy[i],
                scale: (acc / wsum).exp(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odd_reflection_keeps_linear_motion_unbiased() {
        let v: Vec<f64> = (0..50).map(|k| 3.0 * k as f64 + 1.0).collect();
        let s = smooth_odd(&v, &gaussian(4.0, 10));
        for (a, b) in v.iter().zip(&s) {
            assert!((a - b).abs() < 1e-9);
        }
    }

    #[test]
    fn every_bird_stays_inside_even_when_the_flock_jumps() {
        let mut states = Vec::new();
        for k in 0..120 {
            let spread = if (40..60).contains(&k) { 30.0 } else { 3.0 };
            states.push(
                (0..5)
                    .map(|b| BirdState {
                        x: b as f64 * spread,
                        y: k as f64 * 0.5 - b as f64,
                        ..Default::default()
                    })
                    .collect::<Vec<_>>(),
            );
        }
        let views = track(&states, 25.0, 320, 180, &CameraParams::default());
        let m = 0.07 * 180.0;
        for (s, v) in states.iter().zip(&views) {
            for b in s {
                let (px, py) = v.to_pixel(b.x, b.y, 320, 180);
                let r = BIRD_RADIUS * v.scale;
                assert!(px - r >= m - 1e-6 && px + r <= 320.0 - m + 1e-6, "{px}");
                assert!(py - r >= m - 1e-6 && py + r <= 180.0 - m + 1e-6, "{py}");
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
        /// Any flock, any motion, any picture shape: every bird stays inside with the margin.
        #[test]
        fn containment_holds_for_random_flocks(
            seed in 0u64..1000,
            birds in 1usize..20,
            frames in 1usize..80,
            w in 32usize..1200,
            h in 32usize..900,
            spread in 0.0f64..60.0,
        ) {
            use rand::Rng;
            let mut rng = crate::rng::seeded(seed);
            let mut pos: Vec<(f64, f64)> = (0..birds).map(|_| (rng.random_range(-spread..=spread), rng.random_range(-spread..=spread))).collect();
            let mut states = Vec::new();
            for _ in 0..frames {
                for p in pos.iter_mut() {
                    p.0 += rng.random_range(-1.0..1.0);
                    p.1 += rng.random_range(-0.5..2.0);
                }
                states.push(pos.iter().map(|&(x, y)| BirdState { x, y, ..Default::default() }).collect::<Vec<_>>());
            }
            let views = track(&states, 25.0, w, h, &CameraParams::default());
            let m = 0.07 * w.min(h) as f64;
            for (s, v) in states.iter().zip(&views) {
                for b in s {
                    let (px, py) = v.to_pixel(b.x, b.y, w, h);
                    let r = BIRD_RADIUS * v.scale;
                    proptest::prop_assert!(px - r >= m - 1e-6 && px + r <= w as f64 - m + 1e-6);
                    proptest::prop_assert!(py - r >= m - 1e-6 && py + r <= h as f64 - m + 1e-6);
                }
            }
        }
    }
}
