//! glTF 2.0 binary (`.glb`) export, written with `gltf-json` (skinned birds, one clip
//! per stage, metadata, key reduction, the user's own bird).
//!
//! Scene `flock`: a node `flock` holding one root node per bird, `bird_000`, `bird_001`, … (zero
//! padded to at least three digits, so they sort), which carries the flight (translation and
//! heading). Under each root, the bird's skeleton: joints named by the convention of
//! [`bird::JOINTS`] (`body` → `neck`, `tail`, `upper_arm.L` → `hand.L`, `upper_arm.R` →
//! `hand.R`); bank turns `body`, the wingbeat turns the wing and tail joints. Every bird shares one
//! skinned mesh (`JOINTS_0`/`WEIGHTS_0`, one primitive and one material, the parts' colours as
//! `COLOR_0`: one draw call a bird) and one inverse-bind-matrix
//! accessor; each bird's mesh node `bird_000_mesh` sits at the scene root, untransformed, as glTF
//! asks of skinned meshes (only the joints place it), with its own skin `bird_000_skin`.
//!
//! Clips ([`ClipMode`]): by default one animation, `flight`, over every frame, its times those of
//! the animation from its first frame (frame k at k / fps s), so that it plays on import; the
//! stages are in its `extras` and the scene's (`frame_start`, `frame_end`, `fps`). With
//! `ClipMode::Stages`, one animation per stage of the animation file, named after it
//! (`initiation`, `steady`, …; `flight` when the file has no stages), each starting at time 0
//! and ending on the first frame of the next stage, so that played back to back they join
//! without a jump. A loop ends on its closing key (the first frame again, one frame on), which
//! a player cycling by time shows once; `frame_end` is the frame before it. LINEAR
//! keys at every frame (`render.keys` = all) or only those [`keys::keep`] needs (reduced).
//! An animation that followed a path also gets a node `flown_path` at the scene root: a line strip
//! through the course as flown (turns widened), in the same metres and axes.
//!
//! Metadata in `extras`: the scene holds fps, wingspan_m, seed, species, birds, the stages and the
//! bird model; each clip its stage, first frame and start time; each bird root its index.
//!
//! Axes: glTF is Y-up and right-handed with a model's front on +Z. World east `x` → glTF `+X`,
//! world up `z` → glTF `+Y`, world north `y` → glTF `−Z`; lengths are wingspans × `wingspan_m`.
//! The yaw and bank formulas are in [`bird`].

use std::collections::BTreeMap;

use glam::Quat;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use super::bird::{self, BirdAsset, Flight};
use super::keys::{self, ClipMode, Curve, KeyMode, Tolerance};
use super::rig::Side;
use crate::animation::Animation;
use crate::error::{Error, Result};
use crate::wingbeat::{Flapper, WingbeatOptions};

/// Options of the glTF (and USD) export.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneOptions {
    /// Keys at every frame or reduced within `tolerance`.
    pub keys: KeyMode,
    /// Tolerances of `KeyMode::Reduced`.
    pub tolerance: Tolerance,
    /// One clip over every stage, or one per stage.
    pub clips: ClipMode,
    /// The user's bird models, shared out over the birds ([`bird::model_assignment`]); empty =
    /// the built-in bird of the animation's species on every bird.
    pub assets: Vec<BirdAsset>,
    /// Number of the animation's first frame (e.g. 1001): the one clip's keys start at
    /// `start_frame / fps` seconds, and the frame numbers in the metadata and USD time codes
    /// count from it.
    pub start_frame: u64,
    /// The shot's frame rate when the animation is sampled finer (sub-frame samples for motion
    /// blur): frame numbers and the scene's rate are in these frames; `None` = the animation's
    /// own rate.
    pub frame_rate: Option<f64>,
    /// Spread of the birds' sizes, the F of [`bird::bird_scales`] (0 = every bird the same size,
    /// this struct's default; `render.size_variation` defaults to the species').
    pub size_variation: f64,
    /// The flock in parts of [`FLOCK_PART`] birds (`render.gltf_mode` = flock), each part one
    /// skinned mesh on one skin whose skeleton is the part's node, so a DCC makes one armature a
    /// part instead of one per bird (and a viewer one draw call a part); `false` = one skin and
    /// mesh node per bird.
    pub one_skin: bool,
    /// Mean wing-pose error a point-instanced USD crowd's prototypes must meet in every stage,
    /// degrees ([`super::crowd`]); `None` = [`super::crowd::DEFAULT_POSE_ERROR_DEG`].
    pub crowd_pose_error_deg: Option<f64>,
}

impl SceneOptions {
    /// The bird models of `anim`: the user's, else the built-in bird of its species (at least
    /// one).
    pub fn models(&self, anim: &Animation) -> Vec<BirdAsset> {
        if self.assets.is_empty() {
            vec![BirdAsset::builtin(
                WingbeatOptions::for_animation(anim).species,
            )]
        } else {
            self.assets.clone()
        }
    }

    /// Each bird's model: an index into [`SceneOptions::models`].
    pub fn model_of(&self, anim: &Animation) -> Vec<usize> {
        bird::model_assignment(anim.seed, anim.birds, self.assets.len())
    }

    /// The shot's frame rate of `anim`'s samples.
    pub fn rate(&self, anim: &Animation) -> f64 {
        self.frame_rate.unwrap_or(anim.fps)
    }

    /// The shot's frame number of sample `k` of `anim` (fractional between frames).
    pub fn frame_of(&self, anim: &Animation, k: usize) -> f64 {
        let t0 = anim.frames.first().map_or(0.0, |f| f.t);
        let f = (anim.frames[k].t - t0) * self.rate(anim);
        // Frame numbers that are whole to rounding are exactly whole.
        let r = f.round();
        self.start_frame as f64 + if (f - r).abs() < 1e-6 { r } else { f }
    }

    /// The last frame of the range to play (see [`play_end`]), in the shot's frames.
    pub fn frame_end(&self, anim: &Animation) -> u64 {
        let n = anim.frames.len();
        if n == 0 {
            return self.start_frame;
        }
        let last = (self.frame_of(anim, n - 1) - self.start_frame as f64).round() as u64;
        self.start_frame + last.saturating_sub(u64::from(anim.looped && n > 2))
    }
}

