//! Footage in, on a round trip: flocks drawn by formation's own renderer (sky, clouds, sun, the
//! three species, birds from 8 to 60 px across, noise and blur) are tracked, and the tracks are
//! compared with the animation that drew them: detection precision and recall, centroid error in
//! wingspans, id switches, the measured wingspan and heading, and `extract`'s shape on the tracked
//! points against the true ones.

mod support;

use formation::animation::Frame;
use formation::export::pictures::Film;
use formation::export::raster::{Canvas, Mask};
use formation::export::{CameraKind, RenderOptions};
use formation::track::detect::Gray;
use formation::track::{Polarity, TrackOptions, Tracked, Tracking};
use formation::Animation;

/// A V of `n` birds (arms 0.9 wingspans apart across, 0.6 behind) flying at `heading_deg`
/// (clockwise from north) at 5 wingspans a second for `frames` frames at 25 fps, each bird
/// jostling slowly (a few hundredths of a wingspan) so the shape is alive.
fn v_flock(
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
fn degrade(g: &mut Gray, sigma: f64, seed: u64) {
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

struct Shot {
    frames: Vec<Gray>,
    /// True pixel positions of every bird in every frame.
    truth: Vec<Vec<(f64, f64)>>,
    /// True wingspan, pixels, per frame (top view: the view's scale).
    span: Vec<f64>,
    /// True flight direction in the image, degrees clockwise from up.
    heading: f64,
}

fn shoot(a: &Animation, opts: &RenderOptions, noise: f64) -> Shot {
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
            film.states[k]
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

fn track(shot: &Shot, opts: &TrackOptions) -> Tracked {
    let mut t = Tracking::new(opts).unwrap();
    for (k, g) in shot.frames.iter().enumerate() {
        t.push(k, None, g, std::path::Path::new("shot")).unwrap();
    }
    t.finish("shot", Some(25.0)).unwrap()
}

#[derive(Debug, Default)]
struct Score {
    truths: usize,
    found: usize,
    detections: usize,
    sq_err_ws: f64,
    switches: usize,
    worst_span: f64,
    worst_heading: f64,
    along: f64,
    across: f64,
}

fn score(shot: &Shot, tr: &Tracked) -> Score {
    let mut s = Score::default();
    let mut last_id: Vec<Option<usize>> = vec![None; shot.truth[0].len()];
    for (k, f) in tr.frames.iter().enumerate() {
        let truth = &shot.truth[k];
        let ws = shot.span[k];
        s.truths += truth.len();
        s.detections += f.birds.len();
        let cost = |i: usize, j: usize| {
            let (b, t) = (&f.birds[j], truth[i]);
            (b.x - t.0).powi(2) + (b.y - t.1).powi(2)
        };
        if f.birds.len() >= truth.len() {
            let a = formation::annotations::hungarian(truth.len(), f.birds.len(), cost);
            for (i, &j) in a.iter().enumerate() {
                let d2 = cost(i, j);
                if d2.sqrt() <= 0.5 * ws {
                    let hh = shot.heading.to_radians();
                    let (ex, ey) = (f.birds[j].x - truth[i].0, f.birds[j].y - truth[i].1);
                    s.along += (ex * hh.sin() - ey * hh.cos()) / ws;
                    s.across += (ex * hh.cos() + ey * hh.sin()) / ws;
                    s.found += 1;
                    s.sq_err_ws += d2 / (ws * ws);
                    let id = f.birds[j].id;
                    if last_id[i].is_some_and(|l| l != id) {
                        s.switches += 1;
                    }
                    last_id[i] = Some(id);
                }
            }
        } else {
            let a =
                formation::annotations::hungarian(f.birds.len(), truth.len(), |j, i| cost(i, j));
            for (j, &i) in a.iter().enumerate() {
                let d2 = cost(i, j);
                if d2.sqrt() <= 0.5 * ws {
                    let hh = shot.heading.to_radians();
                    let (ex, ey) = (f.birds[j].x - truth[i].0, f.birds[j].y - truth[i].1);
                    s.along += (ex * hh.sin() - ey * hh.cos()) / ws;
                    s.across += (ex * hh.cos() + ey * hh.sin()) / ws;
                    s.found += 1;
                    s.sq_err_ws += d2 / (ws * ws);
                    let id = f.birds[j].id;
                    if last_id[i].is_some_and(|l| l != id) {
                        s.switches += 1;
                    }
                    last_id[i] = Some(id);
                }
            }
        }
        if (f.wingspan_px / ws - 1.0).abs() > s.worst_span.abs() {
            s.worst_span = f.wingspan_px / ws - 1.0;
        }
        let dh = ((f.heading_deg - shot.heading + 540.0) % 360.0 - 180.0).abs();
        s.worst_heading = s.worst_heading.max(dh);
    }
    s
}

fn check(name: &str, s: &Score) {
    let recall = s.found as f64 / s.truths as f64;
    let precision = s.found as f64 / s.detections as f64;
    let rms = (s.sq_err_ws / s.found as f64).sqrt();
    let switches = s.switches as f64 * 100.0 / s.truths as f64;
    eprintln!(
        "{name}: recall {recall:.4} precision {precision:.4} rms {rms:.4} ws, switches {switches:.2}/100, span {:.3}, heading {:.2} deg",
        s.worst_span, s.worst_heading
    );
    assert!(recall >= 0.98, "{name}: recall {recall}");
    assert!(precision >= 0.98, "{name}: precision {precision}");
    // The silhouette's centre of mass lies a little behind the point the renderer places the
    // bird at (0.02-0.05 wingspans, by species); a shift common to all birds moves no distance
    // between them, so the error about it is bounded tighter too.
    let (ma, mc) = (s.along / s.found as f64, s.across / s.found as f64);
    let spread = (rms * rms - ma * ma - mc * mc).max(0.0).sqrt();
    eprintln!(
        "{name}: common shift along {ma:.4} across {mc:.4}, RMS about it {spread:.4} wingspans"
    );
    assert!(
        spread <= 0.03,
        "{name}: centroid RMS about the common shift {spread} wingspans"
    );
    assert!(rms <= 0.05, "{name}: centroid RMS {rms} wingspans");
    assert!(
        switches <= 1.0,
        "{name}: {switches} id switches per 100 bird-frames"
    );
    assert!(
        s.worst_span.abs() <= 0.10,
        "{name}: wingspan off by {}",
        s.worst_span
    );
    assert!(
        s.worst_heading <= 5.0,
        "{name}: heading off by {} deg",
        s.worst_heading
    );
}

/// A fixed top-down camera over the world rectangle of `px` pixels per wingspan, 480 × 270,
/// centred on the flock's middle frame.
fn fixed(a: &Animation, px: f64, sun: bool) -> RenderOptions {
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

#[test]
fn flocks_of_every_species_and_size_are_tracked() {
    // (species, pixels per wingspan, heading, birds, noise σ)
    let cases = [
        ("goose", 12.0, 70.0, 9, 3.0),
        ("crane", 20.0, 30.0, 7, 4.0),
        ("pelican", 30.0, 300.0, 7, 3.0),
        ("goose", 45.0, 95.0, 5, 2.0),
    ];
    for (i, &(species, px, heading, n, noise)) in cases.iter().enumerate() {
        // Long enough to cross a good part of the picture, short enough to stay in it.
        let frames = 24;
        let a = v_flock(n, heading, frames, species, (0.0, 0.0));
        let opts = fixed(&a, px, i % 2 == 0);
        let shot = shoot(&a, &opts, noise);
        if std::env::var_os("FORMATION_TRACK_DUMP").is_some() {
            let g = &shot.frames[frames / 2];
            image::GrayImage::from_raw(g.width as u32, g.height as u32, g.data.clone())
                .unwrap()
                .save(format!("/tmp/track_{species}_{px}.png"))
                .unwrap();
        }
        for t in &shot.truth {
            assert_eq!(t.len(), n, "{species} {px}: every bird in the picture");
        }
        let tr = track(&shot, &TrackOptions::default());
        if std::env::var_os("FORMATION_TRACK_DUMP").is_some() {
            let f = &tr.frames[frames / 2];
            for b in &f.birds {
                eprintln!(
                    "  {:.1},{:.1} area {} span {:.1} snr {:.1}",
                    b.x, b.y, b.blob.area, b.blob.span, b.blob.snr
                );
            }
            eprintln!("  truth {:?}", shot.truth[frames / 2]);
        }
        assert_eq!(tr.polarity, Polarity::Dark);
        check(&format!("{species} {px} px"), &score(&shot, &tr));
    }
}
