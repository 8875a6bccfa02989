//! A bird's power curve after Pennycuick's method (*Modelling the Flying Bird*, 2008, and the
//! Flight program): the mechanical power of steady level flight as the sum of
//!
//! - **induced** power, the cost of holding the bird up: P_ind = k·(mg)² / (2ρ·V·S_d), with the
//!   disc area S_d = π·b²/4 swept by the span b and the induced power factor k = 1.2;
//! - **parasite** power, the body's drag: P_par = ρ·V³·S_b·C_Db / 2, with the body frontal area
//!   S_b = 0.00813·m^0.666 m² and the body drag coefficient C_Db = 0.1;
//! - **profile** power, the wings' own drag, taken as constant over speed: P_pro = X₁·P_am, the
//!   profile power ratio X₁ = 8.4 / AR times the absolute minimum power P_am (the least of
//!   P_ind + P_par, at the minimum-power speed V_mp).
//!
//! A formation saving is a fraction of induced power (Hummel's model normalises by the solo
//! induced drag); [`PowerCurve::induced_share`] converts it to a fraction of the total mechanical
//! power: saving_total = saving × P_ind / (P_ind + P_par + P_pro) at the bird's airspeed. The
//! chemical power (muscle efficiency, basal metabolism) is not modelled: the fractions are of
//! mechanical power.
//!
//! The morphology presets ([`Morphology::of`]) are typical adult values of the species the tool
//! animates, not measurements of the filmed birds; `docs/model.md` tabulates them and their
//! sources. When a flock's wingspan differs from the preset's, the preset is scaled
//! isometrically (mass ∝ b³, wing area ∝ b²) unless the mass is given.

use crate::animation::wing::Species;
use crate::animation::Animation;
use crate::error::{Error, Result};

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;
/// Air density at sea level in the International Standard Atmosphere, kg/m³.
pub const SEA_LEVEL_DENSITY: f64 = 1.225;
/// Pennycuick's induced power factor k (2008).
pub const INDUCED_FACTOR: f64 = 1.2;
/// Pennycuick's body drag coefficient C_Db for a bird's body (2008, from wind-tunnel wakes).
pub const BODY_DRAG_COEF: f64 = 0.1;

/// Ratio of a large bird's largest sustained flight power to its power at the minimum-power
/// speed, for the power-limited climb ([`PowerCurve::climb_rate`]); our choice (large birds have
/// a small power margin, which is why they run to take off), see docs/initiation.md.
pub const CLIMB_POWER_MARGIN: f64 = 1.6;

/// Lightest body mass accepted, kg ([`crate::limits::MIN_BIRD_MASS_KG`]).
pub const MIN_MASS_KG: f64 = crate::limits::MIN_BIRD_MASS_KG;

/// A bird's size: what the power curve needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Morphology {
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Wingspan, m.
    pub span_m: f64,
    /// Wing area (both wings and the body between them), m².
    pub wing_area_m2: f64,
}

impl Morphology {
    /// The typical adult of `species` (see `docs/model.md` for the sources).
    pub fn of(species: Species) -> Morphology {
        match species {
            // Geese of the size filmed in line formations (white-fronted, pink-footed, greylag,
            // Canada): 2.3–3.6 kg for 1.4–1.7 m; aspect ratio about 8.
            Species::Goose => Morphology {
                mass_kg: 2.8,
                span_m: 1.5,
                wing_area_m2: 0.28,
            },
            // Common crane: about 5.5 kg, 2.2 m, aspect ratio about 8.
            Species::Crane => Morphology {
                mass_kg: 5.5,
                span_m: 2.2,
                wing_area_m2: 0.6,
            },
            // Great white pelican: about 9 kg, 2.9 m, aspect ratio about 7.
            Species::Pelican => Morphology {
                mass_kg: 9.0,
                span_m: 2.9,
                wing_area_m2: 1.2,
            },
        }
    }

    /// This bird scaled isometrically to a wingspan of `span_m` (mass ∝ b³, area ∝ b²).
    pub fn scaled_to(&self, span_m: f64) -> Morphology {
        let r = span_m / self.span_m;
        Morphology {
            mass_kg: self.mass_kg * r * r * r,
            span_m,
            wing_area_m2: self.wing_area_m2 * r * r,
        }
    }

    /// Aspect ratio b²/S.
    pub fn aspect_ratio(&self) -> f64 {
        self.span_m * self.span_m / self.wing_area_m2
    }

