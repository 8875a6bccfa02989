//! §5 steps 1–4: initial shapes, power ranges, the Levenberg–Marquardt key-shape solve, and the
//! interpolation into a steady flight.

pub mod given;
pub mod heights;
pub mod initial;
pub mod interpolate;
pub mod jostle;
pub mod keys;
pub mod lateral;
pub mod ranges;
pub mod reorganise;
pub mod separate;
pub mod solve;
pub mod spacing;
pub mod steady;

pub use heights::HeightOptions;
pub use initial::InitialOptions;
pub use jostle::JostleOptions;
pub use keys::KeyOptions;
pub use lateral::LateralOptions;
pub use reorganise::ReorganiseOptions;
pub use solve::{solve, SolveOptions, SolveReport};
pub use steady::{
    steady_flight, steady_flight_in, steady_flight_report, SteadyOptions, SteadyReport,
};
