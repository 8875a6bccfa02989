//! `formation plot wingbeat`: one wingbeat's joint angles over its phase (issue 7).

use std::path::PathBuf;

use clap::Args;
use formation::plot::wingbeat::WingbeatChart;
use formation::wingbeat::Species;
use formation::Result;

use super::Global;

/// Arguments of `formation plot wingbeat`.
#[derive(Debug, Args)]
pub struct PlotWingbeatArgs {
    /// Species preset: goose, crane or pelican.
    #[arg(long, default_value = "goose")]
    pub species: String,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot wingbeat`.
pub fn run_plot_wingbeat(args: PlotWingbeatArgs, _g: Global) -> Result<()> {
    let species: Species = args.species.parse()?;
    formation::plot::save(&WingbeatChart::new(species), &args.output)
}
