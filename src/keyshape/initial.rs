//! §5 step 1: the correspondence between the N animated birds and the N̂ movie birds, and one
//! N-bird initial shape per movie frame. Takes the formation parameters of §4 (docs/formats.md §4.2); gives
//! shapes in the formation frame (`x` right of the flight direction, `y` behind the leader),
//! wingspans. Animated birds are indexed left to right (smallest `x` first).
//!
//! The correspondence (derived from the first movie frame, as the paper does): the leaders are
//! matched; each side of the animated flock gets a share of the N − 1 followers proportional to the
//! movie's side sizes, so the side with more birds is matched to the side with more birds; then,
//! per side, the bird closest to the leader, the farthest one, the outliers and finally the inliers
//! are placed at the animated slot whose rank from the leader is proportional to theirs (the nearest
//! free slot). When N > N̂ the slots left free are the added birds, spread uniformly between the
//! matched ones; when N < N̂ the movie birds that find no free slot are dropped, inliers first,
//! so the special roles (closest, farthest, outliers) survive the reduction.

use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::extract::params::{FormationParams, FrameParams, ShapeModel};
use crate::shape::Shape;

/// Which movie bird each animated bird stands for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Correspondence {
    /// Number of animated birds, N.
    pub birds: usize,
    /// Index of the animated leader (= number of birds to its left).
    pub leader: usize,
    /// Movie bird id per animated bird (left to right); `None` for added birds.
    pub movie: Vec<Option<usize>>,
    /// Movie birds of the first frame that have no animated counterpart (N < N̂).
    pub dropped: Vec<usize>,
}

/// Options of step 1 (the `steady.initial` section of [`crate::pipeline::Config`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitialOptions {
    /// The one physical bound on a lateral gap drawn from the footage's N(μ_x, σ_x), wingspans,
    /// in [0, 1): a gap at or below it (about a body's width: birds nearly in line astern, body
    /// behind body) is redrawn. Overlapping wingtips (gaps under π/4) are kept: real geese fly
    /// there, and the model covers them; wings side by side are excluded later, fore and aft, by
    /// the collision rule (`aero::AeroOptions::collision_chord`).
    pub min_gap: f64,
    /// Redraws of one gap (or deviation) before it is clamped to `min_gap` (or the mean, if
    /// larger), count.
    pub max_gap_draws: usize,
    /// Every follower stays at least this far behind the leader, wingspans (≥ 0): the leader is
    /// the front-most bird by definition (§4), so a Gaussian deviation that would put a follower
    /// abreast of or ahead of it is redrawn (and, after `max_gap_draws` tries or for a carried
    /// outlier deviation, clamped).
    pub lead_margin: f64,
}

impl Default for InitialOptions {
    fn default() -> Self {
        InitialOptions {
            min_gap: 0.1,
            max_gap_draws: 64,
            lead_margin: 0.05,
        }
    }
}

impl InitialOptions {
    /// Checks every option; the error names the option path (`steady.initial.min_gap`).
    pub fn validate(&self) -> Result<()> {
        if !(self.min_gap.is_finite() && self.min_gap >= 0.0 && self.min_gap < 1.0) {
            return Err(Error::parameter(
                "steady.initial.min_gap",
                format!("{}: must be a number of wingspans in [0, 1)", self.min_gap),
            ));
        }
        if !(self.lead_margin.is_finite() && (0.0..=1.0).contains(&self.lead_margin)) {
            return Err(Error::parameter(
                "steady.initial.lead_margin",
                format!(
                    "{}: must be a number of wingspans in [0, 1]",
                    self.lead_margin
                ),
            ));
        }
        Ok(())
    }
}

/// Builds the correspondence of §5 step 1 from the first movie frame for `n` animated birds.
pub fn correspondence(first: &FrameParams, n: usize) -> Result<Correspondence> {
    correspondence_split(first, n, None)
}

