//! Outputs of an animation: the animation file (`.json`), the long CSV
//! (`.csv`), an animated GIF (`.gif`), a directory of numbered PNG frames (`DIR/`), a video
//! (`.mp4`, `.webm`, through the system ffmpeg), a glTF 2.0 binary (`.glb`) and text USD with
//! UsdSkel (`.usda`). [`write_outputs`] is the one entry point of `formation render` and
//! `formation animate`: it checks every output path and option before doing any work, then writes
//! each output atomically (no partial file on failure).
//!
//! Units: the animation is in wingspans (world frame `x` east, `y` north, `z` up); the `.glb` and
//! `.usda` are in metres (`wingspan_m`) on glTF's Y-up axes (see [`gltf`], [`usd`]); the pictures
//! are drawn by one of the [`camera`]s (top-down following the flock by default, a ground
//! observer, or a fixed view) over a procedural sky (see [`scene`], [`silhouette`]).
//!
//! Frame rates: `.json`, `.csv` and `.glb` keep the animation's own frames. The GIF is sampled at
//! [`pictures::GIF_FPS`] = 25 fps by default (GIF delays are whole 1/100 s); PNG frames and video
//! at the animation's frame rate. [`RenderOptions::fps`] overrides every picture rate.

pub mod bird;
pub mod bird_model;
pub mod camera;
pub mod crowd;
pub mod fidelity;
pub mod field;
pub mod gltf;
pub mod keys;
pub mod lzw;
pub mod palette;
pub mod pictures;
pub mod raster;
pub mod rig;
pub mod sample;
pub mod scene;
pub mod silhouette;
pub mod synthetic;
pub mod table;
pub mod usd;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::io::{AtomicFile, OutputKind};
use crate::progress::Progress;

pub use camera::CameraKind;
pub use pictures::{Film, GIF_FPS};
pub use scene::Background;

/// Output kinds `render` and `animate` accept.
pub const OUTPUT_KINDS: [OutputKind; 8] = [
    OutputKind::Gif,
    OutputKind::Directory,
    OutputKind::Mp4,
    OutputKind::Webm,
    OutputKind::Glb,
    OutputKind::Usda,
    OutputKind::Csv,
    OutputKind::Json,
];

/// Smallest image side, pixels.
pub const MIN_SIDE: u32 = 16;
/// Largest image side, pixels (8K UHD width; GIF itself allows 65535).
pub const MAX_SIDE: u32 = 7680;
/// Largest picture frame rate, frames per second.
pub const MAX_FPS: f64 = 120.0;
/// Largest GIF frame rate, frames per second: browsers slow down delays under 2/100 s.
pub const MAX_GIF_FPS: f64 = 50.0;
/// Largest number of picture frames one output may have.
pub const MAX_FRAMES: usize = 200_000;

