//! The built-in skinned bird of the glTF and USD exports: a skeleton whose joints follow
//! a documented naming convention, one skinned mesh per species (goose, crane, pelican), and the
//! per-frame motion of every bird (flight on the bird's root, bank on `body`, wingbeat on the wing
//! joints, tail bend on `tail`).
//!
//! Bird frame (glTF conventions, like [`super::rig`]): `+Y` up, `+Z` forward, `+X` the bird's
//! **left**; lengths in wingspans (a bird is 1 wide with its wings spread). Joints, parents first:
//!
//! | index | name | parent | moves with |
//! |---|---|---|---|
//! | 0 | `body` | the bird's root node | bank φ: `R_Z(φ)` (right wing down positive) |
//! | 1 | `neck` | `body` | nothing (a handle for the user's model) |
//! | 2 | `tail` | `body` | tail bend β: `R_X(β)` (up positive) |
//! | 3, 4 | `upper_arm.L`, `hand.L` | `body`, `upper_arm.L` | shoulder and wrist of [`rig::wing_joints`] |
//! | 5, 6 | `upper_arm.R`, `hand.R` | `body`, `upper_arm.R` | the same, mirrored |
//! | 7, 8 | `leg.L`, `leg.R` | `body` | leg swing a: `R_X(−a)` (0 trailing, π/2 straight down) |
//!
//! The bind (rest) pose is the wing spread flat and straight out (every joint rotation the
//! identity), so the inverse bind matrix of joint j is the translation by minus its bind position
//! `−b_j`, and a vertex skinned to joints j with weights w_j lands at
//! ```math
//! v' = \sum_j w_j\, G_j(t)\, T(-b_j)\, v ,
//! ```
//! with G_j(t) the joint's global transform (linear blend skinning, as glTF and UsdSkel define it).
//!
//! Flight: the root node carries the position (world `x, y, z` → glTF/USD `(x, z, −y)`, metres) and
//! the rotation `R_Y(π − θ) R_X(−ϑ)` of the heading θ and the pitch ϑ (nose up positive, the
//! animation's `pitch`, 0 when absent). Bank φ is the animation's `bank` when present, otherwise
//! the coordinated-turn bank `φ = atan(v θ̇ / g)` from the speed v and turn rate θ̇ (clamped to ±45°).

use std::f32::consts::PI;

use glam::{Quat, Vec3};

use super::rig::{self, Side};
use crate::animation::Animation;
use crate::wingbeat::{Flapper, Species, WingPose};

/// Joint names, in skin order (the convention a user's skinned model must follow to get the
/// wingbeat, see `docs/export.md`).
pub const JOINTS: [&str; N_JOINTS] = [
    "body",
    "neck",
    "tail",
    "upper_arm.L",
    "hand.L",
    "upper_arm.R",
    "hand.R",
    "leg.L",
    "leg.R",
];
/// Number of joints of the convention.
pub const N_JOINTS: usize = 9;
/// Parent of each joint in [`JOINTS`] (`None`: the bird's root node).
pub const PARENT: [Option<usize>; N_JOINTS] = [
    None,
    Some(0),
    Some(0),
    Some(0),
    Some(3),
    Some(0),
    Some(5),
    Some(0),
    Some(0),
];
/// Index of `body`.
pub const BODY: usize = 0;
/// Index of `neck`.
pub const NECK: usize = 1;
/// Index of `tail`.
pub const TAIL: usize = 2;

/// Index of a wing's upper-arm joint.
pub const fn arm_joint(side: Side) -> usize {
    match side {
        Side::Left => 3,
        Side::Right => 5,
    }
}

/// Index of a wing's hand joint.
pub const fn hand_joint(side: Side) -> usize {
    arm_joint(side) + 1
}

/// Index of a leg's joint (at the hip; optional in a user's model).
pub const fn leg_joint(side: Side) -> usize {
    match side {
        Side::Left => 7,
        Side::Right => 8,
    }
}

/// Joint paths as UsdSkel wants them (`body/upper_arm_L/hand_L`; USD path elements cannot hold
/// a dot, so `.L` becomes `_L`).
pub fn usd_joint_paths() -> Vec<String> {
    (0..JOINTS.len())
        .map(|j| {
            let mut chain = vec![j];
            while let Some(p) = PARENT[*chain.last().unwrap_or(&0)] {
                chain.push(p);
            }
            chain
                .iter()
                .rev()
                .map(|&k| JOINTS[k].replace('.', "_"))
                .collect::<Vec<_>>()
                .join("/")
        })
        .collect()
}

/// Parts of the bird, one material each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    /// Body plumage.
    Body,
    /// Neck.
    Neck,
    /// Head.
    Head,
    /// Bill.
    Bill,
    /// Inner wing (coverts and secondaries).
    Wing,
    /// Outer wing (primaries).
    Primaries,
    /// Tail.
    Tail,
    /// Legs and feet.
    Legs,
}

impl Part {
    /// Every part, in material order.
    pub const ALL: [Part; 8] = [
        Part::Body,
        Part::Neck,
        Part::Head,
        Part::Bill,
        Part::Wing,
        Part::Primaries,
        Part::Tail,
        Part::Legs,
    ];

    /// Material name.
    pub fn name(self) -> &'static str {
        match self {
            Part::Body => "body",
            Part::Neck => "neck",
            Part::Head => "head",
            Part::Bill => "bill",
            Part::Wing => "wing",
            Part::Primaries => "primaries",
            Part::Tail => "tail",
            Part::Legs => "legs",
        }
    }
}

/// One cross-section of the body loft: an ellipse at `z` (forward), centre height `y`, half width
/// `w`, upper and lower half heights. Wingspans.
#[derive(Debug, Clone, Copy)]
struct Ring {
    z: f32,
    y: f32,
    w: f32,
    up: f32,
    down: f32,
    part: Part,
}

