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

/// The `--aero-model` flag's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum ModelArg {
    /// Hummel's horseshoe vortices with a vortex core (Klotsman & Tal's model).
    #[default]
    Hummel,
    /// Elliptically loaded lifting lines with continuous trailing sheets (Lissaman &
    /// Shollenberger's kind, as the field studies used; no core).
    Lissaman,
}

impl From<ModelArg> for formation::aero::AeroModel {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Hummel => formation::aero::AeroModel::Hummel,
            ModelArg::Lissaman => formation::aero::AeroModel::Lissaman,
        }
    }
}

/// Savings flags of commands that read savings already computed (`report`, `plot savings`):
/// each one given recomputes the savings with it, the others keep what the input recorded.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SavingsFlags {
    /// Model of the savings: hummel (horseshoes with a core) or lissaman (elliptic lifting
    /// lines, the kind the field studies used); default: the animation's own (docs/model.md).
    #[arg(long = "aero-model", value_enum, value_name = "MODEL")]
    pub aero_model: Option<ModelArg>,
    /// Wake of the savings: planar or 3d (each bird's height); default: the animation's own.
    #[arg(long, value_enum)]
    pub wake: Option<WakeArg>,
    /// Vortex core radius of Hummel's model, wingspans; default: the animation's own.
    #[arg(long = "core-radius", value_name = "R", allow_negative_numbers = true)]
    pub core_radius: Option<f64>,
    /// Body mass of a bird, kg, for its power curve (savings of total power).
    #[arg(long = "mass-kg", value_name = "KG", allow_negative_numbers = true)]
    pub mass_kg: Option<f64>,
    /// Airspeed, m/s, at which savings of total power are evaluated.
    #[arg(long = "speed-ms", value_name = "M/S", allow_negative_numbers = true)]
    pub speed_ms: Option<f64>,
}

impl SavingsFlags {
    /// The savings options these flags give on top of `recorded` (an animation's own model, if
    /// any); `None` when no savings flag was given. Errors name the flag.
    pub fn aero(
        &self,
        recorded: Option<&formation::animation::SavingsModel>,
    ) -> formation::Result<Option<formation::aero::AeroOptions>> {
        use formation::aero::AeroOptions;
        use formation::Error;
        self.flight()?;
        if self.aero_model.is_none() && self.wake.is_none() && self.core_radius.is_none() {
            return Ok(None);
        }
        let mut o = AeroOptions::default();
        if let Some(r) = recorded {
            o.core_radius = r.core_radius;
            o.wake = r.wake.parse().unwrap_or_default();
            o.model = r.model.parse().unwrap_or_default();
        }
        if let Some(m) = self.aero_model {
            o.model = m.into();
        }
        if let Some(w) = self.wake {
            o.wake = w.into();
        }
        if let Some(c) = self.core_radius {
            o.core_radius = c;
        }
        o.validate().map_err(|e| match e {
            Error::Parameter { message, .. } => Error::parameter("--core-radius", message),
            other => other,
        })?;
        Ok(Some(o))
    }

    /// The mass and airspeed given, checked; errors name the flag.
    pub fn flight(&self) -> formation::Result<formation::animation::FlightSettings> {
        let s = formation::animation::FlightSettings {
            mass_kg: self.mass_kg,
            speed_ms: self.speed_ms,
        };
        formation::aero::flight::validate_settings(&s).map_err(|e| match e {
            formation::Error::Parameter { name, message } => formation::Error::parameter(
                if name.ends_with("mass_kg") {
                    "--mass-kg"
                } else {
                    "--speed-ms"
                },
                message,
            ),
            other => other,
        })?;
        Ok(s)
    }

    /// Applies the flags to an animation: its flight settings, and its frames' savings
    /// recomputed with the model, wake and core when one of them was given.
    pub fn apply(&self, anim: &mut formation::Animation) -> formation::Result<()> {
        let f = self.flight()?;
        if !f.is_empty() {
            let mut base = anim.flight.unwrap_or_default();
            if f.mass_kg.is_some() {
                base.mass_kg = f.mass_kg;
            }
            if f.speed_ms.is_some() {
                base.speed_ms = f.speed_ms;
            }
            anim.flight = Some(base);
        }
        if let Some(o) = self.aero(anim.savings_model.as_ref())? {
            formation::aero::recompute_frame_savings(anim, &o);
        }
        Ok(())
    }
}
