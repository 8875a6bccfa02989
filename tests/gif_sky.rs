//! The GIF's sky decoded back and compared with the full-colour pictures of the same film: no
//! pixel outside the birds strays from its true colour by more than a documented bound, nothing
//! stale stays behind once the sky stops changing, no column seam, and the sky gradient is not
//! posterised into wide flat bands.

use std::fs::File;

use formation::export::palette::{Lookup, Palette, DITHER_SPREAD};
use formation::export::pictures::write_gif;
use formation::export::raster::{Canvas, Mask};
use formation::export::{Film, RenderOptions};
use formation::progress::Silent;
use formation::Animation;

mod support;

use support::{run as formation, s, scratch as tmpdir};

const GEESE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples_data/barnacle_geese_v.json"
);

/// Largest error of a sky pixel, levels per channel: the GIF tolerance (10 by default), half the
/// dither's spread, and the learnt palette's own error (under 10 levels in the clouds).
const SKY_BOUND: i32 = 10 + DITHER_SPREAD / 2 + 10;

/// Widest run of one palette colour down a column, in levels of the true colour it covers: the
/// tolerance plus the settle margin of pixels held back while a cloud slid by, or the learnt
/// palette's spacing over a near-white cloud low over the horizon (measured 17 on this film
/// before the take-off began with a second of sitting, 22 since: a pale cloud at the bottom
/// right 11 s in; 24 with the scrolled sky, 26 once positions were stored to 10⁻⁵ wingspans:
/// the camera then scrolls the sky by a whole pixel on other frames, so the held tile sits half
/// a pixel off the exact paint over a cloud edge; the sky gradient alone is dithered into runs
/// of a few pixels).
const BAND_BOUND: i32 = 28;

