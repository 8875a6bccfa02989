//! The animation file (docs/formats.md §4.4), the plain data type that `steady`, `initiate` and `animate`
//! write and `render` reads. World frame: `x` east, `y` north, `z` up, lengths in wingspans, the
//! cruise heading is +y; headings in radians clockwise from +y; speeds in wingspans per second.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::error::{Error, Result};

pub mod axes;
pub mod binary;
pub mod clearance;
pub mod landing;
pub mod relative;
pub mod resample;
pub mod species;
pub mod stats;
pub mod wing;

pub use crate::sniff::ANIMATION_FORMAT;

/// A whole animation: stages, key shapes and per-frame state of every bird.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Animation {
    /// Always [`ANIMATION_FORMAT`].
    pub format: String,
    /// The seed that produced it.
    pub seed: u64,
    /// Frames per second.
    pub fps: f64,
    /// Wingspan of one bird in metres (used by exports in metres, e.g. glTF).
    pub wingspan_m: f64,
    /// Number of birds; every per-bird array has this length.
    pub birds: usize,
    /// Species preset used for wingbeats and drawing, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub species: Option<String>,
    /// Options the wingbeats were assigned with (`wingbeat::assign_phases`), if any; renderers
    /// rebuild the same wingbeats from them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wingbeat: Option<wing::WingbeatOptions>,
    /// Named frame ranges, `start` inclusive, `end` exclusive.
    pub stages: Vec<Stage>,
    /// Key shapes of the steady flight, formation frame.
    #[serde(default)]
    pub key_shapes: Vec<KeyShapeRecord>,
    /// Feasible range [(1 − ε) p_i, (1 + ε) P_i] of each bird's ξ in the steady flight (§5 eq. 2),
    /// when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi_ranges: Option<Vec<[f64; 2]>>,
    /// Flocks flying as several formations (skeins): each formation's birds, leader and key
    /// shapes. Absent when the whole flock is one formation (then `key_shapes` describe it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub formations: Option<Vec<FormationRecord>>,
    /// The steady flight cycles seamlessly (`steady.loop`): the frame after the last
    /// would be the first again, in the flock's moving frame (in the world too on a closed path).
    #[serde(default, skip_serializing_if = "std::ops::Not::not", rename = "loop")]
    pub looped: bool,
    /// Number of the first frame in outputs that number frames (glTF keys, USD time codes, the
    /// CSV's `frame`, PNG file names), e.g. 1001 (0 when absent).
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub start_frame: u64,
    /// Length unit of the frames' positions and speeds and of the path in this file (absent:
    /// wingspans). In memory always wingspans: [`Animation::read`] converts.
    #[serde(default, skip_serializing_if = "axes::Units::is_default")]
    pub units: axes::Units,
    /// Up axis of the frames' positions and of the path in this file (absent: `z`, the world
    /// frame). In memory always `z`: [`Animation::read`] converts.
    #[serde(default, skip_serializing_if = "axes::Up::is_default")]
    pub up: axes::Up,
    /// The path the flock follows (world frame), when it was given one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathRecord>,
    /// The bird's mass and airspeed for its power curve (savings of total power), when given;
    /// absent: the species' typical bird at each bird's own speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flight: Option<FlightSettings>,
    /// The wake model the savings (`e`, `xi`) were computed with, when recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub savings_model: Option<SavingsModel>,
    /// Reorganisations of the steady flight (leader changes, swaps, joins), in time order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<Event>,
    /// The landing's touch-downs, when the animation ends in a `landing` stage.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub landing: Option<landing::LandingRecord>,
    /// The binary file holding the frames instead of `frames` (written when
    /// `RenderOptions::binary_frames` asks; see [`binary`]). In memory always `None`: [`Animation::read`] reads the frames in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames_file: Option<binary::FramesFile>,
    /// One entry per frame (absent from a file whose frames are in `frames_file`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub frames: Vec<Frame>,
}

/// The model behind an animation's savings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavingsModel {
    /// `"planar"` (wakes in the plane, heights ignored) or `"3d"`.
    pub wake: String,
    /// Vortex core radius, wingspans (Hummel's model only).
    pub core_radius: f64,
    /// `"hummel"` (horseshoe vortices with a core; absent means this) or `"lissaman"`
    /// (elliptically loaded lifting lines, no core).
    #[serde(default = "hummel", skip_serializing_if = "is_hummel")]
    pub model: String,
}

fn hummel() -> String {
    "hummel".into()
}

fn is_hummel(s: &str) -> bool {
    s == "hummel"
}

impl std::fmt::Display for SavingsModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.model == "lissaman" {
            write!(
                f,
                "Lissaman & Shollenberger-type lifting lines, {} wake, no core",
                self.wake
            )
        } else {
            write!(
                f,
                "Hummel's model, {} wake, core {} wingspans",
                self.wake, self.core_radius
            )
        }
    }
}