/// Builds the `.glb` bytes for `anim` with birds `wingspan_m` metres wide, every frame keyed and
/// the built-in bird.
pub fn glb_bytes(anim: &Animation, wingspan_m: f64) -> Result<Vec<u8>> {
    glb_bytes_with(anim, wingspan_m, &SceneOptions::default())
}

/// Width of zero-padded bird numbers: at least 3 digits, more for larger flocks.
pub fn bird_digits(birds: usize) -> usize {
    birds.saturating_sub(1).to_string().len().max(3)
}

/// A clip: a named, contiguous range of frames `first..=last`.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// Stage name.
    pub name: String,
    /// First frame.
    pub first: usize,
    /// Last frame (the first frame of the next stage when there is one).
    pub last: usize,
}

/// A looping animation with its closing frame appended ([`Animation::closed_loop`]); any
/// other animation as it is.
pub fn closed_loop(anim: &Animation) -> std::borrow::Cow<'_, Animation> {
    anim.closed_loop()
}

/// The clips of `anim`: `flight` over every frame ([`ClipMode::One`]), or one per non-empty
/// stage (`flight` over every frame when there is none).
pub fn clips(anim: &Animation, mode: ClipMode) -> Vec<Clip> {
    let n = anim.frames.len();
    if mode == ClipMode::One {
        return vec![Clip {
            name: "flight".into(),
            first: 0,
            last: n - 1,
        }];
    }
    let mut out: Vec<Clip> = anim
        .stages
        .iter()
        .filter(|s| s.end > s.start && s.start < n)
        .map(|s| Clip {
            name: s.name.to_string(),
            first: s.start,
            last: s.end.min(n - 1),
        })
        .collect();
    if out.is_empty() {
        out.push(Clip {
            name: "flight".into(),
            first: 0,
            last: n - 1,
        });
    }
    out
}

/// Scene metadata shared by glTF `extras` and USD `customLayerData`.
pub fn metadata(
    anim: &Animation,
    wingspan_m: f64,
    assets: &[BirdAsset],
    opts: &SceneOptions,
) -> serde_json::Value {
    let species = WingbeatOptions::for_animation(anim).species;
    let rate = opts.rate(anim);
    let stage_frame = |k: usize| {
        let n = anim.frames.len();
        frame_value(if k < n || n == 0 {
            opts.frame_of(anim, k.min(n.saturating_sub(1)))
        } else {
            // Past the last sample (a stage's exclusive end): whole frames on from it.
            opts.frame_of(anim, n - 1) + (k - (n - 1)) as f64
        })
    };
    let mut m = serde_json::json!({
        "generator": format!("formation {}", env!("CARGO_PKG_VERSION")),
        "fps": rate,
        "wingspan_m": wingspan_m,
        "seed": anim.seed,
        "species": anim.species.clone().unwrap_or_else(|| species.name().to_string()),
        "birds": anim.birds,
        "frames": opts.frame_end(anim) - opts.start_frame + 1,
        "stages": anim.stages.iter().map(|s| serde_json::json!({"name": s.name, "start": stage_frame(s.start), "end": stage_frame(s.end)})).collect::<Vec<_>>(),
        "bird_model": match assets {
            [one] => serde_json::Value::from(one.source.clone()),
            several => several.iter().map(|a| a.source.clone()).collect(),
        },
        "joints": bird::JOINTS,
        "keys": opts.keys.to_string(),
        "size_variation": opts.size_variation,
        "bird_scales": bird::bird_scales(anim.seed, anim.birds, opts.size_variation)
            .iter()
            .map(|&s| short(s))
            .collect::<Vec<_>>(),
        // How far below the root (in the bird's frame) sizes are taken about.
        "size_pivot_m": short(crate::wingbeat::rest::stance(species).sit as f32 * wingspan_m as f32),
    });
    if let (Some(o), true) = (m.as_object_mut(), assets.len() > 1) {
        o.insert("bird_model_of".into(), opts.model_of(anim).into());
    }
    if opts.frame_rate.is_some() {
        if let Some(o) = m.as_object_mut() {
            o.insert(
                "subframes".into(),
                ((anim.fps / rate).round() as u64).into(),
            );
        }
    }
    m
}

/// An f32 as the JSON number of its shortest text (`1.0365741`, not its f64 widening).
fn short(v: f32) -> serde_json::Value {
    format!("{v}")
        .parse::<f64>()
        .ok()
        .and_then(serde_json::Number::from_f64)
        .map_or(serde_json::Value::Null, serde_json::Value::Number)
}

/// A frame number as JSON: an integer when whole (every frame), else the fractional number
/// (a sub-frame sample).
fn frame_value(f: f64) -> serde_json::Value {
    if f.fract() == 0.0 && (0.0..9.0e15).contains(&f) {
        (f as u64).into()
    } else {
        f.into()
    }
}

/// The scene's `extras`: [`metadata`] and the timeline a player needs: the rate, the first and
/// last frame of the range to play (a loop's closing key is one frame past `frame_end`), and the
/// clip mode.
fn scene_metadata(
    anim: &Animation,
    wingspan_m: f64,
    assets: &[BirdAsset],
    opts: &SceneOptions,
) -> serde_json::Value {
    let mut m = metadata(anim, wingspan_m, assets, opts);
    if let Some(o) = m.as_object_mut() {
        o.insert("frame_start".into(), opts.start_frame.into());
        o.insert("frame_end".into(), opts.frame_end(anim).into());
        o.insert("clips".into(), opts.clips.to_string().into());
    }
    m
}

/// The last frame of the range to play of an animation as [`closed_loop`] gives it: the last
/// frame, or for a loop the one before its closing frame (which repeats the first).
pub fn play_end(anim: &Animation) -> usize {
    let n = anim.frames.len();
    n.saturating_sub(1 + usize::from(anim.looped && n > 2))
}

/// A clip's `extras`: its stage (or `flight`), frames and start time; in one clip, the stages
/// as markers (name, first frame, time).
fn clip_metadata(anim: &Animation, c: &Clip, opts: &SceneOptions) -> serde_json::Value {
    let frame = |k: usize| frame_value(opts.frame_of(anim, k));
    let mut v = serde_json::json!({
        "stage": c.name,
        "first_frame": frame(c.first),
        "last_frame": frame(c.last),
        "start_s": anim.frames[c.first].t,
        "fps": opts.rate(anim),
    });
    if c.name == "flight" && !anim.stages.is_empty() {
        v["markers"] = anim
            .stages
            .iter()
            .filter(|s| s.start < anim.frames.len())
            .map(|s| serde_json::json!({"name": s.name, "frame": frame(s.start), "t": anim.frames[s.start].t}))
            .collect();
    }
    v
}

