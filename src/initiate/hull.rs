//! Robust 2-D geometry for the Hidden Point Removal operator: an orientation predicate that is
//! exact for every pair of finite `f64` inputs (a fast floating-point filter, then an exact
//! expansion sum in the style of Shewchuk's adaptive predicates), and Andrew's monotone-chain
//! convex hull built on it, keeping only strictly convex vertices (a point in the interior of a
//! hull edge is *not* a vertex, so a bird exactly behind another stays hidden).

use glam::DVec2;

/// Sign of the orientation determinant of the triangle `a, b, c`:
///
/// ```math
/// \operatorname{orient}(a,b,c) = (a_x-c_x)(b_y-c_y) - (a_y-c_y)(b_x-c_x)
/// ```
///
/// `> 0` when `a, b, c` turn counter-clockwise, `< 0` clockwise, `0` when collinear. The sign is
/// exact: when the floating-point value is too small to be trusted, the determinant is recomputed
/// as an exact sum of the six products (each split exactly by a fused multiply-add).
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let detleft = (a.x - c.x) * (b.y - c.y);
    let detright = (a.y - c.y) * (b.x - c.x);
    let det = detleft - detright;
    // Shewchuk's ccwerrboundA = (3 + 16ε)ε with ε = 2^-53.
    const ERR_BOUND: f64 = 3.330_669_073_875_472e-16;
    let bound = ERR_BOUND * (detleft.abs() + detright.abs());
    if det.abs() > bound {
        return det.signum();
    }
    orient2d_exact(a, b, c)
}

/// Exact sign of the orientation determinant (always the slow path).
pub fn orient2d_exact(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    // det = ax·by − ax·cy − cx·by − ay·bx + ay·cx + cy·bx (the cx·cy terms cancel).
    let products = [
        (a.x, b.y),
        (-a.x, c.y),
        (-c.x, b.y),
        (-a.y, b.x),
        (a.y, c.x),
        (c.y, b.x),
    ];
    let mut expansion: Vec<f64> = Vec::with_capacity(13);
    for (u, v) in products {
        let (p, e) = two_product(u, v);
        grow_expansion(&mut expansion, e);
        grow_expansion(&mut expansion, p);
    }
    // A non-overlapping expansion sorted by increasing magnitude has the sign of its largest
    // non-zero component.
    expansion
        .iter()
        .rev()
        .find(|c| **c != 0.0)
        .map_or(0.0, |c| c.signum())
}

/// `a·b = p + e` exactly.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// `a + b = s + e` exactly (Knuth's branch-free two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// Adds `b` to the expansion `e` (Shewchuk's Grow-Expansion), keeping it non-overlapping and in
/// increasing order of magnitude.
fn grow_expansion(e: &mut Vec<f64>, b: f64) {
    let mut q = b;
    for c in e.iter_mut() {
        let (s, h) = two_sum(q, *c);
        *c = h;
        q = s;
    }
    e.push(q);
}