#[test]
fn readme_gif_sky_matches_the_full_colour_pictures() {
    let d = tmpdir("gif-sky");
    let json = d.join("flock.json");
    let out = formation(&[
        "animate",
        GEESE,
        "--birds",
        "14",
        "--seconds",
        "4",
        "-o",
        s(&json),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let anim = Animation::read(&json).unwrap();
    let opts = RenderOptions::default();
    let film = Film::with_options(&anim, 25.0, &opts);
    let (w, h) = (film.width, film.height);
    let gif_path = d.join("flock.gif");
    write_gif(&film, &gif_path, 2, &Silent).unwrap();
    // The scrolled sky's tiles are shared by the workers: the file is the same whatever their
    // number.
    let gif3 = d.join("flock3.gif");
    write_gif(&film, &gif3, 3, &Silent).unwrap();
    assert!(
        std::fs::read(&gif_path).unwrap() == std::fs::read(&gif3).unwrap(),
        "the GIF depends on the thread count"
    );

    let mut dopts = gif::DecodeOptions::new();
    dopts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = dopts.read_info(File::open(&gif_path).unwrap()).unwrap();
    let pal: Vec<u8> = dec.global_palette().unwrap().to_vec();
    let palette = Palette {
        colours: pal.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    };
    let mut lookup = Lookup::new(&palette);
    let mut screen = vec![0u8; w * h];
    let (mut canvas, mut sky, mut mask) = (Canvas::new(w, h), Canvas::new(w, h), Mask::new());
    let mut k = 0;
    let (mut worst, mut worst_at) = (0, (0, 0, 0));
    let mut worst_jump = 0.0f64;
    let mut jump_at = (0, 0, 0);
    let mut worst_band = 0i32;
    let mut over = 0usize;
    let mut sky_px = 0usize;
    while let Some(f) = dec.read_next_frame().unwrap() {
        for fy in 0..f.height as usize {
            for fx in 0..f.width as usize {
                let v = f.buffer[fy * f.width as usize + fx];
                if Some(v) != f.transparent {
                    screen[(f.top as usize + fy) * w + f.left as usize + fx] = v;
                }
            }
        }
        // The exact picture (the PNG frame's), not the GIF's scrolled sky: what the GIF shows is
        // held to the true colours.
        film.draw(k, &mut canvas, &mut mask, false);
        film.backdrop().paint(&film.views[k], &mut sky);
        // Sky pixels: the bird-free picture there, two pixels from any bird.
        let mut bird = vec![false; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) * 4;
                if canvas.rgba[i..i + 3] != sky.rgba[i..i + 3] {
                    for yy in y.saturating_sub(2)..(y + 3).min(h) {
                        for xx in x.saturating_sub(2)..(x + 3).min(w) {
                            bird[yy * w + xx] = true;
                        }
                    }
                }
            }
        }
        let err = |x: usize, y: usize, c: usize| -> i32 {
            let p = screen[y * w + x] as usize;
            pal[p * 3 + c] as i32 - canvas.rgba[(y * w + x) * 4 + c] as i32
        };
        // What the frame differencing adds: the shown colour against the pixel's own dithered
        // palette colour (what a frame written whole shows). The palette's own error changes
        // across a cloud's edge whatever the differencing does (bounded by SKY_BOUND and
        // BAND_BOUND); a seam is a jump in what the differencing held back.
        let mut own = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) * 4;
                let rgb = [canvas.rgba[i], canvas.rgba[i + 1], canvas.rgba[i + 2]];
                own[y * w + x] = lookup.index_dithered(rgb, x, y);
            }
        }
        let held = |x: usize, y: usize, c: usize| -> i32 {
            let p = screen[y * w + x] as usize;
            pal[p * 3 + c] as i32 - pal[own[y * w + x] as usize * 3 + c] as i32
        };
        for y in 0..h {
            for x in 0..w {
                if bird[y * w + x] {
                    continue;
                }
                sky_px += 1;
                let e = (0..3).map(|c| err(x, y, c).abs()).max().unwrap();
                if e > worst {
                    (worst, worst_at) = (e, (k, x, y));
                }
                over += (e > 10 + DITHER_SPREAD / 2) as usize;
            }
        }
        // Column seam: the mean of what the differencing held back in each column over strips
        // of 64 rows (the dither's columns all have the same mean) must not jump between
        // neighbours.
        for y0 in (0..h.saturating_sub(63)).step_by(64) {
            for c in 0..3 {
                let mean = |x: usize| -> Option<f64> {
                    let ys: Vec<usize> = (y0..y0 + 64).filter(|&y| !bird[y * w + x]).collect();
                    (ys.len() == 64)
                        .then(|| ys.iter().map(|&y| held(x, y, c) as f64).sum::<f64>() / 64.0)
                };
                for x in 0..w - 1 {
                    if let (Some(a), Some(b)) = (mean(x), mean(x + 1)) {
                        if (a - b).abs() > worst_jump {
                            worst_jump = (a - b).abs();
                            jump_at = (k, x, y0);
                        }
                    }
                }
            }
        }
        // Bands: along each column, a run of one palette colour must not cover more than a
        // few levels of the true gradient.
        for x in (0..w).step_by(7) {
            let mut y = 0;
            while y < h {
                let v = screen[y * w + x];
                let (mut lo, mut hi) = ([255i32; 3], [0i32; 3]);
                let mut e = y;
                while e < h && screen[e * w + x] == v && !bird[e * w + x] {
                    for c in 0..3 {
                        let t = canvas.rgba[(e * w + x) * 4 + c] as i32;
                        lo[c] = lo[c].min(t);
                        hi[c] = hi[c].max(t);
                    }
                    e += 1;
                }
                if e > y {
                    worst_band = worst_band.max((0..3).map(|c| hi[c] - lo[c]).max().unwrap());
                }
                y = e.max(y + 1);
            }
        }
        k += 1;
    }
    assert_eq!(k, film.len());
    let size = std::fs::metadata(&gif_path).unwrap().len();
    eprintln!(
        "{k} frames, {size} bytes: worst sky error {worst} at {worst_at:?}, {:.4} % over {}, column jump {worst_jump:.2} at {jump_at:?}, widest band {worst_band} levels",
        100.0 * over as f64 / sky_px as f64,
        10 + DITHER_SPREAD / 2
    );
    assert!(worst <= SKY_BOUND, "sky error {worst} at {worst_at:?}");
    // Held-back pixels settle to within the settle margin (half the dither plus two levels) of
    // their own colour; a stale half beside a fresh one would jump by up to the tolerance (10).
    assert!(
        worst_jump <= (DITHER_SPREAD / 2 + 2) as f64,
        "column seam: {worst_jump:.2}"
    );
    assert!(worst_band <= BAND_BOUND, "band over {worst_band} levels");
}
