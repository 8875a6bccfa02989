//! Species silhouettes for the pictures: a goose (neck stretched forward, short rounded tail), a
//! crane (long thin neck, legs trailing well past the short tail, grey with black flight
//! feathers) and a pelican (big bill and pouch, head tucked back on the shoulders, broad wings),
//! built as flat 3-D polygons in the bird's body frame so that any camera can project them:
//! the top-down cameras see the plan view, the ground camera sees the birds from below in
//! perspective, with wings foreshortened as they beat and as the bird banks.
//!
//! Body frame: `x` to the bird's right, `y` forward, `z` up, lengths in wingspans (the span of
//! the fully spread wings is 1). Each wing is an arm (shoulder to wrist) and a hand (wrist to
//! tip); the wingbeat's [`WingPose`] moves them:
//! - `dihedral` δ raises the arm about the shoulder's fore–aft axis, `hand_dihedral` δ_h raises
//!   the hand further about the wrist, so a wing seen from above or below spans
//!   `L_a cos δ + L_h cos(δ + δ_h)` instead of `L_a + L_h` (foreshortening of the beat);
//! - `sweep` turns the whole wing about the shoulder's vertical axis (forward positive);
//! - `spread` s < 1 flexes the wrist: the hand folds back by `(1 − s) · 90°` and the arm by a
//!   third of that, so the wing shortens and narrows on the upstroke (wing flex).
//!
//! The bank angle φ (right wing down positive, docs/formats.md §4.4) rolls the whole bird about `y`:
//! `x′ = x cos φ + z sin φ`, `z′ = z cos φ − x sin φ`.
//! Outline proportions are drawn from field-guide plates (span ≈ 1.5 m goose, 2.2 m crane,
//! 2.1 m pelican, scaled to a unit span); they are a picture, not a measured model.

use crate::wingbeat::{Species, WingPose};

/// Colours of one species' silhouette.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plumage {
    /// Body, tail, neck.
    pub body: [u8; 3],
    /// Inner wing (coverts).
    pub arm: [u8; 3],
    /// Outer wing (primaries).
    pub hand: [u8; 3],
    /// Head and bill.
    pub head: [u8; 3],
}

/// The plumage of `species`, as seen against the sky.
pub fn plumage(species: Species) -> Plumage {
    match species {
        // Canada goose: brown-grey back, black neck and head.
        Species::Goose => Plumage {
            body: [58, 52, 50],
            arm: [74, 68, 64],
            hand: [40, 37, 38],
            head: [22, 22, 26],
        },
        // Common crane: ash grey, black primaries and secondaries, dark neck.
        Species::Crane => Plumage {
            body: [118, 122, 128],
            arm: [132, 136, 142],
            hand: [30, 30, 34],
            head: [40, 40, 44],
        },
        // Brown pelican: grey-brown, darker primaries, pale head and a yellowish bill.
        Species::Pelican => Plumage {
            body: [96, 88, 80],
            arm: [118, 110, 100],
            hand: [46, 42, 40],
            head: [206, 186, 128],
        },
    }
}

/// Which colour a part takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    /// Body, tail, neck, legs.
    Body,
    /// Inner wings.
    Arm,
    /// Outer wings.
    Hand,
    /// Head and bill.
    Head,
}

/// Plan-view proportions of a species, wingspans.
struct Build {
    /// Body half-width.
    body_w: f32,
    /// Body from the tail root (negative) to the shoulders and breast (positive).
    body_back: f32,
    body_front: f32,
    /// Neck length forward of the breast, and its half-width.
    neck: f32,
    neck_w: f32,
    /// Head length and half-width, bill length and half-width.
    head: f32,
    head_w: f32,
    bill: f32,
    bill_w: f32,
    /// Tail length behind the tail root, half-width at the root and at the end.
    tail: f32,
    tail_w0: f32,
    tail_w1: f32,
    /// How far the legs trail behind the tail root (0 = none; their hips and reach are the
    /// rig's, `wingbeat::rest::leg`).
    legs: f32,
    /// Arm chord at the body and at the wrist; hand chord at the wrist.
    arm_chord: f32,
    wrist_chord: f32,
    /// Fraction of the semi-span in the arm.
    arm_frac: f32,
    /// Slotted primaries ("fingers") at the tip.
    fingers: bool,
}

