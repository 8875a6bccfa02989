//! Formation-frame shapes (docs/formats.md §2, §4.3): `x` is the lateral offset to the right of the flight
//! direction, `y` the distance behind the leader (downstream positive), both in wingspans.

use serde::{Deserialize, Serialize};
use std::path::Path;
use std::str::FromStr;

use crate::error::{Error, Result};

/// One bird of a shape, formation frame, wingspans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bird {
    /// Lateral offset to the right of the flight direction, wingspans.
    pub x: f64,
    /// Distance behind the leader (downstream positive), wingspans.
    pub y: f64,
    /// Height above the leader's plane (up positive), wingspans; 0 when absent, and then left
    /// out of JSON. Only the 3-D wake uses it.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub z: f64,
}

/// True for 0 (and −0): the height left out of a bird's JSON.
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A flock's shape: the birds' positions in the formation frame (docs/formats.md §4.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Shape {
    /// Birds in input order.
    pub birds: Vec<Bird>,
}

impl Shape {
    /// Builds a shape from parallel coordinate slices (wingspans).
    pub fn from_xy(x: &[f64], y: &[f64]) -> Shape {
        Shape {
            birds: x
                .iter()
                .zip(y)
                .map(|(&x, &y)| Bird { x, y, z: 0.0 })
                .collect(),
        }
    }

    /// Lateral positions, wingspans.
    pub fn xs(&self) -> Vec<f64> {
        self.birds.iter().map(|b| b.x).collect()
    }

    /// Longitudinal positions, wingspans.
    pub fn ys(&self) -> Vec<f64> {
        self.birds.iter().map(|b| b.y).collect()
    }

    /// Heights above the leader's plane (up), wingspans.
    pub fn zs(&self) -> Vec<f64> {
        self.birds.iter().map(|b| b.z).collect()
    }

    /// Number of birds.
    pub fn len(&self) -> usize {
        self.birds.len()
    }

    /// True when the shape has no birds.
    pub fn is_empty(&self) -> bool {
        self.birds.is_empty()
    }

    /// Index of the front-most bird (smallest `y`; ties go to the first).
    pub fn leader(&self) -> Option<usize> {
        self.birds
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.y.total_cmp(&b.1.y))
            .map(|(i, _)| i)
    }

    /// Checks that every coordinate is finite and that there are at least `min_birds` birds;
    /// `origin` names the file in the message.
    pub fn validate(&self, origin: &Path, min_birds: usize) -> Result<()> {
        if self.birds.len() < min_birds {
            return Err(Error::format(
                origin,
                format!(
                    "birds: {} bird(s) given, at least {min_birds} needed",
                    self.birds.len()
                ),
            ));
        }
        if self.birds.len() > crate::limits::MAX_SHAPE_BIRDS {
            return Err(Error::format(
                origin,
                format!(
                    "birds: {} birds given, at most {}",
                    self.birds.len(),
                    crate::limits::MAX_SHAPE_BIRDS
                ),
            ));
        }
        for (i, b) in self.birds.iter().enumerate() {
            if !b.x.is_finite() {
                return Err(Error::format(
                    origin,
                    format!("birds[{i}].x: not a finite number"),
                ));
            }
            if !b.y.is_finite() {
                return Err(Error::format(
                    origin,
                    format!("birds[{i}].y: not a finite number"),
                ));
            }
            if !b.z.is_finite() {
                return Err(Error::format(
                    origin,
                    format!("birds[{i}].z: not a finite number"),
                ));
            }
            let c = crate::limits::MAX_COORDINATE;
            if b.x.abs() > c || b.y.abs() > c || b.z.abs() > c {
                return Err(Error::format(
                    origin,
                    format!(
                        "birds[{i}]: ({:e}, {:e}) is more than {c:e} wingspans from the leader",
                        b.x, b.y
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The shape families of §4 step 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// Two lines meeting at the leader.
    V,
    /// Parabola with its vertex near the flock's centre.
    U,
    /// Parabola with its vertex well off the centre (one arm longer).
    J,
    /// One straight line (echelon, line abreast).
    Line,
}

impl ShapeKind {
    /// `"v"`, `"u"`, `"j"` or `"line"`, as in the params file.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::V => "v",
            ShapeKind::U => "u",
            ShapeKind::J => "j",
            ShapeKind::Line => "line",
        }
    }
}

impl std::fmt::Display for ShapeKind {
    /// `V`, `U`, `J` or `line`, as the summaries print them.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ShapeKind::V => "V",
            ShapeKind::U => "U",
            ShapeKind::J => "J",
            ShapeKind::Line => "line",
        })
    }
}

impl std::fmt::Display for Bird {
    /// `(x, y)` in wingspans, to the given precision (default 2 decimals).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = f.precision().unwrap_or(2);
        write!(f, "({:.p$}, {:.p$})", self.x, self.y)
    }
}

impl std::fmt::Display for Shape {
    /// `3 birds, 1.60 wide, 0.80 deep (wingspans): (-0.80, 0.80), (0.00, 0.00), (0.80, 0.80)`;
    /// the precision applies to every number (`{:.3}`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = f.precision().unwrap_or(2);
        let extent = |v: Vec<f64>| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if v.is_empty() {
                0.0
            } else {
                hi - lo
            }
        };
        write!(
            f,
            "{} bird{}, {:.p$} wide, {:.p$} deep (wingspans)",
            self.birds.len(),
            if self.birds.len() == 1 { "" } else { "s" },
            extent(self.xs()),
            extent(self.ys())
        )?;
        for (i, b) in self.birds.iter().enumerate() {
            write!(f, "{}{b:.p$}", if i == 0 { ": " } else { ", " })?;
        }
        Ok(())
    }
}

impl FromStr for ShapeKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "v" => Ok(ShapeKind::V),
            "u" => Ok(ShapeKind::U),
            "j" => Ok(ShapeKind::J),
            "line" | "echelon" => Ok(ShapeKind::Line),
            _ => Err(format!("`{s}` is not a shape kind; use v, u, j or line")),
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn shapes_print_their_birds() {
        let s = super::Shape::from_xy(&[-0.8, 0.0, 0.8], &[0.8, 0.0, 0.8]);
        assert_eq!(
            s.to_string(),
            "3 birds, 1.60 wide, 0.80 deep (wingspans): (-0.80, 0.80), (0.00, 0.00), (0.80, 0.80)"
        );
        assert_eq!(format!("{:.1}", s.birds[0]), "(-0.8, 0.8)");
        assert_eq!(super::ShapeKind::Line.to_string(), "line");
        assert_eq!(
            super::Shape::default().to_string(),
            "0 birds, 0.00 wide, 0.00 deep (wingspans)"
        );
    }
}
