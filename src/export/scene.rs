//! Drawing one picture of the flock: the background (`render.background`: sky, none or #rrggbb) and every
//! bird as an anti-aliased species [`silhouette`] projected by the frame's camera [`View`].
//!
//! **Sky.** A vertical gradient (by image row for the top-down cameras, by the ray's elevation for
//! the ground camera), an optional sun glow, and two procedural cloud layers. The clouds are
//! fractal value noise hashed on the layer's own coordinates (no texture, so no tile period at any
//! zoom): five octaves, each rotated by 0.5 rad against the one before so the lattice never
//! lines up, with
//! ```math
//! n(u) = \frac{\sum_k a^k \big(w_k\, v(2^k R^k u) + (1 - w_k)/2\big)}{\sum_k a^k}, \qquad
//! \alpha = \operatorname{smoothstep}\Big(\frac{n - n_0}{\Delta}\Big)
//! ```
//! where `v` is bilinear-smoothstep value noise on the integer lattice and `w_k` fades out an
//! octave whose wavelength on screen is under four samples (so zooming out never aliases: fine
//! octaves melt into their mean instead of flickering). For the top-down cameras a layer with
//! parallax `p` is seen at `u = (p c + (q − q₀)/s_L) / L` (camera centre `c`, pixel offset
//! `q − q₀`, feature size `L`), at the layer scale `s_L = s₀ (s/s₀)^ζ` (bird scale `s`, reference
//! `s₀` = [`Style::cloud_px`], ζ = [`Style::cloud_zoom`]): it slides by `p` times the camera's
//! motion, so the nearer layer moves faster than the far one and the flock's travel shows,
//! while the far sky hardly zooms when the camera closes in on the birds. The layers move
//! slowly on purpose (under a pixel per GIF frame at cruise): soft edges that crawl cost the GIF
//! few redrawn pixels, fast ones would cost most of the picture every frame. For the ground
//! camera a layer is a plane at a fixed height above the observer, intersected by each pixel's
//! ray. The background is evaluated on a grid of one sample per [`GRID`] pixels and bilinearly
//! interpolated, which makes it a few milliseconds per 960×540 frame.
//!
//! **Scrolled sky (GIF).** For the top-down cameras each cloud layer moves rigidly by its
//! parallax times the camera's motion as long as the layer scale does not change, so the GIF
//! renders each layer once into a tile larger than the picture ([`SkyCache`], at the layer scale
//! rounded to steps of 1/1024 in log) and shifts it by whole pixels, the offset rounded once per
//! frame ([`Backdrop::paint_scrolled`]). Both layers and the row's gradient are composed through
//! a per-row table indexed by what the two layers let through, `(1 − a₀)(1 − a₁)`. Between two
//! one-pixel steps the sky repeats exactly, which the GIF's frame differencing skips cheaply;
//! the screen-fixed dither maps a repeated colour to the same entry, so nothing flickers. The
//! ground camera and the sun glow keep the exact per-frame paint.

use super::camera::View;
use super::raster::{Canvas, Mask};
use super::sample::BirdState;
use super::silhouette::{self, Part};
use crate::error::{Error, Result};
use crate::wingbeat::Species;

/// What is behind the birds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Background {
    /// Sky gradient and procedural clouds.
    #[default]
    Sky,
    /// Nothing: transparent (PNG frames keep the alpha, for compositing).
    None,
    /// One flat colour.
    Colour([u8; 3]),
}

impl Background {
    /// Parses `sky`, `none` or `#rrggbb`.
    pub fn parse(s: &str) -> Result<Background> {
        match s {
            "sky" => Ok(Background::Sky),
            "none" => Ok(Background::None),
            _ => {
                let hex = s.strip_prefix('#').unwrap_or("");
                if hex.len() == 6 && hex.chars().all(|c| c.is_ascii_hexdigit()) {
                    let c = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0);
                    Ok(Background::Colour([c(0), c(2), c(4)]))
                } else {
                    Err(Error::parameter(
                        "render.background",
                        format!("unknown background {s:?}; use sky, none or a colour like #87ceeb"),
                    ))
                }
            }
        }
    }
}

/// `sky`, `none` or `#rrggbb`, as [`Background::parse`] reads it.
impl std::fmt::Display for Background {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Background::Sky => write!(f, "sky"),
            Background::None => write!(f, "none"),
            Background::Colour([r, g, b]) => write!(f, "#{r:02x}{g:02x}{b:02x}"),
        }
    }
}

/// Colours and look of the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Style {
    /// Sky colour at the top of the picture (the zenith for the ground camera).
    pub sky_top: [u8; 3],
    /// Sky colour halfway down.
    pub sky_mid: [u8; 3],
    /// Sky colour at the bottom of the picture (the horizon for the ground camera).
    pub sky_bottom: [u8; 3],
    /// Colour of the clouds.
    pub cloud: [u8; 3],
    /// Greatest opacity of a cloud, 0..1.
    pub cloud_opacity: f32,
    /// Cloud layers, far to near.
    pub layers: [CloudLayer; 2],
    /// Draw a sun glow in the upper right.
    pub sun: bool,
    /// Scale at which the top-down cameras show the cloud layers, pixels per wingspan, when the
    /// birds are drawn at this same scale.
    pub cloud_px: f64,
    /// How much the cloud layers zoom with the birds: the layers are shown at
    /// `cloud_px · (s / cloud_px)^cloud_zoom` for a bird scale `s` (0 = not at all, 1 = fully).
    /// Distant clouds barely zoom, and a small exponent keeps them from filling the picture
    /// with blur when the camera closes in.
    pub cloud_zoom: f64,
    /// Colour of the sun glow.
    pub sun_colour: [u8; 3],
    /// Colour of the ground below the horizon (ground camera), seen through haze that fades it
    /// into the horizon's sky colour within a few degrees.
    pub ground: [u8; 3],
}

