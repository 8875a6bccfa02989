//! Finding birds in one grey frame: a smooth sky model, the pixels that stand out from it, and
//! their connected regions with sub-pixel centroids, touching birds split.
//!
//! **Sky model.** The frame is cut into square blocks (about 1/24 of the shorter side, 16 to 64
//! px); each block's median grey (a 256-bin histogram of every second pixel of every second
//! row) is the sky there, and the sky at a pixel is the bilinear interpolation of the block
//! values (extrapolated along the outermost slope in the border half blocks). A gradient (sun
//! glow, haze toward the horizon) and clouds larger than a block are followed. A bird must cover
//! a small part of a block so as not to move its median: when the birds found are wider than a
//! block, the sky is modelled again leaving out the pixels that stood out by a quarter of the
//! seed threshold, and the frame searched again ([`detect_frame`]).
//!
//! **Standing out.** The residual r = grey − sky; its noise σ is 1.4826 × the median absolute
//! residual over a sample of pixels. With polarity dark the signal is −r, bright r, auto the
//! side with the larger tail beyond 6 σ (decided once, on the first frame, by the caller). A
//! pixel is a seed when its signal is at least `HIGH_SIGMA` σ (and at least `MIN_CONTRAST`
//! grey levels); a region grows from seeds over 4-connected pixels at least half as strong
//! (hysteresis), so faint wingtips join their body and noise alone starts nothing.
//!
//! **Regions.** Each region's centroid is the signal-weighted mean of its pixels (sub-pixel);
//! its span is the extent along its principal axis (second moments), plus one pixel, of its
//! pixels at least 0.3 × as strong as its upper quartile (a blurred edge crosses half its
//! contrast where the true edge is; a bird's thin wingtips are fainter than its body, hence the
//! lower fraction, chosen on the renderer's three species). A region
//! whose peak signal is under 0.3 × the median peak of the frame's regions is dropped (the
//! diffuse edge of a cloud where the sky model lags, never a bird of the same flock). A region
//! much larger than the frame's median region (more than 1.7 × its area) holds several touching
//! birds: it is split by weighted k-means (k = its area over the median, rounded, 2 to 8),
//! started from points spread along its principal axis.

use super::Polarity;

/// Seeds stand out by at least this many noise σ.
pub const HIGH_SIGMA: f32 = 6.0;
/// Seeds stand out by at least this many grey levels (a noiseless render has σ ≈ 0).
pub const MIN_CONTRAST: f32 = 12.0;
/// Regions whose peak is under this fraction of the frame's median peak are sky, not birds.
pub const FAINT: f32 = 0.3;
/// Regions smaller than this many pixels are noise.
pub const MIN_AREA: usize = 4;
/// Regions smaller than this fraction of a bird's area (once known) are specks.
pub const SPECK: f64 = 0.15;

/// A grey frame (0–255 per pixel, row-major).
#[derive(Debug, Clone)]
pub struct Gray {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// `width × height` grey levels, row by row from the top.
    pub data: Vec<u8>,
}

impl Gray {
    /// The luma (Rec. 601) of straight RGBA pixels.
    pub fn from_rgba(width: usize, height: usize, rgba: &[u8]) -> Gray {
        let data = rgba
            .chunks_exact(4)
            .map(|p| {
                ((299 * p[0] as u32 + 587 * p[1] as u32 + 114 * p[2] as u32 + 500) / 1000) as u8
            })
            .collect();
        Gray {
            width,
            height,
            data,
        }
    }
}

/// One region standing out from the sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blob {
    /// Centroid, pixels (x right).
    pub x: f64,
    /// Centroid, pixels (y down).
    pub y: f64,
    /// Pixels in the region (after a split: pixels assigned to this bird).
    pub area: usize,
    /// Extent along the principal axis, pixels.
    pub span: f64,
    /// Direction of the principal axis, radians (an axis: θ and θ + π are the same).
    pub axis: f64,
    /// Peak signal over the noise σ.
    pub snr: f64,
    /// True when the region was cut out of a larger one (touching birds).
    pub split: bool,
}

