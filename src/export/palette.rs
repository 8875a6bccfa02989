//! The GIF's global 256-colour palette and a fast nearest-colour lookup.
//!
//! The palette is learnt once per GIF with NeuQuant (the `color_quant` crate, the quantiser of
//! the `image` crate family) from pixels of a few frames spread over the whole film, so it fits
//! the sky, the clouds and the birds of this film rather than every possible picture. The
//! species' plumage colours are added exactly (a few hundred bird pixels would otherwise be
//! outvoted by half a million sky pixels), and the last entry is reserved for "unchanged since
//! the previous frame" ([`TRANSPARENT`]). The sky is mapped through a screen-fixed 8×8 ordered
//! dither ([`dither_offset`], [`DITHER_SPREAD`] levels peak to peak): the same colour at the
//! same pixel always gets the same entry, so frame differencing still works, while the palette's
//! steps become a fine pattern instead of contour bands.
//!
//! NeuQuant leaves rare colours far from every entry; the last 48 learnt entries go instead
//! where the sampled pixels are worst served (`cover`).
//!
//! Lookups go through a table indexed by the colour's top 6 bits per channel, filled lazily with
//! the nearest palette entry (perceptually weighted squared RGB distance
//! `3Δr² + 4Δg² + 2Δb²`), which makes mapping a 960×540 frame a few milliseconds and the result
//! independent of frame order and thread count.

/// Palette index reserved for "unchanged since the previous frame" (GIF transparency); the
/// colours are entries `0..TRANSPARENT`.
pub const TRANSPARENT: u8 = 255;

use std::collections::BTreeMap;

/// The 8×8 Bayer matrix (ordered-dither thresholds 0..64).
const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// Peak-to-peak spread of the ordered dither, colour levels: the offsets run from
/// `-DITHER_SPREAD / 2` to just under `+DITHER_SPREAD / 2`. Wide enough to break palette steps
/// of up to about 8 levels (the widest the learnt palette leaves in the clouds) into a fine
/// pattern instead of a contour.
pub const DITHER_SPREAD: i32 = 8;

/// The ordered-dither offset (colour levels, the same for every channel) at screen pixel
/// `(x, y)`: an 8×8 Bayer pattern fixed to the screen.
#[inline]
pub fn dither_offset(x: usize, y: usize) -> i32 {
    (BAYER8[y & 7][x & 7] as i32 * DITHER_SPREAD) / 64 - DITHER_SPREAD / 2
}

/// NeuQuant's sampling factor: 1 looks at every training pixel, 30 at one in 30.
const SAMPLE_FACTOR: i32 = 3;

/// A palette of 256 RGB colours, the last one reserved ([`TRANSPARENT`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Palette {
    /// The colours.
    pub colours: Vec<[u8; 3]>,
}

impl Palette {
    /// A palette for pictures whose colours are sampled in `rgba` (straight RGBA bytes, any
    /// number of pixels, alpha ignored), always holding the colours `exact`.
    pub fn learn(rgba: &[u8], exact: &[[u8; 3]]) -> Palette {
        let mut exact: Vec<[u8; 3]> = exact.to_vec();
        exact.dedup();
        exact.truncate(64);
        let learnt = (TRANSPARENT as usize).saturating_sub(exact.len()).max(2);
        let mut c: Vec<[u8; 3]> = Vec::with_capacity(256);
        let px = rgba.len() / 4;
        if px > 0 {
            // NeuQuant wants RGBA; force opaque so alpha does not take part.
            let mut train: Vec<u8> = rgba[..px * 4].to_vec();
            for p in train.chunks_exact_mut(4) {
                p[3] = 255;
            }
            let nq = color_quant::NeuQuant::new(
                SAMPLE_FACTOR,
                learnt.saturating_sub(COVER).max(2),
                &train,
            );
            for p in nq.color_map_rgba().chunks_exact(4) {
                c.push([p[0], p[1], p[2]]);
            }
        }
        c.truncate(learnt.saturating_sub(COVER).max(2));
        cover(&mut c, rgba, learnt);
        c.extend(exact);
        c.truncate(TRANSPARENT as usize);
        while c.len() < 256 {
            c.push([0, 0, 0]);
        }
        Palette { colours: c }
    }

    /// The palette as `r, g, b` bytes, the layout GIF wants.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.colours.iter().flatten().copied().collect()
    }
}

/// Palette entries kept back from NeuQuant and chosen by [`cover`] instead.
const COVER: usize = 48;

