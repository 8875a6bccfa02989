//! Text USD for large flocks: the birds as one `UsdGeomPointInstancer` (`render.usd_mode` =
//! instancer) instead of one `SkelRoot` per bird.
//!
//! **Prototypes.** A few posed copies of the bird (static meshes, no skeleton), each holding one
//! wing pose: the poses the animation actually uses, chosen by farthest-point sampling over the
//! birds' poses (the first is the pose of the first bird at its first frame; each next one is the
//! pose farthest from those chosen, over a sample of the bird-frames), so a take-off's folded
//! wings, its run-up strokes, the cruise wingbeat and glides each get prototypes. Every bird at
//! every frame shows the prototype nearest its exact pose (largest joint-angle difference); the
//! worst and mean differences are recorded in the stage metadata (`pose_error_rad`).
//!
//! **Instances.** `/flock/crowd` holds, per time sample, `positions` (metres, the `.glb`'s Y-up
//! axes, relative to the crowd's own translation: the flock's centre at that time, to 1 mm),
//! `orientations` (`quath`: heading, pitch and bank) and `protoIndices`; `ids` are the bird
//! numbers. Bank turns the bird about its body joint, as on the rig. Positions are written to
//! 1 mm and orientation components to 1e-3 (about 0.1°; `quath` itself keeps about 5e-4),
//! without spaces or the leading zeros of fractions: the arrays are most of the file.
//!
//! The price: the wingbeat steps between prototypes instead of moving continuously (about 13°
//! at most with 24 prototypes on the README flock), in exchange for a stage that opens in a
//! fraction of the time.

use std::fmt::Write as _;
use std::io::Write;

use glam::{Quat, Vec3};

use super::bird::{self, BirdAsset, PARENT};
use super::gltf::SceneOptions;
use super::usd::{flown_path_prim, stage_head, time_code, topology, vec3};
use crate::animation::Animation;
use crate::wingbeat::{Flapper, WingPose};

/// Prototypes of a crowd (wing poses).
pub const PROTOTYPES: usize = 24;
/// Largest number of bird-frames the prototypes are chosen from.
const SAMPLE: usize = 40_000;
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

