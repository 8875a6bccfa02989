//! Shape-level sums of a flock whose lateral positions stay fixed (the key-shape solve): e_i for
//! many longitudinal placements, the near part of the Jacobian as a band, and products of the
//! exact Jacobian with a vector, each in one pass over the pairs with the birds sorted by x.
//!
//! Pairs less than [`FAR_FIELD`] apart laterally use the closed form ([`AeroOptions::g`]'s pair
//! terms, with the core). Farther pairs use the far-field expansion of [`super::far_pair`]
//! rewritten so that everything that depends on the lateral distance only is summed once, when the
//! field is built: with u = a²/X², Ã = −ln(1 − u) (its series), H₀ = u³(1/3 + u/4) and
//!
//! ```math
//! Q(X, r) = \frac{1}{r}\Bigl[\frac{a^2}{X^2} + \frac{a^4}{12}\Bigl(\frac{6}{X^4} + \frac{3}{X^2 r^2} + \frac{3}{r^4}\Bigr)\Bigr],
//! \qquad r = \sqrt{X^2 + Y^2},
//! ```
//!
//! the bird Y behind the other (Y < 0: ahead) gets (2/π²)·(Ã + sign(Y)·H₀ + Y·Q) and the other
//! (2/π²)·(Ã − sign(Y)·H₀ − Y·Q): the same values as [`super::far_pair`] up to rounding, with one
//! square root and one division per pair. The far loop is written in lanes of four with a fixed
//! summation order, so the result is the same bit for bit whether or not the compiler vectorises it.
//! Its error is the far-field expansion's (relative below 3·10⁻⁸, absolute below 10⁻¹² per
//! pair in g; tested against the closed form).

use super::tree::{FarTree, Kernel, TreeOptions};
use super::{AeroOptions, A, FAR_FIELD, TWO_OVER_PI2};

const A2: f64 = A * A;
const A4_12: f64 = A * A * A * A / 12.0;
const LANES: usize = 4;

/// Ã(X) = −ln(1 − a²/X²) for X ≥ [`FAR_FIELD`], by its series (exact to rounding there).
#[inline(always)]
fn far_a_term(x2: f64) -> f64 {
    let u = A2 / x2;
    u * (1.0 + u * (0.5 + u * (1.0 / 3.0 + u * 0.25)))
}

/// The part of a far pair's share that depends on the stagger, in units of 2/π²: what the bird
/// `y` behind the other gets beyond Ã (the other gets as much less). `x2` = X².
#[inline(always)]
fn far_odd(x2: f64, y: f64) -> f64 {
    let (h0, yq) = far_parts(x2, y);
    let s = if y > 0.0 { h0 } else { -h0 };
    s + yq
}

/// [`far_odd`] without its term sign(y)·H₀ (H₀ = u³(1/3 + u/4) < 1.7·10⁻¹² for X ≥
/// [`FAR_FIELD`], a remainder of the expansion's truncation): smooth in y, for interpolation.
#[inline(always)]
pub(super) fn far_odd_smooth(x2: f64, y: f64) -> f64 {
    far_parts(x2, y).1
}

/// (H₀, y·Q(X, r)) of a far pair, `x2` = X².
#[inline(always)]
fn far_parts(x2: f64, y: f64) -> (f64, f64) {
    let r = (x2 + y * y).sqrt();
    let d = 1.0 / (r * x2);
    let inv_r = x2 * d;
    let inv_x2 = r * d;
    let inv_r2 = inv_r * inv_r;
    let u = A2 * inv_x2;
    let h0 = u * u * u * (1.0 / 3.0 + 0.25 * u);
    let q = inv_r
        * (A2 * inv_x2
            + A4_12 * (6.0 * inv_x2 * inv_x2 + 3.0 * inv_x2 * inv_r2 + 3.0 * inv_r2 * inv_r2));
    (h0, y * q)
}

