//! Clearance: whether two birds of an animation ever fly wing over wing or body into body.
//!
//! The test (the same as `docs/formats.md` states for every written animation): two flying birds
//! (ground speed at least [`FLYING`] wingspans per second) clash by wing when, in the first
//! bird's heading frame, the other is less than [`SPAN`] wingspans aside, [`CHORD`] fore and aft
//! and [`THICKNESS`] in height (their wings would overlap in one plane); any two birds clash by
//! body when their centres are closer than [`BODY`] wingspans in 3-D (birds at rest included).
//! Each pair is counted once a frame (the wing test in the heading frame of the bird with the lower
//! index), as the project's shared clearance tool counts.

use super::{Animation, Frame};

/// Lateral reach of a wing clash, wingspans.
pub const SPAN: f64 = 1.0;
/// Fore-aft reach of a wing clash (about a wing's chord), wingspans.
pub const CHORD: f64 = 0.15;
/// Vertical reach of a wing clash (about a wing's thickness with its flapping), wingspans.
pub const THICKNESS: f64 = 0.08;
/// Closest two bodies may come, wingspans.
pub const BODY: f64 = 0.3;
/// Ground speed from which a bird counts as flying, wingspans per second.
pub const FLYING: f64 = 1.0;
/// Pairs farther apart than this can not clash (wingspans): the grid's cell.
pub const REACH: f64 = 1.2;

/// The closest two birds came.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Their distance, wingspans (3-D).
    pub distance: f64,
    /// The frame (index into the animation's frames).
    pub frame: usize,
    /// The two birds.
    pub birds: (usize, usize),
}

/// Clashes counted over some frames.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Clearance {
    /// Frames looked at.
    pub frames: usize,
    /// Wing clashes (pairs of flying birds, summed over the frames).
    pub wing: usize,
    /// Body clashes (pairs, summed over the frames).
    pub body: usize,
    /// Frames with at least one clash.
    pub frames_with_clash: usize,
    /// The closest pair within the clash reach (1.2 wingspans) of each other, if any came that close.
    pub closest: Option<Closest>,
}

impl Clearance {
    /// Wing and body clashes together.
    pub fn clashes(&self) -> usize {
        self.wing + self.body
    }

    /// Adds another count (of other frames).
    pub fn add(&mut self, other: &Clearance) {
        self.frames += other.frames;
        self.wing += other.wing;
        self.body += other.body;
        self.frames_with_clash += other.frames_with_clash;
        if let Some(c) = other.closest {
            if self.closest.map_or(true, |s| c.distance < s.distance) {
                self.closest = Some(c);
            }
        }
    }

    /// The clearance of the animation's frames `range` (indices into `frames`).
    pub fn of_frames(frames: &[Frame], range: std::ops::Range<usize>) -> Clearance {
        let mut out = Clearance::default();
        let mut grid = Grid::default();
        for k in range {
            if let Some(f) = frames.get(k) {
                out.add(&frame_clearance(f, k, &mut grid));
            }
        }
        out
    }

    /// The clearance of a whole animation.
    pub fn of(anim: &Animation) -> Clearance {
        Clearance::of_frames(&anim.frames, 0..anim.frames.len())
    }

    /// The clearance of each stage of an animation, in stage order, with its name.
    pub fn by_stage(anim: &Animation) -> Vec<(String, Clearance)> {
        anim.stages
            .iter()
            .map(|s| {
                (
                    s.name.to_string(),
                    Clearance::of_frames(&anim.frames, s.start..s.end),
                )
            })
            .collect()
    }
}

/// A uniform grid of cell [`REACH`] over one frame's horizontal positions, reused between frames.
#[derive(Default)]
struct Grid {
    cells: std::collections::HashMap<(i64, i64), Vec<usize>>,
}

/// The clashes of one frame (index `k`).
pub fn frame_clearance_at(f: &Frame, k: usize) -> Clearance {
    frame_clearance(f, k, &mut Grid::default())
}

