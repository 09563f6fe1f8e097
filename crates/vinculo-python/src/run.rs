//! `simulate`: runs the core without the GIL, reports progress, returns numpy arrays.

use crate::errors::{exception, invalid, with_solution};
use crate::reentry::refuse_reentry;
use crate::run_result::PyRunResult;
use crate::system::PySystem;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use std::time::{Duration, Instant};
use vinculo::integrators::{Formulation, JacobianReuse, NewtonOptions, Scheme};
use vinculo::{
    simulate_with_observer, AdaptiveOptions, Observer, SimulationOptions, SparseSolver, StepControl,
};

/// Looks for Ctrl-C (SIGINT) about ten times a second of wall time and calls the Python progress
/// callback about twice a second; an exception of either stops the run after the step just
/// completed (the run's status is then `Interrupted`). The clock itself is read every
/// `stride` steps, a stride that keeps its readings about [`CLOCK_PERIOD`] apart: on a pendulum
/// (0.5 us a step) a reading at every step was 5 % of the run, on a model whose steps take
/// longer than that period it is read at every step.
pub(crate) struct Progress {
    callback: Option<Py<PyAny>>,
    signals_checked: Instant,
    reported: Instant,
    /// The clock's last reading, the steps between readings and the steps left to the next.
    read: Instant,
    stride: u64,
    countdown: u64,
    /// The exception that stopped the run (a `KeyboardInterrupt`, or the callback's).
    pub(crate) error: Option<PyErr>,
}

impl Progress {
    /// Signals checked from now on, and `callback` (if any) called.
    pub(crate) fn new(callback: Option<Py<PyAny>>) -> Progress {
        let now = Instant::now();
        Progress {
            callback,
            signals_checked: now,
            reported: now,
            read: now,
            stride: 1,
            countdown: 1,
            error: None,
        }
    }
}

/// The wall time between two readings of the clock by [`Progress`].
const CLOCK_PERIOD: Duration = Duration::from_millis(1);

impl Observer for Progress {
    fn step(&mut self, t: f64, t_end: f64) -> bool {
        self.countdown -= 1;
        if self.countdown > 0 {
            return true;
        }
        let now = Instant::now();
        // The stride that would have spanned one period over the steps since the last reading
        // (at most doubled at a time, so that a run whose steps slow down is read soon enough).
        let elapsed = now.duration_since(self.read).as_secs_f64();
        let fitting = (self.stride as f64 * CLOCK_PERIOD.as_secs_f64() / elapsed.max(1e-9)) as u64;
        self.stride = fitting.clamp(1, 2 * self.stride);
        self.countdown = self.stride;
        self.read = now;
        if now.duration_since(self.signals_checked) < Duration::from_millis(100) {
            return true;
        }
        self.signals_checked = now;
        let report = self.callback.is_some()
            && now.duration_since(self.reported) >= Duration::from_millis(500);
        if report {
            self.reported = now;
        }
        Python::attach(|py| {
            let result = py.check_signals().and_then(|_| match &self.callback {
                Some(cb) if report => cb.call1(py, (t, t_end)).map(|_| ()),
                _ => Ok(()),
            });
            match result {
                Ok(()) => true,
                Err(e) => {
                    self.error = Some(e);
                    false
                }
            }
        })
    }
}

/// The exception that stopped a run from its observer, to raise: a `KeyboardInterrupt` is
/// reported by the run's own exception (`vinculo.errors.Interrupted`, with the partial
/// solution), any other exception (the progress callback's) is raised as it is, with the
/// partial solution attached as its `solution` attribute and a note saying so.
pub(crate) fn observer_failure(
    py: Python<'_>,
    error: Option<PyErr>,
    result: &Bound<'_, PyRunResult>,
) -> Option<PyErr> {
    let e = error?;
    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
        return None;
    }
    if let Some(partial) = result
        .get()
        .stopped_by(py)
        .and_then(|x| x.getattr("solution").ok())
    {
        let _ = with_solution(py, &e, &partial);
        let t = partial
            .getattr("times")
            .and_then(|times| times.call_method0("max"))
            .and_then(|x| x.extract::<f64>())
            .unwrap_or(f64::NAN);
        let _ = e.value(py).call_method1(
            "add_note",
            (format!(
                "vinculo: the run stopped at t = {t} s; the states it computed are in this \
                 exception's `solution` attribute"
            ),),
        );
    }
    Some(e)
}

