//! Drawing one picture of the flock: a sky gradient, soft clouds that drift past with parallax as
//! the camera follows the flock (the motion cue: the birds hold formation while the world moves),
//! and every bird as an anti-aliased silhouette of [`rig::top_view`] turned to its heading.
//!
//! The view is top-down, north up and east right, so images line up with the CSV's `x`/`y`.
//! Birds higher up (`z`) are drawn slightly larger and later (on top).

use super::camera::View;
use super::raster::{Canvas, Mask};
use super::rig;
use super::sample::BirdState;

/// Colours and look of the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Style {
    /// Sky colour at the top of the picture.
    pub sky_top: [u8; 3],
    /// Sky colour halfway down.
    pub sky_mid: [u8; 3],
    /// Sky colour at the bottom of the picture.
    pub sky_bottom: [u8; 3],
    /// Colour of the clouds.
    pub cloud: [u8; 3],
    /// Greatest opacity of a cloud, 0..1.
    pub cloud_opacity: f32,
    /// Cloud drift as a fraction of the camera's motion (smaller looks farther away).
    pub cloud_parallax: f64,
    /// Size of a cloud texture cell, wingspans.
    pub cloud_cell: f64,
    /// Colour of the birds' bodies and hands.
    pub bird: [u8; 3],
    /// Colour of the inner wings (slightly lighter coverts).
    pub bird_wing: [u8; 3],
}

impl Default for Style {
    fn default() -> Self {
        Style {
            sky_top: [52, 104, 170],
            sky_mid: [112, 166, 214],
            sky_bottom: [206, 224, 236],
            cloud: [250, 251, 253],
            cloud_opacity: 0.6,
            cloud_parallax: 0.3,
            cloud_cell: 0.3,
            bird: [34, 34, 42],
            bird_wing: [50, 49, 57],
        }
    }
}

impl Style {
    /// Sky colour at height fraction `v` (0 top, 1 bottom), as floats.
    pub fn sky(&self, v: f32) -> [f32; 3] {
        let v = v.clamp(0.0, 1.0);
        let (a, b, w) = if v < 0.5 {
            (self.sky_top, self.sky_mid, v * 2.0)
        } else {
            (self.sky_mid, self.sky_bottom, (v - 0.5) * 2.0)
        };
        // Smooth the joint at the middle stop.
        let w = w * w * (3.0 - 2.0 * w) * 0.5 + w * 0.5;
        [0, 1, 2].map(|k| a[k] as f32 + (b[k] as f32 - a[k] as f32) * w)
    }
}

/// 4×4 Bayer matrix, centred: values in −8..8.
const BAYER: [[i32; 4]; 4] = [
    [-8, 0, -6, 2],
    [4, -4, 6, -2],
    [-5, 3, -7, 1],
    [7, -1, 5, -3],
];

/// Side of the square, tileable cloud texture, cells (a power of two).
const TEX: usize = 256;

/// Everything that does not change from frame to frame: the sky rows and the cloud texture.
#[derive(Debug, Clone)]
pub struct Backdrop {
    width: usize,
    height: usize,
    sky_rows: Vec<[f32; 3]>,
    /// Cloud opacity per texture cell, 0..=255.
    clouds: Vec<u8>,
    style: Style,
}

/// Deterministic hash of an integer lattice point to [0, 1).
fn hash(x: i64, y: i64, seed: u64) -> f32 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ seed.wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 29;
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// Tileable value noise with `period` lattice cells across the texture.
fn value_noise(u: f32, v: f32, period: i64, seed: u64) -> f32 {
    let (x0, y0) = (u.floor(), v.floor());
    let (fx, fy) = (u - x0, v - y0);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let (ix, iy) = (x0 as i64, y0 as i64);
    let c = |dx: i64, dy: i64| {
        hash(
            (ix + dx).rem_euclid(period),
            (iy + dy).rem_euclid(period),
            seed,
        )
    };
    let a = c(0, 0) + (c(1, 0) - c(0, 0)) * sx;
    let b = c(0, 1) + (c(1, 1) - c(0, 1)) * sx;
    a + (b - a) * sy
}