/// How to render; every field is checked by [`RenderOptions::validate`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderOptions {
    /// Picture width, pixels.
    pub width: u32,
    /// Picture height, pixels.
    pub height: u32,
    /// Frame rate of the pictures (GIF, PNG frames, video), frames per second; `None` = 25 for
    /// GIF, the animation's own rate for PNG frames and video.
    pub fps: Option<f64>,
    /// Bird wingspan for the `.glb` and the written `.json`, metres; `None` = the animation's.
    pub wingspan_m: Option<f64>,
    /// Worker threads for pictures; 0 = one per core.
    pub threads: usize,
    /// The camera: follow, ground, or fixed with its world rectangle.
    pub camera: CameraKind,
    /// Smallest bird the follow camera draws: its wingspan on screen, pixels (0 = always fit
    /// the whole flock).
    pub min_bird_px: f64,
    /// What is behind the birds: sky, none (transparent) or a colour.
    pub background: Background,
    /// Draw a sun glow in the sky.
    pub sun: bool,
    /// Largest colour error a GIF pixel may show before it is redrawn, 8-bit levels per
    /// channel (0 = redraw every changed palette index).
    pub gif_tolerance: f64,
    /// Keyframes of the `.glb` and `.usda`: every frame, or reduced within the documented
    /// tolerances ([`keys::Tolerance`]).
    pub keys: keys::KeyMode,
    /// Clips of the .glb: one over every stage (default) or one per stage.
    pub clips: keys::ClipMode,
    /// The user's birds (`.glb`) for the `.glb` and `.usda`, shared out over the flock at random
    /// ([`bird::model_assignment`]); empty = the built-in bird. At most
    /// [`bird_model::MAX_MODELS`].
    pub bird_model: Vec<PathBuf>,
    /// JSON files naming the joints of the `bird_model`s by the convention's
    /// ([`bird_model::read_joint_map`]): none, one for every model, or one per model in order.
    pub joint_map: Vec<PathBuf>,
    /// Spread of the birds' sizes in the `.glb` and `.usda`, a fraction (the coefficient of
    /// variation of the wingspan, 0 to [`bird::MAX_SIZE_VARIATION`]): each bird is scaled by
    /// `1 + F·z`, z a standard normal clipped to ±3, drawn from the animation's seed
    /// ([`bird::bird_scales`]). `None` = the species' default
    /// ([`bird::DEFAULT_SIZE_VARIATION`]); 0 = every bird the same size. Positions (and the
    /// `.json` and `.csv`) do not change.
    pub size_variation: Option<f64>,
    /// Number of the first frame in every output that numbers frames (glTF keys and range, USD
    /// time codes, the CSV's `frame`, PNG file names), e.g. 1001; `None` = the animation's own
    /// (`start_frame` of the file, else 0).
    pub start_frame: Option<u64>,
    /// Resample the animation to this many frames per second before writing any output (the
    /// motion in seconds unchanged, see [`crate::animation::resample`]); `None` = its own rate.
    pub animation_fps: Option<f64>,
    /// Samples per frame of the `.glb` and `.usda` (1 = one per frame): keys at fractional
    /// frames for motion blur, from the motion between the frames.
    pub subframes: u32,
    /// Length unit of the CSV and the written animation JSON: wingspans (default) or metres.
    pub units: crate::animation::axes::Units,
    /// Up axis of the CSV and the written animation JSON: `z` (the world frame, default) or `y`.
    pub up: crate::animation::axes::Up,
    /// Also write the path the flock flew ([`Animation::flown_path`]) to this `.json`, in the
    /// path file format (`{"units": ..., "points": [[x, y, z], ...]}`, world frame, z up) in
    /// `units`, which `course.path` reads back.
    pub path_out: Option<PathBuf>,
    /// How the `.usda` holds the birds: one skinned bird each (`skel`) or a point-instanced
    /// crowd of posed prototypes (`instancer`, see [`crowd`]); `None` = instancer from
    /// [`crowd::INSTANCER_FROM`] birds, skel below.
    pub usd_mode: Option<UsdMode>,
    /// How the `.glb` holds the birds: one skin and mesh per bird (`birds`) or the whole flock as
    /// skinned meshes of 64 birds, each on its own skeleton (`flock`, which Blender imports as
    /// one armature a part); `None` =
    /// flock from [`crowd::INSTANCER_FROM`] birds, birds below.
    pub gltf_mode: Option<GltfMode>,
    /// Mean wing-pose error, degrees, that the prototypes of a point-instanced USD crowd must
    /// meet in every stage (take-off and landing included); `None` =
    /// [`crowd::DEFAULT_POSE_ERROR_DEG`]. See [`crowd`].
    pub crowd_pose_error: Option<f64>,
    /// Indent the written animation JSON (and the flown path) for reading; compact by default.
    pub pretty: bool,
    /// Write the animation JSON's frames to a binary file beside it in single precision
    /// ([`crate::animation::binary`]: about 40 bytes a bird-frame instead of about 90), the
    /// JSON keeping everything else and naming that file.
    pub binary_frames: bool,
}

/// How the `.usda` holds the birds ([`RenderOptions::usd_mode`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UsdMode {
    /// One `SkelRoot` per bird with its own skeleton and joint animation (exact wingbeat).
    Skel,
    /// One `PointInstancer` of posed prototypes (fast to open for large flocks).
    Instancer,
}

impl std::str::FromStr for UsdMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<UsdMode> {
        match s.trim().to_ascii_lowercase().as_str() {
            "skel" => Ok(UsdMode::Skel),
            "instancer" => Ok(UsdMode::Instancer),
            _ => Err(Error::parameter(
                "render.usd_mode",
                format!("unknown USD mode \"{s}\": expected skel or instancer"),
            )),
        }
    }
}