/// ∂g/∂y of a far pair in units of 2/π² (as [`super::far_pair`]'s slope). `x2` = X².
#[inline(always)]
pub(super) fn far_slope(x2: f64, y: f64) -> f64 {
    let r2 = x2 + y * y;
    let inv_r = 1.0 / r2.sqrt();
    let inv_r2 = inv_r * inv_r;
    let inv_r3 = inv_r2 * inv_r;
    let inv_r5 = inv_r3 * inv_r2;
    A2 * inv_r3 + A4_12 * (15.0 * x2 * inv_r5 * inv_r2 - 3.0 * inv_r5)
}

/// A flock's lateral positions, sorted, with what depends on them alone summed once.
#[derive(Debug, Clone)]
pub struct Field {
    opts: AeroOptions,
    /// Lateral positions, input order.
    x: Vec<f64>,
    /// Bird at each sorted position (ties: lower index first).
    order: Vec<usize>,
    /// x at each sorted position.
    xs: Vec<f64>,
    /// First sorted position q > p with xs[q] − xs[p] ≥ [`FAR_FIELD`], per p.
    far_start: Vec<usize>,
    /// Index of pair (p, p + 1) in the list of near pairs (p, q < far_start[p]), per p.
    near_offset: Vec<usize>,
    /// Σ of Ã over the far partners of each sorted position (units of 2/π²).
    far_base: Vec<f64>,
    /// Pairs less than this far apart laterally go into the band, wingspans.
    band_span: f64,
    /// Largest q − p of a pair less than `band_span` apart.
    band_width: usize,
}

impl Field {
    /// Sorts the birds by x and sums the far pairs' Ã. `band_span` (wingspans, at most
    /// [`FAR_FIELD`]; larger values are clamped) selects the pairs of [`Field::power_band`]'s
    /// band. The caller guarantees finite x.
    pub fn new(opts: &AeroOptions, x: &[f64], band_span: f64) -> Field {
        let n = x.len();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
        let xs: Vec<f64> = order.iter().map(|&i| x[i]).collect();
        let band_span = band_span.clamp(0.0, FAR_FIELD);
        let mut far_start = vec![n; n];
        let mut band_width = 0;
        let (mut q_far, mut q_band) = (0, 0);
        for p in 0..n {
            q_far = q_far.max(p + 1);
            while q_far < n && xs[q_far] - xs[p] < FAR_FIELD {
                q_far += 1;
            }
            far_start[p] = q_far;
            q_band = q_band.max(p + 1);
            while q_band < n && xs[q_band] - xs[p] < band_span {
                q_band += 1;
            }
            band_width = band_width.max(q_band - 1 - p);
        }
        let mut near_offset = Vec::with_capacity(n + 1);
        let mut count = 0;
        for (p, &fs) in far_start.iter().enumerate() {
            near_offset.push(count);
            count += fs - p - 1;
        }
        near_offset.push(count);
        // Σ of Ã over far partners, in fixed chunks of positions (one buffer each, added in
        // chunk order: the same bits for any number of threads).
        let bounds = chunk_bounds(n);
        let parts = run_chunks(bounds.len() - 1, threads(n), |c| {
            let mut part = vec![0.0; n];
            let mut scratch = vec![0.0; n];
            for p in bounds[c]..bounds[c + 1] {
                let xp = xs[p];
                let fs = far_start[p];
                // A map the compiler vectorises, then a sum in lanes of four.
                let t = &mut scratch[..n - fs];
                for (t, &xq) in t.iter_mut().zip(&xs[fs..]) {
                    let dx = xq - xp;
                    *t = far_a_term(dx * dx);
                }
                for (b, &t) in part[fs..].iter_mut().zip(t.iter()) {
                    *b += t;
                }
                part[p] += lane_sum(t);
            }
            part
        });
        let far_base = add_parts(vec![0.0; n], &parts);
        Field {
            opts: *opts,
            x: x.to_vec(),
            order,
            xs,
            far_start,
            near_offset,
            far_base,
            band_span,
            band_width,
        }
    }

    /// The lateral positions, input order.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// Number of birds.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether there are no birds.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The bird at each sorted position (smallest x first).
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Half-bandwidth b of [`Field::power_band`]'s band.
    pub fn band_width(&self) -> usize {
        self.band_width
    }

