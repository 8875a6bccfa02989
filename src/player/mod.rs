//! `formation view`: one self-contained HTML page that plays an animation in 3-D with WebGL 2
//! (docs/player.md). Nothing is fetched when the page is viewed: the player's script and style
//! are compiled into the binary ([`PLAYER_JS`]), the frames are embedded as base64 of
//! little-endian typed arrays, and the bird mesh is built here from the species' silhouette.
//!
//! What the page holds per bird and stored frame (24 bytes, 32 as base64):
//! - position `x, y, z`: `float32` (wingspans, world frame, z up);
//! - heading: `int16`, π per 32767;
//! - bank, pitch and the wing pose (dihedral, hand dihedral, sweep, spread, leg swing): `int8`
//!   each, scaled by 127 / the largest magnitude of that field in the animation (the scales are
//!   in the page), so every value keeps its full range at 1/254 of it;
//! - the saving `e` (of induced power) and of total power: `int16`, scaled the same way, −32768
//!   where the animation has none (e.g. during the take-off).
//!
//! The wing pose is [`crate::wingbeat::Flapper::pose`] of every frame, the same wingbeat,
//! resting, landing and leg poses as the glTF and USD exports; the page turns the wings by the
//! joint rotations of [`crate::export::rig::wing_joints`] in its vertex shader.

use std::fmt::Write as _;

use serde::Serialize;

use crate::animation::Animation;
use crate::embed::{html_text, script_json_text};
use crate::error::{Error, Result};
use crate::export::silhouette::{self, Part};
use crate::wingbeat::{Flapper, Species, WingPose, WingbeatOptions};

/// The player's script (WebGL 2, no library), compiled in.
pub const PLAYER_JS: &str = include_str!("../../assets/player/player.js");
/// The player's style sheet, compiled in.
pub const PLAYER_CSS: &str = include_str!("../../assets/player/player.css");

/// Bytes a bird and stored frame take in the page before base64.
pub const BYTES_PER_BIRD_FRAME: usize = 24;

/// What [`page`] builds.
#[derive(Debug, Clone, PartialEq)]
pub struct PlayerOptions {
    /// Title of the page (the animation's file name).
    pub title: String,
    /// Number of the animation's first frame in the page (default: the animation's
    /// `start_frame`).
    pub start_frame: Option<u64>,
    /// Keep every `every`-th frame (1: all); the page interpolates between the kept ones.
    pub every: usize,
}

impl Default for PlayerOptions {
    fn default() -> Self {
        PlayerOptions {
            title: "animation".into(),
            start_frame: None,
            every: 1,
        }
    }
}

/// The largest `every`.
pub const MAX_EVERY: usize = 1000;

#[derive(Serialize)]
struct Meta<'a> {
    title: &'a str,
    birds: usize,
    fps: f64,
    frames: usize,
    every: usize,
    start_frame: u64,
    species: &'static str,
    wingspan_m: f64,
    times: Vec<f64>,
    stages: Vec<serde_json::Value>,
    events: Vec<serde_json::Value>,
    formation_of: Option<Vec<usize>>,
    leaders: Vec<usize>,
    scales: Scales,
    has_saving: bool,
    has_total: bool,
    savings_model: String,
    surface: &'static str,
    core_radius: f64,
    vortex_span: f64,
    ground_eye: [f64; 3],
    data_bytes: usize,
    mesh: Mesh,
}

/// Scale (stored units per natural unit) of each quantised field.
#[derive(Serialize, Default)]
struct Scales {
    heading: f64,
    i8: [f64; 7],
    e: f64,
    total: f64,
}

/// The light bird mesh: flat triangles, one colour each vertex, parts tagged for the shader.
#[derive(Serialize, Default)]
struct Mesh {
    /// `x, y, z` per vertex (bird frame: x right, y forward, z up), relative to the vertex's
    /// joint (body: the bird's centre; arm: its shoulder; hand: its wrist; leg: see `part`).
    p: Vec<f32>,
    /// Unit normal per vertex (in the same frame, before the joint turns).
    n: Vec<f32>,
    /// Part per vertex: 0 body, 1 arm, 2 hand, 3 leg (p = lateral, distance from the hip, 0).
    part: Vec<u8>,
    /// Wing side per vertex: +1 the bird's left (x < 0), −1 its right, 0 the body.
    side: Vec<i8>,
    /// Linear 0–1 colour per vertex.
    c: Vec<f32>,
    /// Shoulder's lateral distance from the centre and the arm's length, wingspans.
    shoulder: f32,
    arm: f32,
    /// Leg hip `(lateral, forward, up)`, wingspans (legs only drawn when `legs`).
    hip: [f32; 3],
    legs: bool,
}

