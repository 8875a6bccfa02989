//! Flocks drawn by formation's own renderer for the tracking tests: a V flying straight, its
//! frames in grey with blur and noise, and the true pixel positions of its birds.

#![allow(dead_code)]

use formation::animation::Frame;
use formation::export::pictures::Film;
use formation::export::raster::{Canvas, Mask};
use formation::export::{CameraKind, RenderOptions};
use formation::track::detect::Gray;
use formation::Animation;

/// A V of `n` birds (arms 0.9 wingspans apart across, 0.6 behind) flying at `heading_deg`
/// (clockwise from north) at 5 wingspans a second for `frames` frames at 25 fps, each bird
/// jostling slowly (a few hundredths of a wingspan) so the shape is alive.
pub fn v_flock(
    n: usize,
    heading_deg: f64,
    frames: usize,
    species: &str,
    start: (f64, f64),
) -> Animation {
    let fps = 25.0;
    let mut a = Animation::new(3, fps, 1.5, n);
    a.species = Some(species.to_string());
    let h = heading_deg.to_radians();
    let (fx, fy) = (h.sin(), h.cos());
    let (rx, ry) = (h.cos(), -h.sin());
    for k in 0..frames {
        let t = k as f64 / fps;
        let mut f = Frame {
            t,
            x: vec![],
            y: vec![],
            z: vec![],
            heading: vec![],
            speed: vec![],
            bank: None,
            pitch: None,
            e: None,
            xi: None,
            wing_phase: None,
        };
        for i in 0..n {
            let side = if i % 2 == 1 { 1.0 } else { -1.0 };
            let rank = i.div_ceil(2) as f64;
            let lat = side * 0.9 * rank + 0.04 * (1.3 * t + i as f64).sin();
            let back = 0.6 * rank + 0.04 * (0.9 * t + 2.0 * i as f64).cos();
            let along = 5.0 * t - back;
            f.x.push(start.0 + along * fx + lat * rx);
            f.y.push(start.1 + along * fy + lat * ry);
            f.z.push(0.0);
            f.heading.push(h);
            f.speed.push(5.0);
        }
        a.frames.push(f);
    }
    a
}

/// A deterministic generator for the noise (xorshift), uniform in [0, 1).
struct Noise(u64);
impl Noise {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Approximately normal (sum of 4 uniforms), unit variance.
    fn normal(&mut self) -> f64 {
        (0..4).map(|_| self.next()).sum::<f64>() * 3f64.sqrt() - 2.0 * 3f64.sqrt()
    }
}

/// A 3 × 3 box blur, then Gaussian-like noise of `sigma` grey levels.
pub fn degrade(g: &mut Gray, sigma: f64, seed: u64) {
    let (w, h) = (g.width, g.height);
    let src = g.data.clone();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let mut s = 0u32;
            for dy in 0..3 {
                for dx in 0..3 {
                    s += src[(y + dy - 1) * w + x + dx - 1] as u32;
                }
            }
            g.data[y * w + x] = ((s + 4) / 9) as u8;
        }
    }
    let mut n = Noise(seed | 1);
    for v in &mut g.data {
        *v = (*v as f64 + sigma * n.normal()).round().clamp(0.0, 255.0) as u8;
    }
}

pub struct Shot {
    pub frames: Vec<Gray>,
    /// True pixel positions of every bird in every frame.
    pub truth: Vec<Vec<(f64, f64)>>,
    /// True wingspan, pixels, per frame (top view: the view's scale).
    pub span: Vec<f64>,
    /// True flight direction in the image, degrees clockwise from up.
    pub heading: f64,
}

pub fn shoot(a: &Animation, opts: &RenderOptions, noise: f64) -> Shot {
    let film = Film::with_options(a, a.fps, opts);
    let (w, h) = (film.width, film.height);
    let mut frames = Vec::new();
    let mut truth = Vec::new();
    let mut span = Vec::new();
    let mut mask = Mask::new();
    for k in 0..film.len() {
        let mut c = Canvas::new(w, h);
        film.draw(k, &mut c, &mut mask, false);
        let mut g = Gray::from_rgba(w, h, &c.straight_rgba());
        degrade(&mut g, noise, 17 + k as u64);
        frames.push(g);
        let view = &film.views[k];
        truth.push(
            film.states(k)
                .iter()
                .filter_map(|b| view.project([b.x, b.y, b.z], w, h))
                .map(|(x, y, _)| (x, y))
                .collect(),
        );
        span.push(view.scale());
    }
    let h0 = a.frames[0].heading[0].to_degrees();
    Shot {
        frames,
        truth,
        span,
        heading: h0,
    }
}

/// Writes a grey frame as a PNG.
pub fn save_png(g: &Gray, path: &std::path::Path) {
    image::GrayImage::from_raw(g.width as u32, g.height as u32, g.data.clone())
        .unwrap()
        .save(path)
        .unwrap();
}

/// A fixed top-down camera over the world rectangle of `px` pixels per wingspan, 480 × 270,
/// centred on the flock's middle frame.
pub fn fixed(a: &Animation, px: f64, sun: bool) -> RenderOptions {
    let mid = &a.frames[a.frames.len() / 2];
    let cx = mid.x.iter().sum::<f64>() / mid.x.len() as f64;
    let cy = mid.y.iter().sum::<f64>() / mid.y.len() as f64;
    let (w, h) = (480.0 / px, 270.0 / px);
    RenderOptions {
        width: 480,
        height: 270,
        camera: CameraKind::Fixed([cx - 0.5 * w, cy - 0.5 * h, cx + 0.5 * w, cy + 0.5 * h]),
        sun,
        ..RenderOptions::default()
    }
}
