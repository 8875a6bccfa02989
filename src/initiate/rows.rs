//! One value of every bird at every output frame of a take-off, frame-major in a single
//! allocation. A flock of 10 000 birds flies as about a thousand formations of nine, whose rows
//! held as vectors of their own cost half as much again as their values; in one allocation the
//! take-offs of such a flock take 330 MB instead of about 500.

use std::ops::Index;

/// Rows of `width` values, one a frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows<T> {
    data: Vec<T>,
    width: usize,
    rows: usize,
}

impl<T: Copy> Rows<T> {
    /// No rows yet, `width` values a row.
    pub fn new(width: usize) -> Rows<T> {
        Rows {
            data: Vec::new(),
            width,
            rows: 0,
        }
    }

    /// Number of rows (frames).
    pub fn len(&self) -> usize {
        self.rows
    }

    /// No rows.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// Appends a row; it must hold `width` values.
    pub fn push_row(&mut self, row: impl IntoIterator<Item = T>) {
        let before = self.data.len();
        self.data.extend(row);
        assert_eq!(
            self.data.len() - before,
            self.width,
            "a row of the wrong width"
        );
        self.rows += 1;
    }

    /// Gives back the room reserved for rows not pushed (the rows grow by doubling while the
    /// take-off is flown).
    pub fn shrink_to_fit(&mut self) {
        self.data.shrink_to_fit();
    }

    /// Puts `count` rows in front of the first, row `j` of them `row(j)`.
    pub fn prepend<I: IntoIterator<Item = T>>(
        &mut self,
        count: usize,
        mut row: impl FnMut(usize) -> I,
    ) {
        let mut data = Vec::with_capacity(self.data.len() + count * self.width);
        for j in 0..count {
            let before = data.len();
            data.extend(row(j));
            assert_eq!(data.len() - before, self.width, "a row of the wrong width");
        }
        data.append(&mut self.data);
        self.data = data;
        self.rows += count;
    }
}

impl<T> Index<usize> for Rows<T> {
    type Output = [T];

    /// Row `t`: every bird's value at frame `t`.
    fn index(&self, t: usize) -> &[T] {
        assert!(t < self.rows, "row {t} of {}", self.rows);
        &self.data[t * self.width..(t + 1) * self.width]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_push_prepend_and_index() {
        let mut r: Rows<f64> = Rows::new(2);
        r.push_row([1.0, 2.0]);
        r.push_row([3.0, 4.0]);
        r.prepend(2, |j| [j as f64 * 10.0, -1.0]);
        assert_eq!(r.len(), 4);
        assert_eq!(&r[0], &[0.0, -1.0]);
        assert_eq!(&r[1], &[10.0, -1.0]);
        assert_eq!(&r[3], &[3.0, 4.0]);
        let empty: Rows<f64> = Rows::new(0);
        assert!(empty.is_empty());
    }
}
