//! `Law`: prescribed functions of time, and the conversion of Python numbers or laws into them.

use crate::errors::{invalid, to_py};
use pyo3::prelude::*;
use vinculo::laws::{DrivenLaw, Law, VectorLaw};

/// A prescribed scalar function of time with its first and second derivatives.
#[pyclass(name = "Law", module = "vinculo._core", frozen)]
#[derive(Clone)]
pub struct PyLaw {
    pub inner: Law,
}

#[pymethods]
impl PyLaw {
    /// A constant value.
    #[staticmethod]
    fn constant(value: f64) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::constant(value).map_err(to_py)?,
        })
    }

    /// c0 + c1 t + c2 t^2 + ... (coefficients in increasing powers).
    #[staticmethod]
    fn polynomial(coefficients: Vec<f64>) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::polynomial(coefficients).map_err(to_py)?,
        })
    }

    /// offset + amplitude s(t) sin(2 pi frequency (t - t_start) + phase), s a C2 ramp over ramp_time.
    #[staticmethod]
    #[pyo3(signature = (amplitude, frequency, phase=0.0, offset=0.0, ramp_time=0.0, t_start=0.0))]
    fn sine(
        amplitude: f64,
        frequency: f64,
        phase: f64,
        offset: f64,
        ramp_time: f64,
        t_start: f64,
    ) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::sine(amplitude, frequency, phase, offset, ramp_time, t_start)
                .map_err(to_py)?,
        })
    }

    /// Natural cubic spline through (times, values); defined on [times[0], times[-1]].
    #[staticmethod]
    fn tabulated(times: Vec<f64>, values: Vec<f64>) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::tabulated(times, values).map_err(to_py)?,
        })
    }

    /// Linear interpolation between knots (times, values), at rest outside them.
    #[staticmethod]
    fn piecewise_linear(times: Vec<f64>, values: Vec<f64>) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::piecewise_linear(times, values).map_err(to_py)?,
        })
    }

    /// A piecewise-linear law driven while a run is stepped: value x at time t (and before).
    #[staticmethod]
    #[pyo3(signature = (x, t=0.0))]
    fn driven(x: f64, t: f64) -> PyResult<PyLaw> {
        Ok(PyLaw {
            inner: Law::Driven(DrivenLaw::new(t, x).map_err(to_py)?),
        })
    }

    /// Sets a driven law's value at time t (after the last time set).
    fn set(&self, t: f64, x: f64) -> PyResult<()> {
        match &self.inner {
            Law::Driven(driven) => driven.set(t, x).map_err(to_py),
            _ => Err(invalid(
                "law",
                self.__repr__(),
                "only a driven law (Law.driven) can be set",
            )),
        }
    }

    /// Value at t.
    fn __call__(&self, t: f64) -> f64 {
        self.inner.value(t)
    }

    /// (value, first derivative, second derivative) at t.
    fn derivatives(&self, t: f64) -> (f64, f64, f64) {
        self.inner.eval(t)
    }

    /// Interval of time on which the law is defined.
    fn domain(&self) -> (f64, f64) {
        self.inner.domain()
    }

    fn __repr__(&self) -> String {
        match &self.inner {
            Law::Constant(c) => format!("Law.constant({c})"),
            Law::Polynomial(c) => format!("Law.polynomial({c:?})"),
            Law::Sine { amplitude, frequency, phase, offset, ramp_time, t_start } => format!(
                "Law.sine(amplitude={amplitude}, frequency={frequency}, phase={phase}, offset={offset}, ramp_time={ramp_time}, t_start={t_start})"
            ),
            Law::Tabulated(s) => format!("Law.tabulated(<spline on {:?}>)", s.domain()),
            Law::PiecewiseLinear(_) => "Law(<piecewise linear>)".to_string(),
            Law::Driven(_) => "Law(<driven>)".to_string(),
        }
    }
}

/// A Python float or Law as a core law.
pub fn scalar(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Law> {
    if let Ok(law) = obj.cast::<PyLaw>() {
        return Ok(law.get().inner.clone());
    }
    match obj.extract::<f64>() {
        Ok(v) if v.is_finite() => Ok(Law::Constant(v)),
        Ok(v) => Err(invalid(what, v, "must be finite")),
        Err(_) => Err(invalid(
            what,
            obj.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected a number or a vinculo Law",
        )),
    }
}

/// A sequence of three floats or Laws as a core vector law.
pub fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<VectorLaw> {
    let items: Vec<Bound<'_, PyAny>> = obj
        .try_iter()
        .and_then(|it| it.collect::<PyResult<Vec<_>>>())
        .map_err(|_| {
            invalid(
                what,
                obj.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected 3 numbers or Laws",
            )
        })?;
    if items.len() != 3 {
        return Err(invalid(
            what,
            format!("{} components", items.len()),
            "expected exactly 3 components",
        ));
    }
    let names = ["x", "y", "z"];
    Ok(VectorLaw([
        scalar(&items[0], &format!("{what} ({})", names[0]))?,
        scalar(&items[1], &format!("{what} ({})", names[1]))?,
        scalar(&items[2], &format!("{what} ({})", names[2]))?,
    ]))
}
