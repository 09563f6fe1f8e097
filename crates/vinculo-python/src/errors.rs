//! Maps core errors onto the exception classes of `vinculo.errors` (one root, `VinculoError`).

use crate::user_physics::PendingError;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vinculo::Error;

/// Builds the Python exception `vinculo.errors.<class>(message, **details)`.
pub fn raise(py: Python<'_>, class: &str, message: String, details: Bound<'_, PyDict>) -> PyErr {
    let built = (|| -> PyResult<PyErr> {
        let cls = py.import("vinculo.errors")?.getattr(class)?;
        let exc = cls.call((message.clone(),), Some(&details))?;
        Ok(PyErr::from_value(exc))
    })();
    built.unwrap_or_else(|e| {
        PyRuntimeError::new_err(format!(
            "{message} (and the error class {class} could not be built: {e})"
        ))
    })
}

/// The details each variant carries, as keyword arguments.
fn details<'py>(py: Python<'py>, e: &Error) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match e {
        Error::InvalidParameter { name, value, .. } => {
            d.set_item("name", name)?;
            d.set_item("value", value)?;
        }
        Error::InvalidVector { name, value, .. } => {
            d.set_item("name", name)?;
            d.set_item("value", value.clone())?;
        }
        Error::SameParticle { particle, .. } => d.set_item("value", particle)?,
        Error::ConstraintOnFixedParticles { what } => d.set_item("name", what)?,
        Error::UnknownParticle { index, .. } => d.set_item("value", index)?,
        Error::LawOutOfDomain { what, .. } => d.set_item("name", what)?,
        Error::LawNotFinite { what, t, user, .. } => {
            d.set_item("name", what)?;
            d.set_item("time", t)?;
            if let Some(law) = user {
                d.set_item("group", law)?;
                d.set_item("call", "law")?;
            }
        }
        Error::InconsistentInitialState {
            level,
            constraint,
            violation,
            tolerance,
            ..
        } => {
            d.set_item("level", level)?;
            d.set_item("constraint", constraint)?;
            d.set_item("violation", violation)?;
            d.set_item("tolerance", tolerance)?;
        }
        Error::ProjectionFailed {
            iterations,
            residual,
            equation,
        } => {
            d.set_item("iterations", iterations)?;
            d.set_item("residual", residual)?;
            d.set_item("equation", equation)?;
        }
        Error::NewtonFailed {
            t,
            dt,
            iterations,
            residual,
            equation,
        } => {
            d.set_item("time", t)?;
            d.set_item("step_size", dt)?;
            d.set_item("iterations", iterations)?;
            d.set_item("residual", residual)?;
            d.set_item("equation", equation)?;
        }
        Error::SingularMatrix { t, equation, .. } => {
            d.set_item("time", t)?;
            d.set_item("equation", equation)?;
        }
        Error::StepSizeTooSmall { t, h, h_min, error } => {
            d.set_item("time", t)?;
            d.set_item("step_size", h)?;
            d.set_item("h_min", h_min)?;
            d.set_item("error_norm", error)?;
        }
        Error::StepBelowTimeResolution { t, h, smallest, .. } => {
            d.set_item("time", t)?;
            d.set_item("step_size", h)?;
            d.set_item("h_min", smallest)?;
        }
        Error::EnergyGrowth {
            t,
            dt,
            rho_inf,
            energy,
            initial,
            bound,
        } => {
            d.set_item("time", t)?;
            d.set_item("step_size", dt)?;
            d.set_item("rho_inf", rho_inf)?;
            d.set_item("energy", energy)?;
            d.set_item("initial_energy", initial)?;
            d.set_item("energy_bound", bound)?;
        }
        Error::Interrupted { t } => d.set_item("time", t)?,
        Error::OutputTooLarge {
            t,
            states,
            bytes,
            limit,
            ..
        } => {
            d.set_item("time", t)?;
            d.set_item("states", states.round() as u64)?;
            d.set_item("estimate", bytes.round() as u64)?;
            d.set_item("limit", limit.round() as u64)?;
        }
        Error::Snapshot { what, .. } => {
            d.set_item("name", "snapshot")?;
            d.set_item("value", what)?;
        }
        Error::UserFunction { group, call, t, .. }
        | Error::UserFunctionOutput { group, call, t, .. } => {
            d.set_item("group", group)?;
            d.set_item("call", call)?;
            d.set_item("time", t)?;
        }
        Error::RedundantConstraints {
            constraint,
            index,
            depends_on,
            depends_on_indices,
        } => {
            d.set_item("constraint", constraint)?;
            d.set_item("index", index)?;
            d.set_item("depends_on", depends_on.clone())?;
            d.set_item("depends_on_indices", depends_on_indices.clone())?;
        }
        Error::NegativeTension {
            t,
            constraint,
            index,
            tension,
        } => {
            d.set_item("time", t)?;
            d.set_item("constraint", constraint)?;
            d.set_item("index", index)?;
            d.set_item("tension", tension)?;
        }
    }
    Ok(d)
}

