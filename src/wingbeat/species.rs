//! Species presets: wingbeat frequency (Hz), downstroke fractions, stroke amplitudes (radians),
//! the glide pose and the flap-glide bout lengths of the birds the tool animates. Sources and the
//! status of every number (measured, or an estimate) are tabulated in `docs/wingbeat.md`.

use super::kinematics::{Stroke, Strokes, Timing};
use crate::animation::wing::Species;

impl Species {
    /// The preset of this species.
    pub fn preset(&self) -> SpeciesPreset {
        match self {
            Species::Goose => SpeciesPreset {
                frequency_hz: 3.0,
                timing: Timing {
                    u_alpha: 0.55,
                    u_beta: 0.52,
                    hand_lag: deg(20.0),
                    fold_droop: deg(15.0),
                },
                strokes: Strokes {
                    dihedral: Stroke::new(deg(-30.0), deg(40.0)),
                    hand_dihedral: Stroke::new(deg(-15.0), deg(15.0)),
                    tail_bend: Stroke::new(deg(-4.0), deg(4.0)),
                    sweep: Stroke::new(deg(5.0), deg(-25.0)),
                    arm_twist: Stroke::new(deg(4.0), deg(12.0)),
                    hand_twist: Stroke::new(deg(-2.0), deg(35.0)),
                    spread: Stroke::new(1.0, 0.6),
                },
                glide_dihedral: deg(6.0),
                glide_hand_dihedral: deg(2.0),
                flap_beats: 14,
                glide_beats: 3,
                accel_ref_mps2: 1.0,
            },
            Species::Crane => SpeciesPreset {
                frequency_hz: 2.6,
                timing: Timing {
                    u_alpha: 0.52,
                    u_beta: 0.50,
                    hand_lag: deg(26.0),
                    fold_droop: deg(12.0),
                },
                strokes: Strokes {
                    dihedral: Stroke::new(deg(-28.0), deg(32.0)),
                    // Cranes' characteristic upward flick of the hand at the top of the stroke.
                    hand_dihedral: Stroke::new(deg(-12.0), deg(20.0)),
                    tail_bend: Stroke::new(deg(-3.0), deg(3.0)),
                    sweep: Stroke::new(deg(3.0), deg(-20.0)),
                    arm_twist: Stroke::new(deg(3.0), deg(10.0)),
                    hand_twist: Stroke::new(deg(-2.0), deg(30.0)),
                    spread: Stroke::new(1.0, 0.65),
                },
                glide_dihedral: deg(3.0),
                glide_hand_dihedral: deg(0.0),
                flap_beats: 8,
                glide_beats: 4,
                accel_ref_mps2: 0.8,
            },
            Species::Pelican => SpeciesPreset {
                frequency_hz: 2.2,
                timing: Timing {
                    u_alpha: 0.55,
                    u_beta: 0.53,
                    hand_lag: deg(17.0),
                    fold_droop: deg(10.0),
                },
                strokes: Strokes {
                    dihedral: Stroke::new(deg(-25.0), deg(28.0)),
                    hand_dihedral: Stroke::new(deg(-15.0), deg(10.0)),
                    tail_bend: Stroke::new(deg(-3.0), deg(3.0)),
                    sweep: Stroke::new(deg(2.0), deg(-15.0)),
                    arm_twist: Stroke::new(deg(3.0), deg(8.0)),
                    hand_twist: Stroke::new(deg(-2.0), deg(25.0)),
                    spread: Stroke::new(1.0, 0.7),
                },
                glide_dihedral: deg(0.0),
                glide_hand_dihedral: deg(-3.0),
                flap_beats: 6,
                glide_beats: 5,
                accel_ref_mps2: 0.8,
            },
        }
    }
}

/// The wingbeat of an average bird of a species, before per-bird and per-wingbeat variation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeciesPreset {
    /// Wingbeat frequency in steady cruising flight, Hz.
    pub frequency_hz: f64,
    /// Downstroke fractions u_α, u_β and the hand's lag and fold droop.
    pub timing: Timing,
    /// Stroke parameters u^d, u^u of every DOF (radians; spread as a fraction).
    pub strokes: Strokes,
    /// Arm dihedral held while gliding, radians, up positive.
    pub glide_dihedral: f64,
    /// Hand dihedral held while gliding, radians, up positive.
    pub glide_hand_dihedral: f64,
    /// Flapping wingbeats per flap-glide bout (`wingbeat.glide` = bouts).
    pub flap_beats: u32,
    /// Gliding wingbeat periods per flap-glide bout.
    pub glide_beats: u32,
    /// Forward acceleration, m/s², at which a bird beats at its fastest and deepest (the effort
    /// saturates at ±1 there).
    pub accel_ref_mps2: f64,
}

impl SpeciesPreset {
    /// The strokes of a glide: every DOF held at its downstroke value (wing extended), with the
    /// glide dihedral.
    pub fn glide_strokes(&self) -> Strokes {
        let s = &self.strokes;
        Strokes {
            dihedral: Stroke::hold(self.glide_dihedral),
            hand_dihedral: Stroke::hold(self.glide_hand_dihedral),
            tail_bend: Stroke::hold(0.0),
            sweep: Stroke::hold(s.sweep.down),
            arm_twist: Stroke::hold(s.arm_twist.down),
            hand_twist: Stroke::hold(s.hand_twist.down),
            spread: Stroke::hold(1.0),
        }
    }
}

/// Degrees to radians.
fn deg(d: f64) -> f64 {
    d * std::f64::consts::PI / 180.0
}
