//! Progress reporting without printing: long stages call a [`Progress`] that the binary backs with
//! an indicatif bar on a terminal, and that library users and tests leave silent ([`Silent`]).

/// Receives progress of a long stage. All methods default to doing nothing.
pub trait Progress: Sync {
    /// A stage named `stage` starts with `total` units of work.
    fn start(&self, _stage: &str, _total: u64) {}
    /// `n` more units are done.
    fn advance(&self, _n: u64) {}
    /// The current stage is finished.
    fn finish(&self) {}
}

/// A [`Progress`] that reports nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {}
