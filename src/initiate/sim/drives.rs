//! The target-reaching drive (§6, eqs. 5–6): the point a bird aims for beside its reference bird,
//! the turn rate and speed that take it there, and the final approach into its slot.

use super::*;

impl Simulation {
    /// The target position of a follower of bird `j` at formation-frame `offset` (Δx right,
    /// Δy behind), one reaction time ahead: T = P_j + v_j τ d_j + Δx r_j − Δy d_j.
    pub(super) fn target_point(&self, j: usize, offset: DVec2) -> DVec2 {
        let f = &self.flock;
        let d = self.dir_of(j);
        // Right of d = (sin θ, cos θ) is (cos θ, −sin θ).
        let r = DVec2::new(d.y, -d.x);
        f.pos[j] + d * (f.speed[j] * self.params.opts.reaction_time) + r * offset.x - d * offset.y
    }

    /// Flight direction of bird `j` (cached for the current decision).
    pub(super) fn dir_of(&self, j: usize) -> DVec2 {
        match self.dir.get(j) {
            Some(d) if self.dir.len() == self.flock.pos.len() => *d,
            _ => direction(self.flock.heading[j]),
        }
    }

    /// The request of bird `i` following `j` into slot `c`: eqs. (5)–(6) ([`Self::pursue`]) far
    /// from the slot, the formation-frame controller ([`Self::settle`]) within the approach
    /// distance of it, blended (smoothstep) in between, so the request never jumps.
    pub(super) fn steer(&self, i: usize, j: usize, c: usize, near: &[usize]) -> (f64, f64) {
        let p = &self.params;
        let Some(&slot) = self.slot_pos.get(c) else {
            return self.pursue(i, j, c);
        };
        let r = (self.flock.pos[i] - slot).length();
        let others = near;
        let near = p.opts.approach_distance;
        if r >= 2.0 * near {
            return self.pursue(i, j, c);
        }
        let settle = self.settle(i, c, others);
        if r <= near {
            return settle;
        }
        let u = (2.0 * near - r) / near;
        let w = u * u * (3.0 - 2.0 * u);
        let far = self.pursue(i, j, c);
        (
            far.0 + w * (settle.0 - far.0),
            far.1 + w * (settle.1 - far.1),
        )
    }

    /// Final approach in the formation frame: the bird wants the formation's velocity (the
    /// leader's) plus a closing velocity on its slot (leader position plus the slot's offset
    /// along the cruise heading), linear in the slot error near it
    /// (time constant `approach_time`; across the formation the slower, since a sideways move
    /// needs a turn first) and braked (√(2 a e)) farther out, bounded so that the wanted
    /// velocity stays within the speed range and never points backwards. It is flown as a
    /// heading (turn rate = heading error / (3 τ_ω)) and a speed: a well-damped second-order
    /// approach whose time does not depend on where the reference bird is (no cascade down the
    /// arms). Requested turn rate (rad/s) and speed (wingspans/s).
    pub(super) fn settle(&self, i: usize, c: usize, near: &[usize]) -> (f64, f64) {
        let p = &self.params;
        let f = &self.flock;
        let vf = self.lead_vel;
        let e = self.slot_pos[c] - f.pos[i];
        let dc = direction(p.cruise_heading);
        let rc = right_of(p.cruise_heading);
        let speed_f = vf.length().max(p.min_speed);
        let shape = |e: f64, t: f64, lo: f64, hi: f64| -> f64 {
            let mag = (e.abs() / t).min((2.0 * p.approach_brake * e.abs()).sqrt());
            (mag * e.signum()).clamp(lo, hi)
        };
        // The funnel: a bird still off its slot's line across the formation closes along it
        // only to a distance that grows with the sideways error, so it comes in on its own
        // lane from behind (or ahead) instead of cutting across its neighbours' slots.
        let (ea, ec) = (e.dot(dc), e.dot(rc));
        let room = (FUNNEL_SLOPE * (ec.abs() - FUNNEL_WIDTH).max(0.0)).min(FUNNEL_MAX);
        let ea = if ea > 0.0 {
            (ea - room).max(0.0)
        } else {
            (ea + room).min(0.0)
        };
        let ua = shape(
            ea,
            0.7 * p.approach_time,
            -0.8 * (speed_f - p.min_speed).max(0.0),
            0.8 * (p.max_speed - speed_f).max(0.0),
        );
        let lat = 0.5 * speed_f;
        let uc = shape(ec, p.approach_time, -lat, lat);
        let want = vf + dc * ua + rc * uc + self.separation(i, near);
        let h = want.x.atan2(want.y);
        let herr = wrap_angle(h - f.heading[i]);
        let w = herr / (3.0 * p.opts.turn_lag.max(0.05));
        // Facing away from where it wants to go, a bird slows down and turns tighter.
        let away =
            ((herr.abs() - TURN_SLOW_FROM) / (TURN_SLOW_TO - TURN_SLOW_FROM)).clamp(0.0, 1.0);
        let slow = 1.0 - away * away * (3.0 - 2.0 * away);
        let v = p.min_speed + (want.length() - p.min_speed).max(0.0) * slow;
        (w, v.min(want.length().max(p.min_speed)))
    }

