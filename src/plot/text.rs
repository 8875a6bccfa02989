//! Chart text on bitmaps, laid out glyph by glyph with each glyph's own bearing.
//!
//! plotters 0.3.7 places every glyph of a string at the pen position without the glyph's left
//! side bearing, so narrow glyphs ("." "i" "l" "1") sit too far left and words read as
//! "flock. json" or "d istance". [`GlyphText`] wraps a bitmap backend and draws text itself with
//! `ab_glyph` (the rasteriser plotters uses), at the same layout box plotters measures (the sum
//! of advances and kerning, so chart layout does not move), with the bearing kept. Everything
//! else is passed to the wrapped backend.

use ab_glyph::{Font, FontRef, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// A bitmap backend whose text is drawn by [`draw_glyphs`].
pub struct GlyphText<DB> {
    inner: DB,
    font: FontRef<'static>,
}

impl<DB: DrawingBackend> GlyphText<DB> {
    /// Wraps `inner`; `font` is the one font every chart uses.
    pub fn new(inner: DB, font: &'static [u8]) -> Option<Self> {
        FontRef::try_from_slice(font)
            .ok()
            .map(|font| GlyphText { inner, font })
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
        self.inner.get_size()
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
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
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
        draw_glyphs(&self.font, style.size(), text, |x, y, a| {
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
