//! Reading annotated frames (docs/formats.md §4.1) from every supported format into one type.
//!
//! Takes a file or directory of annotations in pixels: the native JSON, a long CSV
//! (`frame,bird,x,y`), a DLTdv digitizer CSV (`ptN_camM_X/Y`) or Labelme JSON (a file or a directory
//! of files). The format is detected by content ([`detect`]), never by extension. Gives
//! [`Annotations`]: every frame with its birds in the image (pixels, y down) and in wingspans along
//! the flight direction (`lateral` to the right of it, `forward` along it), and a stable bird id per
//! bird across frames — the annotation's own ids, or, when the format carries none, §4 step 1's
//! order by lateral position in the first frame, with later frames matched by an optimal assignment
//! after aligning the leaders ([`assign_ids`]).
//!
//! Heading (docs/formats.md §2): θ clockwise from image-up, so the flight direction in the image (x right,
//! y down) is d = (sin θ, −cos θ) and the right-hand side of the flight is r = (cos θ, sin θ).
//! With the scale s = `wingspan_px`, a pixel point p maps to `lateral = p·r / s`,
//! `forward = p·d / s` (wingspans).

mod csv_formats;
mod labelme;
mod native;
mod npz;
mod sleap_h5;
pub mod synth;
mod trackers;

use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Flight direction of the flock in the image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Heading {
    /// Toward smaller pixel y (the top of the image), 0°.
    Up,
    /// Toward larger pixel x, 90°.
    Right,
    /// Toward larger pixel y, 180°.
    Down,
    /// Toward smaller pixel x, 270°.
    Left,
    /// Degrees clockwise from image-up.
    Degrees(f64),
}

impl Heading {
    /// The heading in degrees clockwise from image-up.
    pub fn degrees(self) -> f64 {
        match self {
            Heading::Up => 0.0,
            Heading::Right => 90.0,
            Heading::Down => 180.0,
            Heading::Left => 270.0,
            Heading::Degrees(d) => d,
        }
    }

    /// Parses `up|down|left|right` or a number of degrees; `None` with a message otherwise.
    pub fn parse(s: &str) -> std::result::Result<Heading, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "up" => Ok(Heading::Up),
            "down" => Ok(Heading::Down),
            "left" => Ok(Heading::Left),
            "right" => Ok(Heading::Right),
            t => match t.trim_end_matches("deg").trim().parse::<f64>() {
                Ok(d) if d.is_finite() => Ok(Heading::Degrees(d)),
                _ => Err(format!(
                    "`{s}` is not a heading; use up, down, left, right or degrees clockwise from image-up (e.g. 30)"
                )),
            },
        }
    }
}

impl FromStr for Heading {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Heading::parse(s)
    }
}

/// Where pixel y = 0 is in a CSV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum YOrigin {
    /// y = 0 is the top edge and y grows downward (image convention; long CSV default).
    Top,
    /// y = 0 is the bottom edge and y grows upward (DLTdv's convention and default).
    Bottom,
}

impl FromStr for YOrigin {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "top" => Ok(YOrigin::Top),
            "bottom" => Ok(YOrigin::Bottom),
            _ => Err(format!("`{s}` is not a y origin; use top or bottom")),
        }
    }
}

/// Options of [`read`]; each `Some` overrides what the file says.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReadOptions {
    /// Flight direction in the image (default: the file's, else up).
    pub heading: Option<Heading>,
    /// Wingspan in pixels, for every frame (default: the file's per-frame or per-file value).
    pub wingspan_px: Option<f64>,
    /// Origin of pixel y in CSV files (default: top for long CSV, bottom for DLTdv).
    pub y_origin: Option<YOrigin>,
    /// The body part (DeepLabCut) or node (SLEAP) giving each bird's position (default: the
    /// first the file lists); an error for other formats.
    pub bodypart: Option<String>,
}

