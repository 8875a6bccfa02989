//! The HTML of `formation report`: sections, tables and inline SVG charts (see [`super`]).

use std::fmt::Write as _;

use super::{footage_savings_with, Subject};
use crate::animation::clearance::{Clearance, Closest};
use crate::animation::stats::{AnimationStats, BirdStats};
use crate::animation::Animation;
use crate::error::Result;
use crate::extract::geometry::Stat;
use crate::extract::FormationParams;
use crate::io::OutputKind;
use crate::plot::{field, Chart};

/// A page being built: its sections and the number of charts in them.
#[derive(Debug, Default)]
pub struct Page {
    body: String,
    charts: usize,
}

/// `s` with `<`, `>`, `&` and `"` escaped.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    esc_into(&mut out, s);
    out
}

/// Appends `s` to `out` with `<`, `>`, `&` and `"` escaped (safe as text and inside a
/// double-quoted attribute).
fn esc_into(out: &mut String, s: &str) {
    out.reserve(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
}

/// `v` with 3 decimals, never "-0.000".
fn clean3(v: f64) -> String {
    num(v, 3)
}

fn pct(v: f64) -> String {
    format!("{} %", num(100.0 * v, 1))
}

fn stat(s: &Option<Stat>, unit: &str, prec: usize) -> String {
    match s {
        Some(s) => format!(
            "{}{unit} (median; {} to {} over {} frames)",
            num(s.median, prec),
            num(s.min, prec),
            num(s.max, prec),
            s.frames
        ),
        None => "–".into(),
    }
}

impl Page {
    fn h2(&mut self, id: &str, title: &str) {
        let _ = writeln!(self.body, "<h2 id=\"{id}\">{}</h2>", esc(title));
    }

    fn p(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p>{}</p>", esc(text));
    }

    fn table(&mut self, head: &[&str], rows: &[Vec<String>]) {
        self.body.push_str("<table><thead><tr>");
        for h in head {
            let _ = write!(self.body, "<th>{}</th>", esc(h));
        }
        self.body.push_str("</tr></thead><tbody>\n");
        for r in rows {
            self.body.push_str("<tr>");
            for c in r {
                let _ = write!(self.body, "<td>{}</td>", esc(c));
            }
            self.body.push_str("</tr>\n");
        }
        self.body.push_str("</tbody></table>\n");
    }

    /// Draws `chart` as inline SVG in a figure named `name`.
    fn chart<C: Chart>(&mut self, name: &str, caption: &str, chart: &C) -> Result<()> {
        let bytes = crate::plot::render(chart, OutputKind::Svg)?;
        let svg = String::from_utf8_lossy(&bytes);
        let svg = svg.trim_start_matches(|c| c != '<');
        let svg = match svg.find("<svg") {
            Some(i) => &svg[i..],
            None => svg,
        };
        let _ = writeln!(
            self.body,
            "<figure class=\"chart\" data-chart=\"{}\">{svg}<figcaption>{}</figcaption></figure>",
            esc(name),
            esc(caption)
        );
        self.charts += 1;
        Ok(())
    }
}

impl Page {
    /// An inline SVG drawn here (not by [`crate::plot`]) in a figure named `name`.
    fn raw_chart(&mut self, name: &str, caption: &str, svg: &str) {
        let _ = writeln!(
            self.body,
            "<figure class=\"chart\" data-chart=\"{}\">{svg}<figcaption>{}</figcaption></figure>",
            esc(name),
            esc(caption)
        );
        self.charts += 1;
    }
}

/// `v` with `prec` decimals; a value that rounds to zero is written without a sign (never
/// "-0.000").
fn num(v: f64, prec: usize) -> String {
    let s = format!("{v:.prec$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

/// `v` with `prec` decimals and a sign ("+0.00" for a value that rounds to zero).
fn signed(v: f64, prec: usize) -> String {
    let s = num(v, prec);
    if s.starts_with('-') {
        s
    } else {
        format!("+{s}")
    }
}

/// One error bar: a quantity's interval and point estimate.
struct Bar {
    label: String,
    point: Option<f64>,
    lo: f64,
    hi: f64,
    /// Decimals printed.
    prec: usize,
    unit: &'static str,
}

/// Error bars, one row per quantity, each on its own axis (its interval in the middle half).
fn intervals_svg(rows: &[Bar]) -> String {
    let (w, row_h, left, right) = (760.0, 44.0, 250.0, 730.0);
    let h = 16.0 + row_h * rows.len() as f64;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\"><rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>"
    );
    for (k, bar) in rows.iter().enumerate() {
        let Bar {
            label,
            point,
            lo,
            hi,
            prec,
            unit,
        } = bar;
        let y = 24.0 + row_h * k as f64;
        let span = (hi - lo).abs().max(1e-9);
        let (a, b) = (lo - 0.5 * span, hi + 0.5 * span);
        let px = |v: f64| left + (right - left) * (v - a) / (b - a);
        let _ = write!(
            out,
            "<text x=\"8\" y=\"{:.1}\">{}</text><line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>",
            y + 4.0,
            esc(label)
        );
        let (x0, x1) = (px(*lo), px(*hi));
        let _ = write!(
            out,
            "<line x1=\"{x0:.1}\" y1=\"{y:.1}\" x2=\"{x1:.1}\" y2=\"{y:.1}\" stroke=\"#1f5fa8\" stroke-width=\"2\"/><line x1=\"{x0:.1}\" y1=\"{:.1}\" x2=\"{x0:.1}\" y2=\"{:.1}\" stroke=\"#1f5fa8\" stroke-width=\"2\"/><line x1=\"{x1:.1}\" y1=\"{:.1}\" x2=\"{x1:.1}\" y2=\"{:.1}\" stroke=\"#1f5fa8\" stroke-width=\"2\"/>",
            y - 7.0,
            y + 7.0,
            y - 7.0,
            y + 7.0
        );
        let _ = write!(
            out,
            "<text x=\"{x0:.1}\" y=\"{:.1}\" text-anchor=\"middle\" fill=\"#555\">{}{unit}</text><text x=\"{x1:.1}\" y=\"{:.1}\" text-anchor=\"middle\" fill=\"#555\">{}{unit}</text>",
            y + 20.0,
            num(*lo, *prec),
            y + 20.0,
            num(*hi, *prec)
        );
        if let Some(p) = point {
            let _ = write!(
                out,
                "<circle cx=\"{:.1}\" cy=\"{y:.1}\" r=\"4\" fill=\"#c0392b\"/><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}{unit}</text>",
                px(*p),
                px(*p),
                y - 10.0,
                num(*p, *prec)
            );
        }
    }
    out.push_str("</svg>");
    out
}

/// The least and the largest flock saving of the band's entries.
fn band_range(entries: &[crate::report::BandEntry]) -> (f64, f64) {
    entries
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| {
            (lo.min(e.saving), hi.max(e.saving))
        })
}

/// The saving's sensitivity band: one dot per model, wake and core on a common axis (percent of
/// induced power), the band from the least to the largest as an error bar on top, and the
/// number the page reports (`main`) marked.
fn band_svg(entries: &[crate::report::BandEntry], main: Option<f64>) -> String {
    let (w, row_h, left, right) = (760.0, 20.0, 250.0, 730.0);
    let h = 70.0 + row_h * entries.len() as f64;
    let (lo, hi) = band_range(entries);
    let a = lo.min(0.0);
    let b = (hi.max(main.unwrap_or(hi)) * 1.1).max(a + 0.01);
    let px = |v: f64| left + (right - left) * (v - a) / (b - a);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\"><rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>"
    );
    // The band as an error bar.
    let y = 22.0;
    let _ = write!(
        out,
        "<text x=\"8\" y=\"{:.1}\" font-weight=\"bold\">band over models, wakes, cores</text><line x1=\"{:.1}\" y1=\"{y}\" x2=\"{:.1}\" y2=\"{y}\" stroke=\"#1f5fa8\" stroke-width=\"3\"/><line x1=\"{:.1}\" y1=\"{}\" x2=\"{:.1}\" y2=\"{}\" stroke=\"#1f5fa8\" stroke-width=\"2\"/><line x1=\"{:.1}\" y1=\"{}\" x2=\"{:.1}\" y2=\"{}\" stroke=\"#1f5fa8\" stroke-width=\"2\"/>",
        y + 4.0,
        px(lo),
        px(hi),
        px(lo),
        y - 8.0,
        px(lo),
        y + 8.0,
        px(hi),
        y - 8.0,
        px(hi),
        y + 8.0
    );
    if let Some(m) = main {
        let _ = write!(
            out,
            "<circle cx=\"{:.1}\" cy=\"{y}\" r=\"5\" fill=\"#c0392b\"/>",
            px(m)
        );
    }
    for (k, e) in entries.iter().enumerate() {
        let y = 48.0 + row_h * k as f64;
        let _ = write!(
            out,
            "<text x=\"8\" y=\"{:.1}\">{}</text><line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"#eee\"/><circle cx=\"{:.1}\" cy=\"{y:.1}\" r=\"3.5\" fill=\"#1f5fa8\"/><text x=\"{:.1}\" y=\"{:.1}\" fill=\"#555\">{}</text>",
            y + 4.0,
            esc(&e.label()),
            px(e.saving),
            px(e.saving) + 8.0,
            y + 4.0,
            pct(e.saving)
        );
    }
    // The axis.
    let ya = h - 12.0;
    let _ = write!(
        out,
        "<line x1=\"{left}\" y1=\"{:.1}\" x2=\"{right}\" y2=\"{:.1}\" stroke=\"#888\"/><text x=\"{left}\" y=\"{ya:.1}\" text-anchor=\"middle\" fill=\"#555\">{}</text><text x=\"{right}\" y=\"{ya:.1}\" text-anchor=\"middle\" fill=\"#555\">{}</text><text x=\"{:.1}\" y=\"{ya:.1}\" text-anchor=\"middle\" fill=\"#555\">flock saving, % of induced power (model estimates)</text>",
        ya - 14.0,
        ya - 14.0,
        pct(a),
        pct(b),
        0.5 * (left + right)
    );
    out.push_str("</svg>");
    out
}