const fn ring(z: f32, y: f32, w: f32, up: f32, down: f32, part: Part) -> Ring {
    Ring {
        z,
        y,
        w,
        up,
        down,
        part,
    }
}

/// One span station of the wing: distance `u` from the shoulder along the span, leading and
/// trailing edge along the chord (forward positive, from the shoulder). Wingspans.
#[derive(Debug, Clone, Copy)]
struct Station {
    u: f32,
    lead: f32,
    trail: f32,
}

const fn st(u: f32, lead: f32, trail: f32) -> Station {
    Station { u, lead, trail }
}

/// Proportions of one species, wingspans (sources and choices in `docs/export.md`).
#[derive(Debug, Clone, Copy)]
struct Proportions {
    /// Left shoulder in the bird frame.
    shoulder: [f32; 3],
    /// Shoulder to wrist along the span.
    arm: f32,
    /// Wrist to tip along the span (shoulder x + arm + hand = 0.5).
    hand: f32,
    /// Neck joint `(y, z)`.
    neck: [f32; 2],
    /// Tail joint `(y, z)`.
    tail: [f32; 2],
    /// Body loft, tail to bill; the bill tip `(y, z)` closes it.
    rings: &'static [Ring],
    bill_tip: [f32; 2],
    /// Wing stations, shoulder to tip.
    wing: &'static [Station],
    /// Left half of the tail fan outline `(x, z)`, from the base outwards and back to the centre.
    tail_fan: &'static [(f32, f32)],
    /// Radius of the legs that the mesh shows (cranes; hips and reach from
    /// [`crate::wingbeat::rest::leg`]), or none.
    legs: Option<f32>,
    /// Linear RGB of each [`Part`].
    colours: [[f32; 3]; 8],
}

use Part::{Bill, Body as B, Head as H, Neck as N};

// Canada goose: span 1.5 m, bill to tail about 0.6 spans, long black neck held straight out,
// narrow pointed wings (mean chord about 0.13 spans), short rounded black tail.
const GOOSE: Proportions = Proportions {
    shoulder: [0.055, 0.03, 0.04],
    arm: 0.19,
    hand: 0.255,
    neck: [0.02, 0.10],
    tail: [0.01, -0.16],
    rings: &[
        ring(-0.21, 0.005, 0.015, 0.008, 0.008, B),
        ring(-0.18, 0.0, 0.045, 0.030, 0.030, B),
        ring(-0.12, 0.0, 0.065, 0.055, 0.060, B),
        ring(-0.04, 0.0, 0.075, 0.062, 0.068, B),
        ring(0.04, 0.005, 0.068, 0.058, 0.060, B),
        ring(0.09, 0.015, 0.045, 0.040, 0.040, B),
        ring(0.13, 0.025, 0.026, 0.026, 0.026, N),
        ring(0.20, 0.035, 0.019, 0.020, 0.020, N),
        ring(0.25, 0.040, 0.020, 0.021, 0.021, N),
        ring(0.275, 0.045, 0.026, 0.027, 0.025, H),
        ring(0.30, 0.046, 0.026, 0.026, 0.022, H),
        ring(0.315, 0.043, 0.018, 0.016, 0.014, H),
        ring(0.325, 0.040, 0.012, 0.008, 0.009, Bill),
        ring(0.355, 0.036, 0.008, 0.004, 0.005, Bill),
    ],
    bill_tip: [0.035, 0.365],
    wing: &[
        st(0.0, 0.045, -0.11),
        st(0.05, 0.055, -0.12),
        st(0.12, 0.065, -0.12),
        st(0.19, 0.075, -0.10),
        st(0.25, 0.065, -0.085),
        st(0.31, 0.048, -0.075),
        st(0.37, 0.025, -0.065),
        st(0.41, 0.0, -0.055),
        st(0.43, -0.02, -0.05),
        st(0.445, -0.04, -0.048),
    ],
    tail_fan: &[
        (0.02, -0.16),
        (0.04, -0.18),
        (0.042, -0.22),
        (0.028, -0.25),
        (0.0, -0.262),
    ],
    legs: None,
    colours: [
        [0.30, 0.24, 0.17],
        [0.02, 0.02, 0.02],
        [0.03, 0.03, 0.03],
        [0.02, 0.02, 0.02],
        [0.26, 0.21, 0.16],
        [0.10, 0.08, 0.07],
        [0.03, 0.03, 0.03],
        [0.05, 0.05, 0.05],
    ],
};