/// Adds colours to `c` (up to `len` entries) where the palette fits the sampled pixels `rgba`
/// worst. NeuQuant places its entries where most pixels are, so rare but wide-apart colours (the
/// pale haze low over the horizon late in a film, a bright cloud seen for a few seconds) can be
/// 10 to 30 levels from every entry, further than the ordered dither can bridge: those show as
/// flat patches of the wrong colour. Greedily, the colour (on a 4-level grid) with the largest
/// `pixels × distance⁴` to its nearest entry (distance to the fourth: a few pixels far off
/// outweigh many a level or two off) is added, until `len` entries.
fn cover(c: &mut Vec<[u8; 3]>, rgba: &[u8], len: usize) {
    let mut cells: BTreeMap<[u8; 3], u32> = BTreeMap::new();
    for p in rgba.chunks_exact(4) {
        *cells.entry([p[0] >> 2, p[1] >> 2, p[2] >> 2]).or_insert(0) += 1;
    }
    if cells.is_empty() {
        return;
    }
    let colour = |k: &[u8; 3]| k.map(|v| (v << 2) | 2);
    let dist = |a: [u8; 3], b: [u8; 3]| -> i64 {
        let (dr, dg, db) = (
            a[0] as i64 - b[0] as i64,
            a[1] as i64 - b[1] as i64,
            a[2] as i64 - b[2] as i64,
        );
        3 * dr * dr + 4 * dg * dg + 2 * db * db
    };
    let mut best: Vec<(i64, [u8; 3], u32)> = cells
        .iter()
        .map(|(k, &n)| {
            let q = colour(k);
            let d = c.iter().map(|&e| dist(q, e)).min().unwrap_or(i64::MAX / 4);
            (d, q, n)
        })
        .collect();
    while c.len() < len {
        let Some(pick) = best
            .iter()
            .enumerate()
            .max_by_key(|(i, (d, _, n))| (d * d * *n as i64, std::cmp::Reverse(*i)))
            .map(|(i, _)| i)
        else {
            break;
        };
        if best[pick].0 == 0 {
            break;
        }
        let q = best[pick].1;
        c.push(q);
        for b in best.iter_mut() {
            b.0 = b.0.min(dist(b.1, q));
        }
    }
}

/// Lazily filled nearest-colour table for one palette; keep one per thread.
#[derive(Debug, Clone)]
pub struct Lookup<'a> {
    palette: &'a Palette,
    /// Entry + 1, 0 = not computed yet; 2^18 cells.
    table: Vec<u16>,
}

impl<'a> Lookup<'a> {
    /// An empty table for `palette`.
    pub fn new(palette: &'a Palette) -> Lookup<'a> {
        Lookup {
            palette,
            table: vec![0; 1 << 18],
        }
    }

    /// The nearest palette entry to the centre of a 6-bit cell.
    fn nearest(&self, cell: usize) -> u8 {
        let r = (((cell >> 12) & 63) << 2 | 2) as i32;
        let g = (((cell >> 6) & 63) << 2 | 2) as i32;
        let b = ((cell & 63) << 2 | 2) as i32;
        let mut best = (i32::MAX, 0u8);
        for (i, p) in self.palette.colours[..TRANSPARENT as usize]
            .iter()
            .enumerate()
        {
            let (dr, dg, db) = (r - p[0] as i32, g - p[1] as i32, b - p[2] as i32);
            let d = 3 * dr * dr + 4 * dg * dg + 2 * db * db;
            if d < best.0 {
                best = (d, i as u8);
            }
        }
        best.1
    }

    /// Palette index for an RGB colour.
    #[inline]
    pub fn index(&mut self, rgb: [u8; 3]) -> u8 {
        let cell =
            ((rgb[0] as usize >> 2) << 12) | ((rgb[1] as usize >> 2) << 6) | (rgb[2] as usize >> 2);
        let t = self.table[cell];
        if t != 0 {
            return (t - 1) as u8;
        }
        let n = self.nearest(cell);
        self.table[cell] = n as u16 + 1;
        n
    }

    /// Palette index for an RGB colour at pixel `(x, y)` of the picture, with the ordered
    /// dither [`dither_offset`] added to every channel first. The offset depends only on the
    /// pixel's place on the screen, so an unchanged colour maps to the same index in every
    /// frame and the frame differencing still sees it unchanged.
    #[inline]
    pub fn index_dithered(&mut self, rgb: [u8; 3], x: usize, y: usize) -> u8 {
        let d = dither_offset(x, y);
        self.index(rgb.map(|c| (c as i32 + d).clamp(0, 255) as u8))
    }

    /// Maps a whole opaque RGBA image to palette indices.
    pub fn map_image(&mut self, rgba: &[u8], out: &mut Vec<u8>) {
        out.clear();
        out.reserve(rgba.len() / 4);
        for p in rgba.chunks_exact(4) {
            out.push(self.index([p[0], p[1], p[2]]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::scene::Style;

    #[test]
    fn learnt_palette_fits_the_sky_closely_and_keeps_exact_colours() {
        let st = Style::default();
        let mut px = Vec::new();
        for k in 0..5000 {
            let s = st.sky(k as f32 / 4999.0).map(|v| v.round() as u8);
            px.extend([s[0], s[1], s[2], 255]);
        }
        let bird = [34, 34, 42];
        let p = Palette::learn(&px, &[bird]);
        assert_eq!(p.colours.len(), 256);
        let mut l = Lookup::new(&p);
        for k in 0..=100 {
            let s = st.sky(k as f32 / 100.0).map(|v| v.round() as u8);
            let q = p.colours[l.index(s) as usize];
            for c in 0..3 {
                assert!((q[c] as i32 - s[c] as i32).abs() <= 4, "{s:?} → {q:?}");
            }
        }
        assert_eq!(p.colours[l.index(bird) as usize], bird);
    }
}
