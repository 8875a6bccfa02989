//! Key shapes without wing overlap: birds moved back until every two birds near each other
//! laterally keep a fore-aft step.
//!
//! Real birds in a line formation never fly abreast of a neighbour within a wingspan: in the
//! stereo-filmed wild V the project compares against, none of 2453 neighbour pairs was, and the
//! nearest bird ahead was a median 1.24 wingspans in front (quartiles 1.06–1.49). Hummel's model
//! alone only forbids overlapping wings (a chord apart), so the key shapes keep a step of
//! [`MIN_STEP`] between any two birds under [`STEP_SPAN`] apart laterally: well under the
//! footage's lower quartile (the key shapes' own spacing keeps to the footage's median), and
//! enough that the position keeping and the manoeuvres have room fore and aft without a wing
//! passing over another.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::aero::{AeroOptions, COLLISION_SPAN};

/// Benchmarks only (`benches/clearance.rs`): while set, the steady flight runs without its
/// clearance machinery, to measure what it costs: [`separate`] moves no bird, [`min_step`] is 0
/// (key shapes may put neighbours abreast) and every bird's position-keeping room is unbounded
/// ([`crate::keyshape::jostle::rooms`]). The output may then clash; never set outside benchmarks.
#[doc(hidden)]
pub static BENCH_WITHOUT_CLEARANCE: AtomicBool = AtomicBool::new(false);

/// Whether [`BENCH_WITHOUT_CLEARANCE`] is set.
#[doc(hidden)]
pub fn bench_without_clearance() -> bool {
    BENCH_WITHOUT_CLEARANCE.load(Ordering::Relaxed)
}

/// Smallest fore-aft distance between two birds of a key shape that are less than
/// [`STEP_SPAN`] apart laterally, wingspans.
pub const MIN_STEP: f64 = 0.35;

/// Lateral distance under which two birds of a key shape keep [`MIN_STEP`] fore and aft,
/// wingspans: a wingspan (the wings would overlap) and a tenth for the lateral drift between
/// key shapes.
pub const STEP_SPAN: f64 = COLLISION_SPAN + 0.1;

/// Factor on the step by which [`separate`] puts a bird behind another.
pub const CLEAR_STEP: f64 = 1.15;

/// The fore-aft step the key shapes keep with these aerodynamic options: [`MIN_STEP`], or a
/// little more than the collision chord when that is set larger.
pub fn min_step(aero: &AeroOptions) -> f64 {
    if bench_without_clearance() {
        return 0.0;
    }
    MIN_STEP.max(1.05 * aero.collision_chord)
}

/// The first pair (lower index first, in order of the lateral sort) of birds at lateral
/// positions `x` and depths `y` that are under [`STEP_SPAN`] apart laterally and under the
/// step `step` (less a rounding tolerance) fore and aft.
pub fn abreast(x: &[f64], y: &[f64], step: f64) -> Option<(usize, usize)> {
    let mut idx: Vec<usize> = (0..x.len()).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    for (k, &i) in idx.iter().enumerate() {
        for &j in &idx[k + 1..] {
            if !(x[j] - x[i] < STEP_SPAN) {
                break;
            }
            if (y[i] - y[j]).abs() < step - 1e-9 {
                return Some((i.min(j), i.max(j)));
            }
        }
    }
    None
}

/// Moves birds back until no two at lateral positions `x` (wingspans) are abreast: for every
/// pair under [`STEP_SPAN`] apart laterally and under [`min_step`] fore and aft, the rear bird
/// (larger y; ties: the one farther from the front-most bird laterally, then the higher index)
/// is put [`CLEAR_STEP`] times the step behind the other (clear of it, not on the boundary, so
/// that key shapes near this placement are not all rejected). Passes repeat until nothing
/// moves (at most N + 1).
pub fn separate(x: &[f64], y: &[f64], aero: &AeroOptions) -> Vec<f64> {
    let n = x.len();
    let mut y = y.to_vec();
    if bench_without_clearance() {
        return y;
    }
    let step = min_step(aero);
    let front = (0..n)
        .min_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    for _ in 0..=n {
        let mut moved = false;
        for (k, &i) in idx.iter().enumerate() {
            for &j in &idx[k + 1..] {
                if !(x[j] - x[i] < STEP_SPAN) {
                    break;
                }
                if !((y[i] - y[j]).abs() < step - 1e-9) {
                    continue;
                }
                let far = |b: usize| ((x[b] - x[front]).abs(), b);
                let rear = if y[i] != y[j] {
                    if y[i] > y[j] {
                        i
                    } else {
                        j
                    }
                } else if far(i) > far(j) {
                    i
                } else {
                    j
                };
                // The front-most bird stays where it is.
                let rear = if rear == front { i + j - rear } else { rear };
                let other = i + j - rear;
                y[rear] = y[other] + CLEAR_STEP * step;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn abreast_birds_are_stepped_back_and_the_front_stays() {
        let aero = AeroOptions::default();
        // A V with two neighbours on the left arm nearly abreast and a third close behind.
        let x = [-2.7, -1.8, -0.9, 0.0, 0.9, 1.8];
        let y = [1.2, 1.1, 0.5, 0.0, 0.6, 1.2];
        assert_eq!(abreast(&x, &y, MIN_STEP), Some((0, 1)));
        let s = separate(&x, &y, &aero);
        assert_eq!(abreast(&x, &s, MIN_STEP), None, "{s:?}");
        assert_eq!(s[3], 0.0);
        // Only birds that were too close moved, and only backwards.
        for (a, b) in y.iter().zip(&s) {
            assert!(b >= a);
        }
        assert_eq!(&s[2..], &y[2..]);
        // Birds a span and more apart laterally may fly level.
        let (x, y) = ([0.0, 1.2, 2.4], [0.0, 0.0, 0.0]);
        assert_eq!(separate(&x, &y, &aero), y.to_vec());
    }
}
