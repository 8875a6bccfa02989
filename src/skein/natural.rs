//! The arrangements of formations other than the lattice of [`super::layout::arrange`]: the
//! *natural* one (formations scattered at irregular distances, at different heights and on
//! slightly different headings, as the skeins of a migrating flock are seen) and the *compound*
//! one (the formations strung along the two arms of one large V, as the compound V formations of
//! large shorebird flocks). Lengths in wingspans, the course frame (x east, y north).
//!
//! **Clearance in every frame.** Each formation's envelope holds a box of its birds for every
//! window of [`super::layout::WINDOW_S`] seconds ([`Envelope::windows`]). A formation is only
//! put where, in every window, its box is at least the clearance from the box of every formation
//! already placed (boxes hold every bird of the window, so their distance bounds the distance
//! of any two birds from below). Formations can therefore sit close where their wanderings
//! differ in time, and never meet.
//!
//! **Natural.** The flock grows formation by formation in a random order: the next one is put
//! beside a formation already placed, chosen at random, in a random direction (wider than deep:
//! directions are drawn on an ellipse of [`super::layout::ASPECT`] : 1). Each formation has a
//! *room* drawn exponential with mean [`ROOM`]·s·w̃ (w̃ the median formation width, s
//! `skein.spread`); two formations keep the clearance plus the larger of their rooms apart in
//! every window, and the new one is put that far from its neighbour plus a small extra gap
//! ([`CLOSE_GAP`]·s·w̃·E, E exponential of mean 1). Most formations sit near a neighbour and a few
//! farther out, so the distances between neighbours vary as in a real sky rather than on a
//! lattice. A place that would bring it within that distance of another formation in some window
//! is rejected and another is drawn; after 40 rejections the gaps are widened by half.
//!
//! **Compound.** The formations, in a random order, go alternately to the right and the left arm
//! of one large V, each behind and outside the one before it on its arm, at a neighbour angle (the
//! angle between the course and the line from one formation to the next) drawn uniform in
//! [`COMPOUND_ANGLE_DEG`], the range Corcoran & Hedrick (2019) measured between neighbours in
//! compound-V shorebird flocks; a place too close to another formation is moved back along the
//! same line until it is clear.
//!
//! **Heights.** Each formation flies at its own height, offset from the others by
//! H·(u₁ + u₂ − 1) (u uniform: a triangular law on [−H, H], standard deviation H/√6), H
//! [`NATURAL_HEIGHT`] for the natural layout and [`COMPOUND_HEIGHT`] for the compound one. After
//! a take-off the offset is reached over the first [`HEIGHT_RAMP_S`] seconds of the steady
//! flight (a smootherstep climb or descent), so every formation leaves the ground and reaches
//! the hand-over as before.

use std::collections::HashMap;

use rand::Rng;
use serde::{Deserialize, Serialize};

use super::layout::{Envelope, Placement, ASPECT};
use crate::keyshape::spacing::median;

/// How the formations of a flock are arranged (`skein.layout`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SkeinLayout {
    /// Scattered at irregular distances, heights and headings (the default).
    #[default]
    Natural,
    /// Lanes side by side, one formation behind the other in each (the arrangement of earlier
    /// versions).
    Grid,
    /// One compound V: formations strung along the two arms of a large V.
    Compound,
}

impl SkeinLayout {
    /// The name as the flag and the config take it.
    pub fn as_str(&self) -> &'static str {
        match self {
            SkeinLayout::Natural => "natural",
            SkeinLayout::Grid => "grid",
            SkeinLayout::Compound => "compound",
        }
    }

    /// The largest heading difference of a formation's drift from the course when
    /// `skein.max_heading_deg` is not given, degrees: the grid's 1°, the natural layout's 3°
    /// (a choice: field data give no heading differences between skeins; with drift amplitudes
    /// between half and all of it, the skeins' headings spread by about 1.5° sd), the compound
    /// V's 1° (one V holds one course).
    pub fn max_heading_deg(&self) -> f64 {
        match self {
            SkeinLayout::Natural => NATURAL_HEADING_DEG,
            SkeinLayout::Grid | SkeinLayout::Compound => 1.0,
        }
    }

    /// H, the largest height offset of a formation, wingspans (see the module doc).
    pub fn height(&self) -> f64 {
        match self {
            SkeinLayout::Natural => NATURAL_HEIGHT,
            SkeinLayout::Grid => 0.0,
            SkeinLayout::Compound => COMPOUND_HEIGHT,
        }
    }
}

