//! `render.bird_model` (a `.glb` file): the user's own bird on every bird of the glTF and USD exports
//!.
//!
//! The file must be a binary glTF 2.0 (`.glb`) with its buffer inside (no external files), at
//! most [`MAX_BYTES`] bytes and [`MAX_VERTICES`] vertices, with at least one triangle mesh in its
//! default scene. Textures, UVs and extensions are not carried over: each primitive keeps its
//! geometry and its material's base colour (times its `COLOR_0` vertex colours, when it has
//! them: the triangles are grouped by the colour of their first vertex).
//!
//! - **Skinned** (a mesh node with a skin whose joints include `body`, `upper_arm.L`, `hand.L`,
//!   `upper_arm.R`, `hand.R`, optionally `neck` and `tail`; names compared case-insensitively,
//!   with `_`, `-`, space and `.` equal and any `prefix:` or `prefix|` dropped): the first such
//!   mesh is used, bound by its own inverse bind matrices; every other joint of its skin follows
//!   its nearest ancestor in the convention (or `body`). The wingbeat turns the wing and tail
//!   joints by the same rotations as the built-in bird's, about their own bind positions, in the
//!   bird's axes.
//! - **Static** (anything else): every triangle mesh of the scene, placed by its nodes'
//!   transforms, bound rigidly to `body` (so the bird flies and banks but does not flap).
//!
//! Placement (both kinds): glTF's conventions, `+Y` up and the front on `+Z`. The axis-aligned
//! bounding box gives the wingspan: its width along X (if the box is longer along Z than X, the
//! model is taken to face `+X` with its wings along Z, and is turned by −90° about Y first). The
//! model is scaled so that this width is one wingspan (`wingspan_m` metres in the output) and
//! moved so that the box's centre is the bird's centre.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use gltf_json as json;

use super::bird::{self, BirdAsset, Part, Skeleton, SkinnedMesh, JOINTS};
use crate::error::{Error, Result};
use crate::wingbeat::Species;

/// Largest accepted file, bytes (64 MiB).
pub const MAX_BYTES: u64 = 64 * 1024 * 1024;
/// Largest accepted number of vertices over all meshes used.
pub const MAX_VERTICES: usize = 200_000;

/// Largest skin weight read (glTF's are fractions; a little over 1 is rounding, far more an
/// error that would make a vertex's normalised weights NaN or zero).
pub const MAX_SKIN_WEIGHT: f32 = 1.5;
/// The farthest a joint may sit from the centre of the mesh, in spans of the mesh.
pub const MAX_JOINT_SPANS: f32 = 100.0;
/// Largest number of elements of one accessor (indices of up to 4 triangles per vertex).
pub const MAX_ACCESSOR_ELEMENTS: usize = 12 * MAX_VERTICES;

fn bad(path: &Path, msg: impl Into<String>) -> Error {
    Error::format(path, format!("render.bird_model: {}", msg.into()))
}

/// Reads and checks the user's bird model; `species` supplies the joints a static model does not
/// have (metadata only).
pub fn load(path: &Path, species: Species) -> Result<BirdAsset> {
    load_with(path, species, None)
}

/// [`load`] with a joint map (`render.joint_map`, see [`read_joint_map`]) naming the model's
/// joints by the convention's.
pub fn load_with(path: &Path, species: Species, joint_map: Option<&Path>) -> Result<BirdAsset> {
    let map = joint_map.map(read_joint_map).transpose()?;
    let meta = std::fs::metadata(path).map_err(|e| bad(path, format!("cannot read it: {e}")))?;
    if meta.is_dir() {
        return Err(bad(path, "is a directory, expected a .glb file"));
    }
    if meta.len() > MAX_BYTES {
        return Err(bad(
            path,
            format!(
                "{} bytes is more than the {MAX_BYTES} byte limit for a bird model; decimate it or remove textures",
                meta.len()
            ),
        ));
    }
    let bytes = crate::io::read_bytes(path)?;
    parse_with(path, &bytes, species, map.as_ref())
}

/// Most bird models one export shares out over its birds.
pub const MAX_MODELS: usize = 16;

/// Loads and checks every model of `paths` ([`load_with`]) with its joint map: `maps` is empty,
/// one map for every model, or one per model in order (checked by the caller's options).
pub fn load_all(paths: &[PathBuf], maps: &[PathBuf], species: Species) -> Result<Vec<BirdAsset>> {
    paths
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let map = match maps {
                [] => None,
                [one] => Some(one.as_path()),
                each => each.get(i).map(PathBuf::as_path),
            };
            load_with(p, species, map)
        })
        .collect()
}

