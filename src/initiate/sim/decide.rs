//! One decision of every departed bird per reaction time (Jacobi update: every decision reads the
//! previous state only, so the result does not depend on the number of threads).

use super::*;

impl Simulation {
    /// One decision of every bird from the current state (Jacobi: all read the same state).
    pub(super) fn decide_all(&mut self) {
        let n = self.len();
        let p = self.params.clone();
        self.update_departed();
        if self.departed.is_empty() {
            return;
        }
        let dc = direction(p.cruise_heading);
        // The leader is the front-most departed bird (with hysteresis against flip-flopping);
        // with assigned slots it is the one of the leader slot throughout.
        let lead = self.flock.leader;
        if let Some(front) = self.front_most(dc).filter(|_| !p.opts.assign_slots) {
            let lead_gone = self.flock.phase[lead] == Phase::Waiting;
            if front != lead
                && (lead_gone
                    || (self.flock.pos[front] - self.flock.pos[lead]).dot(dc)
                        > p.opts.leader_hysteresis)
            {
                self.flock.leader = front;
                self.leader_changes += 1;
                self.match_slots();
            }
        }
        self.build_holders();
        self.slot_pos = self.slot_positions();
        let lead = self.flock.leader;
        self.lead_vel = direction(self.flock.heading[lead]) * self.flock.speed[lead];
        let mut err = std::mem::take(&mut self.slot_err);
        err.clear();
        err.extend((0..n).map(|i| match self.flock.slot[i] {
            Some(s) if s < self.slot_pos.len() => (self.flock.pos[i] - self.slot_pos[s]).length(),
            _ => f64::INFINITY,
        }));
        self.slot_err = err;
        let mut vel = std::mem::take(&mut self.vel);
        vel.clear();
        vel.extend((0..n).map(|i| {
            let h = direction(self.flock.heading[i]) * self.flock.speed[i];
            DVec3::new(h.x, h.y, self.flock.climb[i])
        }));
        self.vel = vel;
        let mut dir = std::mem::take(&mut self.dir);
        dir.clear();
        dir.extend(self.flock.heading.iter().map(|&h| direction(h)));
        self.dir = dir;
        // One grid for perception and avoidance: cells of the avoidance range, perception
        // queries cover as many cells as the visual range needs.
        let mut grid = std::mem::take(&mut self.grid);
        let all: Vec<usize> = (0..n).collect();
        grid.build(
            &self.flock.pos,
            &all,
            p.opts.avoid_range.max(p.opts.visual_range / 4.0),
        );
        self.grid = grid;
        let mut decisions = std::mem::take(&mut self.decisions);
        decisions.clear();
        decisions.resize(n, Decision::default());
        let threads = if self.departed.len() >= PARALLEL_MIN_BIRDS {
            std::thread::available_parallelism().map_or(1, |t| t.get().min(8))
        } else {
            1
        };
        if threads <= 1 {
            let mut perceiver = std::mem::take(&mut self.perceiver);
            let mut visible = std::mem::take(&mut self.visible);
            let mut near = std::mem::take(&mut self.near);
            for (i, d) in decisions.iter_mut().enumerate() {
                if self.flock.phase[i] == Phase::Airborne {
                    *d = self.decide(i, &mut perceiver, &mut visible, &mut near);
                }
            }
            self.perceiver = perceiver;
            self.visible = visible;
            self.near = near;
        } else {
            let chunk = n.div_ceil(threads);
            let this = &*self;
            std::thread::scope(|scope| {
                for (c, out) in decisions.chunks_mut(chunk).enumerate() {
                    scope.spawn(move || {
                        let mut perceiver = Perceiver::new();
                        let mut visible = Vec::new();
                        let mut near = Vec::new();
                        for (k, d) in out.iter_mut().enumerate() {
                            let i = c * chunk + k;
                            if this.flock.phase[i] == Phase::Airborne {
                                *d = this.decide(i, &mut perceiver, &mut visible, &mut near);
                            }
                        }
                    });
                }
            });
        }
        let f = &mut self.flock;
        for (i, d) in decisions.iter().enumerate() {
            if f.phase[i] != Phase::Airborne {
                continue;
            }
            f.request[i] = (d.turn_rate, d.speed);
            f.alt_offset[i] = d.alt_offset;
            self.alt_floor[i] = d.alt_floor;
            self.alt_ceiling[i] = d.alt_ceiling;
            self.next_reference[i] = d.reference;
            self.next_side[i] = d.side;
            self.next_branch[i] = d.branch;
            self.next_unseen[i] = d.unseen;
        }
        for i in 0..n {
            if f.phase[i] != Phase::Airborne {
                self.next_reference[i] = None;
                self.next_side[i] = None;
                self.next_branch[i] = None;
                self.next_unseen[i] = 0;
            }
        }
        self.decisions = decisions;
        std::mem::swap(&mut f.reference, &mut self.next_reference);
        std::mem::swap(&mut f.side, &mut self.next_side);
        std::mem::swap(&mut f.branch, &mut self.next_branch);
        std::mem::swap(&mut f.unseen, &mut self.next_unseen);
        if !p.opts.assign_slots {
            self.match_slots();
        }
    }