impl std::fmt::Display for UsdMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            UsdMode::Skel => "skel",
            UsdMode::Instancer => "instancer",
        })
    }
}

/// How the `.glb` holds the birds ([`RenderOptions::gltf_mode`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GltfMode {
    /// One skin and one skinned mesh node per bird (one armature per bird in a DCC).
    Birds,
    /// The flock in parts of 64 birds, each one skinned mesh on one skin (one armature and one
    /// draw call a part).
    Flock,
}

impl std::str::FromStr for GltfMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<GltfMode> {
        match s.trim().to_ascii_lowercase().as_str() {
            "birds" => Ok(GltfMode::Birds),
            "flock" => Ok(GltfMode::Flock),
            _ => Err(Error::parameter(
                "render.gltf_mode",
                format!("unknown glTF mode \"{s}\": expected birds or flock"),
            )),
        }
    }
}

impl std::fmt::Display for GltfMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            GltfMode::Birds => "birds",
            GltfMode::Flock => "flock",
        })
    }
}

pub use crate::limits::MAX_START_FRAME;
/// Largest accepted [`RenderOptions::subframes`].
pub const MAX_SUBFRAMES: u32 = 16;

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 960,
            height: 540,
            fps: None,
            wingspan_m: None,
            threads: 0,
            camera: CameraKind::Follow,
            min_bird_px: 12.0,
            background: Background::Sky,
            sun: false,
            gif_tolerance: 10.0,
            keys: keys::KeyMode::All,
            clips: keys::ClipMode::One,
            bird_model: Vec::new(),
            joint_map: Vec::new(),
            size_variation: None,
            start_frame: None,
            animation_fps: None,
            subframes: 1,
            units: crate::animation::axes::Units::Wingspans,
            up: crate::animation::axes::Up::Z,
            path_out: None,
            usd_mode: None,
            gltf_mode: None,
            crowd_pose_error: None,
            pretty: false,
            binary_frames: false,
        }
    }
}

