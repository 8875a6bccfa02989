//! The target shape of §6.2.1 as a tree of slots: the leader slot, and on each side an arm of
//! slots ordered outward from the leader, so that every slot but the leader's has exactly one
//! successor (the slot its follower takes) and the leader has one per side.
//!
//! Input is the first key shape in the formation frame (`x` right of the flight direction, `y`
//! behind the leader, wingspans). Arms: slots right of the leader (x > x_L) form the right arm,
//! slots left of it the left arm, each ordered by lateral distance from the leader; slots exactly
//! in line with the leader join the shorter arm. The offset of a follower from its reference is
//! the difference of their slot coordinates, so a perfect chain of followers rebuilds the shape.

use glam::DVec2;

use crate::error::{Error, Result};

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
    /// Mean follower offset (|Δx|, Δy) over all arm links, wingspans: the offset a bird uses
    /// when its reference bird is not matched to any slot.
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
        let mut sum = DVec2::ZERO;
        let mut links = 0usize;
        for (a, arm) in arms.iter().enumerate() {
            let side = if a == 0 { Side::Left } else { Side::Right };
            let mut prev = leader;
            for (k, &s) in arm.iter().enumerate() {
                place[s] = Some((side, k));
                let d = points[s] - points[prev];
                sum += DVec2::new(d.x.abs(), d.y);
                links += 1;
                prev = s;
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

    /// The slot a follower of `slot` on `side` takes, if the shape has one: for the leader the
    /// first slot of that arm; for an arm slot the next one outward on its own arm (a bird on an
    /// arm is followed on its own side only).
    pub fn follower_slot(&self, slot: usize, side: Side) -> Option<usize> {
        if slot == self.leader {
            return self.arms[side.index()].first().copied();
        }
        match self.place.get(slot).copied().flatten() {
            Some((s, k)) if s == side => self.arms[side.index()].get(k + 1).copied(),
            _ => None,
        }
    }

    /// Offset of slot `to` from slot `from` in the formation frame: (Δx right, Δy behind).
    pub fn offset(&self, from: usize, to: usize) -> DVec2 {
        self.slots[to] - self.slots[from]
    }
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
}
