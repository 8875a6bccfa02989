//! glTF 2.0 binary (`.glb`) export, written with `gltf-json`.
//!
//! Scene: a root node `flock`, and per bird `bird_NN` (body mesh) with two children per wing,
//! `bird_NN_upper_arm_left|right` (shoulder joint, arm mesh) and under it `bird_NN_hand_left|right`
//! (wrist joint, hand mesh). One animation, `flight`, keyed at every frame of the animation file
//! (LINEAR): each bird node's translation and rotation, and each wing joint's rotation from
//! [`Flapper::pose`] through [`rig::wing_joints`]. Geometry is the [`rig`] model scaled to metres.
//!
//! Axes: glTF is Y-up and right-handed with a model's front on +Z. World east `x` → glTF `+X`,
//! world up `z` → glTF `+Y`, world north `y` → glTF `−Z`; lengths are wingspans × `wingspan_m`.
//! A bird's local `+Z` is its forward direction, so heading θ (clockwise from north) is the yaw
//! ```math
//! q_\text{bird} = R_Y(\pi - \theta)\,R_Z(\phi), \qquad \phi = \operatorname{atan}(v\,\dot\theta / g)
//! ```
//! with a bank φ into turns: the file's `bank` when it has one, else φ = atan(v θ̇ / g) (v speed,
//! θ̇ turn rate, g gravity in wingspans/s², clamped to ±45°).

use std::collections::BTreeMap;
use std::f32::consts::PI;

use glam::{Quat, Vec3};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use super::rig::{self, Side};
use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::wingbeat::Flapper;