// Common crane: span 2.1 m, slim body, very long thin neck stretched forward, small head, long
// pointed bill, broad wings with a rounded, fingered tip, legs trailing well beyond the tail.
const CRANE: Proportions = Proportions {
    shoulder: [0.05, 0.025, 0.035],
    arm: 0.21,
    hand: 0.24,
    neck: [0.012, 0.09],
    tail: [0.005, -0.14],
    rings: &[
        ring(-0.17, 0.005, 0.02, 0.01, 0.01, B),
        ring(-0.14, 0.0, 0.045, 0.030, 0.035, B),
        ring(-0.08, 0.0, 0.060, 0.045, 0.055, B),
        ring(-0.01, 0.0, 0.062, 0.048, 0.055, B),
        ring(0.05, 0.005, 0.050, 0.040, 0.042, B),
        ring(0.09, 0.012, 0.025, 0.025, 0.025, B),
        ring(0.16, 0.018, 0.014, 0.015, 0.015, N),
        ring(0.26, 0.022, 0.012, 0.013, 0.013, N),
        ring(0.31, 0.024, 0.015, 0.017, 0.015, H),
        ring(0.33, 0.024, 0.015, 0.016, 0.014, H),
        ring(0.345, 0.022, 0.009, 0.009, 0.008, Bill),
        ring(0.39, 0.019, 0.004, 0.003, 0.003, Bill),
    ],
    bill_tip: [0.018, 0.40],
    wing: &[
        st(0.0, 0.045, -0.13),
        st(0.07, 0.06, -0.15),
        st(0.14, 0.07, -0.15),
        st(0.21, 0.075, -0.13),
        st(0.28, 0.07, -0.115),
        st(0.34, 0.055, -0.10),
        st(0.39, 0.035, -0.085),
        st(0.42, 0.01, -0.07),
        st(0.44, -0.015, -0.055),
        st(0.45, -0.03, -0.045),
    ],
    tail_fan: &[
        (0.02, -0.14),
        (0.04, -0.16),
        (0.045, -0.20),
        (0.03, -0.225),
        (0.0, -0.232),
    ],
    legs: Some(0.006),
    colours: [
        [0.40, 0.42, 0.43],
        [0.05, 0.05, 0.05],
        [0.06, 0.05, 0.05],
        [0.45, 0.42, 0.30],
        [0.42, 0.44, 0.45],
        [0.04, 0.04, 0.04],
        [0.10, 0.10, 0.10],
        [0.08, 0.08, 0.08],
    ],
};

// Brown pelican: span 2.0 m, stout body, neck folded so the head rests on the shoulders, a long
// bill with the pouch below it, long broad inner wings.
const PELICAN: Proportions = Proportions {
    shoulder: [0.055, 0.03, 0.04],
    arm: 0.225,
    hand: 0.22,
    neck: [0.03, 0.075],
    tail: [0.01, -0.17],
    rings: &[
        ring(-0.21, 0.005, 0.02, 0.01, 0.01, B),
        ring(-0.18, 0.0, 0.05, 0.035, 0.035, B),
        ring(-0.10, 0.0, 0.068, 0.055, 0.065, B),
        ring(-0.02, 0.0, 0.072, 0.060, 0.070, B),
        ring(0.05, 0.01, 0.065, 0.060, 0.062, B),
        ring(0.095, 0.03, 0.045, 0.045, 0.045, N),
        ring(0.12, 0.045, 0.030, 0.030, 0.028, H),
        ring(0.145, 0.050, 0.024, 0.024, 0.022, H),
        ring(0.16, 0.048, 0.016, 0.010, 0.016, Bill),
        ring(0.20, 0.044, 0.014, 0.006, 0.024, Bill),
        ring(0.26, 0.038, 0.013, 0.006, 0.022, Bill),
        ring(0.30, 0.034, 0.012, 0.005, 0.012, Bill),
        ring(0.32, 0.032, 0.009, 0.005, 0.005, Bill),
    ],
    bill_tip: [0.028, 0.33],
    wing: &[
        st(0.0, 0.045, -0.14),
        st(0.08, 0.06, -0.155),
        st(0.16, 0.07, -0.15),
        st(0.225, 0.075, -0.13),
        st(0.29, 0.068, -0.115),
        st(0.35, 0.05, -0.10),
        st(0.40, 0.025, -0.08),
        st(0.43, 0.0, -0.06),
        st(0.445, -0.02, -0.045),
    ],
    tail_fan: &[
        (0.025, -0.17),
        (0.045, -0.19),
        (0.045, -0.23),
        (0.0, -0.245),
    ],
    legs: None,
    colours: [
        [0.28, 0.26, 0.23],
        [0.20, 0.11, 0.06],
        [0.80, 0.76, 0.58],
        [0.45, 0.33, 0.22],
        [0.30, 0.28, 0.25],
        [0.05, 0.05, 0.05],
        [0.20, 0.19, 0.17],
        [0.10, 0.10, 0.10],
    ],
};

fn proportions(species: Species) -> &'static Proportions {
    match species {
        Species::Goose => &GOOSE,
        Species::Crane => &CRANE,
        Species::Pelican => &PELICAN,
    }
}

/// The skeleton of a bird in its bind pose: every joint's position and rotation in the bird
/// frame (wingspans). The built-in birds bind with every rotation the identity; a user's skinned
/// model may bind its joints rotated (e.g. Blender's bones along their local +Y).
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// Bind position of each joint of [`JOINTS`], bird frame.
    pub bind_pos: [Vec3; N_JOINTS],
    /// Bind rotation of each joint, bird frame.
    pub bind_rot: [Quat; N_JOINTS],
}

impl Skeleton {
    /// The skeleton of the built-in `species`.
    pub fn of(species: Species) -> Skeleton {
        let p = proportions(species);
        let [sx, sy, sz] = p.shoulder;
        let [hx, hy, hz] = crate::wingbeat::rest::leg(species).hip.map(|v| v as f32);
        Skeleton {
            bind_pos: [
                Vec3::ZERO,
                Vec3::new(0.0, p.neck[0], p.neck[1]),
                Vec3::new(0.0, p.tail[0], p.tail[1]),
                Vec3::new(sx, sy, sz),
                Vec3::new(sx + p.arm, sy, sz),
                Vec3::new(-sx, sy, sz),
                Vec3::new(-sx - p.arm, sy, sz),
                Vec3::new(hx, hy, hz),
                Vec3::new(-hx, hy, hz),
            ],
            bind_rot: [Quat::IDENTITY; N_JOINTS],
        }
    }

    fn parent_bind(&self, j: usize) -> (Vec3, Quat) {
        match PARENT[j] {
            Some(p) => (self.bind_pos[p], self.bind_rot[p]),
            None => (Vec3::ZERO, Quat::IDENTITY),
        }
    }

