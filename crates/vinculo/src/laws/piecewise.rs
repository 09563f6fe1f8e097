//! Piecewise-linear laws: a fixed table of knots, and a driven law whose knots an external code
//! appends while a run is stepped ([`crate::Simulation::step_to`]).

use std::sync::{Arc, RwLock};

use super::Derivatives;
use crate::error::{finite, Error, Result};

/// Linear interpolation between knots (t_k, x_k). The first derivative is the slope of the
/// segment that ends at or after t (left-continuous: at a knot, the segment that ends there); the
/// law is constant, at rest, before the first knot (and at it) and after the last.
///
/// Left-continuity makes a table that grows knot by knot ([`DrivenLaw`]) evaluate, at every time
/// up to its last knot, exactly as the full table does.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    times: Vec<f64>,
    values: Vec<f64>,
}

impl PiecewiseLinear {
    /// The table through the knots (`times[k]`, `values[k]`), validated: at least one knot,
    /// finite values, strictly increasing times.
    pub fn new(times: Vec<f64>, values: Vec<f64>) -> Result<PiecewiseLinear> {
        if times.is_empty() || times.len() != values.len() {
            return Err(Error::InvalidParameter {
                name: "number of piecewise-linear knots".into(),
                value: times.len() as f64,
                expected: format!(
                    "give at least one knot, and as many values as times ({} values)",
                    values.len()
                ),
            });
        }
        let mut table = PiecewiseLinear {
            times: Vec::with_capacity(times.len()),
            values: Vec::with_capacity(times.len()),
        };
        for (t, x) in times.into_iter().zip(values) {
            table.push(t, x)?;
        }
        Ok(table)
    }

    /// Appends the knot (t, x): t after the last knot, both finite.
    pub fn push(&mut self, t: f64, x: f64) -> Result<()> {
        let t = finite("knot time", t)?;
        let x = finite("knot value", x)?;
        if let Some(&last) = self.times.last() {
            if t <= last {
                return Err(Error::InvalidParameter {
                    name: "knot time".into(),
                    value: t,
                    expected: format!("must be after the last knot, t = {last}"),
                });
            }
        }
        self.times.push(t);
        self.values.push(x);
        Ok(())
    }

    /// Value, first and (zero) second derivative at `t`.
    pub fn eval(&self, t: f64) -> Derivatives {
        let n = self.times.len();
        if t <= self.times[0] {
            return (self.values[0], 0.0, 0.0);
        }
        if t > self.times[n - 1] {
            return (self.values[n - 1], 0.0, 0.0);
        }
        // The segment (k - 1, k) with t_{k-1} < t <= t_k.
        let k = self.times.partition_point(|&s| s < t);
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let (x0, x1) = (self.values[k - 1], self.values[k]);
        let slope = (x1 - x0) / (t1 - t0);
        (x0 + slope * (t - t0), slope, 0.0)
    }
}

/// A piecewise-linear law whose knots are appended while a run goes on (how an external code
/// drives a prescribed motion between calls of [`crate::Simulation::step_to`]). Clones share the
/// table: keep one to drive, give another to the model.
#[derive(Debug, Clone)]
pub struct DrivenLaw(Arc<RwLock<PiecewiseLinear>>);

impl PartialEq for DrivenLaw {
    /// The same shared table.
    fn eq(&self, other: &DrivenLaw) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl DrivenLaw {
    /// A driven law with value `x` at time `t` (and before).
    pub fn new(t: f64, x: f64) -> Result<DrivenLaw> {
        let table = PiecewiseLinear::new(vec![t], vec![x])?;
        Ok(DrivenLaw(Arc::new(RwLock::new(table))))
    }

    /// Sets the value at time `t` (after the last one set): the law moves linearly to it.
    pub fn set(&self, t: f64, x: f64) -> Result<()> {
        self.0.write().unwrap_or_else(|e| e.into_inner()).push(t, x)
    }

    /// Value, first and (zero) second derivative at `t`.
    pub fn eval(&self, t: f64) -> Derivatives {
        self.0.read().unwrap_or_else(|e| e.into_inner()).eval(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values and slopes against the straight lines through the knots (by hand), left-continuous
    /// at a knot, at rest outside the table; a driven law built knot by knot evaluates as the
    /// full table up to its last knot, bit for bit.
    #[test]
    fn interpolates_and_grows_like_the_full_table() {
        let table = PiecewiseLinear::new(vec![0.0, 1.0, 3.0], vec![2.0, 4.0, 3.0]).unwrap();
        assert_eq!(table.eval(-1.0), (2.0, 0.0, 0.0));
        assert_eq!(table.eval(0.0), (2.0, 0.0, 0.0));
        assert_eq!(table.eval(0.5), (3.0, 2.0, 0.0));
        assert_eq!(table.eval(1.0), (4.0, 2.0, 0.0));
        assert_eq!(table.eval(2.0), (3.5, -0.5, 0.0));
        assert_eq!(table.eval(4.0), (3.0, 0.0, 0.0));
        let driven = DrivenLaw::new(0.0, 2.0).unwrap();
        driven.set(1.0, 4.0).unwrap();
        for t in [0.0, 0.3, 1.0] {
            assert_eq!(driven.eval(t), table.eval(t));
        }
        driven.set(3.0, 3.0).unwrap();
        for t in [1.0, 1.7, 3.0] {
            assert_eq!(driven.eval(t), table.eval(t));
        }
        assert!(driven.set(2.0, 0.0).is_err());
        assert!(PiecewiseLinear::new(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
    }
}