/// The sky model and noise of one frame.
pub struct Sky {
    block: usize,
    cols: usize,
    rows: usize,
    values: Vec<f32>,
    /// Noise σ of the residual, grey levels.
    pub sigma: f32,
}

fn block_size(width: usize, height: usize) -> usize {
    (width.min(height) / 24).clamp(16, 64)
}

impl Sky {
    /// Models the sky of `g` with the default block size.
    pub fn model(g: &Gray) -> Sky {
        Sky::model_with(g, block_size(g.width, g.height), None)
    }

    /// Models the sky of `g` with blocks of `block` pixels, leaving out of each block's median
    /// the pixels where `skip` (a signal image) is at least `above`.
    pub fn model_with(g: &Gray, block: usize, skip: Option<(&[f32], f32)>) -> Sky {
        let cols = g.width.div_ceil(block);
        let rows = g.height.div_ceil(block);
        let mut raw = vec![0f32; cols * rows];
        let mut hist = [0u32; 256];
        for br in 0..rows {
            for bc in 0..cols {
                hist.fill(0);
                let (y0, y1) = (br * block, ((br + 1) * block).min(g.height));
                let (x0, x1) = (bc * block, ((bc + 1) * block).min(g.width));
                let mut n = 0u32;
                for y in (y0..y1).step_by(2) {
                    let row = &g.data[y * g.width..(y + 1) * g.width];
                    match skip {
                        None => {
                            for &v in row[x0..x1].iter().step_by(2) {
                                hist[v as usize] += 1;
                                n += 1;
                            }
                        }
                        Some((sig, above)) => {
                            let srow = &sig[y * g.width..(y + 1) * g.width];
                            for (&v, &q) in row[x0..x1].iter().zip(&srow[x0..x1]).step_by(2) {
                                if q < above {
                                    hist[v as usize] += 1;
                                    n += 1;
                                }
                            }
                        }
                    }
                }
                raw[br * cols + bc] = hist_median(&hist, n);
            }
        }
        let values = raw;
        let mut sky = Sky {
            block,
            cols,
            rows,
            values,
            sigma: 0.0,
        };
        // Noise: median absolute residual of a sparse sample (every 7th pixel of every 5th row).
        let mut res: Vec<f32> = Vec::new();
        let mut line = vec![0f32; g.width];
        for y in (0..g.height).step_by(5) {
            sky.row(y, &mut line);
            for x in (0..g.width).step_by(7) {
                res.push((g.data[y * g.width + x] as f32 - line[x]).abs());
            }
        }
        if !res.is_empty() {
            let m = res.len() / 2;
            res.select_nth_unstable_by(m, f32::total_cmp);
            sky.sigma = 1.4826 * res[m];
        }
        sky
    }

    /// The sky along row `y` into `out` (`width` values).
    pub fn row(&self, y: usize, out: &mut [f32]) {
        let b = self.block as f32;
        // Between block centres linear; beyond the outermost centres (the frame's border half
        // blocks) the outermost slope continues, so a gradient toward the edge is followed.
        let cell = |f: f32, n: usize| -> (usize, usize, f32) {
            if n < 2 {
                return (0, 0, 0.0);
            }
            let i = (f.floor().max(0.0) as usize).min(n - 2);
            (i, i + 1, f - i as f32)
        };
        let (r0, r1, ty) = cell((y as f32 + 0.5) / b - 0.5, self.rows);
        let (a, c) = (
            &self.values[r0 * self.cols..(r0 + 1) * self.cols],
            &self.values[r1 * self.cols..(r1 + 1) * self.cols],
        );
        // The sky along this row at each block centre, then linear between them.
        let mid: Vec<f32> = a.iter().zip(c).map(|(p, q)| p + (q - p) * ty).collect();
        for (x, o) in out.iter_mut().enumerate() {
            let (c0, c1, tx) = cell((x as f32 + 0.5) / b - 0.5, self.cols);
            *o = mid[c0] + (mid[c1] - mid[c0]) * tx;
        }
    }
}

