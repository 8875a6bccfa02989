//! `formation plot wingbeat` (issue 7).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation plot wingbeat`.
#[derive(Debug, Args)]
pub struct PlotWingbeatArgs {
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot wingbeat`.
pub fn run_plot_wingbeat(_args: PlotWingbeatArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("plot wingbeat"))
}