impl RenderOptions {
    /// Checks the size, frame rate and wingspan; errors name the option path (`render.fps`).
    pub fn validate(&self) -> Result<()> {
        for (v, what) in [(self.width, "width"), (self.height, "height")] {
            if !(MIN_SIDE..=MAX_SIDE).contains(&v) {
                return Err(Error::parameter(
                    "render.width/render.height",
                    format!("{what} {v} px is outside {MIN_SIDE}..={MAX_SIDE}; give e.g. render.width/render.height 960x540"),
                ));
            }
        }
        let pixels = self.width as u64 * self.height as u64;
        if pixels > crate::limits::MAX_FRAME_PIXELS {
            return Err(Error::parameter(
                "render.width/render.height",
                format!(
                    "{}x{} is {pixels} pixels, more than 8K UHD (7680x4320 = {}); give a smaller size",
                    self.width,
                    self.height,
                    crate::limits::MAX_FRAME_PIXELS
                ),
            ));
        }
        if let Some(f) = self.fps {
            if !(f.is_finite() && (1.0..=MAX_FPS).contains(&f)) {
                return Err(Error::parameter(
                    "render.fps",
                    format!("{f} frames per second is not a usable frame rate; give a number from 1 to {MAX_FPS}"),
                ));
            }
        }
        if let Some(d) = self.crowd_pose_error {
            if !(d.is_finite() && (crowd::MIN_POSE_ERROR_DEG..=90.0).contains(&d)) {
                return Err(Error::parameter(
                    "render.crowd_pose_error",
                    format!(
                        "{d} degrees is not a usable wing-pose error; give a number from {} to 90, e.g. 5",
                        crowd::MIN_POSE_ERROR_DEG
                    ),
                ));
            }
        }
        if let Some(f) = self.animation_fps {
            if !(f.is_finite() && (1.0..=MAX_FPS).contains(&f)) {
                return Err(Error::parameter(
                    "render.animation_fps",
                    format!("{f} frames per second is not a usable frame rate; give a number from 1 to {MAX_FPS}"),
                ));
            }
        }
        if let Some(s) = self.start_frame {
            if s > MAX_START_FRAME {
                return Err(Error::parameter(
                    "render.start_frame",
                    format!("{s} is past the largest first frame, {MAX_START_FRAME}; studios start at 0, 1, 101 or 1001"),
                ));
            }
        }
        if !(1..=MAX_SUBFRAMES).contains(&self.subframes) {
            return Err(Error::parameter(
                "render.subframes",
                format!(
                    "{} samples per frame: give 1 (one per frame) to {MAX_SUBFRAMES}",
                    self.subframes
                ),
            ));
        }
        if !self.joint_map.is_empty() && self.bird_model.is_empty() {
            return Err(Error::parameter(
                "render.joint_map",
                "names the joints of a bird model; give render.bird_model too",
            ));
        }
        if self.bird_model.len() > bird_model::MAX_MODELS {
            return Err(Error::parameter(
                "render.bird_model",
                format!(
                    "{} bird models: give at most {}",
                    self.bird_model.len(),
                    bird_model::MAX_MODELS
                ),
            ));
        }
        if self.joint_map.len() > 1 && self.joint_map.len() != self.bird_model.len() {
            return Err(Error::parameter(
                "render.joint_map",
                format!(
                    "{} joint maps for {} bird models: give one map for every model, or one per model in the order of the models",
                    self.joint_map.len(),
                    self.bird_model.len()
                ),
            ));
        }
        self.camera.validate()?;
        if !(self.min_bird_px.is_finite() && (0.0..=1000.0).contains(&self.min_bird_px)) {
            return Err(Error::parameter(
                "render.min_bird_px",
                format!("{} is not a bird size; give the smallest on-screen wingspan in pixels, 0 to 1000 (default 12)", self.min_bird_px),
            ));
        }
        if !(self.gif_tolerance.is_finite() && (0.0..=64.0).contains(&self.gif_tolerance)) {
            return Err(Error::parameter(
                "render.gif_tolerance",
                format!("{} is outside 0..=64 colour levels", self.gif_tolerance),
            ));
        }
        if let Some(f) = self.size_variation {
            if !(f.is_finite() && (0.0..=bird::MAX_SIZE_VARIATION).contains(&f)) {
                return Err(Error::parameter(
                    "render.size_variation",
                    format!(
                        "{f} is not a size variation; give a fraction from 0 (every bird the same size) to {} (default {}: wingspans spread by about 4 %)",
                        bird::MAX_SIZE_VARIATION,
                        bird::DEFAULT_SIZE_VARIATION
                    ),
                ));
            }
        }
        if let Some(w) = self.wingspan_m {
            if !(w.is_finite() && (crate::limits::MIN_WINGSPAN_M..=100.0).contains(&w)) {
                return Err(Error::parameter(
                    "render.wingspan_m",
                    format!("{w} m is not a wingspan; give metres between 0 and 100 (a goose is about 1.5)"),
                ));
            }
        }
        Ok(())
    }
}

/// One checked output.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// Where it goes (directories without the trailing slash).
    pub path: PathBuf,
    /// What it is.
    pub kind: OutputKind,
}

