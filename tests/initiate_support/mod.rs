//! Fixtures shared by the initiation tests: synthetic key shapes (V, U, echelon) and steady-flight
//! animations that carry them north at cruise speed.
#![allow(dead_code)]

use formation::animation::{Frame, KeyBird, KeyShapeRecord, Stage};
use formation::Animation;

/// A V of `n` birds: lateral gap `gap` wingspans, each bird `back` wingspans behind the previous
/// one on its arm; the extra bird (odd follower count) goes to the right arm. Small deterministic
/// irregularities so that arms are not perfectly straight.
pub fn v_shape(n: usize, gap: f64, back: f64) -> Vec<(f64, f64)> {
    let mut pts = vec![(0.0, 0.0)];
    for k in 1..n {
        let rank = k.div_ceil(2) as f64;
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        let wobble = 0.05 * ((k as f64) * 1.7).sin();
        pts.push((side * (gap * rank + wobble), back * rank + wobble));
    }
    pts
}

/// A U: like a V, but the arms curve back (longitudinal step grows outward).
pub fn u_shape(n: usize) -> Vec<(f64, f64)> {
    let mut pts = vec![(0.0, 0.0)];
    let mut y = [0.0f64; 2];
    for k in 1..n {
        let rank = k.div_ceil(2) as f64;
        let a = k % 2;
        y[a] += 0.2 + 0.15 * rank;
        let side = if a == 1 { 1.0 } else { -1.0 };
        pts.push((side * 1.05 * rank, y[a]));
    }
    pts
}

/// An echelon: every follower on the right, 0.95 wingspans across and 0.4 back from the previous.
pub fn echelon(n: usize) -> Vec<(f64, f64)> {
    (0..n).map(|k| (0.95 * k as f64, 0.4 * k as f64)).collect()
}

/// A steady flight of `frames` frames carrying `shape` north at `speed` wingspans per second.
pub fn steady(shape: &[(f64, f64)], frames: usize, fps: f64, speed: f64) -> Animation {
    let n = shape.len();
    let mut a = Animation::new(7, fps, 1.5, n);
    a.stages.push(Stage {
        name: "steady".into(),
        start: 0,
        end: frames,
    });
    a.key_shapes.push(KeyShapeRecord {
        frame: 0,
        birds: shape
            .iter()
            .map(|&(x, y)| KeyBird {
                x,
                y,
                xi: 1.0 / n as f64,
                slot: None,
            })
            .collect(),
    });
    let lead_y = 100.0;
    for k in 0..frames {
        let t = k as f64 / fps;
        let dy = speed * t;
        a.frames.push(Frame {
            t,
            x: shape.iter().map(|p| 5.0 + p.0).collect(),
            y: shape.iter().map(|p| lead_y + dy - p.1).collect(),
            z: vec![0.0; n],
            heading: vec![0.0; n],
            speed: vec![speed; n],
            ..Default::default()
        });
    }
    a
}

/// A steady flight carrying `shape` along `heading` (radians clockwise from north).
pub fn steady_heading(
    shape: &[(f64, f64)],
    frames: usize,
    fps: f64,
    speed: f64,
    heading: f64,
) -> Animation {
    let mut a = steady(shape, frames, fps, speed);
    let (s, c) = heading.sin_cos();
    let d = (s, c);
    let r = (c, -s);
    for (k, f) in a.frames.iter_mut().enumerate() {
        let t = k as f64 / fps;
        let lead = (-3.0 + speed * t * d.0, 4.0 + speed * t * d.1);
        for (i, p) in shape.iter().enumerate() {
            f.x[i] = lead.0 + p.0 * r.0 - p.1 * d.0;
            f.y[i] = lead.1 + p.0 * r.1 - p.1 * d.1;
            f.heading[i] = heading;
        }
    }
    a
}
