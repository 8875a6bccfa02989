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
