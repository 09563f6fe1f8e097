//! `Law`: prescribed functions of time, and the conversion of Python numbers or laws into them.

use crate::errors::{invalid, to_py};
use pyo3::prelude::*;
use std::sync::Arc;
use vinculo::laws::{DrivenLaw, EndCondition, Function, Law, UserLaw, VectorLaw};

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

    /// A cubic spline through samples with end condition `ends` ("natural", "clamped" with
    /// `slopes`, or "not-a-knot").
    #[staticmethod]
    #[pyo3(signature = (times, values, ends="natural", slopes=None))]
    fn spline(
        times: Vec<f64>,
        values: Vec<f64>,
        ends: &str,
        slopes: Option<(f64, f64)>,
    ) -> PyResult<PyLaw> {
        let ends = match (ends, slopes) {
            ("natural", None) => EndCondition::Natural,
            ("not-a-knot", None) => EndCondition::NotAKnot,
            ("clamped", Some((d0, dn))) => EndCondition::Clamped(d0, dn),
            ("clamped", None) => {
                return Err(invalid(
                    "slopes",
                    "None",
                    "a clamped spline needs its end slopes: slopes=(first, last)",
                ))
            }
            ("natural" | "not-a-knot", Some(s)) => {
                return Err(invalid(
                    "slopes",
                    format!("{s:?}"),
                    "only a clamped spline takes end slopes (ends='clamped')",
                ))
            }
            (other, _) => {
                return Err(invalid(
                    "ends",
                    other,
                    "expected 'natural', 'clamped' or 'not-a-knot'",
                ))
            }
        };
        Ok(PyLaw {
            inner: Law::tabulated_with(times, values, ends).map_err(to_py)?,
        })
    }

    /// f(law) for f one of sqrt, sin, cos, exp, log, or law ** exponent for "power".
    #[staticmethod]
    #[pyo3(signature = (name, law, exponent=None))]
    fn apply(name: &str, law: &Bound<'_, PyAny>, exponent: Option<f64>) -> PyResult<PyLaw> {
        let f = match (name, exponent) {
            ("sqrt", None) => Function::Sqrt,
            ("sin", None) => Function::Sin,
            ("cos", None) => Function::Cos,
            ("exp", None) => Function::Exp,
            ("log", None) => Function::Log,
            ("power", Some(p)) => Function::Power(p),
            _ => {
                return Err(invalid(
                    "function",
                    name,
                    "expected 'sqrt', 'sin', 'cos', 'exp', 'log', or 'power' with an exponent",
                ))
            }
        };
        let argument = scalar(law, &format!("argument of {name}"))?;
        Ok(PyLaw {
            inner: Law::apply(f, argument).map_err(to_py)?,
        })
    }

    /// A law computed by a Python function t -> (value, rate, acceleration).
    #[staticmethod]
    #[pyo3(signature = (function, name=None))]
    fn function(function: Bound<'_, PyAny>, name: Option<String>) -> PyResult<PyLaw> {
        if !function.is_callable() {
            return Err(invalid(
                "function",
                function.repr()?.to_string(),
                "expected a callable t -> (value, rate, acceleration)",
            ));
        }
        let name = match name {
            Some(n) => n,
            None => function
                .getattr("__name__")
                .and_then(|n| n.extract::<String>())
                .unwrap_or_else(|_| "law".to_string()),
        };
        let callable: Py<PyAny> = function.unbind();
        let call = move |t: f64| -> Result<(f64, f64, f64), String> {
            Python::attach(|py| {
                let out = callable.bind(py).call1((t,)).map_err(|e| e.to_string())?;
                out.extract::<(f64, f64, f64)>().map_err(|_| {
                    let shown = out.repr().map(|r| r.to_string()).unwrap_or_default();
                    format!(
                        "must return (value, rate, acceleration) as three numbers, returned \
                         {shown}"
                    )
                })
            })
        };
        Ok(PyLaw {
            inner: Law::User(UserLaw::new(name, Arc::new(call))),
        })
    }

    fn __add__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, Law::sum)
    }

    fn __radd__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, |a, b| Law::sum(b, a))
    }

    fn __sub__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, |a, b| Law::sum(a, negative(b)))
    }

    fn __rsub__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, |a, b| Law::sum(b, negative(a)))
    }

    fn __mul__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, Law::product)
    }

    fn __rmul__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, |a, b| Law::product(b, a))
    }

    fn __truediv__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, Law::quotient)
    }

    fn __rtruediv__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> Py<PyAny> {
        self.binary(py, other, |a, b| Law::quotient(b, a))
    }

    fn __neg__(&self) -> PyLaw {
        PyLaw {
            inner: negative(self.inner.clone()),
        }
    }

    fn __pos__(&self) -> PyLaw {
        self.clone()
    }

    fn __pow__(
        &self,
        py: Python<'_>,
        exponent: &Bound<'_, PyAny>,
        modulo: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        match (exponent.extract::<f64>(), modulo) {
            (Ok(p), None) => Ok(PyLaw {
                inner: Law::apply(Function::Power(p), self.inner.clone()).map_err(to_py)?,
            }
            .into_pyobject(py)?
            .into_any()
            .unbind()),
            _ => Ok(py.NotImplemented()),
        }
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
            other => format!("Law({})", other.formula()),
        }
    }
}

impl PyLaw {
    /// `op(self, other)` as a new law, or NotImplemented when `other` is neither a number nor
    /// a law (so that Python tries the other operand, then raises TypeError).
    fn binary(
        &self,
        py: Python<'_>,
        other: &Bound<'_, PyAny>,
        op: impl Fn(Law, Law) -> Law,
    ) -> Py<PyAny> {
        let other = match other.cast::<PyLaw>() {
            Ok(law) => law.get().inner.clone(),
            Err(_) => match other.extract::<f64>() {
                // A NaN or infinite operand stays NaN in the law: the run names it (LawNotFinite).
                Ok(v) => Law::Constant(v),
                Err(_) => return py.NotImplemented(),
            },
        };
        let law = PyLaw {
            inner: op(self.inner.clone(), other),
        };
        match law.into_pyobject(py) {
            Ok(obj) => obj.into_any().unbind(),
            Err(_) => py.NotImplemented(),
        }
    }
}

/// -law, as the product with -1.
fn negative(law: Law) -> Law {
    Law::product(Law::Constant(-1.0), law)
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
