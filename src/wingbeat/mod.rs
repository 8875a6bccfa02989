//! Kinematic flapping after Wu & Popović, "Realistic Modeling of Bird Flight Animations"
//! (SIGGRAPH 2003, §4.1–4.3), cheap enough for a thousand birds.
//!
//! Takes an [`Animation`] (world frame, speeds in wingspans/s, headings clockwise from +y) and gives
//! every bird a wingbeat phase per frame ([`assign_phases`] fills `Frame::wing_phase`, radians in
//! [0, 2π), 0 = start of the downstroke) and a wing pose per frame ([`Flapper::pose`], joint angles
//! in radians, see [`WingPose`]). The pieces:
//! - [`kinematics`]: the composite functions g1/g2, the phase transformation h (downstroke
//!   fractions u_α, u_β), the stroke-midpoint alignment and the blending weight;
//! - [`species`]: goose, crane and pelican presets (frequency, amplitudes, downstroke fraction);
//! - this file: per-bird variation drawn from the animation's seed, one parameter set per
//!   wingbeat (changing only at mid-upstroke and blended over a short window, §4.3), faster and
//!   deeper beats while a bird accelerates, gliding, and phase relations between birds
//!   (independent, or locked to the bird ahead with the spatial phasing of Portugal et al. 2014).
//!
//! Determinism: everything is drawn from `rng::stream(anim.seed, Stream::Wingbeat)`, one generator per
//! bird, consumed one wingbeat at a time. [`Flapper::from_animation`] replays the same decisions
//! from the stored phases, so renderers see exactly the wingbeats [`assign_phases`] produced.

pub mod kinematics;
pub mod rest;
pub mod sparse;
pub mod species;

use std::f64::consts::{PI, TAU};
use std::path::Path;

use rand::{Rng, RngCore, SeedableRng};
use rand_distr::StandardNormal;

use crate::animation::{Animation, Frame};
use crate::error::Result;
use crate::rng::{stream, FlockRng};

pub use crate::animation::wing::{Glide, PhaseMode, Species, WingbeatOptions};
pub use kinematics::{blend_weight, g1, g2, pose, PhaseMap, Stroke, Strokes, Timing};
pub use rest::{FLARE, FOLDED};
pub use species::SpeciesPreset;

/// Joint angles of one wing (both wings mirror each other), radians.
///
/// Bird frame: x to the bird's right (along the right wing), y forward, z up. Angles of the right
/// wing; the left wing is its mirror image in the bird's symmetry plane (same values, mirrored
/// rotation axes). All angles are 0 for a wing stretched straight out sideways, horizontal and
/// untwisted.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WingPose {
    /// Shoulder elevation (dihedral) of the upper arm above the horizontal, up positive.
    pub dihedral: f64,
    /// Elevation of the hand relative to the upper arm (wrist/elbow bend), up positive.
    pub hand_dihedral: f64,
    /// Sweep of the whole wing about the vertical axis, forward positive.
    pub sweep: f64,
    /// Twist (pitch) of the arm about its span axis, leading edge up positive.
    pub arm_twist: f64,
    /// Twist of the hand about its span axis, leading edge up positive.
    pub hand_twist: f64,
    /// Wing spread, 0 = folded, 1 = fully extended.
    pub spread: f64,
    /// Tail bend, up positive.
    pub tail_bend: f64,
    /// Leg swing at the hip from trailing (0, legs along the body behind it, as in cruise)
    /// through straight down (π/2) to folded forward under the body (towards π), radians
    /// (see [`rest::leg_angles`]).
    pub legs: f64,
}

impl WingPose {
    /// A wing held straight out, horizontal and fully spread (the pose used outside the animation).
    pub const EXTENDED: WingPose = WingPose {
        dihedral: 0.0,
        hand_dihedral: 0.0,
        sweep: 0.0,
        arm_twist: 0.0,
        hand_twist: 0.0,
        spread: 1.0,
        tail_bend: 0.0,
        legs: 0.0,
    };
}

/// Per-bird variation: standard deviations (at `variation` = 1) of the amplitude scale, the
/// frequency scale, the dihedral offset (radians) and the downstroke fractions.
const BIRD_AMP_SD: f64 = 0.06;
const BIRD_FREQ_SD: f64 = 0.04;
const BIRD_OFFSET_SD: f64 = 2.0 * PI / 180.0;
const BIRD_FRACTION_SD: f64 = 0.015;
/// Per-wingbeat variation (Ju et al.'s scale / offset / timewarp), standard deviations.
const BEAT_AMP_SD: f64 = 0.04;
const BEAT_FREQ_SD: f64 = 0.015;
const BEAT_OFFSET_SD: f64 = 1.0 * PI / 180.0;
/// Response to the effort e ∈ [−1, 1] (forward acceleration / the species' reference): amplitude
/// ×(1 + 0.3e) and frequency ×(1 + 0.2e) when accelerating, amplitude ×(1 + 0.3e) when slowing.
const ACCEL_AMP_GAIN: f64 = 0.3;
const ACCEL_FREQ_GAIN: f64 = 0.2;
const DECEL_AMP_CUT: f64 = 0.3;
/// Half-width of the window over which the acceleration is measured, seconds.
const ACCEL_WINDOW_S: f64 = 0.25;
/// A bird j is "ahead" of i when it is more than this far ahead along i's heading (wingspans)...
const AHEAD_MIN: f64 = 0.1;
/// ...and at most this far to the side (wingspans).
const AHEAD_MAX_LATERAL: f64 = 3.0;
/// ...and at most this far ahead (wingspans): further ahead, its wake has decayed.
const AHEAD_MAX_ALONG: f64 = 6.0;
/// A bird whose bird ahead is less than this far to the side (wingspans) is directly behind it,
/// in its downwash, and flaps in spatial antiphase (Portugal et al. 2014)...
const ANTIPHASE_ENTER: f64 = 0.4;
/// ...until it is more than this far to the side (hysteresis, so a bird keeping position near
/// the boundary does not switch back and forth).
const ANTIPHASE_LEAVE: f64 = 0.6;
/// Below this ground speed (wingspans/s) the streamwise lag is meaningless and a bird flaps freely.
const LOCK_MIN_SPEED: f64 = 0.5;