    /// Rest translation of joint `j` in its parent's frame.
    pub fn rest_translation(&self, j: usize) -> Vec3 {
        let (pp, pr) = self.parent_bind(j);
        pr.inverse() * (self.bind_pos[j] - pp)
    }

    /// Rest rotation of joint `j` relative to its parent.
    pub fn rest_rotation(&self, j: usize) -> Quat {
        let (_, pr) = self.parent_bind(j);
        (pr.inverse() * self.bind_rot[j]).normalize()
    }

    /// Local rotation of joint `j` that turns it by `q` (a rotation of [`joint_rotations`], which
    /// are relative to bird-frame-aligned joints): `R_parent⁻¹ · q · R_j` with the bind rotations.
    pub fn local_rotation(&self, j: usize, q: Quat) -> Quat {
        let (_, pr) = self.parent_bind(j);
        (pr.inverse() * q * self.bind_rot[j]).normalize()
    }

    /// Inverse bind matrix of joint `j` with lengths scaled by `scale` (wingspans → metres),
    /// column-major.
    pub fn inverse_bind(&self, j: usize, scale: f32) -> glam::Mat4 {
        glam::Mat4::from_rotation_translation(self.bind_rot[j], self.bind_pos[j] * scale).inverse()
    }
}

/// Local rotations of every joint of [`JOINTS`] for a wing pose and a bank angle (radians).
pub fn joint_rotations(pose: &WingPose, bank: f32) -> [Quat; N_JOINTS] {
    let mut q = [Quat::IDENTITY; N_JOINTS];
    q[BODY] = Quat::from_rotation_z(bank);
    q[TAIL] = Quat::from_rotation_x(pose.tail_bend as f32);
    for side in Side::BOTH {
        let w = rig::wing_joints(pose, side);
        q[arm_joint(side)] = w.shoulder_q;
        q[hand_joint(side)] = w.wrist_q;
        q[leg_joint(side)] = Quat::from_rotation_x(-(pose.legs as f32));
    }
    q
}

/// A triangle mesh skinned to [`JOINTS`], in the bind pose, bird frame, wingspans.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinnedMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Up to four joints per vertex (indices into [`JOINTS`]); unused slots are 0 with weight 0.
    pub joints: Vec<[u8; 4]>,
    /// Weights of `joints`, summing to 1.
    pub weights: Vec<[f32; 4]>,
    /// Triangles (counter-clockwise seen from outside) grouped by part.
    pub parts: Vec<(Part, Vec<u32>)>,
    /// Linear RGB of each part of `parts`.
    pub colours: Vec<[f32; 3]>,
}

impl SkinnedMesh {
    fn vertex(&mut self, p: Vec3, influences: &[(usize, f32)]) -> u32 {
        let mut j = [0u8; 4];
        let mut w = [0f32; 4];
        let mut k = 0;
        for &(joint, weight) in influences {
            if weight > 1e-4 && k < 4 {
                j[k] = joint as u8;
                w[k] = weight;
                k += 1;
            }
        }
        let sum: f32 = w.iter().sum();
        for v in &mut w {
            *v /= sum;
        }
        self.positions.push(p);
        self.normals.push(Vec3::ZERO);
        self.joints.push(j);
        self.weights.push(w);
        self.positions.len() as u32 - 1
    }

    fn tri(&mut self, part: Part, a: u32, b: u32, c: u32) {
        if a == b || b == c || a == c {
            return;
        }
        match self.parts.iter_mut().find(|(p, _)| *p == part) {
            Some((_, v)) => v.extend_from_slice(&[a, b, c]),
            None => self.parts.push((part, vec![a, b, c])),
        }
    }

    /// Adds a vertex with up to four `(joint, weight)` influences (renormalised); returns its index.
    pub(crate) fn push_vertex(&mut self, p: Vec3, influences: &[(usize, f32)]) -> u32 {
        let mut infl: Vec<(usize, f32)> = influences.to_vec();
        infl.sort_by(|a, b| b.1.total_cmp(&a.1));
        if infl.iter().all(|i| i.1 <= 1e-4) {
            infl = vec![(BODY, 1.0)];
        }
        self.vertex(p, &infl)
    }

    /// Area-weighted normals of the vertices of triangles `idx` from those triangles.
    pub(crate) fn face_normals(&mut self, idx: &[u32]) {
        for t in idx.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
            let f = (b - a).cross(c - a);
            for &i in t {
                self.normals[i as usize] += f;
            }
        }
        for &i in idx {
            let n = &mut self.normals[i as usize];
            *n = n.try_normalize().unwrap_or(Vec3::Y);
        }
    }

    /// Sets the triangle groups and their colours (one material each).
    pub(crate) fn set_parts(&mut self, parts: Vec<(Part, Vec<u32>)>, colours: Vec<[f32; 3]>) {
        self.parts = parts;
        self.colours = colours;
    }

    /// Area-weighted vertex normals from the triangles.
    fn smooth_normals(&mut self) {
        for n in &mut self.normals {
            *n = Vec3::ZERO;
        }
        for (_, idx) in &self.parts {
            for t in idx.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
                let f = (b - a).cross(c - a);
                for &i in t {
                    self.normals[i as usize] += f;
                }
            }
        }
        for n in &mut self.normals {
            *n = n.try_normalize().unwrap_or(Vec3::Y);
        }
    }

    /// Positions of the mesh posed by `global` joint transforms (rotation, translation) of every
    /// joint, by linear blend skinning against the bind positions of `skel` (tests and checks).
    pub fn posed(&self, skel: &Skeleton, global: &[(Quat, Vec3); N_JOINTS]) -> Vec<Vec3> {
        self.positions
            .iter()
            .zip(self.joints.iter().zip(&self.weights))
            .map(|(&p, (j, w))| {
                let mut out = Vec3::ZERO;
                for k in 0..4 {
                    if w[k] > 0.0 {
                        let ji = j[k] as usize;
                        let (q, t) = global[ji];
                        let local = skel.bind_rot[ji].inverse() * (p - skel.bind_pos[ji]);
                        out += w[k] * (t + q * local);
                    }
                }
                out
            })
            .collect()
    }
}

