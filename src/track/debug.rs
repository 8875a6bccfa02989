//! Debug pictures (the `track.debug_frames` option): every processed frame as a PNG, for a user to see
//! why a bird was missed or something else was taken for one.
//!
//! The left half is the frame with what the tracker made of it: a green circle (one wingspan
//! across) for a bird on a track that has lasted [`super::MIN_TRACK_FRAMES`] frames, yellow for
//! a track still young (it counts only if it lasts and moves with the flock), magenta for a bird
//! cut out of a larger region (touching birds), a red square for a region that stood out but was
//! turned down (far fainter or smaller than the birds), the last positions of each track as a
//! cyan trail, and the searched region (`track.roi`) in blue when it is not the whole frame. The right
//! half is the background the birds were measured against (the sky model and its local
//! closing), in grey: clouds should show there, birds should not.

use std::collections::BTreeMap;
use std::path::Path;

use super::detect::{Blob, Found, Gray};
use crate::error::{Error, Result};

/// Positions of a track drawn as its trail.
pub const TRAIL: usize = 12;

/// One detection as drawn.
#[derive(Debug, Clone, Copy)]
pub struct Mark {
    /// The detection.
    pub blob: Blob,
    /// Its track.
    pub id: usize,
    /// Whether the track has lasted long enough to count.
    pub lasting: bool,
}

struct Picture {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Picture {
    fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            let i = 3 * (y as usize * self.w + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    fn line(&mut self, a: (f64, f64), b: (f64, f64), c: [u8; 3]) {
        let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            self.put(
                (a.0 + (b.0 - a.0) * t).floor() as i64,
                (a.1 + (b.1 - a.1) * t).floor() as i64,
                c,
            );
        }
    }

    fn circle(&mut self, x: f64, y: f64, r: f64, c: [u8; 3]) {
        let n = ((8.0 * r).ceil() as usize).clamp(12, 2000);
        for s in 0..n {
            let a = s as f64 / n as f64 * std::f64::consts::TAU;
            self.put(
                (x + r * a.cos()).floor() as i64,
                (y + r * a.sin()).floor() as i64,
                c,
            );
        }
    }

    fn square(&mut self, x: f64, y: f64, r: f64, c: [u8; 3]) {
        let (x0, y0, x1, y1) = (x - r, y - r, x + r, y + r);
        self.line((x0, y0), (x1, y0), c);
        self.line((x1, y0), (x1, y1), c);
        self.line((x1, y1), (x0, y1), c);
        self.line((x0, y1), (x0, y0), c);
    }
}

/// Writes the debug picture of one frame to `path` (see the module).
pub fn write(
    path: &Path,
    g: &Gray,
    found: &Found,
    marks: &[Mark],
    trails: &BTreeMap<usize, Vec<(f64, f64)>>,
    roi: [usize; 4],
) -> Result<()> {
    let (w, h) = (g.width, g.height);
    let mut p = Picture {
        w: 2 * w,
        h,
        rgb: vec![0u8; 6 * w * h],
    };
    for y in 0..h {
        for x in 0..w {
            let v = g.data[y * w + x];
            let i = 3 * (y * 2 * w + x);
            p.rgb[i..i + 3].copy_from_slice(&[v, v, v]);
            let b = found
                .background
                .get(y * w + x)
                .map_or(v, |b| b.round().clamp(0.0, 255.0) as u8);
            let j = 3 * (y * 2 * w + w + x);
            p.rgb[j..j + 3].copy_from_slice(&[b, b, b]);
        }
    }
    if roi != [0, 0, w, h] {
        let [x, y, rw, rh] = roi.map(|v| v as f64);
        let blue = [40, 90, 255];
        p.line((x, y), (x + rw - 1.0, y), blue);
        p.line((x + rw - 1.0, y), (x + rw - 1.0, y + rh - 1.0), blue);
        p.line((x + rw - 1.0, y + rh - 1.0), (x, y + rh - 1.0), blue);
        p.line((x, y + rh - 1.0), (x, y), blue);
    }
    for r in &found.rejected {
        p.square(r.x, r.y, (0.5 * r.span).clamp(2.0, 40.0), [230, 30, 30]);
    }
    for t in trails.values() {
        for s in t.windows(2) {
            p.line(s[0], s[1], [0, 200, 230]);
        }
    }
    for m in marks {
        let c = if m.blob.split {
            [230, 40, 230]
        } else if m.lasting {
            [30, 220, 60]
        } else {
            [240, 220, 30]
        };
        p.circle(m.blob.x, m.blob.y, (0.5 * m.blob.span).max(3.0), c);
        p.put(m.blob.x.floor() as i64, m.blob.y.floor() as i64, c);
    }
    let img = image::RgbImage::from_raw(p.w as u32, p.h as u32, p.rgb)
        .ok_or_else(|| Error::Internal("debug picture size".into()))?;
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::Internal(format!("debug picture: {e}")))?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}