/// A standard normal draw clamped to ±2.5 (no outlandish birds).
fn normal(rng: &mut impl Rng) -> f64 {
    let z: f64 = rng.sample(StandardNormal);
    z.clamp(-2.5, 2.5)
}

/// One wingbeat's deviation from its bird's base wingbeat.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Beat {
    /// Amplitude scale of every DOF's excursion.
    amp: f64,
    /// Dihedral offset, radians.
    offset: f64,
    /// Wingbeat frequency, Hz.
    freq: f64,
    /// Held in the glide pose.
    glide: bool,
}

/// Scales a g1 stroke about its mean by `amp` and shifts it by `offset`.
fn scale_g1(s: Stroke, amp: f64, offset: f64) -> Stroke {
    let mean = 0.5 * (s.up + s.down) + offset;
    let half = 0.5 * (s.up - s.down) * amp;
    Stroke::new(mean - half, mean + half)
}

/// Scales a g2 stroke's excursion from its downstroke value by `amp`.
fn scale_g2(s: Stroke, amp: f64) -> Stroke {
    Stroke::new(s.down, s.down + amp * (s.up - s.down))
}

fn scale_strokes(s: &Strokes, amp: f64, offset: f64) -> Strokes {
    let spread = scale_g2(s.spread, amp);
    Strokes {
        dihedral: scale_g1(s.dihedral, amp, offset),
        hand_dihedral: scale_g1(s.hand_dihedral, amp, 0.0),
        tail_bend: scale_g1(s.tail_bend, amp, 0.0),
        sweep: scale_g2(s.sweep, amp),
        arm_twist: scale_g2(s.arm_twist, amp),
        hand_twist: scale_g2(s.hand_twist, amp),
        spread: Stroke::new(spread.down.clamp(0.0, 1.0), spread.up.clamp(0.1, 1.0)),
    }
}

/// A bird's own wingbeat and its wingbeats so far.
#[derive(Debug, Clone)]
struct BirdBeats {
    timing: Timing,
    strokes: Strokes,
    glide: Strokes,
    /// Own cruising frequency, Hz.
    freq: f64,
    /// Initial phase, radians.
    phase0: f64,
    /// Position of wingbeat 0 in the flap-glide cycle.
    bout_offset: i64,
    flap_beats: i64,
    glide_beats: i64,
    /// Index of `beats[0]`.
    first: i64,
    beats: Vec<Beat>,
    /// A looping animation: the wingbeats repeat after this many (whole cycles over the loop).
    period: Option<i64>,
}

impl BirdBeats {
    /// Index of the wingbeat at unwrapped phase `s`: wingbeat n starts its downstroke at 2πn and
    /// runs from the mid-upstroke before it to the mid-upstroke after it (§4.3).
    fn beat_index(&self, s: f64) -> i64 {
        ((s - self.timing.mid_upstroke()) / TAU).floor() as i64 + 1
    }

    fn beat(&self, n: i64) -> Beat {
        let last = self.beats.len().saturating_sub(1) as i64;
        let k = match self.period {
            Some(p) => (n - self.first).rem_euclid(p.max(1)).min(last),
            None => (n - self.first).clamp(0, last),
        } as usize;
        self.beats.get(k).copied().unwrap_or(Beat {
            amp: 1.0,
            offset: 0.0,
            freq: self.freq,
            glide: false,
        })
    }

    /// The two wingbeats and the blend weight at unwrapped phase `s`.
    fn blend(&self, s: f64) -> (Beat, Beat, f64) {
        let n = self.beat_index(s);
        let b = self.timing.blend_half_width();
        let end = TAU * n as f64 + self.timing.mid_upstroke();
        if s >= end - b {
            let w = blend_weight((s - (end - b)) / (2.0 * b));
            (self.beat(n), self.beat(n + 1), w)
        } else if s < end - TAU + b {
            let w = blend_weight((s - (end - TAU - b)) / (2.0 * b));
            (self.beat(n - 1), self.beat(n), w)
        } else {
            let bt = self.beat(n);
            (bt, bt, 0.0)
        }
    }

    fn beat_strokes(&self, beat: &Beat) -> Strokes {
        if beat.glide {
            // A glide is held steady: no per-wingbeat jitter, only the bird's own offset.
            self.glide
        } else {
            scale_strokes(&self.strokes, beat.amp, beat.offset)
        }
    }

