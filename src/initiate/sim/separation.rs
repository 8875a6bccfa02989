//! The separation drive and collision avoidance (§6): keeping a distance from neighbours, in the
//! plane and in height, and turning away from a predicted near miss.

use super::*;

impl Simulation {
    /// The closest predicted approach of birds `i` and `k` within `horizon` seconds, each flying
    /// on at its current speed, turn rate and climb rate (arcs, sampled [`ARC_SAMPLES`] times):
    /// the time and `k`'s position relative to `i` then (3-D, wingspans). Birds turning round
    /// after a scattered start are on arcs, which a straight-line prediction misses.
    pub(super) fn arc_closest(&self, i: usize, k: usize, horizon: f64) -> (f64, DVec3) {
        let f = &self.flock;
        let at = |b: usize, t: f64| -> DVec3 {
            let (h, v, w) = (f.heading[b], f.speed[b], f.turn_rate[b]);
            let xy = if w.abs() * t < 1e-6 {
                direction(h) * (v * t)
            } else {
                let r = v / w;
                DVec2::new(h.cos() - (h + w * t).cos(), (h + w * t).sin() - h.sin()) * r
            };
            DVec3::new(
                f.pos[b].x + xy.x,
                f.pos[b].y + xy.y,
                f.z[b] + f.climb[b] * t,
            )
        };
        let steps = ARC_SAMPLES;
        let mut best = (0.0, at(k, 0.0) - at(i, 0.0));
        for s in 1..=steps {
            let t = horizon * s as f64 / steps as f64;
            let m = at(k, t) - at(i, t);
            if m.length_squared() < best.1.length_squared() {
                best = (t, m);
            }
        }
        best
    }

    /// The vertical part of an airborne start's separation drive: for the most pressing
    /// flockmate among `near` predicted on its arc ([`Self::arc_closest`]) to come closer than
    /// the pair's separation distance within [`SEPARATION_HORIZON`], an altitude offset away
    /// from it (the higher bird up, the lower down; by index when level), growing linearly to
    /// [`VERTICAL_SEPARATION`] at contact. Birds turning round at their largest turn rate have
    /// no sideways freedom left; they pass above and below. Wingspans.
    /// The distance below which birds `i` and `k` push apart: `dsep`, or less for two birds
    /// whose slots are closer than that (a fraction of their slots' distance).
    pub(super) fn separation_limit(&self, i: usize, k: usize, dsep: f64) -> f64 {
        let f = &self.flock;
        match (f.slot[i], f.slot[k]) {
            (Some(a), Some(b)) => dsep
                .min(SEPARATION_FRACTION * (self.target.slots[a] - self.target.slots[b]).length()),
            _ => dsep,
        }
    }

    pub(super) fn vertical_separation(&self, i: usize, near: &[usize]) -> f64 {
        let f = &self.flock;
        let horizon = SEPARATION_HORIZON;
        let dsep = SEPARATION_DISTANCE;
        let mut out = 0.0f64;
        for &k in near {
            if k == i || f.phase[k] != Phase::Airborne {
                continue;
            }
            let (t, m) = self.arc_closest(i, k, horizon);
            let d = m.length();
            let limit = self.separation_limit(i, k, dsep);
            if d >= limit {
                continue;
            }
            let dz = f.z[k] - f.z[i];
            let sign = if dz.abs() > 1e-9 {
                -dz.signum()
            } else if i < k {
                -1.0
            } else {
                1.0
            };
            let urgency = 1.0 - 0.5 * t / horizon.max(1e-9);
            let push = sign * VERTICAL_SEPARATION * (limit - d) / limit * urgency;
            if push.abs() > out.abs() {
                out = push;
            }
        }
        out
    }