/// One procedural cloud layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudLayer {
    /// Screen motion as a fraction of the camera's (top-down cameras; smaller looks farther).
    pub parallax: f64,
    /// Size of the largest cloud features, wingspans (top-down) or wingspans on the layer's
    /// plane (ground camera).
    pub size: f64,
    /// Height of the layer above the ground observer, wingspans.
    pub height: f64,
    /// Noise level where clouds start, 0..1 (higher = less cloud).
    pub threshold: f32,
    /// Width of the soft cloud edge in noise units.
    pub softness: f32,
    /// Opacity of this layer, 0..1 (times [`Style::cloud_opacity`]).
    pub opacity: f32,
    /// Stretch of the features along east–west (wisps when > 1).
    pub stretch: f64,
}

impl Default for Style {
    fn default() -> Self {
        Style {
            sky_top: [52, 104, 170],
            sky_mid: [112, 166, 214],
            sky_bottom: [206, 224, 236],
            cloud: [250, 251, 253],
            cloud_opacity: 0.85,
            layers: [
                // High, thin and streaky: the far layer.
                CloudLayer {
                    parallax: 0.06,
                    size: 40.0,
                    height: 300.0,
                    threshold: 0.5,
                    softness: 0.2,
                    opacity: 0.3,
                    stretch: 2.5,
                },
                // Puffy fair-weather clouds nearer the flock.
                CloudLayer {
                    parallax: 0.12,
                    size: 14.0,
                    height: 120.0,
                    threshold: 0.63,
                    softness: 0.12,
                    opacity: 0.7,
                    stretch: 1.0,
                },
            ],
            sun: false,
            cloud_px: 16.0,
            cloud_zoom: 0.25,
            sun_colour: [255, 242, 210],
            // A grass field in summer light, muted by distance.
            ground: [104, 122, 84],
        }
    }
}

impl Style {
    /// Pixels per wingspan of the cloud layers when the birds are drawn at `scale`.
    pub fn layer_scale(&self, scale: f64) -> f64 {
        self.cloud_px * (scale.max(1e-6) / self.cloud_px).powf(self.cloud_zoom)
    }

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

/// Angle below the horizon over which the ground's haze fades, radians (about 2°).
const GROUND_HAZE_RAD: f64 = 0.035;

/// Background sample spacing, pixels.
pub const GRID: usize = 8;

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

/// `⌊x⌋` as an integer, without a libm call (baseline x86-64 has no rounding instruction).
#[inline]
fn floor_i(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x {
        i - 1
    } else {
        i
    }
}

/// Value noise on the integer lattice (no period), smoothstep-interpolated, in [0, 1).
#[inline]
fn value_noise(u: f64, v: f64, seed: u64) -> f32 {
    let (ix, iy) = (floor_i(u), floor_i(v));
    let (fx, fy) = ((u - ix as f64) as f32, (v - iy as f64) as f32);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let c00 = hash(ix, iy, seed);
    let c10 = hash(ix + 1, iy, seed);
    let c01 = hash(ix, iy + 1, seed);
    let c11 = hash(ix + 1, iy + 1, seed);
    let a = c00 + (c10 - c00) * sx;
    let b = c01 + (c11 - c01) * sx;
    a + (b - a) * sy
}

/// Octaves of the cloud noise.
const OCTAVES: usize = 5;
/// Amplitude ratio between octaves.
const GAIN: f32 = 0.5;
/// `sin 0.5`, `cos 0.5`: the rotation between octaves.
const ROT: (f64, f64) = (0.479_425_538_604_203, 0.877_582_561_890_372_8);

/// Fractal noise at `(u, v)` (layer units); `footprint` = layer units per background sample.
pub fn cloud_noise(u: f64, v: f64, footprint: f64, seed: u64) -> f32 {
    cloud_noise_within(u, v, footprint, seed, (f32::MIN, f32::MAX))
}

/// [`cloud_noise`], stopping early once the result is sure to be below `bounds.0` or above
/// `bounds.1` (then any value on that side is returned): the finer octaves can move the sum by
/// at most their total amplitude, so most clear-sky samples need only one or two octaves.
pub fn cloud_noise_within(u: f64, v: f64, footprint: f64, seed: u64, bounds: (f32, f32)) -> f32 {
    let (s, c) = ROT;
    let (mut x, mut y) = (u, v);
    // Total amplitude of all octaves, to normalise and to bound what is left.
    let total: f32 = (0..OCTAVES).map(|k| GAIN.powi(k as i32)).sum();
    let (lo, hi) = (bounds.0 * total, bounds.1 * total);
    let (mut n, mut amp, mut rest) = (0.0f32, 1.0f32, total);
    let mut freq = 1.0f64;
    for k in 0..OCTAVES {
        rest -= amp;
        // Wavelength of this octave in samples; fade out below 4.
        let wl = 1.0 / (freq * footprint.max(1e-12));
        let w = ((wl - 2.0) / 2.0).clamp(0.0, 1.0) as f32;
        if w <= 0.0 {
            // This and every finer octave sit at their mean.
            n += 0.5 * (amp + rest);
            break;
        }
        let val = value_noise(x * freq, y * freq, seed.wrapping_add(k as u64 * 7919));
        n += amp * (w * val + (1.0 - w) * 0.5);
        if n + rest < lo || n > hi {
            break;
        }
        amp *= GAIN;
        freq *= 2.0;
        // Rotate the next octave's axes (and shift them) so lattices never line up.
        let (nx, ny) = (x * c - y * s + 17.3, x * s + y * c - 5.1);
        x = nx;
        y = ny;
    }
    n / total
}

fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Everything about the background that does not change from frame to frame.
#[derive(Debug, Clone)]
pub struct Backdrop {
    width: usize,
    height: usize,
    background: Background,
    style: Style,
    seed: u64,
}

impl Backdrop {
    /// The backdrop for a `width × height` picture; `seed` varies the clouds.
    pub fn new(
        width: usize,
        height: usize,
        style: &Style,
        background: Background,
        seed: u64,
    ) -> Backdrop {
        Backdrop {
            width,
            height,
            background,
            style: style.clone(),
            seed,
        }
    }