/// Checks every output path: a known kind, no duplicates, an existing writable parent directory,
/// and for a frames directory, one that is new, empty or holds only earlier frames (it is
/// replaced as a whole). Creates and removes a probe file beside each output; writes nothing else.
pub fn plan_outputs(outputs: &[PathBuf]) -> Result<Vec<Output>> {
    if outputs.is_empty() {
        return Err(Error::parameter(
            "output",
            "no output given; add one, e.g. flock.gif",
        ));
    }
    let mut seen = BTreeSet::new();
    let mut plan = Vec::new();
    for p in outputs {
        // Binary USD is not written: the text stage converts losslessly with usd-core.
        let ext = p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("usdc") | Some("usd") | Some("usdz")) {
            let text = p.with_extension("usda");
            return Err(Error::parameter(
                "output",
                format!(
                    "{}: binary USD is not written by formation; write {} and convert it with usd-core: usdcat {} -o {}",
                    p.display(),
                    text.display(),
                    text.display(),
                    p.display()
                ),
            ));
        }
        let kind = OutputKind::from_path(p, &OUTPUT_KINDS)?;
        let path = if kind == OutputKind::Directory {
            let s = p.to_string_lossy();
            let t = s.trim_end_matches(['/', std::path::MAIN_SEPARATOR]);
            if t.is_empty() || p.file_name().is_none() || t.ends_with("..") {
                return Err(Error::parameter(
                    "output",
                    format!(
                        "{}: name a frames directory to create or replace, e.g. frames/",
                        p.display()
                    ),
                ));
            }
            PathBuf::from(t)
        } else {
            p.clone()
        };
        if !seen.insert(crate::io::output_identity(&path)) {
            return Err(Error::parameter(
                "output",
                format!("{}: given twice", path.display()),
            ));
        }
        crate::io::check_output_dir("output", &path)?;
        if kind == OutputKind::Directory {
            if path.exists() && !path.is_dir() {
                return Err(Error::format(
                    &path,
                    "exists and is not a directory; choose another name for the frames",
                ));
            }
            if path.is_dir() {
                let entries = std::fs::read_dir(&path).map_err(|e| Error::io(&path, e))?;
                for e in entries {
                    let e = e.map_err(|e| Error::io(&path, e))?;
                    let name = e.file_name().to_string_lossy().into_owned();
                    let ours =
                        name.starts_with("frame_") && name.ends_with(".png") && e.path().is_file();
                    if !ours {
                        return Err(Error::format(
                            &path,
                            format!("holds {name}, which is not a frame of ours; frames replace the whole directory, so give a new or empty one"),
                        ));
                    }
                }
            }
        } else if path.is_dir() {
            return Err(Error::format(&path, "is a directory, expected a file name"));
        }
        // Probe: can we create a file beside the target? (Dropped uncommitted: removed again.)
        let probe = match kind {
            OutputKind::Directory => path.with_extension("probe"),
            _ => path.clone(),
        };
        drop(AtomicFile::create(&probe).map_err(|e| match e {
            Error::Io { source, .. } => Error::io(&path, source),
            other => other,
        })?);
        plan.push(Output { path, kind });
    }
    Ok(plan)
}

/// Checks the JSON file a run's report goes to (named `report` in errors): a `.json` name in an
/// existing directory, and not one of the run's outputs (`plan`, from [`plan_outputs`]).
pub fn plan_report(report: &Path, plan: &[Output]) -> Result<()> {
    OutputKind::for_flag("report", report, &[OutputKind::Json])?;
    crate::io::check_output_dir("report", report)?;
    let id = crate::io::output_identity(report);
    if plan
        .iter()
        .any(|o| crate::io::output_identity(&o.path) == id)
    {
        return Err(Error::parameter(
            "report",
            format!(
                "{}: is also an output; the report needs a file of its own",
                report.display()
            ),
        ));
    }
    Ok(())
}

/// Frame rate used for a picture output of `kind`.
pub fn picture_fps(anim: &Animation, kind: OutputKind, opts: &RenderOptions) -> f64 {
    match (kind, opts.fps) {
        (OutputKind::Gif, Some(f)) => 100.0 / (100.0 / f).round().max(2.0),
        (OutputKind::Gif, None) => GIF_FPS,
        (_, Some(f)) => f,
        (_, None) => anim.fps.clamp(1.0, MAX_FPS),
    }
}