    /// Own (unlocked) wingbeat frequency at unwrapped phase `s`, Hz, blended like the strokes.
    fn freq_at(&self, s: f64) -> f64 {
        let (a, b, w) = self.blend(s);
        a.freq + w * (b.freq - a.freq)
    }

    /// Wing pose at unwrapped phase `s`, whose value modulo 2π is `phi`.
    fn pose_at(&self, s: f64, phi: f64) -> WingPose {
        let (a, b, w) = self.blend(s);
        let strokes = if w == 0.0 {
            self.beat_strokes(&a)
        } else {
            Strokes::lerp(&self.beat_strokes(&a), &self.beat_strokes(&b), w)
        };
        pose(&strokes, &self.timing, phi)
    }

    /// Decides every wingbeat that phase `s` touches (including the next one once `s` enters the
    /// blending window before it) from the bird's generator and its current `effort`.
    fn ensure(&mut self, s: f64, effort: f64, rng: &mut FlockRng, glide: Glide, variation: f64) {
        let b = self.timing.blend_half_width();
        let lo = self.beat_index(s - b);
        let hi = self.beat_index(s + b);
        let start = if self.beats.is_empty() {
            self.first = lo;
            lo
        } else {
            self.first + self.beats.len() as i64
        };
        // At most 2π of phase passes per frame, so only a few wingbeats can be new; the cap guards
        // against absurd stored phases.
        let stop = hi.min(start + 4);
        let stop = match self.period {
            Some(p) => stop.min(self.first + p - 1),
            None => stop,
        };
        for n in start..=stop {
            let beat = self.decide(n, effort, rng, glide, variation);
            self.beats.push(beat);
        }
    }

    fn decide(
        &self,
        n: i64,
        effort: f64,
        rng: &mut FlockRng,
        glide: Glide,
        variation: f64,
    ) -> Beat {
        let (z1, z2, z3) = (normal(rng), normal(rng), normal(rng));
        let e = effort.clamp(-1.0, 1.0);
        let (acc, dec) = (e.max(0.0), (-e).max(0.0));
        let amp = (1.0 + variation * BEAT_AMP_SD * z1)
            * (1.0 + ACCEL_AMP_GAIN * acc)
            * (1.0 - DECEL_AMP_CUT * dec);
        let freq =
            self.freq * (1.0 + variation * BEAT_FREQ_SD * z2) * (1.0 + ACCEL_FREQ_GAIN * acc);
        let offset = variation * BEAT_OFFSET_SD * z3;
        let glide = match glide {
            Glide::Off => false,
            Glide::Always => true,
            Glide::Bouts => {
                let cycle = (self.flap_beats + self.glide_beats).max(1);
                (n + self.bout_offset).rem_euclid(cycle) >= self.flap_beats || e < -0.5
            }
        };
        Beat {
            amp,
            offset,
            freq,
            glide,
        }
    }
}

/// Draws every bird's own wingbeat from the seed; returns the birds and their generators.
fn draw_birds(seed: u64, birds: usize, opts: &WingbeatOptions) -> (Vec<BirdBeats>, Vec<FlockRng>) {
    let preset = opts.species.preset();
    let v = opts.variation;
    let mut master = stream(seed, crate::rng::Stream::Wingbeat);
    let cycle = i64::from(preset.flap_beats + preset.glide_beats).max(1);
    let mut out = Vec::with_capacity(birds);
    let mut rngs = Vec::with_capacity(birds);
    for _ in 0..birds {
        let mut r = FlockRng::seed_from_u64(master.next_u64());
        let (za, zf, zo, zu) = (
            normal(&mut r),
            normal(&mut r),
            normal(&mut r),
            normal(&mut r),
        );
        let phase0 = r.random::<f64>() * TAU;
        let bout = r.random_range(0..cycle);
        let mut timing = preset.timing;
        timing.u_alpha = (timing.u_alpha + v * BIRD_FRACTION_SD * zu).clamp(0.3, 0.7);
        timing.u_beta = (timing.u_beta + v * BIRD_FRACTION_SD * zu).clamp(0.3, 0.7);
        let amp = 1.0 + v * BIRD_AMP_SD * za;
        let offset = v * BIRD_OFFSET_SD * zo;
        out.push(BirdBeats {
            timing,
            strokes: scale_strokes(&preset.strokes, amp, offset),
            glide: {
                let mut g = preset.glide_strokes();
                g.dihedral = Stroke::hold(preset.glide_dihedral + offset);
                g
            },
            freq: preset.frequency_hz * (1.0 + v * BIRD_FREQ_SD * zf),
            phase0,
            bout_offset: match opts.phase_mode {
                PhaseMode::Independent => bout,
                // Locked birds share the bout clock, so glides travel down the line with the
                // phase lag.
                PhaseMode::Locked => 0,
            },
            flap_beats: i64::from(preset.flap_beats),
            glide_beats: i64::from(preset.glide_beats),
            first: 0,
            beats: Vec::new(),
            period: None,
        });
        rngs.push(r);
    }
    (out, rngs)
}