    /// The style this backdrop was made with.
    pub fn style(&self) -> &Style {
        &self.style
    }

    /// What is behind the birds.
    pub fn background(&self) -> Background {
        self.background
    }

    /// Cloud opacity (0..1) of layer `l` at pixel `(col, row)` for `view`; `None` where the
    /// layer is not seen (the ground camera's rays below its plane). For tests and the sampler.
    pub fn cloud_alpha(&self, view: &View, l: usize, col: f64, row: f64) -> Option<f32> {
        let s = self.style.layer_scale(view.scale());
        self.cloud_alpha_at(view, s, l, col, row)
    }

    /// [`Backdrop::cloud_alpha`] with the top-down layer scale `s` computed once per frame.
    fn cloud_alpha_at(&self, view: &View, s: f64, l: usize, col: f64, row: f64) -> Option<f32> {
        let layer = &self.style.layers[l];
        let (w, h) = (self.width, self.height);
        let seed = self.seed.wrapping_mul(31).wrapping_add(l as u64 + 1);
        let (u, v, fp) = match view {
            View::Top { cx, cy, .. } => {
                let u = (layer.parallax * cx + (col - 0.5 * w as f64) / s) / layer.size;
                let v = (layer.parallax * cy - (row - 0.5 * h as f64) / s) / layer.size;
                (u, v, GRID as f64 / (s * layer.size))
            }
            View::Ground(e) => {
                let d = e.ray(col, row, w, h);
                if d[2] <= 0.02 {
                    return None;
                }
                let t = layer.height / d[2];
                let (x, y) = (e.at[0] + t * d[0], e.at[1] + t * d[1]);
                // Layer units covered by one sample there: ray length × angle per sample,
                // stretched by the plane's obliquity 1 / sin(elevation).
                let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let len = t * norm;
                let fp = len * GRID as f64 / e.focal_px / (d[2] / norm).max(0.05) / layer.size;
                (x / layer.size, y / layer.size, fp)
            }
        };
        let n = cloud_noise_within(
            u / layer.stretch,
            v,
            fp,
            seed,
            (layer.threshold, layer.threshold + layer.softness),
        );
        Some(smoothstep((n - layer.threshold) / layer.softness) * layer.opacity)
    }

    /// Sky colour (without clouds) at pixel `(col, row)` for `view`.
    fn sky_at(&self, view: &View, col: f64, row: f64) -> [f32; 3] {
        let st = &self.style;
        let (w, h) = (self.width as f64, self.height as f64);
        let v = match view {
            View::Top { .. } => (row / h) as f32,
            View::Ground(e) => {
                let d = e.ray(col, row, self.width, self.height);
                let el = (d[2] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()).clamp(-1.0, 1.0);
                if el < 0.0 {
                    // Below the horizon: the ground, hazy towards the horizon (a few degrees).
                    let haze = (el / GROUND_HAZE_RAD).exp() as f32;
                    let (g, b) = (st.ground, st.sky_bottom);
                    return [0, 1, 2].map(|k| g[k] as f32 + (b[k] as f32 - g[k] as f32) * haze);
                }
                1.0 - (el.asin() / std::f64::consts::FRAC_PI_2).max(0.0) as f32
            }
        };
        let mut c = st.sky(v);
        if st.sun {
            let (dx, dy) = (col - 0.82 * w, row - 0.12 * h);
            let r2 = (dx * dx + dy * dy) / (0.45 * w.max(h)).powi(2);
            let g = (0.6 * (-r2).exp() + 0.4 * (-12.0 * r2).exp()) as f32;
            for (k, ck) in c.iter_mut().enumerate() {
                *ck += (st.sun_colour[k] as f32 - *ck) * g * 0.8;
            }
        }
        c
    }

