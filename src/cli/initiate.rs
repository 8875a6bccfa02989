//! `formation initiate` and `formation plot paths` (issue 5): flags → [`InitiateOptions`], run the
//! §6 simulation into the first key shape of a steady-flight file, write the combined animation.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use formation::animation::Animation;
use formation::initiate::{
    self, InitiateOptions, PerceptionMode, Start, StartRegion, StartState, HPR_GAMMA_DEFAULT,
};
use formation::io::OutputKind;
use formation::pipeline::{initiate_stage, Config};
use formation::{Error, Result};

use super::progress::TermProgress;
use super::Global;

/// Occlusion model of the perception.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PerceptionArg {
    /// Hidden Point Removal (the paper's; radius R = max distance · 10^γ).
    Hpr,
    /// Birds as discs of half a wingspan occluding one another.
    Exact,
}

/// Arguments of `formation initiate`.
#[derive(Debug, Args)]
pub struct InitiateArgs {
    /// A steady-flight animation file (its first key shape is the target).
    pub steady: PathBuf,
    /// Outputs by extension: .json (the animation file), .csv, and also .gif, DIR/, .glb; may be
    /// repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    #[command(flatten)]
    pub initiate: InitiateFlags,
    #[command(flatten)]
    pub wingbeat: super::wingbeat::WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
    /// Print the run's statistics as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Initiation flags shared by `initiate` and `animate` (the `initiate` section of the library's
/// `Config`; defaults from `InitiateOptions::default()`, angles shown in degrees).
#[derive(Debug, Clone, Args)]
pub struct InitiateFlags {
    /// Step limit (one step = one frame); no convergence within it fails with exit 1.
    #[arg(long, default_value_t = InitiateOptions::default().max_steps)]
    pub max_steps: usize,
    /// Occlusion model.
    #[arg(long, value_enum, default_value_t = PerceptionArg::of(InitiateOptions::default().perception.mode))]
    pub perception: PerceptionArg,
    /// HPR radius exponent γ: R = (distance of the farthest bird) · 10^γ, dimensionless.
    #[arg(long, default_value_t = HPR_GAMMA_DEFAULT, allow_negative_numbers = true)]
    pub hpr_gamma: f64,
    /// Visual field per eye, degrees from straight ahead (paper: 90); widened when the key shape
    /// needs it (see docs/initiation.md).
    #[arg(long, default_value_t = InitiateOptions::default().perception.fov_per_eye.to_degrees(), allow_negative_numbers = true)]
    pub fov: f64,
    /// Cone per eye in which the closest visible bird is the preferred reference, degrees
    /// (paper: 0.35π).
    #[arg(long, default_value_t = InitiateOptions::default().perception.reference_cone.to_degrees(), allow_negative_numbers = true)]
    pub reference_cone: f64,
    /// α of eq. (6) (heading gain), dimensionless.
    #[arg(long, default_value_t = InitiateOptions::default().alpha, allow_negative_numbers = true)]
    pub alpha: f64,
    /// |K| of eq. (5) (speed gain), per √wingspan.
    #[arg(long, default_value_t = InitiateOptions::default().k, allow_negative_numbers = true)]
    pub k: f64,
    /// Maximum turn rate, degrees per second.
    #[arg(long, default_value_t = InitiateOptions::default().max_turn_rate.to_degrees(), allow_negative_numbers = true)]
    pub max_turn_rate: f64,
    /// Maximum acceleration, wingspans per second squared.
    #[arg(long, default_value_t = InitiateOptions::default().max_accel, allow_negative_numbers = true)]
    pub max_accel: f64,
    /// Minimum flight speed, fraction of the cruise speed.
    #[arg(long, default_value_t = InitiateOptions::default().min_speed, allow_negative_numbers = true)]
    pub min_speed: f64,
    /// Maximum flight speed, fraction of the cruise speed.
    #[arg(long, default_value_t = InitiateOptions::default().max_speed, allow_negative_numbers = true)]
    pub max_speed: f64,
    /// Separation drive distance, wingspans (the paper's).
    #[arg(long, default_value_t = InitiateOptions::default().separation_distance, allow_negative_numbers = true)]
    pub separation: f64,
    /// Collision avoidance: predicted closest approach that triggers evasion, wingspans.
    #[arg(long, default_value_t = InitiateOptions::default().avoid_distance, allow_negative_numbers = true)]
    pub avoid_distance: f64,
    /// Convergence: every bird within this distance of its slot, wingspans.
    #[arg(long, default_value_t = InitiateOptions::default().tolerance, allow_negative_numbers = true)]
    pub tolerance: f64,
    /// Convergence: for this long, seconds (also the hand-over blend window).
    #[arg(long, default_value_t = InitiateOptions::default().hold, allow_negative_numbers = true)]
    pub hold: f64,
    /// Start file: JSON {"x": [...], "y": [...], "heading": [...], "speed": [...]} (world frame,
    /// wingspans, radians clockwise from north, wingspans per second; heading and speed optional).
    #[arg(long, conflicts_with_all = ["start_width", "start_depth", "heading_spread"])]
    pub start: Option<PathBuf>,
    /// Width of the random start region across the cruise heading, wingspans (default: grows
    /// with the flock, see docs/initiation.md).
    #[arg(long, allow_negative_numbers = true)]
    pub start_width: Option<f64>,
    /// Depth of the random start region along the cruise heading, wingspans (default: the width).
    #[arg(long, allow_negative_numbers = true)]
    pub start_depth: Option<f64>,
    /// Start headings are uniform within this many degrees of the cruise heading (180: any).
    #[arg(long, default_value_t = StartRegion::default().heading_spread.to_degrees(), allow_negative_numbers = true)]
    pub heading_spread: f64,
}

impl PerceptionArg {
    /// The flag value of a library perception mode.
    pub fn of(mode: PerceptionMode) -> PerceptionArg {
        match mode {
            PerceptionMode::Hpr { .. } => PerceptionArg::Hpr,
            PerceptionMode::Exact => PerceptionArg::Exact,
        }
    }
}

impl InitiateFlags {
    /// The library options these flags describe, for `birds` birds (a start file is read and
    /// checked against that count; the options are validated by the library).
    pub fn options(&self, birds: usize) -> Result<InitiateOptions> {
        let mut o = InitiateOptions {
            max_steps: self.max_steps,
            alpha: self.alpha,
            k: self.k,
            max_turn_rate: self.max_turn_rate.to_radians(),
            max_accel: self.max_accel,
            min_speed: self.min_speed,
            max_speed: self.max_speed,
            separation_distance: self.separation,
            avoid_distance: self.avoid_distance,
            tolerance: self.tolerance,
            hold: self.hold,
            ..Default::default()
        };
        o.perception.fov_per_eye = self.fov.to_radians();
        o.perception.reference_cone = self.reference_cone.to_radians();
        o.perception.mode = match self.perception {
            PerceptionArg::Hpr => PerceptionMode::Hpr {
                gamma: self.hpr_gamma,
            },
            PerceptionArg::Exact => PerceptionMode::Exact,
        };
        o.start = match &self.start {
            Some(path) => Start::Given(StartState::read(path, birds)?),
            None => Start::Random(StartRegion {
                width: self.start_width,
                depth: self.start_depth,
                heading_spread: self.heading_spread.to_radians(),
                ..Default::default()
            }),
        };
        Ok(o)
    }
}

/// Runs `formation initiate`.
pub fn run(args: InitiateArgs, g: Global) -> Result<()> {
    let wingbeat = args.wingbeat.options()?;
    wingbeat.validate()?;
    formation::export::plan_outputs(&args.output)?;
    let steady = Animation::read(&args.steady)?;
    initiate::check_steady(&steady, &args.steady)?;
    let config = Config {
        seed: g.seed,
        initiate: args.initiate.options(steady.birds)?,
        wingbeat,
        ..Config::default()
    };
    let progress = TermProgress::new(g.quiet);
    let (mut anim, stats) = initiate_stage(&steady, &config, &progress)?;
    formation::wingbeat::assign_phases(&mut anim, &config.wingbeat)?;
    super::write_animation(&anim, &args.output, &args.scene.options(), g)?;
    if args.json {
        let text = formation::finite::to_json_pretty("statistics", &stats)?;
        super::stdout::println(&text)?;
    }
    Ok(())
}

/// Arguments of `formation plot paths`.
#[derive(Debug, Args)]
pub struct PlotPathsArgs {
    /// An animation file with an initiation stage.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot paths`.
pub fn run_plot_paths(args: PlotPathsArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let a = Animation::read(&args.input)?;
    let chart = formation::plot::paths::PathsChart::from_animation(&a)
        .map_err(|e| Error::format(&args.input, e.to_string()))?;
    formation::plot::save(&chart, &args.output)
}
