//! From footage to annotations: find the birds in every frame and link them into tracks.
//!
//! [`detect`] finds the birds of one frame (sky model, regions standing out from it, sub-pixel
//! centroids, touching birds split); [`tracker`] links them across frames by assignment with
//! constant-velocity prediction; [`Tracking`] runs both over a sequence of frames and gives
//! [`Tracked`]: per frame the birds with stable ids and a confidence, the wingspan in pixels (the
//! median of the birds' spans) and the flight direction (from the tracks' motion). [`source`]
//! reads frames from a video (through the system `ffmpeg`), a directory or a glob.
//! [`Tracked::to_native`] writes the native annotation JSON that `extract` reads.

pub mod debug;
pub mod detect;
pub mod review;
pub mod source;
pub mod tracker;

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::progress::Progress;
use detect::{Blob, Gray, Hints, Sky};

/// Whether birds are darker or brighter than the sky.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Polarity {
    /// Chosen on the first frame: the side that stands out more.
    #[default]
    Auto,
    /// Dark birds on a bright sky (the usual silhouette).
    Dark,
    /// Bright birds on a dark sky (lit from the side, or an infrared camera).
    Bright,
}

impl std::str::FromStr for Polarity {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Polarity::Auto),
            "dark" => Ok(Polarity::Dark),
            "bright" => Ok(Polarity::Bright),
            _ => Err(format!("`{s}` is not a polarity; use auto, dark or bright")),
        }
    }
}

/// Options of tracking; checked by [`TrackOptions::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrackOptions {
    /// Dark or bright birds.
    pub polarity: Polarity,
    /// Annotate every K-th frame (1 = all).
    pub every: usize,
    /// First frame and one past the last to read (0-based), `None` = to the end.
    pub frames: (usize, Option<usize>),
    /// Region of interest `[x, y, w, h]`, pixels; `None` = the whole frame.
    pub roi: Option<[usize; 4]>,
    /// Frames per second, overriding the video's (needed for image frames to carry times).
    pub fps: Option<f64>,
    /// The birds' wingspan, pixels, when the user knows it: sets the detection's scale and the
    /// wingspan written, instead of the one measured.
    pub wingspan_px: Option<f64>,
    /// Write every processed frame here as a PNG with the detections, the tracks and the
    /// background drawn ([`debug`]).
    pub debug_frames: Option<std::path::PathBuf>,
}

impl Default for TrackOptions {
    fn default() -> Self {
        TrackOptions {
            polarity: Polarity::Auto,
            every: 1,
            frames: (0, None),
            roi: None,
            fps: None,
            wingspan_px: None,
            debug_frames: None,
        }
    }
}

impl TrackOptions {
    /// Checks the options that do not depend on the footage.
    pub fn validate(&self) -> Result<()> {
        if self.every == 0 {
            return Err(Error::parameter(
                "track.every",
                "must be at least 1 (1 = every frame, 5 = every fifth)",
            ));
        }
        if let (a, Some(b)) = self.frames {
            if b <= a {
                return Err(Error::parameter(
                    "track.frames",
                    format!("{a}..{b} holds no frame; give A..B with B > A (B excluded), or A.. to the end"),
                ));
            }
        }
        if let Some([_, _, w, h]) = self.roi {
            if w == 0 || h == 0 {
                return Err(Error::parameter(
                    "track.roi",
                    "the region has zero width or height; give x,y,w,h in pixels",
                ));
            }
        }
        if let Some(w) = self.wingspan_px {
            if !(w.is_finite() && (2.0..=4000.0).contains(&w)) {
                return Err(Error::parameter(
                    "track.wingspan_px",
                    format!("{w} is not a wingspan in pixels; give a bird's wingspan on screen, from 2 to 4000"),
                ));
            }
        }
        if let Some(f) = self.fps {
            if !(f.is_finite() && f > 0.0 && f <= crate::limits::MAX_FPS) {
                return Err(Error::parameter(
                    "track.fps",
                    format!("{f} is not a frame rate; give frames per second, e.g. 25"),
                ));
            }
        }
        Ok(())
    }

