//! Command-line definitions (clap derive) and dispatch. Flags are parsed into the library's
//! options structs (their defaults come from those structs' `Default`), the library validates and
//! runs, and [`flags`] turns the option paths its errors name into this command's flags.

use clap::{Parser, Subcommand};
use formation::Result;

mod animate;
mod annotate;
mod chart;
mod course;
mod extract;
pub mod flags;
mod initiate;
mod plot;
mod power;
pub mod progress;
mod render;
mod report;
mod savings;
mod solve;
mod start;
mod stdout;
mod steady;
pub mod summary;
mod track;
mod view;
mod wake;
mod wingbeat;

/// Animate bird flocks flying in line formations (V, U, J, echelon), after Klotsman & Tal.
#[derive(Debug, Parser)]
#[command(name = "formation", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Hide progress bars and the summary each command prints when it is done.
    #[arg(long, short = 'q', global = true)]
    quiet: bool,
    /// Seed of every random draw; equal seeds and inputs give byte-identical outputs.
    #[arg(long, global = true, default_value_t = formation::pipeline::Config::default().seed)]
    seed: u64,
    /// Treat warnings about suspicious input (a formation opening forward, an implausible
    /// scale, too few frames) as errors: exit 2 and write nothing.
    #[arg(long, global = true)]
    strict: bool,
}

