//! Natural cubic spline interpolation of tabulated samples (C2: value, slope and curvature are
//! continuous), so that a measured motion can drive constraints with smooth velocity and
//! acceleration.

use crate::error::{finite, Error, Result};

/// A natural cubic spline (zero curvature at both ends) through (t_i, y_i).
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the knots.
    m: Vec<f64>,
}

impl CubicSpline {
    /// Builds the spline; times must be finite and strictly increasing, at least two samples.
    ///
    /// The knot curvatures solve the tridiagonal system
    /// h_{i-1} m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_i m_{i+1} = 6 (s_i - s_{i-1}),
    /// s_i = (y_{i+1} - y_i) / h_i, with m_0 = m_{n-1} = 0 (Thomas algorithm).
    pub fn new(t: Vec<f64>, y: Vec<f64>) -> Result<CubicSpline> {
        if t.len() != y.len() {
            return Err(Error::InvalidParameter {
                name: "number of tabulated values".into(),
                value: y.len() as f64,
                expected: format!("must equal the number of times ({})", t.len()),
            });
        }
        if t.len() < 2 {
            return Err(Error::InvalidParameter {
                name: "number of tabulated samples".into(),
                value: t.len() as f64,
                expected: "give at least 2 samples".into(),
            });
        }
        for (i, (&ti, &yi)) in t.iter().zip(&y).enumerate() {
            finite(format!("tabulated time #{i}"), ti)?;
            finite(format!("tabulated value #{i}"), yi)?;
            if i > 0 && ti <= t[i - 1] {
                return Err(Error::InvalidParameter {
                    name: format!("tabulated time #{i}"),
                    value: ti,
                    expected: format!("times must increase strictly (previous is {})", t[i - 1]),
                });
            }
        }
        let n = t.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            let k = n - 2; // interior unknowns m_1..m_{n-2}
            let mut diag = vec![0.0; k];
            let mut rhs = vec![0.0; k];
            let mut upper = vec![0.0; k];
            for j in 0..k {
                let i = j + 1;
                let h0 = t[i] - t[i - 1];
                let h1 = t[i + 1] - t[i];
                diag[j] = 2.0 * (h0 + h1);
                upper[j] = h1;
                rhs[j] = 6.0 * ((y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0);
            }
            for j in 1..k {
                let lower = t[j + 1] - t[j];
                let w = lower / diag[j - 1];
                diag[j] -= w * upper[j - 1];
                rhs[j] -= w * rhs[j - 1];
            }
            m[k] = rhs[k - 1] / diag[k - 1];
            for j in (0..k - 1).rev() {
                m[j + 1] = (rhs[j] - upper[j] * m[j + 2]) / diag[j];
            }
        }
        Ok(CubicSpline { t, y, m })
    }

    /// First and last sample times.
    pub fn domain(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// Value, slope and curvature at `t`. Outside the samples the spline continues as the straight
    /// line tangent at the end (its curvature is zero there, so the extension stays C2).
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let (first, last) = self.domain();
        if t < first || t > last {
            let end = t.clamp(first, last);
            let (y, slope, _) = self.eval(end);
            return (y + slope * (t - end), slope, 0.0);
        }
        let n = self.t.len();
        let i = match self.t.partition_point(|&x| x <= t) {
            0 => 0,
            k if k >= n => n - 2,
            k => k - 1,
        };
        let h = self.t[i + 1] - self.t[i];
        let a = (self.t[i + 1] - t) / h;
        let b = (t - self.t[i]) / h;
        let (m0, m1) = (self.m[i], self.m[i + 1]);
        let (y0, y1) = (self.y[i], self.y[i + 1]);
        let v = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d1 = (y1 - y0) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        let d2 = a * m0 + b * m1;
        (v, d1, d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_linear_data_exactly() {
        // A straight line has zero curvature everywhere: the natural spline is that line.
        let t: Vec<f64> = (0..7)
            .map(|i| 0.3 * i as f64 + 0.1 * (i * i) as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|x| 2.0 - 3.0 * x).collect();
        let s = CubicSpline::new(t, y).unwrap();
        for k in 0..50 {
            let x = 0.05 * k as f64;
            let (v, d1, d2) = s.eval(x.min(s.domain().1));
            assert!((v - (2.0 - 3.0 * x.min(s.domain().1))).abs() < 1e-12);
            assert!((d1 + 3.0).abs() < 1e-12 && d2.abs() < 1e-10);
        }
    }

    #[test]
    fn interpolates_a_sine_to_fourth_order_accuracy_inside() {
        // Spline error on a smooth function is O(h^4) away from the natural ends.
        let n = 201;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t.iter().map(|x| (3.0 * x).sin()).collect();
        let s = CubicSpline::new(t, y).unwrap();
        for k in 0..100 {
            let x = 0.5 + 0.01 * k as f64 + 0.003;
            let (v, d1, d2) = s.eval(x);
            assert!((v - (3.0 * x).sin()).abs() < 1e-8);
            assert!((d1 - 3.0 * (3.0 * x).cos()).abs() < 1e-5);
            assert!((d2 + 9.0 * (3.0 * x).sin()).abs() < 1e-2);
        }
    }

    #[test]
    fn rejects_unsorted_times() {
        let e = CubicSpline::new(vec![0.0, 1.0, 1.0], vec![0.0; 3]).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }));
    }
}