/// Indices of the strictly convex vertices of the convex hull of `points`, counter-clockwise,
/// starting at the lexicographically smallest point. Duplicated points appear once (one index of
/// the group). Fewer than three distinct points: all distinct points are returned.
///
/// `sorted` is scratch space (reused between calls to avoid allocation). Returns the number of
/// distinct points.
pub fn convex_hull(
    points: &[DVec2],
    sorted: &mut Vec<(f64, f64, usize)>,
    hull: &mut Vec<usize>,
) -> usize {
    hull.clear();
    sorted.clear();
    sorted.extend(points.iter().enumerate().map(|(i, p)| (p.x, p.y, i)));
    // Sorting the coordinates themselves (not indices into `points`) keeps the sort cache-friendly.
    sorted.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    sorted.dedup_by(|b, a| a.0 == b.0 && a.1 == b.1);
    let n = sorted.len();
    let pt = |k: usize| DVec2::new(sorted[k].0, sorted[k].1);
    if n < 3 {
        hull.extend(sorted.iter().map(|s| s.2));
        return n;
    }
    // Positions (in `sorted`) of the chain; lower hull, then upper hull; pop on clockwise or
    // collinear turns (strict convexity).
    let mut chain = std::mem::take(hull);
    for k in 0..n {
        while chain.len() >= 2
            && orient2d(
                pt(chain[chain.len() - 2]),
                pt(chain[chain.len() - 1]),
                pt(k),
            ) <= 0.0
        {
            chain.pop();
        }
        chain.push(k);
    }
    let lower_len = chain.len() + 1;
    for k in (0..n - 1).rev() {
        while chain.len() >= lower_len
            && orient2d(
                pt(chain[chain.len() - 2]),
                pt(chain[chain.len() - 1]),
                pt(k),
            ) <= 0.0
        {
            chain.pop();
        }
        chain.push(k);
    }
    // The last point pushed is the first one again.
    chain.pop();
    if chain.len() < 3 {
        // All points collinear: the two extremes are the hull.
        chain.clear();
        chain.push(0);
        chain.push(n - 1);
    }
    // `chain` holds positions in `sorted`; turn them into indices of `points` in place.
    for k in chain.iter_mut() {
        *k = sorted[*k].2;
    }
    *hull = chain;
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn orientation_signs() {
        assert!(orient2d(v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)) > 0.0);
        assert!(orient2d(v(0.0, 0.0), v(0.0, 1.0), v(1.0, 0.0)) < 0.0);
        assert_eq!(orient2d(v(0.0, 0.0), v(1.0, 1.0), v(2.0, 2.0)), 0.0);
    }

    #[test]
    fn orientation_is_exact_near_degenerate() {
        // Points on the line y = x, perturbed by one ulp: the naive formula gets these wrong.
        let a = v(0.5, 0.5);
        let b = v(12.0, 12.0);
        let c = v(24.0, 24.0);
        assert_eq!(orient2d(a, b, c), 0.0);
        let c_up = v(24.0, 24.000000000000004);
        assert!(orient2d(a, b, c_up) > 0.0);
        let c_down = v(24.0, 23.999999999999996);
        assert!(orient2d(a, b, c_down) < 0.0);
        // Exact path agrees with the filter wherever the filter decides.
        for &(p, q, r) in &[
            (v(0.1, 0.2), v(3.3, 1.7), v(-2.0, 5.5)),
            (v(1e10, 1.0), v(1e10 + 1.0, 2.0), v(1e10 + 2.0, 3.0)),
        ] {
            let det = (p.x - r.x) * (q.y - r.y) - (p.y - r.y) * (q.x - r.x);
            if det.abs() > 1e-6 {
                assert_eq!(orient2d_exact(p, q, r), det.signum());
            }
        }
        assert_eq!(
            orient2d(v(1e10, 1.0), v(1e10 + 1.0, 2.0), v(1e10 + 2.0, 3.0)),
            0.0
        );
    }

    #[test]
    fn hull_of_square_with_interior_and_edge_points() {
        let pts = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(1.0, 1.0),
            v(0.0, 1.0),
            v(0.5, 0.5),
            v(0.5, 0.0),
            v(1.0, 1.0),
        ];
        let (mut o, mut h) = (Vec::new(), Vec::new());
        convex_hull(&pts, &mut o, &mut h);
        let mut s = h.clone();
        s.sort_unstable();
        assert_eq!(s, vec![0, 1, 2, 3]);
    }

    #[test]
    fn hull_of_collinear_points_is_its_ends() {
        let pts = [v(0.0, 0.0), v(2.0, 2.0), v(1.0, 1.0), v(3.0, 3.0)];
        let (mut o, mut h) = (Vec::new(), Vec::new());
        convex_hull(&pts, &mut o, &mut h);
        let mut s = h.clone();
        s.sort_unstable();
        assert_eq!(s, vec![0, 3]);
    }
}