/// Animated birds left of the leader in a formation of `n` birds: the proportional split of the
/// N − 1 followers, monotone in the first movie frame's left share, so the larger movie side
/// stays the larger (or equal) animated side.
pub fn proportional_left(first: &FrameParams, n: usize) -> usize {
    let n_hat = first.order.len();
    let lead_pos = first
        .order
        .iter()
        .position(|&id| id == first.leader)
        .unwrap_or(0);
    if n_hat <= 1 || n < 2 {
        0
    } else {
        (((n - 1) as f64) * (lead_pos as f64) / ((n_hat - 1) as f64)).round() as usize
    }
}

/// [`correspondence`] with the number of animated birds left of the leader given (`left`, at
/// most N − 1; a start file's formation), instead of the movie's proportional split.
pub fn correspondence_split(
    first: &FrameParams,
    n: usize,
    left: Option<usize>,
) -> Result<Correspondence> {
    if n < 2 {
        return Err(Error::parameter(
            "steady.birds",
            format!("{n} bird(s): a formation needs at least 2"),
        ));
    }
    let order = &first.order;
    let lead_pos = order
        .iter()
        .position(|&id| id == first.leader)
        .ok_or_else(|| Error::Internal("leader not in order (params not validated)".into()))?;
    let left = left
        .unwrap_or_else(|| proportional_left(first, n))
        .min(n - 1);
    let right = n - 1 - left;

    let mut movie = vec![None; n];
    movie[left] = Some(first.leader);
    let mut dropped = Vec::new();

    // Movie side lists, closest to the leader first.
    let movie_left: Vec<usize> = order[..lead_pos].iter().rev().copied().collect();
    let movie_right: Vec<usize> = order[lead_pos + 1..].to_vec();
    for (side_ids, slots, to_index) in [
        (
            movie_left,
            left,
            Box::new(|s: usize| left - 1 - s) as Box<dyn Fn(usize) -> usize>,
        ),
        (movie_right, right, Box::new(|s: usize| left + 1 + s)),
    ] {
        let assigned = match_side(&side_ids, slots, &first.outliers, &mut dropped);
        for (slot, id) in assigned.into_iter().enumerate() {
            movie[to_index(slot)] = id;
        }
    }
    dropped.sort_unstable();
    Ok(Correspondence {
        birds: n,
        leader: left,
        movie,
        dropped,
    })
}

