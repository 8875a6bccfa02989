//! Linking detections across frames into tracks with stable ids.
//!
//! Every track predicts its next position with a constant velocity (its own, or, for a track
//! seen once, the flock's: the median velocity of the tracks that have one, or the shift most
//! detections agree on). Detections are assigned to predictions by the minimum-cost assignment
//! (Hungarian algorithm) of squared distances; a pair further apart than the gate (half a
//! wingspan, at least 3 px) is no match. A matched track moves to its detection and blends the
//! new displacement into its velocity (half and half); an unmatched track coasts on its
//! prediction for up to `MAX_MISSED` processed frames and is then closed; an unmatched
//! detection starts a track. Ids are given in the order tracks start, and the tracks that start
//! in the same frame are numbered left to right.
//!
//! Two birds crossing merge into one region for a few frames, too overlapped to be split by
//! its size. The track that lost the assignment is then not coasted out of sight: a track seen
//! `HIDDEN_HITS` times or more whose prediction falls within the gate of a detection another
//! track took is hidden in it, and both birds are placed at their predictions moved together by
//! the detection's centroid minus the predictions' mean (marked `split`, so their merged size
//! does not count as a wingspan). Birds in formation keep a wingspan or so apart, twice the
//! gate: only birds whose silhouettes overlap share a detection.

use super::detect::Blob;

/// Processed frames a track may go unseen before it is closed.
pub const MAX_MISSED: usize = 5;

/// Times a track must have been seen before it may be hidden in another bird's detection.
pub const HIDDEN_HITS: usize = 3;

/// One bird's track.
#[derive(Debug, Clone)]
pub struct Track {
    /// Stable id.
    pub id: usize,
    /// Last position (measured or predicted), pixels.
    pub pos: (f64, f64),
    /// Velocity, pixels per processed frame, once seen twice.
    pub vel: Option<(f64, f64)>,
    /// Processed frames since it was last seen.
    pub missed: usize,
    /// Times it was seen.
    pub hits: usize,
    /// Processed frames in a row it has been hidden in another bird's detection.
    pub hidden: usize,
}

/// The tracker's state between frames.
#[derive(Debug, Default)]
pub struct Tracker {
    /// Open tracks.
    pub tracks: Vec<Track>,
    next_id: usize,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The minimum-cost assignment of detections to predictions (`usize::MAX`: none), costs capped
/// at `(2 gate)²`. A detection and a prediction further apart than that cost the cap whatever
/// they are paired with, so the problem falls apart into the groups linked by nearer pairs, each
/// solved alone (Hungarian): the same optimum, in time cubic in a group's size rather than the
/// frame's.
fn assign(
    blobs: &[Blob],
    pred: &[(f64, f64)],
    gate: f64,
    cost: impl Fn(usize, usize) -> f64,
) -> Vec<usize> {
    let (n, m) = (blobs.len(), pred.len());
    let mut of_blob = vec![usize::MAX; n];
    if n == 0 || m == 0 {
        return of_blob;
    }
    // Union-find over detections 0..n and predictions n..n+m.
    let mut parent: Vec<usize> = (0..n + m).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let reach = 2.0 * gate;
    let grid = Grid::new(blobs, reach);
    for (j, q) in pred.iter().enumerate() {
        grid.each_within(blobs, *q, reach, |i| {
            let (a, b) = (root(&mut parent, i), root(&mut parent, n + j));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        });
    }
    let mut groups: std::collections::BTreeMap<usize, (Vec<usize>, Vec<usize>)> =
        std::collections::BTreeMap::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().0.push(i);
    }
    for j in 0..m {
        let r = root(&mut parent, n + j);
        groups.entry(r).or_default().1.push(j);
    }
    for (rows, cols) in groups.values() {
        if rows.is_empty() || cols.is_empty() {
            continue;
        }
        if rows.len() <= cols.len() {
            let a = crate::annotations::hungarian(rows.len(), cols.len(), |i, j| {
                cost(rows[i], cols[j])
            });
            for (i, &j) in a.iter().enumerate() {
                if j < cols.len() {
                    of_blob[rows[i]] = cols[j];
                }
            }
        } else {
            let a = crate::annotations::hungarian(cols.len(), rows.len(), |j, i| {
                cost(rows[i], cols[j])
            });
            for (j, &i) in a.iter().enumerate() {
                if i < rows.len() {
                    of_blob[rows[i]] = cols[j];
                }
            }
        }
    }
    of_blob
}