/// Builds the `.glb` bytes for `anim` with birds `wingspan_m` metres wide.
pub fn glb_bytes(anim: &Animation, wingspan_m: f64) -> Result<Vec<u8>> {
    let mut b = Builder::default();
    let ws = wingspan_m as f32;
    let mut root = json::Root {
        asset: json::Asset {
            version: "2.0".into(),
            generator: Some(format!("formation {}", env!("CARGO_PKG_VERSION"))),
            copyright: None,
            extensions: None,
            extras: Default::default(),
            min_version: None,
        },
        ..Default::default()
    };
    let body_mat = root.push(material("feathers_body", [0.16, 0.15, 0.14, 1.0]));
    let wing_mat = root.push(material("feathers_wing", [0.30, 0.29, 0.28, 1.0]));
    let body = b.mesh(&mut root, "body", &body_mesh(ws), body_mat);
    let mut arm = BTreeMap::new();
    let mut hand = BTreeMap::new();
    for side in Side::BOTH {
        let a = b.mesh(
            &mut root,
            &format!("upper_arm_{}", side.name()),
            &wing_mesh(side, &rig::ARM_OUTLINE, ws),
            wing_mat,
        );
        let h = b.mesh(
            &mut root,
            &format!("hand_{}", side.name()),
            &wing_mesh(side, &rig::HAND_OUTLINE, ws),
            body_mat,
        );
        arm.insert(side.name(), a);
        hand.insert(side.name(), h);
    }

    let times: Vec<f32> = anim
        .frames
        .iter()
        .map(|f| (f.t - anim.frames[0].t) as f32)
        .collect();
    for w in times.windows(2) {
        if w[1] <= w[0] {
            return Err(Error::parameter(
                "frames",
                "frame times are too close to store as glTF keyframes (32-bit floats); render at a lower fps",
            ));
        }
    }
    let time_acc = b.accessor(
        &mut root,
        &times,
        1,
        json::accessor::Type::Scalar,
        true,
        None,
    );
    let flapper = Flapper::from_animation(anim);
    let g = (9.81 / wingspan_m) as f32;
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    let mut bird_nodes = Vec::new();
    let n = anim.frames.len();
    for bird in 0..anim.birds {
        // Keyframes of the bird node.
        let mut tr = Vec::with_capacity(3 * n);
        let mut rot = Vec::with_capacity(4 * n);
        let mut joints: BTreeMap<(&str, bool), Vec<f32>> = BTreeMap::new();
        let mut prev: BTreeMap<(&str, bool), Quat> = BTreeMap::new();
        let mut prev_body = Quat::IDENTITY;
        for (k, f) in anim.frames.iter().enumerate() {
            let at = |v: &Vec<f64>| v.get(bird).copied().unwrap_or(0.0) as f32;
            tr.extend_from_slice(&[at(&f.x) * ws, at(&f.z) * ws, -at(&f.y) * ws]);
            let theta = at(&f.heading);
            let (ka, kb) = (k.saturating_sub(2), (k + 2).min(n - 1));
            let rate = if kb > ka {
                let (fa, fb) = (&anim.frames[ka], &anim.frames[kb]);
                let ha = fa.heading.get(bird).copied().unwrap_or(0.0);
                let hb = fb.heading.get(bird).copied().unwrap_or(0.0);
                (super::sample::angle_diff(ha, hb) / (fb.t - fa.t)) as f32
            } else {
                0.0
            };
            // The file's bank when it has one (the take-off writes it), else a coordinated turn.
            let bank = match f.bank.as_ref().and_then(|b| b.get(bird)) {
                Some(&b) => b as f32,
                None => (at(&f.speed) * rate / g).atan().clamp(-PI / 4.0, PI / 4.0),
            };
            let q = continuous(
                prev_body,
                Quat::from_rotation_y(PI - theta) * Quat::from_rotation_z(bank),
            );
            prev_body = q;
            rot.extend_from_slice(&q.to_array());
            let pose = flapper.pose(k, bird);
            for side in Side::BOTH {
                let j = rig::wing_joints(&pose, side);
                for (is_hand, q) in [(false, j.shoulder_q), (true, j.wrist_q)] {
                    let key = (side.name(), is_hand);
                    let p = prev.get(&key).copied().unwrap_or(Quat::IDENTITY);
                    let q = continuous(p, q);
                    prev.insert(key, q);
                    joints
                        .entry(key)
                        .or_default()
                        .extend_from_slice(&q.to_array());
                }
            }
        }
        let mut children = Vec::new();
        let mut joint_nodes = Vec::new();
        for side in Side::BOTH {
            let j = rig::wing_joints(&flapper.pose(0, bird), side);
            let hand_node = root.push(node(
                format!("bird_{bird:02}_hand_{}", side.name()),
                Some(hand[side.name()]),
                (j.wrist_t * ws).to_array(),
                None,
            ));
            let arm_node = root.push(node(
                format!("bird_{bird:02}_upper_arm_{}", side.name()),
                Some(arm[side.name()]),
                (j.shoulder_t * ws).to_array(),
                Some(vec![hand_node]),
            ));
            children.push(arm_node);
            joint_nodes.push(((side.name(), false), arm_node));
            joint_nodes.push(((side.name(), true), hand_node));
        }
        let bird_node = root.push(node(
            format!("bird_{bird:02}"),
            Some(body),
            [tr[0], tr[1], tr[2]],
            Some(children),
        ));
        bird_nodes.push(bird_node);
        let tr_acc = b.accessor(&mut root, &tr, 3, json::accessor::Type::Vec3, false, None);
        let rot_acc = b.accessor(&mut root, &rot, 4, json::accessor::Type::Vec4, false, None);
        let mut add = |target: json::Index<json::Node>,
                       path: json::animation::Property,
                       out: json::Index<json::Accessor>| {
            samplers.push(json::animation::Sampler {
                extensions: None,
                extras: Default::default(),
                input: time_acc,
                interpolation: Valid(json::animation::Interpolation::Linear),
                output: out,
            });
            channels.push(json::animation::Channel {
                sampler: json::Index::new(samplers.len() as u32 - 1),
                target: json::animation::Target {
                    extensions: None,
                    extras: Default::default(),
                    node: target,
                    path: Valid(path),
                },
                extensions: None,
                extras: Default::default(),
            });
        };
        add(bird_node, json::animation::Property::Translation, tr_acc);
        add(bird_node, json::animation::Property::Rotation, rot_acc);
        for (key, nd) in joint_nodes {
            let data = joints.get(&key).cloned().unwrap_or_default();
            let acc = b.accessor(&mut root, &data, 4, json::accessor::Type::Vec4, false, None);
            add(nd, json::animation::Property::Rotation, acc);
        }
    }
    let flock = root.push(node("flock".into(), None, [0.0; 3], Some(bird_nodes)));
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some("flock".into()),
        nodes: vec![flock],
    });
    root.scene = Some(scene);
    root.push(json::Animation {
        extensions: None,
        extras: Default::default(),
        channels,
        name: Some("flight".into()),
        samplers,
    });
    if let Some(at) = b.non_finite.take() {
        return Err(Error::Internal(format!(
            "glTF: refusing to write a non-finite number in {at}"
        )));
    }
    let bin = b.finish(&mut root);
    let json_bytes = root
        .to_vec()
        .map_err(|e| Error::Internal(format!("serialising glTF JSON: {e}")))?;
    Ok(glb(json_bytes, bin))
}

