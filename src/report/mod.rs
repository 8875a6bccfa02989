//! `formation report INPUT -o report.html`: one self-contained HTML page about
//! annotations (extracted on the fly), a params file or an animation: the extracted parameters
//! per frame with fit charts, the savings per bird and per position, the take-off statistics and
//! the comparison with field studies of real formations.
//!
//! Takes [`FormationParams`] and/or an [`Animation`]; gives the page's text. Every chart is an
//! inline SVG drawn by [`crate::plot`] (no image files, no scripts or fonts fetched from anywhere),
//! inside `<figure class="chart" data-chart="NAME">`. A few lines of inline script count the
//! charts that rendered and set `data-charts-rendered` on `<body>` beside `data-charts`, so a
//! headless browser can check the page (CI does).

mod html;

use std::path::Path;

use crate::aero::AeroOptions;
use crate::animation::stats::{AnimationStats, BirdStats};
use crate::animation::Animation;
use crate::error::Result;
use crate::extract::FormationParams;

pub use html::Page;

/// What a report is about.
#[derive(Debug, Clone, Copy)]
pub struct Subject<'a> {
    /// The input file, named in the title.
    pub origin: &'a Path,
    /// Formation parameters (read, or extracted from annotations).
    pub params: Option<&'a FormationParams>,
    /// The inlier threshold the parameters were extracted with, when known (wingspans).
    pub threshold: Option<f64>,
    /// An animation.
    pub animation: Option<&'a Animation>,
    /// The savings model of the footage's savings (default: Hummel's, planar, default core).
    /// An animation's savings are its own (recompute them with
    /// [`crate::aero::recompute_frame_savings`] first to change the model).
    pub aero: Option<AeroOptions>,
}

/// Core radii of the saving's sensitivity band, wingspans (as `formation power`'s).
pub const BAND_CORES: [f64; 5] = [0.02, 0.04, 0.08, 0.16, 0.32];

/// Largest number of frames of an animation the band is evaluated on (evenly spaced over the
/// steady flight): the lifting-line model costs about 20 µs per pair.
pub const BAND_FRAMES: usize = 24;

/// Flocks of more birds leave the lifting-line model out of an animation's band (its pairs cost
/// about 20 µs each: a 60-bird band takes a few seconds).
pub const BAND_LIFTING_LINE_BIRDS: usize = 60;

/// Flocks of more birds get no band at all: each of its options sums over every pair of birds
/// (a 100 000-bird sky took minutes), and the main saving, computed once, stands alone.
pub const BAND_MAX_BIRDS: usize = 2000;

/// One entry of the saving's sensitivity band: a model, wake and core, and the flock's mean
/// saving (fraction of induced power) with them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandEntry {
    /// The options.
    pub aero: AeroOptions,
    /// The flock's saving.
    pub saving: f64,
}

impl BandEntry {
    /// "hummel, planar, core 0.04" or "lissaman, 3d".
    pub fn label(&self) -> String {
        if self.aero.model.is_hummel() {
            format!(
                "{}, {}, core {}",
                self.aero.model.name(),
                self.aero.wake.name(),
                self.aero.core_radius
            )
        } else {
            format!("{}, {}", self.aero.model.name(), self.aero.wake.name())
        }
    }
}

/// The options of the band: Hummel's model at every core of [`BAND_CORES`] and the lifting-line
/// model, each with the planar wake and, when `heights`, the 3-D wake.
pub fn band_options(heights: bool) -> Vec<AeroOptions> {
    use crate::aero::{AeroModel, Wake};
    let wakes: &[Wake] = if heights {
        &[Wake::Planar, Wake::ThreeD]
    } else {
        &[Wake::Planar]
    };
    let mut out = Vec::new();
    for &wake in wakes {
        for core_radius in BAND_CORES {
            out.push(AeroOptions {
                core_radius,
                wake,
                ..AeroOptions::default()
            });
        }
        out.push(AeroOptions {
            wake,
            model: AeroModel::Lissaman,
            ..AeroOptions::default()
        });
    }
    out
}

/// The footage's flock saving with every option of [`band_options`] (the footage is planar: one
/// wake).
pub fn footage_band(p: &FormationParams) -> Vec<BandEntry> {
    band_options(false)
        .into_iter()
        .filter_map(|aero| {
            footage_savings_with(p, &aero)
                .steady_saving
                .map(|saving| BandEntry { aero, saving })
        })
        .collect()
}

