//! The footage's spacing in generated flocks: the median lateral and longitudinal
//! distance from each bird to its nearest bird ahead (the nearest, in the plane, of the birds with
//! a smaller `y`), for a shape or pooled over several. Formation frame, wingspans.
//!
//! Two uses in the steady flight: U and J curves are scaled so that the initial shapes have the
//! footage's median longitudinal spacing ([`depth_scale`]), and every key shape's median
//! longitudinal spacing must stay inside the band the initial shapes span
//! ([`crate::keyshape::keys::Structure`]), as each bird's ξ stays inside its range.

/// (|Δx|, Δy) from every bird to its nearest bird ahead (smallest Euclidean distance among the
/// birds with a smaller `y`); the front-most bird has none. Wingspans. Exact, and fast for line
/// formations: birds are scanned outward in lateral order from each bird until the lateral
/// distance alone exceeds the best distance found.
pub fn nearest_ahead(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let mut out = Vec::with_capacity(n.saturating_sub(1));
    for (p, &i) in order.iter().enumerate() {
        let mut best: Option<(f64, usize)> = None;
        let consider = |j: usize, best: &mut Option<(f64, usize)>| -> bool {
            let dx = x[j] - x[i];
            if let Some((d2, _)) = *best {
                if dx * dx >= d2 {
                    return false;
                }
            }
            if y[j] < y[i] {
                let d2 = dx * dx + (y[i] - y[j]).powi(2);
                if best.map_or(true, |(b, _)| d2 < b) {
                    *best = Some((d2, j));
                }
            }
            true
        };
        for &j in order[..p].iter().rev() {
            if !consider(j, &mut best) {
                break;
            }
        }
        for &j in &order[p + 1..] {
            if !consider(j, &mut best) {
                break;
            }
        }
        if let Some((_, j)) = best {
            out.push(((x[i] - x[j]).abs(), y[i] - y[j]));
        }
    }
    out
}

/// Median of `v` (the mean of the two middle values for an even count); NaN when empty.
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Median (lateral, longitudinal) distance to the nearest bird ahead, pooled over `shapes`
/// (each a pair of lateral and longitudinal positions), wingspans.
pub fn spacing<'a>(shapes: impl IntoIterator<Item = (&'a [f64], &'a [f64])>) -> (f64, f64) {
    let pairs: Vec<(f64, f64)> = shapes
        .into_iter()
        .flat_map(|(x, y)| nearest_ahead(x, y))
        .collect();
    (
        median(pairs.iter().map(|p| p.0).collect()),
        median(pairs.iter().map(|p| p.1).collect()),
    )
}

/// The footage's spacing from the positions of its frames (docs/formats.md §4.2 `positions`), or `None`
/// when no frame has positions of at least two birds.
pub fn footage_spacing(params: &crate::extract::params::FormationParams) -> Option<(f64, f64)> {
    let frames: Vec<(Vec<f64>, Vec<f64>)> = params
        .frames
        .iter()
        .filter(|f| f.positions.len() >= 2)
        .map(|f| {
            (
                f.positions.iter().map(|b| b.x).collect(),
                f.positions.iter().map(|b| b.y).collect(),
            )
        })
        .collect();
    if frames.is_empty() {
        return None;
    }
    let s = spacing(frames.iter().map(|(x, y)| (x.as_slice(), y.as_slice())));
    (s.0.is_finite() && s.1.is_finite() && s.1 > 0.0).then_some(s)
}

/// The factor t ∈ [1/`limit`, `limit`] by which the U and J curves' rank scale is multiplied so
/// that the median longitudinal spacing of the shapes made by `make(t)` is `target` (the
/// footage's). The median grows with t (a deeper curve, larger steps between neighbours), so the
/// factor is found by bisection on log t; an unreachable target gives the nearer end.
pub fn depth_scale(target: f64, limit: f64, mut make: impl FnMut(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (-limit.ln(), limit.ln());
    let at = |m: f64| m - target;
    let f_lo = at(make(lo.exp()));
    let f_hi = at(make(hi.exp()));
    if !(f_lo.is_finite() && f_hi.is_finite()) {
        return 1.0;
    }
    if f_lo >= 0.0 {
        return lo.exp();
    }
    if f_hi <= 0.0 {
        return hi.exp();
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if at(make(mid.exp())) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-4 {
            break;
        }
    }
    (0.5 * (lo + hi)).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain O(N²) definition.
    fn brute(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        let mut order: Vec<usize> = (0..x.len()).collect();
        order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
        for &i in &order {
            let best = (0..x.len())
                .filter(|&j| j != i && y[j] < y[i])
                .map(|j| ((x[i] - x[j]).powi(2) + (y[i] - y[j]).powi(2), j))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, j)) = best {
                out.push(((x[i] - x[j]).abs(), y[i] - y[j]));
            }
        }
        out
    }

    #[test]
    fn nearest_ahead_matches_the_definition() {
        use rand::Rng;
        let mut rng = crate::rng::seeded(5);
        for n in [2usize, 3, 9, 40] {
            for _ in 0..50 {
                let x: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
                let y: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..5.0)).collect();
                let a = nearest_ahead(&x, &y);
                let b = brute(&x, &y);
                assert_eq!(a.len(), b.len());
                for (p, q) in a.iter().zip(&b) {
                    // Equal distances may pick different birds; the distance is the same.
                    assert!(
                        (p.0.hypot(p.1) - q.0.hypot(q.1)).abs() < 1e-12,
                        "{p:?} {q:?}"
                    );
                }
            }
        }
        // A V: each bird's nearest bird ahead is its inner neighbour.
        let x = [-2.0, -1.0, 0.0, 1.0, 2.0];
        let y = [1.2, 0.6, 0.0, 0.6, 1.2];
        let s = spacing([(&x[..], &y[..])]);
        assert!(
            (s.0 - 1.0).abs() < 1e-12 && (s.1 - 0.6).abs() < 1e-12,
            "{s:?}"
        );
    }

    #[test]
    fn depth_scale_hits_a_monotone_target() {
        let t = depth_scale(1.5, 4.0, |t| 0.5 * t);
        assert!((t - 3.0).abs() < 1e-3, "{t}");
        assert_eq!(depth_scale(100.0, 2.0, |t| t), 2.0);
        assert_eq!(depth_scale(0.01, 2.0, |t| t), 0.5);
        assert_eq!(median(vec![3.0, 1.0, 2.0, 10.0]), 2.5);
    }
}
