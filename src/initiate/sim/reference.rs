//! The reference bird and side (§6 "perception"): which visible bird a bird follows and on which
//! side of it, under the target shape's correspondence.

use super::*;

impl Simulation {
    /// Which follower slot of `j` on `side` bird `i` may take, if any. `j` must be matched (an
    /// unmatched bird gives no consistent target, and birds following each other in a cycle
    /// never reach the flock) and its slot must have a follower slot on that side (capacity: the
    /// tail of an arm has none); a follower slot is refused when a visible bird that already takes
    /// it is within the separation distance and nearer its target (separation drive, §6.2.2).
    /// Among the free ones, the bird keeps the one it holds, else takes the one whose target is
    /// nearest.
    pub(super) fn acceptable(
        &self,
        i: usize,
        j: usize,
        side: Side,
        visible: &[usize],
    ) -> Option<usize> {
        let f = &self.flock;
        let sj = f.slot[j]?;
        let mut best: Option<(f64, usize)> = None;
        for &c in self.target.followers(sj, side) {
            let t = self.target_point(j, self.target.offset(sj, c));
            let my = (f.pos[i] - t).length();
            // A bird that does not take the slot yet must be nearer than a holder by a margin to
            // claim it, so that birds at the tail of an arm do not trade places forever.
            let holds =
                f.reference[i] == Some(j) && f.side[i] == Some(side) && f.slot[i] == Some(c);
            let margin = if holds { 0.0 } else { SLOT_CLAIM_MARGIN };
            // Birds that take slot `c` (a short list, from the per-decision table), of those
            // the visible ones (`visible` is sorted).
            let holders = &self.holders[self.holder_start[c]..self.holder_start[c + 1]];
            let taken = holders.iter().any(|&k| {
                k != i
                    && visible.binary_search(&k).is_ok()
                    && f.reference[k] == Some(j)
                    && f.side[k] == Some(side)
                    && f.slot[k] == Some(c)
                    && ((f.pos[k] - f.pos[i]).length() < self.params.opts.separation_distance
                        || (f.pos[k] - t).length() < SETTLED_DISTANCE)
                    && (f.pos[k] - t).length() < my + margin
            });
            if taken {
                continue;
            }
            let score = if holds { f64::NEG_INFINITY } else { my };
            if best.map_or(true, |b| score < b.0) {
                best = Some((score, c));
            }
        }
        best.map(|b| b.1)
    }

    /// Side rule of §6.2.1 for bird `i` following `j`: the reference's side if it has one (it is
    /// matched to an arm, or has chosen a side itself), else by relative position.
    pub(super) fn sides_for(&self, i: usize, j: usize) -> [Option<Side>; 2] {
        let f = &self.flock;
        let dj = self.dir_of(j);
        let geometric = if (f.pos[i] - f.pos[j]).dot(DVec2::new(dj.y, -dj.x)) > 0.0 {
            Side::Right
        } else {
            Side::Left
        };
        if j == f.leader {
            return [Some(geometric), Some(geometric.other())];
        }
        let own = match f.slot[j] {
            Some(sj) => self.target.side_of(sj),
            None => f.side[j],
        };
        [Some(own.unwrap_or(geometric)), None]
    }

    /// Reference bird, side and follower slot of bird `i` among its `visible` flockmates, and
    /// the steps since the reference was last seen. The current reference is kept while it stays
    /// acceptable and is visible, or hidden for no more than the reference memory (a bird does not
    /// forget the bird it follows when another passes in front of it for a moment).
    pub(super) fn choose(&self, i: usize, visible: &[usize]) -> Option<(usize, Side, usize, u32)> {
        let f = &self.flock;
        if self.params.opts.sticky_reference {
            if let (Some(j), Some(side)) = (f.reference[i], f.side[i]) {
                let seen = visible.contains(&j);
                let remembered = seen || f.unseen[i] < self.params.reference_memory;
                if remembered && self.sides_for(i, j).contains(&Some(side)) {
                    if let Some(c) = self.acceptable(i, j, side, visible) {
                        let unseen = if seen { 0 } else { f.unseen[i] + 1 };
                        return Some((j, side, c, unseen));
                    }
                }
            }
        }
        let mut chosen = None;
        let reference = choose_reference(
            i,
            visible,
            &f.pos,
            f.heading[i],
            self.params.opts.perception.reference_cone,
            |j| {
                for side in self.sides_for(i, j).into_iter().flatten() {
                    if let Some(c) = self.acceptable(i, j, side, visible) {
                        chosen = Some((side, c));
                        return true;
                    }
                }
                false
            },
        );
        reference.zip(chosen).map(|(j, (side, c))| (j, side, c, 0))
    }
}