fn build(species: Species) -> Build {
    match species {
        Species::Goose => Build {
            body_w: 0.07,
            body_back: -0.19,
            body_front: 0.14,
            neck: 0.17,
            neck_w: 0.018,
            head: 0.045,
            head_w: 0.022,
            bill: 0.035,
            bill_w: 0.011,
            tail: 0.07,
            tail_w0: 0.035,
            tail_w1: 0.025,
            legs: 0.0,
            arm_chord: 0.2,
            wrist_chord: 0.17,
            arm_frac: 0.45,
            fingers: false,
        },
        Species::Crane => Build {
            body_w: 0.055,
            body_back: -0.13,
            body_front: 0.11,
            neck: 0.27,
            neck_w: 0.011,
            head: 0.035,
            head_w: 0.015,
            bill: 0.06,
            bill_w: 0.006,
            tail: 0.05,
            tail_w0: 0.03,
            tail_w1: 0.02,
            legs: 0.13,
            arm_chord: 0.2,
            wrist_chord: 0.18,
            arm_frac: 0.5,
            fingers: true,
        },
        Species::Pelican => Build {
            body_w: 0.08,
            body_back: -0.17,
            body_front: 0.11,
            // Head drawn back onto the shoulders: almost no neck shows.
            neck: 0.02,
            neck_w: 0.03,
            head: 0.05,
            head_w: 0.03,
            bill: 0.22,
            bill_w: 0.032,
            tail: 0.05,
            tail_w0: 0.04,
            tail_w1: 0.035,
            legs: 0.0,
            arm_chord: 0.22,
            wrist_chord: 0.19,
            arm_frac: 0.52,
            fingers: true,
        },
    }
}

/// One flat polygon of the bird in its body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Its colour.
    pub part: Part,
    /// Vertices `(x right, y forward, z up)`, wingspans.
    pub points: Vec<[f32; 3]>,
}

fn flat(part: Part, pts: &[(f32, f32)]) -> Piece {
    Piece {
        part,
        points: pts.iter().map(|&(x, y)| [x, y, 0.0]).collect(),
    }
}

/// Mirror a right-side outline (`x ≥ 0`, tail to front) into a closed symmetric outline.
fn symmetric(part: Part, right: &[(f32, f32)]) -> Piece {
    let mut pts: Vec<(f32, f32)> = right.to_vec();
    pts.extend(right.iter().rev().map(|&(x, y)| (-x, y)));
    flat(part, &pts)
}

/// Rotation of `p` about the axis through `o` along `y` by `a` (x toward z for `a > 0`).
fn roll_y(p: [f32; 3], o: [f32; 3], a: f32) -> [f32; 3] {
    let (s, c) = a.sin_cos();
    let (x, z) = (p[0] - o[0], p[2] - o[2]);
    [o[0] + x * c - z * s, p[1], o[2] + x * s + z * c]
}

/// Rotation of `p` about the vertical through `o` by `a` (x toward y for `a > 0`).
fn yaw_z(p: [f32; 3], o: [f32; 3], a: f32) -> [f32; 3] {
    let (s, c) = a.sin_cos();
    let (x, y) = (p[0] - o[0], p[1] - o[1]);
    [o[0] + x * c - y * s, o[1] + x * s + y * c, p[2]]
}

