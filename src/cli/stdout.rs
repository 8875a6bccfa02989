//! Standard output for tables and `--json` text. A reader that goes away (`| head -1`, a closed
//! pipe) ends the printing quietly, as command-line tools do: the rest of the text is dropped
//! and the command still finishes and commits its output files. Any other failure (a full
//! device, `>/dev/full`) is an error naming stdout, exit 2.

use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

use formation::{Error, Result};

/// Set once the reader has closed the pipe; later text is dropped.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `text` to stdout and flushes it.
pub fn print(text: &str) -> Result<()> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(Error::io("stdout", e)),
    }
}

/// Writes `text` and a newline to stdout.
pub fn println(text: &str) -> Result<()> {
    print(&format!("{text}\n"))
}

/// Longest line of a warning or summary on stderr, characters.
pub const MAX_DIAGNOSTIC_CHARS: usize = 2000;

/// Writes a summary (`text`, one or more lines) to stderr. Each line is made safe as errors are
/// (`error::one_line_within`: control characters from file content or a file's name escaped,
/// numbers of more than 24 digits shortened, cut at [`MAX_DIAGNOSTIC_CHARS`]). A failed write
/// (stderr closed, on a full device) is ignored: a diagnostic never ends a run, so the run's
/// outputs are still committed (`eprintln!` panicked there, exit 101).
pub fn diagnostic(text: &str) {
    let mut safe = String::with_capacity(text.len() + 1);
    for line in text.lines() {
        safe.push_str(&formation::error::one_line_within(
            line,
            MAX_DIAGNOSTIC_CHARS,
        ));
        safe.push('\n');
    }
    write_stderr(&safe);
}

/// Writes `warning: TEXT` to stderr as one line, whatever `text` holds (a newline in a file's
/// name is shown as `\n`), as [`diagnostic`] does otherwise.
pub fn warning(text: &str) {
    let line = formation::error::one_line_within(&format!("warning: {text}"), MAX_DIAGNOSTIC_CHARS);
    write_stderr(&format!("{line}\n"));
}

fn write_stderr(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes()).and_then(|()| err.flush());
}

/// A file's name for a summary line: control characters escaped (a newline in it would start a
/// line of its own).
pub fn file_name(p: &std::path::Path) -> String {
    formation::error::one_line_within(&p.display().to_string(), MAX_DIAGNOSTIC_CHARS)
}
