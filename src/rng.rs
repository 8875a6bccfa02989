//! Seeded randomness. Every stochastic function takes `&mut impl rand::Rng`; the binary builds one
//! [`FlockRng`] from `--seed` with [`seeded`]. ChaCha8 is portable and its stream is stable across
//! platforms and crate versions, which keeps equal seeds byte-identical.

use rand::SeedableRng;

/// The generator used by the command line.
pub type FlockRng = rand_chacha::ChaCha8Rng;

/// A generator seeded from `seed`.
pub fn seeded(seed: u64) -> FlockRng {
    FlockRng::seed_from_u64(seed)
}

/// An independent generator for a sub-stage (so that adding draws to one stage does not shift the
/// random stream of another), derived from the run's seed and a stage label.
pub fn stream(seed: u64, stage: &str) -> FlockRng {
    // FNV-1a of the label, mixed with the seed.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in stage.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    FlockRng::seed_from_u64(seed ^ h.rotate_left(17))
}
