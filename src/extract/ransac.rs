//! Robust curve fits for §4 step 2: RANSAC with the MSAC cost, exhaustive minimal samples when
//! they are few, and local optimisation (least squares on the inliers, repeated).
//!
//! Points are `(x, y)` in the formation frame (wingspans). A point's distance from a curve is
//! taken to first order (Sampson): d = r / √(1 + y'(x)²) with r = y − curve(x) the vertical
//! deviation the params file records as `dy`. A fit's cost is MSAC's truncated quadratic
//!
//! ```math
//! C = \sum_i \min(d_i^2, T^2)
//! ```
//!
//! with T the inlier threshold (wingspans). Minimal samples: 2 points for a line, 3 for a
//! parabola. When `C(n, k)` is at most `max_samples` every subset is tried (deterministic);
//! otherwise subsets are drawn from the caller's generator until the standard RANSAC bound
//! `N = ln(1 − p) / ln(1 − w^k)` (p = 0.999, w = best inlier ratio so far) or `max_samples` is
//! reached, with at least `min(max_samples, 200)` draws.

use rand::Rng;

/// A line `y = c + s·x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// `y` at `x = 0`, wingspans.
    pub c: f64,
    /// Slope dy/dx.
    pub s: f64,
}

/// A parabola `y = a·x² + b·x + c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parabola {
    /// Quadratic coefficient, 1/wingspan.
    pub a: f64,
    /// Linear coefficient.
    pub b: f64,
    /// Constant, wingspans.
    pub c: f64,
}

/// Two straight arms meeting at the leader's lateral position (x = 0):
/// `y = c + sl·x` for x < 0 and `y = c + sr·x` for x ≥ 0, both swept back (`sl ≤ 0 ≤ sr`). Three parameters: the apex's depth
/// and the two slopes (the apex lies on the leader's line of flight by construction, §4 step 1
/// puts the leader at x = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vee {
    /// `y` at the apex (x = 0), wingspans.
    pub c: f64,
    /// Slope dy/dx of the left arm (x < 0); negative for an arm swept back.
    pub sl: f64,
    /// Slope dy/dx of the right arm (x ≥ 0); positive for an arm swept back.
    pub sr: f64,
}

/// A curve that RANSAC can fit.
pub trait Model: Copy {
    /// Minimal sample size.
    const K: usize;
    /// Least-squares fit to the points (exact through a minimal sample); `None` if degenerate.
    fn fit(pts: &[(f64, f64)]) -> Option<Self>;
    /// The curve's y at x.
    fn y_at(&self, x: f64) -> f64;
    /// The curve's slope dy/dx at x.
    fn slope_at(&self, x: f64) -> f64;
    /// Squared distance of a point from the curve to first order (the Sampson approximation
    /// r² / (1 + y'(x)²), r = y − curve(x)): isotropic image noise on a steep arm is not
    /// mistaken for an outlier.
    fn dist2(&self, x: f64, y: f64) -> f64 {
        let r = y - self.y_at(x);
        let s = self.slope_at(x);
        r * r / (1.0 + s * s)
    }
    /// Whether the model is admissible (a U/J parabola must open backward, `a > 0`).
    fn valid(&self) -> bool {
        true
    }
}

impl Model for Line {
    const K: usize = 2;
    fn fit(pts: &[(f64, f64)]) -> Option<Line> {
        let n = pts.len() as f64;
        if pts.len() < 2 {
            return None;
        }
        let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
        let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        if sxx <= 1e-12 * n {
            return None;
        }
        let s = sxy / sxx;
        let l = Line { c: my - s * mx, s };
        (l.c.is_finite() && l.s.is_finite()).then_some(l)
    }
    fn y_at(&self, x: f64) -> f64 {
        self.c + self.s * x
    }
    fn slope_at(&self, _x: f64) -> f64 {
        self.s
    }
}