/// Farthest-point choice of `count` poses among those of the bird-frames of `anim`.
fn choose(anim: &Animation, flapper: &Flapper, count: usize) -> Vec<WingPose> {
    let total = anim.frames.len() * anim.birds;
    let step = total.div_ceil(SAMPLE).max(1);
    let pool: Vec<(WingPose, [f64; 8])> = (0..total)
        .step_by(step)
        .map(|i| {
            let p = flapper.pose(i / anim.birds, i % anim.birds);
            (p, angles(&p))
        })
        .collect();
    if pool.is_empty() {
        return vec![WingPose::EXTENDED];
    }
    let mut chosen = vec![pool[0].0];
    let mut near: Vec<f64> = pool.iter().map(|(_, a)| distance(a, &pool[0].1)).collect();
    while chosen.len() < count {
        let (i, &d) = near
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            .expect("a pool");
        if d <= 1e-9 {
            break;
        }
        chosen.push(pool[i].0);
        let a = pool[i].1;
        for (n, (_, b)) in near.iter_mut().zip(&pool) {
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
    let poses = if assets.iter().any(|a| a.wingbeat) {
        choose(anim, &flapper, PROTOTYPES)
    } else {
        vec![WingPose::EXTENDED]
    };
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
    let pose_angles: Vec<[f64; 8]> = poses.iter().map(angles).collect();
    let n = anim.frames.len();
    let birds = anim.birds;
    // Each bird-frame's prototype and the error it makes.
    let mut index: Vec<u16> = (0..n * birds)
        .map(|i| offsets[model_of[i % birds.max(1)]] as u16)
        .collect();
    let (mut worst, mut sum) = (0.0f64, 0.0f64);
    if poses.len() > 1 {
        for k in 0..n {
            for b in (0..birds).filter(|&b| assets[model_of[b]].wingbeat) {
                let a = angles(&flapper.pose(k, b));
                let (i, d) = pose_angles
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (i, distance(&a, p)))
                    .min_by(|x, y| x.1.total_cmp(&y.1))
                    .unwrap_or((0, 0.0));
                index[k * birds + b] = (offsets[model_of[b]] + i) as u16;
                worst = worst.max(d);
                sum += d;
            }
        }
    }
    let mean = sum / (n * birds).max(1) as f64;
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
            "pose_error_rad": format!("worst {worst:.4}, mean {mean:.4}"),
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
    writeln!(out, "        int64[] ids = [{}]", ids.join(", "))?;
    // The flight of every bird (metres, yaw with pitch, bank).
    let flights: Vec<bird::Flight> = (0..birds)
        .map(|b| bird::flight(anim, b, wingspan_m))
        .collect();
    let pivots: Vec<Vec3> = (0..birds)
        .map(|b| assets[model_of[b]].skeleton.bind_pos[bird::BODY] * ws)
        .collect();
    // Each bird's size, taken about the same point as on the skeletal birds: an instance scales
    // its prototype about the root, so its position carries the skeleton's shift of `body`.
    let scales = bird::bird_scales(anim.seed, birds, opts.size_variation);
    let species = crate::wingbeat::WingbeatOptions::for_animation(anim).species;
    let shifts: Vec<Vec3> = scales
        .iter()
        .zip(&pivots)
        .map(|(&s, &pivot)| (pivot + bird::size_pivot(species, s) * ws) * s)
        .collect();
    let mut pos = String::new();
    let mut rot = String::new();
    let mut idx = String::new();
    // Positions in whole millimetres relative to the flock's centre at each frame (the
    // instancer's own translation, rounded to 1 mm; its scale 0.001 turns millimetres into
    // metres, and each prototype's scale 1000 undoes it for the bird): short numbers however far
    // the flock flies, as glTF's quantised positions do it.
    let mut centres: Vec<[f64; 3]> = Vec::with_capacity(n);
    let mut world: Vec<Vec3> = Vec::with_capacity(birds);
    out.write_all(
        b"        uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:scale\"]\n",
    )?;
    out.write_all(b"        double3 xformOp:scale = (0.001, 0.001, 0.001)\n")?;
    out.write_all(b"        point3f[] positions.timeSamples = {\n")?;
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for k in 0..n {
        world.clear();
        for (b, fl) in flights.iter().enumerate() {
            // The skeleton's world point of a prototype point x: t + yaw·s·(b + d + bank·(x − b))
            // (b the body joint, d its size shift); the instance's: p + yaw·bank·s·x.
            let bank = Quat::from_rotation_z(fl.bank[k]);
            world
                .push(fl.translation[k] + fl.yaw[k] * (shifts[b] - bank * (pivots[b] * scales[b])));
        }
        let mut c = [0.0f64; 3];
        for p in &world {
            for (ci, v) in c.iter_mut().zip(p.to_array()) {
                *ci += v as f64;
            }
        }
        let c = c.map(|v| (v / birds.max(1) as f64 * 1e3).round() / 1e3);
        centres.push(c);
        pos.clear();
        for (b, p) in world.iter().enumerate() {
            let mm = |v: f32, c: f64| ((v as f64 - c) * 1e3).round() as i64;
            let (x, y, z) = (mm(p.x, c[0]), mm(p.y, c[1]), mm(p.z, c[2]));
            let local = Vec3::new(x as f32, y as f32, z as f32);
            lo = lo.min(local);
            hi = hi.max(local);
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(pos, "{sep}({x},{y},{z})");
        }
        writeln!(out, "            {}: [{pos}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n        double3 xformOp:translate.timeSamples = {\n")?;
    for (k, c) in centres.iter().enumerate() {
        writeln!(
            out,
            "            {}: ({},{},{}),",
            time_code(anim, opts, k),
            c[0],
            c[1],
            c[2]
        )?;
    }
    out.write_all(b"        }\n        quath[] orientations.timeSamples = {\n")?;
    for k in 0..n {
        rot.clear();
        for (b, fl) in flights.iter().enumerate() {
            let bank = Quat::from_rotation_z(fl.bank[k]);
            let q = (fl.yaw[k] * bank).normalize();
            // USD writes quaternions real part first, here in one hemisphere.
            let q = if q.w < 0.0 { -q } else { q };
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(
                rot,
                "{sep}({},{},{},{})",
                rounded(q.w, 1e3),
                rounded(q.x, 1e3),
                rounded(q.y, 1e3),
                rounded(q.z, 1e3)
            );
        }
        writeln!(out, "            {}: [{rot}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n        int[] protoIndices.timeSamples = {\n")?;
    for k in 0..n {
        idx.clear();
        for b in 0..birds {
            let sep = if b == 0 { "" } else { "," };
            let _ = write!(idx, "{sep}{}", index[k * birds + b]);
        }
        writeln!(out, "            {}: [{idx}],", time_code(anim, opts, k))?;
    }
    out.write_all(b"        }\n")?;
    // The birds' sizes (left out when every bird has size 1).
    if scales.iter().any(|&s| s != 1.0) {
        let items: Vec<String> = scales.iter().map(|&s| format!("({s},{s},{s})")).collect();
        writeln!(out, "        float3[] scales = [{}]", items.join(","))?;
    }
    // The instances' extent over the whole shot (millimetres about the centre), grown by the
    // largest bird's wingspan.
    let largest = scales.iter().fold(1.0f32, |a, &s| a.max(s));
    let pad = Vec3::splat(ws * largest * 1e3);
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
        // The crowd's positions are in millimetres: its scale 0.001, undone here.
        let _ = writeln!(
            s,
            "                uniform token[] xformOpOrder = [\"xformOp:scale\"]\n                double3 xformOp:scale = (1000, 1000, 1000)"
        );
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
