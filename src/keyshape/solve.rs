//! The key-shape solve of eq. (4): given the birds' lateral positions and target relative savings
//! ξ̂, find the longitudinal positions that realise them, by Newton's method on the symmetric
//! system: up to [`SolveOptions::dense_limit`] birds with a dense Cholesky factorisation per step
//! (a Levenberg–Marquardt damping when a full step does not lower the residual), beyond by
//! conjugate gradients on the exact Jacobian with a banded Cholesky preconditioner
//! ([`crate::aero::Field`] sums every pair in O(N²) without storing anything of that size).
//!
//! ```math
//! e_i(y) = \hat\xi_i\,E, \qquad i = 1..N, \qquad E = \sum_{i<j} 2\,g(|x_i - x_j|, 0)
//! ```
//!
//! (Klotsman & Tal eq. 3–4). By Munk's stagger theorem E depends only on the lateral positions, so
//! it is computed once ([`crate::aero::AeroOptions::munk_total`]) and the targets are renormalised
//! to Σξ̂ = 1. Unknowns: the N − 1 longitudinal positions of every bird but one (held fixed, since
//! only differences matter); residuals r_i = ξ_i(y) − ξ̂_i; Jacobian ∂r_i/∂y_k = (1/E)·∂e_i/∂y_k.
//!
//! e(y) is the gradient of the potential Φ(y) = Σ_{i<j} G(x_ij, y_i − y_j) with ∂G/∂y = g, and
//! ∂g/∂y > 0, so the Jacobian is a weighted graph Laplacian: symmetric, positive definite once
//! one bird is fixed. Pairs whose wings overlap laterally (under one wingspan apart) cannot pass
//! each other without colliding, and for overlapping wingtips (x < π/4) g has a pole at y = 0,
//! so the solve keeps the **fore-aft order of those pairs** as it is in the start (a step is
//! shortened so that no such pair changes order). Within one order Φ is strictly convex: the
//! solution is unique up to a shift when it exists, and it exists exactly when every subset of
//! birds asks for a share between what its pairs can give it ([`reachability`], one maximum flow,
//! which names the birds of a violating subset). "Converged" means ‖ξ − ξ̂‖₂ ≤ tolerance.
//!
//! Symbols → code: x → `x`, ξ̂ → `xi_target` (renormalised: `target`), y → [`SolveReport::y`],
//! E → `total`.

use std::cell::Cell;

use nalgebra::{DMatrix, DVector};

use crate::aero::{AeroOptions, ApproxField, Field, TreeOptions, COLLISION_SPAN};
use crate::error::{Error, Result};
use crate::progress::{Progress, Silent};

/// Options of [`solve`].
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Converged means ‖ξ − ξ̂‖₂ ≤ this (dimensionless; ξ sums to 1).
    pub tolerance: f64,
    /// Budget: at most this many Jacobians (Newton steps) per attempt.
    pub patience: usize,
    /// Check that the targets are reachable before solving (one maximum flow). Done up front for
    /// flocks up to [`SolveOptions::check_limit`] birds; larger flocks are checked only when the
    /// solve fails, to explain why.
    pub check_reachable: bool,
    /// Largest flock whose reachability is checked before solving (the check is a dense maximum
    /// flow, O(N³) in the worst case), birds.
    pub check_limit: usize,
    /// Largest flock solved with the exact dense Jacobian (one dense Cholesky per step, O(N³)),
    /// birds. Larger flocks use Newton–conjugate gradients preconditioned by the band of
    /// [`SolveOptions::band_span`].
    pub dense_limit: usize,
    /// For flocks above `dense_limit`: the preconditioner of the Newton steps' conjugate
    /// gradients is the Jacobian of the pairs less than this far apart laterally (∂g/∂y decays
    /// like a²/R³), a banded matrix once the birds are sorted by x, factorised in O(N·b²); the
    /// residual and the Jacobian products stay exact. Wingspans, at most
    /// [`crate::aero::FAR_FIELD`] (larger values act as it).
    pub band_span: f64,
    /// For flocks above `dense_limit`: most conjugate-gradient products per Newton step.
    pub cg_limit: usize,
    /// Flocks of at least this many birds iterate with the far pairs interpolated
    /// ([`crate::aero::ApproxField`]) and check the result with the exact sums (the reported
    /// residual is always exact), birds.
    pub interpolate_from: usize,
    /// The interpolation of the far pairs for `interpolate_from`.
    pub interpolation: TreeOptions,
    /// The aerodynamic model's core radius and collision distance.
    pub aero: AeroOptions,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tolerance: 1e-9,
            patience: 100,
            check_reachable: true,
            check_limit: 200,
            dense_limit: 100,
            band_span: 60.0,
            cg_limit: 50,
            interpolate_from: 2000,
            interpolation: TreeOptions::default(),
            aero: AeroOptions::default(),
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
    /// Total saving E (fixed by the lateral positions).
    pub total: f64,
    /// Which iteration produced the result and why it stopped, for diagnostics.
    pub termination: String,
}

