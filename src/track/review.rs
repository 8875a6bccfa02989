//! The review page that `formation track` writes on request: one self-contained HTML file (the
//! frames embedded as JPEG data URLs, the annotations as JSON, the editor in plain JavaScript; no
//! server, no network) where the user corrects the tracked birds and saves the corrected native
//! JSON.
//!
//! On the page: the frame with every bird as a ring labelled with its id (green when the
//! confidence is at least 0.8, orange from 0.5, red below), the frame's heading as an arrow from
//! the flock's centre and its wingspan as a bar in the corner. Click the sky to add a bird (a new
//! id), drag a bird to move it, click a bird and press Delete (or the button) to remove it; give
//! a selected bird another id with "Renumber" (from this frame on, swapping with the bird that
//! had it); the heading and wingspan fields set the frame's values; ← and → (or , and .) step
//! through the frames; "Save" downloads the corrected annotations (edited birds get confidence
//! 1), which `formation extract` reads.

use std::collections::BTreeMap;

use super::detect::Gray;
use super::Tracked;
use crate::error::{Error, Result};

/// Widest embedded frame, pixels (larger frames are shrunk; the annotations keep full-size
/// pixels).
pub const MAX_WIDTH: usize = 960;
/// Most frames one page embeds.
pub const MAX_FRAMES: usize = 400;

/// A frame shrunk to at most [`MAX_WIDTH`] wide (box filter) and encoded as JPEG.
pub fn frame_jpeg(g: &Gray) -> Result<Vec<u8>> {
    let f = g.width.div_ceil(MAX_WIDTH).max(1);
    let (w, h) = ((g.width / f).max(1), (g.height / f).max(1));
    let mut small = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0u32;
            for dy in 0..f {
                let row = &g.data[(y * f + dy) * g.width..];
                for dx in 0..f {
                    s += row[x * f + dx] as u32;
                }
            }
            small[y * w + x] = (s / (f * f) as u32) as u8;
        }
    }
    let mut out = Vec::new();
    let enc = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 85);
    image::ImageEncoder::write_image(
        enc,
        &small,
        w as u32,
        h as u32,
        image::ExtendedColorType::L8,
    )
    .map_err(|e| Error::Internal(format!("review frame to JPEG: {e}")))?;
    Ok(out)
}

fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        s.push(T[(n >> 18) as usize & 63] as char);
        s.push(T[(n >> 12) as usize & 63] as char);
        s.push(if c.len() > 1 {
            T[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        s.push(if c.len() > 2 {
            T[n as usize & 63] as char
        } else {
            '='
        });
    }
    s
}

/// The review page of annotations made elsewhere (any input format) over their footage's frames
/// `images` (in order): each annotated frame shows the image its `image` field names, else the
/// image at its frame index. Positions become pixels from the top-left (y down) as the page
/// edits them; every bird starts with confidence 1. `save_as` is the file name "Save" suggests.
pub fn annotations_page(
    ann: &crate::annotations::Annotations,
    images: &[std::path::PathBuf],
    save_as: &str,
) -> Result<String> {
    if ann.frames.len() > MAX_FRAMES {
        return Err(Error::format(
            &ann.path,
            format!(
                "{} annotated frames; a review page holds at most {MAX_FRAMES}",
                ann.frames.len()
            ),
        ));
    }
    let mut jpegs = BTreeMap::new();
    let mut frames = Vec::with_capacity(ann.frames.len());
    let mut size: Option<(usize, usize)> = None;
    for f in &ann.frames {
        let by_name = f.image.as_deref().and_then(|name| {
            let file = std::path::Path::new(name).file_name()?;
            images.iter().find(|p| p.file_name() == Some(file))
        });
        let by_index = usize::try_from(f.index).ok().and_then(|i| images.get(i));
        let path = by_name.or(by_index).ok_or_else(|| {
            Error::format(
                &ann.path,
                format!(
                    "frame {}: no image for it ({} images given; frames are matched by their image name, else by frame index from 0)",
                    f.index,
                    images.len()
                ),
            )
        })?;
        let gray = super::source::read_image(path)?;
        let (w, h) = (gray.width, gray.height);
        size.get_or_insert((w, h));
        let index = usize::try_from(f.index).map_err(|_| {
            Error::format(
                &ann.path,
                format!("frame {}: a negative frame index", f.index),
            )
        })?;
        let birds = f
            .birds
            .iter()
            .map(|b| {
                let y = if ann.y_up { h as f64 - b.py } else { b.py };
                super::TrackedBird {
                    id: b.id,
                    x: b.px,
                    y,
                    confidence: 1.0,
                    blob: super::detect::Blob {
                        x: b.px,
                        y,
                        area: 0,
                        span: f.wingspan_px,
                        axis: 0.0,
                        snr: 0.0,
                        split: false,
                    },
                }
            })
            .collect();
        jpegs.insert(index, frame_jpeg(&gray)?);
        frames.push(super::TrackedFrame {
            index,
            image: path.file_name().map(|n| n.to_string_lossy().into_owned()),
            wingspan_px: f.wingspan_px,
            heading_deg: f.heading_deg,
            birds,
        });
    }
    let (width, height) = size.unwrap_or((0, 0));
    let tracked = Tracked {
        source: ann.source.clone(),
        width,
        height,
        fps: ann.fps,
        polarity: super::Polarity::Dark,
        frames,
        decoded: None,
        warnings: Vec::new(),
    };
    Ok(page(&tracked, &jpegs, save_as))
}

/// The page for `tracked`, with `jpegs` (frame index → JPEG of [`frame_jpeg`]); `save_as` is
/// the file name the page's "Save" suggests.
pub fn page(tracked: &Tracked, jpegs: &BTreeMap<usize, Vec<u8>>, save_as: &str) -> String {
    let images: BTreeMap<String, String> = jpegs
        .iter()
        .map(|(k, j)| {
            (
                k.to_string(),
                format!("data:image/jpeg;base64,{}", base64(j)),
            )
        })
        .collect();
    let data = serde_json::json!({
        "name": save_as,
        "images": images,
        "annotations": serde_json::from_str::<serde_json::Value>(&tracked.to_native())
            .unwrap_or(serde_json::Value::Null),
    });
    // Inside a <script> element nothing may close it or open a comment: no `<` at all.
    let data = crate::embed::script_json(&data);
    let title = crate::embed::html_text(&tracked.source);
    format!(
        r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>formation review: {title}</title>
<style>
body {{ font: 14px system-ui, sans-serif; margin: 0; background: #222; color: #eee; }}
#bar {{ display: flex; flex-wrap: wrap; gap: 0.5em; align-items: center; padding: 0.5em; background: #333; }}
#bar input {{ width: 5em; }}
#c {{ display: block; margin: 0.5em auto; max-width: calc(100vw - 1em); cursor: crosshair; background: #000; }}
#help {{ color: #bbb; padding: 0 1em; }}
</style></head>
<body>
<div id="bar">
<button id="prev" title="previous frame (←)">◀</button>
<span id="where"></span>
<button id="next" title="next frame (→)">▶</button>
<label>heading <input id="heading" type="number" step="1"> °</label>
<label>wingspan <input id="span" type="number" step="0.5" min="0.5"> px</label>
<span id="selected">no bird selected</span>
<label>id <input id="newid" type="number" min="0" step="1"></label>
<button id="renumber">Renumber</button>
<button id="delete">Delete</button>
<button id="save">Save</button>
</div>
<canvas id="c"></canvas>
<p id="help">Click the sky to add a bird; drag a bird to move it; click a bird and press Delete to
remove it; Renumber gives the selected bird the id in the field from this frame on (swapping with
the bird that had it). ← → step through the frames. Save downloads the corrected annotations for
<code>formation extract</code>. Rings: green confident, orange unsure, red doubtful.</p>
<script type="application/json" id="data">{data}</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const A = D.annotations;
const W = A.image_size[0], H = A.image_size[1];
const cv = document.getElementById("c"), g = cv.getContext("2d");
const ui = id => document.getElementById(id);
let k = 0, sel = null, drag = null;
const imgs = A.frames.map(f => {{
  const im = new Image();
  im.onload = () => {{ if (A.frames[k] === f) draw(); }};
  if (D.images[String(f.index)]) im.src = D.images[String(f.index)];
  return im;
}});
const scale = Math.min(960 / W, 640 / H);
cv.width = Math.round(W * scale); cv.height = Math.round(H * scale);
const frame = () => A.frames[k];
const r2 = v => Math.round(v * 100) / 100;
function toImage(e) {{
  const r = cv.getBoundingClientRect();
  return [(e.clientX - r.left) * W / r.width, (e.clientY - r.top) * H / r.height];
}}
function reach() {{ return Math.max(0.35 * frame().wingspan_px, 6 / scale); }}
function hit(p) {{
  let best = null, bd = reach();
  for (const b of frame().birds) {{
    const d = Math.hypot(b.x - p[0], b.y - p[1]);
    if (d <= bd) {{ best = b; bd = d; }}
  }}
  return best;
}}
function nextId() {{
  let m = -1;
  for (const f of A.frames) for (const b of f.birds) m = Math.max(m, b.id);
  return m + 1;
}}
function draw() {{
  const f = frame();
  g.setTransform(1, 0, 0, 1, 0, 0);
  g.clearRect(0, 0, cv.width, cv.height);
  if (imgs[k].complete && imgs[k].naturalWidth) g.drawImage(imgs[k], 0, 0, cv.width, cv.height);
  g.setTransform(scale, 0, 0, scale, 0, 0);
  const rad = Math.max(0.3 * f.wingspan_px, 4 / scale);
  g.lineWidth = 2 / scale;
  g.font = (12 / scale) + "px system-ui, sans-serif";
  for (const b of f.birds) {{
    g.strokeStyle = b === sel ? "#0af" : b.confidence >= 0.8 ? "#2c2" : b.confidence >= 0.5 ? "#f90" : "#e22";
    g.beginPath(); g.arc(b.x, b.y, rad, 0, 2 * Math.PI); g.stroke();
    g.fillStyle = g.strokeStyle;
    g.fillText(String(b.id), b.x + rad + 2 / scale, b.y - rad);
  }}
  if (f.birds.length) {{
    const cx = f.birds.reduce((s, b) => s + b.x, 0) / f.birds.length;
    const cy = f.birds.reduce((s, b) => s + b.y, 0) / f.birds.length;
    const a = f.heading * Math.PI / 180, L = 2 * f.wingspan_px;
    const ex = cx + L * Math.sin(a), ey = cy - L * Math.cos(a);
    g.strokeStyle = "#ff0"; g.beginPath(); g.moveTo(cx, cy); g.lineTo(ex, ey);
    const h = 0.4 * f.wingspan_px;
    g.lineTo(ex - h * Math.sin(a - 0.5), ey + h * Math.cos(a - 0.5));
    g.moveTo(ex, ey); g.lineTo(ex - h * Math.sin(a + 0.5), ey + h * Math.cos(a + 0.5)); g.stroke();
  }}
  g.strokeStyle = "#0ff"; g.lineWidth = 4 / scale;
  g.beginPath(); g.moveTo(10 / scale, H - 12 / scale); g.lineTo(10 / scale + f.wingspan_px, H - 12 / scale); g.stroke();
  ui("where").textContent = "frame " + f.index + " (" + (k + 1) + " of " + A.frames.length + "), " + f.birds.length + " birds";
  ui("heading").value = f.heading;
  ui("span").value = f.wingspan_px;
  ui("selected").textContent = sel ? "bird " + sel.id + " selected" : "no bird selected";
  if (sel) ui("newid").value = sel.id;
}}
function step(d) {{ k = Math.min(A.frames.length - 1, Math.max(0, k + d)); sel = null; draw(); }}
function remove() {{
  if (!sel) return;
  frame().birds = frame().birds.filter(b => b !== sel);
  sel = null; draw();
}}
function renumber() {{
  if (!sel) return;
  const to = Math.floor(Number(ui("newid").value)), from = sel.id;
  if (!(to >= 0) || to === from) return;
  for (const f of A.frames.slice(k)) for (const b of f.birds) {{
    if (b.id === from) b.id = to; else if (b.id === to) b.id = from;
  }}
  draw();
}}
cv.addEventListener("mousedown", e => {{
  const p = toImage(e), b = hit(p);
  if (b) {{ sel = b; drag = b; }}
  else {{
    sel = {{ id: nextId(), x: r2(p[0]), y: r2(p[1]), confidence: 1 }};
    frame().birds.push(sel);
  }}
  draw();
}});
cv.addEventListener("mousemove", e => {{
  if (!drag) return;
  const p = toImage(e);
  drag.x = r2(Math.min(W, Math.max(0, p[0]))); drag.y = r2(Math.min(H, Math.max(0, p[1])));
  drag.confidence = 1; draw();
}});
window.addEventListener("mouseup", () => {{ drag = null; }});
window.addEventListener("keydown", e => {{
  if (e.target.tagName === "INPUT") return;
  if (e.key === "ArrowRight" || e.key === ".") step(1);
  else if (e.key === "ArrowLeft" || e.key === ",") step(-1);
  else if (e.key === "Delete" || e.key === "Backspace") remove();
  else return;
  e.preventDefault();
}});
ui("prev").onclick = () => step(-1);
ui("next").onclick = () => step(1);
ui("delete").onclick = remove;
ui("renumber").onclick = renumber;
ui("heading").onchange = () => {{ const v = Number(ui("heading").value); if (isFinite(v)) {{ frame().heading = ((v % 360) + 360) % 360; draw(); }} }};
ui("span").onchange = () => {{ const v = Number(ui("span").value); if (v > 0) {{ frame().wingspan_px = v; draw(); }} }};
function corrected() {{
  let c = 0, s = 0;
  for (const f of A.frames) {{ c += Math.cos(f.heading * Math.PI / 180); s += Math.sin(f.heading * Math.PI / 180); }}
  A.heading = Math.round(((Math.atan2(s, c) * 180 / Math.PI) + 360) % 360 * 10) / 10;
  const spans = A.frames.map(f => f.wingspan_px).sort((a, b) => a - b), n = spans.length;
  A.wingspan_px = n % 2 ? spans[(n - 1) / 2] : (spans[n / 2 - 1] + spans[n / 2]) / 2;
  return JSON.stringify(A, null, 2) + "\n";
}}
ui("save").onclick = () => {{
  const url = URL.createObjectURL(new Blob([corrected()], {{ type: "application/json" }}));
  const a = document.createElement("a");
  a.href = url; a.download = D.name; document.body.appendChild(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}};
draw();
</script>
</body></html>
"##
    )
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_pads_like_the_standard() {
        assert_eq!(base64(b"Man"), "TWFu");
        assert_eq!(base64(b"Ma"), "TWE=");
        assert_eq!(base64(b"M"), "TQ==");
        assert_eq!(base64(b""), "");
    }
}