/// The scheme a name and its parameters select. A parameter of another scheme is refused rather
/// than ignored (the ranges are checked by the core).
fn scheme_by_name(
    name: &str,
    alpha: Option<f64>,
    rho_inf: Option<f64>,
    formulation: Formulation,
) -> PyResult<Scheme> {
    let only_alpha_point = "rho_inf applies to scheme='generalized-alpha' only";
    match name {
        "trapezoidal" => match rho_inf {
            Some(rho) => Err(invalid("rho_inf", rho, only_alpha_point)),
            None => Ok(Scheme::GeneralizedTrapezoidal {
                alpha: alpha.unwrap_or(0.5),
            }),
        },
        "backward-euler" => match (alpha, rho_inf) {
            (Some(a), _) if a != 1.0 => Err(invalid(
                "alpha",
                a,
                "backward-euler is alpha = 1; for another alpha use scheme='trapezoidal'",
            )),
            (_, Some(rho)) => Err(invalid("rho_inf", rho, only_alpha_point)),
            _ => Ok(Scheme::GeneralizedTrapezoidal { alpha: 1.0 }),
        },
        "generalized-alpha" => match alpha {
            Some(a) => Err(invalid(
                "alpha",
                a,
                "alpha belongs to the trapezoidal schemes; generalized-alpha takes rho_inf",
            )),
            None => Ok(Scheme::GeneralizedAlpha {
                rho_inf: rho_inf.unwrap_or_else(|| default_rho_inf(formulation)),
            }),
        },
        other => Err(invalid(
            "scheme",
            format!("'{other}'"),
            "expected 'trapezoidal', 'backward-euler' or 'generalized-alpha'",
        )),
    }
}

/// The spectral radius of generalised-alpha when none is given: the safe choice of each
/// formulation. Index-3 generalised-alpha is unstable at coarse steps for large rho_inf (on the
/// pendulum of `docs/theory/time-rules.md`: 0.5 is stable from 10 steps a period, 0.9 only from
/// 100), so its default is 0.5; the GGL form was stable at every step and rho_inf measured, so
/// it keeps 0.9, which damps only the highest frequencies.
pub(crate) fn default_rho_inf(formulation: Formulation) -> f64 {
    match formulation {
        Formulation::Index3 => 0.5,
        Formulation::Ggl => 0.9,
    }
}

/// The choice of sparse solver a name selects.
fn sparse_solver_by_name(name: &str) -> PyResult<SparseSolver> {
    match name {
        "auto" => Ok(SparseSolver::Auto),
        "sparse-lu" => Ok(SparseSolver::SparseLu),
        other => Err(invalid(
            "linear_solver",
            format!("'{other}'"),
            "expected 'auto' or 'sparse-lu'",
        )),
    }
}

/// The formulation a name selects.
fn formulation_by_name(name: &str) -> PyResult<Formulation> {
    match name {
        "index-3" => Ok(Formulation::Index3),
        "ggl" => Ok(Formulation::Ggl),
        other => Err(invalid(
            "formulation",
            format!("'{other}'"),
            "expected 'index-3' or 'ggl'",
        )),
    }
}

/// Integrates the system; returns the run (`RunResult`, see the type stubs `_core.pyi`), which
/// carries the error that stopped it early, if any, as its exception.
#[pyfunction]
#[pyo3(signature = (system, settings, progress=None))]
pub fn simulate<'py>(
    py: Python<'py>,
    system: Bound<'py, PySystem>,
    settings: PyRef<'py, PyRunSettings>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyRunResult>> {
    let options = &settings.options;
    let this = system.borrow();
    let model = &this.inner;
    let pending = this.user_errors.clone();
    refuse_reentry(py, &pending, "simulate")?;
    // The exception of a user function of an earlier run is no longer of interest.
    pending.lock().unwrap_or_else(|p| p.into_inner()).take();
    let mut observer = Progress::new(progress);
    let result = py.detach(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            simulate_with_observer(model, options, &mut observer)
        }))
    });
    let sol = result
        .map_err(crate::errors::internal)?
        .map_err(|e| exception(py, &e, Some(&pending)))?;
    drop(this);
    let result = PyRunResult::finished(py, sol, &pending, system.as_any())?;
    match observer_failure(py, observer.error.take(), &result) {
        Some(e) => Err(e),
        None => Ok(result),
    }
}