impl std::str::FromStr for SkeinLayout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "natural" => Ok(SkeinLayout::Natural),
            "grid" => Ok(SkeinLayout::Grid),
            "compound" => Ok(SkeinLayout::Compound),
            other => Err(format!("{other:?}: give natural, grid or compound")),
        }
    }
}

/// Largest heading difference of the natural layout's drift, degrees (see
/// [`SkeinLayout::max_heading_deg`]).
pub const NATURAL_HEADING_DEG: f64 = 3.0;

/// H of the natural layout, wingspans: heights spread by H/√6 ≈ 1.2 wingspans sd (a choice:
/// field data measure heights within a formation, not between skeins; skeins of one flock are
/// seen at visibly different heights).
pub const NATURAL_HEIGHT: f64 = 3.0;

/// H of the compound V, wingspans: Corcoran & Hedrick (2019) found 97.9 % of neighbours within
/// ±1 wingspan of height in shorebird flocks.
pub const COMPOUND_HEIGHT: f64 = 1.0;

/// Seconds over which a formation reaches its height offset after a take-off.
pub const HEIGHT_RAMP_S: f64 = 8.0;

/// Range of the angle between the course and the line from one formation to the next on an arm
/// of the compound V, degrees (Corcoran & Hedrick 2019: neighbour angles 33.7–51.8° in compound-V
/// shorebird flocks).
pub const COMPOUND_ANGLE_DEG: [f64; 2] = [33.7, 51.8];

/// Share of the natural layout's formations put at a loose gap from the one they join (the others
/// at a close one): skeins of a migrating flock are seen in loose groups, a few at a distance.
pub const LOOSE_SHARE: f64 = 0.0;
/// Mean extra gap of a loose formation, in units of s·w̃ (see the module doc).
pub const LOOSE_GAP: f64 = 6.0;
/// Mean extra gap of a close formation, in units of s·w̃.
pub const CLOSE_GAP: f64 = 0.2;

/// Mean room of a formation of the natural layout, in units of s·w̃ (exponential).
pub const ROOM: f64 = 1.5;

/// Places drawn for one formation before the gaps of the natural layout are widened.
const TRIES: usize = 40;

/// `env` in a frame moving with the flock: from every window of every envelope the median centre
/// of that window over all formations is subtracted. Distances between formations in one
/// window are unchanged; the bounds of a formation over all windows are then its extent
/// relative to the flock (not the length of its flight).
fn co_moving(env: &[Envelope]) -> Vec<Envelope> {
    let n = env.iter().map(|e| e.windows.len()).min().unwrap_or(0);
    let refs: Vec<[f64; 2]> = (0..n)
        .map(|w| {
            let c = |i: usize| {
                median(
                    env.iter()
                        .map(|e| 0.5 * (e.windows[w][i] + e.windows[w][i + 2]))
                        .collect(),
                )
            };
            [c(0), c(1)]
        })
        .collect();
    env.iter()
        .map(|e| Envelope {
            x: e.x,
            rear: Vec::new(),
            front: Vec::new(),
            windows: e
                .windows
                .iter()
                .zip(&refs)
                .map(|(b, r)| [b[0] - r[0], b[1] - r[1], b[2] - r[0], b[3] - r[1]])
                .collect(),
        })
        .collect()
}

/// The formations placed so far, bucketed by the centre of their bounds on a grid of cells
/// larger than any formation plus the clearance, so that only the 3 × 3 cells around a place
/// can hold a formation within the clearance of it.
struct Placed<'a> {
    env: &'a [Envelope],
    clearance: f64,
    cell: f64,
    cells: HashMap<(i64, i64), Vec<usize>>,
    offset: Vec<Option<[f64; 2]>>,
    /// Each formation's room: two formations keep the clearance plus the larger of their rooms
    /// apart.
    room: Vec<f64>,
}