    pub(super) fn separation(&self, i: usize, near: &[usize]) -> DVec2 {
        let f = &self.flock;
        let pi = DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]);
        let vi = self.vel.get(i).copied().unwrap_or(DVec3::ZERO);
        let horizon = SEPARATION_HORIZON;
        let dsep = SEPARATION_DISTANCE;
        let gain = SEPARATION_SPEED;
        let mut out = DVec2::ZERO;
        for &k in near {
            if k == i || f.phase[k] == Phase::Waiting {
                continue;
            }
            let dp = DVec3::new(f.pos[k].x, f.pos[k].y, f.z[k]) - pi;
            if dp.truncate().length_squared() > 4.0 * dsep * dsep + 36.0 * horizon * horizon {
                continue;
            }
            let dv = self.vel.get(k).copied().unwrap_or(DVec3::ZERO) - vi;
            let vv = dv.length_squared();
            let (t, m) = if self.airborne_start() {
                self.arc_closest(i, k, horizon)
            } else {
                let t = if vv > 1e-12 {
                    (-dp.dot(dv) / vv).clamp(0.0, horizon)
                } else {
                    0.0
                };
                (t, dp + dv * t)
            };
            let d = m.length();
            let limit = self.separation_limit(i, k, dsep);
            if d >= limit {
                continue;
            }
            let away = -m.truncate();
            let away = if away.length_squared() > 1e-12 {
                away.normalize()
            } else if i < k {
                // Exactly above one another: apart across the cruise heading, by index.
                -right_of(self.params.cruise_heading)
            } else {
                right_of(self.params.cruise_heading)
            };
            // Nearer in time counts more: a closest approach now is pressing.
            let urgency = 1.0 - 0.5 * t / horizon.max(1e-9);
            out += away * (gain * (limit - d) / limit * urgency);
        }
        out
    }

    /// Short-range collision avoidance in 3-D, all around (not limited to the visual field). A
    /// threat is a flockmate among `near` (within `avoid_range` horizontally) whose predicted
    /// closest approach (both flying straight, climb rates included) within the horizon is below
    /// `avoid_distance`, or one already that close. When there is a threat, the bird picks among
    /// its requested turn rate `want` and five across the turn-rate range the one that maximises
    /// the smallest predicted miss distance, its heading changed by that rate over one reaction
    /// time (the requested turn wins whenever it is safe, then the one nearest to it), and slows
    /// if the nearest threat is ahead. Birds flying in parallel (V neighbours) are no threat.
    /// Returns the turn rate (rad/s) and whether to slow.
    pub(super) fn avoidance(
        &self,
        i: usize,
        want: f64,
        near: &[usize],
    ) -> Option<(f64, bool, f64)> {
        let p = &self.params;
        let f = &self.flock;
        let pi = DVec3::new(f.pos[i].x, f.pos[i].y, f.z[i]);
        let vel = &self.vel;
        let vi = vel[i];
        let miss = |dp: DVec3, dv: DVec3| -> f64 {
            let vv = dv.length_squared();
            let tau = if vv > 1e-12 {
                (-dp.dot(dv) / vv).clamp(0.0, p.opts.avoid_horizon)
            } else {
                0.0
            };
            (dp + dv * tau).length()
        };
        let at = |k: usize| DVec3::new(f.pos[k].x, f.pos[k].y, f.z[k]);
        let mut threat: Option<(f64, DVec3, usize)> = None;
        for &k in near {
            if k == i {
                continue;
            }
            let dp = at(k) - pi;
            let dv = vel[k] - vi;
            let closing = dv.length() >= AVOID_MIN_RELATIVE_SPEED * p.cruise_speed;
            let m = miss(dp, dv);
            let d = dp.length();
            // Two birds near their own slots only keep their slots' distance apart: the
            // threshold yields to the shape's geometry (slots may overlap wingtips).
            let limit = match (f.slot[i], f.slot[k]) {
                (Some(a), Some(b))
                    if self.slot_err.get(i).is_some_and(|&e| e < YIELD_DISTANCE)
                        && self.slot_err.get(k).is_some_and(|&e| e < YIELD_DISTANCE) =>
                {
                    p.opts.avoid_distance.min(
                        (YIELD_FRACTION * (self.target.slots[a] - self.target.slots[b]).length())
                            .max(YIELD_FLOOR),
                    )
                }
                _ => p.opts.avoid_distance,
            };
            let is_threat = (closing && m < limit) || d < limit;
            if is_threat && threat.map_or(true, |t| d < t.0) {
                threat = Some((d, dp, k));
            }
        }
        let (_, nearest, other) = threat?;
        let score = |w: f64| -> f64 {
            // The heading after holding that turn rate for the avoidance commitment time (a
            // turn takes effect over a fraction of a second, not one reaction time).
            let h = direction(f.heading[i] + w * AVOID_COMMIT) * f.speed[i];
            let vnew = DVec3::new(h.x, h.y, vi.z);
            let mut worst = f64::INFINITY;
            for &k in near {
                if k != i {
                    worst = worst.min(miss(at(k) - pi, vel[k] - vnew));
                }
            }
            worst
        };
        let m = p.opts.max_turn_rate;
        let mut best = (score(want), want);
        if best.0 < p.opts.avoid_distance {
            for w in [-m, -0.5 * m, 0.0, 0.5 * m, m] {
                let sc = score(w);
                let better = sc > best.0 + 1e-9
                    || ((sc - best.0).abs() <= 1e-9 && (w - want).abs() < (best.1 - want).abs());
                if better {
                    best = (sc, w);
                }
            }
        }
        let ahead = nearest.truncate().dot(direction(f.heading[i])) > 0.0;
        // In 3-D a bird can also pass above or below: the higher of the two (the one with the
        // higher index when level) climbs, the other dives, by 1.5 avoidance distances, while the
        // threat lasts (airborne birds only; the hand-over needs the cruise altitude back).
        let above = f.z[i] > f.z[other] || (f.z[i] == f.z[other] && i > other);
        let dz = if f.phase[other] == Phase::Airborne && f.z[i] > 0.5 * p.opts.avoid_distance {
            if above {
                1.5 * p.opts.avoid_distance
            } else {
                -1.5 * p.opts.avoid_distance
            }
        } else {
            0.0
        };
        Some((best.1, ahead, dz))
    }
}