    /// The region of interest checked against a `width × height` frame.
    pub fn roi_in(&self, width: usize, height: usize) -> Result<[usize; 4]> {
        match self.roi {
            None => Ok([0, 0, width, height]),
            Some([x, y, w, h]) => {
                if x.saturating_add(w) > width || y.saturating_add(h) > height {
                    return Err(Error::parameter(
                        "track.roi",
                        format!("{x},{y},{w},{h} reaches outside the {width}x{height} frame"),
                    ));
                }
                Ok([x, y, w, h])
            }
        }
    }

    /// Whether frame `k` of the footage is processed.
    pub fn wants(&self, k: usize) -> bool {
        k >= self.frames.0 && !self.done(k) && (k - self.frames.0) % self.every == 0
    }

    /// Whether no frame from `k` on is processed.
    pub fn done(&self, k: usize) -> bool {
        self.frames.1.is_some_and(|b| k >= b)
    }
}

/// One tracked bird in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackedBird {
    /// Track id, stable across frames.
    pub id: usize,
    /// Position, pixels (x right): the centroid smoothed along the track.
    pub x: f64,
    /// Position, pixels (y down).
    pub y: f64,
    /// 0–1: how sure the detection and its track are: the blob's contrast × its track's length
    /// (full from 5 frames) × 0.8 when it was cut from a larger region (set by [`Tracking::finish`]).
    pub confidence: f64,
    /// The detection.
    pub blob: Blob,
}

/// One processed frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedFrame {
    /// Frame number in the footage (0-based).
    pub index: usize,
    /// Image file name, for image frames.
    pub image: Option<String>,
    /// Wingspan, pixels: the median over the frame's birds of each one's widest span within
    /// 6 processed frames either side (its 7 nearest whole detections when fewer are there:
    /// a bird cut from a larger region has no span of its own).
    pub wingspan_px: f64,
    /// Flight direction, degrees clockwise from image-up.
    pub heading_deg: f64,
    /// The birds.
    pub birds: Vec<TrackedBird>,
}

/// The result of tracking footage.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracked {
    /// Describes the footage.
    pub source: String,
    /// Frame size, pixels.
    pub width: usize,
    /// Frame size, pixels.
    pub height: usize,
    /// Frames per second of the footage, when known.
    pub fps: Option<f64>,
    /// Polarity used.
    pub polarity: Polarity,
    /// Processed frames in order.
    pub frames: Vec<TrackedFrame>,
    /// Frames ffmpeg decoded, for a video (read until the chosen range ended).
    pub decoded: Option<usize>,
    /// What the user should know about the footage (a damaged video), one line each.
    pub warnings: Vec<String>,
}

/// Runs detection and tracking frame by frame.
pub struct Tracking {
    opts: TrackOptions,
    polarity: Option<Polarity>,
    tracker: tracker::Tracker,
    size: Option<(usize, usize)>,
    roi: [usize; 4],
    frames: Vec<TrackedFrame>,
    last_span: Option<f64>,
    hints: Hints,
    trails: BTreeMap<usize, Vec<(f64, f64)>>,
}

/// Processed frames a track must be seen in before it counts (fewer when the footage is short:
/// half its frames).
pub const MIN_TRACK_FRAMES: usize = 5;

/// Times a track must have been seen before its birds teach the detection their size and
/// contrast ([`Hints`]).
const CONFIRMED_HITS: usize = 3;

/// Processed frames either side over which a bird's widest spread is its wingspan.
const SPAN_WINDOW: usize = 6;

/// Processed frames either side over which a bird's position is smoothed by a straight line.
const SMOOTH_WINDOW: usize = 4;

/// Frames a heading is measured over, either side.
const HEADING_WINDOW: usize = 3;

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

impl Tracking {
    /// Starts with checked options.
    pub fn new(opts: &TrackOptions) -> Result<Tracking> {
        opts.validate()?;
        Ok(Tracking {
            opts: opts.clone(),
            polarity: match opts.polarity {
                Polarity::Auto => None,
                p => Some(p),
            },
            tracker: tracker::Tracker::default(),
            size: None,
            roi: [0, 0, 0, 0],
            frames: Vec::new(),
            last_span: None,
            hints: Hints {
                wingspan_px: opts.wingspan_px,
                ..Hints::default()
            },
            trails: BTreeMap::new(),
        })
    }