/// Places the movie birds of one side (closest first) into `slots` animated slots (closest first).
///
/// With at least as many slots as movie birds, every movie bird is placed, in the priority
/// closest, farthest, outliers, inliers, at the slot whose rank is proportional to its own (the
/// nearest free one). With fewer slots (a choice the paper leaves open) the side is sub-sampled
/// uniformly: the closest and the farthest bird keep the end slots, the side's outliers keep
/// their share of the slots (round(outliers · slots / birds), closest first, at their
/// proportional slots), and every other slot takes the inlier whose rank is nearest to the
/// slot's proportional rank, so the survivors are spread along the side as the footage's birds
/// are (not crowded next to the leader) and the smaller flock has the footage's share of
/// stragglers.
fn match_side(
    ids: &[usize],
    slots: usize,
    outliers: &[usize],
    dropped: &mut Vec<usize>,
) -> Vec<Option<usize>> {
    let mut out = vec![None; slots];
    let k = ids.len();
    if k == 0 {
        return out;
    }
    let proportional = |r: usize| -> usize {
        if k == 1 || slots <= 1 {
            0
        } else {
            ((r as f64) * ((slots - 1) as f64) / ((k - 1) as f64)).round() as usize
        }
    };
    let middle = 1..k.saturating_sub(1);
    let (out_ranks, in_ranks): (Vec<usize>, Vec<usize>) =
        middle.partition(|&r| outliers.contains(&ids[r]));
    let mut placed = vec![false; k];
    let mut place = |out: &mut Vec<Option<usize>>, r: usize| {
        if let Some(s) = nearest_free(out, proportional(r)) {
            out[s] = Some(r);
            placed[r] = true;
        }
    };
    // Closest, farthest.
    place(&mut out, 0);
    if k > 1 {
        place(&mut out, k - 1);
    }
    if slots >= k {
        for r in out_ranks.iter().chain(&in_ranks) {
            place(&mut out, *r);
        }
    } else {
        let share = ((out_ranks.len() * slots) as f64 / k as f64).round() as usize;
        for r in out_ranks.iter().take(share) {
            place(&mut out, *r);
        }
        // Each free slot takes the unplaced inlier nearest to its proportional rank (ties
        // toward the leader), between the ranks of the slots' placed neighbours.
        for s in 0..slots {
            if out[s].is_some() {
                continue;
            }
            let want = if slots <= 1 {
                0.0
            } else {
                s as f64 * (k - 1) as f64 / (slots - 1) as f64
            };
            let lo = out[..s].iter().flatten().max().copied();
            let hi = out[s + 1..].iter().flatten().min().copied();
            let best = in_ranks
                .iter()
                .copied()
                .filter(|&r| !placed[r] && lo.map_or(true, |l| r > l) && hi.map_or(true, |h| r < h))
                .min_by(|&a, &b| {
                    (a as f64 - want)
                        .abs()
                        .total_cmp(&(b as f64 - want).abs())
                        .then(a.cmp(&b))
                });
            if let Some(r) = best {
                out[s] = Some(r);
                placed[r] = true;
            }
        }
    }
    for (r, &id) in ids.iter().enumerate() {
        if !placed[r] {
            dropped.push(id);
        }
    }
    // Collisions can swap neighbours; keep the movie's lateral order on the occupied slots (the
    // priority decided which birds survive and which slots they occupy, not their order).
    let mut ranks: Vec<usize> = out.iter().flatten().copied().collect();
    ranks.sort_unstable();
    let mut ranks = ranks.into_iter();
    for slot in out.iter_mut().filter(|s| s.is_some()) {
        *slot = ranks.next().map(|r| ids[r]);
    }
    out
}

/// The free slot nearest to `target`, ties toward the leader.
fn nearest_free(slots: &[Option<usize>], target: usize) -> Option<usize> {
    let n = slots.len();
    for d in 0..n {
        if target >= d && target - d < n && slots[target - d].is_none() {
            return Some(target - d);
        }
        if target + d < n && slots[target + d].is_none() {
            return Some(target + d);
        }
    }
    None
}

/// `count` lateral gaps from N(μ, σ), each redrawn while it is at or below `opts.min_gap`
/// (the only bound: see [`InitialOptions::min_gap`]), wingspans.
pub fn lateral_gaps(
    rng: &mut impl Rng,
    mu: f64,
    sigma: f64,
    count: usize,
    opts: &InitialOptions,
) -> Vec<f64> {
    let floor = opts.min_gap;
    let normal = Normal::new(mu, sigma.max(0.0)).ok();
    (0..count)
        .map(|_| {
            if let Some(normal) = &normal {
                for _ in 0..opts.max_gap_draws {
                    let g = normal.sample(rng);
                    if g > floor {
                        return g;
                    }
                }
            }
            mu.max(floor)
        })
        .collect()
}

/// Lateral positions with the leader (index `leader`) at 0 from the N − 1 gaps between lateral
/// neighbours, left to right, wingspans.
pub fn positions_from_gaps(gaps: &[f64], leader: usize) -> Vec<f64> {
    let n = gaps.len() + 1;
    let mut x = vec![0.0; n];
    for i in (0..leader).rev() {
        x[i] = x[i + 1] - gaps[i];
    }
    for i in leader + 1..n {
        x[i] = x[i - 1] + gaps[i - 1];
    }
    x
}