/// Validates the inputs of [`solve`] and returns the renormalised targets.
fn validate(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    aero: &AeroOptions,
) -> Result<Vec<f64>> {
    aero.validate()?;
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
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(Error::parameter(
            format!("x[{i}]"),
            "lateral position is not a finite number",
        ));
    }
    if let Some(i) = xi_target.iter().position(|v| !v.is_finite()) {
        return Err(Error::parameter(format!("xi[{i}]"), "not a finite number"));
    }
    let sum: f64 = xi_target.iter().sum();
    if !(sum > 0.0) {
        return Err(Error::parameter(
            "xi",
            format!("the targets sum to {sum}; relative savings sum to 1 (negative values are allowed for birds in downwash, but not a non-positive total)"),
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
        aero.check_shape(x, y0)?;
    }
    Ok(xi_target.iter().map(|v| v / sum).collect())
}

/// The solver's own starts when no guess is given, in the order they are tried. With every pair
/// at least one wingspan apart laterally it is the **line abreast** y = 0 alone, where every pair
/// splits its saving evenly (the one start that favours no bird). Otherwise the line abreast
/// collides, and the fore-aft order of the laterally overlapping pairs has to be chosen (the
/// solve keeps it; each order has at most one solution):
///
/// 1. a **V** behind the bird with the smallest non-negative target (the bird that gains least
///    flies in front; a negative target is a bird in downwash, which is behind): y_i = |x_i − x_m| (45° arms), the right arm one collision chord further back so
///    that birds at equal distances on both arms are not abreast: every overlapping pair in
///    lateral order away from the leader, as in the V, J, echelon and U of real flocks;
/// 2. an order **by targets**: in a pair the bird in front gets less than half the pair's
///    saving, so birds are placed in order of increasing target, negative targets last (ties:
///    lower index first), each
///    two collision chords behind the rearmost already placed bird it overlaps laterally.
pub fn default_starts(x: &[f64], target: &[f64], aero: &AeroOptions) -> Vec<Vec<f64>> {
    let n = x.len();
    let zeros = vec![0.0; n];
    if aero.first_collision(x, &zeros).is_none() {
        return vec![zeros];
    }
    let chord = aero.collision_chord.max(1e-3);
    // A negative target is a bird in downwash, i.e. behind: it neither leads nor goes in front.
    let rank = |i: usize| (target[i] < 0.0, target[i]);
    let by_rank = |a: &usize, b: &usize| {
        let (ra, rb) = (rank(*a), rank(*b));
        ra.0.cmp(&rb.0).then(ra.1.total_cmp(&rb.1)).then(a.cmp(b))
    };
    let m = (0..n).min_by(by_rank).unwrap_or(0);
    let v: Vec<f64> = x
        .iter()
        .map(|&xi| (xi - x[m]).abs() + if xi > x[m] { chord } else { 0.0 })
        .collect();
    let step = 2.0 * chord;
    let mut by_x: Vec<usize> = (0..n).collect();
    by_x.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let sorted_x: Vec<f64> = by_x.iter().map(|&i| x[i]).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(by_rank);
    let mut y = vec![f64::NAN; n];
    for &i in &order {
        let lo = sorted_x.partition_point(|&v| v <= x[i] - COLLISION_SPAN);
        let mut yi: f64 = 0.0;
        for &j in by_x[lo..]
            .iter()
            .take_while(|&&j| x[j] < x[i] + COLLISION_SPAN)
        {
            if j != i && y[j].is_finite() {
                yi = yi.max(y[j] + step);
            }
        }
        y[i] = yi;
    }
    if ordered_pairs(x, &v) == ordered_pairs(x, &y) {
        vec![v]
    } else {
        vec![v, y]
    }
}

/// Pairs (front, rear) whose fore-aft order the solve keeps: lateral distance under one
/// wingspan, ordered as in `y` (ties: lower index in front).
pub fn ordered_pairs(x: &[f64], y: &[f64]) -> Vec<(usize, usize)> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let mut out = Vec::new();
    for (k, &i) in idx.iter().enumerate() {
        for &j in &idx[k + 1..] {
            if !(x[j] - x[i] < COLLISION_SPAN) {
                break;
            }
            let (a, b) = (i.min(j), i.max(j));
            if y[b] < y[a] {
                out.push((b, a));
            } else {
                out.push((a, b));
            }
        }
    }
    out
}

/// Solves eq. (4): longitudinal positions y such that ξ(x, y) = ξ̂ (renormalised to sum to 1),
/// starting from `y0` if given, else from [`default_starts`]. The output is shifted so that the
/// front-most bird is at y = 0.
///
/// Errors: fewer than 2 birds, mismatched lengths, non-finite values, targets that do not sum
/// to a positive number ([`Error::Parameter`]); a start whose birds collide, or a solution that
/// only exists with two birds' wings side by side ([`Error::Collision`]); targets that no
/// placement reaches ([`Error::Unreachable`], naming the birds). A feasible target on which the
/// iteration stalls is returned with `converged == false`.
pub fn solve(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    opts: &SolveOptions,
) -> Result<SolveReport> {
    solve_with_progress(x, xi_target, y0, opts, &Silent)
}

