//! What a biologist reads off an extracted frame: the V's apex angle per arm, the
//! formation's depth and width, and the mean wingtip spacing, per frame and over the movie.
//!
//! Takes [`FrameParams`] (formation frame, leader at the origin, wingspans) and gives
//! [`FrameGeometry`] and [`GeometrySummary`]. Definitions (the field studies' words, see
//! `docs/formats.md`):
//!
//! - **arm angle**: each arm is the least-squares line through the inliers on that side of the
//!   leader, the leader included; its angle is measured from the flight axis behind the leader,
//!   so 90° is line abreast and a swept-back arm is under 90°. With slope s = dy/dx,
//!   `left = atan2(1, −s)` and `right = atan2(1, s)`, degrees. A side without birds has no arm
//!   (an echelon has one).
//! - **apex angle**: left + right arm angle (the V angle of Gould & Heppner 1974 and O'Malley &
//!   Evans 1982), only when both arms exist.
//! - **depth**: the farthest inlier behind the leader; **width**: the inliers' lateral extent;
//!   wingspans.
//! - **wingtip spacing** (WTS): lateral distance between lateral neighbours minus one wingspan,
//!   averaged over the frame's neighbour pairs, i.e. μ_x − 1; negative when wingtips overlap.
//!   Metres when the wingspan in metres is known.

use serde::{Deserialize, Serialize};

use super::params::FrameParams;
use super::ransac::{Line, Model};

/// Geometry of one extracted frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrameGeometry {
    /// Angle of the left arm from the flight axis behind the leader, degrees; `None` without a
    /// bird left of the leader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_left_deg: Option<f64>,
    /// Angle of the right arm, degrees; `None` without a bird right of the leader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_right_deg: Option<f64>,
    /// Apex angle, left + right arm, degrees; `None` unless both arms exist.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_deg: Option<f64>,
    /// Farthest inlier behind the leader, wingspans.
    pub depth: f64,
    /// Lateral extent of the inliers, wingspans.
    pub width: f64,
    /// Mean wingtip spacing of lateral neighbours (μ_x − 1), wingspans.
    pub wingtip_spacing: f64,
    /// The same in metres, when the wingspan in metres is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing_m: Option<f64>,
}

/// Median, mean and range of one quantity over the frames that have it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Frames that have the quantity.
    pub frames: usize,
    /// Median.
    pub median: f64,
    /// Mean.
    pub mean: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Stat {
    /// The statistics of `v`; `None` when empty.
    pub fn of(v: &[f64]) -> Option<Stat> {
        if v.is_empty() {
            return None;
        }
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        let n = s.len();
        let median = if n % 2 == 1 {
            s[n / 2]
        } else {
            (s[n / 2 - 1] + s[n / 2]) / 2.0
        };
        Some(Stat {
            frames: n,
            median,
            mean: s.iter().sum::<f64>() / n as f64,
            min: s[0],
            max: s[n - 1],
        })
    }
}

/// The movie's geometry over all frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GeometrySummary {
    /// Apex angle, degrees (frames with two arms).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_deg: Option<Stat>,
    /// Left arm angle, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_left_deg: Option<Stat>,
    /// Right arm angle, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_right_deg: Option<Stat>,
    /// Depth, wingspans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<Stat>,
    /// Mean wingtip spacing, wingspans.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing: Option<Stat>,
    /// Mean wingtip spacing, metres, when the wingspan in metres is known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingtip_spacing_m: Option<Stat>,
}

/// Angle of an arm of slope `s` (dy/dx) from the flight axis behind the leader, degrees; `left`
/// for an arm at x < 0.
pub fn arm_angle_deg(s: f64, left: bool) -> f64 {
    let s = if left { -s } else { s };
    1.0f64.atan2(s).to_degrees()
}