    /// Paints the background for the camera `view` into `canvas` (replacing every pixel).
    pub fn paint(&self, view: &View, canvas: &mut Canvas) {
        let w = self.width;
        debug_assert_eq!(canvas.width, w);
        match self.background {
            Background::None => canvas.rgba.fill(0),
            Background::Colour(c) => {
                for p in canvas.rgba.chunks_exact_mut(4) {
                    p.copy_from_slice(&[c[0], c[1], c[2], 255]);
                }
                if let View::Ground(e) = view {
                    self.paint_plain_ground(e, c, canvas);
                }
            }
            Background::Sky => self.paint_sky(view, canvas),
        }
    }

    /// The ground camera over a plain colour `c`: the ground below the horizon, in a colour that
    /// stands out from `c` ([`ground_for`]), hazy towards the horizon as over the
    /// sky, so the horizon shows on any colour (dark ones too). The eye does not roll, so the
    /// horizon is level and one ray per row decides it.
    fn paint_plain_ground(&self, e: &super::camera::Eye, c: [u8; 3], canvas: &mut Canvas) {
        let (w, h) = (self.width, self.height);
        let g = ground_for(c);
        for r in 0..h {
            let d = e.ray(0.5 * w as f64, r as f64 + 0.5, w, h);
            let el = d[2] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if el.is_nan() || el >= 0.0 {
                continue;
            }
            let haze = (el / GROUND_HAZE_RAD).exp() as f32;
            let px = [0, 1, 2].map(|k| {
                (g[k] as f32 + (c[k] as f32 - g[k] as f32) * haze)
                    .round()
                    .clamp(0.0, 255.0) as u8
            });
            for p in canvas.rgba[r * w * 4..(r + 1) * w * 4].chunks_exact_mut(4) {
                p.copy_from_slice(&[px[0], px[1], px[2], 255]);
            }
        }
    }

    fn paint_sky(&self, view: &View, canvas: &mut Canvas) {
        let (w, h) = (self.width, self.height);
        let st = &self.style;
        let gw = w / GRID + 2;
        let gh = h / GRID + 2;
        let cloud = st.cloud.map(|c| c as f32);
        let s_layer = st.layer_scale(view.scale());
        // Colour at every grid sample, 8.8 fixed point.
        let mut grid = vec![[0i32; 3]; gw * gh];
        for gy in 0..gh {
            let row = (gy * GRID) as f64 + 0.5;
            for gx in 0..gw {
                let col = (gx * GRID) as f64 + 0.5;
                let mut c = self.sky_at(view, col, row);
                for l in 0..st.layers.len() {
                    if let Some(a) = self.cloud_alpha_at(view, s_layer, l, col, row) {
                        let a = a * st.cloud_opacity;
                        for k in 0..3 {
                            c[k] += (cloud[k] - c[k]) * a;
                        }
                    }
                }
                grid[gy * gw + gx] = c.map(|v| (v * 256.0) as i32);
            }
        }
        // Bilinear interpolation to every pixel (GRID = 2^SH).
        const SH: i32 = GRID.trailing_zeros() as i32;
        const OUT: i32 = 8 + 2 * SH;
        const HALF: i32 = 1 << (OUT - 1);
        let mut line = vec![[0i32; 3]; gw];
        for r in 0..h {
            let (gy, fy) = (r / GRID, (r % GRID) as i32);
            let (a, b) = (
                &grid[gy * gw..(gy + 1) * gw],
                &grid[(gy + 1) * gw..(gy + 2) * gw],
            );
            for (x, l) in line.iter_mut().enumerate() {
                for k in 0..3 {
                    l[k] = (a[x][k] << SH) + (b[x][k] - a[x][k]) * fy;
                }
            }
            let out = &mut canvas.rgba[r * w * 4..(r + 1) * w * 4];
            for (gx, cell) in out.chunks_mut(4 * GRID).enumerate() {
                let (p, q) = (line[gx], line[gx + 1]);
                // Value × GRID² in 8.8 fixed point, stepped along the cell.
                let mut v = [p[0] << SH, p[1] << SH, p[2] << SH];
                let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                for px in cell.chunks_exact_mut(4) {
                    px[0] = ((v[0] + HALF) >> OUT).clamp(0, 255) as u8;
                    px[1] = ((v[1] + HALF) >> OUT).clamp(0, 255) as u8;
                    px[2] = ((v[2] + HALF) >> OUT).clamp(0, 255) as u8;
                    px[3] = 255;
                    v[0] += d[0];
                    v[1] += d[1];
                    v[2] += d[2];
                }
            }
        }
    }
}

/// Steps of the top-down layer scale at which the scrolled sky is rendered, in natural log:
/// the layer scale is rounded to `e^(k/1024)`, so a zoom shows the far edge of a 960-pixel
/// picture at most a quarter of a pixel off (our choice: under the half pixel the scroll rounds).
const SCALE_STEP: f64 = 1.0 / 1024.0;
/// Cloud opacity in the scrolled tiles: fixed point with this many fraction bits.
const ALPHA_BITS: u32 = 12;
/// Pixels of layer rendered beyond each edge of the picture when a tile is first made for a
/// scale, and when the picture has scrolled out of the one before at the same scale (a zoom
/// changes the scale every few frames, steady flight never). Our choice.
const TILE_MARGIN: (usize, usize) = (8, 384);
/// Tiles kept per layer (workers a few frames apart may need two). Our choice.
const TILES_KEPT: usize = 3;

/// One cloud layer's opacity over a rectangle of the layer's own pixel lattice at one quantised
/// scale: a pure function of the lattice point and the scale, whichever frame made it.
#[derive(Debug)]
struct Tile {
    /// Quantised layer scale, steps of [`SCALE_STEP`].
    key: i64,
    /// Lattice point of the tile's first sample.
    x0: i64,
    y0: i64,
    w: usize,
    h: usize,
    /// Opacity (layer opacity × [`Style::cloud_opacity`] included), 0..=255.
    alpha: Vec<u8>,
}

impl Tile {
    fn covers(&self, key: i64, x: i64, y: i64, w: usize, h: usize) -> bool {
        self.key == key
            && x >= self.x0
            && y >= self.y0
            && x + w as i64 <= self.x0 + self.w as i64
            && y + h as i64 <= self.y0 + self.h as i64
    }
}

/// The top-down sky, each cloud layer rendered once per scale and scrolled by whole pixels
/// ([`Backdrop::paint_scrolled`]); shared by the workers drawing one film. Everything it holds
/// is a pure function of the backdrop and the scale, so what is painted does not depend on
/// which worker made a tile or in which order frames were drawn.
#[derive(Debug, Default)]
pub struct SkyCache {
    /// Each row's colours under the clouds, made on first use: entry `i` of row `r` is the row's
    /// sky colour seen through clouds that let `(256 i + 128)/255²` of it through (both layers
    /// together: a far layer of opacity `a₀` under a near one of `a₁` lets `(1 − a₀)(1 − a₁)`
    /// through, and the cloud colour makes up the rest), as RGBA bytes.
    rows: std::sync::OnceLock<Vec<[u8; 4]>>,
    /// Recent tiles of each layer, newest last.
    tiles: [std::sync::Mutex<Vec<std::sync::Arc<Tile>>>; 2],
}

impl Backdrop {
    /// The quantised layer scale's step number and value for the bird scale `scale`.
    fn quantised_scale(&self, scale: f64) -> (i64, f64) {
        let s = self.style.layer_scale(scale);
        let key = (s.ln() / SCALE_STEP).round() as i64;
        (key, (key as f64 * SCALE_STEP).exp())
    }