impl Model for Parabola {
    const K: usize = 3;
    fn fit(pts: &[(f64, f64)]) -> Option<Parabola> {
        if pts.len() < 3 {
            return None;
        }
        // Centre and scale x for conditioning: y = α u² + β u + γ with u = (x − m)/h.
        let n = pts.len() as f64;
        let m = pts.iter().map(|p| p.0).sum::<f64>() / n;
        let h = pts.iter().map(|p| (p.0 - m).abs()).fold(0.0f64, f64::max);
        if h <= 1e-9 {
            return None;
        }
        let mut ata = nalgebra::Matrix3::<f64>::zeros();
        let mut aty = nalgebra::Vector3::<f64>::zeros();
        for &(x, y) in pts {
            let u = (x - m) / h;
            let row = nalgebra::Vector3::new(u * u, u, 1.0);
            ata += row * row.transpose();
            aty += row * y;
        }
        // Reject near-degenerate samples (two x's almost equal) instead of fitting noise.
        let det = ata.determinant();
        if det.abs() < 1e-10 * n * n * n {
            return None;
        }
        let sol = ata.lu().solve(&aty)?;
        let (al, be, ga) = (sol[0], sol[1], sol[2]);
        let a = al / (h * h);
        let b = be / h - 2.0 * al * m / (h * h);
        let c = ga - be * m / h + al * m * m / (h * h);
        let p = Parabola { a, b, c };
        (a.is_finite() && b.is_finite() && c.is_finite()).then_some(p)
    }
    fn y_at(&self, x: f64) -> f64 {
        (self.a * x + self.b) * x + self.c
    }
    fn slope_at(&self, x: f64) -> f64 {
        2.0 * self.a * x + self.b
    }
    fn valid(&self) -> bool {
        self.a > 0.0
    }
}

impl Model for Vee {
    const K: usize = 3;
    fn fit(pts: &[(f64, f64)]) -> Option<Vee> {
        if pts.len() < 3 {
            return None;
        }
        // Linear least squares on the design row (1, min(x, 0), max(x, 0)); singular when one
        // side of the leader has no point.
        let mut ata = nalgebra::Matrix3::<f64>::zeros();
        let mut aty = nalgebra::Vector3::<f64>::zeros();
        let scale = pts.iter().map(|p| p.0.abs()).fold(0.0f64, f64::max);
        if scale <= 1e-9 {
            return None;
        }
        for &(x, y) in pts {
            let u = x / scale;
            let row = nalgebra::Vector3::new(1.0, u.min(0.0), u.max(0.0));
            ata += row * row.transpose();
            aty += row * y;
        }
        let n = pts.len() as f64;
        if ata.determinant().abs() < 1e-10 * n * n * n {
            return None;
        }
        let sol = ata.lu().solve(&aty)?;
        let v = Vee {
            c: sol[0],
            sl: sol[1] / scale,
            sr: sol[2] / scale,
        };
        (v.c.is_finite() && v.sl.is_finite() && v.sr.is_finite()).then_some(v)
    }
    fn y_at(&self, x: f64) -> f64 {
        self.c + if x < 0.0 { self.sl * x } else { self.sr * x }
    }
    fn slope_at(&self, x: f64) -> f64 {
        if x < 0.0 {
            self.sl
        } else {
            self.sr
        }
    }
    /// Both arms swept back (or flat): an arm reaching forward of the leader's flank is no V
    /// (it is what a formation opening forward looks like, see `extract::checks`).
    fn valid(&self) -> bool {
        self.sl <= 0.0 && self.sr >= 0.0
    }
}

/// RANSAC settings.
#[derive(Debug, Clone, Copy)]
pub struct RansacOptions {
    /// Inlier threshold T on |y − curve(x)|, wingspans.
    pub threshold: f64,
    /// Most minimal samples tried; below this count of subsets all of them are tried.
    pub max_samples: usize,
    /// Rounds of least squares on the inliers after the sampling.
    pub refine_rounds: usize,
}

/// MSAC cost of a model over points.
pub fn msac_cost<M: Model>(m: &M, pts: &[(f64, f64)], t2: f64) -> f64 {
    pts.iter().map(|&(x, y)| m.dist2(x, y).min(t2)).sum()
}

fn binomial(n: usize, k: usize) -> u128 {
    let mut r: u128 = 1;
    for i in 0..k {
        r = r * (n - i) as u128 / (i + 1) as u128;
    }
    r
}

/// Calls `f` with every k-subset of 0..n (lexicographic).
fn for_each_subset(n: usize, k: usize, mut f: impl FnMut(&[usize])) {
    if k > n || k == 0 {
        return;
    }
    let mut idx: Vec<usize> = (0..k).collect();
    loop {
        f(&idx);
        let Some(i) = (0..k).rev().find(|&i| idx[i] < n - k + i) else {
            return;
        };
        idx[i] += 1;
        for j in (i + 1)..k {
            idx[j] = idx[j - 1] + 1;
        }
    }
}