/// Effort of every bird at frame `k`, into `out` (one value a bird): forward acceleration
/// (m/s², from the speed change over ±0.25 s) over the species' reference, clamped into
/// [−1, 1]; 0 where the frames give no time step. One frame at a time, so no table of the whole
/// animation is held.
fn efforts_at(anim: &Animation, preset: &SpeciesPreset, k: usize, out: &mut Vec<f64>) {
    let n = anim.birds;
    let nf = anim.frames.len();
    let half = ((ACCEL_WINDOW_S * anim.fps).round() as usize).max(1);
    out.clear();
    out.resize(n, 0.0);
    let kp = k.saturating_sub(half);
    let kn = (k + half).min(nf.saturating_sub(1));
    let (Some(fp), Some(fnx)) = (anim.frames.get(kp), anim.frames.get(kn)) else {
        return;
    };
    let dt = fnx.t - fp.t;
    if dt.is_nan() || dt <= 1e-9 {
        return;
    }
    for (i, o) in out.iter_mut().enumerate() {
        let v0 = fp.speed.get(i).copied().unwrap_or(0.0);
        let v1 = fnx.speed.get(i).copied().unwrap_or(0.0);
        let accel = (v1 - v0) / dt * anim.wingspan_m;
        let e = (accel / preset.accel_ref_mps2).clamp(-1.0, 1.0);
        *o = if e.is_finite() { e } else { 0.0 };
    }
}

/// The bird ahead of bird `i` in `frame` and the streamwise distance to it (wingspans, along
/// bird i's heading): among birds between 0.1 and 6 wingspans ahead and at most 3 wingspans to the
/// side, the nearest one (ties: the lower index). `None` for a leader (or a bird index out of
/// range). O(n); [`AheadIndex`] answers the same question for a whole frame in O(n).
pub fn bird_ahead(frame: &Frame, i: usize) -> Option<(usize, f64)> {
    ahead_among(frame, i, 0..frame.x.len()).map(|(j, along, _)| (j, along))
}

/// [`bird_ahead`] restricted to the candidates `js`, with the bird ahead's distance to the side
/// (wingspans, ≥ 0).
fn ahead_among(
    frame: &Frame,
    i: usize,
    js: impl IntoIterator<Item = usize>,
) -> Option<(usize, f64, f64)> {
    let (xi, yi, hd) = (*frame.x.get(i)?, *frame.y.get(i)?, *frame.heading.get(i)?);
    let (fx, fy) = (hd.sin(), hd.cos());
    let mut best: Option<(usize, f64, f64, f64)> = None;
    for j in js {
        let (Some(&xj), Some(&yj)) = (frame.x.get(j), frame.y.get(j)) else {
            continue;
        };
        if j == i {
            continue;
        }
        let (dx, dy) = (xj - xi, yj - yi);
        let along = dx * fx + dy * fy;
        let lateral = (dx * fy - dy * fx).abs();
        if along > AHEAD_MIN && along < AHEAD_MAX_ALONG && lateral < AHEAD_MAX_LATERAL {
            let d2 = along * along + lateral * lateral;
            let better = match best {
                None => true,
                Some((bj, _, _, bd)) => d2 < bd || (d2 == bd && j < bj),
            };
            if better {
                best = Some((j, along, lateral, d2));
            }
        }
    }
    best.map(|(j, along, lateral, _)| (j, along, lateral))
}

/// A uniform grid over one frame's positions (cells of 6.75 wingspans) that finds every bird's
/// [`bird_ahead`] by looking only at nearby cells: O(n) per frame for a spread-out flock instead of
/// O(n²).
#[derive(Debug, Clone)]
pub struct AheadIndex {
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

impl AheadIndex {
    /// Cell size, wingspans: the farthest a bird ahead can be (√(6² + 3²) ≈ 6.71), so only the 3×3
    /// cells around a bird hold candidates.
    const CELL: f64 = 6.75;
    /// Below this many birds a plain scan is faster than hashing.
    const SCAN_BELOW: usize = 64;

    fn key(x: f64, y: f64) -> (i64, i64) {
        (
            (x / Self::CELL).floor() as i64,
            (y / Self::CELL).floor() as i64,
        )
    }

    /// Indexes the birds of `frame`.
    pub fn new(frame: &Frame) -> AheadIndex {
        let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> =
            std::collections::HashMap::new();
        if frame.x.len() < Self::SCAN_BELOW {
            return AheadIndex { cells };
        }
        for (j, (&x, &y)) in frame.x.iter().zip(frame.y.iter()).enumerate() {
            cells.entry(Self::key(x, y)).or_default().push(j);
        }
        AheadIndex { cells }
    }

    /// Same answer as [`bird_ahead`]`(frame, i)`; `frame` must be the indexed frame.
    pub fn ahead(&self, frame: &Frame, i: usize) -> Option<(usize, f64)> {
        self.ahead_aside(frame, i).map(|(j, along, _)| (j, along))
    }

