//! §5 step 3: new key shapes. Each key k draws relative power reductions ξ̂_k by eq. (2) inside the
//! birds' feasible ranges and near ξ̂_{k−1}, and places the birds fore and aft by the
//! Levenberg–Marquardt solve of eq. (4) ([`crate::keyshape::solve()`]) with the lateral positions
//! fixed. Formation frame, wingspans; ξ dimensionless.
//!
//! ```math
//! \hat\xi_{i,k} \in [(1-\varepsilon)\,p_i,\ (1+\varepsilon)\,P_i] \cap [C_1\,\hat\xi_{i,k-1},\ C_2\,\hat\xi_{i,k-1}]
//! \qquad \text{(Klotsman \& Tal, eq. 2)}
//! ```
//! (`p_i, P_i` = [`XiRanges`]; `ε, C_1, C_2` = [`KeyOptions`] `epsilon`, `c1`, `c2`).
//! Munk's stagger theorem fixes E = Σ e_i by the lateral positions alone, so eq. (3)–(4) reduce to
//! ξ(x, y) = ξ̂ with Σ ξ̂ = 1: a draw is renormalised, clipped back into its range and renormalised
//! again, which keeps the system consistent.
//!
//! A key shape is accepted only when the solve reaches the residual bound, the leader stays
//! front-most, no bird falls further back than the depth limit, the arms keep the monotone steps of
//! the first key shape (side structure), and no bird moves more than `max_jump` from the previous key.
//! A rejected shape is never used as a starting point. Failing draws are redrawn (`max_draws`);
//! when all fail, the draws are damped toward ξ̂_{k−1} (ξ̂_{k−1} + λ (ξ̂ − ξ̂_{k−1})), whose
//! solution is the previous key shape at λ = 0, so the reachable set always contains a fallback.

use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::keyshape::ranges::XiRanges;
use crate::keyshape::solve::{solve, SolveOptions};

/// Options of step 3 (the `steady.keys` section of [`crate::pipeline::Config`]): eq. (2)'s
/// draws, the key interval, and what a key shape must satisfy to be accepted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KeyOptions {
    /// ε of eq. (2): widening of [p_i, P_i], dimensionless, in [0, 0.5] (paper: 0 ≤ ε ≤ 0.2).
    pub epsilon: f64,
    /// C₁ of eq. (2): smallest ratio ξ̂_{i,k} / ξ̂_{i,k−1}, dimensionless, in [0.5, 1]
    /// (paper: 0.75–0.9).
    pub c1: f64,
    /// C₂ of eq. (2): largest ratio ξ̂_{i,k} / ξ̂_{i,k−1}, dimensionless, in [1, 2]
    /// (paper: 1.1–1.25).
    pub c2: f64,
    /// Time between key shapes, seconds (keys are spread evenly over the flight, about this far
    /// apart).
    pub key_every_s: f64,
    /// Largest move of any bird between consecutive key shapes, wingspans.
    pub max_jump: f64,
    /// Draws of ξ̂ per key before damping, count.
    pub max_draws: usize,
    /// Halvings of the damping factor λ before the previous key shape is held, count.
    pub max_damping: usize,
    /// A key shape is solved when ‖ξ − ξ̂‖₂ is at most this, dimensionless (the solve's own
    /// tolerance is a thousandth of it).
    pub accept_residual: f64,
    /// Depth limit of key shapes: no bird further behind the leader than this factor times the
    /// deepest initial shape plus one wingspan, dimensionless (≥ 1).
    pub max_depth_factor: f64,
    /// Widening of the band of the median longitudinal distance to the nearest bird ahead that
    /// the initial shapes span, inside which every key shape's must stay (the footage's
    /// spacing), fraction in [0, 1].
    pub spacing_margin: f64,
}

impl Default for KeyOptions {
    fn default() -> Self {
        KeyOptions {
            epsilon: 0.1,
            c1: 0.85,
            c2: 1.15,
            key_every_s: 3.0,
            max_jump: 0.5,
            max_draws: 3,
            max_damping: 12,
            accept_residual: 1e-6,
            max_depth_factor: 1.5,
            spacing_margin: 0.0,
        }
    }
}