impl Backdrop {
    /// The backdrop for a `width × height` picture; `seed` varies the clouds.
    pub fn new(width: usize, height: usize, style: &Style, seed: u64) -> Backdrop {
        let sky_rows = (0..height)
            .map(|r| style.sky((r as f32 + 0.5) / height.max(1) as f32))
            .collect();
        let mut clouds = vec![0u8; TEX * TEX];
        for y in 0..TEX {
            for x in 0..TEX {
                let (u, v) = (x as f32 / TEX as f32, y as f32 / TEX as f32);
                let mut n = 0.0;
                let mut amp = 0.5;
                let mut total = 0.0;
                for (o, period) in [8i64, 16, 32, 64, 128].iter().enumerate() {
                    n += amp
                        * value_noise(
                            u * *period as f32,
                            v * *period as f32,
                            *period,
                            seed.wrapping_add(o as u64),
                        );
                    total += amp;
                    amp *= 0.5;
                }
                let n = n / total;
                // Puffy clouds over roughly a third of the sky, soft edges.
                let t = ((n - 0.53) / 0.12).clamp(0.0, 1.0);
                let a = t * t * (3.0 - 2.0 * t);
                clouds[y * TEX + x] = (a * 255.0 + 0.5) as u8;
            }
        }
        Backdrop {
            width,
            height,
            sky_rows,
            clouds,
            style: style.clone(),
        }
    }

    /// The style this backdrop was made with.
    pub fn style(&self) -> &Style {
        &self.style
    }

    /// Paints sky and clouds for the camera `view` into `canvas`. With `dither`, cloud opacity
    /// gets a 4×4 ordered (Bayer) dither of about one palette step, so that the GIF's fixed
    /// palette shows soft clouds instead of contour bands, and the sky a fixed ±3-level dither
    /// against banding (fixed on screen like the gradient, so it stays identical from frame to
    /// frame and costs nothing after the first frame).
    pub fn paint(&self, view: &View, canvas: &mut Canvas, dither: bool) {
        let (w, h) = (self.width, self.height);
        debug_assert_eq!(canvas.width, w);
        let st = &self.style;
        // Texture coordinates (cells, fixed point 16.16) of a pixel: the clouds move by
        // parallax × camera motion, and scale with the zoom.
        let cell_px = st.cloud_cell * view.scale;
        let step = (65536.0 / cell_px.max(1e-3)).round() as i64;
        let ox = view.cx * st.cloud_parallax / st.cloud_cell - 0.5 * w as f64 / cell_px;
        let oy = -view.cy * st.cloud_parallax / st.cloud_cell - 0.5 * h as f64 / cell_px;
        let ox = (ox.rem_euclid(TEX as f64) * 65536.0) as i64;
        let oy = (oy.rem_euclid(TEX as f64) * 65536.0) as i64;
        let cloud = st.cloud.map(|c| c as i32);
        let amax = (st.cloud_opacity.clamp(0.0, 1.0) * 256.0) as i32;
        // Texture coordinates wrap at TEX cells = 2^24 in 16.16 fixed point.
        const WRAP: u32 = ((TEX as u32) << 16) - 1;
        let step = step.clamp(0, WRAP as i64) as u32;
        for r in 0..h {
            let sky_i = self.sky_rows[r].map(|c| (c * 256.0) as i32);
            let ty = ((oy + step as i64 * r as i64).rem_euclid(WRAP as i64 + 1)) as u32;
            let (y0, fy) = ((ty >> 16) as usize, ((ty & 0xFFFF) >> 8) as i32);
            let y1 = (y0 + 1) & (TEX - 1);
            let row0 = &self.clouds[y0 * TEX..(y0 + 1) * TEX];
            let row1 = &self.clouds[y1 * TEX..(y1 + 1) * TEX];
            let line = &mut canvas.rgb[r * w * 3..(r + 1) * w * 3];
            let bayer = &BAYER[r & 3];
            // Clear-sky pixels of this row, one per dither column.
            let clear: [[u8; 3]; 4] = std::array::from_fn(|c| {
                let sd = if dither { bayer[c] * 96 } else { 0 };
                sky_i.map(|s| ((s + sd + 128) >> 8).clamp(0, 255) as u8)
            });
            let mut tx = ox as u32;
            for (col, px) in line.chunks_exact_mut(3).enumerate() {
                let x0 = ((tx & WRAP) >> 16) as usize;
                let x1 = (x0 + 1) & (TEX - 1);
                let (c00, c01, c10, c11) = (row0[x0], row0[x1], row1[x0], row1[x1]);
                tx = tx.wrapping_add(step);
                if c00 | c01 | c10 | c11 == 0 {
                    px.copy_from_slice(&clear[col & 3]);
                    continue;
                }
                let fx = (((tx.wrapping_sub(step)) & 0xFFFF) >> 8) as i32;
                let a0 = c00 as i32 * (256 - fx) + c01 as i32 * fx;
                let a1 = c10 as i32 * (256 - fx) + c11 as i32 * fx;
                // Opacity in 1/256 units.
                let mut a = (((a0 * (256 - fy) + a1 * fy) >> 16) * amax) >> 8;
                if dither && a > 0 {
                    // ±half a palette opacity step (the palette has 9 opacity levels).
                    a = (a + bayer[col & 3] * amax / (9 * 16)).clamp(0, 256);
                }
                // Sky dither: ±3 levels, fixed on screen like the gradient itself.
                let sd = if dither { bayer[col & 3] * 96 } else { 0 };
                for k in 0..3 {
                    let s = sky_i[k] + sd;
                    let v = s + ((((cloud[k] << 8) - s) * a) >> 8);
                    px[k] = ((v + 128) >> 8).clamp(0, 255) as u8;
                }
            }
        }
    }
}

