//! The §6 simulation loop: one call of [`Simulation::step`] advances every bird by one animation
//! frame. Each bird perceives the flock as it was at the previous step (Jacobi update), chooses its
//! reference bird and side, derives its target position from the correspondence with the target
//! shape, and changes speed (eq. 5) and heading (eq. 6) within its limits; short-range collision
//! avoidance may override the heading change.
//!
//! Internal units: wingspans, radians, *steps* (one step = one frame = 1/fps s), so speeds are in
//! wingspans per step and turn rates in radians per step. [`StepParams`] holds the per-step values
//! derived from the user's per-second [`super::InitiateOptions`].

use glam::DVec2;

use super::perception::{
    bearing, choose_reference, direction, right_of, Perceiver, PerceptionParams,
};
use super::target::{Side, TargetShape};

/// Collision avoidance ignores flockmates whose speed relative to the bird is below this
/// fraction of the cruise speed (unless they are already closer than the avoidance distance).
pub const AVOID_MIN_RELATIVE_SPEED: f64 = 0.08;

/// Per-step parameters of the drives and actions (derived from [`super::InitiateOptions`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepParams {
    /// Perception model.
    pub perception: PerceptionParams,
    /// α of eq. (6), dimensionless.
    pub alpha: f64,
    /// |K| of eq. (5), per √wingspan.
    pub k: f64,
    /// Maximum heading change, radians per step.
    pub max_turn: f64,
    /// Maximum speed change, wingspans per step per step.
    pub max_dv: f64,
    /// Minimum flight speed, wingspans per step.
    pub min_speed: f64,
    /// Maximum flight speed, wingspans per step.
    pub max_speed: f64,
    /// Cruise heading, radians clockwise from +y.
    pub cruise_heading: f64,
    /// Cruise speed, wingspans per step.
    pub cruise_speed: f64,
    /// Separation drive: two birds sharing a reference within this distance → the rear one
    /// chooses another, wingspans (paper: 10).
    pub separation_distance: f64,
    /// Look-ahead distance of a bird near or ahead of its target: it steers at the point this far
    /// ahead of itself on the target's line, wingspans.
    pub lookahead: f64,
    /// Collision avoidance: predicted closest approach below which a bird evades, wingspans.
    pub avoid_distance: f64,
    /// Collision avoidance: only birds nearer than this are considered, wingspans.
    pub avoid_range: f64,
    /// Collision avoidance: prediction horizon, steps.
    pub avoid_horizon: f64,
    /// Speed factor of a bird without a reference bird (slows a little until it sees the flock).
    pub lost_speed_factor: f64,
    /// A bird replaces the leader only when it is this much farther ahead, wingspans.
    pub leader_hysteresis: f64,
    /// Keep the current reference bird while it stays visible and acceptable.
    pub sticky_reference: bool,
    /// A kept reference hidden for at most this many steps is kept all the same.
    pub reference_memory: u32,
    /// Upper bound of the distance divisor of eq. (6), wingspans.
    pub turn_distance_cap: f64,
    /// Half-width of the linear zone of eq. (5)'s √|r − v_j| around its fixed point, wingspans.
    pub linear_zone: f64,
}

/// A bird claims a slot already held by a visible bird only when it is nearer the slot's target
/// by this much, wingspans.
pub const SLOT_CLAIM_MARGIN: f64 = 1.0;

/// A bird this close to its target holds its slot against a claimant at any distance, wingspans
/// (the separation drive's distance threshold only lets birds far apart share a reference while
/// neither is in the slot yet).
pub const SETTLED_DISTANCE: f64 = 1.0;

/// Flocks at least this large decide in parallel (one thread per core).
pub const PARALLEL_MIN_BIRDS: usize = 256;

/// What one bird does in the next step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Decision {
    /// Heading change, radians.
    turn: f64,
    /// New speed, wingspans per step.
    speed: f64,
    reference: Option<usize>,
    side: Option<Side>,
    branch: Option<usize>,
    unseen: u32,
}