/// Body, neck and head of `b` as flat outlines in the body's horizontal plane (plan view).
fn trunk(b: &Build) -> Vec<Piece> {
    let mut out = Vec::with_capacity(3);
    // Body: a rounded spindle from the tail root to the breast.
    let body: Vec<(f32, f32)> = (0..=8)
        .map(|k| {
            let t = k as f32 / 8.0;
            let y = b.body_back + (b.body_front - b.body_back) * t;
            // Widest a little ahead of the middle.
            let w = b.body_w * (std::f32::consts::PI * (0.1 + 0.85 * t)).sin().max(0.25);
            (w, y)
        })
        .collect();
    // Tail: a short fan behind the body.
    let tail = [
        (b.tail_w1, b.body_back - b.tail),
        (b.tail_w0, b.body_back + 0.02),
    ];
    let mut body_pts = vec![(0.0, b.body_back - b.tail - 0.01)];
    body_pts.extend(tail);
    body_pts.extend(body);
    out.push(symmetric(Part::Body, &body_pts));
    // Neck forward of the breast.
    let neck_end = b.body_front + b.neck;
    out.push(symmetric(
        Part::Body,
        &[
            (b.neck_w * 1.6, b.body_front - 0.04),
            (b.neck_w, neck_end + 0.01),
        ],
    ));
    // Head and bill.
    let head_end = neck_end + b.head;
    out.push(symmetric(
        Part::Head,
        &[
            (b.head_w * 0.8, neck_end - 0.01),
            (b.head_w, neck_end + 0.4 * b.head),
            (b.bill_w * 1.2, head_end),
            (b.bill_w, head_end + 0.6 * b.bill),
            (b.bill_w * 0.3, head_end + b.bill),
        ],
    ));
    out
}

/// The side view of one bird of `species` banked by `bank` radians: its body, neck and head as
/// outlines in the body's vertical plane, the body as deep as it is wide. The plan view
/// ([`pieces`]) is flat, so a bird seen level with the eye (sitting or running on a field,
/// seen from the ground) would be a line; with its side view it is seen as a bird. From above
/// the side view is a line inside the plan's outline.
pub fn profile(species: Species, bank: f64) -> Vec<Piece> {
    let bank = bank as f32;
    let mut out = trunk(&build(species));
    for p in &mut out {
        for q in &mut p.points {
            // The plan's x (across) becomes up: [x, y, 0] -> [0, y, x].
            *q = roll_y([q[2], q[1], q[0]], [0.0; 3], -bank);
        }
    }
    out
}

