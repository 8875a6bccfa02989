//! `formation extract` and `formation plot shape` (issue 3).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// Annotations: native JSON, long CSV, DLTdv CSV, Labelme JSON file or directory.
    pub annotations: PathBuf,
    /// Output params file (.json).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation extract`.
pub fn run(_args: ExtractArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("extract"))
}

/// Arguments of `formation plot shape`.
#[derive(Debug, Args)]
pub struct PlotShapeArgs {
    /// A params file written by `formation extract`.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot shape`.
pub fn run_plot_shape(_args: PlotShapeArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("plot shape"))
}