/// The state of every bird (world frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Flock {
    /// Positions, wingspans.
    pub pos: Vec<DVec2>,
    /// Headings, radians clockwise from +y.
    pub heading: Vec<f64>,
    /// Speeds, wingspans per step.
    pub speed: Vec<f64>,
    /// Reference bird of each bird (`None` for the leader and for lost birds).
    pub reference: Vec<Option<usize>>,
    /// Side of each bird relative to its reference bird.
    pub side: Vec<Option<Side>>,
    /// The follower slot of its reference's slot each bird aims for (where the target tree
    /// branches, a reference slot has several).
    pub branch: Vec<Option<usize>>,
    /// Steps since each bird last saw its reference bird (0: visible now).
    pub unseen: Vec<u32>,
    /// Slot of the target shape each bird corresponds to (§6.2.1), if matched.
    pub slot: Vec<Option<usize>>,
    /// The leader: the front-most bird along the cruise heading.
    pub leader: usize,
}

/// The simulation: target shape, parameters, flock and scratch buffers.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Target shape (slot tree).
    pub target: TargetShape,
    /// Per-step parameters.
    pub params: StepParams,
    /// Current state.
    pub flock: Flock,
    /// Steps done so far.
    pub steps: usize,
    /// Largest heading change of any bird in any step so far, radians.
    pub max_heading_change: f64,
    /// Number of times the leader changed.
    pub leader_changes: usize,
    perceiver: Perceiver,
    visible: Vec<usize>,
    vel: Vec<DVec2>,
    dir: Vec<DVec2>,
    decisions: Vec<Decision>,
    next_reference: Vec<Option<usize>>,
    next_side: Vec<Option<Side>>,
    next_branch: Vec<Option<usize>>,
    next_unseen: Vec<u32>,
}

impl Simulation {
    /// A simulation starting from `pos`, `heading`, `speed` (wingspans, radians, wingspans per
    /// step); the leader is the front-most bird.
    pub fn new(
        target: TargetShape,
        params: StepParams,
        pos: Vec<DVec2>,
        heading: Vec<f64>,
        speed: Vec<f64>,
    ) -> Simulation {
        let n = pos.len();
        let dc = direction(params.cruise_heading);
        let leader = front_most(&pos, dc);
        let mut sim = Simulation {
            target,
            params,
            flock: Flock {
                pos,
                heading,
                speed,
                reference: vec![None; n],
                side: vec![None; n],
                branch: vec![None; n],
                unseen: vec![0; n],
                slot: vec![None; n],
                leader,
            },
            steps: 0,
            max_heading_change: 0.0,
            leader_changes: 0,
            perceiver: Perceiver::new(),
            visible: Vec::new(),
            vel: Vec::new(),
            dir: Vec::new(),
            decisions: Vec::new(),
            next_reference: vec![None; n],
            next_side: vec![None; n],
            next_branch: vec![None; n],
            next_unseen: vec![0; n],
        };
        sim.match_slots();
        sim
    }

    /// Number of birds.
    pub fn len(&self) -> usize {
        self.flock.pos.len()
    }

    /// True when there are no birds.
    pub fn is_empty(&self) -> bool {
        self.flock.pos.is_empty()
    }

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

    /// The target position of a follower of bird `j` at formation-frame `offset` (Δx right,
    /// Δy behind), one step ahead: T = P_j + v_j d_j + Δx r_j − Δy d_j.
    fn target_point(&self, j: usize, offset: DVec2) -> DVec2 {
        let f = &self.flock;
        let d = self.dir_of(j);
        // Right of d = (sin θ, cos θ) is (cos θ, −sin θ).
        let r = DVec2::new(d.y, -d.x);
        f.pos[j] + d * f.speed[j] + r * offset.x - d * offset.y
    }

    /// Flight direction of bird `j` (cached for the current step).
    fn dir_of(&self, j: usize) -> DVec2 {
        match self.dir.get(j) {
            Some(d) if self.dir.len() == self.flock.pos.len() => *d,
            _ => direction(self.flock.heading[j]),
        }
    }