/// The wing envelope's lateral reach: a flockmate less than this far aside (in either bird's
/// heading frame) could put a wing over the bird's, wingspans (the clash test's span and a
/// margin for the lateral drift over a decision).
pub const ENVELOPE_SPAN: f64 = 1.08;

/// The wing envelope's fore-aft reach, wingspans: the clash test's chord (0.15) and a margin.
/// Between birds whose slots are a step apart fore and aft it is at most the step less
/// [`ENVELOPE_SLACK`] (the key shapes keep at least 0.35), so that birds in their slots keep no
/// envelope between them.
pub const ENVELOPE_CHORD: f64 = 0.24;

/// The least fore-aft reach of the envelope between birds whose slots are a small step apart
/// (see [`ENVELOPE_SLACK`]): the clash test's chord and a little, wingspans. Pairs whose slots
/// are closer than this and the slack fore and aft (within a wingspan aside) keep none: the
/// key shape's business.
pub const ENVELOPE_CHORD_MIN: f64 = 0.16;

/// Room fore and aft the envelope leaves two birds settling into slots that are a step apart
/// (within a wingspan aside): its reach is at most the step less this, wingspans (each bird
/// counts as settled within 0.1 wingspans of its slot; a little more, so that two birds already
/// settling do not start an envelope in the last moments of the convergence).
pub const ENVELOPE_SLACK: f64 = 0.13;

/// How far ahead the wing envelope looks for a flockmate coming within reach (both flying on at
/// their current velocities), seconds.
pub const ENVELOPE_LOOKAHEAD: f64 = 0.5;

/// Height between two birds within each other's wing envelope, wingspans: the lower one keeps
/// at least this far under the other, the upper one this far over it (the clash test's wing
/// thickness is 0.08).
pub const ENVELOPE_GAP: f64 = 0.16;

/// Height between two birds of which one passes under the other (less than
/// [`ENVELOPE_PASS_ASIDE`] aside while within the chord fore and aft), wingspans: their bodies
/// keep the clash test's 0.3 wingspans and a margin.
pub const ENVELOPE_PASS_GAP: f64 = 0.38;

/// Lateral distance under which a bird within the wing envelope passes under or over the other
/// rather than beside it, wingspans.
pub const ENVELOPE_PASS_ASIDE: f64 = 0.45;

/// Flockmates flying more than this across a bird's heading pass under the short-range
/// avoidance, not the envelope, radians (45°).
pub const ENVELOPE_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

/// The altitude a bird flies towards: `base` (the cruise altitude with its offsets), kept
/// within its wing envelope's bounds (`floor` from the flockmates under it, `ceiling` from those
/// over it); when both bind, halfway between them.
pub(super) fn envelope_altitude(base: f64, floor: f64, ceiling: f64) -> f64 {
    if floor > ceiling {
        0.5 * (floor + ceiling)
    } else {
        base.max(floor).min(ceiling)
    }
}

