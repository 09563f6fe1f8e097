//! `simulate`: runs the core without the GIL, reports progress, returns numpy arrays.

use crate::errors::{details, invalid, to_py};
use crate::system::PySystem;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::{Duration, Instant};
use vinculo::integrators::{Formulation, NewtonOptions, Scheme};
use vinculo::{simulate_with_observer, AdaptiveOptions, Observer, SimulationOptions, StepControl};

/// Calls the Python progress callback and checks for Ctrl-C about twice a second.
struct Progress {
    callback: Option<Py<PyAny>>,
    last: Instant,
    error: Option<PyErr>,
}

impl Observer for Progress {
    fn step(&mut self, t: f64, t_end: f64) -> bool {
        if self.last.elapsed() < Duration::from_millis(500) {
            return true;
        }
        self.last = Instant::now();
        Python::attach(|py| {
            let result = py.check_signals().and_then(|_| match &self.callback {
                Some(cb) => cb.call1(py, (t, t_end)).map(|_| ()),
                None => Ok(()),
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

/// The scheme a name and its parameters select. A parameter of another scheme is refused rather
/// than ignored (the ranges are checked by the core).
fn scheme_by_name(name: &str, alpha: Option<f64>, rho_inf: Option<f64>) -> PyResult<Scheme> {
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
                rho_inf: rho_inf.unwrap_or(0.9),
            }),
        },
        other => Err(invalid(
            "scheme",
            format!("'{other}'"),
            "expected 'trapezoidal', 'backward-euler' or 'generalized-alpha'",
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

/// Integrates the system; see the type stubs (`_core.pyi`) for the returned dictionary.
#[pyfunction]
#[pyo3(signature = (system, settings, progress=None))]
pub fn simulate<'py>(
    py: Python<'py>,
    system: PyRef<'py, PySystem>,
    settings: PyRef<'py, PyRunSettings>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = &settings.options;
    let model = &system.inner;
    // The exception of a user function of an earlier run is no longer of interest.
    let pending = system.user_errors.clone();
    pending.lock().unwrap_or_else(|p| p.into_inner()).take();
    let mut observer = Progress {
        callback: progress,
        last: Instant::now(),
        error: None,
    };
    let result = py.detach(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            simulate_with_observer(model, options, &mut observer)
        }))
    });
    if let Some(e) = observer.error.take() {
        return Err(e);
    }
    let sol = result.map_err(crate::errors::internal)?.map_err(|e| {
        let user = matches!(e, vinculo::Error::UserFunction { .. });
        let err = to_py(e);
        let cause = pending.lock().unwrap_or_else(|p| p.into_inner()).take();
        if let (true, Some(cause)) = (user, cause) {
            err.set_cause(py, Some(cause));
        }
        err
    })?;

    solution_dict(py, &sol, &pending)
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
                        jacobian_reuse=false, scheme="trapezoidal", rho_inf=None,
                        formulation="index-3", adaptive=false, rtol=1e-6, atol=1e-6, h_min=1e-10,
                        h_max=None, t_eval=None))]
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
        jacobian_reuse: bool,
        scheme: &str,
        rho_inf: Option<f64>,
        formulation: &str,
        adaptive: bool,
        rtol: f64,
        atol: f64,
        h_min: f64,
        h_max: Option<f64>,
        t_eval: Option<Vec<f64>>,
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
            scheme: scheme_by_name(scheme, alpha, rho_inf)?,
            formulation: formulation_by_name(formulation)?,
            newton: NewtonOptions {
                tolerance,
                max_iterations: count("max_iterations", max_iterations, 1)?,
                jacobian_reuse,
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
            ..Default::default()
        };
        Ok(Self { options })
    }

    fn __repr__(&self) -> String {
        format!("RunSettings({:?})", self.options)
    }
}

/// The dictionary `Solution.from_core` reads (stubs, `_core.pyi`), with the user's exception of a
/// failed user function as the error's `cause`.
pub fn solution_dict<'py>(
    py: Python<'py>,
    sol: &vinculo::Solution,
    pending: &crate::user_physics::PendingError,
) -> PyResult<Bound<'py, PyDict>> {
    let (s, n, m) = (sol.len(), sol.particles, sol.constraints);
    let out = PyDict::new(py);
    out.set_item("times", Array1::from(sol.times.clone()).into_pyarray(py))?;
    out.set_item(
        "positions",
        Array3::from_shape_vec((s, n, 3), sol.positions.clone())
            .expect("shape")
            .into_pyarray(py),
    )?;
    out.set_item(
        "velocities",
        Array3::from_shape_vec((s, n, 3), sol.velocities.clone())
            .expect("shape")
            .into_pyarray(py),
    )?;
    out.set_item(
        "multipliers",
        Array2::from_shape_vec((s, m), sol.multipliers.clone())
            .expect("shape")
            .into_pyarray(py),
    )?;
    out.set_item(
        "constraint_residual",
        Array1::from(sol.constraint_residual.clone()).into_pyarray(py),
    )?;
    out.set_item(
        "velocity_violation",
        Array1::from(sol.velocity_violation.clone()).into_pyarray(py),
    )?;
    let stat = |f: &dyn Fn(&vinculo::StepStats) -> f64| Array1::from_iter(sol.stats.iter().map(f));
    out.set_item(
        "newton_iterations",
        Array1::from_iter(sol.stats.iter().map(|x| x.newton_iterations as i64)).into_pyarray(py),
    )?;
    out.set_item("step_sizes", stat(&|x| x.step_size).into_pyarray(py))?;
    out.set_item(
        "residual_norms",
        stat(&|x| x.residual_norm).into_pyarray(py),
    )?;
    out.set_item(
        "increment_norms",
        stat(&|x| x.increment_norm).into_pyarray(py),
    )?;
    out.set_item("steps_taken", sol.steps_taken)?;
    out.set_item("steps_rejected", sol.steps_rejected)?;
    out.set_item(
        "accepted_step_sizes",
        Array1::from(sol.accepted_step_sizes.clone()).into_pyarray(py),
    )?;
    out.set_item("factorisations", sol.factorisations)?;
    out.set_item("linear_solver", sol.linear_solver)?;
    out.set_item("scheme", sol.scheme.name())?;
    out.set_item("formulation", sol.formulation.name())?;
    match &sol.status {
        Ok(()) => out.set_item("error", py.None())?,
        Err(e) => {
            let d = details(py, e)?;
            d.set_item("kind", e.kind())?;
            d.set_item("message", e.to_string())?;
            // The user's own exception (with its traceback), to be raised as the cause.
            if let vinculo::Error::UserFunction { .. } = e {
                let cause = pending.lock().unwrap_or_else(|p| p.into_inner()).take();
                if let Some(cause) = cause {
                    d.set_item("cause", cause.into_value(py))?;
                }
            }
            out.set_item("error", d)?;
        }
    }
    Ok(out)
}
