//! # formation
//!
//! Animates bird flocks flying in line formations (V, U, J, echelon), after M. Klotsman and
//! A. Tal, "Animation of Flocks Flying in Line Formations". The pipeline:
//!
//! ```text
//! annotated frames ─extract─▶ formation parameters ─steady─▶ key shapes + steady-flight frames
//!                                  (RANSAC, §4)          (Hummel upwash + Levenberg–Marquardt, §5)
//! random start ─initiate (HPR perception, drives, §6)─▶ converges into the first key shape
//! initiation + steady flight ─render─▶ GIF · PNG frames · glTF (.glb) · CSV · JSON · plots
//! ```
//!
//! One call runs it all: [`pipeline::Pipeline`] takes annotations (a file, or points in memory
//! via [`annotations::Annotations::from_points`]) or formation parameters, and
//! [`pipeline::Pipeline::run`] gives the [`Animation`] and a report of every stage, with every
//! option in one serde-ready [`pipeline::Config`]. `examples/library.rs` goes from points to a
//! `.glb` in a few lines; `docs/architecture.md` describes the design.
//!
//! Layers: each uses only those below it, and no two top-level modules depend on each other.
//!
//! ```text
//! pipeline      pipeline (Config, Pipeline, one function per stage)
//!                  │
//! report        report (one HTML page over plot, extract and animation statistics)
//!                  │
//! stages        extract (§4) · keyshape (§5, with aero) · initiate (§6) · wingbeat · export · plot
//!                  │
//! data types    annotations · extract::params · shape · animation (+ animation::wing) · sniff
//!                  │
//! foundation    error · io · limits · finite · rng · progress · memory
//! ```
//!
//! | stage | module |
//! |---|---|
//! | the whole chain, its options | [`pipeline`] |
//! | reading annotations (every input format) | [`annotations`] |
//! | telling formation's files apart | [`sniff`] |
//! | §4 parameter extraction, RANSAC | [`extract`] |
//! | §5 step 2, Hummel's power-reduction model | [`aero`] |
//! | §5 steps 1–4, key shapes and steady flight | [`keyshape`] |
//! | §6 initiation | [`initiate`] |
//! | the course: paths, turns, climbs | [`course`] |
//! | wingbeats (Wu & Popović) | [`wingbeat`] |
//! | GIF, PNG, glTF, CSV, JSON | [`export`] |
//! | charts | [`plot`] |
//! | the HTML report (parameters, fits, savings, take-off, field studies) | [`report`] |
//!
//! Library code never prints or exits; errors are [`Error`] values naming the option path
//! (`steady.fps`) or the file, frame and bird at fault. The `formation` binary (feature `cli`, on
//! by default) maps option paths to its flags.
//!
//! Conventions (docs/formats.md §2): lengths in wingspans; formation frame `x` right of the flight direction,
//! `y` behind the leader; world frame `x` east, `y` north, `z` up, cruise heading +y.

// `!(a > b)` is used on purpose: it also rejects NaN, which `a <= b` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod aero;
pub mod animation;
pub mod annotations;
pub mod course;
pub mod embed;
pub mod error;
pub mod export;
pub mod extract;
pub mod finite;
pub mod initiate;
pub mod io;
pub mod keyshape;
pub mod limits;
pub mod memory;
pub mod pipeline;
pub mod player;
pub mod plot;
pub mod progress;
pub mod report;
pub mod rng;
pub mod shape;
pub mod skein;
pub mod sniff;
pub mod track;
pub mod wingbeat;

pub use animation::Animation;
pub use error::{Error, Result};
pub use shape::{Bird, Shape};
