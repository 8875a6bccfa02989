//! Chart text on bitmaps, laid out glyph by glyph with each glyph's own bearing.
//!
//! plotters 0.3.7 places every glyph of a string at the pen position without the glyph's left
//! side bearing, so narrow glyphs ("." "i" "l" "1") sit too far left and words read as
//! "flock. json" or "d istance". [`GlyphText`] wraps a bitmap backend and draws text itself with
//! `ab_glyph` (the rasteriser plotters uses), at the same layout box plotters measures (the sum
//! of advances and kerning, so chart layout does not move), with the bearing kept. Everything
//! else is passed to the wrapped backend.
//!
//! With a scale (a chart drawn at more than its screen resolution, 300 dpi for print), the chart
//! is laid out at its usual size and everything is drawn `scale` times larger on the wrapped
//! backend: coordinates, line widths, circle radii and text (glyphs rasterised at the larger
//! size, so they stay sharp). At scale 1 the drawing is exactly the unscaled one.

use ab_glyph::{Font, FontRef, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// A bitmap backend whose text is drawn by [`draw_glyphs`], optionally at a scale.
pub struct GlyphText<DB> {
    inner: DB,
    font: FontRef<'static>,
    scale: f64,
}

impl<DB: DrawingBackend> GlyphText<DB> {
    /// Wraps `inner`; `font` is the one font every chart uses.
    pub fn new(inner: DB, font: &'static [u8]) -> Option<Self> {
        Self::with_scale(inner, font, 1.0)
    }

    /// Wraps `inner`, which is `scale` times the chart's size on each side.
    pub fn with_scale(inner: DB, font: &'static [u8], scale: f64) -> Option<Self> {
        FontRef::try_from_slice(font).ok().map(|font| GlyphText {
            inner,
            font,
            scale: if scale.is_finite() && scale > 0.0 {
                scale
            } else {
                1.0
            },
        })
    }

    fn at(&self, p: BackendCoord) -> BackendCoord {
        if self.scale == 1.0 {
            return p;
        }
        (
            (f64::from(p.0) * self.scale).round() as i32,
            (f64::from(p.1) * self.scale).round() as i32,
        )
    }

    fn len(&self, v: u32) -> u32 {
        if self.scale == 1.0 {
            return v;
        }
        (f64::from(v) * self.scale).round().max(1.0) as u32
    }
}

/// A style with its line width scaled.
struct Wider<'a, S> {
    style: &'a S,
    width: u32,
}

impl<S: BackendStyle> BackendStyle for Wider<'_, S> {
    fn color(&self) -> BackendColor {
        self.style.color()
    }
    fn stroke_width(&self) -> u32 {
        self.width
    }
}

/// Each covered pixel of `text` at `size` pixels, the pen starting at (0, 0): (x, y, coverage).
/// The vertical placement is plotters' (the glyph's top at size/2 + its bounds), the horizontal
/// the pen position plus the glyph's own left bearing, with kerning.
pub fn draw_glyphs(font: &FontRef<'_>, size: f64, text: &str, mut put: impl FnMut(i32, i32, f32)) {
    let scaled = font.as_scaled(size as f32);
    let mut pen = 0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            pen += scaled.kern(p, id);
        }
        prev = Some(id);
        let glyph = id.with_scale_and_position(size as f32, ab_glyph::point(pen, 0.0));
        if let Some(q) = scaled.outline_glyph(glyph) {
            let r = q.px_bounds();
            let (x0, y0) = (r.min.x as i32, (size as f32 / 2.0 + r.min.y) as i32);
            q.draw(|x, y, a| put(x0 + x as i32, y0 + y as i32, a));
        }
        pen += scaled.h_advance(id);
    }
}

