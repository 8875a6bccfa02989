//! A small anti-aliased polygon rasteriser: exact pixel coverage by signed-area accumulation
//! (the method of font-rs / libart). Each edge adds, to the cells it crosses, the signed area it
//! sweeps; a running sum along each row then gives the winding-weighted coverage of every pixel.
//! Several closed contours of the same orientation accumulate into one mask, whose coverage is
//! clamped to 1, so overlapping parts (wing roots over the body) fill as a union with clean edges.
//!
//! Coordinates are pixels with `(0, 0)` the top-left corner of the top-left pixel and `y` down.

/// An RGB image, 8 bits per channel, rows top to bottom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Canvas {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `width × height × 3` bytes.
    pub rgb: Vec<u8>,
}

impl Canvas {
    /// A black canvas.
    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            rgb: vec![0; width * height * 3],
        }
    }

    /// Fills the union of `contours` (closed, same orientation) with `colour` at `opacity`.
    pub fn fill(
        &mut self,
        contours: &[Vec<[f32; 2]>],
        colour: [u8; 3],
        opacity: f32,
        mask: &mut Mask,
    ) {
        if !mask.accumulate(contours, self.width, self.height) {
            return;
        }
        let c = [colour[0] as f32, colour[1] as f32, colour[2] as f32];
        let (x0, y0, w, h) = (mask.x0, mask.y0, mask.w, mask.h);
        for row in 0..h {
            let mut acc = 0.0f32;
            let line = &mask.cells[row * (w + 2)..(row + 1) * (w + 2)];
            let base = ((y0 + row) * self.width + x0) * 3;
            for (col, cell) in line.iter().take(w).enumerate() {
                acc += cell;
                let a = acc.abs().min(1.0) * opacity;
                if a > 1.0 / 512.0 {
                    let p = &mut self.rgb[base + col * 3..base + col * 3 + 3];
                    for k in 0..3 {
                        let v = p[k] as f32;
                        p[k] = (v + (c[k] - v) * a + 0.5) as u8;
                    }
                }
            }
        }
    }
}

/// Scratch accumulation buffer covering the bounding box of the contours being filled.
#[derive(Debug, Default, Clone)]
pub struct Mask {
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
    cells: Vec<f32>,
}

impl Mask {
    /// An empty mask; reuse one across fills to avoid allocations.
    pub fn new() -> Mask {
        Mask::default()
    }

    /// Coverage of pixel `(x, y)` after the last accumulation (0 outside its box), for tests.
    pub fn coverage(&self, x: usize, y: usize) -> f32 {
        if x < self.x0 || y < self.y0 || x >= self.x0 + self.w || y >= self.y0 + self.h {
            return 0.0;
        }
        let row = y - self.y0;
        let line = &self.cells[row * (self.w + 2)..];
        let acc: f32 = line[..=(x - self.x0)].iter().sum();
        acc.abs().min(1.0)
    }

