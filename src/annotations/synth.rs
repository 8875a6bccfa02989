//! Synthetic annotated flocks with known truth, for tests, benchmarks and `examples_data/`.
//!
//! [`generate`] lays `birds` birds on a V, U, J or line in the formation frame (wingspans; lateral
//! gaps drawn from N(spacing, spacing_sd), at least 0.8), then for every frame adds a slow random
//! walk to each bird's position, per-frame noise, and fixed offsets for the chosen outlier birds.
//! [`SynthFlock`]'s writers turn it into pixels under any heading and scale, in every input format
//! of docs/formats.md §4.1. The truth kept per frame (formation-frame positions, outliers, leader) lets tests
//! check what `extract` finds.

use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde_json::json;

use crate::shape::ShapeKind;

/// What to generate. Lengths in wingspans unless the name ends in `_px`.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthSpec {
    /// Shape family.
    pub kind: ShapeKind,
    /// Number of birds.
    pub birds: usize,
    /// Number of frames.
    pub frames: usize,
    /// Mean lateral gap between neighbours, wingspans.
    pub spacing: f64,
    /// Standard deviation of the lateral gaps, wingspans.
    pub spacing_sd: f64,
    /// V: |dy/dx| of the left arm; line: dy/dx.
    pub slope_left: f64,
    /// V: dy/dx of the right arm.
    pub slope_right: f64,
    /// U/J: quadratic coefficient a of y = a x², 1/wingspan.
    pub curvature: f64,
    /// Position of the leader within the flock's lateral order, 0 (left end) to 1 (right end).
    pub leader_at: f64,
    /// Per-frame noise of each bird's position (both axes), wingspans.
    pub noise: f64,
    /// Step of the slow random walk of each bird per frame, wingspans.
    pub drift: f64,
    /// Number of outlier birds.
    pub outliers: usize,
    /// Range of the outliers' |y offset| from the curve, wingspans.
    pub outlier_offset: (f64, f64),
    /// Flight direction in the image, degrees clockwise from image-up.
    pub heading_deg: f64,
    /// Scale, pixels per wingspan.
    pub wingspan_px: f64,
    /// Pixel position of the leader in the first frame (x right, y down).
    pub origin_px: (f64, f64),
}

impl Default for SynthSpec {
    fn default() -> Self {
        SynthSpec {
            kind: ShapeKind::V,
            birds: 9,
            frames: 10,
            spacing: 0.92,
            spacing_sd: 0.08,
            slope_left: 0.75,
            slope_right: 0.75,
            curvature: 0.12,
            leader_at: 0.5,
            noise: 0.04,
            drift: 0.01,
            outliers: 0,
            outlier_offset: (1.2, 2.0),
            heading_deg: 0.0,
            wingspan_px: 40.0,
            origin_px: (960.0, 300.0),
        }
    }
}

/// One bird of one generated frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynthBird {
    /// True id: the bird's lateral order in the first frame.
    pub id: usize,
    /// Lateral position relative to the frame's front-most bird, wingspans.
    pub x: f64,
    /// Distance behind the frame's front-most bird, wingspans.
    pub y: f64,
    /// Pixel x.
    pub px: f64,
    /// Pixel y (down).
    pub py: f64,
    /// Whether the bird was displaced off the curve.
    pub outlier: bool,
}

/// One generated frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthFrame {
    /// Birds in id order.
    pub birds: Vec<SynthBird>,
    /// Id of the front-most bird.
    pub leader: usize,
}

/// A generated flock with its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthFlock {
    /// What was asked for.
    pub spec: SynthSpec,
    /// The frames.
    pub frames: Vec<SynthFrame>,
}

fn curve(spec: &SynthSpec, x: f64) -> f64 {
    match spec.kind {
        ShapeKind::V => {
            if x < 0.0 {
                -spec.slope_left * x
            } else {
                spec.slope_right * x
            }
        }
        ShapeKind::U | ShapeKind::J => spec.curvature * x * x,
        ShapeKind::Line => spec.slope_left * x,
    }
}