impl KeyOptions {
    /// Checks every option; the error names the option path (`steady.keys.epsilon`).
    pub fn validate(&self) -> Result<()> {
        let p = |name: &str, msg: String| Err(Error::parameter(name, msg));
        if !(self.epsilon.is_finite() && (0.0..=0.5).contains(&self.epsilon)) {
            return p(
                "steady.keys.epsilon",
                format!(
                    "{}: must be in [0, 0.5] (the paper uses 0 to 0.2)",
                    self.epsilon
                ),
            );
        }
        if !(self.c1.is_finite() && (0.5..=1.0).contains(&self.c1)) {
            return p(
                "steady.keys.c1",
                format!(
                    "{}: must be in [0.5, 1] (the paper uses 0.75 to 0.9)",
                    self.c1
                ),
            );
        }
        if !(self.c2.is_finite() && (1.0..=2.0).contains(&self.c2)) {
            return p(
                "steady.keys.c2",
                format!(
                    "{}: must be in [1, 2] (the paper uses 1.1 to 1.25)",
                    self.c2
                ),
            );
        }
        if !(self.key_every_s.is_finite() && self.key_every_s > 0.0) {
            return p(
                "steady.keys.key_every_s",
                format!("{}: must be a positive number of seconds", self.key_every_s),
            );
        }
        if !(self.max_jump.is_finite() && self.max_jump > 0.0) {
            return p(
                "steady.keys.max_jump",
                "must be a positive number of wingspans".into(),
            );
        }
        if !(self.accept_residual.is_finite() && self.accept_residual > 0.0) {
            return p("steady.keys.accept_residual", "must be positive".into());
        }
        if !(self.max_depth_factor.is_finite() && self.max_depth_factor >= 1.0) {
            return p("steady.keys.max_depth_factor", "must be at least 1".into());
        }
        if !(self.spacing_margin.is_finite() && (0.0..=1.0).contains(&self.spacing_margin)) {
            return p(
                "steady.keys.spacing_margin",
                format!("{}: must be in [0, 1]", self.spacing_margin),
            );
        }
        Ok(())
    }

    /// The Levenberg–Marquardt solve's options: tolerance a thousandth of `accept_residual`
    /// (at least 10⁻¹²), the given aerodynamic model.
    pub fn solve_options(&self, aero: &crate::aero::AeroOptions) -> SolveOptions {
        SolveOptions {
            tolerance: (self.accept_residual * 1e-3).max(1e-12),
            aero: *aero,
            ..SolveOptions::default()
        }
    }
}

/// One key shape, formation frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KeyShape {
    /// Lateral position of each bird, wingspans (the key's own: they drift slowly between keys).
    pub x: Vec<f64>,
    /// Distance of each bird behind the leader, wingspans (leader at 0).
    pub y: Vec<f64>,
    /// The target ξ̂ the shape was solved for (after damping).
    pub xi_target: Vec<f64>,
    /// ξ achieved.
    pub xi: Vec<f64>,
    /// ‖ξ − ξ̂‖₂.
    pub residual: f64,
    /// Damping λ used: 1 for an undamped draw, 0 when the previous shape was held.
    pub damping: f64,
    /// Draws of ξ̂ spent on this key.
    pub draws: usize,
}

/// Counts of step 3 over all keys.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct KeyStats {
    /// Key shapes made (including the first, taken from an initial shape).
    pub keys: usize,
    /// Draws of ξ̂ in total.
    pub draws: usize,
    /// Draws beyond the first of a key.
    pub redraws: usize,
    /// Keys accepted only after damping (0 < λ < 1).
    pub damped: usize,
    /// Keys where every damped target failed and the previous shape was held (λ = 0).
    pub held: usize,
    /// Solves run.
    pub solves: usize,
    /// Draws redrawn (or damping steps skipped) because their linear prediction already broke
    /// the structure or the jump bound; no solve was spent on them.
    pub rejected_predicted: usize,
    /// Solves that reported an error (unreachable target, collision).
    pub solve_errors: usize,
    /// Solves above the residual bound.
    pub rejected_residual: usize,
    /// Solved shapes rejected for the leader, depth or arm order.
    pub rejected_structure: usize,
    /// Solved shapes rejected for a jump above `max_jump`.
    pub rejected_jump: usize,
    /// Model evaluations of all solves.
    pub evaluations: usize,
    /// Smallest λ among accepted keys (1 when none was damped).
    pub min_damping: f64,
    /// Largest residual among accepted keys.
    pub max_residual: f64,
    /// Largest move of a bird between consecutive keys, wingspans.
    pub max_jump: f64,
    /// Keys where no shape fitted the drifted lateral positions, which then kept the previous
    /// key's lateral positions.
    pub lateral_held: usize,
}