fn frame_clearance(f: &Frame, k: usize, grid: &mut Grid) -> Clearance {
    let n = f.x.len();
    let mut out = Clearance {
        frames: 1,
        ..Clearance::default()
    };
    // Cleared, not emptied cell by cell: a moving flock visits new cells every second, and
    // keeping the old ones would make every frame walk all the cells ever visited.
    grid.cells.clear();
    let cell = |i: usize| {
        (
            (f.x[i] / REACH).floor() as i64,
            (f.y[i] / REACH).floor() as i64,
        )
    };
    for i in 0..n {
        if f.x[i].is_finite() && f.y[i].is_finite() {
            grid.cells.entry(cell(i)).or_default().push(i);
        }
    }
    let z = |i: usize| f.z.get(i).copied().unwrap_or(0.0);
    let mut clash_here = false;
    for i in 0..n {
        if !(f.x[i].is_finite() && f.y[i].is_finite()) {
            continue;
        }
        let (cx, cy) = cell(i);
        let (hx, hy) = f.heading.get(i).map_or((0.0, 1.0), |h| h.sin_cos());
        let flying_i = f.speed.get(i).is_some_and(|&v| v >= FLYING);
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(members) = grid.cells.get(&(cx + dx, cy + dy)) else {
                    continue;
                };
                for &j in members {
                    if j <= i {
                        continue;
                    }
                    let (ex, ey, ez) = (f.x[j] - f.x[i], f.y[j] - f.y[i], z(j) - z(i));
                    let d = (ex * ex + ey * ey + ez * ez).sqrt();
                    if !(d < REACH) {
                        continue;
                    }
                    if out.closest.map_or(true, |c| d < c.distance) {
                        out.closest = Some(Closest {
                            distance: d,
                            frame: k,
                            birds: (i, j),
                        });
                    }
                    if d < BODY {
                        out.body += 1;
                        clash_here = true;
                        continue;
                    }
                    let flying_j = f.speed.get(j).is_some_and(|&v| v >= FLYING);
                    if !(flying_i && flying_j) {
                        continue;
                    }
                    let along = ex * hx + ey * hy;
                    let lateral = ex * hy - ey * hx;
                    if lateral.abs() < SPAN && along.abs() < CHORD && ez.abs() < THICKNESS {
                        out.wing += 1;
                        clash_here = true;
                    }
                }
            }
        }
    }
    out.frames_with_clash = usize::from(clash_here);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(pts: &[(f64, f64, f64)], speed: f64) -> Frame {
        Frame {
            x: pts.iter().map(|p| p.0).collect(),
            y: pts.iter().map(|p| p.1).collect(),
            z: pts.iter().map(|p| p.2).collect(),
            heading: vec![0.0; pts.len()],
            speed: vec![speed; pts.len()],
            ..Frame::default()
        }
    }

    #[test]
    fn abreast_birds_clash_by_wing_and_staggered_ones_do_not() {
        let c = frame_clearance_at(&frame(&[(0.0, 0.0, 0.0), (0.79, 0.07, 0.0)], 10.0), 0);
        assert_eq!((c.wing, c.body), (1, 0));
        let c = frame_clearance_at(&frame(&[(0.0, 0.0, 0.0), (0.77, -1.24, 0.0)], 10.0), 0);
        assert_eq!(c.clashes(), 0);
        // Above by more than a wing's thickness.
        let c = frame_clearance_at(&frame(&[(0.0, 0.0, 0.0), (0.79, 0.07, 0.1)], 10.0), 0);
        assert_eq!(c.clashes(), 0);
        // At rest, only bodies count.
        let c = frame_clearance_at(&frame(&[(0.0, 0.0, 0.0), (0.5, 0.0, 0.0)], 0.0), 0);
        assert_eq!(c.clashes(), 0);
        let c = frame_clearance_at(&frame(&[(0.0, 0.0, 0.0), (0.2, 0.0, 0.0)], 0.0), 0);
        assert_eq!((c.wing, c.body), (0, 1));
        assert!((c.closest.unwrap().distance - 0.2).abs() < 1e-12);
    }

    #[test]
    fn the_heading_frame_is_the_first_birds() {
        // Two birds 0.5 apart along x: abreast when flying north, in line when flying east.
        let mut f = frame(&[(0.0, 0.0, 0.0), (0.5, 0.0, 0.0)], 10.0);
        assert_eq!(frame_clearance_at(&f, 0).wing, 1);
        f.heading = vec![std::f64::consts::FRAC_PI_2; 2];
        assert_eq!(frame_clearance_at(&f, 0).wing, 0);
    }

    #[test]
    fn pairs_across_grid_cells_are_found() {
        let c = frame_clearance_at(&frame(&[(1.19, 0.0, 0.0), (1.21, 0.05, 0.0)], 10.0), 0);
        assert_eq!(c.body, 1);
        let c = frame_clearance_at(&frame(&[(-0.01, -0.01, 0.0), (0.01, 0.01, 0.0)], 10.0), 0);
        assert_eq!(c.body, 1);
    }
}