/// Smooth step 0 → 1 over x ∈ [0, 1].
fn smooth(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The built-in skinned mesh of `species`, bind pose, wingspans.
pub fn mesh(species: Species) -> SkinnedMesh {
    let p = proportions(species);
    let skel = Skeleton::of(species);
    let mut m = SkinnedMesh::default();
    body(&mut m, p);
    for side in Side::BOTH {
        wing(&mut m, p, &skel, side);
    }
    tail(&mut m, p);
    if let Some(r) = p.legs {
        // Trailing straight back from the hip in the bind pose; the cap reaches `reach`.
        let reach = crate::wingbeat::rest::leg(species).reach as f32;
        for side in Side::BOTH {
            let a = skel.bind_pos[leg_joint(side)];
            let b = a - Vec3::Z * (reach - 0.5 * r);
            tube(&mut m, a, b, r, Part::Legs, &[(leg_joint(side), 1.0)]);
        }
    }
    m.smooth_normals();
    let mut parts = std::mem::take(&mut m.parts);
    parts.sort_by_key(|(part, _)| *part);
    m.colours = parts
        .iter()
        .map(|(part, _)| p.colours[*part as usize])
        .collect();
    m.parts = parts;
    m
}

/// Body, neck, head and bill as one loft of rings, closed at both ends. Rings ahead of the neck
/// joint follow `neck`, blended with `body` over 0.03 wingspans around it.
fn body(m: &mut SkinnedMesh, p: &Proportions) {
    const RING: u32 = 16;
    let neck_z = p.neck[1];
    let weight = |z: f32| {
        let n = smooth((z - (neck_z - 0.015)) / 0.03);
        [(BODY, 1.0 - n), (NECK, n)]
    };
    let first = m.positions.len() as u32;
    for r in p.rings {
        for k in 0..RING {
            let a = k as f32 / RING as f32 * 2.0 * PI;
            let (s, c) = a.sin_cos();
            let h = if s >= 0.0 { r.up } else { r.down };
            m.vertex(Vec3::new(r.w * c, r.y + h * s, r.z), &weight(r.z));
        }
    }
    let n = p.rings.len() as u32;
    for i in 0..n - 1 {
        let part = p.rings[i as usize + 1].part;
        let part = if part == Part::Bill && p.rings[i as usize].part != Part::Bill {
            p.rings[i as usize].part
        } else {
            part
        };
        for k in 0..RING {
            let a = first + i * RING + k;
            let b = first + i * RING + (k + 1) % RING;
            let (c, d) = (a + RING, b + RING);
            // Counter-clockwise seen from outside: the ring runs counter-clockwise seen from the
            // front (+Z), and the loft runs forward.
            m.tri(part, a, b, d);
            m.tri(part, a, d, c);
        }
    }
    let r0 = p.rings[0];
    let back = m.vertex(Vec3::new(0.0, r0.y, r0.z - 0.004), &weight(r0.z));
    let tip = m.vertex(
        Vec3::new(0.0, p.bill_tip[0], p.bill_tip[1]),
        &weight(p.bill_tip[1]),
    );
    let last = first + (n - 1) * RING;
    for k in 0..RING {
        let k1 = (k + 1) % RING;
        m.tri(r0.part, back, first + k1, first + k);
        m.tri(Part::Bill, tip, last + k, last + k1);
    }
}

/// One wing as a closed, cambered surface through the stations: six points per station (leading
/// edge, two on top, trailing edge, two below). Weights: `body` → arm over the first 0.03
/// wingspans, arm → hand over ±0.025 around the wrist.
fn wing(m: &mut SkinnedMesh, p: &Proportions, skel: &Skeleton, side: Side) {
    let s = side.sign();
    let shoulder = skel.bind_pos[arm_joint(side)];
    let (arm, hand) = (arm_joint(side), hand_joint(side));
    let span = p.arm + p.hand;
    let first = m.positions.len() as u32;
    const SECTION: u32 = 6;
    for stn in p.wing {
        let chord = (stn.lead - stn.trail).max(1e-3);
        // Thickness: 10 % of the chord at the root thinning to 3 % at the tip; camber 4 %.
        let f = stn.u / span;
        let thick = chord * (0.10 - 0.07 * f);
        let camber = chord * 0.04;
        let at = |x: f32| stn.lead - x * chord;
        let section = [
            (at(0.0), 0.0),
            (at(0.25), camber + 0.5 * thick),
            (at(0.6), 0.8 * camber + 0.3 * thick),
            (at(1.0), 0.0),
            (at(0.6), 0.8 * camber - 0.2 * thick),
            (at(0.25), camber - 0.4 * thick),
        ];
        let wh = smooth((stn.u - (p.arm - 0.025)) / 0.05);
        let wb = 1.0 - smooth(stn.u / 0.03);
        let wa = (1.0 - wh) * (1.0 - wb);
        let infl = [(BODY, wb), (arm, wa), (hand, wh * (1.0 - wb))];
        for (c, y) in section {
            m.vertex(shoulder + Vec3::new(s * stn.u, y, c), &infl);
        }
    }
    let n = p.wing.len() as u32;
    for i in 0..n - 1 {
        let part = if p.wing[i as usize].u >= p.arm - 1e-4 {
            Part::Primaries
        } else {
            Part::Wing
        };
        for k in 0..SECTION {
            let a = first + i * SECTION + k;
            let b = first + i * SECTION + (k + 1) % SECTION;
            let (c, d) = (a + SECTION, b + SECTION);
            // The section runs lead → top → trail → bottom; orientation fixed by `s` so that the
            // faces point outwards on both wings.
            if s > 0.0 {
                m.tri(part, a, d, b);
                m.tri(part, a, c, d);
            } else {
                m.tri(part, a, b, d);
                m.tri(part, a, d, c);
            }
        }
    }
    // Close the tip with a fan around its centre; the root stays open inside the body.
    let last = first + (n - 1) * SECTION;
    let stn = p.wing[n as usize - 1];
    let centre = m.vertex(
        shoulder + Vec3::new(s * (stn.u + 0.004), 0.0, 0.5 * (stn.lead + stn.trail)),
        &[(hand, 1.0)],
    );
    for k in 0..SECTION {
        let (a, b) = (last + k, last + (k + 1) % SECTION);
        if s > 0.0 {
            m.tri(Part::Primaries, centre, b, a);
        } else {
            m.tri(Part::Primaries, centre, a, b);
        }
    }
}

/// The tail fan, a thin slab on the `tail` joint (top and bottom faces).
fn tail(m: &mut SkinnedMesh, p: &Proportions) {
    let y = p.tail[0];
    let z0 = p.tail[1];
    let mut outline: Vec<(f32, f32)> = p.tail_fan.to_vec();
    // Mirror to the right side (skipping the centre point at the end).
    let right: Vec<(f32, f32)> = p
        .tail_fan
        .iter()
        .rev()
        .skip(1)
        .map(|&(x, z)| (-x, z))
        .collect();
    outline.extend(right);
    for (dy, up) in [(0.004f32, true), (-0.004, false)] {
        let c = m.vertex(Vec3::new(0.0, y + dy, z0), &[(TAIL, 1.0)]);
        let ids: Vec<u32> = outline
            .iter()
            .map(|&(x, z)| m.vertex(Vec3::new(x, y + dy, z), &[(TAIL, 1.0)]))
            .collect();
        for w in ids.windows(2) {
            let (a, b) = (w[0], w[1]);
            // The outline runs down the left side and up the right: (c, a, b) faces +Y.
            if up {
                m.tri(Part::Tail, c, a, b);
            } else {
                m.tri(Part::Tail, c, b, a);
            }
        }
    }
}

/// A six-sided tube from `a` to `b`, closed at the far end.
fn tube(m: &mut SkinnedMesh, a: Vec3, b: Vec3, r: f32, part: Part, infl: &[(usize, f32)]) {
    const SIDES: u32 = 6;
    let axis = (b - a).normalize();
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let first = m.positions.len() as u32;
    for (end, rr) in [(a, r), (b, 0.7 * r)] {
        for k in 0..SIDES {
            let t = k as f32 / SIDES as f32 * 2.0 * PI;
            m.vertex(end + rr * (t.cos() * u + t.sin() * v), infl);
        }
    }
    for k in 0..SIDES {
        let (i0, i1) = (first + k, first + (k + 1) % SIDES);
        let (j0, j1) = (i0 + SIDES, i1 + SIDES);
        m.tri(part, i0, i1, j1);
        m.tri(part, i0, j1, j0);
    }
    let cap = m.vertex(b + 0.5 * r * axis, infl);
    for k in 0..SIDES {
        m.tri(
            part,
            cap,
            first + SIDES + k,
            first + SIDES + (k + 1) % SIDES,
        );
    }
}

/// What every bird of an export wears: a skeleton following [`JOINTS`], a mesh skinned to it,
/// and whether the wing and tail joints play the wingbeat (a static user model only flies and
/// banks).
#[derive(Debug, Clone, PartialEq)]
pub struct BirdAsset {
    /// Where it comes from (`built-in goose`, or the user's file), for metadata.
    pub source: String,
    /// Bind pose of the joints.
    pub skeleton: Skeleton,
    /// The skinned mesh, bind pose, bird frame, wingspans.
    pub mesh: SkinnedMesh,
    /// Whether the wing and tail joints are animated.
    pub wingbeat: bool,
}

impl BirdAsset {
    /// Whether the legs' joints move anything: a skinned model with vertices on `leg.L` or
    /// `leg.R` (the built-in crane). Without, the leg joints stay at rest (no animation for them).
    pub fn has_legs(&self) -> bool {
        let legs = Side::BOTH.map(leg_joint);
        self.wingbeat
            && self
                .mesh
                .joints
                .iter()
                .zip(&self.mesh.weights)
                .any(|(j, w)| (0..4).any(|k| w[k] > 0.0 && legs.contains(&(j[k] as usize))))
    }

    /// The built-in bird of `species`.
    pub fn builtin(species: Species) -> BirdAsset {
        BirdAsset {
            source: format!("built-in {species}"),
            skeleton: Skeleton::of(species),
            mesh: mesh(species),
            wingbeat: true,
        }
    }
}

/// Default spread of the birds' sizes (`render.size_variation`): the coefficient of variation of
/// the wingspan, the same for every species. Our choice, not a measurement (the project's field
/// data has no within-flock wingspan spread): a few per cent, so that a flock does not look cloned
/// while no bird looks like another species.
pub const DEFAULT_SIZE_VARIATION: f64 = 0.04;
/// Largest accepted `render.size_variation`.
pub const MAX_SIZE_VARIATION: f64 = 0.3;
/// How far the normal draw of a bird's size is clipped, standard deviations.
pub const SIZE_CLIP_SIGMA: f64 = 3.0;

/// The default size variation of `species` ([`DEFAULT_SIZE_VARIATION`] for every species).
pub fn default_size_variation(species: Species) -> f64 {
    let _ = species;
    DEFAULT_SIZE_VARIATION
}

/// Each bird's uniform scale for a size variation `variation` (F): `s = 1 + F·z`, z a standard
/// normal draw clipped to ±[`SIZE_CLIP_SIGMA`], drawn for birds 0, 1, … in order from the
/// stream `export.sizes` of the animation's `seed` (so bird k's size does not depend on the
/// flock's size). `variation` 0 gives every bird scale 1 exactly.
pub fn bird_scales(seed: u64, birds: usize, variation: f64) -> Vec<f32> {
    use rand::Rng;
    if variation == 0.0 {
        return vec![1.0; birds];
    }
    let mut rng = crate::rng::stream(seed, crate::rng::Stream::BirdSizes);
    (0..birds)
        .map(|_| {
            let z: f64 = rng.sample(rand_distr::StandardNormal);
            (1.0 + variation * z.clamp(-SIZE_CLIP_SIGMA, SIZE_CLIP_SIGMA)) as f32
        })
        .collect()
}

/// Which of `models` bird models each of `birds` birds wears: every model on the same number
/// of birds (to one), which birds at random (a Fisher–Yates shuffle of `0, 1, …, models − 1,
/// 0, 1, …` drawn from the stream `export.models` of the animation's `seed`). One model (or
/// none) gives every bird model 0.
pub fn model_assignment(seed: u64, birds: usize, models: usize) -> Vec<usize> {
    use rand::Rng;
    let mut out: Vec<usize> = (0..birds).map(|b| b % models.max(1)).collect();
    if models <= 1 {
        return out;
    }
    let mut rng = crate::rng::stream(seed, crate::rng::Stream::BirdModels);
    for i in (1..birds).rev() {
        let j = rng.random_range(0..=i);
        out.swap(i, j);
    }
    out
}

/// Where the size of a bird of `scale` is taken about, as a shift of its `body` joint in the
/// root's frame (wingspans, before the root's scale): the point on the ground under a sitting
/// bird of `species` (its sitting height below the root, `wingbeat::rest::stance`). The root's
/// scale alone would grow a bird about its centre and push a larger one's belly into the ground
/// at rest; with this shift `s·(b + p) = p` for that point p, so every bird sits on the ground as
/// the built-in one of scale 1 does, and a flying bird's centre moves by (s − 1)·h_sit, under
/// 0.01 wingspans for the default spread.
pub fn size_pivot(species: Species, scale: f32) -> Vec3 {
    let sit = crate::wingbeat::rest::stance(species).sit as f32;
    Vec3::new(0.0, sit * (1.0 - 1.0 / scale), 0.0)
}

/// The flight of one bird on export axes: per frame the root translation (metres, `(x, z, −y)`),
/// the yaw quaternion of the root and the bank angle of `body` (radians).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Flight {
    /// Root translation per frame, metres.
    pub translation: Vec<Vec3>,
    /// Root rotation (yaw, then pitch) per frame, sign-continuous.
    pub yaw: Vec<Quat>,
    /// Bank per frame, radians, right wing down positive.
    pub bank: Vec<f32>,
}

