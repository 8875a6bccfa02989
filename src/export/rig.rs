//! The bird model shared by every renderer: body outline, wing segments and the joint rotations a
//! [`WingPose`] implies. The GIF silhouettes and the glTF/USD skeletons turn their wings by the
//! same [`wing_joints`] rotations, so the wingbeat a user sees in the GIF is the one they import
//! into Blender; the 3D birds' species proportions are in [`super::bird`].
//!
//! Lengths are in wingspans (a bird is 1 wide with its wings fully spread). The bird's own frame
//! uses glTF's conventions: `+Y` up, `+Z` forward (the glTF "front" of an asset), hence `+X` is the
//! bird's **left** and the right wing lies on `−X`. A wing point `(u, 0, c)` of a segment (`u` ≥ 0
//! along the span outward, `c` along the chord, forward positive) sits at `(s·u, 0, c)` in that
//! segment's node frame, with side `s = −1` for the right wing and `s = +1` for the left.
//!
//! Joint rotations (node rotations, applied to children as `p_parent = T + q·p_child`):
//! ```math
//! q_\text{shoulder} = R_Y(-s\,(\sigma - f_a(1-\rho)))\;R_Z(s\,\delta)\;R_X(-\tau_a), \qquad
//! q_\text{wrist} = R_Y(s\,f_h(1-\rho))\;R_Z(s\,\delta_h)\;R_X(-\tau_h)
//! ```
//! with σ = `sweep`, δ = `dihedral`, δ_h = `hand_dihedral`, τ = `arm_twist`/`hand_twist`,
//! ρ = `spread`, and fold angles f_a = [`ARM_FOLD`], f_h = [`HAND_FOLD`] (how far the arm and the
//! hand swing back when the wing is folded, ρ = 0).

use glam::{Quat, Vec3};

use crate::wingbeat::WingPose;

/// Shoulder joint of the left wing in the bird frame, wingspans (the right one mirrors `x`).
pub const SHOULDER: [f32; 3] = [0.06, 0.02, 0.03];
/// Length of the upper arm (shoulder to wrist) along the span, wingspans.
pub const ARM_LENGTH: f32 = 0.20;
/// Length of the hand (wrist to tip) along the span, wingspans.
pub const HAND_LENGTH: f32 = 0.24;
/// Backward swing of the arm when the wing is fully folded, radians.
pub const ARM_FOLD: f32 = 0.5;
/// Backward swing of the hand relative to the arm when the wing is fully folded, radians.
pub const HAND_FOLD: f32 = 2.2;
/// Radius of a disc around the bird's centre that contains every pose, wingspans.
pub const BIRD_RADIUS: f64 = 0.6;

/// Body profile along the forward axis: `(z, half width, half height)`, wingspans, tail to bill
/// (a goose: body about half the span long, long thin neck, small head).
pub const BODY_PROFILE: [(f32, f32, f32); 12] = [
    (-0.25, 0.010, 0.006),
    (-0.23, 0.040, 0.012),
    (-0.19, 0.052, 0.030),
    (-0.11, 0.072, 0.060),
    (-0.01, 0.080, 0.068),
    (0.07, 0.064, 0.054),
    (0.12, 0.030, 0.030),
    (0.20, 0.020, 0.022),
    (0.245, 0.026, 0.026),
    (0.275, 0.024, 0.022),
    (0.30, 0.012, 0.010),
    (0.325, 0.004, 0.004),
];

/// Outline of the upper arm in its segment frame, `(u, c)`: leading edge outward, then trailing
/// edge back to the root. Wingspans. The wrist sits a little forward, the secondaries make a
/// broad, slightly curved trailing edge.
pub const ARM_OUTLINE: [(f32, f32); 7] = [
    (0.0, 0.060),
    (0.10, 0.072),
    // A sliver past the wrist, hidden under the hand, so the two parts join without a seam.
    (ARM_LENGTH + 0.012, 0.078),
    (ARM_LENGTH + 0.012, -0.085),
    (0.14, -0.108),
    (0.07, -0.120),
    (0.0, -0.125),
];