    /// [`AheadIndex::ahead`] with the bird ahead's distance to the side (wingspans, ≥ 0).
    pub fn ahead_aside(&self, frame: &Frame, i: usize) -> Option<(usize, f64, f64)> {
        if frame.x.len() < Self::SCAN_BELOW {
            return ahead_among(frame, i, 0..frame.x.len());
        }
        let (xi, yi) = (*frame.x.get(i)?, *frame.y.get(i)?);
        let (cx, cy) = Self::key(xi, yi);
        let reach = 1;
        let cand = (-reach..=reach)
            .flat_map(|ox| (-reach..=reach).map(move |oy| (cx + ox, cy + oy)))
            .filter_map(|k| self.cells.get(&k))
            .flatten()
            .copied();
        ahead_among(frame, i, cand)
    }
}

/// Wraps an angle into (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// Everything the wingbeat stage derives for an animation.
struct Run {
    birds: Vec<BirdBeats>,
    /// Wrapped phase per frame and bird (frame-major), radians in [0, 2π).
    phase: Vec<f64>,
    /// Unwrapped phase per frame and bird (frame-major), radians.
    unwrapped: Vec<f64>,
    /// Fold weight per frame and bird (frame-major; empty: never at rest), see [`rest`].
    fold: sparse::FrameTable<f64>,
}

/// Integrates every bird's phase through the animation (what [`assign_phases`] stores). The
/// unwrapped phases are kept only when `unwrapped` is asked for (the renderers' wingbeats; a
/// looping animation computes them anyway): [`assign_phases`] stores only the wrapped ones.
fn simulate(anim: &Animation, opts: &WingbeatOptions, keep_unwrapped: bool) -> Run {
    let n = anim.birds;
    let nf = anim.frames.len();
    let preset = opts.species.preset();
    let mut eff = Vec::with_capacity(n);
    let fold = rest::fold_weights(anim);
    let (mut birds, mut rngs) = draw_birds(anim.seed, n, opts);
    let mut phi: Vec<f64> = birds.iter().map(|b| b.phase0).collect();
    let mut cycles = vec![0u64; n];
    let mut own = vec![0.0; n];
    let mut rate = vec![0.0; n];
    let mut last_rate = vec![0.0; n];
    let mut anti = vec![false; n];
    let mut phase = vec![0.0; n * nf];
    let keep_unwrapped = keep_unwrapped || (anim.looped && nf > 1);
    let mut unwrapped = if keep_unwrapped {
        vec![0.0; n * nf]
    } else {
        Vec::new()
    };
    for k in 0..nf {
        efforts_at(anim, &preset, k, &mut eff);
        for i in 0..n {
            let s = TAU * cycles[i] as f64 + phi[i];
            phase[k * n + i] = phi[i];
            if keep_unwrapped {
                unwrapped[k * n + i] = s;
            }
            birds[i].ensure(s, eff[i], &mut rngs[i], opts.glide, opts.variation);
            own[i] = birds[i].freq_at(s);
        }
        if k == 0 {
            last_rate.copy_from_slice(&own);
        }
        let (Some(frame), Some(next)) = (anim.frames.get(k), anim.frames.get(k + 1)) else {
            break;
        };
        let dt = (next.t - frame.t).max(0.0);
        let index = match opts.phase_mode {
            PhaseMode::Locked => Some(AheadIndex::new(frame)),
            PhaseMode::Independent => None,
        };
        for i in 0..n {
            rate[i] = match &index {
                None => own[i],
                Some(index) => {
                    let ahead = index.ahead_aside(frame, i);
                    anti[i] = match ahead {
                        Some((_, _, aside)) if anti[i] => aside < ANTIPHASE_LEAVE,
                        Some((_, _, aside)) => aside < ANTIPHASE_ENTER,
                        None => false,
                    };
                    let ahead = ahead.map(|(j, along, _)| (j, along));
                    let lock = Lock {
                        tau: opts.lock_time_s,
                        antiphase: anti[i],
                    };
                    locked_rate(frame, i, ahead, &phi, &last_rate, own[i], lock)
                }
            };
        }
        if !fold.is_empty() {
            // A bird at rest holds its phase (no wingbeat below the rest speed; the wings fold
            // from the pose they stopped in).
            for (i, r) in rate.iter_mut().enumerate() {
                if fold.get(k * n + i).unwrap_or(0.0) >= 1.0 || rest::at_rest(anim, k, i) {
                    *r = 0.0;
                }
            }
        }
        for i in 0..n {
            let step = (TAU * rate[i] * dt).clamp(0.0, PI);
            let mut p = phi[i] + step;
            if p >= TAU {
                p -= TAU;
                cycles[i] += 1;
            }
            phi[i] = p.clamp(0.0, TAU - f64::EPSILON * TAU);
            last_rate[i] = rate[i];
        }
    }
    if anim.looped && nf > 1 {
        // A whole number of cycles over the loop: every bird's phase advance, including the
        // step from the last frame back to the first, is scaled to the nearest multiple of 2π,
        // and the wingbeats are replayed so that they repeat with the loop.
        let dt = 1.0 / anim.fps;
        for i in 0..n {
            let s0 = unwrapped[i];
            let advance = unwrapped[(nf - 1) * n + i] - s0 + (TAU * own[i] * dt).clamp(0.0, PI);
            let m = (advance / TAU).round().max(1.0);
            let f = if advance > 0.0 {
                TAU * m / advance
            } else {
                1.0
            };
            for k in 0..nf {
                let s = s0 + (unwrapped[k * n + i] - s0) * f;
                unwrapped[k * n + i] = s;
                phase[k * n + i] = s.rem_euclid(TAU).min(TAU - f64::EPSILON * TAU);
            }
        }
        return replay_phases(anim, opts, |k, i| phase[k * n + i]);
    }
    Run {
        birds,
        phase,
        unwrapped,
        fold,
    }
}

/// How a follower locks to the bird ahead.
#[derive(Debug, Clone, Copy)]
struct Lock {
    /// Time constant of the lock, seconds.
    tau: f64,
    /// Directly behind the bird ahead: spatial antiphase (π added to the target).
    antiphase: bool,
}

/// Phase-locked frequency of bird `i` (Hz): the bird ahead's frequency plus a correction that
/// pulls the phase towards the spatial-phasing target φ_ahead − 2π f Δy / U (plus π directly
/// behind it: spatial antiphase), with U the bird's own speed.
fn locked_rate(
    frame: &Frame,
    i: usize,
    ahead: Option<(usize, f64)>,
    phi: &[f64],
    last_rate: &[f64],
    own: f64,
    lock: Lock,
) -> f64 {
    let tau = lock.tau;
    let speed = frame.speed.get(i).copied().unwrap_or(0.0);
    let Some((j, dy)) = ahead else {
        return own;
    };
    let (Some(&pj), Some(&fj), Some(&pi)) = (phi.get(j), last_rate.get(j), phi.get(i)) else {
        return own;
    };
    if speed.is_nan() || speed < LOCK_MIN_SPEED {
        return own;
    }
    let target = pj - TAU * fj * dy / speed + if lock.antiphase { PI } else { 0.0 };
    let err = wrap_pi(target - pi);
    (fj + err / (TAU * tau)).clamp(0.5 * own, 1.5 * own)
}

/// Rebuilds the wingbeat decisions from phases stored in the animation (what the renderers see).
fn replay(anim: &Animation, opts: &WingbeatOptions) -> Run {
    replay_phases(anim, opts, |k, i| {
        anim.frames[k]
            .wing_phase
            .as_deref()
            .and_then(|p| p.get(i))
            .copied()
            .unwrap_or(0.0)
    })
}

/// [`replay`] of the phases `stored(frame, bird)`; a looping animation's wingbeats repeat with
/// its whole cycles (counted from the phases, the wrap step included).
fn replay_phases(
    anim: &Animation,
    opts: &WingbeatOptions,
    stored: impl Fn(usize, usize) -> f64,
) -> Run {
    let n = anim.birds;
    let nf = anim.frames.len();
    let preset = opts.species.preset();
    let mut eff = Vec::with_capacity(n);
    let (mut birds, mut rngs) = draw_birds(anim.seed, n, opts);
    let wrapped = |k: usize, i: usize| {
        let raw = stored(k, i);
        if raw.is_finite() {
            raw.rem_euclid(TAU)
        } else {
            0.0
        }
    };
    if anim.looped && nf > 1 {
        for (i, b) in birds.iter_mut().enumerate() {
            let wraps = (1..nf)
                .filter(|&k| wrapped(k, i) < wrapped(k - 1, i))
                .count() as i64;
            let closing = i64::from(wrapped(0, i) <= wrapped(nf - 1, i));
            b.period = Some((wraps + closing).max(1));
        }
    }
    let mut cycles = vec![0u64; n];
    let mut prev = vec![0.0; n];
    let mut phase = vec![0.0; n * nf];
    let mut unwrapped = vec![0.0; n * nf];
    for k in 0..nf {
        efforts_at(anim, &preset, k, &mut eff);
        for i in 0..n {
            let p = wrapped(k, i);
            if k > 0 && p < prev[i] {
                cycles[i] += 1;
            }
            prev[i] = p;
            let s = TAU * cycles[i] as f64 + p;
            phase[k * n + i] = p;
            unwrapped[k * n + i] = s;
            birds[i].ensure(s, eff[i], &mut rngs[i], opts.glide, opts.variation);
        }
    }
    Run {
        birds,
        phase,
        unwrapped,
        fold: rest::fold_weights(anim),
    }
}

/// Fills `Frame::wing_phase` of every frame (radians in [0, 2π), 0 = start of the downstroke) and
/// records the species and options in the animation (`species`, `wingbeat`), so that
/// [`Flapper::from_animation`] rebuilds the same wingbeats. Seeded from `anim.seed`: equal seeds,
/// inputs and options give equal phases.
///
/// Phase integration per bird, from frame k to k + 1 (Δt = t_{k+1} − t_k):
/// ```math
/// \varphi_{k+1} = \varphi_k + 2\pi f_k \Delta t, \qquad
/// f_k = \begin{cases} f^{\text{own}}_k & \text{independent, or no bird ahead}\\
///   f_{j} + \dfrac{\operatorname{wrap}(\varphi_j - 2\pi f_j \Delta y / U - \varphi_k)}{2\pi\tau}
///   & \text{locked to bird } j \text{ ahead} \end{cases}
/// ```
/// with f^own the bird's blended wingbeat frequency, Δy the streamwise distance to the bird ahead
/// (wingspans), U the bird's speed (wingspans/s) and τ = `lock_time_s` (Portugal et al. 2014).
pub fn assign_phases(anim: &mut Animation, opts: &WingbeatOptions) -> Result<()> {
    opts.validate()?;
    anim.validate(Path::new("<animation>"))?;
    let run = simulate(anim, opts, false);
    let n = anim.birds;
    drop(run.birds);
    drop(run.fold);
    // The simulation's scratch, freed, would otherwise stay with the process while the rows are
    // made and the outputs written.
    crate::memory::release_free();
    // Frame by frame from the last, each row moved out and the table shrunk behind it, so the
    // phases are never held twice.
    let mut phase = run.phase;
    for (k, frame) in anim.frames.iter_mut().enumerate().rev() {
        let row = phase.split_off((k * n).min(phase.len()));
        phase.shrink_to_fit();
        frame.wing_phase = Some(row);
    }
    // A real species the animation already names keeps its name when its family flaps.
    let real = anim
        .species
        .as_deref()
        .and_then(crate::animation::species::lookup)
        .filter(|b| b.family == opts.species.name());
    anim.species = Some(real.map_or(opts.species.name(), |b| b.name).to_string());
    anim.wingbeat = Some(opts.clone());
    Ok(())
}

/// Per-bird wingbeats of a whole animation.
#[derive(Debug, Clone)]
pub struct Flapper {
    birds: Vec<BirdBeats>,
    /// Wrapped phase per frame and bird (frame-major).
    phase: Vec<f64>,
    /// Unwrapped phase per frame and bird (frame-major).
    unwrapped: Vec<f64>,
    /// Fold weight per frame and bird (frame-major; empty: never at rest). Like the tables
    /// below, kept only for the frames where some bird is not at its usual value (0 here), so a
    /// long flight costs a few bytes a frame.
    fold: sparse::FrameTable<f64>,
    /// Flare weight per frame and bird (frame-major; empty: no landing).
    flare: sparse::FrameTable<f64>,
    /// Root height and bank per frame and bird (frame-major) of a flight that starts on the
    /// ground (empty otherwise): the downstroke is kept off the ground. Kept for the frames
    /// within one of a frame where some bird is less than a wingspan up (others read as
    /// infinitely high and level, which no use tells apart).
    ground: sparse::FrameTable<(f64, f64)>,
    /// Leg swing per frame and bird (frame-major; empty: the legs trail throughout).
    legs: sparse::FrameTable<f64>,
    nbirds: usize,
    nframes: usize,
}

impl Flapper {
    /// Rebuilds the wingbeats of `anim`: from its stored `wing_phase` (as written by
    /// [`assign_phases`]) when every frame has one, otherwise by computing the phases with the
    /// options recorded in the file (or the defaults for its species). Never fails; a malformed
    /// animation gives neutral poses where data is missing.
    pub fn from_animation(anim: &Animation) -> Flapper {
        Flapper::with_options(anim, &WingbeatOptions::for_animation(anim))
    }

