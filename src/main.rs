//! The `formation` binary: parse the command line, run the library, map errors to exit codes.
//! This is the only place that prints errors: one line on stderr, exit 2 for bad input or usage,
//! 1 for the tool's own failures.

mod cli;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = match cli::Cli::try_parse() {
        Ok(a) => a,
        Err(e) => {
            use clap::error::ErrorKind;
            return match e.kind() {
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    // On stderr, and the run fails anyway.
                    let _ = e.print();
                    ExitCode::from(2)
                }
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    // On stdout, as tables and --json are: a reader that goes away ends it
                    // quietly, any other failure (a full device) is exit 2 naming stdout.
                    match e.print().and_then(|()| std::io::stdout().flush()) {
                        Err(w) if w.kind() != std::io::ErrorKind::BrokenPipe => {
                            let _ = writeln!(std::io::stderr(), "error: stdout: {w}");
                            ExitCode::from(2)
                        }
                        _ => ExitCode::SUCCESS,
                    }
                }
                _ => {
                    // clap's message is several lines (usage, tip); keep the first, which says
                    // what is wrong, and point at --help.
                    let rendered = e.render().to_string();
                    let mut lines = rendered.lines().map(str::trim).filter(|l| !l.is_empty());
                    let mut first = lines.next().unwrap_or("error: invalid usage").to_string();
                    if first.ends_with(':') {
                        // "the following required arguments were not provided:" + the list.
                        if let Some(next) = lines.next() {
                            first = format!("{first} {next}");
                        }
                    }
                    // Keep what tells the user the way out: the possible values, and clap's
                    // "a similar argument exists" tip.
                    for l in lines {
                        if l.starts_with("[possible values") || l.starts_with("tip:") {
                            first = format!("{first} {l}");
                        }
                    }
                    let _ = writeln!(std::io::stderr(), "{first} (see `formation --help`)");
                    ExitCode::from(2)
                }
            };
        }
    };
    cli::install_signal_cleanup();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(
                std::io::stderr(),
                "error: {}",
                formation::error::one_line(&e.to_string())
            );
            ExitCode::from(e.exit_code())
        }
    }
}
