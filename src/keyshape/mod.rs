//! §5 steps 1–4: initial shapes, power ranges, the Levenberg–Marquardt key-shape solve, and the
//! interpolation into a steady flight.

pub mod initial;
pub mod interpolate;
pub mod keys;
pub mod ranges;
pub mod solve;
pub mod steady;

pub use solve::{solve, SolveOptions, SolveReport};
pub use steady::{steady_flight, steady_flight_report, SteadyOptions, SteadyReport};