/// The polygons of one bird of `species` in wing pose `pose`, banked by `bank` radians (right
/// wing down positive), in the body frame. Drawn in order: wings, body, head.
pub fn pieces(species: Species, pose: &WingPose, bank: f64) -> Vec<Piece> {
    let b = build(species);
    let mut out = Vec::with_capacity(9);
    out.extend(trunk(&b));
    // Legs (cranes): two thin strips from the hips as long as the rig's, swung by the pose's
    // leg swing from trailing behind the tail (0) to down under the body (π/2) and folded
    // forward (towards π).
    if b.legs > 0.0 {
        let leg = crate::wingbeat::rest::leg(species);
        let (y0, reach) = (leg.hip[2] as f32, leg.reach as f32);
        let z0 = leg.hip[1] as f32;
        let (sa, ca) = (pose.legs as f32).sin_cos();
        for side in [-1.0f32, 1.0] {
            let x = side * leg.hip[0] as f32;
            let at = |dx: f32, d: f32| [x + dx, y0 - d * ca, z0 - d * sa];
            out.push(Piece {
                part: Part::Body,
                points: vec![
                    at(-0.004, 0.0),
                    at(0.004, 0.0),
                    at(0.003, reach),
                    at(-0.003, reach),
                ],
            });
        }
    }
    // Wings.
    let flex = (1.0 - pose.spread.clamp(0.0, 1.0)) as f32 * 90f32.to_radians();
    let (dih, hdih, sweep) = (
        pose.dihedral as f32,
        pose.hand_dihedral as f32,
        pose.sweep as f32,
    );
    let semi = 0.5 - b.body_w * 0.6;
    let (la, lh) = (semi * b.arm_frac, semi * (1.0 - b.arm_frac));
    for side in [1.0f32, -1.0] {
        // Build the right wing (x > 0) flat, then move it; mirror x for the left one.
        let root = [b.body_w * 0.6, 0.0, 0.0];
        let lead = b.arm_chord * 0.35;
        // Arm: leading edge bowing forward to the wrist (the carpal joint leads the wing),
        // trailing edge of the secondaries slightly concave.
        let arm_flat = [
            [root[0], lead, 0.0],
            [root[0] + 0.5 * la, b.arm_chord * 0.42, 0.0],
            [root[0] + la, b.wrist_chord * 0.45, 0.0],
            [root[0] + la, -b.wrist_chord * 0.55, 0.0],
            [root[0] + 0.5 * la, -b.arm_chord * 0.58, 0.0],
            [root[0], -b.arm_chord * 0.65, 0.0],
        ];
        let wrist = [root[0] + la, 0.0, 0.0];
        let mut hand_flat: Vec<[f32; 3]> = vec![[wrist[0], b.wrist_chord * 0.45, 0.0]];
        if b.fingers {
            // Slotted tip: five primaries spread like fingers.
            let tip_chord = b.wrist_chord * 0.8;
            hand_flat.push([wrist[0] + lh * 0.7, b.wrist_chord * 0.3, 0.0]);
            for k in 0..5 {
                let f = k as f32 / 4.0;
                let len = lh * (1.0 - 0.15 * f);
                let y = b.wrist_chord * 0.25 - tip_chord * f;
                hand_flat.push([wrist[0] + len, y, 0.0]);
                hand_flat.push([wrist[0] + len * 0.85, y - tip_chord * 0.13, 0.0]);
            }
        } else {
            // Pointed goose hand, swept back to the tip.
            hand_flat.push([wrist[0] + lh * 0.55, b.wrist_chord * 0.3, 0.0]);
            hand_flat.push([wrist[0] + lh, -b.wrist_chord * 0.2, 0.0]);
            hand_flat.push([wrist[0] + lh * 0.8, -b.wrist_chord * 0.42, 0.0]);
            hand_flat.push([wrist[0] + lh * 0.4, -b.wrist_chord * 0.55, 0.0]);
        }
        hand_flat.push([wrist[0], -b.wrist_chord * 0.55, 0.0]);
        let arm_move = |p: [f32; 3]| {
            let p = yaw_z(p, root, -flex / 3.0 + sweep);
            roll_y(p, root, dih)
        };
        let hand_move = |p: [f32; 3]| {
            // Hand about the wrist first (flex back, raise), then carried by the arm.
            let p = yaw_z(p, wrist, -flex);
            arm_move(roll_y(p, wrist, hdih))
        };
        let mirror = |p: [f32; 3]| [side * p[0], p[1], p[2]];
        out.insert(
            0,
            Piece {
                part: Part::Hand,
                points: hand_flat.iter().map(|&p| mirror(hand_move(p))).collect(),
            },
        );
        out.insert(
            0,
            Piece {
                part: Part::Arm,
                points: arm_flat.iter().map(|&p| mirror(arm_move(p))).collect(),
            },
        );
    }
    // Bank: roll everything about the body's fore–aft axis.
    let bank = bank as f32;
    if bank != 0.0 {
        for p in &mut out {
            for q in &mut p.points {
                // Right wing down for bank > 0: x toward −z.
                *q = roll_y(*q, [0.0; 3], -bank);
            }
        }
    }
    out
}

/// Distance from the body origin to the farthest point any pose can reach, wingspans.
pub fn radius(species: Species) -> f64 {
    let b = build(species);
    let front = b.body_front + b.neck + b.head + b.bill;
    let back = -(b.body_back - b.tail.max(b.legs));
    (front.max(back).max(0.5) as f64) + 0.02
}

#[cfg(test)]
mod tests {
    use super::*;

    fn span(p: &[Piece]) -> f32 {
        let xs = p.iter().flat_map(|q| q.points.iter().map(|v| v[0]));
        let (lo, hi) = xs.fold((f32::MAX, f32::MIN), |(a, b), x| (a.min(x), b.max(x)));
        hi - lo
    }

