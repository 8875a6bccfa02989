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
        /// The option path (`steady.birds`, see [`crate::pipeline::Config`]) or input field
        /// (`target.xi[3]`); the command line shows its own flag instead of an option path.
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
    /// This error with a parameter named `from` renamed `to` (any other error as it is): a
    /// helper's parameter named by the caller's option path.
    pub fn renamed(self, from: &str, to: &str) -> Self {
        match self {
            Error::Parameter { name, message } if name == from => Error::Parameter {
                name: to.to_string(),
                message,
            },
            other => other,
        }
    }

    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Most characters of an error message as printed: file content quoted in a message (a field, a
/// header) could otherwise fill the terminal.
pub const MAX_MESSAGE_CHARS: usize = 400;

/// An error message made fit for one terminal line: control characters from file content
/// (newlines, ESC, BEL) shown as escapes, numbers of more than 24 digits (1e308 printed in full)
/// shortened to scientific notation (every 64-bit integer keeps its digits), and the whole cut to [`MAX_MESSAGE_CHARS`].
pub fn one_line(message: &str) -> String {
    one_line_within(message, MAX_MESSAGE_CHARS)
}

/// [`one_line`] cut at `max` characters instead of [`MAX_MESSAGE_CHARS`] (warnings, which carry
/// advice after the file's name, are allowed longer lines).
pub fn one_line_within(message: &str, max: usize) -> String {
    let mut out = String::with_capacity(message.len().min(max + 64));
    let mut number = String::new();
    let flush = |number: &mut String, out: &mut String| {
        let digits = number.bytes().filter(u8::is_ascii_digit).count();
        match number.parse::<f64>() {
            Ok(v) if digits > 24 && v.is_finite() => out.push_str(&format!("{v:e}")),
            _ => out.push_str(number),
        }
        number.clear();
    };
    for c in message.chars() {
        if c.is_ascii_digit() || (c == '.' && !number.is_empty()) {
            number.push(c);
            continue;
        }
        if !number.is_empty() {
            flush(&mut number, &mut out);
        }
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push(' '),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    flush(&mut number, &mut out);
    let count = out.chars().count();
    if count > max {
        let cut: String = out.chars().take(max).collect();
        return format!("{cut}… ({} more characters)", count - max);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_short_line() {
        assert_eq!(one_line("a\nb\u{1b}[31m\u{7}c"), "a\\nb\\u{1b}[31m\\u{7}c");
        let huge = format!("value {}", 1e308);
        assert_eq!(one_line(&huge), "value 1e308");
        assert_eq!(one_line("frame 12, bird 3: 0.75"), "frame 12, bird 3: 0.75");
        assert_eq!(
            one_line("got 18446744073709551615"),
            "got 18446744073709551615"
        );
        let long = one_line(&"x".repeat(10_000_000));
        assert!(
            long.chars().count() < MAX_MESSAGE_CHARS + 40,
            "{}",
            long.len()
        );
        assert!(long.ends_with("(9999600 more characters)"), "{long}");
    }
}