impl<'a> Placed<'a> {
    fn new(env: &'a [Envelope], clearance: f64, room: Vec<f64>) -> Placed<'a> {
        let big = env
            .iter()
            .map(|e| {
                let b = e.bounds();
                (b[2] - b[0]).max(b[3] - b[1])
            })
            .fold(0.0, f64::max);
        Placed {
            env,
            clearance,
            cell: (big + clearance + room.iter().copied().fold(0.0, f64::max)).max(1.0),
            cells: HashMap::new(),
            offset: vec![None; env.len()],
            room,
        }
    }

    fn key(&self, f: usize, at: [f64; 2]) -> (i64, i64) {
        let b = self.env[f].bounds();
        (
            ((0.5 * (b[0] + b[2]) + at[0]) / self.cell).floor() as i64,
            ((0.5 * (b[1] + b[3]) + at[1]) / self.cell).floor() as i64,
        )
    }

    /// Whether formation `f` at offset `at` is the clearance from every placed one in every
    /// window.
    fn clear(&self, f: usize, at: [f64; 2]) -> bool {
        let (cx, cy) = self.key(f, at);
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(list) = self.cells.get(&(cx + dx, cy + dy)) else {
                    continue;
                };
                for &g in list {
                    let c = self.clearance + self.room[f].max(self.room[g]);
                    let c2 = c * c;
                    let o = self.offset[g].expect("placed");
                    let (a, b) = (&self.env[f].windows, &self.env[g].windows);
                    for (wa, wb) in a.iter().zip(b) {
                        let gx = ((wa[0] + at[0]) - (wb[2] + o[0]))
                            .max((wb[0] + o[0]) - (wa[2] + at[0]))
                            .max(0.0);
                        let gy = ((wa[1] + at[1]) - (wb[3] + o[1]))
                            .max((wb[1] + o[1]) - (wa[3] + at[1]))
                            .max(0.0);
                        if gx * gx + gy * gy < c2 {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    fn put(&mut self, f: usize, at: [f64; 2]) {
        let k = self.key(f, at);
        self.cells.entry(k).or_default().push(f);
        self.offset[f] = Some(at);
    }

    /// The centre of formation `f`'s bounds at offset `at`.
    fn centre(&self, f: usize, at: [f64; 2]) -> [f64; 2] {
        let b = self.env[f].bounds();
        [0.5 * (b[0] + b[2]) + at[0], 0.5 * (b[1] + b[3]) + at[1]]
    }
}

/// Half the width and depth of formation `f`'s bounds.
fn half(env: &Envelope) -> [f64; 2] {
    let b = env.bounds();
    [0.5 * (b[2] - b[0]), 0.5 * (b[3] - b[1])]
}

/// A random order of `0..k`.
fn shuffled(k: usize, rng: &mut impl Rng) -> Vec<usize> {
    let mut order: Vec<usize> = (0..k).collect();
    for i in (1..k).rev() {
        let j = rng.random_range(0..=i);
        order.swap(i, j);
    }
    order
}

/// The offset that puts the centre of formation `f`'s bounds at `c`.
fn offset_for(env: &Envelope, c: [f64; 2]) -> [f64; 2] {
    let b = env.bounds();
    [c[0] - 0.5 * (b[0] + b[2]), c[1] - 0.5 * (b[1] + b[3])]
}

/// The natural arrangement of formations with envelopes `env` (see the module doc).
pub fn arrange_natural(
    env: &[Envelope],
    clearance: f64,
    spread: f64,
    rng: &mut impl Rng,
) -> Vec<Placement> {
    let k = env.len();
    let w_med = median(env.iter().map(Envelope::width).collect());
    let env = &co_moving(env);
    let room: Vec<f64> = (0..k)
        .map(|_| ROOM * spread * w_med * -(1.0 - rng.random_range(0.0..1.0f64)).ln())
        .collect();
    let mut placed = Placed::new(env, clearance, room.clone());
    let mut centres: Vec<usize> = Vec::with_capacity(k);
    let mut group: Vec<usize> = Vec::new();
    for (row, f) in shuffled(k, rng).into_iter().enumerate() {
        if centres.is_empty() {
            placed.put(f, offset_for(&env[f], [0.0, 0.0]));
            centres.push(f);
            group.push(f);
            continue;
        }
        let hf = half(&env[f]);
        let mut widen = 1.0;
        // A new group beside any formation placed so far, at a loose gap; or the next
        // formation of the current group, beside one of its members at a close gap.
        let loose = rng.random_bool(LOOSE_SHARE);
        if loose {
            group.clear();
        }
        let scale = if loose { LOOSE_GAP } else { CLOSE_GAP };
        let at = 'found: loop {
            for _ in 0..TRIES {
                let a = if loose || group.is_empty() {
                    centres[rng.random_range(0..centres.len())]
                } else {
                    group[rng.random_range(0..group.len())]
                };
                let ca = placed.centre(a, placed.offset[a].expect("placed"));
                let ha = half(&env[a]);
                let th = rng.random_range(0.0..std::f64::consts::TAU);
                let (ux, uy) = (ASPECT * th.cos(), th.sin());
                let n = ux.hypot(uy);
                let (ux, uy) = (ux / n, uy / n);
                let e: f64 = -(1.0 - rng.random_range(0.0..1.0f64)).ln();
                let gap = widen * (clearance + room[f].max(room[a]) + scale * spread * w_med * e);
                // Far enough along (ux, uy) for the bounds to be `gap` apart on one axis.
                let tx = if ux.abs() > 1e-9 {
                    (ha[0] + hf[0] + gap) / ux.abs()
                } else {
                    f64::INFINITY
                };
                let ty = if uy.abs() > 1e-9 {
                    (ha[1] + hf[1] + gap) / uy.abs()
                } else {
                    f64::INFINITY
                };
                let t = tx.min(ty);
                let at = offset_for(&env[f], [ca[0] + t * ux, ca[1] + t * uy]);
                if placed.clear(f, at) {
                    break 'found at;
                }
            }
            widen *= 1.5;
        };
        placed.put(f, at);
        centres.push(f);
        group.push(f);
        let _ = row;
    }
    placed
        .offset
        .iter()
        .enumerate()
        .map(|(row, o)| Placement {
            offset: o.unwrap_or([0.0, 0.0]),
            lane: 0,
            row,
            height: 0.0,
        })
        .collect()
}

/// The compound-V arrangement of formations with envelopes `env` (see the module doc).
pub fn arrange_compound(
    env: &[Envelope],
    clearance: f64,
    spread: f64,
    rng: &mut impl Rng,
) -> Vec<Placement> {
    let k = env.len();
    let w_med = median(env.iter().map(Envelope::width).collect());
    let env = &co_moving(env);
    let mut placed = Placed::new(env, clearance, vec![0.0; k]);
    let order = shuffled(k, rng);
    let mut lane = vec![0usize; k];
    let mut row = vec![0usize; k];
    // The last formation on each arm (0 left, 1 right), and the apex.
    let mut last: [Option<usize>; 2] = [None, None];
    let apex = order[0];
    placed.put(apex, offset_for(&env[apex], [0.0, 0.0]));
    lane[apex] = 1;
    for (i, &f) in order.iter().enumerate().skip(1) {
        let arm = i % 2;
        let side = if arm == 1 { 1.0 } else { -1.0 };
        let prev = last[arm].unwrap_or(apex);
        let cp = placed.centre(prev, placed.offset[prev].expect("placed"));
        let (hp, hf) = (half(&env[prev]), half(&env[f]));
        let angle = rng
            .random_range(COMPOUND_ANGLE_DEG[0]..=COMPOUND_ANGLE_DEG[1])
            .to_radians();
        let gap = clearance + 0.5 * spread * w_med * rng.random_range(0.0..=1.0);
        // Aside by the half widths and the gap; behind at the neighbour angle.
        let mut lateral = hp[0] + hf[0] + gap;
        let at = loop {
            let behind = (lateral / angle.tan()).max(hp[1] + hf[1] + gap);
            let at = offset_for(&env[f], [cp[0] + side * lateral, cp[1] - behind]);
            if placed.clear(f, at) {
                break at;
            }
            lateral += 0.1 * (hp[0] + hf[0]).max(1.0);
        };
        placed.put(f, at);
        lane[f] = 2 * arm;
        row[f] = last[arm].map_or(1, |p| row[p] + 1);
        last[arm] = Some(f);
    }
    placed
        .offset
        .iter()
        .enumerate()
        .map(|(f, o)| Placement {
            offset: o.unwrap_or([0.0, 0.0]),
            lane: lane[f],
            row: row[f],
            height: 0.0,
        })
        .collect()
}

/// Height offsets of `k` formations of the layout, drawn from `rng` (see the module doc).
pub fn heights(layout: SkeinLayout, k: usize, rng: &mut impl Rng) -> Vec<f64> {
    let h = layout.height();
    if h == 0.0 || k < 2 {
        return vec![0.0; k];
    }
    (0..k)
        .map(|_| h * (rng.random_range(0.0..=1.0) + rng.random_range(0.0..=1.0) - 1.0))
        .collect()
}

/// The share of a formation's height offset flown `t` seconds into the steady flight after a
/// take-off: a smootherstep from 0 to 1 over [`HEIGHT_RAMP_S`].
pub fn height_ramp(t: f64) -> f64 {
    let u = (t / HEIGHT_RAMP_S).clamp(0.0, 1.0);
    u * u * u * (u * (6.0 * u - 15.0) + 10.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_box(w: f64, d: f64, wander: f64, n: usize) -> Envelope {
        let windows: Vec<[f64; 4]> = (0..n)
            .map(|j| {
                let s = wander * (j as f64 * 0.3).sin();
                [-w / 2.0 + s, -d, w / 2.0 + s, 0.0]
            })
            .collect();
        Envelope {
            x: [-w / 2.0 - wander, w / 2.0 + wander],
            rear: vec![-d; n],
            front: vec![0.0; n],
            windows,
        }
    }

    fn check(env: &[Envelope], p: &[Placement], clearance: f64) {
        for a in 0..env.len() {
            for b in 0..a {
                for (wa, wb) in env[a].windows.iter().zip(&env[b].windows) {
                    let (oa, ob) = (p[a].offset, p[b].offset);
                    let gx = ((wa[0] + oa[0]) - (wb[2] + ob[0]))
                        .max((wb[0] + ob[0]) - (wa[2] + oa[0]))
                        .max(0.0);
                    let gy = ((wa[1] + oa[1]) - (wb[3] + ob[1]))
                        .max((wb[1] + ob[1]) - (wa[3] + oa[1]))
                        .max(0.0);
                    assert!(gx.hypot(gy) >= clearance - 1e-9);
                }
            }
        }
    }

    #[test]
    fn natural_and_compound_keep_the_clearance_in_every_window() {
        for seed in 0..10 {
            let env: Vec<Envelope> = (0..40)
                .map(|k| env_box(8.0 + (k % 7) as f64, 3.0 + (k % 3) as f64, 2.0, 30))
                .collect();
            let mut rng = crate::rng::seeded(seed);
            check(&env, &arrange_natural(&env, 5.0, 0.5, &mut rng), 5.0);
            check(&env, &arrange_compound(&env, 5.0, 0.5, &mut rng), 5.0);
        }
    }

    #[test]
    fn natural_distances_are_irregular_and_the_compound_is_a_v() {
        let env: Vec<Envelope> = (0..60).map(|_| env_box(10.0, 4.0, 0.0, 4)).collect();
        let p = arrange_natural(&env, 5.0, 0.5, &mut crate::rng::seeded(3));
        let nn: Vec<f64> = (0..p.len())
            .map(|a| {
                (0..p.len())
                    .filter(|&b| b != a)
                    .map(|b| {
                        let (u, v) = (p[a].offset, p[b].offset);
                        (u[0] - v[0]).hypot(u[1] - v[1])
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let mean = nn.iter().sum::<f64>() / nn.len() as f64;
        let sd = (nn.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / nn.len() as f64).sqrt();
        assert!(sd / mean > 0.15, "cv {}", sd / mean);
        let c = arrange_compound(&env, 5.0, 0.5, &mut crate::rng::seeded(3));
        // Every formation but the apex is behind the apex, on its arm's side.
        let apex = c.iter().position(|p| p.row == 0).unwrap();
        for p in &c {
            if p.row > 0 {
                assert!(p.offset[1] < c[apex].offset[1]);
                let side = p.offset[0] - c[apex].offset[0];
                assert_eq!(side > 0.0, p.lane == 2, "{p:?}");
            }
        }
    }

    #[test]
    fn heights_spread_as_said_and_the_ramp_is_smooth() {
        let h = heights(SkeinLayout::Natural, 4000, &mut crate::rng::seeded(1));
        let mean = h.iter().sum::<f64>() / h.len() as f64;
        let sd = (h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / h.len() as f64).sqrt();
        assert!((sd - NATURAL_HEIGHT / 6f64.sqrt()).abs() < 0.05, "{sd}");
        assert!(h.iter().all(|v| v.abs() <= NATURAL_HEIGHT));
        assert_eq!(
            heights(SkeinLayout::Grid, 5, &mut crate::rng::seeded(1)),
            vec![0.0; 5]
        );
        assert_eq!(height_ramp(0.0), 0.0);
        assert_eq!(height_ramp(HEIGHT_RAMP_S), 1.0);
        assert!((height_ramp(HEIGHT_RAMP_S / 2.0) - 0.5).abs() < 1e-12);
    }
}
