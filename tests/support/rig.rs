//! The built-in bird posed on its rig, for the tests that check it against the ground (take-off
//! and landing): the same joint chain the exports write, evaluated with glam.

use formation::export::bird::{self, BirdAsset, JOINTS, PARENT};
use formation::wingbeat::WingPose;
use glam::{Quat, Vec3};

/// World positions (bird frame of the export: +Y up) of the built-in bird's vertices for a pose,
/// root at `root` with rotation `rot`, bank `bank`.
pub fn posed(asset: &BirdAsset, pose: &WingPose, bank: f32, root: Vec3, rot: Quat) -> Vec<Vec3> {
    let q = bird::joint_rotations(pose, bank);
    let skel = &asset.skeleton;
    let mut g = [Quat::IDENTITY; 7];
    let mut t = [Vec3::ZERO; 7];
    let mut global = [(Quat::IDENTITY, Vec3::ZERO); 7];
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
    asset.mesh.posed(skel, &global)
}

/// The lowest vertex (its height, +Y up) of [`posed`].
pub fn lowest_vertex(asset: &BirdAsset, pose: &WingPose, bank: f32, root: Vec3, rot: Quat) -> f32 {
    posed(asset, pose, bank, root, rot)
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min)
}