/// The band's table and chart.
fn band_section(
    page: &mut Page,
    name: &str,
    entries: &[crate::report::BandEntry],
    main: Option<f64>,
    share: Option<f64>,
    what: &str,
) {
    if entries.is_empty() {
        return;
    }
    let (lo, hi) = band_range(entries);
    let total = share.map_or(String::new(), |k| {
        format!(" ({} to {} of total power)", pct(lo * k), pct(hi * k))
    });
    page.p(&format!(
        "Sensitivity of the flock saving to modelling choices no measurement fixes ({what}): {} to {} of induced power{total} over Hummel's model at vortex cores of 0.02 to 0.32 wingspans{}{}; {} (an unsteady vortex-lattice computation of flapping wings; docs/model.md).",
        pct(lo),
        pct(hi),
        if entries.iter().any(|e| !e.aero.model.is_hummel()) {
            " and the lifting-line model (Lissaman & Shollenberger's kind, no core)".to_string()
        } else {
            format!(
                " (the lifting-line model is left out for flocks of more than {} birds: too slow)",
                crate::report::BAND_LIFTING_LINE_BIRDS
            )
        },
        if entries.iter().any(|e| !e.aero.wake.is_planar()) {
            ", each with the planar and the 3-D wake"
        } else {
            " (the birds have no heights: the 3-D wake equals the planar one)"
        },
        crate::aero::flapping::flapping_note()
    ));
    let svg = band_svg(entries, main);
    page.raw_chart(
        name,
        "The flock saving with each model, wake and core (dots), the band they span (bar on top) and the number reported above (red); all model estimates.",
        &svg,
    );
}

