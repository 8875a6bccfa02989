//! The key-shape solve of eq. (4): given the birds' lateral positions and target relative power
//! reductions ξ̂, find the longitudinal positions that realise them, with the
//! `levenberg-marquardt` crate and an analytic Jacobian.
//!
//! ```math
//! e_i(y) = \hat\xi_i\,E, \qquad i = 1..N, \qquad E = \sum_{i<j} 2\,g(|x_i - x_j|, 0)
//! ```
//!
//! (Klotsman & Tal eq. 3–4). By Munk's stagger theorem E depends only on the lateral positions, so
//! it is computed once ([`crate::aero::munk_total`]) and the targets are renormalised to Σξ̂ = 1.
//! Unknowns: the N − 1 longitudinal positions of every bird but one (held fixed, since only
//! differences matter); residuals: r_i = ξ_i(y) − ξ̂_i for all N birds; Jacobian
//! ∂r_i/∂y_k = (1/E)·∂e_i/∂y_k, computed with e in one pass over the pairs
//! ([`crate::aero::power_and_jacobian_unchecked`]).
//!
//! e(y) is the gradient of the convex potential Σ_{i<j} G(x_ij, y_i − y_j) with ∂G/∂y = g, so
//! the system has a solution (unique up to a common shift) exactly when ξ̂·E lies in the interior
//! of the gradient's range: every subset S of birds must ask for a share strictly between what
//! the pairs inside S give (if everyone else flew infinitely far ahead) and that plus the pairs
//! crossing S's boundary. [`reachability`] decides this with one minimum cut and names the birds
//! of a violating subset; [`solve`] runs it first, so an impossible request is an error that says
//! which birds ask for the impossible, never a wild shape. "Converged" means the residual
//! ‖ξ − ξ̂‖₂ is below the tolerance, never the LM termination status alone.
//!
//! Symbols → code: x → `x`, ξ̂ → `xi_target` (renormalised: `target`), y → [`SolveReport::y`],
//! E → `total`.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use crate::aero;
use crate::error::{Error, Result};

/// Options of [`solve`].
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Converged means ‖ξ − ξ̂‖₂ ≤ this (dimensionless; ξ sums to 1).
    pub tolerance: f64,
    /// LM's budget: at most `patience·N` model evaluations per attempt.
    pub patience: usize,
    /// Check that the targets are reachable before solving (one minimum cut). Done up front for
    /// flocks up to [`SolveOptions::direct_limit`] birds; larger flocks are checked only when the
    /// solve fails, to explain why.
    pub check_reachable: bool,
    /// Largest flock solved with the `levenberg-marquardt` crate (MINPACK's pivoted-QR LM, the
    /// paper's method). Beyond it, each of that method's trial steps costs a dense O(N³) QR and
    /// O(N³) Givens updates (20 s for N = 1000), so the same Levenberg–Marquardt iteration runs
    /// in the symmetric form of [`solve_symmetric`] (one Cholesky per trial step).
    pub direct_limit: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tolerance: 1e-9,
            patience: 100,
            check_reachable: true,
            direct_limit: 200,
        }
    }
}

impl SolveOptions {
    /// Checks the options; errors name the option path (`solve.tolerance`).
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Error::parameter(
                "solve.tolerance",
                "must be a positive number",
            ));
        }
        Ok(())
    }
}

/// Outcome of a solve. Non-convergence is not an error: read `converged`.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveReport {
    /// Longitudinal positions, distance behind the front-most bird (which is at 0), wingspans.
    pub y: Vec<f64>,
    /// ξ achieved at `y`.
    pub xi: Vec<f64>,
    /// The renormalised targets ξ̂ (Σ = 1).
    pub target: Vec<f64>,
    /// ‖ξ − ξ̂‖₂.
    pub residual: f64,
    /// Model evaluations used (residual evaluations, all attempts).
    pub evaluations: usize,
    /// `residual <= tolerance`.
    pub converged: bool,
    /// Total power reduction E (fixed by the lateral positions).
    pub total: f64,
    /// Which iteration produced the result and why it stopped, for diagnostics.
    pub termination: String,
}

