//! A line's tension as a function of its strain, from a table: MoorDyn's nonlinear EA (a
//! strain-tension file in place of the number), for an elastic segment whose compliance then
//! depends on its tension (`docs/theory/moorings.md`, "Nonlinear stiffness").
//!
//! The table's strains e_k and tensions T_k both increase; between them the curve is linear,
//! and beyond its first and last points it continues along its first and last pieces (MoorDyn
//! holds the last tension beyond the table, a stiffness of zero that no implicit step could
//! solve; here the line keeps the stiffness it had). The segment's equation `Phi + c T = 0`
//! (Hooke's, `elastic_distance.rs`) becomes
//!
//! ```text
//! Phi + L e(T) = 0,       e(T) the strain at tension T (the table read the other way)
//! d/dT: L e'(T) = L / (dT/de)    the compliance at the current tension
//! ```
//!
//! so that the tension's row keeps a bounded diagonal entry, L over the local stiffness.

use crate::error::{Error, Result};

/// Tensions at strains, both increasing: a piecewise linear tension-strain curve.
#[derive(Debug, Clone, PartialEq)]
pub struct StrainCurve {
    strains: Vec<f64>,
    tensions: Vec<f64>,
}

impl StrainCurve {
    /// The curve through (strains[k], tensions[k]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for fewer than two points, lists of different lengths, a
    /// value that is not finite, strains or tensions that do not increase, or a first point
    /// other than (0, 0) (a segment at its length has no tension; shorter, it is slack).
    pub fn new(strains: Vec<f64>, tensions: Vec<f64>) -> Result<StrainCurve> {
        if strains.len() < 2 || strains.len() != tensions.len() {
            return Err(Error::InvalidParameter {
                name: "strain-tension curve".into(),
                value: strains.len() as f64,
                expected: format!(
                    "at least two points, as many tensions as strains ({} tensions)",
                    tensions.len()
                ),
            });
        }
        for (name, values) in [("strain", &strains), ("tension", &tensions)] {
            if let Some(k) = values.iter().position(|x| !x.is_finite()) {
                return Err(Error::InvalidParameter {
                    name: format!("{name} {} of the strain-tension curve", k + 1),
                    value: values[k],
                    expected: "a finite number".into(),
                });
            }
            if let Some(k) = values.windows(2).position(|w| w[1] <= w[0]) {
                return Err(Error::InvalidParameter {
                    name: format!("{name} {} of the strain-tension curve", k + 2),
                    value: values[k + 1],
                    expected: format!(
                        "above the one before it ({}): strains and tensions increase",
                        values[k]
                    ),
                });
            }
        }
        if strains[0] != 0.0 || tensions[0] != 0.0 {
            return Err(Error::InvalidParameter {
                name: "first point of the strain-tension curve".into(),
                value: strains[0],
                expected: format!(
                    "strain 0 at tension 0 (the segment slack below its length), not ({}, {})",
                    strains[0], tensions[0]
                ),
            });
        }
        Ok(StrainCurve { strains, tensions })
    }

    /// The piece of `xs` that holds `x` (the first or last beyond the ends).
    #[inline]
    fn piece(xs: &[f64], x: f64) -> usize {
        xs.partition_point(|&v| v <= x)
            .saturating_sub(1)
            .min(xs.len() - 2)
    }

    /// The strain at tension `tension` and its derivative de/dT (1 over the local stiffness).
    #[inline]
    pub fn strain(&self, tension: f64) -> (f64, f64) {
        let k = Self::piece(&self.tensions, tension);
        let (t0, t1) = (self.tensions[k], self.tensions[k + 1]);
        let (e0, e1) = (self.strains[k], self.strains[k + 1]);
        let slope = (e1 - e0) / (t1 - t0);
        (e0 + slope * (tension - t0), slope)
    }

    /// The tension at strain `strain` (the curve itself).
    #[inline]
    pub fn tension(&self, strain: f64) -> f64 {
        let k = Self::piece(&self.strains, strain);
        let (e0, e1) = (self.strains[k], self.strains[k + 1]);
        let (t0, t1) = (self.tensions[k], self.tensions[k + 1]);
        t0 + (t1 - t0) / (e1 - e0) * (strain - e0)
    }

    /// The stiffest piece's dT/de (N): the axial stiffness EA that scales the segment where
    /// one number must (the static solve's first pseudo-steps).
    pub fn stiffest(&self) -> f64 {
        self.strains
            .windows(2)
            .zip(self.tensions.windows(2))
            .map(|(e, t)| (t[1] - t[0]) / (e[1] - e[0]))
            .fold(0.0, f64::max)
    }

    /// The table's strains.
    pub fn strains(&self) -> &[f64] {
        &self.strains
    }

    /// The table's tensions (N).
    pub fn tensions(&self) -> &[f64] {
        &self.tensions
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bilinear rope: 1e6 N per unit strain to 1 %, then 4e6 N: the strain of a tension on
    /// either piece, beyond both ends along the end pieces, and the curve read both ways.
    #[test]
    fn the_curve_is_read_both_ways_and_continued_beyond_its_ends() {
        let c = StrainCurve::new(vec![0.0, 0.01, 0.03], vec![0.0, 1e4, 9e4]).unwrap();
        for (tension, strain, slope) in [
            (5e3, 0.005, 1e-6),
            (3e4, 0.015, 0.25e-6),
            (1.3e5, 0.04, 0.25e-6),
            (-2e3, -0.002, 1e-6),
        ] {
            let (e, de) = c.strain(tension);
            assert!(
                (e - strain).abs() < 1e-15 && (de - slope).abs() < 1e-21,
                "{e} {de}"
            );
            assert!((c.tension(strain) - tension).abs() < 1e-9 * (1.0 + tension.abs()));
        }
        assert!((c.stiffest() - 4e6).abs() < 1e-6, "{}", c.stiffest());
    }

    /// Too few points, decreasing tensions and a NaN are refused, named.
    #[test]
    fn bad_curves_are_refused() {
        assert!(StrainCurve::new(vec![0.0], vec![0.0]).is_err());
        let e = StrainCurve::new(vec![0.0, 0.1, 0.2], vec![0.0, 5.0, 4.0]).unwrap_err();
        assert!(e.to_string().contains("tension 3"), "{e}");
        let e = StrainCurve::new(vec![0.0, f64::NAN], vec![0.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("strain 2"), "{e}");
        let e = StrainCurve::new(vec![0.001, 0.01], vec![0.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("first point"), "{e}");
    }
}