    /// E = Σ_i e_i, which by Munk's theorem depends on x only: Σ over pairs of 2g(x_ij, 0).
    pub fn munk_total(&self) -> f64 {
        let n = self.len();
        let mut total: f64 = self.far_base.iter().sum();
        for p in 0..n {
            for q in (p + 1)..self.far_start[p] {
                total += 2.0 * self.opts.pair(self.xs[q] - self.xs[p], 1.0).a_term;
            }
        }
        TWO_OVER_PI2 * total
    }

    /// e_i (input order) for longitudinal positions `y` (input order, no collision: the caller
    /// checks). With `band`, also the Jacobian ∂e/∂y restricted to the pairs less than
    /// `band_span` apart, in sorted positions: a symmetric band matrix stored as
    /// `band[p * (b + 1) + k]` = J[p][p − k] for k ≤ b = [`Field::band_width`] (a weighted graph
    /// Laplacian; the slot is resized and overwritten). With `near`, also every near pair's
    /// ∂g/∂y (units of 2/π²) for [`Field::jacobian_times`].
    pub fn power_band(
        &self,
        y: &[f64],
        mut band: Option<&mut Vec<f64>>,
        mut near: Option<&mut Vec<f64>>,
    ) -> Vec<f64> {
        let n = self.len();
        self.prepare(band.as_deref_mut(), near.as_deref_mut());
        let ys = self.sorted(y);
        let mut e = self.far_base.clone();
        let mut scratch = vec![0.0; n];
        for p in 0..n {
            let acc = self.near_row(p, &ys, &mut e, band.as_deref_mut(), near.as_deref_mut());
            let far = self.far_row(p, &ys, &mut e, &mut scratch);
            e[p] += acc + far;
        }
        self.unsorted(&e)
    }

    /// e_i (input order) for longitudinal positions `y` (input order, no collision): the same
    /// sums as [`Field::power_band`] without the band and the slopes. From `PARALLEL_MIN` (2000) birds
    /// the pairs are split into fixed chunks of sorted positions run on up to two threads (the
    /// machine's cores, at most `CHUNKS`); each chunk adds into its own buffer and the buffers
    /// are added in chunk order, so the result has the same bits for any number of threads.
    pub fn power(&self, y: &[f64]) -> Vec<f64> {
        self.power_threads(y, threads(self.len()))
    }

    /// [`Field::power`] on at most `threads` threads.
    pub(crate) fn power_threads(&self, y: &[f64], threads: usize) -> Vec<f64> {
        let n = self.len();
        if n < PARALLEL_MIN {
            return self.power_band(y, None, None);
        }
        let ys = self.sorted(y);
        let bounds = chunk_bounds(n);
        let parts = run_chunks(bounds.len() - 1, threads, |c| {
            let mut part = vec![0.0; n];
            let mut scratch = vec![0.0; n];
            for p in bounds[c]..bounds[c + 1] {
                let acc = self.near_row(p, &ys, &mut part, None, None);
                let acc = acc + self.far_row(p, &ys, &mut part, &mut scratch);
                part[p] += acc;
            }
            part
        });
        self.unsorted(&add_parts(self.far_base.clone(), &parts))
    }

    /// The far partners q of sorted position p: subtracts the stagger-dependent part of their
    /// shares from `e[q]`, returns p's (units of 2/π²). `scratch` has room for N values.
    #[inline]
    fn far_row(&self, p: usize, ys: &[f64], e: &mut [f64], scratch: &mut [f64]) -> f64 {
        let (xp, yp) = (self.xs[p], ys[p]);
        let fs = self.far_start[p];
        // A map the compiler vectorises, then sums in lanes of four (fixed summation order).
        let far = &self.xs[fs..];
        let far_y = &ys[fs..];
        let t = &mut scratch[..far.len()];
        for ((t, &xq), &yq) in t.iter_mut().zip(far).zip(far_y) {
            let dx = xq - xp;
            *t = far_odd(dx * dx, yp - yq);
        }
        for (eq, &t) in e[fs..].iter_mut().zip(t.iter()) {
            *eq -= t;
        }
        lane_sum(t)
    }