/// The least-squares problem handed to the LM crate.
struct KeyShapeProblem<'a> {
    x: &'a [f64],
    target: &'a [f64],
    total: f64,
    /// Index of the bird whose y stays fixed.
    fixed: usize,
    /// Full y vector (fixed bird included).
    y: Vec<f64>,
    /// e_i at `y`.
    e: Vec<f64>,
    /// ∂e_i/∂y_k at `y`, row-major N×N (computed with `e`: the pairs share their square roots).
    jac: Vec<f64>,
}

impl<'a> KeyShapeProblem<'a> {
    fn new(x: &'a [f64], target: &'a [f64], total: f64, y0: &[f64], fixed: usize) -> Self {
        let y = y0.to_vec();
        let (e, jac) = aero::power_and_jacobian_unchecked(x, &y);
        KeyShapeProblem {
            x,
            target,
            total,
            fixed,
            y,
            e,
            jac,
        }
    }

    /// Position in the parameter vector → bird index.
    fn bird(&self, p: usize) -> usize {
        if p < self.fixed {
            p
        } else {
            p + 1
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for KeyShapeProblem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, p: &DVector<f64>) {
        for k in 0..p.len() {
            let b = self.bird(k);
            self.y[b] = p[k];
        }
        (self.e, self.jac) = aero::power_and_jacobian_unchecked(self.x, &self.y);
    }

    fn params(&self) -> DVector<f64> {
        let n = self.y.len();
        DVector::from_iterator(n - 1, (0..n - 1).map(|k| self.y[self.bird(k)]))
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = DVector::from_iterator(
            self.e.len(),
            self.e
                .iter()
                .zip(self.target)
                .map(|(e, t)| e / self.total - t),
        );
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let n = self.y.len();
        let inv = 1.0 / self.total;
        let jac = DMatrix::from_fn(n, n - 1, |i, k| self.jac[i * n + self.bird(k)] * inv);
        jac.iter().all(|v| v.is_finite()).then_some(jac)
    }
}

/// Validates the inputs of [`solve`] and returns the renormalised targets.
fn validate(x: &[f64], xi_target: &[f64], y0: Option<&[f64]>) -> Result<Vec<f64>> {
    let n = x.len();
    if n < 2 {
        return Err(Error::parameter(
            "x",
            format!("{n} bird(s) given, at least 2 needed"),
        ));
    }
    if xi_target.len() != n {
        return Err(Error::parameter(
            "xi",
            format!(
                "{} targets for {n} lateral positions; give one ξ per bird",
                xi_target.len()
            ),
        ));
    }
    if let Some(i) = xi_target.iter().position(|v| !v.is_finite()) {
        return Err(Error::parameter(format!("xi[{i}]"), "not a finite number"));
    }
    if let Some(i) = xi_target.iter().position(|&v| v < 0.0) {
        return Err(Error::parameter(
            format!("xi[{i}]"),
            format!(
                "negative target {}; relative power reductions are positive",
                xi_target[i]
            ),
        ));
    }
    let sum: f64 = xi_target.iter().sum();
    if !(sum > 0.0) {
        return Err(Error::parameter(
            "xi",
            "all targets are zero; give each bird a positive relative power reduction",
        ));
    }
    if let Some(y0) = y0 {
        if y0.len() != n {
            return Err(Error::parameter(
                "y",
                format!("{} initial positions for {n} birds", y0.len()),
            ));
        }
        if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
            return Err(Error::parameter(format!("y[{i}]"), "not a finite number"));
        }
    }
    aero::check_lateral(x)?;
    Ok(xi_target.iter().map(|v| v / sum).collect())
}

