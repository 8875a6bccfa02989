//! Key shapes without collisions: birds moved back until no two wings overlap.

use crate::aero::AeroOptions;

/// Moves birds back until no two collide at lateral positions `x` (wingspans): for every pair
/// under one wingspan apart laterally and under `aero.collision_chord` fore and aft, the rear bird
/// (larger y; ties: the one farther from the front-most bird laterally, then the higher index) is
/// put two chords behind the other (clear of its wing, not just touching it, so that key shapes
/// near this placement are not all on the collision boundary). Passes repeat until nothing moves
/// (at most N).
pub fn separate(x: &[f64], y: &[f64], aero: &AeroOptions) -> Vec<f64> {
    let n = x.len();
    let mut y = y.to_vec();
    let chord = aero.collision_chord;
    let front = (0..n)
        .min_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    for _ in 0..n.max(1) {
        let mut moved = false;
        for (k, &i) in idx.iter().enumerate() {
            for &j in &idx[k + 1..] {
                if !(x[j] - x[i] < crate::aero::COLLISION_SPAN) {
                    break;
                }
                if !aero.collides(x[j] - x[i], y[i] - y[j]) {
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
                let other = if rear == i { j } else { i };
                y[rear] = y[other] + 1.05 * chord.max(1e-9);
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    y
}