/// The structure every key shape must keep: leader, arm steps and depth.
#[derive(Debug, Clone)]
pub struct Structure {
    /// Index of the leader (front-most bird).
    pub leader: usize,
    /// (inner, outer) lateral neighbours on the same arm whose outer bird is not ahead of the inner
    /// one in the first key shape; they must stay that way.
    pub monotone_pairs: Vec<(usize, usize)>,
    /// Deepest allowed position, wingspans.
    pub max_depth: f64,
    /// An outer bird may come this far ahead of its inner neighbour before the arm counts as
    /// broken, wingspans (near-ties, e.g. around a J's vertex, would otherwise block every move).
    pub monotone_tolerance: f64,
    /// The band [lo, hi] of the median longitudinal distance to the nearest bird ahead
    /// ([`crate::keyshape::spacing`]), wingspans: the footage's spacing, as the initial shapes
    /// span it. `None`: not checked.
    pub spacing: Option<(f64, f64)>,
    /// Fore-aft step every two birds under [`crate::keyshape::separate::STEP_SPAN`] apart
    /// laterally must keep, wingspans (0: not checked).
    pub min_step: f64,
}

impl Structure {
    /// The structure of a first key shape with lateral positions `x` and depths `y`.
    pub fn of(x: &[f64], y: &[f64], leader: usize, max_depth: f64) -> Structure {
        let mut idx: Vec<usize> = (0..x.len()).collect();
        idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
        let lp = idx.iter().position(|&i| i == leader).unwrap_or(0);
        let mut pairs = Vec::new();
        // Left arm: from the leader outward is toward smaller rank.
        for r in (1..=lp).rev() {
            let (inner, outer) = (idx[r], idx[r - 1]);
            if y[outer] >= y[inner] {
                pairs.push((inner, outer));
            }
        }
        for r in lp..idx.len().saturating_sub(1) {
            let (inner, outer) = (idx[r], idx[r + 1]);
            if y[outer] >= y[inner] {
                pairs.push((inner, outer));
            }
        }
        Structure {
            leader,
            monotone_pairs: pairs,
            max_depth,
            monotone_tolerance: 0.1,
            spacing: None,
            min_step: 0.0,
        }
    }

    /// True when the depths `y` at lateral positions `x` keep the leader front-most, the depth
    /// limit, the arms' monotone steps, the spacing band and the fore-aft step between birds
    /// near each other laterally.
    pub fn accepts(&self, x: &[f64], y: &[f64]) -> bool {
        let Some(&yl) = y.get(self.leader) else {
            return false;
        };
        let ok_leader = y
            .iter()
            .enumerate()
            .all(|(i, &v)| i == self.leader || v > yl);
        let ok_depth = y.iter().all(|&v| v - yl <= self.max_depth);
        let ok_arms = self
            .monotone_pairs
            .iter()
            .all(|&(inner, outer)| y[outer] >= y[inner] - self.monotone_tolerance);
        ok_leader
            && ok_depth
            && ok_arms
            && (self.min_step <= 0.0
                || crate::keyshape::separate::abreast(x, y, self.min_step).is_none())
            && self.spacing.map_or(true, |(lo, hi)| {
                let m = crate::keyshape::spacing::spacing([(x, y)]).1;
                m >= lo && m <= hi
            })
    }
}