    /// Processes frame number `index` of the footage; `name` names it in messages.
    pub fn push(
        &mut self,
        index: usize,
        image: Option<String>,
        g: &Gray,
        name: &Path,
    ) -> Result<()> {
        match self.size {
            None => {
                self.roi = self.opts.roi_in(g.width, g.height)?;
                self.size = Some((g.width, g.height));
            }
            Some((w, h)) if (w, h) != (g.width, g.height) => {
                return Err(Error::format(
                    name,
                    format!(
                        "frame {index} is {}x{}, the first frame was {w}x{h}; all frames must be the same size",
                        g.width, g.height
                    ),
                ))
            }
            _ => {}
        }
        let sky = Sky::model(g);
        let polarity = *self
            .polarity
            .get_or_insert_with(|| detect::auto_polarity(g, &sky));
        let mut found = detect::detect_with(g, &sky, polarity, self.roi, &self.hints);
        let blobs = &found.blobs;
        if blobs.is_empty() {
            return Err(Error::format(
                name,
                format!(
                    "frame {index}: no bird found; check track.polarity (dark birds on a bright sky, or bright on dark), track.roi, or leave the frame out with track.frames"
                ),
            ));
        }
        if blobs.len() > crate::limits::MAX_ANNOTATED_BIRDS {
            return Err(Error::format(
                name,
                format!(
                    "frame {index}: {} birds found, more than the {} a frame that annotations hold; search part of the frame with track.roi, or check track.polarity (noise or texture taken for birds)",
                    blobs.len(),
                    crate::limits::MAX_ANNOTATED_BIRDS
                ),
            ));
        }
        if self.frames.len() >= crate::limits::MAX_ANNOTATED_FRAMES {
            return Err(Error::parameter(
                "track.frames",
                format!(
                    "more than {} frames to track, the most annotations hold (frame {index} is one too many); choose fewer with track.every or track.frames",
                    crate::limits::MAX_ANNOTATED_FRAMES
                ),
            ));
        }
        // The frame's bird size: the user's, else the size of the birds on lasting tracks, else
        // this frame's regions weighted by area (specks do not outvote birds).
        let span = self.opts.wingspan_px.unwrap_or_else(|| {
            let whole = detect::weighted_median(
                blobs
                    .iter()
                    .filter(|b| !b.split)
                    .map(|b| (b.span, b.area as f64)),
            );
            if whole > 0.0 {
                whole
            } else {
                detect::weighted_median(blobs.iter().map(|b| (b.span, b.area as f64))).max(1.0)
            }
        });
        let gate_span = self.hints.wingspan_px.unwrap_or(span);
        let ids = self.tracker.step(
            &mut found.blobs,
            self.last_span.unwrap_or(gate_span).max(gate_span),
        );
        let blobs = &found.blobs;
        self.last_span = Some(gate_span);
        self.learn(blobs, &ids, found.sigma);
        if let Some(dir) = &self.opts.debug_frames {
            let hits: BTreeMap<usize, usize> =
                self.tracker.tracks.iter().map(|t| (t.id, t.hits)).collect();
            for (b, id) in blobs.iter().zip(&ids) {
                let t = self.trails.entry(*id).or_default();
                t.push((b.x, b.y));
                if t.len() > debug::TRAIL {
                    t.remove(0);
                }
            }
            self.trails.retain(|id, _| hits.contains_key(id));
            let marks: Vec<debug::Mark> = blobs
                .iter()
                .zip(&ids)
                .map(|(b, id)| debug::Mark {
                    blob: *b,
                    id: *id,
                    lasting: hits.get(id).copied().unwrap_or(0) >= MIN_TRACK_FRAMES,
                })
                .collect();
            let path = dir.join(format!("frame_{index:06}.png"));
            debug::write(&path, g, &found, &marks, &self.trails, self.roi)?;
        }
        self.frames.push(TrackedFrame {
            index,
            image,
            wingspan_px: span,
            heading_deg: f64::NAN,
            birds: blobs
                .iter()
                .zip(ids.iter().copied())
                .map(|(b, id)| TrackedBird {
                    id,
                    x: b.x,
                    y: b.y,
                    confidence: 0.0,
                    blob: *b,
                })
                .collect(),
        });
        Ok(())
    }

