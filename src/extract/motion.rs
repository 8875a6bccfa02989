//! Position keeping in the footage: how much each bird moves about its slot in steady flight.
//! Needs frame times (frame index / fps, the annotations' top-level `fps` or `extract.footage_fps`).
//! Positions are taken relative to the centroid of the birds seen in both frames of a pair (or in
//! the frame, for the spread), so the whole formation's wandering in the image does not count.
//! Lateral is across the flight direction, fore-aft along it, wingspans.
//!
//! Measured per axis: the median and 90th percentile of a bird's move over 0.5 s and over 3 s,
//! and the per-bird standard deviation about its mean slot (median over the birds seen in at
//! least half of the frames). The steady flight's motion model (`keyshape::jostle`) reproduces
//! them with a smooth stationary process per bird whose correlation time is fitted here to the
//! 0.5 s move and the spread.

use std::collections::BTreeMap;

/// The short lag of the move statistics, seconds.
pub const SHORT_LAG_S: f64 = 0.5;
/// The long lag of the move statistics, seconds.
pub const LONG_LAG_S: f64 = 3.0;
/// Median of |N(0, 1)|: the median absolute value of a zero-mean Gaussian is this times its sd.
const HALF_NORMAL_MEDIAN: f64 = 0.674_489_750_196_081_7;

pub use super::params::{AxisKeeping, KeepingSource, PositionKeeping};

impl AxisKeeping {
    /// An axis from its 0.5 s move median and spread, with the fitted correlation time.
    pub fn fitted(move_median: f64, move_p90: f64, long: Option<f64>, spread: f64) -> Self {
        AxisKeeping {
            move_median,
            move_p90,
            move_long_median: long,
            spread,
            time_scale: time_scale(move_median, spread),
        }
    }
}

impl PositionKeeping {
    /// The default when the footage has no timing: stereo tracks of a wild V of 15 greater
    /// white-fronted geese (60 fps), relative to the centroid of the birds seen: median lateral
    /// move 0.071 wingspans in 0.5 s (90th percentile 0.21), per-bird lateral standard deviation
    /// 0.16 wingspans. Fore-aft is not reported there: the same figures are used (a choice).
    pub fn field_default() -> Self {
        let axis = AxisKeeping::fitted(0.071, 0.21, None, 0.16);
        PositionKeeping {
            source: KeepingSource::FieldData,
            fps: None,
            lateral: axis,
            fore_aft: axis,
        }
    }
}

/// Correlation time ℓ (seconds) of a stationary Gaussian process with sd `spread` and
/// autocorrelation exp(−τ²/(2ℓ²)) whose move over 0.5 s has median `move_median`:
/// median |Δ| = 0.6745 · spread · √(2(1 − ρ)), ρ = ρ(0.5 s). ρ is kept in [0.5, 0.999]: at
/// least 0.42 s, so that a spread too small for the moves does not make the birds jerk.
pub fn time_scale(move_median: f64, spread: f64) -> f64 {
    if !(spread > 0.0 && move_median > 0.0) {
        return 2.0;
    }
    let r = move_median / (HALF_NORMAL_MEDIAN * spread);
    let rho = (1.0 - r * r / 2.0).clamp(0.5, 0.999);
    SHORT_LAG_S / (-2.0 * rho.ln()).sqrt()
}

/// Tracks of birds over time: `frames[k]` holds (bird id, lateral, fore-aft) at `times[k]`.
pub struct Tracks<'a> {
    /// Seconds, one per frame.
    pub times: &'a [f64],
    /// The birds seen in each frame.
    pub frames: &'a [Vec<(usize, f64, f64)>],
}

fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let pos = q * (v.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    Some(v[lo] + (v[hi] - v[lo]) * (pos - lo as f64))
}

/// Moves over `lag` seconds (±20 %), both axes, relative to the centroid of the birds seen in
/// both frames.
fn moves(tr: &Tracks, lag: f64) -> (Vec<f64>, Vec<f64>) {
    let mut order: Vec<usize> = (0..tr.times.len()).collect();
    order.sort_by(|&a, &b| tr.times[a].total_cmp(&tr.times[b]));
    let (mut lat, mut fa) = (Vec::new(), Vec::new());
    for (pos, &a) in order.iter().enumerate() {
        // The frame closest to `lag` later.
        let want = tr.times[a] + lag;
        let best = order[pos + 1..]
            .iter()
            .copied()
            .min_by(|&b, &c| {
                (tr.times[b] - want)
                    .abs()
                    .total_cmp(&(tr.times[c] - want).abs())
            })
            .filter(|&b| (tr.times[b] - want).abs() <= 0.2 * lag);
        let Some(b) = best else { continue };
        let fb: BTreeMap<usize, (f64, f64)> = tr.frames[b]
            .iter()
            .map(|&(id, x, y)| (id, (x, y)))
            .collect();
        let common: Vec<((f64, f64), (f64, f64))> = tr.frames[a]
            .iter()
            .filter_map(|&(id, x, y)| fb.get(&id).map(|&q| ((x, y), q)))
            .collect();
        if common.len() < 2 {
            continue;
        }
        let n = common.len() as f64;
        let (mut c0, mut c1) = ((0.0, 0.0), (0.0, 0.0));
        for (p, q) in &common {
            c0 = (c0.0 + p.0 / n, c0.1 + p.1 / n);
            c1 = (c1.0 + q.0 / n, c1.1 + q.1 / n);
        }
        for (p, q) in &common {
            lat.push(((q.0 - c1.0) - (p.0 - c0.0)).abs());
            fa.push(((q.1 - c1.1) - (p.1 - c0.1)).abs());
        }
    }
    (lat, fa)
}

