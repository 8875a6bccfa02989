//! The image outputs: an animated GIF, a directory of numbered PNG frames and a video (`.mp4`
//! H.264, `.webm` VP9, encoded by the system `ffmpeg`), all drawn by [`scene`] along the
//! [`camera`] path.
//!
//! Frames are drawn in parallel (one worker per core pulls the next frame number; results are
//! consumed in order), and every frame depends only on its own time, so outputs are
//! byte-identical whatever the thread count.
//!
//! **GIF.** One global palette learnt from the film ([`Palette::learn`], NeuQuant), with a
//! screen-fixed ordered dither in the sky ([`Lookup::index_dithered`]; the plumage is mapped
//! exactly).
//! Every frame after the first stores only what changed, as the bounding box of the changed
//! pixels with unchanged ones transparent (disposal "keep"). "Changed" is judged against what the
//! viewer currently sees, with a tolerance ([`super::RenderOptions::gif_tolerance`]): a pixel is
//! redrawn only when its true colour differs from the shown palette colour by more than the
//! tolerance in some channel, so a soft cloud sliding by a pixel costs little, while every bird
//! (dark on the sky) is redrawn exactly. The shown picture therefore never strays from the true
//! one by more than the tolerance (plus half the dither and the palette's own error), and a
//! pixel held back that way is set to its own colour once its true colour stops changing. The
//! differencing is
//! sequential in time but independent per pixel, so it runs in parallel over bands of rows,
//! and skips runs of pixels that repeat the previous frame (the top-down sky is scrolled by whole
//! pixels, [`Backdrop::paint_scrolled`], so most of the sky repeats from frame to frame); LZW
//! compression ([`super::lzw`], which matches a run of the transparent index in one step per
//! code) runs in parallel over frames. GIF frame delays are whole hundredths of a
//! second, so the GIF frame rate is `100 / round(100 / fps)`: 25 fps by default.
//!
//! **Video.** Raw RGBA frames are piped into `ffmpeg` (found on `PATH`, or at the path in the
//! `FORMATION_FFMPEG` environment variable), which writes the temporary file that is renamed
//! into place when it succeeds (like every output, atomically).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

use super::camera::{self, CameraParams, View};
use super::field::Field;
use super::lzw::Lzw;
use super::palette::{Lookup, Palette, TRANSPARENT};
use super::raster::{Canvas, Mask};
use super::sample::{self, BirdState, Place};
use super::scene::{self, Backdrop, Background, SkyCache, Style};
use super::RenderOptions;
use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::io::{AtomicDir, AtomicFile};
use crate::progress::Progress;
use crate::wingbeat::{Flapper, Species};

/// Default frame rate of GIF output, frames per second (a whole number of 1/100 s per frame).
pub const GIF_FPS: f64 = 25.0;

/// Everything needed to draw any frame of one image output. The birds of a frame are sampled
/// from the animation when the frame is drawn ([`Film::states`]), so a film holds its camera
/// and the wingbeats, not a copy of the flock at every picture frame.
pub struct Film<'a> {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Output frame rate, frames per second.
    pub fps: f64,
    /// Time of each output frame, seconds.
    pub times: Vec<f64>,
    /// The animation the birds are sampled from.
    anim: &'a Animation,
    /// Its wingbeats.
    flapper: Flapper,
    /// A loop drawn in the flock's moving frame: the flock's travel taken off (see
    /// [`loop_travel`]).
    travel: Option<LoopTravel>,
    /// Camera at each output frame.
    pub views: Vec<View>,
    /// The birds' species (silhouette and plumage).
    pub species: Species,
    backdrop: Backdrop,
    /// The GIF's scrolled sky, shared by the workers.
    sky: SkyCache,
    /// The ground or water under the birds on it (top-down cameras).
    field: Field,
    gif_tolerance: i32,
    /// One cycle of a loop: the GIF's last frame is written exactly (no tolerance), so that the
    /// step back to the first frame (always drawn whole) is a true step.
    looped: bool,
}