/// [`solve`] reporting its progress to `progress`: one stage "solve" of 100 units, the fraction
/// of the way from the first residual to the tolerance in orders of magnitude (Newton's steps
/// gain more of them as they go, so the bar speeds up towards the end).
pub fn solve_with_progress(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    opts: &SolveOptions,
    progress: &dyn Progress,
) -> Result<SolveReport> {
    progress.start("solve", 100);
    let tracker = Tracker {
        progress,
        tolerance: opts.tolerance,
        first: Cell::new(f64::NAN),
        shown: Cell::new(0),
    };
    let out = solve_tracked(x, xi_target, y0, opts, &tracker);
    progress.finish();
    out
}

/// Turns residuals into progress units (see [`solve_with_progress`]).
struct Tracker<'a> {
    progress: &'a dyn Progress,
    tolerance: f64,
    first: Cell<f64>,
    shown: Cell<u64>,
}

impl Tracker<'_> {
    /// The iteration reached residual ‖ξ − ξ̂‖ = `r`.
    fn residual(&self, r: f64) {
        if !(r.is_finite() && r > 0.0) {
            return;
        }
        if self.first.get().is_nan() {
            self.first.set(r.max(10.0 * self.tolerance));
        }
        let first = self.first.get();
        let frac = ((first / r).ln() / (first / self.tolerance).ln()).clamp(0.0, 1.0);
        let units = (frac * 100.0).floor() as u64;
        if units > self.shown.get() {
            self.progress.advance(units - self.shown.get());
            self.shown.set(units);
        }
    }
}

fn solve_tracked(
    x: &[f64],
    xi_target: &[f64],
    y0: Option<&[f64]>,
    opts: &SolveOptions,
    tracker: &Tracker,
) -> Result<SolveReport> {
    let aero = &opts.aero;
    let target = validate(x, xi_target, y0, aero)?;
    let n = x.len();
    // Large flocks: the sorted field, built once, gives E and every evaluation of the solve.
    let field = (n > opts.dense_limit).then(|| Field::new(aero, x, opts.band_span));
    let total = match field.as_ref().map(Field::munk_total) {
        Some(t) if t.is_finite() => t,
        _ => aero.munk_total(x)?,
    };
    if !(total > 0.0) {
        return Err(Error::Unreachable(format!(
            "these lateral positions give the flock a total saving E = {total:.6} ≤ 0 (wingtips overlap so much that the birds fly in one another's downwash); no placement shares out a positive saving; widen the lateral gaps"
        )));
    }
    let small = n <= opts.check_limit;
    let starts: Vec<Vec<f64>> = match y0 {
        Some(y) => vec![y.to_vec()],
        None => default_starts(x, &target, aero),
    };
    // Each start fixes the fore-aft order of the overlapping pairs; the first order in which
    // the targets are reachable and the solve converges without a collision wins.
    let mut first_error: Option<Error> = None;
    let mut best: Option<SolveReport> = None;
    let mut evaluations = 0;
    let mut tried_neutral = y0.is_none();
    let mut queue = starts;
    let mut k = 0;
    while k < queue.len() {
        let start = queue[k].clone();
        k += 1;
        if opts.check_reachable && small {
            if let Err(e) = reachability_ordered(x, &target, total, &start, aero) {
                first_error.get_or_insert(e);
                if k == queue.len() && !tried_neutral {
                    // A poor guess: the neutral starts are the fallback.
                    tried_neutral = true;
                    queue.extend(default_starts(x, &target, aero));
                }
                continue;
            }
        }
        let rep = match &field {
            None => newton(x, &target, total, &start, opts, tracker),
            Some(f) => newton_krylov(f, &target, total, &start, opts, tracker),
        };
        evaluations += rep.evaluations;
        if rep.converged {
            if let Err(e) = aero.check_shape(x, &rep.y) {
                first_error.get_or_insert(e);
            } else {
                best = Some(rep);
                break;
            }
        } else if best.as_ref().map_or(true, |b| rep.residual < b.residual) {
            best = Some(rep);
        }
        if k == queue.len() && !tried_neutral {
            // A poor guess can strand the iteration on a plateau of g; the neutral starts are
            // the fallback.
            tried_neutral = true;
            queue.extend(default_starts(x, &target, aero));
        }
    }
    match best {
        Some(mut rep) if rep.converged || first_error.is_none() => {
            rep.evaluations = evaluations;
            if !rep.converged && opts.check_reachable && !small {
                reachability_ordered(x, &target, total, &queue[0], aero)?;
            }
            Ok(rep)
        }
        _ => Err(first_error.unwrap_or_else(|| Error::Internal("no start tried".into()))),
    }
}

