//! An animation at another frame rate: the same motion in seconds, sampled at `fps` frames per
//! second (`render.animation_fps`, and the sub-frame samples of the 3-D outputs, `render.subframes`).
//!
//! Sample times are `t₀ + j / fps` from the first frame's time. A sample that falls on a frame
//! (within 1e-9 of the frame interval) is that frame, bit for bit, so the times two rates share
//! keep their values. Between frames:
//! - positions `x`, `y`, `z` by a monotone piecewise-cubic Hermite interpolant (PCHIP:
//!   Fritsch–Butland tangents, zero at a local extremum), which is smooth and, unlike a
//!   Catmull-Rom spline, never overshoots the frames (a bird resting on the ground never dips
//!   below it when it starts to rise);
//! - headings along the shorter arc, bank, pitch, speed, `e` and `ξ` linearly;
//! - the wing phase forward (it only advances), so the wingbeat is phase-continuous.
//!
//! Stages keep their times: a stage starts at the first sample at or after its first frame's
//! time. Key shapes and a formation's first steady frame move to the nearest sample. Events
//! carry times and are unchanged. A loop keeps looping: its period (frames / fps) must be a
//! whole number of samples at the new rate.

use std::f64::consts::{PI, TAU};

use super::{Animation, Frame};
use crate::error::{Error, Result};

/// Largest accepted rate, frames per second (sub-frame samples included).
pub const MAX_RESAMPLE_FPS: f64 = 1000.0;

/// Tolerance, in frame intervals, within which a sample time counts as a frame's time.
const ON_FRAME: f64 = 1e-9;

/// How many frames [`resample`] gives `anim` at `fps` (without sampling them; 0 for a rate
/// it refuses).
pub fn resampled_count(anim: &Animation, fps: f64) -> usize {
    let n = anim.frames.len();
    if !(fps.is_finite() && (1.0..=MAX_RESAMPLE_FPS).contains(&fps)) || n == 0 {
        return 0;
    }
    if anim.looped && n >= 2 {
        return (n as f64 / anim.fps * fps).round() as usize;
    }
    let span = anim.frames[n - 1].t - anim.frames[0].t;
    (span * fps + 1e-6).floor().max(0.0) as usize + 1
}

/// `anim` sampled at `fps` frames per second (see the module documentation). Errors name
/// `fps`: a rate that is not finite or outside 1..=[`MAX_RESAMPLE_FPS`], or for a loop, a
/// period that is not a whole number of frames at `fps`.
pub fn resample(anim: &Animation, fps: f64) -> Result<Animation> {
    if !(fps.is_finite() && (1.0..=MAX_RESAMPLE_FPS).contains(&fps)) {
        return Err(Error::parameter(
            "fps",
            format!("{fps} frames per second is not a usable rate; give 1 to {MAX_RESAMPLE_FPS}"),
        ));
    }
    let n = anim.frames.len();
    // The size at the new rate is held to the limits of an animation before any of it is made
    // (or the animation copied): a long animation at a high rate would otherwise fill memory and
    // disk with a file formation refuses to read.
    if n >= 1 {
        let seconds = if anim.looped && n >= 2 {
            n as f64 / anim.fps
        } else {
            anim.frames[n - 1].t - anim.frames[0].t
        };
        let count = (seconds * fps).max(0.0) + 1.0;
        let most =
            (crate::limits::MAX_BIRD_FRAMES / anim.birds.max(1)).min(crate::limits::MAX_FRAMES);
        if count.is_nan() || count > most as f64 + 0.5 {
            return Err(Error::parameter(
                "fps",
                format!(
                    "{fps} frames per second makes {count:.0} frames of {} birds ({seconds:.0} s), more than the {most} an animation may have (at most {} frames and {} bird-frames); give a lower rate",
                    anim.birds,
                    crate::limits::MAX_FRAMES,
                    crate::limits::MAX_BIRD_FRAMES
                ),
            ));
        }
    }
    let mut out = anim.clone();
    out.fps = fps;
    if n == 0 {
        return Ok(out);
    }
    let t0 = anim.frames[0].t;
    // A loop is sampled over its whole period, its closing frame (the first again, one frame
    // on) included so that the last interval interpolates towards it.
    let closed;
    let (src, count) = if anim.looped && n >= 2 {
        let period = n as f64 / anim.fps;
        let m = period * fps;
        if (m - m.round()).abs() > 1e-6 * m.max(1.0) {
            return Err(Error::parameter(
                "fps",
                format!(
                    "the loop lasts {period} s ({n} frames at {} fps), which is {m:.3} frames at {fps} fps; a loop needs a whole number of frames: give a rate that fits, e.g. {}",
                    anim.fps,
                    anim.fps
                ),
            ));
        }
        closed = anim.closed_loop().into_owned();
        (&closed.frames, m.round() as usize)
    } else {
        let span = anim.frames[n - 1].t - t0;
        let m = (span * fps + 1e-6).floor().max(0.0) as usize + 1;
        (&anim.frames, m)
    };
    let times: Vec<f64> = src.iter().map(|f| f.t).collect();
    let mut frames = Vec::with_capacity(count);
    let mut k = 0usize;
    for j in 0..count {
        let t = t0 + j as f64 / fps;
        while k + 1 < times.len() && times[k + 1] <= t {
            k += 1;
        }
        frames.push(sample(src, &times, k, t));
    }
    // Times of the original frames, for moving frame indices.
    let index_at = |frame: usize, round: bool| -> usize {
        if frame >= n {
            return count;
        }
        let s = (anim.frames[frame].t - t0) * fps;
        let j = if round {
            s.round()
        } else {
            (s - ON_FRAME * fps / anim.fps).ceil()
        };
        (j.max(0.0) as usize).min(count)
    };
    for st in &mut out.stages {
        st.start = index_at(st.start, false);
        st.end = index_at(st.end, false);
    }
    let last = count.saturating_sub(1);
    for ks in &mut out.key_shapes {
        ks.frame = index_at(ks.frame, true).min(last);
    }
    if let Some(forms) = out.formations.as_mut() {
        for f in forms {
            for ks in &mut f.key_shapes {
                ks.frame = index_at(ks.frame, true).min(last);
            }
            if let Some(s) = f.steady_start.as_mut() {
                *s = index_at(*s, false).min(last);
            }
        }
    }
    out.frames = frames;
    Ok(out)
}

