//! How far an animated GIF strays from the full-colour pictures it was made from, the measure
//! of what the GIF writer's frame differencing leaves behind (the example `gif_error`, in
//! `examples/gif_error.rs`, measures any GIF beside its PNG frames drawn at the GIF's rate).
//!
//! A GIF has 256 colours, so every pixel is off by the dither and the palette: that is fine
//! noise. What shows is error that is *coherent*: a stale rectangle of old cloud left where the
//! differencing did not refresh, the trail of a bird that moved on, faint blocks in a sky
//! gradient. Two numbers catch that, both on the signed error `gif − true` per channel, in
//! levels of 0–255:
//!
//! - **low-frequency error**: the largest mean error, in some channel, over any 8 × 8 box (boxes
//!   every 4 pixels), the error the eye sees once the dither's grain is averaged out;
//! - **seam**: the largest step of the mean error across any line: between the 4 × 16 pixel
//!   strips either side of a column (or the 16 × 4 strips either side of a row), which is what a
//!   hard-edged stale region shows as.
//!
//! Pixels the true picture leaves transparent (`render.background none`) are not counted.

use std::io::Read;

use crate::error::{Error, Result};

/// Side of the boxes of the low-frequency error, pixels.
pub const BOX: usize = 8;
/// Step between boxes, pixels.
pub const BOX_STEP: usize = 4;
/// Width of the strips either side of a seam, pixels.
pub const STRIP: usize = 4;
/// Length of the strips along a seam, pixels.
pub const STRIP_LEN: usize = 16;

/// The error of one GIF frame against its true picture.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameError {
    /// Largest mean error over an 8 × 8 box, levels.
    pub low_frequency: f64,
    /// Largest step of the mean error across a line, levels.
    pub seam: f64,
}

impl FrameError {
    /// The larger of each measure.
    pub fn max(self, o: FrameError) -> FrameError {
        FrameError {
            low_frequency: self.low_frequency.max(o.low_frequency),
            seam: self.seam.max(o.seam),
        }
    }
}

/// The error of `shown` (RGBA, what the GIF shows) against `truth` (RGBA), both `width` wide.
pub fn frame_error(shown: &[u8], truth: &[u8], width: usize) -> FrameError {
    let height = truth.len() / 4 / width.max(1);
    let (w, h) = (width, height);
    if w < BOX || h < BOX {
        return FrameError::default();
    }
    // Summed-area tables of the error per channel and of the counted pixels.
    let stride = w + 1;
    let mut sat = vec![[0i64; 4]; stride * (h + 1)];
    for y in 0..h {
        let mut row = [0i64; 4];
        for x in 0..w {
            let i = (y * w + x) * 4;
            if truth[i + 3] != 0 {
                for k in 0..3 {
                    row[k] += shown[i + k] as i64 - truth[i + k] as i64;
                }
                row[3] += 1;
            }
            let above = sat[y * stride + x + 1];
            sat[(y + 1) * stride + x + 1] = [0, 1, 2, 3].map(|k| above[k] + row[k]);
        }
    }
    let mean = |x0: usize, y0: usize, bw: usize, bh: usize| -> Option<[f64; 3]> {
        let g = |x: usize, y: usize| sat[y * stride + x];
        let (a, b, c, d) = (
            g(x0, y0),
            g(x0 + bw, y0),
            g(x0, y0 + bh),
            g(x0 + bw, y0 + bh),
        );
        let s = [0, 1, 2, 3].map(|k| d[k] - b[k] - c[k] + a[k]);
        // Only boxes fully inside the counted picture.
        (s[3] == (bw * bh) as i64).then(|| [0, 1, 2].map(|k| s[k] as f64 / s[3] as f64))
    };
    let mut e = FrameError::default();
    for y in (0..=h - BOX).step_by(BOX_STEP) {
        for x in (0..=w - BOX).step_by(BOX_STEP) {
            if let Some(m) = mean(x, y, BOX, BOX) {
                e.low_frequency = m.iter().fold(e.low_frequency, |a, v| a.max(v.abs()));
            }
        }
    }
    let step = |a: Option<[f64; 3]>, b: Option<[f64; 3]>, acc: f64| match (a, b) {
        (Some(a), Some(b)) => (0..3).fold(acc, |m, k| m.max((a[k] - b[k]).abs())),
        _ => acc,
    };
    if h >= STRIP_LEN && w >= 2 * STRIP {
        for y in (0..=h - STRIP_LEN).step_by(STRIP_LEN / 2) {
            for x in STRIP..=w - STRIP {
                let (l, r) = (
                    mean(x - STRIP, y, STRIP, STRIP_LEN),
                    mean(x, y, STRIP, STRIP_LEN),
                );
                e.seam = step(l, r, e.seam);
            }
        }
    }
    if w >= STRIP_LEN && h >= 2 * STRIP {
        for x in (0..=w - STRIP_LEN).step_by(STRIP_LEN / 2) {
            for y in STRIP..=h - STRIP {
                let (a, b) = (
                    mean(x, y - STRIP, STRIP_LEN, STRIP),
                    mean(x, y, STRIP_LEN, STRIP),
                );
                e.seam = step(a, b, e.seam);
            }
        }
    }
    e
}