/// What the power curve of an animation's birds is computed from besides the species and the
/// wingspan (`steady.flight`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FlightSettings {
    /// Body mass, kg (default: the species' typical mass scaled to the wingspan).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Airspeed, m/s, for every bird (default: each bird's own speed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_ms: Option<f64>,
}

impl FlightSettings {
    /// Whether nothing is set.
    pub fn is_empty(&self) -> bool {
        self.mass_kg.is_none() && self.speed_ms.is_none()
    }

    /// Checks what is set: a body mass a flying bird can have and an airspeed in (0, 100] m/s
    /// ([`crate::limits::check_bird_mass`], [`crate::limits::check_airspeed`]); errors name
    /// `{prefix}.mass_kg` or `{prefix}.speed_ms`.
    pub fn validate(&self, prefix: &str) -> Result<()> {
        if let Some(m) = self.mass_kg {
            crate::limits::check_bird_mass(&format!("{prefix}.mass_kg"), m)?;
        }
        if let Some(v) = self.speed_ms {
            crate::limits::check_airspeed(&format!("{prefix}.speed_ms"), v)?;
        }
        Ok(())
    }
}

/// The path an animation follows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathRecord {
    /// The file it was read from.
    pub source: String,
    /// Its control points, wingspans, world frame (a closed path without the repeated first point).
    pub points: Vec<[f64; 3]>,
    /// The path is a closed loop.
    pub closed: bool,
    /// Arc length of the flown course, wingspans.
    pub length: f64,
    /// Some turn was too tight for the flock and was widened.
    pub widened: bool,
    /// The course as flown (turns widened), wingspans, world frame: points about a wingspan
    /// apart along it (empty in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flown: Vec<[f64; 3]>,
}

/// One formation (skein) of a flock of several formations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FormationRecord {
    /// The animation's bird indices that fly in this formation, in formation order.
    pub birds: Vec<usize>,
    /// The animation's bird index of this formation's leader.
    pub leader: usize,
    /// Key shapes of this formation's steady flight (formation frame, birds in the order of
    /// `birds`).
    #[serde(default)]
    pub key_shapes: Vec<KeyShapeRecord>,
    /// Feasible ξ range of each of this formation's birds (order of `birds`), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi_ranges: Option<Vec<[f64; 2]>>,
    /// First frame of this formation's steady flight (the frame its take-off hands over at),
    /// when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steady_start: Option<usize>,
}

/// A named range of frames.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stage {
    /// `"initiation"`, `"steady"` or `"landing"` in the file.
    pub name: StageName,
    /// First frame, inclusive.
    pub start: usize,
    /// Last frame, exclusive.
    pub end: usize,
}

/// The name of a [`Stage`], written as its lowercase word. Names this version does not know (a
/// file written by a later one) are kept as they are.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(from = "String", into = "String")]
pub enum StageName {
    /// §6: from the start to the hand-over into the first key shape.
    Initiation,
    /// §5: the steady flight through the key shapes.
    Steady,
    /// After the steady flight: descent, flare, touch-down and stop (docs/landing.md).
    Landing,
    /// Any other name.
    Other(String),
}

impl StageName {
    /// The name as written in the file.
    pub fn as_str(&self) -> &str {
        match self {
            StageName::Initiation => "initiation",
            StageName::Steady => "steady",
            StageName::Landing => "landing",
            StageName::Other(s) => s,
        }
    }
}

impl From<&str> for StageName {
    fn from(s: &str) -> StageName {
        match s {
            "initiation" => StageName::Initiation,
            "steady" => StageName::Steady,
            "landing" => StageName::Landing,
            other => StageName::Other(other.to_string()),
        }
    }
}

impl From<String> for StageName {
    fn from(s: String) -> StageName {
        StageName::from(s.as_str())
    }
}

impl From<StageName> for String {
    fn from(s: StageName) -> String {
        s.as_str().to_string()
    }
}

impl PartialEq<str> for StageName {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for StageName {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl std::ops::Deref for StageName {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl std::fmt::Display for StageName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A key shape placed at a frame (formation frame, wingspans).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeyShapeRecord {
    /// Frame index at which the flock has exactly this shape.
    pub frame: usize,
    /// Birds in animation order.
    pub birds: Vec<KeyBird>,
}

/// The kind of a reorganisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// The leader and the first bird of an arm exchange slots.
    LeaderChange,
    /// Two neighbours along an arm exchange slots.
    Swap,
    /// A bird joins the formation.
    Join,
}

/// One reorganisation of a steady flight, in the animation file's `events`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Start of the manoeuvre, seconds (the animation's time).
    pub t: f64,
    /// What happened.
    pub kind: EventKind,
    /// The birds involved (animation indices); for a leader change the old leader first, then
    /// the new one.
    pub birds: Vec<usize>,
    /// Length of the manoeuvre, seconds.
    pub duration: f64,
}

/// One bird of a key shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KeyBird {
    /// Lateral offset, wingspans.
    pub x: f64,
    /// Distance behind the leader, wingspans.
    pub y: f64,
    /// Relative power reduction ξ achieved.
    pub xi: f64,
    /// The slot the bird flies in at this key (index into `xi_ranges` and into the first key
    /// shape's birds), when birds have changed places (leader changes, swaps); absent: its own
    /// index.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slot: Option<usize>,
}

