//! §5 steps 1–4: initial shapes, power ranges, the Levenberg–Marquardt key-shape solve, and the
//! interpolation into a steady flight.

pub mod solve;

pub use solve::{solve, SolveOptions, SolveReport};
