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

use super::detect::Blob;

/// Processed frames a track may go unseen before it is closed.
pub const MAX_MISSED: usize = 5;

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
        // within the gate of some detection; ties to the smaller shift.
        let mut best = ((0.0, 0.0), 0usize, 0.0f64);
        for t in &self.tracks {
            for b in blobs {
                let s = (b.x - t.pos.0, b.y - t.pos.1);
                let votes = self
                    .tracks
                    .iter()
                    .filter(|u| {
                        blobs.iter().any(|c| {
                            (c.x - u.pos.0 - s.0).powi(2) + (c.y - u.pos.1 - s.1).powi(2)
                                <= gate * gate
                        })
                    })
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
    pub fn step(&mut self, blobs: &[Blob], wingspan: f64) -> Vec<usize> {
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
        let mut of_blob = vec![usize::MAX; n];
        if n > 0 && m > 0 {
            if n <= m {
                for (i, &j) in crate::annotations::hungarian(n, m, cost).iter().enumerate() {
                    of_blob[i] = j;
                }
            } else {
                for (j, &i) in crate::annotations::hungarian(m, n, |j, i| cost(i, j))
                    .iter()
                    .enumerate()
                {
                    of_blob[i] = j;
                }
            }
        }
        let mut matched = vec![false; m];
        let mut ids = vec![usize::MAX; n];
        for i in 0..n {
            let j = of_blob[i];
            if j == usize::MAX || cost(i, j) > gate * gate {
                continue;
            }
            matched[j] = true;
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
            });
            self.next_id += 1;
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
        let first: Vec<usize> = t.step(&[blob(0.0, 0.0), blob(12.0, 5.0), blob(24.0, 10.0)], 10.0);
        assert_eq!(first, vec![0, 1, 2]);
        for k in 1..10 {
            let s = 30.0 * k as f64;
            // Listed in another order each frame.
            let ids = t.step(
                &[blob(24.0 + s, 10.0), blob(s, 0.0), blob(12.0 + s, 5.0)],
                10.0,
            );
            assert_eq!(ids, vec![2, 0, 1], "frame {k}");
        }
    }

    #[test]
    fn a_bird_missed_for_a_frame_keeps_its_id() {
        let mut t = Tracker::default();
        t.step(&[blob(0.0, 0.0), blob(40.0, 0.0)], 10.0);
        t.step(&[blob(5.0, 0.0), blob(45.0, 0.0)], 10.0);
        t.step(&[blob(10.0, 0.0)], 10.0);
        let ids = t.step(&[blob(55.0, 0.0), blob(15.0, 0.0)], 10.0);
        assert_eq!(ids, vec![1, 0]);
    }
}