    /// Like [`Flapper::from_animation`] with explicit options (which must be those the phases were
    /// assigned with for the per-wingbeat variation to match).
    pub fn with_options(anim: &Animation, opts: &WingbeatOptions) -> Flapper {
        let n = anim.birds;
        let stored = !anim.frames.is_empty()
            && anim
                .frames
                .iter()
                .all(|f| f.wing_phase.as_ref().is_some_and(|p| p.len() == n));
        let run = if stored {
            replay(anim, opts)
        } else {
            simulate(anim, opts, true)
        };
        let frames = &anim.frames;
        let ground = if run.fold.is_empty() {
            sparse::FrameTable::default()
        } else {
            let low: Vec<bool> = frames
                .iter()
                .map(|f| (0..n).any(|i| f.z.get(i).copied().unwrap_or(f64::INFINITY) < 1.0))
                .collect();
            let near = |k: usize| {
                low[k.saturating_sub(1)..(k + 2).min(low.len())]
                    .iter()
                    .any(|&l| l)
            };
            sparse::FrameTable::from_fn(frames.len(), n, (f64::INFINITY, 0.0), near, |k, i| {
                let f = &frames[k];
                let z = f.z.get(i).copied().unwrap_or(f64::INFINITY);
                let bank = f.bank.as_ref().and_then(|b| b.get(i)).copied();
                (z, bank.unwrap_or(0.0))
            })
        };
        let table = |v: Vec<f64>| sparse::FrameTable::from_dense(&v, n, 0.0);
        Flapper {
            birds: run.birds,
            phase: run.phase,
            unwrapped: run.unwrapped,
            ground,
            fold: run.fold,
            flare: table(rest::flare_weights(anim)),
            legs: table(rest::leg_angles(anim, opts.species)),
            nbirds: n,
            nframes: anim.frames.len(),
        }
    }

