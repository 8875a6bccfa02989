//! Birds at rest on the ground: wings folded, no wingbeat.
//!
//! A bird is *at rest* in a frame when it is slower than [`REST_SPEED_MS`] (0.5 m/s) and within
//! [`GROUND_BAND`] wingspans of the ground: it holds the [`FOLDED`] pose and its wingbeat phase
//! does not advance. When it leaves rest (the take-off run starts) its wings unfold into the
//! wingbeat over [`UNFOLD_S`] seconds, and fold again over the same time when it comes to rest.
//! The weights depend on the frames' speeds, heights and times only, so they are the same when
//! the phases are computed and when they are replayed from a file, and the same at any frame rate.

use crate::animation::Animation;

use super::sparse::FrameTable;
use super::{Species, WingPose};

/// Below this ground speed, metres per second, a bird on the ground is at rest.
pub const REST_SPEED_MS: f64 = 0.5;
/// A slow bird less than this far above the ground (wingspans) is on the ground.
pub const GROUND_BAND: f64 = 1.0;
/// Time the wings take to unfold into the wingbeat, or to fold from it, seconds.
pub const UNFOLD_S: f64 = 0.15;

/// Ground speed, metres per second, at which a bird that starts its run has risen from sitting
/// to standing (the body lifts as speed builds).
pub const STAND_UP_SPEED_MS: f64 = 0.5;

/// Heights of a bird's root (body centre) above the ground, wingspans.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// Sitting at rest, belly on the ground, wings folded.
    pub sit: f64,
    /// Standing and running: high enough that a full downstroke clears the ground.
    pub stand: f64,
}

/// The stance of the built-in bird of `species` (its lowest point folded, and over a wingbeat,
/// plus a margin; the ground tests check these against the mesh). A goose of 1.5 m stands with
/// its body centre 0.39 m up, about a real goose's.
pub fn stance(species: Species) -> Stance {
    match species {
        Species::Goose => Stance {
            sit: 0.070,
            stand: 0.26,
        },
        Species::Crane => Stance {
            sit: 0.057,
            stand: 0.24,
        },
        Species::Pelican => Stance {
            sit: 0.072,
            stand: 0.22,
        },
    }
}

/// Puts the take-off's birds (the `initiation` stage) on the ground as they are: sitting at
/// rest, standing up as the run starts, and lifted by their standing height at lift-off, fading
/// out as they climb. The root's height becomes
/// ```math
/// z' = z + h(v)\,e^{-z/h_\text{stand}}, \qquad
/// h(v) = h_\text{sit} + (h_\text{stand} - h_\text{sit})\,\operatorname{smoothstep}(v / v_\text{up})
/// ```
/// (v the ground speed, v_up = [`STAND_UP_SPEED_MS`]): monotonic and smooth in z, equal to z
/// for a bird high up (below 1e-17 wingspans from 10 wingspans up). Run it after the course
/// (whose pitch comes from the height change, so the body stays level while the bird stands
/// up) and before the wingbeats. Animations without a take-off are left as they are.
///
/// The `landing` stage is treated the same way (the flare ends standing, the running steps slow
/// to sitting), except on water, where a bird skis on its feet with the root at half its
/// standing height and floats, root [`crate::animation::landing::FLOAT_HEIGHT`] above the
/// waterline, once slow.
pub fn stand_on_ground(anim: &mut Animation, species: Species) {
    let st = stance(species);
    let ws = anim.wingspan_m;
    if !(ws.is_finite() && ws > 0.0) {
        return;
    }
    let water = anim
        .landing
        .as_ref()
        .is_some_and(|l| l.surface == crate::animation::landing::Surface::Water);
    for name in ["initiation", "landing"] {
        let Some(stage) = anim.stage(name).cloned() else {
            continue;
        };
        let float = (name == "landing" && water).then_some(crate::animation::landing::FLOAT_HEIGHT);
        let end = stage.end.min(anim.frames.len());
        for f in &mut anim.frames[stage.start.min(end)..end] {
            for (z, &v) in f.z.iter_mut().zip(&f.speed) {
                let u = (v * ws / STAND_UP_SPEED_MS).clamp(0.0, 1.0);
                // On water a bird skis on its feet while fast, body half out of the water,
                // and floats once slow.
                let (sit, stand) = match float {
                    Some(fl) => (fl, 0.5 * st.stand),
                    None => (st.sit, st.stand),
                };
                let h = sit + (stand - sit) * u * u * (3.0 - 2.0 * u);
                let lift = h * (-z.max(0.0) / st.stand).exp();
                if z.is_finite() && lift.is_finite() {
                    *z += lift;
                }
            }
        }
    }
}