/// Draws every bird of `birds` for `view` on `canvas`.
pub fn draw_birds(
    canvas: &mut Canvas,
    birds: &[BirdState],
    view: &View,
    style: &Style,
    mask: &mut Mask,
) {
    let (w, h) = (canvas.width, canvas.height);
    let mut order: Vec<usize> = (0..birds.len()).collect();
    // Lower birds first; ties keep index order so output is deterministic.
    order.sort_by(|&a, &b| birds[a].z.total_cmp(&birds[b].z).then(a.cmp(&b)));
    let zmin = birds.iter().map(|b| b.z).fold(f64::MAX, f64::min);
    for i in order {
        let b = &birds[i];
        let (px, py) = view.to_pixel(b.x, b.y, w, h);
        // A bird 10 wingspans higher looks 5 % larger: a hint of depth without breaking scale.
        let s = (view.scale * (1.0 + 0.005 * (b.z - zmin).clamp(0.0, 10.0))) as f32;
        let (sin, cos) = (b.heading.sin() as f32, b.heading.cos() as f32);
        // Ground-plane (right, forward) → pixels: forward is (sin θ, cos θ) east/north, right is
        // (cos θ, −sin θ); screen rows grow southward.
        // A banked bird seen from above shows its wings foreshortened by cos φ.
        let across = b.bank.cos().abs() as f32;
        let place = |p: &[f32; 2]| {
            let (r, f) = (p[0] * across, p[1]);
            let e = r * cos + f * sin;
            let n = -r * sin + f * cos;
            [px as f32 + e * s, py as f32 - n * s]
        };
        let outlines = rig::top_view(&b.pose);
        let mut placed: Vec<Vec<[f32; 2]>> = outlines
            .iter()
            .map(|o| o.iter().map(place).collect())
            .collect();
        // Screen y is flipped, so the winding flips too; every contour flips alike, which keeps
        // the union. Inner wings (arm) a touch lighter, then body and hands on top.
        let arms = vec![placed[1].clone(), placed[3].clone()];
        canvas.fill(&arms, style.bird_wing, 1.0, mask);
        placed.remove(3);
        placed.remove(1);
        canvas.fill(&placed, style.bird, 1.0, mask);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sky_gradient_runs_from_top_to_bottom_colour() {
        let st = Style::default();
        let top = st.sky(0.0);
        let bottom = st.sky(1.0);
        for k in 0..3 {
            assert!((top[k] - st.sky_top[k] as f32).abs() < 1e-3);
            assert!((bottom[k] - st.sky_bottom[k] as f32).abs() < 1e-3);
        }
    }

    #[test]
    fn a_bird_darkens_the_pixels_under_it() {
        let st = Style::default();
        let bd = Backdrop::new(200, 120, &st, 0);
        let mut c = Canvas::new(200, 120);
        let view = View {
            cx: 0.0,
            cy: 0.0,
            scale: 60.0,
        };
        bd.paint(&view, &mut c, false);
        let before = c.clone();
        let bird = BirdState {
            pose: crate::wingbeat::WingPose {
                spread: 1.0,
                ..Default::default()
            },
            ..Default::default()
        };
        draw_birds(&mut c, &[bird], &view, &st, &mut Mask::new());
        let centre = (60 * 200 + 100) * 3;
        assert!(c.rgb[centre] < 60 && before.rgb[centre] > 100);
        // Wing tip region 0.45 wingspans to the right (east) is covered, far corners are not.
        let tip = (60 * 200 + 100 + 26) * 3;
        assert!(c.rgb[tip] < before.rgb[tip]);
        assert_eq!(c.rgb[0..3], before.rgb[0..3]);
    }
}