impl<'a> Film<'a> {
    /// Samples `anim` at `fps` and plans the default camera for a `width × height` picture.
    pub fn new(anim: &'a Animation, fps: f64, width: usize, height: usize) -> Film<'a> {
        let opts = RenderOptions {
            width: width as u32,
            height: height as u32,
            ..RenderOptions::default()
        };
        Film::with_options(anim, fps, &opts)
    }

    /// Samples `anim` at `fps` and plans the camera, background and look of `opts` (its
    /// `width × height`; its other fields are assumed checked by [`RenderOptions::validate`]).
    pub fn with_options(anim: &'a Animation, fps: f64, opts: &RenderOptions) -> Film<'a> {
        let (width, height) = (opts.width as usize, opts.height as usize);
        let times = sample::output_times(anim, fps);
        let travel = loop_travel(anim);
        // The camera plans from the birds' places at every picture frame (a quarter of their
        // whole states, and only while it plans).
        let mut places: Vec<Vec<Place>> =
            times.iter().map(|&t| sample::places_at(anim, t)).collect();
        if let Some(lt) = &travel {
            for (&t, st) in times.iter().zip(places.iter_mut()) {
                let (dx, dy) = lt.at(t);
                for b in st.iter_mut() {
                    b.x -= dx;
                    b.y -= dy;
                }
            }
        }
        let species = anim
            .species
            .as_deref()
            .and_then(|s| s.parse::<Species>().ok())
            .unwrap_or_default();
        let params = CameraParams {
            kind: opts.camera,
            min_bird_px: camera::min_bird_px_for(opts.min_bird_px, anim.formation_count()),
            bird_radius: super::silhouette::radius(species),
            cyclic: anim.looped,
            ..CameraParams::default()
        };
        let views = camera::track(&places, fps, width, height, &params);
        let field = surface_field(anim, opts);
        drop(places);
        let flapper = Flapper::from_animation(anim);
        let style = Style {
            sun: opts.sun,
            ..Style::default()
        };
        Film {
            width,
            height,
            fps,
            times,
            anim,
            flapper,
            travel,
            views,
            species,
            backdrop: Backdrop::new(width, height, &style, opts.background, anim.seed),
            sky: SkyCache::default(),
            field,
            gif_tolerance: opts.gif_tolerance.round().clamp(0.0, 255.0) as i32,
            looped: anim.looped,
        }
    }

    /// The birds at frame `k` (empty past the end).
    pub fn states(&self, k: usize) -> Vec<BirdState> {
        let Some(&t) = self.times.get(k) else {
            return Vec::new();
        };
        let mut st = sample::state_at(self.anim, &self.flapper, t);
        if let Some(lt) = &self.travel {
            let (dx, dy) = lt.at(t);
            for b in st.iter_mut() {
                b.x -= dx;
                b.y -= dy;
            }
        }
        st
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when there is no frame.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The background behind the birds.
    pub fn background(&self) -> Background {
        self.backdrop.background()
    }

    /// The backdrop (sky and clouds).
    pub fn backdrop(&self) -> &Backdrop {
        &self.backdrop
    }

    /// Draws frame `k` into `canvas` (which must be `width × height`). With `for_gif` the
    /// top-down sky's cloud layers are rendered once and scrolled by whole pixels
    /// ([`Backdrop::paint_scrolled`]: the GIF's frames then repeat the sky exactly between
    /// steps); without, every frame's sky is painted exactly (PNG frames, video).
    pub fn draw(&self, k: usize, canvas: &mut Canvas, mask: &mut Mask, for_gif: bool) {
        if for_gif {
            self.backdrop
                .paint_scrolled(&self.views[k], canvas, &self.sky);
        } else {
            self.backdrop.paint(&self.views[k], canvas);
        }
        self.field.paint(&self.views[k], canvas);
        scene::draw_birds(canvas, &self.states(k), &self.views[k], self.species, mask);
    }

    /// The GIF palette: NeuQuant over pixels of up to 60 frames spread over the film (every
    /// 47th pixel of each: as many pixels as 17 frames at every 13th, over more of the film's
    /// skies, so a camera that tilts to a deeper blue or a pale haze seen for a few seconds is
    /// still in the sample; 17 frames left the README job's last seconds 8 levels off), plus the
    /// species' plumage exactly.
    pub fn palette(&self) -> Palette {
        const PALETTE_FRAMES: usize = 60;
        const PALETTE_STEP: usize = 47;
        let (w, h) = (self.width, self.height);
        let n = self.len();
        let picks: Vec<usize> = if n == 0 {
            Vec::new()
        } else {
            // Frames spread over the film.
            let m = n.min(PALETTE_FRAMES);
            let mut v: Vec<usize> = (0..m).map(|i| i * (n - 1) / (m - 1).max(1)).collect();
            v.dedup();
            v
        };
        let mut canvas = Canvas::new(w, h);
        let mut mask = Mask::new();
        let mut train = Vec::new();
        for k in picks {
            self.draw(k, &mut canvas, &mut mask, true);
            for p in canvas.rgba.chunks_exact(4).step_by(PALETTE_STEP) {
                train.extend_from_slice(p);
            }
        }
        // The field's soft edge blends its colours into the sky for the few seconds it is in
        // view, too few of the sampled frames to teach the palette those blends (the edge came
        // out in bands 20 levels deep): every 8th sampled pixel, blended into each field
        // colour along the fade.
        let blends: Vec<u8> = self
            .field
            .colours()
            .iter()
            .flat_map(|&g| {
                train.chunks_exact(4).step_by(8).flat_map(move |p| {
                    [0.1f32, 0.22, 0.34, 0.46, 0.58, 0.7, 0.82, 0.94]
                        .into_iter()
                        .flat_map(move |a| {
                            let mix = |k: usize| {
                                (p[k] as f32 + (g[k] as f32 - p[k] as f32) * a).round() as u8
                            };
                            [mix(0), mix(1), mix(2), 255]
                        })
                })
            })
            .collect();
        train.extend_from_slice(&blends);
        Palette::learn(&train, &self.exact_colours())
    }

    /// The colours the GIF palette holds exactly and maps undithered: the plumage, and the flat
    /// colours of the field under the birds.
    fn exact_colours(&self) -> Vec<[u8; 3]> {
        let pl = super::silhouette::plumage(self.species);
        let mut v = vec![pl.body, pl.arm, pl.hand, pl.head];
        v.extend(self.field.colours());
        v
    }
}

/// A loop in the flock's moving frame (`Animation::looped`, not on a closed path) is drawn in
/// that frame: the flock's travel over the loop, spread evenly over its duration, is taken off
/// every bird, so the camera, the sky and the birds of the last picture lead into the first
/// without a jump (the flock holds its place in a still sky). On a closed path the loop is in
/// the world and is drawn as it is.
struct LoopTravel {
    /// Time of the loop's first frame, seconds.
    start: f64,
    /// The loop's duration, seconds.
    period: f64,
    /// The flock's travel over one loop, wingspans east and north.
    dx: f64,
    dy: f64,
}

impl LoopTravel {
    /// The travel taken off at time `t`, wingspans east and north.
    fn at(&self, t: f64) -> (f64, f64) {
        let u = (t - self.start) / self.period;
        (u * self.dx, u * self.dy)
    }
}

/// The travel [`LoopTravel`] of `anim`, `None` when it is not a loop in the flock's frame.
fn loop_travel(anim: &Animation) -> Option<LoopTravel> {
    if !anim.looped || anim.path.as_ref().is_some_and(|p| p.closed) {
        return None;
    }
    let closed = super::gltf::closed_loop(anim);
    let (first, close) = (anim.frames.first()?, closed.frames.last()?);
    let period = close.t - first.t;
    if !(period > 0.0) || closed.frames.len() == anim.frames.len() {
        return None;
    }
    Some(LoopTravel {
        start: first.t,
        period,
        dx: close.x[0] - first.x[0],
        dy: close.y[0] - first.y[0],
    })
}

/// Number of worker threads to use when `requested` is 0 (automatic).
pub fn worker_count(requested: usize) -> usize {
    if requested > 0 {
        return requested.min(64);
    }
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(16)
}

/// Runs `work(k, state)` for `k in 0..n` on `threads` workers, each with its own `state` from
/// `init`, and hands results to `sink` in frame order. Stops at the first error.
pub fn run_frames<S, T, I, F, K>(
    n: usize,
    threads: usize,
    init: I,
    work: F,
    mut sink: K,
) -> Result<()>
where
    T: Send,
    I: Fn() -> S + Sync,
    F: Fn(usize, &mut S) -> Result<T> + Sync,
    K: FnMut(usize, T) -> Result<()>,
{
    let threads = threads.clamp(1, n.max(1));
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::sync_channel::<(usize, Result<T>)>(2 * threads);
        for _ in 0..threads {
            let tx = tx.clone();
            let (next, stop, init, work) = (&next, &stop, &init, &work);
            scope.spawn(move || {
                let mut state = init();
                loop {
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= n {
                        break;
                    }
                    let r = work(k, &mut state);
                    if tx.send((k, r)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        let mut pending = BTreeMap::new();
        let mut want = 0;
        let result = (|| {
            for (k, r) in rx.iter() {
                pending.insert(k, r);
                while let Some(r) = pending.remove(&want) {
                    sink(want, r?)?;
                    want += 1;
                }
            }
            Ok(())
        })();
        stop.store(true, Ordering::Relaxed);
        drop(rx);
        result
    })
}

/// GIF frames are drawn, differenced and compressed in batches of at most this many frames
/// (bounded memory: a batch holds its RGBA pictures and sub-frames).
const GIF_BATCH: usize = 16;

/// Bytes of RGBA pictures a GIF batch may hold: 16 frames up to 1920×1080 (133 MB), fewer for
/// larger pictures (two at 8K, where 16 held 2.1 GB and the run peaked at 3.1 GB).
const GIF_BATCH_BYTES: usize = 136 << 20;

/// Frames per GIF batch for `w × h` pictures and `threads` workers: as many as fit in
/// [`GIF_BATCH_BYTES`], at least one per worker (and at least two), at most [`GIF_BATCH`]. The
/// batch size changes nothing in the file: frames are differenced in order whatever the batches.
fn gif_batch(w: usize, h: usize, threads: usize) -> usize {
    let frame = (w * h * 4).max(1);
    (GIF_BATCH_BYTES / frame).clamp(threads.clamp(2, GIF_BATCH), GIF_BATCH)
}

/// The part of `cur` that differs from `prev` as a GIF sub-frame: its bounding box, with
/// unchanged pixels set to [`TRANSPARENT`] (shown through from the previous frame, which the
/// `Keep` disposal leaves in place). Returns `(left, top, width, height, indices)`.
pub fn frame_delta(prev: &[u8], cur: &[u8], width: usize) -> (usize, usize, usize, usize, Vec<u8>) {
    let out: Vec<u8> = prev
        .iter()
        .zip(cur)
        .map(|(&p, &q)| if p == q { TRANSPARENT } else { q })
        .collect();
    crop_changed(&out, width)
}

/// The bounding box of the non-[`TRANSPARENT`] pixels of `delta` (a full `width`-wide frame)
/// and its contents; a 1×1 transparent frame when nothing changed.
fn crop_changed(delta: &[u8], width: usize) -> (usize, usize, usize, usize, Vec<u8>) {
    let height = delta.len() / width.max(1);
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for y in 0..height {
        let row = &delta[y * width..(y + 1) * width];
        let Some(first) = row.iter().position(|&v| v != TRANSPARENT) else {
            continue;
        };
        let last = width
            - 1
            - row
                .iter()
                .rev()
                .position(|&v| v != TRANSPARENT)
                .unwrap_or(0);
        x0 = x0.min(first);
        x1 = x1.max(last);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 == usize::MAX {
        return (0, 0, 1, 1, vec![TRANSPARENT]);
    }
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut out = Vec::with_capacity(w * h);
    for y in y0..=y1 {
        out.extend_from_slice(&delta[y * width + x0..y * width + x1 + 1]);
    }
    (x0, y0, w, h, out)
}

/// One step of the tolerant differencing for a run of pixels starting at pixel `start` of a
/// picture `width` wide: `shown` (palette indices the viewer sees, updated in place; `first` for
/// the first frame), `dirty` (1 where the shown index was held back by the tolerance and may
/// differ from the true colour's own index), the frame's true colours `rgba` and the previous
/// frame's `prev`; writes the sub-frame indices (or [`TRANSPARENT`]) to `out`. Only pixels that
/// must change are looked up in the palette. A pixel's "own" index is its colour with the
/// screen-fixed ordered dither ([`Lookup::index_dithered`]), except the colours in `plain` (the
/// plumage, which the palette holds exactly) which are mapped undithered.
///
/// Runs of [`DELTA_BLOCK`] pixels whose colour is the same as in the previous frame and that
/// hold nothing back are skipped whole: nothing to send there (the scrolled sky repeats
/// exactly between its whole-pixel steps, so most of a frame is such runs).
#[allow(clippy::too_many_arguments)]
fn delta_step(
    shown: &mut [u8],
    dirty: &mut [u8],
    first: bool,
    rgba: &[u8],
    prev: &[u8],
    out: &mut [u8],
    lookup: &mut Lookup,
    palette: &Palette,
    tolerance: i32,
    catch_up: bool,
    refresh: bool,
    (start, width): (usize, usize),
    plain: &[[u8; 3]],
) {
    let n = shown.len().min(dirty.len()).min(out.len());
    let skip = !first && !catch_up;
    let mut i = 0;
    while i < n {
        let e = (i + DELTA_BLOCK).min(n);
        if skip && rgba[i * 4..e * 4] == prev[i * 4..e * 4] && dirty[i..e].iter().all(|&d| d == 0) {
            out[i..e].fill(TRANSPARENT);
        } else {
            delta_pixels(
                &mut shown[i..e],
                &mut dirty[i..e],
                first,
                &rgba[i * 4..e * 4],
                &prev[i * 4..e * 4],
                &mut out[i..e],
                lookup,
                palette,
                tolerance,
                catch_up,
                refresh,
                (start + i, width),
                plain,
            );
        }
        i = e;
    }
}

/// Side of the blocks whose mean error `block_refresh` bounds, pixels.
pub const REFRESH_BLOCK: usize = 4;

/// Largest mean error, levels in some channel, that a [`REFRESH_BLOCK`]-square block of the
/// GIF may keep against the true picture before it is sent again at its own colours. Every
/// 8 × 8 box on the block grid averages four blocks, so no such box strays from the true
/// picture by more than this on top of what the palette and dither leave in a freshly sent
/// block.
pub const BLOCK_MEAN_TOLERANCE: f64 = 4.0;

/// The second pass of the differencing over a band of rows (after [`delta_step`]): the
/// per-pixel tolerance alone lets many pixels lag the same way at once (the soft edge of a cloud
/// sliding by, the faint trail of a bird, a slow gradient), which the eye sees as a stale patch
/// once the dither's grain is averaged out. So the band is cut into
/// [`REFRESH_BLOCK`]-square blocks on a screen-fixed grid (the band starts on a block row), and
/// every block whose true colours changed, or which sent something this frame, is checked: when
/// the mean of `shown − true` over the block exceeds [`BLOCK_MEAN_TOLERANCE`] in some channel,
/// every pixel of the block is set to its own (dithered) index. Blocks that did not change keep
/// the state that was checked when they last did, so the bound holds in every frame.
#[allow(clippy::too_many_arguments)]
fn block_refresh(
    shown: &mut [u8],
    dirty: &mut [u8],
    rgba: &[u8],
    prev: &[u8],
    out: &mut [u8],
    lookup: &mut Lookup,
    palette: &Palette,
    all: bool,
    (start, width): (usize, usize),
    plain: &[[u8; 3]],
) {
    let width = width.max(1);
    let n = shown.len().min(dirty.len()).min(out.len());
    let rows = n / width;
    let y_base = start / width;
    let limit = (BLOCK_MEAN_TOLERANCE * (REFRESH_BLOCK * REFRESH_BLOCK) as f64) as i32;
    for by in (0..rows).step_by(REFRESH_BLOCK) {
        let y1 = (by + REFRESH_BLOCK).min(rows);
        for bx in (0..width).step_by(REFRESH_BLOCK) {
            let x1 = (bx + REFRESH_BLOCK).min(width);
            let touched = all
                || (by..y1).any(|y| {
                    let (a, b) = (y * width + bx, y * width + x1);
                    rgba[a * 4..b * 4] != prev[a * 4..b * 4]
                        || out[a..b].iter().any(|&o| o != TRANSPARENT)
                });
            if !touched {
                continue;
            }
            let mut sum = [0i32; 3];
            for y in by..y1 {
                for i in y * width + bx..y * width + x1 {
                    let c = palette.colours[shown[i] as usize];
                    for k in 0..3 {
                        sum[k] += c[k] as i32 - rgba[i * 4 + k] as i32;
                    }
                }
            }
            let count = ((y1 - by) * (x1 - bx)) as i32;
            // Scaled to a full block: `limit` is the tolerance times a full block's pixels.
            let full = (REFRESH_BLOCK * REFRESH_BLOCK) as i32;
            if sum.iter().all(|s| s.abs() * full <= limit * count) {
                continue;
            }
            for y in by..y1 {
                for i in y * width + bx..y * width + x1 {
                    let p = &rgba[i * 4..i * 4 + 3];
                    let rgb = [p[0], p[1], p[2]];
                    let q = if plain.contains(&rgb) {
                        lookup.index(rgb)
                    } else {
                        lookup.index_dithered(rgb, i % width, y_base + y)
                    };
                    dirty[i] = 0;
                    if q != shown[i] {
                        shown[i] = q;
                        out[i] = q;
                    }
                }
            }
        }
    }
}

/// Pixels [`delta_step`] skips in one comparison when nothing changed there.
const DELTA_BLOCK: usize = 32;

/// [`delta_step`] pixel by pixel.
#[allow(clippy::too_many_arguments)]
#[inline]
fn delta_pixels(
    shown: &mut [u8],
    dirty: &mut [u8],
    first: bool,
    rgba: &[u8],
    prev: &[u8],
    out: &mut [u8],
    lookup: &mut Lookup,
    palette: &Palette,
    tolerance: i32,
    catch_up: bool,
    refresh: bool,
    (start, width): (usize, usize),
    plain: &[[u8; 3]],
) {
    let width = width.max(1);
    let (mut x, mut y) = (start % width, start / width);
    for ((((s, d), p), o), q) in shown
        .iter_mut()
        .zip(dirty.iter_mut())
        .zip(rgba.chunks_exact(4))
        .zip(out.iter_mut())
        .zip(prev.chunks_exact(4))
    {
        let (px, py) = (x, y);
        x += 1;
        if x == width {
            x = 0;
            y += 1;
        }
        let rgb = [p[0], p[1], p[2]];
        let own = |lookup: &mut Lookup| {
            if plain.contains(&rgb) {
                lookup.index(rgb)
            } else {
                lookup.index_dithered(rgb, px, py)
            }
        };
        if first {
            let q = own(lookup);
            *s = q;
            *o = q;
            *d = 0;
            continue;
        }
        // Same true colour as in the previous frame: what is shown was within the tolerance of
        // it then (or set to it), so it still is, unless the tolerance is lower now (the end of
        // a loop catching up with what earlier frames held back: every pixel is checked). A
        // pixel held back while its colour moved (a cloud edge sliding by) is set to its own
        // index as soon as its colour stops changing, so nothing stale stays behind a cloud.
        if !catch_up && p == q {
            *o = TRANSPARENT;
            if *d != 0 {
                *d = 0;
                // Within the settle margin of the true colour: as good as its own index.
                let c = palette.colours[*s as usize];
                let err = (0..3)
                    .map(|k| (c[k] as i32 - p[k] as i32).abs())
                    .max()
                    .unwrap_or(0);
                if err <= SETTLE_MARGIN {
                    continue;
                }
                let q = own(lookup);
                if q != *s {
                    *o = q;
                    *s = q;
                }
            }
            continue;
        }
        let c = palette.colours[*s as usize];
        let err = (c[0] as i32 - p[0] as i32)
            .abs()
            .max((c[1] as i32 - p[1] as i32).abs())
            .max((c[2] as i32 - p[2] as i32).abs());
        // Held back within the tolerance; a refresh frame (every REFRESH_S) sends the held
        // pixels that have drifted past the settle margin, so a cloud drifting under a still
        // camera cannot leave a stale half beside a fresh one.
        if err <= tolerance && !(refresh && err > SETTLE_MARGIN) {
            *o = TRANSPARENT;
            *d = 1;
            continue;
        }
        *d = 0;
        let q = own(lookup);
        if q == *s {
            *o = TRANSPARENT;
        } else {
            *o = q;
            *s = q;
        }
    }
}

/// A held-back pixel whose colour has stopped changing is set to its own index only when what
/// is shown is more than this many levels (in some channel) from its true colour: the dither's
/// half spread plus two levels of the palette, so what is left is no more visible than the
/// dither itself.
const SETTLE_MARGIN: i32 = super::palette::DITHER_SPREAD / 2 + 2;

/// Held-back pixels more than [`SETTLE_MARGIN`] off are sent at least this often, seconds.
const REFRESH_S: f64 = 0.5;

/// Seconds over which the GIF of a loop lowers its tolerance to 0 before the last frame.
const LOOP_CATCH_UP_S: f64 = 2.0;

/// The differencing tolerance of frame `k` of `total`: `base`, except over the last `ramp`
/// frames of a loop, where it falls linearly to 0 at the last frame, so that what the tolerance
/// held back (soft clouds lagging by a few grey levels) is caught up gradually and the last
/// frame, shown exactly, leads into the first (always drawn whole) like any other step.
fn loop_tolerance(base: i32, looped: bool, k: usize, total: usize, ramp: usize) -> i32 {
    let left = total.saturating_sub(k + 1);
    if !looped || left >= ramp {
        return base;
    }
    (base as f64 * left as f64 / ramp as f64).floor() as i32
}

/// The field under the birds at rest ([`Field`]), for a top-down camera over the sky or a plain
/// colour; empty otherwise (the ground camera has its own ground and horizon, and a transparent
/// background stays transparent for compositing). Ground where the flock takes off and where it
/// lands on a field, water where it lands on water.
///
/// A bird lays field where it is at rest on the surface: in a take-off or landing stage (the
/// stages whose heights are above the ground), its body under [`ON_SURFACE`] wingspans up and
/// slower than [`REST_SPEED`]. Steady flight, and flights made by hand or tracked, have a level
/// at z = 0 but no ground, and birds flying low through it are not sitting. The field reaches far
/// enough round the resting places to hold the take-off's run and the landing's roll-out.
///
/// [`ON_SURFACE`]: super::field::ON_SURFACE
fn surface_field(anim: &Animation, opts: &RenderOptions) -> Field {
    let top_down = !matches!(opts.camera, camera::CameraKind::Ground);
    if !top_down || opts.background == Background::None {
        return Field::default();
    }
    let water_from = anim
        .landing
        .as_ref()
        .filter(|l| l.surface == crate::animation::landing::Surface::Water)
        .and_then(|_| anim.stage("landing"))
        .map(|s| s.start);
    let points = anim
        .stages
        .iter()
        .filter(|s| s.name == "initiation" || s.name == "landing")
        .flat_map(|s| s.start..s.end.min(anim.frames.len()))
        .flat_map(|k| {
            let f = &anim.frames[k];
            let water = water_from.is_some_and(|k0| k >= k0);
            (0..f.x.len())
                .filter(move |&i| {
                    f.z[i] < super::field::ON_SURFACE && f.speed[i].abs() < REST_SPEED
                })
                .map(move |i| (f.x[i], f.y[i], water))
        });
    let ground = match opts.background {
        Background::Colour(c) => super::scene::ground_for(c),
        _ => Style::default().ground,
    };
    Field::new(points, ground)
}

/// Below this speed, wingspans per second, a bird on the surface is at rest (sitting, or
/// floating): a walking goose's pace; a take-off run or a landing's roll-out is faster.
const REST_SPEED: f64 = 1.0;

/// A value borrowed from a pool for one worker of [`run_frames`], handed back when dropped.
struct Pooled<'a, T: Default> {
    item: Option<T>,
    pool: &'a std::sync::Mutex<Vec<T>>,
}

impl<'a, T: Default> Pooled<'a, T> {
    /// A value from `pool`, or a new one.
    fn take(pool: &'a std::sync::Mutex<Vec<T>>) -> Self {
        let item = pool
            .lock()
            .ok()
            .and_then(|mut p| p.pop())
            .unwrap_or_default();
        Pooled {
            item: Some(item),
            pool,
        }
    }

    fn get(&mut self) -> &mut T {
        self.item.get_or_insert_with(T::default)
    }
}

impl<T: Default> Drop for Pooled<'_, T> {
    fn drop(&mut self) {
        if let (Some(item), Ok(mut p)) = (self.item.take(), self.pool.lock()) {
            p.push(item);
        }
    }
}

/// Writes an animated, looping GIF of `film` to `path` (atomically).
pub fn write_gif(film: &Film, path: &Path, threads: usize, progress: &dyn Progress) -> Result<()> {
    let (w, h) = (film.width, film.height);
    let delay = (100.0 / film.fps).round().max(1.0) as u16;
    let palette = film.palette();
    let tolerance = film.gif_tolerance;
    let (looped, frames_total) = (film.looped, film.len());
    let ramp = (LOOP_CATCH_UP_S * film.fps).round().max(1.0) as usize;
    let refresh_every = (REFRESH_S * film.fps).round().max(1.0) as usize;
    let mut file = AtomicFile::create(path)?;
    let io_err = |e: gif::EncodingError| match e {
        gif::EncodingError::Io(e) => Error::io(path, e),
        other => Error::Internal(format!("{}: GIF encoder: {other}", path.display())),
    };
    {
        let mut enc = gif::Encoder::new(file.writer(), w as u16, h as u16, &palette.to_bytes())
            .map_err(io_err)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(io_err)?;
        progress.start("gif", film.len() as u64);
        // Palette indices the viewer sees after the frames written so far, in bands of rows
        // (one per worker), each with its own lookup table.
        // Bands start on a row of the refresh blocks' grid.
        let band = h
            .div_ceil(threads.max(1))
            .next_multiple_of(REFRESH_BLOCK)
            .max(REFRESH_BLOCK)
            * w;
        let mut shown = vec![0u8; w * h];
        let mut dirty = vec![0u8; w * h];
        let plain = film.exact_colours();
        let mut lookups: Vec<Lookup> = shown.chunks(band).map(|_| Lookup::new(&palette)).collect();
        // The previous frame's picture, the batch's sub-frames, and spare picture buffers.
        let mut last = vec![0u8; w * h * 4];
        let batch = gif_batch(w, h, threads);
        let mut deltas: Vec<Vec<u8>> = vec![vec![TRANSPARENT; w * h]; batch];
        let pool: std::sync::Mutex<Vec<Vec<u8>>> = std::sync::Mutex::new(Vec::new());
        let encoders: std::sync::Mutex<Vec<Lzw>> = std::sync::Mutex::new(Vec::new());
        for start in (0..film.len()).step_by(batch) {
            let count = batch.min(film.len() - start);
            // 1. Draw the batch in parallel (into buffers reused from earlier batches).
            let mut drawn: Vec<Vec<u8>> = Vec::with_capacity(count);
            run_frames(
                count,
                threads,
                || (Canvas::new(w, h), Mask::new()),
                |k, (canvas, mask): &mut (Canvas, Mask)| {
                    film.draw(start + k, canvas, mask, true);
                    let mut buf = pool
                        .lock()
                        .map(|mut p| p.pop())
                        .ok()
                        .flatten()
                        .unwrap_or_default();
                    buf.clear();
                    buf.extend_from_slice(&canvas.rgba);
                    Ok(buf)
                },
                |_, d| {
                    drawn.push(d);
                    Ok(())
                },
            )?;
            // 2. Tolerant differencing against what is shown, in parallel over bands of rows.
            {
                let mut outs: Vec<std::slice::ChunksMut<u8>> =
                    deltas.iter_mut().map(|d| d.chunks_mut(band)).collect();
                let drawn = &drawn;
                let palette = &palette;
                let last = &last;
                let plain = &plain;
                std::thread::scope(|scope| {
                    for (b, ((s, dt), lookup)) in shown
                        .chunks_mut(band)
                        .zip(dirty.chunks_mut(band))
                        .zip(&mut lookups)
                        .enumerate()
                    {
                        let mine: Vec<&mut [u8]> =
                            outs.iter_mut().map(|o| o.next().expect("band")).collect();
                        scope.spawn(move || {
                            let lo = b * band;
                            let hi = lo + s.len();
                            for (k, o) in mine.into_iter().take(count).enumerate() {
                                let prev = if k == 0 { last } else { &drawn[k - 1] };
                                let tol = loop_tolerance(
                                    tolerance,
                                    looped,
                                    start + k,
                                    frames_total,
                                    ramp,
                                );
                                delta_step(
                                    s,
                                    dt,
                                    start + k == 0,
                                    &drawn[k][lo * 4..hi * 4],
                                    &prev[lo * 4..hi * 4],
                                    o,
                                    lookup,
                                    palette,
                                    tol,
                                    tol < tolerance,
                                    (start + k) % refresh_every == 0,
                                    (lo, w),
                                    plain,
                                );
                                if start + k > 0 {
                                    block_refresh(
                                        s,
                                        dt,
                                        &drawn[k][lo * 4..hi * 4],
                                        &prev[lo * 4..hi * 4],
                                        o,
                                        lookup,
                                        palette,
                                        tol < tolerance,
                                        (lo, w),
                                        plain,
                                    );
                                }
                            }
                        });
                    }
                });
            }
            // Keep the batch's last picture for the next batch; recycle the others.
            if let Some(l) = drawn.pop() {
                let old = std::mem::replace(&mut last, l);
                drawn.push(old);
            }
            if let Ok(mut p) = pool.lock() {
                p.extend(drawn);
            }
            // 3. Crop to the changed box and LZW-compress in parallel (one encoder per worker,
            // its dictionary table kept from batch to batch).
            let mut frames = Vec::with_capacity(count);
            let deltas = &deltas;
            run_frames(
                count,
                threads,
                || Pooled::take(&encoders),
                |k, lzw: &mut Pooled<Lzw>| {
                    let (left, top, fw, fh, buf, transparent) = if start + k == 0 {
                        (0, 0, w, h, deltas[0].clone(), None)
                    } else {
                        let (l, t, fw, fh, b) = crop_changed(&deltas[k], w);
                        (l, t, fw, fh, b, Some(TRANSPARENT))
                    };
                    let mut frame = gif::Frame {
                        left: left as u16,
                        top: top as u16,
                        width: fw as u16,
                        height: fh as u16,
                        delay,
                        dispose: gif::DisposalMethod::Keep,
                        transparent,
                        ..gif::Frame::default()
                    };
                    let mut code = Vec::with_capacity(buf.len() / 4 + 16);
                    lzw.get().encode_frame(&buf, &mut code);
                    frame.buffer = Cow::Owned(code);
                    Ok(frame)
                },
                |_, frame| {
                    frames.push(frame);
                    Ok(())
                },
            )?;
            for frame in &frames {
                enc.write_lzw_pre_encoded_frame(frame).map_err(io_err)?;
                progress.advance(1);
            }
        }
        enc.into_inner().map_err(io_err)?;
    }
    file.writer().flush().map_err(|e| Error::io(path, e))?;
    file.commit()?;
    progress.finish();
    Ok(())
}

/// Name of the PNG file of frame `k` in a frames directory.
pub fn frame_name(k: usize) -> String {
    format!("frame_{k:05}.png")
}

/// Writes numbered PNG frames `frame_00000.png`, … of `film` into the directory `path`, numbered
/// from `first` (`frame_01001.png`, … for a shot starting at 1001) (atomically: a temporary sibling directory renamed into place when complete). Frames are RGB,
/// or RGBA with `render.background` none (transparent sky, for compositing).
pub fn write_png_dir(
    film: &Film,
    path: &Path,
    first: u64,
    threads: usize,
    progress: &dyn Progress,
) -> Result<()> {
    let (w, h) = (film.width, film.height);
    let alpha = film.background() == Background::None;
    let dir = AtomicDir::create(path)?;
    progress.start("png frames", film.len() as u64);
    run_frames(
        film.len(),
        threads,
        || (Canvas::new(w, h), Mask::new()),
        |k, (canvas, mask): &mut (Canvas, Mask)| {
            film.draw(k, canvas, mask, false);
            let target = dir.path(&frame_name(first as usize + k));
            let file = std::fs::File::create(&target).map_err(|e| Error::io(path, e))?;
            let mut out = std::io::BufWriter::new(file);
            let enc = image::codecs::png::PngEncoder::new_with_quality(
                &mut out,
                image::codecs::png::CompressionType::Fast,
                image::codecs::png::FilterType::Adaptive,
            );
            let (bytes, colour) = if alpha {
                (canvas.straight_rgba(), image::ExtendedColorType::Rgba8)
            } else {
                let rgb: Vec<u8> = canvas
                    .rgba
                    .chunks_exact(4)
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect();
                (rgb, image::ExtendedColorType::Rgb8)
            };
            image::ImageEncoder::write_image(enc, &bytes, w as u32, h as u32, colour).map_err(
                |e| match e {
                    // A full disk or a file-size limit: the user's problem with the output, exit 2.
                    image::ImageError::IoError(e) => Error::io(path, e),
                    other => Error::Internal(format!("{}: PNG encoder: {other}", path.display())),
                },
            )?;
            out.flush().map_err(|e| Error::io(path, e))?;
            Ok(())
        },
        |_, ()| {
            progress.advance(1);
            Ok(())
        },
    )?;
    dir.commit()?;
    progress.finish();
    Ok(())
}

/// The video codecs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VideoCodec {
    /// H.264 in MP4 (`libx264`, yuv420p, CRF 20: plays everywhere).
    H264,
    /// VP9 in WebM (`libvpx-vp9`, yuv420p, CRF 32, realtime speed).
    Vp9,
}

/// The `ffmpeg` to use: `FORMATION_FFMPEG` if set, else `ffmpeg` on `PATH`.
pub fn ffmpeg_program() -> PathBuf {
    std::env::var_os("FORMATION_FFMPEG")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("ffmpeg"))
}

/// Checks that `ffmpeg` runs, before any work; the error names the output and how to install it.
pub fn check_ffmpeg(output: &Path) -> Result<()> {
    let prog = ffmpeg_program();
    let ok = Command::new(&prog)
        .arg("-version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if ok {
        Ok(())
    } else {
        Err(Error::parameter(
            "output",
            format!(
                "{}: video is encoded by ffmpeg, and {} was not found or does not run; install it (apt-get install ffmpeg) or write .gif or PNG frames",
                output.display(),
                prog.display()
            ),
        ))
    }
}

/// Threads of ffmpeg's encoders, whatever the machine: x264's bitstream (and its options record)
/// and VP9's tiling change with the thread count, so following the cores (as the frames'
/// workers do) made equal inputs give other files on another machine or under `taskset`.
pub const VIDEO_ENCODER_THREADS: usize = 4;

/// Writes `film` as a video to `path` (atomically) by piping raw RGBA frames into `ffmpeg`.
pub fn write_video(
    film: &Film,
    path: &Path,
    codec: VideoCodec,
    threads: usize,
    progress: &dyn Progress,
) -> Result<()> {
    let (w, h) = (film.width, film.height);
    let file = AtomicFile::create(path)?;
    let mut cmd = Command::new(ffmpeg_program());
    cmd.args(["-hide_banner", "-nostdin", "-loglevel", "error", "-y"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgba"])
        .args(["-s", &format!("{w}x{h}")])
        .args(["-framerate", &format!("{}", film.fps)])
        .args(["-i", "pipe:0"])
        .args(["-map_metadata", "-1", "-fflags", "+bitexact"]);
    match codec {
        VideoCodec::H264 => cmd.args([
            "-c:v",
            "libx264",
            "-preset",
            "veryfast",
            "-crf",
            "20",
            "-threads",
            &VIDEO_ENCODER_THREADS.to_string(),
            "-pix_fmt",
            "yuv420p",
            "-movflags",
            "+faststart",
            "-f",
            "mp4",
        ]),
        VideoCodec::Vp9 => cmd.args([
            "-c:v",
            "libvpx-vp9",
            "-crf",
            "32",
            "-b:v",
            "0",
            "-deadline",
            "realtime",
            "-cpu-used",
            "8",
            "-row-mt",
            "1",
            "-threads",
            &VIDEO_ENCODER_THREADS.to_string(),
            "-pix_fmt",
            "yuv420p",
            "-f",
            "webm",
        ]),
    };
    cmd.arg(file.temp_path())
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let ff_err = |m: String| Error::Internal(format!("{}: ffmpeg: {m}", path.display()));
    let mut child = cmd.spawn().map_err(|e| ff_err(e.to_string()))?;
    let mut stdin = child.stdin.take().expect("piped");
    // Read ffmpeg's messages on a thread so a chatty encoder cannot block the pipe.
    let mut stderr = child.stderr.take().expect("piped");
    let messages = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut s);
        s
    });
    progress.start("video", film.len() as u64);
    let piped = run_frames(
        film.len(),
        threads,
        || (Canvas::new(w, h), Mask::new()),
        |k, (canvas, mask): &mut (Canvas, Mask)| {
            film.draw(k, canvas, mask, false);
            Ok(canvas.rgba.clone())
        },
        |_, rgba| {
            stdin
                .write_all(&rgba)
                .map_err(|e| ff_err(format!("stopped reading frames ({e})")))?;
            progress.advance(1);
            Ok(())
        },
    );
    drop(stdin);
    let status = child.wait().map_err(|e| ff_err(e.to_string()))?;
    let said = messages.join().unwrap_or_default();
    if !status.success() {
        let last = said
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("");
        return Err(ff_err(format!("failed ({status}): {last}")));
    }
    piped?;
    file.commit()?;
    progress.finish();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_loop_lowers_the_gif_tolerance_to_zero_at_its_last_frame() {
        // 100 frames, a ramp of 10: the base up to frame 89, then falling to 0 at frame 99.
        let t: Vec<i32> = (0..100)
            .map(|k| loop_tolerance(12, true, k, 100, 10))
            .collect();
        assert!(t[..90].iter().all(|&v| v == 12));
        assert!(t[90..].windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(t[99], 0);
        assert!(t[95] > 0 && t[95] < 12);
        // Not a loop: the base everywhere.
        assert!((0..100).all(|k| loop_tolerance(12, false, k, 100, 10) == 12));
    }

    #[test]
    fn a_frame_written_exactly_catches_up_with_held_back_pixels() {
        // One grey pixel shown as palette colour 0 (black) while its true colour has been white
        // for two frames: the tolerant step keeps it (same true colour as before), the
        // catching-up step at tolerance 0 sends it.
        let mut colours = vec![[0u8, 0, 0]; 256];
        colours[1] = [255, 255, 255];
        let palette = Palette { colours };
        let mut lookup = Lookup::new(&palette);
        let white = [255u8, 255, 255, 255];
        let white3 = [255u8, 255, 255];
        let mut out = [TRANSPARENT];
        let mut shown = [0u8];
        let mut dirty = [0u8];
        delta_step(
            &mut shown,
            &mut dirty,
            false,
            &white,
            &white,
            &mut out,
            &mut lookup,
            &palette,
            255,
            false,
            false,
            (0, 1),
            &[white3],
        );
        assert_eq!((shown[0], out[0]), (0, TRANSPARENT));
        delta_step(
            &mut shown,
            &mut dirty,
            false,
            &white,
            &white,
            &mut out,
            &mut lookup,
            &palette,
            0,
            true,
            false,
            (0, 1),
            &[white3],
        );
        assert_eq!((shown[0], out[0]), (1, 1));
    }

    #[test]
    fn frame_delta_keeps_only_the_changed_box() {
        let prev = vec![1u8; 6 * 4];
        let mut cur = prev.clone();
        cur[6 + 2] = 7;
        cur[2 * 6 + 4] = 9;
        let (l, t, w, h, buf) = frame_delta(&prev, &cur, 6);
        assert_eq!((l, t, w, h), (2, 1, 3, 2));
        assert_eq!(
            buf,
            vec![7, TRANSPARENT, TRANSPARENT, TRANSPARENT, TRANSPARENT, 9]
        );
        let (_, _, w, h, buf) = frame_delta(&prev, &prev, 6);
        assert_eq!((w, h, buf), (1, 1, vec![TRANSPARENT]));
    }
}
