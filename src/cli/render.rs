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
    /// `--fps` is the animation's own rate, fixed by the file: refused with a pointer to
    /// `--picture-fps` (one vocabulary across commands).
    #[arg(long = "fps", hide = true, allow_hyphen_values = true)]
    pub animation_fps: Option<String>,
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
    /// skinned one whose joints follow the naming convention (docs/export.md) also flaps.
    #[arg(long, value_name = "FILE.glb")]
    pub bird_model: Option<PathBuf>,
}

impl SceneArgs {
    /// Default render options with these flags.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            keys: self.keys,
            clips: self.clips,
            bird_model: self.bird_model.clone(),
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
            keys: self.scene.keys,
            clips: self.scene.clips,
            bird_model: self.scene.bird_model.clone(),
            ..RenderOptions::default()
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
    if let Some(v) = &args.animation_fps {
        return Err(formation::Error::parameter(
            "--fps",
            format!(
                "{v}: --fps is the animation's own frame rate, fixed by the file for `render`; give the rate of the pictures with --picture-fps"
            ),
        ));
    }
    let mut opts = args.picture.options();
    args.shot.apply(&mut opts)?;
    opts.validate()?;
    // Check the outputs before reading a possibly large animation.
    formation::export::plan_outputs(&args.output)?;
    let anim = Animation::read(&args.animation)?;
    formation::export::sample::check_times(&anim, &args.animation)?;
    // `--seed` does not apply: rendering is deterministic, and the clouds take the animation's seed.
    let _ = g.seed;
    write_outputs(&anim, &args.output, &opts, &TermProgress::new(g.quiet))?;
    super::summary::render(g, &anim, &args.animation, &args.output);
    Ok(())
}
