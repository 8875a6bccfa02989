//! Keyframe reduction for the glTF and USD exports (`render.keys` = reduced).
//!
//! The animation is sampled at every frame; `reduced` keeps a subset of those frames such that
//! LINEAR interpolation between the kept keys (straight lines for positions, slerp for rotations,
//! as glTF and USD interpolate) reproduces **every** original frame within a tolerance:
//! ```math
//! \lvert p_k - \operatorname{lerp}(p_a, p_b, u_k)\rvert \le \varepsilon_p, \qquad
//! 2 \arccos \lvert q_k \cdot \operatorname{slerp}(q_a, q_b, u_k) \rvert \le \varepsilon_q,
//! \qquad u_k = \frac{t_k - t_a}{t_b - t_a}
//! ```
//! for every frame k between consecutive kept keys a < b. The search is greedy: from a kept key,
//! the next key is the furthest frame for which every frame in between passes. Several channels
//! can share one key set (a bird's wing joints do), which keeps one time accessor per set.

use std::fmt;
use std::str::FromStr;

use glam::{Quat, Vec3};

use crate::error::{Error, Result};

/// How the 3D outputs' animation is cut into clips.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ClipMode {
    /// One clip per bird over every stage (`flight`), times from the animation's first frame:
    /// plays on import without arranging anything (the default).
    #[default]
    One,
    /// One clip per stage (`initiation`, `steady`, ...), each from time 0.
    Stages,
}

impl FromStr for ClipMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<ClipMode> {
        match s.trim().to_ascii_lowercase().as_str() {
            "one" => Ok(ClipMode::One),
            "stages" => Ok(ClipMode::Stages),
            _ => Err(Error::parameter(
                "render.clips",
                format!("unknown clip mode \"{s}\": expected one or stages"),
            )),
        }
    }
}

impl fmt::Display for ClipMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ClipMode::One => "one",
            ClipMode::Stages => "stages",
        })
    }
}

/// Which keys to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum KeyMode {
    /// A key at every frame of the animation (the default: exact).
    #[default]
    All,
    /// Only the keys needed to stay within [`Tolerance`] of every frame.
    Reduced,
}

impl FromStr for KeyMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<KeyMode> {
        match s.trim().to_ascii_lowercase().as_str() {
            "all" => Ok(KeyMode::All),
            "reduced" => Ok(KeyMode::Reduced),
            _ => Err(Error::parameter(
                "render.keys",
                format!("unknown key mode \"{s}\": expected all or reduced"),
            )),
        }
    }
}

impl fmt::Display for KeyMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            KeyMode::All => "all",
            KeyMode::Reduced => "reduced",
        })
    }
}

/// Largest deviation `reduced` allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Positions, metres.
    pub position_m: f32,
    /// Flight rotations (heading, bank), radians.
    pub rotation_rad: f32,
    /// Wingbeat joint rotations (shoulder, wrist, tail), radians.
    pub wing_rad: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance {
            // 0.9 mm, so that every frame stays within 1 mm after the files' own rounding
            // (f32 positions hundreds of metres out, USD's text digits).
            position_m: 0.0009,
            rotation_rad: 0.1f32.to_radians(),
            wing_rad: 1.0f32.to_radians(),
        }
    }
}