/// A leg of the built-in rig: the left hip in the bird frame (`x` left, `y` up, `z` forward) and
/// the leg's reach from the hip to the tip of the toes, wingspans. The reach is what a straight
/// leg needs to stand the bird at its [`Stance::stand`] height, less [`leg_gap`]: the built-in
/// rig has one joint per leg, so a standing bird's legs are straight and under the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
    /// Left hip, bird frame, wingspans (the right one mirrored).
    pub hip: [f64; 3],
    /// Hip to the toes' tip, wingspans.
    pub reach: f64,
    /// Gap kept between the toes and the ground ([`leg_gap`]), wingspans.
    pub gap: f64,
}

/// Gap kept between the toes and the ground, wingspans: 0.006 for the toes' rounding, plus what
/// a bird larger by [`LEG_SCALE_MARGIN`] sinks its toes by when it stands (exports scale a bird
/// about the ground point under it sitting, so a larger one's standing toes are lower by
/// (s − 1)(h_stand − h_sit)).
pub fn leg_gap(species: Species) -> f64 {
    let st = stance(species);
    0.006 + LEG_SCALE_MARGIN * (st.stand - st.sit)
}

/// Size margin of [`leg_gap`]: 0.12, three standard deviations of the exports' default size
/// spread (4 %, clipped at three), so that no bird of the default spread puts a toe below the
/// ground.
pub const LEG_SCALE_MARGIN: f64 = 0.12;

/// The legs of `species`: hips just behind the body's centre, low in the body; reach from the
/// standing height (our choice, docs/landing.md).
pub fn leg(species: Species) -> Leg {
    let hip = match species {
        Species::Goose => [0.02, -0.04, -0.04],
        Species::Crane => [0.018, -0.035, -0.06],
        Species::Pelican => [0.02, -0.04, -0.05],
    };
    let gap = leg_gap(species);
    Leg {
        hip,
        reach: stance(species).stand + hip[1] - gap,
        gap,
    }
}

/// Leg swing of a bird standing or in the flare (from trailing, radians): 100°, straight down
/// and a little forward, so the feet are under the body's centre. Our choice.
pub const LEGS_DOWN: f64 = 100.0 * std::f64::consts::PI / 180.0;
/// Time the legs take to swing back after lift-off, seconds (our choice, docs/landing.md).
pub const LEG_SWING_S: f64 = 0.5;
/// A bird of the take-off whose root is more than this above its standing height (wingspans)
/// has lifted off; lower, it is on its legs.
pub const LIFT_OFF_BAND: f64 = 0.05;

/// Leg swing of a bird with its legs lowered whose root is `z` wingspans above the ground with
/// the body pitched `pitch` radians nose up: [`LEGS_DOWN`] when the feet clear the ground, and
/// otherwise swung further forward, just as far as the toes keep [`leg_gap`] off the ground
/// (a bird sitting down folds its legs forward under its belly).
pub fn legs_down(leg: &Leg, z: f64, pitch: f64) -> f64 {
    let (s, c) = pitch.sin_cos();
    let hip = z + leg.hip[1] * c + leg.hip[2] * s;
    // Toe height of a swing a: hip − reach·sin(a + pitch).
    let r = ((hip - leg.gap) / leg.reach).clamp(0.0, 1.0);
    LEGS_DOWN.max(std::f64::consts::PI - r.asin() - pitch)
}

