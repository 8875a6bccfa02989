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

pub use crate::aero::band::{
    animation_band, band_options, BandEntry, BAND_CORES, BAND_FRAMES, BAND_LIFTING_LINE_BIRDS,
    BAND_MAX_BIRDS,
};

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