/// One curve sampled at every frame.
#[derive(Debug, Clone, Copy)]
pub enum Curve<'a> {
    /// Positions and their tolerance (same unit).
    Vec3(&'a [Vec3], f32),
    /// Rotations (sign-continuous) and their tolerance, radians.
    Quat(&'a [Quat], f32),
    /// Rotations as written (e.g. quantised, `stored`) against the exact ones (`exact`); the
    /// interpolation of the stored keys must stay within the tolerance of the exact curve.
    Stored {
        /// The exact rotations.
        exact: &'a [Quat],
        /// The rotations as the file stores them.
        stored: &'a [Quat],
        /// Tolerance, radians.
        tol: f32,
    },
    /// Scalars (e.g. a bank angle) and their tolerance.
    Scalar(&'a [f32], f32),
}

impl Curve<'_> {
    fn within(&self, a: usize, b: usize, k: usize, u: f32) -> bool {
        match *self {
            Curve::Vec3(v, tol) => (v[a].lerp(v[b], u) - v[k]).length() <= tol,
            Curve::Quat(q, tol) => angle(q[a].slerp(q[b], u), q[k]) <= tol,
            Curve::Stored { exact, stored, tol } => {
                let i = stored[a].slerp(stored[b], u);
                angle(i, exact[k]) <= tol
            }
            Curve::Scalar(s, tol) => (s[a] + u * (s[b] - s[a]) - s[k]).abs() <= tol,
        }
    }
}

/// Angle between two unit rotations, radians: `2 atan2(|d_xyz|, |d_w|)` of `d = a⁻¹ b`, which
/// keeps full precision for small angles (where `2 acos(a·b)` in f32 bottoms out near 0.03°).
pub fn angle(a: Quat, b: Quat) -> f32 {
    let d = a.conjugate() * b;
    2.0 * d.xyz().length().atan2(d.w.abs())
}

/// A unit rotation quantised to normalised signed bytes (glTF's `BYTE` normalised rotation
/// outputs: c = round(127 q)), and the rotation a reader decodes from them (c / 127, normalised).
pub fn quantise_i8(q: Quat) -> ([i8; 4], Quat) {
    let c = q
        .normalize()
        .to_array()
        .map(|v| (v * 127.0).round().clamp(-127.0, 127.0) as i8);
    let back = Quat::from_array(c.map(|v| v as f32 / 127.0)).normalize();
    (c, back)
}

/// A unit rotation quantised to normalised signed shorts (c = round(32767 q)), and the rotation a
/// reader decodes from them.
pub fn quantise_i16(q: Quat) -> ([i16; 4], Quat) {
    let c = q
        .normalize()
        .to_array()
        .map(|v| (v * 32767.0).round().clamp(-32767.0, 32767.0) as i16);
    let back = Quat::from_array(c.map(|v| v as f32 / 32767.0)).normalize();
    (c, back)
}

/// Frames to keep (indices into `times`, first and last always kept) so that every curve stays
/// within its tolerance (module doc). `KeyMode::All` keeps every frame.
pub fn keep(mode: KeyMode, times: &[f32], curves: &[Curve]) -> Vec<usize> {
    let n = times.len();
    if mode == KeyMode::All || n <= 2 {
        return (0..n).collect();
    }
    let mut kept = vec![0];
    let mut a = 0;
    while a < n - 1 {
        // Furthest b with every frame in (a, b) within tolerance; b = a + 1 always passes.
        let mut b = a + 1;
        while b + 1 < n {
            let c = b + 1;
            let span = times[c] - times[a];
            let ok = (a + 1..c).all(|k| {
                let u = (times[k] - times[a]) / span;
                curves.iter().all(|cv| cv.within(a, c, k, u))
            });
            if !ok {
                break;
            }
            b = c;
        }
        kept.push(b);
        a = b;
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_line_keeps_two_keys_and_a_sine_keeps_enough() {
        let t: Vec<f32> = (0..300).map(|k| k as f32 / 30.0).collect();
        let line: Vec<Vec3> = t.iter().map(|&t| Vec3::new(t, 2.0 * t, 0.0)).collect();
        assert_eq!(
            keep(KeyMode::Reduced, &t, &[Curve::Vec3(&line, 1e-3)]),
            vec![0, 299]
        );
        let sine: Vec<f32> = t.iter().map(|&t| (3.0 * t).sin()).collect();
        let k = keep(KeyMode::Reduced, &t, &[Curve::Scalar(&sine, 1e-3)]);
        assert!(k.len() > 10 && k.len() < 300, "{}", k.len());
        // Every frame is within the tolerance of the interpolated keys.
        for w in k.windows(2) {
            for i in w[0]..=w[1] {
                let u = (t[i] - t[w[0]]) / (t[w[1]] - t[w[0]]);
                let v = sine[w[0]] + u * (sine[w[1]] - sine[w[0]]);
                assert!((v - sine[i]).abs() <= 1e-3);
            }
        }
        assert_eq!(keep(KeyMode::All, &t, &[]).len(), 300);
    }

    #[test]
    fn rotations_use_the_slerp_angle() {
        let t: Vec<f32> = (0..100).map(|k| k as f32).collect();
        let steady: Vec<Quat> = t.iter().map(|&t| Quat::from_rotation_y(0.01 * t)).collect();
        assert_eq!(
            keep(KeyMode::Reduced, &t, &[Curve::Quat(&steady, 1e-4)]),
            vec![0, 99]
        );
        let wobble: Vec<Quat> = t
            .iter()
            .map(|&t| Quat::from_rotation_x(0.3 * (0.5 * t).sin()))
            .collect();
        assert!(keep(KeyMode::Reduced, &t, &[Curve::Quat(&wobble, 1e-3)]).len() > 20);
    }
}
