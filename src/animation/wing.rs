//! The wingbeat options recorded in an animation file (`"wingbeat"`, docs/formats.md §4.4) and the names
//! they use: species, phase relation between birds, gliding. Plain data, below the stages: the
//! `wingbeat` stage reads them ([`crate::wingbeat`] re-exports every item), the animation file
//! stores them, and renderers rebuild the same wingbeats from them. Times in seconds.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::Animation;
use crate::error::{Error, Result};

/// A species whose wingbeat the tool knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Species {
    /// Canada goose (*Branta canadensis*), the default.
    #[default]
    Goose,
    /// Common crane (*Grus grus*).
    Crane,
    /// Pelican (brown pelican, *Pelecanus occidentalis*).
    Pelican,
}

impl Species {
    /// Every species, in documentation order.
    pub const ALL: [Species; 3] = [Species::Goose, Species::Crane, Species::Pelican];

    /// The lowercase name used on the command line and in animation files.
    pub fn name(&self) -> &'static str {
        match self {
            Species::Goose => "goose",
            Species::Crane => "crane",
            Species::Pelican => "pelican",
        }
    }

    /// Every name a species may be given by: the real species (`barnacle-goose`, see
    /// [`super::species`]), then the families.
    pub fn known_names() -> Vec<&'static str> {
        super::species::SPECIES
            .iter()
            .map(|s| s.name)
            .chain(Species::ALL.iter().map(|s| s.name()))
            .collect()
    }
}

impl fmt::Display for Species {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Species {
    type Err = Error;

    fn from_str(s: &str) -> Result<Species> {
        let t = s.trim().to_ascii_lowercase();
        // A real species is drawn by its family's rig (docs/species.md).
        if let Some(b) = super::species::lookup(&t) {
            return b.family.parse();
        }
        Species::ALL
            .into_iter()
            .find(|sp| sp.name() == t)
            .ok_or_else(|| {
                Error::parameter(
                    "wingbeat.species",
                    format!(
                        "unknown species \"{s}\": expected one of {}",
                        Species::known_names().join(", ")
                    ),
                )
            })
    }
}

/// How the wingbeat phases of different birds relate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PhaseMode {
    /// Followers lock their phase to the bird ahead with a lag that tracks the streamwise distance
    /// (spatial phasing, Portugal et al. 2014). The default.
    #[default]
    Locked,
    /// Every bird flaps at its own frequency from a random initial phase.
    Independent,
}

impl FromStr for PhaseMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<PhaseMode> {
        match s.trim().to_ascii_lowercase().as_str() {
            "locked" => Ok(PhaseMode::Locked),
            "independent" => Ok(PhaseMode::Independent),
            _ => Err(Error::parameter(
                "wingbeat.phase_mode",
                format!("unknown phase mode \"{s}\": expected locked or independent"),
            )),
        }
    }
}

impl fmt::Display for PhaseMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PhaseMode::Locked => "locked",
            PhaseMode::Independent => "independent",
        })
    }
}

/// Gliding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Glide {
    /// Continuous flapping (the default).
    #[default]
    Off,
    /// Flap-gliding: bouts of the species' `flap_beats` wingbeats followed by `glide_beats` wingbeat
    /// periods of gliding; a bird that decelerates hard also glides.
    Bouts,
    /// Pure gliding: wings held in the glide pose throughout.
    Always,
}

impl FromStr for Glide {
    type Err = Error;
    fn from_str(s: &str) -> Result<Glide> {
        match s.trim().to_ascii_lowercase().as_str() {
            "off" | "none" => Ok(Glide::Off),
            "bouts" | "on" => Ok(Glide::Bouts),
            "always" => Ok(Glide::Always),
            _ => Err(Error::parameter(
                "wingbeat.glide",
                format!("unknown glide mode \"{s}\": expected off, bouts or always"),
            )),
        }
    }
}

impl fmt::Display for Glide {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Glide::Off => "off",
            Glide::Bouts => "bouts",
            Glide::Always => "always",
        })
    }
}

/// Options of the wingbeat stage. Stored in the animation file (`"wingbeat"`) by
/// `wingbeat::assign_phases` so that renderers rebuild the same wingbeats.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WingbeatOptions {
    /// Species preset.
    pub species: Species,
    /// Phase relation between birds (default: locked to the bird ahead).
    pub phase_mode: PhaseMode,
    /// Gliding mode (default: off).
    pub glide: Glide,
    /// Scale of the random per-bird and per-wingbeat variation, dimensionless: 0 = identical
    /// birds and wingbeats, 1 = the documented default spread.
    pub variation: f64,
    /// Time constant of phase locking, seconds: a phase error decays as e^{−t/τ}.
    pub lock_time_s: f64,
}

impl Default for WingbeatOptions {
    fn default() -> Self {
        WingbeatOptions {
            species: Species::Goose,
            phase_mode: PhaseMode::Locked,
            glide: Glide::Off,
            variation: 1.0,
            lock_time_s: 0.6,
        }
    }
}

impl WingbeatOptions {
    /// Checks the numeric options.
    pub fn validate(&self) -> Result<()> {
        if !(self.variation.is_finite() && (0.0..=5.0).contains(&self.variation)) {
            return Err(Error::parameter(
                "wingbeat.variation",
                format!("{}: must be between 0 and 5", self.variation),
            ));
        }
        if !(self.lock_time_s.is_finite() && self.lock_time_s >= 0.05 && self.lock_time_s <= 60.0) {
            return Err(Error::parameter(
                "wingbeat.lock_time_s",
                format!("{}: must be between 0.05 and 60 seconds", self.lock_time_s),
            ));
        }
        Ok(())
    }

    /// The options an animation was made with: its `wingbeat` record if present, else the
    /// defaults with the animation's `species` (goose if absent or unknown).
    pub fn for_animation(anim: &Animation) -> WingbeatOptions {
        if let Some(o) = &anim.wingbeat {
            if o.validate().is_ok() {
                return o.clone();
            }
        }
        let species = anim
            .species
            .as_deref()
            .and_then(|s| s.parse().ok())
            .unwrap_or_default();
        WingbeatOptions {
            species,
            ..WingbeatOptions::default()
        }
    }
}