    /// Eqs. (5) and (6) with the fixes of docs/initiation.md, in physical time: requested turn
    /// rate (rad/s) and speed (wingspans/s) of bird `i` following `j` into slot `c` (a follower
    /// slot of `j`'s slot). With τ the reaction time, eq. (6) θ' = θ + α Δd / max(r, 1) per step
    /// becomes ω = α Δd / (max(r, 1) τ), and eq. (5)'s v_j (a distance per step) is v_j τ.
    pub(super) fn pursue(&self, i: usize, j: usize, c: usize) -> (f64, f64) {
        let p = &self.params;
        let f = &self.flock;
        let tau = p.opts.reaction_time;
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
        let aim = if behind >= p.opts.lookahead {
            t
        } else {
            t + dj * (p.opts.lookahead - behind)
        };
        let to_aim = aim - f.pos[i];
        let dd = bearing(f.heading[i], to_aim);
        let vj = f.speed[j];
        let step_j = vj * tau;
        // Eq. (5): K > 0 only when behind the target by more than one step of the reference, and
        // not while facing away from it (a far bird flying the wrong way must not speed up).
        let k = if behind <= step_j {
            -p.k
        } else if dd.abs() < std::f64::consts::FRAC_PI_2 {
            p.k
        } else {
            0.0
        };
        // √|u| has an infinite slope at the fixed point u = 0, which with a bounded acceleration
        // makes a speed limit cycle; within `linear_zone` use its chord |u|/√u₀ instead.
        // The distance is signed (negative ahead of the target): with |r − v_j τ| alone a bird one
        // step *ahead* of its target would sit at a second fixed point of eq. (5).
        let signed_r = if behind >= 0.0 { r } else { -r };
        // With `gap_speed`, the distance is the longitudinal gap alone: the lateral error is the
        // heading's business (eq. 6), and with the full distance K's sign flip at the target
        // (|u| ≈ the lateral error there) is a jump of 2 K φ v_j in the wanted speed.
        let (k, u) = if p.opts.gap_speed {
            let g = behind - step_j;
            let k = if g <= 0.0 {
                -p.k
            } else if dd.abs() < std::f64::consts::FRAC_PI_2 {
                p.k
            } else {
                0.0
            };
            (k, g.abs())
        } else {
            (k, (signed_r - step_j).abs())
        };
        let z = p.opts.linear_zone;
        // Far from the fixed point (beyond the catch-up distance u₁) the term grows linearly,
        // √u₁ · u/u₁, so that a bird far behind closes the gap in seconds, not tens of seconds
        // (eq. 5's √ alone closes 25 wingspans in 1/(v_j K) ≈ 17 s at 10 wingspans/s).
        let far = p.catchup_distance;
        let root = if u < z {
            u / z.sqrt()
        } else if u > far {
            u / far.sqrt()
        } else {
            u.sqrt()
        };
        let mut v = vj * (1.0 - dd.abs() / std::f64::consts::PI + k * root);
        // Braking distance: close on the target no faster than the speed that can still be shed
        // before reaching it, v ≤ v_j + √(2 a g) with g the longitudinal gap (no overshoot); the
        // speed lag adds a distance v τ_v, taken off the gap.
        let gap = (behind - step_j - (f.speed[i] - vj).max(0.0) * p.opts.speed_lag).max(0.0);
        v = v.min(vj + (2.0 * p.opts.max_accel * gap).sqrt());
        // Eq. (6) as a rate, the divisor capped so that a far bird can still turn to its target.
        let w = p.opts.alpha * dd / (r.clamp(1.0, p.opts.turn_distance_cap) * tau);
        (w, v)
    }
}