/// The animation at time `t`, in the interval from frame `k` (`times[k] <= t`) to `k + 1`.
fn sample(frames: &[Frame], times: &[f64], k: usize, t: f64) -> Frame {
    let a = &frames[k];
    if k + 1 >= frames.len() {
        return a.clone();
    }
    let h = times[k + 1] - times[k];
    let u = (t - times[k]) / h;
    if u <= ON_FRAME {
        return a.clone();
    }
    if u >= 1.0 - ON_FRAME {
        return frames[k + 1].clone();
    }
    let b = &frames[k + 1];
    let prev = k.checked_sub(1).map(|i| (&frames[i], times[k] - times[i]));
    let next = frames.get(k + 2).map(|f| (f, times[k + 2] - times[k + 1]));
    let cubic = |get: fn(&Frame) -> &Vec<f64>| -> Vec<f64> {
        (0..get(a).len())
            .map(|i| {
                let before = prev.map(|(f, hp)| (get(f)[i], hp));
                let after = next.map(|(f, hn)| (get(f)[i], hn));
                pchip(before, get(a)[i], get(b)[i], after, h, u)
            })
            .collect()
    };
    let lin = |p: &[f64], q: &[f64]| -> Vec<f64> {
        p.iter().zip(q).map(|(p, q)| p + (q - p) * u).collect()
    };
    let opt = |p: &Option<Vec<f64>>, q: &Option<Vec<f64>>| -> Option<Vec<f64>> {
        match (p, q) {
            (Some(p), Some(q)) => Some(lin(p, q)),
            // A field one of the frames lacks: the nearer frame's.
            _ => {
                if u < 0.5 {
                    p.clone()
                } else {
                    q.clone()
                }
            }
        }
    };
    let heading = a
        .heading
        .iter()
        .zip(&b.heading)
        .map(|(&p, &q)| {
            let d = (q - p + PI).rem_euclid(TAU) - PI;
            let h = p + d * u;
            // Keep the file's convention: within [0, 2π) when both ends are.
            if (0.0..TAU).contains(&p) && (0.0..TAU).contains(&q) {
                h.rem_euclid(TAU)
            } else {
                h
            }
        })
        .collect();
    let wing_phase = match (&a.wing_phase, &b.wing_phase) {
        (Some(p), Some(q)) => Some(
            p.iter()
                .zip(q)
                .map(|(&p, &q)| (p + (q - p).rem_euclid(TAU) * u).rem_euclid(TAU))
                .collect(),
        ),
        _ => opt(&a.wing_phase, &b.wing_phase),
    };
    Frame {
        t,
        x: cubic(|f| &f.x),
        y: cubic(|f| &f.y),
        z: cubic(|f| &f.z),
        heading,
        speed: lin(&a.speed, &b.speed),
        bank: opt(&a.bank, &b.bank),
        pitch: opt(&a.pitch, &b.pitch),
        e: opt(&a.e, &b.e),
        xi: opt(&a.xi, &b.xi),
        wing_phase,
    }
}

/// The monotone cubic (PCHIP) through `p0` at u = 0 and `p1` at u = 1 of an interval `h` long,
/// with the neighbouring values `before` (`h` before `p0`) and `after` (after `p1`) setting the
/// tangents.
fn pchip(
    before: Option<(f64, f64)>,
    p0: f64,
    p1: f64,
    after: Option<(f64, f64)>,
    h: f64,
    u: f64,
) -> f64 {
    let d = (p1 - p0) / h;
    let tangent = |dl: f64, hl: f64, dr: f64, hr: f64| -> f64 {
        if dl * dr <= 0.0 {
            0.0
        } else {
            let w1 = 2.0 * hr + hl;
            let w2 = hr + 2.0 * hl;
            (w1 + w2) / (w1 / dl + w2 / dr)
        }
    };
    let m0 = match before {
        Some((q, hp)) => tangent((p0 - q) / hp, hp, d, h),
        None => d,
    };
    let m1 = match after {
        Some((q, hn)) => tangent(d, h, (q - p1) / hn, hn),
        None => d,
    };
    let u2 = u * u;
    let u3 = u2 * u;
    let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
    let h10 = u3 - 2.0 * u2 + u;
    let h01 = -2.0 * u3 + 3.0 * u2;
    let h11 = u3 - u2;
    h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pchip_is_exact_on_lines_and_never_overshoots_a_step() {
        for &u in &[0.1, 0.5, 0.9] {
            let v = pchip(Some((0.0, 1.0)), 1.0, 2.0, Some((3.0, 1.0)), 1.0, u);
            assert!((v - (1.0 + u)).abs() < 1e-12);
            // Resting, then rising: never below the resting value.
            let w = pchip(Some((0.0, 1.0)), 0.0, 0.0, Some((1.0, 1.0)), 1.0, u);
            assert!(w >= 0.0 && w.abs() < 1e-12, "{w}");
            let r = pchip(Some((0.0, 1.0)), 0.0, 1.0, Some((1.0, 1.0)), 1.0, u);
            assert!((0.0..=1.0).contains(&r));
        }
    }
}
