//! `formation animate`: the whole chain in one command (issue 6). Annotations (any format) or a
//! params file → §4 extraction → §5 steady flight → §6 initiation → wingbeats → every output the
//! `-o` extensions ask for. Each stage draws from its own seeded stream (`rng::stream(seed,
//! stage)`), so `animate` gives exactly what `extract`, `steady` and `initiate` give when run one
//! after the other with the same `--seed`.

use std::path::PathBuf;

use clap::Args;
use formation::export::RenderOptions;
use formation::extract::{self, ExtractOptions};
use formation::{initiate, keyshape, rng, wingbeat, Error, Result};

use super::extract::ReadArgs;
use super::initiate::InitiateFlags;
use super::progress::TermProgress;
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
    /// needs to form, by default about 7 + 1.1 × birds seconds: 17 s for 9 birds, 22 s for 14,
    /// 52 s for 41; see --takeoff).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Skip the take-off: the animation is the steady flight alone.
    #[arg(long)]
    pub no_initiation: bool,
    /// Picture size WIDTHxHEIGHT in pixels (GIF and PNG frames).
    #[arg(long, value_name = "WxH", default_value = "960x540", value_parser = super::render::parse_size)]
    pub size: (u32, u32),
    /// Frame rate of the pictures [default: 25 for GIF, the animation's --fps for PNG frames and video].
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
    pub steady: SteadyFlags,
    #[command(flatten)]
    pub initiate: InitiateFlags,
    #[command(flatten)]
    pub wingbeat: WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
}

/// Runs `formation animate`.
pub fn run(args: AnimateArgs, g: Global) -> Result<()> {
    // Everything that can be checked is checked before any work.
    if !(args.seconds.is_finite() && args.seconds > 0.0) {
        return Err(Error::parameter(
            "--seconds",
            format!("must be a positive number of seconds, got {}", args.seconds),
        ));
    }
    let frames_f = (args.seconds * args.steady.fps).round();
    if !(1.0..=formation::limits::MAX_FRAMES as f64).contains(&frames_f) {
        return Err(Error::parameter(
            "--seconds",
            format!(
                "{} s at {} fps is {frames_f} frames; give between 1 and {} frames",
                args.seconds,
                args.steady.fps,
                formation::limits::MAX_FRAMES
            ),
        ));
    }
    let frames = frames_f as usize;
    let steady_opts = args.steady.options(args.birds, frames, g.seed)?;
    let init_opts = args.initiate.options(g.seed, args.birds)?;
    let wing = args.wingbeat.options()?;
    let mut render = RenderOptions {
        width: args.size.0,
        height: args.size.1,
        fps: args.picture_fps,
        keys: args.scene.keys,
        bird_model: args.scene.bird_model.clone(),
        ..RenderOptions::default()
    };
    args.shot.apply(&mut render)?;
    render.validate()?;
    formation::export::plan_outputs(&args.output)?;
    if let Some(p) = &args.scene.bird_model {
        formation::export::bird_model::load(p, wing.species)?;
    }

    let progress = TermProgress::new(g.quiet);
    let params = extract::params_from_path(
        &args.input,
        &args.read.options(),
        &ExtractOptions::default(),
        &mut rng::stream(g.seed, "extract"),
    )?;
    let steady = keyshape::steady::steady_flight(
        &params,
        &steady_opts,
        &mut rng::stream(g.seed, "steady"),
        &progress,
    )?;
    let mut anim = if args.no_initiation {
        steady
    } else {
        initiate::check_steady(&steady, &args.input)?;
        let (anim, _stats) = initiate::initiate(
            &steady,
            &init_opts,
            &mut rng::stream(g.seed, "initiate"),
            &progress,
        )?;
        anim
    };
    // Savings (e, ξ) in the take-off frames too.
    formation::aero::fill_frame_savings(&mut anim, &steady_opts.aero);
    wingbeat::assign_phases(&mut anim, &wing)?;
    super::write_animation(&anim, &args.output, &render, g)
}
