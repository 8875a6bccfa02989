//! Formation-frame shapes (SPEC §2, §4.3): `x` is the lateral offset to the right of the flight
//! direction, `y` the distance behind the leader (downstream positive), both in wingspans.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::error::{Error, Result};

/// One bird of a shape, formation frame, wingspans.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bird {
    /// Lateral offset to the right of the flight direction, wingspans.
    pub x: f64,
    /// Distance behind the leader (downstream positive), wingspans.
    pub y: f64,
}

/// A flock's shape: the birds' positions in the formation frame (SPEC §4.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Shape {
    /// Birds in input order.
    pub birds: Vec<Bird>,
}

impl Shape {
    /// Builds a shape from parallel coordinate slices (wingspans).
    pub fn from_xy(x: &[f64], y: &[f64]) -> Shape {
        Shape {
            birds: x.iter().zip(y).map(|(&x, &y)| Bird { x, y }).collect(),
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
            let c = crate::limits::MAX_COORDINATE;
            if b.x.abs() > c || b.y.abs() > c {
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