/// Parses and checks the bytes of a bird model (`path` is only named in messages); what [`load`]
/// does after reading the file.
pub fn parse(path: &Path, bytes: &[u8], species: Species) -> Result<BirdAsset> {
    parse_with(path, bytes, species, None)
}

/// [`parse`] with a joint map.
pub fn parse_with(
    path: &Path,
    bytes: &[u8],
    species: Species,
    map: Option<&JointMap>,
) -> Result<BirdAsset> {
    let (root, bin) = parse_glb(path, bytes)?;
    if let Some(ext) = root.extensions_required.first() {
        return Err(bad(
            path,
            format!(
                "requires the glTF extension {ext}, which formation does not read; export the model without it (no mesh compression or quantization)"
            ),
        ));
    }
    let r = Reader {
        path,
        root: &root,
        bin,
        map,
    };
    if let Some(m) = map {
        // Every name the map gives must be a node of the model.
        let names: std::collections::BTreeSet<String> = root
            .nodes
            .iter()
            .filter_map(|n| n.name.as_deref().map(norm_name))
            .collect();
        if let Some((from, _)) = m
            .entries
            .iter()
            .find(|(f, _)| !names.contains(&norm_name(f)))
        {
            return Err(Error::format(
                &m.path,
                format!(
                    "render.joint_map: \"{from}\" is not a joint of {}; its names are the model's node names",
                    path.display()
                ),
            ));
        }
    }
    r.asset(species)
}

/// A joint map: the model's joint names and the convention's joint each stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMap {
    /// The file it was read from.
    pub path: std::path::PathBuf,
    /// (model's name, convention's name), in file order.
    pub entries: Vec<(String, String)>,
}

impl JointMap {
    /// The convention's joint the model's node `name` stands for.
    fn target(&self, name: &str) -> Option<usize> {
        let n = norm_name(name);
        let (_, to) = self.entries.iter().find(|(f, _)| norm_name(f) == n)?;
        let t = norm_name(to);
        JOINTS.iter().position(|j| norm_name(j) == t)
    }
}

/// Reads a joint map (`render.joint_map`): a JSON object from the model's joint names to the
/// convention's (`{"UpperArm.L": "upper_arm.L", "Hand.L": "hand.L", ...}`), names compared as
/// joint names are (case and separators ignored). Every target must be a joint of the
/// convention, and at most one model joint may map to each.
pub fn read_joint_map(path: &Path) -> Result<JointMap> {
    let text = crate::io::read_text(path)?;
    let v: serde_json::Value = crate::io::parse_json(path, &text)?;
    let Some(obj) = v.as_object() else {
        return Err(Error::format(
            path,
            "render.joint_map: expected a JSON object from your joint names to the convention's, e.g. {\"UpperArm.L\": \"upper_arm.L\"}",
        ));
    };
    let mut entries = Vec::new();
    let mut seen: BTreeMap<usize, String> = BTreeMap::new();
    for (from, to) in obj {
        let Some(to) = to.as_str() else {
            return Err(Error::format(
                path,
                format!("render.joint_map: \"{from}\": expected the convention's joint name as a string"),
            ));
        };
        let t = norm_name(to);
        let Some(j) = JOINTS.iter().position(|n| norm_name(n) == t) else {
            return Err(Error::format(
                path,
                format!(
                    "render.joint_map: \"{from}\": \"{to}\" is not a joint of the convention ({})",
                    JOINTS.join(", ")
                ),
            ));
        };
        if let Some(other) = seen.insert(j, from.clone()) {
            return Err(Error::format(
                path,
                format!(
                    "render.joint_map: \"{from}\" and \"{other}\" both map to {}; one joint each",
                    JOINTS[j]
                ),
            ));
        }
        entries.push((from.clone(), to.to_string()));
    }
    Ok(JointMap {
        path: path.to_path_buf(),
        entries,
    })
}

/// The warning for a model the birds cannot flap with (no skinned mesh), or `None`.
pub fn static_warning(asset: &BirdAsset) -> Option<String> {
    (!asset.wingbeat).then(|| {
        format!(
            "render.bird_model: {} has no animatable joints (no skinned mesh): the birds will fly and bank but not flap; give a skinned model with the joints {} (neck, tail and legs optional), or map yours with render.joint_map",
            asset.source,
            REQUIRED.map(|j| JOINTS[j]).join(", ")
        )
    })
}

/// The joints a skinned model must have (neck, tail and the legs are optional: a model without
/// leg joints flies with its legs as they are modelled).
const REQUIRED: [usize; 5] = [bird::BODY, 3, 4, 5, 6];