impl Simulation {
    /// Whether airborne birds `i` and `k` are, or within [`ENVELOPE_LOOKAHEAD`] will be, within
    /// each other's wing reach in the plane (then the least distance aside while within reach,
    /// wingspans): under [`ENVELOPE_SPAN`] aside and
    /// [`ENVELOPE_CHORD`] fore and aft in the heading frame of either (flying on at their
    /// current velocities). Pairs flying across each other, and pairs whose slots themselves are
    /// that close (the key shape's business), are not.
    pub(super) fn within_wing_reach(&self, i: usize, k: usize) -> Option<f64> {
        let f = &self.flock;
        if wrap_angle(f.heading[k] - f.heading[i]).abs() > ENVELOPE_ANGLE {
            return None;
        }
        let mut chord = ENVELOPE_CHORD;
        if let (Some(a), Some(b)) = (f.slot[i], f.slot[k]) {
            if a < self.target.len() && b < self.target.len() {
                let o = self.target.slots[b] - self.target.slots[a];
                if o.x.abs() < ENVELOPE_SPAN {
                    // Slots a small step apart fore and aft: the envelope leaves the two birds
                    // room to settle into them (within [`ENVELOPE_SLACK`] of the step).
                    chord = chord.min(o.y.abs() - ENVELOPE_SLACK);
                    if chord < ENVELOPE_CHORD_MIN {
                        return None;
                    }
                }
            }
        }
        let rel = f.pos[k] - f.pos[i];
        if rel.length_squared() > 16.0 {
            return None;
        }
        let vel = |b: usize| {
            self.vel
                .get(b)
                .map_or(direction(f.heading[b]) * f.speed[b], |v| v.truncate())
        };
        let dv = vel(k) - vel(i);
        const SAMPLES: usize = 8;
        let mut aside: Option<f64> = None;
        for b in [i, k] {
            let d = self.dir_of(b);
            let r = DVec2::new(d.y, -d.x);
            for s in 0..=SAMPLES {
                let p = rel + dv * (ENVELOPE_LOOKAHEAD * s as f64 / SAMPLES as f64);
                let c = p.dot(r).abs();
                if p.dot(d).abs() < chord && c < ENVELOPE_SPAN {
                    aside = Some(aside.map_or(c, |a| a.min(c)));
                }
            }
        }
        aside
    }

    /// The wing envelope of airborne bird `i` among `near`: for every flockmate within its wing
    /// reach ([`Self::within_wing_reach`]) and less than a wingspan away in height, the lower of
    /// the two (the later in index order when level) keeps [`ENVELOPE_GAP`] under the other,
    /// the upper that far over it ([`ENVELOPE_PASS_GAP`] when one passes under the other).
    /// Birds climbing at the same rate side by side (their slots a
    /// step apart fore and aft, one overtaking the other while they settle) so climb at
    /// different rates until one has passed; the bounds are altitudes the bird flies towards
    /// with its bounded climb rate and vertical acceleration, so nothing jumps. Returns the
    /// floor and the ceiling (±∞ when free), wingspans.
    pub(super) fn wing_envelope(&self, i: usize, near: &[usize]) -> (f64, f64) {
        let f = &self.flock;
        let (mut floor, mut ceiling) = (f64::NEG_INFINITY, f64::INFINITY);
        if f.phase[i] != Phase::Airborne {
            return (floor, ceiling);
        }
        for &k in near {
            if k == i || f.phase[k] == Phase::Waiting {
                continue;
            }
            let dz = f.z[k] - f.z[i];
            if dz.abs() >= 1.0 {
                continue;
            }
            let Some(aside) = self.within_wing_reach(i, k) else {
                continue;
            };
            // A bird crossing under or over the other keeps its body clear too.
            let gap = if aside < ENVELOPE_PASS_ASIDE {
                ENVELOPE_PASS_GAP
            } else {
                ENVELOPE_GAP
            };
            let below = if dz.abs() > 1e-9 { dz > 0.0 } else { i > k };
            if below {
                ceiling = ceiling.min(f.z[k] - gap);
            } else {
                floor = floor.max(f.z[k] + gap);
            }
        }
        // Never down into the ground: a bird just off it holds its height instead.
        (floor, ceiling.max(f.z[i].min(0.3)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_bounds_the_altitude_and_meets_halfway_when_squeezed() {
        let inf = f64::INFINITY;
        assert_eq!(envelope_altitude(10.0, -inf, inf), 10.0);
        assert_eq!(envelope_altitude(10.0, -inf, 9.84), 9.84);
        assert_eq!(envelope_altitude(10.0, 10.16, inf), 10.16);
        assert_eq!(envelope_altitude(10.0, 9.0, 11.0), 10.0);
        assert!((envelope_altitude(10.0, 10.2, 9.8) - 10.0).abs() < 1e-12);
    }
}
