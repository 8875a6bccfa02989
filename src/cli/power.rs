//! `formation power` (issue 2).

use std::path::PathBuf;

use clap::Args;
use formation::Result;

use super::Global;

/// Arguments of `formation power`.
#[derive(Debug, Args)]
pub struct PowerArgs {
    /// Input file.
    pub input: PathBuf,
}

/// Runs `formation power`.
pub fn run(_args: PowerArgs, _g: Global) -> Result<()> {
    Err(super::not_yet("power"))
}
