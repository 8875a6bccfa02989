//! A uniform grid over the birds' horizontal positions, for neighbour queries within a radius
//! (perception within the visual range, avoidance within its range).

use super::*;

/// A uniform grid of square cells over the horizontal plane, for neighbour queries.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    cell: f64,
    origin: DVec2,
    nx: usize,
    ny: usize,
    /// Start of each cell's run in `items` (prefix sums; length nx·ny + 1).
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Grid {
    /// Rebuilds the grid over the points `pos[i]` for the `members` (cells of `cell` wingspans).
    pub fn build(&mut self, pos: &[DVec2], members: &[usize], cell: f64) {
        self.cell = cell.max(1e-6);
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &i in members {
            lo = lo.min(pos[i]);
            hi = hi.max(pos[i]);
        }
        if members.is_empty() {
            lo = DVec2::ZERO;
            hi = DVec2::ZERO;
        }
        self.origin = lo;
        // Cap the cell count so a bird far away cannot make the grid huge.
        let span = (hi - lo) / self.cell;
        let cap = (4 * members.len()).max(16) as f64;
        let scale = ((span.x + 1.0) * (span.y + 1.0) / cap).max(1.0).sqrt();
        self.cell *= scale;
        self.nx = ((hi.x - lo.x) / self.cell).floor() as usize + 1;
        self.ny = ((hi.y - lo.y) / self.cell).floor() as usize + 1;
        let cells = self.nx * self.ny;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &i in members {
            let c = self.cell_of(pos[i]);
            self.start[c + 1] += 1;
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(members.len(), 0);
        let mut fill = self.start.clone();
        for &i in members {
            let c = self.cell_of(pos[i]);
            self.items[fill[c]] = i;
            fill[c] += 1;
        }
    }

    fn cell_of(&self, p: DVec2) -> usize {
        let cx = (((p.x - self.origin.x) / self.cell).floor().max(0.0) as usize).min(self.nx - 1);
        let cy = (((p.y - self.origin.y) / self.cell).floor().max(0.0) as usize).min(self.ny - 1);
        cy * self.nx + cx
    }

    /// Members within `radius` of `p` (horizontal distance), in increasing index order.
    pub fn within(&self, pos: &[DVec2], p: DVec2, radius: f64, out: &mut Vec<usize>) {
        out.clear();
        if self.nx == 0 {
            return;
        }
        let r2 = radius * radius;
        let lo = ((p - DVec2::splat(radius) - self.origin) / self.cell).floor();
        let hi = ((p + DVec2::splat(radius) - self.origin) / self.cell).floor();
        if hi.x < 0.0 || hi.y < 0.0 || lo.x >= self.nx as f64 || lo.y >= self.ny as f64 {
            return;
        }
        let x0 = lo.x.max(0.0) as usize;
        let y0 = lo.y.max(0.0) as usize;
        let x1 = (hi.x as usize).min(self.nx - 1);
        let y1 = (hi.y as usize).min(self.ny - 1);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let c = cy * self.nx + cx;
                for &i in &self.items[self.start[c]..self.start[c + 1]] {
                    if (pos[i] - p).length_squared() <= r2 {
                        out.push(i);
                    }
                }
            }
        }
        out.sort_unstable();
    }
}