/// Per-bird sd about the mean slot (relative to each frame's centroid), median over the birds
/// seen in at least half of the frames (and at least 3).
fn spreads(tr: &Tracks) -> (Option<f64>, Option<f64>) {
    let mut per: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
    for f in tr.frames {
        if f.len() < 2 {
            continue;
        }
        let n = f.len() as f64;
        let cx = f.iter().map(|b| b.1).sum::<f64>() / n;
        let cy = f.iter().map(|b| b.2).sum::<f64>() / n;
        for &(id, x, y) in f {
            per.entry(id).or_default().push((x - cx, y - cy));
        }
    }
    let need = (tr.frames.len().div_ceil(2)).max(3);
    let sd = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    };
    let (mut sx, mut sy) = (Vec::new(), Vec::new());
    for v in per.values().filter(|v| v.len() >= need) {
        sx.push(sd(&v.iter().map(|p| p.0).collect::<Vec<_>>()));
        sy.push(sd(&v.iter().map(|p| p.1).collect::<Vec<_>>()));
    }
    (quantile(&mut sx, 0.5), quantile(&mut sy, 0.5))
}

/// The position-keeping statistics of `tracks`, or `None` when no two frames are 0.5 s apart or
/// no bird is seen in half of the frames.
pub fn measure(tr: &Tracks) -> Option<(AxisKeeping, AxisKeeping)> {
    let (mut lat, mut fa) = moves(tr, SHORT_LAG_S);
    if lat.len() < 3 {
        return None;
    }
    let (mut llat, mut lfa) = moves(tr, LONG_LAG_S);
    let (sx, sy) = spreads(tr);
    let (sx, sy) = (sx?, sy?);
    let axis = |v: &mut Vec<f64>, long: &mut Vec<f64>, s: f64| {
        let m = quantile(v, 0.5).unwrap_or(0.0);
        let p90 = quantile(v, 0.9).unwrap_or(0.0);
        AxisKeeping::fitted(m, p90, quantile(long, 0.5), s)
    };
    Some((axis(&mut lat, &mut llat, sx), axis(&mut fa, &mut lfa, sy)))
}

/// The footage's position keeping from the params' frames (formation frame, wingspans) at
/// `fps`: frame times are index / fps. `None` when the frames do not allow it.
pub fn footage_keeping(frames: &[super::params::FrameParams], fps: f64) -> Option<PositionKeeping> {
    if !(fps.is_finite() && fps > 0.0) {
        return None;
    }
    let times: Vec<f64> = frames.iter().map(|f| f.index as f64 / fps).collect();
    // The formation frame has the leader at the origin; the centroid removes that reference.
    let birds: Vec<Vec<(usize, f64, f64)>> = frames
        .iter()
        .map(|f| f.positions.iter().map(|b| (b.id, b.x, b.y)).collect())
        .collect();
    let (lateral, fore_aft) = measure(&Tracks {
        times: &times,
        frames: &birds,
    })?;
    Some(PositionKeeping {
        source: KeepingSource::Footage,
        fps: Some(fps),
        lateral,
        fore_aft,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_scale_inverts_the_move_median() {
        // ρ(0.5) = exp(−0.125/ℓ²); median |Δ| = 0.6745 s √(2(1 − ρ)).
        for l in [0.5, 0.7, 1.5] {
            let rho: f64 = (-(SHORT_LAG_S * SHORT_LAG_S) / (2.0 * l * l)).exp();
            let m = HALF_NORMAL_MEDIAN * 0.2 * (2.0 * (1.0 - rho)).sqrt();
            assert!((time_scale(m, 0.2) - l).abs() < 1e-9, "{l}");
        }
    }

    #[test]
    fn field_default_matches_the_field_figures() {
        let d = PositionKeeping::field_default();
        assert_eq!(d.lateral.move_median, 0.071);
        assert_eq!(d.lateral.spread, 0.16);
        assert!(d.lateral.time_scale > 0.5 && d.lateral.time_scale < 1.0);
    }
}
