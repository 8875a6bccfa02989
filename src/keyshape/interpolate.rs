//! §5 step 4: interpolation between key shapes. Each bird's longitudinal position `y` (wingspans
//! behind the leader) is a piecewise cubic Hermite curve of time (seconds) through its key values,
//! with Fritsch–Carlson (PCHIP) tangents: C¹ (no velocity kinks at key frames) and without
//! overshoot, so between two keys a bird stays between its two key positions. Hence the leader
//! stays front-most and the depth limit holds at every frame, not only at keys. The tangents at the
//! first and last keys are zero: the flock holds its shape as the steady flight starts and ends.
//!
//! On the segment [t_k, t_{k+1}] with h = t_{k+1} − t_k, s = (t − t_k)/h:
//! ```math
//! y(t) = h_{00}(s)\,y_k + h_{10}(s)\,h\,m_k + h_{01}(s)\,y_{k+1} + h_{11}(s)\,h\,m_{k+1}
//! ```
//! with the cubic Hermite basis h₀₀ = 2s³ − 3s² + 1, h₁₀ = s³ − 2s² + s, h₀₁ = −2s³ + 3s²,
//! h₁₁ = s³ − s²; the slopes m_k are the weighted harmonic means of the neighbouring secant slopes
//! (0 where they differ in sign), Fritsch & Butland's form for uneven key spacing.

/// One interpolated coordinate over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    t: Vec<f64>,
    v: Vec<f64>,
    m: Vec<f64>,
}

impl Track {
    /// A monotone C¹ cubic through `(t[k], v[k])`; `t` strictly increasing and as long as `v`.
    /// A single knot gives a constant.
    pub fn pchip(t: &[f64], v: &[f64]) -> Track {
        let n = t.len().min(v.len());
        let (t, v) = (t[..n].to_vec(), v[..n].to_vec());
        let mut m = vec![0.0; n];
        for k in 1..n.saturating_sub(1) {
            let h0 = t[k] - t[k - 1];
            let h1 = t[k + 1] - t[k];
            let d0 = (v[k] - v[k - 1]) / h0;
            let d1 = (v[k + 1] - v[k]) / h1;
            if d0 * d1 > 0.0 {
                let w1 = 2.0 * h1 + h0;
                let w2 = h1 + 2.0 * h0;
                m[k] = (w1 + w2) / (w1 / d0 + w2 / d1);
            }
        }
        Track { t, v, m }
    }

    /// Value and time derivative at `t` (clamped to the knots' span).
    pub fn eval(&self, t: f64) -> (f64, f64) {
        let n = self.t.len();
        if n == 0 {
            return (0.0, 0.0);
        }
        if n == 1 || t <= self.t[0] {
            return (self.v[0], if n == 1 { 0.0 } else { self.m[0] });
        }
        if t >= self.t[n - 1] {
            return (self.v[n - 1], self.m[n - 1]);
        }
        let k = (self.t.partition_point(|&tk| tk <= t) - 1).min(n - 2);
        let h = self.t[k + 1] - self.t[k];
        let s = (t - self.t[k]) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (y0, y1, m0, m1) = (self.v[k], self.v[k + 1], self.m[k], self.m[k + 1]);
        let value = (2.0 * s3 - 3.0 * s2 + 1.0) * y0
            + (s3 - 2.0 * s2 + s) * h * m0
            + (-2.0 * s3 + 3.0 * s2) * y1
            + (s3 - s2) * h * m1;
        let ds = (6.0 * s2 - 6.0 * s) * y0
            + (3.0 * s2 - 4.0 * s + 1.0) * h * m0
            + (-6.0 * s2 + 6.0 * s) * y1
            + (3.0 * s2 - 2.0 * s) * h * m1;
        (value, ds / h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn passes_through_knots_with_continuous_slope() {
        let t = [0.0, 1.0, 3.0, 4.0];
        let v = [0.0, 1.0, 1.5, 0.2];
        let tr = Track::pchip(&t, &v);
        for k in 0..4 {
            assert!((tr.eval(t[k]).0 - v[k]).abs() < 1e-12);
        }
        // C1: derivative just left and right of an interior knot agree.
        for &tk in &t[1..3] {
            let (_, dl) = tr.eval(tk - 1e-9);
            let (_, dr) = tr.eval(tk + 1e-9);
            assert!((dl - dr).abs() < 1e-6, "{dl} vs {dr}");
        }
        assert_eq!(tr.eval(0.0).1, 0.0);
        assert_eq!(tr.eval(4.0).1, 0.0);
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let tr = Track::pchip(&[0.0, 2.0, 3.0, 6.0], &[1.0, 0.2, 0.9, 2.0]);
        for i in 1..59 {
            let t = i as f64 * 0.1;
            let h = 1e-6;
            let fd = (tr.eval(t + h).0 - tr.eval(t - h).0) / (2.0 * h);
            assert!((fd - tr.eval(t).1).abs() < 1e-5, "t={t}");
        }
    }

    proptest! {
        #[test]
        fn never_overshoots(v in proptest::collection::vec(-3.0f64..3.0, 2..8), q in 0.0f64..1.0) {
            let t: Vec<f64> = (0..v.len()).map(|k| k as f64 * 1.5 + (k as f64).sqrt()).collect();
            let tr = Track::pchip(&t, &v);
            for k in 0..v.len() - 1 {
                let tt = t[k] + q * (t[k + 1] - t[k]);
                let y = tr.eval(tt).0;
                let (lo, hi) = (v[k].min(v[k + 1]), v[k].max(v[k + 1]));
                prop_assert!(y >= lo - 1e-12 && y <= hi + 1e-12);
            }
        }
    }
}
