//! `formation render`: outputs from an existing animation file. Flags become a
//! [`RenderOptions`]; everything else is [`formation::export::write_outputs`].

use std::path::PathBuf;

use clap::Args;
use formation::export::{write_outputs, RenderOptions};
use formation::{Animation, Result};

use super::progress::TermProgress;
use super::Global;

/// Arguments of `formation render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// An animation file (docs/formats.md).
    pub animation: PathBuf,
    /// Outputs by extension: .gif, DIR/ (numbered PNG frames), .mp4, .webm (through ffmpeg),
    /// .glb, .usda, .csv, .json; may be repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    #[command(flatten)]
    pub picture: PictureArgs,
    #[command(flatten)]
    pub shot: ShotArgs,
    /// Resample the animation to FPS frames per second before writing every output (the motion
    /// in seconds is unchanged: positions by a smooth curve through the frames, wingbeats
    /// phase-continuous); a loop needs a rate that gives it a whole number of frames.
    #[arg(long = "fps", value_name = "FPS", allow_negative_numbers = true)]
    pub animation_fps: Option<f64>,
}

/// Camera and look of the pictures, shared by `render` and `animate` (defaults from
/// [`RenderOptions::default`]).
#[derive(Debug, Clone, Args)]
pub struct ShotArgs {
    /// Camera: follow (top-down, frames the flock), ground (an observer looking up as the flock
    /// passes over) or fixed (the --view rectangle).
    #[arg(long, value_name = "NAME", default_value_t = RenderOptions::default().camera.name().to_string())]
    pub camera: String,
    /// World rectangle of --camera fixed: x0,y0,x1,y1 in wingspans (x east, y north).
    #[arg(long, value_name = "X0,Y0,X1,Y1", allow_hyphen_values = true, value_parser = formation::export::camera::parse_view)]
    pub view: Option<[f64; 4]>,
    /// Smallest on-screen wingspan of the follow camera, pixels; when the whole flock would be
    /// smaller it zooms in on the leading birds (0 = always show the whole flock).
    #[arg(long, value_name = "PX", default_value_t = RenderOptions::default().min_bird_px, allow_negative_numbers = true)]
    pub min_bird_px: f64,
    /// Background: sky (gradient and clouds), none (transparent PNG frames) or a colour #rrggbb.
    #[arg(long, value_name = "BG", default_value_t = RenderOptions::default().background.to_string())]
    pub background: String,
    /// Add a sun glow to the sky.
    #[arg(long)]
    pub sun: bool,
    /// GIF: largest colour error (8-bit levels) a pixel may show before it is redrawn; higher
    /// is smaller, 0 is exact.
    #[arg(long, value_name = "LEVELS", default_value_t = RenderOptions::default().gif_tolerance, allow_negative_numbers = true)]
    pub gif_tolerance: f64,
}

impl ShotArgs {
    /// Sets the camera and look in `opts`.
    pub fn apply(&self, opts: &mut RenderOptions) -> Result<()> {
        opts.camera = formation::export::CameraKind::parse(&self.camera, self.view)?;
        opts.background = formation::export::Background::parse(&self.background)?;
        opts.min_bird_px = self.min_bird_px;
        opts.sun = self.sun;
        opts.gif_tolerance = self.gif_tolerance;
        Ok(())
    }
}

/// Picture and export flags shared by `render` and `animate`.
#[derive(Debug, Clone, Args)]
pub struct PictureArgs {
    /// Picture size WIDTHxHEIGHT in pixels (GIF and PNG frames), each side 16..=7680.
    #[arg(long, value_name = "WxH", default_value_t = Size::of(&RenderOptions::default()), value_parser = parse_size)]
    pub size: Size,
    /// Frame rate of the pictures, frames per second (default: the GIF rate, rounded to whole
    /// 1/100 s per frame, for GIF; the animation's own rate for PNG frames and video). JSON, CSV and glTF
    /// keep the animation's frames.
    #[arg(
        long = "picture-fps",
        value_name = "FPS",
        allow_negative_numbers = true
    )]
    pub fps: Option<f64>,
    /// Bird wingspan in metres for the .glb (and recorded in the .json) (default: the
    /// animation's).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub wingspan_m: Option<f64>,
    #[command(flatten)]
    pub scene: SceneArgs,
}

