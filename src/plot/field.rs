//! Published measurements of real line formations that the charts and `formation report` draw
//! beside the tool's numbers (from the review of Bajec & Heppner 2009, the table of Seiler, Pant
//! & Hedrick 2002, and a stereo-filmed wild V of greater white-fronted geese; see
//! `docs/formats.md` for the sources). Ranges are what the studies report, not confidence
//! intervals of one population.

/// One study's value or range of one quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldRange {
    /// Who measured it.
    pub source: &'static str,
    /// Which birds, how many.
    pub species: &'static str,
    /// Lower end (units of the table it is in).
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

const fn r(source: &'static str, species: &'static str, lo: f64, hi: f64) -> FieldRange {
    FieldRange {
        source,
        species,
        lo,
        hi,
    }
}

/// Induced-power saving of the flock in formation flight, fraction (the same quantity as the
/// tool's mean `e`): model estimates, not measurements. Each study measured wingtip spacings and
/// turned them into a saving with a lifting-line model (Hainsworth 1987 used Lissaman &
/// Shollenberger's).
pub const FLOCK_SAVING: &[FieldRange] = &[
    r(
        "Cutts & Speakman 1994",
        "pink-footed goose, 54 skeins",
        0.14,
        0.14,
    ),
    r(
        "Speakman & Banks 1998",
        "greylag goose, 25 formations",
        0.27,
        0.27,
    ),
    r("Hainsworth 1987", "Canada goose, 8 formations", 0.36, 0.36),
];

/// The span of [`FLOCK_SAVING`]: 14–36 %.
pub const FLOCK_SAVING_SPAN: (f64, f64) = (0.14, 0.36);

/// V apex angle, degrees.
pub const APEX_ANGLE: &[FieldRange] = &[
    r(
        "Gould & Heppner 1974",
        "Canada goose, 5 flocks (34 ± 6°)",
        28.0,
        40.0,
    ),
    r(
        "stereo-filmed wild V",
        "greater white-fronted goose, 15 birds",
        50.0,
        73.0,
    ),
    r(
        "O'Malley & Evans 1982",
        "white pelican, 12 Vs (67 ± 8°)",
        59.0,
        75.0,
    ),
    r("Williams et al. 1976", "Canada goose (radar)", 38.0, 124.0),
];

/// Wingtip spacing, metres (negative: wingtips overlap).
pub const WINGTIP_SPACING_M: &[FieldRange] = &[
    r("Hainsworth 1987", "Canada goose, 55 birds", -1.71, 1.83),
    r("Cutts & Speakman 1994", "pink-footed goose", -0.90, 1.89),
    r("Speakman & Banks 1998", "greylag goose", -1.00, 1.60),
    r("Hainsworth 1988", "brown pelican", -1.30, 2.89),
];

/// Nearest bird ahead, wingspans: lateral and behind (median, with quartiles), from the
/// stereo-filmed wild V; and the godwit V of Corcoran & Hedrick 2019 (modal offset).
pub const NEIGHBOUR_AHEAD: &[(&str, f64, f64)] = &[
    ("stereo-filmed wild V, geese (median)", 0.77, 1.24),
    ("Corcoran & Hedrick 2019, godwits (mode)", 0.8, 0.5),
];