    /// Number of birds.
    pub fn birds(&self) -> usize {
        self.nbirds
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.nframes
    }

    /// Wingbeat phase of `bird` at `frame`, radians in [0, 2π), 0 = start of the downstroke
    /// (0 outside the animation).
    pub fn phase(&self, frame: usize, bird: usize) -> f64 {
        self.index(frame, bird)
            .and_then(|k| self.phase.get(k))
            .copied()
            .unwrap_or(0.0)
    }

    fn index(&self, frame: usize, bird: usize) -> Option<usize> {
        (frame < self.nframes && bird < self.nbirds).then(|| frame * self.nbirds + bird)
    }

    /// Pose of `bird` at `frame` ([`WingPose::EXTENDED`] outside the animation).
    pub fn pose(&self, frame: usize, bird: usize) -> WingPose {
        let (Some(k), Some(b)) = (self.index(frame, bird), self.birds.get(bird)) else {
            return WingPose::EXTENDED;
        };
        let p = match (self.unwrapped.get(k), self.phase.get(k)) {
            (Some(&s), Some(&phi)) => b.pose_at(s, phi),
            _ => return WingPose::EXTENDED,
        };
        let p = self.flared(p, self.flare.get(k).unwrap_or(0.0));
        let mut p = self.folded(p, self.fold.get(k).unwrap_or(0.0));
        p.legs = self.legs.get(k).unwrap_or(0.0);
        match self.ground.get(k) {
            Some((z, bank)) if z < 1.0 => rest::clear_ground(p, z, bank),
            _ => p,
        }
    }

