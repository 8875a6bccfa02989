//! The image outputs: an animated GIF and a directory of numbered PNG frames, both drawn by
//! [`scene`] along the [`camera`] path.
//!
//! Frames are drawn in parallel (one worker per core pulls the next frame number; results are
//! written in order), and every frame depends only on its own time, so outputs are byte-identical
//! whatever the thread count. GIF frames are mapped to the fixed [`Palette`] and LZW-compressed in
//! the workers, and every frame after the first stores only the box of pixels that changed, with
//! unchanged ones transparent (clear sky is fixed on screen, so most of it costs nothing); the
//! file is one global palette, a NETSCAPE loop extension (loop forever) and the
//! frames. GIF frame delays are whole hundredths of a second, so the GIF frame rate is
//! `100 / round(100 / fps)`: 25 fps by default (4/100 s per frame).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

use super::camera::{self, CameraParams, View};
use super::palette::{Lookup, Palette, TRANSPARENT};
use super::raster::{Canvas, Mask};
use super::sample::{self, BirdState};
use super::scene::{self, Backdrop, Style};
use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::io::{AtomicDir, AtomicFile};
use crate::progress::Progress;
use crate::wingbeat::Flapper;

/// Default frame rate of GIF output, frames per second (a whole number of 1/100 s per frame).
pub const GIF_FPS: f64 = 25.0;

/// Everything needed to draw any frame of one image output.
pub struct Film {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Output frame rate, frames per second.
    pub fps: f64,
    /// Time of each output frame, seconds.
    pub times: Vec<f64>,
    /// Birds at each output frame.
    pub states: Vec<Vec<BirdState>>,
    /// Camera at each output frame.
    pub views: Vec<View>,
    backdrop: Backdrop,
}

