//! `formation animate`: the whole chain in one command. The flags become a library
//! `pipeline::Config`; `pipeline::Pipeline::from_path(INPUT).run_with` does annotations (any
//! format) or a params file → §4 extraction → §5 steady flight → §6 initiation → wingbeats, and
//! `export::write_outputs` every output the `-o` extensions ask for. Each stage draws from its own
//! seeded stream (`rng::Stream`), so `animate` gives exactly what `extract`, `steady` and
//! `initiate` give when run one after the other with the same `--seed`.

use std::path::PathBuf;

use clap::Args;
use formation::export::RenderOptions;
use formation::extract::ExtractOptions;
use formation::pipeline::{Config, Pipeline};
use formation::Result;

use super::extract::ReadArgs;
use super::initiate::InitiateFlags;
use super::progress::TermProgress;
use super::render::Size;
use super::steady::SteadyFlags;
use super::wingbeat::WingbeatFlags;
use super::Global;

/// Arguments of `formation animate`.
#[derive(Debug, Args)]
pub struct AnimateArgs {
    /// Annotations (native JSON, long CSV, DLTdv CSV, Labelme file or directory) or a params file
    /// written by `formation extract`.
    pub input: PathBuf,
    /// Number of birds to animate (N ≥ 2; any number, whatever the movie had).
    #[arg(long)]
    pub birds: usize,
    /// Outputs by extension: .gif, DIR/ (numbered PNG frames), .mp4, .webm (through ffmpeg), .glb,
    /// .usda, .csv, .json; may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    /// Length of the steady flight, seconds (the take-off before it lasts as long as the flock
    /// needs to form, see --takeoff; the summary printed at the end says how long it took).
    #[arg(long, default_value_t = formation::pipeline::DEFAULT_SECONDS, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Length of the whole shot, seconds, take-off included: the animation has exactly
    /// round(S × fps) frames and the steady flight takes what the take-off leaves (refused when
    /// the take-off alone is as long). Instead of --seconds.
    #[arg(
        long,
        value_name = "S",
        allow_negative_numbers = true,
        conflicts_with = "seconds"
    )]
    pub shot_seconds: Option<f64>,
    /// Skip the take-off: the animation is the steady flight alone.
    #[arg(long)]
    pub no_initiation: bool,
    /// Picture size WIDTHxHEIGHT in pixels (GIF and PNG frames).
    #[arg(long, value_name = "WxH", default_value_t = Size::of(&RenderOptions::default()), value_parser = super::render::parse_size)]
    pub size: Size,
    /// Frame rate of the pictures, frames per second (default: the GIF rate for GIF, the
    /// animation's --fps for PNG frames and video).
    #[arg(
        long = "picture-fps",
        value_name = "FPS",
        allow_negative_numbers = true
    )]
    pub picture_fps: Option<f64>,
    #[command(flatten)]
    pub shot: super::render::ShotArgs,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub timing: super::extract::TimingArgs,
    #[command(flatten)]
    pub steady: SteadyFlags,
    #[command(flatten)]
    pub path: super::course::PathFlags,
    #[command(flatten)]
    pub land: super::course::LandFlags,
    #[command(flatten)]
    pub skein: super::steady::SkeinFlags,
    #[command(flatten)]
    pub initiate: InitiateFlags,
    #[command(flatten)]
    pub wingbeat: WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
}

/// Runs `formation animate`.
pub fn run(args: AnimateArgs, g: Global) -> Result<()> {
    let mut config = Config {
        seed: g.seed,
        seconds: Some(args.seconds),
        shot_seconds: args.shot_seconds,
        initiation: !args.no_initiation,
        read: args.read.options(),
        extract: ExtractOptions {
            footage_fps: args.timing.footage_fps,
            ..ExtractOptions::default()
        },
        steady: args.steady.options(args.birds),
        skein: args.skein.options(),
        ..Config::default()
    };
    super::savings::apply_species(&mut config.steady, &args.wingbeat.species);
    // In the order the stages run: the steady flight's options are checked first.
    config.steady_options()?;
    // The take-off's length (and the --takeoff warning) is its largest formation's; the whole
    // flock's memory bound is checked by `config.validate()` below.
    let takeoff_birds = config.takeoff_birds();
    let species = args.wingbeat.options()?.species;
    let cruise =
        formation::initiate::Cruise::of_birds(0.0, 1.0, species, config.steady.wingspan_m, None);
    config.initiate = args.initiate.options(g.seed, takeoff_birds, &cruise)?;
    config.course = args.path.options();
    args.land.apply(&mut config);
    if args.no_initiation {
        // Without a take-off the steady flight itself flies at the cruise altitude.
        config.course.cruise_altitude = Some(config.initiate.cruise_altitude);
    }
    config.wingbeat = args.wingbeat.options()?;
    config.render = RenderOptions {
        width: args.size.width,
        height: args.size.height,
        fps: args.picture_fps,
        ..args.scene.options()
    };
    args.shot.apply(&mut config.render)?;
    // Everything that can be checked is checked before any work.
    config.validate()?;
    formation::export::plan_outputs(&args.output)?;
    super::course::check_path_kept(&args.path, &args.output, &config.render)?;
    super::check_bird_model(
        super::flags::Cmd::Animate,
        g,
        &config.render,
        config.wingbeat.species,
    )?;
    let progress = TermProgress::new(g.quiet);
    let (mut anim, report) = Pipeline::from_path(&args.input).run_with(&config, &progress)?;
    // A real species is named in the animation (its family's rig draws it).
    if let Some(b) = formation::aero::species::lookup(&args.wingbeat.species) {
        anim.species = Some(b.name.to_string());
    }
    let warnings = report
        .params
        .summary
        .as_ref()
        .map(|s| s.warnings.clone())
        .unwrap_or_default();
    super::warn(super::flags::Cmd::Animate, g, &warnings)?;
    super::course::warn(super::flags::Cmd::Animate, g, &report.course)?;
    super::write_animation(&anim, &args.output, &config.render, g)?;
    let written = formation::export::written_files(&args.output, &config.render);
    super::summary::animate(g, &anim, &report, &written);
    if let (Some(f), false) = (&report.skein, g.quiet) {
        super::stdout::diagnostic(&super::steady::flock_summary(f));
    }
    Ok(())
}