/// The input formats of docs/formats.md §4.1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// `{"frames": [{"birds": [[x, y], ...]}]}`.
    Native,
    /// CSV with header `frame,bird,x,y` (`bird` optional).
    LongCsv,
    /// DLTdv digitizer CSV, `pt1_cam1_X,pt1_cam1_Y,...`, one row per frame.
    Dltdv,
    /// One Labelme JSON file (`point` shapes are birds).
    Labelme,
    /// A directory of Labelme JSON files, one per frame.
    LabelmeDir,
    /// SLEAP analysis CSV (`track,frame_idx,...,NODE.x,NODE.y,...`).
    Sleap,
    /// DeepLabCut multi-animal CSV (header rows scorer, individuals, bodyparts, coords).
    Dlc,
    /// MOTChallenge / CVAT MOT text (`frame,id,left,top,width,height,...`, no header).
    Mot,
    /// idtracker.ai `trajectories.csv` (`time,x1,y1,x2,y2,...`).
    #[serde(rename = "idtracker")]
    IdTracker,
    /// TRex's `.npz` archives, one per individual (`VIDEO_fish0.npz`, ...).
    Trex,
    /// SLEAP analysis HDF5 (`tracks`, `track_names`, `node_names`), told by its signature.
    #[serde(rename = "sleap_h5")]
    SleapH5,
}

impl Format {
    /// Human name of the format.
    pub fn name(self) -> &'static str {
        match self {
            Format::Native => "native JSON",
            Format::LongCsv => "long CSV",
            Format::Dltdv => "DLTdv CSV",
            Format::Labelme => "Labelme JSON",
            Format::LabelmeDir => "Labelme directory",
            Format::Sleap => "SLEAP analysis CSV",
            Format::Dlc => "DeepLabCut CSV",
            Format::Mot => "MOT text",
            Format::IdTracker => "idtracker.ai CSV",
            Format::Trex => "TRex .npz",
            Format::SleapH5 => "SLEAP analysis HDF5",
        }
    }
}

/// One marked bird of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MarkedBird {
    /// Bird id, stable across frames.
    pub id: usize,
    /// Image x, pixels (right).
    pub px: f64,
    /// Image y, pixels, as in the file (downward from the top edge, or upward from the bottom edge
    /// for DLTdv and `read.y_origin` bottom).
    pub py: f64,
    /// Offset to the right of the flight direction from the image origin, wingspans.
    pub lateral: f64,
    /// Offset along the flight direction from the image origin, wingspans.
    pub forward: f64,
    /// Height (upward), wingspans, for 3-D files (DLTdv `xyzpts`, a long CSV with `z`, native
    /// JSON with `"z"`); `None` for image annotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
}

/// One annotated frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnnotatedFrame {
    /// Frame index (from the file, else the position in it).
    pub index: i64,
    /// Image file name, when the format gives one.
    pub image: Option<String>,
    /// Flight direction, degrees clockwise from image-up.
    pub heading_deg: f64,
    /// Scale, pixels per wingspan.
    pub wingspan_px: f64,
    /// The marked birds, in file order.
    pub birds: Vec<MarkedBird>,
}

/// Annotations of one movie, in any input format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Annotations {
    /// The file or directory read.
    pub path: PathBuf,
    /// Free text describing the footage (`source`), or the file name.
    pub source: String,
    /// Detected input format.
    pub format: Format,
    /// True when the file carried bird ids; false when they were assigned by [`assign_ids`].
    pub ids_given: bool,
    /// True when pixel y grew upward as read (DLTdv, `read.y_origin` bottom).
    #[serde(default)]
    pub y_up: bool,
    /// Frames per second of the footage when the file gives it (native JSON's top-level `fps`):
    /// frame times are frame index / fps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f64>,
    /// Frames in file order.
    pub frames: Vec<AnnotatedFrame>,
}

impl Annotations {
    /// Annotations built from points in memory, checked and resolved exactly as a file of the
    /// native format would be (docs/formats.md §4.1): `frames[k]` holds the image positions `[x, y]` of the
    /// birds marked in frame `k`, pixels, x right and y down; `heading` is the flock's flight
    /// direction in the image; `wingspan_px` the scale, pixels per wingspan. Bird ids are
    /// assigned by lateral order and matched across frames, as for a file without ids. `source`
    /// describes the footage and names the annotations in messages.
    pub fn from_points(
        source: &str,
        heading: Heading,
        wingspan_px: f64,
        frames: &[Vec<[f64; 2]>],
    ) -> Result<Annotations> {
        let path = Path::new(source);
        for (k, birds) in frames.iter().enumerate() {
            if let Some(i) = birds
                .iter()
                .position(|p| !(p[0].is_finite() && p[1].is_finite()))
            {
                return Err(Error::format(
                    path,
                    format!("frames[{k}][{i}]: not a finite number"),
                ));
            }
        }
        let raw = RawAnnotations {
            format: Format::Native,
            source: Some(source.to_string()),
            heading: Some(heading),
            wingspan_px: Some(wingspan_px),
            fps: None,
            y_up: false,
            is_csv: false,
            frames: frames
                .iter()
                .enumerate()
                .map(|(k, birds)| RawFrame {
                    index: k as i64,
                    image: None,
                    wingspan_px: None,
                    at: format!("frames[{k}]"),
                    birds: birds
                        .iter()
                        .enumerate()
                        .map(|(i, p)| RawBird {
                            z: None,
                            id: None,
                            x: p[0],
                            y: p[1],
                            at: format!("frames[{k}][{i}]"),
                        })
                        .collect(),
                })
                .collect(),
        };
        finish(path, raw, &ReadOptions::default())
    }

