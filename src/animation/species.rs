//! Real species: the morphology (mass, span, wing area), cruise airspeed and wingbeat frequency
//! of the birds that fly in line formations, each with the name of the rig family (goose, crane,
//! pelican) that draws it. Plain data, below the stages: an animation file's `species` may name
//! one, [`super::wing::Species`] parses it to its family, and [`crate::aero::species`] gives its
//! power curve. `docs/species.md` tabulates every number with its source and its status
//! (handbook value, measurement, or our estimate); a test checks the table against [`SPECIES`].

/// One real species.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BirdSpecies {
    /// The name on the command line and in animation files (`barnacle-goose`).
    pub name: &'static str,
    /// English name.
    pub common: &'static str,
    /// Scientific name.
    pub latin: &'static str,
    /// The name of the rig family that draws it (silhouette, skeleton, wingbeat preset):
    /// `goose`, `crane` or `pelican`, a name of [`super::wing::Species`].
    pub family: &'static str,
    /// Typical adult body mass, kg.
    pub mass_kg: f64,
    /// The handbook's range of adult body mass, kg.
    pub mass_range_kg: [f64; 2],
    /// Typical wingspan, m.
    pub span_m: f64,
    /// The handbook's range of wingspan, m.
    pub span_range_m: [f64; 2],
    /// Wing area (both wings and the body between them), m².
    pub wing_area_m2: f64,
    /// Cruise airspeed, m/s.
    pub cruise_ms: f64,
    /// Wingbeat frequency in cruising flight, Hz.
    pub wingbeat_hz: f64,
}

impl BirdSpecies {
    /// Cruise speed in wingspans per second.
    pub fn cruise_wingspans_s(&self) -> f64 {
        self.cruise_ms / self.span_m
    }
}

/// Every real species, in documentation order (sources in `docs/species.md`).
pub const SPECIES: [BirdSpecies; 8] = [
    BirdSpecies {
        name: "barnacle-goose",
        common: "barnacle goose",
        latin: "Branta leucopsis",
        family: "goose",
        mass_kg: 1.8,
        mass_range_kg: [1.2, 2.2],
        span_m: 1.38,
        span_range_m: [1.30, 1.45],
        wing_area_m2: 0.224,
        cruise_ms: 18.0,
        wingbeat_hz: 4.0,
    },
    BirdSpecies {
        name: "greylag-goose",
        common: "greylag goose",
        latin: "Anser anser",
        family: "goose",
        mass_kg: 3.3,
        mass_range_kg: [2.1, 4.6],
        span_m: 1.62,
        span_range_m: [1.47, 1.80],
        wing_area_m2: 0.316,
        cruise_ms: 17.0,
        wingbeat_hz: 3.4,
    },
    BirdSpecies {
        name: "canada-goose",
        common: "Canada goose",
        latin: "Branta canadensis",
        family: "goose",
        mass_kg: 3.6,
        mass_range_kg: [2.6, 6.5],
        span_m: 1.6,
        span_range_m: [1.27, 1.85],
        wing_area_m2: 0.312,
        cruise_ms: 18.0,
        wingbeat_hz: 3.0,
    },
    BirdSpecies {
        name: "white-fronted-goose",
        common: "greater white-fronted goose",
        latin: "Anser albifrons",
        family: "goose",
        mass_kg: 2.5,
        mass_range_kg: [1.8, 3.3],
        span_m: 1.46,
        span_range_m: [1.30, 1.65],
        wing_area_m2: 0.257,
        cruise_ms: 11.7,
        wingbeat_hz: 3.6,
    },
    BirdSpecies {
        name: "pink-footed-goose",
        common: "pink-footed goose",
        latin: "Anser brachyrhynchus",
        family: "goose",
        mass_kg: 2.6,
        mass_range_kg: [1.8, 3.4],
        span_m: 1.52,
        span_range_m: [1.35, 1.70],
        wing_area_m2: 0.278,
        cruise_ms: 17.0,
        wingbeat_hz: 3.6,
    },
    BirdSpecies {
        name: "common-crane",
        common: "common crane",
        latin: "Grus grus",
        family: "crane",
        mass_kg: 5.5,
        mass_range_kg: [4.5, 6.1],
        span_m: 2.2,
        span_range_m: [1.80, 2.40],
        wing_area_m2: 0.6,
        cruise_ms: 15.0,
        wingbeat_hz: 2.6,
    },
    BirdSpecies {
        name: "white-pelican",
        common: "great white pelican",
        latin: "Pelecanus onocrotalus",
        family: "pelican",
        mass_kg: 9.0,
        mass_range_kg: [5.4, 15.0],
        span_m: 2.9,
        span_range_m: [2.45, 3.60],
        wing_area_m2: 1.2,
        cruise_ms: 14.0,
        wingbeat_hz: 2.2,
    },
    BirdSpecies {
        name: "northern-bald-ibis",
        common: "northern bald ibis",
        latin: "Geronticus eremita",
        family: "crane",
        mass_kg: 1.3,
        mass_range_kg: [1.0, 1.5],
        span_m: 1.3,
        span_range_m: [1.25, 1.35],
        wing_area_m2: 0.26,
        cruise_ms: 14.0,
        wingbeat_hz: 3.5,
    },
];

/// The real species named `name` (case and surrounding blanks ignored; `_` and ` ` taken as
/// `-`), or `None` (families are not real species).
pub fn lookup(name: &str) -> Option<&'static BirdSpecies> {
    let t = name.trim().to_ascii_lowercase().replace(['_', ' '], "-");
    SPECIES.iter().find(|s| s.name == t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::wing::Species;

    #[test]
    fn every_species_names_a_family_and_parses_to_it() {
        for s in &SPECIES {
            let family: Species = s.family.parse().unwrap();
            assert_eq!(family.name(), s.family);
            assert_eq!(s.name.parse::<Species>().unwrap(), family, "{}", s.name);
            assert!(Species::known_names().contains(&s.name));
        }
        assert!("dodo".parse::<Species>().is_err());
    }
}