fn extras(v: &serde_json::Value) -> json::Extras {
    serde_json::value::RawValue::from_string(v.to_string()).ok()
}

/// Key times of clip `c`: from the clip's first frame, and for the one clip over every stage
/// from the shot's first frame number (`start_frame / fps` s); refused when 32-bit floats cannot
/// keep them increasing.
fn clip_times(anim: &Animation, c: &Clip, opts: &SceneOptions) -> Result<Vec<f32>> {
    let t0 = anim.frames[c.first].t;
    let offset = if opts.clips == ClipMode::One {
        opts.start_frame as f64 / opts.rate(anim)
    } else {
        0.0
    };
    let times: Vec<f32> = anim.frames[c.first..=c.last]
        .iter()
        .map(|f| (f.t - t0 + offset) as f32)
        .collect();
    if times.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::parameter(
            "frames",
            "frame times are too close to store as glTF keyframes (32-bit floats); render at a lower fps, fewer sub-frames or an earlier first frame",
        ));
    }
    Ok(times)
}

/// The joints the wingbeat moves.
const WING_JOINTS: [usize; 5] = [
    bird::TAIL,
    bird::arm_joint(Side::Left),
    bird::hand_joint(Side::Left),
    bird::arm_joint(Side::Right),
    bird::hand_joint(Side::Right),
];

/// The leg joints: animated only for a bird whose legs move in the animation (a take-off or a
/// landing), so that a flight in the air keeps the channels it had without them.
const LEG_JOINTS: [usize; 2] = [bird::leg_joint(Side::Left), bird::leg_joint(Side::Right)];

/// Per bird: flight and local joint rotations at every frame, on the asset's skeleton.
pub struct BirdTrack {
    /// Root translation (metres) and yaw, and the bank.
    pub flight: Flight,
    /// Local rotation of every joint at every frame (bind rotations applied), sign-continuous.
    pub joints: Vec<[Quat; bird::N_JOINTS]>,
}

/// The track of `bird` for `asset`.
pub fn bird_track(
    anim: &Animation,
    flapper: &Flapper,
    asset: &BirdAsset,
    bird: usize,
    wingspan_m: f64,
) -> BirdTrack {
    let flight = bird::flight(anim, bird, wingspan_m);
    let ours = bird::joint_track(flapper, &flight, bird);
    let skel = &asset.skeleton;
    let mut joints: Vec<[Quat; bird::N_JOINTS]> = Vec::with_capacity(ours.len());
    let still_legs = !asset.has_legs();
    for q in ours {
        let mut l: [Quat; bird::N_JOINTS] = std::array::from_fn(|j| {
            // The neck never moves; a static model moves only its body; legs that nothing is
            // skinned to stay at rest.
            if j == bird::NECK
                || (!asset.wingbeat && j != bird::BODY)
                || (still_legs && LEG_JOINTS.contains(&j))
            {
                skel.rest_rotation(j)
            } else {
                skel.local_rotation(j, q[j])
            }
        });
        if let Some(p) = joints.last() {
            for j in 0..bird::N_JOINTS {
                l[j] = bird::continuous(p[j], l[j]);
            }
        }
        joints.push(l);
    }
    BirdTrack { flight, joints }
}

/// Builds the `.glb` bytes with `opts`.
pub fn glb_bytes_with(anim: &Animation, wingspan_m: f64, opts: &SceneOptions) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    write_glb_with(anim, wingspan_m, opts, &mut out)
        .map_err(|e| Error::Internal(format!("writing glTF to memory: {e}")))??;
    Ok(out)
}

/// [`glb_bytes_with`] written to `out` as it is made: the binary chunk goes out from the buffer
/// it was built in, not through a copy of the whole file. The outer error is `out`'s; the inner
/// one the scene's.
pub fn write_glb_with(
    anim: &Animation,
    wingspan_m: f64,
    opts: &SceneOptions,
    out: &mut impl std::io::Write,
) -> std::io::Result<Result<()>> {
    let (json_bytes, bin, _) = match glb_parts(anim, wingspan_m, opts, None) {
        Ok(parts) => parts?,
        Err(e) => return Ok(Err(e)),
    };
    write_glb(json_bytes, &mut &bin[..], bin.len(), out)?;
    Ok(Ok(()))
}

/// [`write_glb_with`] with the binary chunk written to `spill` (a scratch file) as it is made
/// and copied from `spill_path` into `out` after the JSON: memory holds the JSON, never the
/// binary data (the larger part: 1000 birds for 53 s is 220 MB of it).
pub fn write_glb_spilled(
    anim: &Animation,
    wingspan_m: f64,
    opts: &SceneOptions,
    spill: &mut std::io::BufWriter<std::fs::File>,
    spill_path: &std::path::Path,
    out: &mut impl std::io::Write,
) -> std::io::Result<Result<()>> {
    let (json_bytes, _, len) = match glb_parts(anim, wingspan_m, opts, Some(spill)) {
        Ok(parts) => parts?,
        Err(e) => return Ok(Err(e)),
    };
    std::io::Write::flush(spill)?;
    let mut back = std::io::BufReader::new(std::fs::File::open(spill_path)?);
    write_glb(json_bytes, &mut back, len, out)?;
    Ok(Ok(()))
}

/// A scene's JSON chunk, binary chunk (empty when spilled) and the binary chunk's length.
type GlbParts = (Vec<u8>, Vec<u8>, usize);