impl Film {
    /// Samples `anim` at `fps` and plans the camera for a `width × height` picture.
    pub fn new(anim: &Animation, fps: f64, width: usize, height: usize) -> Film {
        let flapper = Flapper::from_animation(anim);
        let times = sample::output_times(anim, fps);
        let states: Vec<Vec<BirdState>> = times
            .iter()
            .map(|&t| sample::state_at(anim, &flapper, t))
            .collect();
        let views = camera::track(&states, fps, width, height, &CameraParams::default());
        let style = Style::default();
        Film {
            width,
            height,
            fps,
            times,
            states,
            views,
            backdrop: Backdrop::new(width, height, &style, anim.seed),
        }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when there is no frame.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Draws frame `k` into `canvas` (which must be `width × height`); `dither` prepares it for
    /// the GIF palette (see [`Backdrop::paint`]).
    pub fn draw(&self, k: usize, canvas: &mut Canvas, mask: &mut Mask, dither: bool) {
        self.backdrop.paint(&self.views[k], canvas, dither);
        scene::draw_birds(
            canvas,
            &self.states[k],
            &self.views[k],
            self.backdrop.style(),
            mask,
        );
    }

    /// The palette for GIF output.
    pub fn palette(&self) -> Palette {
        Palette::for_style(self.backdrop.style())
    }
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

/// GIF frames are mapped and compressed in batches of this many frames (bounded memory).
const GIF_BATCH: usize = 32;

/// The part of `cur` that differs from `prev` as a GIF sub-frame: its bounding box, with
/// unchanged pixels set to [`TRANSPARENT`] (shown through from the previous frame, which the
/// `Keep` disposal leaves in place). Returns `(left, top, width, height, indices)`.
pub fn frame_delta(prev: &[u8], cur: &[u8], width: usize) -> (usize, usize, usize, usize, Vec<u8>) {
    let height = cur.len() / width.max(1);
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for y in 0..height {
        let (a, b) = (
            &prev[y * width..(y + 1) * width],
            &cur[y * width..(y + 1) * width],
        );
        if a == b {
            continue;
        }
        let first = a.iter().zip(b).position(|(p, q)| p != q).unwrap_or(0);
        let last = width
            - 1
            - a.iter()
                .rev()
                .zip(b.iter().rev())
                .position(|(p, q)| p != q)
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
        let row = y * width;
        for x in x0..=x1 {
            let q = cur[row + x];
            out.push(if prev[row + x] == q { TRANSPARENT } else { q });
        }
    }
    (x0, y0, w, h, out)
}

/// Writes an animated, looping GIF of `film` to `path` (atomically).
pub fn write_gif(film: &Film, path: &Path, threads: usize, progress: &dyn Progress) -> Result<()> {
    let (w, h) = (film.width, film.height);
    let delay = (100.0 / film.fps).round().max(1.0) as u16;
    let palette = film.palette();
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
        // Indices of the frame before the current batch.
        let mut prev: Option<Vec<u8>> = None;
        for start in (0..film.len()).step_by(GIF_BATCH) {
            let count = GIF_BATCH.min(film.len() - start);
            // 1. Draw and map the batch in parallel.
            let mut indexed: Vec<Vec<u8>> = Vec::with_capacity(count);
            run_frames(
                count,
                threads,
                || (Canvas::new(w, h), Mask::new(), Lookup::new(&palette)),
                |k, (canvas, mask, lookup): &mut (Canvas, Mask, Lookup)| {
                    film.draw(start + k, canvas, mask, true);
                    let mut idx = Vec::new();
                    lookup.map_image(&canvas.rgb, &mut idx);
                    Ok(idx)
                },
                |_, idx| {
                    indexed.push(idx);
                    Ok(())
                },
            )?;
            // 2. Difference against the previous frame and LZW-compress in parallel.
            let before = |k: usize| {
                if k == 0 {
                    prev.as_deref()
                } else {
                    Some(indexed[k - 1].as_slice())
                }
            };
            let mut frames = Vec::with_capacity(count);
            run_frames(
                count,
                threads,
                || (),
                |k, _| {
                    let cur = &indexed[k];
                    let (left, top, fw, fh, buf, transparent) = match before(k) {
                        None => (0, 0, w, h, cur.clone(), None),
                        Some(p) => {
                            let (l, t, fw, fh, b) = frame_delta(p, cur, w);
                            (l, t, fw, fh, b, Some(TRANSPARENT))
                        }
                    };
                    let mut frame = gif::Frame {
                        left: left as u16,
                        top: top as u16,
                        width: fw as u16,
                        height: fh as u16,
                        delay,
                        dispose: gif::DisposalMethod::Keep,
                        transparent,
                        buffer: Cow::Owned(buf),
                        ..gif::Frame::default()
                    };
                    frame.make_lzw_pre_encoded();
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
            prev = indexed.pop();
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

/// Writes numbered PNG frames `frame_00000.png`, … of `film` into the directory `path`
/// (atomically: a temporary sibling directory renamed into place when complete).
pub fn write_png_dir(
    film: &Film,
    path: &Path,
    threads: usize,
    progress: &dyn Progress,
) -> Result<()> {
    let (w, h) = (film.width, film.height);
    let dir = AtomicDir::create(path)?;
    progress.start("png frames", film.len() as u64);
    run_frames(
        film.len(),
        threads,
        || (Canvas::new(w, h), Mask::new()),
        |k, (canvas, mask): &mut (Canvas, Mask)| {
            film.draw(k, canvas, mask, false);
            let target = dir.path(&frame_name(k));
            let file = std::fs::File::create(&target).map_err(|e| Error::io(path, e))?;
            let mut out = std::io::BufWriter::new(file);
            let enc = image::codecs::png::PngEncoder::new_with_quality(
                &mut out,
                image::codecs::png::CompressionType::Fast,
                image::codecs::png::FilterType::Adaptive,
            );
            image::ImageEncoder::write_image(
                enc,
                &canvas.rgb,
                w as u32,
                h as u32,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| match e {
                // A full disk or a file-size limit: the user's problem with the output, exit 2.
                image::ImageError::IoError(e) => Error::io(path, e),
                other => Error::Internal(format!("{}: PNG encoder: {other}", path.display())),
            })?;
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

#[cfg(test)]
mod tests {
    use super::*;

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