/// Flags of the 3D outputs (.glb, .usda), shared by `render` and `animate`.
#[derive(Debug, Clone, Args)]
pub struct SceneArgs {
    /// Keyframes of .glb and .usda: `all` (every frame) or `reduced` (only the keys needed to
    /// stay within 1 mm and 0.1° of every frame for the flight, 1° for the wingbeat).
    #[arg(long, value_name = "all|reduced", default_value_t = RenderOptions::default().keys)]
    pub keys: formation::export::keys::KeyMode,
    /// Clips of the .glb: `one` (one clip per bird over the whole flight, which plays on import)
    /// or `stages` (one clip per stage: initiation, steady, ..., each from time 0).
    #[arg(long, value_name = "one|stages", default_value_t = RenderOptions::default().clips)]
    pub clips: formation::export::keys::ClipMode,
    /// Your own bird (.glb) on every bird of the .glb and .usda: a static mesh flies and banks, a
    /// skinned one whose joints follow the naming convention (docs/export.md) also flaps. Give it
    /// up to 16 times: the models are shared out over the birds at random (seeded).
    #[arg(long, value_name = "FILE.glb")]
    pub bird_model: Vec<PathBuf>,
    /// A JSON file naming your bird model's joints by the convention's, e.g.
    /// {"UpperArm.L": "upper_arm.L", "Hand.L": "hand.L", ...} (docs/export.md); once for every
    /// model, or once per --bird-model in the same order.
    #[arg(long, value_name = "FILE.json")]
    pub joint_map: Vec<PathBuf>,
    /// Spread of the birds' sizes in the .glb and .usda: each bird is scaled by 1 + F·z, z a
    /// normal draw clipped to ±3, from the seed of the animation; 0 to 0.3, 0 = all the same
    /// size [default: 0.04, our choice]. Positions (.json, .csv) do not change.
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub size_variation: Option<f64>,
    /// Number of the first frame in every output that numbers frames: .glb keys and range, USD
    /// time codes, the CSV's frame column, PNG file names (e.g. 1001; default: the animation
    /// file's, else 0).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_start_frame)]
    pub start_frame: Option<u64>,
    /// Samples per frame in the .glb and .usda (1 to 16): keys at fractional frames, from the
    /// motion between the frames, for motion blur (USD time samples at fractional time codes).
    #[arg(long, value_name = "K", default_value_t = 1, allow_negative_numbers = true, value_parser = parse_subframes)]
    pub subframes: u32,
    /// Length unit of the .csv and .json: wingspans (the model's) or m (metres, × the
    /// wingspan); a .json in metres records it and reads back as usual.
    #[arg(long, value_name = "wingspans|m", default_value_t = RenderOptions::default().units)]
    pub units: formation::animation::axes::Units,
    /// Up axis of the .csv and .json: z (x east, y north, z up) or y (x east, y up, z south, as
    /// the .glb and .usda; for Houdini and Unreal).
    #[arg(long, value_name = "z|y", default_value_t = RenderOptions::default().up)]
    pub up: formation::animation::axes::Up,
    /// Also write the path the flock flew to FILE.json, in the path file format that --path
    /// reads (world frame, z up, in --units): the course with its turns widened, or without a
    /// path the flock's centre once a second.
    #[arg(long, value_name = "FILE.json")]
    pub path_out: Option<PathBuf>,
    /// How the .usda holds the birds: skel (one skinned bird each, the exact wingbeat) or
    /// instancer (one point-instanced crowd of posed birds, quick to open) [default: instancer
    /// from 200 birds, skel below].
    #[arg(long, value_name = "skel|instancer")]
    pub usd_mode: Option<formation::export::UsdMode>,
    /// How the .glb holds the birds: birds (one skin and mesh each: one armature per bird in
    /// Blender) or flock (the birds in parts of 64, each one skinned mesh on one skin: one
    /// armature and one draw call a part, quick to import) [default: flock from 200 birds, birds
    /// below].
    #[arg(long, value_name = "birds|flock")]
    pub gltf_mode: Option<formation::export::GltfMode>,
    /// Mean wing-pose error, degrees, that a point-instanced USD crowd's prototypes must meet in
    /// every stage (take-off and landing included): smaller means more prototypes [default: 5].
    #[arg(long, value_name = "DEG")]
    pub crowd_pose_error: Option<f64>,
    /// Indent the written .json for reading (it is one compact line by default).
    #[arg(long)]
    pub pretty: bool,
    /// Write the .json's frames to a binary file beside it (flock.json → flock.frames: single
    /// precision, about 40 bytes a bird and frame instead of about 90 as text); the .json keeps
    /// everything else and names that file, and formation reads the pair back as one animation.
    #[arg(long)]
    pub binary_frames: bool,
}