/// Best model by MSAC cost over `pts`, with its cost; `None` when no sample gives a model.
pub fn ransac<M: Model>(
    pts: &[(f64, f64)],
    opts: &RansacOptions,
    rng: &mut impl Rng,
) -> Option<(M, f64)> {
    let n = pts.len();
    let k = M::K;
    if n < k {
        return None;
    }
    let t2 = opts.threshold * opts.threshold;
    let mut best: Option<(M, f64)> = None;
    let mut sample = [(0.0, 0.0); 3];
    let consider = |m: M, best: &mut Option<(M, f64)>| {
        if !m.valid() {
            return;
        }
        let c = msac_cost(&m, pts, t2);
        if best.as_ref().map_or(true, |b| c < b.1) {
            *best = Some((m, c));
        }
    };
    if binomial(n, k) <= opts.max_samples as u128 {
        for_each_subset(n, k, |idx| {
            for (s, &i) in sample.iter_mut().zip(idx) {
                *s = pts[i];
            }
            if let Some(m) = M::fit(&sample[..k]) {
                consider(m, &mut best);
            }
        });
    } else {
        let floor = opts.max_samples.min(200);
        let mut needed = opts.max_samples;
        let mut it = 0;
        let mut idx = [0usize; 3];
        while it < needed.max(floor).min(opts.max_samples) {
            it += 1;
            // k distinct indices.
            let mut filled = 0;
            while filled < k {
                let c = rng.random_range(0..n);
                if !idx[..filled].contains(&c) {
                    idx[filled] = c;
                    filled += 1;
                }
            }
            for (s, &i) in sample.iter_mut().zip(&idx[..k]) {
                *s = pts[i];
            }
            if let Some(m) = M::fit(&sample[..k]) {
                consider(m, &mut best);
                if let Some((bm, _)) = &best {
                    let inl = pts.iter().filter(|&&(x, y)| bm.dist2(x, y) <= t2).count() as f64
                        / n as f64;
                    let wk = inl.powi(k as i32);
                    needed = if wk >= 1.0 - 1e-12 {
                        0
                    } else {
                        ((1.0f64 - 0.999).ln() / (1.0 - wk).ln()).ceil().max(0.0) as usize
                    };
                }
            }
        }
    }
    // Local optimisation: least squares on the inliers while the cost drops.
    let (mut m, mut c) = best?;
    let mut inl: Vec<(f64, f64)> = Vec::with_capacity(n);
    for _ in 0..opts.refine_rounds {
        inl.clear();
        inl.extend(pts.iter().filter(|&&(x, y)| m.dist2(x, y) <= t2));
        let Some(m2) = M::fit(&inl).filter(|m| m.valid()) else {
            break;
        };
        let c2 = msac_cost(&m2, pts, t2);
        if c2 < c - 1e-12 {
            m = m2;
            c = c2;
        } else {
            break;
        }
    }
    Some((m, c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn subsets_are_all_enumerated() {
        let mut count = 0;
        for_each_subset(7, 3, |_| count += 1);
        assert_eq!(count, 35);
        let mut count = 0;
        for_each_subset(2, 2, |_| count += 1);
        assert_eq!(count, 1);
    }

    #[test]
    fn parabola_through_three_points_is_exact() {
        let p = Parabola::fit(&[(-2.0, 4.5), (1.0, 1.5), (3.0, 9.5)]).unwrap();
        for &(x, y) in &[(-2.0, 4.5), (1.0, 1.5), (3.0, 9.5)] {
            assert!((p.y_at(x) - y).abs() < 1e-9);
        }
    }

    #[test]
    fn vee_through_three_points_is_exact_and_needs_both_sides() {
        let pts = [(-0.9, 0.6), (0.0, 0.0), (1.0, 0.5)];
        let v = Vee::fit(&pts).unwrap();
        for &(x, y) in &pts {
            assert!((v.y_at(x) - y).abs() < 1e-9);
        }
        assert!(Vee::fit(&[(0.0, 0.0), (1.0, 0.5), (2.0, 1.1)]).is_none());
    }

    #[test]
    fn line_ransac_ignores_gross_outliers() {
        let mut pts: Vec<(f64, f64)> = (0..20).map(|i| (i as f64, 0.5 * i as f64 + 1.0)).collect();
        pts[3].1 += 5.0;
        pts[11].1 -= 4.0;
        let opts = RansacOptions {
            threshold: 0.3,
            max_samples: 50,
            refine_rounds: 3,
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let (l, _) = ransac::<Line>(&pts, &opts, &mut rng).unwrap();
        assert!((l.s - 0.5).abs() < 1e-9 && (l.c - 1.0).abs() < 1e-9);
    }
}