/// Splits a GLB container into its JSON root and binary chunk.
fn parse_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<(json::Root, &'a [u8])> {
    if bytes.len() < 20 || &bytes[0..4] != b"glTF" {
        let hint = if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
            "is glTF JSON (.gltf), not a binary .glb; export it as glTF Binary (.glb)"
        } else {
            "not a glTF binary (.glb) file (no \"glTF\" header)"
        };
        return Err(bad(path, hint));
    }
    let version = u32::from_le_bytes(bytes[4..8].try_into().unwrap_or_default());
    if version != 2 {
        return Err(bad(path, format!("glTF version {version}; expected 2")));
    }
    let total = u32::from_le_bytes(bytes[8..12].try_into().unwrap_or_default()) as usize;
    if total > bytes.len() {
        return Err(bad(
            path,
            format!(
                "truncated: header says {total} bytes, file has {}",
                bytes.len()
            ),
        ));
    }
    let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap_or_default()) as usize;
    if &bytes[16..20] != b"JSON" || 20 + jlen > total {
        return Err(bad(path, "first chunk is not a complete JSON chunk"));
    }
    let root = json::Root::from_slice(&bytes[20..20 + jlen])
        .map_err(|e| bad(path, format!("invalid glTF JSON: {e}")))?;
    let mut bin: &[u8] = &[];
    let rest = 20 + jlen;
    if rest + 8 <= total {
        let blen =
            u32::from_le_bytes(bytes[rest..rest + 4].try_into().unwrap_or_default()) as usize;
        if &bytes[rest + 4..rest + 8] == b"BIN\0" {
            if rest + 8 + blen > total {
                return Err(bad(path, "truncated binary chunk"));
            }
            bin = &bytes[rest + 8..rest + 8 + blen];
        }
    }
    Ok((root, bin))
}

struct Reader<'a> {
    path: &'a Path,
    root: &'a json::Root,
    bin: &'a [u8],
    map: Option<&'a JointMap>,
}

/// A skin mapped to the convention: our joint for every skin slot, and the bind (model-space)
/// matrix of each of our joints the skin has.
type Convention = (Vec<usize>, [Option<Mat4>; bird::N_JOINTS]);

/// One triangle primitive gathered from the file, in model space.
struct Prim {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    indices: Vec<u32>,
    colour: [f32; 3],
    /// Per vertex colour (`COLOR_0`, multiplied into `colour`), when the primitive has one.
    vertex_colours: Option<Vec<[f32; 3]>>,
    /// Per vertex, up to four (joint of the convention, weight).
    influences: Vec<Vec<(usize, f32)>>,
}

/// Normalised joint name: lower case, separators unified, namespace dropped.
fn norm_name(s: &str) -> String {
    let s = s.rsplit([':', '|']).next().unwrap_or(s);
    s.to_ascii_lowercase().replace(['_', '-', ' '], ".")
}