/// Generates a flock (see the module docs). Outliers are displaced along y so that their distance
/// from the curve is drawn from `outlier_offset`.
pub fn generate(spec: &SynthSpec, rng: &mut impl Rng) -> SynthFlock {
    let n = spec.birds.max(3);
    let gap = Normal::new(spec.spacing, spec.spacing_sd.max(0.0)).unwrap_or_else(|_| {
        Normal::new(0.92, 0.0).unwrap_or_else(|_| unreachable!("constant normal"))
    });
    let unit = Normal::new(0.0, 1.0).unwrap_or_else(|_| unreachable!("standard normal"));
    let mut xs = vec![0.0f64; n];
    for i in 1..n {
        xs[i] = xs[i - 1] + gap.sample(rng).max(0.8);
    }
    let lead = ((spec.leader_at.clamp(0.0, 1.0)) * (n - 1) as f64).round() as usize;
    let x0 = xs[lead];
    for x in &mut xs {
        *x -= x0;
    }
    // A line formation's leader sits at an end; for a line, slope the line away from it.
    let base: Vec<(f64, f64)> = xs
        .iter()
        .map(|&x| {
            let y = if spec.kind == ShapeKind::Line && lead == n - 1 {
                -spec.slope_left * x
            } else {
                curve(spec, x)
            };
            (x, y)
        })
        .collect();
    // Outliers: birds at least two places from the leader, spread over the flock.
    let mut candidates: Vec<usize> = (0..n).filter(|&i| i.abs_diff(lead) >= 2).collect();
    let mut out_ids = Vec::new();
    for _ in 0..spec.outliers.min(candidates.len()) {
        let k = rng.random_range(0..candidates.len());
        out_ids.push(candidates.remove(k));
    }
    out_ids.sort_unstable();
    // Outliers move along y (their lateral places are kept) by offset·√(1 + y'²), which puts
    // them `offset` wingspans off the curve geometrically, also on a steep arm.
    let normals: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let x = base[i].0;
            let h = 1e-6;
            let s = if spec.kind == ShapeKind::Line && lead == n - 1 {
                -spec.slope_left
            } else if spec.kind == ShapeKind::V {
                if x < 0.0 {
                    -spec.slope_left
                } else {
                    spec.slope_right
                }
            } else {
                (curve(spec, x + h) - curve(spec, x - h)) / (2.0 * h)
            };
            (0.0, (1.0 + s * s).sqrt())
        })
        .collect();
    let offsets: Vec<f64> = (0..n)
        .map(|i| {
            if !out_ids.contains(&i) {
                return 0.0;
            }
            let (lo, hi) = spec.outlier_offset;
            let mag = lo + (hi - lo) * rng.random::<f64>();
            // Forward offsets only where the bird stays well behind the leader.
            if rng.random::<bool>() && base[i].1 > mag * normals[i].1 + 0.8 {
                -mag
            } else {
                mag
            }
        })
        .collect();
    let theta = spec.heading_deg.to_radians();
    let (d, r) = ((theta.sin(), -theta.cos()), (theta.cos(), theta.sin()));
    let mut walk = vec![(0.0f64, 0.0f64); n];
    let mut frames = Vec::with_capacity(spec.frames);
    for fi in 0..spec.frames {
        let mut raw = Vec::with_capacity(n);
        for i in 0..n {
            walk[i].0 += spec.drift * unit.sample(rng);
            walk[i].1 += spec.drift * unit.sample(rng);
            // The walk is pulled back so birds keep their places over long movies.
            walk[i].0 *= 0.9;
            walk[i].1 *= 0.9;
            let x =
                base[i].0 + offsets[i] * normals[i].0 + walk[i].0 + spec.noise * unit.sample(rng);
            let y =
                base[i].1 + offsets[i] * normals[i].1 + walk[i].1 + spec.noise * unit.sample(rng);
            raw.push((x, y));
        }
        let leader = (0..n)
            .min_by(|&a, &b| raw[a].1.total_cmp(&raw[b].1))
            .unwrap_or(0);
        let (lx, ly) = raw[leader];
        // The whole flock moves slowly across the image.
        let shift = fi as f64 * 0.15;
        let birds = (0..n)
            .map(|i| {
                let (x, y) = raw[i];
                let fwd = -(y - ly) + shift;
                let lat = x - lx;
                SynthBird {
                    id: i,
                    x: x - lx,
                    y: y - ly,
                    px: spec.origin_px.0 + spec.wingspan_px * (lat * r.0 + fwd * d.0),
                    py: spec.origin_px.1 + spec.wingspan_px * (lat * r.1 + fwd * d.1),
                    outlier: offsets[i] != 0.0,
                }
            })
            .collect();
        frames.push(SynthFrame { birds, leader });
    }
    // True ids are the lateral order in the first frame (§4 step 1), after noise and offsets.
    if let Some(f0) = frames.first() {
        let mut by_x: Vec<usize> = (0..n).collect();
        by_x.sort_by(|&a, &b| f0.birds[a].x.total_cmp(&f0.birds[b].x));
        let mut rank = vec![0usize; n];
        for (r, &i) in by_x.iter().enumerate() {
            rank[i] = r;
        }
        for f in &mut frames {
            for b in &mut f.birds {
                b.id = rank[b.id];
            }
            f.leader = rank[f.leader];
            f.birds.sort_by_key(|b| b.id);
        }
    }
    SynthFlock {
        spec: spec.clone(),
        frames,
    }
}

