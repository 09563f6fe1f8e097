//! Cubic spline interpolation of tabulated samples (C2: value, slope and curvature are
//! continuous), so that a measured motion can drive constraints with smooth velocity and
//! acceleration.
//!
//! On [t_i, t_{i+1}] (h_i = t_{i+1} - t_i, s_i = (y_{i+1} - y_i) / h_i) the spline is fixed by
//! its knot curvatures m_i; continuity of the slope at an interior knot gives
//! h_{i-1} m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_i m_{i+1} = 6 (s_i - s_{i-1}), i = 1..n-2,
//! and two end conditions close the system:
//! - natural: m_0 = m_{n-1} = 0;
//! - clamped (end slopes d_0, d_n): the slope s_0 - h_0 (2 m_0 + m_1) / 6 = d_0, i.e.
//!   2 h_0 m_0 + h_0 m_1 = 6 (s_0 - d_0), and h m_{n-2} + 2 h m_{n-1} = 6 (d_n - s_{n-2}),
//!   h = h_{n-2};
//! - not-a-knot: the third derivative is continuous at t_1 and t_{n-2}, (m_1 - m_0) / h_0 =
//!   (m_2 - m_1) / h_1, so m_0 = m_1 - h_0 (m_2 - m_1) / h_1 (and likewise m_{n-1}); substituted
//!   into the first and last interior equations, the system in m_1..m_{n-2} stays tridiagonal.
//!   With three samples the two conditions coincide and the spline is the parabola through
//!   them; with two, the line.
//!
//! A clamped or not-a-knot spline reproduces a cubic exactly; a natural spline reproduces
//! a line, and where the data's curvature is not zero at an end its slope there is only O(h)
//! (the slope a natural table gives a moving guide at its ends).

use crate::error::{finite, Error, Result};

/// How a spline ends (de Boor, *A Practical Guide to Splines*, ch. IV).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EndCondition {
    /// Zero curvature at both ends.
    Natural,
    /// Given slopes at the first and last sample.
    Clamped(f64, f64),
    /// The first two and the last two pieces are one cubic each.
    NotAKnot,
}

/// A cubic spline through (t_i, y_i).
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the knots.
    m: Vec<f64>,
}

/// Solves the tridiagonal system (lower[i] x[i-1] + diag[i] x[i] + upper[i] x[i+1] = rhs[i])
/// by the Thomas algorithm (the spline systems are diagonally dominant).
fn thomas(lower: &[f64], mut diag: Vec<f64>, upper: &[f64], mut rhs: Vec<f64>) -> Vec<f64> {
    let k = diag.len();
    for j in 1..k {
        let w = lower[j] / diag[j - 1];
        diag[j] -= w * upper[j - 1];
        rhs[j] -= w * rhs[j - 1];
    }
    let mut x = vec![0.0; k];
    x[k - 1] = rhs[k - 1] / diag[k - 1];
    for j in (0..k - 1).rev() {
        x[j] = (rhs[j] - upper[j] * x[j + 1]) / diag[j];
    }
    x
}

impl CubicSpline {
    /// A natural spline; times must be finite and strictly increasing, at least two samples.
    pub fn new(t: Vec<f64>, y: Vec<f64>) -> Result<CubicSpline> {
        CubicSpline::with_ends(t, y, EndCondition::Natural)
    }

    /// A spline with the given end condition (module doc), validated.
    pub fn with_ends(t: Vec<f64>, y: Vec<f64>, ends: EndCondition) -> Result<CubicSpline> {
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
        if let EndCondition::Clamped(d0, dn) = ends {
            finite("clamped spline's first slope", d0)?;
            finite("clamped spline's last slope", dn)?;
        }
        let m = curvatures(&t, &y, ends);
        Ok(CubicSpline { t, y, m })
    }

