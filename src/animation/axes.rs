//! Units and up axis of the point data written for other tools (`render.units`, `render.up`):
//! the CSV and the animation JSON are in wingspans with `z` up by default (the world frame: `x`
//! east, `y` north, `z` up); Houdini and Unreal read metres and Y up more directly.
//!
//! With `up = y` the axes are those of the `.glb` and `.usda`: `x` east, `y` up, `z` south
//! (`(x, y, z)_y-up = (x, z, −y)_z-up`). With `units = m`, positions, speeds and path lengths are
//! multiplied by `wingspan_m`. An animation file records both (`"units"`, `"up"`), and reading
//! it converts back, so every command reads such a file as it reads its own.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::Animation;
use crate::error::{Error, Result};

/// Length unit of the point data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// Wingspans (the model's own unit).
    #[default]
    Wingspans,
    /// Metres (wingspans × `wingspan_m`).
    M,
}

/// The up axis of the point data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Up {
    /// `x` east, `y` north, `z` up (the world frame).
    #[default]
    Z,
    /// `x` east, `y` up, `z` south (glTF's and USD's Y-up axes).
    Y,
}

impl Units {
    /// The default (wingspans).
    pub fn is_default(&self) -> bool {
        *self == Units::Wingspans
    }
}

impl Up {
    /// The default (`z` up).
    pub fn is_default(&self) -> bool {
        *self == Up::Z
    }

    /// A world-frame point `(east, north, up)` on these axes.
    pub fn from_world(self, p: [f64; 3]) -> [f64; 3] {
        match self {
            Up::Z => p,
            Up::Y => [p[0], p[2], -p[1]],
        }
    }

    /// A point on these axes back in the world frame.
    pub fn to_world(self, p: [f64; 3]) -> [f64; 3] {
        match self {
            Up::Z => p,
            Up::Y => [p[0], -p[2], p[1]],
        }
    }
}

impl FromStr for Units {
    type Err = Error;
    fn from_str(s: &str) -> Result<Units> {
        match s.trim().to_ascii_lowercase().as_str() {
            "wingspans" => Ok(Units::Wingspans),
            "m" => Ok(Units::M),
            _ => Err(Error::parameter(
                "render.units",
                format!("unknown unit \"{s}\": expected wingspans or m"),
            )),
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Units::Wingspans => "wingspans",
            Units::M => "m",
        })
    }
}

impl FromStr for Up {
    type Err = Error;
    fn from_str(s: &str) -> Result<Up> {
        match s.trim().to_ascii_lowercase().as_str() {
            "z" => Ok(Up::Z),
            "y" => Ok(Up::Y),
            _ => Err(Error::parameter(
                "render.up",
                format!("unknown up axis \"{s}\": expected z or y"),
            )),
        }
    }
}

impl fmt::Display for Up {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Up::Z => "z",
            Up::Y => "y",
        })
    }
}

/// The orientation of a bird as a unit quaternion `[x, y, z, w]` taking its own axes to the
/// output's: for `Up::Z` the bird's axes are x = right wing, y = forward, z = up, and the world's
/// east, north, up: `R_z(−heading) · R_x(pitch) · R_y(bank)`; for `Up::Y` they are those of a
/// glTF model (x = left wing, y = up, z = forward) in (east, up, south):
/// `R_y(π − heading) · R_x(−pitch) · R_z(bank)`, the rotation the `.glb` gives the bird.
/// Heading clockwise from north, pitch nose up, bank right wing down, radians.
pub fn orientation(up: Up, heading: f64, pitch: f64, bank: f64) -> [f64; 4] {
    let (h, p, b) = match up {
        Up::Z => (
            axis_angle([0.0, 0.0, 1.0], -heading),
            axis_angle([1.0, 0.0, 0.0], pitch),
            axis_angle([0.0, 1.0, 0.0], bank),
        ),
        Up::Y => (
            axis_angle([0.0, 1.0, 0.0], std::f64::consts::PI - heading),
            axis_angle([1.0, 0.0, 0.0], -pitch),
            axis_angle([0.0, 0.0, 1.0], bank),
        ),
    };
    let q = mul(mul(h, p), b);
    // One hemisphere (w ≥ 0), so that the same orientation always reads the same.
    if q[3] < 0.0 {
        q.map(|v| -v)
    } else {
        q
    }
}