/// Largest bank derived from the turn rate when the animation has none, radians (45°).
pub const MAX_DERIVED_BANK: f32 = PI / 4.0;

/// The flight of `bird` (formulas in the module doc).
pub fn flight(anim: &Animation, bird: usize, wingspan_m: f64) -> Flight {
    let ws = wingspan_m as f32;
    let g = (9.81 / wingspan_m) as f32;
    let n = anim.frames.len();
    let at = |v: &Vec<f64>| v.get(bird).copied().unwrap_or(0.0);
    let mut out = Flight {
        translation: Vec::with_capacity(n),
        yaw: Vec::with_capacity(n),
        bank: Vec::with_capacity(n),
    };
    let mut prev = Quat::IDENTITY;
    for (k, f) in anim.frames.iter().enumerate() {
        out.translation.push(Vec3::new(
            at(&f.x) as f32 * ws,
            at(&f.z) as f32 * ws,
            -(at(&f.y) as f32) * ws,
        ));
        let theta = at(&f.heading) as f32;
        // Nose up ϑ: about the bird's left axis (+X), which takes its front (+Z) toward up.
        let pitch = f.pitch.as_ref().map_or(0.0, at) as f32;
        let q = continuous(
            prev,
            Quat::from_rotation_y(PI - theta) * Quat::from_rotation_x(-pitch),
        );
        prev = q;
        out.yaw.push(q);
        let bank = match &f.bank {
            Some(b) => at(b) as f32,
            None => {
                let (ka, kb) = (k.saturating_sub(2), (k + 2).min(n - 1));
                let rate = if kb > ka {
                    let (fa, fb) = (&anim.frames[ka], &anim.frames[kb]);
                    (super::sample::angle_diff(at(&fa.heading), at(&fb.heading)) / (fb.t - fa.t))
                        as f32
                } else {
                    0.0
                };
                (at(&f.speed) as f32 * rate / g)
                    .atan()
                    .clamp(-MAX_DERIVED_BANK, MAX_DERIVED_BANK)
            }
        };
        out.bank.push(bank);
    }
    out
}

