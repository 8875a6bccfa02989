//! Kinematic flapping after Wu & Popović (issue 7).
//!
//! Interface used by the renderers: [`Flapper::from_animation`] rebuilds every bird's wingbeat
//! from an animation file (its seed, species and per-frame `wing_phase`), and [`Flapper::pose`]
//! gives the joint angles of one bird at one frame. The placeholder below is a plain sinusoid;
//! the wingbeat work replaces the internals, not the interface.

use crate::animation::Animation;

/// Joint angles of one wing (both wings mirror each other), radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WingPose {
    /// Shoulder elevation (dihedral) of the upper arm above the horizontal, up positive.
    pub dihedral: f64,
    /// Elevation of the hand relative to the upper arm (wrist/elbow bend), up positive.
    pub hand_dihedral: f64,
    /// Sweep of the whole wing about the vertical axis, forward positive.
    pub sweep: f64,
    /// Twist (pitch) of the arm about its span axis, leading edge up positive.
    pub arm_twist: f64,
    /// Twist of the hand about its span axis, leading edge up positive.
    pub hand_twist: f64,
    /// Wing spread, 0 = folded, 1 = fully extended.
    pub spread: f64,
    /// Tail bend, up positive.
    pub tail_bend: f64,
}

/// Per-bird wingbeats of a whole animation.
#[derive(Debug, Clone)]
pub struct Flapper {
    phases: Vec<Vec<f64>>,
}

impl Flapper {
    /// Rebuilds the wingbeats of `anim`.
    pub fn from_animation(anim: &Animation) -> Flapper {
        let freq = 3.0; // Hz, placeholder
        let phases = anim
            .frames
            .iter()
            .map(|f| match &f.wing_phase {
                Some(p) => p.clone(),
                None => (0..anim.birds)
                    .map(|i| {
                        (std::f64::consts::TAU * freq * f.t + i as f64)
                            .rem_euclid(std::f64::consts::TAU)
                    })
                    .collect(),
            })
            .collect();
        Flapper { phases }
    }

    /// Pose of `bird` at `frame`.
    pub fn pose(&self, frame: usize, bird: usize) -> WingPose {
        let phase = self
            .phases
            .get(frame)
            .and_then(|p| p.get(bird))
            .copied()
            .unwrap_or(0.0);
        WingPose {
            dihedral: 0.5 * phase.cos(),
            hand_dihedral: 0.2 * phase.cos(),
            spread: 1.0,
            ..WingPose::default()
        }
    }
}