fn axis_angle(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [axis[0] * s, axis[1] * s, axis[2] * s, c]
}

/// The Hamilton product `a · b` of quaternions `[x, y, z, w]`.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ]
}

impl Animation {
    /// A copy in `units` on the `up` axes, recording both (the frames' positions and speeds and
    /// the path's points and length; key shapes stay in the formation frame, wingspans).
    pub fn in_axes(&self, units: Units, up: Up) -> Animation {
        let mut a = self.clone();
        let s = match units {
            Units::Wingspans => 1.0,
            Units::M => self.wingspan_m,
        };
        for f in &mut a.frames {
            for i in 0..f.x.len() {
                let p = up.from_world([f.x[i], f.y[i], f.z[i]]);
                f.x[i] = p[0] * s;
                f.y[i] = p[1] * s;
                f.z[i] = p[2] * s;
            }
            f.speed.iter_mut().for_each(|v| *v *= s);
        }
        if let Some(path) = a.path.as_mut() {
            for p in path.points.iter_mut().chain(path.flown.iter_mut()) {
                *p = up.from_world(*p).map(|v| v * s);
            }
            path.length *= s;
        }
        a.units = units;
        a.up = up;
        a
    }

    /// Back in wingspans and the world frame, when read from a file written in other units or
    /// axes ([`Animation::in_axes`]).
    pub fn to_world_axes(&mut self) {
        if self.units.is_default() && self.up.is_default() {
            return;
        }
        let s = match self.units {
            Units::Wingspans => 1.0,
            Units::M => 1.0 / self.wingspan_m,
        };
        let up = self.up;
        for f in &mut self.frames {
            for i in 0..f.x.len().min(f.y.len()).min(f.z.len()) {
                let p = up.to_world([f.x[i], f.y[i], f.z[i]]);
                f.x[i] = p[0] * s;
                f.y[i] = p[1] * s;
                f.z[i] = p[2] * s;
            }
            f.speed.iter_mut().for_each(|v| *v *= s);
        }
        if let Some(path) = self.path.as_mut() {
            for p in path.points.iter_mut().chain(path.flown.iter_mut()) {
                *p = up.to_world(*p).map(|v| v * s);
            }
            path.length *= s;
        }
        self.units = Units::Wingspans;
        self.up = Up::Z;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
        let p = mul(mul(q, [v[0], v[1], v[2], 0.0]), [-q[0], -q[1], -q[2], q[3]]);
        [p[0], p[1], p[2]]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(a, b)| (a - b).abs() < 1e-12)
    }

    #[test]
    fn orientation_points_the_bird_where_its_angles_say() {
        let h = 0.7f64;
        // Z up: forward along the heading, clockwise from north.
        let q = orientation(Up::Z, h, 0.0, 0.0);
        assert!(close(rotate(q, [0.0, 1.0, 0.0]), [h.sin(), h.cos(), 0.0]));
        // Nose up pitch raises the forward axis; a right bank lowers the right wing.
        let q = orientation(Up::Z, 0.0, 0.3, 0.0);
        assert!(rotate(q, [0.0, 1.0, 0.0])[2] > 0.29);
        let q = orientation(Up::Z, 0.0, 0.0, 0.4);
        assert!(rotate(q, [1.0, 0.0, 0.0])[2] < -0.38);
        // Y up: the same bird on the .glb's axes (front +Z of the model).
        let qz = orientation(Up::Z, h, 0.2, -0.3);
        let qy = orientation(Up::Y, h, 0.2, -0.3);
        let fwd_z = rotate(qz, [0.0, 1.0, 0.0]);
        let fwd_y = rotate(qy, [0.0, 0.0, 1.0]);
        assert!(close(Up::Y.from_world(fwd_z), fwd_y));
        let right_z = rotate(qz, [1.0, 0.0, 0.0]);
        let right_y = rotate(qy, [-1.0, 0.0, 0.0]);
        assert!(close(Up::Y.from_world(right_z), right_y));
    }

    #[test]
    fn axes_round_trip() {
        let p = [1.5, -2.25, 3.0];
        assert_eq!(Up::Y.to_world(Up::Y.from_world(p)), p);
        assert_eq!(Up::Y.from_world(p), [1.5, 3.0, 2.25]);
    }
}
