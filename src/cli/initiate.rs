//! `formation initiate` and `formation plot paths` (issue 5).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation initiate`.
#[derive(Debug, Args)]
pub struct InitiateArgs {
    /// A steady-flight animation file (its first key shape is the target).
    pub steady: PathBuf,
    /// Output animation (.json or .csv); may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
}

/// Runs `formation initiate`.
pub fn run(_args: InitiateArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("initiate"))
}

/// Arguments of `formation plot paths`.
#[derive(Debug, Args)]
pub struct PlotPathsArgs {
    /// An animation file with an initiation stage.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot paths`.
pub fn run_plot_paths(_args: PlotPathsArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("plot paths"))
}