    /// Screen offset of layer `l`'s lattice for the top-down view centred on `(cx, cy)` at the
    /// quantised layer scale `sq`: pixel `(col, row)` shows lattice point
    /// `(col + ox, row − oy)`. Rounded once per frame, so the layer moves rigidly by whole pixels.
    fn lattice_offset(&self, l: usize, cx: f64, cy: f64, sq: f64) -> (i64, i64) {
        let p = self.style.layers[l].parallax;
        (floor_i(p * cx * sq + 0.5), floor_i(p * cy * sq + 0.5))
    }

    /// Opacity (times [`Style::cloud_opacity`]) of layer `l` at lattice sample `(x, y)` of the
    /// quantised layer scale `sq`.
    fn lattice_alpha(&self, l: usize, sq: f64, x: i64, y: i64) -> f32 {
        let layer = &self.style.layers[l];
        let seed = self.seed.wrapping_mul(31).wrapping_add(l as u64 + 1);
        let k = 1.0 / (sq * layer.size);
        let u = (x as f64 + 0.5 - 0.5 * self.width as f64) * k;
        let v = (0.5 * self.height as f64 - (y as f64 + 0.5)) * k;
        let n = cloud_noise_within(
            u / layer.stretch,
            v,
            GRID as f64 * k,
            seed,
            (layer.threshold, layer.threshold + layer.softness),
        );
        smoothstep((n - layer.threshold) / layer.softness)
            * layer.opacity
            * self.style.cloud_opacity
    }