/// The JSON and binary chunks of the scene, and the binary chunk's length; with `spill`, the
/// binary chunk is written there as it is made (and the one returned is empty).
fn glb_parts(
    anim: &Animation,
    wingspan_m: f64,
    opts: &SceneOptions,
    spill: Option<&mut dyn std::io::Write>,
) -> Result<std::io::Result<GlbParts>> {
    let mut b = Builder {
        bin: match spill {
            Some(out) => Sink::Spill {
                out,
                len: 0,
                error: None,
            },
            None => Sink::default(),
        },
        non_finite: None,
    };
    let ws = wingspan_m as f32;
    let assets = opts.models(anim);
    let model_of = opts.model_of(anim);
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
    // Each model's inverse bind matrices (its joints, column-major).
    let model_ibm: Vec<Vec<f32>> = assets
        .iter()
        .map(|asset| {
            (0..bird::JOINTS.len())
                .flat_map(|j| asset.skeleton.inverse_bind(j, ws).to_cols_array())
                .collect()
        })
        .collect();
    // Each model's mesh and inverse bind matrices, shared by the birds that wear it (none with
    // one skin for the flock: its mesh is made after the birds).
    let shared: Vec<(json::Index<json::Mesh>, json::Index<json::Accessor>)> = assets
        .iter()
        .filter(|_| !opts.one_skin)
        .enumerate()
        .map(|(m, asset)| {
            let name = if assets.len() == 1 {
                "bird".to_string()
            } else {
                format!("bird_model_{m}")
            };
            let mesh = b.skinned_mesh(&mut root, asset, ws, &name);
            let ibm_acc = b.accessor(
                &mut root,
                &model_ibm[m],
                16,
                json::accessor::Type::Mat4,
                false,
                None,
            );
            (mesh, ibm_acc)
        })
        .collect();

    let clips = clips(anim, opts.clips);
    let flapper = Flapper::from_animation(anim);
    let digits = bird_digits(anim.birds);
    let scales = bird::bird_scales(anim.seed, anim.birds, opts.size_variation);
    let species = WingbeatOptions::for_animation(anim).species;
    let mut bird_nodes = Vec::with_capacity(anim.birds);
    let mut mesh_nodes = Vec::with_capacity(anim.birds);
    // With one skin for the flock: every bird's joints, in bird order.
    let mut flock_joints = Vec::new();
    // Per clip: channels and samplers.
    let mut anims: Vec<(Vec<json::animation::Channel>, Vec<json::animation::Sampler>)> =
        clips.iter().map(|_| (Vec::new(), Vec::new())).collect();
    let clip_t: Vec<Vec<f32>> = clips
        .iter()
        .map(|c| clip_times(anim, c, opts))
        .collect::<Result<_>>()?;
    // One time accessor per clip for every channel keyed at every frame (made when first needed).
    let mut shared_t: Vec<Option<json::Index<json::Accessor>>> = vec![None; clips.len()];
    for (bird, &scale) in scales.iter().enumerate() {
        let model = model_of[bird];
        let asset = &assets[model];
        let track = bird_track(anim, &flapper, asset, bird, wingspan_m);
        // Skeleton nodes, children before parents so indices are known.
        let mut joint_nodes: [Option<json::Index<json::Node>>; bird::N_JOINTS] =
            [None; bird::N_JOINTS];
        for j in (0..bird::JOINTS.len()).rev() {
            let children: Vec<_> = (0..bird::JOINTS.len())
                .filter(|&c| bird::PARENT[c] == Some(j))
                .filter_map(|c| joint_nodes[c])
                .collect();
            let mut rest = asset.skeleton.rest_translation(j);
            if j == bird::BODY && scale != 1.0 {
                rest += bird::size_pivot(species, scale);
            }
            // Joint names repeat from bird to bird; in a part's skeleton they carry the bird's name.
            let joint_name = if opts.one_skin {
                format!("bird_{bird:0digits$}.{}", bird::JOINTS[j])
            } else {
                bird::JOINTS[j].to_string()
            };
            let node = root.push(json::Node {
                name: Some(joint_name),
                translation: Some((rest * ws).to_array()),
                rotation: Some(json::scene::UnitQuaternion(track.joints[0][j].to_array())),
                children: (!children.is_empty()).then_some(children),
                ..Default::default()
            });
            joint_nodes[j] = Some(node);
        }
        let joints: Vec<_> = joint_nodes
            .iter()
            .map(|n| n.expect("every joint built"))
            .collect();
        let name = format!("bird_{bird:0digits$}");
        let bird_node = root.push(json::Node {
            name: Some(name.clone()),
            translation: Some(track.flight.translation[0].to_array()),
            rotation: Some(json::scene::UnitQuaternion(track.flight.yaw[0].to_array())),
            // The bird's size: the scale scales its skeleton and so its skinned mesh, not its
            // place (a scale of exactly 1 is left out, as glTF's default).
            scale: (scale != 1.0).then_some([scale; 3]),
            children: Some(vec![joints[bird::BODY]]),
            extras: extras(&{
                let mut e = serde_json::json!({"bird": bird});
                if scale != 1.0 {
                    e["scale"] = short(scale);
                }
                if assets.len() > 1 {
                    e["bird_model"] = model.into();
                }
                e
            }),
            ..Default::default()
        });
        bird_nodes.push(bird_node);
        if opts.one_skin {
            // The bird's root is a joint too (bound to no vertex, its bind at the origin): an
            // importer then takes each bone's rest from its own bind, not from its children's.
            flock_joints.push(bird_node);
            flock_joints.extend(joints.iter().copied());
        } else {
            let (mesh, ibm_acc) = shared[model];
            let skin = root.push(json::Skin {
                extensions: None,
                extras: Default::default(),
                inverse_bind_matrices: Some(ibm_acc),
                joints: joints.clone(),
                name: Some(format!("{name}_skin")),
                skeleton: Some(joints[bird::BODY]),
            });
            mesh_nodes.push(root.push(json::Node {
                name: Some(format!("{name}_mesh")),
                mesh: Some(mesh),
                skin: Some(skin),
                ..Default::default()
            }));
        }

        // The wing joints, and the legs when they move in any frame of the bird's track.
        let rest_leg = |j: usize| asset.skeleton.rest_rotation(j);
        let legs_move = LEG_JOINTS.iter().any(|&j| {
            track
                .joints
                .iter()
                .any(|q| q[j].dot(rest_leg(j)).abs() < 1.0 - 1e-7)
        });
        let moving: Vec<usize> = WING_JOINTS
            .iter()
            .chain(LEG_JOINTS.iter().filter(|_| legs_move))
            .copied()
            .collect();
        for (ci, c) in clips.iter().enumerate() {
            let r = c.first..c.last + 1;
            let times = &clip_t[ci];
            let tr = &track.flight.translation[r.clone()];
            let yaw = &track.flight.yaw[r.clone()];
            let per_joint: Vec<Vec<Quat>> = (0..bird::JOINTS.len())
                .map(|j| track.joints[r.clone()].iter().map(|q| q[j]).collect())
                .collect();
            let tol = opts.tolerance;
            let reduced = opts.keys == KeyMode::Reduced;
            let mut ch = ClipWriter {
                b: &mut b,
                root: &mut root,
                times,
                shared: &mut shared_t[ci],
                out: &mut anims[ci],
            };
            use json::animation::Property::{Rotation, Translation};
            // Flight: translation as floats; yaw and bank as normalised shorts when reduced
            // (error under 0.01°, far inside the tolerance, which the key choice accounts for).
            let (yaw16, yaw_s): (Vec<[i16; 4]>, Vec<Quat>) =
                yaw.iter().map(|&q| keys::quantise_i16(q)).unzip();
            let (bank16, bank_s): (Vec<[i16; 4]>, Vec<Quat>) = per_joint[bird::BODY]
                .iter()
                .map(|&q| keys::quantise_i16(q))
                .unzip();
            let kept = keys::keep(
                opts.keys,
                times,
                &[
                    Curve::Vec3(tr, tol.position_m),
                    Curve::Stored {
                        exact: yaw,
                        stored: &yaw_s,
                        tol: tol.rotation_rad,
                    },
                    Curve::Stored {
                        exact: &per_joint[bird::BODY],
                        stored: &bank_s,
                        tol: tol.rotation_rad,
                    },
                ],
            );
            let input = ch.input(&kept);
            let trs: Vec<f32> = kept.iter().flat_map(|&k| tr[k].to_array()).collect();
            ch.floats(input, bird_node, Translation, &trs, 3);
            if reduced {
                ch.shorts(input, bird_node, &yaw16, &kept);
                ch.shorts(input, joints[bird::BODY], &bank16, &kept);
            } else {
                ch.quats(input, bird_node, yaw, &kept);
                ch.quats(input, joints[bird::BODY], &per_joint[bird::BODY], &kept);
            }
            if asset.wingbeat {
                if !reduced {
                    let all: Vec<usize> = (0..times.len()).collect();
                    let input = ch.input(&all);
                    for &j in &moving {
                        ch.quats(input, joints[j], &per_joint[j], &all);
                    }
                } else {
                    // Reduced: the wing rotations are stored as normalised bytes (4 bytes a key
                    // instead of 16), and the kept keys are chosen against the decoded values.
                    let q8: Vec<(Vec<[i8; 4]>, Vec<Quat>)> = moving
                        .iter()
                        .map(|&j| per_joint[j].iter().map(|&q| keys::quantise_i8(q)).unzip())
                        .collect();
                    let curves: Vec<Curve> = moving
                        .iter()
                        .zip(&q8)
                        .map(|(&j, (_, stored))| Curve::Stored {
                            exact: &per_joint[j],
                            stored,
                            tol: tol.wing_rad,
                        })
                        .collect();
                    let mut kept = keys::keep(opts.keys, times, &curves);
                    // A time accessor of its own costs 4 bytes a key; keeping every frame on the
                    // clip's shared one costs 4 bytes a joint for each extra key: take the smaller.
                    let n = times.len();
                    if kept.len() * (4 + 4 * moving.len()) >= n * 4 * moving.len() {
                        kept = (0..n).collect();
                    }
                    let input = ch.input(&kept);
                    for (&j, (bytes, _)) in moving.iter().zip(&q8) {
                        let data: Vec<u8> = kept
                            .iter()
                            .flat_map(|&k| bytes[k].map(|v| v as u8))
                            .collect();
                        ch.raw(
                            input,
                            joints[j],
                            Rotation,
                            &data,
                            kept.len(),
                            json::accessor::ComponentType::I8,
                        );
                    }
                }
            }
        }
    }
    // With one skin a part, the part's birds hang from a node of their own (`flock_000`, …),
    // the root of the part's skeleton.
    let part_digits = bird_digits(anim.birds.div_ceil(FLOCK_PART));
    let flock_children: Vec<_> = if opts.one_skin {
        bird_nodes
            .chunks(FLOCK_PART)
            .enumerate()
            .map(|(p, birds)| {
                root.push(json::Node {
                    name: Some(format!("flock_{p:0part_digits$}")),
                    children: Some(birds.to_vec()),
                    ..Default::default()
                })
            })
            .collect()
    } else {
        bird_nodes
    };
    let flock = root.push(json::Node {
        name: Some("flock".into()),
        children: Some(flock_children.clone()),
        ..Default::default()
    });
    if opts.one_skin {
        // The flock in parts of FLOCK_PART birds: each part one mesh holding its birds (each
        // bird's copy of its model bound to its own joints) on one skin of their joints, whose
        // skeleton is the part's node, so a DCC makes one armature a part. Parts keep each
        // mesh's skin small (Blender's importer binds a mesh's vertices joint by joint) and
        // each armature's action: Blender's importer looks up every new curve among the
        // action's curves, and builds its scene graph slower the more bones an armature has
        // (1000 birds: 67 s of CPU as one armature, 44 s as 16).
        let joints_per_bird = bird::JOINTS.len() + 1;
        let models = &assets;
        for (p, first) in (0..anim.birds).step_by(FLOCK_PART).enumerate() {
            let last = (first + FLOCK_PART).min(anim.birds);
            let name = format!("flock_{p:0part_digits$}");
            let mesh = b.skinned_meshes(&mut root, models, &model_of[first..last], ws, &name, true);
            // Per bird: its root's bind (the origin), then its model's joints.
            let identity = glam::Mat4::IDENTITY.to_cols_array();
            let ibm: Vec<f32> = model_of[first..last]
                .iter()
                .flat_map(|&m| identity.iter().chain(&model_ibm[m]).copied())
                .collect();
            let ibm = b.accessor(&mut root, &ibm, 16, json::accessor::Type::Mat4, false, None);
            let skin = root.push(json::Skin {
                extensions: None,
                extras: Default::default(),
                inverse_bind_matrices: Some(ibm),
                joints: flock_joints[first * joints_per_bird..last * joints_per_bird].to_vec(),
                name: Some(format!("{name}_skin")),
                skeleton: Some(flock_children[p]),
            });
            mesh_nodes.push(root.push(json::Node {
                name: Some(format!("{name}_mesh")),
                mesh: Some(mesh),
                skin: Some(skin),
                ..Default::default()
            }));
        }
    }
    let mut scene_nodes = vec![flock];
    scene_nodes.extend(mesh_nodes);
    // The course as flown (turns widened), for layout: a line strip (no material: a viewer
    // draws it in its default colour; Blender imports it as a mesh of edges).
    if let Some(path) = anim.path.as_ref().filter(|p| p.flown.len() >= 2) {
        let pts: Vec<f32> = path
            .flown
            .iter()
            .flat_map(|p| {
                [
                    (p[0] * wingspan_m) as f32,
                    (p[2] * wingspan_m) as f32,
                    -(p[1] * wingspan_m) as f32,
                ]
            })
            .collect();
        let pos = b.accessor(
            &mut root,
            &pts,
            3,
            json::accessor::Type::Vec3,
            true,
            Some(json::buffer::Target::ArrayBuffer),
        );
        let mut attributes = BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some("flown_path".into()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: None,
                material: None,
                mode: Valid(json::mesh::Mode::LineStrip),
                targets: None,
            }],
            weights: None,
        });
        scene_nodes.push(root.push(json::Node {
            name: Some("flown_path".into()),
            mesh: Some(mesh),
            extras: extras(&serde_json::json!({"flown_path": true, "closed": path.closed})),
            ..Default::default()
        }));
    }
    let scene = root.push(json::Scene {
        extensions: None,
        extras: extras(&scene_metadata(anim, wingspan_m, &assets, opts)),
        name: Some("flock".into()),
        nodes: scene_nodes,
    });
    root.scene = Some(scene);
    for (c, (channels, samplers)) in clips.iter().zip(anims) {
        root.push(json::Animation {
            extensions: None,
            extras: extras(&clip_metadata(anim, c, opts)),
            channels,
            name: Some(c.name.clone()),
            samplers,
        });
    }
    if let Some(at) = b.non_finite.take() {
        return Err(Error::Internal(format!(
            "glTF: refusing to write a non-finite number in {at}"
        )));
    }
    let (bin, len) = match b.finish(&mut root) {
        Ok(b) => b,
        Err(e) => return Ok(Err(e)),
    };
    let json_bytes = root
        .to_vec()
        .map_err(|e| Error::Internal(format!("serialising glTF JSON: {e}")))?;
    Ok(Ok((json_bytes, bin, len)))
}

