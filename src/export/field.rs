//! The ground (or water) the birds sit on, for the top-down cameras.
//!
//! The top-down sky is a stylised backdrop: it shows the flock's travel, not what lies under
//! it. Birds sitting, running or floating must be seen on something they can sit on, so every
//! place where a bird rests on the surface in a take-off or a landing (its body less than
//! [`ON_SURFACE`] wingspans up, slower than a walk) lays a patch of ground, or of water where
//! the flock lands on water,
//! [`REACH`] wingspans around it, with a soft edge [`EDGE`] wide, drawn over the sky at its
//! place in the world. The patch stays where it is while the camera follows the flock, so as
//! the birds run, lift off and climb, the camera carries them off the field and brings in the
//! sky; a flock that lands flies onto a new field. The patch is one flat colour (a world-fixed
//! texture would change every pixel of it whenever the camera moves, and every GIF frame would
//! cost a whole picture), so only its edge moves from frame to frame.
//!
//! The patch at a pixel is the smoothstep of the distance to the nearest surface point,
//! evaluated on the backdrop's sample grid and interpolated bilinearly, like the sky.

use std::collections::HashMap;

use super::camera::View;
use super::raster::Canvas;

/// A bird whose body is less than this high, wingspans, is on the surface.
pub const ON_SURFACE: f64 = 0.45;
/// How far the field reaches around a bird on it, wingspans (full opacity): far enough that a
/// sitting flock fills the follow camera's picture with its field (the camera frames the flock
/// with a small margin), so the birds are seen on the ground, not on a patch of it.
pub const REACH: f64 = 9.0;
/// Width of the field's soft edge, wingspans: the field fades into the sky over it as the
/// camera carries the flock away, like ground falling away below a climbing bird.
pub const EDGE: f64 = 8.0;
/// Spacing of the surface points kept, wingspans.
const POINT_STEP: f64 = 0.5;
/// Backdrop sample spacing, pixels.
const GRID: usize = 8;

/// Colour of water seen from above.
pub const WATER: [u8; 3] = [78, 108, 122];

/// Surface points `(x, y, on_water)` binned by cell.
type Bins = HashMap<(i64, i64), Vec<(f64, f64, bool)>>;

/// Where the birds touch the ground or water, in the world (the picture's frame: a loop's
/// travel taken off).
#[derive(Debug, Clone, Default)]
pub struct Field {
    /// Surface points, binned by cells [`Field::cell`] wingspans wide, with their surface
    /// (true: water).
    cells: Bins,
    ground: [u8; 3],
    /// Bounding box of the surface points `[x0, y0, x1, y1]`, wingspans.
    bounds: [f64; 4],
    /// [`Field::at`] sampled every [`RASTER`] wingspans over the bounds widened by the reach
    /// and edge (from their corner), opacity and water, for painting: a picture looks it up
    /// instead of searching the points at every sample.
    raster: Vec<(f32, bool)>,
    /// Columns of `raster`.
    raster_w: usize,
}

/// Spacing of the field's raster, wingspans (its edge is [`EDGE`] wide, so a bilinear lookup
/// shows no steps).
const RASTER: f64 = 1.0;

impl Field {
    /// Side of a bin, wingspans: a point further than this from a bin's cells does not reach it.
    const CELL: f64 = REACH + EDGE;