    /// Learns the birds' size and contrast from the detections on tracks seen at least
    /// [`CONFIRMED_HITS`] times (bird-shaped regions that last and move, not the most common
    /// region of one frame); blended over frames so one frame cannot swing them.
    fn learn(&mut self, blobs: &[Blob], ids: &[usize], sigma: f32) {
        let hits: std::collections::HashMap<usize, usize> =
            self.tracker.tracks.iter().map(|t| (t.id, t.hits)).collect();
        let lasting: Vec<&Blob> = blobs
            .iter()
            .zip(ids)
            .filter(|(b, id)| !b.split && hits.get(id).is_some_and(|&h| h >= CONFIRMED_HITS))
            .map(|(b, _)| b)
            .collect();
        if lasting.is_empty() {
            return;
        }
        let noise = sigma.max(1.0) as f64;
        let w = |b: &&Blob| b.area as f64;
        let span = detect::weighted_median(lasting.iter().map(|b| (b.span, w(b))));
        let area = detect::weighted_median(lasting.iter().map(|b| (b.area as f64, w(b))));
        // The contrast by signal energy, as the detection's first guess (see `detect`).
        let peak = detect::weighted_median(
            lasting
                .iter()
                .map(|b| (b.snr * noise, w(b) * (b.snr * noise).powi(2))),
        );
        let blend = |old: Option<f64>, new: f64| {
            Some(match old {
                Some(o) => 0.7 * o + 0.3 * new,
                None => new,
            })
        };
        if self.opts.wingspan_px.is_none() {
            self.hints.wingspan_px = blend(self.hints.wingspan_px, span);
        }
        self.hints.area = blend(self.hints.area, area);
        self.hints.peak = blend(self.hints.peak, peak);
    }