/// Decodes an animated GIF frame by frame into the pictures a viewer shows (RGBA, each frame
/// laid over the one before: the writer's disposal "keep"), calling `each(k, rgba, width)`.
pub fn decode_gif<R: Read>(
    source: R,
    mut each: impl FnMut(usize, &[u8], usize) -> Result<()>,
) -> Result<(usize, usize, usize)> {
    let bad = |e: gif::DecodingError| Error::Internal(format!("GIF: {e}"));
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(source).map_err(bad)?;
    let (w, h) = (dec.width() as usize, dec.height() as usize);
    let mut screen = vec![0u8; w * h * 4];
    let mut k = 0;
    while let Some(f) = dec.read_next_frame().map_err(bad)? {
        let (fl, ft, fw, fh) = (
            f.left as usize,
            f.top as usize,
            f.width as usize,
            f.height as usize,
        );
        for y in 0..fh {
            for x in 0..fw {
                let (sx, sy) = (fl + x, ft + y);
                if sx >= w || sy >= h {
                    continue;
                }
                let src = &f.buffer[(y * fw + x) * 4..(y * fw + x) * 4 + 4];
                if src[3] != 0 {
                    screen[(sy * w + sx) * 4..(sy * w + sx) * 4 + 4].copy_from_slice(src);
                }
            }
        }
        each(k, &screen, w)?;
        k += 1;
    }
    Ok((w, h, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(w: usize, h: usize, c: u8) -> Vec<u8> {
        (0..w * h).flat_map(|_| [c, c, c, 255]).collect()
    }

    #[test]
    fn noise_averages_out_and_a_stale_block_does_not() {
        let (w, h) = (64, 48);
        let truth = flat(w, h, 100);
        // ±6 levels alternating: a dither's grain, no low-frequency error.
        let mut grain = truth.clone();
        for (i, p) in grain.chunks_exact_mut(4).enumerate() {
            let d = if (i + i / w) % 2 == 0 { 6 } else { -6 };
            for c in &mut p[..3] {
                *c = (*c as i32 + d) as u8;
            }
        }
        let e = frame_error(&grain, &truth, w);
        assert!(e.low_frequency < 0.01 && e.seam < 0.01, "{e:?}");
        // A stale block 5 levels off, hard-edged: both measures see it.
        let mut stale = truth.clone();
        for y in 10..30 {
            for x in 20..50 {
                for c in &mut stale[(y * w + x) * 4..(y * w + x) * 4 + 3] {
                    *c = 105;
                }
            }
        }
        let e = frame_error(&stale, &truth, w);
        assert!((e.low_frequency - 5.0).abs() < 1e-9, "{e:?}");
        assert!((e.seam - 5.0).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn transparent_pixels_are_not_counted() {
        let (w, h) = (32, 32);
        let mut truth = flat(w, h, 50);
        for p in truth.chunks_exact_mut(4) {
            p[3] = 0;
        }
        let shown = flat(w, h, 200);
        assert_eq!(frame_error(&shown, &truth, w), FrameError::default());
    }
}
