//! The saving's sensitivity band: the flock's saving under every model, wake and core the tool
//! offers, so a saving is read as a range (the report, `plot savings` and the summaries).

use crate::aero::AeroOptions;
use crate::animation::Animation;

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