/// Outline of the hand in its segment frame, `(u, c)`, same order as [`ARM_OUTLINE`]: a long,
/// swept-back, pointed hand like a goose's primaries.
pub const HAND_OUTLINE: [(f32, f32); 10] = [
    (0.0, 0.078),
    (0.07, 0.070),
    (0.14, 0.046),
    (0.20, 0.006),
    (HAND_LENGTH, -0.050),
    (0.215, -0.072),
    (0.17, -0.082),
    (0.11, -0.088),
    (0.05, -0.088),
    (0.0, -0.085),
];

/// Which wing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The bird's left wing, on `+X`.
    Left,
    /// The bird's right wing, on `−X`.
    Right,
}

impl Side {
    /// Both wings, left first.
    pub const BOTH: [Side; 2] = [Side::Left, Side::Right];

    /// The sign `s` of the module doc: +1 left, −1 right.
    pub fn sign(self) -> f32 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }

    /// `"left"` or `"right"`.
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

/// Local transforms of one wing's two joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WingJoints {
    /// Shoulder position in the bird frame, wingspans.
    pub shoulder_t: Vec3,
    /// Shoulder rotation (upper-arm node).
    pub shoulder_q: Quat,
    /// Wrist position in the shoulder frame, wingspans.
    pub wrist_t: Vec3,
    /// Wrist rotation relative to the arm (hand node).
    pub wrist_q: Quat,
}

/// Joint transforms of one wing for a pose (formulas in the module doc).
pub fn wing_joints(pose: &WingPose, side: Side) -> WingJoints {
    let s = side.sign();
    let fold = (1.0 - pose.spread.clamp(0.0, 1.0)) as f32;
    let shoulder_q = Quat::from_rotation_y(-s * (pose.sweep as f32 - ARM_FOLD * fold))
        * Quat::from_rotation_z(s * pose.dihedral as f32)
        * Quat::from_rotation_x(-(pose.arm_twist as f32));
    let wrist_q = Quat::from_rotation_y(s * HAND_FOLD * fold)
        * Quat::from_rotation_z(s * pose.hand_dihedral as f32)
        * Quat::from_rotation_x(-(pose.hand_twist as f32));
    WingJoints {
        shoulder_t: Vec3::new(s * SHOULDER[0], SHOULDER[1], SHOULDER[2]),
        shoulder_q: shoulder_q.normalize(),
        wrist_t: Vec3::new(s * ARM_LENGTH, 0.0, 0.0),
        wrist_q: wrist_q.normalize(),
    }
}

/// A segment outline point `(u, c)` placed in its node frame for `side`.
pub fn segment_point(side: Side, (u, c): (f32, f32)) -> Vec3 {
    Vec3::new(side.sign() * u, 0.0, c)
}

/// Closed outlines of the bird seen from above for a pose, in the bird's ground-plane frame
/// `(right, forward)`, wingspans: the body first, then each wing's arm and hand. Each outline is
/// counter-clockwise in `(right, forward)` so that overlapping parts fill as a union.
pub fn top_view(pose: &WingPose) -> Vec<Vec<[f32; 2]>> {
    let mut out = Vec::with_capacity(5);
    // Body: left edge from tail to bill, then right edge back.
    let mut body = Vec::with_capacity(2 * BODY_PROFILE.len());
    for &(z, w, _) in BODY_PROFILE.iter() {
        body.push([w, z]);
    }
    for &(z, w, _) in BODY_PROFILE.iter().rev() {
        body.push([-w, z]);
    }
    out.push(ccw(body));
    for side in Side::BOTH {
        let j = wing_joints(pose, side);
        let arm = |p: Vec3| j.shoulder_t + j.shoulder_q * p;
        let hand = |p: Vec3| j.shoulder_t + j.shoulder_q * (j.wrist_t + j.wrist_q * p);
        // Bird frame (X left, Z forward) to ground plane (right, forward) = (−X, Z).
        let flat = |p: Vec3| [-p.x, p.z];
        let a: Vec<[f32; 2]> = ARM_OUTLINE
            .iter()
            .map(|&q| flat(arm(segment_point(side, q))))
            .collect();
        let h: Vec<[f32; 2]> = HAND_OUTLINE
            .iter()
            .map(|&q| flat(hand(segment_point(side, q))))
            .collect();
        out.push(ccw(a));
        out.push(ccw(h));
    }
    out
}

