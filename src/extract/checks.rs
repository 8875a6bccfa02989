//! Warnings instead of silent wrong answers: suspicious annotations that extract
//! without error but probably do not say what the user meant.
//!
//! Takes the [`Annotations`], the extracted [`FormationParams`] and each frame's model-selection
//! scores, and gives [`Warning`]s whose messages name the option that fixes the input by its
//! path (`read.heading`, `read.y_origin`, `read.wingspan_px`); the command line shows its flags.
//!
//! - **Opens forward**: the birds with pixel y mirrored (a y axis pointing the other way) or
//!   with the flight direction reversed (a flock flying the other way) fit a formation far
//!   better than as given: the criterion S of the module [`super`] drops by more than ln n
//!   (the price of one parameter) in most frames (at most [`MAX_CHECKED_FRAMES`], evenly spaced, are refitted).
//!   Typical sign: the leader at a wingtip and the other birds ahead of its arms.
//! - **Heading**: the same with the flight direction turned 90° either way; and, when many birds
//!   of most frames are off the fitted shape ([`MOSTLY_OUTLIERS`]), the flight direction that
//!   fits best is searched in steps of [`AXIS_STEP_DEG`] (then 5°) over at most
//!   [`AXIS_CHECKED_FRAMES`] frames: a turn of at least [`AXIS_MIN_TURN_DEG`] that fits far better
//!   in most of them is named with the heading to give; otherwise the warning says that the
//!   shape leaves most birds out and what to check.
//! - **Scale**: the median distance from a bird to its nearest neighbour is outside
//!   [`PLAUSIBLE_NEIGHBOUR`] wingspans (real formations keep about 0.8–2.5, see
//!   `docs/formats.md`); the wingspan in pixels is probably wrong.
//! - **Few frames**: fewer than [`MIN_FRAMES`] annotated frames: μ and σ of the spacing are
//!   learnt across frames.
//! - **Three birds**: frames of 3 birds fit a V and a parabola exactly; they are taken as a V.

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::params::FormationParams;
use super::{ExtractOptions, FrameReport};
use crate::annotations::{AnnotatedFrame, Annotations, Format};

/// Most frames the orientation checks refit (evenly spaced): each costs three more fits, and
/// a majority over 30 frames is as clear as over 1000.
pub const MAX_CHECKED_FRAMES: usize = 30;

/// A frame is suspicious when more than this fraction of its birds are off the fitted shape (a
/// real formation with a few stragglers stays well below; a wrong flight direction leaves about
/// half of a V out).
pub const MOSTLY_OUTLIERS: f64 = 0.4;

/// Step of the search for the flight direction that fits, degrees.
pub const AXIS_STEP_DEG: f64 = 15.0;

/// Smallest turn of the flight direction that the search reports, degrees (smaller ones are
/// within what the fit absorbs).
pub const AXIS_MIN_TURN_DEG: f64 = 10.0;

/// Most frames the flight-direction search refits (evenly spaced): each costs 26 fits.
pub const AXIS_CHECKED_FRAMES: usize = 6;

/// Fewest annotated frames without a warning.
pub const MIN_FRAMES: usize = 3;

/// Median nearest-neighbour distance outside which the scale is suspicious, wingspans.
pub const PLAUSIBLE_NEIGHBOUR: (f64, f64) = (0.4, 5.0);

/// A typical nearest-neighbour distance in real line formations, wingspans (field data: about
/// 0.8 lateral and 0.5–1.2 behind, so 1–1.5 apart); used to suggest a scale.
pub const TYPICAL_NEIGHBOUR: f64 = 1.2;

/// What kind of suspicion a [`Warning`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// The formation opens forward (y axis or heading reversed).
    OpensForward,
    /// The formation fits far better with the heading turned 90°.
    Heading,
    /// Birds implausibly close or far for the given wingspan in pixels.
    Scale,
    /// Fewer than [`MIN_FRAMES`] frames.
    FewFrames,
    /// Frames of exactly 3 birds (V and U indistinguishable).
    ThreeBirds,
    /// Frames unlike the others (gaps, scatter or birds off the shape), left out of the spacing.
    OddFrame,
}