    /// Sizes `band` and `near` for [`Field::power_band`] (zeroed).
    fn prepare(&self, band: Option<&mut Vec<f64>>, near: Option<&mut Vec<f64>>) {
        let n = self.len();
        if let Some(b) = band {
            b.clear();
            b.resize(n * (self.band_width + 1), 0.0);
        }
        if let Some(s) = near {
            s.clear();
            s.resize(self.near_offset[n], 0.0);
        }
    }

    /// `v` (input order) at the sorted positions.
    fn sorted(&self, v: &[f64]) -> Vec<f64> {
        self.order.iter().map(|&i| v[i]).collect()
    }

    /// Sorted sums in units of 2/π² → values in input order.
    fn unsorted(&self, s: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; s.len()];
        for (p, &i) in self.order.iter().enumerate() {
            out[i] = TWO_OVER_PI2 * s[p];
        }
        out
    }

    /// The near pairs (p, q > p) of sorted position p: adds q's share to `e[q]`, fills the band
    /// and the near slopes, returns p's share (units of 2/π²).
    #[inline]
    fn near_row(
        &self,
        p: usize,
        ys: &[f64],
        e: &mut [f64],
        mut band: Option<&mut Vec<f64>>,
        mut near: Option<&mut Vec<f64>>,
    ) -> f64 {
        let w = self.band_width + 1;
        let (xp, yp) = (self.xs[p], ys[p]);
        let mut acc = 0.0;
        for q in (p + 1)..self.far_start[p] {
            let dx = self.xs[q] - xp;
            // p is dy behind q.
            let dy = yp - ys[q];
            let pr = self.opts.pair(dx, dy);
            let (front, back) = (pr.d_term, 2.0 * pr.a_term - pr.d_term);
            if dy > 0.0 {
                acc += back;
                e[q] += front;
            } else {
                acc += front;
                e[q] += back;
            }
            if let Some(s) = near.as_deref_mut() {
                s[self.near_offset[p] + (q - p - 1)] = pr.slope;
            }
            if dx < self.band_span {
                if let Some(b) = band.as_deref_mut() {
                    let s = TWO_OVER_PI2 * pr.slope;
                    b[q * w + (q - p)] -= s;
                    b[p * w] += s;
                    b[q * w] += s;
                }
            }
        }
        acc
    }

    /// The near pairs' part of J·v at sorted position p (units of 2/π²): subtracts q's part
    /// from `out[q]`, returns p's.
    #[inline]
    fn near_product_row(&self, p: usize, vs: &[f64], near: &[f64], out: &mut [f64]) -> f64 {
        let vp = vs[p];
        let mut acc = 0.0;
        let slopes = &near[self.near_offset[p]..self.near_offset[p + 1]];
        for (k, &s) in slopes.iter().enumerate() {
            let q = p + 1 + k;
            let t = s * (vp - vs[q]);
            acc += t;
            out[q] -= t;
        }
        acc
    }

    /// The same sums with the far pairs interpolated ([`TreeOptions`]): for the inner
    /// iterations of the key-shape solve of large flocks, whose result is then checked with the
    /// exact sums.
    pub fn approximate(&self, opts: TreeOptions) -> ApproxField<'_> {
        ApproxField {
            field: self,
            tree: FarTree::new(self.len(), opts),
        }
    }
}

/// [`Field`]'s sums with the far pairs (lateral distance ≥ [`FAR_FIELD`]) interpolated on a dual
/// tree (`aero::tree`): the near pairs, the band and the y-independent part Ã stay exact; the
/// stagger-dependent part of the far pairs has an error of about 10⁻⁷ of the far sum at the
/// default [`TreeOptions`] (tested), at a small fraction of the cost for thousands of birds.
#[derive(Debug, Clone)]
pub struct ApproxField<'a> {
    field: &'a Field,
    tree: FarTree,
}

