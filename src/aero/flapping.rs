//! The flapping check: how much of a rigid wake's saving a flapping-wing computation keeps.
//!
//! `scripts/flapping_check.py` ran an unsteady vortex-lattice solver (Ptera Software) on
//! goose-like wings in 2- and 3-bird formations at the field's offsets, once with rigid wings
//! and once flapping, and stored the follower's saving in `tests/data/flapping_check.json`.
//! That file is compiled in here, so the ratio the summaries print ("a flapping wake gives about
//! X of this") is the stored one and is typed nowhere else; `tests/flapping_check.rs` checks the
//! file against the tool's own models and docs/model.md. See docs/model.md, "A flapping check".

use serde::Deserialize;
use std::sync::OnceLock;

/// The stored output of `scripts/flapping_check.py`.
pub const FLAPPING_CHECK_JSON: &str = include_str!("../../tests/data/flapping_check.json");

/// One bird of one run: cycle-averaged inviscid power and lift, and its saving against the
/// same wing alone.
#[derive(Debug, Clone, Deserialize)]
pub struct RunBird {
    /// Cycle-averaged inviscid mechanical power, W.
    pub power_w: f64,
    /// Cycle-averaged lift, N.
    pub lift_n: f64,
    /// Saving at equal lift, a fraction of the lone wing's inviscid power.
    pub saving: f64,
    /// The same in watts.
    pub saved_w: f64,
    /// Saving at the same incidence (no correction for the extra lift).
    pub saving_same_incidence: f64,
}

/// One run (rigid or flapping) of one formation.
#[derive(Debug, Clone, Deserialize)]
pub struct Run {
    /// The birds, leader first; positions in wingspans (lateral, behind, above).
    pub positions: Vec<[f64; 3]>,
    /// Each bird's result.
    pub birds: Vec<RunBird>,
}

/// One formation: every follower at the same offset from the bird ahead.
#[derive(Debug, Clone, Deserialize)]
pub struct Case {
    /// Where the offset comes from.
    pub offset: String,
    /// Lateral distance between body centres, wingspans.
    pub lateral: f64,
    /// Distance behind the bird ahead, wingspans.
    pub behind: f64,
    /// Height above the bird ahead, wingspans.
    pub above: f64,
    /// Number of birds (leader included).
    pub birds: usize,
    /// Rigid wings (a steady wake).
    pub rigid: Run,
    /// Flapping wings.
    pub flapping: Run,
    /// The last follower's flapping saving over its rigid saving (fractions of each wing's own
    /// inviscid power).
    pub ratio: f64,
    /// The same in watts saved.
    pub ratio_watts: f64,
}

/// The whole stored check.
#[derive(Debug, Clone, Deserialize)]
pub struct FlappingCheck {
    /// The solver's package version the numbers were made with.
    pub package_version: String,
    /// The formations.
    pub cases: Vec<Case>,
    /// Median of `ratio` over the 2-bird formations.
    pub ratio_median: f64,
    /// Lowest and highest `ratio` over the 2-bird formations.
    pub ratio_range: [f64; 2],
}

/// The stored check, parsed once (`None` only if the compiled-in file were malformed, which
/// `tests/flapping_check.rs` rules out).
pub fn flapping_check() -> Option<&'static FlappingCheck> {
    static CHECK: OnceLock<Option<FlappingCheck>> = OnceLock::new();
    CHECK
        .get_or_init(|| serde_json::from_str(FLAPPING_CHECK_JSON).ok())
        .as_ref()
}

/// The phrase the summaries put beside the saving range: "a flapping wake gives about 0.73×
/// this (0.60–0.90× at the field's offsets)" (the stored median and range of `ratio`).
pub fn flapping_note() -> String {
    match flapping_check() {
        Some(c) => format!(
            "a flapping wake gives about {:.2}× this ({:.2}–{:.2}× at the field's offsets)",
            c.ratio_median, c.ratio_range[0], c.ratio_range[1]
        ),
        None => String::new(),
    }
}
