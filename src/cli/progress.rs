//! A [`Progress`] backed by an indicatif bar on stderr, shown only on a terminal and without
//! `--quiet`.

use std::io::IsTerminal;
use std::sync::Mutex;

use formation::progress::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// Terminal progress bar; silent when hidden.
pub struct TermProgress {
    hidden: bool,
    bar: Mutex<Option<ProgressBar>>,
}

impl TermProgress {
    /// A bar that shows only when `!quiet` and stderr is a terminal.
    pub fn new(quiet: bool) -> TermProgress {
        TermProgress {
            hidden: quiet || !std::io::stderr().is_terminal(),
            bar: Mutex::new(None),
        }
    }
}

impl Progress for TermProgress {
    fn start(&self, stage: &str, total: u64) {
        if self.hidden {
            return;
        }
        let bar = ProgressBar::new(total);
        bar.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40.cyan/blue}] {pos}/{len} {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_message(stage.to_string());
        if let Ok(mut b) = self.bar.lock() {
            if let Some(old) = b.take() {
                old.finish_and_clear();
            }
            *b = Some(bar);
        }
    }

    fn advance(&self, n: u64) {
        if let Ok(b) = self.bar.lock() {
            if let Some(b) = b.as_ref() {
                b.inc(n);
            }
        }
    }

    fn finish(&self) {
        if let Ok(mut b) = self.bar.lock() {
            if let Some(b) = b.take() {
                b.finish_and_clear();
            }
        }
    }
}