/// Checks everything, then writes every output of `outputs` (kinds by extension, see
/// [`OUTPUT_KINDS`]). Nothing is written when any path or option is invalid; each output is
/// written atomically; outputs written before a later one fails stay in place.
pub fn write_outputs(
    anim: &Animation,
    outputs: &[PathBuf],
    opts: &RenderOptions,
    progress: &dyn Progress,
) -> Result<()> {
    opts.validate()?;
    let origin = Path::new("animation");
    // No NaN or infinity reaches any output (CSV, glTF, pictures, JSON).
    crate::finite::check_serialize("animation", anim)?;
    anim.validate(origin)?;
    sample::check_times(anim, origin)?;
    let mut shot = match opts.animation_fps {
        Some(f) if f != anim.fps => std::borrow::Cow::Owned(
            crate::animation::resample::resample(anim, f)
                .map_err(|e| e.renamed("fps", "render.animation_fps"))?,
        ),
        _ => std::borrow::Cow::Borrowed(anim),
    };
    if let Some(s) = opts.start_frame {
        if s != shot.start_frame {
            shot.to_mut().start_frame = s;
        }
    }
    let anim: &Animation = &shot;
    let plan = plan_outputs(outputs)?;
    check_written(outputs, opts, &[])?;
    for o in &plan {
        let video = matches!(o.kind, OutputKind::Mp4 | OutputKind::Webm);
        if (video || o.kind == OutputKind::Gif) && opts.background == Background::None {
            return Err(Error::parameter(
                "render.background",
                format!("none (transparent) is only for PNG frames; {} has no alpha: give a frames/ output or a colour like render.background '#87ceeb'", o.path.display()),
            ));
        }
        if video {
            if opts.width % 2 == 1 || opts.height % 2 == 1 {
                return Err(Error::parameter(
                    "render.width/render.height",
                    format!(
                        "{}: {}x{} has an odd side; video (yuv420p) needs even width and height",
                        o.path.display(),
                        opts.width,
                        opts.height
                    ),
                ));
            }
            pictures::check_ffmpeg(&o.path)?;
        }
        if o.kind == OutputKind::Gif {
            if let Some(f) = opts.fps {
                if f > MAX_GIF_FPS {
                    return Err(Error::parameter(
                        "render.fps",
                        format!("{f}: a GIF plays at most {MAX_GIF_FPS} frames per second (delays are whole 1/100 s, browsers slow shorter ones); give render.fps 50 or less"),
                    ));
                }
            }
        }
        if matches!(
            o.kind,
            OutputKind::Gif | OutputKind::Directory | OutputKind::Mp4 | OutputKind::Webm
        ) {
            let fps = picture_fps(anim, o.kind, opts);
            let n = sample::output_count(anim, fps);
            let pixels = n as u64 * opts.width as u64 * opts.height as u64;
            if n <= MAX_FRAMES && pixels > crate::limits::MAX_PICTURE_PIXELS {
                return Err(Error::parameter(
                    "render.width/render.height",
                    format!(
                        "{}: {n} frames of {}x{} is {:.1e} pixels, more than the {:.0e} limit (about {} GB uncompressed); lower render.width/render.height or render.fps",
                        o.path.display(),
                        opts.width,
                        opts.height,
                        pixels as f64,
                        crate::limits::MAX_PICTURE_PIXELS as f64,
                        crate::limits::MAX_PICTURE_PIXELS / 1_000_000_000
                    ),
                ));
            }
            if n > MAX_FRAMES {
                return Err(Error::parameter(
                    "render.fps",
                    format!(
                        "{}: {n} frames at {fps} fps is more than {MAX_FRAMES}; lower render.fps",
                        o.path.display()
                    ),
                ));
            }
        }
    }
    if let Some(p) = &opts.path_out {
        OutputKind::for_flag("render.path_out", p, &[OutputKind::Json])?;
        crate::io::check_output_dir("render.path_out", p)?;
        let id = crate::io::output_identity(p);
        if plan
            .iter()
            .any(|o| crate::io::output_identity(&o.path) == id)
        {
            return Err(Error::parameter(
                "render.path_out",
                format!(
                    "{}: is also an output; the path needs a file of its own",
                    p.display()
                ),
            ));
        }
    }
    let wingspan_m = opts.wingspan_m.unwrap_or(anim.wingspan_m);
    // The user's birds are checked before any output is written (exit 2 with the reason).
    let assets = bird_model::load_all(
        &opts.bird_model,
        &opts.joint_map,
        crate::wingbeat::WingbeatOptions::for_animation(anim).species,
    )?;
    let scene = gltf::SceneOptions {
        keys: opts.keys,
        tolerance: keys::Tolerance::default(),
        clips: opts.clips,
        assets,
        start_frame: anim.start_frame,
        frame_rate: None,
        crowd_pose_error_deg: opts.crowd_pose_error,
        one_skin: match opts.gltf_mode {
            Some(m) => m == GltfMode::Flock,
            None => anim.birds >= crowd::INSTANCER_FROM,
        },
        size_variation: opts.size_variation.unwrap_or_else(|| {
            bird::default_size_variation(
                crate::wingbeat::WingbeatOptions::for_animation(anim).species,
            )
        }),
    };
    // The 3-D outputs' samples: the animation (a loop with its closing frame), at
    // `subframes` samples a frame.
    let scene_anim = || -> Result<(std::borrow::Cow<'_, Animation>, gltf::SceneOptions)> {
        let closed = gltf::closed_loop(anim);
        if opts.subframes <= 1 {
            return Ok((closed, scene.clone()));
        }
        // A loop's closing frame is part of the samples already: resampled as an open
        // stretch, then marked as the loop it is (its last sample closes it).
        let mut open = closed.into_owned();
        open.looped = false;
        let mut fine =
            crate::animation::resample::resample(&open, anim.fps * f64::from(opts.subframes))
                .map_err(|e| e.renamed("fps", "render.subframes"))?;
        fine.looped = anim.looped;
        let mut sc = scene.clone();
        sc.frame_rate = Some(anim.fps);
        Ok((std::borrow::Cow::Owned(fine), sc))
    };
    let threads = pictures::worker_count(opts.threads);
    for o in &plan {
        crate::io::set_current_output(&o.path);
        match o.kind {
            OutputKind::Json => {
                // A copy only when the file differs from the animation in memory.
                let same_axes = opts.units.is_default() && opts.up.is_default();
                let a = if wingspan_m == anim.wingspan_m && same_axes {
                    std::borrow::Cow::Borrowed(anim)
                } else {
                    let mut a = anim.clone();
                    a.wingspan_m = wingspan_m;
                    if !same_axes {
                        a = a.in_axes(opts.units, opts.up);
                    }
                    std::borrow::Cow::Owned(a)
                };
                if opts.binary_frames {
                    write_binary_frames(a.as_ref(), &o.path, opts.pretty)?;
                } else {
                    crate::io::write_json_atomic_as(&o.path, a.as_ref(), opts.pretty)?;
                }
            }
            OutputKind::Csv => {
                // Streamed into the temporary file (not built in memory: up to 1.4 GB).
                let mut f = AtomicFile::create(&o.path)?;
                table::write_csv_in(anim, opts.units, opts.up, wingspan_m, f.writer())
                    .map_err(|e| Error::io(&o.path, e))?;
                f.commit()?;
            }
            OutputKind::Glb => {
                progress.start("glb", 1);
                let (a, sc) = scene_anim()?;
                // The binary chunk is written to a scratch file beside the output as it is made,
                // then copied after the JSON chunk (never held whole in memory); the scratch file
                // is removed in any case.
                let mut f = AtomicFile::create(&o.path)?;
                let mut spill = AtomicFile::create(&o.path)?;
                let spill_path = spill.temp_path().to_path_buf();
                gltf::write_glb_spilled(
                    &a,
                    wingspan_m,
                    &sc,
                    spill.writer(),
                    &spill_path,
                    f.writer(),
                )
                .map_err(|e| Error::io(&o.path, e))??;
                drop(spill);
                f.commit()?;
                progress.advance(1);
                progress.finish();
            }
            OutputKind::Usda => {
                progress.start("usda", 1);
                // Streamed into the temporary file (a 100-bird minute is tens of MB of text).
                let mut f = AtomicFile::create(&o.path)?;
                let (a, sc) = scene_anim()?;
                let instancer = match opts.usd_mode {
                    Some(m) => m == UsdMode::Instancer,
                    None => anim.birds >= crowd::INSTANCER_FROM,
                };
                if instancer {
                    crowd::write_usda_instancer(&a, wingspan_m, &sc, f.writer())
                } else {
                    usd::write_usda(&a, wingspan_m, &sc, f.writer())
                }
                .map_err(|e| Error::io(&o.path, e))?;
                f.commit()?;
                progress.advance(1);
                progress.finish();
            }
            OutputKind::Gif => {
                let film = Film::with_options(anim, picture_fps(anim, o.kind, opts), opts);
                pictures::write_gif(&film, &o.path, threads, progress)?;
            }
            OutputKind::Directory => {
                let film = Film::with_options(anim, picture_fps(anim, o.kind, opts), opts);
                pictures::write_png_dir(&film, &o.path, anim.start_frame, threads, progress)?;
            }
            OutputKind::Mp4 | OutputKind::Webm => {
                let film = Film::with_options(anim, picture_fps(anim, o.kind, opts), opts);
                let codec = if o.kind == OutputKind::Mp4 {
                    pictures::VideoCodec::H264
                } else {
                    pictures::VideoCodec::Vp9
                };
                pictures::write_video(&film, &o.path, codec, threads, progress)?;
            }
            OutputKind::Png | OutputKind::Svg | OutputKind::Html => {
                return Err(Error::Internal(format!(
                    "{}: not an animation output",
                    o.path.display()
                )));
            }
        }
    }
    if let Some(p) = &opts.path_out {
        let scale = match opts.units {
            crate::animation::axes::Units::Wingspans => 1.0,
            crate::animation::axes::Units::M => wingspan_m,
        };
        let points: Vec<[f64; 3]> = anim
            .flown_path()
            .into_iter()
            .map(|q| q.map(|v| v * scale))
            .collect();
        let doc = serde_json::json!({
            "units": opts.units.to_string(),
            "points": points,
        });
        crate::io::write_json_atomic_as(p, &doc, opts.pretty)?;
    }
    Ok(())
}