/// The settings of a run (the keyword arguments of `vinculo.simulate`, less `progress`), converted
/// to the core's `SimulationOptions` and checked once; `simulate` and `Simulation` take it.
#[pyclass(name = "RunSettings", module = "vinculo._core", frozen)]
pub struct PyRunSettings {
    pub(crate) options: SimulationOptions,
}

#[pymethods]
impl PyRunSettings {
    #[new]
    #[pyo3(signature = (t_end, dt, alpha=None, t_start=0.0, tolerance=1e-10, max_iterations=25,
                        max_halvings=4, initial_tolerance=1e-8, save_every=1,
                        jacobian_reuse=None, scheme="trapezoidal", rho_inf=None,
                        formulation="index-3", adaptive=false, rtol=1e-6, atol=1e-6, h_min=1e-10,
                        h_max=None, t_eval=None, max_output_bytes=None,
                        linear_solver="auto"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        t_end: f64,
        dt: f64,
        alpha: Option<f64>,
        t_start: f64,
        tolerance: f64,
        max_iterations: i64,
        max_halvings: i64,
        initial_tolerance: f64,
        save_every: i64,
        jacobian_reuse: Option<bool>,
        scheme: &str,
        rho_inf: Option<f64>,
        formulation: &str,
        adaptive: bool,
        rtol: f64,
        atol: f64,
        h_min: f64,
        h_max: Option<f64>,
        t_eval: Option<Vec<f64>>,
        max_output_bytes: Option<f64>,
        linear_solver: &str,
    ) -> PyResult<Self> {
        let count = |name: &str, v: i64, min: i64| -> PyResult<usize> {
            if v < min {
                Err(invalid(name, v, &format!("must be an integer >= {min}")))
            } else {
                Ok(v as usize)
            }
        };
        let options = SimulationOptions {
            t_start,
            t_end,
            dt,
            scheme: scheme_by_name(scheme, alpha, rho_inf, formulation_by_name(formulation)?)?,
            formulation: formulation_by_name(formulation)?,
            newton: NewtonOptions {
                tolerance,
                max_iterations: count("max_iterations", max_iterations, 1)?,
                jacobian_reuse: match jacobian_reuse {
                    None => JacobianReuse::WhileFast,
                    Some(true) => JacobianReuse::Always,
                    Some(false) => JacobianReuse::Never,
                },
            },
            max_halvings: count("max_halvings", max_halvings, 0)?,
            initial_tolerance,
            save_every: count("save_every", save_every, 1)?,
            step_control: if adaptive {
                StepControl::Adaptive(AdaptiveOptions {
                    rtol,
                    atol,
                    h_min,
                    h_max: h_max.unwrap_or(f64::INFINITY),
                    ..Default::default()
                })
            } else {
                StepControl::Fixed
            },
            output_times: t_eval,
            max_output_bytes,
            sparse_solver: sparse_solver_by_name(linear_solver)?,
            ..Default::default()
        };
        Ok(Self { options })
    }

    fn __repr__(&self) -> String {
        format!("RunSettings({:?})", self.options)
    }
}

/// The least wall-clock time (s) of `repeats` runs of the core's `simulate` on `system` with
/// `settings`, in Rust alone: no conversion of the solution to Python objects. The Python
/// overhead benchmark (`python -m vinculo.bench python-overhead`) sets `vinculo.simulate`'s
/// time against it, on the same model in the same process.
#[pyfunction]
#[pyo3(signature = (system, settings, repeats=1))]
pub fn time_simulate(
    py: Python<'_>,
    system: PyRef<'_, PySystem>,
    settings: PyRef<'_, PyRunSettings>,
    repeats: i64,
) -> PyResult<f64> {
    if repeats < 1 {
        return Err(invalid("repeats", repeats, "must be an integer >= 1"));
    }
    let (model, options) = (&system.inner, &settings.options);
    let best = py.detach(|| {
        let mut best = f64::INFINITY;
        for _ in 0..repeats {
            let start = Instant::now();
            let run = vinculo::simulate(model, options);
            let elapsed = start.elapsed().as_secs_f64();
            // An error before the first step, or one that stopped the run part-way.
            run.map_err(|e| e.to_string())?
                .status
                .map_err(|e| e.to_string())?;
            best = best.min(elapsed);
        }
        Ok::<f64, String>(best)
    });
    best.map_err(pyo3::exceptions::PyRuntimeError::new_err)
}