    #[test]
    fn spread_level_wings_span_one_wingspan() {
        for s in Species::ALL {
            let w = span(&pieces(s, &WingPose::EXTENDED, 0.0));
            assert!((w - 1.0).abs() < 0.03, "{s:?}: {w}");
        }
    }

    #[test]
    fn raised_or_flexed_wings_are_foreshortened_and_bank_lowers_the_right_wing() {
        let up = WingPose {
            dihedral: 0.6,
            ..WingPose::EXTENDED
        };
        let flexed = WingPose {
            spread: 0.5,
            ..WingPose::EXTENDED
        };
        for s in Species::ALL {
            let full = span(&pieces(s, &WingPose::EXTENDED, 0.0));
            assert!(span(&pieces(s, &up, 0.0)) < full * 0.9);
            assert!(span(&pieces(s, &flexed, 0.0)) < full * 0.93);
            let banked = pieces(s, &WingPose::EXTENDED, 0.3);
            let right_tip = banked
                .iter()
                .flat_map(|p| p.points.iter())
                .max_by(|a, b| a[0].total_cmp(&b[0]))
                .unwrap();
            assert!(right_tip[2] < -0.1, "{s:?}: {right_tip:?}");
        }
    }

    #[test]
    fn species_differ_where_they_should() {
        let reach = |s: Species, f: fn(&[f32; 3]) -> f32| {
            pieces(s, &WingPose::EXTENDED, 0.0)
                .iter()
                .flat_map(|p| p.points.iter().map(f).collect::<Vec<_>>())
                .fold(f32::MIN, f32::max)
        };
        let front = |p: &[f32; 3]| p[1];
        let back = |p: &[f32; 3]| -p[1];
        // Cranes' legs trail well past their tail; geese and cranes stretch the neck; pelicans'
        // bill is long.
        let crane = build(Species::Crane);
        assert!(reach(Species::Crane, back) > -(crane.body_back - crane.tail) + 0.05);
        // Lowered, they hang under the body.
        let down = WingPose {
            legs: std::f64::consts::FRAC_PI_2,
            ..WingPose::EXTENDED
        };
        let low = pieces(Species::Crane, &down, 0.0)
            .iter()
            .flat_map(|p| p.points.iter().map(|q| q[2]))
            .fold(f32::MAX, f32::min);
        assert!(low < -0.2, "{low}");
        assert!(reach(Species::Crane, front) > reach(Species::Goose, front));
        let b = build(Species::Pelican);
        assert!(b.bill > 3.0 * build(Species::Goose).bill && b.neck < 0.05);
        for s in Species::ALL {
            let r = radius(s) as f32;
            for p in pieces(s, &WingPose::EXTENDED, 0.4) {
                for q in p.points {
                    assert!(
                        (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() <= r,
                        "{s:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_side_view_is_as_deep_as_the_plan_is_wide_and_banks_with_the_bird() {
        let extent = |p: &[Piece], k: usize| {
            let v = p.iter().flat_map(|q| q.points.iter().map(move |v| v[k]));
            let (lo, hi) = v.fold((f32::MAX, f32::MIN), |(a, b), x| (a.min(x), b.max(x)));
            hi - lo
        };
        for s in Species::ALL {
            let b = build(s);
            let side = profile(s, 0.0);
            // Level: in the vertical plane, the body as deep as the plan is wide (within the
            // outline's sampling).
            assert!(extent(&side, 0).abs() < 1e-6, "{s:?}");
            let depth = extent(&side, 2) / (2.0 * b.body_w);
            assert!((0.98..=1.0 + 1e-6).contains(&depth), "{s:?}: {depth}");
            // Same length as the plan's body, neck and head.
            let plan = trunk(&b);
            assert!((extent(&side, 1) - extent(&plan, 1)).abs() < 1e-6);
            // Banked 90°, the side view lies flat (across).
            let rolled = profile(s, std::f64::consts::FRAC_PI_2);
            assert!(
                extent(&rolled, 2) < 1e-5 && extent(&rolled, 0) > 0.1,
                "{s:?}"
            );
        }
    }
}