    /// Checks every field; the error names the option (`flight.mass_kg`, `flight.span_m`,
    /// `flight.wing_area_m2`).
    pub fn validate(&self) -> Result<()> {
        let check = |name: &str, v: f64, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::parameter(
                    name,
                    format!("{v}: the {what} must be a positive number"),
                ))
            }
        };
        crate::limits::check_bird_mass("flight.mass_kg", self.mass_kg)?;
        check("flight.span_m", self.span_m, "wingspan (m)")?;
        check("flight.wing_area_m2", self.wing_area_m2, "wing area (m²)")?;
        Ok(())
    }
}

/// The power curve of one bird in still air.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerCurve {
    /// The bird.
    pub bird: Morphology,
    /// Air density, kg/m³.
    pub air_density: f64,
}

/// The three parts of the mechanical power at one airspeed, W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerParts {
    /// Induced power.
    pub induced: f64,
    /// Parasite (body drag) power.
    pub parasite: f64,
    /// Profile (wing drag) power.
    pub profile: f64,
}

impl PowerParts {
    /// Total mechanical power, W.
    pub fn total(&self) -> f64 {
        self.induced + self.parasite + self.profile
    }
}

impl PowerCurve {
    /// The curve of `bird` at sea level.
    pub fn new(bird: Morphology) -> PowerCurve {
        PowerCurve {
            bird,
            air_density: SEA_LEVEL_DENSITY,
        }
    }

    /// Weight mg, N.
    fn weight(&self) -> f64 {
        self.bird.mass_kg * GRAVITY
    }

    /// Body frontal area S_b = 0.00813·m^0.666, m² (Pennycuick 2008, from frozen bodies).
    pub fn body_frontal_area(&self) -> f64 {
        0.00813 * self.bird.mass_kg.powf(0.666)
    }

    /// Disc area π b²/4, m².
    fn disc_area(&self) -> f64 {
        std::f64::consts::FRAC_PI_4 * self.bird.span_m * self.bird.span_m
    }

    /// Induced power at airspeed `v` (m/s), W.
    pub fn induced(&self, v: f64) -> f64 {
        let w = self.weight();
        INDUCED_FACTOR * w * w / (2.0 * self.air_density * v * self.disc_area())
    }

    /// Parasite power at airspeed `v` (m/s), W.
    pub fn parasite(&self, v: f64) -> f64 {
        0.5 * self.air_density * v * v * v * self.body_frontal_area() * BODY_DRAG_COEF
    }

    /// The minimum-power speed V_mp of P_ind + P_par, m/s (closed form: the root of its
    /// derivative, V⁴ = P_ind·V / (3·P_par/V³)).
    pub fn minimum_power_speed(&self) -> f64 {
        let a = self.induced(1.0); // P_ind = a / V
        let b = self.parasite(1.0); // P_par = b·V³
        (a / (3.0 * b)).powf(0.25)
    }

    /// The absolute minimum power P_am = (P_ind + P_par)(V_mp), W.
    pub fn absolute_minimum_power(&self) -> f64 {
        let v = self.minimum_power_speed();
        self.induced(v) + self.parasite(v)
    }

    /// Profile power ratio X₁ = 8.4 / AR.
    pub fn profile_ratio(&self) -> f64 {
        8.4 / self.bird.aspect_ratio()
    }

    /// The parts of the power at airspeed `v` (m/s).
    pub fn at(&self, v: f64) -> PowerParts {
        PowerParts {
            induced: self.induced(v),
            parasite: self.parasite(v),
            profile: self.profile_ratio() * self.absolute_minimum_power(),
        }
    }

    /// The share of the total mechanical power that is induced power at airspeed `v`: the factor
    /// from a saving of induced power to a saving of total power.
    pub fn induced_share(&self, v: f64) -> f64 {
        let p = self.at(v);
        p.induced / p.total()
    }

    /// Power-limited climb rate at airspeed `v` (m/s), m/s: the excess of the available power
    /// over the power needed for level flight, divided by the weight,
    /// ```math
    /// w = \frac{P_\text{avail} - P(v)}{m g}, \qquad P_\text{avail} = M \, P(V_\text{mp}),
    /// ```
    /// with M = `margin`, the ratio of the largest sustained power to the power at the
    /// minimum-power speed (M = [`CLIMB_POWER_MARGIN`] is our choice; docs/initiation.md). 0 when
    /// no power is left.
    pub fn climb_rate(&self, v: f64, margin: f64) -> f64 {
        let avail = margin * self.at(self.minimum_power_speed()).total();
        ((avail - self.at(v).total()) / self.weight()).max(0.0)
    }

