//! The target shape of §6.2.1 as a tree of slots: the leader slot, and on each side an arm of
//! slots ordered outward from the leader; every arm slot follows a *reference slot* nearer the
//! leader on its own arm (or the leader itself), which is the slot its bird's reference bird
//! holds when the flock is in formation.
//!
//! Input is the first key shape in the formation frame (`x` right of the flight direction, `y`
//! behind the leader, wingspans). Arms: slots right of the leader (x > x_L) form the right arm,
//! slots left of it the left arm, each ordered by lateral distance from the leader; slots exactly
//! in line with the leader join the shorter arm. The reference slot of an arm slot is the next
//! slot inward on its arm (the paper's chain: every bird followed by at most one) when a bird in
//! the slot can see it, i.e. it lies at most [`MAX_LINK_BEARING`] from straight ahead; otherwise
//! the nearest slot it can see among the leader and the inner slots of its arm (the leader,
//! front-most, always qualifies). On a clean V, U or echelon every arm is a chain; on a real key
//! shape an outlier behind the line hangs off it as a branch (the next slot skips it), the slot
//! after an outlier ahead of the line follows the outlier, and no bird has to follow one behind
//! its back.
//! The offset of a follower from its reference is the difference of their slot coordinates, so
//! a perfect tree of followers rebuilds the shape.

use glam::DVec2;

use crate::error::{Error, Result};

/// Largest bearing of a slot's reference slot, seen from the slot along the flight direction,
/// radians (100°: ahead, abreast, or a little behind abreast). Birds see their reference within
/// their visual field only if this bearing is inside it; see [`TargetShape::required_field`].
pub const MAX_LINK_BEARING: f64 = 100.0 * std::f64::consts::PI / 180.0;

/// Left or right of the reference bird, seen along its flight direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// Left arm (x < x_leader).
    Left,
    /// Right arm (x > x_leader).
    Right,
}

impl Side {
    /// Index into [`TargetShape::arms`]: 0 for left, 1 for right.
    pub fn index(self) -> usize {
        match self {
            Side::Left => 0,
            Side::Right => 1,
        }
    }

    /// The other side.
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// The target shape as slots in arms.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetShape {
    /// Slot positions, formation frame (x right, y behind the leader), wingspans; slot `s` is bird
    /// `s` of the key shape.
    pub slots: Vec<DVec2>,
    /// The leader slot (front-most: smallest y).
    pub leader: usize,
    /// `arms[0]` left, `arms[1]` right: slot indices from the leader outward.
    pub arms: [Vec<usize>; 2],
    /// For every slot, its arm and position in the arm (`None` for the leader).
    pub place: Vec<Option<(Side, usize)>>,
    /// For every slot, its reference slot (`None` for the leader).
    pub parent: Vec<Option<usize>>,
    /// For every slot, the slots that follow it, `[left, right]`, in arm order (an arm slot is
    /// followed on its own side only; the leader on both).
    pub children: Vec<[Vec<usize>; 2]>,
    /// Mean follower offset (|Δx|, Δy) over all links, wingspans (informational; a bird never
    /// follows an unmatched reference bird).
    pub mean_offset: DVec2,
}

