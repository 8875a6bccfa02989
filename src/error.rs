//! The library's error type: every fallible stage returns [`Error`], whose message is one line that
//! names the file, frame, bird or field at fault and what to do about it.
//!
//! Bad input (malformed files, impossible parameters, birds whose wings collide) is the common
//! case and maps to exit code 2 in the binary; [`Error::NotConverged`] and [`Error::Internal`] are
//! the tool's own failures and map to exit code 1 (see [`Error::exit_code`]).

use std::path::PathBuf;

/// Result alias used across the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong, with the data a user needs to fix it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A file was read but its content is malformed (syntax, wrong structure, bad value).
    #[error("{}: {message}", path.display())]
    Format {
        /// The file concerned.
        path: PathBuf,
        /// Where (line/column, frame, row or field) and what is wrong.
        message: String,
    },
    /// A parameter (command-line flag or field of an input) is outside its valid range.
    #[error("{name}: {message}")]
    Parameter {
        /// The flag or field, e.g. `--birds` or `target.xi[3]`.
        name: String,
        /// What is wrong and what would be valid.
        message: String,
    },
    /// Two birds' wings overlap side by side (lateral distance under one wingspan and fore-aft
    /// distance under the collision chord), or the birds coincide.
    #[error("birds {i} and {j} collide: {dx:.4} wingspans apart laterally and {dy:.4} fore and aft (wings overlap side by side when under 1 wingspan laterally and under {chord} fore and aft); move one of them back")]
    Collision {
        /// First bird (index in input order).
        i: usize,
        /// Second bird.
        j: usize,
        /// Their lateral distance, wingspans.
        dx: f64,
        /// Their fore-aft distance, wingspans.
        dy: f64,
        /// The collision chord in force, wingspans.
        chord: f64,
    },
    /// The requested ξ targets cannot be reached by any longitudinal placement.
    #[error("{0}")]
    Unreachable(String),
    /// A numerical procedure did not reach its tolerance (the tool's failure, exit 1).
    #[error("{0}")]
    NotConverged(String),
    /// A bug or an unexpected state inside the tool (exit 1).
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    /// Process exit code for this error: 2 for bad input or usage, 1 for the tool's own failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::NotConverged(_) | Error::Internal(_) => 1,
            _ => 2,
        }
    }

    /// Shorthand for a [`Error::Format`] error.
    pub fn format(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Format {
            path: path.into(),
            message: message.into(),
        }
    }

    /// Shorthand for a [`Error::Parameter`] error.
    pub fn parameter(name: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Parameter {
            name: name.into(),
            message: message.into(),
        }
    }

    /// Shorthand for an [`Error::Io`] error.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}