    /// The table of birds by slot the decisions read (counting sort, O(N)).
    pub(super) fn build_holders(&mut self) {
        let slots = self.target.len();
        self.holder_start.clear();
        self.holder_start.resize(slots + 1, 0);
        for s in self.flock.slot.iter().flatten() {
            if *s < slots {
                self.holder_start[*s + 1] += 1;
            }
        }
        for s in 0..slots {
            self.holder_start[s + 1] += self.holder_start[s];
        }
        self.holders.clear();
        self.holders.resize(self.holder_start[slots], 0);
        let mut fill = self.holder_start.clone();
        for (i, s) in self.flock.slot.iter().enumerate() {
            if let Some(s) = *s {
                if s < slots {
                    self.holders[fill[s]] = i;
                    fill[s] += 1;
                }
            }
        }
    }

    /// The decision of airborne bird `i`, from the current state only.
    pub(super) fn decide(
        &self,
        i: usize,
        perceiver: &mut Perceiver,
        visible: &mut Vec<usize>,
        near: &mut Vec<usize>,
    ) -> Decision {
        let p = &self.params;
        let f = &self.flock;
        let tau = p.opts.reaction_time;
        let mut unseen = 0;
        let (turn, want_speed, reference, side, branch) = if i == f.leader {
            let dd = wrap_angle(p.cruise_heading - f.heading[i]);
            // While flockmates are still on the ground the leader flies at the gathering speed
            // (a fraction of the cruise speed), so that the last to leave is not left far behind.
            // From the air, it also waits while a flockmate is still turning round (heading
            // more than 90° off the cruise heading): flown away at cruise speed, the leader left
            // those birds up to 50 wingspans behind every slot.
            let turning = self.airborne_start()
                && f.heading.iter().enumerate().any(|(k, &h)| {
                    k != i && wrap_angle(h - p.cruise_heading).abs() > AIR_GATHER_ANGLE
                });
            let v = if turning
                || self.departed.len() < f.pos.len()
                || f.phase.iter().any(|&ph| ph != Phase::Airborne)
            {
                p.gather_speed.max(p.min_speed)
            } else {
                p.cruise_speed
            };
            (p.opts.alpha * dd / tau, v, None, None, None)
        } else if let Some(c) = f.slot[i].filter(|_| p.opts.assign_slots) {
            // Assigned slot: the reference is the bird of the nearest airborne ancestor of the
            // slot (its reference slot, or farther up the tree while that bird is on the ground).
            let mut s = c;
            let j = loop {
                match self.target.parent[s] {
                    Some(ps) => {
                        let j = self.bird_of_slot[ps];
                        if f.phase[j] == Phase::Airborne || ps == self.target.leader {
                            break j;
                        }
                        s = ps;
                    }
                    None => break f.leader,
                }
            };
            // The whole way in the formation frame: eqs. (5)–(6) relative to a reference bird
            // that is itself still far from its slot would pass its lag down the arm.
            self.grid.within(&f.pos, f.pos[i], p.opts.avoid_range, near);
            let (w, v) = self.settle(i, c, near);
            (w, v, Some(j), self.target.side_of(c), Some(c))
        } else {
            // Perception: departed flockmates within the visual range.
            self.grid
                .within(&f.pos, f.pos[i], p.opts.visual_range, near);
            near.retain(|&j| f.phase[j] != Phase::Waiting);
            perceiver.visible_among(i, &f.pos, near, f.heading[i], &p.opts.perception, visible);
            match self.choose(i, visible) {
                Some((j, side, c, u)) => {
                    unseen = u;
                    let (w, v) = self.steer(i, j, c, near);
                    (w, v, Some(j), Some(side), Some(c))
                }
                None if near.is_empty() => {
                    // Nobody within the visual range: head for the flock, which is seen from
                    // much farther as a whole (its centroid), at cruise speed.
                    let c = self.departed.iter().map(|&j| f.pos[j]).sum::<DVec2>()
                        / self.departed.len().max(1) as f64;
                    let dd = bearing(f.heading[i], c - f.pos[i]);
                    (p.opts.alpha * dd / tau, p.max_speed, None, None, None)
                }
                None => {
                    let d = direction(f.heading[i]);
                    let nearest = visible
                        .iter()
                        .map(|&j| (f.pos[j] - f.pos[i], j))
                        .min_by(|a, b| a.0.length_squared().total_cmp(&b.0.length_squared()));
                    match nearest {
                        // Lost behind the flock (every visible bird ahead, the nearest farther
                        // than the separation distance): close on the nearest, a little faster
                        // than the cruise, instead of falling back ever farther.
                        Some((rel, _))
                            if rel.length() > p.opts.separation_distance
                                && visible.iter().all(|&j| (f.pos[j] - f.pos[i]).dot(d) > 0.0) =>
                        {
                            let dd = bearing(f.heading[i], rel);
                            let gain =
                                (0.02 * (rel.length() - p.opts.separation_distance)).min(0.3);
                            (
                                p.opts.alpha * dd / (p.opts.turn_distance_cap * tau),
                                p.cruise_speed * (1.0 + gain),
                                None,
                                None,
                                None,
                            )
                        }
                        _ => {
                            // Lost: turn toward the cruise heading and slow a little.
                            let dd = wrap_angle(p.cruise_heading - f.heading[i]);
                            (
                                p.opts.alpha * dd / tau,
                                p.opts.lost_speed_factor * p.cruise_speed,
                                None,
                                None,
                                None,
                            )
                        }
                    }
                }
            }
        };
        let (mut w, mut v) = (
            turn.clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate),
            want_speed,
        );
        self.grid.within(&f.pos, f.pos[i], p.opts.avoid_range, near);
        // With assigned slots, neighbours across the formation fly in two layers while they are
        // away from their slots (half a wingspan apart in height), merging as they settle, so
        // that two birds passing each other on the way are apart in 3-D.
        let mut alt_offset = match (self.layer.get(i), self.slot_err.get(i)) {
            (Some(&l), Some(&e)) if e.is_finite() => layer_offset(l, e),
            _ => 0.0,
        };
        if self.airborne_start() && f.slot[i].is_some() {
            alt_offset += self.vertical_separation(i, near);
        }
        if let Some((turn, slow, dz)) = self.avoidance(i, w, near) {
            w = turn;
            alt_offset = dz;
            if slow {
                v = v.min(f.speed[i] - p.opts.max_accel * p.opts.speed_lag);
            }
        }
        let (alt_floor, alt_ceiling) = self.wing_envelope(i, near);
        Decision {
            turn_rate: w.clamp(-p.opts.max_turn_rate, p.opts.max_turn_rate),
            speed: v.clamp(p.min_speed, p.max_speed),
            alt_offset,
            alt_floor,
            alt_ceiling,
            reference,
            side,
            branch,
            unseen,
        }
    }
}