impl<DB: DrawingBackend> DrawingBackend for GlyphText<DB> {
    type ErrorType = DB::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        let (w, h) = self.inner.get_size();
        if self.scale == 1.0 {
            return (w, h);
        }
        (
            (f64::from(w) / self.scale).round() as u32,
            (f64::from(h) / self.scale).round() as u32,
        )
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        if self.scale == 1.0 {
            return self.inner.draw_pixel(point, color);
        }
        // One chart pixel is a square of the scaled size.
        let a = self.at(point);
        let b = self.at((point.0 + 1, point.1 + 1));
        let fill = Wider {
            style: &color,
            width: 1,
        };
        self.inner.draw_rect(a, (b.0 - 1, b.1 - 1), &fill, true)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let wide = Wider {
            style,
            width: self.len(style.stroke_width()),
        };
        let (from, to) = (self.at(from), self.at(to));
        self.inner.draw_line(from, to, &wide)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let wide = Wider {
            style,
            width: self.len(style.stroke_width()),
        };
        let (a, b) = (self.at(upper_left), self.at(bottom_right));
        self.inner.draw_rect(a, b, &wide, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let wide = Wider {
            style,
            width: self.len(style.stroke_width()),
        };
        let path: Vec<BackendCoord> = path.into_iter().map(|p| self.at(p)).collect();
        self.inner.draw_path(path, &wide)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let wide = Wider {
            style,
            width: self.len(style.stroke_width()),
        };
        let (c, r) = (self.at(center), self.len(radius));
        self.inner.draw_circle(c, r, &wide, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let vert: Vec<BackendCoord> = vert.into_iter().map(|p| self.at(p)).collect();
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        if self.scale == 1.0 {
            return self.inner.blit_bitmap(pos, size, src);
        }
        // Each source pixel (RGB) as a square of the scaled size.
        for (k, px) in src.chunks_exact(3).enumerate() {
            let (x, y) = (
                (k as u32 % size.0) as i32,
                (k as u32 / size.0.max(1)) as i32,
            );
            let c = BackendColor {
                alpha: 1.0,
                rgb: (px[0], px[1], px[2]),
            };
            self.draw_pixel((pos.0 + x, pos.1 + y), c)?;
        }
        Ok(())
    }
    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        self.inner.estimate_text_size(text, style)
    }

    /// plotters' own placement (anchor, rotation, layout box), with [`draw_glyphs`] drawing.
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        // The layout box at the scaled size (plotters measures at the chart's own size).
        let k = |v: i32| {
            if self.scale == 1.0 {
                v
            } else {
                (f64::from(v) * self.scale).round() as i32
            }
        };
        let (min_x, min_y, max_x, max_y) = (k(min_x), k(min_y), k(max_x), k(max_y));
        let pos = self.at(pos);
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let trans = style.transform();
        let (w, h) = self.inner.get_size();
        let mut pixels = Vec::new();
        draw_glyphs(&self.font, style.size() * self.scale, text, |x, y, a| {
            pixels.push((x, y, a))
        });
        for (x, y, a) in pixels {
            let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
            let (x, y) = (pos.0 + x, pos.1 + y);
            if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                let c = BackendColor {
                    alpha: color.alpha * f64::from(a.clamp(0.0, 1.0)),
                    rgb: color.rgb,
                };
                self.inner.draw_pixel((x, y), c)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Columns of `text` with any ink, at 20 px.
    fn inked_columns(text: &str) -> Vec<bool> {
        let font = FontRef::try_from_slice(super::super::FONT).unwrap();
        let mut cols = vec![false; 400];
        draw_glyphs(&font, 20.0, text, |x, _, a| {
            if a > 0.3 && (0..400).contains(&x) {
                cols[x as usize] = true;
            }
        });
        cols
    }

    /// Widest run of blank columns between the first and the last inked column.
    fn widest_gap(cols: &[bool]) -> usize {
        let first = cols.iter().position(|&c| c).unwrap();
        let last = cols.iter().rposition(|&c| c).unwrap();
        let (mut best, mut run) = (0, 0);
        for &c in &cols[first..=last] {
            run = if c { 0 } else { run + 1 };
            best = best.max(run);
        }
        best
    }

    #[test]
    fn letters_of_a_word_keep_even_gaps() {
        // "flock.json" and "distance" have no space: no gap inside them may be as wide as the
        // one a real space leaves in "a b" (plotters' own layout leaves one after "." and "d").
        let space = widest_gap(&inked_columns("a b"));
        for word in ["flock.json", "distance", "14"] {
            let gap = widest_gap(&inked_columns(word));
            assert!(
                gap * 2 < space,
                "{word}: a gap of {gap} px inside the word, a space is {space} px"
            );
        }
    }
}
