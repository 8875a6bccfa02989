//! Fast **approximate** sums over the far pairs of a flock (lateral distance at least
//! [`FAR_FIELD`]), for the inner iterations of the key-shape solve of large flocks: a dual tree
//! over the birds sorted by x with Chebyshev interpolation of the kernel on both boxes of a
//! well-separated pair of nodes (the "black-box" fast multipole idea, without translations).
//!
//! For targets in node A and sources in node B whose lateral gap is at least [`FAR_FIELD`] and at
//! least 1/θ times the largest side of either bounding box, the kernel K(x_p − x_q, y_p − y_q)
//! is replaced by its tensor-product Chebyshev interpolant of order `order` in each of the four
//! coordinates: K ≈ Σ_jk L_j(p) K(z_j − z_k) L_k(q), which costs `order`⁴ kernel evaluations per
//! pair of nodes instead of |A|·|B|. Other far pairs are summed directly. The kernel is analytic
//! wherever x_p ≠ x_q, with its nearest singularities a lateral gap away (the line x_p = x_q,
//! and y_p − y_q = ±i(x_p − x_q) in the complex plane), so the error falls geometrically with the
//! order: about 10⁻⁷ of the far sum at order 8 and θ = 1/2 (tested against the direct sums in
//! this file's tests, for Vs at real spacing and for scattered flocks).
//!
//! The key-shape solve only uses these sums to **find** the solution: its result is always
//! checked with the exact sums of [`super::Field`] (every pair, far ones by their expansion), so
//! the interpolation changes how many iterations the solve takes, never what it reports.
//!
//! Deterministic: one sequential traversal in a fixed order; the same bits on every run.

use super::far::{far_odd_smooth, far_slope, parallel, PARALLEL_MIN};
use super::FAR_FIELD;

/// Which far-pair function [`FarTree::sum`] adds up (units of 2/π²).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kernel {
    /// The stagger-dependent part of g: what bird p gets from q beyond Ã (odd in y_p − y_q).
    Odd,
    /// ∂g/∂y (even in y_p − y_q).
    Slope,
}

impl Kernel {
    #[inline(always)]
    fn eval(self, x2: f64, y: f64) -> f64 {
        match self {
            Kernel::Odd => far_odd_smooth(x2, y),
            Kernel::Slope => far_slope(x2, y),
        }
    }

    /// K(−X, −Y) = parity · K(X, Y).
    fn parity(self) -> f64 {
        match self {
            Kernel::Odd => -1.0,
            Kernel::Slope => 1.0,
        }
    }
}

/// Options of the interpolation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeOptions {
    /// Chebyshev points per coordinate (2..=16).
    pub order: usize,
    /// Admissibility: a pair of nodes is interpolated when its lateral gap is at least the
    /// largest side of either bounding box divided by θ.
    pub theta: f64,
    /// Most birds in a leaf.
    pub leaf: usize,
}