/// The curve's `y` behind the leader at animated lateral offset `x` (leader on the curve).
///
/// V and line curves are evaluated as they are (their arms keep their angle however many birds
/// fly). A U or J parabola is mapped by rank: with s the ratio of movie to animated birds on that
/// side, the animated bird at x takes the movie curve's slope at x·s, i.e.
/// y = (curve(x·s) − curve(0))/s. Each bird then sits behind its lateral neighbour by what the
/// movie bird of the same relative rank does (the footage's spacing), and a flock with
/// more birds per side makes a U of the movie's proportions that is deeper in proportion to its
/// birds per side (with the movie's depth, the neighbours of a larger flock would crowd
/// together fore and aft; with the unscaled parabola, its outer birds would string out).
pub fn curve_y(model: &ShapeModel, x: f64, scale_left: f64, scale_right: f64) -> f64 {
    match model {
        ShapeModel::U { .. } | ShapeModel::J { .. } => {
            let s = if x < 0.0 { scale_left } else { scale_right };
            if s > 0.0 && s.is_finite() {
                (model.y_at(x * s) - model.y_at(0.0)) / s
            } else {
                model.y_at(x) - model.y_at(0.0)
            }
        }
        _ => model.y_at(x) - model.y_at(0.0),
    }
}

/// One initial shape per movie frame (§5 step 1): lateral gaps from N(μ_x, σ_x), `y` on the
/// frame's curve, the movie outliers' deviations carried over to their animated counterparts and
/// N(μ_y, σ_y) deviations for every other follower, which stay at least `lead_margin` behind the
/// leader at (0, 0).
pub fn initial_shapes(
    params: &FormationParams,
    corr: &Correspondence,
    rng: &mut impl Rng,
    opts: &InitialOptions,
) -> Vec<Shape> {
    initial_shapes_scaled(params, corr, side_scales(params, corr), rng, opts)
}

/// [`initial_shapes`] with the U and J curves' rank scales (left, right) given (see
/// [`curve_y`]; [`side_scales`] are the plain ratios of birds per side).
pub fn initial_shapes_scaled(
    params: &FormationParams,
    corr: &Correspondence,
    (scale_left, scale_right): (f64, f64),
    rng: &mut impl Rng,
    opts: &InitialOptions,
) -> Vec<Shape> {
    let n = corr.birds;
    params
        .frames
        .iter()
        .map(|f| {
            let gaps = lateral_gaps(rng, f.mu_x, f.sigma_x, n - 1, opts);
            let x = positions_from_gaps(&gaps, corr.leader);
            let dev = Normal::new(f.mu_y, f.sigma_y.max(0.0)).ok();
            let y: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(i, &xi)| {
                    if i == corr.leader {
                        return 0.0;
                    }
                    let base = curve_y(
                        &f.shape,
                        depth_x(&f.shape, xi, i, corr.leader, f.mu_x),
                        scale_left,
                        scale_right,
                    );
                    let carried = corr.movie[i].and_then(|id| {
                        if f.outliers.contains(&id) {
                            f.positions.iter().find(|p| p.id == id).map(|p| p.dy)
                        } else {
                            None
                        }
                    });
                    let y = match (carried, &dev) {
                        (Some(d), _) => base + d,
                        (None, None) => base + f.mu_y,
                        (None, Some(dev)) => {
                            let mut y = base + dev.sample(rng);
                            for _ in 0..opts.max_gap_draws {
                                if y >= opts.lead_margin {
                                    break;
                                }
                                y = base + dev.sample(rng);
                            }
                            y
                        }
                    };
                    y.max(opts.lead_margin)
                })
                .collect();
            Shape::from_xy(&x, &y)
        })
        .collect()
}

/// Where a bird's depth is read on the frame's curve: its lateral offset `x` for V and line
/// curves, and for U and J parabolas its **rank** from the leader times the frame's mean lateral
/// gap `mu_x` (signed like `x`). A parabola's step between neighbours grows with the square of the
/// lateral offset, so reading it at the noisy drawn offsets would turn every wide gap near the
/// flock's ends into a deep step (the U's and J's neighbours would sit about a third farther
/// apart fore and aft than the footage's); by rank, each bird sits behind its neighbour by what
/// the movie bird of the same relative rank does.
pub fn depth_x(model: &ShapeModel, x: f64, index: usize, leader: usize, mu_x: f64) -> f64 {
    match model {
        ShapeModel::U { .. } | ShapeModel::J { .. } if mu_x > 0.0 && mu_x.is_finite() => {
            (index as f64 - leader as f64) * mu_x
        }
        _ => x,
    }
}

