//! Smooth design laws tabulated by the designer: wrap angle θ(m), thickness τ(m), θ across spans.
//!
//! A [`Law`] is the natural cubic spline through the tabulated points (x_i, y_i) (de Boor,
//! *A Practical Guide to Splines*, ch. IV): C² inside, second derivative zero at both ends,
//! continued linearly (with the end slope) outside the table. One point gives a constant, two
//! points a straight line. Building costs O(n) (tridiagonal solve); evaluation O(log n).

/// A natural cubic spline y(x) through tabulated points, linear outside the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Law {
    x: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the knots (zero at both ends).
    m: Vec<f64>,
}

impl Law {
    /// The natural cubic spline through `points` = [(x, y), ...].
    ///
    /// Errors (as a reason phrase) when the table is empty, holds a non-finite value, or the x
    /// values are not strictly increasing.
    pub fn new(points: &[[f64; 2]]) -> Result<Self, String> {
        if points.is_empty() {
            return Err("must hold at least one point".into());
        }
        for (i, p) in points.iter().enumerate() {
            if !p[0].is_finite() || !p[1].is_finite() {
                return Err(format!("point {i} is not finite"));
            }
            if i > 0 && p[0] <= points[i - 1][0] {
                return Err(format!(
                    "abscissae must increase strictly (point {i}: {} after {})",
                    p[0],
                    points[i - 1][0]
                ));
            }
        }
        let x: Vec<f64> = points.iter().map(|p| p[0]).collect();
        let y: Vec<f64> = points.iter().map(|p| p[1]).collect();
        let n = x.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            // Tridiagonal system for the interior second derivatives (Thomas algorithm).
            let k = n - 2;
            let mut diag = vec![0.0; k];
            let mut upper = vec![0.0; k];
            let mut rhs = vec![0.0; k];
            for i in 1..n - 1 {
                let h0 = x[i] - x[i - 1];
                let h1 = x[i + 1] - x[i];
                diag[i - 1] = 2.0 * (h0 + h1);
                upper[i - 1] = h1;
                rhs[i - 1] = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
            }
            for i in 1..k {
                let lower = x[i + 1] - x[i];
                let w = lower / diag[i - 1];
                diag[i] -= w * upper[i - 1];
                rhs[i] -= w * rhs[i - 1];
            }
            m[k] = rhs[k - 1] / diag[k - 1];
            for i in (0..k - 1).rev() {
                m[i + 1] = (rhs[i] - upper[i] * m[i + 2]) / diag[i];
            }
        }
        Ok(Self { x, y, m })
    }

    /// A constant law.
    pub fn constant(value: f64) -> Self {
        Self {
            x: vec![0.0],
            y: vec![value],
            m: vec![0.0],
        }
    }

    /// Smallest and largest tabulated ordinate.
    pub fn table_range(&self) -> (f64, f64) {
        self.y
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            })
    }

    fn segment(&self, x: f64) -> usize {
        let n = self.x.len();
        match self.x.partition_point(|&xi| xi <= x) {
            0 => 0,
            i if i >= n => n - 2,
            i => i - 1,
        }
    }

    /// Value and first derivative at `x`.
    pub fn eval_d(&self, x: f64) -> (f64, f64) {
        let n = self.x.len();
        if n == 1 {
            return (self.y[0], 0.0);
        }
        if x <= self.x[0] || x >= self.x[n - 1] {
            let (i, xe) = if x <= self.x[0] {
                (0, self.x[0])
            } else {
                (n - 1, self.x[n - 1])
            };
            let slope = self.inner(xe.clamp(self.x[0], self.x[n - 1])).1;
            return (self.y[i] + slope * (x - xe), slope);
        }
        self.inner(x)
    }

    fn inner(&self, x: f64) -> (f64, f64) {
        let i = self.segment(x);
        let h = self.x[i + 1] - self.x[i];
        let a = (self.x[i + 1] - x) / h;
        let b = (x - self.x[i]) / h;
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let v = a * self.y[i]
            + b * self.y[i + 1]
            + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d = (self.y[i + 1] - self.y[i]) / h
            + (-(3.0 * a * a - 1.0) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        (v, d)
    }

    /// Value at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        self.eval_d(x).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_table_and_cubic_continuity() {
        let law = Law::new(&[[0.0, 0.0], [0.3, 1.0], [0.7, 0.5], [1.0, 2.0]]).unwrap();
        for p in [[0.0, 0.0], [0.3, 1.0], [0.7, 0.5], [1.0, 2.0]] {
            assert!((law.eval(p[0]) - p[1]).abs() < 1e-12);
        }
        // C1 across an interior knot.
        let e = 1e-7;
        let (_, d0) = law.eval_d(0.3 - e);
        let (_, d1) = law.eval_d(0.3 + e);
        assert!((d0 - d1).abs() < 1e-5);
        // Derivative agrees with a central difference.
        let x = 0.55;
        let fd = (law.eval(x + 1e-6) - law.eval(x - 1e-6)) / 2e-6;
        assert!((fd - law.eval_d(x).1).abs() < 1e-6);
    }

    #[test]
    fn reproduces_straight_lines_exactly_and_extrapolates_linearly() {
        let law = Law::new(&[[0.0, 1.0], [0.5, 2.0], [1.0, 3.0]]).unwrap();
        for x in [-0.5, 0.1, 0.77, 1.4] {
            assert!((law.eval(x) - (1.0 + 2.0 * x)).abs() < 1e-12);
        }
        assert_eq!(Law::new(&[[0.2, 4.0]]).unwrap().eval(0.9), 4.0);
    }

    #[test]
    fn rejects_bad_tables() {
        assert!(Law::new(&[]).is_err());
        assert!(Law::new(&[[0.0, 1.0], [0.0, 2.0]]).is_err());
        assert!(Law::new(&[[0.0, f64::NAN]]).is_err());
    }
}
