//! `formation plot KIND`: dispatch to the chart of each stage.

use clap::{Args, Subcommand};
use formation::Result;

use super::Global;

/// Arguments of `formation plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Resolution of a PNG chart, dots per inch (50 to 600): the chart is drawn DPI/96 times
    /// larger on each side, with the same layout and sharper lines and text, and the resolution
    /// is recorded in the file (300 for print). SVG charts are resolution-free and unchanged.
    #[arg(long, global = true)]
    dpi: Option<f64>,
    #[command(subcommand)]
    kind: PlotKind,
}

#[derive(Debug, Subcommand)]
enum PlotKind {
    /// Per-bird power reduction of a shape, key shape or frame, with feasible ranges.
    Power(super::steady::PlotPowerArgs),
    /// ξ of every bird over time in an animation.
    Xi(super::steady::PlotXiArgs),
    /// Birds, fitted curve, leader and outliers of one frame of a params file.
    Shape(super::extract::PlotShapeArgs),
    /// Top view of the birds' trajectories during initiation.
    Paths(super::initiate::PlotPathsArgs),
    /// Joint angles of one wingbeat over its phase.
    Wingbeat(super::wingbeat::PlotWingbeatArgs),
    /// Each bird's saving against its rank, and the flock's saving over time through the
    /// take-off, with the field studies' flock savings for comparison.
    Savings(SavingsArgs),
}

/// Arguments of `formation plot savings`.
#[derive(Debug, Args)]
pub struct SavingsArgs {
    /// An animation file.
    pub input: std::path::PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: std::path::PathBuf,
    #[command(flatten)]
    pub savings: super::wake::SavingsFlags,
}

fn run_plot_savings(args: SavingsArgs) -> Result<()> {
    use formation::io::OutputKind;
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    args.savings.aero(None)?;
    let mut anim = formation::Animation::read(&args.input)?;
    args.savings.apply(&mut anim)?;
    let chart = formation::plot::savings::SavingsChart::from_animation(&anim, &args.input)?;
    super::chart::save(&chart, &args.output)
}

impl PlotArgs {
    /// The chart's entry in the flag table.
    pub fn cmd(&self) -> super::flags::Cmd {
        use super::flags::Cmd;
        match self.kind {
            PlotKind::Power(_) => Cmd::PlotPower,
            PlotKind::Xi(_) => Cmd::PlotXi,
            PlotKind::Shape(_) => Cmd::PlotShape,
            PlotKind::Paths(_) => Cmd::PlotPaths,
            PlotKind::Wingbeat(_) => Cmd::PlotWingbeat,
            PlotKind::Savings(_) => Cmd::PlotSavings,
        }
    }
}

/// Runs `formation plot`.
pub fn run(args: PlotArgs, g: Global) -> Result<()> {
    use std::path::PathBuf;
    if let Some(d) = args.dpi {
        super::chart::set_dpi(d);
    }
    let (what, input, output): (String, PathBuf, PathBuf) = match &args.kind {
        PlotKind::Power(a) => (
            match (a.key, a.frame) {
                (Some(k), _) => {
                    format!("each bird's saving in key shape {k}, with its feasible range")
                }
                (None, Some(f)) => {
                    format!("each bird's saving in frame {f}, with its feasible range")
                }
                _ => "each bird's saving, with its feasible range".into(),
            },
            a.input.clone(),
            a.output.clone(),
        ),
        PlotKind::Xi(a) => (
            "ξ of every bird over time".into(),
            a.input.clone(),
            a.output.clone(),
        ),
        PlotKind::Shape(a) => (
            match a.frame {
                Some(f) => format!("the birds, fitted curve, leader and outliers of frame {f}"),
                None => "the birds, fitted curve, leader and outliers of a frame".into(),
            },
            a.input.clone(),
            a.output.clone(),
        ),
        PlotKind::Paths(a) => (
            "the take-off's trajectories from above".into(),
            a.input.clone(),
            a.output.clone(),
        ),
        PlotKind::Wingbeat(a) => (
            format!("joint angles over one wingbeat of the {}", a.species),
            PathBuf::from(format!("the {} preset", a.species)),
            a.output.clone(),
        ),
        PlotKind::Savings(a) => (
            match a.savings.aero(None).ok().flatten() {
                Some(o) => format!(
                    "each bird's saving against its rank, and the flock's saving over time ({})",
                    o.record()
                ),
                None => {
                    "each bird's saving against its rank, and the flock's saving over time".into()
                }
            },
            a.input.clone(),
            a.output.clone(),
        ),
    };
    let kind = match args.kind {
        PlotKind::Power(a) => super::steady::run_plot_power(a, g),
        PlotKind::Xi(a) => super::steady::run_plot_xi(a, g),
        PlotKind::Shape(a) => super::extract::run_plot_shape(a, g),
        PlotKind::Paths(a) => super::initiate::run_plot_paths(a, g),
        PlotKind::Wingbeat(a) => super::wingbeat::run_plot_wingbeat(a, g),
        PlotKind::Savings(a) => run_plot_savings(a),
    };
    kind?;
    super::summary::chart(g, "plot", &what, &input, &output);
    Ok(())
}