/// The factors that map animated lateral offsets onto the movie's curve for U and J shapes (see
/// [`curve_y`]): movie birds per animated bird on the left and on the right of the leader.
pub fn side_scales(params: &FormationParams, corr: &Correspondence) -> (f64, f64) {
    let Some(first) = params.frames.first() else {
        return (1.0, 1.0);
    };
    let lead_pos = first
        .order
        .iter()
        .position(|&id| id == first.leader)
        .unwrap_or(0);
    let movie_left = lead_pos as f64;
    let movie_right = (first.order.len() - 1 - lead_pos) as f64;
    let anim_left = corr.leader as f64;
    let anim_right = (corr.birds - 1 - corr.leader) as f64;
    let ratio = |m: f64, a: f64| if m > 0.0 && a > 0.0 { m / a } else { 1.0 };
    (ratio(movie_left, anim_left), ratio(movie_right, anim_right))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extract::params::LineCoef;
    use crate::rng::seeded;

    fn frame(order: Vec<usize>, leader: usize, outliers: Vec<usize>) -> FrameParams {
        FrameParams {
            index: 0,
            inliers: order
                .iter()
                .copied()
                .filter(|i| !outliers.contains(i))
                .collect(),
            order,
            leader,
            mu_x: 1.0,
            sigma_x: 0.2,
            mu_y: 0.0,
            sigma_y: 0.1,
            shape: ShapeModel::V {
                left: LineCoef {
                    intercept: 0.0,
                    slope: -0.7,
                },
                right: LineCoef {
                    intercept: 0.0,
                    slope: 0.7,
                },
            },
            outliers,
            positions: vec![],
            geometry: None,
        }
    }

    fn matched(c: &Correspondence) -> Vec<usize> {
        let mut m: Vec<usize> = c.movie.iter().flatten().copied().collect();
        m.sort_unstable();
        m
    }

    #[test]
    fn equal_counts_match_one_to_one_in_order() {
        let f = frame(vec![0, 1, 2, 3, 4, 5, 6, 7, 8], 3, vec![6]);
        let c = correspondence(&f, 9).unwrap();
        assert_eq!(c.leader, 3);
        assert_eq!(
            c.movie,
            (0..9).map(Some).collect::<Vec<_>>(),
            "N = N̂ keeps every bird in place"
        );
        assert!(c.dropped.is_empty());
    }

    #[test]
    fn more_birds_keep_roles_and_spread_added_ones() {
        let f = frame(vec![0, 1, 2, 3, 4, 5, 6, 7, 8], 3, vec![6]);
        let c = correspondence(&f, 14).unwrap();
        assert_eq!(c.movie[c.leader], Some(3));
        assert_eq!(
            matched(&c),
            (0..9).collect::<Vec<_>>(),
            "every movie bird kept"
        );
        // Closest and farthest per side.
        assert_eq!(c.movie[c.leader - 1], Some(2));
        assert_eq!(c.movie[c.leader + 1], Some(4));
        assert_eq!(c.movie[0], Some(0));
        assert_eq!(c.movie[13], Some(8));
        // Larger side stays larger.
        assert!(13 - c.leader > c.leader);
        // Added birds are not bunched: no two adjacent added birds on the right side of 5 slots.
        let added: Vec<usize> = (0..14).filter(|&i| c.movie[i].is_none()).collect();
        assert_eq!(added.len(), 5);
    }

    #[test]
    fn fewer_birds_drop_inliers_first() {
        let f = frame(vec![0, 1, 2, 3, 4, 5, 6, 7, 8], 3, vec![6]);
        let c = correspondence(&f, 7).unwrap();
        assert_eq!(c.movie[c.leader], Some(3));
        let m = matched(&c);
        assert!(m.contains(&6), "the outlier survives: {m:?}");
        for id in [0, 2, 4, 8] {
            assert!(m.contains(&id), "closest and farthest kept: {m:?}");
        }
        assert_eq!(c.dropped, vec![1, 7], "inliers dropped");
        // With only the two ends of each side left, closest and farthest win over the outlier.
        let c = correspondence(&f, 5).unwrap();
        assert_eq!(matched(&c), vec![0, 2, 3, 4, 8]);
    }

    proptest::proptest! {
        #[test]
        fn correspondence_is_a_partial_bijection(
            n_hat in 2usize..30,
            n in 2usize..60,
            lead_frac in 0.0f64..1.0,
            out_mask in proptest::collection::vec(proptest::bool::weighted(0.2), 30),
        ) {
            let lead = ((n_hat - 1) as f64 * lead_frac).round() as usize;
            let outliers: Vec<usize> = (0..n_hat).filter(|&i| i != lead && out_mask[i]).collect();
            let f = frame((0..n_hat).collect(), lead, outliers);
            let c = correspondence(&f, n).unwrap();
            proptest::prop_assert_eq!(c.movie.len(), n);
            proptest::prop_assert_eq!(c.movie[c.leader], Some(lead));
            let m = matched(&c);
            let mut all: Vec<usize> = m.iter().chain(&c.dropped).copied().collect();
            all.sort_unstable();
            proptest::prop_assert_eq!(all, (0..n_hat).collect::<Vec<_>>(), "each movie bird once");
            proptest::prop_assert!(c.dropped.len() == n_hat.saturating_sub(n) || n < n_hat);
            if n >= n_hat {
                proptest::prop_assert!(c.dropped.is_empty());
            }
            // Movie side order is kept: matched ids increase left to right.
            proptest::prop_assert!(c.movie.iter().flatten().collect::<Vec<_>>().windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn gaps_keep_the_footage_distribution_above_the_physical_bound() {
        let mut rng = seeded(1);
        let opts = InitialOptions::default();
        let g = lateral_gaps(&mut rng, 0.77, 0.2, 5000, &opts);
        assert!(g.iter().all(|&v| v > opts.min_gap));
        // Overlapping wingtips are kept: the sample mean and spread are the footage's.
        let mean = g.iter().sum::<f64>() / g.len() as f64;
        let sd = (g.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / g.len() as f64).sqrt();
        assert!(
            (mean - 0.77).abs() < 0.01 && (sd - 0.2).abs() < 0.01,
            "{mean} {sd}"
        );
        assert!(
            g.iter()
                .filter(|&&v| v < std::f64::consts::FRAC_PI_4)
                .count()
                > 2000
        );
        let g = lateral_gaps(&mut rng, 0.05, 0.0, 3, &opts);
        assert!(g.iter().all(|&v| v == opts.min_gap));
    }

    #[test]
    fn positions_put_leader_at_zero() {
        let x = positions_from_gaps(&[1.0, 2.0, 3.0], 1);
        assert_eq!(x, vec![-1.0, 0.0, 2.0, 5.0]);
    }

    #[test]
    fn initial_shapes_follow_curve_and_carry_outliers() {
        let mut f = frame(vec![0, 1, 2, 3, 4], 2, vec![4]);
        f.sigma_y = 0.0;
        f.positions = vec![crate::extract::params::BirdPosition {
            id: 4,
            x: 2.0,
            y: 2.5,
            dy: 1.1,
        }];
        let p = FormationParams {
            format: crate::extract::params::PARAMS_FORMAT.into(),
            source: String::new(),
            birds: 5,
            frames: vec![f],
            summary: None,
            motion: None,
            ci: None,
            heights: None,
        };
        let c = correspondence(&p.frames[0], 5).unwrap();
        let s = initial_shapes(&p, &c, &mut seeded(0), &InitialOptions::default());
        assert_eq!(s.len(), 1);
        let b = &s[0].birds;
        assert_eq!(b[2].y, 0.0);
        assert!((b[1].y - 0.7 * b[1].x.abs()).abs() < 1e-12);
        assert!((b[4].y - (0.7 * b[4].x + 1.1)).abs() < 1e-12, "{:?}", b[4]);
    }
}
