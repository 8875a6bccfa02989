//! The HTML of `formation report`: sections, tables and inline SVG charts (see [`super`]).

use std::fmt::Write as _;

use super::{footage_savings, Subject};
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
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

fn stat(s: &Option<Stat>, unit: &str, prec: usize) -> String {
    match s {
        Some(s) => format!(
            "{:.prec$}{unit} (median; {:.prec$} to {:.prec$} over {} frames)",
            s.median, s.min, s.max, s.frames
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
    field_section(&mut page, s.params, s.animation);
    page.h2("notes", "How these numbers are defined");
    page.p("Lengths are in wingspans unless marked m. The formation frame puts each formation's leader at the origin: lateral is to the right of its flight direction, behind is along it. Angles are measured from the flight axis behind the leader (90° = line abreast); the apex angle is the sum of both arms' angles. Wingtip spacing is the lateral distance between lateral neighbours minus one wingspan (negative: wingtips overlap). Savings are fractions of a bird's solo induced power saved by the others' upwash (Hummel's horseshoe-vortex model with a vortex core of 0.04 wingspans, as in Klotsman & Tal §5); \"of total power\" multiplies them by the share of induced power in the bird's power curve (Pennycuick's method). All savings on this page are model estimates. The field studies' savings are model estimates too (lifting-line models applied to the spacings they measured); the only measured effect, a 11–15 % lower heart rate of pelicans in formation, is not a power saving. Their ranges are a comparison, not a target. docs/formats.md in the tool's documentation defines every field.");
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
            let o = |v: Option<f64>, prec: usize| v.map_or("–".into(), |v| format!("{v:.prec$}"));
            vec![
                f.index.to_string(),
                f.order.len().to_string(),
                f.shape.kind().to_uppercase(),
                f.leader.to_string(),
                format!("{:.3}", f.mu_x),
                format!("{:.3}", f.sigma_x),
                format!("{:.3}", f.mu_y),
                format!("{:.3}", f.sigma_y),
                format!("{:?}", f.outliers),
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
    let st = footage_savings(p);
    page.h2(
        "footage-savings",
        "Savings in the footage (Hummel's model on the annotated birds)",
    );
    page.p(&format!(
        "Flock saving averaged over the annotated frames: {}.",
        st.steady_saving.map_or("–".into(), pct)
    ));
    if !st.birds.is_empty() {
        let chart = crate::plot::savings::SavingsChart {
            title: format!(
                "{}: savings of the annotated birds",
                crate::plot::power::file_name(s.origin)
            ),
            stats: st.clone(),
            takeoff: None,
            time_label: "annotated frame".into(),
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
    if let Some(e) = st.steady_saving {
        rows.push(vec![
            "flock saving in steady flight (of induced power, Hummel's model)".into(),
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
    if let Some(t) = crate::aero::flight::steady_saving_total(a) {
        rows.push(vec![
            "flock saving in steady flight (of total power, Pennycuick's power curve)".into(),
            pct(t),
        ]);
    }
    page.table(&["quantity", "value"], &rows);
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
        let mut closest = f64::INFINITY;
        for f in &a.frames[k0..=k1] {
            for i in 0..a.birds {
                for j in (i + 1)..a.birds {
                    let d = ((f.x[i] - f.x[j]).powi(2)
                        + (f.y[i] - f.y[j]).powi(2)
                        + (f.z[i] - f.z[j]).powi(2))
                    .sqrt();
                    closest = closest.min(d);
                }
            }
        }
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
                format!("{:.2} / {:.2} wingspans", mean(&f0.z), mean(&f1.z)),
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
                format!("{closest:.2} wingspans"),
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
    Ok(())
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
                format!("{:.1}", b.rank),
                format!("{:+.2}", b.lateral),
                format!("{:.2}", b.behind),
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

fn field_section(page: &mut Page, p: Option<&FormationParams>, a: Option<&Animation>) {
    page.h2("field", "Compared with real formations");
    let mut rows: Vec<Vec<String>> = Vec::new();
    let geo = p.and_then(|p| p.summary.as_ref()).map(|s| s.geometry);
    let ours_apex = geo.and_then(|g| g.apex_deg).map_or("–".into(), |s| {
        format!("{:.1}° ({:.1}–{:.1})", s.median, s.min, s.max)
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
        .or_else(|| p.map(footage_savings).and_then(|s| s.steady_saving))
        .map_or("–".into(), pct);
    for f in field::FLOCK_SAVING {
        rows.push(vec![
            "flock's induced-power saving (a model applied to measured spacings)".into(),
            format!("{}, {}", f.source, f.species),
            pct(f.lo),
            ours_saving.clone(),
        ]);
    }
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