/// Draws ξ̂_k by eq. (2) uniformly in each bird's interval, then renormalises, clips into the
/// feasible ranges and renormalises again, until both hold (Σ ξ̂ = 1, as Munk's theorem requires,
/// and every ξ̂_i inside its range).
pub fn draw_target(
    prev: &[f64],
    feasible: &XiRanges,
    c1: f64,
    c2: f64,
    rng: &mut impl Rng,
) -> Vec<f64> {
    let mut xi: Vec<f64> = prev
        .iter()
        .zip(&feasible.min)
        .zip(&feasible.max)
        .map(|((&p, &lo), &hi)| {
            // The step ratios of eq. (2); for a negative ξ (a bird in downwash) c₁p > c₂p.
            let (r1, r2) = (c1 * p, c2 * p);
            let a = lo.max(r1.min(r2));
            let b = hi.min(r1.max(r2));
            let u: f64 = rng.random();
            if a <= b {
                a + u * (b - a)
            } else {
                // Empty intersection (ξ̂_{k−1} outside its range): the range end nearest to it.
                p.clamp(lo, hi.max(lo))
            }
        })
        .collect();
    // Renormalise, clip, renormalise (the last step can push a clipped value out again by the
    // rescaling; repeating converges to a point of the box ∩ simplex, which is not empty: it holds
    // every initial shape's ξ).
    renormalise(&mut xi);
    for _ in 0..100 {
        if feasible.excess(&xi) <= 1e-13 {
            break;
        }
        feasible.clip(&mut xi);
        renormalise(&mut xi);
    }
    xi
}

fn renormalise(xi: &mut [f64]) {
    let s: f64 = xi.iter().sum();
    if s > 0.0 && s.is_finite() {
        for v in xi.iter_mut() {
            *v /= s;
        }
    }
}

enum Attempt {
    Accepted(Vec<f64>, Vec<f64>, f64),
    Rejected,
}

/// Solves for `target` from `start` at the lateral positions `ctx.x`, checks the result against
/// `prev` and `ctx`'s structure and options; counts into `stats`.
fn attempt(
    ctx: &KeyContext,
    prev: &KeyShape,
    start: &[f64],
    target: &[f64],
    stats: &mut KeyStats,
) -> Result<Attempt> {
    let KeyContext {
        x,
        structure,
        opts,
        solve: solve_opts,
        ..
    } = *ctx;
    stats.solves += 1;
    // A predicted start may put two birds wing to wing; the solve starts from them separated.
    let start = crate::keyshape::separate::separate(x, start, &solve_opts.aero);
    let report = match solve(x, target, Some(&start), solve_opts) {
        Ok(r) => r,
        Err(Error::Unreachable(_) | Error::Collision { .. } | Error::NotConverged(_)) => {
            stats.solve_errors += 1;
            return Ok(Attempt::Rejected);
        }
        Err(e) => return Err(e),
    };
    stats.evaluations += report.evaluations;
    if !(report.residual.is_finite() && report.residual <= opts.accept_residual)
        || report.y.len() != x.len()
        || report.y.iter().any(|v| !v.is_finite())
    {
        stats.rejected_residual += 1;
        return Ok(Attempt::Rejected);
    }
    // Leader at 0 (the solver puts the front-most bird there; re-anchor on ours).
    let yl = report.y[structure.leader];
    let y: Vec<f64> = report.y.iter().map(|v| v - yl).collect();
    if !structure.accepts(x, &y) {
        stats.rejected_structure += 1;
        return Ok(Attempt::Rejected);
    }
    if max_jump(&prev.y, &y) > opts.max_jump {
        stats.rejected_jump += 1;
        return Ok(Attempt::Rejected);
    }
    Ok(Attempt::Accepted(y, report.xi, report.residual))
}

/// Largest |Δy_i| between two shapes, wingspans.
pub fn max_jump(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

/// What every key shape of one flight shares.
#[derive(Debug, Clone, Copy)]
pub struct KeyContext<'a> {
    /// Lateral positions, wingspans.
    pub x: &'a [f64],
    /// Feasible ranges of ξ (already widened by ε).
    pub feasible: &'a XiRanges,
    /// Leader, arms and depth to keep.
    pub structure: &'a Structure,
    /// Step-3 options.
    pub opts: &'a KeyOptions,
    /// The solve's options (from [`KeyOptions::solve_options`]).
    pub solve: &'a SolveOptions,
    /// E of every key shape (Munk: fixed by `x`).
    pub total: f64,
}