/// Leg swing of every bird in every frame (frame-major, radians, see [`WingPose::legs`]); empty
/// for a flight that neither starts on the ground nor lands (the legs trail throughout).
///
/// The legs are lowered (weight w = 1) while a bird of the take-off is on the ground (root less
/// than [`LIFT_OFF_BAND`] above its standing height) and swing back over [`LEG_SWING_S`] seconds
/// after lift-off; in the landing they swing down over the first two thirds of each bird's
/// flare (its touch-down time and the flare's length from the landing record) and stay down.
/// The swing is `w ·` [`legs_down`]. Times, heights and pitch only: the same at any frame rate.
pub fn leg_angles(anim: &Animation, species: Species) -> Vec<f64> {
    let init = anim.stage("initiation").cloned();
    let rec = anim.landing.as_ref();
    if init.is_none() && rec.is_none() {
        return Vec::new();
    }
    let n = anim.birds;
    let nf = anim.frames.len();
    let st = stance(species);
    let leg = leg(species);
    let smooth = |x: f64| {
        let x = x.clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    };
    let on_ground = |k: usize, i: usize| {
        init.as_ref().is_some_and(|s| (s.start..s.end).contains(&k))
            && anim.frames[k]
                .z
                .get(i)
                .is_some_and(|&z| z < st.stand + LIFT_OFF_BAND)
    };
    let mut out = vec![0.0; n * nf];
    for i in 0..n {
        // Lowered on the ground: a ramp of LEG_SWING_S from the weight reached at each change.
        let mut since = f64::NEG_INFINITY;
        let mut was = nf > 0 && on_ground(0, i);
        let mut from = if was { 1.0 } else { 0.0 };
        let mut prev = from;
        for k in 0..nf {
            let f = &anim.frames[k];
            let g = on_ground(k, i);
            if g != was {
                from = prev;
                since = anim.frames[k.saturating_sub(1)].t;
                was = g;
            }
            let target = if g { 1.0 } else { 0.0 };
            let u = if since.is_finite() {
                smooth((f.t - since) / LEG_SWING_S)
            } else {
                1.0
            };
            let ground = from + (target - from) * u;
            prev = ground;
            let landing = rec
                .and_then(|r| r.touchdown.get(i).map(|&td| (td, r.flare_seconds)))
                .map_or(0.0, |(td, fs)| {
                    let fs = fs.max(1e-6);
                    smooth((f.t - (td - fs)) / (2.0 * fs / 3.0))
                });
            let w = ground.max(landing);
            let z = f.z.get(i).copied().unwrap_or(f64::INFINITY);
            let pitch = f
                .pitch
                .as_ref()
                .and_then(|p| p.get(i))
                .copied()
                .unwrap_or(0.0);
            let a = if w > 0.0 && z.is_finite() && pitch.is_finite() {
                w * legs_down(&leg, z, pitch)
            } else {
                0.0
            };
            out[k * n + i] = a;
        }
    }
    out
}

/// Height of the shoulder above the bird's root, wingspans (the built-in birds: 0.02 or less).
const SHOULDER_UP: f64 = 0.02;
/// Reach of a wing from the shoulder to the tip, and half its widest chord, wingspans: at least
/// the built-in birds' (0.44 and 0.125), so the clearance below is on the safe side.
const WING_REACH: f64 = 0.46;
const HALF_CHORD: f64 = 0.13;
/// Least gap kept between a wingtip and the ground, wingspans.
const GROUND_GAP: f64 = 0.01;

/// Lowest point of a wing in `p` below the root, wingspans, for a bird banked by `bank` radians
/// (an upper bound for the built-in birds).
fn wing_drop(p: &WingPose, bank: f64) -> f64 {
    let arm = (0.45 * WING_REACH) * p.dihedral.min(0.0).sin();
    let hand = (0.55 * WING_REACH) * (p.dihedral + p.hand_dihedral).min(0.0).sin();
    let twist = HALF_CHORD * p.arm_twist.sin().abs().max(p.hand_twist.sin().abs());
    -(SHOULDER_UP + arm + hand) + twist + (WING_REACH + 0.1) * bank.sin().abs()
}