/// The birds `birds` (indices into `f`'s arrays, in that order) of frame `f`; a missing index
/// reads as 0.
fn formation_frame(f: &Frame, birds: &[usize]) -> Frame {
    f.map_values(|v| {
        birds
            .iter()
            .map(|&b| v.get(b).copied().unwrap_or(0.0))
            .collect()
    })
}

/// The state of every bird at one instant (world frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Frame {
    /// Time, seconds since the start of the animation.
    pub t: f64,
    /// East, wingspans.
    #[serde(serialize_with = "precision::positions")]
    pub x: Vec<f64>,
    /// North, wingspans.
    #[serde(serialize_with = "precision::positions")]
    pub y: Vec<f64>,
    /// Up, wingspans.
    #[serde(serialize_with = "precision::positions")]
    pub z: Vec<f64>,
    /// Heading, radians clockwise from +y (north).
    #[serde(serialize_with = "precision::angles")]
    pub heading: Vec<f64>,
    /// Ground speed, wingspans per second.
    #[serde(serialize_with = "precision::speeds")]
    pub speed: Vec<f64>,
    /// Bank angle, radians, right wing down positive (coordinated turns; 0 in straight flight).
    /// Absent in files that do not carry it (then level).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "precision::some_angles"
    )]
    pub bank: Option<Vec<f64>>,
    /// Pitch angle, radians, nose up positive (climbs and descents; 0 in level flight). Absent in
    /// files that do not carry it (then level).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "precision::some_angles"
    )]
    pub pitch: Option<Vec<f64>>,
    /// Power reduction e_i of the current shape (absent when undefined, e.g. during initiation).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "precision::some_savings"
    )]
    pub e: Option<Vec<f64>>,
    /// Relative power reduction ξ_i of the current shape (absent when undefined).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "precision::some_savings"
    )]
    pub xi: Option<Vec<f64>>,
    /// Wingbeat phase, radians in [0, 2π), 0 = start of the downstroke.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "precision::some_angles"
    )]
    pub wing_phase: Option<Vec<f64>>,
}

impl Frame {
    /// A frame at the same time whose every per-bird array is `map` of this frame's (the
    /// optional ones where this frame has them).
    pub fn map_values(&self, map: impl Fn(&[f64]) -> Vec<f64>) -> Frame {
        let opt = |v: &Option<Vec<f64>>| v.as_deref().map(&map);
        Frame {
            t: self.t,
            x: map(&self.x),
            y: map(&self.y),
            z: map(&self.z),
            heading: map(&self.heading),
            speed: map(&self.speed),
            bank: opt(&self.bank),
            pitch: opt(&self.pitch),
            e: opt(&self.e),
            xi: opt(&self.xi),
            wing_phase: opt(&self.wing_phase),
        }
    }

    /// The per-bird arrays of a frame, in the order the animation file writes them, each with its
    /// precision in steps per unit ([`precision`]); the first [`Frame::REQUIRED`] are in every
    /// frame, the others optional.
    pub const FIELDS: [(&'static str, f64); 10] = [
        ("x", precision::POSITION),
        ("y", precision::POSITION),
        ("z", precision::POSITION),
        ("heading", precision::ANGLE),
        ("speed", precision::SPEED),
        ("bank", precision::ANGLE),
        ("pitch", precision::ANGLE),
        ("e", precision::SAVING),
        ("xi", precision::SAVING),
        ("wing_phase", precision::ANGLE),
    ];

    /// How many of [`Frame::FIELDS`] every frame has.
    pub const REQUIRED: usize = 5;

    /// The values of field `k` of [`Frame::FIELDS`], `None` where this frame has none.
    pub fn values(&self, k: usize) -> Option<&[f64]> {
        match k {
            0 => Some(&self.x),
            1 => Some(&self.y),
            2 => Some(&self.z),
            3 => Some(&self.heading),
            4 => Some(&self.speed),
            5 => self.bank.as_deref(),
            6 => self.pitch.as_deref(),
            7 => self.e.as_deref(),
            8 => self.xi.as_deref(),
            _ => self.wing_phase.as_deref(),
        }
    }

    /// The slot of field `k` of [`Frame::FIELDS`] (a required field's always holds values).
    fn slot(&mut self, k: usize) -> Slot<'_> {
        match k {
            0 => Slot::Required(&mut self.x),
            1 => Slot::Required(&mut self.y),
            2 => Slot::Required(&mut self.z),
            3 => Slot::Required(&mut self.heading),
            4 => Slot::Required(&mut self.speed),
            5 => Slot::Optional(&mut self.bank),
            6 => Slot::Optional(&mut self.pitch),
            7 => Slot::Optional(&mut self.e),
            8 => Slot::Optional(&mut self.xi),
            _ => Slot::Optional(&mut self.wing_phase),
        }
    }