impl ApproxField<'_> {
    /// [`Field::power_band`] with the far pairs interpolated.
    pub fn power_band(
        &self,
        y: &[f64],
        mut band: Option<&mut Vec<f64>>,
        mut near: Option<&mut Vec<f64>>,
    ) -> Vec<f64> {
        let f = self.field;
        let n = f.len();
        f.prepare(band.as_deref_mut(), near.as_deref_mut());
        let ys = f.sorted(y);
        let mut e = f.far_base.clone();
        let ones = vec![1.0; n];
        let tree = || self.tree.sum(&f.xs, &ys, Kernel::Odd, &[&ones]);
        let mut near_part = |e: &mut [f64]| {
            for p in 0..n {
                let acc = f.near_row(p, &ys, e, band.as_deref_mut(), near.as_deref_mut());
                e[p] += acc;
            }
        };
        // The near pairs and the interpolated far ones are independent: two threads for large
        // flocks (the same bits either way).
        let far = if n >= PARALLEL_MIN && parallel() {
            std::thread::scope(|s| {
                let t = s.spawn(tree);
                near_part(&mut e);
                t.join().unwrap_or_else(|e| std::panic::resume_unwind(e))
            })
        } else {
            near_part(&mut e);
            tree()
        };
        for (e, t) in e.iter_mut().zip(&far[0]) {
            *e += t;
        }
        f.unsorted(&e)
    }

    /// [`Field::jacobian_times`] with the far pairs interpolated (the same symmetric operator for
    /// every `v`: a weighted graph Laplacian).
    pub fn jacobian_times(&self, y: &[f64], near: &[f64], v: &[f64]) -> Vec<f64> {
        let f = self.field;
        let n = f.len();
        let ys = f.sorted(y);
        let vs = f.sorted(v);
        let mut out = vec![0.0; n];
        for p in 0..n {
            let acc = f.near_product_row(p, &vs, near, &mut out);
            out[p] += acc;
        }
        let ones = vec![1.0; n];
        let far = self.tree.sum(&f.xs, &ys, Kernel::Slope, &[&ones, &vs]);
        for p in 0..n {
            out[p] += vs[p] * far[0][p] - far[1][p];
        }
        f.unsorted(&out)
    }
}

impl Field {
    /// J·v for the exact Jacobian J = ∂e/∂y at `y` (input order in and out), with the near
    /// pairs' slopes `near` from [`Field::power_band`] at the same `y` and the far pairs' slopes
    /// recomputed (one square root and one division per pair): (Jv)_i = Σ_j ∂g/∂y(x_ij, y_ij)
    /// (v_i − v_j).
    pub fn jacobian_times(&self, y: &[f64], near: &[f64], v: &[f64]) -> Vec<f64> {
        let n = self.len();
        let ys = self.sorted(y);
        let vs = self.sorted(v);
        let mut out = vec![0.0; n];
        let mut scratch = vec![0.0; n];
        for p in 0..n {
            let (yp, vp, xp) = (ys[p], vs[p], self.xs[p]);
            let fs = self.far_start[p];
            let acc = self.near_product_row(p, &vs, near, &mut out);
            let far = &self.xs[fs..];
            let t = &mut scratch[..far.len()];
            for (((t, &xq), &yq), &vq) in t.iter_mut().zip(far).zip(&ys[fs..]).zip(&vs[fs..]) {
                let dx = xq - xp;
                *t = far_slope(dx * dx, yp - yq) * (vp - vq);
            }
            for (o, &t) in out[fs..].iter_mut().zip(t.iter()) {
                *o -= t;
            }
            out[p] += acc + lane_sum(t);
        }
        self.unsorted(&out)
    }
}

/// Flocks of at least this many birds have their exact sums ([`Field::power`], the far part of
/// [`Field::new`]) split into fixed chunks that run on several threads.
pub const PARALLEL_MIN: usize = 2000;
/// Number of chunks of [`PARALLEL_MIN`] (fixed: the result does not depend on the threads).
pub const CHUNKS: usize = 8;

