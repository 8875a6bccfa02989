//! The `formation` binary: parse the command line, run the library, map errors to exit codes.
//! This is the only place that prints errors: one line on stderr, exit 2 for bad input or usage,
//! 1 for the tool's own failures.

pub(crate) mod cli;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

/// The binary's allocator: the system's, except that an allocation that fails ends the run
/// cleanly ([`formation::io::out_of_memory`]: temporaries removed, one line naming the output and
/// the size, exit 2) instead of aborting with a backtrace and leaving temporaries behind.
#[cfg(feature = "cli")]
mod guarded_alloc {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;
    use std::sync::atomic::{AtomicBool, Ordering};

    struct Guarded;

    /// Set by the first thread that runs out of memory.
    static FAILING: AtomicBool = AtomicBool::new(false);

    thread_local! {
        static HANDLING: Cell<bool> = const { Cell::new(false) };
    }

    #[cold]
    fn failed(bytes: usize) -> ! {
        if HANDLING.with(|h| h.replace(true)) {
            // The handler itself could not allocate: nothing gentler is left.
            std::process::abort();
        }
        if FAILING.swap(true, Ordering::SeqCst) {
            // Another thread is reporting and ending the process: wait for it.
            loop {
                std::thread::sleep(std::time::Duration::from_secs(1));
            }
        }
        formation::io::out_of_memory(bytes)
    }

    unsafe impl GlobalAlloc for Guarded {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            let p = System.alloc(layout);
            if p.is_null() {
                failed(layout.size());
            }
            p
        }
        unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
            let p = System.alloc_zeroed(layout);
            if p.is_null() {
                failed(layout.size());
            }
            p
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            System.dealloc(ptr, layout)
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            let p = System.realloc(ptr, layout, new_size);
            if p.is_null() {
                failed(new_size);
            }
            p
        }
    }

    #[global_allocator]
    static ALLOCATOR: Guarded = Guarded;
}

fn main() -> ExitCode {
    one_malloc_arena();
    ExitCode::from(run_main(std::env::args_os()))
}

/// glibc gives each thread that allocates an arena of its own, and memory freed in one arena is
/// not reused by the others: the flight's threads made a 1000-bird run's resident memory 1.6
/// times its heap (317 MB for 177 MB; 193 MB with one arena, no slower). One arena, unless the
/// user chose otherwise with `MALLOC_ARENA_MAX`.
fn one_malloc_arena() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        use std::ffi::c_int;
        extern "C" {
            fn mallopt(param: c_int, value: c_int) -> c_int;
        }
        /// glibc's `M_ARENA_MAX` (malloc.h).
        const M_ARENA_MAX: c_int = -8;
        if std::env::var_os("MALLOC_ARENA_MAX").is_none() {
            // SAFETY: mallopt only sets an allocator parameter; called before any thread starts.
            unsafe {
                mallopt(M_ARENA_MAX, 1);
            }
        }
    }
}

/// The whole binary for the arguments `args` (the first is the program's name), giving the exit
/// status: what `main` runs, and what the Python package's `formation` command runs.
pub fn run_main<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args = match cli::Cli::try_parse_from(args) {
        Ok(a) => a,
        Err(e) => {
            use clap::error::ErrorKind;
            return match e.kind() {
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    // On stderr, and the run fails anyway.
                    let _ = e.print();
                    2
                }
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    // On stdout, as tables and --json are: a reader that goes away ends it
                    // quietly, any other failure (a full device) is exit 2 naming stdout.
                    match e.print().and_then(|()| std::io::stdout().flush()) {
                        Err(w) if w.kind() != std::io::ErrorKind::BrokenPipe => {
                            let _ = writeln!(std::io::stderr(), "error: stdout: {w}");
                            2
                        }
                        _ => 0,
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
                    2
                }
            };
        }
    };
    cli::install_signal_cleanup();
    match cli::run(args) {
        Ok(()) => 0,
        Err(e) => {
            let _ = writeln!(
                std::io::stderr(),
                "error: {}",
                formation::error::one_line(&e.to_string())
            );
            e.exit_code()
        }
    }
}