fn hist_median(hist: &[u32; 256], n: u32) -> f32 {
    let half = n.div_ceil(2).max(1);
    let mut acc = 0u32;
    for (v, &h) in hist.iter().enumerate() {
        acc += h;
        if acc >= half {
            return v as f32;
        }
    }
    255.0
}

/// The signal (standing out in the chosen polarity) of every pixel of `g`, grey levels,
/// negative where the pixel goes the other way.
pub fn signal(g: &Gray, sky: &Sky, polarity: Polarity) -> Vec<f32> {
    let sign = match polarity {
        Polarity::Bright => 1.0,
        _ => -1.0,
    };
    let mut out = vec![0f32; g.width * g.height];
    let mut line = vec![0f32; g.width];
    for y in 0..g.height {
        sky.row(y, &mut line);
        let src = &g.data[y * g.width..(y + 1) * g.width];
        let dst = &mut out[y * g.width..(y + 1) * g.width];
        for ((d, &v), &s) in dst.iter_mut().zip(src).zip(&line) {
            *d = sign * (v as f32 - s);
        }
    }
    out
}

/// Which polarity stands out more in `g`: the side of the residual with more pixels beyond
/// 6 σ (dark on a tie: birds against the sky are usually darker).
pub fn auto_polarity(g: &Gray, sky: &Sky) -> Polarity {
    let t = (6.0 * sky.sigma).max(MIN_CONTRAST);
    let s = signal(g, sky, Polarity::Dark);
    let dark = s.iter().filter(|&&v| v >= t).count();
    let bright = s.iter().filter(|&&v| v <= -t).count();
    if bright > dark {
        Polarity::Bright
    } else {
        Polarity::Dark
    }
}

/// Finds the birds of `g` in the region `roi` (`[x, y, w, h]`, pixels, inside the frame).
pub fn detect(g: &Gray, polarity: Polarity, roi: [usize; 4]) -> Vec<Blob> {
    detect_frame(g, &Sky::model(g), polarity, roi)
}

/// [`detect`] with the frame's default sky model already made; models the sky again with
/// larger blocks when the birds are too large for the default ones.
pub fn detect_frame(g: &Gray, sky: &Sky, polarity: Polarity, roi: [usize; 4]) -> Vec<Blob> {
    detect_with(g, sky, polarity, roi, &Hints::default()).blobs
}

/// What is known of the birds from the frames before (the birds on tracks that lasted), to
/// guide the detection of the next frame; all `None` on the first frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Hints {
    /// A bird's wingspan, pixels (sets the local-contrast window).
    pub wingspan_px: Option<f64>,
    /// A bird's area, pixels (the unit regions are split by, and the smallest region kept).
    pub area: Option<f64>,
    /// A bird's peak contrast, grey levels (regions far fainter are sky).
    pub peak: Option<f64>,
}

/// The regions of one frame: the birds, and the regions turned down (for debug pictures).
#[derive(Debug, Clone, Default)]
pub struct Found {
    /// The birds.
    pub blobs: Vec<Blob>,
    /// Regions that stood out but were too faint or too small beside the birds.
    pub rejected: Vec<Blob>,
    /// Noise σ of the frame, grey levels.
    pub sigma: f32,
    /// The background the birds were measured against, per pixel (see [`background`]).
    pub background: Vec<f32>,
}

/// The local-contrast window, pixels (odd): about 0.8 wingspans when the birds' size is known,
/// else the sky's block.
pub fn window(sky: &Sky, hints: &Hints) -> usize {
    let k = match hints.wingspan_px {
        Some(w) if w.is_finite() && w > 0.0 => (0.8 * w).round() as usize,
        _ => sky.block,
    };
    k.clamp(5, 129) | 1
}