impl TargetShape {
    /// Builds the slot tree of a key shape given as formation-frame points (wingspans).
    pub fn new(points: &[DVec2]) -> Result<TargetShape> {
        if points.is_empty() {
            return Err(Error::parameter(
                "key_shapes[0]",
                "the key shape has no birds",
            ));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(Error::parameter(
                format!("key_shapes[0].birds[{i}]"),
                "not a finite number",
            ));
        }
        let leader = points
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.y.total_cmp(&b.1.y).then(a.0.cmp(&b.0)))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let xl = points[leader].x;
        let mut arms: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let mut centre = Vec::new();
        for (s, p) in points.iter().enumerate() {
            if s == leader {
                continue;
            }
            if p.x > xl {
                arms[1].push(s);
            } else if p.x < xl {
                arms[0].push(s);
            } else {
                centre.push(s);
            }
        }
        for s in centre {
            let a = if arms[0].len() <= arms[1].len() { 0 } else { 1 };
            arms[a].push(s);
        }
        for arm in arms.iter_mut() {
            arm.sort_by(|&a, &b| {
                (points[a].x - xl)
                    .abs()
                    .total_cmp(&(points[b].x - xl).abs())
                    .then(points[a].y.total_cmp(&points[b].y))
                    .then(a.cmp(&b))
            });
        }
        let mut place = vec![None; points.len()];
        let mut parent = vec![None; points.len()];
        let mut children: Vec<[Vec<usize>; 2]> = vec![[Vec::new(), Vec::new()]; points.len()];
        let mut sum = DVec2::ZERO;
        let mut links = 0usize;
        for (a, arm) in arms.iter().enumerate() {
            let side = if a == 0 { Side::Left } else { Side::Right };
            for (k, &s) in arm.iter().enumerate() {
                place[s] = Some((side, k));
                // The previous slot of the arm (the paper's chain) if a bird in this slot can see
                // it, else the nearest visible one among the leader and the inner slots of the
                // arm (ties to the one nearer the leader). The leader, front-most, is always
                // visible.
                let prev = if k == 0 { leader } else { arm[k - 1] };
                let p = if link_bearing(points[s], points[prev]) <= MAX_LINK_BEARING {
                    prev
                } else {
                    let mut best = (leader, (points[leader] - points[s]).length());
                    for &c in &arm[..k] {
                        let d = (points[c] - points[s]).length();
                        if link_bearing(points[s], points[c]) <= MAX_LINK_BEARING && d < best.1 {
                            best = (c, d);
                        }
                    }
                    best.0
                };
                parent[s] = Some(p);
                children[p][a].push(s);
                let d = points[s] - points[p];
                sum += DVec2::new(d.x.abs(), d.y);
                links += 1;
            }
        }
        let mean_offset = if links > 0 {
            sum / links as f64
        } else {
            DVec2::new(1.0, 0.5)
        };
        Ok(TargetShape {
            slots: points.to_vec(),
            leader,
            arms,
            place,
            parent,
            children,
            mean_offset,
        })
    }

    /// Number of slots.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when there are no slots.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// The arm a slot belongs to (`None` for the leader).
    pub fn side_of(&self, slot: usize) -> Option<Side> {
        self.place.get(slot).copied().flatten().map(|p| p.0)
    }

    /// The slots a follower of `slot` on `side` may take, in arm order: for the leader the slots
    /// of that arm that follow it, for an arm slot those that follow it on its own arm (empty
    /// for the other side, and for the tail of an arm).
    pub fn followers(&self, slot: usize, side: Side) -> &[usize] {
        self.children
            .get(slot)
            .map_or(&[][..], |c| c[side.index()].as_slice())
    }

    /// The first slot following `slot` on `side`, if any (on a chain-shaped arm, the only one).
    pub fn follower_slot(&self, slot: usize, side: Side) -> Option<usize> {
        self.followers(slot, side).first().copied()
    }

    /// The largest bearing, over all slots, of a slot's reference slot seen from the slot along
    /// the flight direction, radians (0 for a lone leader).
    pub fn max_link_bearing(&self) -> f64 {
        (0..self.len())
            .filter_map(|s| self.parent[s].map(|p| link_bearing(self.slots[s], self.slots[p])))
            .fold(0.0, f64::max)
    }

    /// The visual field per eye (radians) a bird needs to see its reference bird from every slot
    /// with `margin` radians to spare: the largest link bearing plus the margin, capped at π.
    pub fn required_field(&self, margin: f64) -> f64 {
        (self.max_link_bearing() + margin).min(std::f64::consts::PI)
    }

    /// Offset of slot `to` from slot `from` in the formation frame: (Δx right, Δy behind).
    pub fn offset(&self, from: usize, to: usize) -> DVec2 {
        self.slots[to] - self.slots[from]
    }
}

