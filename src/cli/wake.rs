//! `--wake planar|3d`: which wake model gives the savings (docs/model.md, "The 3-D wake").

use clap::ValueEnum;
use formation::aero::Wake;

/// The wake flag's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum WakeArg {
    /// Hummel's planar horseshoe wake: heights ignored.
    #[default]
    Planar,
    /// The same horseshoes with each bird's height (a shape's "z", wingspans, up).
    #[value(name = "3d")]
    ThreeD,
}

impl From<WakeArg> for Wake {
    fn from(w: WakeArg) -> Wake {
        match w {
            WakeArg::Planar => Wake::Planar,
            WakeArg::ThreeD => Wake::ThreeD,
        }
    }
}