/// The background of `g` against which birds stand out: the block sky, and, where the sky
/// changes faster than its blocks follow (a cloud's edge), the morphological closing (for dark
/// birds; the opening for bright) over a square of `k` pixels, which keeps any shading wider
/// than `k` and fills in whatever is narrower: the birds. Per pixel, grey levels.
pub fn background(g: &Gray, sky: &Sky, polarity: Polarity, k: usize) -> Vec<f32> {
    let dark = polarity != Polarity::Bright;
    let r = k / 2;
    // Dark birds: max then min (closing); bright: min then max (opening).
    let first = morph(&g.data, g.width, g.height, r, dark);
    let env = morph(&first, g.width, g.height, r, !dark);
    let mut out = vec![0f32; g.width * g.height];
    let mut line = vec![0f32; g.width];
    for y in 0..g.height {
        sky.row(y, &mut line);
        let e = &env[y * g.width..(y + 1) * g.width];
        let o = &mut out[y * g.width..(y + 1) * g.width];
        for ((o, &s), &e) in o.iter_mut().zip(&line).zip(e) {
            *o = if dark {
                s.min(e as f32)
            } else {
                s.max(e as f32)
            };
        }
    }
    out
}

/// The max (`max` true) or min filter of a `w × h` picture over a square of `2r + 1` pixels,
/// separable, each pass in constant time per pixel (van Herk / Gil–Werman).
fn morph(src: &[u8], w: usize, h: usize, r: usize, max: bool) -> Vec<u8> {
    let mut tmp = vec![0u8; w * h];
    let mut buf = Vec::new();
    let mut out_line = Vec::new();
    for y in 0..h {
        filter_1d(&src[y * w..(y + 1) * w], &mut out_line, r, max, &mut buf);
        tmp[y * w..(y + 1) * w].copy_from_slice(&out_line);
    }
    let mut out = vec![0u8; w * h];
    let mut col = vec![0u8; h];
    for x in 0..w {
        for (y, c) in col.iter_mut().enumerate() {
            *c = tmp[y * w + x];
        }
        filter_1d(&col, &mut out_line, r, max, &mut buf);
        for (y, &v) in out_line.iter().enumerate() {
            out[y * w + x] = v;
        }
    }
    out
}

fn filter_1d(src: &[u8], out: &mut Vec<u8>, r: usize, max: bool, buf: &mut Vec<u8>) {
    let n = src.len();
    let win = 2 * r + 1;
    let neutral = if max { 0u8 } else { 255u8 };
    let op = |a: u8, b: u8| if max { a.max(b) } else { a.min(b) };
    let m = n + 2 * r;
    // buf holds the padded line, then the prefix (g) and suffix (h) runs within blocks.
    buf.clear();
    buf.resize(3 * m, neutral);
    buf[r..r + n].copy_from_slice(src);
    let (p, rest) = buf.split_at_mut(m);
    let (g, hs) = rest.split_at_mut(m);
    for i in 0..m {
        g[i] = if i % win == 0 {
            p[i]
        } else {
            op(g[i - 1], p[i])
        };
    }
    for i in (0..m).rev() {
        hs[i] = if i % win == win - 1 || i == m - 1 {
            p[i]
        } else {
            op(hs[i + 1], p[i])
        };
    }
    out.clear();
    out.extend((0..n).map(|j| op(hs[j], g[j + win - 1])));
}

/// The signal of every pixel of `g` against a per-pixel background (see [`signal`]).
pub fn signal_against(g: &Gray, bg: &[f32], polarity: Polarity) -> Vec<f32> {
    let sign = match polarity {
        Polarity::Bright => 1.0,
        _ => -1.0,
    };
    g.data
        .iter()
        .zip(bg)
        .map(|(&v, &b)| sign * (v as f32 - b))
        .collect()
}