    /// The field of `points` `(x, y, on_water)`, ground coloured `ground`.
    pub fn new(points: impl IntoIterator<Item = (f64, f64, bool)>, ground: [u8; 3]) -> Field {
        let mut seen = std::collections::BTreeSet::new();
        let mut bounds = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
        let mut cells: Bins = HashMap::new();
        for (x, y, water) in points {
            if !(x.is_finite() && y.is_finite()) {
                continue;
            }
            let key = (
                (x / POINT_STEP).round() as i64,
                (y / POINT_STEP).round() as i64,
                water,
            );
            if !seen.insert(key) {
                continue;
            }
            let (qx, qy) = (key.0 as f64 * POINT_STEP, key.1 as f64 * POINT_STEP);
            bounds = [
                bounds[0].min(qx),
                bounds[1].min(qy),
                bounds[2].max(qx),
                bounds[3].max(qy),
            ];
            cells
                .entry(Field::cell(qx, qy))
                .or_default()
                .push((qx, qy, water));
        }
        let mut f = Field {
            cells,
            ground,
            bounds,
            raster: Vec::new(),
            raster_w: 0,
        };
        if !f.is_empty() {
            let m = REACH + EDGE;
            let rw = ((bounds[2] - bounds[0] + 2.0 * m) / RASTER).ceil() as usize + 2;
            let rh = ((bounds[3] - bounds[1] + 2.0 * m) / RASTER).ceil() as usize + 2;
            let (x0, y0) = (bounds[0] - m, bounds[1] - m);
            f.raster = (0..rh)
                .flat_map(|j| (0..rw).map(move |i| (i, j)))
                .map(|(i, j)| f.at(x0 + i as f64 * RASTER, y0 + j as f64 * RASTER))
                .collect();
            f.raster_w = rw;
        }
        f
    }

    /// True when no bird is ever on the surface.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// The flat colours the field is drawn in (none when empty).
    pub fn colours(&self) -> Vec<[u8; 3]> {
        let mut v = Vec::new();
        for &(_, _, water) in self.cells.values().flatten() {
            let c = if water { WATER } else { self.ground };
            if !v.contains(&c) {
                v.push(c);
            }
        }
        v.sort();
        v
    }

    fn cell(x: f64, y: f64) -> (i64, i64) {
        (
            (x / Field::CELL).floor() as i64,
            (y / Field::CELL).floor() as i64,
        )
    }

