//! §4 parameter extraction: per-frame ordering, lateral spacing statistics, leader, and the RANSAC
//! shape fit (issue 3).

pub mod params;

pub use params::{BirdPosition, FormationParams, FrameParams, LineCoef, ShapeModel, PARAMS_FORMAT};