/// Writes the channels of one bird in one clip.
struct ClipWriter<'a, 's> {
    b: &'a mut Builder<'s>,
    root: &'a mut json::Root,
    /// Times of every frame of the clip, seconds from its start.
    times: &'a [f32],
    /// The clip's time accessor over every frame, once made.
    shared: &'a mut Option<json::Index<json::Accessor>>,
    out: &'a mut (Vec<json::animation::Channel>, Vec<json::animation::Sampler>),
}

impl ClipWriter<'_, '_> {
    /// The time accessor of the frames `kept` (the shared one when that is every frame).
    fn input(&mut self, kept: &[usize]) -> json::Index<json::Accessor> {
        if kept.len() == self.times.len() {
            if let Some(i) = *self.shared {
                return i;
            }
            let i = self.b.accessor(
                self.root,
                self.times,
                1,
                json::accessor::Type::Scalar,
                true,
                None,
            );
            *self.shared = Some(i);
            return i;
        }
        let t: Vec<f32> = kept.iter().map(|&k| self.times[k]).collect();
        self.b
            .accessor(self.root, &t, 1, json::accessor::Type::Scalar, true, None)
    }

    fn push(
        &mut self,
        input: json::Index<json::Accessor>,
        output: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
        path: json::animation::Property,
    ) {
        let (channels, samplers) = &mut *self.out;
        samplers.push(sampler(input, output));
        channels.push(channel(samplers.len() - 1, node, path));
    }