    /// Number of distinct bird ids over all frames (N̂).
    pub fn bird_count(&self) -> usize {
        let mut ids: Vec<usize> = self
            .frames
            .iter()
            .flat_map(|f| f.birds.iter().map(|b| b.id))
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    }
}

/// A bird as parsed, before scale, heading and ids are resolved.
#[derive(Debug, Clone)]
pub(crate) struct RawBird {
    pub id: Option<usize>,
    pub x: f64,
    pub y: f64,
    /// Height in the file's units (3-D files: DLTdv xyzpts, long CSV with `z`, native `"z"`).
    pub z: Option<f64>,
    /// Where it came from, for messages (`row 12`, `frames[3].birds[2]`, `shapes[4]`).
    pub at: String,
}

/// A frame as parsed.
#[derive(Debug, Clone)]
pub(crate) struct RawFrame {
    pub index: i64,
    pub image: Option<String>,
    pub wingspan_px: Option<f64>,
    /// Where the frame's scale came from, for messages.
    pub at: String,
    pub birds: Vec<RawBird>,
}

/// A whole file as parsed.
#[derive(Debug, Clone)]
pub(crate) struct RawAnnotations {
    pub format: Format,
    pub source: Option<String>,
    pub heading: Option<Heading>,
    pub wingspan_px: Option<f64>,
    /// Frames per second of the footage (native JSON's top-level `fps`).
    pub fps: Option<f64>,
    /// Whether pixel y grows upward in the file (before any `read.y_origin`).
    pub y_up: bool,
    /// Whether `read.y_origin` applies (CSV formats).
    pub is_csv: bool,
    pub frames: Vec<RawFrame>,
}

/// What a path holds, judged by content.
pub fn detect(path: &Path) -> Result<Format> {
    if (path.is_dir() && npz::dir_has_npz(path)) || (path.is_file() && npz::is_zip(path)) {
        return Ok(Format::Trex);
    }
    if path.is_dir() {
        return Ok(Format::LabelmeDir);
    }
    if sleap_h5::file_is_hdf5(path) {
        return Ok(Format::SleapH5);
    }
    let text = crate::io::read_text(path)?;
    detect_text(path, &text)
}

fn detect_text(path: &Path, text: &str) -> Result<Format> {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.is_empty() {
        return Err(Error::format(
            path,
            "file is empty; expected annotations (native JSON, long CSV, DLTdv CSV or Labelme JSON)",
        ));
    }
    if t.starts_with('{') || t.starts_with('[') {
        // Only the top-level keys matter here: skip the values instead of building them in
        // memory (a parsed JSON tree takes about ten times the text).
        #[derive(Deserialize)]
        struct TopLevel {
            #[serde(default)]
            format: Option<serde_json::Value>,
            #[serde(default)]
            shapes: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            frames: Option<serde::de::IgnoredAny>,
        }
        if t.starts_with('[') {
            crate::io::parse_json::<serde::de::IgnoredAny>(path, t)?;
            return Err(Error::format(
                path,
                "top level: expected a JSON object with \"frames\" (native) or \"shapes\" (Labelme)",
            ));
        }
        let top: TopLevel = crate::io::parse_json(path, t)?;
        if top.format.as_ref().and_then(|f| f.as_str()) == Some(crate::sniff::PARAMS_FORMAT) {
            return Err(Error::format(
                path,
                "this is a params file written by `formation extract`, not annotations",
            ));
        }
        if top.format.as_ref().and_then(|f| f.as_str()) == Some(crate::sniff::ANIMATION_FORMAT) {
            return Err(Error::format(
                path,
                "this is an animation file, not annotations: `formation render`, `formation plot` and `formation report` read it",
            ));
        }
        if top.shapes.is_some() {
            return Ok(Format::Labelme);
        }
        if top.frames.is_some() {
            native::check_counts(path, t)?;
            return Ok(Format::Native);
        }
        // Another of formation's own files: say which command reads it.
        let kind = crate::sniff::text_kind(t).unwrap_or(crate::sniff::Kind::Unknown);
        let reader = match kind {
            crate::sniff::Kind::Shape => {
                Some("`formation power` and `formation plot power` read it")
            }
            crate::sniff::Kind::Target => Some("`formation solve` reads it"),
            _ => None,
        };
        if let Some(reader) = reader {
            return Err(Error::format(
                path,
                format!(
                    "this is {}, not annotations: {reader}; annotations have \"frames\" (native) or \"shapes\" (Labelme)",
                    kind.describe()
                ),
            ));
        }
        return Err(Error::format(
            path,
            "top level: no \"frames\" (native annotations) or \"shapes\" (Labelme) field",
        ));
    }
    if let Some(f) = trackers::detect(t) {
        return Ok(f);
    }
    csv_formats::detect_csv(path, t)
}