    /// Renders layer `l` over at least the lattice points `x0.. x0 + w`, `y0 .. y0 + h` at scale
    /// step `key` (widened to whole grid cells): samples every [`GRID`] lattice points (aligned
    /// to multiples of `GRID`, so every tile interpolates the same samples) and bilinear between
    /// them.
    fn make_tile(
        &self,
        l: usize,
        (key, sq): (i64, f64),
        (x0, y0): (i64, i64),
        (w, h): (usize, usize),
    ) -> Tile {
        let g = GRID as i64;
        // Aligned to the grid: from a grid point, whole cells.
        let (gx0, gy0) = (x0.div_euclid(g), y0.div_euclid(g));
        let (x0, y0) = (gx0 * g, gy0 * g);
        let (w, h) = (
            w.div_ceil(GRID) * GRID + GRID,
            h.div_ceil(GRID) * GRID + GRID,
        );
        let (gw, gh) = (w / GRID + 1, h / GRID + 1);
        let one = (1u32 << ALPHA_BITS) as f32;
        let mut grid = vec![0i32; gw * gh];
        for j in 0..gh {
            for i in 0..gw {
                let a = self.lattice_alpha(l, sq, (gx0 + i as i64) * g, (gy0 + j as i64) * g);
                grid[j * gw + i] = (a * one).round() as i32;
            }
        }
        const SH: u32 = GRID.trailing_zeros();
        const ROUND: i32 = 1 << (ALPHA_BITS + 2 * SH - 1);
        let mut alpha = vec![0u8; w * h];
        let mut line = vec![0i32; gw];
        for (r, out) in alpha.chunks_exact_mut(w).enumerate() {
            let (j, fy) = (r / GRID, (r % GRID) as i32);
            let (a, b) = (
                &grid[j * gw..(j + 1) * gw],
                &grid[(j + 1) * gw..(j + 2) * gw],
            );
            for ((l, &p), &q) in line.iter_mut().zip(a).zip(b) {
                *l = (p << SH) + (q - p) * fy;
            }
            // Whole cells of GRID pixels (the tile is aligned to the grid).
            for (cell, pair) in out.chunks_exact_mut(GRID).zip(line.windows(2)) {
                let (p, d) = (pair[0] << SH, pair[1] - pair[0]);
                for (fx, o) in cell.iter_mut().enumerate() {
                    let v = (p + d * fx as i32).max(0);
                    // Fixed point ALPHA_BITS + 2·SH bits to 0..=255, rounded.
                    *o = ((v * 255 + ROUND) >> (ALPHA_BITS + 2 * SH)).min(255) as u8;
                }
            }
        }
        Tile {
            key,
            x0,
            y0,
            w,
            h,
            alpha,
        }
    }

    /// The tile of layer `l` at scale step `key` holding the picture's lattice window from
    /// `(x, y)`, from `cache` or newly made (and kept).
    fn tile(
        &self,
        cache: &SkyCache,
        l: usize,
        (key, sq): (i64, f64),
        x: i64,
        y: i64,
    ) -> std::sync::Arc<Tile> {
        let (w, h) = (self.width, self.height);
        let same_scale = {
            let tiles = cache.tiles[l].lock().unwrap_or_else(|e| e.into_inner());
            if let Some(t) = tiles.iter().rev().find(|t| t.covers(key, x, y, w, h)) {
                return t.clone();
            }
            tiles.iter().any(|t| t.key == key)
        };
        let m = if same_scale {
            TILE_MARGIN.1
        } else {
            TILE_MARGIN.0
        };
        let t = std::sync::Arc::new(self.make_tile(
            l,
            (key, sq),
            (x - m as i64, y - m as i64),
            (w + 2 * m, h + 2 * m),
        ));
        let mut tiles = cache.tiles[l].lock().unwrap_or_else(|e| e.into_inner());
        tiles.push(t.clone());
        if tiles.len() > TILES_KEPT {
            tiles.remove(0);
        }
        t
    }