/// First-order prediction of the key shape for `target`: the Newton step of eq. (4) from the
/// previous shape, Δy = J⁻¹ E (ξ̂ − ξ_{k−1}) with J = ∂e/∂y at the previous shape, the leader's row
/// and column removed (e is invariant under a common shift, and Σ e_i = E is fixed, so the rest
/// of J is positive definite: e is the gradient of a convex potential).
struct Predictor {
    lu: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
    leader: usize,
    total: f64,
    /// ξ of the previous shape's y at this key's lateral positions (they drift between keys).
    base: Vec<f64>,
}

impl Predictor {
    fn new(
        x: &[f64],
        prev: &KeyShape,
        leader: usize,
        total: f64,
        aero: &crate::aero::AeroOptions,
    ) -> Option<Predictor> {
        let n = x.len();
        if n < 2 || leader >= n {
            return None;
        }
        let jac = aero.power_jacobian_unchecked(x, &prev.y);
        let keep: Vec<usize> = (0..n).filter(|&i| i != leader).collect();
        let m = nalgebra::DMatrix::from_fn(n - 1, n - 1, |r, c| jac[keep[r] * n + keep[c]]);
        let lu = m.lu();
        if !lu.is_invertible() {
            return None;
        }
        let e = aero.power_lenient(x, &prev.y);
        let base = if prev.x.as_slice() == x {
            prev.xi.clone()
        } else {
            e.iter().map(|v| v / total).collect()
        };
        Some(Predictor {
            lu,
            leader,
            total,
            base,
        })
    }

    fn predict(&self, prev: &KeyShape, target: &[f64]) -> Option<Vec<f64>> {
        let n = prev.y.len();
        let rhs = nalgebra::DVector::from_iterator(
            n - 1,
            (0..n)
                .filter(|&i| i != self.leader)
                .map(|i| self.total * (target[i] - self.base[i])),
        );
        let dy = self.lu.solve(&rhs)?;
        let mut y = prev.y.clone();
        let mut r = 0;
        for (i, v) in y.iter_mut().enumerate() {
            if i != self.leader {
                *v += dy[r];
                r += 1;
            }
        }
        y.iter().all(|v| v.is_finite()).then_some(y)
    }
}