/// The detections binned in square cells of one gate, to find those near a point.
struct Grid {
    cell: f64,
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

impl Grid {
    fn new(blobs: &[Blob], cell: f64) -> Grid {
        let cell = cell.max(1e-9);
        let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> =
            std::collections::HashMap::new();
        for (i, b) in blobs.iter().enumerate() {
            cells
                .entry(((b.x / cell).floor() as i64, (b.y / cell).floor() as i64))
                .or_default()
                .push(i);
        }
        Grid { cell, cells }
    }

    /// Calls `f` with every detection within `r` (at most one cell) of `p`.
    fn each_within(&self, blobs: &[Blob], p: (f64, f64), r: f64, mut f: impl FnMut(usize)) {
        let (cx, cy) = (
            (p.0 / self.cell).floor() as i64,
            (p.1 / self.cell).floor() as i64,
        );
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                    for &i in v {
                        if (blobs[i].x - p.0).powi(2) + (blobs[i].y - p.1).powi(2) < r * r {
                            f(i);
                        }
                    }
                }
            }
        }
    }

    /// Whether a detection lies within `r` (at most one cell) of `p`.
    fn any_within(&self, blobs: &[Blob], p: (f64, f64), r: f64) -> bool {
        let (cx, cy) = (
            (p.0 / self.cell).floor() as i64,
            (p.1 / self.cell).floor() as i64,
        );
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                    if v.iter()
                        .any(|&i| (blobs[i].x - p.0).powi(2) + (blobs[i].y - p.1).powi(2) <= r * r)
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

impl Tracker {
    /// The flock's shift per frame for tracks without a velocity of their own.
    fn flock_shift(&self, blobs: &[Blob], gate: f64) -> (f64, f64) {
        let mut vx: Vec<f64> = self
            .tracks
            .iter()
            .filter_map(|t| t.vel.map(|v| v.0))
            .collect();
        let mut vy: Vec<f64> = self
            .tracks
            .iter()
            .filter_map(|t| t.vel.map(|v| v.1))
            .collect();
        if !vx.is_empty() {
            return (median(&mut vx), median(&mut vy));
        }
        // Vote: the candidate shift (a detection minus a track) that brings the most tracks
        // within the gate of some detection; ties to the smaller shift. Every pair's shift is
        // binned in cells of one gate; the fullest cells' pairs are the candidates, each
        // counted exactly over a grid of the detections: pairs plus the tracks times a few
        // candidates, not the tracks squared times the detections squared.
        let cell = gate.max(1e-9);
        let key = |v: (f64, f64)| ((v.0 / cell).floor() as i64, (v.1 / cell).floor() as i64);
        let mut bins: std::collections::HashMap<(i64, i64), usize> =
            std::collections::HashMap::new();
        for t in &self.tracks {
            for b in blobs {
                *bins.entry(key((b.x - t.pos.0, b.y - t.pos.1))).or_default() += 1;
            }
        }
        let mut full: Vec<((i64, i64), usize)> = bins.into_iter().collect();
        full.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        // A shift's votes spread over up to four neighbouring cells: every cell within a few
        // of the fullest count's quarter is looked at.
        let top = full.first().map_or(0, |c| c.1);
        let cells: std::collections::HashSet<(i64, i64)> = full
            .iter()
            .take_while(|c| 4 * c.1 >= top)
            .take(16)
            .map(|c| c.0)
            .collect();
        let grid = Grid::new(blobs, gate);
        let mut tried: std::collections::HashMap<(i64, i64), usize> =
            std::collections::HashMap::new();
        let mut best = ((0.0, 0.0), 0usize, 0.0f64);
        for t in &self.tracks {
            for b in blobs {
                let s = (b.x - t.pos.0, b.y - t.pos.1);
                if !cells.contains(&key(s)) {
                    continue;
                }
                // A few pairs of a cell stand for it (they agree within a gate).
                let n = tried.entry(key(s)).or_default();
                if *n >= 8 {
                    continue;
                }
                *n += 1;
                let votes = self
                    .tracks
                    .iter()
                    .filter(|u| grid.any_within(blobs, (u.pos.0 + s.0, u.pos.1 + s.1), gate))
                    .count();
                let size = s.0.hypot(s.1);
                if votes > best.1 || (votes == best.1 && size < best.2) {
                    best = (s, votes, size);
                }
            }
        }
        best.0
    }

    /// Links this frame's detections; gives each detection's track id, in `blobs` order.
    /// `wingspan` is the frame's bird size in pixels (it sets the gate).
    ///
    /// A bird hidden in another's detection (see the module) is added to `blobs` (marked
    /// `split`) and the detection it shares is moved to its owner's share.
    pub fn step(&mut self, blobs: &mut Vec<Blob>, wingspan: f64) -> Vec<usize> {
        let gate = (0.5 * wingspan).max(3.0);
        let shift = if self.tracks.iter().any(|t| t.vel.is_none()) {
            self.flock_shift(blobs, gate)
        } else {
            (0.0, 0.0)
        };
        let pred: Vec<(f64, f64)> = self
            .tracks
            .iter()
            .map(|t| {
                let v = t.vel.unwrap_or(shift);
                (t.pos.0 + v.0, t.pos.1 + v.1)
            })
            .collect();
        let (n, m) = (blobs.len(), self.tracks.len());
        let cap = 4.0 * gate * gate;
        let cost = |i: usize, j: usize| {
            let d = (blobs[i].x - pred[j].0).powi(2) + (blobs[i].y - pred[j].1).powi(2);
            d.min(cap)
        };
        let of_blob = assign(blobs, &pred, gate, cost);
        let mut matched = vec![false; m];
        let mut owner: Vec<Option<usize>> = vec![None; n];
        for i in 0..n {
            let j = of_blob[i];
            if j != usize::MAX && cost(i, j) <= gate * gate {
                matched[j] = true;
                owner[i] = Some(j);
            }
        }
        // Birds hidden in another's detection: a confirmed track left without a detection
        // whose prediction falls within the gate of a detection another track took (two birds
        // crossing, their silhouettes merged into one region too small to split). It stays
        // where its motion puts it, and the detection's position is shared: each bird at its
        // prediction shifted by the detection's centroid minus the predictions' mean (the
        // centroid of two like silhouettes is the mean of theirs).
        let mut hidden: Vec<(usize, usize)> = Vec::new();
        for j in 0..m {
            let t = &self.tracks[j];
            if matched[j]
                || t.hits < HIDDEN_HITS
                || t.vel.is_none()
                || t.missed > 0
                || t.hidden >= MAX_MISSED
            {
                continue;
            }
            let confirmed = |a: usize| {
                let o = &self.tracks[a];
                o.hits >= HIDDEN_HITS && o.vel.is_some()
            };
            let near = (0..n)
                .filter(|&i| owner[i].is_some_and(confirmed))
                .map(|i| {
                    let d = (blobs[i].x - pred[j].0).powi(2) + (blobs[i].y - pred[j].1).powi(2);
                    (i, d)
                })
                .filter(|&(_, d)| d <= gate * gate)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((i, _)) = near {
                hidden.push((i, j));
            }
        }
        let mut extra: Vec<(Blob, usize)> = Vec::new();
        for i in 0..n {
            let Some(a) = owner[i] else { continue };
            let with: Vec<usize> = hidden.iter().filter(|h| h.0 == i).map(|h| h.1).collect();
            if with.is_empty() {
                continue;
            }
            let k = (with.len() + 1) as f64;
            let mean = with
                .iter()
                .fold(pred[a], |s, &j| (s.0 + pred[j].0, s.1 + pred[j].1));
            let off = (blobs[i].x - mean.0 / k, blobs[i].y - mean.1 / k);
            let shared = Blob {
                split: true,
                ..blobs[i]
            };
            blobs[i] = Blob {
                x: pred[a].0 + off.0,
                y: pred[a].1 + off.1,
                ..shared
            };
            for &j in &with {
                let b = Blob {
                    x: pred[j].0 + off.0,
                    y: pred[j].1 + off.1,
                    ..shared
                };
                let t = &mut self.tracks[j];
                t.pos = (b.x, b.y);
                t.missed = 0;
                t.hits += 1;
                t.hidden += 1;
                matched[j] = true;
                extra.push((b, t.id));
            }
        }
        let mut ids = vec![usize::MAX; n];
        for i in 0..n {
            let Some(j) = owner[i] else { continue };
            let t = &mut self.tracks[j];
            let steps = (t.missed + 1) as f64;
            let d = (
                (blobs[i].x - t.pos.0) / steps,
                (blobs[i].y - t.pos.1) / steps,
            );
            t.vel = Some(match t.vel {
                Some(v) => (0.5 * (v.0 + d.0), 0.5 * (v.1 + d.1)),
                None => d,
            });
            t.pos = (blobs[i].x, blobs[i].y);
            t.missed = 0;
            t.hidden = 0;
            t.hits += 1;
            ids[i] = t.id;
        }
        // Coast or close the unmatched tracks.
        let mut kept = Vec::with_capacity(m);
        for (j, mut t) in std::mem::take(&mut self.tracks).into_iter().enumerate() {
            if !matched[j] {
                t.missed += 1;
                t.pos = pred[j];
                if t.missed > MAX_MISSED {
                    continue;
                }
            }
            kept.push(t);
        }
        self.tracks = kept;
        // New tracks, numbered left to right.
        let mut fresh: Vec<usize> = (0..n).filter(|&i| ids[i] == usize::MAX).collect();
        fresh.sort_by(|&a, &b| blobs[a].x.total_cmp(&blobs[b].x));
        for i in fresh {
            ids[i] = self.next_id;
            self.tracks.push(Track {
                id: self.next_id,
                pos: (blobs[i].x, blobs[i].y),
                vel: None,
                missed: 0,
                hits: 1,
                hidden: 0,
            });
            self.next_id += 1;
        }
        for (b, id) in extra {
            blobs.push(b);
            ids.push(id);
        }
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blob(x: f64, y: f64) -> Blob {
        Blob {
            x,
            y,
            area: 10,
            span: 10.0,
            axis: 0.0,
            snr: 10.0,
            split: false,
        }
    }

    #[test]
    fn a_flock_moving_more_than_its_spacing_keeps_its_ids() {
        // Birds 12 px apart moving 30 px a frame: nearest-neighbour linking would swap them.
        let mut t = Tracker::default();
        let first: Vec<usize> = t.step(
            &mut vec![blob(0.0, 0.0), blob(12.0, 5.0), blob(24.0, 10.0)],
            10.0,
        );
        assert_eq!(first, vec![0, 1, 2]);
        for k in 1..10 {
            let s = 30.0 * k as f64;
            // Listed in another order each frame.
            let ids = t.step(
                &mut vec![blob(24.0 + s, 10.0), blob(s, 0.0), blob(12.0 + s, 5.0)],
                10.0,
            );
            assert_eq!(ids, vec![2, 0, 1], "frame {k}");
        }
    }

    #[test]
    fn a_bird_missed_for_a_frame_keeps_its_id() {
        let mut t = Tracker::default();
        t.step(&mut vec![blob(0.0, 0.0), blob(40.0, 0.0)], 10.0);
        t.step(&mut vec![blob(5.0, 0.0), blob(45.0, 0.0)], 10.0);
        t.step(&mut vec![blob(10.0, 0.0)], 10.0);
        let ids = t.step(&mut vec![blob(55.0, 0.0), blob(15.0, 0.0)], 10.0);
        assert_eq!(ids, vec![1, 0]);
    }

    #[test]
    fn two_birds_merged_while_crossing_keep_their_ids_and_positions() {
        // Two birds 10 px across on crossing paths (one down-right, one up-right), merged into
        // one detection at their centroids' mean for frames 5 and 6.
        let mut t = Tracker::default();
        let at = |k: f64| ((3.0 * k, 2.0 * k), (3.0 * k, 20.0 - 2.0 * k));
        for k in 0..5 {
            let (a, b) = at(k as f64);
            let mut blobs = vec![blob(a.0, a.1), blob(b.0, b.1)];
            assert_eq!(t.step(&mut blobs, 10.0), vec![0, 1], "frame {k}");
        }
        for k in 5..7 {
            let (a, b) = at(k as f64);
            let mut blobs = vec![blob(0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1))];
            let ids = t.step(&mut blobs, 10.0);
            assert_eq!(ids.len(), 2, "frame {k}: both birds");
            for (bl, id) in blobs.iter().zip(&ids) {
                let truth = if *id == 0 { a } else { b };
                assert!(
                    (bl.x - truth.0).hypot(bl.y - truth.1) < 0.5,
                    "frame {k}: bird {id} at {bl:?}, truth {truth:?}"
                );
                assert!(bl.split);
            }
        }
        for k in 7..10 {
            let (a, b) = at(k as f64);
            let mut blobs = vec![blob(b.0, b.1), blob(a.0, a.1)];
            assert_eq!(t.step(&mut blobs, 10.0), vec![1, 0], "frame {k}");
        }
    }

    #[test]
    fn a_bird_that_leaves_is_not_kept_beside_a_neighbour() {
        // Birds a wingspan and more apart: one vanishes; it is not placed into the other.
        let mut t = Tracker::default();
        for k in 0..5 {
            let s = 4.0 * k as f64;
            t.step(&mut vec![blob(s, 0.0), blob(s, 12.0)], 10.0);
        }
        let mut blobs = vec![blob(20.0, 0.0)];
        assert_eq!(t.step(&mut blobs, 10.0), vec![0]);
        assert_eq!(blobs.len(), 1);
    }
}