/// One warning: its kind and a one-line message naming the option that fixes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// What kind of suspicion.
    pub kind: WarningKind,
    /// One line: the file, what looks wrong, the likely cause, the option that fixes it.
    pub message: String,
}

/// `deg` as the annotation format writes it: `up`, `right`, `down`, `left` or degrees.
pub fn heading_word(deg: f64) -> String {
    let d = deg.rem_euclid(360.0);
    let d = if (d - 360.0).abs() < 1e-9 { 0.0 } else { d };
    match d {
        d if d.abs() < 1e-9 => "up".into(),
        d if (d - 90.0).abs() < 1e-9 => "right".into(),
        d if (d - 180.0).abs() < 1e-9 => "down".into(),
        d if (d - 270.0).abs() < 1e-9 => "left".into(),
        d => format!("{}", (d * 1000.0).round() / 1000.0),
    }
}

/// Formation-frame points (leader at the origin, sorted by x) of `f`'s birds with the image
/// mirrored front to back (`mirror`) and the flight direction turned by `turn_deg`.
fn reoriented(f: &AnnotatedFrame, mirror: bool, turn_deg: f64) -> Vec<(f64, f64)> {
    let th = f.heading_deg.to_radians();
    let (d, r) = ((th.sin(), -th.cos()), (th.cos(), th.sin()));
    let th2 = (f.heading_deg + turn_deg).to_radians();
    let (d2, r2) = ((th2.sin(), -th2.cos()), (th2.cos(), th2.sin()));
    let moved: Vec<(f64, f64)> = f
        .birds
        .iter()
        .map(|b| {
            // Back to the image (wingspans, y down), mirrored, then into the new frame.
            let px = b.lateral * r.0 + b.forward * d.0;
            let mut py = b.lateral * r.1 + b.forward * d.1;
            if mirror {
                py = -py;
            }
            (px * r2.0 + py * r2.1, px * d2.0 + py * d2.1)
        })
        .collect();
    let lead = (0..moved.len())
        .max_by(|&a, &b| moved[a].1.total_cmp(&moved[b].1).then(b.cmp(&a)))
        .unwrap_or(0);
    let (l0, f0) = moved[lead];
    let mut pts: Vec<(f64, f64)> = moved.iter().map(|&(l, fw)| (l - l0, f0 - fw)).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts
}

fn best_score(r: &FrameReport) -> Option<f64> {
    r.scores.iter().map(|s| s.1).min_by(f64::total_cmp)
}

