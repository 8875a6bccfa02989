//! The animation file (SPEC §4.4), the plain data type that `steady`, `initiate` and `animate`
//! write and `render` reads. World frame: `x` east, `y` north, `z` up, lengths in wingspans, the
//! cruise heading is +y; headings in radians clockwise from +y; speeds in wingspans per second.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::error::{Error, Result};

/// Format tag of animation files.
pub const ANIMATION_FORMAT: &str = "formation-animation/1";

/// A whole animation: stages, key shapes and per-frame state of every bird.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Animation {
    /// Always [`ANIMATION_FORMAT`].
    pub format: String,
    /// The `--seed` that produced it.
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
    pub wingbeat: Option<crate::wingbeat::WingbeatOptions>,
    /// Named frame ranges, `start` inclusive, `end` exclusive.
    pub stages: Vec<Stage>,
    /// Key shapes of the steady flight, formation frame.
    #[serde(default)]
    pub key_shapes: Vec<KeyShapeRecord>,
    /// Feasible range [(1 − ε) p_i, (1 + ε) P_i] of each bird's ξ in the steady flight (§5 eq. 2),
    /// when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi_ranges: Option<Vec<[f64; 2]>>,
    /// One entry per frame.
    pub frames: Vec<Frame>,
}

/// A named range of frames.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stage {
    /// `"initiation"` or `"steady"`.
    pub name: String,
    /// First frame, inclusive.
    pub start: usize,
    /// Last frame, exclusive.
    pub end: usize,
}

/// A key shape placed at a frame (formation frame, wingspans).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KeyShapeRecord {
    /// Frame index at which the flock has exactly this shape.
    pub frame: usize,
    /// Birds in animation order.
    pub birds: Vec<KeyBird>,
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
}

/// The state of every bird at one instant (world frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Frame {
    /// Time, seconds since the start of the animation.
    pub t: f64,
    /// East, wingspans.
    pub x: Vec<f64>,
    /// North, wingspans.
    pub y: Vec<f64>,
    /// Up, wingspans.
    pub z: Vec<f64>,
    /// Heading, radians clockwise from +y (north).
    pub heading: Vec<f64>,
    /// Ground speed, wingspans per second.
    pub speed: Vec<f64>,
    /// Bank angle, radians, right wing down positive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bank: Option<Vec<f64>>,
    /// Power reduction e_i of the current shape (absent when undefined, e.g. during initiation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub e: Option<Vec<f64>>,
    /// Relative power reduction ξ_i of the current shape (absent when undefined).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi: Option<Vec<f64>>,
    /// Wingbeat phase, radians in [0, 2π), 0 = start of the downstroke.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wing_phase: Option<Vec<f64>>,
}

impl Animation {
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
            frames: Vec::new(),
        }
    }

    /// Reads and validates an animation file.
    pub fn read(path: &Path) -> Result<Animation> {
        let text = crate::io::read_text(path)?;
        let a: Animation = crate::io::parse_json(path, &text).map_err(|e| {
            // A structure error on another kind of file: say what the file is instead.
            let tag = serde_json::from_str::<serde_json::Value>(&text).ok().map(|v| {
                match v.get("format").and_then(|f| f.as_str()) {
                    Some(t) => format!("a \"{t}\" file"),
                    None if v.get("birds").is_some_and(|b| b.is_array()) => "a shape file".into(),
                    None => "no \"format\" field".into(),
                }
            });
            match tag {
                Some(found) if !found.contains(ANIMATION_FORMAT) => Error::format(
                    path,
                    format!("not an animation file ({found}, expected \"format\": \"{ANIMATION_FORMAT}\"); write one with `formation steady` or `formation animate`"),
                ),
                _ => e,
            }
        })?;
        a.validate(path)?;
        Ok(a)
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
        use crate::limits::{MAX_COORDINATE, MAX_FPS, MAX_FRAME_VALUE, MAX_WINGSPAN_M};
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= MAX_FPS) {
            return Err(Error::format(
                origin,
                format!("fps: must be a positive number of frames per second, at most {MAX_FPS}"),
            ));
        }
        if !(self.wingspan_m.is_finite()
            && self.wingspan_m > 0.0
            && self.wingspan_m <= MAX_WINGSPAN_M)
        {
            return Err(Error::format(
                origin,
                format!(
                    "wingspan_m: must be a positive number of metres, at most {MAX_WINGSPAN_M}"
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
            let arrays: [(&str, Option<&Vec<f64>>); 8] = [
                ("x", Some(&f.x)),
                ("y", Some(&f.y)),
                ("z", Some(&f.z)),
                ("heading", Some(&f.heading)),
                ("speed", Some(&f.speed)),
                ("e", f.e.as_ref()),
                ("xi", f.xi.as_ref()),
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
            }
        }
        Ok(())
    }

    /// The stage with this name, if present.
    pub fn stage(&self, name: &str) -> Option<&Stage> {
        self.stages.iter().find(|s| s.name == name)
    }
}