/// An animation's flock saving in steady flight (all frames without a steady stage) with every
/// option of [`band_options`], on at most [`BAND_FRAMES`] evenly spaced frames (fewer, down to 3,
/// for flocks of more than 200 birds; none above [`BAND_MAX_BIRDS`]), each evaluated
/// in the course frame as [`crate::aero::fill_frame_savings`] does.
pub fn animation_band(a: &Animation) -> Vec<BandEntry> {
    let range = a
        .stage("steady")
        .map(|s| s.start..s.end.min(a.frames.len()))
        .unwrap_or(0..a.frames.len());
    let len = range.end.saturating_sub(range.start);
    if len == 0 || a.birds < 2 || a.birds > BAND_MAX_BIRDS {
        return Vec::new();
    }
    // Big flocks: fewer frames (the sums are O(N²) per frame), at least 3.
    let budget = if a.birds <= 200 {
        BAND_FRAMES
    } else {
        (BAND_FRAMES * 200 * 200 / (a.birds * a.birds)).max(3)
    };
    let picks: Vec<usize> = if len <= budget {
        range.collect()
    } else {
        (0..budget)
            .map(|k| range.start + k * (len - 1) / (budget - 1))
            .collect()
    };
    let mut b = a.with_frames(picks.iter().map(|&k| a.frames[k].clone()).collect());
    b.stages.clear();
    let heights = b.frames.iter().any(|f| {
        let m = f.z.iter().sum::<f64>() / f.z.len().max(1) as f64;
        f.z.iter().any(|z| (z - m).abs() > 1e-9)
    });
    band_options(heights)
        .into_iter()
        .filter(|o| o.model.is_hummel() || a.birds <= BAND_LIFTING_LINE_BIRDS)
        .filter_map(|aero| {
            crate::aero::recompute_frame_savings(&mut b, &aero);
            let per: Vec<f64> = b
                .frames
                .iter()
                .filter_map(|f| f.e.as_ref())
                .filter(|e| !e.is_empty())
                .map(|e| e.iter().sum::<f64>() / e.len() as f64)
                .collect();
            (!per.is_empty()).then(|| BandEntry {
                aero,
                saving: per.iter().sum::<f64>() / per.len() as f64,
            })
        })
        .collect()
}

/// The footage's own savings with Hummel's model and the default core
/// ([`footage_savings_with`]).
pub fn footage_savings(p: &FormationParams) -> AnimationStats {
    footage_savings_with(p, &AeroOptions::default())
}

/// The footage's own savings: the model of `aero` (docs/formats.md §3) evaluated on every
/// annotated frame's birds (formation frame, no heights), as [`AnimationStats`] with the frame
/// index as "time". Birds whose wings overlap side by side are evaluated at the collision
/// distance (never an error).
pub fn footage_savings_with(p: &FormationParams, aero: &AeroOptions) -> AnimationStats {
    let mut ids: Vec<usize> = p
        .frames
        .iter()
        .flat_map(|f| f.positions.iter().map(|b| b.id))
        .collect();
    ids.sort_unstable();
    ids.dedup();
    // Per id: (frames, rank sum, saving sum, lateral sum, behind sum, times leader).
    let mut acc = vec![(0usize, 0.0, 0.0, 0.0, 0.0, 0usize); ids.len()];
    let mut over_time = Vec::new();
    for f in &p.frames {
        if f.positions.len() < 2 {
            continue;
        }
        let x: Vec<f64> = f.positions.iter().map(|b| b.x).collect();
        let y: Vec<f64> = f.positions.iter().map(|b| b.y).collect();
        let e = aero.power_lenient_3d(&x, &y, &vec![0.0; x.len()]);
        over_time.push((f.index as f64, e.iter().sum::<f64>() / e.len() as f64));
        let mut by_y: Vec<usize> = (0..y.len()).collect();
        by_y.sort_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)));
        for (rank, &j) in by_y.iter().enumerate() {
            let b = &f.positions[j];
            let Ok(k) = ids.binary_search(&b.id) else {
                continue;
            };
            let a = &mut acc[k];
            a.0 += 1;
            a.1 += rank as f64;
            a.2 += e[j];
            a.3 += b.x;
            a.4 += b.y;
            a.5 += usize::from(b.id == f.leader);
        }
    }
    let birds = ids
        .iter()
        .zip(&acc)
        .filter(|(_, a)| a.0 > 0)
        .map(|(&id, a)| {
            let m = a.0 as f64;
            BirdStats {
                bird: id,
                formation: 0,
                leader: 2 * a.5 > a.0,
                rank: a.1 / m,
                saving: a.2 / m,
                lateral: a.3 / m,
                behind: a.4 / m,
            }
        })
        .collect();
    let flock = (!over_time.is_empty())
        .then(|| over_time.iter().map(|p| p.1).sum::<f64>() / over_time.len() as f64);
    AnimationStats {
        formations: 1,
        takeoff_s: None,
        landing_s: None,
        steady_s: None,
        steady_saving: flock,
        saving_over_time: over_time,
        birds,
    }
}

/// The page for `subject`.
pub fn report(subject: &Subject<'_>) -> Result<String> {
    html::build(subject)
}