/// Bearing of the slot at `to` seen from the slot at `from` when the flock flies in formation
/// (formation frame: straight ahead is −y), radians in [0, π].
pub fn link_bearing(from: DVec2, to: DVec2) -> f64 {
    let q = to - from;
    q.x.abs().atan2(-q.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn v_shape_arms() {
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(-1.0, 0.5),
            DVec2::new(1.0, 0.6),
            DVec2::new(-2.0, 1.0),
            DVec2::new(2.1, 1.2),
        ];
        let t = TargetShape::new(&pts).unwrap();
        assert_eq!(t.leader, 0);
        assert_eq!(t.arms, [vec![1, 3], vec![2, 4]]);
        assert_eq!(t.follower_slot(0, Side::Left), Some(1));
        assert_eq!(t.follower_slot(0, Side::Right), Some(2));
        assert_eq!(t.follower_slot(1, Side::Left), Some(3));
        assert_eq!(t.follower_slot(1, Side::Right), None);
        assert_eq!(t.follower_slot(3, Side::Left), None);
        assert!((t.offset(2, 4) - DVec2::new(1.1, 0.6)).length() < 1e-12);
        // Chaining offsets from the leader rebuilds every slot.
        for (a, arm) in t.arms.iter().enumerate() {
            let mut pos = t.slots[t.leader];
            let mut prev = t.leader;
            for &s in arm {
                pos += t.offset(prev, s);
                assert!((pos - t.slots[s]).length() < 1e-12, "arm {a}");
                prev = s;
            }
        }
    }

    #[test]
    fn outlier_behind_the_line_hangs_off_as_a_branch() {
        // Right arm: 1, 2, then 3 lies 2.7 behind the line and 4 is back on it.
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(2.0, 1.0),
            DVec2::new(3.0, 4.2),
            DVec2::new(4.0, 2.0),
            DVec2::new(5.0, 2.5),
        ];
        let t = TargetShape::new(&pts).unwrap();
        assert_eq!(t.arms[1], vec![1, 2, 3, 4, 5]);
        assert_eq!(t.parent[3], Some(2));
        // From slot 4, slot 3 is behind its back: it follows 2, which has two followers.
        assert_eq!(t.parent[4], Some(2));
        assert_eq!(t.followers(2, Side::Right), &[3, 4]);
        assert_eq!(t.follower_slot(3, Side::Right), None);
        assert_eq!(t.parent[5], Some(4));
        assert!(t.max_link_bearing() <= MAX_LINK_BEARING);
    }

    #[test]
    fn slot_after_an_outlier_ahead_follows_the_outlier() {
        // Right arm: 1..3 on a line, 4 is 1.5 ahead of it, 5 back on the line.
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.5),
            DVec2::new(2.0, 1.0),
            DVec2::new(3.0, 1.5),
            DVec2::new(4.0, 0.5),
            DVec2::new(5.0, 2.5),
        ];
        let t = TargetShape::new(&pts).unwrap();
        // Slots 3 and 2 are behind slot 4's back (135° and 104°): 4 follows the nearest slot it
        // can see, 1 (abreast), and the chain goes on through the outlier.
        assert_eq!(t.parent[4], Some(1));
        assert_eq!(t.parent[5], Some(4));
        assert_eq!(t.followers(1, Side::Right), &[2, 4]);
        for s in 1..pts.len() {
            let p = t.parent[s].unwrap();
            assert!(link_bearing(pts[s], pts[p]) <= MAX_LINK_BEARING, "slot {s}");
        }
    }

    #[test]
    fn abreast_neighbours_need_a_wider_field() {
        // A flat J front: the second bird is 0.001 ahead of the first on the right arm.
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.1),
            DVec2::new(2.0, 0.099),
            DVec2::new(3.0, 0.6),
        ];
        let t = TargetShape::new(&pts).unwrap();
        assert_eq!(t.parent[2], Some(1));
        let need = t.required_field(0.0);
        assert!(need > std::f64::consts::FRAC_PI_2 && need < 1.6, "{need}");
        // A clean V needs less than the paper's 90° even with a 15° margin.
        let v = TargetShape::new(&[
            DVec2::new(0.0, 0.0),
            DVec2::new(-1.0, 0.6),
            DVec2::new(1.0, 0.6),
        ])
        .unwrap();
        assert!(v.required_field(15f64.to_radians()) < std::f64::consts::FRAC_PI_2);
    }
}
