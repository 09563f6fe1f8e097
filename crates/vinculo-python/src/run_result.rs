//! `RunResult`: what a run returns to Python (`_core.simulate`, `_core.Simulation.solution`), the
//! core's [`vinculo::Solution`] behind typed read-only getters, with the error that stopped the
//! run as the exception that reports it.

use crate::errors::{exception, with_solution};
use crate::user_physics::PendingError;
use numpy::ndarray::Dimension;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{Element, IntoPyArray, PyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;

/// `array` (fresh, shared with nobody) made read-only: a run's stored arrays are its record,
/// not to be edited in place (`vinculo.Solution` hands them out as they are).
fn read_only<'py, T: Element, D: Dimension>(
    array: Bound<'py, PyArray<T, D>>,
) -> Bound<'py, PyArray<T, D>> {
    let frozen = array.readwrite().make_nonwriteable();
    (*frozen).clone()
}

/// The stored states of a run, its statistics, and the exception of the error that stopped it.
#[pyclass(name = "RunResult", module = "vinculo._core", frozen)]
pub struct PyRunResult {
    solution: vinculo::Solution,
    /// The `vinculo.errors` exception of the error that stopped the run (None: it reached its end).
    error: Option<Py<PyAny>>,
}

impl PyRunResult {
    /// The result of a run that ended with `solution`. A run that stopped early carries its error
    /// as the exception the one mapping builds ([`exception`]), the user's exception of a failed
    /// user function (taken from `pending`) as its cause, and the partial solution: the
    /// `vinculo.Solution` of this result and a copy of `system`, as its `solution` attribute.
    pub fn finished<'py>(
        py: Python<'py>,
        solution: vinculo::Solution,
        pending: &PendingError,
        system: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyRunResult>> {
        let Err(e) = &solution.status else {
            return Bound::new(
                py,
                PyRunResult {
                    solution,
                    error: None,
                },
            );
        };
        let error = exception(py, e, Some(pending));
        let result = Bound::new(
            py,
            PyRunResult {
                solution,
                error: Some(error.value(py).clone().into_any().unbind()),
            },
        )?;
        // The partial solution is built from this result (so it reads the error's description
        // from it): it can only be attached once the exception exists.
        let partial = py
            .import("vinculo.solution")?
            .getattr("Solution")?
            .call_method1("from_core", (&result, system.call_method0("copy")?))?;
        with_solution(py, &error, &partial)?;
        Ok(result)
    }

    /// The exception of the error that stopped the run, to raise (None: it reached its end).
    pub fn raised(&self, py: Python<'_>) -> Option<PyErr> {
        self.error
            .as_ref()
            .map(|e| PyErr::from_value(e.bind(py).clone()))
    }

    /// The exception of the error that stopped the run, as an object (None: it reached its end).
    pub fn stopped_by<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.error.as_ref().map(|e| e.bind(py).clone())
    }

    /// A per-step statistic as an array.
    fn stat<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        f: impl Fn(&vinculo::StepStats) -> T,
    ) -> Bound<'py, PyArray1<T>> {
        read_only(Array1::from_iter(self.solution.stats.iter().map(f)).into_pyarray(py))
    }

    /// A per-state array of (particles, 3) rows.
    fn states<'py>(&self, py: Python<'py>, flat: &[f64]) -> Bound<'py, PyArray3<f64>> {
        let shape = (self.solution.len(), self.solution.particles, 3);
        read_only(
            Array3::from_shape_vec(shape, flat.to_vec())
                .expect("the core stores 3 coordinates per particle and state")
                .into_pyarray(py),
        )
    }
}

#[pymethods]
impl PyRunResult {
    /// Stored times, shape (s,), in s.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        read_only(PyArray1::from_slice(py, &self.solution.times))
    }

    /// Positions, shape (s, n, 3), in m.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        self.states(py, &self.solution.positions)
    }

    /// Velocities, shape (s, n, 3), in m/s.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        self.states(py, &self.solution.velocities)
    }

    /// Lagrange multipliers, shape (s, m).
    #[getter]
    fn multipliers<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let shape = (self.solution.len(), self.solution.constraints);
        read_only(
            Array2::from_shape_vec(shape, self.solution.multipliers.clone())
                .expect("the core stores one multiplier per constraint equation and state")
                .into_pyarray(py),
        )
    }

    /// max_k |s_k Phi_k| at each stored time, shape (s,), in m.
    #[getter]
    fn constraint_residual<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        read_only(PyArray1::from_slice(py, &self.solution.constraint_residual))
    }

    /// max_k |s_k (Phi_q v + Phi_t)| at each stored time, shape (s,), in m/s.
    #[getter]
    fn velocity_violation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        read_only(PyArray1::from_slice(py, &self.solution.velocity_violation))
    }

    /// Newton iterations of each stored step, shape (s,).
    #[getter]
    fn newton_iterations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.stat(py, |x| x.newton_iterations as i64)
    }

    /// Size of each stored step, shape (s,), in s.
    #[getter]
    fn step_sizes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.stat(py, |x| x.step_size)
    }

    /// The last scaled residual norm Newton evaluated in each stored step, shape (s,), in m.
    #[getter]
    fn residual_norms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.stat(py, |x| x.residual_norm)
    }

    /// Last scaled Newton increment norm of each stored step, shape (s,), in m.
    #[getter]
    fn increment_norms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.stat(py, |x| x.increment_norm)
    }

    /// Size of every accepted step, stored or not, in s.
    #[getter]
    fn accepted_step_sizes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        read_only(PyArray1::from_slice(py, &self.solution.accepted_step_sizes))
    }

    /// Steps attempted, including those rejected and retried.
    #[getter]
    fn steps_taken(&self) -> usize {
        self.solution.steps_taken
    }

    /// Attempts rejected.
    #[getter]
    fn steps_rejected(&self) -> usize {
        self.solution.steps_rejected
    }

    /// Newton iteration matrices factorised.
    #[getter]
    fn factorisations(&self) -> usize {
        self.solution.factorisations
    }

    /// Residual evaluations of the step equations by Newton's iterations.
    #[getter]
    fn residual_evaluations(&self) -> usize {
        self.solution.residual_evaluations
    }

    /// The linear solver of the steps.
    #[getter]
    fn linear_solver(&self) -> &'static str {
        self.solution.linear_solver
    }

    /// The time discretisation.
    #[getter]
    fn scheme(&self) -> &'static str {
        self.solution.scheme.name()
    }

    /// The equations discretised.
    #[getter]
    fn formulation(&self) -> &'static str {
        self.solution.formulation.name()
    }

    /// The exception of the error that stopped the run, None when it reached its end.
    #[getter]
    fn error(&self, py: Python<'_>) -> Option<Py<PyAny>> {
        self.error.as_ref().map(|e| e.clone_ref(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "RunResult({} states, {} particles, {} constraint equations, {})",
            self.solution.len(),
            self.solution.particles,
            self.solution.constraints,
            match &self.solution.status {
                Ok(()) => "complete".to_string(),
                Err(e) => format!("stopped: {}", e.kind()),
            }
        )
    }
}