/// Chooses the sign of `q` closest to `prev`, so LINEAR (slerp) keys never take the long way.
fn continuous(prev: Quat, q: Quat) -> Quat {
    let q = q.normalize();
    if prev.dot(q) < 0.0 {
        -q
    } else {
        q
    }
}

fn material(name: &str, rgba: [f32; 4]) -> json::Material {
    json::Material {
        name: Some(name.into()),
        double_sided: true,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor(rgba),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.85),
            ..Default::default()
        },
        ..Default::default()
    }
}

fn node(
    name: String,
    mesh: Option<json::Index<json::Mesh>>,
    translation: [f32; 3],
    children: Option<Vec<json::Index<json::Node>>>,
) -> json::Node {
    json::Node {
        name: Some(name),
        mesh,
        translation: Some(translation),
        children,
        ..Default::default()
    }
}

/// Triangle mesh: positions, normals (unit), indices.
struct MeshData {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u16>,
}

/// The body as a loft of ellipses along [`rig::BODY_PROFILE`], closed by a point at each end.
fn body_mesh(ws: f32) -> MeshData {
    const RING: usize = 12;
    let mut m = MeshData {
        positions: Vec::new(),
        normals: Vec::new(),
        indices: Vec::new(),
    };
    let prof = &rig::BODY_PROFILE;
    for &(z, w, h) in prof.iter() {
        for r in 0..RING {
            let a = r as f32 / RING as f32 * 2.0 * PI;
            let (s, c) = a.sin_cos();
            m.positions.push([w * c * ws, h * s * ws, z * ws]);
            m.normals.push(
                Vec3::new(c / w.max(1e-4), s / h.max(1e-4), 0.0)
                    .normalize()
                    .to_array(),
            );
        }
    }
    for st in 0..prof.len() - 1 {
        for r in 0..RING {
            let a = (st * RING + r) as u16;
            let b = (st * RING + (r + 1) % RING) as u16;
            let c = a + RING as u16;
            let d = b + RING as u16;
            // Counter-clockwise seen from outside.
            m.indices.extend_from_slice(&[a, d, b, a, c, d]);
        }
    }
    let tail = m.positions.len() as u16;
    m.positions.push([0.0, 0.0, (prof[0].0 - 0.004) * ws]);
    m.normals.push([0.0, 0.0, -1.0]);
    let bill = m.positions.len() as u16;
    m.positions
        .push([0.0, 0.0, (prof[prof.len() - 1].0 + 0.006) * ws]);
    m.normals.push([0.0, 0.0, 1.0]);
    let last = ((prof.len() - 1) * RING) as u16;
    for r in 0..RING as u16 {
        let r1 = (r + 1) % RING as u16;
        m.indices.extend_from_slice(&[tail, r, r1]);
        m.indices.extend_from_slice(&[bill, last + r1, last + r]);
    }
    fix_winding(&mut m);
    m
}

/// A flat wing segment (double-sided material), a fan around its centroid, normal up.
fn wing_mesh(side: Side, outline: &[(f32, f32)], ws: f32) -> MeshData {
    let mut m = MeshData {
        positions: Vec::new(),
        normals: Vec::new(),
        indices: Vec::new(),
    };
    let n = outline.len();
    let (su, sc) = outline
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let centre = rig::segment_point(side, (su / n as f32, sc / n as f32)) * ws;
    m.positions.push(centre.to_array());
    m.normals.push([0.0, 1.0, 0.0]);
    for &p in outline {
        m.positions
            .push((rig::segment_point(side, p) * ws).to_array());
        m.normals.push([0.0, 1.0, 0.0]);
    }
    for i in 0..n as u16 {
        let (a, b) = (1 + i, 1 + (i + 1) % n as u16);
        let (pa, pb) = (
            Vec3::from(m.positions[a as usize]),
            Vec3::from(m.positions[b as usize]),
        );
        // Front face up (+Y): counter-clockwise seen from above.
        if (pa - centre).cross(pb - centre).y >= 0.0 {
            m.indices.extend_from_slice(&[0, a, b]);
        } else {
            m.indices.extend_from_slice(&[0, b, a]);
        }
    }
    m
}

