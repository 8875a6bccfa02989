//! Charts (plotters) written as PNG or SVG. Each chart is a type implementing [`Chart`]; [`save`]
//! picks the backend from the output extension, draws with the bundled DejaVu Sans font (no system
//! fonts are needed) and writes the file atomically. PNGs are encoded with the `image` crate.

use std::path::Path;
use std::sync::Once;

pub mod field;
pub mod geometry;
pub mod paths;
pub mod power;
pub mod savings;
pub mod shape;
pub mod text;
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

/// The leader's colour in every chart (not in the birds' colour map).
pub const LEADER: RGBColor = RGBColor(200, 30, 30);

/// Colour of the bird at `rank` (0 = front) of `n` birds: the viridis map (perceptually
/// uniform, readable in grey and by colour-blind readers) from dark purple at the front to green
/// at the back, stopped before its pale yellow end so that every line reads on white.
pub fn bird_colour(rank: usize, n: usize) -> RGBColor {
    const V: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let s = 0.78 * rank as f64 / (n.max(2) - 1) as f64;
    let u = s.clamp(0.0, 1.0) * 4.0;
    let i = (u.floor() as usize).min(3);
    let f = u - i as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * f).round() as u8;
    RGBColor(
        mix(V[i].0, V[i + 1].0),
        mix(V[i].1, V[i + 1].1),
        mix(V[i].2, V[i + 1].2),
    )
}

/// Ranks (for the legend) worth a label among `n` birds: the front, the back and a few between.
pub fn legend_ranks(n: usize) -> Vec<usize> {
    if n <= 12 {
        return (0..n).collect();
    }
    let mut r: Vec<usize> = (0..5).map(|k| k * (n - 1) / 4).collect();
    r.dedup();
    r
}

/// Start and end of an animation's take-off, seconds (the end is the hand-over frame's time).
pub fn takeoff_span(anim: &crate::animation::Animation) -> Option<(f64, f64)> {
    let s = anim.stage("initiation")?;
    let a = anim.frames.get(s.start)?.t;
    let b = anim.frames.get(s.end).or(anim.frames.last())?.t;
    (s.end > s.start).then_some((a, b))
}

/// What an animation holds, for titles: `take-off and steady flight`, `steady flight only`.
pub fn stages_title(anim: &crate::animation::Animation) -> String {
    let names: Vec<&str> = anim
        .stages
        .iter()
        .filter(|s| s.end > s.start)
        .map(|s| match s.name.as_str() {
            "initiation" => "take-off",
            "steady" => "steady flight",
            other => other,
        })
        .collect();
    match names.as_slice() {
        [] => "no stages".into(),
        [one] => format!("{one} only"),
        many => many.join(" and "),
    }
}

/// Formation `k` (default 0) of a flock of several formations, as an animation of its own, and
/// the words a chart's title adds for it (`None` for an animation of one formation). Errors
/// name `plot.formation` and the file `origin` the animation was read from.
pub fn one_formation(
    anim: crate::animation::Animation,
    k: Option<usize>,
    origin: &Path,
) -> Result<(crate::animation::Animation, Option<String>)> {
    let count = anim.formation_count();
    let k = k.unwrap_or(0);
    if anim.formations.is_none() && k == 0 {
        return Ok((anim, None));
    }
    let one = anim.formation(k).ok_or_else(|| {
        Error::parameter(
            "plot.formation",
            format!(
                "{k}: {} has {count} formation(s) (0..{})",
                origin.display(),
                count - 1
            ),
        )
    })?;
    Ok((one, Some(format!(", formation {k} of {count}"))))
}

/// Error type of a drawing operation on backend `DB`.
pub type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A number as a reader expects it: at most `decimals` decimals, trailing zeros and a trailing
/// point dropped, and never "-0" (`-0.0001` with 3 decimals is "0", `20.0` is "20", `0.150` is
/// "0.15").
pub fn clean_number(v: f64, decimals: usize) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

/// A tick label of an f64 axis: [`clean_number`] with up to 6 decimals (the ticks are round
/// numbers; the decimals only absorb their float noise).
pub fn tick_label(v: &f64) -> String {
    clean_number(*v, 6)
}

/// A 2-D f64 chart's coordinate system.
pub type Cartesian64 =
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>;

/// Draws the grid and the axis descriptions every chart shares (light grey minor lines, tick
/// labels of `label_size` points, written by [`tick_label`]: `20`, not `20.0`; `0`, not `-0.0`).
pub fn draw_mesh<DB>(
    chart: &mut ChartContext<'_, DB, Cartesian64>,
    x_desc: &str,
    y_desc: &str,
    label_size: u32,
) -> DrawResult<DB>
where
    DB: DrawingBackend,
{
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .label_style((FONT_FAMILY, label_size))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
}

