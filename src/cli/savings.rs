//! How the summaries state a flock's saving: the range over the modelling choices first, called
//! a model estimate, beside field figures of the same kind (induced beside induced, total beside
//! total), then the chosen model's value.

use formation::aero::AeroOptions;
use formation::animation::Animation;

/// Field figures of savings of induced power: models applied to measured spacings (Cutts &
/// Speakman 1994, Speakman & Banks 1998, Hainsworth 1987).
const FIELD_INDUCED: &str = "field: models at measured spacings 14–36 %";
/// Field figures of savings of total power: models at measured spacings (2.4 % "might be as
/// low as", 5–9 %), pelicans' wake share 1.7–3.4 %, a flapping-wing follower about 11 %.
const FIELD_TOTAL: &str = "field and flapping studies 2–11 %";

/// The one line that explains per-bird values above 1.
pub const E_ABOVE_ONE: &str = "e > 1: the rigid, flat, inviscid wake lets the upwash of several birds ahead exceed a bird's own downwash; a real wake rolls up, sinks and decays, so read it as the model's upper bound, not a bird flying for free";

/// "hummel, planar wake, core 0.04".
pub fn label(o: &AeroOptions) -> String {
    if o.model.is_hummel() {
        format!(
            "{}, {} wake, core {}",
            o.model.name(),
            o.wake.name(),
            o.core_radius
        )
    } else {
        format!("{}, {} wake", o.model.name(), o.wake.name())
    }
}

/// The leading statement: `lo`–`hi` of induced power over the band, the same times `share` of
/// total, what a flapping wake gives of it, then the chosen model's `point`.
pub fn range_line(lo: f64, hi: f64, share: f64, point: f64, chosen: &str) -> String {
    let flapping = formation::aero::flapping::flapping_note();
    format!(
        "flock saving, a model estimate: {:.1}–{:.1} % of induced power ({FIELD_INDUCED}), {:.1}–{:.1} % of total power ({FIELD_TOTAL}) over models, wakes and cores; {flapping}; by {chosen}: {:.1} % of induced, {:.1} % of total power",
        100.0 * lo,
        100.0 * hi,
        100.0 * lo * share,
        100.0 * hi * share,
        100.0 * point,
        100.0 * point * share
    )
}

/// An animation's steady saving stated with its range (`None` without a steady saving).
pub fn animation_line(anim: &Animation, point: f64) -> Option<String> {
    let total = formation::aero::flight::steady_saving_total(anim)?;
    let share = if point.abs() > 1e-12 {
        total / point
    } else {
        0.0
    };
    let band = formation::report::animation_band(anim);
    let (lo, hi) = band
        .iter()
        .map(|b| b.saving)
        .fold((point, point), |(l, h), v| (l.min(v), h.max(v)));
    let chosen = anim
        .savings_model
        .as_ref()
        .map(AeroOptions::from_record)
        .map_or("Hummel's model".to_string(), |o| label(&o));
    let mut line = range_line(lo, hi, share, point, &chosen).replacen(
        "flock saving,",
        "flock saving in steady flight,",
        1,
    );
    // Per-bird values above 1 in the steady flight.
    if let Some(st) = anim.stage("steady") {
        let (mut above, mut all) = (0usize, 0usize);
        for f in &anim.frames[st.start..st.end.min(anim.frames.len())] {
            if let Some(e) = &f.e {
                above += e.iter().filter(|&&v| v > 1.0).count();
                all += e.len();
            }
        }
        if above > 0 {
            line.push_str(&format!(
                "; {:.1} % of steady bird-frames have e > 1 ({E_ABOVE_ONE})",
                100.0 * above as f64 / all.max(1) as f64
            ));
        }
    }
    Some(line)
}

/// A real species given to `animate` or `steady` sets the flock's wingspan and cruise speed
/// (wingspans per second from its cruise airspeed) where `--wingspan-m` and `--speed` were left
/// at their defaults.
pub fn apply_species(steady: &mut formation::keyshape::SteadyOptions, species: &str) {
    let Some(b) = formation::aero::species::lookup(species) else {
        return;
    };
    let d = formation::keyshape::SteadyOptions::default();
    if steady.wingspan_m == d.wingspan_m && steady.speed == d.speed {
        steady.wingspan_m = b.span_m;
        steady.speed = b.cruise_wingspans_s();
    }
}