/// Finds the birds of `g` in `roi` against the local background ([`background`]), guided by
/// `hints`; models the sky again leaving the birds out when they are wider than its blocks.
pub fn detect_with(
    g: &Gray,
    sky: &Sky,
    polarity: Polarity,
    roi: [usize; 4],
    hints: &Hints,
) -> Found {
    let k = window(sky, hints);
    let bg = background(g, sky, polarity, k);
    let s = signal_against(g, &bg, polarity);
    let mut found = blobs_with(&s, g.width, sky.sigma, roi, hints);
    let span = weighted_median(found.blobs.iter().map(|b| (b.span, b.area as f64)));
    if span > sky.block as f64 {
        let above = 0.25 * (HIGH_SIGMA * sky.sigma).max(MIN_CONTRAST);
        let sky2 = Sky::model_with(g, sky.block, Some((&s, above)));
        let bg2 = background(g, &sky2, polarity, k);
        let s2 = signal_against(g, &bg2, polarity);
        let mut found = blobs_with(&s2, g.width, sky2.sigma, roi, hints);
        found.background = bg2;
        return found;
    }
    found.background = bg;
    found
}

/// The median of values weighted (by area: a region's pixels vote, so that many specks of
/// cloud texture or compression do not outvote a few birds); 0 when empty.
pub fn weighted_median(v: impl Iterator<Item = (f64, f64)>) -> f64 {
    let mut v: Vec<(f64, f64)> = v.filter(|p| p.0.is_finite() && p.1 > 0.0).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = v.iter().map(|p| p.1).sum();
    let mut acc = 0.0;
    for p in &v {
        acc += p.1;
        if acc >= 0.5 * total {
            return p.0;
        }
    }
    v[v.len() - 1].0
}

/// The regions of a signal image (see the module's description).
pub fn blobs(s: &[f32], width: usize, sigma: f32, roi: [usize; 4]) -> Vec<Blob> {
    blobs_with(s, width, sigma, roi, &Hints::default()).blobs
}

/// [`blobs`] guided by what is known of the birds ([`Hints`]): the birds' peak contrast and
/// area come from the hints when given, else from this frame's regions weighted by area.
pub fn blobs_with(s: &[f32], width: usize, sigma: f32, roi: [usize; 4], hints: &Hints) -> Found {
    let hi = (HIGH_SIGMA * sigma).max(MIN_CONTRAST);
    let lo = 0.5 * hi;
    let [rx, ry, rw, rh] = roi;
    let mut seen = vec![false; rw * rh];
    let mut stack: Vec<(usize, usize)> = Vec::new();
    let mut pixels: Vec<(usize, usize, f32)> = Vec::new();
    let mut regions: Vec<Vec<(usize, usize, f32)>> = Vec::new();
    for y in 0..rh {
        let row = &s[(ry + y) * width + rx..(ry + y) * width + rx + rw];
        for (x, &v) in row.iter().enumerate() {
            if v < hi || seen[y * rw + x] {
                continue;
            }
            // A seed: grow its region over pixels above the low threshold.
            pixels.clear();
            seen[y * rw + x] = true;
            stack.push((x, y));
            while let Some((px, py)) = stack.pop() {
                let v = s[(ry + py) * width + rx + px];
                pixels.push((px + rx, py + ry, v));
                let mut visit = |qx: usize, qy: usize| {
                    let i = qy * rw + qx;
                    if !seen[i] && s[(ry + qy) * width + rx + qx] >= lo {
                        seen[i] = true;
                        stack.push((qx, qy));
                    }
                };
                if px > 0 {
                    visit(px - 1, py);
                }
                if px + 1 < rw {
                    visit(px + 1, py);
                }
                if py > 0 {
                    visit(px, py - 1);
                }
                if py + 1 < rh {
                    visit(px, py + 1);
                }
            }
            if pixels.len() >= MIN_AREA {
                regions.push(pixels.clone());
            }
        }
    }
    let noise = sigma.max(1.0) as f64;
    let peak_of = |r: &[(usize, usize, f32)]| r.iter().fold(0f32, |m, p| m.max(p.2)) as f64;
    // Regions far fainter than the birds are sky (a cloud's edge, compression's blocks), and
    // regions far smaller than a bird are specks.
    // Before the birds are known, regions vote by their signal energy (area × peak²): the birds
    // the camera was pointed at stand out most, and dozens of faint texture regions, each as
    // large as a bird (cloud detail, a codec's blocks, where compression has flattened the
    // noise the thresholds scale with), do not outvote fifteen dark geese.
    let typical = hints.peak.unwrap_or_else(|| {
        weighted_median(
            regions
                .iter()
                .map(|r| (peak_of(r), r.len() as f64 * peak_of(r).powi(2))),
        )
    });
    let unit = hints.area.unwrap_or_else(|| {
        weighted_median(regions.iter().map(|r| (r.len() as f64, r.len() as f64)))
    });
    let smallest = if hints.area.is_some() {
        (SPECK * unit).max(MIN_AREA as f64)
    } else {
        MIN_AREA as f64
    };
    let mut out = Vec::with_capacity(regions.len());
    let mut rejected = Vec::new();
    for r in &regions {
        if peak_of(r) < FAINT as f64 * typical || (r.len() as f64) < smallest {
            rejected.push(measure(r, noise, false));
            continue;
        }
        let k = if unit > 0.0 && r.len() as f64 > 1.7 * unit {
            ((r.len() as f64 / unit).round() as usize).clamp(2, 8)
        } else {
            1
        };
        if k == 1 {
            out.push(measure(r, noise, false));
        } else {
            for part in split(r, k) {
                if part.len() >= MIN_AREA {
                    out.push(measure(&part, noise, true));
                }
            }
        }
    }
    Found {
        blobs: out,
        rejected,
        sigma,
        background: Vec::new(),
    }
}