    /// Opacity of the field (0..1) at world point `(x, y)` and whether it is water there.
    pub fn at(&self, x: f64, y: f64) -> (f32, bool) {
        let (cx, cy) = Field::cell(x, y);
        let mut best = (f64::MAX, false);
        for dy in -1..=1 {
            for dx in -1..=1 {
                for &(px, py, water) in self.cells.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    let d2 = (px - x).powi(2) + (py - y).powi(2);
                    if d2 < best.0 {
                        best = (d2, water);
                    }
                }
            }
        }
        let d = best.0.sqrt();
        let u = ((REACH + EDGE - d) / EDGE).clamp(0.0, 1.0) as f32;
        (u * u * (3.0 - 2.0 * u), best.1)
    }

    /// [`Field::at`] from the raster: bilinear in opacity, the nearest sample's surface.
    fn lookup(&self, x: f64, y: f64) -> (f32, bool) {
        let m = REACH + EDGE;
        let u = (x - (self.bounds[0] - m)) / RASTER;
        let v = (y - (self.bounds[1] - m)) / RASTER;
        let rw = self.raster_w;
        let rh = self.raster.len() / rw.max(1);
        if !(u >= 0.0 && v >= 0.0 && u < (rw - 1) as f64 && v < (rh - 1) as f64) {
            return (0.0, false);
        }
        let (i, j) = (u as usize, v as usize);
        let (fx, fy) = ((u - i as f64) as f32, (v - j as f64) as f32);
        let k = j * rw + i;
        let r = &self.raster;
        let a = (r[k].0 * (1.0 - fx) + r[k + 1].0 * fx) * (1.0 - fy)
            + (r[k + rw].0 * (1.0 - fx) + r[k + rw + 1].0 * fx) * fy;
        let near = r[k + (fy >= 0.5) as usize * rw + (fx >= 0.5) as usize].1;
        (a, near)
    }

    /// Lays the field over `canvas` (a top-down `view`; other views are left as they are).
    pub fn paint(&self, view: &View, canvas: &mut Canvas) {
        let View::Top { cx, cy, scale } = *view else {
            return;
        };
        if self.is_empty() || !(scale.is_finite() && scale > 0.0) {
            return;
        }
        let (w, h) = (canvas.width, canvas.height);
        // Nothing to do when the picture is wholly beyond the field's reach.
        let (hw, hh, m) = (0.5 * w as f64 / scale, 0.5 * h as f64 / scale, REACH + EDGE);
        let b = self.bounds;
        if cx + hw < b[0] - m || cx - hw > b[2] + m || cy + hh < b[1] - m || cy - hh > b[3] + m {
            return;
        }
        let gw = w / GRID + 2;
        let gh = h / GRID + 2;
        let mut alpha = vec![0f32; gw * gh];
        let mut water = vec![false; gw * gh];
        let mut any = false;
        for gy in 0..gh {
            let row = (gy * GRID) as f64 + 0.5;
            let y = cy - (row - 0.5 * h as f64) / scale;
            for gx in 0..gw {
                let col = (gx * GRID) as f64 + 0.5;
                let x = cx + (col - 0.5 * w as f64) / scale;
                let (a, wt) = self.lookup(x, y);
                alpha[gy * gw + gx] = a;
                water[gy * gw + gx] = wt;
                any |= a > 0.0;
            }
        }
        if !any {
            return;
        }
        for r in 0..h {
            let (gy, fy) = (r / GRID, (r % GRID) as f32 / GRID as f32);
            for gx in 0..w.div_ceil(GRID) {
                let i = gy * gw + gx;
                let (a00, a10, a01, a11) =
                    (alpha[i], alpha[i + 1], alpha[i + gw], alpha[i + gw + 1]);
                if a00 == 0.0 && a10 == 0.0 && a01 == 0.0 && a11 == 0.0 {
                    continue;
                }
                let colour = if water[i] { WATER } else { self.ground };
                let cols = gx * GRID..((gx + 1) * GRID).min(w);
                let run = &mut canvas.rgba[(r * w + cols.start) * 4..(r * w + cols.end) * 4];
                if a00 >= 1.0 && a10 >= 1.0 && a01 >= 1.0 && a11 >= 1.0 {
                    for px in run.chunks_exact_mut(4) {
                        px.copy_from_slice(&[colour[0], colour[1], colour[2], 255]);
                    }
                    continue;
                }
                for (c, px) in run.chunks_exact_mut(4).enumerate() {
                    let fx = c as f32 / GRID as f32;
                    let a = (a00 * (1.0 - fx) + a10 * fx) * (1.0 - fy)
                        + (a01 * (1.0 - fx) + a11 * fx) * fy;
                    if a >= 1.0 {
                        px.copy_from_slice(&[colour[0], colour[1], colour[2], 255]);
                        continue;
                    }
                    // Over a transparent background the field is laid with its own opacity
                    // (premultiplied, like the canvas).
                    let a8 = (a * 255.0).round() as u32;
                    for k in 0..3 {
                        px[k] =
                            ((px[k] as u32 * (255 - a8) + colour[k] as u32 * a8 + 127) / 255) as u8;
                    }
                    px[3] = ((px[3] as u32 * (255 - a8) + 255 * a8 + 127) / 255) as u8;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_field_is_opaque_near_a_bird_and_gone_past_its_edge() {
        let f = Field::new([(0.0, 0.0, false), (10.0, 0.0, true)], [1, 2, 3]);
        assert_eq!(f.at(0.0, REACH).0, 1.0);
        assert_eq!(f.at(0.0, REACH + EDGE + 0.01).0, 0.0);
        let mid = f.at(0.0, REACH + 0.5 * EDGE).0;
        assert!((mid - 0.5).abs() < 1e-6, "{mid}");
        assert!(f.at(10.0, 1.0).1 && !f.at(0.5, 0.0).1);
        assert!(Field::new([], [0; 3]).is_empty());
    }

    #[test]
    fn a_top_down_picture_shows_the_field_under_the_birds_only() {
        let f = Field::new([(0.0, 0.0, false)], [100, 120, 80]);
        let mut c = Canvas::new(64, 64);
        for p in c.rgba.chunks_exact_mut(4) {
            p.copy_from_slice(&[10, 20, 200, 255]);
        }
        let view = View::Top {
            cx: 0.0,
            cy: 0.0,
            scale: 2.0, // px per wingspan: the corner is 22 wingspans out, past the fade
        };
        f.paint(&view, &mut c);
        let px = |x: usize, y: usize| c.rgba[(y * 64 + x) * 4..(y * 64 + x) * 4 + 3].to_vec();
        assert_eq!(px(32, 32), vec![100, 120, 80]);
        assert_eq!(px(1, 1), vec![10, 20, 200]);
    }
}