/// Builds the report for positions `y` (shifted so that the front-most bird is at 0) with their
/// savings `e`.
fn report(
    target: &[f64],
    total: f64,
    mut y: Vec<f64>,
    e: Vec<f64>,
    evaluations: usize,
    opts: &SolveOptions,
    termination: String,
) -> SolveReport {
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
        converged: residual.is_finite() && residual <= opts.tolerance,
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

/// Newton's method on the symmetric system, damped in Levenberg–Marquardt's way when needed.
///
/// The Jacobian J = (1/E)·∂e/∂y restricted to the free birds is symmetric positive definite, so
/// the step
/// ```math
/// (J + \lambda\,\bar d\,I)\,\delta = -r
/// ```
/// (d̄ the mean diagonal of J) is found with one Cholesky factorisation and is a descent
/// direction of ‖r‖² for every λ ≥ 0. λ starts at 10⁻⁶ (a Newton step, quadratic convergence
/// near the solution) and follows Marquardt's rule: ÷10 after a step that lowers ‖r‖, ×10 (and
/// the step retried) after one that does not. A step that would make two laterally overlapping
/// birds pass each other is shortened to 90 % of the way to abreast. Stops at the tolerance,
/// after `patience` Jacobians, or when λ exceeds 10¹².
fn newton(
    x: &[f64],
    target: &[f64],
    total: f64,
    y0: &[f64],
    opts: &SolveOptions,
    tracker: &Tracker,
) -> SolveReport {
    let n = x.len();
    let aero = &opts.aero;
    let fixed = (0..n)
        .min_by(|&a, &b| y0[a].total_cmp(&y0[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let free: Vec<usize> = (0..n).filter(|&i| i != fixed).collect();
    let m = free.len();
    let order = ordered_pairs(x, y0);
    let evaluate = |y: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let (e, jac) = aero.power_and_jacobian_unchecked(x, y);
        let r = e.iter().zip(target).map(|(e, t)| e / total - t).collect();
        (r, jac)
    };
    // Merit: the free birds' residuals (the fixed bird's is minus their sum, since Σξ = Σξ̂ = 1).
    let merit = |r: &[f64]| -> f64 { free.iter().map(|&i| r[i] * r[i]).sum::<f64>().sqrt() };
    let mut y = y0.to_vec();
    let (mut r, mut full) = evaluate(&y);
    let mut norm = merit(&r);
    let mut evaluations = 1;
    let mut lambda = 1e-6;
    let mut why = "iteration budget exhausted";
    let stop = opts.tolerance * 1e-3;
    let inv = 1.0 / total;
    'outer: for _ in 0..opts.patience.max(1) {
        if norm <= stop {
            why = "residual below tolerance";
            break;
        }
        if !norm.is_finite() {
            why = "the start has an infinite saving (birds abreast with overlapping wingtips)";
            break;
        }
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
            let mut full_step = vec![0.0; n];
            for (a, &i) in free.iter().enumerate() {
                full_step[i] = step[a];
            }
            // Keep the fore-aft order of laterally overlapping pairs.
            let alpha = order_preserving_length(&order, &y, &full_step);
            let trial: Vec<f64> = y
                .iter()
                .zip(&full_step)
                .map(|(v, s)| v + alpha * s)
                .collect();
            let (tr, tjac) = evaluate(&trial);
            evaluations += 1;
            let tnorm = merit(&tr);
            if tnorm.is_finite() && tnorm < norm {
                y = trial;
                r = tr;
                full = tjac;
                norm = tnorm;
                tracker.residual(norm);
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
    let e = aero.power_unchecked(x, &y);
    report(
        target,
        total,
        y,
        e,
        evaluations,
        opts,
        format!("symmetric Newton–Levenberg–Marquardt: {why}"),
    )
}

/// Cholesky factor of a symmetric positive definite band matrix: `band[i * (b + 1) + k]` holds
/// A[i][i − k] for k ≤ b (and i − k ≥ 0). Returns the factor in the same layout, or `None` when
/// the matrix is not positive definite. O(m·b²).
fn band_cholesky(band: &[f64], m: usize, b: usize) -> Option<Vec<f64>> {
    let w = b + 1;
    let mut l = vec![0.0; m * w];
    for i in 0..m {
        let j0 = i.saturating_sub(b);
        for j in j0..=i {
            // L[i][j] = (A[i][j] − Σ_{k<j} L[i][k] L[j][k]) / L[j][j]
            let mut s = band[i * w + (i - j)];
            let k0 = j0.max(j.saturating_sub(b));
            for k in k0..j {
                s -= l[i * w + (i - k)] * l[j * w + (j - k)];
            }
            if i == j {
                if !(s > 0.0) {
                    return None;
                }
                l[i * w] = s.sqrt();
            } else {
                l[i * w + (i - j)] = s / l[j * w];
            }
        }
    }
    Some(l)
}

/// Solves L Lᵀ z = r with the factor of [`band_cholesky`].
fn band_solve(l: &[f64], m: usize, b: usize, r: &[f64]) -> Vec<f64> {
    let w = b + 1;
    let mut z = r.to_vec();
    for i in 0..m {
        let mut s = z[i];
        for k in i.saturating_sub(b)..i {
            s -= l[i * w + (i - k)] * z[k];
        }
        z[i] = s / l[i * w];
    }
    for i in (0..m).rev() {
        let mut s = z[i];
        for k in (i + 1)..(i + 1 + b).min(m) {
            s -= l[k * w + (k - i)] * z[k];
        }
        z[i] = s / l[i * w];
    }
    z
}

/// The sums a Newton–conjugate-gradient iteration needs: e with the band and the near slopes,
/// and products with the Jacobian. [`Field`] gives them exactly, [`ApproxField`] with the far
/// pairs interpolated.
trait Sums {
    fn power_band(&self, y: &[f64], band: &mut Vec<f64>, near: &mut Vec<f64>) -> Vec<f64>;
    fn jacobian_times(&self, y: &[f64], near: &[f64], v: &[f64]) -> Vec<f64>;
    /// Whether the sums are exact (for the work counters).
    fn exact(&self) -> bool;
}

impl Sums for Field {
    fn power_band(&self, y: &[f64], band: &mut Vec<f64>, near: &mut Vec<f64>) -> Vec<f64> {
        Field::power_band(self, y, Some(band), Some(near))
    }
    fn jacobian_times(&self, y: &[f64], near: &[f64], v: &[f64]) -> Vec<f64> {
        Field::jacobian_times(self, y, near, v)
    }
    fn exact(&self) -> bool {
        true
    }
}

impl Sums for ApproxField<'_> {
    fn power_band(&self, y: &[f64], band: &mut Vec<f64>, near: &mut Vec<f64>) -> Vec<f64> {
        ApproxField::power_band(self, y, Some(band), Some(near))
    }
    fn jacobian_times(&self, y: &[f64], near: &[f64], v: &[f64]) -> Vec<f64> {
        ApproxField::jacobian_times(self, y, near, v)
    }
    fn exact(&self) -> bool {
        false
    }
}

/// Work counters of [`newton_krylov`].
#[derive(Debug, Default)]
struct Work {
    /// Exact evaluations of e (every pair).
    exact: usize,
    /// Evaluations with the far pairs interpolated.
    interpolated: usize,
    /// Jacobian products.
    products: usize,
    /// Exact checks that asked for another interpolated round.
    corrections: usize,
}

/// Where [`krylov`] stopped.
struct Inner {
    y: Vec<f64>,
    /// The sums' e at `y` (without the correction).
    e: Vec<f64>,
    why: &'static str,
}

/// [`newton`] for large flocks: inexact Newton steps, each step's linear system J δ = −r solved
/// by conjugate gradients (J symmetric positive definite once one bird is fixed), preconditioned
/// by the band of the pairs less than `band_span` apart laterally (a weighted graph Laplacian
/// with a narrow band once the birds are sorted by x, factorised by Cholesky in O(N·b²)). The
/// band alone misses the far pairs' coupling (∂g/∂y ~ a²/R³ summed over the flock), which
/// matters for the slow, flock-wide modes: as a preconditioner it leaves J's spectrum within a
/// small factor, and conjugate gradients converge in a few products. Each linear solve is
/// accurate to a fraction η = min(10⁻², ‖r‖/‖r₀‖) of the residual (superlinear convergence); a
/// step is shortened to keep the fore-aft order of overlapping pairs and halved until ‖r‖
/// decreases.
///
/// Up to [`SolveOptions::interpolate_from`] birds every sum is exact ([`Field`]: every pair, far
/// ones by their expansion). From there on the iteration runs on [`ApproxField`] (the far pairs'
/// stagger-dependent part interpolated on a tree, about 10⁻⁷ of the far sum, O(N log N)-like
/// instead of O(N²)), and its result is **checked with the exact sums**: if the exact residual
/// is not below a tenth of the tolerance, the difference between the exact and the interpolated
/// e at that point is added to the interpolated residual as a fixed correction and the
/// iteration continues (a defect correction: each round gains the interpolation's relative
/// accuracy); after three rounds the exact iteration finishes the job. The reported residual is
/// always the exact one.
fn newton_krylov(
    field: &Field,
    target: &[f64],
    total: f64,
    y0: &[f64],
    opts: &SolveOptions,
    tracker: &Tracker,
) -> SolveReport {
    let n = field.len();
    let mut work = Work::default();
    let exact_done = 0.1 * opts.tolerance;
    let mut y = y0.to_vec();
    let mut verified: Option<(Vec<f64>, &'static str)> = None;
    if n >= opts.interpolate_from {
        let approx = field.approximate(opts.interpolation);
        let mut corr = vec![0.0; n];
        for _round in 0..3 {
            let inner = krylov(
                &approx,
                field,
                target,
                total,
                &y,
                &corr,
                0.3 * exact_done,
                opts,
                &mut work,
                tracker,
            );
            y = inner.y;
            let e = field.power(&y);
            work.exact += 1;
            let r = norm_diff_scaled(&e, target, 1.0 / total);
            tracker.residual(r);
            if r <= exact_done {
                verified = Some((e, inner.why));
                break;
            }
            work.corrections += 1;
            for ((c, ex), ap) in corr.iter_mut().zip(&e).zip(&inner.e) {
                *c = ex - ap;
            }
            if r <= opts.tolerance && inner.why != "residual below tolerance" {
                // Converged, and the interpolated iteration cannot do better.
                verified = Some((e, inner.why));
                break;
            }
        }
    }
    let (e, why) = match verified {
        Some(v) => v,
        None => {
            let zero = vec![0.0; n];
            let inner = krylov(
                field, field, target, total, &y, &zero, exact_done, opts, &mut work, tracker,
            );
            y = inner.y;
            (inner.e, inner.why)
        }
    };
    let b = field.band_width();
    let evaluations = work.exact + work.interpolated;
    report(
        target,
        total,
        y,
        e,
        evaluations,
        opts,
        format!(
            "Newton–conjugate gradients, band preconditioner (bandwidth {b}; {} exact and {} interpolated evaluations, {} Jacobian products, {} corrections): {why}",
            work.exact, work.interpolated, work.products, work.corrections
        ),
    )
}

/// ‖e·scale − t‖₂.
fn norm_diff_scaled(e: &[f64], t: &[f64], scale: f64) -> f64 {
    e.iter()
        .zip(t)
        .map(|(e, t)| (e * scale - t) * (e * scale - t))
        .sum::<f64>()
        .sqrt()
}

/// The Newton–conjugate-gradient iteration of [`newton_krylov`] on the residual
/// (e + `corr`)/E − ξ̂ with e and the products from `sums`, from `y0` until the full residual is
/// at most `done_at` (or the free birds' below a thousandth of the tolerance).
#[allow(clippy::too_many_arguments)]
fn krylov<S: Sums>(
    sums: &S,
    field: &Field,
    target: &[f64],
    total: f64,
    y0: &[f64],
    corr: &[f64],
    done_at: f64,
    opts: &SolveOptions,
    work: &mut Work,
    tracker: &Tracker,
) -> Inner {
    let exact = sums.exact();
    let count = |work: &mut Work| {
        if exact {
            work.exact += 1;
        } else {
            work.interpolated += 1;
        }
    };
    let n = field.len();
    let x = field.x();
    let b = field.band_width();
    let fixed = (0..n)
        .min_by(|&a, &b| y0[a].total_cmp(&y0[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let pf = field.order().iter().position(|&i| i == fixed).unwrap_or(0);
    // Free birds in lateral order: position p ↔ bird free[p].
    let free: Vec<usize> = field
        .order()
        .iter()
        .copied()
        .filter(|&i| i != fixed)
        .collect();
    let m = free.len();
    let order = ordered_pairs(x, y0);
    let merit = |r: &[f64]| -> f64 { free.iter().map(|&i| r[i] * r[i]).sum::<f64>().sqrt() };
    let inv = 1.0 / total;
    let mut full_band = Vec::new();
    let mut near = Vec::new();
    let mut y = y0.to_vec();
    let mut e = sums.power_band(&y, &mut full_band, &mut near);
    count(work);
    let resid = |e: &[f64]| -> Vec<f64> {
        e.iter()
            .zip(corr)
            .zip(target)
            .map(|((e, c), t)| (e + c) * inv - t)
            .collect()
    };
    let mut r = resid(&e);
    let mut norm = merit(&r);
    let norm0 = norm;
    let mut why = "iteration budget exhausted";
    let stop = opts.tolerance * 1e-3;
    let done = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt() <= done_at;
    for _ in 0..opts.patience.max(1) {
        if norm <= stop || done(&r) {
            why = "residual below tolerance";
            break;
        }
        if !norm.is_finite() {
            why = "the start has an infinite saving (birds abreast with overlapping wingtips)";
            break;
        }
        let l = band_factor(&full_band, n, b, pf, inv);
        let Some(l) = l else {
            why = "band preconditioner not positive definite";
            break;
        };
        // Conjugate gradients on J δ = −r (free birds, sorted positions).
        let rhs: Vec<f64> = free.iter().map(|&i| -r[i]).collect();
        let eta = (norm / norm0).min(1e-2).max(stop / norm * 0.1);
        let rhs_norm = dot(&rhs, &rhs).sqrt();
        let mut delta = vec![0.0; m];
        let mut res = rhs.clone();
        let mut z = band_solve(&l, m, b, &res);
        let mut dir = z.clone();
        let mut rz = dot(&res, &z);
        let mut v = vec![0.0; n];
        for _ in 0..opts.cg_limit.max(1) {
            for (p, &i) in free.iter().enumerate() {
                v[i] = dir[p];
            }
            let jv = sums.jacobian_times(&y, &near, &v);
            work.products += 1;
            let ad: Vec<f64> = free.iter().map(|&i| jv[i] * inv).collect();
            let curv = dot(&dir, &ad);
            if !(curv > 0.0) {
                break;
            }
            let alpha = rz / curv;
            for p in 0..m {
                delta[p] += alpha * dir[p];
                res[p] -= alpha * ad[p];
            }
            if dot(&res, &res).sqrt() <= eta * rhs_norm {
                break;
            }
            z = band_solve(&l, m, b, &res);
            let rz_new = dot(&res, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            for p in 0..m {
                dir[p] = z[p] + beta * dir[p];
            }
        }
        let mut full_step = vec![0.0; n];
        for (p, &i) in free.iter().enumerate() {
            full_step[i] = delta[p];
        }
        let mut alpha = order_preserving_length(&order, &y, &full_step);
        let mut accepted = false;
        for _ in 0..30 {
            let trial: Vec<f64> = y
                .iter()
                .zip(&full_step)
                .map(|(v, s)| v + alpha * s)
                .collect();
            let mut tband = Vec::new();
            let mut tnear = Vec::new();
            let te = sums.power_band(&trial, &mut tband, &mut tnear);
            count(work);
            let tr = resid(&te);
            let tnorm = merit(&tr);
            if tnorm.is_finite() && tnorm < norm {
                y = trial;
                e = te;
                r = tr;
                norm = tnorm;
                full_band = tband;
                near = tnear;
                tracker.residual(r.iter().map(|v| v * v).sum::<f64>().sqrt());
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            why = "no step lowers the residual";
            break;
        }
    }
    Inner { y, e, why }
}

/// Cholesky factor of the free birds' band (`full` from [`Field::power_band`] without sorted
/// position `pf`, times `scale`), the diagonal shifted a little if rounding makes it indefinite;
/// `None` if even a shift of its mean diagonal does not help.
fn band_factor(full: &[f64], n: usize, b: usize, pf: usize, scale: f64) -> Option<Vec<f64>> {
    let m = n - 1;
    let band = drop_position(full, n, b, pf, scale);
    let mut damped = band.clone();
    let mut shift = 0.0;
    loop {
        if let Some(l) = band_cholesky(&damped, m, b) {
            return Some(l);
        }
        // Not positive definite in floating point: shift the diagonal.
        let mean = (0..m).map(|p| band[p * w_of(b)]).sum::<f64>() / m as f64;
        shift = if shift == 0.0 {
            1e-10 * mean
        } else {
            shift * 10.0
        };
        if !(shift < mean) {
            return None;
        }
        damped = band.clone();
        for p in 0..m {
            damped[p * w_of(b)] += shift;
        }
    }
}

fn w_of(b: usize) -> usize {
    b + 1
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p * q).sum()
}

/// The band matrix of [`Field::power_band`] (n sorted positions, half-bandwidth b) without row
/// and column `pf` (the fixed bird), times `scale`: still a band of half-bandwidth b.
fn drop_position(full: &[f64], n: usize, b: usize, pf: usize, scale: f64) -> Vec<f64> {
    let w = b + 1;
    let m = n - 1;
    let mut out = vec![0.0; m * w];
    for i in 0..m {
        let oi = i + usize::from(i >= pf);
        for k in 0..=b.min(i) {
            let j = i - k;
            let oj = j + usize::from(j >= pf);
            if oi - oj <= b {
                out[i * w + k] = full[oi * w + (oi - oj)] * scale;
            }
        }
    }
    out
}

/// The longest fraction (≤ 1) of `step` that keeps every laterally overlapping pair of `order`
/// (front, rear) in its fore-aft order: at most 90 % of the way to abreast.
fn order_preserving_length(order: &[(usize, usize)], y: &[f64], step: &[f64]) -> f64 {
    let mut alpha: f64 = 1.0;
    for &(f, bk) in order {
        let gap = y[bk] - y[f];
        let closing = step[f] - step[bk];
        if closing > 0.0 && closing * alpha >= 0.9 * gap {
            alpha = alpha.min(0.9 * gap / closing);
        }
    }
    alpha
}

/// Decides whether renormalised targets `target` (Σ = 1) are reachable for lateral positions `x`
/// with total `total` (= [`crate::aero::munk_total`]), with the default model and the fore-aft order
/// of overlapping pairs of the solver's own start; see [`reachability_ordered`].
pub fn reachability(x: &[f64], target: &[f64], total: f64) -> Result<()> {
    let aero = AeroOptions::default();
    let starts = default_starts(x, target, &aero);
    reachability_ordered(x, target, total, &starts[0], &aero)
}

/// Decides whether renormalised targets `target` (Σ = 1) are reachable for lateral positions `x`
/// with total `total`, keeping the fore-aft order that `start` gives laterally overlapping pairs,
/// and names the birds of a violating subset when they are not ([`Error::Unreachable`]).
///
/// Each pair (i, j) contributes w_ij = 2g(x_ij, 0)/E to ξ (negative for heavily overlapping
/// wings), split between its two birds by their stagger. A pair at least one wingspan apart
/// laterally can give either bird any share in (0, w) (all to the rear bird as the stagger → ∞).
/// A laterally overlapping pair keeps its order: the front bird f gets a share in (0, D_c) with
/// D_c = g(x, −chord)/E (the most it gets just outside a collision), the rear bird the rest. So
/// each pair is a base amount for one bird plus a transfer t ∈ (0, span) to the other, and the
/// targets are reachable iff the transfers can deliver every bird's target minus its bases: a
/// feasible flow, decided by one maximum flow (Dinic on a dense matrix). Single birds are
/// checked first for clearer messages.
pub fn reachability_ordered(
    x: &[f64],
    target: &[f64],
    total: f64,
    start: &[f64],
    aero: &AeroOptions,
) -> Result<()> {
    let n = x.len();
    // Per pair: base to `to_base`, transfer of up to `span` from `to_base` to `gets`.
    let mut overlapping = vec![false; n * n];
    for &(f, b) in &ordered_pairs(x, start) {
        overlapping[f * n + b] = true;
    }
    let mut base = vec![0.0; n];
    let mut lo = vec![0.0; n];
    let mut hi = vec![0.0; n];
    // span[v * n + u]: transfer capacity from v to u.
    let mut span = vec![0.0; n * n];
    let mut w = vec![0.0; n * n];
    let chord = aero.collision_chord.max(1e-3);
    for i in 0..n {
        for j in (i + 1)..n {
            let dx = (x[i] - x[j]).abs();
            let wij = 2.0 * aero.g0(dx) / total;
            w[i * n + j] = wij;
            w[j * n + i] = wij;
            let (front, rear, cap) = if overlapping[i * n + j] {
                (i, j, aero.g(dx, -chord) / total)
            } else if overlapping[j * n + i] {
                (j, i, aero.g(dx, -chord) / total)
            } else {
                (i, j, wij)
            };
            // front gets t ∈ (0, cap), rear gets w − t ∈ (w − cap, w).
            base[rear] += wij;
            span[rear * n + front] = cap;
            hi[front] += cap;
            lo[rear] += wij - cap;
            hi[rear] += wij;
        }
    }
    let list = |set: &[usize]| -> String {
        set.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let margin = 1e-12;
    for i in 0..n {
        if !(target[i] > lo[i] + margin) {
            return Err(Error::Unreachable(format!(
                "bird {i} asks for ξ = {:.6}, but its pairs give it at least {:.6} wherever it flies (every other bird as far ahead as it can be, birds whose wings overlap it laterally kept on their side of it); give it a larger share",
                target[i], lo[i]
            )));
        }
        if !(target[i] < hi[i] - margin) {
            return Err(Error::Unreachable(format!(
                "bird {i} asks for ξ = {:.6}, more than all its pairs can give it (at most {:.6}: every other bird as far behind as it can be, birds whose wings overlap it laterally kept on their side of it)",
                target[i], hi[i]
            )));
        }
    }
    if n <= 2 {
        return Ok(());
    }
    // Flow network: nodes 0..n birds, s = n, t = n + 1. Bird i needs net inflow target_i − base_i.
    let s = n;
    let t = n + 1;
    let mm = n + 2;
    let mut cap = vec![0.0; mm * mm];
    let mut demand = 0.0;
    for v in 0..n {
        for u in 0..n {
            if u != v {
                cap[v * mm + u] = span[v * n + u];
            }
        }
        let need = target[v] - base[v];
        if need > 0.0 {
            cap[v * mm + t] = need;
            demand += need;
        } else {
            cap[s * mm + v] = -need;
        }
    }
    let flow = max_flow_dense(&mut cap, mm, s, t);
    if flow >= demand - 1e-12 {
        return Ok(());
    }
    // Source side of the minimum cut: birds whose surplus cannot be shipped out, i.e. a set that
    // asks for less than its pairs give it at least.
    let side = reachable_from(&cap, mm, s);
    let tset: Vec<usize> = (0..n).filter(|&i| side[i]).collect();
    let uset: Vec<usize> = (0..n).filter(|&i| !side[i]).collect();
    let ask = |set: &[usize]| -> f64 { set.iter().map(|&i| target[i]).sum() };
    // Least a set gets: its inside pairs, plus the least of each crossing pair; most: plus the most.
    let bounds = |set: &[usize]| -> (f64, f64) {
        let mut inside = vec![false; n];
        for &i in set {
            inside[i] = true;
        }
        let (mut least, mut most) = (0.0, 0.0);
        for i in 0..n {
            for j in (i + 1)..n {
                match (inside[i], inside[j]) {
                    (true, true) => {
                        least += w[i * n + j];
                        most += w[i * n + j];
                    }
                    (true, false) | (false, true) => {
                        let (me, other) = if inside[i] { (i, j) } else { (j, i) };
                        // me as the receiver of other's transfer, or as the giver.
                        let to_me = span[other * n + me];
                        let from_me = span[me * n + other];
                        if to_me > 0.0 || from_me == 0.0 {
                            // me is the front bird of this pair (gets 0..cap).
                            most += to_me;
                        } else {
                            least += w[i * n + j] - from_me;
                            most += w[i * n + j];
                        }
                    }
                    _ => {}
                }
            }
        }
        (least, most)
    };
    if tset.len() <= uset.len() || uset.is_empty() {
        let (least, _) = bounds(&tset);
        Err(Error::Unreachable(format!(
            "birds {} ask for ξ = {:.6} together, but their pairs give them at least {:.6} however the others fly; raise their targets or lower the others'",
            list(&tset),
            ask(&tset),
            least
        )))
    } else {
        let (_, most) = bounds(&uset);
        Err(Error::Unreachable(format!(
            "birds {} ask for ξ = {:.6} together, but all the pairs they belong to give them at most {:.6} however the others fly; lower their targets or raise the others'",
            list(&uset),
            ask(&uset),
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
    use crate::aero;

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
        let x = [0.0, 1.1, 5.0, 6.1];
        let total = aero::munk_total(&x).unwrap();
        let w01 = 2.0 * aero::g0(1.1) / total;
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

    #[test]
    fn overlapping_pairs_keep_their_order_and_the_check_knows_it() {
        // Real spacing: 0.77 wingspans laterally, 1.24 behind, wingtips overlapping.
        let x = [0.0, 0.77, 1.54, -0.77, -1.54];
        let y = [0.0, 1.24, 2.5, 1.1, 2.3];
        let xi = aero::power_reduction(&x, &y).unwrap().xi;
        let rep = solve(&x, &xi, None, &SolveOptions::default()).unwrap();
        assert!(rep.converged, "{rep:?}");
        for (a, b) in rep.y.iter().zip(&y) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
        // Bird 1 asking for 90 % of the flock's saving is more than its pairs can give it.
        let err = solve(
            &x,
            &[0.02, 0.9, 0.02, 0.03, 0.03],
            None,
            &SolveOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(err, Error::Unreachable(_)), "{err}");
    }
}