/// The polyline `points` cut to the band `lo ≤ v ≤ hi` of its second coordinate: the runs
/// inside the band, each ended where the line crosses an edge (interpolated), so that nothing
/// is drawn outside a chart's frame. Non-finite values break the line.
pub fn clip_to_band(points: &[(f64, f64)], lo: f64, hi: f64) -> Vec<Vec<(f64, f64)>> {
    let inside = |v: f64| v >= lo && v <= hi;
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut prev: Option<(f64, f64)> = None;
    let flush = |cur: &mut Vec<(f64, f64)>, runs: &mut Vec<Vec<(f64, f64)>>| {
        if cur.len() > 1 {
            runs.push(std::mem::take(cur));
        } else {
            cur.clear();
        }
    };
    for &(t, v) in points {
        if !(t.is_finite() && v.is_finite()) {
            flush(&mut cur, &mut runs);
            prev = None;
            continue;
        }
        if let Some((t0, v0)) = prev {
            // The part of the segment (t0, v0)–(t, v) inside the band, as parameters [a, b].
            let at = |edge: f64| (edge - v0) / (v - v0);
            let (mut a, mut b) = (0.0f64, 1.0f64);
            if v != v0 {
                let (ea, eb) = (at(lo), at(hi));
                a = a.max(ea.min(eb));
                b = b.min(ea.max(eb));
            } else if !inside(v) {
                a = 1.0;
                b = 0.0;
            }
            // Clamped: with a huge value at one end the interpolation loses every digit.
            let p = |u: f64| (t0 + (t - t0) * u, (v0 + (v - v0) * u).clamp(lo, hi));
            if a <= b {
                if a > 0.0 || cur.is_empty() {
                    flush(&mut cur, &mut runs);
                    cur.push(p(a));
                }
                cur.push(p(b));
                if b < 1.0 {
                    flush(&mut cur, &mut runs);
                }
            } else {
                flush(&mut cur, &mut runs);
            }
        } else if inside(v) {
            cur.push((t, v));
        }
        prev = Some((t, v));
    }
    flush(&mut cur, &mut runs);
    runs
}

/// How a [`side_legend`] entry is drawn.
#[derive(Debug, Clone, Copy)]
pub enum Key {
    /// A line of this width.
    Line(u32),
    /// A filled box (a shaded span).
    Box,
    /// A filled circle.
    Dot,
    /// A filled diamond (the leader's marker).
    Diamond,
    /// No mark: a note.
    Note,
}

/// A legend drawn beside a chart rather than over its data: one entry a line, in `area`
/// (pixels), from its top left.
pub fn side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor, Key)],
    label_size: u32,
) -> DrawResult<DB> {
    let line_h = (label_size as i32 * 3) / 2 + 2;
    for (k, (label, colour, key)) in entries.iter().enumerate() {
        let y = 8 + line_h * k as i32 + line_h / 2;
        let x = 6;
        match key {
            Key::Line(w) => area.draw(&PathElement::new(
                vec![(x, y), (x + 20, y)],
                colour.stroke_width(*w),
            ))?,
            Key::Box => area.draw(&Rectangle::new(
                [(x, y - 6), (x + 20, y + 6)],
                colour.mix(0.4).filled(),
            ))?,
            Key::Dot => area.draw(&Circle::new((x + 10, y), 5, colour.filled()))?,
            Key::Diamond => area.draw(&Polygon::new(
                vec![(x + 10, y - 8), (x + 16, y), (x + 10, y + 8), (x + 4, y)],
                colour.filled(),
            ))?,
            Key::Note => {}
        }
        let tx = if matches!(key, Key::Note) { x } else { x + 28 };
        area.draw(&Text::new(
            label.clone(),
            (tx, y - label_size as i32 / 2 - 1),
            (FONT_FAMILY, label_size)
                .into_font()
                .color(&RGBColor(30, 30, 30)),
        ))?;
    }
    Ok(())
}

/// Draws the legend box every chart shares (white, black border, labels of `label_size`
/// points) at `position`.
pub fn draw_legend<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    label_size: u32,
    position: SeriesLabelPosition,
) -> DrawResult<DB>
where
    DB: DrawingBackend + 'a,
    X: Ranged,
    Y: Ranged,
{
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT_FAMILY, label_size))
        .position(position)
        .draw()
}