/// The fraction of the arm's backward swing and the hand's when the wing folds
/// ([`crate::export::rig::ARM_FOLD`], [`crate::export::rig::HAND_FOLD`]).
#[derive(Serialize)]
struct Fold {
    arm: f32,
    hand: f32,
}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
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

fn species_of(anim: &Animation) -> Species {
    WingbeatOptions::for_animation(anim).species
}

/// Ear-clipping triangulation of a simple polygon (2-D), indices into `pts`.
fn triangulate(pts: &[[f32; 2]]) -> Vec<[usize; 3]> {
    let n = pts.len();
    if n < 3 {
        return Vec::new();
    }
    let area: f32 = (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    let ccw = area > 0.0;
    let mut idx: Vec<usize> = (0..n).collect();
    if !ccw {
        idx.reverse();
    }
    let cross = |o: [f32; 2], a: [f32; 2], b: [f32; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let inside = |p: [f32; 2], a: [f32; 2], b: [f32; 2], c: [f32; 2]| {
        cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
    };
    let mut out = Vec::new();
    let mut guard = 0;
    while idx.len() > 3 && guard < 10 * n {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for i in 0..m {
            let (ia, ib, ic) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
            if cross(a, b, c) <= 1e-9 {
                continue;
            }
            let blocked = idx
                .iter()
                .any(|&j| j != ia && j != ib && j != ic && inside(pts[j], a, b, c));
            if !blocked {
                out.push([ia, ib, ic]);
                idx.remove(i);
                clipped = true;
                break;
            }
        }
        if !clipped {
            break;
        }
    }
    if idx.len() >= 3 {
        // What is left (degenerate or a failed clip): a fan, drawn two-sided anyway.
        for k in 1..idx.len() - 1 {
            out.push([idx[0], idx[k], idx[k + 1]]);
        }
    }
    out
}

fn rgb(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| v as f32 / 255.0)
}

/// The species' light mesh, from its silhouette with the wings spread flat.
fn mesh(species: Species) -> Mesh {
    let plumage = silhouette::plumage(species);
    let pieces = silhouette::pieces(species, &WingPose::EXTENDED, 0.0);
    let mut m = Mesh::default();
    let push = |m: &mut Mesh, p: [f32; 3], n: [f32; 3], part: u8, side: i8, c: [f32; 3]| {
        m.p.extend(p);
        m.n.extend(n);
        m.part.push(part);
        m.side.push(side);
        m.c.extend(c);
    };
    // The right wing's arm gives the shoulder (its innermost point) and the hand the wrist.
    let right = |part: Part| {
        pieces
            .iter()
            .find(|p| p.part == part && p.points.iter().all(|q| q[0] >= 0.0))
    };
    let (Some(arm), Some(hand)) = (right(Part::Arm), right(Part::Hand)) else {
        return m;
    };
    let shoulder = arm
        .points
        .iter()
        .map(|q| q[0])
        .fold(f32::INFINITY, f32::min);
    let wrist = hand.points[0][0];
    m.shoulder = shoulder;
    m.arm = wrist - shoulder;
    for (piece, part, joint, colour) in [
        (arm, 1u8, shoulder, plumage.arm),
        (hand, 2u8, wrist, plumage.hand),
    ] {
        let flat: Vec<[f32; 2]> = piece.points.iter().map(|q| [q[0], q[1]]).collect();
        for tri in triangulate(&flat) {
            for side in [-1i8, 1] {
                // Side −1 (right, x > 0) as built; +1 mirrored.
                let sx = -(side as f32);
                for &v in &tri {
                    let q = flat[v];
                    push(
                        &mut m,
                        [sx * (q[0] - joint), q[1], 0.0],
                        [0.0, 0.0, 1.0],
                        part,
                        side,
                        rgb(colour),
                    );
                }
            }
        }
    }
    // Body, neck, head: each symmetric outline's right half lofted into a spindle.
    for piece in pieces
        .iter()
        .filter(|p| matches!(p.part, Part::Body | Part::Head) && p.points.len() > 4)
    {
        let half = &piece.points[..piece.points.len() / 2];
        let mut prof: Vec<(f32, f32)> = half.iter().map(|q| (q[1], q[0].abs())).collect();
        prof.sort_by(|a, b| a.0.total_cmp(&b.0));
        let colour = rgb(if piece.part == Part::Head {
            plumage.head
        } else {
            plumage.body
        });
        const SIDES: usize = 6;
        let ring = |(y, w): (f32, f32), j: usize| {
            let a = std::f32::consts::TAU * j as f32 / SIDES as f32;
            let h = if piece.part == Part::Head {
                0.9 * w
            } else {
                0.75 * w
            };
            ([w * a.cos(), y, h * a.sin()], [a.cos(), 0.0, a.sin()])
        };
        for k in 0..prof.len().saturating_sub(1) {
            for j in 0..SIDES {
                let (a, na) = ring(prof[k], j);
                let (b, nb) = ring(prof[k], j + 1);
                let (c, nc) = ring(prof[k + 1], j + 1);
                let (d, nd) = ring(prof[k + 1], j);
                for (p, n) in [(a, na), (b, nb), (c, nc), (a, na), (c, nc), (d, nd)] {
                    push(&mut m, p, n, 0, 0, colour);
                }
            }
        }
    }
    // Legs (the species whose silhouette shows them): two thin strips from the hips.
    if species == Species::Crane {
        let leg = crate::wingbeat::rest::leg(species);
        m.hip = [leg.hip[0] as f32, leg.hip[2] as f32, leg.hip[1] as f32];
        m.legs = true;
        let reach = leg.reach as f32;
        for s in [-1.0f32, 1.0] {
            let x = s * m.hip[0];
            let q = [
                [x - 0.004, 0.0],
                [x + 0.004, 0.0],
                [x + 0.003, reach],
                [x - 0.004, 0.0],
                [x + 0.003, reach],
                [x - 0.003, reach],
            ];
            for [lx, d] in q {
                push(
                    &mut m,
                    [lx, d, 0.0],
                    [0.0, 0.0, 1.0],
                    3,
                    0,
                    rgb(plumage.head),
                );
            }
        }
    }
    m
}

/// Quantises `v` to `i8` by `scale` (clamped).
fn q8(v: f64, scale: f64) -> u8 {
    ((v * scale).round().clamp(-127.0, 127.0) as i8) as u8
}

/// Quantises `v` to `i16` by `scale` (clamped); `None` is −32768.
fn q16(v: Option<f64>, scale: f64) -> [u8; 2] {
    let x = match v {
        Some(v) if v.is_finite() => (v * scale).round().clamp(-32767.0, 32767.0) as i16,
        _ => i16::MIN,
    };
    x.to_le_bytes()
}

fn scale_for(max_abs: f64, steps: f64) -> f64 {
    if max_abs > 1e-12 {
        steps / max_abs
    } else {
        steps
    }
}

/// The player page of `anim`.
pub fn page(anim: &Animation, opts: &PlayerOptions) -> Result<String> {
    if anim.frames.is_empty() || anim.birds == 0 {
        return Err(Error::parameter(
            "animation",
            "the animation has no frames or no birds; nothing to play",
        ));
    }
    if opts.every == 0 || opts.every > MAX_EVERY {
        return Err(Error::parameter(
            "view.every",
            format!(
                "{}: keep every 1st to every {MAX_EVERY}th frame",
                opts.every
            ),
        ));
    }
    let species = species_of(anim);
    let flapper = Flapper::from_animation(anim);
    let kept: Vec<usize> = (0..anim.frames.len()).step_by(opts.every).collect();
    let nb = anim.birds;
    let nk = kept.len();
    let curve = crate::aero::flight::curve_of(anim);
    let totals: Vec<Option<Vec<f64>>> = kept
        .iter()
        .map(|&k| crate::aero::flight::frame_savings_total(anim, &curve, k))
        .collect();
    let poses: Vec<Vec<WingPose>> = kept
        .iter()
        .map(|&k| (0..nb).map(|b| flapper.pose(k, b)).collect())
        .collect();
    // The largest magnitudes give the scales.
    let mut max8 = [0f64; 7];
    let (mut max_e, mut max_t) = (0f64, 0f64);
    for (i, &k) in kept.iter().enumerate() {
        let f = &anim.frames[k];
        for (b, p) in poses[i].iter().enumerate() {
            let v = [
                f.bank
                    .as_ref()
                    .and_then(|v| v.get(b))
                    .copied()
                    .unwrap_or(0.0),
                f.pitch
                    .as_ref()
                    .and_then(|v| v.get(b))
                    .copied()
                    .unwrap_or(0.0),
                p.dihedral,
                p.hand_dihedral,
                p.sweep,
                p.spread,
                p.legs,
            ];
            for (m, x) in max8.iter_mut().zip(v) {
                if x.is_finite() {
                    *m = m.max(x.abs());
                }
            }
            if let Some(e) = f.e.as_ref().and_then(|v| v.get(b)) {
                max_e = max_e.max(e.abs());
            }
            if let Some(t) = totals[i].as_ref().and_then(|v| v.get(b)) {
                max_t = max_t.max(t.abs());
            }
        }
    }
    let scales = Scales {
        heading: 32767.0 / std::f64::consts::PI,
        i8: max8.map(|m| scale_for(m, 127.0)),
        e: scale_for(max_e, 32767.0),
        total: scale_for(max_t, 32767.0),
    };
    let mut pos = Vec::with_capacity(nk * nb * 12);
    let mut hdg = Vec::with_capacity(nk * nb * 2);
    let mut small = Vec::with_capacity(nk * nb * 7);
    let mut sav = Vec::with_capacity(nk * nb * 2);
    let mut tot = Vec::with_capacity(nk * nb * 2);
    for (i, &k) in kept.iter().enumerate() {
        let f = &anim.frames[k];
        for (b, p) in poses[i].iter().enumerate() {
            for v in [&f.x, &f.y, &f.z] {
                pos.extend((v.get(b).copied().unwrap_or(0.0) as f32).to_le_bytes());
            }
            let h =
                crate::export::sample::angle_diff(0.0, f.heading.get(b).copied().unwrap_or(0.0));
            hdg.extend(q16(Some(h), scales.heading));
            let v = [
                f.bank
                    .as_ref()
                    .and_then(|v| v.get(b))
                    .copied()
                    .unwrap_or(0.0),
                f.pitch
                    .as_ref()
                    .and_then(|v| v.get(b))
                    .copied()
                    .unwrap_or(0.0),
                p.dihedral,
                p.hand_dihedral,
                p.sweep,
                p.spread,
                p.legs,
            ];
            for (x, s) in v.iter().zip(scales.i8) {
                small.push(q8(if x.is_finite() { *x } else { 0.0 }, s));
            }
            sav.extend(q16(f.e.as_ref().and_then(|v| v.get(b)).copied(), scales.e));
            tot.extend(q16(
                totals[i].as_ref().and_then(|v| v.get(b)).copied(),
                scales.total,
            ));
        }
    }
    let data_bytes = pos.len() + hdg.len() + small.len() + sav.len() + tot.len();
    let (formation_of, leaders) = match &anim.formations {
        Some(fs) if !fs.is_empty() => {
            let mut of = vec![0usize; nb];
            for (i, f) in fs.iter().enumerate() {
                for &b in &f.birds {
                    if let Some(o) = of.get_mut(b) {
                        *o = i;
                    }
                }
            }
            (Some(of), fs.iter().map(|f| f.leader).collect())
        }
        _ => (None, Vec::new()),
    };
    // The ground camera's observer: where the GIF's ground camera stands.
    let ground_eye = {
        let step = (anim.frames.len() / 200).max(1);
        let states: Vec<Vec<crate::export::sample::Place>> = (0..anim.frames.len())
            .step_by(step)
            .map(|k| crate::export::sample::places_at(anim, anim.frames[k].t))
            .collect();
        crate::export::camera::ground_position(
            &states,
            &crate::export::camera::GroundParams::default(),
        )
    };
    let start_frame = opts.start_frame.unwrap_or(anim.start_frame);
    let meta = Meta {
        title: &opts.title,
        birds: nb,
        fps: anim.fps,
        frames: nk,
        every: opts.every,
        start_frame,
        species: species.name(),
        wingspan_m: anim.wingspan_m,
        times: kept.iter().map(|&k| anim.frames[k].t).collect(),
        stages: anim
            .stages
            .iter()
            .map(|s| serde_json::json!({"name": s.name.as_str(), "start": s.start, "end": s.end}))
            .collect(),
        events: anim
            .events
            .iter()
            .filter_map(|e| serde_json::to_value(e).ok())
            .collect(),
        formation_of,
        leaders,
        scales,
        has_saving: anim.frames.iter().any(|f| f.e.is_some()),
        has_total: totals.iter().any(Option::is_some),
        savings_model: anim
            .savings_model
            .as_ref()
            .map_or("Hummel's model".into(), |m| m.to_string()),
        surface: match &anim.landing {
            Some(l) if l.surface == crate::animation::landing::Surface::Water => "water",
            _ => "ground",
        },
        core_radius: anim
            .savings_model
            .as_ref()
            .map_or(crate::aero::AeroOptions::default().core_radius, |m| {
                m.core_radius
            }),
        vortex_span: crate::aero::VORTEX_SPAN,
        ground_eye,
        data_bytes,
        mesh: mesh(species),
    };
    let meta_json = serde_json::to_string(&meta)
        .map_err(|e| Error::Internal(format!("player metadata to JSON: {e}")))?;
    let fold = serde_json::to_string(&Fold {
        arm: crate::export::rig::ARM_FOLD,
        hand: crate::export::rig::HAND_FOLD,
    })
    .map_err(|e| Error::Internal(format!("player metadata to JSON: {e}")))?;
    let mut out = String::with_capacity(data_bytes * 4 / 3 + PLAYER_JS.len() + 8192);
    let title = html_text(&format!("formation view: {}", opts.title));
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n\
<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
<title>{title}</title>\n<style>{css}</style></head>\n<body>\n",
        css = PLAYER_CSS
    );
    out.push_str(
        "<div id=\"fp-root\"><canvas id=\"fp-canvas\"></canvas><div id=\"fp-ui\"></div></div>\n",
    );
    let _ = writeln!(
        out,
        "<script type=\"application/json\" id=\"fp-meta\">{}</script>",
        script_json_text(&meta_json)
    );
    let _ = writeln!(
        out,
        "<script type=\"application/json\" id=\"fp-fold\">{}</script>",
        script_json_text(&fold)
    );
    for (id, bytes) in [
        ("pos", &pos),
        ("hdg", &hdg),
        ("i8", &small),
        ("e", &sav),
        ("total", &tot),
    ] {
        let _ = writeln!(
            out,
            "<script type=\"application/octet-stream\" id=\"fp-{id}\">{}</script>",
            base64(bytes)
        );
    }
    // The page's own size, stated in the page: the tag's length counted in.
    let tail = format!("<script>\n{PLAYER_JS}\n</script>\n</body></html>\n");
    let mut size = out.len() + tail.len();
    loop {
        let tag = format!("<script type=\"application/json\" id=\"fp-bytes\">{size}</script>\n");
        let total = out.len() + tag.len() + tail.len();
        if total == size {
            out.push_str(&tag);
            break;
        }
        size = total;
    }
    out.push_str(&tail);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_json_text_leaves_no_tag_or_comment() {
        let s = script_json_text(r#"{"title":"</script><!-- x & y"}"#);
        assert!(!s.contains('<') && !s.contains('>') && !s.contains('&'));
        let back: serde_json::Value = serde_json::from_str(&s).unwrap();
        assert_eq!(back["title"], "</script><!-- x & y");
    }

    #[test]
    fn base64_pads_like_the_standard() {
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn triangulation_covers_a_concave_polygon() {
        // An L shape of area 3.
        let pts = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let tris = triangulate(&pts);
        assert_eq!(tris.len(), 4);
        let area: f32 = tris
            .iter()
            .map(|t| {
                let (a, b, c) = (pts[t[0]], pts[t[1]], pts[t[2]]);
                ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
            })
            .sum();
        assert!((area - 3.0).abs() < 1e-5);
    }

    #[test]
    fn every_species_has_a_mesh_with_both_wings() {
        for sp in Species::ALL {
            let m = mesh(sp);
            assert!(m.shoulder > 0.0 && m.arm > 0.0, "{sp}");
            assert!(m.side.contains(&1) && m.side.contains(&-1), "{sp}");
            assert_eq!(m.p.len(), 3 * m.part.len());
            assert!(m.part.len() < 2000, "{sp}: a light mesh");
        }
    }
}