/// The next key shape after `prev` (§5 step 3): redraws first, damping as the fallback, the
/// previous shape held as the last resort (never an error for an unlucky draw).
///
/// Each draw is first judged on its linear prediction (cheap): a draw whose predicted shape
/// breaks the structure or jumps more than `max_jump` is redrawn without a solve; a promising
/// one is solved starting from the prediction, so LM starts next to the answer. When every draw
/// fails, the draws are damped in turn: λ is halved until the prediction passes, then solved, and
/// halved again while the solve is rejected.
pub fn next_key(
    ctx: &KeyContext,
    prev: &KeyShape,
    home: Option<(&[f64], f64)>,
    rng: &mut impl Rng,
    stats: &mut KeyStats,
) -> Result<KeyShape> {
    let KeyContext {
        x,
        feasible,
        structure,
        opts,
        solve: solve_opts,
        total,
    } = *ctx;
    // The lateral positions drifted since the previous key: its fore-aft placement at the new
    // positions is the reference of eq. (2) (and the fallback at λ = 0, reachable by design).
    let moved;
    let mut hull = XiRanges {
        min: vec![],
        max: vec![],
    };
    let prev = if prev.x.as_slice() == x {
        prev
    } else {
        // A pair brought wing to wing by the drift: the bird behind drops back (as in step 1).
        let y = crate::keyshape::separate::separate(x, &prev.y, &solve_opts.aero);
        let xi: Vec<f64> = solve_opts
            .aero
            .power_lenient(x, &y)
            .iter()
            .map(|e| e / total)
            .collect();
        // The reference of eq. (2) is this placement as it is (ξ̂ at λ = 0, which the previous
        // y solves exactly); the ranges at the new positions are extended to it, so that the
        // damped targets between it and a draw inside the ranges stay in them.
        hull = feasible.including(&xi);
        moved = KeyShape {
            x: x.to_vec(),
            y,
            xi_target: xi.clone(),
            xi,
            ..prev.clone()
        };
        &moved
    };
    let feasible = if hull.is_empty() { feasible } else { &hull };
    let predictor = Predictor::new(x, prev, structure.leader, total, &solve_opts.aero);
    let promising = |y: &[f64]| structure.accepts(x, y) && max_jump(&prev.y, y) <= opts.max_jump;
    let mut tried: Vec<Vec<f64>> = Vec::new();
    let mut draws = 0;
    for _ in 0..opts.max_draws.max(1) {
        let mut target = draw_target(&prev.xi_target, feasible, opts.c1, opts.c2, rng);
        if let Some((xi0, w)) = home {
            // A loop returns to its first key: the draw is pulled toward it (Σ stays 1).
            for (t, h) in target.iter_mut().zip(xi0) {
                *t += w * (h - *t);
            }
        }
        draws += 1;
        stats.draws += 1;
        if draws > 1 {
            stats.redraws += 1;
        }
        let predicted = predictor.as_ref().and_then(|p| p.predict(prev, &target));
        let start = match &predicted {
            Some(y) if promising(y) => y.clone(),
            Some(_) => {
                stats.rejected_predicted += 1;
                tried.push(target);
                continue;
            }
            None => prev.y.clone(),
        };
        if let Attempt::Accepted(y, xi, residual) = attempt(ctx, prev, &start, &target, stats)? {
            return Ok(KeyShape {
                x: x.to_vec(),
                y,
                xi_target: target,
                xi,
                residual,
                damping: 1.0,
                draws,
            });
        }
        tried.push(target);
    }
    // Damping: each draw in turn, λ halved until its prediction passes, then solved.
    for draw in &tried {
        let mut lambda = 1.0;
        for _ in 0..opts.max_damping {
            lambda *= 0.5;
            let target: Vec<f64> = prev
                .xi_target
                .iter()
                .zip(draw)
                .map(|(p, d)| p + lambda * (d - p))
                .collect();
            let predicted = predictor.as_ref().and_then(|p| p.predict(prev, &target));
            let start = match &predicted {
                Some(y) if promising(y) => y.clone(),
                Some(_) => continue,
                None => prev.y.clone(),
            };
            if let Attempt::Accepted(y, xi, residual) = attempt(ctx, prev, &start, &target, stats)?
            {
                stats.damped += 1;
                return Ok(KeyShape {
                    x: x.to_vec(),
                    y,
                    xi_target: target,
                    xi,
                    residual,
                    damping: lambda,
                    draws,
                });
            }
        }
    }
    stats.held += 1;
    Ok(KeyShape {
        damping: 0.0,
        draws,
        ..prev.clone()
    })
}

/// One key's lateral positions and what depends on them.
#[derive(Debug, Clone)]
pub struct LateralKey {
    /// Lateral positions, wingspans.
    pub x: Vec<f64>,
    /// E there (Munk), dimensionless.
    pub total: f64,
    /// Feasible ranges of ξ there (the initial shapes' ξ at these positions, widened by ε).
    pub feasible: XiRanges,
}

/// The lateral positions of every key (with E and the feasible ranges there), and whether the
/// keys return to the first one (a loop: each draw is pulled toward the first key's ξ̂, more so
/// near the end).
#[derive(Debug, Clone, Default)]
pub struct KeyPlan {
    /// Per key (the first included): its lateral positions; empty: `ctx.x` for every key.
    pub lateral: Vec<LateralKey>,
    /// Pull the draws back toward the first key (a loop).
    pub home: bool,
}

/// `ctx` at the lateral positions of `l` (`None`: as it is).
fn context_at<'b>(ctx: &KeyContext<'b>, l: Option<&'b LateralKey>) -> KeyContext<'b> {
    match l {
        Some(l) => KeyContext {
            x: &l.x,
            total: l.total,
            feasible: &l.feasible,
            ..*ctx
        },
        None => *ctx,
    }
}