/// Joint rotations of `bird` at every frame, sign-continuous per joint (so LINEAR/slerp keys
/// never take the long way round).
pub fn joint_track(flapper: &Flapper, flight: &Flight, bird: usize) -> Vec<[Quat; N_JOINTS]> {
    let n = flight.bank.len();
    let mut out: Vec<[Quat; N_JOINTS]> = Vec::with_capacity(n);
    for k in 0..n {
        let mut q = joint_rotations(&flapper.pose(k, bird), flight.bank[k]);
        if let Some(p) = out.last() {
            for j in 0..N_JOINTS {
                q[j] = continuous(p[j], q[j]);
            }
        }
        out.push(q);
    }
    out
}

/// Chooses the sign of `q` closest to `prev`.
pub fn continuous(prev: Quat, q: Quat) -> Quat {
    let q = q.normalize();
    if prev.dot(q) < 0.0 {
        -q
    } else {
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_species_spans_one_wingspan_and_weights_sum_to_one() {
        for sp in Species::ALL {
            let m = mesh(sp);
            let xs: Vec<f32> = m.positions.iter().map(|p| p.x).collect();
            let max = xs.iter().cloned().fold(f32::MIN, f32::max);
            let min = xs.iter().cloned().fold(f32::MAX, f32::min);
            assert!(
                (max - 0.5).abs() < 0.01 && (min + 0.5).abs() < 0.01,
                "{sp}: {min} {max}"
            );
            for w in &m.weights {
                assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
                assert!(w.iter().all(|&v| v >= 0.0));
            }
            for n in &m.normals {
                assert!((n.length() - 1.0).abs() < 1e-4);
            }
            let nv = m.positions.len() as u32;
            assert!(m.parts.iter().all(|(_, t)| t.iter().all(|&i| i < nv)));
        }
    }

    #[test]
    fn bind_pose_skinning_is_the_identity_and_a_raised_wing_lifts_its_tip() {
        let skel = Skeleton::of(Species::Goose);
        let m = mesh(Species::Goose);
        let rest: [(Quat, Vec3); N_JOINTS] =
            std::array::from_fn(|j| (Quat::IDENTITY, skel.bind_pos[j]));
        let posed = m.posed(&skel, &rest);
        for (a, b) in posed.iter().zip(&m.positions) {
            assert!((*a - *b).length() < 1e-6);
        }
        // Raise the left shoulder 30°: the left tip goes up, the right one stays.
        let pose = WingPose {
            dihedral: 0.5,
            ..WingPose::EXTENDED
        };
        let q = joint_rotations(&pose, 0.0);
        let mut global = rest;
        for j in 0..N_JOINTS {
            let (mut gq, mut gt) = (q[j], skel.rest_translation(j));
            if let Some(p) = PARENT[j] {
                let (pq, pt) = global[p];
                gt = pt + pq * gt;
                gq = pq * gq;
            }
            global[j] = (gq, gt);
        }
        let posed = m.posed(&skel, &global);
        let tip = |x: f32| {
            m.positions
                .iter()
                .zip(&posed)
                .filter(|(p, _)| p.x * x > 0.44)
                .map(|(_, q)| q.y)
                .fold(f32::MIN, f32::max)
        };
        assert!(tip(1.0) > 0.15, "left tip {}", tip(1.0));
        assert!(tip(-1.0) > 0.15, "right tip (mirrored pose) {}", tip(-1.0));
    }

    #[test]
    fn bird_scales_are_clipped_seeded_and_one_without_variation() {
        assert!(bird_scales(7, 50, 0.0).iter().all(|&s| s == 1.0));
        let a = bird_scales(7, 2000, 0.1);
        assert_eq!(a, bird_scales(7, 2000, 0.1));
        assert_ne!(a, bird_scales(8, 2000, 0.1));
        // Bird k's size does not depend on the flock's size.
        assert_eq!(bird_scales(7, 10, 0.1)[..], a[..10]);
        assert!(a.iter().all(|&s| (0.7 - 1e-6..=1.3 + 1e-6).contains(&s)));
        let mean = a.iter().map(|&s| f64::from(s)).sum::<f64>() / a.len() as f64;
        let sd = (a
            .iter()
            .map(|&s| (f64::from(s) - mean).powi(2))
            .sum::<f64>()
            / a.len() as f64)
            .sqrt();
        assert!(
            (mean - 1.0).abs() < 0.01 && (sd - 0.1).abs() < 0.01,
            "{mean} {sd}"
        );
    }

    #[test]
    fn models_are_shared_out_evenly_at_random_and_seeded() {
        assert_eq!(model_assignment(3, 5, 1), vec![0; 5]);
        assert_eq!(model_assignment(3, 5, 0), vec![0; 5]);
        let a = model_assignment(3, 100, 3);
        assert_eq!(a, model_assignment(3, 100, 3));
        assert_ne!(a, model_assignment(4, 100, 3));
        let count = |m: usize| a.iter().filter(|&&x| x == m).count();
        assert_eq!((count(0), count(1), count(2)), (34, 33, 33));
        // Shuffled, not in turn.
        assert_ne!(a, (0..100).map(|b| b % 3).collect::<Vec<_>>());
        // Fewer birds than models: each bird a different model.
        let few = model_assignment(9, 2, 3);
        assert!(few[0] != few[1] && few.iter().all(|&m| m < 3));
    }

    #[test]
    fn a_scaled_bird_keeps_its_sitting_ground_point() {
        for sp in Species::ALL {
            let sit = crate::wingbeat::rest::stance(sp).sit as f32;
            let ground = Vec3::new(0.0, -sit, 0.0);
            for s in [0.85_f32, 1.0, 1.12] {
                let moved = s * (size_pivot(sp, s) + ground);
                assert!((moved - ground).length() < 1e-6, "{sp} {s}: {moved}");
            }
        }
    }

    #[test]
    fn usd_paths_follow_the_hierarchy() {
        let p = usd_joint_paths();
        assert_eq!(p[0], "body");
        assert_eq!(p[4], "body/upper_arm_L/hand_L");
        assert_eq!(p[6], "body/upper_arm_R/hand_R");
    }
}
