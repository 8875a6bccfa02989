//! Sampling an animation at arbitrary times for the image outputs: positions are interpolated
//! linearly between the two surrounding frames, headings along the shorter arc, and wing poses
//! field by field (the frames are much closer together than a wingbeat). World frame, wingspans.

use std::f64::consts::{PI, TAU};
use std::path::Path;

use crate::animation::{Animation, Frame};
use crate::error::{Error, Result};
use crate::wingbeat::{Flapper, WingPose};

/// One bird at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BirdState {
    /// East, wingspans.
    pub x: f64,
    /// North, wingspans.
    pub y: f64,
    /// Up, wingspans.
    pub z: f64,
    /// Heading, radians clockwise from north.
    pub heading: f64,
    /// Bank angle, radians, right wing down positive (0 when the animation has none).
    pub bank: f64,
    /// Pitch angle, radians, nose up positive (0 when the animation has none).
    pub pitch: f64,
    /// Wing joint angles.
    pub pose: WingPose,
}

/// Where one bird is and which way it heads at one instant: what the camera plans from (a
/// quarter of a [`BirdState`], so a whole film's places are cheap to hold).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Place {
    /// East, wingspans.
    pub x: f64,
    /// North, wingspans.
    pub y: f64,
    /// Up, wingspans.
    pub z: f64,
    /// Heading, radians clockwise from north.
    pub heading: f64,
}

/// Checks that frame times strictly increase (every resampling and the glTF time keys need it).
pub fn check_times(anim: &Animation, origin: &Path) -> Result<()> {
    for (k, w) in anim.frames.windows(2).enumerate() {
        if w[1].t <= w[0].t {
            return Err(Error::format(
                origin,
                format!(
                    "frames[{}].t = {} is not after frames[{k}].t = {}; frame times must increase",
                    k + 1,
                    w[1].t,
                    w[0].t
                ),
            ));
        }
    }
    Ok(())
}

/// Number of output frames at `fps` (of [`output_times`]), computed without allocating them, so
/// that an absurd count can be refused first. Saturates at `usize::MAX`.
pub fn output_count(anim: &Animation, fps: f64) -> usize {
    let (Some(first), Some(last)) = (anim.frames.first(), anim.frames.last()) else {
        return 0;
    };
    // `as usize` saturates (and maps NaN to 0).
    (((last.t - first.t) * fps + 1e-6).floor().max(0.0) as usize).saturating_add(1)
}

/// Times of the output frames at `fps`, from the first frame's time up to the last one's.
pub fn output_times(anim: &Animation, fps: f64) -> Vec<f64> {
    let Some(first) = anim.frames.first() else {
        return Vec::new();
    };
    let n = output_count(anim, fps);
    (0..n).map(|k| first.t + k as f64 / fps).collect()
}

/// Shortest signed angle from `a` to `b`, radians in (−π, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (b - a).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

fn lerp_pose(a: &WingPose, b: &WingPose, w: f64) -> WingPose {
    let l = |p: f64, q: f64| p + (q - p) * w;
    WingPose {
        dihedral: l(a.dihedral, b.dihedral),
        hand_dihedral: l(a.hand_dihedral, b.hand_dihedral),
        sweep: l(a.sweep, b.sweep),
        arm_twist: l(a.arm_twist, b.arm_twist),
        hand_twist: l(a.hand_twist, b.hand_twist),
        spread: l(a.spread, b.spread),
        tail_bend: l(a.tail_bend, b.tail_bend),
        legs: l(a.legs, b.legs),
    }
}

/// Frame index `i` and weight `w` such that time `t` lies at `(1 − w)·frame[i] + w·frame[i+1]`.
pub fn locate(anim: &Animation, t: f64) -> (usize, f64) {
    let n = anim.frames.len();
    if n < 2 {
        return (0, 0.0);
    }
    let i = anim.frames.partition_point(|f| f.t <= t).clamp(1, n - 1) - 1;
    let (t0, t1) = (anim.frames[i].t, anim.frames[i + 1].t);
    let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
    (i, w)
}