    /// [`Backdrop::paint`], with the top-down sky's cloud layers rendered once per scale into
    /// `cache` and scrolled by whole pixels (parallax kept: each layer by its own offset), for
    /// the GIF: the clouds move in whole-pixel steps, so the frames between steps repeat the sky
    /// exactly and the frame differencing finds nothing to write there. Within a quarter of a
    /// pixel of zoom and half a pixel of position of [`Backdrop::paint`], and a few levels of
    /// colour (measured in the tests). The ground camera and plain backgrounds paint as
    /// [`Backdrop::paint`].
    pub fn paint_scrolled(&self, view: &View, canvas: &mut Canvas, cache: &SkyCache) {
        let View::Top { cx, cy, scale } = *view else {
            return self.paint(view, canvas);
        };
        if self.background != Background::Sky || self.style.sun {
            // The sun glow is not the same along a row: painted per frame.
            return self.paint(view, canvas);
        }
        let (w, h) = (self.width, self.height);
        let cloud = self.style.cloud.map(|c| c as f64);
        let rows = cache.rows.get_or_init(|| {
            let mut v = Vec::with_capacity(h * 256);
            for r in 0..h {
                let b = self.sky_at(view, 0.5, r as f64 + 0.5);
                for i in 0..256 {
                    let t = (256.0 * i as f64 + 128.0) / 65025.0;
                    let c = [0, 1, 2]
                        .map(|k| (cloud[k] - (cloud[k] - b[k] as f64) * t.min(1.0)).round());
                    v.push([c[0] as u8, c[1] as u8, c[2] as u8, 255]);
                }
            }
            v
        });
        let q = self.quantised_scale(scale);
        let (o0, o1) = (
            self.lattice_offset(0, cx, cy, q.1),
            self.lattice_offset(1, cx, cy, q.1),
        );
        let t0 = self.tile(cache, 0, q, o0.0, -o0.1);
        let t1 = self.tile(cache, 1, q, o1.0, -o1.1);
        for r in 0..h {
            let i0 = (-o0.1 + r as i64 - t0.y0) as usize * t0.w + (o0.0 - t0.x0) as usize;
            let i1 = (-o1.1 + r as i64 - t1.y0) as usize * t1.w + (o1.0 - t1.x0) as usize;
            let a0 = &t0.alpha[i0..i0 + w];
            let a1 = &t1.alpha[i1..i1 + w];
            let lut = &rows[r * 256..(r + 1) * 256];
            let out = &mut canvas.rgba[r * w * 4..(r + 1) * w * 4];
            for ((px, &p), &q) in out.chunks_exact_mut(4).zip(a0).zip(a1) {
                // What both layers let through, 0..=65025, to 0..=254.
                let t = (255 - p as u32) * (255 - q as u32);
                px.copy_from_slice(&lut[(t >> 8) as usize]);
            }
        }
    }
}

/// Draws every bird of `birds` (of `species`) for `view` on `canvas`, far ones first.
pub fn draw_birds(
    canvas: &mut Canvas,
    birds: &[BirdState],
    view: &View,
    species: Species,
    mask: &mut Mask,
) {
    let (w, h) = (canvas.width, canvas.height);
    let plumage = silhouette::plumage(species);
    let radius = silhouette::radius(species);
    // Painter's order: lower birds first from above, farther birds first from the ground; ties
    // keep index order so output is deterministic.
    let depth = |b: &BirdState| -> f64 {
        match view {
            View::Top { .. } => b.z,
            View::Ground(e) => {
                -((b.x - e.at[0]) * e.forward[0]
                    + (b.y - e.at[1]) * e.forward[1]
                    + (b.z - e.at[2]) * e.forward[2])
            }
        }
    };
    let mut order: Vec<(f64, usize)> = birds.iter().map(depth).zip(0..).collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let zmin = birds.iter().map(|b| b.z).fold(f64::MAX, f64::min);
    let mut layers: [Vec<Vec<[f32; 2]>>; 4] = Default::default();
    for (_, i) in order {
        let b = &birds[i];
        let Some((px, py, s)) = view.project([b.x, b.y, b.z], w, h) else {
            continue;
        };
        // Cull birds wholly off the picture.
        let r = radius * s;
        if px + r < 0.0 || py + r < 0.0 || px - r > w as f64 || py - r > h as f64 {
            continue;
        }
        let (sin, cos) = b.heading.sin_cos();
        let (sp, cp) = b.pitch.sin_cos();
        // Body frame (right, forward, up) → world: pitched nose up by ϑ about the right axis,
        // then forward (sin θ, cos θ), right (cos θ, −sin θ).
        let to_world = |q: &[f32; 3]| {
            let (x, y0, z0) = (q[0] as f64, q[1] as f64, q[2] as f64);
            let (y, z) = (y0 * cp - z0 * sp, y0 * sp + z0 * cp);
            [b.x + x * cos + y * sin, b.y - x * sin + y * cos, b.z + z]
        };
        // Top-down: a bird 10 wingspans higher looks 5 % larger, a hint of depth.
        let lift = 1.0 + 0.005 * (b.z - zmin).clamp(0.0, 10.0);
        for l in layers.iter_mut() {
            l.clear();
        }
        // From the ground the birds also show their side view (body, neck, head): the plan is
        // flat, and a bird level with the eye would otherwise be a line.
        let side = match view {
            View::Top { .. } => Vec::new(),
            View::Ground(_) => silhouette::profile(species, b.bank),
        };
        for piece in silhouette::pieces(species, &b.pose, b.bank)
            .into_iter()
            .chain(side)
        {
            let mut pts = Vec::with_capacity(piece.points.len());
            for q in &piece.points {
                let p = to_world(q);
                let proj = match view {
                    View::Top { .. } => {
                        let (c, r, _) = view.project(p, w, h).expect("top view");
                        Some((px + (c - px) * lift, py + (r - py) * lift))
                    }
                    View::Ground(_) => view.project(p, w, h).map(|(c, r, _)| (c, r)),
                };
                match proj {
                    Some((c, r)) => pts.push([c as f32, r as f32]),
                    None => break,
                }
            }
            if pts.len() == piece.points.len() {
                layers[piece.part as usize].push(pts);
            }
        }
        // From below, the far wing's inner part shows through nothing: order is wings, body,
        // head; each colour's polygons fill as one union.
        let colours = [plumage.body, plumage.arm, plumage.hand, plumage.head];
        for part in [Part::Arm, Part::Hand, Part::Body, Part::Head] {
            let k = part as usize;
            if !layers[k].is_empty() {
                canvas.fill(&layers[k], colours[k], 1.0, mask);
            }
        }
    }
}

/// Colour of the ground over the plain background colour `c`: the grass field's colour, or, where
/// that would hardly stand out from `c` (a difference of less than 40 levels of luminance), `c`
/// made darker (or lighter, for a dark `c`), so the field and its edge are always seen.
pub fn ground_for(c: [u8; 3]) -> [u8; 3] {
    let g = Style::default().ground;
    let lum = |c: [u8; 3]| 0.299 * c[0] as f64 + 0.587 * c[1] as f64 + 0.114 * c[2] as f64;
    if (lum(g) - lum(c)).abs() >= 40.0 {
        return g;
    }
    if lum(c) >= 96.0 {
        c.map(|v| (v as f64 * 0.55).round() as u8)
    } else {
        c.map(|v| (v as f64 + (255.0 - v as f64) * 0.45).round() as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backgrounds_read_back_what_they_write() {
        for b in [
            Background::Sky,
            Background::None,
            Background::Colour([0x87, 0xce, 0x0b]),
        ] {
            assert_eq!(Background::parse(&b.to_string()).unwrap(), b);
        }
        assert_eq!(Background::Colour([1, 2, 255]).to_string(), "#0102ff");
    }

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
    fn backgrounds_parse_and_bad_ones_name_the_flag() {
        assert_eq!(Background::parse("sky").unwrap(), Background::Sky);
        assert_eq!(Background::parse("none").unwrap(), Background::None);
        assert_eq!(
            Background::parse("#87ceeb").unwrap(),
            Background::Colour([0x87, 0xce, 0xeb])
        );
        for bad in ["#12345", "blue", "#gg0000", ""] {
            let e = Background::parse(bad).unwrap_err().to_string();
            assert!(e.contains("render.background"), "{e}");
        }
    }

    #[test]
    fn a_bird_darkens_the_pixels_under_it() {
        let st = Style::default();
        let bd = Backdrop::new(200, 120, &st, Background::Sky, 0);
        let mut c = Canvas::new(200, 120);
        let view = View::Top {
            cx: 0.0,
            cy: 0.0,
            scale: 60.0,
        };
        bd.paint(&view, &mut c);
        let before = c.clone();
        let bird = BirdState {
            pose: crate::wingbeat::WingPose::EXTENDED,
            ..Default::default()
        };
        draw_birds(&mut c, &[bird], &view, Species::Goose, &mut Mask::new());
        assert!(c.pixel(100, 60)[0] < 90 && before.pixel(100, 60)[0] > 100);
        // Wing region 0.4 wingspans to the right (east) is covered, far corners are not.
        assert!(c.pixel(124, 60)[0] < before.pixel(124, 60)[0]);
        assert_eq!(c.pixel(0, 0), before.pixel(0, 0));
    }

    #[test]
    fn cloud_noise_has_no_period() {
        // Value noise hashed on the lattice: shifting by any whole number of cells changes it.
        for period in [8.0, 64.0, 256.0, 4096.0] {
            let diff: f32 = (0..200)
                .map(|k| {
                    let (u, v) = (k as f64 * 0.37, k as f64 * 0.11);
                    (cloud_noise(u, v, 0.01, 3) - cloud_noise(u + period, v, 0.01, 3)).abs()
                })
                .sum::<f32>()
                / 200.0;
            assert!(diff > 0.03, "period {period}: {diff}");
        }
    }
}

#[cfg(test)]
mod scrolled_tests {
    use super::*;

    /// Largest and mean channel difference between the scrolled and the exact sky, and the
    /// share of pixels more than 4 levels apart.
    fn compare(bd: &Backdrop, cache: &SkyCache, view: &View) -> (i32, f64, f64) {
        let (w, h) = (bd.width, bd.height);
        let (mut a, mut b) = (Canvas::new(w, h), Canvas::new(w, h));
        bd.paint(view, &mut a);
        bd.paint_scrolled(view, &mut b, cache);
        let (mut worst, mut sum, mut over) = (0, 0.0, 0usize);
        for (p, q) in a.rgba.chunks_exact(4).zip(b.rgba.chunks_exact(4)) {
            let d = (0..3)
                .map(|k| (p[k] as i32 - q[k] as i32).abs())
                .max()
                .unwrap();
            worst = worst.max(d);
            sum += d as f64;
            over += (d > 4) as usize;
        }
        (worst, sum / (w * h) as f64, over as f64 / (w * h) as f64)
    }

    #[test]
    fn scrolled_sky_stays_near_the_exact_one_and_does_not_depend_on_what_came_before() {
        let st = Style::default();
        let bd = Backdrop::new(480, 270, &st, Background::Sky, 11);
        let cache = SkyCache::default();
        let views: Vec<View> = (0..40)
            .map(|i| View::Top {
                cx: 3.7 * i as f64 - 50.0,
                cy: 1.3 * i as f64 + 20.0,
                scale: 12.0 + 0.37 * (i / 8) as f64,
            })
            .collect();
        let mut worst = (0, 0.0f64, 0.0f64);
        for v in &views {
            let (m, mean, over) = compare(&bd, &cache, v);
            worst = (worst.0.max(m), worst.1.max(mean), worst.2.max(over));
        }
        eprintln!(
            "scrolled vs exact: largest {} levels, mean up to {:.3}, over 4 levels {:.4} %",
            worst.0,
            worst.1,
            100.0 * worst.2
        );
        assert!(
            worst.0 <= 10 && worst.1 < 1.0 && worst.2 < 0.001,
            "{worst:?}"
        );
        // The same view painted from a fresh cache and from one that has seen other views.
        for v in [&views[5], &views[39], &views[17]] {
            let (mut a, mut b) = (Canvas::new(480, 270), Canvas::new(480, 270));
            bd.paint_scrolled(v, &mut a, &SkyCache::default());
            bd.paint_scrolled(v, &mut b, &cache);
            assert!(a.rgba == b.rgba);
        }
        // A still camera repeats the sky exactly; a step of a tenth of a pixel moves no cloud.
        let (mut a, mut b) = (Canvas::new(480, 270), Canvas::new(480, 270));
        let at = |cx: f64| View::Top {
            cx,
            cy: 0.0,
            scale: 16.0,
        };
        bd.paint_scrolled(&at(100.0), &mut a, &cache);
        bd.paint_scrolled(
            &at(100.0 + 0.1 / (0.12 * st.layer_scale(16.0))),
            &mut b,
            &cache,
        );
        assert!(a.rgba == b.rgba);
    }
}