fn shuffled(n: usize, rng: &mut impl Rng) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = rng.random_range(0..=i);
        v.swap(i, j);
    }
    v
}

fn heading_value(deg: f64) -> serde_json::Value {
    match deg {
        0.0 => json!("up"),
        90.0 => json!("right"),
        180.0 => json!("down"),
        270.0 => json!("left"),
        d => json!(d),
    }
}

fn r2(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

impl SynthFlock {
    /// Native JSON. With `ids`, birds are `{"id","x","y"}` objects; without, `[x, y]` pairs in a
    /// random order per frame (so identity must be recovered). Coordinates rounded to 0.01 px.
    pub fn native_json(&self, source: &str, ids: bool, rng: &mut impl Rng) -> String {
        // Written by hand so that each frame's birds stay on one line (easy to read and edit).
        let mut s = String::from("{\n");
        s.push_str(&format!("  \"source\": {},\n", json!(source)));
        s.push_str(&format!(
            "  \"heading\": {},\n",
            heading_value(self.spec.heading_deg)
        ));
        s.push_str(&format!(
            "  \"wingspan_px\": {},\n  \"frames\": [\n",
            json!(self.spec.wingspan_px)
        ));
        for (k, f) in self.frames.iter().enumerate() {
            let perm = if ids {
                (0..f.birds.len()).collect()
            } else {
                shuffled(f.birds.len(), rng)
            };
            let birds: Vec<String> = perm
                .iter()
                .map(|&i| {
                    let b = &f.birds[i];
                    if ids {
                        json!({"id": b.id, "x": r2(b.px), "y": r2(b.py)}).to_string()
                    } else {
                        json!([r2(b.px), r2(b.py)]).to_string()
                    }
                })
                .collect();
            s.push_str(&format!(
                "    {{\"index\": {k}, \"image\": \"f{k:03}.png\", \"birds\": [{}]}}{}\n",
                birds.join(", "),
                if k + 1 < self.frames.len() { "," } else { "" }
            ));
        }
        s.push_str("  ]\n}\n");
        s
    }

    /// Long CSV `frame,bird,x,y[,wingspan_px]` (y down). Without `ids` the bird column is left
    /// out and rows are shuffled within each frame. `header` lines become `# key: value` comments.
    pub fn long_csv(
        &self,
        header: &[(&str, String)],
        ids: bool,
        scale_column: bool,
        rng: &mut impl Rng,
    ) -> String {
        let mut s = String::new();
        for (k, v) in header {
            s.push_str(&format!("# {k}: {v}\n"));
        }
        s.push_str(if ids { "frame,bird,x,y" } else { "frame,x,y" });
        s.push_str(if scale_column { ",wingspan_px\n" } else { "\n" });
        for (k, f) in self.frames.iter().enumerate() {
            let perm = if ids {
                (0..f.birds.len()).collect()
            } else {
                shuffled(f.birds.len(), rng)
            };
            for &i in &perm {
                let b = &f.birds[i];
                if ids {
                    s.push_str(&format!("{k},{},{:.2},{:.2}", b.id, b.px, b.py));
                } else {
                    s.push_str(&format!("{k},{:.2},{:.2}", b.px, b.py));
                }
                if scale_column {
                    s.push_str(&format!(",{}", self.spec.wingspan_px));
                }
                s.push('\n');
            }
        }
        s
    }

    /// DLTdv CSV for camera 1 (y up from the bottom of an image `image_height_px` tall). Birds in
    /// `missing` (frame, id) are written as NaN.
    pub fn dltdv_csv(&self, image_height_px: f64, missing: &[(usize, usize)]) -> String {
        let n = self.frames.first().map(|f| f.birds.len()).unwrap_or(0);
        let cols: Vec<String> = (1..=n)
            .flat_map(|i| [format!("pt{i}_cam1_X"), format!("pt{i}_cam1_Y")])
            .collect();
        let mut s = cols.join(",");
        s.push('\n');
        for (k, f) in self.frames.iter().enumerate() {
            let row: Vec<String> = f
                .birds
                .iter()
                .flat_map(|b| {
                    if missing.contains(&(k, b.id)) {
                        ["NaN".to_string(), "NaN".to_string()]
                    } else {
                        [
                            format!("{:.4}", b.px),
                            format!("{:.4}", image_height_px - b.py),
                        ]
                    }
                })
                .collect();
            s.push_str(&row.join(","));
            s.push('\n');
        }
        s
    }

    /// Labelme files `(name, json)`, one per frame; birds are point shapes labelled `bird` (no id)
    /// and one `wingspan` line shape gives the scale.
    pub fn labelme_files(&self, rng: &mut impl Rng) -> Vec<(String, String)> {
        let theta = self.spec.heading_deg.to_radians();
        let r = (theta.cos(), theta.sin());
        self.frames
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let mut shapes: Vec<serde_json::Value> = shuffled(f.birds.len(), rng)
                    .iter()
                    .map(|&i| {
                        let b = &f.birds[i];
                        json!({"label": "bird", "points": [[r2(b.px), r2(b.py)]],
                               "group_id": null, "description": "", "shape_type": "point", "flags": {}})
                    })
                    .collect();
                if let Some(b) = f.birds.first() {
                    let h = self.spec.wingspan_px / 2.0;
                    shapes.push(json!({"label": "wingspan",
                        "points": [[b.px - h * r.0, b.py - h * r.1], [b.px + h * r.0, b.py + h * r.1]],
                        "group_id": null, "description": "", "shape_type": "line", "flags": {}}));
                }
                let name = format!("frame_{k:04}.json");
                let mut v = json!({"version": "5.4.1", "flags": {}, "shapes": shapes,
                    "imagePath": format!("frame_{k:04}.jpg"), "imageData": null,
                    "imageHeight": 1080, "imageWidth": 1920});
                // Labelme keeps unknown top-level keys when it re-saves a file.
                if self.spec.heading_deg != 0.0 {
                    v["heading"] = heading_value(self.spec.heading_deg);
                }
                (name, serde_json::to_string_pretty(&v).unwrap_or_default() + "\n")
            })
            .collect()
    }
}