impl Default for TreeOptions {
    fn default() -> Self {
        TreeOptions {
            order: 8,
            theta: 0.5,
            leaf: 64,
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: usize,
    hi: usize,
    kids: Option<(usize, usize)>,
}

/// The tree of a flock's sorted lateral positions (fixed for a solve; the boxes' y extents are
/// taken at every sum).
#[derive(Debug, Clone)]
pub(crate) struct FarTree {
    nodes: Vec<Node>,
    opts: TreeOptions,
    /// Chebyshev points on [−1, 1] and their barycentric weights.
    cheb: Vec<f64>,
    bary: Vec<f64>,
}

/// A pass's plan: which node pairs are interpolated and which are summed directly.
#[derive(Debug, Clone)]
struct Plan {
    m2l: Vec<(usize, usize)>,
    direct: Vec<(usize, usize)>,
    selfs: Vec<usize>,
}

impl FarTree {
    /// Builds the tree over `n` sorted positions (balanced splits by index).
    pub fn new(n: usize, opts: TreeOptions) -> FarTree {
        let order = opts.order.clamp(2, 16);
        let opts = TreeOptions {
            order,
            theta: opts.theta,
            leaf: opts.leaf.max(1),
        };
        let mut nodes = Vec::new();
        build(&mut nodes, 0, n, opts.leaf);
        let cheb: Vec<f64> = (0..order)
            .map(|k| ((2 * k + 1) as f64 * std::f64::consts::PI / (2 * order) as f64).cos())
            .collect();
        let bary: Vec<f64> = (0..order)
            .map(|k| {
                let s = ((2 * k + 1) as f64 * std::f64::consts::PI / (2 * order) as f64).sin();
                if k % 2 == 0 {
                    s
                } else {
                    -s
                }
            })
            .collect();
        FarTree {
            nodes,
            opts,
            cheb,
            bary,
        }
    }

    /// For each sorted position p and each weight vector w (sorted positions), approximately
    /// Σ_q K(x_p − x_q, y_p − y_q)·w_q over the q with |x_p − x_q| ≥ [`FAR_FIELD`]. `xs` sorted
    /// ascending.
    pub fn sum(&self, xs: &[f64], ys: &[f64], kernel: Kernel, weights: &[&[f64]]) -> Vec<Vec<f64>> {
        self.run(xs, ys, kernel, weights)
    }

    fn run(&self, xs: &[f64], ys: &[f64], kernel: Kernel, weights: &[&[f64]]) -> Vec<Vec<f64>> {
        let n = xs.len();
        let nw = weights.len();
        if self.nodes.is_empty() || n == 0 {
            return vec![vec![0.0; n]; nw];
        }
        let boxes = self.boxes(xs, ys);
        let plan = self.plan(xs, &boxes);

        let k = self.opts.order;
        let k2 = k * k;
        let parity = kernel.parity();
        let interpolated = || {
            let mut out = vec![vec![0.0; n]; nw];
            // Proxy charges of every interpolated node.
            let mut used = vec![false; self.nodes.len()];
            for &(a, b) in &plan.m2l {
                used[a] = true;
                used[b] = true;
            }
            let mut charge: Vec<Vec<f64>> = vec![Vec::new(); self.nodes.len()];
            let mut local: Vec<Vec<f64>> = vec![Vec::new(); self.nodes.len()];
            let (mut lx, mut ly) = (vec![0.0; k], vec![0.0; k]);
            for (id, node) in self.nodes.iter().enumerate() {
                if !used[id] {
                    continue;
                }
                let bx = &boxes[id];
                let mut c = vec![0.0; nw * k2];
                for q in node.lo..node.hi {
                    self.basis(xs[q], bx.cx, bx.hx, &mut lx);
                    self.basis(ys[q], bx.cy, bx.hy, &mut ly);
                    for (v, w) in weights.iter().enumerate() {
                        let wq = w[q];
                        let cv = &mut c[v * k2..(v + 1) * k2];
                        for (j1, &a) in lx.iter().enumerate() {
                            let aw = a * wq;
                            for (j2, &b) in ly.iter().enumerate() {
                                cv[j1 * k + j2] += aw * b;
                            }
                        }
                    }
                }
                charge[id] = c;
                local[id] = vec![0.0; nw * k2];
            }
            // Interactions of interpolated pairs.
            let mut row = vec![0.0; k2];
            let (mut zbx, mut zby) = (vec![0.0; k2], vec![0.0; k2]);
            for &(a, b) in &plan.m2l {
                let (ba, bb) = (&boxes[a], &boxes[b]);
                for k1 in 0..k {
                    for k2i in 0..k {
                        zbx[k1 * k + k2i] = bb.cx + bb.hx * self.cheb[k1];
                        zby[k1 * k + k2i] = bb.cy + bb.hy * self.cheb[k2i];
                    }
                }
                let mut la = std::mem::take(&mut local[a]);
                let mut lb = std::mem::take(&mut local[b]);
                for j1 in 0..k {
                    let zax = ba.cx + ba.hx * self.cheb[j1];
                    for j2 in 0..k {
                        let j = j1 * k + j2;
                        let zay = ba.cy + ba.hy * self.cheb[j2];
                        for ((r, &zx), &zy) in row.iter_mut().zip(&zbx).zip(&zby) {
                            let dx = zax - zx;
                            *r = kernel.eval(dx * dx, zay - zy);
                        }
                        for v in 0..nw {
                            let cb = &charge[b][v * k2..(v + 1) * k2];
                            la[v * k2 + j] += dot(&row, cb);
                            let wa = parity * charge[a][v * k2 + j];
                            let lbv = &mut lb[v * k2..(v + 1) * k2];
                            for (l, &r) in lbv.iter_mut().zip(&row) {
                                *l += wa * r;
                            }
                        }
                    }
                }
                local[a] = la;
                local[b] = lb;
            }
            // Evaluate the local interpolants at the birds.
            for (id, node) in self.nodes.iter().enumerate() {
                if !used[id] {
                    continue;
                }
                let bx = &boxes[id];
                let l = &local[id];
                for p in node.lo..node.hi {
                    self.basis(xs[p], bx.cx, bx.hx, &mut lx);
                    self.basis(ys[p], bx.cy, bx.hy, &mut ly);
                    for v in 0..nw {
                        let lv = &l[v * k2..(v + 1) * k2];
                        let mut s = 0.0;
                        for (j1, &a) in lx.iter().enumerate() {
                            s += a * dot(&lv[j1 * k..(j1 + 1) * k], &ly);
                        }
                        out[v][p] += s;
                    }
                }
            }
            out
        };
        let direct = || {
            let mut out = vec![vec![0.0; n]; nw];
            // Direct far pairs.
            let mut t = vec![0.0; n];
            let ranges: Vec<(usize, usize, usize, usize)> = plan
                .selfs
                .iter()
                .map(|&s| {
                    let nd = self.nodes[s];
                    (nd.lo, nd.hi, nd.lo, nd.hi)
                })
                .chain(plan.direct.iter().map(|&(a, b)| {
                    let (na, nb) = (self.nodes[a], self.nodes[b]);
                    (na.lo, na.hi, nb.lo, nb.hi)
                }))
                .collect();
            for (alo, ahi, blo, bhi) in ranges {
                for p in alo..ahi {
                    let start = blo.max(p + 1);
                    let lim = xs[p] + FAR_FIELD;
                    let q0 = start + xs[start..bhi].partition_point(|&v| v < lim);
                    let (xp, yp) = (xs[p], ys[p]);
                    let tt = &mut t[..bhi - q0];
                    for ((t, &xq), &yq) in tt.iter_mut().zip(&xs[q0..bhi]).zip(&ys[q0..bhi]) {
                        let dx = xq - xp;
                        *t = kernel.eval(dx * dx, yp - yq);
                    }
                    for (v, w) in weights.iter().enumerate() {
                        out[v][p] += dot(tt, &w[q0..bhi]);
                        let wp = parity * w[p];
                        for (o, &tv) in out[v][q0..bhi].iter_mut().zip(tt.iter()) {
                            *o += wp * tv;
                        }
                    }
                }
            }
            out
        };
        // The two parts are independent: on two threads for large flocks (the same bits).
        let (mut out, extra) = if n >= PARALLEL_MIN && parallel() {
            std::thread::scope(|s| {
                let d = s.spawn(direct);
                let i = interpolated();
                (i, d.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            })
        } else {
            (interpolated(), direct())
        };
        for (o, e) in out.iter_mut().zip(&extra) {
            for (a, b) in o.iter_mut().zip(e) {
                *a += b;
            }
        }
        out
    }

    /// Lagrange basis of the Chebyshev points on [c − h, c + h] at `v` (barycentric form).
    fn basis(&self, v: f64, c: f64, h: f64, out: &mut [f64]) {
        let s = (v - c) / h;
        let mut total = 0.0;
        for (k, (&t, &w)) in self.cheb.iter().zip(&self.bary).enumerate() {
            let d = s - t;
            if d == 0.0 {
                out.iter_mut().for_each(|o| *o = 0.0);
                out[k] = 1.0;
                return;
            }
            out[k] = w / d;
            total += out[k];
        }
        let inv = 1.0 / total;
        out.iter_mut().for_each(|o| *o *= inv);
    }

    fn boxes(&self, xs: &[f64], ys: &[f64]) -> Vec<BoxInfo> {
        let mut ylo = vec![0.0f64; self.nodes.len()];
        let mut yhi = vec![0.0f64; self.nodes.len()];
        // Children come after their parent: fill from the end.
        for id in (0..self.nodes.len()).rev() {
            let nd = self.nodes[id];
            let (lo, hi) = match nd.kids {
                Some((l, r)) => (ylo[l].min(ylo[r]), yhi[l].max(yhi[r])),
                None => ys[nd.lo..nd.hi].iter().fold(
                    (f64::INFINITY, f64::NEG_INFINITY),
                    |(a, b): (f64, f64), &v| (a.min(v), b.max(v)),
                ),
            };
            ylo[id] = lo;
            yhi[id] = hi;
        }
        self.nodes
            .iter()
            .enumerate()
            .map(|(id, nd)| {
                let (x0, x1): (f64, f64) = (xs[nd.lo], xs[nd.hi - 1]);
                let (y0, y1): (f64, f64) = (ylo[id], yhi[id]);
                // A box of zero width still needs distinct points; any width interpolates a
                // point set inside it.
                let tiny = 1e-9 * (1.0 + x0.abs().max(x1.abs()) + y0.abs().max(y1.abs()));
                BoxInfo {
                    cx: 0.5 * (x0 + x1),
                    hx: (0.5 * (x1 - x0)).max(tiny),
                    cy: 0.5 * (y0 + y1),
                    hy: (0.5 * (y1 - y0)).max(tiny),
                    side: (x1 - x0).max(y1 - y0),
                }
            })
            .collect()
    }

    fn plan(&self, xs: &[f64], boxes: &[BoxInfo]) -> Plan {
        let mut plan = Plan {
            m2l: Vec::new(),
            direct: Vec::new(),
            selfs: Vec::new(),
        };
        let k = self.opts.order;
        let cost = (k * k * k * k) as f64;
        let mut stack: Vec<(usize, usize)> = vec![(0, 0)];
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (self.nodes[a], self.nodes[b]);
            if a == b {
                if xs[na.hi - 1] - xs[na.lo] < FAR_FIELD {
                    continue;
                }
                match na.kids {
                    None => plan.selfs.push(a),
                    Some((l, r)) => {
                        stack.push((l, r));
                        stack.push((r, r));
                        stack.push((l, l));
                    }
                }
                continue;
            }
            // a is left of b in sorted order.
            if xs[nb.hi - 1] - xs[na.lo] < FAR_FIELD {
                continue;
            }
            let gap = xs[nb.lo] - xs[na.hi - 1];
            let side = boxes[a].side.max(boxes[b].side);
            if gap >= FAR_FIELD && side <= self.opts.theta * gap {
                let pairs = ((na.hi - na.lo) * (nb.hi - nb.lo)) as f64;
                if pairs > cost {
                    plan.m2l.push((a, b));
                } else {
                    plan.direct.push((a, b));
                }
                continue;
            }
            match (na.kids, nb.kids) {
                (None, None) => plan.direct.push((a, b)),
                (Some((l, r)), None) => {
                    stack.push((r, b));
                    stack.push((l, b));
                }
                (None, Some((l, r))) => {
                    stack.push((a, r));
                    stack.push((a, l));
                }
                (Some((al, ar)), Some((bl, br))) => {
                    if na.hi - na.lo >= nb.hi - nb.lo {
                        stack.push((ar, b));
                        stack.push((al, b));
                    } else {
                        stack.push((a, br));
                        stack.push((a, bl));
                    }
                }
            }
        }
        plan
    }
}

#[derive(Debug, Clone, Copy)]
struct BoxInfo {
    cx: f64,
    hx: f64,
    cy: f64,
    hy: f64,
    side: f64,
}

fn build(nodes: &mut Vec<Node>, lo: usize, hi: usize, leaf: usize) -> usize {
    let id = nodes.len();
    nodes.push(Node { lo, hi, kids: None });
    if hi - lo > leaf {
        let mid = lo + (hi - lo) / 2;
        let l = build(nodes, lo, mid, leaf);
        let r = build(nodes, mid, hi, leaf);
        nodes[id].kids = Some((l, r));
    }
    id
}

/// Σ a_i b_i in four lanes (a fixed order, so that it vectorises and gives the same bits
/// everywhere).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            lanes[l] += x[l] * y[l];
        }
    }
    for (x, y) in ra.iter().zip(rb) {
        lanes[0] += x * y;
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use rand::Rng;

    fn direct_sum(xs: &[f64], ys: &[f64], kernel: Kernel, w: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = xs.len();
        let mut out = vec![0.0; n];
        let mut mag = vec![0.0; n];
        for p in 0..n {
            for q in 0..n {
                if (xs[p] - xs[q]).abs() >= FAR_FIELD {
                    let dx = xs[p] - xs[q];
                    let t = kernel.eval(dx * dx, ys[p] - ys[q]) * w[q];
                    out[p] += t;
                    mag[p] += t.abs();
                }
            }
        }
        (out, mag)
    }

    /// Sorted flocks: a V at real spacing (noisy), an echelon, and a scattered cloud.
    fn flocks() -> Vec<(Vec<f64>, Vec<f64>)> {
        let mut rng = seeded(5);
        let mut out = Vec::new();
        let n = 2500;
        let mut v: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let rank = (k as usize).div_ceil(2) as f64;
                let side = if k % 2 == 1 { 1.0 } else { -1.0 };
                let x = side * rank * rng.random_range(0.6..1.1);
                (x, rank * 0.55 + rng.random_range(-0.3..0.3))
            })
            .collect();
        let ech: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                (
                    k as f64 * 0.77,
                    k as f64 * 0.4 + rng.random_range(-1.0..1.0),
                )
            })
            .collect();
        let cloud: Vec<(f64, f64)> = (0..n)
            .map(|_| {
                (
                    rng.random_range(-800.0..800.0),
                    rng.random_range(-500.0..500.0),
                )
            })
            .collect();
        for mut f in [std::mem::take(&mut v), ech, cloud] {
            f.sort_by(|a, b| a.0.total_cmp(&b.0));
            out.push((
                f.iter().map(|p| p.0).collect(),
                f.iter().map(|p| p.1).collect(),
            ));
        }
        out
    }

    #[test]
    fn interpolated_far_sums_match_the_direct_sums() {
        let mut rng = seeded(9);
        for (case, (xs, ys)) in flocks().into_iter().enumerate() {
            let n = xs.len();
            let tree = FarTree::new(n, TreeOptions::default());
            let w: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let ones = vec![1.0; n];
            for kernel in [Kernel::Odd, Kernel::Slope] {
                let got = tree.sum(&xs, &ys, kernel, &[&ones, &w]);
                for (v, wv) in [&ones, &w].into_iter().enumerate() {
                    let (want, mag) = direct_sum(&xs, &ys, kernel, wv);
                    let scale = mag.iter().copied().fold(0.0, f64::max);
                    let worst = got[v]
                        .iter()
                        .zip(&want)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    assert!(
                        worst <= 1e-6 * scale,
                        "case {case} {kernel:?} weights {v}: error {worst:e} of {scale:e}"
                    );
                }
            }
        }
    }
}
