//! How many formations a flock of N birds flies as, and how many birds each has.
//!
//! The footage shows one formation of N̂ birds (the params file's `birds`). By default a flock of
//! N ≤ 2N̂ birds is one formation (the README's 14 geese from a 9-goose movie are one V) and a
//! larger one flies as K = round(N / N̂) formations; `formation_size` M replaces N̂ (then
//! K = round(N / M), at least 1) and `formations` gives K itself.
//!
//! Sizes: weights w_k = 2^{u_k} with u_k uniform in [−0.75, 0.75] (so between about 0.6 and 1.7
//! times the mean m = N / K), sizes proportional to them rounded to whole birds by the largest
//! remainder (ties: the lower index), then moved one bird at a time into
//! [max(3, ⌈m/2⌉), max(lo, ⌊2m⌋)]: between half and twice the mean, never a formation of one or
//! two birds unless the flock is too small for threes (m < 3, then at least 2).

use rand::Rng;

use crate::error::{Error, Result};
use crate::limits::MAX_FORMATION_BIRDS;

/// Largest |log₂| of a formation's weight: sizes between 2^−0.75 ≈ 0.6 and 2^0.75 ≈ 1.7 times the
/// mean before the bounds.
pub const SIZE_SPREAD_LOG2: f64 = 0.75;

/// The number of formations of `n` birds: `formations`, or round(n / `formation_size`), or by
/// default one formation up to 2 `n_hat` birds and round(n / `n_hat`) beyond; at most n / 2 (a
/// formation has at least 2 birds).
pub fn formation_count(
    n: usize,
    n_hat: usize,
    formations: Option<usize>,
    formation_size: Option<usize>,
) -> usize {
    let n_hat = n_hat.max(2);
    let k = match (formations, formation_size) {
        (Some(k), _) => k,
        (None, Some(m)) => ((n as f64 / m.max(1) as f64).round() as usize).max(1),
        (None, None) if n <= 2 * n_hat => 1,
        (None, None) => (n as f64 / n_hat as f64).round() as usize,
    };
    k.clamp(1, (n / 2).max(1))
}

/// Smallest and largest formation size for `n` birds in `k` formations (see the module doc).
pub fn size_bounds(n: usize, k: usize) -> (usize, usize) {
    let m = n as f64 / k.max(1) as f64;
    let lo = if m >= 3.0 {
        3usize.max((m / 2.0).ceil() as usize)
    } else {
        2
    };
    (lo, lo.max((2.0 * m).floor() as usize))
}

/// Sizes of `k` formations of `n` birds, drawn from `rng` (see the module doc); they sum to `n`.
/// `k` = 1 gives `[n]` without drawing.
pub fn formation_sizes(n: usize, k: usize, rng: &mut impl Rng) -> Result<Vec<usize>> {
    if k <= 1 {
        return Ok(vec![n]);
    }
    if 2 * k > n {
        return Err(Error::parameter(
            "skein.formations",
            format!(
                "{k} formations of {n} birds: a formation needs at least 2 birds, so at most {}",
                n / 2
            ),
        ));
    }
    let (lo, hi) = size_bounds(n, k);
    if hi > MAX_FORMATION_BIRDS {
        return Err(Error::parameter(
            "skein.formations",
            format!("{k} formations of {n} birds have up to {hi} birds each; at most {MAX_FORMATION_BIRDS} birds fly as one formation: give more formations"),
        ));
    }
    let w: Vec<f64> = (0..k)
        .map(|_| 2f64.powf(rng.random_range(-SIZE_SPREAD_LOG2..=SIZE_SPREAD_LOG2)))
        .collect();
    let total: f64 = w.iter().sum();
    let exact: Vec<f64> = w.iter().map(|v| n as f64 * v / total).collect();
    let mut sizes: Vec<usize> = exact.iter().map(|v| v.floor() as usize).collect();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| {
        let fa = exact[a] - exact[a].floor();
        let fb = exact[b] - exact[b].floor();
        fb.total_cmp(&fa).then(a.cmp(&b))
    });
    let short = n - sizes.iter().sum::<usize>();
    for &i in order.iter().cycle().take(short) {
        sizes[i] += 1;
    }
    // Into the bounds, one bird at a time: the mean lies inside them, so this ends.
    loop {
        let (imin, &smin) = sizes
            .iter()
            .enumerate()
            .min_by_key(|&(i, s)| (*s, i))
            .expect("k ≥ 2");
        let (imax, &smax) = sizes
            .iter()
            .enumerate()
            .max_by_key(|&(i, s)| (*s, std::cmp::Reverse(i)))
            .expect("k ≥ 2");
        if smin >= lo && smax <= hi {
            break;
        }
        sizes[imin] += 1;
        sizes[imax] -= 1;
    }
    Ok(sizes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_the_footage() {
        assert_eq!(formation_count(14, 9, None, None), 1);
        assert_eq!(formation_count(18, 9, None, None), 1);
        assert_eq!(formation_count(19, 9, None, None), 2);
        assert_eq!(formation_count(1000, 9, None, None), 111);
        assert_eq!(formation_count(1000, 9, Some(1), None), 1);
        assert_eq!(formation_count(1000, 9, None, Some(20)), 50);
        assert_eq!(formation_count(5, 9, None, Some(2)), 2);
        assert_eq!(formation_count(10, 9, None, Some(100)), 1);
    }

    #[test]
    fn sizes_sum_to_the_flock_and_stay_in_bounds_for_many_seeds() {
        for seed in 0..50 {
            for &(n, k) in &[
                (1000, 111),
                (19, 2),
                (200, 22),
                (10, 5),
                (7, 3),
                (10_000, 1111),
            ] {
                let mut rng = crate::rng::seeded(seed);
                let s = formation_sizes(n, k, &mut rng).unwrap();
                let (lo, hi) = size_bounds(n, k);
                assert_eq!(s.len(), k);
                assert_eq!(s.iter().sum::<usize>(), n);
                assert!(s.iter().all(|&v| v >= lo && v <= hi), "{n} {k} {s:?}");
                if n / k >= 3 {
                    assert!(s.iter().all(|&v| v >= 3));
                }
            }
        }
        let mut rng = crate::rng::seeded(1);
        let s = formation_sizes(1000, 111, &mut rng).unwrap();
        assert!(s.iter().min() != s.iter().max(), "sizes vary: {s:?}");
        assert!(formation_sizes(10, 6, &mut rng).is_err());
    }
}