    /// Finishes: headings and confidences.
    pub fn finish(self, source: &str, fps: Option<f64>) -> Result<Tracked> {
        let Some((width, height)) = self.size else {
            return Err(Error::format(
                source,
                "no frame was read in the chosen range; check track.frames and track.every",
            ));
        };
        let mut frames = self.frames;
        let fps_eff = self.opts.fps.or(fps).unwrap_or(25.0);
        let coherence = keep_lasting(
            &mut frames,
            self.hints.wingspan_px,
            self.opts.every as f64 / fps_eff,
        );
        // Each track's observations: processed-frame position -> (x, y).
        let mut tracks: BTreeMap<usize, Vec<(usize, f64, f64)>> = BTreeMap::new();
        for (k, f) in frames.iter().enumerate() {
            for b in &f.birds {
                tracks.entry(b.id).or_default().push((k, b.x, b.y));
            }
        }
        // Positions: a straight line fitted to each bird's centroids over SMOOTH_WINDOW
        // processed frames either side, taken at the frame (the silhouette's centre of mass
        // moves back and forth with the wingbeat; the bird's motion is smooth over this time).
        let observed = tracks.clone();
        for (k, f) in frames.iter_mut().enumerate() {
            for b in &mut f.birds {
                let obs: Vec<&(usize, f64, f64)> = observed[&b.id]
                    .iter()
                    .filter(|o| o.0 + SMOOTH_WINDOW >= k && o.0 <= k + SMOOTH_WINDOW)
                    .collect();
                if obs.len() < 3 {
                    continue;
                }
                let n = obs.len() as f64;
                let mt = obs.iter().map(|o| o.0 as f64).sum::<f64>() / n;
                let mx = obs.iter().map(|o| o.1).sum::<f64>() / n;
                let my = obs.iter().map(|o| o.2).sum::<f64>() / n;
                let stt = obs.iter().map(|o| (o.0 as f64 - mt).powi(2)).sum::<f64>();
                let stx = obs
                    .iter()
                    .map(|o| (o.0 as f64 - mt) * (o.1 - mx))
                    .sum::<f64>();
                let sty = obs
                    .iter()
                    .map(|o| (o.0 as f64 - mt) * (o.2 - my))
                    .sum::<f64>();
                let dt = k as f64 - mt;
                b.x = mx + stx / stt * dt;
                b.y = my + sty / stt * dt;
            }
        }
        // Wingspan: each bird's widest spread within a wingbeat or two (a wing raised or swept
        // back shortens the span seen from below), then the median over the frame's birds.
        let spans: BTreeMap<usize, Vec<(usize, f64)>> = {
            let mut m: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
            for (k, f) in frames.iter().enumerate() {
                for b in f.birds.iter().filter(|b| !b.blob.split) {
                    m.entry(b.id).or_default().push((k, b.blob.span));
                }
            }
            m
        };
        // A bird cut from a larger region for a while (crossing another) has fewer whole
        // observations in the window than a wingbeat needs: its nearest SPAN_WINDOW + 1 whole
        // observations in time are taken instead.
        for (k, f) in frames.iter_mut().enumerate() {
            let (lo, hi) = (k.saturating_sub(SPAN_WINDOW), k + SPAN_WINDOW);
            let widest: Vec<f64> = f
                .birds
                .iter()
                .filter_map(|b| {
                    let v = spans.get(&b.id)?;
                    let near: Vec<&(usize, f64)> =
                        v.iter().filter(|o| o.0 >= lo && o.0 <= hi).collect();
                    let near = if near.len() > SPAN_WINDOW {
                        near
                    } else {
                        let mut all: Vec<&(usize, f64)> = v.iter().collect();
                        all.sort_by_key(|o| (o.0.abs_diff(k), o.0));
                        all.truncate(SPAN_WINDOW + 1);
                        all
                    };
                    near.iter().map(|o| o.1).reduce(f64::max)
                })
                .collect();
            if let Some(w) = median(widest) {
                f.wingspan_px = w;
            }
        }
        let shape_heading = |f: &TrackedFrame| shape_heading(&f.birds);
        let n = frames.len();
        let mut headings = Vec::with_capacity(n);
        for (k, frame) in frames.iter().enumerate() {
            let (lo, hi) = (
                k.saturating_sub(HEADING_WINDOW),
                (k + HEADING_WINDOW).min(n - 1),
            );
            let (mut sx, mut sy, mut steps) = (0.0, 0.0, 0.0);
            for b in &frame.birds {
                let obs = &tracks[&b.id];
                let first = obs.iter().find(|o| o.0 >= lo);
                let last = obs.iter().rev().find(|o| o.0 <= hi);
                if let (Some(a), Some(c)) = (first, last) {
                    if c.0 > a.0 {
                        sx += c.1 - a.1;
                        sy += c.2 - a.2;
                        steps += (c.0 - a.0) as f64;
                    }
                }
            }
            let moving = steps > 0.0
                && sx.hypot(sy) / steps >= 0.05 * frame.wingspan_px * self.opts.every as f64;
            headings.push(if moving {
                sx.atan2(-sy).to_degrees().rem_euclid(360.0)
            } else {
                shape_heading(frame)
            });
        }
        for (f, h) in frames.iter_mut().zip(headings) {
            f.heading_deg = h;
            if let Some(w) = self.opts.wingspan_px {
                f.wingspan_px = w;
            }
        }
        // Confidence: contrast × track length × not cut from a larger region.
        let lengths: BTreeMap<usize, usize> = tracks.iter().map(|(id, o)| (*id, o.len())).collect();
        for f in &mut frames {
            for b in &mut f.birds {
                let contrast = 1.0 - 0.5f64.powf(b.blob.snr / detect::HIGH_SIGMA as f64);
                let length = (lengths[&b.id] as f64 / 5.0).min(1.0);
                let split = if b.blob.split { 0.8 } else { 1.0 };
                let along = coherence.get(&b.id).copied().unwrap_or(0.4);
                b.confidence = (contrast * length * split * along * 1000.0).round() / 1000.0;
            }
        }
        Ok(Tracked {
            source: source.to_string(),
            width,
            height,
            fps: self.opts.fps.or(fps),
            polarity: self.polarity.unwrap_or(Polarity::Dark),
            frames,
            decoded: None,
            warnings: Vec::new(),
        })
    }
}

