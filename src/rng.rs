//! Seeded randomness. Every stochastic function takes `&mut impl rand::Rng`; the pipeline builds
//! one generator per stage from the run's seed with [`stream`], named by a [`Stream`], so that
//! adding draws to one stage does not shift the random numbers of another. ChaCha8 is portable and
//! its stream is stable across platforms and crate versions, which keeps equal seeds
//! byte-identical.

use rand::SeedableRng;

/// The generator used by the pipeline.
pub type FlockRng = rand_chacha::ChaCha8Rng;

/// A generator seeded from `seed`.
pub fn seeded(seed: u64) -> FlockRng {
    FlockRng::seed_from_u64(seed)
}

/// The random stream of each stage of the pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stream {
    /// §4 RANSAC sampling.
    Extract,
    /// §5 steady flight: lateral gaps, ξ̂ draws.
    Steady,
    /// §6 initiation: the random start.
    Initiate,
    /// Wingbeats: per-bird frequencies, amplitudes and initial phases.
    Wingbeat,
    /// Flocks of several formations (skeins): per-formation drift.
    Skein,
    /// §5 steady flight: the slow drift of the lateral gaps from key shape to key shape.
    SteadyLateral,
    /// Steady flight: the birds' small height differences.
    SteadyHeight,
    /// Skeins: how many birds each formation has.
    SkeinSizes,
    /// Skeins: where the formations fly relative to one another.
    SkeinLayout,
    /// Steady flight: each bird's position-keeping motion about its slot.
    SteadyJostle,
    /// Steady flight: leader changes and swaps (when, which birds).
    SteadyEvents,
    /// 3D exports: each bird's size (`render.size_variation`).
    BirdSizes,
    /// 3D exports: which of several bird models each bird wears (`render.bird_model`).
    BirdModels,
}

impl Stream {
    /// The label the stream is derived from. Part of the output contract: renaming one changes
    /// every animation made with that stage.
    pub fn label(self) -> &'static str {
        match self {
            Stream::Extract => "extract",
            Stream::Steady => "steady",
            Stream::Initiate => "initiate",
            Stream::Wingbeat => "wingbeat",
            Stream::Skein => "skein",
            Stream::SteadyLateral => "steady.lateral",
            Stream::SteadyHeight => "steady.height",
            Stream::SkeinSizes => "skein/sizes",
            Stream::SkeinLayout => "skein/layout",
            Stream::SteadyJostle => "steady.jostle",
            Stream::SteadyEvents => "steady.events",
            Stream::BirdSizes => "export.sizes",
            Stream::BirdModels => "export.models",
        }
    }
}

/// What names a stream: a pipeline [`Stream`], or a free label (tests, benches, fixture
/// generators that need a stream of their own).
pub trait StreamLabel {
    /// The bytes hashed into the stream's seed.
    fn label(&self) -> &str;
}

impl StreamLabel for Stream {
    fn label(&self) -> &str {
        Stream::label(*self)
    }
}

impl StreamLabel for &str {
    fn label(&self) -> &str {
        self
    }
}

/// An independent generator for `stage`, derived from the run's seed.
pub fn stream(seed: u64, stage: impl StreamLabel) -> FlockRng {
    // FNV-1a of the label, mixed with the seed.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in stage.label().bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    FlockRng::seed_from_u64(seed ^ h.rotate_left(17))
}

/// The generator of formation `k` of a flock of several formations for `stage` (label
/// `"{stage}/formation/{k}"`): every formation draws its own numbers, so one formation's draws do
/// not shift another's.
pub fn formation_stream(seed: u64, stage: Stream, k: usize) -> FlockRng {
    stream(seed, format!("{}/formation/{k}", stage.label()).as_str())
}

/// The generator of retry `t` (≥ 1) of formation `k` for `stage` (label
/// `"{stage}/formation/{k}/try/{t}"`): a formation whose first draw fails draws afresh without
/// touching any other formation's numbers.
pub fn retry_stream(seed: u64, stage: Stream, k: usize, t: usize) -> FlockRng {
    stream(
        seed,
        format!("{}/formation/{k}/try/{t}", stage.label()).as_str(),
    )
}

/// Whose numbers a stage draws: the run's own (a flock of one formation), formation `k`'s of a
/// flock of several, or retry `t` of formation `k`'s. Every stage of one formation draws from
/// the same scope, so formations of equal size do not share any plan (lateral gaps, their drift,
/// the heights), and a run of one formation draws exactly what it did before flocks of several
/// formations existed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Scope {
    /// The run's streams ([`stream`]).
    #[default]
    Run,
    /// Formation `k`'s streams ([`formation_stream`]).
    Formation(usize),
    /// Retry `t` (≥ 1) of formation `k` ([`retry_stream`]).
    Retry {
        /// The formation.
        formation: usize,
        /// The retry, from 1.
        attempt: usize,
    },
}

impl Scope {
    /// Formation `k`'s first draw (`t` = 0) or its retry `t`.
    pub fn formation(k: usize, t: usize) -> Scope {
        if t == 0 {
            Scope::Formation(k)
        } else {
            Scope::Retry {
                formation: k,
                attempt: t,
            }
        }
    }

    /// The generator of `stage` in this scope.
    pub fn stream(self, seed: u64, stage: Stream) -> FlockRng {
        match self {
            Scope::Run => stream(seed, stage),
            Scope::Formation(k) => formation_stream(seed, stage, k),
            Scope::Retry { formation, attempt } => retry_stream(seed, stage, formation, attempt),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn named_streams_are_the_labelled_ones() {
        for s in [
            Stream::Extract,
            Stream::Steady,
            Stream::Initiate,
            Stream::Wingbeat,
            Stream::Skein,
            Stream::SteadyLateral,
            Stream::SteadyHeight,
            Stream::SkeinSizes,
            Stream::SkeinLayout,
        ] {
            let a: u64 = stream(42, s).random();
            let b: u64 = stream(42, s.label()).random();
            assert_eq!(a, b);
        }
        let e: u64 = stream(42, Stream::Extract).random();
        let s: u64 = stream(42, Stream::Steady).random();
        assert_ne!(e, s);
        let a: u64 = formation_stream(42, Stream::Steady, 0).random();
        let b: u64 = formation_stream(42, Stream::Steady, 1).random();
        assert!(a != b && a != s);
        let r: u64 = retry_stream(42, Stream::Skein, 3, 2).random();
        let l: u64 = stream(42, "skein/formation/3/try/2").random();
        assert_eq!(r, l);
    }

    #[test]
    fn scopes_are_the_derived_streams() {
        let draw = |mut g: FlockRng| -> u64 { g.random() };
        for s in [Stream::SteadyLateral, Stream::SteadyHeight, Stream::Steady] {
            assert_eq!(draw(Scope::Run.stream(9, s)), draw(stream(9, s)));
            assert_eq!(
                draw(Scope::formation(4, 0).stream(9, s)),
                draw(formation_stream(9, s, 4))
            );
            assert_eq!(
                draw(Scope::formation(4, 2).stream(9, s)),
                draw(retry_stream(9, s, 4, 2))
            );
            let all = [
                draw(Scope::Run.stream(9, s)),
                draw(Scope::formation(0, 0).stream(9, s)),
                draw(Scope::formation(1, 0).stream(9, s)),
                draw(Scope::formation(1, 1).stream(9, s)),
            ];
            for i in 0..all.len() {
                for j in i + 1..all.len() {
                    assert_ne!(all[i], all[j], "{s:?}: scopes {i} and {j}");
                }
            }
        }
    }
}