/// Every bird's state at time `t` (clamped to the animation's time range).
pub fn state_at(anim: &Animation, flapper: &Flapper, t: f64) -> Vec<BirdState> {
    let (i, w) = locate(anim, t);
    let j = (i + 1).min(anim.frames.len().saturating_sub(1));
    let (fa, fb) = (&anim.frames[i], &anim.frames[j]);
    (0..anim.birds)
        .map(|b| {
            let Place { x, y, z, heading } = place_between(fa, fb, w, b);
            let g = |va: &Vec<f64>, vb: &Vec<f64>| lerp_at(va, vb, w, b);
            BirdState {
                x,
                y,
                z,
                heading,
                bank: match (&fa.bank, &fb.bank) {
                    (Some(a), Some(c)) => g(a, c),
                    (Some(a), None) => a.get(b).copied().unwrap_or(0.0),
                    _ => 0.0,
                },
                pitch: match (&fa.pitch, &fb.pitch) {
                    (Some(a), Some(c)) => g(a, c),
                    (Some(a), None) => a.get(b).copied().unwrap_or(0.0),
                    _ => 0.0,
                },
                pose: lerp_pose(&flapper.pose(i, b), &flapper.pose(j, b), w),
            }
        })
        .collect()
}

/// Every bird's place at time `t`: the position and heading of [`state_at`], without the
/// wingbeats.
pub fn places_at(anim: &Animation, t: f64) -> Vec<Place> {
    let (i, w) = locate(anim, t);
    let j = (i + 1).min(anim.frames.len().saturating_sub(1));
    let (fa, fb) = (&anim.frames[i], &anim.frames[j]);
    (0..anim.birds)
        .map(|b| place_between(fa, fb, w, b))
        .collect()
}

/// Bird `b`'s value of `va` (frame a) and `vb` (frame b) at fraction `w` between them; a value
/// missing in frame b is frame a's, one missing in both 0.
fn lerp_at(va: &[f64], vb: &[f64], w: f64, b: usize) -> f64 {
    let a = va.get(b).copied().unwrap_or(0.0);
    let c = vb.get(b).copied().unwrap_or(a);
    a + (c - a) * w
}

/// Bird `b`'s place at fraction `w` from frame `fa` to frame `fb` (the heading the short way
/// round).
fn place_between(fa: &Frame, fb: &Frame, w: f64, b: usize) -> Place {
    let ha = fa.heading.get(b).copied().unwrap_or(0.0);
    let hb = fb.heading.get(b).copied().unwrap_or(ha);
    Place {
        x: lerp_at(&fa.x, &fb.x, w, b),
        y: lerp_at(&fa.y, &fb.y, w, b),
        z: lerp_at(&fa.z, &fb.z, w, b),
        heading: ha + angle_diff(ha, hb) * w,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heading_interpolates_across_north() {
        assert!((angle_diff(TAU - 0.1, 0.1) - 0.2).abs() < 1e-12);
        assert!((angle_diff(0.1, TAU - 0.1) + 0.2).abs() < 1e-12);
    }

    #[test]
    fn output_times_cover_the_animation() {
        let mut a = Animation::new(0, 30.0, 1.5, 1);
        for k in 0..61 {
            a.frames.push(crate::animation::Frame {
                t: k as f64 / 30.0,
                x: vec![k as f64],
                y: vec![0.0],
                z: vec![0.0],
                heading: vec![0.0],
                speed: vec![1.0],
                ..Default::default()
            });
        }
        let ts = output_times(&a, 25.0);
        assert_eq!(ts.len(), 51);
        let f = Flapper::from_animation(&a);
        let s = state_at(&a, &f, 1.0);
        assert!((s[0].x - 30.0).abs() < 1e-9);
        let s = state_at(&a, &f, 0.5 / 30.0);
        assert!((s[0].x - 0.5).abs() < 1e-9);
    }
}