    /// First and last sample times.
    pub fn domain(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// Value, slope and curvature at `t`. Outside the samples the spline continues as the straight
    /// line tangent at the end (C2 for a natural spline, whose end curvature is zero; C1 for the
    /// other end conditions).
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

/// The knot curvatures m_i for the end condition (module doc).
fn curvatures(t: &[f64], y: &[f64], ends: EndCondition) -> Vec<f64> {
    let n = t.len();
    let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let s: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    match ends {
        EndCondition::Clamped(d0, dn) => {
            // All n unknowns: the two slope rows, then the interior rows.
            let mut lower = vec![0.0; n];
            let mut diag = vec![0.0; n];
            let mut upper = vec![0.0; n];
            let mut rhs = vec![0.0; n];
            (diag[0], upper[0], rhs[0]) = (2.0 * h[0], h[0], 6.0 * (s[0] - d0));
            for i in 1..n - 1 {
                lower[i] = h[i - 1];
                diag[i] = 2.0 * (h[i - 1] + h[i]);
                upper[i] = h[i];
                rhs[i] = 6.0 * (s[i] - s[i - 1]);
            }
            let l = h[n - 2];
            (lower[n - 1], diag[n - 1], rhs[n - 1]) = (l, 2.0 * l, 6.0 * (dn - s[n - 2]));
            thomas(&lower, diag, &upper, rhs)
        }
        EndCondition::Natural | EndCondition::NotAKnot if n == 2 => vec![0.0; 2],
        EndCondition::NotAKnot if n == 3 => vec![2.0 * (s[1] - s[0]) / (h[0] + h[1]); 3],
        EndCondition::Natural | EndCondition::NotAKnot => {
            // Interior unknowns m_1..m_{n-2}.
            let k = n - 2;
            let mut lower = vec![0.0; k];
            let mut diag = vec![0.0; k];
            let mut upper = vec![0.0; k];
            let mut rhs = vec![0.0; k];
            for j in 0..k {
                let i = j + 1;
                lower[j] = h[i - 1];
                diag[j] = 2.0 * (h[i - 1] + h[i]);
                upper[j] = h[i];
                rhs[j] = 6.0 * (s[i] - s[i - 1]);
            }
            let not_a_knot = ends == EndCondition::NotAKnot;
            if not_a_knot {
                // m_0 = ((h0 + h1) m_1 - h0 m_2) / h1 into row 1; the mirror at the end.
                let (h0, h1) = (h[0], h[1]);
                diag[0] += h0 * (h0 + h1) / h1;
                upper[0] -= h0 * h0 / h1;
                let (a, b) = (h[n - 3], h[n - 2]);
                diag[k - 1] += b * (a + b) / a;
                lower[k - 1] -= b * b / a;
            }
            let interior = thomas(&lower, diag, &upper, rhs);
            let mut m = vec![0.0; n];
            m[1..n - 1].copy_from_slice(&interior);
            if not_a_knot {
                m[0] = m[1] - h[0] * (m[2] - m[1]) / h[1];
                m[n - 1] = m[n - 2] + h[n - 2] * (m[n - 2] - m[n - 3]) / h[n - 3];
            }
            m
        }
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
    fn clamped_and_not_a_knot_splines_reproduce_a_cubic_exactly() {
        // A cubic is its own clamped spline (given its end slopes) and its own not-a-knot spline
        // (de Boor ch. IV): value, slope and curvature everywhere, ends included, on uneven knots.
        let p = |x: f64| {
            (
                1.0 - 2.0 * x + 0.5 * x * x - 0.3 * x * x * x,
                -2.0 + x - 0.9 * x * x,
            )
        };
        let curvature = |x: f64| 1.0 - 1.8 * x;
        let t: Vec<f64> = (0..7)
            .map(|i| 0.4 * i as f64 + 0.05 * (i * i) as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|&x| p(x).0).collect();
        let (a, b) = (t[0], t[6]);
        for ends in [
            EndCondition::Clamped(p(a).1, p(b).1),
            EndCondition::NotAKnot,
        ] {
            let s = CubicSpline::with_ends(t.clone(), y.clone(), ends).unwrap();
            for k in 0..=60 {
                let x = a + (b - a) * k as f64 / 60.0;
                let (v, d1, d2) = s.eval(x);
                assert!((v - p(x).0).abs() < 1e-12, "{ends:?} value at {x}");
                assert!((d1 - p(x).1).abs() < 1e-11, "{ends:?} slope at {x}");
                assert!(
                    (d2 - curvature(x)).abs() < 1e-10,
                    "{ends:?} curvature at {x}"
                );
            }
        }
        // Three samples, not-a-knot: the parabola through them; two: the line.
        let q = |x: f64| 2.0 + 0.5 * x - 1.5 * x * x;
        let s = CubicSpline::with_ends(
            vec![0.0, 0.3, 1.0],
            vec![q(0.0), q(0.3), q(1.0)],
            EndCondition::NotAKnot,
        )
        .unwrap();
        let (v, d1, d2) = s.eval(0.8);
        assert!((v - q(0.8)).abs() < 1e-13 && (d1 - (0.5 - 2.4)).abs() < 1e-12);
        assert!((d2 + 3.0).abs() < 1e-12);
        let s = CubicSpline::with_ends(vec![0.0, 2.0], vec![1.0, 5.0], EndCondition::NotAKnot);
        assert_eq!(s.unwrap().eval(0.5), (2.0, 2.0, 0.0));
    }

    #[test]
    fn natural_ends_lose_accuracy_where_clamped_and_not_a_knot_ends_do_not() {
        // sin on [0, 1] (curvature -sin 1 != 0 at t = 1): the natural spline's m_{n-1} = 0 is
        // wrong by O(1), so its slope on the last piece is wrong by O(h); the clamped and
        // not-a-knot ones' are O(h^3) or better. Halving h: ratios ~2 and >= ~8.
        let slope_error = |n: usize, ends: EndCondition| {
            let t: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
            let y: Vec<f64> = t.iter().map(|x| x.sin()).collect();
            let s = CubicSpline::with_ends(t, y, ends).unwrap();
            let x = 1.0 - 0.5 / n as f64; // the middle of the last piece
            (s.eval(x).1 - x.cos()).abs()
        };
        let clamped = EndCondition::Clamped(1.0, 1f64.cos());
        for (ends, low, high) in [
            (EndCondition::Natural, 1.8, 2.2),
            (clamped, 7.0, 1e9),
            (EndCondition::NotAKnot, 7.0, 1e9),
        ] {
            let ratio = slope_error(20, ends) / slope_error(40, ends);
            assert!(ratio > low && ratio < high, "{ends:?}: ratio {ratio}");
        }
    }

    #[test]
    fn rejects_unsorted_times() {
        let e = CubicSpline::new(vec![0.0, 1.0, 1.0], vec![0.0; 3]).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }));
    }
}