/// Line fit of a track's positions over [`SMOOTH_WINDOW`] processed frames either side of
/// `k`: the velocity there, pixels per processed frame (`None` with fewer than 3 positions).
fn velocity_at(obs: &[(usize, f64, f64)], k: usize) -> Option<(f64, f64)> {
    let near: Vec<&(usize, f64, f64)> = obs
        .iter()
        .filter(|o| o.0 + SMOOTH_WINDOW >= k && o.0 <= k + SMOOTH_WINDOW)
        .collect();
    if near.len() < 3 {
        return None;
    }
    let n = near.len() as f64;
    let mt = near.iter().map(|o| o.0 as f64).sum::<f64>() / n;
    let mx = near.iter().map(|o| o.1).sum::<f64>() / n;
    let my = near.iter().map(|o| o.2).sum::<f64>() / n;
    let stt = near.iter().map(|o| (o.0 as f64 - mt).powi(2)).sum::<f64>();
    if stt <= 0.0 {
        return None;
    }
    let stx = near
        .iter()
        .map(|o| (o.0 as f64 - mt) * (o.1 - mx))
        .sum::<f64>();
    let sty = near
        .iter()
        .map(|o| (o.0 as f64 - mt) * (o.2 - my))
        .sum::<f64>();
    Some((stx / stt, sty / stt))
}

/// Birds a frame must hold on lasting tracks for the flock's motion to judge a track by.
const FLOCK_BIRDS: usize = 6;

/// Keeps the detections that belong to birds: on a track seen in at least
/// [`MIN_TRACK_FRAMES`] processed frames (half the footage when it is shorter) and, where the
/// frame holds a flock ([`FLOCK_BIRDS`] lasting tracks or more), moving with it: a track whose
/// velocity differs from the flock's (the median of the lasting tracks', frame by frame, each
/// weighted by its detection's signal energy, area × contrast², so that faint texture drifting
/// with the clouds, however many its regions, does not set the flock's motion) by
/// more than half the flock's speed plus half a wingspan a second, in the median over its
/// frames, is texture of the sky drifting with the clouds, not a bird. A frame that would be
/// left with no bird keeps its detections. Gives each kept track's coherence factor (1 when
/// it deviates by at most half the allowance, down to 0.5 at the allowance) for its confidence.
/// `seconds` is the time between processed frames.
fn keep_lasting(
    frames: &mut [TrackedFrame],
    wingspan: Option<f64>,
    seconds: f64,
) -> BTreeMap<usize, f64> {
    let n = frames.len();
    let min_len = MIN_TRACK_FRAMES.min(n.div_ceil(2)).max(1);
    let mut tracks: BTreeMap<usize, Vec<(usize, f64, f64)>> = BTreeMap::new();
    for (k, f) in frames.iter().enumerate() {
        for b in &f.birds {
            tracks.entry(b.id).or_default().push((k, b.x, b.y));
        }
    }
    let lasting: BTreeMap<usize, &Vec<(usize, f64, f64)>> = tracks
        .iter()
        .filter(|(_, o)| o.len() >= min_len)
        .map(|(id, o)| (*id, o))
        .collect();
    // Velocities of the lasting tracks, frame by frame, and the flock's.
    let mut vel: BTreeMap<(usize, usize), (f64, f64)> = BTreeMap::new();
    let mut flock: Vec<Option<(f64, f64)>> = vec![None; n];
    for (k, f) in frames.iter().enumerate() {
        let mut vx = Vec::new();
        let mut vy = Vec::new();
        for b in &f.birds {
            if let Some(o) = lasting.get(&b.id) {
                if let Some(v) = velocity_at(o, k) {
                    vel.insert((b.id, k), v);
                    // Weighted by signal energy: the flock is what stands out most.
                    let w = b.blob.area as f64 * b.blob.snr.powi(2);
                    vx.push((v.0, w));
                    vy.push((v.1, w));
                }
            }
        }
        if vx.len() >= FLOCK_BIRDS {
            flock[k] = Some((
                detect::weighted_median(vx.into_iter()),
                detect::weighted_median(vy.into_iter()),
            ));
        }
    }
    let mut coherence = BTreeMap::new();
    for (&id, obs) in &lasting {
        let ratios: Vec<f64> = obs
            .iter()
            .filter_map(|&(k, _, _)| {
                let (f, v) = (flock[k]?, vel.get(&(id, k))?);
                let ws = wingspan.unwrap_or(frames[k].wingspan_px);
                let allow = 0.5 * f.0.hypot(f.1) + 0.5 * ws * seconds;
                Some((v.0 - f.0).hypot(v.1 - f.1) / allow.max(1e-9))
            })
            .collect();
        let ratio = median(ratios).unwrap_or(0.0);
        if ratio <= 1.0 {
            coherence.insert(id, (1.5 - ratio).clamp(0.5, 1.0));
        }
    }
    for f in frames.iter_mut() {
        if f.birds.iter().any(|b| coherence.contains_key(&b.id)) {
            f.birds.retain(|b| coherence.contains_key(&b.id));
        }
    }
    coherence
}