    /// The best power-limited climb rate, m/s: [`PowerCurve::climb_rate`] at the minimum-power
    /// speed with the margin [`CLIMB_POWER_MARGIN`] (goose 0.76, crane 0.67, pelican 0.67 m/s for
    /// the presets' typical birds). The take-off's default climb after lift-off
    /// (docs/initiation.md).
    pub fn best_climb_rate(&self) -> f64 {
        self.climb_rate(self.minimum_power_speed(), CLIMB_POWER_MARGIN)
    }

    /// The minimum-power speed of the total curve (with profile power constant, the same as
    /// [`PowerCurve::minimum_power_speed`]).
    pub fn cruise_default(&self) -> f64 {
        self.minimum_power_speed()
    }
}

/// The power curve of an animation's birds: the species' typical bird (a goose when the file
/// names none or one the tool does not know), scaled to the animation's wingspan.
pub fn animation_curve(species: Option<&str>, wingspan_m: f64) -> PowerCurve {
    animation_curve_with(species, wingspan_m, None)
}

/// [`animation_curve`] with the animation's mass, when it gives one.
pub fn animation_curve_with(
    species: Option<&str>,
    wingspan_m: f64,
    mass_kg: Option<f64>,
) -> PowerCurve {
    let mut c = animation_curve_plain(species, wingspan_m);
    if let Some(m) = mass_kg.filter(|m| m.is_finite() && *m > 0.0) {
        c.bird.mass_kg = m;
    }
    c
}

/// The curve of an animation: its species, wingspan and mass (`flight.mass_kg`).
pub fn curve_of(anim: &Animation) -> PowerCurve {
    animation_curve_with(
        anim.species.as_deref(),
        anim.wingspan_m,
        anim.flight.and_then(|f| f.mass_kg),
    )
}

fn animation_curve_plain(species: Option<&str>, wingspan_m: f64) -> PowerCurve {
    let bird = match species.and_then(crate::animation::species::lookup) {
        Some(b) => b.morphology(),
        None => Morphology::of(
            species
                .and_then(|s| s.parse::<Species>().ok())
                .unwrap_or(Species::Goose),
        ),
    };
    // The species' own span is kept exactly (no rescaling round-off).
    let bird = if wingspan_m.is_finite() && wingspan_m > 0.0 && wingspan_m != bird.span_m {
        bird.scaled_to(wingspan_m)
    } else {
        bird
    };
    PowerCurve::new(bird)
}

/// The airspeed (m/s) a bird's saving of total power is evaluated at: its own speed in the
/// animation, or the minimum-power speed for a bird at rest (under 0.5 m/s) or without a speed.
pub fn airspeed_ms(curve: &PowerCurve, speed_wingspans: f64, wingspan_m: f64) -> f64 {
    let v = speed_wingspans * wingspan_m;
    if v.is_finite() && v > 0.5 {
        v
    } else {
        curve.minimum_power_speed()
    }
}

/// Each bird's saving as a fraction of its total mechanical power at frame `k` (`None` when the
/// frame has no savings).
pub fn frame_savings_total(anim: &Animation, curve: &PowerCurve, k: usize) -> Option<Vec<f64>> {
    let f = anim.frames.get(k)?;
    let e = f.e.as_ref()?;
    Some(
        e.iter()
            .enumerate()
            .map(|(b, e)| {
                let v = match anim.flight.and_then(|f| f.speed_ms) {
                    Some(v) => v,
                    None => airspeed_ms(
                        curve,
                        f.speed.get(b).copied().unwrap_or(f64::NAN),
                        anim.wingspan_m,
                    ),
                };
                e * curve.induced_share(v)
            })
            .collect(),
    )
}

/// The flock's mean saving of total power over the steady flight (`None` without a steady stage
/// or savings), with the animation's own curve ([`animation_curve`]).
pub fn steady_saving_total(anim: &Animation) -> Option<f64> {
    let st = anim.stage("steady")?;
    let curve = curve_of(anim);
    let (mut sum, mut n) = (0.0, 0usize);
    for k in st.start..st.end.min(anim.frames.len()) {
        if let Some(t) = frame_savings_total(anim, &curve, k) {
            if !t.is_empty() {
                sum += t.iter().sum::<f64>() / t.len() as f64;
                n += 1;
            }
        }
    }
    (n > 0).then(|| sum / n as f64)
}

/// Checks an animation's flight settings; errors name `steady.flight.mass_kg` or
/// `steady.flight.speed_ms`.
pub fn validate_settings(s: &crate::animation::FlightSettings) -> Result<()> {
    s.validate("steady.flight")
}