    /// Accumulates the edges of `contours`, clipped to a `width × height` image. Returns false
    /// when nothing is visible.
    pub fn accumulate(&mut self, contours: &[Vec<[f32; 2]>], width: usize, height: usize) -> bool {
        let (mut minx, mut miny, mut maxx, mut maxy) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
        for p in contours.iter().flatten() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return false;
            }
            minx = minx.min(p[0]);
            miny = miny.min(p[1]);
            maxx = maxx.max(p[0]);
            maxy = maxy.max(p[1]);
        }
        if minx > maxx
            || maxx <= 0.0
            || maxy <= 0.0
            || minx >= width as f32
            || miny >= height as f32
        {
            return false;
        }
        let x0 = minx.max(0.0).floor() as usize;
        let y0 = miny.max(0.0).floor() as usize;
        let x1 = (maxx.ceil() as usize).min(width);
        let y1 = (maxy.ceil() as usize).min(height);
        if x1 <= x0 || y1 <= y0 {
            return false;
        }
        self.x0 = x0;
        self.y0 = y0;
        self.w = x1 - x0;
        self.h = y1 - y0;
        self.cells.clear();
        self.cells.resize((self.w + 2) * self.h, 0.0);
        let (fx, fy) = (x0 as f32, y0 as f32);
        let wmax = self.w as f32;
        for c in contours {
            let n = c.len();
            for i in 0..n {
                let a = c[i];
                let b = c[(i + 1) % n];
                self.clipped_line([a[0] - fx, a[1] - fy], [b[0] - fx, b[1] - fy], wmax);
            }
        }
        true
    }

    /// Splits an edge where it crosses the box's left or right side; pieces outside are pressed
    /// flat onto that side (a vertical edge there adds the same area to every pixel to its right,
    /// or none), which keeps the coverage inside the box exact.
    fn clipped_line(&mut self, p0: [f32; 2], p1: [f32; 2], wmax: f32) {
        let mut cuts = [0.0f32, 1.0, 1.0, 1.0];
        let mut n = 1;
        let dx = p1[0] - p0[0];
        if dx != 0.0 {
            for edge in [0.0, wmax] {
                let t = (edge - p0[0]) / dx;
                if t > 0.0 && t < 1.0 {
                    cuts[n] = t;
                    n += 1;
                }
            }
        }
        cuts[n] = 1.0;
        cuts[1..n].sort_by(f32::total_cmp);
        let at = |t: f32| {
            let x = if t == 1.0 { p1[0] } else { p0[0] + dx * t };
            let y = if t == 1.0 {
                p1[1]
            } else {
                p0[1] + (p1[1] - p0[1]) * t
            };
            [x.clamp(0.0, wmax), y]
        };
        for k in 0..n {
            self.line(at(cuts[k]), at(cuts[k + 1]));
        }
    }

    fn line(&mut self, p0: [f32; 2], p1: [f32; 2]) {
        if (p0[1] - p1[1]).abs() <= f32::EPSILON {
            return;
        }
        let (dir, p0, p1) = if p0[1] < p1[1] {
            (1.0, p0, p1)
        } else {
            (-1.0, p1, p0)
        };
        let stride = self.w + 2;
        let dxdy = (p1[0] - p0[0]) / (p1[1] - p0[1]);
        let mut x = p0[0];
        if p0[1] < 0.0 {
            x -= p0[1] * dxdy;
        }
        let ystart = p0[1].max(0.0) as usize;
        let yend = (p1[1].ceil().max(0.0) as usize).min(self.h);
        for y in ystart..yend {
            let line = y * stride;
            let dy = ((y + 1) as f32).min(p1[1]) - (y as f32).max(p0[1]);
            let xnext = x + dxdy * dy;
            let d = dy * dir;
            let (xa, xb) = if x < xnext { (x, xnext) } else { (xnext, x) };
            // Rounding can leave an end a hair below 0; the cell maths needs xa ≥ 0.
            let (xa, xb) = (xa.max(0.0), xb.max(0.0));
            let xa_floor = xa.floor();
            let xai = xa_floor.max(0.0) as usize;
            let xb_ceil = xb.ceil();
            let xbi = xb_ceil.max(0.0) as usize;
            if xbi <= xai + 1 {
                let xmf = 0.5 * (xa + xb) - xa_floor;
                self.cells[line + xai] += d - d * xmf;
                self.cells[line + xai + 1] += d * xmf;
            } else {
                let s = (xb - xa).recip();
                let xaf = xa - xa_floor;
                let a0 = 0.5 * s * (1.0 - xaf) * (1.0 - xaf);
                let xbf = xb - xb_ceil + 1.0;
                let am = 0.5 * s * xbf * xbf;
                self.cells[line + xai] += d * a0;
                if xbi == xai + 2 {
                    self.cells[line + xai + 1] += d * (1.0 - a0 - am);
                } else {
                    let a1 = s * (1.5 - xaf);
                    self.cells[line + xai + 1] += d * (a1 - a0);
                    for xi in xai + 2..xbi - 1 {
                        self.cells[line + xi] += d * s;
                    }
                    let a2 = a1 + (xbi - xai - 3) as f32 * s;
                    self.cells[line + xbi - 1] += d * (1.0 - a2 - am);
                }
                self.cells[line + xbi] += d * am;
            }
            x = xnext;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f32, y0: f32, x1: f32, y1: f32) -> Vec<[f32; 2]> {
        vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    #[test]
    fn pixel_aligned_square_has_full_and_zero_coverage() {
        let mut m = Mask::new();
        assert!(m.accumulate(&[square(2.0, 2.0, 6.0, 5.0)], 10, 10));
        assert_eq!(m.coverage(3, 3), 1.0);
        assert_eq!(m.coverage(2, 2), 1.0);
        assert_eq!(m.coverage(6, 3), 0.0);
        assert_eq!(m.coverage(1, 3), 0.0);
    }

    #[test]
    fn coverage_sums_to_the_polygon_area() {
        let tri = vec![[1.3, 1.7], [8.6, 2.2], [4.1, 7.9]];
        let area = crate::export::rig::signed_area(&tri).abs();
        let mut m = Mask::new();
        m.accumulate(&[tri], 12, 12);
        let total: f32 = (0..12)
            .flat_map(|y| (0..12).map(move |x| (x, y)))
            .map(|(x, y)| m.coverage(x, y))
            .sum();
        assert!((total - area).abs() < 1e-3, "{total} vs {area}");
    }

    #[test]
    fn half_covered_pixel_is_half_blended_and_overlaps_union() {
        let mut c = Canvas::new(4, 1);
        let mut m = Mask::new();
        let a = square(0.0, 0.0, 1.5, 1.0);
        // Overlaps add up and clamp at full coverage (edges of one part inside another vanish).
        let b = square(0.25, 0.0, 1.0, 1.0);
        c.fill(&[a, b], [200, 100, 50], 1.0, &mut m);
        assert_eq!(&c.rgb[0..3], &[200, 100, 50]);
        assert_eq!(&c.rgb[3..6], &[100, 50, 25]);
        assert_eq!(&c.rgb[6..9], &[0, 0, 0]);
    }

    #[test]
    fn shapes_outside_or_partly_outside_are_clipped() {
        let mut c = Canvas::new(5, 5);
        let mut m = Mask::new();
        c.fill(&[square(-10.0, -10.0, -2.0, -2.0)], [255; 3], 1.0, &mut m);
        assert!(c.rgb.iter().all(|&v| v == 0));
        c.fill(&[square(-3.0, -3.0, 2.0, 8.0)], [255; 3], 1.0, &mut m);
        assert_eq!(&c.rgb[0..3], &[255; 3]);
        assert_eq!(&c.rgb[(4 * 5 + 1) * 3..(4 * 5 + 1) * 3 + 3], &[255; 3]);
        assert_eq!(&c.rgb[(4 * 5 + 2) * 3..(4 * 5 + 2) * 3 + 3], &[0; 3]);
    }

    proptest::proptest! {
        /// Coverage of any triangle, even partly off the image, sums to its visible area.
        #[test]
        fn coverage_is_exact_for_random_triangles(
            pts in proptest::collection::vec((-4.0f32..20.0, -4.0f32..20.0), 3)
        ) {
            let tri: Vec<[f32; 2]> = pts.iter().map(|&(x, y)| [x, y]).collect();
            let mut m = Mask::new();
            let total: f32 = if m.accumulate(std::slice::from_ref(&tri), 16, 16) {
                (0..16).flat_map(|y| (0..16).map(move |x| (x, y))).map(|(x, y)| m.coverage(x, y)).sum()
            } else {
                0.0
            };
            // Reference: Sutherland–Hodgman clip to the image square, then the shoelace area.
            let mut poly = tri.clone();
            for (axis, bound, keep_below) in [(0, 0.0f32, false), (0, 16.0, true), (1, 0.0, false), (1, 16.0, true)] {
                let inside = |p: &[f32; 2]| if keep_below { p[axis] <= bound } else { p[axis] >= bound };
                let mut out = Vec::new();
                for i in 0..poly.len() {
                    let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                    if inside(&a) {
                        out.push(a);
                    }
                    if inside(&a) != inside(&b) {
                        let t = (bound - a[axis]) / (b[axis] - a[axis]);
                        out.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
                    }
                }
                poly = out;
                if poly.is_empty() {
                    break;
                }
            }
            let reference = if poly.len() < 3 { 0.0 } else { crate::export::rig::signed_area(&poly).abs() };
            proptest::prop_assert!((total - reference).abs() < 2e-3 * reference.max(1.0), "{} vs {}", total, reference);
        }
    }
}