/// Reads annotations from `path` (a file in any docs/formats.md §4.1 format, or a Labelme directory),
/// resolving heading, scale and bird ids.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Annotations> {
    if (path.is_dir() && npz::dir_has_npz(path)) || (path.is_file() && npz::is_zip(path)) {
        if opts.bodypart.is_some() {
            return Err(Error::parameter(
                "read.bodypart",
                format!(
                    "{}: is TRex's tracks, which have one point per individual; a body part is chosen only in SLEAP and DeepLabCut files",
                    path.display()
                ),
            ));
        }
        let raw = npz::read(path)?;
        return finish(path, raw, opts);
    }
    if path.is_dir() {
        if opts.bodypart.is_some() {
            return Err(Error::parameter(
                "read.bodypart",
                format!(
                    "{}: is a directory of Labelme files, which have one point per bird; a body part is chosen only in SLEAP and DeepLabCut files",
                    path.display()
                ),
            ));
        }
        let raw = labelme::read_dir(path)?;
        return finish(path, raw, opts);
    }
    if sleap_h5::file_is_hdf5(path) {
        return parse_sleap_h5_bytes(path, crate::io::read_bytes(path)?, opts);
    }
    let text = crate::io::read_text(path)?;
    parse_str(path, &text, opts)
}

/// Parses one TRex `.npz` archive (one individual, bird 0) from bytes as if read from `path`
/// (which only names it in messages), checked as [`read`] checks a file.
pub fn parse_trex_bytes(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Annotations> {
    let raw = npz::read_one(path, bytes)?;
    finish(path, raw, opts)
}

/// Parses SLEAP's analysis HDF5 from bytes as if read from `path` (which only names the file in
/// messages); bytes without the HDF5 signature are refused.
pub fn parse_sleap_h5_bytes(
    path: &Path,
    bytes: Vec<u8>,
    opts: &ReadOptions,
) -> Result<Annotations> {
    if !sleap_h5::is_hdf5(&bytes) {
        return Err(Error::format(path, "not an HDF5 file (no HDF5 signature)"));
    }
    let raw = sleap_h5::parse(path, bytes, opts.bodypart.as_deref())?;
    finish(path, raw, opts)
}

/// Parses annotation text as if read from `path` (which only names the file in messages).
pub fn parse_str(path: &Path, text: &str, opts: &ReadOptions) -> Result<Annotations> {
    let format = detect_text(path, text)?;
    if opts.bodypart.is_some() && !matches!(format, Format::Sleap | Format::Dlc) {
        return Err(Error::parameter(
            "read.bodypart",
            format!(
                "{}: is {}, which has one point per bird; a body part is chosen only in SLEAP and DeepLabCut files",
                path.display(),
                format.name()
            ),
        ));
    }
    let t = text.trim_start_matches('\u{feff}');
    let raw = match format {
        Format::Native => native::parse(path, t)?,
        Format::Labelme => labelme::parse_file(path, t)?,
        Format::LongCsv | Format::Dltdv => csv_formats::parse(path, t, format)?,
        Format::Sleap | Format::Dlc => trackers::parse(path, t, format, opts.bodypart.as_deref())?,
        Format::Mot | Format::IdTracker => trackers::parse(path, t, format, None)?,
        Format::LabelmeDir | Format::Trex | Format::SleapH5 => {
            return Err(Error::Internal(format!(
                "{} detected for text",
                format.name()
            )))
        }
    };
    finish(path, raw, opts)
}

/// Largest wingspan in pixels: wider than any image (a 1e6-px bird in an 8K frame is an error).
const MAX_WINGSPAN_PX: f64 = 1e6;

fn check_scale(path: &Path, at: &str, v: f64) -> Result<f64> {
    if !v.is_finite() || v <= 0.0 || v > MAX_WINGSPAN_PX {
        return Err(Error::format(
            path,
            format!("{at}: wingspan_px must be a positive number of pixels, at most {MAX_WINGSPAN_PX}, got {v}"),
        ));
    }
    Ok(v)
}

/// Resolves options, validates every frame and assigns ids.
fn finish(path: &Path, raw: RawAnnotations, opts: &ReadOptions) -> Result<Annotations> {
    if raw.frames.is_empty() {
        return Err(Error::format(path, "no frames with marked birds"));
    }
    use crate::limits::{MAX_ANNOTATED_BIRDS, MAX_ANNOTATED_FRAMES};
    if raw.frames.len() > MAX_ANNOTATED_FRAMES {
        return Err(Error::format(
            path,
            format!(
                "{} annotated frames, at most {MAX_ANNOTATED_FRAMES}; annotate a subset (a few dozen frames are plenty)",
                raw.frames.len()
            ),
        ));
    }
    if let Some(f) = raw
        .frames
        .iter()
        .find(|f| f.birds.len() > MAX_ANNOTATED_BIRDS)
    {
        return Err(Error::format(
            path,
            format!(
                "frame {}: {} birds marked, at most {MAX_ANNOTATED_BIRDS} per frame",
                f.index,
                f.birds.len()
            ),
        ));
    }
    if let Some(w) = opts.wingspan_px {
        // A wingspan wider than any image (1e308 px) made every bird coincide in wingspans.
        if !w.is_finite() || w <= 0.0 || w > MAX_WINGSPAN_PX {
            return Err(Error::parameter(
                "read.wingspan_px",
                format!("must be a positive number of pixels, at most {MAX_WINGSPAN_PX}, got {w}"),
            ));
        }
    }
    if let Some(Heading::Degrees(d)) = opts.heading {
        if !d.is_finite() {
            return Err(Error::parameter("read.heading", "must be a finite angle"));
        }
    }
    let y_up = match (raw.is_csv, opts.y_origin) {
        (true, Some(o)) => o == YOrigin::Bottom,
        _ => raw.y_up,
    };
    let three_d = raw
        .frames
        .first()
        .and_then(|f| f.birds.first())
        .is_some_and(|b| b.z.is_some());
    for f in &raw.frames {
        if let Some(b) = f.birds.iter().find(|b| b.z.is_some() != three_d) {
            return Err(Error::format(
                path,
                format!(
                    "frame {}, {}: {} a height (z) while the file's first bird {}; give every bird a z or none",
                    f.index,
                    b.at,
                    if three_d { "has no" } else { "has" },
                    if three_d { "has one" } else { "has none" }
                ),
            ));
        }
    }
    let heading = match opts.heading.or(raw.heading) {
        Some(h) => h,
        // 3-D points lie in the given horizontal plane; the flight direction is their motion.
        None if three_d => heading_from_motion(&raw, y_up).unwrap_or(Heading::Up),
        None => Heading::Up,
    };
    let theta = heading.degrees().to_radians();
    let (d, r) = ((theta.sin(), -theta.cos()), (theta.cos(), theta.sin()));
    let file_scale = match raw.wingspan_px {
        Some(w) => Some(check_scale(path, "wingspan_px", w)?),
        None => None,
    };
    let ids_given = raw
        .frames
        .iter()
        .any(|f| f.birds.iter().any(|b| b.id.is_some()));
    let mut frames = Vec::with_capacity(raw.frames.len());
    for f in raw.frames {
        let scale = match (opts.wingspan_px, f.wingspan_px, file_scale) {
            (Some(w), _, _) => w,
            (None, Some(w), _) => check_scale(path, &f.at, w)?,
            (None, None, Some(w)) => w,
            (None, None, None) => {
                return Err(Error::format(
                    path,
                    format!(
                        "frame {}: no scale; give read.wingspan_px PIXELS, or \"wingspan_px\" in the file (per file or per frame; see docs/annotating.md)",
                        f.index
                    ),
                ))
            }
        };
        if f.birds.len() < 3 {
            return Err(Error::format(
                path,
                format!(
                    "frame {}: {} bird(s) marked, a line formation needs at least 3",
                    f.index,
                    f.birds.len()
                ),
            ));
        }
        if ids_given {
            if let Some(b) = f.birds.iter().find(|b| b.id.is_none()) {
                return Err(Error::format(
                    path,
                    format!(
                        "frame {}, {}: bird has no id while other birds have one; give every bird an id or none",
                        f.index, b.at
                    ),
                ));
            }
        }
        let mut birds = Vec::with_capacity(f.birds.len());
        for b in &f.birds {
            // Pixel y measured downward (a y-up file's y negated: only differences matter).
            let py = if y_up { -b.y } else { b.y };
            birds.push(MarkedBird {
                id: b.id.unwrap_or(usize::MAX),
                px: b.x,
                py: b.y,
                lateral: (b.x * r.0 + py * r.1) / scale,
                forward: (b.x * d.0 + py * d.1) / scale,
                height: b.z.map(|z| z / scale),
            });
        }
        if let Some((b, _)) = f
            .birds
            .iter()
            .zip(&birds)
            .find(|(_, m)| m.lateral.abs() > 1e6 || m.forward.abs() > 1e6)
        {
            return Err(Error::format(
                path,
                format!(
                    "frame {}, {}: ({}, {}) px is more than a million wingspans ({scale} px each) from the image origin; check the coordinates and wingspan_px",
                    f.index, b.at, b.x, b.y
                ),
            ));
        }
        // Duplicate marks (same pixel, or the same id twice) cannot be two birds.
        for i in 0..birds.len() {
            for j in (i + 1)..birds.len() {
                let (a, c) = (&f.birds[i], &f.birds[j]);
                if a.x == c.x && a.y == c.y {
                    return Err(Error::format(
                        path,
                        format!(
                            "frame {}: {} and {} are the same point ({}, {}); remove the duplicate mark",
                            f.index, a.at, c.at, a.x, a.y
                        ),
                    ));
                }
                if a.id.is_some() && a.id == c.id {
                    return Err(Error::format(
                        path,
                        format!(
                            "frame {}: bird id {} is marked twice ({} and {})",
                            f.index,
                            a.id.unwrap_or(0),
                            a.at,
                            c.at
                        ),
                    ));
                }
            }
        }
        frames.push(AnnotatedFrame {
            index: f.index,
            image: f.image,
            heading_deg: heading.degrees(),
            wingspan_px: scale,
            birds,
        });
    }
    if !ids_given {
        assign_ids(&mut frames);
    }
    let source = raw.source.unwrap_or_else(|| {
        path.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    Ok(Annotations {
        path: path.to_path_buf(),
        source,
        format: raw.format,
        ids_given,
        y_up,
        fps: raw.fps,
        frames,
    })
}

/// Flight direction of 3-D points from their motion: the mean displacement, first frame to
/// last, of the ids in both (x right, y upward when `y_up`); `None` without ids, with
/// one frame or without motion.
fn heading_from_motion(raw: &RawAnnotations, y_up: bool) -> Option<Heading> {
    let (first, last) = (raw.frames.first()?, raw.frames.last()?);
    let (mut dx, mut dy, mut n) = (0.0, 0.0, 0usize);
    for b in &first.birds {
        let Some(id) = b.id else { continue };
        if let Some(c) = last.birds.iter().find(|c| c.id == Some(id)) {
            dx += c.x - b.x;
            dy += c.y - b.y;
            n += 1;
        }
    }
    if n == 0 || (dx == 0.0 && dy == 0.0) {
        return None;
    }
    // Pixel y downward: a y-up file's y negated.
    let down = if y_up { -dy } else { dy };
    let deg = dx.atan2(-down).to_degrees();
    Some(Heading::Degrees(if deg < 0.0 { deg + 360.0 } else { deg }))
}

/// Index of the front-most bird (largest `forward`; ties to the first).
pub(crate) fn front_most(birds: &[MarkedBird]) -> usize {
    let mut best = 0;
    for (i, b) in birds.iter().enumerate() {
        if b.forward > birds[best].forward {
            best = i;
        }
    }
    best
}

/// Gives ids to birds of a movie whose format carries none.
///
/// Frame 0 follows §4 step 1: birds sorted by lateral position (left to right of the flight
/// direction) get ids 0, 1, …. Every later frame is matched to the last known positions of the
/// ids, both expressed relative to their frame's leader (front-most bird), by the assignment that
/// minimises the sum of squared distances (Hungarian algorithm). Birds left over when a frame has
/// more birds than ids seen so far get new ids in lateral order.
pub fn assign_ids(frames: &mut [AnnotatedFrame]) {
    // Last known leader-relative position of every id.
    let mut known: Vec<(f64, f64)> = Vec::new();
    for (k, f) in frames.iter_mut().enumerate() {
        let n = f.birds.len();
        if n == 0 {
            continue;
        }
        let lead = front_most(&f.birds);
        let (l0, f0) = (f.birds[lead].lateral, f.birds[lead].forward);
        let rel: Vec<(f64, f64)> = f
            .birds
            .iter()
            .map(|b| (b.lateral - l0, b.forward - f0))
            .collect();
        let mut ids = vec![usize::MAX; n];
        if k > 0 && !known.is_empty() {
            let m = known.len();
            let cost = |i: usize, j: usize| {
                let (a, b) = (rel[i], known[j]);
                (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)
            };
            if n <= m {
                let assign = hungarian(n, m, cost);
                for (i, &j) in assign.iter().enumerate() {
                    ids[i] = j;
                }
            } else {
                let assign = hungarian(m, n, |j, i| cost(i, j));
                for (j, &i) in assign.iter().enumerate() {
                    ids[i] = j;
                }
            }
        }
        // Unmatched birds (all of frame 0) get fresh ids, left to right.
        let mut fresh: Vec<usize> = (0..n).filter(|&i| ids[i] == usize::MAX).collect();
        fresh.sort_by(|&a, &b| {
            rel[a]
                .0
                .total_cmp(&rel[b].0)
                .then(rel[b].1.total_cmp(&rel[a].1))
        });
        for i in fresh {
            ids[i] = known.len();
            known.push(rel[i]);
        }
        for (i, b) in f.birds.iter_mut().enumerate() {
            b.id = ids[i];
            known[ids[i]] = rel[i];
        }
    }
}

/// Minimum-cost assignment of `n` rows to distinct columns among `m ≥ n` (Kuhn–Munkres with
/// potentials, O(n²m)). Returns the column of each row.
pub fn hungarian(n: usize, m: usize, cost: impl Fn(usize, usize) -> f64) -> Vec<usize> {
    // 1-based arrays as in the classical formulation; p[j] = row matched to column j.
    let mut u = vec![0.0f64; n + 1];
    let mut v = vec![0.0f64; m + 1];
    let mut p = vec![0usize; m + 1];
    let mut way = vec![0usize; m + 1];
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0usize;
        let mut minv = vec![f64::INFINITY; m + 1];
        let mut used = vec![false; m + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0usize;
            for j in 1..=m {
                if !used[j] {
                    let cur = cost(i0 - 1, j - 1) - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            if j1 == 0 {
                break; // only with non-finite costs; leaves the row unassigned
            }
            for j in 0..=m {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut ans = vec![0usize; n];
    let mut taken = vec![false; m];
    for j in 1..=m {
        if p[j] > 0 {
            ans[p[j] - 1] = j - 1;
            taken[j - 1] = true;
        }
    }
    ans
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hungarian_finds_the_optimum() {
        let c = [[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]];
        let a = hungarian(3, 3, |i, j| c[i][j]);
        let total: f64 = a.iter().enumerate().map(|(i, &j)| c[i][j]).sum();
        assert_eq!(total, 5.0);
        let mut s = a.clone();
        s.sort();
        assert_eq!(s, vec![0, 1, 2]);
    }

    #[test]
    fn hungarian_rectangular() {
        let a = hungarian(2, 4, |i, j| ((i as f64 * 2.0) - j as f64).abs());
        assert_eq!(a, vec![0, 2]);
    }

    #[test]
    fn heading_maps_flight_direction_to_forward() {
        let text = r#"{"wingspan_px": 10, "heading": "right", "frames": [{"birds": [[0,0],[10,0],[20,5]]}]}"#;
        let a = parse_str(Path::new("t.json"), text, &ReadOptions::default()).unwrap();
        let f = &a.frames[0];
        // Flying right: larger pixel x is further forward; pixel y down is the right-hand side.
        assert!((f.birds[1].forward - 1.0).abs() < 1e-12);
        assert!((f.birds[2].lateral - 0.5).abs() < 1e-12);
    }
}
