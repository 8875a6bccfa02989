//! `formation solve` (issue 2).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `formation solve`.
pub fn run(_args: SolveArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("solve"))
}
