//! Each bird relative to its own formation's leader: the formation frame of docs/formats.md §2
//! (`lateral` to the right of the leader's heading, `behind` the leader along it, wingspans) at
//! every frame of a world-frame [`Animation`], and the bird's rank in its formation.
//!
//! With the leader L heading θ (clockwise from +y), the flight direction is d = (sin θ, cos θ)
//! and its right-hand side r = (cos θ, −sin θ); for bird i, `lateral = (p_i − p_L)·r` and
//! `behind = −(p_i − p_L)·d`. The rank counts from the front of the formation: the leader is 0,
//! then its birds by increasing `behind` (ties by index). Works for several formations
//! ([`Animation::formation_of_birds`], [`Animation::leaders`]) and any heading.

use super::Animation;

/// One bird at one frame, relative to its formation's leader.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relative {
    /// Index of the bird's formation (0 for a flock of one formation).
    pub formation: usize,
    /// Whether the bird leads its formation.
    pub leader: bool,
    /// Place in the formation from the front, 0 = the leader.
    pub rank: usize,
    /// Offset to the right of the leader's heading, wingspans.
    pub lateral: f64,
    /// Distance behind the leader along its heading, wingspans.
    pub behind: f64,
}

impl Animation {
    /// Every bird of frame `k` relative to its formation's leader; empty when `k` is out of
    /// range.
    pub fn relative(&self, k: usize) -> Vec<Relative> {
        let of = self.formation_of_birds();
        let leaders = self.leaders();
        self.relative_with(k, &of, &leaders)
    }

    /// The formations' leaders at `t` seconds: `leaders` (at the start of the steady flight,
    /// [`Animation::leaders`]) after every leader change whose manoeuvre is half done by `t`
    /// (the new leader is then ahead of the old).
    pub fn leaders_at(&self, leaders: &[usize], t: f64) -> Vec<usize> {
        let mut out = leaders.to_vec();
        for e in &self.events {
            if e.kind != super::EventKind::LeaderChange || e.t + 0.5 * e.duration > t {
                continue;
            }
            if let [old, new] = e.birds[..] {
                for l in out.iter_mut().filter(|l| **l == old) {
                    *l = new;
                }
            }
        }
        out
    }

    /// [`Animation::relative`] with the formations and leaders computed once by the caller
    /// (leaders at the start; leader changes are applied at each frame's time).
    pub fn relative_with(&self, k: usize, of: &[usize], leaders: &[usize]) -> Vec<Relative> {
        let Some(f) = self.frames.get(k) else {
            return Vec::new();
        };
        let n = self.birds;
        let current = self.leaders_at(leaders, f.t);
        let leaders = current.as_slice();
        let mut out: Vec<Relative> = (0..n)
            .map(|i| {
                let fm = of.get(i).copied().unwrap_or(0);
                let l = leaders
                    .get(fm)
                    .copied()
                    .unwrap_or(0)
                    .min(n.saturating_sub(1));
                let h = f.heading.get(l).copied().unwrap_or(0.0);
                let (dx, dy) = (f.x[i] - f.x[l], f.y[i] - f.y[l]);
                Relative {
                    formation: fm,
                    leader: i == l,
                    rank: 0,
                    lateral: dx * h.cos() - dy * h.sin(),
                    behind: -(dx * h.sin() + dy * h.cos()),
                }
            })
            .collect();
        let formations = of.iter().copied().max().map_or(1, |m| m + 1);
        // Birds by formation in one pass (filtering all birds once per formation was quadratic
        // for a sky of many small formations: 11 111 formations of 100 000 birds took 14 s a
        // frame in `formation report`).
        let mut by_formation: Vec<Vec<usize>> = vec![Vec::new(); formations];
        for (i, r) in out.iter().enumerate() {
            if let Some(m) = by_formation.get_mut(r.formation) {
                m.push(i);
            }
        }
        for mut members in by_formation {
            members.sort_by(|&a, &b| {
                (!out[a].leader)
                    .cmp(&!out[b].leader)
                    .then(out[a].behind.total_cmp(&out[b].behind))
                    .then(a.cmp(&b))
            });
            for (r, &i) in members.iter().enumerate() {
                out[i].rank = r;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::{FormationRecord, Frame};

    fn anim(heading: f64) -> Animation {
        // Leader 0 at the origin; bird 1 one wingspan to its right and two behind, in the
        // leader's own frame, placed in the world for this heading.
        let (d, r) = (
            (heading.sin(), heading.cos()),
            (heading.cos(), -heading.sin()),
        );
        let p1 = (r.0 - 2.0 * d.0, r.1 - 2.0 * d.1);
        let p2 = (-0.5 * r.0 - 1.0 * d.0, -0.5 * r.1 - 1.0 * d.1);
        let mut a = Animation::new(0, 30.0, 1.0, 3);
        a.frames.push(Frame {
            t: 0.0,
            x: vec![0.0, p1.0, p2.0],
            y: vec![0.0, p1.1, p2.1],
            z: vec![0.0; 3],
            heading: vec![heading; 3],
            speed: vec![1.0; 3],
            ..Frame::default()
        });
        a.formations = Some(vec![FormationRecord {
            birds: vec![0, 1, 2],
            leader: 0,
            key_shapes: vec![],
            xi_ranges: None,
            steady_start: None,
        }]);
        a
    }

    #[test]
    fn the_formation_frame_does_not_depend_on_the_heading() {
        for h in [0.0, 0.7, -2.0, 3.1] {
            let r = anim(h).relative(0);
            assert!(r[0].leader && r[0].rank == 0 && r[0].lateral == 0.0);
            assert!((r[1].lateral - 1.0).abs() < 1e-12 && (r[1].behind - 2.0).abs() < 1e-12);
            assert!((r[2].lateral + 0.5).abs() < 1e-12 && (r[2].behind - 1.0).abs() < 1e-12);
            assert_eq!((r[1].rank, r[2].rank), (2, 1));
        }
    }

    #[test]
    fn each_formation_is_measured_from_its_own_leader() {
        let mut a = anim(0.0);
        a.formations = Some(vec![
            FormationRecord {
                birds: vec![0, 2],
                leader: 0,
                key_shapes: vec![],
                xi_ranges: None,
                steady_start: None,
            },
            FormationRecord {
                birds: vec![1],
                leader: 1,
                key_shapes: vec![],
                xi_ranges: None,
                steady_start: None,
            },
        ]);
        let r = a.relative(0);
        assert_eq!((r[1].formation, r[1].leader, r[1].rank), (1, true, 0));
        assert_eq!((r[1].lateral, r[1].behind), (0.0, 0.0));
        assert_eq!((r[2].formation, r[2].rank), (0, 1));
    }
}
