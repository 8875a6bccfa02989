//! `formation solve TARGET -o shape.json`: the key shape whose ξ matches the targets (eq. 4).

use std::path::PathBuf;

use clap::Args;
use formation::io::{write_json_atomic, OutputKind};
use formation::keyshape::solve::solve_with_progress;
use formation::keyshape::SolveOptions;
use formation::{Error, Result};
use serde::{Deserialize, Serialize};

use super::power::in_file;
use super::progress::TermProgress;
use super::wake::WakeArg;
use super::Global;

/// Solves of at least this many birds show a progress bar (smaller ones take milliseconds).
const PROGRESS_FROM: usize = 1000;

/// Arguments of `formation solve`.
#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Target file: {"x": [lateral positions], "xi": [targets], "y": [optional initial guess]}.
    pub target: PathBuf,
    /// Output shape (.json).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Converged means ‖ξ − ξ̂‖₂ at most this, dimensionless.
    #[arg(long, default_value_t = SolveOptions::default().tolerance, allow_negative_numbers = true)]
    pub tolerance: f64,
    /// Write the shape even when the solver does not converge (the exit code is still 1).
    #[arg(long)]
    pub keep_unconverged: bool,
    /// Vortex core radius of Hummel's model, wingspans (docs/model.md).
    #[arg(long, allow_negative_numbers = true, default_value_t = formation::aero::AeroOptions::default().core_radius)]
    pub core_radius: f64,
    /// Wake model, planar or 3d (docs/model.md); the key shape lies in one plane, where both
    /// give the same savings.
    #[arg(long, value_enum, default_value_t = WakeArg::Planar)]
    pub wake: WakeArg,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Target {
    x: Vec<f64>,
    xi: Vec<f64>,
    #[serde(default)]
    y: Option<Vec<f64>>,
}

#[derive(Serialize)]
struct Solved {
    birds: Vec<formation::Bird>,
    xi: Vec<f64>,
    target: Vec<f64>,
    residual: f64,
    converged: bool,
    evaluations: usize,
    total: f64,
}

/// Runs `formation solve`.
pub fn run(args: SolveArgs, g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Json])?;
    let opts = SolveOptions {
        tolerance: args.tolerance,
        aero: formation::aero::AeroOptions {
            core_radius: args.core_radius,
            wake: args.wake.into(),
            ..Default::default()
        },
        ..SolveOptions::default()
    };
    opts.validate()?;
    opts.aero.validate().map_err(|e| match e {
        Error::Parameter { message, .. } => Error::parameter("--core-radius", message),
        other => other,
    })?;
    let target: Target = formation::io::read_json(&args.target)?;
    formation::limits::check_shape_size(&format!("{}: x", args.target.display()), target.x.len())?;
    // Flocks of a thousand birds and more take a noticeable time: a bar on a terminal.
    let progress = TermProgress::new(g.quiet || target.x.len() < PROGRESS_FROM);
    let rep = solve_with_progress(&target.x, &target.xi, target.y.as_deref(), &opts, &progress)
        .map_err(|e| in_file(&args.target, e))?;
    if !rep.converged && !args.keep_unconverged {
        return Err(Error::NotConverged(format!(
            "{}: the solver stopped at residual ‖ξ − ξ̂‖ = {:.3e} (tolerance {:.1e}) after {} evaluations; nothing written (try another initial guess \"y\", or --keep-unconverged to see the shape)",
            args.target.display(),
            rep.residual,
            opts.tolerance,
            rep.evaluations
        )));
    }
    let out = Solved {
        birds: target
            .x
            .iter()
            .zip(&rep.y)
            .map(|(&x, &y)| formation::Bird { x, y, z: 0.0 })
            .collect(),
        xi: rep.xi.clone(),
        target: rep.target.clone(),
        residual: rep.residual,
        converged: rep.converged,
        evaluations: rep.evaluations,
        total: rep.total,
    };
    write_json_atomic(&args.output, &out)?;
    super::summary::solve(
        g,
        target.x.len(),
        &rep,
        opts.tolerance,
        &opts.aero,
        &args.output,
    );
    if !rep.converged {
        return Err(Error::NotConverged(format!(
            "{}: not converged (residual {:.3e}); shape written to {} with \"converged\": false",
            args.target.display(),
            rep.residual,
            args.output.display()
        )));
    }
    Ok(())
}
