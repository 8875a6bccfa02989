//! The picture buffer and its polygon filler. Birds are filled with `tiny-skia` (the maintained
//! CPU rasteriser of the Skia family: analytic anti-aliasing, non-zero winding) instead of a
//! hand-written scanline filler. Several closed contours given to one [`Canvas::fill`] are made
//! to wind the same way first, so that overlapping parts (wing roots over the body, a neck over
//! the body) fill as a union with clean edges and no seams, whatever way the camera's projection
//! turned each polygon.
//!
//! Coordinates are pixels with `(0, 0)` the top-left corner of the top-left pixel and `y` down.
//! The buffer is RGBA, 8 bits per channel, **premultiplied** by alpha (tiny-skia's layout); a
//! picture over an opaque sky has alpha 255 everywhere, so its bytes are plain RGB + 255.

use tiny_skia::{FillRule, Paint, PathBuilder, PixmapMut, Transform};

/// An RGBA image (premultiplied alpha), rows top to bottom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Canvas {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `width × height × 4` bytes: r, g, b, a, premultiplied by a.
    pub rgba: Vec<u8>,
}

impl Canvas {
    /// A fully transparent canvas.
    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            rgba: vec![0; width * height * 4],
        }
    }

    /// The colour of pixel `(x, y)` as straight (not premultiplied) RGBA.
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 4] {
        let i = (y * self.width + x) * 4;
        let p = &self.rgba[i..i + 4];
        demultiply([p[0], p[1], p[2], p[3]])
    }

    /// The image as straight (not premultiplied) RGBA bytes, the layout PNG wants.
    pub fn straight_rgba(&self) -> Vec<u8> {
        self.rgba
            .chunks_exact(4)
            .flat_map(|p| demultiply([p[0], p[1], p[2], p[3]]))
            .collect()
    }

    /// Fills the union of the closed `contours` (any orientation) with `colour` at `opacity`
    /// (0..1), anti-aliased. `scratch` keeps buffers between calls.
    pub fn fill(
        &mut self,
        contours: &[Vec<[f32; 2]>],
        colour: [u8; 3],
        opacity: f32,
        scratch: &mut Mask,
    ) {
        let mut pb = std::mem::take(&mut scratch.builder).unwrap_or_default();
        let (w, h) = (self.width as f32, self.height as f32);
        for c in contours {
            if c.len() < 3 || c.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
                continue;
            }
            // Skip contours wholly outside the picture (cheap; tiny-skia would clip them anyway).
            let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
            for p in c {
                x0 = x0.min(p[0]);
                y0 = y0.min(p[1]);
                x1 = x1.max(p[0]);
                y1 = y1.max(p[1]);
            }
            if x1 <= 0.0 || y1 <= 0.0 || x0 >= w || y0 >= h {
                continue;
            }
            // Same winding for every contour, so that non-zero filling is their union.
            let forward = signed_area(c) >= 0.0;
            let mut pts = c.iter();
            let first = if forward {
                c[0]
            } else {
                *c.last().expect("3 points")
            };
            pb.move_to(first[0], first[1]);
            if forward {
                for p in pts.by_ref().skip(1) {
                    pb.line_to(p[0], p[1]);
                }
            } else {
                for p in c.iter().rev().skip(1) {
                    pb.line_to(p[0], p[1]);
                }
            }
            pb.close();
        }
        let Some(path) = pb.finish() else {
            return;
        };
        if let Some(mut pm) =
            PixmapMut::from_bytes(&mut self.rgba, self.width as u32, self.height as u32)
        {
            let mut paint = Paint::default();
            let a = (opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
            paint.set_color_rgba8(colour[0], colour[1], colour[2], a);
            paint.anti_alias = true;
            pm.fill_path(
                &path,
                &paint,
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
        scratch.builder = Some(path.clear());
    }
}

/// Straight alpha from premultiplied: `c = round(255 c′ / a)`.
pub fn demultiply(p: [u8; 4]) -> [u8; 4] {
    let a = p[3] as u32;
    match a {
        0 => [0, 0, 0, 0],
        255 => p,
        _ => {
            let d = |c: u8| ((c as u32 * 255 + a / 2) / a).min(255) as u8;
            [d(p[0]), d(p[1]), d(p[2]), p[3]]
        }
    }
}

/// Signed area of a closed polygon (shoelace), positive when counter-clockwise in `y`-up axes.
pub fn signed_area(p: &[[f32; 2]]) -> f32 {
    let n = p.len();
    let mut a = 0.0;
    for i in 0..n {
        let [x0, y0] = p[i];
        let [x1, y1] = p[(i + 1) % n];
        a += x0 * y1 - x1 * y0;
    }
    0.5 * a
}

/// Scratch state of [`Canvas::fill`]: a path builder whose buffers are reused between fills.
#[derive(Debug, Default, Clone)]
pub struct Mask {
    builder: Option<PathBuilder>,
}

impl Mask {
    /// Empty scratch; reuse one across fills to avoid allocations.
    pub fn new() -> Mask {
        Mask::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f32, y0: f32, x1: f32, y1: f32) -> Vec<[f32; 2]> {
        vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    fn opaque(w: usize, h: usize) -> Canvas {
        let mut c = Canvas::new(w, h);
        for p in c.rgba.chunks_exact_mut(4) {
            p.copy_from_slice(&[0, 0, 0, 255]);
        }
        c
    }

    #[test]
    fn pixel_aligned_square_is_solid_inside_and_untouched_outside() {
        let mut c = opaque(10, 10);
        c.fill(
            &[square(2.0, 2.0, 6.0, 5.0)],
            [200, 100, 50],
            1.0,
            &mut Mask::new(),
        );
        assert_eq!(c.pixel(3, 3), [200, 100, 50, 255]);
        assert_eq!(c.pixel(2, 2), [200, 100, 50, 255]);
        assert_eq!(c.pixel(6, 3), [0, 0, 0, 255]);
        assert_eq!(c.pixel(1, 3), [0, 0, 0, 255]);
    }

    #[test]
    fn coverage_sums_to_the_polygon_area() {
        let tri = vec![[1.3, 1.7], [8.6, 2.2], [4.1, 7.9]];
        let area = signed_area(&tri).abs();
        let mut c = opaque(12, 12);
        c.fill(&[tri], [255, 255, 255], 1.0, &mut Mask::new());
        let total: f32 = c.rgba.chunks_exact(4).map(|p| p[0] as f32 / 255.0).sum();
        // tiny-skia's anti-aliasing is exact to a few percent at this size.
        assert!((total - area).abs() < 0.05 * area, "{total} vs {area}");
    }

    #[test]
    fn opposite_windings_still_fill_as_a_union() {
        let mut c = opaque(8, 4);
        let a = square(0.0, 0.0, 4.0, 4.0);
        let mut b = square(2.0, 0.0, 6.0, 4.0);
        b.reverse();
        c.fill(&[a, b], [255, 255, 255], 1.0, &mut Mask::new());
        for x in 0..6 {
            assert_eq!(c.pixel(x, 2), [255, 255, 255, 255], "x {x}");
        }
        assert_eq!(c.pixel(7, 2), [0, 0, 0, 255]);
    }

    #[test]
    fn transparent_canvas_gets_alpha_only_where_drawn() {
        let mut c = Canvas::new(6, 6);
        c.fill(
            &[square(1.0, 1.0, 3.5, 3.0)],
            [40, 80, 120],
            1.0,
            &mut Mask::new(),
        );
        assert_eq!(c.pixel(0, 0)[3], 0);
        assert_eq!(c.pixel(2, 2), [40, 80, 120, 255]);
        let edge = c.pixel(3, 2);
        assert!(edge[3] > 100 && edge[3] < 155, "{edge:?}");
        // Straight colour survives the half coverage (within rounding).
        assert!((edge[2] as i32 - 120).abs() <= 2, "{edge:?}");
    }

    #[test]
    fn shapes_outside_or_partly_outside_are_clipped() {
        let mut c = opaque(5, 5);
        c.fill(
            &[square(-10.0, -10.0, -2.0, -2.0)],
            [255; 3],
            1.0,
            &mut Mask::new(),
        );
        assert!(c.rgba.chunks_exact(4).all(|p| p[0] == 0));
        c.fill(
            &[square(-3.0, -3.0, 2.0, 8.0)],
            [255; 3],
            1.0,
            &mut Mask::new(),
        );
        assert_eq!(c.pixel(0, 0), [255, 255, 255, 255]);
        assert_eq!(c.pixel(1, 4), [255, 255, 255, 255]);
        assert_eq!(c.pixel(2, 4), [0, 0, 0, 255]);
    }
}
