//! `formation render`: outputs from an existing animation file (issue 6).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// An animation file.
    pub animation: PathBuf,
    /// Outputs (.gif, DIR/, .glb, .csv, .json); may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
}

/// Runs `formation render`.
pub fn run(_args: RenderArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("render"))
}
