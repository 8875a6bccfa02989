//! The landing record of an animation file (`landing`) and the surface a flock lands on; the
//! landing itself is planned in `initiate::landing` (docs/landing.md).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Height of the root (body centre) of a bird floating on water above the waterline, wingspans:
/// the body rests at the waterline, its lower half under water.
pub const FLOAT_HEIGHT: f64 = 0.01;

/// Where the flock lands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Surface {
    /// A field: touch down, a few running steps, sit.
    #[default]
    Ground,
    /// Water: touch down skiing on the feet, settle with the body at the waterline.
    Water,
}

impl Surface {
    /// The word of the flag and the file.
    pub fn word(self) -> &'static str {
        match self {
            Surface::Ground => "ground",
            Surface::Water => "water",
        }
    }

    /// The surface a word names, or an error listing the choices.
    pub fn parse(s: &str) -> Result<Surface> {
        match s {
            "ground" => Ok(Surface::Ground),
            "water" => Ok(Surface::Water),
            other => Err(Error::parameter(
                "landing.surface",
                format!("{other:?} is not a surface to land on; give ground or water"),
            )),
        }
    }
}

/// What the landing stage did, recorded in the animation file (`landing`) so that renderers
/// pose the flare from the file alone.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LandingRecord {
    /// `"ground"` or `"water"`.
    pub surface: Surface,
    /// Each bird's touch-down time, seconds (animation time).
    pub touchdown: Vec<f64>,
    /// Each bird's time of coming to rest, seconds.
    pub rest: Vec<f64>,
    /// Length of the flare before each touch-down, seconds.
    pub flare_seconds: f64,
}

impl LandingRecord {
    /// Birds in order of arrival (touch-down time, then index).
    pub fn arrival_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.touchdown.len()).collect();
        order.sort_by(|&a, &b| {
            self.touchdown[a]
                .total_cmp(&self.touchdown[b])
                .then(a.cmp(&b))
        });
        order
    }

    /// Flare weight of bird `i` at time `t`: 0 before the flare, rising to 1 over its first
    /// third, 1 to touch-down, falling to 0 over the next `flare_seconds` (a smoothstep each way).
    pub fn flare_weight(&self, i: usize, t: f64) -> f64 {
        let Some(&td) = self.touchdown.get(i) else {
            return 0.0;
        };
        let fs = self.flare_seconds.max(1e-6);
        let rise = smooth((t - (td - fs)) / (fs / 3.0));
        let fall = 1.0 - smooth((t - td) / fs);
        rise.min(fall)
    }
}

/// smoothstep on [0, 1], clamped.
fn smooth(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}