/// Solves eq. (4): longitudinal positions y such that ξ(x, y) = ξ̂ (renormalised to sum to 1),
/// starting from `y0` if given, else from the line abreast y = 0 (where every pair splits its
/// savings evenly: the one start that favours no bird). The output is shifted so that the
/// front-most bird is at y = 0.
///
/// Errors: fewer than 2 birds, mismatched lengths, non-finite values, negative or all-zero
/// targets ([`Error::Parameter`]); a pair within π/4 laterally ([`Error::Downwash`]); targets
/// that no placement reaches ([`Error::Unreachable`], naming the birds). A feasible target on
/// which LM stalls is returned with `converged == false`.
pub fn solve(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    opts: &SolveOptions,
) -> Result<SolveReport> {
    let target = validate(x, xi_target, y0)?;
    let total = aero::munk_total_unchecked(x);
    let n = x.len();
    let small = n <= opts.direct_limit;
    if opts.check_reachable && small {
        reachability(x, &target, total)?;
    }
    let zeros = vec![0.0; n];
    let run = |start: &[f64]| {
        if small {
            attempt(x, &target, total, start, opts)
        } else {
            solve_symmetric(x, &target, total, start, opts)
        }
    };
    let mut best = run(y0.unwrap_or(&zeros));
    if !best.converged && y0.is_some() {
        // A poor guess can strand LM on a plateau of g; the neutral start is the fallback.
        let retry = run(&zeros);
        let evaluations = best.evaluations + retry.evaluations;
        if retry.residual < best.residual {
            best = retry;
        }
        best.evaluations = evaluations;
    }
    if !best.converged && opts.check_reachable && !small {
        reachability(x, &target, total)?;
    }
    Ok(best)
}

