//! Text USD for large flocks: the birds as one `UsdGeomPointInstancer` (`render.usd_mode` =
//! instancer) instead of one `SkelRoot` per bird.
//!
//! **Prototypes.** Posed copies of the bird (static meshes, no skeleton), each holding one wing
//! pose the animation uses: chosen by farthest-point sampling over a sample of every stage's
//! bird-frames, then fitted to every bird-frame, until each stage's mean wing-pose error (largest
//! joint-angle difference) is at most `render.crowd_pose_error` (default
//! [`DEFAULT_POSE_ERROR_DEG`]) and its worst at most [`WORST_FACTOR`] times that, or
//! [`MAX_PROTOTYPES`] are chosen. The errors per stage are in the stage metadata
//! (`pose_error_stages`, `pose_error_mean_deg`, `pose_error_worst_deg`, `pose_error`).
//!
//! **Instances.** `/flock/crowd` holds, per time sample, `positions` (metres, the `.glb`'s Y-up
//! axes, relative to the crowd's own translation: the flock's centre at that time, to 1 mm;
//! positions to 0.1 mm, no scale), `velocities` (m/s relative to that centre, to 0.1 m/s),
//! `orientations` (`quath`: heading, pitch and bank, to 1e-3), `angularVelocities` (degrees per
//! second, to 1°/s) and `protoIndices`; `ids` are the bird numbers, with the per-instance
//! primvars `bird_id` and `size`. Bank turns the bird about its body joint, as on the rig.
//!
//! The price: the wingbeat steps between prototypes instead of moving continuously, in
//! exchange for a stage that opens in a fraction of the time.

use std::fmt::Write as _;
use std::io::Write;

use glam::{Quat, Vec3};

use super::bird::{self, BirdAsset, PARENT};
use super::gltf::SceneOptions;
use super::usd::{flown_path_prim, stage_head, time_code, topology, vec3};
use crate::animation::Animation;
use crate::wingbeat::{Flapper, WingPose};

/// Default mean wing-pose error the prototypes must meet in every stage, degrees.
pub const DEFAULT_POSE_ERROR_DEG: f64 = 5.0;
/// Smallest accepted pose error target, degrees.
pub const MIN_POSE_ERROR_DEG: f64 = 0.5;
/// The worst pose error allowed, as a multiple of the mean target (12° at the default 5°).
pub const WORST_FACTOR: f64 = 2.4;
/// Most prototypes of one model (a bound on the stage's size: about 6 kB of text each).
pub const MAX_PROTOTYPES: usize = 1024;
/// Largest number of bird-frames the prototypes are chosen from.
const SAMPLE: usize = 60_000;
/// Flocks of at least this many birds get an instancer when no USD mode is asked for.
pub const INSTANCER_FROM: usize = 200;

/// The wing pose as a vector of its joint angles (spread scaled to radians), the legs' swing
/// last.
fn angles(p: &WingPose) -> [f64; 8] {
    [
        p.dihedral,
        p.hand_dihedral,
        p.sweep,
        p.arm_twist,
        p.hand_twist,
        p.spread * std::f64::consts::FRAC_PI_2,
        p.tail_bend,
        p.legs,
    ]
}

/// Largest angle difference between two poses, radians.
fn distance(a: &[f64; 8], b: &[f64; 8]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The prototype nearest `a` among `protos` and its distance (early exit per prototype once a
/// joint differs by more than the best so far).
fn nearest(a: &[f64; 8], protos: &[[f64; 8]]) -> (usize, f64) {
    let mut best = (0, f64::MAX);
    'p: for (i, p) in protos.iter().enumerate() {
        let mut d = 0.0f64;
        for (x, y) in a.iter().zip(p) {
            d = d.max((x - y).abs());
            if d >= best.1 {
                continue 'p;
            }
        }
        best = (i, d);
    }
    best
}

/// The groups the pose error is measured over: the animation's stages (frames outside every
/// stage form a group `flight`). Returns the group names and each frame's group.
pub fn pose_groups(anim: &Animation) -> (Vec<String>, Vec<usize>) {
    let n = anim.frames.len();
    let mut names: Vec<String> = Vec::new();
    let mut of = vec![usize::MAX; n];
    for st in &anim.stages {
        let name = st.name.as_str().to_string();
        let g = match names.iter().position(|x| *x == name) {
            Some(g) => g,
            None => {
                names.push(name);
                names.len() - 1
            }
        };
        for f in of.iter_mut().take(st.end.min(n)).skip(st.start) {
            *f = g;
        }
    }
    if of.contains(&usize::MAX) {
        names.push("flight".into());
        let g = names.len() - 1;
        for f in of.iter_mut().filter(|f| **f == usize::MAX) {
            *f = g;
        }
    }
    (names, of)
}

/// The wing-pose error a crowd's prototypes make, per group of frames (stage), degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseError {
    /// Group (stage) names.
    pub stages: Vec<String>,
    /// Mean error per group over its bird-frames, degrees.
    pub mean_deg: Vec<f64>,
    /// Worst error per group, degrees.
    pub worst_deg: Vec<f64>,
    /// Number of prototypes (of a model that flaps).
    pub prototypes: usize,
}