/// The flight direction from the birds' shapes alone (no motion): across the wings' mean
/// axis, pointing to the end where the flock is narrowest (a V's or a J's leader).
fn shape_heading(birds: &[TrackedBird]) -> f64 {
    let (c, s) = birds.iter().fold((0.0, 0.0), |(c, s), b| {
        (c + (2.0 * b.blob.axis).cos(), s + (2.0 * b.blob.axis).sin())
    });
    let wing = 0.5 * s.atan2(c);
    // Flight axis, image coordinates (x right, y down).
    let (ux, uy) = (-wing.sin(), wing.cos());
    // Along the flight axis t, across it l: a line formation widens from its leader backward,
    // so the front is where the birds' distance from the middle line shrinks.
    let t: Vec<f64> = birds.iter().map(|b| b.x * ux + b.y * uy).collect();
    let l: Vec<f64> = birds.iter().map(|b| b.x * uy - b.y * ux).collect();
    let lm = median(l.clone()).unwrap_or(0.0);
    let n = t.len().max(1) as f64;
    let tm = t.iter().sum::<f64>() / n;
    let wm = l.iter().map(|v| (v - lm).abs()).sum::<f64>() / n;
    let cov: f64 = t
        .iter()
        .zip(&l)
        .map(|(ti, li)| (ti - tm) * ((li - lm).abs() - wm))
        .sum();
    let (dx, dy) = if cov <= 0.0 { (ux, uy) } else { (-ux, -uy) };
    dx.atan2(-dy).to_degrees().rem_euclid(360.0)
}

/// Circular mean of angles in degrees.
fn mean_angle(a: impl Iterator<Item = f64>) -> f64 {
    let (c, s) = a.fold((0.0, 0.0), |(c, s), d: f64| {
        (c + d.to_radians().cos(), s + d.to_radians().sin())
    });
    s.atan2(c).to_degrees().rem_euclid(360.0)
}

fn round_to(v: f64, digits: i32) -> f64 {
    let p = 10f64.powi(digits);
    (v * p).round() / p
}

impl Tracked {
    /// The flock's flight direction over the whole footage (circular mean), degrees.
    pub fn heading_deg(&self) -> f64 {
        mean_angle(self.frames.iter().map(|f| f.heading_deg))
    }

    /// The median wingspan over frames, pixels.
    pub fn wingspan_px(&self) -> f64 {
        median(self.frames.iter().map(|f| f.wingspan_px).collect()).unwrap_or(1.0)
    }

    /// Number of distinct track ids.
    pub fn track_count(&self) -> usize {
        let mut ids: Vec<usize> = self
            .frames
            .iter()
            .flat_map(|f| f.birds.iter().map(|b| b.id))
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    }