    /// Which follower slot of `j` on `side` bird `i` may take, if any. `j` must be matched (an
    /// unmatched bird gives no consistent target, and birds following each other in a cycle
    /// never reach the flock) and its slot must have a follower slot on that side (capacity: the
    /// tail of an arm has none); a follower slot is refused when a visible bird that already takes
    /// it is within the separation distance and nearer its target (separation drive, §6.2.2).
    /// Among the free ones, the bird keeps the one it holds, else takes the one whose target is
    /// nearest.
    fn acceptable(&self, i: usize, j: usize, side: Side, visible: &[usize]) -> Option<usize> {
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
            let taken = visible.iter().any(|&k| {
                k != i
                    && f.reference[k] == Some(j)
                    && f.side[k] == Some(side)
                    && f.slot[k] == Some(c)
                    && ((f.pos[k] - f.pos[i]).length() < self.params.separation_distance
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
    fn sides_for(&self, i: usize, j: usize) -> [Option<Side>; 2] {
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

    /// Advances the flock by one step.
    pub fn step(&mut self) {
        let n = self.len();
        if n == 0 {
            return;
        }
        let p = self.params;
        let dc = direction(p.cruise_heading);
        // The leader is the front-most bird (with hysteresis against flip-flopping).
        let front = front_most(&self.flock.pos, dc);
        let lead = self.flock.leader;
        if front != lead
            && (self.flock.pos[front] - self.flock.pos[lead]).dot(dc) > p.leader_hysteresis
        {
            self.flock.leader = front;
            self.leader_changes += 1;
            self.match_slots();
        }
        // Velocities of the previous step, shared by every bird's decisions.
        let mut vel = std::mem::take(&mut self.vel);
        vel.clear();
        vel.extend((0..n).map(|i| direction(self.flock.heading[i]) * self.flock.speed[i]));
        self.vel = vel;
        let mut dir = std::mem::take(&mut self.dir);
        dir.clear();
        dir.extend(self.flock.heading.iter().map(|&h| direction(h)));
        self.dir = dir;
        let mut decisions = std::mem::take(&mut self.decisions);
        decisions.resize(n, Decision::default());
        let threads = if n >= PARALLEL_MIN_BIRDS {
            std::thread::available_parallelism().map_or(1, |t| t.get().min(8))
        } else {
            1
        };
        if threads <= 1 {
            let mut perceiver = std::mem::take(&mut self.perceiver);
            let mut visible = std::mem::take(&mut self.visible);
            for (i, d) in decisions.iter_mut().enumerate() {
                *d = self.decide(i, &mut perceiver, &mut visible);
            }
            self.perceiver = perceiver;
            self.visible = visible;
        } else {
            // Every decision reads only the previous state, so birds can be split across
            // threads; the result does not depend on the split.
            let chunk = n.div_ceil(threads);
            let this = &*self;
            std::thread::scope(|scope| {
                for (c, out) in decisions.chunks_mut(chunk).enumerate() {
                    scope.spawn(move || {
                        let mut perceiver = Perceiver::new();
                        let mut visible = Vec::new();
                        for (k, d) in out.iter_mut().enumerate() {
                            *d = this.decide(c * chunk + k, &mut perceiver, &mut visible);
                        }
                    });
                }
            });
        }
        let f = &mut self.flock;
        for (i, d) in decisions.iter().enumerate() {
            self.max_heading_change = self.max_heading_change.max(d.turn.abs());
            f.heading[i] = wrap_angle(f.heading[i] + d.turn);
            f.speed[i] = d.speed;
            f.pos[i] += direction(f.heading[i]) * f.speed[i];
            self.next_reference[i] = d.reference;
            self.next_side[i] = d.side;
            self.next_branch[i] = d.branch;
            self.next_unseen[i] = d.unseen;
        }
        self.decisions = decisions;
        std::mem::swap(&mut f.reference, &mut self.next_reference);
        std::mem::swap(&mut f.side, &mut self.next_side);
        std::mem::swap(&mut f.branch, &mut self.next_branch);
        std::mem::swap(&mut f.unseen, &mut self.next_unseen);
        self.steps += 1;
        self.match_slots();
    }

    /// The decision of bird `i` for the next step, from the current state only.
    fn decide(&self, i: usize, perceiver: &mut Perceiver, visible: &mut Vec<usize>) -> Decision {
        let p = &self.params;
        let f = &self.flock;
        let mut unseen = 0;
        let (want_heading, want_speed, reference, side, branch) = if i == f.leader {
            (p.cruise_heading, p.cruise_speed, None, None, None)
        } else {
            perceiver.visible(i, &f.pos, f.heading[i], &p.perception, visible);
            match self.choose(i, visible) {
                Some((j, side, c, u)) => {
                    unseen = u;
                    let (h, v) = self.pursue(i, j, c);
                    (h, v, Some(j), Some(side), Some(c))
                }
                None => {
                    // Lost: turn toward the cruise heading and slow a little.
                    let dd = wrap_angle(p.cruise_heading - f.heading[i]);
                    (
                        f.heading[i] + p.alpha * dd,
                        p.lost_speed_factor * p.cruise_speed,
                        None,
                        None,
                        None,
                    )
                }
            }
        };
        let (mut dh, mut v) = (wrap_angle(want_heading - f.heading[i]), want_speed);
        if let Some((turn, slow)) = self.avoidance(i, dh.clamp(-p.max_turn, p.max_turn)) {
            dh = turn;
            if slow {
                v = v.min(f.speed[i] - p.max_dv);
            }
        }
        let v0 = f.speed[i];
        Decision {
            turn: dh.clamp(-p.max_turn, p.max_turn),
            speed: v
                .clamp(v0 - p.max_dv, v0 + p.max_dv)
                .clamp(p.min_speed, p.max_speed),
            reference,
            side,
            branch,
            unseen,
        }
    }

    /// Reference bird, side and follower slot of bird `i` among its `visible` flockmates, and
    /// the steps since the reference was last seen. The current reference is kept while it stays
    /// acceptable and is visible, or hidden for no more than the reference memory (a bird does not
    /// forget the bird it follows when another passes in front of it for a moment).
    fn choose(&self, i: usize, visible: &[usize]) -> Option<(usize, Side, usize, u32)> {
        let f = &self.flock;
        if self.params.sticky_reference {
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
            self.params.perception.reference_cone,
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

    /// Eqs. (5) and (6) with the fixes of docs/initiation.md: desired heading and speed of bird `i`
    /// following `j` into slot `c` (a follower slot of `j`'s slot).
    fn pursue(&self, i: usize, j: usize, c: usize) -> (f64, f64) {
        let p = &self.params;
        let f = &self.flock;
        let offset = match f.slot[j] {
            Some(sj) => self.target.offset(sj, c),
            None => self.target.mean_offset,
        };
        let t = self.target_point(j, offset);
        let dj = self.dir_of(j);
        let to_t = t - f.pos[i];
        let r = to_t.length();
        // How far the bird is behind its target along the reference's flight direction.
        let behind = to_t.dot(dj);
        // Near or ahead of the target: steer at a point ahead on the target's line instead of
        // turning back toward it (turnaround fix).
        let aim = if behind >= p.lookahead {
            t
        } else {
            t + dj * (p.lookahead - behind)
        };
        let to_aim = aim - f.pos[i];
        let dd = bearing(f.heading[i], to_aim);
        let vj = f.speed[j];
        // Eq. (5): K > 0 only when behind the target by more than one step of the reference, and
        // not while facing away from it (a far bird flying the wrong way must not speed up).
        let k = if behind <= vj {
            -p.k
        } else if dd.abs() < std::f64::consts::FRAC_PI_2 {
            p.k
        } else {
            0.0
        };
        // √|u| has an infinite slope at the fixed point u = 0, which with a bounded acceleration
        // makes a speed limit cycle; within `linear_zone` use its chord |u|/√u₀ instead.
        // The distance is signed (negative ahead of the target): with |r − v_j| alone a bird one
        // step *ahead* of its target would sit at a second fixed point of eq. (5).
        let signed_r = if behind >= 0.0 { r } else { -r };
        let u = (signed_r - vj).abs();
        let z = p.linear_zone;
        let root = if u < z { u / z.sqrt() } else { u.sqrt() };
        let mut v = vj * (1.0 - dd.abs() / std::f64::consts::PI + k * root);
        // Braking distance: close on the target no faster than the speed that can still be shed
        // before reaching it, v ≤ v_j + √(2 a g) with g the longitudinal gap (no overshoot).
        let gap = (behind - vj).max(0.0);
        v = v.min(vj + (2.0 * p.max_dv * gap).sqrt());
        // Eq. (6), with the divisor capped so that a far bird can still turn toward its target.
        let h = f.heading[i] + p.alpha * dd / r.clamp(1.0, p.turn_distance_cap);
        (h, v)
    }

    /// Short-range collision avoidance, all around (not limited to the visual field). A threat is
    /// a flockmate within `avoid_range` whose predicted closest approach (both flying straight)
    /// within the horizon is below `avoid_distance`, or one already that close. When there is a
    /// threat, the bird picks among its desired turn `want` and five turns across the turn-rate
    /// range the one that maximises the smallest predicted miss distance to every flockmate in
    /// range (the desired turn wins whenever it is safe, then the one nearest to it), and slows if
    /// the nearest threat is ahead. Birds flying in parallel (V neighbours) are no threat, so they
    /// are left alone. Returns the heading change (radians) and whether to slow.
    fn avoidance(&self, i: usize, want: f64) -> Option<(f64, bool)> {
        let p = &self.params;
        let f = &self.flock;
        let pi = f.pos[i];
        let vel = &self.vel;
        let vi = vel[i];
        let range2 = p.avoid_range * p.avoid_range;
        let miss = |dp: DVec2, dv: DVec2| -> f64 {
            let vv = dv.length_squared();
            let tau = if vv > 1e-12 {
                (-dp.dot(dv) / vv).clamp(0.0, p.avoid_horizon)
            } else {
                0.0
            };
            (dp + dv * tau).length()
        };
        let mut threat: Option<(f64, DVec2)> = None;
        for (k, &pk) in f.pos.iter().enumerate() {
            if k == i {
                continue;
            }
            let dp = pk - pi;
            if dp.length_squared() > range2 {
                continue;
            }
            let dv = vel[k] - vi;
            let closing = dv.length() >= AVOID_MIN_RELATIVE_SPEED * p.cruise_speed;
            let m = miss(dp, dv);
            if (closing && m < p.avoid_distance) || dp.length() < p.avoid_distance {
                let d = dp.length();
                if threat.map_or(true, |t| d < t.0) {
                    threat = Some((d, dp));
                }
            }
        }
        let (_, nearest) = threat?;
        // Score of a heading change: the smallest predicted miss distance over the neighbours.
        let score = |dh: f64| -> f64 {
            let vnew = direction(f.heading[i] + dh) * f.speed[i];
            let mut worst = f64::INFINITY;
            for (k, &pk) in f.pos.iter().enumerate() {
                let dp = pk - pi;
                if k == i || dp.length_squared() > range2 {
                    continue;
                }
                let dv = vel[k] - vnew;
                worst = worst.min(miss(dp, dv));
            }
            worst
        };
        let m = p.max_turn;
        let mut best = (score(want), want);
        if best.0 < p.avoid_distance {
            for dh in [-m, -0.5 * m, 0.0, 0.5 * m, m] {
                let sc = score(dh);
                let better = sc > best.0 + 1e-9
                    || ((sc - best.0).abs() <= 1e-9 && (dh - want).abs() < (best.1 - want).abs());
                if better {
                    best = (sc, dh);
                }
            }
        }
        let ahead = nearest.dot(direction(f.heading[i])) > 0.0;
        Some((best.1, ahead))
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

    /// The convergence test of one step: the matching is one-to-one and every bird is within
    /// `tolerance` wingspans of its slot, within `heading_tolerance` radians of the cruise heading
    /// and within `speed_tolerance` (fraction) of the cruise speed.
    pub fn in_formation(
        &self,
        tolerance: f64,
        heading_tolerance: f64,
        speed_tolerance: f64,
    ) -> bool {
        let n = self.len();
        let f = &self.flock;
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
            (f.pos[i] - slots[s]).length() <= tolerance
                && wrap_angle(f.heading[i] - p.cruise_heading).abs() <= heading_tolerance
                && (f.speed[i] - p.cruise_speed).abs() <= speed_tolerance * p.cruise_speed
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

    /// Smallest distance between two birds now, wingspans (∞ for fewer than two birds).
    pub fn min_distance(&self) -> f64 {
        min_pair_distance(&self.flock.pos)
    }
}

/// Smallest distance between two points, wingspans (∞ for fewer than two). Sort-and-sweep on x.
pub fn min_pair_distance(pos: &[DVec2]) -> f64 {
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

/// Index of the bird farthest along `dir` (ties to the lower index).
fn front_most(pos: &[DVec2], dir: DVec2) -> usize {
    let mut best = 0;
    for (i, p) in pos.iter().enumerate() {
        if p.dot(dir) > pos[best].dot(dir) {
            best = i;
        }
    }
    best
}

/// An angle wrapped into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::PI;
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    } else if a <= -PI {
        a += 2.0 * PI;
    }
    a
}