/// Error bars of the extracted parameters from the params' 95 % bootstrap intervals, with the
/// point estimates (the medians the intervals are of).
fn intervals_figure(page: &mut Page, p: &FormationParams, ci: &crate::extract::params::Intervals) {
    let geo = p.summary.as_ref().map(|s| s.geometry);
    let mut lat = Vec::new();
    let mut behind = Vec::new();
    for f in &p.frames {
        for (x, y) in crate::extract::bootstrap::nearest_ahead(f) {
            lat.push(x);
            behind.push(y);
        }
    }
    let med = |v: &mut Vec<f64>| crate::extract::bootstrap::median(v);
    let mut rows: Vec<Bar> = Vec::new();
    let mut push = |label: &str, point: Option<f64>, iv: Option<[f64; 2]>, prec, unit| {
        if let Some([lo, hi]) = iv {
            rows.push(Bar {
                label: label.to_string(),
                point,
                lo,
                hi,
                prec,
                unit,
            });
        }
    };
    push(
        "apex angle",
        geo.and_then(|g| g.apex_deg).map(|s| s.median),
        ci.apex_deg,
        1,
        "°",
    );
    push(
        "nearest bird ahead: aside",
        med(&mut lat),
        ci.lateral,
        2,
        "",
    );
    push(
        "nearest bird ahead: behind",
        med(&mut behind),
        ci.behind,
        2,
        "",
    );
    push(
        "depth",
        geo.and_then(|g| g.depth).map(|s| s.median),
        ci.depth,
        2,
        "",
    );
    push(
        "wingtip spacing",
        geo.and_then(|g| g.wingtip_spacing).map(|s| s.median),
        ci.wts,
        2,
        "",
    );
    if rows.is_empty() {
        return;
    }
    let svg = intervals_svg(&rows);
    page.raw_chart(
        "intervals",
        "95 % bootstrap intervals (over frames and birds, seeded) of the extracted parameters as error bars, the median marked; lengths in wingspans.",
        &svg,
    );
}

/// Describes a savings model for the page.
fn model_text(a: &crate::aero::AeroOptions) -> String {
    a.record().to_string()
}