    /// The native annotation JSON (what `extract` reads), with the footage's `fps`, each frame's
    /// time `t`, measured `wingspan_px` and `heading`, and each bird's `confidence`.
    /// Pretty-printed, fields in the documented order, ending with a newline.
    pub fn to_native(&self) -> String {
        #[derive(Serialize)]
        struct Bird {
            id: usize,
            x: f64,
            y: f64,
            confidence: f64,
        }
        #[derive(Serialize)]
        struct Frame<'a> {
            index: usize,
            #[serde(skip_serializing_if = "Option::is_none")]
            t: Option<f64>,
            #[serde(skip_serializing_if = "Option::is_none")]
            image: Option<&'a str>,
            wingspan_px: f64,
            heading: f64,
            birds: Vec<Bird>,
        }
        #[derive(Serialize)]
        struct File<'a> {
            source: &'a str,
            #[serde(skip_serializing_if = "Option::is_none")]
            fps: Option<f64>,
            heading: f64,
            wingspan_px: f64,
            image_size: [usize; 2],
            polarity: &'static str,
            frames: Vec<Frame<'a>>,
        }
        let file = File {
            source: &self.source,
            fps: self.fps,
            heading: round_to(self.heading_deg(), 1),
            wingspan_px: round_to(self.wingspan_px(), 2),
            image_size: [self.width, self.height],
            polarity: match self.polarity {
                Polarity::Bright => "bright",
                _ => "dark",
            },
            frames: self
                .frames
                .iter()
                .map(|f| Frame {
                    index: f.index,
                    t: self.fps.map(|fps| round_to(f.index as f64 / fps, 6)),
                    image: f.image.as_deref(),
                    wingspan_px: round_to(f.wingspan_px, 2),
                    heading: round_to(f.heading_deg, 1),
                    birds: f
                        .birds
                        .iter()
                        .map(|b| Bird {
                            id: b.id,
                            x: round_to(b.x, 2),
                            y: round_to(b.y, 2),
                            confidence: b.confidence,
                        })
                        .collect(),
                })
                .collect(),
        };
        let mut text = serde_json::to_string_pretty(&file).unwrap_or_default();
        text.push('\n');
        text
    }
}

/// Tracks the footage at `input` (a video, a directory of images or a glob).
pub fn track_path(
    input: &Path,
    opts: &TrackOptions,
    progress: &dyn Progress,
    mut keep: impl FnMut(usize, &Gray),
) -> Result<Tracked> {
    opts.validate()?;
    let mut run = Tracking::new(opts)?;
    let source = input.display().to_string();
    match source::open(input)? {
        source::Input::Images(files) => {
            let wanted: Vec<(usize, &std::path::PathBuf)> = files
                .iter()
                .enumerate()
                .filter(|(k, _)| opts.wants(*k))
                .collect();
            if wanted.len() > crate::limits::MAX_ANNOTATED_FRAMES {
                return Err(Error::parameter(
                    "track.frames",
                    format!(
                        "{} frames to track, at most {} (the most annotations hold); choose fewer with track.every or track.frames",
                        wanted.len(),
                        crate::limits::MAX_ANNOTATED_FRAMES
                    ),
                ));
            }
            if wanted.is_empty() {
                return Err(Error::parameter(
                    "track.frames",
                    format!(
                        "no frame in the chosen range: the footage has {} frames",
                        files.len()
                    ),
                ));
            }
            progress.start("tracking", wanted.len() as u64);
            for (k, p) in wanted {
                let g = source::read_image(p)?;
                let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
                run.push(k, name, &g, p)?;
                keep(k, &g);
                progress.advance(1);
            }
            progress.finish();
            run.finish(&source, None)
        }
        source::Input::Video { path, .. } => {
            let mut v = source::VideoFrames::start(&path)?;
            let fps = v.fps;
            if let Err(e) = opts.roi_in(v.width, v.height) {
                v.stop();
                return Err(e);
            }
            let mut warning = None;
            progress.start("tracking", 0);
            let mut k = 0usize;
            loop {
                if opts.done(k) {
                    v.stop();
                    break;
                }
                let frame = match v.next_frame() {
                    Ok(Some(g)) => g,
                    Ok(None) => {
                        warning = v.finish(k)?;
                        break;
                    }
                    Err(e) => {
                        v.stop();
                        return Err(e);
                    }
                };
                if opts.wants(k) {
                    if let Err(e) = run.push(k, None, &frame, &path) {
                        v.stop();
                        return Err(e);
                    }
                    keep(k, &frame);
                    progress.advance(1);
                }
                k += 1;
            }
            progress.finish();
            if k == 0 {
                return Err(Error::format(
                    &path,
                    "ffmpeg gave no frame: the video is empty or cannot be decoded",
                ));
            }
            let mut tracked = run.finish(&source, fps).map_err(|e| match e {
                Error::Format { .. } => Error::parameter(
                    "track.frames",
                    format!("no frame in the chosen range: the video has {k} frames"),
                ),
                e => e,
            })?;
            tracked.decoded = Some(k);
            tracked.warnings.extend(warning);
            Ok(tracked)
        }
    }
}