    fn floats(
        &mut self,
        input: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
        path: json::animation::Property,
        data: &[f32],
        width: usize,
    ) {
        let ty = if width == 3 {
            json::accessor::Type::Vec3
        } else {
            json::accessor::Type::Vec4
        };
        let out = self.b.accessor(self.root, data, width, ty, false, None);
        self.push(input, out, node, path);
    }

    fn quats(
        &mut self,
        input: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
        q: &[Quat],
        kept: &[usize],
    ) {
        let data: Vec<f32> = kept.iter().flat_map(|&k| q[k].to_array()).collect();
        self.floats(input, node, json::animation::Property::Rotation, &data, 4);
    }

    fn shorts(
        &mut self,
        input: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
        q: &[[i16; 4]],
        kept: &[usize],
    ) {
        let data: Vec<u8> = kept
            .iter()
            .flat_map(|&k| q[k])
            .flat_map(|v| v.to_le_bytes())
            .collect();
        self.raw(
            input,
            node,
            json::animation::Property::Rotation,
            &data,
            kept.len(),
            json::accessor::ComponentType::I16,
        );
    }

    fn raw(
        &mut self,
        input: json::Index<json::Accessor>,
        node: json::Index<json::Node>,
        path: json::animation::Property,
        data: &[u8],
        count: usize,
        ct: json::accessor::ComponentType,
    ) {
        let out = self.b.raw_accessor(
            self.root,
            data,
            count,
            ct,
            json::accessor::Type::Vec4,
            true,
            None,
        );
        self.push(input, out, node, path);
    }
}

fn sampler(
    input: json::Index<json::Accessor>,
    output: json::Index<json::Accessor>,
) -> json::animation::Sampler {
    json::animation::Sampler {
        extensions: None,
        extras: Default::default(),
        input,
        interpolation: Valid(json::animation::Interpolation::Linear),
        output,
    }
}

fn channel(
    sampler: usize,
    node: json::Index<json::Node>,
    path: json::animation::Property,
) -> json::animation::Channel {
    json::animation::Channel {
        sampler: json::Index::new(sampler as u32),
        target: json::animation::Target {
            extensions: None,
            extras: Default::default(),
            node,
            path: Valid(path),
        },
        extensions: None,
        extras: Default::default(),
    }
}