/// `p` with its downstroke made shallower where a bird whose root is `height` wingspans above the
/// ground would strike it (a bird running or just airborne): the arm and hand dihedral are scaled
/// towards level until the lowest wing point keeps a small gap. Unchanged higher up.
pub fn clear_ground(p: WingPose, height: f64, bank: f64) -> WingPose {
    let room = height - GROUND_GAP;
    if wing_drop(&p, bank) <= room {
        return p;
    }
    let scaled = |l: f64| WingPose {
        dihedral: if p.dihedral < 0.0 {
            l * p.dihedral
        } else {
            p.dihedral
        },
        hand_dihedral: if p.dihedral + p.hand_dihedral < 0.0 {
            l * p.hand_dihedral
        } else {
            p.hand_dihedral
        },
        ..p
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if wing_drop(&scaled(mid), bank) <= room {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    scaled(lo)
}

/// Wings folded along the body, the primaries crossing over the tail: the whole wing swept back
/// 69°, a quarter folded (so the hand tucks in behind the wrist), level, untwisted.
pub const FOLDED: WingPose = WingPose {
    dihedral: -0.05,
    hand_dihedral: 0.0,
    sweep: -1.2,
    arm_twist: 0.0,
    hand_twist: 0.0,
    spread: 0.75,
    tail_bend: 0.0,
    legs: 0.0,
};

/// The landing flare: wings spread wide and held, raised a little, swept forward, twisted
/// leading edge up (air brakes at a high angle of attack), tail spread down. Our choice from
/// photographs of geese and swans landing (docs/landing.md).
pub const FLARE: WingPose = WingPose {
    dihedral: 0.2,
    hand_dihedral: -0.1,
    sweep: 0.2,
    arm_twist: 0.35,
    hand_twist: 0.25,
    spread: 1.0,
    tail_bend: -0.35,
    legs: 0.0,
};

/// Flare weight of every bird in every frame (frame-major) from the animation's landing record
/// ([`crate::animation::landing::LandingRecord::flare_weight`]); empty without a landing.
pub fn flare_weights(anim: &Animation) -> Vec<f64> {
    let Some(rec) = anim.landing.as_ref() else {
        return Vec::new();
    };
    anim.frames
        .iter()
        .flat_map(|f| (0..anim.birds).map(move |i| rec.flare_weight(i, f.t)))
        .collect()
}

impl WingPose {
    /// The pose a fraction `w` of the way from `self` to `other` (every angle linearly).
    pub fn lerp(&self, other: &WingPose, w: f64) -> WingPose {
        let l = |a: f64, b: f64| a + w * (b - a);
        WingPose {
            dihedral: l(self.dihedral, other.dihedral),
            hand_dihedral: l(self.hand_dihedral, other.hand_dihedral),
            sweep: l(self.sweep, other.sweep),
            arm_twist: l(self.arm_twist, other.arm_twist),
            hand_twist: l(self.hand_twist, other.hand_twist),
            spread: l(self.spread, other.spread),
            tail_bend: l(self.tail_bend, other.tail_bend),
            legs: l(self.legs, other.legs),
        }
    }
}

/// Whether bird `i` is at rest in frame `k` of `anim`.
pub fn at_rest(anim: &Animation, k: usize, i: usize) -> bool {
    let Some(f) = anim.frames.get(k) else {
        return false;
    };
    let (Some(&v), Some(&z)) = (f.speed.get(i), f.z.get(i)) else {
        return false;
    };
    let v_ms = v * anim.wingspan_m;
    v_ms.is_finite() && v_ms < REST_SPEED_MS && z.is_finite() && z < GROUND_BAND
}

/// Fold weight of every bird in every frame (frame-major): 1 at rest (folded, phase held), 0 in
/// the wingbeat, a smoothstep between while the wings unfold or fold. Empty when no bird is ever
/// at rest (the common case of a flight that starts in the air), so callers can skip the blend;
/// otherwise only the frames where some bird's wings are not spread are stored.
pub fn fold_weights(anim: &Animation) -> FrameTable<f64> {
    let n = anim.birds;
    let nf = anim.frames.len();
    if !(anim.wingspan_m.is_finite() && anim.wingspan_m > 0.0) {
        return FrameTable::default();
    }
    let rest: Vec<bool> = (0..nf)
        .flat_map(|k| (0..n).map(move |i| (k, i)))
        .map(|(k, i)| at_rest(anim, k, i))
        .collect();
    if !rest.iter().any(|&r| r) {
        return FrameTable::default();
    }
    let smooth = |x: f64| {
        let x = x.clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    };
    let mut out = FrameTable::new(n, 0.0);
    // Per bird: the time of the last change between rest and motion, the weight then, whether
    // it was at rest, and its weight at the previous frame.
    let mut since = vec![f64::NEG_INFINITY; n];
    let mut from: Vec<f64> = rest[..n]
        .iter()
        .map(|&r| if r { 1.0 } else { 0.0 })
        .collect();
    let mut was = rest[..n].to_vec();
    let mut row = vec![0.0; n];
    for k in 0..nf {
        let t = anim.frames[k].t;
        for i in 0..n {
            let r = rest[k * n + i];
            if r != was[i] {
                // Start the new ramp from the weight reached so far (no jump mid-ramp).
                from[i] = row[i];
                since[i] = anim.frames[k.saturating_sub(1)].t;
                was[i] = r;
            }
            let target = if r { 1.0 } else { 0.0 };
            let u = if since[i].is_finite() {
                smooth((t - since[i]) / UNFOLD_S)
            } else {
                1.0
            };
            row[i] = from[i] + (target - from[i]) * u;
        }
        out.push_row(&row);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::Frame;

    fn anim(speeds: &[f64], fps: f64) -> Animation {
        let frames = speeds
            .iter()
            .enumerate()
            .map(|(k, &v)| Frame {
                t: k as f64 / fps,
                x: vec![0.0],
                y: vec![0.0],
                z: vec![0.07],
                heading: vec![0.0],
                speed: vec![v],
                ..Default::default()
            })
            .collect();
        let mut a = Animation::new(0, fps, 1.5, 1);
        a.frames = frames;
        a
    }

    #[test]
    fn a_resting_bird_is_folded_and_unfolds_smoothly_when_it_runs() {
        let mut v = vec![0.0; 30];
        v.extend((1..60).map(|k| 0.05 * k as f64));
        let table = fold_weights(&anim(&v, 30.0));
        let w: Vec<f64> = (0..v.len()).map(|k| table.get(k).unwrap()).collect();
        assert!(w[..30].iter().all(|&x| x == 1.0));
        // 0.5 m/s = 0.333 wingspans/s: frame 36 is the first in motion.
        assert!(w[36] < 1.0 && w[35] == 1.0, "{:?}", &w[30..40]);
        let done = 35 + (UNFOLD_S * 30.0).ceil() as usize;
        assert!(w[done..].iter().all(|&x| x == 0.0));
        for p in w.windows(2) {
            assert!(p[1] <= p[0]);
        }
    }

    #[test]
    fn legs_stand_straight_down_and_fold_forward_as_the_body_sinks() {
        for sp in Species::ALL {
            let (st, l) = (stance(sp), leg(sp));
            assert_eq!(legs_down(&l, st.stand, 0.0), LEGS_DOWN);
            let sitting = legs_down(&l, st.sit, 0.0);
            assert!(sitting > 2.8, "{sp}: {sitting}");
            let mut prev = LEGS_DOWN;
            for k in 0..=20 {
                let z = st.stand - (st.stand - st.sit) * k as f64 / 20.0;
                let a = legs_down(&l, z, 0.0);
                assert!(a >= prev - 1e-12, "{sp}: {z} {a}");
                // The toes keep the gap (hip height − reach·sin(a)), or lie level with the hip
                // when it is lower than the gap (a sitting crane).
                let hip = z + l.hip[1];
                let toe = hip - l.reach * a.sin();
                assert!(toe >= l.gap.min(hip) - 1e-9, "{sp}: {z} {toe}");
                prev = a;
            }
        }
    }

    #[test]
    fn a_flight_without_rest_needs_no_weights() {
        assert!(fold_weights(&anim(&[5.0; 10], 30.0)).is_empty());
    }
}