impl PoseError {
    /// One line: `stage mean M° worst W°, ...`.
    pub fn text(&self) -> String {
        self.stages
            .iter()
            .zip(self.mean_deg.iter().zip(&self.worst_deg))
            .map(|(s, (m, w))| format!("{s} mean {m:.1}° worst {w:.1}°"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Chooses prototype poses among the bird-frames of `anim` until the mean error of every group
/// (stage) is at most `target` radians and the worst at most [`WORST_FACTOR`] × `target`, or
/// [`MAX_PROTOTYPES`] are chosen. The pool is a sample of every group's bird-frames (each group
/// sampled on its own, so a short take-off is not outweighed by a long cruise); each next
/// prototype is the pose farthest from those chosen: over the whole pool while the worst bound
/// is missed, else within the group furthest over its mean target.
fn choose(anim: &Animation, flapper: &Flapper, birds: &[usize], target: f64) -> Vec<WingPose> {
    let (names, group_of) = pose_groups(anim);
    let groups = names.len();
    let mut pool: Vec<(WingPose, [f64; 8], usize)> = Vec::new();
    for g in 0..groups {
        let frames: Vec<usize> = (0..anim.frames.len())
            .filter(|&k| group_of[k] == g)
            .collect();
        let total = frames.len() * birds.len();
        let step = total.div_ceil(SAMPLE / groups.max(1)).max(1);
        for i in (0..total).step_by(step) {
            let p = flapper.pose(frames[i / birds.len()], birds[i % birds.len()]);
            pool.push((p, angles(&p), g));
        }
    }
    if pool.is_empty() {
        return vec![WingPose::EXTENDED];
    }
    let counts: Vec<f64> = (0..groups)
        .map(|g| pool.iter().filter(|p| p.2 == g).count().max(1) as f64)
        .collect();
    let mut chosen = vec![pool[0].0];
    let mut near: Vec<f64> = pool
        .iter()
        .map(|(_, a, _)| distance(a, &pool[0].1))
        .collect();
    while chosen.len() < MAX_PROTOTYPES {
        let mut sums = vec![0.0; groups];
        for (d, p) in near.iter().zip(&pool) {
            sums[p.2] += d;
        }
        let (worst_i, &worst) = near
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            .expect("a pool");
        let (over_g, over) = (0..groups)
            .map(|g| (g, sums[g] / counts[g] / target))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .expect("a group");
        let pick = if worst > WORST_FACTOR * target {
            worst_i
        } else if over > 1.0 {
            match near
                .iter()
                .enumerate()
                .filter(|(i, _)| pool[*i].2 == over_g)
                .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            {
                Some((i, _)) => i,
                None => break,
            }
        } else {
            break;
        };
        if near[pick] <= 1e-9 {
            break;
        }
        chosen.push(pool[pick].0);
        let a = pool[pick].1;
        for (n, (_, b, _)) in near.iter_mut().zip(&pool) {
            *n = n.min(distance(&a, b));
        }
    }
    chosen
}

/// The bird's vertices in `pose` (bank 0, root at the origin), metres.
fn posed(asset: &BirdAsset, pose: &WingPose, ws: f32) -> Vec<Vec3> {
    let skel = &asset.skeleton;
    let q = bird::joint_rotations(pose, 0.0);
    let mut global = [(Quat::IDENTITY, Vec3::ZERO); bird::N_JOINTS];
    for j in 0..bird::JOINTS.len() {
        let local = if j == bird::NECK || (!asset.wingbeat && j != bird::BODY) {
            skel.rest_rotation(j)
        } else {
            skel.local_rotation(j, q[j])
        };
        let (mut gq, mut gt) = (local, skel.rest_translation(j));
        if let Some(p) = PARENT[j] {
            let (pq, pt) = global[p];
            gt = pt + pq * gt;
            gq = pq * gq;
        }
        global[j] = (gq, gt);
    }
    asset
        .mesh
        .posed(skel, &global)
        .into_iter()
        .map(|p| p * ws)
        .collect()
}

/// A number rounded to `scale` (e.g. 1e4 for 4 decimals), as short text.
/// Without the leading zero of a fraction (`.25`, `-.5`): USD's text format reads both, and these
/// arrays are most of the file.
fn rounded(v: f32, scale: f32) -> String {
    let r = (v * scale).round() / scale;
    if r == 0.0 {
        return "0".into();
    }
    let s = format!("{r}");
    if let Some(rest) = s.strip_prefix("0.") {
        format!(".{rest}")
    } else if let Some(rest) = s.strip_prefix("-0.") {
        format!("-.{rest}")
    } else {
        s
    }
}

/// Prototypes fitted to every bird-frame: the poses, and per bird-frame (frame-major over the
/// flapping birds) its prototype and error (radians).
struct Fit {
    poses: Vec<WingPose>,
    index: Vec<u32>,
    dist: Vec<f32>,
}

/// Joint angles (radians) to 1e-4, in 16 bits (every angle of a wing pose is within ±π).
fn quantise(a: &[f64; 8]) -> [i16; 8] {
    a.map(|x| {
        (x * QUANTUM)
            .round()
            .clamp(i16::MIN as f64, i16::MAX as f64) as i16
    })
}

/// The angles [`quantise`] kept.
fn unquantise(a: &[i16; 8]) -> [f64; 8] {
    a.map(|x| x as f64 / QUANTUM)
}

/// Steps per radian of [`quantise`].
const QUANTUM: f64 = 1e4;

/// Fits `poses` (chosen on a sample by [`choose`]) to every bird-frame of the `flapping` birds,
/// adding the pose of the bird-frame that misses most (the worst error over the worst bound, or
/// the farthest bird-frame of the group furthest over its mean target) until every group
/// (`group_of` each frame's) meets `target` and [`WORST_FACTOR`] × `target`, or
/// [`MAX_PROTOTYPES`] are chosen.
fn refine(
    anim: &Animation,
    flapper: &Flapper,
    flapping: &[usize],
    group_of: &[usize],
    groups: usize,
    mut poses: Vec<WingPose>,
    target: f64,
) -> Fit {
    let nb = flapping.len();
    let n = anim.frames.len();
    // Held to 1e-4 radians (0.006°, far below the smallest error bound a user can ask for) in
    // 16 bits: 16 bytes a bird-frame instead of 64, beside the animation itself.
    let all: Vec<[i16; 8]> = (0..n * nb)
        .map(|j| quantise(&angles(&flapper.pose(j / nb, flapping[j % nb]))))
        .collect();
    let protos: Vec<[f64; 8]> = poses.iter().map(angles).collect();
    let mut index = Vec::with_capacity(all.len());
    let mut dist = Vec::with_capacity(all.len());
    for a in &all {
        let (i, d) = nearest(&unquantise(a), &protos);
        index.push(i as u32);
        dist.push(d as f32);
    }
    let counts: Vec<f64> = (0..groups)
        .map(|g| (group_of.iter().filter(|&&x| x == g).count() * nb).max(1) as f64)
        .collect();
    while poses.len() < MAX_PROTOTYPES {
        let mut sums = vec![0.0f64; groups];
        let mut far = vec![(0usize, 0.0f32); groups];
        for (j, &d) in dist.iter().enumerate() {
            let g = group_of[j / nb];
            sums[g] += d as f64;
            if d > far[g].1 {
                far[g] = (j, d);
            }
        }
        let (wg, &(wj, wd)) = far
            .iter()
            .enumerate()
            .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(b.0.cmp(&a.0)))
            .expect("a group");
        let _ = wg;
        let (og, over) = (0..groups)
            .map(|g| (g, sums[g] / counts[g] / target))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .expect("a group");
        let pick = if wd as f64 > WORST_FACTOR * target {
            wj
        } else if over > 1.0 {
            far[og].0
        } else {
            break;
        };
        if dist[pick] <= 1e-7 {
            break;
        }
        let a = unquantise(&all[pick]);
        let i = poses.len() as u32;
        poses.push(flapper.pose(pick / nb, flapping[pick % nb]));
        for ((x, d), ix) in all.iter().zip(dist.iter_mut()).zip(index.iter_mut()) {
            let e = distance(&unquantise(x), &a) as f32;
            if e < *d {
                *d = e;
                *ix = i;
            }
        }
    }
    Fit { poses, index, dist }
}

/// Writes the `.usda` of `anim` as a point-instanced crowd (see the module documentation).
pub fn write_usda_instancer(
    anim: &Animation,
    wingspan_m: f64,
    opts: &SceneOptions,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let ws = wingspan_m as f32;
    let assets = opts.models(anim);
    let model_of = opts.model_of(anim);
    let flapper = Flapper::from_animation(anim);
    let n = anim.frames.len();
    let birds = anim.birds;
    let target_deg = opts.crowd_pose_error_deg.unwrap_or(DEFAULT_POSE_ERROR_DEG);
    let flapping: Vec<usize> = (0..birds)
        .filter(|&b| assets[model_of[b]].wingbeat)
        .collect();
    let mut poses = if flapping.is_empty() {
        vec![WingPose::EXTENDED]
    } else {
        // The sample's choice aims a little under the target: the whole flock is then fitted.
        choose(anim, &flapper, &flapping, 0.9 * target_deg.to_radians())
    };
    // Each bird-frame's prototype and the error it makes, per stage.
    let (names, group_of) = pose_groups(anim);
    let mut proto_of: Vec<u32> = Vec::new();
    let mut sums = vec![0.0f64; names.len()];
    let mut worst = vec![0.0f64; names.len()];
    let mut counts = vec![0usize; names.len()];
    if poses.len() > 1 || !flapping.is_empty() {
        let fit = refine(
            anim,
            &flapper,
            &flapping,
            &group_of,
            names.len(),
            poses,
            target_deg.to_radians(),
        );
        poses = fit.poses;
        for (j, &d) in fit.dist.iter().enumerate() {
            let g = group_of[j / flapping.len()];
            worst[g] = worst[g].max(d as f64);
            sums[g] += d as f64;
            counts[g] += 1;
        }
        proto_of = fit.index;
    }
    // Each model's prototypes: every pose for a model that flaps, the bind pose for a static
    // one; model m's come after those of the models before it.
    let model_poses: Vec<Vec<WingPose>> = assets
        .iter()
        .map(|a| {
            if a.wingbeat {
                poses.clone()
            } else {
                vec![WingPose::EXTENDED]
            }
        })
        .collect();
    let offsets: Vec<usize> = model_poses
        .iter()
        .scan(0, |acc, p| {
            let o = *acc;
            *acc += p.len();
            Some(o)
        })
        .collect();
    let total: usize = model_poses.iter().map(Vec::len).sum();
    let mut index: Vec<u16> = (0..n * birds)
        .map(|i| offsets[model_of[i % birds.max(1)]] as u16)
        .collect();
    for (j, &i) in proto_of.iter().enumerate() {
        let (k, b) = (j / flapping.len(), flapping[j % flapping.len()]);
        index[k * birds + b] = (offsets[model_of[b]] + i as usize) as u16;
    }
    let error = PoseError {
        stages: names,
        mean_deg: sums
            .iter()
            .zip(&counts)
            .map(|(s, &c)| (s / c.max(1) as f64).to_degrees())
            .collect(),
        worst_deg: worst.iter().map(|w| w.to_degrees()).collect(),
        prototypes: poses.len(),
    };
    let round2 = |v: f64| (v * 100.0).round() / 100.0;
    // The wingbeats' tables are done with: not held beside the birds' flights below.
    drop(flapper);
    let head = stage_head(
        anim,
        wingspan_m,
        &assets,
        opts,
        &serde_json::json!({
            "usd_mode": "instancer",
            "prototypes": total,
            // Each model's body joint in the bird's frame, metres (the bank's pivot).
            "body_m": assets
                .iter()
                .map(|a| (a.skeleton.bind_pos[bird::BODY] * ws).to_array().to_vec())
                .collect::<Vec<_>>(),
            "pose_error_target_deg": target_deg,
            "pose_error_stages": error.stages,
            "pose_error_mean_deg": error.mean_deg.iter().map(|&v| round2(v)).collect::<Vec<_>>(),
            "pose_error_worst_deg": error.worst_deg.iter().map(|&v| round2(v)).collect::<Vec<_>>(),
            "pose_error": error.text(),
        }),
    );
    out.write_all(head.as_bytes())?;
    out.write_all(b"def Xform \"flock\" (\n    kind = \"assembly\"\n)\n{\n")?;
    out.write_all(b"    def PointInstancer \"crowd\"\n    {\n")?;
    let protos: Vec<String> = model_poses
        .iter()
        .enumerate()
        .flat_map(|(m, p)| {
            let several = assets.len() > 1;
            (0..p.len()).map(move |i| {
                format!(
                    "</flock/crowd/prototypes/{}>",
                    proto_name(several.then_some(m), i)
                )
            })
        })
        .collect();
    writeln!(out, "        rel prototypes = [{}]", protos.join(", "))?;
    let ids: Vec<String> = (0..birds).map(|b| b.to_string()).collect();
    writeln!(out, "        int64[] ids = [{}]", ids.join(","))?;
    // Per-instance primvars: the bird's number and size (a shader or a selection can use them).
    writeln!(
        out,
        "        int[] primvars:bird_id = [{}] (\n            interpolation = \"vertex\"\n        )",
        ids.join(",")
    )?;
    let pivots: Vec<Vec3> = (0..birds)
        .map(|b| assets[model_of[b]].skeleton.bind_pos[bird::BODY] * ws)
        .collect();
    // Each bird's size, taken about the same point as on the skeletal birds: an instance scales
    // its prototype about the root, so its position carries the skeleton's shift of `body`.
    let scales = bird::bird_scales(anim.seed, birds, opts.size_variation);
    let sizes: Vec<String> = scales.iter().map(|&s| format!("{s}")).collect();
    writeln!(
        out,
        "        float[] primvars:size = [{}] (\n            interpolation = \"vertex\"\n        )",
        sizes.join(",")
    )?;
    let species = crate::wingbeat::WingbeatOptions::for_animation(anim).species;
    let shifts: Vec<Vec3> = scales
        .iter()
        .zip(&pivots)
        .map(|(&s, &pivot)| (pivot + bird::size_pivot(species, s) * ws) * s)
        .collect();
    // Every instance's point (the prototype's origin) and orientation in world metres, and the
    // flock's centre, per sample. One bird's flight (metres, yaw with pitch, bank) is held at a
    // time.
    let mut world: Vec<Vec3> = vec![Vec3::ZERO; n * birds];
    let mut turn: Vec<Quat> = vec![Quat::IDENTITY; n * birds];
    for b in 0..birds {
        let fl = bird::flight(anim, b, wingspan_m);
        for k in 0..n {
            // The skeleton's world point of a prototype point x: t + yaw·s·(b + d + bank·(x − b))
            // (b the body joint, d its size shift); the instance's: p + yaw·bank·s·x.
            let bank = Quat::from_rotation_z(fl.bank[k]);
            world[k * birds + b] =
                fl.translation[k] + fl.yaw[k] * (shifts[b] - bank * (pivots[b] * scales[b]));
            let q = (fl.yaw[k] * bank).normalize();
            // USD writes quaternions real part first, here in one hemisphere.
            turn[k * birds + b] = if q.w < 0.0 { -q } else { q };
        }
    }
    let centres: Vec<[f64; 3]> = (0..n)
        .map(|k| {
            let mut c = [0.0f64; 3];
            for p in &world[k * birds..(k + 1) * birds] {
                for (ci, v) in c.iter_mut().zip(p.to_array()) {
                    *ci += v as f64;
                }
            }
            c.map(|v| v / birds.max(1) as f64)
        })
        .collect();
    // The neighbours of sample k for central differences (one-sided at the ends) and the time
    // between them, seconds.
    let span = |k: usize| -> (usize, usize, f64) {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
        let dt = anim.frames[b].t - anim.frames[a].t;
        (a, b, if dt > 0.0 { dt } else { 1.0 })
    };
    let mut pos = String::new();
    let mut line = String::new();
    // Positions in metres relative to the flock's centre at each sample (the instancer's own
    // translation, to 1 mm): short numbers however far the flock flies.
    let rounded_centres: Vec<[f64; 3]> = centres
        .iter()
        .map(|c| c.map(|v| (v * 1e3).round() / 1e3))
        .collect();
    out.write_all(b"        uniform token[] xformOpOrder = [\"xformOp:translate\"]\n")?;
    out.write_all(b"        point3f[] positions.timeSamples = {\n")?;
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for k in 0..n {
        pos.clear();
        let c = rounded_centres[k];
        for b in 0..birds {
            let p = world[k * birds + b];
            let local = Vec3::new(
                (p.x as f64 - c[0]) as f32,
                (p.y as f64 - c[1]) as f32,
                (p.z as f64 - c[2]) as f32,
            );
            lo = lo.min(local);
            hi = hi.max(local);
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(
                pos,
                "{sep}({},{},{})",
                rounded(local.x, 1e4),
                rounded(local.y, 1e4),
                rounded(local.z, 1e4)
            );
        }
        writeln!(out, "            {}: [{pos}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n        double3 xformOp:translate.timeSamples = {\n")?;
    for (k, c) in rounded_centres.iter().enumerate() {
        writeln!(
            out,
            "            {}: ({},{},{}),",
            time_code(anim, opts, k),
            c[0],
            c[1],
            c[2]
        )?;
    }
    // Velocities (metres per second, relative to the moving centre: the instancer's own
    // translation carries the flock's) for motion blur, to 0.1 m/s.
    out.write_all(b"        }\n        vector3f[] velocities.timeSamples = {\n")?;
    for k in 0..n {
        line.clear();
        let (a, z, dt) = span(k);
        let cv = [0, 1, 2].map(|i| (centres[z][i] - centres[a][i]) / dt);
        for b in 0..birds {
            let d = world[z * birds + b] - world[a * birds + b];
            let v = [d.x, d.y, d.z]
                .iter()
                .zip(cv)
                .map(|(&d, c)| rounded((d as f64 / dt - c) as f32, 10.0))
                .collect::<Vec<_>>();
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(line, "{sep}({},{},{})", v[0], v[1], v[2]);
        }
        writeln!(out, "            {}: [{line}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n        quath[] orientations.timeSamples = {\n")?;
    for k in 0..n {
        line.clear();
        for b in 0..birds {
            let q = turn[k * birds + b];
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(
                line,
                "{sep}({},{},{},{})",
                rounded(q.w, 1e3),
                rounded(q.x, 1e3),
                rounded(q.y, 1e3),
                rounded(q.z, 1e3)
            );
        }
        writeln!(out, "            {}: [{line}],", time_code(anim, opts, k))?;
    }
    // Angular velocities (degrees per second, about the instancer's axes: the turn from the
    // sample before to the one after), to 1°/s.
    out.write_all(b"        }\n        vector3f[] angularVelocities.timeSamples = {\n")?;
    for k in 0..n {
        line.clear();
        let (a, z, dt) = span(k);
        for b in 0..birds {
            let w = angular_velocity(turn[a * birds + b], turn[z * birds + b], dt as f32);
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(
                line,
                "{sep}({},{},{})",
                rounded(w.x, 1.0),
                rounded(w.y, 1.0),
                rounded(w.z, 1.0)
            );
        }
        writeln!(out, "            {}: [{line}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n        int[] protoIndices.timeSamples = {\n")?;
    for k in 0..n {
        line.clear();
        for b in 0..birds {
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(line, "{sep}{}", index[k * birds + b]);
        }
        writeln!(out, "            {}: [{line}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n")?;
    // The birds' sizes (left out when every bird has size 1).
    if scales.iter().any(|&s| s != 1.0) {
        let items: Vec<String> = scales.iter().map(|&s| format!("({s},{s},{s})")).collect();
        writeln!(out, "        float3[] scales = [{}]", items.join(","))?;
    }
    // The instances' extent over the whole shot (metres about the centre), grown by the largest
    // bird's wingspan.
    let largest = scales.iter().fold(1.0f32, |a, &s| a.max(s));
    let pad = Vec3::splat(ws * largest);
    if n > 0 && birds > 0 {
        writeln!(
            out,
            "        float3[] extent = [{}, {}]",
            vec3(lo - pad),
            vec3(hi + pad)
        )?;
    }
    let several = assets.len() > 1;
    out.write_all(b"        def Scope \"prototypes\"\n        {\n")?;
    for (m, (asset, p)) in assets.iter().zip(&model_poses).enumerate() {
        out.write_all(prototypes(asset, p, ws, several.then_some(m)).as_bytes())?;
    }
    out.write_all(b"        }\n")?;
    out.write_all(b"    }\n")?;
    out.write_all(flown_path_prim(anim, wingspan_m).as_bytes())?;
    out.write_all(b"}\n")?;
    Ok(())
}

/// Angular velocity, degrees per second about the parent's axes, that turns `from` into `to`
/// in `dt` seconds (USD's convention: the turn is applied after the orientation).
fn angular_velocity(from: Quat, to: Quat, dt: f32) -> Vec3 {
    let mut d = to * from.inverse();
    if d.w < 0.0 {
        d = -d;
    }
    let (axis, angle) = d.normalize().to_axis_angle();
    if angle.abs() < 1e-7 || !axis.is_finite() {
        return Vec3::ZERO;
    }
    axis * (angle.to_degrees() / dt)
}

/// The stage's recorded wing-pose error, read back from the head of a crowd `.usda` written by
/// [`write_usda_instancer`]: `(prototypes, text)`, or `None` for a file without one.
pub fn recorded_pose_error(path: &std::path::Path) -> Option<(u64, String)> {
    use std::io::BufRead;
    let f = std::fs::File::open(path).ok()?;
    let (mut protos, mut text) = (None, None);
    for l in std::io::BufReader::new(f).lines().take(64) {
        let l = l.ok()?;
        let l = l.trim();
        if let Some(v) = l.strip_prefix("int64 prototypes = ") {
            protos = v.parse().ok();
        } else if let Some(v) = l.strip_prefix("string pose_error = ") {
            text = serde_json::from_str::<String>(v).ok();
        } else if l.starts_with("defaultPrim") {
            break;
        }
    }
    Some((protos?, text?))
}

/// The name of prototype `i` (of model `model` when there are several models).
fn proto_name(model: Option<usize>, i: usize) -> String {
    match model {
        Some(m) => format!("model_{m}_pose_{i:02}"),
        None => format!("pose_{i:02}"),
    }
}

/// The prototypes of one model: one static mesh of the bird per pose, to go under
/// `/flock/crowd/prototypes`.
fn prototypes(asset: &BirdAsset, poses: &[WingPose], ws: f32, model: Option<usize>) -> String {
    let m = &asset.mesh;
    let (counts, indices, colours) = topology(m);
    let (counts, indices, colours) = (counts.join(", "), indices.join(", "), colours.join(", "));
    let mut s = String::new();
    for (i, pose) in poses.iter().enumerate() {
        let pts = posed(asset, pose, ws);
        let (lo, hi) = pts.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(a, b), &p| (a.min(p), b.max(p)),
        );
        let points: Vec<String> = pts.iter().map(|&p| vec3(p)).collect();
        let _ = writeln!(
            s,
            "            def Mesh \"{}\"\n            {{",
            proto_name(model, i)
        );
        let _ = writeln!(s, "                uniform bool doubleSided = 1");
        let _ = writeln!(
            s,
            "                float3[] extent = [{}, {}]",
            vec3(lo),
            vec3(hi)
        );
        let _ = writeln!(s, "                int[] faceVertexCounts = [{counts}]");
        let _ = writeln!(s, "                int[] faceVertexIndices = [{indices}]");
        let _ = writeln!(
            s,
            "                point3f[] points = [{}]",
            points.join(", ")
        );
        let _ = writeln!(
            s,
            "                color3f[] primvars:displayColor = [{colours}] (\n                    interpolation = \"uniform\"\n                )"
        );
        let _ = writeln!(
            s,
            "                uniform token subdivisionScheme = \"none\"\n            }}"
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wingbeat::Species;

    #[test]
    fn the_extended_pose_is_the_bind_pose() {
        let asset = BirdAsset::builtin(Species::Goose);
        let pts = posed(&asset, &WingPose::EXTENDED, 1.0);
        let worst = pts
            .iter()
            .zip(&asset.mesh.positions)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{worst}");
    }
}