fn material(name: &str, rgb: [f32; 3]) -> json::Material {
    json::Material {
        name: Some(name.into()),
        double_sided: true,
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([rgb[0], rgb[1], rgb[2], 1.0]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.85),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// The parts of `m` as one primitive: the vertices to write (indices into `m`, in order), each
/// one's colour (its part's) and the triangles over them. A vertex shared by parts of different
/// colours is written once per colour; a vertex no triangle uses is white.
fn one_primitive(m: &bird::SkinnedMesh) -> (Vec<usize>, Vec<[f32; 3]>, Vec<u32>) {
    let n = m.positions.len();
    let mut order: Vec<usize> = (0..n).collect();
    let mut colours: Vec<Option<[f32; 3]>> = vec![None; n];
    let mut copies: BTreeMap<(u32, [u32; 3]), u32> = BTreeMap::new();
    let mut idx = Vec::with_capacity(m.parts.iter().map(|(_, i)| i.len()).sum());
    for ((_, part), &rgb) in m.parts.iter().zip(&m.colours) {
        for &v in part {
            let i = v as usize;
            let out = match colours[i] {
                None => {
                    colours[i] = Some(rgb);
                    v
                }
                Some(c) if c == rgb => v,
                Some(_) => *copies.entry((v, rgb.map(f32::to_bits))).or_insert_with(|| {
                    order.push(i);
                    colours.push(Some(rgb));
                    (order.len() - 1) as u32
                }),
            };
            idx.push(out);
        }
    }
    let colours = colours.into_iter().map(|c| c.unwrap_or([1.0; 3])).collect();
    (order, colours, idx)
}

/// Birds per skinned mesh and skeleton in the flock mode ([`SceneOptions::one_skin`]): 64 birds
/// are 640 joints (ten a bird with its root), within what real-time engines skin in one draw call.
pub const FLOCK_PART: usize = 64;

/// A value in 0..=1 as a normalised byte.
fn unit_byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Skin weights as normalised bytes summing to exactly 255 (the rounding's remainder goes to
/// the largest weight), as glTF asks of quantised weights.
fn weight_bytes(w: [f32; 4]) -> [u8; 4] {
    let total: f32 = w.iter().sum();
    let mut q = w.map(|v| {
        ((v / total.max(f32::MIN_POSITIVE)) * 255.0)
            .round()
            .clamp(0.0, 255.0) as i32
    });
    let largest = (0..4)
        .max_by(|&a, &b| q[a].cmp(&q[b]).then(b.cmp(&a)))
        .unwrap_or(0);
    q[largest] += 255 - q.iter().sum::<i32>();
    q.map(|v| v.clamp(0, 255) as u8)
}

/// Collects binary data, 4-byte aligned, one buffer view per accessor.
/// Where the binary chunk is built: in memory, or written out as it grows (a scratch file, so
/// that a large scene's binary data is never held whole).
enum Sink<'a> {
    Memory(Vec<u8>),
    Spill {
        out: &'a mut dyn std::io::Write,
        len: usize,
        error: Option<std::io::Error>,
    },
}

impl Default for Sink<'_> {
    fn default() -> Self {
        Sink::Memory(Vec::new())
    }
}

impl Sink<'_> {
    fn len(&self) -> usize {
        match self {
            Sink::Memory(v) => v.len(),
            Sink::Spill { len, .. } => *len,
        }
    }

    fn extend(&mut self, bytes: &[u8]) {
        match self {
            Sink::Memory(v) => v.extend_from_slice(bytes),
            Sink::Spill { out, len, error } => {
                *len += bytes.len();
                if error.is_none() {
                    if let Err(e) = out.write_all(bytes) {
                        *error = Some(e);
                    }
                }
            }
        }
    }

    /// Zero bytes up to the next multiple of 4.
    fn pad(&mut self) {
        let n = (4 - self.len() % 4) % 4;
        self.extend(&[0u8; 3][..n]);
    }
}

#[derive(Default)]
struct Builder<'a> {
    bin: Sink<'a>,
    /// The first accessor holding a non-finite number (never written), by index.
    non_finite: Option<String>,
}