/// The one mapping from a core error to the Python exception that reports it, for every path (an
/// error returned by a call, and the error that stopped a run): the class of `vinculo.errors` the
/// variant selects ([`Error::kind`], a match on the variant), the core's message, the variant's
/// details as keyword arguments, and, for a failed user function, the user's own exception (with
/// its traceback) taken from `pending` as the cause. A run's partial solution is attached
/// afterwards by [`with_solution`] (it is built from the run's result, which holds this exception).
///
/// A user function's exception that is not a failure of the function passes through instead:
/// a `KeyboardInterrupt` (Ctrl-C landed in the function) becomes `vinculo.errors.Interrupted`
/// (the user's exception, with its traceback, as the cause), and a `ReentrantRunError` (the
/// function called back into its own system) or a `BaseException` that is not an `Exception`
/// (`SystemExit`, ...) is raised as it is.
pub fn exception(py: Python<'_>, e: &Error, pending: Option<&PendingError>) -> PyErr {
    // The pending exception is the one a user function raised in this run; it is the cause of
    // this error only when the error is that function's failure.
    let cause = pending.and_then(|p| p.lock().unwrap_or_else(|p| p.into_inner()).take());
    let (Error::UserFunction { group, call, t, .. }, Some(cause)) = (e, cause) else {
        return match details(py, e) {
            Ok(d) => raise(py, e.kind(), e.to_string(), d),
            Err(err) => err,
        };
    };
    let value = cause.value(py);
    if value.is_instance_of::<PyKeyboardInterrupt>() {
        let d = PyDict::new(py);
        let built = d
            .set_item("time", t)
            .and_then(|_| d.set_item("group", group))
            .and_then(|_| d.set_item("call", call));
        if let Err(err) = built {
            return err;
        }
        let message =
            format!("run interrupted at t = {t:.6} s, inside {call}() of group '{group}'");
        let err = raise(py, "Interrupted", message, d);
        err.set_cause(py, Some(cause));
        return err;
    }
    let reentrant = py
        .import("vinculo.errors")
        .and_then(|m| m.getattr("ReentrantRunError"))
        .and_then(|cls| value.is_instance(&cls))
        .unwrap_or(false);
    if reentrant || !value.is_instance_of::<PyException>() {
        return cause;
    }
    let err = match details(py, e) {
        Ok(d) => raise(py, e.kind(), e.to_string(), d),
        Err(err) => return err,
    };
    err.set_cause(py, Some(cause));
    err
}

/// Attaches the partial solution of a stopped run to its exception: the `solution` attribute and
/// detail of the `vinculo.errors` classes.
pub fn with_solution(py: Python<'_>, err: &PyErr, partial: &Bound<'_, PyAny>) -> PyResult<()> {
    let exc = err.value(py);
    exc.setattr("solution", partial)?;
    if let Ok(details) = exc.getattr("details") {
        // (a user's exception may have a `details` of its own that is not a dict)
        let _ = details.set_item("solution", partial);
    }
    Ok(())
}

/// Converts a core error (of a call that has no user function to blame) into the matching Python
/// exception ([`exception`]).
pub fn to_py(e: Error) -> PyErr {
    Python::attach(|py| exception(py, &e, None))
}

/// An input error with a name and value, raised as `InvalidInputError`.
pub fn invalid(name: &str, value: impl std::fmt::Display, expected: &str) -> PyErr {
    Python::attach(|py| {
        let d = PyDict::new(py);
        let _ = d.set_item("name", name);
        let _ = d.set_item("value", value.to_string());
        raise(
            py,
            "InvalidInputError",
            format!("invalid {name}: {value} ({expected})"),
            d,
        )
    })
}

/// Turns a panic (a bug) into `InternalError` instead of crashing the interpreter.
pub fn internal(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = payload
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "unknown panic".into());
    Python::attach(|py| {
        raise(
            py,
            "InternalError",
            format!("internal error in vinculo's core (please report it): {what}"),
            PyDict::new(py),
        )
    })
}
