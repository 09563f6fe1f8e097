//! `Simulation`: the core's stepping object behind a Python class (glue only).

use crate::errors::{invalid, to_py};
use crate::reentry::refuse_reentry;
use crate::run::{Progress, PyRunSettings};
use crate::run_result::PyRunResult;
use crate::system::PySystem;
use crate::user_physics::PendingError;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};
use vinculo::model::System;
use vinculo::{Simulation, Snapshot};

/// A copy of a running simulation's state, with what identifies the model it belongs to.
#[pyclass(name = "Snapshot", module = "vinculo._core", frozen)]
pub struct PySnapshot {
    inner: Snapshot,
}

#[pymethods]
impl PySnapshot {
    /// Time of the snapshot, in s.
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }

    /// Saves the snapshot to a file.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.inner.save(path).map_err(to_py)
    }

    /// Loads a snapshot saved by `save`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<PySnapshot> {
        Ok(PySnapshot {
            inner: Snapshot::load(path).map_err(to_py)?,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Snapshot(time={}, particles={}, constraint equations={})",
            self.inner.time(),
            self.inner.particles(),
            self.inner.constraints()
        )
    }
}

/// A running simulation of its own copy of a system.
#[pyclass(name = "Simulation", module = "vinculo._core")]
pub struct PySimulation {
    // Declared before `_system`, so dropped before it: `sim` borrows the boxed system.
    // In a mutex only to make the class Sync (Python holds the GIL around every call but
    // step_to, which has the `&mut` borrow).
    sim: Mutex<Simulation<'static>>,
    // Never moved out of nor mutated while `sim` lives (the box keeps its address).
    _system: Box<System>,
    user_errors: PendingError,
    /// A copy of the Python system, for the `vinculo.Solution` of a stopped run's exception.
    system: Py<PyAny>,
}

impl PySimulation {
    /// The running simulation.
    fn sim(&self) -> MutexGuard<'_, Simulation<'static>> {
        self.sim.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The exception of the error that stopped the run, raised.
    fn stopped(&self, py: Python<'_>) -> PyResult<()> {
        match self.solution(py)?.get().raised(py) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Forgets the exception of a user function of an earlier call.
    fn clear_pending(&self) {
        self.user_errors
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take();
    }
}

#[pymethods]
impl PySimulation {
    #[new]
    #[pyo3(signature = (system, settings))]
    fn new(
        system: Bound<'_, PySystem>,
        settings: PyRef<'_, PyRunSettings>,
    ) -> PyResult<PySimulation> {
        let py = system.py();
        let options = &settings.options;
        refuse_reentry(py, &system.borrow().user_errors, "Simulation")?;
        let copy = system.call_method0("copy")?.unbind();
        let system = system.borrow();
        // The simulation's own copy: editing the Python system afterwards does not reach it
        // (driven laws and user groups are shared with the copy).
        let model = Box::new(system.inner.clone());
        let user_errors = system.user_errors.clone();
        user_errors.lock().unwrap_or_else(|p| p.into_inner()).take();
        // SAFETY: the reference points into the box, which lives as long as `sim` (dropped
        // first, field order) and is never moved out of or mutated.
        let borrowed: &'static System = unsafe { &*(model.as_ref() as *const System) };
        let sim = Simulation::new(borrowed, options)
            .map_err(|e| crate::errors::exception(py, &e, Some(&user_errors)))?;
        Ok(PySimulation {
            sim: Mutex::new(sim),
            _system: model,
            user_errors,
            system: copy,
        })
    }

    /// Advances to time t (at most t_end); raises the exception of the error that stopped the run
    /// (with the states stored so far as its partial solution).
    fn step_to(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        if t.is_nan() || t < self.sim().time() {
            return Err(invalid(
                "t",
                t,
                &format!(
                    "must not be before the current time {}; restore a snapshot to go back",
                    self.sim().time()
                ),
            ));
        }
        if self.sim().status().is_err() {
            return self.stopped(py);
        }
        refuse_reentry(py, &self.user_errors, "Simulation.step_to")?;
        self.clear_pending();
        let sim = self.sim.get_mut().unwrap_or_else(|p| p.into_inner());
        // Ctrl-C stops the steps (the run's status is then `Interrupted`).
        let mut observer = Progress::new(None);
        let result = py.detach(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                sim.step_to_with_observer(t, &mut observer).is_ok()
            }))
        });
        if result.map_err(crate::errors::internal)? {
            Ok(())
        } else {
            self.stopped(py)
        }
    }

    /// Current time, in s.
    #[getter]
    fn time(&self) -> f64 {
        self.sim().time()
    }

    /// Current positions, shape (n, 3).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let sim = self.sim();
        let q = sim.positions();
        Array2::from_shape_vec((q.len(), 3), q.iter().flatten().copied().collect())
            .expect("shape")
            .into_pyarray(py)
    }

    /// Current velocities, shape (n, 3).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let sim = self.sim();
        let v = sim.velocities();
        Array2::from_shape_vec((v.len(), 3), v.iter().flatten().copied().collect())
            .expect("shape")
            .into_pyarray(py)
    }

    /// Current multipliers, shape (m,).
    #[getter]
    fn multipliers<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.sim().multipliers().to_vec()).into_pyarray(py)
    }

    /// The stored states so far, as `_core.simulate` returns them.
    fn solution<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyRunResult>> {
        let solution = self.sim().solution().clone();
        PyRunResult::finished(py, solution, &self.user_errors, self.system.bind(py))
    }

    /// A copy of the running state.
    fn snapshot(&self) -> PySnapshot {
        PySnapshot {
            inner: self.sim().snapshot(),
        }
    }

    /// Returns to the state of a snapshot of this simulation's model.
    fn restore(&mut self, snapshot: &Bound<'_, PyAny>) -> PyResult<()> {
        let Ok(snapshot) = snapshot.cast::<PySnapshot>() else {
            return Err(invalid(
                "snapshot",
                snapshot.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected a Snapshot taken by Simulation.snapshot()",
            ));
        };
        self.sim().try_restore(&snapshot.get().inner).map_err(to_py)
    }
}