/// Threads for a flock of `n` birds: the machine's (at most [`CHUNKS`]) from [`PARALLEL_MIN`]
/// birds on, else 1.
fn threads(n: usize) -> usize {
    if n < PARALLEL_MIN {
        return 1;
    }
    std::thread::available_parallelism()
        .map(|v| v.get())
        .unwrap_or(1)
        .min(CHUNKS)
}

/// Whether the machine has more than one core.
pub(super) fn parallel() -> bool {
    std::thread::available_parallelism().is_ok_and(|v| v.get() > 1)
}

/// Boundaries of [`CHUNKS`] ranges of sorted positions with about as many pairs (p, q > p)
/// each; one range below [`PARALLEL_MIN`] birds.
fn chunk_bounds(n: usize) -> Vec<usize> {
    if n < PARALLEL_MIN {
        return vec![0, n];
    }
    let total = n * (n - 1) / 2;
    let mut bounds = vec![0];
    let mut done = 0;
    for p in 0..n {
        done += n - 1 - p;
        let c = bounds.len();
        if c < CHUNKS && done * CHUNKS >= c * total {
            bounds.push(p + 1);
        }
    }
    bounds.push(n);
    bounds.dedup();
    bounds
}

/// Runs `f(0..count)` on up to `threads` threads and returns the results in chunk order.
fn run_chunks<T: Send>(count: usize, threads: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    if threads <= 1 || count <= 1 {
        return (0..count).map(f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut slots: Vec<Option<T>> = (0..count).map(|_| None).collect();
    std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads.min(count))
            .map(|_| {
                s.spawn(|| {
                    let mut got = Vec::new();
                    loop {
                        let c = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        if c >= count {
                            break got;
                        }
                        got.push((c, f(c)));
                    }
                })
            })
            .collect();
        for w in workers {
            let got = w.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            for (c, v) in got {
                slots[c] = Some(v);
            }
        }
    });
    slots.into_iter().flatten().collect()
}

/// `base` plus every part, in order.
fn add_parts(mut base: Vec<f64>, parts: &[Vec<f64>]) -> Vec<f64> {
    for part in parts {
        for (b, v) in base.iter_mut().zip(part) {
            *b += v;
        }
    }
    base
}