/// Options shared by every command.
#[derive(Debug, Clone, Copy)]
pub struct Global {
    /// `--quiet`.
    pub quiet: bool,
    /// `--seed`.
    pub seed: u64,
    /// `--strict`.
    pub strict: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// §4 parameter extraction: annotated frames → formation parameters (RANSAC shape fits).
    Extract(extract::ExtractArgs),
    /// Power reduction e_i, relative values ξ_i and total E of a shape (Hummel's model).
    Power(power::PowerArgs),
    /// Key shape whose ξ matches the targets (Levenberg–Marquardt, eq. 4).
    Solve(solve::SolveArgs),
    /// §5 Algorithm 1: a steady-flight animation from formation parameters.
    Steady(Box<steady::SteadyArgs>),
    /// §6 initiation: random take-off converging into the first key shape.
    Initiate(Box<initiate::InitiateArgs>),
    /// The whole chain: annotations or params → extract → steady → initiate → outputs.
    Animate(Box<animate::AnimateArgs>),
    /// Render or export an animation file (GIF, PNG frames, MP4, WebM, glTF .glb, USD .usda,
    /// CSV, JSON).
    Render(render::RenderArgs),
    /// Charts: power, xi, shape, paths, wingbeat, savings.
    Plot(plot::PlotArgs),
    /// One self-contained HTML page (inline SVG charts) about annotations, params or an
    /// animation: parameters per frame with fits, savings per bird, take-off, field comparison.
    Report(report::ReportArgs),
    /// Find and track the birds of footage (a video, a directory of images or a glob) and write
    /// native annotations for `extract`.
    Track(track::TrackArgs),
    /// A review page for annotations made elsewhere (any format extract reads) over the
    /// footage's frames, to check and correct them in a browser.
    Annotate(annotate::AnnotateArgs),
    /// One self-contained HTML page that plays an animation in 3-D (WebGL): cameras, timeline
    /// with stages and events, birds coloured by saving, rank or formation.
    View(view::ViewArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    let g = Global {
        quiet: cli.quiet,
        seed: cli.seed,
        strict: cli.strict,
    };
    use flags::Cmd;
    // Every output of the command is committed together at the end, or none of them.
    let outputs = formation::io::OutputBatch::begin()?;
    let (cmd, result) = match cli.command {
        Command::Extract(a) => (Cmd::Extract, extract::run(a, g)),
        Command::Power(a) => (Cmd::Power, power::run(a, g)),
        Command::Solve(a) => (Cmd::Solve, solve::run(a, g)),
        Command::Steady(a) => (Cmd::Steady, steady::run(*a, g)),
        Command::Initiate(a) => (Cmd::Initiate, initiate::run(*a, g)),
        Command::Animate(a) => (Cmd::Animate, animate::run(*a, g)),
        Command::Render(a) => (Cmd::Render, render::run(a, g)),
        Command::Plot(a) => (a.cmd(), plot::run(a, g)),
        Command::Report(a) => (Cmd::Report, report::run(a, g)),
        Command::Track(a) => (Cmd::Track, track::run(a, g)),
        Command::Annotate(a) => (Cmd::Annotate, annotate::run(a, g)),
        Command::View(a) => (Cmd::View, view::run(a, g)),
    };
    // Library errors name option paths; the user typed this command's flags.
    result.map_err(|e| flags::name_flags(cmd, e))?;
    outputs.commit().map_err(|e| flags::name_flags(cmd, e))?;
    summary::print_deferred();
    Ok(())
}

/// Prints the warnings recorded in `params` (already in the command's flags) and applies
/// `--strict`.
pub fn warn_params(g: Global, params: &formation::extract::FormationParams) -> Result<()> {
    let w = params
        .summary
        .as_ref()
        .map(|s| s.warnings.as_slice())
        .unwrap_or(&[]);
    warn(flags::Cmd::Extract, g, w)
}

/// Prints `warnings` on stderr (`warning: …`, option paths shown as `cmd`'s flags, even with
/// `--quiet`). With `--strict` the first warning is the error instead (exit 2, one line,
/// nothing written).
pub fn warn(cmd: flags::Cmd, g: Global, warnings: &[formation::extract::Warning]) -> Result<()> {
    let messages: Vec<&str> = warnings.iter().map(|w| w.message.as_str()).collect();
    warn_lines(cmd, g, &messages)
}

/// [`warn`] of plain one-line messages (the course step's).
pub fn warn_lines(cmd: flags::Cmd, g: Global, warnings: &[&str]) -> Result<()> {
    if g.strict {
        if let Some(first) = warnings.first() {
            let more = match warnings.len() - 1 {
                0 => String::new(),
                1 => " (and 1 more warning)".into(),
                n => format!(" (and {n} more warnings)"),
            };
            return Err(formation::Error::parameter(
                "--strict",
                format!("{}{more}; no output written", flags::rewrite(cmd, first)),
            ));
        }
    }
    for w in warnings {
        stdout::warning(&flags::rewrite(cmd, w));
    }
    Ok(())
}

/// On a terminating signal, remove temporary output files before exiting (no partial outputs).
///
/// Ctrl-C, SIGTERM, SIGHUP, SIGQUIT, SIGALRM, SIGUSR1/2, SIGXCPU (a CPU-time limit) and
/// SIGVTALRM/SIGPROF all end the run the same way: temporaries removed, one line on stderr, exit
/// 128 + the signal's number. SIGXFSZ (a `ulimit -f` file-size limit) is caught and ignored, so
/// the write that crossed the limit fails with "File too large" and the run ends as for a full
/// disk: exit 2 naming the output. Only SIGKILL cannot be caught; the temporaries it leaves are
/// removed by the next run that writes into the same directory (`formation::io`).
pub fn install_signal_cleanup() {
    use signal_hook::consts::signal::*;
    // An existing output is never touched before the final rename, so removing the temporaries
    // is all a clean interruption needs.
    let terminating = [
        SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGALRM, SIGUSR1, SIGUSR2, SIGXCPU, SIGVTALRM, SIGPROF,
    ];
    if let Ok(mut signals) =
        signal_hook::iterator::Signals::new(terminating.iter().chain(&[SIGXFSZ]))
    {
        std::thread::spawn(move || {
            for sig in signals.forever() {
                if sig == SIGXFSZ {
                    continue;
                }
                formation::io::remove_open_temporaries();
                let what = match sig {
                    SIGINT | SIGTERM => "interrupted".to_string(),
                    _ => format!(
                        "stopped by signal {}",
                        signal_hook::low_level::signal_name(sig).unwrap_or("?")
                    ),
                };
                // Not eprintln!: a panic here (stderr on a full device) would end only this
                // thread, leaving the run stopped on the lock it holds.
                let line = format!("error: {what}; no output written\n");
                let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
                std::process::exit(128 + sig);
            }
        });
    }
}

/// Loads the user's bird models (when given) before any work: a model that cannot be used is the
/// error; a model the birds cannot flap with is a warning (the error with `--strict`).
pub fn check_bird_model(
    cmd: flags::Cmd,
    g: Global,
    opts: &formation::export::RenderOptions,
    species: formation::wingbeat::Species,
) -> Result<()> {
    let assets =
        formation::export::bird_model::load_all(&opts.bird_model, &opts.joint_map, species)?;
    let warnings: Vec<String> = assets
        .iter()
        .filter_map(formation::export::bird_model::static_warning)
        .collect();
    if warnings.is_empty() {
        return Ok(());
    }
    let lines: Vec<&str> = warnings.iter().map(String::as_str).collect();
    warn_lines(cmd, g, &lines)
}

/// Writes `anim` to every output (by extension: .json, .csv, .gif, DIR/, .glb), atomically, with
/// a progress bar unless `--quiet`.
pub fn write_animation(
    anim: &formation::Animation,
    outputs: &[std::path::PathBuf],
    opts: &formation::export::RenderOptions,
    g: Global,
) -> Result<()> {
    formation::export::write_outputs(anim, outputs, opts, &progress::TermProgress::new(g.quiet))
}