    /// Sets field `k` of [`Frame::FIELDS`] (`None`: absent; a required field is left empty).
    pub fn set_values(&mut self, k: usize, v: Option<Vec<f64>>) {
        match self.slot(k) {
            Slot::Required(x) => *x = v.unwrap_or_default(),
            Slot::Optional(x) => *x = v,
        }
    }

    /// Rounds every bird's values to the precision the animation file stores
    /// ([`precision`]), so that what is written and read back is exactly what every other output
    /// of the same run was made from.
    pub fn quantize(&mut self) {
        for (k, &(_, steps)) in Frame::FIELDS.iter().enumerate() {
            let v = match self.slot(k) {
                Slot::Required(x) => Some(x),
                Slot::Optional(x) => x.as_mut(),
            };
            for x in v.into_iter().flatten() {
                *x = precision::to(*x, steps);
            }
        }
    }
}

/// Where one of a frame's per-bird arrays is held ([`Frame::FIELDS`]).
enum Slot<'a> {
    Required(&'a mut Vec<f64>),
    Optional(&'a mut Option<Vec<f64>>),
}

/// The precision of the animation file's per-bird values, in steps per unit: positions to 10⁻⁵
/// of their unit (wingspans, or metres in files written in metres: 0.015 mm for a goose's 1.5 m
/// wingspan) whatever their distance from the origin, speeds to 10⁻⁵ units per second, angles
/// (heading, bank, pitch, wingbeat phase) to 10⁻⁶ radians, savings (`e`, `xi`) to 10⁻⁶. A value
/// is rounded to its step and written with the fewest digits that read back to the same number,
/// so a file is about half the size of one at full precision and reads back exactly to the
/// rounded values, which are what every output of the run is made from.
pub mod precision {
    use serde::ser::{SerializeSeq, Serializer};

    /// Steps per unit of a position (wingspans or metres).
    pub const POSITION: f64 = 1e5;
    /// Steps per unit of a speed (wingspans or metres per second).
    pub const SPEED: f64 = 1e5;
    /// Steps per radian of an angle.
    pub const ANGLE: f64 = 1e6;
    /// Steps per unit of a saving (a fraction of power).
    pub const SAVING: f64 = 1e6;

    /// `x` rounded to the nearest of `steps` per unit (values too large to round, and
    /// non-finite ones, which are refused elsewhere, kept as they are). Rounding twice gives
    /// the same value.
    pub fn to(x: f64, steps: f64) -> f64 {
        let q = (x * steps).round() / steps;
        if q.is_finite() && (x * steps).abs() < 9e15 {
            q
        } else {
            x
        }
    }

    fn rounded<S: Serializer>(v: &[f64], steps: f64, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(v.len()))?;
        for &x in v {
            seq.serialize_element(&to(x, steps))?;
        }
        seq.end()
    }

    /// Writes positions at the file's precision.
    pub fn positions<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        rounded(v, POSITION, s)
    }

    /// Writes speeds at the file's precision.
    pub fn speeds<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        rounded(v, SPEED, s)
    }

    /// Writes angles at the file's precision.
    pub fn angles<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        rounded(v, ANGLE, s)
    }

    /// Writes optional angles (only called when present).
    pub fn some_angles<S: Serializer>(v: &Option<Vec<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => rounded(v, ANGLE, s),
            None => s.serialize_none(),
        }
    }

    /// Writes optional savings (only called when present).
    pub fn some_savings<S: Serializer>(v: &Option<Vec<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => rounded(v, SAVING, s),
            None => s.serialize_none(),
        }
    }
}

impl Animation {
    /// The path the flock flew, wingspans, world frame: the course as flown when it followed a
    /// path (turns widened), else the flock's centre once a second over the steady flight (the
    /// whole animation when it has no steady stage), and at its last frame.
    pub fn flown_path(&self) -> Vec<[f64; 3]> {
        if let Some(p) = self.path.as_ref().filter(|p| !p.flown.is_empty()) {
            return p.flown.clone();
        }
        let range = self
            .stage("steady")
            .map(|s| s.start..s.end.min(self.frames.len()))
            .filter(|r| !r.is_empty())
            .unwrap_or(0..self.frames.len());
        let step = (self.fps.round() as usize).max(1);
        let centre = |f: &Frame| {
            let n = f.x.len().max(1) as f64;
            [
                f.x.iter().sum::<f64>() / n,
                f.y.iter().sum::<f64>() / n,
                f.z.iter().sum::<f64>() / n,
            ]
        };
        let mut out: Vec<[f64; 3]> = range
            .clone()
            .step_by(step)
            .map(|k| centre(&self.frames[k]))
            .collect();
        let first = range.start;
        if let Some(last) = range.last() {
            if (last - first) % step != 0 {
                out.push(centre(&self.frames[last]));
            }
        }
        out
    }