/// Σ of `t` in lanes of four (a fixed order, the same whether or not it is vectorised).
#[inline]
fn lane_sum(t: &[f64]) -> f64 {
    let mut lanes = [0.0; LANES];
    let mut chunks = t.chunks_exact(LANES);
    for c in &mut chunks {
        for l in 0..LANES {
            lanes[l] += c[l];
        }
    }
    for &v in chunks.remainder() {
        lanes[0] += v;
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn far_terms_match_the_closed_form() {
        let o = AeroOptions::default();
        let mut worst: f64 = 0.0;
        for i in 0..200 {
            let x = FAR_FIELD * (1.0 + i as f64 * 0.1);
            for k in -40..=40 {
                let y = k as f64 * x / 8.0;
                let p = o.pair(x, y);
                let exact = if y > 0.0 {
                    2.0 * p.a_term - p.d_term
                } else {
                    p.d_term
                };
                let fast = far_a_term(x * x) + far_odd(x * x, y);
                let err = (exact - fast).abs();
                assert!(
                    err < 3e-8 * exact.abs() + 1e-15,
                    "x={x} y={y}: {exact} vs {fast}"
                );
                worst = worst.max(TWO_OVER_PI2 * err);
            }
        }
        assert!(worst < 1e-12, "worst absolute error of g {worst:e}");
    }
}

#[cfg(test)]
mod flock_tests {
    use super::*;
    use crate::rng::seeded;
    use rand::Rng;

    /// A V of `n` birds at real spacing (lateral gaps 0.6–1.1 wingspans, overlapping wingtips
    /// included) with noisy depth, wide enough that most pairs are far.
    fn flock(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = seeded(seed);
        let (mut x, mut y) = (vec![0.0], vec![0.0]);
        let (mut xl, mut xr, mut yl, mut yr) = (0.0, 0.0, 0.0, 0.0);
        for k in 1..n {
            let gap = rng.random_range(0.6..1.1);
            let back = rng.random_range(0.3..1.6);
            if k % 2 == 1 {
                xr += gap;
                yr += back;
                x.push(xr);
                y.push(yr);
            } else {
                xl -= gap;
                yl += back;
                x.push(xl);
                y.push(yl);
            }
        }
        (x, y)
    }

    /// e_i pair by pair with the closed form, in input order.
    fn reference(o: &AeroOptions, x: &[f64], y: &[f64]) -> Vec<f64> {
        let n = x.len();
        let mut e = vec![0.0; n];
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    e[i] += o.g((x[i] - x[j]).abs(), y[i] - y[j]);
                }
            }
        }
        e
    }

    #[test]
    fn savings_band_and_products_match_the_pairwise_closed_form() {
        let o = AeroOptions::default();
        for seed in 0..3 {
            let (x, y) = flock(301, seed);
            let field = Field::new(&o, &x, 30.0);
            let mut band = Vec::new();
            let mut near = Vec::new();
            let e = field.power_band(&y, Some(&mut band), Some(&mut near));
            let e_ref = reference(&o, &x, &y);
            for (a, b) in e.iter().zip(&e_ref) {
                assert!((a - b).abs() < 1e-11, "seed {seed}: {a} vs {b}");
            }
            let total: f64 = e.iter().sum();
            assert!((field.munk_total() - total).abs() < 1e-10 * total);
            // The band holds the dense Jacobian's entries of the pairs within 30 wingspans.
            let jac = o.power_jacobian_unchecked(&x, &y);
            let n = x.len();
            let w = field.band_width() + 1;
            let ord = field.order();
            for p in 0..n {
                for k in 1..w.min(p + 1) {
                    let (i, j) = (ord[p], ord[p - k]);
                    let want = if (x[i] - x[j]).abs() < 30.0 {
                        jac[i * n + j]
                    } else {
                        0.0
                    };
                    assert!((band[p * w + k] - want).abs() < 1e-13, "band ({p}, {k})");
                }
            }
            // J·v against the dense Jacobian.
            let mut rng = seeded(seed + 10);
            let v: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let jv = field.jacobian_times(&y, &near, &v);
            for i in 0..n {
                let want: f64 = (0..n).map(|k| jac[i * n + k] * v[k]).sum();
                assert!(
                    (jv[i] - want).abs() < 1e-12,
                    "seed {seed} bird {i}: {} vs {want}",
                    jv[i]
                );
            }
        }
    }

    #[test]
    fn the_same_bits_for_any_number_of_threads() {
        let o = AeroOptions::default();
        let (x, y) = flock(PARALLEL_MIN + 301, 3);
        let field = Field::new(&o, &x, 60.0);
        let one = field.power_threads(&y, 1);
        for threads in [2, 3, CHUNKS] {
            let many = field.power_threads(&y, threads);
            for (a, b) in one.iter().zip(&many) {
                assert_eq!(a.to_bits(), b.to_bits(), "{threads} threads");
            }
        }
        // And the same values as the sequential sums, to rounding.
        let seq = field.power_band(&y, None, None);
        for (a, b) in one.iter().zip(&seq) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn the_same_bits_for_any_input_order() {
        let o = AeroOptions::default();
        let (x, y) = flock(300, 7);
        let e = Field::new(&o, &x, 10.0).power_band(&y, None, None);
        let perm: Vec<usize> = (0..x.len()).rev().collect();
        let xp: Vec<f64> = perm.iter().map(|&i| x[i]).collect();
        let yp: Vec<f64> = perm.iter().map(|&i| y[i]).collect();
        let ep = Field::new(&o, &xp, 10.0).power_band(&yp, None, None);
        for (k, &i) in perm.iter().enumerate() {
            assert_eq!(ep[k].to_bits(), e[i].to_bits());
        }
    }
}
