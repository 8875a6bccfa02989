//! Real species in the power curve: [`BirdSpecies::morphology`] for the table of
//! [`crate::animation::species`] (morphology, cruise airspeed and wingbeat frequency of the birds
//! that fly in line formations; `docs/species.md` gives every number's source).
//!
//! The species option (`wingbeat.species`) takes a real species (`barnacle-goose`) or a family
//! (`goose`); a family keeps the family's typical bird of
//! [`crate::aero::flight::Morphology::of`] and has no cruise airspeed of its own.

pub use crate::animation::species::{lookup, BirdSpecies, SPECIES};

impl BirdSpecies {
    /// The morphology of the power curve.
    pub fn morphology(&self) -> crate::aero::flight::Morphology {
        crate::aero::flight::Morphology {
            mass_kg: self.mass_kg,
            span_m: self.span_m,
            wing_area_m2: self.wing_area_m2,
        }
    }
}

/// Every name the species option accepts: the real species, then the families.
pub fn known_names() -> Vec<&'static str> {
    crate::animation::wing::Species::known_names()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aero::flight::PowerCurve;
    use crate::animation::wing::Species;

    #[test]
    fn presets_lie_in_their_handbook_ranges_and_fly() {
        for s in &SPECIES {
            assert!(
                (s.mass_range_kg[0]..=s.mass_range_kg[1]).contains(&s.mass_kg),
                "{}",
                s.name
            );
            assert!(
                (s.span_range_m[0]..=s.span_range_m[1]).contains(&s.span_m),
                "{}",
                s.name
            );
            let m = s.morphology();
            m.validate().unwrap();
            // Aspect ratios of the big soaring-flapping birds: 6 to 10.
            assert!((6.0..10.0).contains(&m.aspect_ratio()), "{}", s.name);
            let c = PowerCurve::new(m);
            let share = c.induced_share(s.cruise_ms);
            assert!((0.1..0.7).contains(&share), "{}: {share}", s.name);
            assert_eq!(lookup(s.name), Some(s));
            assert_eq!(lookup(&s.name.replace('-', "_").to_uppercase()), Some(s));
        }
        assert!(lookup("goose").is_none() && lookup("dodo").is_none());
        assert_eq!(known_names().len(), SPECIES.len() + Species::ALL.len());
    }

    #[test]
    fn a_barnacle_goose_at_cruise_has_an_induced_share_of_about_a_quarter_to_a_third() {
        // The issue that asked for species measured 0.26–0.37 for a barnacle goose of
        // 1.7–2.0 kg and 1.35–1.45 m at 17–19 m/s.
        let b = lookup("barnacle-goose").unwrap();
        let s = PowerCurve::new(b.morphology()).induced_share(b.cruise_ms);
        assert!((0.26..0.37).contains(&s), "{s}");
    }
}

#[cfg(test)]
mod doc_table {
    use super::*;

    /// docs/species.md's table row by row equals [`SPECIES`].
    #[test]
    fn docs_table_equals_the_presets() {
        let doc = include_str!("../../docs/species.md");
        let rows: Vec<Vec<String>> = doc
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| name"))
            .map(|l| {
                l.trim_matches('|')
                    .split('|')
                    .map(|c| c.trim().to_string())
                    .collect()
            })
            .collect();
        assert_eq!(rows.len(), SPECIES.len());
        let num = |t: &str| -> Vec<f64> {
            t.split(['(', ')', '–', ' '])
                .filter(|p| !p.is_empty())
                .map(|p| p.parse::<f64>().unwrap())
                .collect()
        };
        for (r, s) in rows.iter().zip(&SPECIES) {
            assert_eq!(r[0], s.name);
            assert_eq!(r[1].trim_matches('*'), s.latin);
            assert_eq!(r[2], s.family);
            assert_eq!(
                num(&r[3]),
                vec![s.mass_kg, s.mass_range_kg[0], s.mass_range_kg[1]]
            );
            assert_eq!(
                num(&r[4]),
                vec![s.span_m, s.span_range_m[0], s.span_range_m[1]]
            );
            assert_eq!(num(&r[5]), vec![s.wing_area_m2]);
            assert_eq!(num(&r[6]), vec![s.cruise_ms]);
            assert_eq!(num(&r[7]), vec![s.wingbeat_hz]);
        }
    }
}