    /// Keeps the first `frames` frames: stages end by then (those starting later are dropped),
    /// key shapes and a formation's first steady frame past it are dropped, and so are events
    /// after the last frame kept. A loop stops being one.
    pub fn truncate(&mut self, frames: usize) {
        if frames >= self.frames.len() {
            return;
        }
        self.frames.truncate(frames);
        self.stages.retain(|s| s.start < frames);
        for s in &mut self.stages {
            s.end = s.end.min(frames);
        }
        self.key_shapes.retain(|k| k.frame < frames);
        if let Some(forms) = self.formations.as_mut() {
            for f in forms {
                f.key_shapes.retain(|k| k.frame < frames);
                if f.steady_start.is_some_and(|s| s >= frames) {
                    f.steady_start = None;
                }
            }
        }
        let end = self.frames.last().map_or(f64::NEG_INFINITY, |f| f.t);
        self.events.retain(|e| e.t <= end);
        self.looped = false;
    }

    /// A looping animation (`Animation::looped`) with its closing frame appended: the first frame
    /// again, one frame after the last, moved by the flock's travel over the loop (none on a closed
    /// path, which loops in the world), so that a clip played over and over has no jump in the
    /// flock's moving frame (a game moving the flock itself gets a seamless cycle). Any other
    /// animation as it is.
    pub fn closed_loop(&self) -> std::borrow::Cow<'_, Animation> {
        let anim = self;
        use std::borrow::Cow;
        let (Some(first), Some(last)) = (anim.frames.first(), anim.frames.last()) else {
            return Cow::Borrowed(anim);
        };
        if !anim.looped || anim.frames.len() < 2 {
            return Cow::Borrowed(anim);
        }
        let lead = anim.leaders().first().copied().unwrap_or(0);
        let dt = 1.0 / anim.fps;
        let (dx, dy) = if anim.path.as_ref().is_some_and(|p| p.closed) {
            (0.0, 0.0)
        } else {
            let v = last.speed[lead] * dt;
            (
                last.x[lead] + v * last.heading[lead].sin() - first.x[lead],
                last.y[lead] + v * last.heading[lead].cos() - first.y[lead],
            )
        };
        let mut close = first.clone();
        close.t = last.t + dt;
        close.x.iter_mut().for_each(|x| *x += dx);
        close.y.iter_mut().for_each(|y| *y += dy);
        let mut out = anim.clone();
        out.frames.push(close);
        for st in &mut out.stages {
            if st.end == anim.frames.len() {
                st.end += 1;
            }
        }
        Cow::Owned(out)
    }

    /// Rounds every frame's values to the precision the file stores ([`precision`]): the last
    /// step of every run, so that all its outputs and the animation file read back agree.
    pub fn quantize(&mut self) {
        self.frames.iter_mut().for_each(Frame::quantize);
    }

    /// A copy of everything but the frames, with `frames` instead (a few frames of a large
    /// animation without copying the rest first).
    pub fn with_frames(&self, frames: Vec<Frame>) -> Animation {
        let Animation {
            format,
            seed,
            fps,
            wingspan_m,
            birds,
            species,
            wingbeat,
            stages,
            key_shapes,
            xi_ranges,
            formations,
            looped,
            start_frame,
            units,
            up,
            path,
            flight,
            savings_model,
            events,
            landing,
            frames_file,
            frames: _,
        } = self;
        Animation {
            format: format.clone(),
            seed: *seed,
            fps: *fps,
            wingspan_m: *wingspan_m,
            birds: *birds,
            species: species.clone(),
            wingbeat: wingbeat.clone(),
            stages: stages.clone(),
            key_shapes: key_shapes.clone(),
            xi_ranges: xi_ranges.clone(),
            formations: formations.clone(),
            looped: *looped,
            start_frame: *start_frame,
            units: *units,
            up: *up,
            path: path.clone(),
            flight: *flight,
            savings_model: savings_model.clone(),
            events: events.clone(),
            landing: landing.clone(),
            frames_file: frames_file.clone(),
            frames,
        }
    }

    /// An empty animation with the format tag set.
    pub fn new(seed: u64, fps: f64, wingspan_m: f64, birds: usize) -> Animation {
        Animation {
            format: ANIMATION_FORMAT.to_string(),
            seed,
            fps,
            wingspan_m,
            birds,
            species: None,
            wingbeat: None,
            stages: Vec::new(),
            key_shapes: Vec::new(),
            xi_ranges: None,
            formations: None,
            looped: false,
            start_frame: 0,
            units: axes::Units::Wingspans,
            up: axes::Up::Z,
            path: None,
            flight: None,
            savings_model: None,
            events: Vec::new(),
            landing: None,
            frames_file: None,
            frames: Vec::new(),
        }
    }

    /// Reads and validates an animation file.
    ///
    /// The file is parsed as it is read, never held whole: reading takes the memory of the
    /// animation itself (about 90 bytes per bird and frame), not that and the text's.
    pub fn read(path: &Path) -> Result<Animation> {
        let mut a: Animation = crate::io::read_json_streaming(path).map_err(|e| {
            // A structure error on another kind of file: say what the file is instead (the file
            // is read again only on this path).
            match crate::sniff::stream_kind(path) {
                Ok(Some(kind)) if kind != crate::sniff::Kind::Animation => Error::format(
                    path,
                    format!("not an animation file ({}, expected \"format\": \"{ANIMATION_FORMAT}\"); write one with `formation steady` or `formation animate`", kind.describe()),
                ),
                _ => e,
            }
        })?;
        binary::read_frames(&mut a, path)?;
        let metres = !a.units.is_default();
        if metres && !(a.wingspan_m.is_finite() && a.wingspan_m > 0.0) {
            return Err(Error::format(
                path,
                "wingspan_m: must be a positive number of metres to read positions in metres",
            ));
        }
        a.to_world_axes();
        a.validate(path)?;
        Ok(a)
    }

    /// Refuses an `fps` that contradicts the frame times: with three frames or more, the (lower)
    /// median step between frames must be one frame at `fps` (within 1 %). Everything that samples an
    /// animation (pictures, resampling, glTF keys, loops) takes the rate from `fps` and the
    /// instants from `t`; a file whose two disagree would play at the wrong speed or repeat frames.
    /// Two-frame files (a start and an end) have no rate to contradict.
    fn check_fps(&self, origin: &Path) -> Result<()> {
        if self.frames.len() < 3 {
            return Ok(());
        }
        let mut steps: Vec<f64> = self.frames.windows(2).map(|w| w[1].t - w[0].t).collect();
        steps.sort_by(f64::total_cmp);
        // The lower median: a file with one long pause keeps its rate.
        let step = steps[(steps.len() - 1) / 2];
        if step > 0.0 && ((step * self.fps) - 1.0).abs() > 0.01 {
            return Err(Error::format(
                origin,
                format!(
                    "fps: {} contradicts the frame times, whose median step is {step:.6} s ({:.3} frames per second); give \"fps\": {:.3} or fix the times",
                    self.fps,
                    1.0 / step,
                    1.0 / step
                ),
            ));
        }
        Ok(())
    }

    /// Checks the format tag, array lengths, finiteness and stage ranges; `origin` names the file.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        if self.format != ANIMATION_FORMAT {
            return Err(Error::format(
                origin,
                format!(
                    "format: expected \"{ANIMATION_FORMAT}\", found \"{}\"",
                    self.format
                ),
            ));
        }
        use crate::limits::{
            MAX_COORDINATE, MAX_FPS, MAX_FRAME_VALUE, MAX_WINGSPAN_M, MIN_WINGSPAN_M,
        };
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= MAX_FPS) {
            return Err(Error::format(
                origin,
                format!("fps: must be a positive number of frames per second, at most {MAX_FPS}"),
            ));
        }
        if !(self.wingspan_m.is_finite()
            && self.wingspan_m >= MIN_WINGSPAN_M
            && self.wingspan_m <= MAX_WINGSPAN_M)
        {
            return Err(Error::format(
                origin,
                format!(
                    "wingspan_m: must be a number of metres from {MIN_WINGSPAN_M} to {MAX_WINGSPAN_M}"
                ),
            ));
        }
        if self.start_frame > crate::limits::MAX_START_FRAME {
            return Err(Error::format(
                origin,
                format!(
                    "start_frame: {} is past the largest first frame, {}",
                    self.start_frame,
                    crate::limits::MAX_START_FRAME
                ),
            ));
        }
        if self.birds == 0 {
            return Err(Error::format(origin, "birds: must be at least 1"));
        }
        if self.frames.is_empty() {
            return Err(Error::format(origin, "frames: no frames"));
        }
        crate::limits::check_animation_size(
            &origin.display().to_string(),
            self.birds,
            self.frames.len(),
        )?;
        let n = self.birds;
        for (k, f) in self.frames.iter().enumerate() {
            if !(f.t.is_finite() && f.t.abs() <= MAX_FRAME_VALUE) {
                return Err(Error::format(
                    origin,
                    format!(
                        "frames[{k}].t: not a finite number of seconds within ±{MAX_FRAME_VALUE:e}"
                    ),
                ));
            }
            let arrays: [(&str, Option<&Vec<f64>>); 10] = [
                ("x", Some(&f.x)),
                ("y", Some(&f.y)),
                ("z", Some(&f.z)),
                ("heading", Some(&f.heading)),
                ("speed", Some(&f.speed)),
                ("e", f.e.as_ref()),
                ("xi", f.xi.as_ref()),
                ("bank", f.bank.as_ref()),
                ("pitch", f.pitch.as_ref()),
                ("wing_phase", f.wing_phase.as_ref()),
            ];
            for (name, arr) in arrays {
                let Some(arr) = arr else { continue };
                if arr.len() != n {
                    return Err(Error::format(
                        origin,
                        format!(
                            "frames[{k}].{name}: {} values, expected one per bird ({n})",
                            arr.len()
                        ),
                    ));
                }
                if let Some(i) = arr.iter().position(|v| !v.is_finite()) {
                    return Err(Error::format(
                        origin,
                        format!("frames[{k}].{name}[{i}]: not a finite number"),
                    ));
                }
                // Exports convert to f32 (glTF, USD): a value beyond these bounds would overflow
                // or lose all precision there.
                let bound = if matches!(name, "x" | "y" | "z") {
                    MAX_COORDINATE
                } else {
                    MAX_FRAME_VALUE
                };
                if let Some(i) = arr.iter().position(|v| v.abs() > bound) {
                    return Err(Error::format(
                        origin,
                        format!("frames[{k}].{name}[{i}]: {:e} is beyond ±{bound:e}", arr[i]),
                    ));
                }
                if name == "speed" {
                    if let Some(i) = arr.iter().position(|v| *v < 0.0) {
                        return Err(Error::format(
                            origin,
                            format!(
                                "frames[{k}].speed[{i}]: {} is negative; a speed is wingspans per second, 0 or more",
                                arr[i]
                            ),
                        ));
                    }
                }
            }
        }
        self.check_fps(origin)?;
        if let Some(f) = &self.flight {
            // A mass or airspeed no bird has would make every saving of total power NaN.
            f.validate("flight").map_err(|e| match e {
                Error::Parameter { name, message } => {
                    Error::format(origin, format!("{name}: {message}"))
                }
                other => other,
            })?;
        }
        if let Some(sp) = &self.species {
            if sp.parse::<wing::Species>().is_err() {
                return Err(Error::format(
                    origin,
                    format!(
                        "species: \"{sp}\" is not a species formation draws ({}); give one of them or leave the field out",
                        wing::Species::known_names().join(", ")
                    ),
                ));
            }
        }
        if let Some(p) = &self.path {
            if !(p.length.is_finite() && p.length >= 0.0) {
                return Err(Error::format(
                    origin,
                    format!("path.length: {} is not a length (0 or more)", p.length),
                ));
            }
        }
        for (s, st) in self.stages.iter().enumerate() {
            if st.start > st.end || st.end > self.frames.len() {
                return Err(Error::format(
                    origin,
                    format!(
                        "stages[{s}] ({}): range {}..{} outside the {} frames",
                        st.name,
                        st.start,
                        st.end,
                        self.frames.len()
                    ),
                ));
            }
        }
        for (s, ks) in self.key_shapes.iter().enumerate() {
            if ks.birds.len() != n {
                return Err(Error::format(
                    origin,
                    format!(
                        "key_shapes[{s}].birds: {} birds, expected {n}",
                        ks.birds.len()
                    ),
                ));
            }
            for (i, b) in ks.birds.iter().enumerate() {
                if !(b.x.is_finite() && b.y.is_finite() && b.xi.is_finite())
                    || b.x.abs().max(b.y.abs()) > MAX_COORDINATE
                {
                    return Err(Error::format(
                        origin,
                        format!("key_shapes[{s}].birds[{i}]: not a finite number within ±{MAX_COORDINATE:e}"),
                    ));
                }
                if b.slot.is_some_and(|q| q >= n) {
                    return Err(Error::format(
                        origin,
                        format!("key_shapes[{s}].birds[{i}].slot: not one of the {n} slots"),
                    ));
                }
            }
        }
        for (k, e) in self.events.iter().enumerate() {
            if !(e.t.is_finite() && e.duration.is_finite() && e.duration >= 0.0) {
                return Err(Error::format(
                    origin,
                    format!("events[{k}]: t and duration must be finite, duration ≥ 0"),
                ));
            }
            if let Some(b) = e.birds.iter().find(|&&b| b >= n) {
                return Err(Error::format(
                    origin,
                    format!("events[{k}].birds: bird {b} is not one of the {n} birds"),
                ));
            }
        }
        if let Some(fs) = &self.formations {
            let mut seen = vec![false; n];
            for (k, fm) in fs.iter().enumerate() {
                if fm.birds.is_empty() {
                    return Err(Error::format(
                        origin,
                        format!("formations[{k}].birds: empty"),
                    ));
                }
                for &b in &fm.birds {
                    if b >= n || std::mem::replace(&mut seen[b], true) {
                        return Err(Error::format(
                            origin,
                            format!("formations[{k}].birds: bird {b} is not one of the {n} birds or is in two formations"),
                        ));
                    }
                }
                if !fm.birds.contains(&fm.leader) {
                    return Err(Error::format(
                        origin,
                        format!(
                            "formations[{k}].leader: bird {} is not in this formation",
                            fm.leader
                        ),
                    ));
                }
                for (s, ks) in fm.key_shapes.iter().enumerate() {
                    if ks.birds.len() != fm.birds.len() {
                        return Err(Error::format(
                            origin,
                            format!(
                                "formations[{k}].key_shapes[{s}].birds: {} birds, expected {}",
                                ks.birds.len(),
                                fm.birds.len()
                            ),
                        ));
                    }
                }
                if fm.steady_start.is_some_and(|s| s >= self.frames.len()) {
                    return Err(Error::format(
                        origin,
                        format!(
                            "formations[{k}].steady_start: beyond the {} frames",
                            self.frames.len()
                        ),
                    ));
                }
                for (s, ks) in fm.key_shapes.iter().enumerate() {
                    if ks.frame >= self.frames.len() {
                        return Err(Error::format(
                            origin,
                            format!(
                                "formations[{k}].key_shapes[{s}].frame: {} is beyond the {} frames",
                                ks.frame,
                                self.frames.len()
                            ),
                        ));
                    }
                }
                if let Some(r) = &fm.xi_ranges {
                    if r.len() != fm.birds.len() {
                        return Err(Error::format(
                            origin,
                            format!(
                                "formations[{k}].xi_ranges: {} ranges, expected {}",
                                r.len(),
                                fm.birds.len()
                            ),
                        ));
                    }
                }
            }
            if let Some(b) = seen.iter().position(|s| !s) {
                return Err(Error::format(
                    origin,
                    format!("formations: bird {b} is in no formation"),
                ));
            }
        }
        Ok(())
    }

    /// The stage with this name, if present.
    pub fn stage(&self, name: &str) -> Option<&Stage> {
        self.stages.iter().find(|s| s.name == name)
    }

    /// Each bird's formation index (all 0 for a flock of one formation).
    pub fn formation_of_birds(&self) -> Vec<usize> {
        let mut of = vec![0; self.birds];
        if let Some(fs) = &self.formations {
            for (k, f) in fs.iter().enumerate() {
                for &b in &f.birds {
                    if b < of.len() {
                        of[b] = k;
                    }
                }
            }
        }
        of
    }

    /// Number of formations (1 for a flock of one formation).
    pub fn formation_count(&self) -> usize {
        self.formations.as_ref().map_or(1, |f| f.len().max(1))
    }

    /// Formation `k` alone, as an animation of one formation: its birds (in the order of its
    /// record), its key shapes and ranges, every frame and stage. Formation 0 of a flock of one
    /// formation is the animation itself. `None` when there is no formation `k`.
    pub fn formation(&self, k: usize) -> Option<Animation> {
        let Some(fs) = &self.formations else {
            return (k == 0).then(|| self.clone());
        };
        let fm = fs.get(k)?;
        let mut a = self.formation_shell(fm);
        a.frames = self
            .frames
            .iter()
            .map(|f| formation_frame(f, &fm.birds))
            .collect();
        Some(a)
    }

    /// Every formation alone, as [`Animation::formation`] gives them, taking the frames apart as
    /// it goes (each frame of the flock is dropped once its formations have their shares), so a
    /// flock's frames are never held twice. Empty when the record lists no formation.
    pub fn into_formations(mut self) -> Vec<Animation> {
        let Some(fs) = self.formations.take() else {
            return vec![self];
        };
        let frames = std::mem::take(&mut self.frames);
        let mut out: Vec<Animation> = fs
            .iter()
            .map(|fm| {
                let mut a = self.formation_shell(fm);
                a.frames = Vec::with_capacity(frames.len());
                a
            })
            .collect();
        for f in frames {
            for (a, fm) in out.iter_mut().zip(&fs) {
                a.frames.push(formation_frame(&f, &fm.birds));
            }
        }
        out
    }

    /// Formation `fm` of this flock without frames: its birds, key shapes and ranges, and the
    /// flock's rate, species, stages and records.
    fn formation_shell(&self, fm: &FormationRecord) -> Animation {
        let mut a = Animation::new(self.seed, self.fps, self.wingspan_m, fm.birds.len());
        a.species = self.species.clone();
        a.flight = self.flight;
        a.savings_model = self.savings_model.clone();
        a.wingbeat = self.wingbeat.clone();
        a.stages = self.stages.clone();
        a.key_shapes = fm.key_shapes.clone();
        a.xi_ranges = fm.xi_ranges.clone();
        a
    }

    /// Each formation's leader (one entry for a flock of one formation): the recorded leader, or
    /// the bird at the front of the first key shape, or else the front-most bird of the last frame
    /// along its heading.
    pub fn leaders(&self) -> Vec<usize> {
        if let Some(fs) = &self.formations {
            return fs.iter().map(|f| f.leader).collect();
        }
        if let Some(ks) = self.key_shapes.first() {
            let lead = (0..ks.birds.len())
                .min_by(|&a, &b| ks.birds[a].y.total_cmp(&ks.birds[b].y))
                .unwrap_or(0);
            return vec![lead];
        }
        let Some(f) = self.frames.last() else {
            return vec![0];
        };
        let n = f.x.len().min(f.y.len()).min(f.heading.len());
        let ahead = |i: usize| {
            let h = f.heading[i];
            f.x[i] * h.sin() + f.y[i] * h.cos()
        };
        let lead = (0..n)
            .max_by(|&a, &b| ahead(a).total_cmp(&ahead(b)))
            .unwrap_or(0);
        vec![lead]
    }
}

fn is_zero_u64(v: &u64) -> bool {
    *v == 0
}