    /// `p` held towards the flare pose by weight `w` (1: [`rest::FLARE`]).
    fn flared(&self, p: WingPose, w: f64) -> WingPose {
        if w > 0.0 {
            p.lerp(&rest::FLARE, w.min(1.0))
        } else {
            p
        }
    }

    /// `p` folded by weight `w` (1: the resting pose).
    fn folded(&self, p: WingPose, w: f64) -> WingPose {
        if w >= 1.0 {
            FOLDED
        } else if w > 0.0 {
            p.lerp(&FOLDED, w)
        } else {
            p
        }
    }

    /// Fold weight of `bird` at `frame`: 1 at rest on the ground (wings folded, no wingbeat), 0
    /// in the wingbeat, between while the wings unfold or fold (see [`rest`]).
    pub fn fold(&self, frame: usize, bird: usize) -> f64 {
        self.index(frame, bird)
            .and_then(|k| self.fold.get(k))
            .unwrap_or(0.0)
    }

    /// Poses of every bird at `frame`, written into `out` (cleared first).
    pub fn poses_into(&self, frame: usize, out: &mut Vec<WingPose>) {
        out.clear();
        out.extend((0..self.nbirds).map(|i| self.pose(frame, i)));
    }

    /// Pose of `bird` at a fractional frame position (linear interpolation of the unwrapped
    /// phase between frames), for renderers that sample between frames (e.g. glTF keyframes).
    pub fn pose_at(&self, frame: f64, bird: usize) -> WingPose {
        if !(frame.is_finite() && frame >= 0.0) || self.nframes == 0 {
            return self.pose(0, bird);
        }
        let k = (frame.floor() as usize).min(self.nframes - 1);
        let w = (frame - k as f64).clamp(0.0, 1.0);
        let (Some(a), Some(b)) = (self.index(k, bird), self.birds.get(bird)) else {
            return WingPose::EXTENDED;
        };
        let s0 = self.unwrapped.get(a).copied().unwrap_or(0.0);
        let s1 = self
            .index(k + 1, bird)
            .and_then(|i| self.unwrapped.get(i))
            .copied()
            .unwrap_or(s0);
        let s = s0 + w * (s1 - s0);
        let f0 = self.fold.get(a).unwrap_or(0.0);
        let f1 = self
            .index(k + 1, bird)
            .and_then(|i| self.fold.get(i))
            .unwrap_or(f0);
        let q0 = self.flare.get(a).unwrap_or(0.0);
        let q1 = self
            .index(k + 1, bird)
            .and_then(|i| self.flare.get(i))
            .unwrap_or(q0);
        let l0 = self.legs.get(a).unwrap_or(0.0);
        let l1 = self
            .index(k + 1, bird)
            .and_then(|i| self.legs.get(i))
            .unwrap_or(l0);
        let p = self.flared(b.pose_at(s, s.rem_euclid(TAU)), q0 + w * (q1 - q0));
        let mut p = self.folded(p, f0 + w * (f1 - f0));
        p.legs = l0 + w * (l1 - l0);
        let g0 = self.ground.get(a);
        let g1 = self.index(k + 1, bird).and_then(|i| self.ground.get(i));
        match (g0, g1.or(g0)) {
            (Some((z0, b0)), Some((z1, b1))) if z0.min(z1) < 1.0 => {
                rest::clear_ground(p, z0.min(z1), b0.abs().max(b1.abs()))
            }
            _ => p,
        }
    }
}

/// One wingbeat of the average bird of `species`: `samples` poses at phases 0..2π (inclusive).
pub fn wingbeat_curve(species: Species, samples: usize) -> Vec<(f64, WingPose)> {
    let preset = species.preset();
    let m = samples.max(2);
    (0..m)
        .map(|k| {
            let phi = TAU * k as f64 / (m - 1) as f64;
            (phi, pose(&preset.strokes, &preset.timing, phi))
        })
        .collect()
}

#[doc(hidden)]
/// Unwrapped phase and own-frequency access for tests of the blending (not a stable API).
pub mod probe {
    use super::*;

    /// The pose and own frequency of a synthetic bird with the given wingbeats at unwrapped
    /// phase `s`: wingbeat n (n = 0, 1, ...) has amplitude `amps[n]` and frequency `freqs[n]`.
    pub fn blended(species: Species, amps: &[f64], freqs: &[f64], s: f64) -> (WingPose, f64) {
        let preset = species.preset();
        let b = BirdBeats {
            timing: preset.timing,
            strokes: preset.strokes,
            glide: preset.glide_strokes(),
            freq: preset.frequency_hz,
            phase0: 0.0,
            bout_offset: 0,
            flap_beats: 1,
            glide_beats: 0,
            first: 0,
            beats: amps
                .iter()
                .zip(freqs)
                .map(|(&amp, &freq)| Beat {
                    amp,
                    offset: 0.0,
                    freq,
                    glide: false,
                })
                .collect(),
            period: None,
        };
        (b.pose_at(s, s.rem_euclid(TAU)), b.freq_at(s))
    }

    /// Unwrapped phases of every bird at every frame (frame-major) as the renderers see them.
    pub fn unwrapped(f: &Flapper) -> &[f64] {
        &f.unwrapped
    }
}