impl Builder<'_> {
    fn view(
        &mut self,
        root: &mut json::Root,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        self.bin.pad();
        let offset = self.bin.len();
        self.bin.extend(bytes);
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

    /// An accessor over raw little-endian `bytes` of `count` elements.
    #[allow(clippy::too_many_arguments)]
    fn raw_accessor(
        &mut self,
        root: &mut json::Root,
        bytes: &[u8],
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        normalized: bool,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        let view = self.view(root, bytes, target);
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min: None,
            max: None,
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// A vertex attribute of `count` four-byte elements, normalised bytes (colours, weights).
    fn unit_bytes4(
        &mut self,
        root: &mut json::Root,
        bytes: &[u8],
        count: usize,
    ) -> json::Index<json::Accessor> {
        self.raw_accessor(
            root,
            bytes,
            count,
            json::accessor::ComponentType::U8,
            json::accessor::Type::Vec4,
            true,
            Some(json::buffer::Target::ArrayBuffer),
        )
    }

    /// The asset's skinned mesh in metres, as one primitive with one material (one draw call a
    /// bird): each part's colour is its vertices' `COLOR_0`, which glTF multiplies into the
    /// white base colour (see [`one_primitive`]).
    fn skinned_mesh(
        &mut self,
        root: &mut json::Root,
        asset: &BirdAsset,
        ws: f32,
        name: &str,
    ) -> json::Index<json::Mesh> {
        self.skinned_meshes(root, std::slice::from_ref(asset), &[0], ws, name, false)
    }

    /// One skinned primitive holding, for every bird `i`, a copy of the mesh of its model
    /// `assets[model_of[i]]` bound to its joints of one skin. `flock`: a part of the flock's one
    /// skeleton, where each bird has 10 joints (its root, then the nine of [`bird::JOINTS`]; joints `10·i + 1 ..`)
    /// and colours and weights are normalised bytes; else one bird's mesh (joints `0 .. 9`).
    fn skinned_meshes(
        &mut self,
        root: &mut json::Root,
        assets: &[BirdAsset],
        model_of: &[usize],
        ws: f32,
        name: &str,
        flock: bool,
    ) -> json::Index<json::Mesh> {
        let joints_per_bird = bird::JOINTS.len() + usize::from(flock);
        let (mut pos, mut nor, mut col) = (Vec::new(), Vec::new(), Vec::new());
        let (mut jw, mut wf, mut idx): (Vec<u16>, Vec<f32>, Vec<u32>) =
            (Vec::new(), Vec::new(), Vec::new());
        // Each model's primitive, made once.
        let made: Vec<_> = assets.iter().map(|a| one_primitive(&a.mesh)).collect();
        for (i, &model) in model_of.iter().enumerate() {
            let (order, colours, tri) = &made[model];
            let m = &assets[model].mesh;
            let base = (pos.len() / 3) as u32;
            let first_joint = (i * joints_per_bird + usize::from(flock)) as u16;
            for &v in order {
                pos.extend((m.positions[v] * ws).to_array());
                nor.extend(m.normals[v].to_array());
                // Unused slots (weight 0) stay at joint 0, as glTF asks.
                for (&j, &w) in m.joints[v].iter().zip(&m.weights[v]) {
                    jw.push(if w > 0.0 {
                        first_joint + u16::from(j)
                    } else {
                        0
                    });
                }
                wf.extend(m.weights[v]);
            }
            col.extend(colours.iter().flatten().copied());
            idx.extend(tri.iter().map(|&t| base + t));
        }
        let vertices = pos.len() / 3;
        let target = Some(json::buffer::Target::ArrayBuffer);
        let pos = self.accessor(root, &pos, 3, json::accessor::Type::Vec3, true, target);
        let nor = self.accessor(root, &nor, 3, json::accessor::Type::Vec3, false, target);
        // A flock's mesh repeats the bird a thousand times: colours and weights as normalised
        // bytes there (4 bytes each instead of 12 and 16); one bird's mesh keeps floats. A weight
        // that rounds to 0 frees its slot (joint 0, as glTF asks of unused slots).
        let mut bytes = Vec::new();
        if flock {
            for (w, j) in wf.chunks_exact(4).zip(jw.chunks_exact_mut(4)) {
                let q = weight_bytes([w[0], w[1], w[2], w[3]]);
                for (jk, &qk) in j.iter_mut().zip(&q) {
                    if qk == 0 {
                        *jk = 0;
                    }
                }
                bytes.extend(q);
            }
        }
        let col = if flock {
            let rgba: Vec<u8> = col
                .chunks_exact(3)
                .flat_map(|c| [unit_byte(c[0]), unit_byte(c[1]), unit_byte(c[2]), 255])
                .collect();
            self.unit_bytes4(root, &rgba, vertices)
        } else {
            self.accessor(root, &col, 3, json::accessor::Type::Vec3, false, target)
        };
        // Joint indices as bytes while they fit (one bird: 9 joints), else as shorts.
        let (jb, jct): (Vec<u8>, _) = if model_of.len() * joints_per_bird <= 256 {
            (
                jw.iter().map(|&j| j as u8).collect(),
                json::accessor::ComponentType::U8,
            )
        } else {
            (
                jw.iter().flat_map(|j| j.to_le_bytes()).collect(),
                json::accessor::ComponentType::U16,
            )
        };
        let joints = self.raw_accessor(
            root,
            &jb,
            vertices,
            jct,
            json::accessor::Type::Vec4,
            false,
            target,
        );
        let weights = if flock {
            self.unit_bytes4(root, &bytes, vertices)
        } else {
            self.accessor(root, &wf, 4, json::accessor::Type::Vec4, false, target)
        };
        let mat = root.push(material(name, [1.0, 1.0, 1.0]));
        let (bytes, ct): (Vec<u8>, _) = if vertices > u16::MAX as usize {
            (
                idx.iter().flat_map(|v| v.to_le_bytes()).collect(),
                json::accessor::ComponentType::U32,
            )
        } else {
            (
                idx.iter().flat_map(|&v| (v as u16).to_le_bytes()).collect(),
                json::accessor::ComponentType::U16,
            )
        };
        let ia = self.raw_accessor(
            root,
            &bytes,
            idx.len(),
            ct,
            json::accessor::Type::Scalar,
            false,
            Some(json::buffer::Target::ElementArrayBuffer),
        );
        let mut attributes = BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        attributes.insert(Valid(json::mesh::Semantic::Normals), nor);
        attributes.insert(Valid(json::mesh::Semantic::Colors(0)), col);
        attributes.insert(Valid(json::mesh::Semantic::Joints(0)), joints);
        attributes.insert(Valid(json::mesh::Semantic::Weights(0)), weights);
        root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.into()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(ia),
                material: Some(mat),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        })
    }

    /// The buffer's entry in `root`, and the binary chunk when it was built in memory (empty
    /// when it was spilled; the spill's write error, if any, is the `Err`).
    fn finish(mut self, root: &mut json::Root) -> std::io::Result<(Vec<u8>, usize)> {
        self.bin.pad();
        let len = self.bin.len();
        root.push(json::Buffer {
            byte_length: USize64::from(len),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        match self.bin {
            Sink::Memory(v) => Ok((v, len)),
            Sink::Spill { error: Some(e), .. } => Err(e),
            Sink::Spill { .. } => Ok((Vec::new(), len)),
        }
    }
}

/// Writes JSON and binary chunks as a GLB container (JSON padded with spaces, BIN with zeros).
fn write_glb(
    mut json_bytes: Vec<u8>,
    bin: &mut impl std::io::Read,
    bin_len: usize,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin_len;
    let too_big = |what: &str| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{what} is more than the 4 GiB a GLB file can hold"),
        )
    };
    let total = u32::try_from(total).map_err(|_| too_big("the scene"))?;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json_bytes.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&json_bytes)?;
    out.write_all(&(bin_len as u32).to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    let copied = std::io::copy(&mut std::io::Read::take(bin, bin_len as u64), out)?;
    if copied != bin_len as u64 {
        return Err(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            "the binary chunk's scratch file is shorter than written",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn heading_east_faces_glb_plus_x() {
        let q = Quat::from_rotation_y(std::f32::consts::PI - std::f32::consts::PI / 2.0);
        let f = q * Vec3::Z;
        assert!((f - Vec3::X).length() < 1e-6, "{f}");
        let q = Quat::from_rotation_y(std::f32::consts::PI);
        assert!((q * Vec3::Z - Vec3::NEG_Z).length() < 1e-6, "north is −Z");
    }

    #[test]
    fn bird_numbers_are_zero_padded() {
        assert_eq!(bird_digits(14), 3);
        assert_eq!(bird_digits(1000), 3);
        assert_eq!(bird_digits(1001), 4);
    }
}