fn ccw(mut p: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    if super::raster::signed_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spread() -> WingPose {
        WingPose {
            spread: 1.0,
            ..WingPose::default()
        }
    }

    #[test]
    fn spread_wings_span_one_wingspan() {
        let outlines = top_view(&spread());
        let xs: Vec<f32> = outlines.iter().flatten().map(|p| p[0]).collect();
        let min = xs.iter().cloned().fold(f32::MAX, f32::min);
        let max = xs.iter().cloned().fold(f32::MIN, f32::max);
        assert!(
            (max - 0.5).abs() < 1e-5 && (min + 0.5).abs() < 1e-5,
            "{min} {max}"
        );
    }

    #[test]
    fn dihedral_raises_both_tips_and_shortens_the_projected_span() {
        let pose = WingPose {
            dihedral: 0.6,
            ..spread()
        };
        for side in Side::BOTH {
            let j = wing_joints(&pose, side);
            let tip = j.shoulder_t
                + j.shoulder_q * (j.wrist_t + j.wrist_q * segment_point(side, (HAND_LENGTH, 0.0)));
            assert!(tip.y > 0.2, "{side:?} tip {tip}");
            assert!(tip.x.abs() < 0.5 * 0.9, "{side:?} tip {tip}");
        }
    }

    #[test]
    fn sweep_forward_moves_tips_forward_and_folding_moves_them_back() {
        for side in Side::BOTH {
            let tip = |pose: WingPose| {
                let j = wing_joints(&pose, side);
                j.shoulder_t
                    + j.shoulder_q
                        * (j.wrist_t + j.wrist_q * segment_point(side, (HAND_LENGTH, 0.0)))
            };
            let base = tip(spread()).z;
            assert!(
                tip(WingPose {
                    sweep: 0.3,
                    ..spread()
                })
                .z > base + 0.05
            );
            assert!(
                tip(WingPose {
                    spread: 0.0,
                    ..spread()
                })
                .z < base - 0.1
            );
        }
    }

    #[test]
    fn twist_raises_the_leading_edge() {
        let pose = WingPose {
            arm_twist: 0.3,
            ..spread()
        };
        for side in Side::BOTH {
            let j = wing_joints(&pose, side);
            let lead = j.shoulder_q * segment_point(side, (0.1, 0.07));
            assert!(lead.y > 0.0, "{side:?} {lead}");
        }
    }

    #[test]
    fn every_pose_fits_in_the_bird_radius() {
        for sweep in [-1.2, -0.5, 0.0, 0.5, 1.2] {
            for dihedral in [-1.0, 0.0, 1.0] {
                for spread in [0.0, 0.5, 1.0] {
                    let pose = WingPose {
                        sweep,
                        dihedral,
                        hand_dihedral: -dihedral,
                        arm_twist: 0.5,
                        hand_twist: -0.5,
                        spread,
                        ..WingPose::default()
                    };
                    for o in top_view(&pose) {
                        for p in o {
                            let r = (p[0] * p[0] + p[1] * p[1]).sqrt() as f64;
                            assert!(r < BIRD_RADIUS, "{pose:?}: {r}");
                        }
                    }
                }
            }
        }
    }
}
