//! The GIF's fixed 256-colour palette and a fast nearest-colour lookup.
//!
//! The palette is built once per render from the [`Style`]: it knows which colours a picture can
//! contain (sky gradient, clouds blended over the sky, birds and their anti-aliased edges over sky
//! and cloud), so it spends its entries there instead of quantising every frame (no NeuQuant).
//! Cloud gradients are dithered by the renderer (see [`super::scene::Backdrop::paint`]).
//! Lookups go through a table indexed by the colour's top 6 bits per channel, filled lazily with
//! the nearest palette entry (perceptually weighted squared RGB distance), which makes mapping a
//! 960×540 frame a few milliseconds and the result independent of frame order and thread count.

use super::scene::Style;

/// Palette index reserved for "unchanged since the previous frame" (GIF transparency); the
/// colours are entries `0..TRANSPARENT`.
pub const TRANSPARENT: u8 = 255;

/// A palette of 256 RGB colours, the last one reserved ([`TRANSPARENT`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Palette {
    /// The colours.
    pub colours: Vec<[u8; 3]>,
}

fn mix(a: [f32; 3], b: [f32; 3], w: f32) -> [u8; 3] {
    [0, 1, 2].map(|k| (a[k] + (b[k] - a[k]) * w).round().clamp(0.0, 255.0) as u8)
}

fn f(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| v as f32)
}

impl Palette {
    /// The palette for pictures drawn in `style`.
    pub fn for_style(style: &Style) -> Palette {
        let mut c: Vec<[u8; 3]> = Vec::with_capacity(256);
        let sky = |v: f32| style.sky(v);
        // 68 steps of the sky gradient (the rest of the table): about 2 levels per channel.
        const SKY: usize = 68;
        for k in 0..SKY {
            let s = sky(k as f32 / (SKY - 1) as f32);
            c.push(mix(s, s, 0.0));
        }
        // Clouds over the sky: 12 heights × 9 opacities.
        let cloud = f(style.cloud);
        for k in 0..12 {
            let s = sky(k as f32 / 11.0);
            for a in 1..=9 {
                c.push(mix(s, cloud, style.cloud_opacity * a as f32 / 9.0));
            }
        }
        // Birds: both tones solid and their shading in between.
        let (bird, wing) = (f(style.bird), f(style.bird_wing));
        for k in 0..6 {
            c.push(mix(bird, wing, k as f32 / 5.0));
        }
        // Anti-aliased edges: bird over sky at 7 heights × 8 coverages.
        for k in 0..7 {
            let s = sky(k as f32 / 6.0);
            for a in 1..=8 {
                c.push(mix(s, bird, a as f32 / 9.0));
            }
        }
        // Edges over cloud and the lighter wing tone over sky.
        let cloudy = mix(sky(0.5), cloud, style.cloud_opacity * 0.8);
        for a in 1..=8 {
            c.push(mix(f(cloudy), bird, a as f32 / 9.0));
        }
        for k in 0..3 {
            let s = sky(k as f32 / 2.0);
            for a in [0.3f32, 0.55, 0.8] {
                c.push(mix(s, wing, a));
            }
        }
        debug_assert_eq!(c.len(), TRANSPARENT as usize);
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

    /// Maps a whole RGB image to palette indices.
    pub fn map_image(&mut self, rgb: &[u8], out: &mut Vec<u8>) {
        out.clear();
        out.reserve(rgb.len() / 3);
        for p in rgb.chunks_exact(3) {
            out.push(self.index([p[0], p[1], p[2]]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_has_256_entries_and_sky_maps_closely() {
        let st = Style::default();
        let p = Palette::for_style(&st);
        assert_eq!(p.colours.len(), 256);
        let mut l = Lookup::new(&p);
        for k in 0..=100 {
            let s = st.sky(k as f32 / 100.0).map(|v| v.round() as u8);
            let q = p.colours[l.index(s) as usize];
            for c in 0..3 {
                assert!((q[c] as i32 - s[c] as i32).abs() <= 5, "{s:?} → {q:?}");
            }
        }
        let b = p.colours[l.index(st.bird) as usize];
        assert_eq!(b, st.bird);
    }
}
