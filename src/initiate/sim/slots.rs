//! Slots in the target shape: matching birds to slots, and the measures of how far the flock is
//! from its formation (in formation, birds in slot, stray distance, closest pair).

use super::*;

/// The slot of every bird and the leader for start positions `pos` (wingspans) of a flock
/// flying along `heading`: the leader is the front-most bird of the middle half across the
/// heading, and with `max_offset` (wingspans) of those at most that far across from the middle
/// bird (the middle bird itself when none is); the other birds take the other slots in the order
/// of their positions across the heading (the leftmost bird the leftmost slot, ties along the
/// heading), so that no two birds cross sideways on their way to their slots.
pub fn assign_slots(
    target: &TargetShape,
    pos: &[DVec2],
    heading: f64,
    max_offset: Option<f64>,
) -> (Vec<usize>, usize) {
    let n = pos.len().min(target.len());
    let dc = direction(heading);
    let rc = right_of(heading);
    let across = |i: usize| pos[i].dot(rc);
    let along = |i: usize| pos[i].dot(dc);
    let mut by_x: Vec<usize> = (0..n).collect();
    by_x.sort_by(|&a, &b| across(a).total_cmp(&across(b)).then(a.cmp(&b)));
    let (lo, hi) = (n / 4, (n - n / 4).max(n / 4 + 1).min(n));
    let middle = by_x.get(n / 2).copied().unwrap_or(0);
    let near_middle = |i: usize| {
        i == middle
            || match max_offset {
                Some(m) => (across(i) - across(middle)).abs() <= m,
                None => true,
            }
    };
    let leader = by_x[lo..hi]
        .iter()
        .copied()
        .filter(|&i| near_middle(i))
        .max_by(|&a, &b| along(a).total_cmp(&along(b)).then(b.cmp(&a)))
        .unwrap_or(0);
    let mut slots: Vec<usize> = (0..target.len()).filter(|&s| s != target.leader).collect();
    slots.sort_by(|&a, &b| {
        let (pa, pb) = (target.slots[a], target.slots[b]);
        pa.x.total_cmp(&pb.x)
            .then(pa.y.total_cmp(&pb.y))
            .then(a.cmp(&b))
    });
    let mut slot = vec![target.leader; pos.len()];
    let others = by_x.iter().copied().filter(|&i| i != leader);
    for (i, s) in others.zip(slots) {
        slot[i] = s;
    }
    (slot, leader)
}

/// Convergence tolerances of [`Simulation::in_formation`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Distance from the slot and from the cruise altitude, wingspans.
    pub distance: f64,
    /// Heading difference, radians.
    pub heading: f64,
    /// Speed difference, fraction of the cruise speed.
    pub speed: f64,
    /// Turn rate, radians per second.
    pub turn_rate: f64,
    /// Acceleration, wingspans per second squared.
    pub accel: f64,
    /// Climb rate, wingspans per second.
    pub climb: f64,
}

/// Smallest distance between two points, wingspans (∞ for fewer than two). Sort-and-sweep on x.
pub fn min_pair_distance(pos: &[DVec3]) -> f64 {
    let mut order: Vec<usize> = (0..pos.len()).collect();
    order.sort_unstable_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x));
    let mut best = f64::INFINITY;
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if pos[b].x - pos[a].x >= best {
                break;
            }
            best = best.min((pos[b] - pos[a]).length());
        }
    }
    best
}

impl Simulation {
    /// §6.2.1 correspondence: the leader takes the leader slot; a bird whose reference bird is
    /// matched takes the slot that follows its reference's slot on its side (the one it aims for
    /// where the tree branches, else the first). Birds in cycles, with unmatched references, or
    /// on a full arm stay unmatched. Several birds may share a slot.
    pub fn match_slots(&mut self) {
        let f = &mut self.flock;
        let n = f.pos.len();
        // 0 = unknown, 1 = on the current walk, 2 = resolved.
        let mut state = vec![0u8; n];
        for s in f.slot.iter_mut() {
            *s = None;
        }
        if n == 0 {
            return;
        }
        f.slot[f.leader] = Some(self.target.leader);
        state[f.leader] = 2;
        let mut path = Vec::new();
        for start in 0..n {
            path.clear();
            let mut i = start;
            // Walk up the reference chain until a resolved bird, a cycle, or no reference.
            let base = loop {
                if state[i] == 2 {
                    break f.slot[i];
                }
                if state[i] == 1 {
                    break None;
                }
                state[i] = 1;
                path.push(i);
                match f.reference[i] {
                    Some(j) if j < n => i = j,
                    _ => break None,
                }
            };
            // Assign back down the walk.
            let mut s = base;
            for &b in path.iter().rev() {
                s = match (s, f.side[b]) {
                    (Some(sj), Some(side)) if f.reference[b].is_some() => {
                        let fl = self.target.followers(sj, side);
                        match f.branch[b] {
                            Some(c) if fl.contains(&c) => Some(c),
                            _ => fl.first().copied(),
                        }
                    }
                    _ => None,
                };
                f.slot[b] = s;
                state[b] = 2;
            }
        }
    }