/// Parses `--start-frame`: a whole number from 0 to the largest first frame.
fn parse_start_frame(s: &str) -> std::result::Result<u64, String> {
    let max = formation::export::MAX_START_FRAME;
    match s.trim().parse::<i64>() {
        Ok(v) if (0..=max as i64).contains(&v) => Ok(v as u64),
        _ => Err(format!(
            "the first frame is a whole number from 0 to {max} (studios use 0, 1, 101 or 1001)"
        )),
    }
}

/// Parses `--subframes`: a whole number of samples per frame, 1 to the largest.
fn parse_subframes(s: &str) -> std::result::Result<u32, String> {
    let max = formation::export::MAX_SUBFRAMES;
    match s.trim().parse::<i64>() {
        Ok(v) if (1..=i64::from(max)).contains(&v) => Ok(v as u32),
        _ => Err(format!(
            "give 1 (one sample a frame) to {max} samples per frame (4 is plenty for motion blur)"
        )),
    }
}

impl SceneArgs {
    /// Default render options with these flags.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            keys: self.keys,
            clips: self.clips,
            bird_model: self.bird_model.clone(),
            joint_map: self.joint_map.clone(),
            size_variation: self.size_variation,
            start_frame: self.start_frame,
            subframes: self.subframes,
            units: self.units,
            up: self.up,
            path_out: self.path_out.clone(),
            usd_mode: self.usd_mode,
            gltf_mode: self.gltf_mode,
            crowd_pose_error: self.crowd_pose_error,
            pretty: self.pretty,
            binary_frames: self.binary_frames,
            ..RenderOptions::default()
        }
    }
}

impl PictureArgs {
    /// The library options for these flags.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            width: self.size.width,
            height: self.size.height,
            fps: self.fps,
            wingspan_m: self.wingspan_m,
            ..self.scene.options()
        }
    }
}

/// A picture size, pixels; written and parsed as `WIDTHxHEIGHT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

impl Size {
    /// The size of `opts`.
    pub fn of(opts: &RenderOptions) -> Size {
        Size {
            width: opts.width,
            height: opts.height,
        }
    }
}

impl std::fmt::Display for Size {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

/// Parses `960x540`.
pub fn parse_size(s: &str) -> std::result::Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT like 960x540, got {s:?}"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected WIDTHxHEIGHT like 960x540, got {s:?}"))
    };
    let (w, h) = (parse(w)?, parse(h)?);
    let opts = RenderOptions {
        width: w,
        height: h,
        ..RenderOptions::default()
    };
    // `--size` is the same flag for `render` and `animate`.
    opts.validate().map_err(|e| match e {
        formation::Error::Parameter { message, .. } => {
            super::flags::rewrite(super::flags::Cmd::Render, &message)
        }
        other => other.to_string(),
    })?;
    Ok(Size {
        width: w,
        height: h,
    })
}

/// Runs `formation render`.
pub fn run(args: RenderArgs, g: Global) -> Result<()> {
    let mut opts = args.picture.options();
    opts.animation_fps = args.animation_fps;
    args.shot.apply(&mut opts)?;
    opts.validate()?;
    // Check the outputs before reading a possibly large animation.
    formation::export::plan_outputs(&args.output)?;
    formation::export::check_written(&args.output, &opts, &[])?;
    let anim = Animation::read(&args.animation)?;
    formation::export::sample::check_times(&anim, &args.animation)?;
    super::check_bird_model(
        super::flags::Cmd::Render,
        g,
        &opts,
        formation::wingbeat::WingbeatOptions::for_animation(&anim).species,
    )?;
    // `--seed` does not apply: rendering is deterministic, and the clouds take the animation's seed.
    let _ = g.seed;
    write_outputs(&anim, &args.output, &opts, &TermProgress::new(g.quiet))?;
    let written = formation::export::written_files(&args.output, &opts);
    super::summary::render(g, &anim, &opts, &args.animation, &written);
    Ok(())
}
