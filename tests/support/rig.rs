//! The built-in bird posed on its rig, for the tests that check it against the ground (take-off
//! and landing): the same joint chain the exports write, evaluated with glam.

use formation::export::bird::{self, BirdAsset, JOINTS, PARENT};
use formation::export::rig::Side;
use formation::wingbeat::WingPose;
use glam::{Quat, Vec3};

/// Global (rotation, position) of every joint of the built-in bird for a pose, root at `root`
/// with rotation `rot`, bank `bank` (bird frame of the export: +Y up).
fn globals(
    asset: &BirdAsset,
    pose: &WingPose,
    bank: f32,
    root: Vec3,
    rot: Quat,
) -> [(Quat, Vec3); bird::N_JOINTS] {
    let q = bird::joint_rotations(pose, bank);
    let skel = &asset.skeleton;
    let mut g = [Quat::IDENTITY; bird::N_JOINTS];
    let mut t = [Vec3::ZERO; bird::N_JOINTS];
    let mut global = [(Quat::IDENTITY, Vec3::ZERO); bird::N_JOINTS];
    for j in 0..JOINTS.len() {
        match PARENT[j] {
            None => {
                g[j] = rot * q[j];
                t[j] = root + rot * skel.bind_pos[j];
            }
            Some(p) => {
                g[j] = g[p] * q[j];
                t[j] = t[p] + g[p] * (skel.bind_pos[j] - skel.bind_pos[p]);
            }
        }
        global[j] = (g[j] * skel.bind_rot[j], t[j]);
    }
    global
}

/// World positions of the built-in bird's vertices for a pose, root at `root` with rotation
/// `rot`, bank `bank`.
pub fn posed(asset: &BirdAsset, pose: &WingPose, bank: f32, root: Vec3, rot: Quat) -> Vec<Vec3> {
    let global = globals(asset, pose, bank, root, rot);
    asset.mesh.posed(&asset.skeleton, &global)
}

/// The lowest vertex (its height, +Y up) of [`posed`].
pub fn lowest_vertex(asset: &BirdAsset, pose: &WingPose, bank: f32, root: Vec3, rot: Quat) -> f32 {
    posed(asset, pose, bank, root, rot)
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min)
}

/// Each leg's hip and the tip of its toes in the world for a pose: the leg mesh's farthest
/// vertex from the hip (the built-in crane), posed on the rig.
pub fn legs(
    asset: &BirdAsset,
    pose: &WingPose,
    bank: f32,
    root: Vec3,
    rot: Quat,
) -> [(Vec3, Vec3); 2] {
    let global = globals(asset, pose, bank, root, rot);
    let posed = asset.mesh.posed(&asset.skeleton, &global);
    Side::BOTH.map(|side| {
        let j = bird::leg_joint(side);
        let hip = global[j].1;
        let toe = posed
            .iter()
            .zip(&asset.mesh.joints)
            .filter(|(_, js)| js[0] as usize == j)
            .map(|(p, _)| *p)
            .max_by(|a, b| (*a - hip).length().total_cmp(&(*b - hip).length()))
            .expect("a leg");
        (hip, toe)
    })
}

/// The wing and tail part of a pose (the legs' swing set to 0), to compare with the folded pose.
pub fn wings(p: WingPose) -> WingPose {
    WingPose { legs: 0.0, ..p }
}