impl Reader<'_> {
    fn err(&self, msg: impl Into<String>) -> Error {
        bad(self.path, msg)
    }

    /// Every element of accessor `i` as floats (normalised integers decoded), `width` per element.
    fn floats(&self, i: json::Index<json::Accessor>) -> Result<(Vec<f32>, usize)> {
        use json::accessor::ComponentType as C;
        let a = self
            .root
            .accessors
            .get(i.value())
            .ok_or_else(|| self.err(format!("accessor {} does not exist", i.value())))?;
        if a.sparse.is_some() {
            return Err(self.err(format!(
                "accessor {}: sparse accessors are not supported",
                i.value()
            )));
        }
        let width = match a.type_ {
            json::validation::Checked::Valid(t) => t.multiplicity(),
            _ => return Err(self.err(format!("accessor {}: unknown type", i.value()))),
        };
        let ct = match a.component_type {
            json::validation::Checked::Valid(c) => c.0,
            _ => return Err(self.err(format!("accessor {}: unknown component type", i.value()))),
        };
        let count = a.count.0 as usize;
        // Every accessor the model uses holds vertices, indices (three per triangle) or one
        // matrix per joint: more elements than that cannot be a model within the limits, and an
        // accessor without a buffer view (zeros) costs memory for nothing (4·10⁹ MAT4 zeros in a
        // 300-byte file tried to allocate 256 GB).
        if count > MAX_ACCESSOR_ELEMENTS {
            return Err(self.err(format!(
                "accessor {}: {count} elements, more than the {MAX_ACCESSOR_ELEMENTS} a bird model may have",
                i.value()
            )));
        }
        let Some(view_i) = a.buffer_view else {
            return Ok((vec![0.0; count * width], width));
        };
        let view =
            self.root.buffer_views.get(view_i.value()).ok_or_else(|| {
                self.err(format!("buffer view {} does not exist", view_i.value()))
            })?;
        let buffer = self.root.buffers.get(view.buffer.value());
        if let Some(b) = buffer {
            if let Some(uri) = &b.uri {
                return Err(self.err(format!(
                    "buffer {} refers to the external file \"{uri}\"; export a single self-contained .glb",
                    view.buffer.value()
                )));
            }
        }
        let size = ct.size();
        let elem = size * width;
        let stride = view.byte_stride.map(|s| s.0).unwrap_or(elem);
        if stride < elem {
            return Err(self.err(format!(
                "accessor {}: buffer view {} has a byteStride of {stride} bytes, less than one element ({elem} bytes)",
                i.value(),
                view_i.value()
            )));
        }
        // Offsets and lengths are the file's numbers (up to 2⁶⁴ − 1): checked arithmetic, so
        // that an absurd one is "past the end" rather than an overflow.
        let view_offset = view.byte_offset.map_or(0, |o| o.0 as usize);
        let start = view_offset.checked_add(a.byte_offset.map_or(0, |o| o.0 as usize));
        let end_view = view_offset.checked_add(view.byte_length.0 as usize);
        let last = start.and_then(|s| {
            count
                .saturating_sub(1)
                .checked_mul(stride)
                .and_then(|o| o.checked_add(s))
                .and_then(|o| o.checked_add(elem))
        });
        let (Some(start), Some(end_view), Some(last)) = (start, end_view, last) else {
            return Err(self.err(format!(
                "accessor {} runs past the end of its buffer",
                i.value()
            )));
        };
        if count > 0 && (last > end_view || end_view > self.bin.len()) {
            return Err(self.err(format!(
                "accessor {} runs past the end of its buffer",
                i.value()
            )));
        }
        let mut out = Vec::with_capacity(count * width);
        for e in 0..count {
            for c in 0..width {
                let o = start + e * stride + c * size;
                let b = &self.bin[o..o + size];
                let v = match ct {
                    C::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                    C::U16 => {
                        let v = u16::from_le_bytes([b[0], b[1]]) as f32;
                        if a.normalized {
                            v / 65535.0
                        } else {
                            v
                        }
                    }
                    C::I16 => {
                        let v = i16::from_le_bytes([b[0], b[1]]) as f32;
                        if a.normalized {
                            (v / 32767.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                    C::U8 => {
                        let v = b[0] as f32;
                        if a.normalized {
                            v / 255.0
                        } else {
                            v
                        }
                    }
                    C::I8 => {
                        let v = b[0] as i8 as f32;
                        if a.normalized {
                            (v / 127.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                };
                if !v.is_finite() {
                    return Err(self.err(format!(
                        "accessor {}: element {e} is not a finite number",
                        i.value()
                    )));
                }
                out.push(v);
            }
        }
        Ok((out, width))
    }

    fn vec3s(&self, i: json::Index<json::Accessor>, what: &str) -> Result<Vec<Vec3>> {
        let (v, w) = self.floats(i)?;
        if w != 3 {
            return Err(self.err(format!("{what} accessor {} is not VEC3", i.value())));
        }
        Ok(v.chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect())
    }

    /// Local matrix of a node.
    fn local(&self, n: &json::Node) -> Mat4 {
        if let Some(m) = n.matrix {
            return Mat4::from_cols_array(&m);
        }
        let t = n.translation.map(Vec3::from).unwrap_or(Vec3::ZERO);
        let r = n
            .rotation
            .map(|q| Quat::from_array(q.0).normalize())
            .unwrap_or(Quat::IDENTITY);
        let s = n.scale.map(Vec3::from).unwrap_or(Vec3::ONE);
        Mat4::from_scale_rotation_translation(s, r, t)
    }

    /// World matrices of every node reachable from the default scene (or every root node).
    fn world(&self) -> Result<BTreeMap<usize, Mat4>> {
        let nodes = &self.root.nodes;
        let roots: Vec<usize> = match self
            .root
            .scene
            .or_else(|| (!self.root.scenes.is_empty()).then(|| json::Index::new(0)))
        {
            Some(s) => self
                .root
                .scenes
                .get(s.value())
                .map(|s| s.nodes.iter().map(|n| n.value()).collect())
                .unwrap_or_default(),
            None => {
                let mut child = vec![false; nodes.len()];
                for n in nodes {
                    for c in n.children.iter().flatten() {
                        if let Some(x) = child.get_mut(c.value()) {
                            *x = true;
                        }
                    }
                }
                (0..nodes.len()).filter(|&i| !child[i]).collect()
            }
        };
        let mut out = BTreeMap::new();
        let mut stack: Vec<(usize, Mat4)> =
            roots.into_iter().map(|r| (r, Mat4::IDENTITY)).collect();
        while let Some((i, parent)) = stack.pop() {
            let n = nodes
                .get(i)
                .ok_or_else(|| self.err(format!("node {i} does not exist")))?;
            if out.contains_key(&i) || out.len() > nodes.len() {
                return Err(self.err(format!("node {i} appears twice in the scene hierarchy")));
            }
            let m = parent * self.local(n);
            out.insert(i, m);
            for c in n.children.iter().flatten() {
                stack.push((c.value(), m));
            }
        }
        Ok(out)
    }

    fn colour(&self, p: &json::mesh::Primitive) -> [f32; 3] {
        p.material
            .and_then(|m| self.root.materials.get(m.value()))
            .map(|m| {
                let c = m.pbr_metallic_roughness.base_color_factor.0;
                [c[0], c[1], c[2]]
            })
            .unwrap_or([0.5, 0.5, 0.5])
    }

    /// Triangle primitives of mesh `mi`; `joint_map` maps skin joint slots to the convention.
    /// Refuses accessor `i` (a `what` accessor) unless its component type is one of `allowed`
    /// (`expected` names them), as the glTF specification requires for that attribute.
    fn component_types(
        &self,
        i: json::Index<json::Accessor>,
        allowed: &[json::accessor::ComponentType],
        what: &str,
        expected: &str,
    ) -> Result<()> {
        let ct = self
            .root
            .accessors
            .get(i.value())
            .and_then(|a| match a.component_type {
                json::validation::Checked::Valid(c) => Some(c.0),
                _ => None,
            });
        match ct {
            Some(c) if !allowed.contains(&c) => Err(self.err(format!(
                "{what} accessor {}: component type {c:?}, expected {expected}",
                i.value()
            ))),
            _ => Ok(()),
        }
    }

    fn prims(&self, mi: usize, joint_map: Option<&[usize]>) -> Result<Vec<Prim>> {
        use json::accessor::ComponentType as C;
        let mesh = self
            .root
            .meshes
            .get(mi)
            .ok_or_else(|| self.err(format!("mesh {mi} does not exist")))?;
        let mut out = Vec::new();
        for (pi, p) in mesh.primitives.iter().enumerate() {
            let mode = match p.mode {
                json::validation::Checked::Valid(m) => m,
                _ => continue,
            };
            if mode != json::mesh::Mode::Triangles {
                continue;
            }
            let get = |s: json::mesh::Semantic| {
                p.attributes
                    .get(&json::validation::Checked::Valid(s))
                    .copied()
            };
            let Some(pos) = get(json::mesh::Semantic::Positions) else {
                continue;
            };
            self.component_types(
                pos,
                &[C::F32],
                "POSITION",
                "FLOAT (without the KHR_mesh_quantization extension)",
            )?;
            let positions = self.vec3s(pos, "POSITION")?;
            let normals = match get(json::mesh::Semantic::Normals) {
                Some(n) => Some(self.vec3s(n, "NORMAL")?),
                None => None,
            };
            let nv = positions.len();
            if let Some(ns) = normals.as_ref().filter(|ns| ns.len() != nv) {
                return Err(self.err(format!(
                    "mesh {mi} primitive {pi}: NORMAL has {} vectors for its {nv} vertices (every attribute of a primitive has one value a vertex)",
                    ns.len()
                )));
            }
            let indices: Vec<u32> = match p.indices {
                Some(i) => {
                    self.component_types(
                        i,
                        &[C::U8, C::U16, C::U32],
                        "index",
                        "UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
                    )?;
                    self.floats(i)?.0.into_iter().map(|v| v as u32).collect()
                }
                None => (0..nv as u32).collect(),
            };
            if let Some(&bad_i) = indices.iter().find(|&&i| i as usize >= nv) {
                return Err(self.err(format!(
                    "mesh {mi} primitive {pi}: index {bad_i} beyond its {nv} vertices"
                )));
            }
            let indices: Vec<u32> = indices[..indices.len() / 3 * 3].to_vec();
            let vertex_colours = match get(json::mesh::Semantic::Colors(0)) {
                Some(c) => {
                    let (v, w) = self.floats(c)?;
                    if !(w == 3 || w == 4) || v.len() < nv * w {
                        return Err(self.err(format!(
                            "mesh {mi} primitive {pi}: COLOR_0 is not one RGB or RGBA colour per vertex"
                        )));
                    }
                    Some(v.chunks_exact(w).map(|c| [c[0], c[1], c[2]]).collect())
                }
                None => None,
            };
            let mut influences = vec![vec![(bird::BODY, 1.0)]; nv];
            if let Some(map) = joint_map {
                if let (Some(j), Some(w)) = (
                    get(json::mesh::Semantic::Joints(0)),
                    get(json::mesh::Semantic::Weights(0)),
                ) {
                    let (jv, _) = self.floats(j)?;
                    let (wv, _) = self.floats(w)?;
                    for (k, infl) in influences.iter_mut().enumerate() {
                        let mut acc: BTreeMap<usize, f32> = BTreeMap::new();
                        for c in 0..4 {
                            let (slot, weight) = (
                                jv.get(4 * k + c).copied().unwrap_or(0.0) as usize,
                                wv.get(4 * k + c).copied().unwrap_or(0.0),
                            );
                            if !(weight.is_finite() && weight <= MAX_SKIN_WEIGHT) {
                                return Err(self.err(format!(
                                    "mesh {mi} primitive {pi}: vertex {k} has a skin weight of {weight} (weights are fractions, at most 1)"
                                )));
                            }
                            if weight > 0.0 {
                                let ours = *map.get(slot).ok_or_else(|| {
                                    self.err(format!("mesh {mi} primitive {pi}: vertex {k} uses joint {slot}, beyond its skin"))
                                })?;
                                *acc.entry(ours).or_default() += weight;
                            }
                        }
                        if !acc.is_empty() {
                            *infl = acc.into_iter().collect();
                        }
                    }
                }
            }
            out.push(Prim {
                positions,
                normals,
                indices,
                colour: self.colour(p),
                vertex_colours,
                influences,
            });
        }
        Ok(out)
    }

    /// The skin of node `n` mapped to the convention: per skin slot our joint, and the bind
    /// (model-space) matrix of each of our joints found. `Err(missing)`, the required joints it
    /// lacks, when the convention is not met.
    fn convention(&self, skin: &json::Skin) -> Result<std::result::Result<Convention, Vec<usize>>> {
        let names: Vec<String> = JOINTS.iter().map(|n| norm_name(n)).collect();
        let ibm: Vec<Mat4> = match skin.inverse_bind_matrices {
            Some(a) => {
                let (v, w) = self.floats(a)?;
                if w != 16 || v.len() / 16 < skin.joints.len() {
                    return Err(self.err("skin: inverse bind matrices are not one MAT4 per joint"));
                }
                v.chunks_exact(16).map(Mat4::from_cols_slice).collect()
            }
            None => vec![Mat4::IDENTITY; skin.joints.len()],
        };
        if let Some((slot, n)) = skin
            .joints
            .iter()
            .enumerate()
            .find(|(_, n)| n.value() >= self.root.nodes.len())
        {
            return Err(self.err(format!(
                "skin: joint {slot} is node {}, but the model has {} nodes",
                n.value(),
                self.root.nodes.len()
            )));
        }
        let node_slot: BTreeMap<usize, usize> = skin
            .joints
            .iter()
            .enumerate()
            .map(|(s, n)| (n.value(), s))
            .collect();
        let mut parent_of: BTreeMap<usize, usize> = BTreeMap::new();
        for (i, n) in self.root.nodes.iter().enumerate() {
            for c in n.children.iter().flatten() {
                parent_of.insert(c.value(), i);
            }
        }
        let ours = |node: usize| -> Option<usize> {
            let name = self.root.nodes.get(node)?.name.as_deref()?;
            if let Some(j) = self.map.and_then(|m| m.target(name)) {
                return Some(j);
            }
            let nm = norm_name(name);
            names.iter().position(|n| *n == nm)
        };
        // Two joints standing for the same joint of the convention: one would silently win.
        let mut seen: [Option<usize>; bird::N_JOINTS] = [None; bird::N_JOINTS];
        for (slot, n) in skin.joints.iter().enumerate() {
            if let Some(j) = ours(n.value()) {
                if let Some(first) = seen[j].replace(slot) {
                    return Err(self.err(format!(
                        "skin: joints {first} and {slot} both stand for the convention's joint \"{}\" (names compare without case, namespace or separators); give every joint its own name or map them with a joint map",
                        JOINTS[j]
                    )));
                }
            }
        }
        let mut bind: [Option<Mat4>; bird::N_JOINTS] = [None; bird::N_JOINTS];
        for (slot, n) in skin.joints.iter().enumerate() {
            if let Some(j) = ours(n.value()) {
                let m = ibm[slot].inverse();
                if !m.is_finite() {
                    return Err(self.err(format!(
                        "skin: the inverse bind matrix of joint {slot} ({}) cannot be inverted",
                        JOINTS[j]
                    )));
                }
                bind[j] = Some(m);
            }
        }
        let missing: Vec<usize> = REQUIRED
            .iter()
            .copied()
            .filter(|&j| bind[j].is_none())
            .collect();
        if !missing.is_empty() {
            return Ok(Err(missing));
        }
        let map = skin
            .joints
            .iter()
            .map(|n| {
                let mut k = n.value();
                let mut guard = 0;
                loop {
                    if let Some(j) = ours(k) {
                        if node_slot.contains_key(&k) || j == bird::BODY {
                            return j;
                        }
                    }
                    match parent_of.get(&k) {
                        Some(&p) if guard < 1000 => {
                            k = p;
                            guard += 1;
                        }
                        _ => return bird::BODY,
                    }
                }
            })
            .collect();
        Ok(Ok((map, bind)))
    }

    fn asset(&self, species: Species) -> Result<BirdAsset> {
        let world = self.world()?;
        // A skinned mesh whose skin follows the convention?
        let mut unmatched: Option<(json::Skin, Vec<usize>)> = None;
        for &ni in world.keys() {
            let n = &self.root.nodes[ni];
            let (Some(mi), Some(si)) = (n.mesh, n.skin) else {
                continue;
            };
            let skin = self
                .root
                .skins
                .get(si.value())
                .ok_or_else(|| self.err(format!("skin {} does not exist", si.value())))?;
            match self.convention(skin)? {
                Ok((map, bind)) => {
                    let prims = self.prims(mi.value(), Some(&map))?;
                    return self.build(prims, Some(bind), species);
                }
                Err(missing) => {
                    if unmatched.is_none() {
                        unmatched = Some((skin.clone(), missing));
                    }
                }
            }
        }
        // A skinned model whose joints are named otherwise would silently not flap: refused.
        if let Some((skin, missing)) = unmatched {
            let found: Vec<&str> = skin
                .joints
                .iter()
                .filter_map(|n| self.root.nodes.get(n.value())?.name.as_deref())
                .take(12)
                .collect();
            let more = if skin.joints.len() > found.len() {
                ", ..."
            } else {
                ""
            };
            return Err(self.err(format!(
                "its skin has no joint{} {} (its joints: {}{more}); name them by the convention ({}) or map yours with render.joint_map",
                if missing.len() == 1 { "" } else { "s" },
                missing.iter().map(|&j| JOINTS[j]).collect::<Vec<_>>().join(", "),
                if found.is_empty() { "unnamed".to_string() } else { found.join(", ") },
                JOINTS.join(", ")
            )));
        }
        // Static: every triangle mesh, placed by its node.
        let mut prims = Vec::new();
        for (&ni, m) in &world {
            let Some(mi) = self.root.nodes[ni].mesh else {
                continue;
            };
            for mut p in self.prims(mi.value(), None)? {
                let nm = Mat3ish::from(*m);
                for v in &mut p.positions {
                    *v = m.transform_point3(*v);
                }
                if let Some(ns) = &mut p.normals {
                    for v in ns.iter_mut() {
                        *v = nm.normal(*v);
                    }
                }
                if m.determinant() < 0.0 {
                    for t in p.indices.chunks_exact_mut(3) {
                        t.swap(1, 2);
                    }
                }
                prims.push(p);
            }
        }
        self.build(prims, None, species)
    }

    fn build(
        &self,
        prims: Vec<Prim>,
        bind: Option<[Option<Mat4>; bird::N_JOINTS]>,
        species: Species,
    ) -> Result<BirdAsset> {
        let nv: usize = prims.iter().map(|p| p.positions.len()).sum();
        let nt: usize = prims.iter().map(|p| p.indices.len() / 3).sum();
        if nt == 0 {
            return Err(self.err("has no triangle mesh in its scene (nothing to put on the birds)"));
        }
        if nv > MAX_VERTICES {
            return Err(self.err(format!(
                "{nv} vertices is more than the {MAX_VERTICES} allowed for a bird (it is copied onto every bird); decimate it"
            )));
        }
        // Bounding box → orientation, scale, centre.
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for p in &prims {
            for v in &p.positions {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        let ext = hi - lo;
        let turn = if ext.z > ext.x {
            Quat::from_rotation_y(-std::f32::consts::FRAC_PI_2)
        } else {
            Quat::IDENTITY
        };
        let span = ext.x.max(ext.z);
        if !(span.is_finite() && span > 0.0) {
            return Err(
                self.err("its mesh has no width (all vertices in one plane across the span)")
            );
        }
        let s = 1.0 / span;
        let centre = 0.5 * (lo + hi);
        let place = Mat4::from_scale(Vec3::splat(s))
            * Mat4::from_quat(turn)
            * Mat4::from_translation(-centre);
        let mut mesh = SkinnedMesh::default();
        let mut parts: Vec<(Part, Vec<u32>)> = Vec::new();
        let mut colours = Vec::new();
        for (k, p) in prims.into_iter().enumerate() {
            let base = mesh.positions.len() as u32;
            for (i, v) in p.positions.iter().enumerate() {
                let id = mesh.push_vertex(place.transform_point3(*v), &p.influences[i]);
                if let Some(ns) = &p.normals {
                    mesh.normals[id as usize] = (turn * ns[i]).try_normalize().unwrap_or(Vec3::Y);
                }
            }
            let idx: Vec<u32> = p.indices.iter().map(|i| base + i).collect();
            if p.normals.is_none() {
                mesh.face_normals(&idx);
            }
            // Materials are numbered by primitive; the part tag only names them.
            let part = Part::ALL[k % Part::ALL.len()];
            match &p.vertex_colours {
                // Vertex colours: the triangles grouped by the colour of their first vertex
                // (times the material's), one part per colour in order of appearance.
                Some(vc) => {
                    let mut groups: Vec<([f32; 3], Vec<u32>)> = Vec::new();
                    let mut group_of: BTreeMap<[u32; 3], usize> = BTreeMap::new();
                    for (t, local) in idx.chunks_exact(3).zip(p.indices.chunks_exact(3)) {
                        let c = vc[local[0] as usize];
                        let rgb = [c[0] * p.colour[0], c[1] * p.colour[1], c[2] * p.colour[2]];
                        let g = *group_of.entry(rgb.map(f32::to_bits)).or_insert_with(|| {
                            groups.push((rgb, Vec::new()));
                            groups.len() - 1
                        });
                        groups[g].1.extend_from_slice(t);
                    }
                    for (rgb, tris) in groups {
                        parts.push((part, tris));
                        colours.push(rgb);
                    }
                }
                None => {
                    parts.push((part, idx));
                    colours.push(p.colour);
                }
            }
        }
        mesh.set_parts(parts, colours);
        let mut skel = Skeleton::of(species);
        let wingbeat = bind.is_some();
        if let Some(bind) = bind {
            let body = bind[bird::BODY].unwrap_or(Mat4::IDENTITY);
            for (j, b) in bind.iter().enumerate() {
                let m = place * b.unwrap_or(body);
                let (_, r, t) = m.to_scale_rotation_translation();
                skel.bind_pos[j] = t;
                skel.bind_rot[j] = r.normalize();
            }
        }
        // Finite inputs can still give a degenerate placement (a joint's matrix that overflows
        // f32, a bind rotation of a singular matrix): refuse it here, not as an internal error
        // of the glTF writer or a NaN in the USD text (found by fuzzing).
        let finite = mesh.positions.iter().all(|v| v.is_finite())
            && mesh.normals.iter().all(|v| v.is_finite())
            && skel.bind_pos.iter().all(|v| v.is_finite())
            && skel.bind_rot.iter().all(|q| q.is_finite());
        if !finite {
            return Err(self.err(
                "its transforms are degenerate (a matrix that cannot be inverted or overflows 32-bit floats); fix the model's joints and nodes",
            ));
        }
        // A joint far from the mesh it moves is an error of the model's transforms, and its
        // offsets overflow 32-bit floats once scaled to a wingspan and composed down the chain
        // (found by fuzzing: a joint 10³⁷ spans away gave `inf` in the USD text).
        if let Some(j) =
            (0..bird::N_JOINTS).find(|&j| skel.bind_pos[j].abs().max_element() > MAX_JOINT_SPANS)
        {
            return Err(self.err(format!(
                "skin: joint \"{}\" sits {:.3e} of the mesh's spans from the mesh's centre along an axis (at most {MAX_JOINT_SPANS}); fix the joint's bind matrix or its node's transform",
                JOINTS[j],
                skel.bind_pos[j].abs().max_element()
            )));
        }
        // A static model keeps the species' skeleton: `body` at the centre, so bank turns the
        // model about the centre of its bounding box.
        Ok(BirdAsset {
            source: self.path.display().to_string(),
            skeleton: skel,
            mesh,
            wingbeat,
        })
    }
}

/// Normal transform (inverse transpose of the upper 3×3).
struct Mat3ish(glam::Mat3);

impl From<Mat4> for Mat3ish {
    fn from(m: Mat4) -> Self {
        Mat3ish(glam::Mat3::from_mat4(m).inverse().transpose())
    }
}

impl Mat3ish {
    fn normal(&self, n: Vec3) -> Vec3 {
        (self.0 * n).try_normalize().unwrap_or(Vec3::Y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_names_compare_loosely() {
        assert_eq!(norm_name("Armature|Upper_Arm.L"), norm_name("upper_arm.L"));
        assert_eq!(norm_name("rig:hand_r"), norm_name("hand.R"));
        assert_ne!(norm_name("hand.L"), norm_name("hand.R"));
    }
}