    /// Positions of the slots in the world if the leader were exactly in its slot and the flock
    /// flew along the cruise heading: S_s = P_L + (x_s − x_L) r_c − (y_s − y_L) d_c.
    pub fn slot_positions(&self) -> Vec<DVec2> {
        let p = &self.params;
        let dc = direction(p.cruise_heading);
        let rc = right_of(p.cruise_heading);
        let l = self.flock.pos[self.flock.leader];
        let sl = self.target.slots[self.target.leader];
        self.target
            .slots
            .iter()
            .map(|s| l + rc * (s.x - sl.x) - dc * (s.y - sl.y))
            .collect()
    }

    /// The convergence test at one instant: every bird is airborne, the matching is one-to-one
    /// and every bird is within `tol.distance` wingspans of its slot (and of the cruise
    /// altitude), within `tol.heading` radians of the cruise heading, within `tol.speed`
    /// (fraction) of the cruise speed, and flying steadily (turn rate, acceleration and climb
    /// rate small, so that the hand-over to the steady flight has no jerk).
    pub fn in_formation(&self, tol: &Tolerances) -> bool {
        self.formed(tol) && self.at_cruise_height(tol)
    }

    /// The convergence test in the horizontal alone (the V is formed, whatever the height):
    /// [`Self::in_formation`] without its altitude and climb-rate conditions.
    pub fn formed(&self, tol: &Tolerances) -> bool {
        let n = self.len();
        let f = &self.flock;
        if !self.all_airborne() {
            return false;
        }
        let mut taken = vec![false; n];
        for s in &f.slot {
            match s {
                Some(s) if *s < n && !taken[*s] => taken[*s] = true,
                _ => return false,
            }
        }
        let slots = self.slot_positions();
        let p = &self.params;
        (0..n).all(|i| {
            let s = f.slot[i].unwrap_or(0);
            (f.pos[i] - slots[s]).length() <= tol.distance
                && wrap_angle(f.heading[i] - p.cruise_heading).abs() <= tol.heading
                && (f.speed[i] - p.cruise_speed).abs() <= tol.speed * p.cruise_speed
                && f.turn_rate[i].abs() <= tol.turn_rate
                && f.accel[i].abs() <= tol.accel
        })
    }

    /// The height part of the convergence test: every bird is airborne, within `tol.distance`
    /// wingspans of the cruise altitude and levelled off (climb rate within `tol.climb`).
    pub fn at_cruise_height(&self, tol: &Tolerances) -> bool {
        let f = &self.flock;
        let p = &self.params;
        self.all_airborne()
            && (0..self.len()).all(|i| {
                (f.z[i] - p.opts.cruise_altitude).abs() <= tol.distance
                    && f.climb[i].abs() <= tol.climb
            })
    }

    /// Number of birds within `tolerance` of their (uniquely held) slot.
    pub fn birds_in_slot(&self, tolerance: f64) -> usize {
        let slots = self.slot_positions();
        let f = &self.flock;
        let mut count = vec![0usize; self.len()];
        for s in f.slot.iter().flatten() {
            if let Some(c) = count.get_mut(*s) {
                *c += 1;
            }
        }
        (0..self.len())
            .filter(|&i| match f.slot[i] {
                Some(s) => count[s] == 1 && (f.pos[i] - slots[s]).length() <= tolerance,
                None => false,
            })
            .count()
    }

    /// Largest distance of a bird beyond the formed flock: its horizontal distance from the
    /// nearest slot position (slots placed behind the current leader), wingspans.
    pub fn stray_distance(&self) -> f64 {
        let slots = self.slot_positions();
        let mut grid = Grid::default();
        let all: Vec<usize> = (0..slots.len()).collect();
        grid.build(&slots, &all, 8.0);
        let mut out = Vec::new();
        let mut worst = 0.0f64;
        for &p in &self.flock.pos {
            // Slots within a growing radius; the first hit bounds the nearest.
            let mut r = 8.0;
            let d = loop {
                grid.within(&slots, p, r, &mut out);
                if let Some(d) = out
                    .iter()
                    .map(|&s| (slots[s] - p).length())
                    .reduce(f64::min)
                {
                    break d;
                }
                r *= 2.0;
                if r > 1e7 {
                    break r;
                }
            };
            worst = worst.max(d);
        }
        worst
    }

    /// Smallest 3-D distance between two birds now, wingspans (∞ for fewer than two birds).
    pub fn min_distance(&self) -> f64 {
        let f = &self.flock;
        let pts: Vec<DVec3> = (0..self.len())
            .map(|i| DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]))
            .collect();
        min_pair_distance(&pts)
    }
}