/// Every warning about `ann` and what was extracted from it. `rng` draws the RANSAC samples of
/// the reoriented fits (the extraction's own stream, after the extraction).
pub fn check(
    ann: &Annotations,
    params: &FormationParams,
    reports: &[FrameReport],
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> Vec<Warning> {
    let path = ann.path.display();
    let n = ann.frames.len();
    let mut out = Vec::new();
    // Orientation: pixel y mirrored, the flight direction reversed, turned +90°, turned −90°.
    let alternatives = [(true, 0.0), (false, 180.0), (false, 90.0), (false, -90.0)];
    let mut wins = [0usize; 4];
    let step = n.div_ceil(MAX_CHECKED_FRAMES).max(1);
    let checked = n.div_ceil(step);
    if opts.kind.is_none() {
        for (f, r) in ann.frames.iter().zip(reports).step_by(step) {
            let Some(s0) = best_score(r) else { continue };
            let margin = (f.birds.len() as f64).ln();
            for (k, &(mirror, turn)) in alternatives.iter().enumerate() {
                let pts = reoriented(f, mirror, turn);
                let alt = super::choose_model(&pts, opts, rng)
                    .and_then(|(_, s)| s.iter().map(|s| s.1).min_by(f64::total_cmp));
                if alt.is_some_and(|a| a < s0 - margin) {
                    wins[k] += 1;
                }
            }
        }
    }
    let heading = ann.frames.first().map_or(0.0, |f| f.heading_deg);
    let of = if checked == n {
        format!("{n}")
    } else {
        format!("{checked} checked (of {n})")
    };
    let (mirrored, reversed) = (wins[0], wins[1]);
    let turned = wins[2].max(wins[3]);
    let forward = mirrored.max(reversed);
    if 2 * forward > checked && forward >= turned {
        let csv = matches!(ann.format, Format::LongCsv | Format::Dltdv);
        let back = heading_word(heading + 180.0);
        let origin = if ann.y_up { "top" } else { "bottom" };
        let grows = if ann.y_up { "downward" } else { "upward" };
        // CSV: the y origin is the likely cause unless only reversing the flight explains it.
        let fix = match (csv, reversed > mirrored, reversed >= mirrored) {
            (true, false, _) => format!(
                "pixel y probably grows {grows}; give read.y_origin {origin} (or read.heading {back} if the flock flies the other way)"
            ),
            (true, true, _) => format!(
                "the flock probably flies the other way; give read.heading {back} (or read.y_origin {origin} if pixel y grows {grows})"
            ),
            (false, _, true) => format!(
                "the flock probably flies the other way, or pixel y grows upward; give read.heading {back}"
            ),
            (false, _, false) => format!(
                "pixel y probably grows upward; give read.heading {} (left and right are then swapped)",
                heading_word(180.0 - heading)
            ),
        };
        out.push(Warning {
            kind: WarningKind::OpensForward,
            message: format!(
                "{path}: the formation opens forward in {forward} of {of} frames (birds ahead of the leader's arms): {fix}"
            ),
        });
    } else if 2 * turned > checked {
        let turn = if wins[2] >= wins[3] { 90.0 } else { -90.0 };
        out.push(Warning {
            kind: WarningKind::Heading,
            message: format!(
                "{path}: the birds fit a line formation far better with the flight direction turned {turn:+}° in {turned} of {of} frames: the heading ({}) is probably wrong; give read.heading {}",
                heading_word(heading),
                heading_word(heading + turn)
            ),
        });
    }
    if out.is_empty() {
        out.extend(axis_check(ann, params, reports, opts, rng));
    }
    // Scale: median nearest-neighbour distance over every bird of every frame.
    let mut nn: Vec<f64> = Vec::new();
    for f in &params.frames {
        for p in &f.positions {
            let d = f
                .positions
                .iter()
                .filter(|q| q.id != p.id)
                .map(|q| (q.x - p.x).hypot(q.y - p.y))
                .fold(f64::INFINITY, f64::min);
            if d.is_finite() {
                nn.push(d);
            }
        }
    }
    if let Some(med) = super::geometry::Stat::of(&nn).map(|s| s.median) {
        let (lo, hi) = PLAUSIBLE_NEIGHBOUR;
        if med < lo || med > hi {
            let px = ann.frames.first().map_or(1.0, |f| f.wingspan_px);
            out.push(Warning {
                kind: WarningKind::Scale,
                message: format!(
                    "{path}: birds are {med:.2} wingspans from their nearest neighbour (median), real formations keep about 0.8–2.5: is the scale right? A wingspan is {px} px; if the birds are about {TYPICAL_NEIGHBOUR} wingspans apart, give read.wingspan_px {:.0}",
                    px * med / TYPICAL_NEIGHBOUR
                ),
            });
        }
    }
    if n < MIN_FRAMES {
        out.push(Warning {
            kind: WarningKind::FewFrames,
            message: format!(
                "{path}: only {n} annotated frame{}; the spacing statistics are learnt across frames, annotate 10–30 frames for a steady flight that varies like the footage",
                if n == 1 { "" } else { "s" }
            ),
        });
    }
    let odd = super::screen::odd_frames(params);
    if !odd.is_empty() {
        let list: Vec<String> = odd
            .iter()
            .map(|o| format!("frame {} ({})", o.index, o.reason))
            .collect();
        out.push(Warning {
            kind: WarningKind::OddFrame,
            message: format!(
                "{path}: {} unlike the others: {}; the steady flight leaves {} out of the spacing it draws from; check {} marks (missing, swapped or extra birds) or remove {}",
                if odd.len() == 1 { "one frame is".to_string() } else { format!("{} frames are", odd.len()) },
                list.join(", "),
                if odd.len() == 1 { "it" } else { "them" },
                if odd.len() == 1 { "its" } else { "their" },
                if odd.len() == 1 { "it" } else { "them" },
            ),
        });
    }
    let three = params.frames.iter().filter(|f| f.order.len() == 3).count();
    if three > 0 && opts.kind.is_none() {
        out.push(Warning {
            kind: WarningKind::ThreeBirds,
            message: format!(
                "{path}: {three} of {n} frames mark only 3 birds, which a V and a U both fit exactly; they are taken as a V (give extract.kind to choose)"
            ),
        });
    }
    out
}

/// The warning when most birds of most frames are off the fitted shape: the flight direction
/// that fits best (searched over whole turns), or what else to check.
fn axis_check(
    ann: &Annotations,
    params: &FormationParams,
    reports: &[FrameReport],
    opts: &ExtractOptions,
    rng: &mut impl Rng,
) -> Option<Warning> {
    let n = params.frames.len();
    let mostly = params
        .frames
        .iter()
        .filter(|f| f.outliers.len() as f64 > MOSTLY_OUTLIERS * f.order.len() as f64)
        .count();
    if n == 0 || 2 * mostly <= n {
        return None;
    }
    let marks: usize = params.frames.iter().map(|f| f.outliers.len()).sum();
    let all: usize = params.frames.iter().map(|f| f.order.len()).sum();
    let path = ann.path.display();
    let heading = ann.frames.first().map_or(0.0, |f| f.heading_deg);
    let step = ann.frames.len().div_ceil(AXIS_CHECKED_FRAMES).max(1);
    let frames: Vec<(&AnnotatedFrame, f64)> = ann
        .frames
        .iter()
        .zip(reports)
        .step_by(step)
        .filter_map(|(f, r)| best_score(r).map(|s| (f, s)))
        .collect();
    // (wins, total improvement) of turning the flight direction by `turn`.
    let mut score_of = |turn: f64| -> (usize, f64) {
        let mut wins = 0;
        let mut gain = 0.0;
        for &(f, s0) in &frames {
            let pts = reoriented(f, false, turn);
            let alt = super::choose_model(&pts, opts, rng)
                .and_then(|(_, s)| s.iter().map(|s| s.1).min_by(f64::total_cmp));
            if let Some(a) = alt {
                if a < s0 - (f.birds.len() as f64).ln() {
                    wins += 1;
                }
                gain += s0 - a;
            }
        }
        (wins, gain)
    };
    let better = |a: (usize, f64), b: (usize, f64)| a.0 > b.0 || (a.0 == b.0 && a.1 > b.1);
    let mut best: Option<(f64, (usize, f64))> = None;
    let steps = (360.0 / AXIS_STEP_DEG).round() as usize;
    for k in 1..steps {
        let turn = k as f64 * AXIS_STEP_DEG;
        let sc = score_of(turn);
        if best.map_or(true, |(_, b)| better(sc, b)) {
            best = Some((turn, sc));
        }
    }
    if let Some((coarse, _)) = best {
        for d in [-10.0, -5.0, 5.0, 10.0] {
            let turn = coarse + d;
            let sc = score_of(turn);
            if best.map_or(true, |(_, b)| better(sc, b)) {
                best = Some((turn, sc));
            }
        }
    }
    let lead = format!(
        "{path}: {marks} of {all} marks are off the fitted shape (more than {:.0} % of the birds in {mostly} of {n} frames)",
        100.0 * MOSTLY_OUTLIERS
    );
    let signed = |t: f64| {
        let t = t.rem_euclid(360.0);
        if t > 180.0 {
            t - 360.0
        } else {
            t
        }
    };
    let message = match best {
        Some((turn, (wins, _)))
            if 2 * wins > frames.len() && signed(turn).abs() >= AXIS_MIN_TURN_DEG =>
        {
            format!(
                "{lead}, and they fit far better with the flight direction turned {:+}° in {wins} of {} frames checked: the heading ({}) is probably wrong; give read.heading {}",
                signed(turn),
                frames.len(),
                heading_word(heading),
                heading_word(heading + turn)
            )
        }
        _ => format!(
            "{lead}: check the heading (read.heading), the scale (read.wingspan_px), and whether the frames hold one formation"
        ),
    };
    Some(Warning {
        kind: WarningKind::Heading,
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_are_written_as_the_format_does() {
        assert_eq!(heading_word(180.0), "down");
        assert_eq!(heading_word(-90.0), "left");
        assert_eq!(heading_word(450.0), "right");
        assert_eq!(heading_word(360.0), "up");
        assert_eq!(heading_word(300.0 + 90.0), "30");
    }
}
