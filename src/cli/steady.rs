//! `formation steady`, `formation plot power` and `formation plot xi` (issue 4).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation steady`.
#[derive(Debug, Args)]
pub struct SteadyArgs {
    /// A params file written by `formation extract`.
    pub params: PathBuf,
    /// Number of birds to animate.
    #[arg(long)]
    pub birds: usize,
    /// Number of frames.
    #[arg(long)]
    pub frames: usize,
    /// Output animation (.json or .csv); may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
}

/// Runs `formation steady`.
pub fn run(_args: SteadyArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("steady"))
}

/// Arguments of `formation plot power`.
#[derive(Debug, Args)]
pub struct PlotPowerArgs {
    /// A shape file or an animation file.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot power`.
pub fn run_plot_power(_args: PlotPowerArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("plot power"))
}

/// Arguments of `formation plot xi`.
#[derive(Debug, Args)]
pub struct PlotXiArgs {
    /// An animation file.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot xi`.
pub fn run_plot_xi(_args: PlotXiArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("plot xi"))
}