/// Writes `anim` as the animation file `target` whose frames are in the binary file beside it
/// ([`crate::animation::binary::frames_path`]); both are moved into place together (in the open
/// [`crate::io::OutputBatch`], or the frames file just before the animation file).
fn write_binary_frames(anim: &Animation, target: &Path, pretty: bool) -> Result<()> {
    use crate::animation::binary;
    let frames_target = binary::frames_path(target);
    if std::fs::metadata(&frames_target).is_ok_and(|m| !m.is_file()) {
        return Err(Error::format(
            &frames_target,
            format!(
                "exists and is not a regular file; the frames of {} go there: remove it or choose another name",
                target.display()
            ),
        ));
    }
    let mut f = AtomicFile::create(&frames_target)?;
    let ff = binary::write_frames(anim, f.writer(), &frames_target)
        .map_err(|e| Error::io(&frames_target, e))?;
    let mut header = anim.with_frames(Vec::new());
    header.frames_file = Some(ff);
    f.commit()?;
    crate::io::write_json_atomic_as(target, &header, pretty)
}

/// Checks the files a run writes besides its outputs against each other and against its inputs,
/// before any work: with `opts.binary_frames`, no two `.json` outputs may share a frames file
/// (`a.json` and `a.JSON` both keep their frames in `a.frames`), nor may one be another output;
/// and no file written ([`written_files`]) may be one of `inputs` (an option path such as
/// `course.path` with the file it reads), which it would replace. The same file is found by
/// device and inode where it exists, so `./p.json`, `d/../p.json` and a link to it are one.
pub fn check_written(
    outputs: &[PathBuf],
    opts: &RenderOptions,
    inputs: &[(&str, &Path)],
) -> Result<()> {
    if opts.binary_frames {
        let mut seen: Vec<(PathBuf, &PathBuf)> = Vec::new();
        for p in outputs {
            if !p
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"))
            {
                continue;
            }
            let frames = crate::animation::binary::frames_path(p);
            let id = crate::io::output_identity(&frames);
            if let Some((_, first)) = seen.iter().find(|(f, _)| *f == id) {
                return Err(Error::parameter(
                    "output",
                    format!(
                        "{}: its frames would go to {}, as those of {} do (render.binary_frames); give the two .json outputs names that differ before the extension",
                        p.display(),
                        frames.display(),
                        first.display()
                    ),
                ));
            }
            if let Some(o) = outputs.iter().find(|o| crate::io::output_identity(o) == id) {
                return Err(Error::parameter(
                    "output",
                    format!(
                        "{}: is also where the frames of {} go (render.binary_frames); give it another name",
                        o.display(),
                        p.display()
                    ),
                ));
            }
            seen.push((id, p));
        }
    }
    for (flag, input) in inputs {
        for w in written_files(outputs, opts) {
            if crate::io::same_file(input, &w) {
                let (name, what) = if opts.path_out.as_ref() == Some(&w) {
                    ("render.path_out", "the flown path")
                } else if outputs.contains(&w) {
                    ("output", "an output")
                } else {
                    ("output", "a frames file (render.binary_frames)")
                };
                return Err(Error::parameter(
                    name,
                    format!(
                        "{}: is the file {flag} reads ({}); writing {what} there would replace it: give another name",
                        w.display(),
                        input.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Every file [`write_outputs`] writes for `outputs` with `opts`: the outputs, then each `.json`
/// output's frames file when `opts.binary_frames`, then the flown path.
pub fn written_files(outputs: &[PathBuf], opts: &RenderOptions) -> Vec<PathBuf> {
    let frames = outputs
        .iter()
        .filter(|p| {
            opts.binary_frames
                && p.extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        })
        .map(|p| crate::animation::binary::frames_path(p));
    outputs
        .iter()
        .cloned()
        .chain(frames)
        .chain(opts.path_out.iter().cloned())
        .collect()
}