/// A chart that can draw itself on any plotters backend.
pub trait Chart {
    /// Default size in pixels (width, height).
    fn size(&self) -> (u32, u32) {
        (960, 600)
    }
    /// Draws the chart onto `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// The resolution a chart's own size is meant for, dots per inch (a screen's).
pub const SCREEN_DPI: f64 = 96.0;

/// The resolutions a PNG chart may be drawn at, dots per inch (600 dpi is 6000 × 3750 pixels for
/// the usual 960 × 600 chart).
pub const DPI_RANGE: std::ops::RangeInclusive<f64> = 50.0..=600.0;

/// Renders `chart` to `path` (`.png` or `.svg`, by extension), atomically.
pub fn save<C: Chart>(chart: &C, path: &Path) -> Result<()> {
    save_at(chart, path, None)
}

/// [`save`] with a PNG resolution: `Some(dpi)` draws the chart `dpi / 96` times larger on each
/// side (the same layout, sharper: for print, 300 dpi) and records the resolution in the PNG;
/// an SVG is resolution-free and unchanged.
pub fn save_at<C: Chart>(chart: &C, path: &Path, dpi: Option<f64>) -> Result<()> {
    let kind = OutputKind::from_path(path, &[OutputKind::Png, OutputKind::Svg])?;
    let bytes = render_at(chart, kind, dpi)?;
    write_bytes_atomic(path, &bytes)
}

/// Renders `chart` into the bytes of a PNG or SVG file.
pub fn render<C: Chart>(chart: &C, kind: OutputKind) -> Result<Vec<u8>> {
    render_at(chart, kind, None)
}

/// [`render`] at a PNG resolution (see [`save_at`]).
pub fn render_at<C: Chart>(chart: &C, kind: OutputKind, dpi: Option<f64>) -> Result<Vec<u8>> {
    if let Some(d) = dpi {
        if !DPI_RANGE.contains(&d) {
            return Err(Error::parameter(
                "plot.dpi",
                format!(
                    "{d}: must be between {} and {} dots per inch",
                    DPI_RANGE.start(),
                    DPI_RANGE.end()
                ),
            ));
        }
    }
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
            let scale = dpi.map_or(1.0, |d| d / SCREEN_DPI);
            let (w, h) = (
                (f64::from(w) * scale).round() as u32,
                (f64::from(h) * scale).round() as u32,
            );
            let mut buf = vec![0u8; (w as usize) * (h as usize) * 3];
            {
                let bitmap = BitMapBackend::with_buffer(&mut buf, (w, h));
                let root = text::GlyphText::with_scale(bitmap, FONT, scale)
                    .ok_or_else(|| Error::Internal("the bundled font does not load".into()))?
                    .into_drawing_area();
                root.fill(&WHITE).map_err(|e| draw_err(e.to_string()))?;
                chart.draw(&root).map_err(|e| draw_err(e.to_string()))?;
                root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            let png = encode_png_rgb(&buf, w, h)?;
            Ok(match dpi {
                Some(d) => with_resolution(png, d),
                None => png,
            })
        }
        _ => Err(Error::Internal("charts are PNG or SVG".into())),
    }
}

/// `png` with a `pHYs` chunk after its header saying `dpi` dots per inch (as pixels per metre),
/// so that layout and print software place it at its size.
pub fn with_resolution(png: Vec<u8>, dpi: f64) -> Vec<u8> {
    // Signature (8) + IHDR (4 length + 4 type + 13 data + 4 CRC) = 33 bytes.
    const AFTER_IHDR: usize = 33;
    if png.len() < AFTER_IHDR || &png[12..16] != b"IHDR" {
        return png;
    }
    let ppm = (dpi / 0.0254).round() as u32;
    let mut chunk = Vec::with_capacity(21);
    chunk.extend_from_slice(&9u32.to_be_bytes());
    chunk.extend_from_slice(b"pHYs");
    chunk.extend_from_slice(&ppm.to_be_bytes());
    chunk.extend_from_slice(&ppm.to_be_bytes());
    chunk.push(1); // unit: metre
    let crc = crc32(&chunk[4..]);
    chunk.extend_from_slice(&crc.to_be_bytes());
    let mut out = Vec::with_capacity(png.len() + chunk.len());
    out.extend_from_slice(&png[..AFTER_IHDR]);
    out.extend_from_slice(&chunk);
    out.extend_from_slice(&png[AFTER_IHDR..]);
    out
}

/// The CRC-32 of PNG chunks (ISO 3309, reflected, polynomial 0xEDB88320).
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
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

#[cfg(test)]
mod helper_tests {
    use super::*;

    #[test]
    fn numbers_are_clean() {
        assert_eq!(clean_number(-0.0001, 3), "0");
        assert_eq!(clean_number(-0.0, 1), "0");
        assert_eq!(clean_number(20.0, 1), "20");
        assert_eq!(clean_number(0.15000000000000002, 6), "0.15");
        assert_eq!(clean_number(-1.25, 2), "-1.25");
        assert_eq!(tick_label(&2.0), "2");
    }

    #[test]
    fn lines_are_cut_at_the_band_and_nothing_leaves_it() {
        let pts = [(0.0, 0.5), (1.0, 2.0), (2.0, 0.5), (3.0, -1.0), (4.0, 0.2)];
        let runs = clip_to_band(&pts, 0.0, 1.0);
        assert_eq!(runs.len(), 3, "{runs:?}");
        for r in &runs {
            for p in r {
                assert!((-1e-12..=1.0 + 1e-12).contains(&p.1), "{runs:?}");
            }
        }
        // The first run ends where the line crosses 1 (t = 1/3).
        let end = runs[0].last().unwrap();
        assert!((end.0 - 1.0 / 3.0).abs() < 1e-12 && (end.1 - 1.0).abs() < 1e-12);
        // A line inside the band is kept whole.
        assert_eq!(clip_to_band(&[(0.0, 0.1), (1.0, 0.2)], 0.0, 1.0).len(), 1);
        // A gap breaks it.
        assert_eq!(
            clip_to_band(
                &[
                    (0.0, 0.1),
                    (1.0, 0.2),
                    (2.0, f64::NAN),
                    (3.0, 0.1),
                    (4.0, 0.3)
                ],
                0.0,
                1.0
            )
            .len(),
            2
        );
    }
}
