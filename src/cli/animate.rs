//! `formation animate`: the whole chain (issue 6).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation animate`.
#[derive(Debug, Args)]
pub struct AnimateArgs {
    /// Annotations (any supported format) or a params file.
    pub input: PathBuf,
    /// Number of birds to animate.
    #[arg(long)]
    pub birds: usize,
    /// Outputs (.gif, DIR/, .glb, .csv, .json); may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
}

/// Runs `formation animate`.
pub fn run(_args: AnimateArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("animate"))
}
