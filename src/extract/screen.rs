//! Frames unlike the others. One badly annotated or half-tracked frame (birds missing, marks
//! swapped, a bird of another flock) can have lateral gaps far wider or more scattered than the
//! rest; the steady flight draws its mean gap from the range of the frames' μ_x and its scatter
//! from their σ_x, so that one frame would widen every generated flock. [`odd_frames`] finds
//! them with robust statistics over the frames; `extract` warns, naming each, and the steady
//! flight leaves them out of the spacing it draws from ([`spacing_frames`]).
//!
//! A frame is odd when, against the median over the frames and a robust scale (1.4826 × the
//! median absolute deviation, at least [`MIN_SCALE`] of the median gap):
//! - its mean gap μ_x is more than [`ODD_Z`] scales from the median, or
//! - its gap scatter σ_x is more than [`ODD_Z`] scales above the median scatter, or
//! - more than [`ODD_OUTLIER_SHARE`] of its birds are off the fitted shape while the median
//!   frame has under half that share.
//!
//! Screening needs at least [`MIN_SCREENED`] frames, and never leaves fewer than half of them.

use super::params::{FormationParams, FrameParams};

/// Robust z above which a frame's μ_x or σ_x is odd.
pub const ODD_Z: f64 = 4.0;
/// Floor of the robust scale, as a fraction of the median gap (frames whose gaps differ by a
/// few per cent are never odd, however alike the others are).
pub const MIN_SCALE: f64 = 0.05;
/// Share of a frame's birds off the fitted shape above which it is odd.
pub const ODD_OUTLIER_SHARE: f64 = 0.4;
/// Fewest frames screened.
pub const MIN_SCREENED: usize = 5;

/// One odd frame.
#[derive(Debug, Clone, PartialEq)]
pub struct OddFrame {
    /// Position in `params.frames`.
    pub position: usize,
    /// The frame's index in the footage.
    pub index: i64,
    /// Why, in words with numbers.
    pub reason: String,
}

/// The median of the finite values of `v` (NaN when there are none).
fn median(v: &[f64]) -> f64 {
    let mut finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    super::bootstrap::median(&mut finite).unwrap_or(f64::NAN)
}

fn outlier_share(f: &FrameParams) -> f64 {
    let n = f.inliers.len() + f.outliers.len();
    if n == 0 {
        0.0
    } else {
        f.outliers.len() as f64 / n as f64
    }
}

/// The odd frames of `params`, in file order (empty with fewer than [`MIN_SCREENED`] frames).
pub fn odd_frames(params: &FormationParams) -> Vec<OddFrame> {
    let fr = &params.frames;
    if fr.len() < MIN_SCREENED {
        return Vec::new();
    }
    let mu: Vec<f64> = fr.iter().map(|f| f.mu_x).collect();
    let sd: Vec<f64> = fr.iter().map(|f| f.sigma_x).collect();
    let share: Vec<f64> = fr.iter().map(outlier_share).collect();
    let (mu_med, sd_med, share_med) = (median(&mu), median(&sd), median(&share));
    let floor = MIN_SCALE * mu_med.abs().max(0.1);
    let scale = |v: &[f64], m: f64| {
        let dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
        (1.4826 * median(&dev)).max(floor)
    };
    let (mu_s, sd_s) = (scale(&mu, mu_med), scale(&sd, sd_med));
    let mut odd: Vec<OddFrame> = Vec::new();
    for (k, f) in fr.iter().enumerate() {
        let mut why = Vec::new();
        if ((f.mu_x - mu_med) / mu_s).abs() > ODD_Z || ((f.sigma_x - sd_med) / sd_s) > ODD_Z {
            why.push(format!(
                "lateral gaps {:.2} ± {:.2} wingspans against {:.2} ± {:.2} in the median frame",
                f.mu_x, f.sigma_x, mu_med, sd_med
            ));
        }
        if share[k] > ODD_OUTLIER_SHARE && share_med < 0.5 * ODD_OUTLIER_SHARE {
            why.push(format!(
                "{} of {} birds off the fitted shape",
                f.outliers.len(),
                f.inliers.len() + f.outliers.len()
            ));
        }
        if !why.is_empty() {
            odd.push(OddFrame {
                position: k,
                index: f.index,
                reason: why.join("; "),
            });
        }
    }
    if 2 * odd.len() > fr.len() {
        // Most frames "odd": the footage is simply varied; screen nothing.
        return Vec::new();
    }
    odd
}

/// The frames the steady flight draws its lateral spacing from: every frame but the odd ones.
pub fn spacing_frames(params: &FormationParams) -> Vec<&FrameParams> {
    let odd = odd_frames(params);
    params
        .frames
        .iter()
        .enumerate()
        .filter(|(k, _)| !odd.iter().any(|o| o.position == *k))
        .map(|(_, f)| f)
        .collect()
}