/// `count` key shapes starting from `first` (already solved), each from the one before, key k
/// at the lateral positions `plan.lateral[k]`. When no shape fits a key's drifted positions
/// (every damped target failed), that key keeps the previous key's positions
/// (`KeyStats::lateral_held`).
pub fn key_shapes(
    ctx: &KeyContext,
    plan: &KeyPlan,
    first: KeyShape,
    count: usize,
    lateral_at: &dyn Fn(&[f64]) -> Option<LateralKey>,
    rng: &mut impl Rng,
    mut on_key: impl FnMut(),
) -> Result<(Vec<KeyShape>, KeyStats)> {
    let mut stats = KeyStats {
        min_damping: 1.0,
        max_residual: first.residual,
        ..KeyStats::default()
    };
    let mut keys = Vec::with_capacity(count);
    keys.push(first);
    on_key();
    // The positions the previous key has (`None`: `ctx.x`).
    let mut current: Option<LateralKey> = plan.lateral.first().cloned();
    while keys.len() < count {
        let prev = keys
            .last()
            .ok_or_else(|| Error::Internal("no key".into()))?;
        let at = keys.len();
        let mut here = plan.lateral.get(at).cloned().or_else(|| current.clone());
        // After a key that kept older positions, the plan can be more than `max_jump` away:
        // this key goes that far toward it.
        if let Some(l) = &here {
            let jump = max_jump(&prev.x, &l.x);
            if jump > ctx.opts.max_jump {
                let f = ctx.opts.max_jump / jump;
                let x: Vec<f64> = prev
                    .x
                    .iter()
                    .zip(&l.x)
                    .map(|(a, b)| a + f * (b - a))
                    .collect();
                here = lateral_at(&x).or_else(|| current.clone());
            }
        }
        let w = (at as f64 / count.max(2) as f64).powi(2);
        let home = plan.home.then(|| (keys[0].xi_target.as_slice(), w));
        let mut k = next_key(&context_at(ctx, here.as_ref()), prev, home, rng, &mut stats)?;
        if k.damping == 0.0 && k.x != prev.x {
            // No shape at the drifted lateral positions: this key keeps the previous ones.
            stats.held -= 1;
            stats.lateral_held += 1;
            k = next_key(
                &context_at(ctx, current.as_ref()),
                prev,
                home,
                rng,
                &mut stats,
            )?;
        } else {
            current = here;
        }
        stats.min_damping = stats.min_damping.min(k.damping);
        stats.max_residual = stats.max_residual.max(k.residual);
        stats.max_jump = stats.max_jump.max(max_jump(&prev.y, &k.y));
        keys.push(k);
        on_key();
    }
    stats.keys = keys.len();
    Ok((keys, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn draws_respect_eq2_and_sum_to_one() {
        let feasible = XiRanges {
            min: vec![0.05, 0.1, 0.2, 0.1],
            max: vec![0.2, 0.3, 0.5, 0.4],
        };
        let mut prev = vec![0.1, 0.2, 0.4, 0.3];
        let mut rng = seeded(3);
        for _ in 0..500 {
            let d = draw_target(&prev, &feasible, 0.85, 1.15, &mut rng);
            let s: f64 = d.iter().sum();
            assert!((s - 1.0).abs() < 1e-12);
            for i in 0..4 {
                assert!(d[i] >= feasible.min[i] - 1e-12 && d[i] <= feasible.max[i] + 1e-12);
                assert!(d[i] >= prev[i] * 0.85 * 0.8 && d[i] <= prev[i] * 1.15 * 1.2);
            }
            prev = d;
        }
    }

    #[test]
    fn structure_keeps_leader_and_arms() {
        let x = [-2.0, -1.0, 0.0, 1.0, 2.0];
        let y = [1.4, 0.7, 0.0, 0.7, 1.4];
        let mut s = Structure::of(&x, &y, 2, 5.0);
        assert_eq!(s.monotone_pairs.len(), 4);
        assert!(s.accepts(&x, &y));
        assert!(
            !s.accepts(&x, &[1.4, 0.7, 0.0, -0.1, 1.4]),
            "bird ahead of leader"
        );
        assert!(
            !s.accepts(&x, &[0.5, 0.7, 0.0, 0.7, 1.4]),
            "arm not monotone"
        );
        assert!(
            s.accepts(&x, &[0.65, 0.7, 0.0, 0.7, 1.4]),
            "within the tolerance"
        );
        assert!(!s.accepts(&x, &[1.4, 0.7, 0.0, 0.7, 6.0]), "too deep");
        // The spacing band: median step to the nearest bird ahead 0.7 here.
        s.spacing = Some((0.6, 0.8));
        assert!(s.accepts(&x, &y));
        assert!(
            !s.accepts(&x, &[2.0, 1.0, 0.0, 1.0, 2.0]),
            "steps of 1 outside the band"
        );
    }
}