/// Orients every body triangle so its face normal agrees with its vertex normals.
fn fix_winding(m: &mut MeshData) {
    for t in m.indices.chunks_exact_mut(3) {
        let p = |i: u16| Vec3::from(m.positions[i as usize]);
        let face = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
        let avg: Vec3 = t.iter().map(|&i| Vec3::from(m.normals[i as usize])).sum();
        if face.dot(avg) < 0.0 {
            t.swap(1, 2);
        }
    }
}

/// Collects binary data, 4-byte aligned, one buffer view per accessor.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    /// The first accessor holding a non-finite number (issue 8: never written), by index.
    non_finite: Option<String>,
}

impl Builder {
    fn view(
        &mut self,
        root: &mut json::Root,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// A float accessor over `data` (`width` components per element); `min_max` records bounds.
    fn accessor(
        &mut self,
        root: &mut json::Root,
        data: &[f32],
        width: usize,
        type_: json::accessor::Type,
        min_max: bool,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        if self.non_finite.is_none() {
            if let Some(i) = data.iter().position(|v| !v.is_finite()) {
                self.non_finite = Some(format!(
                    "accessor {} element {} ({}; beyond f32 range?)",
                    root.accessors.len(),
                    i / width.max(1),
                    data[i]
                ));
            }
        }
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(root, &bytes, target);
        let (min, max) = if min_max {
            let mut lo = vec![f32::MAX; width];
            let mut hi = vec![f32::MIN; width];
            for e in data.chunks_exact(width) {
                for k in 0..width {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            (Some(json::Value::from(lo)), Some(json::Value::from(hi)))
        } else {
            (None, None)
        };
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(data.len() / width),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    fn mesh(
        &mut self,
        root: &mut json::Root,
        name: &str,
        m: &MeshData,
        material: json::Index<json::Material>,
    ) -> json::Index<json::Mesh> {
        let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let pos = self.accessor(
            root,
            &flat(&m.positions),
            3,
            json::accessor::Type::Vec3,
            true,
            Some(json::buffer::Target::ArrayBuffer),
        );
        let nor = self.accessor(
            root,
            &flat(&m.normals),
            3,
            json::accessor::Type::Vec3,
            false,
            Some(json::buffer::Target::ArrayBuffer),
        );
        let ibytes: Vec<u8> = m.indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let iview = self.view(
            root,
            &ibytes,
            Some(json::buffer::Target::ElementArrayBuffer),
        );
        let idx = root.push(json::Accessor {
            buffer_view: Some(iview),
            byte_offset: None,
            count: USize64::from(m.indices.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U16,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        });
        let mut attributes = BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        attributes.insert(Valid(json::mesh::Semantic::Normals), nor);
        root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.into()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(idx),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        })
    }

    fn finish(mut self, root: &mut json::Root) -> Vec<u8> {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        self.bin
    }
}

/// Packs JSON and binary chunks into a GLB container (JSON padded with spaces, BIN with zeros).
fn glb(mut json_bytes: Vec<u8>, bin: Vec<u8>) -> Vec<u8> {
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn body_and_wings_have_unit_normals_and_valid_indices() {
        for m in [
            body_mesh(1.5),
            wing_mesh(Side::Left, &rig::HAND_OUTLINE, 1.5),
            wing_mesh(Side::Right, &rig::ARM_OUTLINE, 1.5),
        ] {
            for n in &m.normals {
                assert!((Vec3::from(*n).length() - 1.0).abs() < 1e-5);
            }
            assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
            assert_eq!(m.indices.len() % 3, 0);
        }
    }

    #[test]
    fn heading_east_faces_glb_plus_x() {
        let q = Quat::from_rotation_y(PI - PI / 2.0);
        let f = q * Vec3::Z;
        assert!((f - Vec3::X).length() < 1e-6, "{f}");
        let q = Quat::from_rotation_y(PI);
        assert!((q * Vec3::Z - Vec3::NEG_Z).length() < 1e-6, "north is −Z");
    }
}