/// Checks an airspeed given on the command line or in options (`flight.speed_ms`).
pub fn validate_speed(v: f64) -> Result<()> {
    crate::limits::check_airspeed("flight.speed_ms", v)
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_power_limited_climb_is_slow_for_large_birds_and_zero_without_a_margin() {
        for (sp, lo, hi) in [
            (Species::Goose, 0.5, 1.2),
            (Species::Crane, 0.5, 1.5),
            (Species::Pelican, 0.3, 1.5),
        ] {
            let c = PowerCurve::new(Morphology::of(sp));
            let v = c.minimum_power_speed();
            let w = c.climb_rate(v, CLIMB_POWER_MARGIN);
            assert!((lo..hi).contains(&w), "{sp:?}: {w} m/s");
            // Faster or slower than V_mp climbs less; no margin, no climb.
            assert!(c.climb_rate(1.5 * v, CLIMB_POWER_MARGIN) < w);
            assert!(c.climb_rate(0.6 * v, CLIMB_POWER_MARGIN) < w);
            assert_eq!(c.climb_rate(v, 1.0), 0.0);
        }
    }

    use super::*;

    #[test]
    fn minimum_power_speed_is_the_minimum_of_the_curve() {
        for sp in Species::ALL {
            let c = PowerCurve::new(Morphology::of(sp));
            let vmp = c.minimum_power_speed();
            let p = |v: f64| c.at(v).total();
            // A fine scan finds no lower power than at V_mp.
            let mut best = (f64::MAX, 0.0);
            for i in 1..4000 {
                let v = i as f64 * 0.01;
                if p(v) < best.0 {
                    best = (p(v), v);
                }
            }
            assert!((best.1 - vmp).abs() < 0.011, "{sp}: {} vs {vmp}", best.1);
            assert!(p(vmp) <= best.0 + 1e-9);
            // Pennycuick's printed closed forms: V_mp = 0.807 k^¼ m^½ g^½ / (ρ^½ b^½ S_b^¼ C_Db^¼)
            // and P_am = 1.05 k^¾ m^{3/2} g^{3/2} S_b^¼ C_Db^¼ / (ρ^½ b^{3/2}).
            let (m, b, rho) = (c.bird.mass_kg, c.bird.span_m, c.air_density);
            let sb_cd = (c.body_frontal_area() * BODY_DRAG_COEF).powf(0.25);
            let v_printed = 0.807 * INDUCED_FACTOR.powf(0.25) * (m * GRAVITY).sqrt()
                / (rho.sqrt() * b.sqrt() * sb_cd);
            let p_printed = 1.05 * INDUCED_FACTOR.powf(0.75) * (m * GRAVITY).powf(1.5) * sb_cd
                / (rho.sqrt() * b.powf(1.5));
            assert!((vmp / v_printed - 1.0).abs() < 1e-3, "{sp}");
            assert!(
                (c.absolute_minimum_power() / p_printed - 1.0).abs() < 2e-3,
                "{sp}"
            );
        }
    }

    #[test]
    fn induced_power_dominates_slow_flight_and_fades_with_speed() {
        let c = PowerCurve::new(Morphology::of(Species::Goose));
        let vmp = c.minimum_power_speed();
        // At V_mp induced power is three times parasite power (dP/dV = 0).
        let p = c.at(vmp);
        assert!((p.induced / p.parasite - 3.0).abs() < 1e-9);
        let mut last = 1.0;
        for i in 1..30 {
            let s = c.induced_share(i as f64);
            assert!(s < last && s > 0.0);
            last = s;
        }
        // A goose at its minimum-power speed: induced power is three quarters of P_am and profile
        // power about as much again (X₁ ≈ 1 at aspect ratio 8), so about 37 % of the total.
        let s = c.induced_share(vmp);
        assert!((0.3..0.45).contains(&s), "{s}");
    }

    #[test]
    fn scaling_and_validation() {
        let g = Morphology::of(Species::Goose);
        let big = g.scaled_to(3.0);
        assert!((big.mass_kg / g.mass_kg - 8.0).abs() < 1e-12);
        assert!((big.aspect_ratio() - g.aspect_ratio()).abs() < 1e-12);
        for bad in [0.0, -1.0, f64::NAN, 200.0, 1e-200, 1e-300, 1e300, 0.001] {
            let m = Morphology { mass_kg: bad, ..g };
            assert!(m.validate().unwrap_err().to_string().contains("mass"));
        }
        assert!(validate_speed(-3.0).is_err() && validate_speed(12.0).is_ok());
    }
}