/// Weighted moments of a set of pixels: (weight, mean x, mean y, cxx, cxy, cyy).
fn moments(p: &[(usize, usize, f32)]) -> (f64, f64, f64, f64, f64, f64) {
    let (mut w, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for &(x, y, v) in p {
        let v = v as f64;
        w += v;
        sx += v * x as f64;
        sy += v * y as f64;
    }
    let (mx, my) = (sx / w, sy / w);
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    for &(x, y, v) in p {
        let (dx, dy, v) = (x as f64 - mx, y as f64 - my, v as f64);
        cxx += v * dx * dx;
        cxy += v * dx * dy;
        cyy += v * dy * dy;
    }
    (w, mx, my, cxx / w, cxy / w, cyy / w)
}

fn measure(p: &[(usize, usize, f32)], noise: f64, split: bool) -> Blob {
    let (_, mx, my, cxx, cxy, cyy) = moments(p);
    let axis = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
    let (ux, uy) = (axis.cos(), axis.sin());
    // The extent at 0.3 × the region's typical strength (its upper quartile); see the module.
    let mut vs: Vec<f32> = p.iter().map(|q| q.2).collect();
    let q3 = vs.len() * 3 / 4;
    vs.select_nth_unstable_by(q3, f32::total_cmp);
    let half = 0.3 * vs[q3];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut peak = 0f32;
    for &(x, y, v) in p {
        peak = peak.max(v);
        if v < half {
            continue;
        }
        let t = (x as f64 - mx) * ux + (y as f64 - my) * uy;
        lo = lo.min(t);
        hi = hi.max(t);
    }
    // Pixel centres: the region reaches half a pixel beyond the outermost ones.
    Blob {
        x: mx + 0.5,
        y: my + 0.5,
        area: p.len(),
        span: hi - lo + 1.0,
        axis,
        snr: peak as f64 / noise,
        split,
    }
}

/// Weighted k-means of a region's pixels into `k` parts.
fn split(p: &[(usize, usize, f32)], k: usize) -> Vec<Vec<(usize, usize, f32)>> {
    let (_, mx, my, cxx, cxy, cyy) = moments(p);
    let axis = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
    let (ux, uy) = (axis.cos(), axis.sin());
    let t: Vec<f64> = p
        .iter()
        .map(|&(x, y, _)| (x as f64 - mx) * ux + (y as f64 - my) * uy)
        .collect();
    let (lo, hi) = t
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let mut centres: Vec<(f64, f64)> = (0..k)
        .map(|i| {
            let s = lo + (hi - lo) * (i as f64 + 0.5) / k as f64;
            (mx + s * ux, my + s * uy)
        })
        .collect();
    let mut label = vec![0usize; p.len()];
    for _ in 0..20 {
        let mut changed = false;
        for (i, &(x, y, _)) in p.iter().enumerate() {
            let (x, y) = (x as f64, y as f64);
            let best = (0..k)
                .min_by(|&a, &b| {
                    let da = (x - centres[a].0).powi(2) + (y - centres[a].1).powi(2);
                    let db = (x - centres[b].0).powi(2) + (y - centres[b].1).powi(2);
                    da.total_cmp(&db)
                })
                .unwrap_or(0);
            if label[i] != best {
                label[i] = best;
                changed = true;
            }
        }
        let mut acc = vec![(0.0, 0.0, 0.0); k];
        for (i, &(x, y, v)) in p.iter().enumerate() {
            let a = &mut acc[label[i]];
            a.0 += v as f64;
            a.1 += v as f64 * x as f64;
            a.2 += v as f64 * y as f64;
        }
        for (c, a) in centres.iter_mut().zip(&acc) {
            if a.0 > 0.0 {
                *c = (a.1 / a.0, a.2 / a.0);
            }
        }
        if !changed {
            break;
        }
    }
    let mut parts = vec![Vec::new(); k];
    for (i, &q) in p.iter().enumerate() {
        parts[label[i]].push(q);
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame_with(dots: &[(f64, f64, f64)], w: usize, h: usize) -> Gray {
        let mut data = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                // A sky gradient from 150 to 210 grey levels, top to bottom.
                let mut v = 150.0 + 60.0 * y as f64 / h as f64;
                for &(cx, cy, r) in dots {
                    let d = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
                    if d < r {
                        v = 40.0;
                    }
                }
                data[y * w + x] = v as u8;
            }
        }
        Gray {
            width: w,
            height: h,
            data,
        }
    }

    #[test]
    fn dark_discs_on_a_gradient_are_found_at_their_centres() {
        let dots = [(40.3, 50.7, 4.0), (120.0, 90.2, 5.0), (200.5, 30.5, 3.0)];
        let g = frame_with(&dots, 256, 160);
        let b = detect(&g, Polarity::Dark, [0, 0, 256, 160]);
        assert_eq!(b.len(), 3, "{b:?}");
        for (cx, cy, r) in dots {
            let m = b
                .iter()
                .find(|q| (q.x - cx).abs() < 1.0 && (q.y - cy).abs() < 1.0)
                .unwrap_or_else(|| panic!("no blob at {cx},{cy}: {b:?}"));
            assert!((m.span - 2.0 * r).abs() <= 1.5, "{m:?}");
        }
        assert_eq!(auto_polarity(&g, &Sky::model(&g)), Polarity::Dark);
    }

    #[test]
    fn touching_discs_are_split() {
        let dots = [
            (60.0, 60.0, 4.0),
            (67.5, 60.0, 4.0),
            (150.0, 60.0, 4.0),
            (100.0, 120.0, 4.0),
        ];
        let g = frame_with(&dots, 256, 160);
        let b = detect(&g, Polarity::Dark, [0, 0, 256, 160]);
        assert_eq!(b.len(), 4, "{b:?}");
        assert_eq!(b.iter().filter(|q| q.split).count(), 2);
    }
}