fn attempt(x: &[f64], target: &[f64], total: f64, y0: &[f64], opts: &SolveOptions) -> SolveReport {
    let n = x.len();
    // The front-most bird of the start stays fixed; only differences of y matter.
    let fixed = (0..n)
        .min_by(|&a, &b| y0[a].total_cmp(&y0[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let problem = KeyShapeProblem::new(x, target, total, y0, fixed);
    let lm = LevenbergMarquardt::new()
        .with_ftol(1e-15)
        .with_xtol(1e-15)
        .with_gtol(1e-15)
        .with_patience(opts.patience.max(1));
    let (problem, lm_report) = lm.minimize(problem);
    let y = if problem.y.iter().all(|v| v.is_finite()) {
        problem.y
    } else {
        y0.to_vec()
    };
    report(
        x,
        target,
        total,
        y,
        lm_report.number_of_evaluations,
        opts.tolerance,
        format!("levenberg-marquardt crate: {:?}", lm_report.termination),
    )
}

/// Builds the report for positions `y` (shifted so that the front-most bird is at 0).
fn report(
    x: &[f64],
    target: &[f64],
    total: f64,
    mut y: Vec<f64>,
    evaluations: usize,
    tolerance: f64,
    termination: String,
) -> SolveReport {
    let e = aero::power_unchecked(x, &y);
    let xi: Vec<f64> = e.iter().map(|v| v / total).collect();
    let residual = norm_diff(&xi, target);
    let front = y.iter().copied().fold(f64::INFINITY, f64::min);
    for v in &mut y {
        *v -= front;
    }
    SolveReport {
        y,
        xi,
        target: target.to_vec(),
        residual,
        evaluations,
        converged: residual.is_finite() && residual <= tolerance,
        total,
        termination,
    }
}

fn norm_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
}

/// Levenberg–Marquardt for large flocks, in the form the problem's symmetry allows.
///
/// The Jacobian J = (1/E)·∂e/∂y is a weighted graph Laplacian: symmetric, and positive definite
/// once the fixed bird's row and column are removed. So the LM step
/// ```math
/// (J + \lambda\,\bar d\,I)\,\delta = -r
/// ```
/// (d̄ the mean diagonal of J; r and J restricted to the free birds) is a descent direction of
/// ‖r‖² for every λ ≥ 0, is found with one
/// Cholesky factorisation of an (N−1)×(N−1) matrix, and λ follows Marquardt's rule: divided by
/// 10 after a step that lowers ‖r‖, multiplied by 10 (and the step retried) after one that does
/// not. Stops at the tolerance, after `patience` Jacobians, or when λ exceeds 10¹².
pub fn solve_symmetric(
    x: &[f64],
    target: &[f64],
    total: f64,
    y0: &[f64],
    opts: &SolveOptions,
) -> SolveReport {
    let n = x.len();
    let fixed = (0..n)
        .min_by(|&a, &b| y0[a].total_cmp(&y0[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let free: Vec<usize> = (0..n).filter(|&i| i != fixed).collect();
    let m = free.len();
    let evaluate = |y: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let (e, jac) = aero::power_and_jacobian_unchecked(x, y);
        let r = e.iter().zip(target).map(|(e, t)| e / total - t).collect();
        (r, jac)
    };
    // Merit: the free birds' residuals (the fixed bird's is minus their sum, since Σξ = Σξ̂ = 1);
    // in this norm the damped step is a descent direction for every λ.
    let merit = |r: &[f64]| -> f64 { free.iter().map(|&i| r[i] * r[i]).sum::<f64>().sqrt() };
    let mut y = y0.to_vec();
    let (mut r, mut full) = evaluate(&y);
    let mut norm = merit(&r);
    let mut evaluations = 1;
    let mut lambda = 1e-3;
    let mut why = "iteration budget exhausted";
    let stop = opts.tolerance * 1e-3;
    'outer: for _ in 0..opts.patience.max(1) {
        if norm <= stop {
            why = "residual below tolerance";
            break;
        }
        let inv = 1.0 / total;
        let jac = DMatrix::from_fn(m, m, |a, b| full[free[a] * n + free[b]] * inv);
        let mean_diag = (0..m).map(|a| jac[(a, a)]).sum::<f64>() / m as f64;
        let rhs = DVector::from_iterator(m, free.iter().map(|&i| -r[i]));
        loop {
            let mut damped = jac.clone();
            for a in 0..m {
                damped[(a, a)] += lambda * mean_diag;
            }
            let Some(chol) = damped.cholesky() else {
                lambda *= 10.0;
                if lambda > 1e12 {
                    why = "damped Jacobian not positive definite";
                    break 'outer;
                }
                continue;
            };
            let step = chol.solve(&rhs);
            let mut trial = y.clone();
            for (a, &i) in free.iter().enumerate() {
                trial[i] += step[a];
            }
            let (tr, tjac) = evaluate(&trial);
            evaluations += 1;
            let tnorm = merit(&tr);
            if tnorm.is_finite() && tnorm < norm {
                y = trial;
                r = tr;
                full = tjac;
                norm = tnorm;
                lambda = (lambda / 10.0).max(1e-15);
                break;
            }
            lambda *= 10.0;
            if lambda > 1e12 {
                why = "no step lowers the residual";
                break 'outer;
            }
        }
    }
    report(
        x,
        target,
        total,
        y,
        evaluations,
        opts.tolerance,
        format!("symmetric Levenberg–Marquardt: {why}"),
    )
}

/// Decides whether renormalised targets `target` (Σ = 1) are reachable for lateral positions
/// `x` with total `total` (= [`aero::munk_total`]), and names the birds of a violating subset
/// when they are not ([`Error::Unreachable`]).
///
/// Each pair (i, j) contributes w_ij = 2g(x_ij, 0)/E to ξ, split between its two birds by their
/// stagger (all to the rear bird as the stagger → ∞). A subset T asks too little when
/// ξ̂(T) ≤ W(T), the pairs inside T; maximising W(T) − ξ̂(T) over T is a minimum cut
/// (Goldberg's densest-subgraph construction): b_i = ξ̂_i − deg_i/2, arcs i↔j of capacity
/// w_ij/2, s→i of capacity −b_i where b_i < 0, i→t of capacity b_i where b_i > 0.
pub fn reachability(x: &[f64], target: &[f64], total: f64) -> Result<()> {
    let n = x.len();
    let mut w = vec![0.0; n * n];
    let mut deg = vec![0.0; n];
    for i in 0..n {
        for j in (i + 1)..n {
            let v = 2.0 * aero::g0((x[i] - x[j]).abs()) / total;
            w[i * n + j] = v;
            w[j * n + i] = v;
            deg[i] += v;
            deg[j] += v;
        }
    }
    // Singletons first: the common, easily explained cases (and the boundary ξ̂_i = 0, which the
    // cut cannot distinguish from the empty set).
    for i in 0..n {
        if !(target[i] > 0.0) {
            return Err(Error::Unreachable(format!(
                "bird {i} asks for ξ = 0, but every bird gains from its flockmates wherever it flies; give it a positive share"
            )));
        }
        if !(target[i] < deg[i]) {
            return Err(Error::Unreachable(format!(
                "bird {i} asks for ξ = {:.6}, more than all its pairs can give it (at most {:.6}, with every other bird infinitely far ahead)",
                target[i], deg[i]
            )));
        }
    }
    if n <= 2 {
        return Ok(());
    }
    let b: Vec<f64> = (0..n).map(|i| target[i] - deg[i] / 2.0).collect();
    let s = n;
    let t = n + 1;
    let m = n + 2;
    let mut cap = vec![0.0; m * m];
    let mut neg = 0.0;
    for i in 0..n {
        for j in 0..n {
            if i != j {
                cap[i * m + j] = w[i * n + j] / 2.0;
            }
        }
        if b[i] > 0.0 {
            cap[i * m + t] = b[i];
        } else {
            cap[s * m + i] = -b[i];
            neg += -b[i];
        }
    }
    let flow = max_flow_dense(&mut cap, m, s, t);
    let objective = flow - neg;
    let tol = 1e-12;
    if objective >= -tol {
        return Ok(());
    }
    // Source side of the minimum cut = the subset T that asks too little.
    let side = reachable_from(&cap, m, s);
    let tset: Vec<usize> = (0..n).filter(|&i| side[i]).collect();
    let sset: Vec<usize> = (0..n).filter(|&i| !side[i]).collect();
    let inside = |set: &[usize]| -> f64 {
        let mut acc = 0.0;
        for (k, &i) in set.iter().enumerate() {
            for &j in &set[k + 1..] {
                acc += w[i * n + j];
            }
        }
        acc
    };
    let ask = |set: &[usize]| -> f64 { set.iter().map(|&i| target[i]).sum() };
    let list = |set: &[usize]| -> String {
        set.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if tset.len() <= sset.len() || sset.is_empty() {
        Err(Error::Unreachable(format!(
            "birds {} ask for ξ = {:.6} together, but the pairs among them alone give them at least {:.6} however far back the others fly; raise their targets or lower the others'",
            list(&tset),
            ask(&tset),
            inside(&tset)
        )))
    } else {
        let most: f64 = 1.0 - inside(&tset);
        Err(Error::Unreachable(format!(
            "birds {} ask for ξ = {:.6} together, but all the pairs they belong to give them at most {:.6} even with every other bird infinitely far ahead; lower their targets or raise the others'",
            list(&sset),
            ask(&sset),
            most
        )))
    }
}

/// Dinic's maximum flow on a dense capacity matrix (modified in place into the residual graph).
fn max_flow_dense(cap: &mut [f64], m: usize, s: usize, t: usize) -> f64 {
    let scale: f64 = cap.iter().copied().fold(0.0, f64::max);
    let eps = scale * 1e-14;
    let mut flow = 0.0;
    let mut level = vec![usize::MAX; m];
    let mut queue = Vec::with_capacity(m);
    let mut next = vec![0usize; m];
    loop {
        level.iter_mut().for_each(|l| *l = usize::MAX);
        level[s] = 0;
        queue.clear();
        queue.push(s);
        let mut head = 0;
        while head < queue.len() {
            let u = queue[head];
            head += 1;
            for v in 0..m {
                if level[v] == usize::MAX && cap[u * m + v] > eps {
                    level[v] = level[u] + 1;
                    queue.push(v);
                }
            }
        }
        if level[t] == usize::MAX {
            return flow;
        }
        next.iter_mut().for_each(|p| *p = 0);
        loop {
            let pushed = augment(cap, m, s, t, f64::INFINITY, &level, &mut next, eps);
            if pushed <= eps {
                break;
            }
            flow += pushed;
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn augment(
    cap: &mut [f64],
    m: usize,
    u: usize,
    t: usize,
    limit: f64,
    level: &[usize],
    next: &mut [usize],
    eps: f64,
) -> f64 {
    if u == t {
        return limit;
    }
    while next[u] < m {
        let v = next[u];
        let c = cap[u * m + v];
        if c > eps && level[v] == level[u] + 1 {
            let got = augment(cap, m, v, t, limit.min(c), level, next, eps);
            if got > eps {
                cap[u * m + v] -= got;
                cap[v * m + u] += got;
                return got;
            }
        }
        next[u] += 1;
    }
    0.0
}

fn reachable_from(cap: &[f64], m: usize, s: usize) -> Vec<bool> {
    let scale: f64 = cap.iter().copied().fold(0.0, f64::max);
    let eps = scale * 1e-14;
    let mut seen = vec![false; m];
    let mut stack = vec![s];
    seen[s] = true;
    while let Some(u) = stack.pop() {
        for v in 0..m {
            if !seen[v] && cap[u * m + v] > eps {
                seen[v] = true;
                stack.push(v);
            }
        }
    }
    seen
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v_shape(n: usize, gap: f64, depth: f64) -> (Vec<f64>, Vec<f64>) {
        // Leader in the middle, arms alternating right/left.
        let mut x = vec![0.0];
        let mut y = vec![0.0];
        for k in 1..n {
            let rank = k.div_ceil(2) as f64;
            let side = if k % 2 == 1 { 1.0 } else { -1.0 };
            x.push(side * rank * gap);
            y.push(rank * depth);
        }
        (x, y)
    }

    #[test]
    fn round_trip_v() {
        let (x, y) = v_shape(9, 1.0, 0.6);
        let pr = aero::power_reduction(&x, &y).unwrap();
        let guess: Vec<f64> = y.iter().map(|v| v * 1.3 + 0.1).collect();
        let rep = solve(&x, &pr.xi, Some(&guess), &SolveOptions::default()).unwrap();
        assert!(rep.converged, "{rep:?}");
        for (a, b) in rep.y.iter().zip(&y) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn zero_target_is_unreachable() {
        let (x, _) = v_shape(5, 1.0, 0.6);
        let err = solve(
            &x,
            &[0.0, 0.25, 0.25, 0.25, 0.25],
            None,
            &SolveOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(err, Error::Unreachable(_)));
        assert!(err.to_string().contains("bird 0"), "{err}");
    }

    #[test]
    fn cut_finds_pair_asking_too_little() {
        // Two close pairs far apart. Birds 0 and 1 together ask for less than their own pair
        // gives them, while every bird alone asks for something it could get.
        let x = [0.0, 0.9, 5.0, 6.0];
        let total = aero::munk_total(&x).unwrap();
        let w01 = 2.0 * aero::g0(0.9) / total;
        let a = 0.45 * w01;
        let b = (1.0 - 2.0 * a) / 2.0;
        let err = solve(&x, &[a, a, b, b], None, &SolveOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, Error::Unreachable(_)));
        assert!(msg.contains("birds 0, 1 "), "{msg}");
        // The ξ of an actual placement is reachable, from the neutral start.
        let xi = aero::power_reduction(&x, &[0.0, 1.0, 0.5, 2.0]).unwrap().xi;
        let rep = solve(&x, &xi, None, &SolveOptions::default()).unwrap();
        assert!(rep.converged, "{rep:?}");
    }
}