/// The geometry of one frame; `wingspan_m` converts the spacing to metres.
pub fn frame_geometry(f: &FrameParams, wingspan_m: Option<f64>) -> FrameGeometry {
    let inl: Vec<(f64, f64)> = f
        .positions
        .iter()
        .filter(|p| f.inliers.contains(&p.id))
        .map(|p| (p.x, p.y))
        .collect();
    let arm = |left: bool| -> Option<f64> {
        let side: Vec<(f64, f64)> = inl
            .iter()
            .copied()
            .filter(|p| p.0 == 0.0 && p.1 == 0.0 || if left { p.0 < 0.0 } else { p.0 > 0.0 })
            .collect();
        if side.iter().all(|p| p.0 == 0.0) {
            return None;
        }
        let mut pts = side;
        if !pts.iter().any(|p| p.0 == 0.0 && p.1 == 0.0) {
            pts.push((0.0, 0.0));
        }
        Line::fit(&pts).map(|l| arm_angle_deg(l.slope_at(0.0), left))
    };
    let (arm_left_deg, arm_right_deg) = (arm(true), arm(false));
    let (lo, hi) = inl
        .iter()
        .fold((0.0f64, 0.0f64), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
    let wts = f.mu_x - 1.0;
    FrameGeometry {
        arm_left_deg,
        arm_right_deg,
        apex_deg: arm_left_deg.zip(arm_right_deg).map(|(l, r)| l + r),
        depth: inl.iter().map(|p| p.1).fold(0.0, f64::max),
        width: hi - lo,
        wingtip_spacing: wts,
        wingtip_spacing_m: wingspan_m.map(|m| wts * m),
    }
}

/// The summary over frames.
pub fn summarise(g: &[FrameGeometry]) -> GeometrySummary {
    let col = |f: &dyn Fn(&FrameGeometry) -> Option<f64>| -> Option<Stat> {
        Stat::of(&g.iter().filter_map(f).collect::<Vec<_>>())
    };
    GeometrySummary {
        apex_deg: col(&|g| g.apex_deg),
        arm_left_deg: col(&|g| g.arm_left_deg),
        arm_right_deg: col(&|g| g.arm_right_deg),
        depth: col(&|g| Some(g.depth)),
        wingtip_spacing: col(&|g| Some(g.wingtip_spacing)),
        wingtip_spacing_m: col(&|g| g.wingtip_spacing_m),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extract::params::{BirdPosition, ShapeModel};

    fn frame(pts: &[(f64, f64)]) -> FrameParams {
        FrameParams {
            index: 0,
            order: (0..pts.len()).collect(),
            leader: 0,
            mu_x: 0.9,
            sigma_x: 0.0,
            mu_y: 0.0,
            sigma_y: 0.0,
            shape: ShapeModel::Line {
                intercept: 0.0,
                slope: 0.0,
            },
            inliers: (0..pts.len()).collect(),
            outliers: vec![],
            positions: pts
                .iter()
                .enumerate()
                .map(|(id, &(x, y))| BirdPosition { id, x, y, dy: 0.0 })
                .collect(),
            geometry: None,
        }
    }

    #[test]
    fn a_symmetric_v_has_equal_arms_that_sum_to_the_apex() {
        // Arms at 30° from the flight axis: x = y·tan 30°.
        let t = 30f64.to_radians().tan();
        let f = frame(&[
            (0.0, 0.0),
            (-t, 1.0),
            (t, 1.0),
            (-2.0 * t, 2.0),
            (2.0 * t, 2.0),
        ]);
        let g = frame_geometry(&f, Some(1.5));
        assert!((g.arm_left_deg.unwrap() - 30.0).abs() < 1e-9);
        assert!((g.arm_right_deg.unwrap() - 30.0).abs() < 1e-9);
        assert!((g.apex_deg.unwrap() - 60.0).abs() < 1e-9);
        assert!((g.depth - 2.0).abs() < 1e-12);
        assert!((g.wingtip_spacing + 0.1).abs() < 1e-12);
        assert!((g.wingtip_spacing_m.unwrap() + 0.15).abs() < 1e-12);
    }

    #[test]
    fn an_echelon_has_one_arm_and_no_apex() {
        let f = frame(&[(0.0, 0.0), (0.9, 0.5), (1.8, 1.0)]);
        let g = frame_geometry(&f, None);
        assert!(g.arm_left_deg.is_none() && g.apex_deg.is_none());
        let a = g.arm_right_deg.unwrap();
        assert!((a - (0.9f64).atan2(0.5).to_degrees()).abs() < 1e-9, "{a}");
        assert_eq!(g.wingtip_spacing_m, None);
    }

    #[test]
    fn stats_of_an_even_count_take_the_middle_pair() {
        let s = Stat::of(&[4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!(
            (s.median, s.mean, s.min, s.max, s.frames),
            (2.5, 2.5, 1.0, 4.0, 4)
        );
        assert!(Stat::of(&[]).is_none());
    }
}
