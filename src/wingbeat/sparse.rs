//! A per-frame, per-bird table that is mostly one value (a fold weight of 0 in flight, a flare
//! weight of 0 before the landing): only the frames where some bird differs from it are kept,
//! so a long flight's table costs four bytes a frame instead of eight or sixteen a bird-frame.

/// Frame-major values of `birds` birds over `frames` frames, `fill` except in the rows kept.
#[derive(Debug, Clone, Default)]
pub struct FrameTable<T> {
    /// Row of each frame in `data`, or [`NONE`] when every bird has `fill`.
    rows: Vec<u32>,
    data: Vec<T>,
    birds: usize,
    fill: T,
}

const NONE: u32 = u32::MAX;

impl<T: Copy + PartialEq> FrameTable<T> {
    /// The table of `values` (frame-major, `birds` a frame; empty: every value is `fill`).
    pub fn from_dense(values: &[T], birds: usize, fill: T) -> FrameTable<T> {
        FrameTable::from_rows(values, birds, fill, |_, row| row.iter().any(|v| *v != fill))
    }

    /// The table of `values` keeping the frames `keep(frame, values)` says to keep; every other
    /// frame reads as `fill` for every bird.
    pub fn from_rows(
        values: &[T],
        birds: usize,
        fill: T,
        keep: impl Fn(usize, &[T]) -> bool,
    ) -> FrameTable<T> {
        let mut rows = Vec::new();
        let mut data = Vec::new();
        if let Some(frames) = values.len().checked_div(birds) {
            rows.reserve(frames);
            for (f, row) in values.chunks(birds).enumerate() {
                if !keep(f, row) {
                    rows.push(NONE);
                } else {
                    rows.push((data.len() / birds) as u32);
                    data.extend_from_slice(row);
                    // A partial last row (a malformed input) is padded.
                    data.resize(data.len().div_ceil(birds) * birds, fill);
                }
            }
        }
        FrameTable {
            rows,
            data,
            birds,
            fill,
        }
    }

    /// The table of `frames` frames whose kept frames (`keep`) hold `value(frame, bird)`; every
    /// other frame reads as `fill` (no dense table is made).
    pub fn from_fn(
        frames: usize,
        birds: usize,
        fill: T,
        keep: impl Fn(usize) -> bool,
        value: impl Fn(usize, usize) -> T,
    ) -> FrameTable<T> {
        let mut rows = Vec::with_capacity(frames);
        let mut data = Vec::new();
        for f in 0..frames {
            if birds > 0 && keep(f) {
                rows.push((data.len() / birds) as u32);
                data.extend((0..birds).map(|b| value(f, b)));
            } else {
                rows.push(NONE);
            }
        }
        FrameTable {
            rows,
            data,
            birds,
            fill,
        }
    }

    /// A table of no frames yet, `birds` a frame; frames are added with [`FrameTable::push_row`].
    pub fn new(birds: usize, fill: T) -> FrameTable<T> {
        FrameTable {
            rows: Vec::new(),
            data: Vec::new(),
            birds,
            fill,
        }
    }

    /// Adds the next frame's values (one a bird), kept only if some bird differs from `fill`.
    pub fn push_row(&mut self, row: &[T]) {
        if self.birds > 0 && row.iter().any(|v| *v != self.fill) {
            self.rows.push((self.data.len() / self.birds) as u32);
            self.data.extend_from_slice(row);
            // A short row (a malformed input) is padded.
            self.data
                .resize(self.data.len().div_ceil(self.birds) * self.birds, self.fill);
        } else {
            self.rows.push(NONE);
        }
    }

    /// Whether the table has no frames (the dense table was empty).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The value at frame-major index `k` (`frame × birds + bird`), `None` past the table.
    pub fn get(&self, k: usize) -> Option<T> {
        if self.birds == 0 {
            return None;
        }
        let (frame, bird) = (k / self.birds, k % self.birds);
        let row = *self.rows.get(frame)?;
        if row == NONE {
            Some(self.fill)
        } else {
            self.data.get(row as usize * self.birds + bird).copied()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sparse_table_gives_the_dense_values() {
        let birds = 3;
        let dense: Vec<f64> = (0..30)
            .map(|k| if (9..15).contains(&k) { k as f64 } else { 0.0 })
            .collect();
        let t = FrameTable::from_dense(&dense, birds, 0.0);
        for (k, v) in dense.iter().enumerate() {
            assert_eq!(t.get(k), Some(*v));
        }
        assert_eq!(t.get(30), None);
        // Only frames 3 and 4 (values 9..15) are kept.
        assert_eq!(t.data.len(), 2 * birds);
        let empty = FrameTable::from_dense(&[] as &[f64], birds, 0.0);
        assert!(empty.is_empty() && empty.get(0).is_none());
    }
}