/// The whole page.
pub fn build(s: &Subject<'_>) -> Result<String> {
    let mut page = Page::default();
    let name = crate::plot::power::file_name(s.origin);
    if let Some(p) = s.params {
        params_sections(&mut page, p, s)?;
    }
    if let Some(a) = s.animation {
        animation_sections(&mut page, a, s)?;
    }
    field_section(&mut page, s.params, s.animation, s.aero.unwrap_or_default());
    page.h2("notes", "How these numbers are defined");
    let used = match (s.animation.and_then(|a| a.savings_model.as_ref()), s.params) {
        (Some(m), _) => m.to_string(),
        (None, Some(_)) => model_text(&s.aero.unwrap_or_default()),
        (None, None) => model_text(&crate::aero::AeroOptions::default()),
    };
    page.p(&format!("Lengths are in wingspans unless marked m. The formation frame puts each formation's leader at the origin: lateral is to the right of its flight direction, behind is along it. Angles are measured from the flight axis behind the leader (90° = line abreast); the apex angle is the sum of both arms' angles. Wingtip spacing is the lateral distance between lateral neighbours minus one wingspan (negative: wingtips overlap). Savings are fractions of a bird's solo induced power saved by the others' upwash ({used}; Klotsman & Tal §5 use Hummel's horseshoe-vortex model, the field studies lifting lines of Lissaman & Shollenberger's kind); \"of total power\" multiplies them by the share of induced power in the bird's power curve (Pennycuick's method). All savings on this page are model estimates. The field studies' savings are model estimates too (lifting-line models applied to the spacings they measured); the only measured effect, a 11–15 % lower heart rate of pelicans in formation, is not a power saving. Their ranges are a comparison, not a target. docs/formats.md in the tool's documentation defines every field."));
    let title = format!("formation report: {name}");
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{t}</title>
<style>
body {{ font-family: sans-serif; margin: 2em auto; max-width: 1240px; color: #222; line-height: 1.4; }}
h1 {{ font-size: 1.6em; }} h2 {{ border-bottom: 1px solid #ccc; padding-bottom: .2em; margin-top: 2em; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: .9em; }}
th, td {{ border: 1px solid #ccc; padding: .25em .6em; text-align: right; }}
th {{ background: #f2f2f2; }} td:first-child, th:first-child {{ text-align: left; }}
figure.chart {{ margin: 1em 0; }} figure.chart svg {{ max-width: 100%; height: auto; border: 1px solid #eee; }}
figcaption {{ color: #555; font-size: .9em; }}
.warning {{ background: #fff4e0; border-left: 4px solid #e08a00; padding: .4em .8em; }}
</style></head>
<body data-charts="{n}">
<h1>{t}</h1>
{body}<script>
document.body.dataset.chartsRendered = String(
  Array.from(document.querySelectorAll("figure.chart svg")).filter(function (s) {{
    var b = s.getBBox(); return b.width > 0 && b.height > 0; }}).length);
</script>
</body></html>
"#,
        t = esc(&title),
        n = page.charts,
        body = page.body
    );
    Ok(out)
}

fn params_sections(page: &mut Page, p: &FormationParams, s: &Subject<'_>) -> Result<()> {
    page.h2("parameters", "Extracted parameters (§4)");
    page.p(&format!(
        "{}: {} annotated frames, {} birds. Shapes fitted: {}.",
        p.source,
        p.frames.len(),
        p.birds,
        kinds(p)
    ));
    if let Some(sum) = &p.summary {
        for w in &sum.warnings {
            let _ = writeln!(
                page.body,
                "<p class=\"warning\">warning: {}</p>",
                esc(&w.message)
            );
        }
        let g = &sum.geometry;
        let mut rows = vec![
            vec!["apex angle".into(), stat(&g.apex_deg, "°", 1)],
            vec!["left arm angle".into(), stat(&g.arm_left_deg, "°", 1)],
            vec!["right arm angle".into(), stat(&g.arm_right_deg, "°", 1)],
            vec!["depth".into(), stat(&g.depth, " wingspans", 2)],
            vec![
                "mean wingtip spacing".into(),
                stat(&g.wingtip_spacing, " wingspans", 2),
            ],
        ];
        if g.wingtip_spacing_m.is_some() {
            rows.push(vec![
                "mean wingtip spacing".into(),
                stat(&g.wingtip_spacing_m, " m", 2),
            ]);
        }
        page.table(&["over the frames", "value"], &rows);
    }
    let rows: Vec<Vec<String>> = p
        .frames
        .iter()
        .map(|f| {
            let g = f.geometry;
            let o = |v: Option<f64>, prec: usize| v.map_or("–".into(), |v| num(v, prec));
            vec![
                f.index.to_string(),
                f.order.len().to_string(),
                f.shape.kind().to_uppercase(),
                f.leader.to_string(),
                clean3(f.mu_x),
                clean3(f.sigma_x),
                clean3(f.mu_y),
                clean3(f.sigma_y),
                if f.outliers.is_empty() {
                    "none".to_string()
                } else {
                    f.outliers
                        .iter()
                        .map(|b| b.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                },
                o(g.and_then(|g| g.apex_deg), 1),
                o(g.and_then(|g| g.arm_left_deg), 1),
                o(g.and_then(|g| g.arm_right_deg), 1),
                o(g.map(|g| g.depth), 2),
                o(g.map(|g| g.wingtip_spacing), 2),
            ]
        })
        .collect();
    page.table(
        &[
            "frame", "birds", "kind", "leader", "μx", "σx", "μy", "σy", "outliers", "apex °",
            "left °", "right °", "depth", "WTS",
        ],
        &rows,
    );
    if let Some(c) =
        crate::plot::geometry::GeometryChart::from_params(p, "Geometry over the annotated frames")
    {
        page.chart(
            "geometry",
            "Apex and arm angles per frame with field studies' V angles shaded; mean wingtip spacing per frame.",
            &c,
        )?;
    }
    let picks = pick_frames(p);
    for idx in picks {
        let c = crate::plot::shape::ShapeChart::from_params(p, Some(idx), s.threshold, s.origin)?;
        page.chart(
            &format!("fit-{idx}"),
            &format!("Frame {idx}: the birds in the formation frame and the fitted curve, leader and outliers marked."),
            &c,
        )?;
    }
    if let Some(ci) = &p.ci {
        intervals_figure(page, p, ci);
    }
    let aero = s.aero.unwrap_or_default();
    let st = footage_savings_with(p, &aero);
    page.h2(
        "footage-savings",
        &format!(
            "Savings in the footage ({} on the annotated birds)",
            aero.model.describe()
        ),
    );
    page.p(&format!(
        "Flock saving averaged over the annotated frames: {} of induced power ({}; a model estimate from the measured positions).",
        st.steady_saving.map_or("–".into(), pct),
        model_text(&aero)
    ));
    band_section(
        page,
        "saving-band",
        &crate::report::footage_band(p),
        st.steady_saving,
        None,
        "the annotated frames",
    );
    if !st.birds.is_empty() {
        let chart = crate::plot::savings::SavingsChart {
            title: format!(
                "{}: savings of the annotated birds",
                crate::plot::power::file_name(s.origin)
            ),
            stats: st.clone(),
            takeoff: None,
            time_label: "annotated frame".into(),
            range: crate::plot::savings::range_of(
                &crate::report::footage_band(p),
                st.steady_saving,
            ),
            model: model_text(&aero),
        };
        page.chart(
            "footage-savings",
            "Each annotated bird's mean saving against its mean rank (0 = front), and the flock's saving per frame; the range that field studies estimated with models from measured spacings shaded.",
            &chart,
        )?;
        bird_tables(page, &st.birds);
    }
    Ok(())
}

fn animation_sections(page: &mut Page, a: &Animation, s: &Subject<'_>) -> Result<()> {
    let st = AnimationStats::of(a);
    page.h2("animation", "Animation");
    let mut rows = vec![
        vec!["birds".into(), a.birds.to_string()],
        vec!["formations".into(), st.formations.to_string()],
        vec![
            "frames".into(),
            format!("{} at {} fps", a.frames.len(), a.fps),
        ],
        vec!["stages".into(), crate::plot::stages_title(a)],
        vec!["wingspan".into(), format!("{} m", a.wingspan_m)],
        vec!["seed".into(), a.seed.to_string()],
    ];
    if let Some(t) = st.steady_s {
        rows.push(vec!["steady flight".into(), format!("{t:.1} s")]);
    }
    let used = a
        .savings_model
        .as_ref()
        .map_or("Hummel's model".to_string(), |m| m.to_string());
    // The range over the modelling choices leads; the chosen model's values follow.
    let band = crate::report::animation_band(a);
    let total = crate::aero::flight::steady_saving_total(a);
    let share = match (st.steady_saving, total) {
        (Some(e), Some(t)) if e.abs() > 1e-12 => Some(t / e),
        _ => None,
    };
    if let (Some(e), false) = (st.steady_saving, band.is_empty()) {
        let (lo, hi) = band_range(&band);
        let (lo, hi) = (lo.min(e), hi.max(e));
        let mut v = format!("{} to {} of induced power", pct(lo), pct(hi));
        if let Some(k) = share {
            v.push_str(&format!(
                "; {} to {} of total power",
                pct(lo * k),
                pct(hi * k)
            ));
        }
        rows.push(vec![
            "flock saving in steady flight, range over models, wakes and cores (model estimates)"
                .into(),
            v,
        ]);
    }
    if let Some(e) = st.steady_saving {
        rows.push(vec![
            format!("flock saving in steady flight (of induced power, {used})"),
            pct(e),
        ]);
    }
    if let Some(m) = &a.savings_model {
        rows.push(vec!["savings model".into(), m.to_string()]);
    }
    {
        let c = crate::aero::flight::curve_of(a);
        let b = &c.bird;
        let speed = a
            .flight
            .and_then(|f| f.speed_ms)
            .map_or("each bird's own airspeed".to_string(), |v| {
                format!("{v} m/s")
            });
        rows.push(vec![
            "power curve (Pennycuick 2008)".into(),
            format!(
                "{:.2} kg, {:.2} m span, {:.3} m² wings; {speed}",
                b.mass_kg, b.span_m, b.wing_area_m2
            ),
        ]);
    }
    if let Some(t) = total {
        rows.push(vec![
            format!(
                "flock saving in steady flight (of total power, {used}, Pennycuick's power curve)"
            ),
            pct(t),
        ]);
    }
    let clearance = clearance_by_stage(a);
    rows.push(vec![
        "clearance (wing and body clashes; 0 is the expectation)".into(),
        clearance_summary(a, &clearance),
    ]);
    page.table(&["quantity", "value"], &rows);
    clearance_section(page, a, &clearance);
    if a.birds > crate::report::BAND_MAX_BIRDS {
        page.p(&format!(
            "The saving's sensitivity to the model, wake and vortex core is left out for flocks of more than {} birds: each choice sums over every pair of birds.",
            crate::report::BAND_MAX_BIRDS
        ));
    }
    band_section(
        page,
        "saving-band",
        &band,
        st.steady_saving,
        share,
        &format!(
            "steady flight, up to {} frames evenly spaced",
            crate::report::BAND_FRAMES
        ),
    );
    if !st.birds.is_empty() {
        let c = crate::plot::savings::SavingsChart::from_animation(a, s.origin)?;
        page.chart(
            "savings",
            "Each bird's mean saving in steady flight against its rank (the leader in red), and the flock's saving over time through the take-off; the range that field studies estimated with models from measured spacings shaded.",
            &c,
        )?;
        bird_tables(page, &st.birds);
    }
    if let Ok(c) = crate::plot::xi::XiChart::from_animation(a, s.origin) {
        page.chart(
            "xi",
            "ξ of every bird over time, coloured by rank (the leader in red), take-off shaded.",
            &c,
        )?;
    }
    if let Some(stage) = a.stage("initiation").filter(|s| s.end > s.start) {
        page.h2("takeoff", "Take-off (§6)");
        let (k0, k1) = (stage.start, stage.end - 1);
        let f0 = &a.frames[k0];
        let f1 = &a.frames[k1];
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let closest = clearance
            .iter()
            .find(|(name, _)| name == "initiation")
            .map(|(_, c)| c.closest);
        let save =
            |f: &crate::animation::Frame| f.e.as_deref().map_or("–".into(), |e| pct(mean(e)));
        let rows = vec![
            vec![
                "duration".into(),
                format!(
                    "{:.1} s ({} frames)",
                    st.takeoff_s.unwrap_or(0.0),
                    stage.end - stage.start
                ),
            ],
            vec!["flock saving at the start".into(), save(f0)],
            vec!["flock saving at the hand-over".into(), save(f1)],
            vec![
                "mean height at the start / hand-over".into(),
                format!(
                    "{} / {} wingspans",
                    num(mean(&f0.z), 2),
                    num(mean(&f1.z), 2)
                ),
            ],
            vec![
                "mean speed at the start / hand-over".into(),
                format!(
                    "{:.2} / {:.2} wingspans/s",
                    mean(&f0.speed),
                    mean(&f1.speed)
                ),
            ],
            vec![
                "closest approach of two birds".into(),
                match closest {
                    Some(Some(c)) => closest_text(a, &c),
                    _ => format!(
                        "{:.1} wingspans or more",
                        crate::animation::clearance::REACH
                    ),
                },
            ],
        ];
        page.table(&["quantity", "value"], &rows);
        let c = crate::plot::paths::PathsChart::from_animation(a)?;
        page.chart(
            "paths",
            "The take-off seen from above, in the world and moving with the flock; the leader in red.",
            &c,
        )?;
    }
    player_section(page, a, s)?;
    Ok(())
}

/// Most bird-frames the report's player embeds before it keeps only every n-th frame (about 20
/// bytes each: a player of about 5 MB at most, so the report stays near the animation file's
/// size in memory).
const REPORT_PLAYER_BIRD_FRAMES: usize = 250_000;

/// The flock in 3-D: the page `formation view` writes, in an `<iframe srcdoc>` (its script and
/// styles kept apart from the report's), frames thinned for long or large flocks.
fn player_section(page: &mut Page, a: &Animation, s: &Subject<'_>) -> Result<()> {
    if a.frames.is_empty() || a.birds == 0 {
        return Ok(());
    }
    let every = (a.birds * a.frames.len())
        .div_ceil(REPORT_PLAYER_BIRD_FRAMES)
        .clamp(1, crate::player::MAX_EVERY);
    let opts = crate::player::PlayerOptions {
        title: crate::plot::power::file_name(s.origin),
        start_frame: None,
        every,
    };
    let html = crate::player::page(a, &opts)?;
    page.h2("player", "The flock in 3-D");
    let thinned = if every > 1 {
        format!(" Every {every}th frame is kept here (the player interpolates between them); `formation view` writes a page with them all.")
    } else {
        String::new()
    };
    page.p(&format!(
        "The animation played in 3-D (WebGL): drag to turn the view, scroll to zoom, pick a camera, colour the birds by saving, rank or formation, scrub the timeline to a stage or an event, click a bird for its numbers.{thinned}"
    ));
    // Escaped straight into the page: no second copy of the player.
    page.body
        .push_str("<iframe class=\"player\" title=\"3-D player\" srcdoc=\"");
    esc_into(&mut page.body, &html);
    drop(html);
    page.body.push_str("\" style=\"width:100%;height:560px;border:1px solid #ccc\" sandbox=\"allow-scripts\"></iframe>\n");
    Ok(())
}

/// The clearance of each stage (the whole animation as one "frames" entry without stages).
fn clearance_by_stage(a: &Animation) -> Vec<(String, Clearance)> {
    if a.stages.is_empty() {
        vec![("frames".to_string(), Clearance::of(a))]
    } else {
        Clearance::by_stage(a)
    }
}

/// "0.78 wingspans (birds 0 and 1, frame 1169, 39.0 s)", the frame in the shot's numbering.
fn closest_text(a: &Animation, c: &Closest) -> String {
    format!(
        "{:.2} wingspans (birds {} and {}, frame {}, {:.1} s)",
        c.distance,
        c.birds.0,
        c.birds.1,
        a.start_frame + c.frame as u64,
        c.frame as f64 / a.fps
    )
}

/// One line: the clashes over all stages and the closest approach.
fn clearance_summary(a: &Animation, stages: &[(String, Clearance)]) -> String {
    let mut all = Clearance::default();
    for (_, c) in stages {
        all.add(c);
    }
    let closest = all.closest.map_or_else(
        || {
            format!(
                "no two birds came within {:.1} wingspans",
                crate::animation::clearance::REACH
            )
        },
        |c| format!("closest approach {}", closest_text(a, &c)),
    );
    if all.clashes() == 0 {
        format!(
            "no two birds clash in any of {} frames; {closest}",
            all.frames
        )
    } else {
        format!(
            "{} wing and {} body clashes in {} of {} frames; {closest}",
            all.wing, all.body, all.frames_with_clash, all.frames
        )
    }
}

/// The clearance per stage: the test, then a table of clashes and closest approaches.
fn clearance_section(page: &mut Page, a: &Animation, stages: &[(String, Clearance)]) {
    use crate::animation::clearance::{BODY, CHORD, FLYING, SPAN, THICKNESS};
    page.h2(
        "clearance",
        "Clearance: no wing over wing, no body into body",
    );
    page.p(&format!(
        "Two flying birds (ground speed at least {FLYING} wingspan per second) clash by wing when, in the first bird's heading frame, the other is less than {SPAN} wingspan aside, {CHORD} fore and aft and {THICKNESS} in height: their wings would overlap. Any two birds, at rest included, clash by body when their centres are closer than {BODY} wingspans. Each pair is counted once a frame. Real birds never clash: 0 is the expectation in every stage."
    ));
    let rows: Vec<Vec<String>> = stages
        .iter()
        .map(|(name, c)| {
            vec![
                name.clone(),
                c.frames.to_string(),
                c.wing.to_string(),
                c.body.to_string(),
                c.frames_with_clash.to_string(),
                c.closest.map_or_else(
                    || {
                        format!(
                            "{:.1} wingspans or more",
                            crate::animation::clearance::REACH
                        )
                    },
                    |c| closest_text(a, &c),
                ),
            ]
        })
        .collect();
    page.table(
        &[
            "stage",
            "frames",
            "wing clashes",
            "body clashes",
            "frames with a clash",
            "closest approach",
        ],
        &rows,
    );
}

/// Per bird and per position (rank rounded) tables.
fn bird_tables(page: &mut Page, birds: &[BirdStats]) {
    let mut sorted: Vec<&BirdStats> = birds.iter().collect();
    sorted.sort_by(|a, b| a.rank.total_cmp(&b.rank));
    let rows: Vec<Vec<String>> = sorted
        .iter()
        .map(|b| {
            vec![
                b.bird.to_string(),
                b.formation.to_string(),
                if b.leader { "yes".into() } else { "".into() },
                num(b.rank, 1),
                signed(b.lateral, 2),
                num(b.behind, 2),
                pct(b.saving),
            ]
        })
        .collect();
    page.table(
        &[
            "bird",
            "formation",
            "leader",
            "mean rank",
            "lateral",
            "behind",
            "saving",
        ],
        &rows,
    );
    // Position in the formation: the leader, or the k-th bird back along the left or right arm
    // (by mean distance behind the leader), pooled over formations.
    // Place k on an arm: 1 + the birds of the same formation and arm ahead of it, counted by
    // sorting each arm once (counting them for every bird was quadratic: 100 000 birds took
    // seconds).
    let mut arm: Vec<usize> = (0..birds.len()).filter(|&i| !birds[i].leader).collect();
    let side = |b: &BirdStats| (b.formation, b.lateral >= 0.0);
    arm.sort_by(|&i, &j| {
        let (a, b) = (&birds[i], &birds[j]);
        side(a).cmp(&side(b)).then(
            (a.behind, a.bird)
                .partial_cmp(&(b.behind, b.bird))
                .unwrap_or(std::cmp::Ordering::Equal),
        )
    });
    let mut place = vec![0usize; birds.len()];
    for (w, &i) in arm.iter().enumerate() {
        place[i] = match w.checked_sub(1).map(|v| arm[v]) {
            Some(prev) if side(&birds[prev]) == side(&birds[i]) => place[prev] + 1,
            _ => 1,
        };
    }
    let mut pos: Vec<(String, f64, usize)> = Vec::new();
    for (i, b) in birds.iter().enumerate() {
        let label = if b.leader {
            "leader".to_string()
        } else {
            let left = b.lateral < 0.0;
            format!("{} {}", if left { "left" } else { "right" }, place[i])
        };
        match pos.iter_mut().find(|p| p.0 == label) {
            Some(p) => {
                p.1 += b.saving;
                p.2 += 1;
            }
            None => pos.push((label, b.saving, 1)),
        }
    }
    let key = |l: &str| -> (usize, usize) {
        match l.split_once(' ') {
            Some((side, k)) => (k.parse().unwrap_or(0), usize::from(side == "right")),
            None => (0, 0),
        }
    };
    pos.sort_by_key(|p| key(&p.0));
    let rows: Vec<Vec<String>> = pos
        .iter()
        .map(|p| vec![p.0.clone(), p.2.to_string(), pct(p.1 / p.2 as f64)])
        .collect();
    page.table(
        &[
            "position (arm, place from the leader)",
            "birds",
            "mean saving",
        ],
        &rows,
    );
}

fn field_section(
    page: &mut Page,
    p: Option<&FormationParams>,
    a: Option<&Animation>,
    aero: crate::aero::AeroOptions,
) {
    let used = match a.and_then(|a| a.savings_model.as_ref()) {
        Some(m) => m.to_string(),
        None if a.is_some() => "Hummel's model".to_string(),
        None => model_text(&aero),
    };
    page.h2("field", "Compared with real formations");
    let mut rows: Vec<Vec<String>> = Vec::new();
    let geo = p.and_then(|p| p.summary.as_ref()).map(|s| s.geometry);
    let ours_apex = geo.and_then(|g| g.apex_deg).map_or("–".into(), |s| {
        format!(
            "{}° ({}–{})",
            num(s.median, 1),
            num(s.min, 1),
            num(s.max, 1)
        )
    });
    for f in field::APEX_ANGLE {
        rows.push(vec![
            "V apex angle".into(),
            format!("{}, {}", f.source, f.species),
            format!("{}–{}°", f.lo, f.hi),
            ours_apex.clone(),
        ]);
    }
    let ours_wts = geo
        .and_then(|g| g.wingtip_spacing_m)
        .map_or("– (give the wingspan in metres)".into(), |s| {
            format!("{:+.2} m ({:+.2} to {:+.2})", s.median, s.min, s.max)
        });
    for f in field::WINGTIP_SPACING_M {
        rows.push(vec![
            "wingtip spacing".into(),
            format!("{}, {}", f.source, f.species),
            format!("{:+.2} to {:+.2} m", f.lo, f.hi),
            ours_wts.clone(),
        ]);
    }
    let ours_saving = a
        .map(AnimationStats::of)
        .and_then(|s| s.steady_saving)
        .or_else(|| {
            p.map(|p| footage_savings_with(p, &aero))
                .and_then(|s| s.steady_saving)
        })
        .map_or("–".into(), |v| format!("{} ({})", pct(v), used));
    for f in field::FLOCK_SAVING {
        rows.push(vec![
            "flock's induced-power saving (a model applied to measured spacings)".into(),
            format!("{}, {}", f.source, f.species),
            pct(f.lo),
            ours_saving.clone(),
        ]);
    }
    rows.push(vec![
        "heart rate in formation (measured)".into(),
        "Weimerskirch et al. 2001, great white pelican, 8 birds".into(),
        "11–15 % lower than alone (1.7–3.4 % of power credited to the wake)".into(),
        "– (the tool models power, not heart rate)".into(),
    ]);
    let ours_size = a
        .map(|a| a.birds.to_string())
        .or_else(|| p.map(|p| p.birds.to_string()))
        .unwrap_or_default();
    rows.push(vec![
        "flock size".into(),
        "Gould & Heppner 1974, Canada goose; Badgerow 1988: most under 12".into(),
        "18 ± 12".into(),
        ours_size,
    ]);
    page.table(&["quantity", "study", "field", "here"], &rows);
}

fn kinds(p: &FormationParams) -> String {
    p.kind_counts()
        .iter()
        .map(|(k, c)| format!("{} in {c} of {}", k.to_uppercase(), p.frames.len()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The first, middle and last frame indices (fewer for short movies).
fn pick_frames(p: &FormationParams) -> Vec<i64> {
    let n = p.frames.len();
    let mut k = vec![0, n / 2, n.saturating_sub(1)];
    k.dedup();
    k.into_iter().map(|i| p.frames[i].index).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_that_round_to_zero_have_no_minus_sign() {
        assert_eq!(num(-0.0001, 3), "0.000");
        assert_eq!(num(-0.0, 1), "0.0");
        assert_eq!(num(-0.04, 1), "0.0");
        assert_eq!(num(-0.05001, 1), "-0.1");
        assert_eq!(num(-12.5, 0), "-12");
        assert_eq!(clean3(-1e-9), "0.000");
        assert_eq!(pct(-1e-6), "0.0 %");
        assert_eq!(signed(-0.001, 2), "+0.00");
        assert_eq!(signed(0.5, 2), "+0.50");
        assert_eq!(signed(-0.5, 2), "-0.50");
    }
}
