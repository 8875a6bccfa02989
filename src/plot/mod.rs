//! Charts (plotters) written as PNG or SVG. Each chart is a type implementing [`Chart`]; [`save`]
//! picks the backend from the output extension, draws with the bundled DejaVu Sans font (no system
//! fonts are needed) and writes the file atomically. PNGs are encoded with the `image` crate.

use std::path::Path;
use std::sync::Once;

pub mod paths;
pub mod power;
pub mod shape;
pub mod wingbeat;
pub mod xi;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::{Error, Result};
use crate::io::{write_bytes_atomic, OutputKind};

/// The bundled font, registered as "sans-serif" on first use.
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Font family name to use in charts.
pub const FONT_FAMILY: &str = "sans-serif";

fn register_font() {
    REGISTER.call_once(|| {
        // The bundled file is a valid TrueType font; failure here would be a build defect.
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT);
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Bold, FONT);
    });
}

/// Error type of a drawing operation on backend `DB`.
pub type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A chart that can draw itself on any plotters backend.
pub trait Chart {
    /// Default size in pixels (width, height).
    fn size(&self) -> (u32, u32) {
        (960, 600)
    }
    /// Draws the chart onto `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Renders `chart` to `path` (`.png` or `.svg`, by extension), atomically.
pub fn save<C: Chart>(chart: &C, path: &Path) -> Result<()> {
    let kind = OutputKind::from_path(path, &[OutputKind::Png, OutputKind::Svg])?;
    let bytes = render(chart, kind)?;
    write_bytes_atomic(path, &bytes)
}

/// Renders `chart` into the bytes of a PNG or SVG file.
pub fn render<C: Chart>(chart: &C, kind: OutputKind) -> Result<Vec<u8>> {
    register_font();
    let (w, h) = chart.size();
    let draw_err = |e: String| Error::Internal(format!("drawing chart: {e}"));
    match kind {
        OutputKind::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                chart.draw(&root).map_err(|e| draw_err(e.to_string()))?;
                root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            Ok(svg.into_bytes())
        }
        OutputKind::Png => {
            let mut buf = vec![0u8; (w as usize) * (h as usize) * 3];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                chart.draw(&root).map_err(|e| draw_err(e.to_string()))?;
                root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            encode_png_rgb(&buf, w, h)
        }
        _ => Err(Error::Internal("charts are PNG or SVG".into())),
    }
}

/// Encodes an RGB8 buffer as PNG bytes.
pub fn encode_png_rgb(buf: &[u8], w: u32, h: u32) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::Internal(format!("encoding PNG: {e}")))?;
    Ok(out)
}

use image::ImageEncoder as _;
