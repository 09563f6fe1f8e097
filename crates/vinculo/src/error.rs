//! The one error type of vinculo. Every variant carries the numbers a user needs to act on it.

use thiserror::Error as ThisError;

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong, from bad input to a step that does not converge.
#[derive(Debug, Clone, PartialEq, ThisError)]
pub enum Error {
    /// A scalar input is outside its valid range (or not finite).
    #[error("invalid {name}: {value} ({expected})")]
    InvalidParameter {
        /// What the value is (e.g. "mass of particle 3").
        name: String,
        /// The offending value.
        value: f64,
        /// What is expected instead.
        expected: String,
    },
    /// A vector input has a non-finite component or is otherwise invalid.
    #[error("invalid {name}: {value:?} ({expected})")]
    InvalidVector {
        /// What the vector is (e.g. "position of particle 0").
        name: String,
        /// The offending vector.
        value: Vec<f64>,
        /// What is expected instead.
        expected: String,
    },
    /// An element was given the same particle twice.
    #[error("{what} links particle {particle} to itself: give different particles")]
    SameParticle {
        /// The element kind.
        what: String,
        /// The particle index.
        particle: usize,
    },
    /// A constraint touches only fixed particles, so it has no unknown to act on.
    #[error("{what} touches only fixed particles: it cannot be enforced (free one of them or remove it)")]
    ConstraintOnFixedParticles {
        /// The constraint's name.
        what: String,
    },
    /// A handle does not belong to this system.
    #[error("unknown particle handle {index}: this system has {count} particles (was the handle made by another System?)")]
    UnknownParticle {
        /// The handle's index.
        index: usize,
        /// How many particles the system has.
        count: usize,
    },
    /// A prescribed law is evaluated outside the interval it is defined on.
    #[error("{what} is defined on [{start}, {end}] s but the run needs it on [{t_start}, {t_end}] s: extend the table or shorten the run")]
    LawOutOfDomain {
        /// Where the law is used.
        what: String,
        /// First sample time.
        start: f64,
        /// Last sample time.
        end: f64,
        /// Simulation start.
        t_start: f64,
        /// Simulation end.
        t_end: f64,
    },
    /// A prescribed law gives no finite value, rate or acceleration at a time the run needs it
    /// (a square root of a negative value, a quotient by zero), or its user function failed.
    #[error("the law of {what} cannot be evaluated at t = {t:.6} s: {detail}; the states computed before are kept")]
    LawNotFinite {
        /// Where the law is used.
        what: String,
        /// The time.
        t: f64,
        /// What went wrong.
        detail: String,
        /// The user law's name when its function failed (a `UserFunctionError`).
        user: Option<String>,
    },
    /// The initial positions (Phi) or velocities (Phi_q v + Phi_t) violate a constraint.
    #[error("initial {level} violate {constraint}: |{quantity}| = {violation:.3e} (scaled: {scaled:.3e}) exceeds the tolerance {tolerance:.1e}; call System.project_initial_state() to move the state onto the constraints")]
    InconsistentInitialState {
        /// "positions" or "velocities".
        level: String,
        /// The violated quantity ("Phi" or "Phi_q v + Phi_t").
        quantity: String,
        /// The constraint's name.
        constraint: String,
        /// Raw residual |Phi|.
        violation: f64,
        /// Residual scaled to a length (m) or a speed (m/s).
        scaled: f64,
        /// The tolerance that was exceeded.
        tolerance: f64,
    },
    /// Projecting the initial state onto the constraints did not converge.
    #[error("projection onto the constraints did not converge after {iterations} iterations: residual {residual:.3e} m at {equation}")]
    ProjectionFailed {
        /// Iterations made.
        iterations: usize,
        /// Final scaled residual.
        residual: f64,
        /// The dominant equation.
        equation: String,
    },
    /// Newton's method did not converge, even after reducing the step.
    #[error("Newton iterations did not converge at t = {t:.6} s (step {dt:.3e} s) after {iterations} iterations: residual {residual:.3e} dominated by {equation}")]
    NewtonFailed {
        /// Time at the start of the failing step.
        t: f64,
        /// The smallest step tried.
        dt: f64,
        /// Iterations of the last attempt.
        iterations: usize,
        /// Scaled residual norm of the last attempt.
        residual: f64,
        /// The equation (particle or constraint) that dominates the residual.
        equation: String,
    },
    /// The iteration matrix could not be factorised.
    #[error("singular iteration matrix at t = {t:.6} s near {equation}: {detail}")]
    SingularMatrix {
        /// Time at the start of the failing step.
        t: f64,
        /// The equation (particle or constraint) where elimination found no pivot, if known.
        equation: String,
        /// What the linear solver reported, and what the structure of the matrix says of the
        /// cause (redundant constraints, or the mass and force block).
        detail: String,
    },
    /// Some constraint equations are combinations of others: the constraint gradients are
    /// linearly dependent, so the multipliers are not unique and the KKT matrix is singular.
    #[error("redundant constraints: {constraint} is a linear combination of {}; remove it (or one of those) so that every constraint adds a condition of its own", depends_on.join(", "))]
    RedundantConstraints {
        /// The constraint found to be dependent on earlier ones.
        constraint: String,
        /// Index of that constraint.
        index: usize,
        /// The constraints it is a combination of.
        depends_on: Vec<String>,
        /// Their indices.
        depends_on_indices: Vec<usize>,
    },
    /// A tension-only constraint (a string) would have to push to keep its length.
    #[error("{constraint} would have to push at t = {t:.6} s (tension {tension:.4e} N < 0): a string cannot; the model is not valid from this time on (a buoy denser than the fluid, or an excitation violent enough to slacken the string)")]
    NegativeTension {
        /// Time of the first step where the tension is negative.
        t: f64,
        /// The constraint's name.
        constraint: String,
        /// Index of the constraint.
        index: usize,
        /// The tension it would need (N, negative).
        tension: f64,
    },
    /// Error-controlled steps: meeting rtol/atol would take a step below the smallest allowed.
    #[error("at t = {t:.6} s the step needed to meet rtol/atol would be {h:.3e} s (error norm {error:.3e} at the last step tried), below h_min = {h_min:.3e} s: loosen rtol/atol, lower h_min, or look for a discontinuity in the model's laws")]
    StepSizeTooSmall {
        /// Time at the start of the step that could not be completed.
        t: f64,
        /// The step the controller proposed.
        h: f64,
        /// The smallest step allowed.
        h_min: f64,
        /// Weighted error norm of the last attempt (1 meets the tolerances).
        error: f64,
    },
    /// A step is too small for the floating-point times to resolve: t + h would not advance t
    /// by h (to 1 %), so times would repeat or the steps taken differ from the ones integrated.
    #[error("at t = {t:e} s the step {h:.3e} s is below the resolution of the time (floating-point spacing {spacing:.3e} s; a step must be >= {smallest:.3e} s there): use a larger dt (or, with error-controlled steps, looser rtol/atol), or count time from nearer 0 (a smaller t_start)")]
    StepBelowTimeResolution {
        /// Time at the start of the step.
        t: f64,
        /// The step that could not be taken.
        h: f64,
        /// The spacing of floating-point numbers at t.
        spacing: f64,
        /// The smallest step resolved there.
        smallest: f64,
    },
    /// Index-3 generalised-alpha went unstable: the mechanical energy of a model that takes in
    /// none grew beyond everything the model holds (`integrators/energy_guard.rs`).
    #[error("index-3 generalised-alpha is unstable at this step: at t = {t:.6} s the mechanical energy is {energy:.4e} J, above {bound:.4e} J (initial {initial:.4e} J plus all the energy the model can exchange; it takes in none), with rho_inf = {rho_inf} and dt = {dt:.3e} s; use formulation='ggl' (stable at every step measured), or rho_inf <= 0.5 (stable from 10 steps a period on a pendulum), or a smaller step (rho_inf = 0.9 needs 100 steps a period of the fastest motion; docs/theory/time-rules.md has the measured table)")]
    EnergyGrowth {
        /// Time at the end of the step where the energy passed the bound.
        t: f64,
        /// The step size.
        dt: f64,
        /// The scheme's spectral radius at infinite frequency.
        rho_inf: f64,
        /// The mechanical energy reached (J).
        energy: f64,
        /// The initial mechanical energy (J).
        initial: f64,
        /// The bound it passed (J).
        bound: f64,
    },
    /// A user function of a force or constraint group failed (raised an error).
    #[error("user function {call}() of group '{group}' failed at t = {t:.6} s: {message}")]
    UserFunction {
        /// The group's name.
        group: String,
        /// The function ("force", "jacobian", "phi", "gradient", "hessian", "phi_t", "gamma").
        call: String,
        /// Time of the failing call.
        t: f64,
        /// What the function reported.
        message: String,
    },
    /// A user function of a force or constraint group returned an unusable output.
    #[error("user function {call}() of group '{group}' {problem} at t = {t:.6} s; return a finite float array of the documented shape (see System.add_force_group / add_constraint_group)")]
    UserFunctionOutput {
        /// The group's name.
        group: String,
        /// The function.
        call: String,
        /// Time of the call.
        t: f64,
        /// What is wrong with the output (the shape returned and the one expected, or the
        /// first element with a non-finite value).
        problem: String,
    },
    /// A snapshot that cannot be used: an unreadable, corrupt or foreign snapshot file, or a
    /// snapshot of another model.
    #[error("{what}: {problem}")]
    Snapshot {
        /// The snapshot (its file's path, or "snapshot").
        what: String,
        /// What is wrong and what to do instead.
        problem: String,
    },
    /// The stored output of a run would exceed (or has reached) the memory allowed
    /// ([`crate::SimulationOptions::max_output_bytes`]; `output_size.rs`).
    #[error("{}", output_message(*.t, *.states, *.state_bytes, *.steps, *.bytes, *.limit, .limit_source, *.save_every))]
    OutputTooLarge {
        /// Where the run stopped (None: refused before it started).
        t: Option<f64>,
        /// Stored states (estimated before the run).
        states: f64,
        /// Bytes of one stored state.
        state_bytes: usize,
        /// Accepted steps (their sizes are stored too).
        steps: f64,
        /// The output's size, in bytes.
        bytes: f64,
        /// The largest size allowed, in bytes.
        limit: f64,
        /// Where the limit comes from.
        limit_source: String,
        /// The run's `save_every`.
        save_every: usize,
    },
    /// The run was stopped by its observer (for instance a keyboard interrupt).
    #[error("run interrupted at t = {t:.6} s")]
    Interrupted {
        /// Time reached.
        t: f64,
    },
}

impl Error {
    /// Short name of the error family, used to map errors onto exception classes.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::InvalidParameter { .. }
            | Error::InvalidVector { .. }
            | Error::SameParticle { .. }
            | Error::ConstraintOnFixedParticles { .. }
            | Error::LawOutOfDomain { .. }
            | Error::LawNotFinite { user: None, .. }
            | Error::Snapshot { .. } => "InvalidInputError",
            Error::LawNotFinite { user: Some(_), .. } => "UserFunctionError",
            Error::UnknownParticle { .. } => "UnknownHandleError",
            Error::InconsistentInitialState { .. } => "InconsistentInitialStateError",
            Error::RedundantConstraints { .. } => "RedundantConstraintsError",
            Error::NegativeTension { .. } => "NegativeTensionError",
            Error::EnergyGrowth { .. } => "InstabilityError",
            Error::StepSizeTooSmall { .. } | Error::StepBelowTimeResolution { .. } => {
                "StepSizeTooSmallError"
            }
            Error::UserFunction { .. } => "UserFunctionError",
            Error::UserFunctionOutput { .. } => "UserFunctionOutputError",
            Error::ProjectionFailed { .. }
            | Error::NewtonFailed { .. }
            | Error::SingularMatrix { .. } => "ConvergenceError",
            Error::Interrupted { .. } => "Interrupted",
            Error::OutputTooLarge { .. } => "OutputTooLargeError",
        }
    }
}

/// The message of [`Error::OutputTooLarge`].
#[allow(clippy::too_many_arguments)]
fn output_message(
    t: Option<f64>,
    states: f64,
    state_bytes: usize,
    steps: f64,
    bytes: f64,
    limit: f64,
    source: &str,
    save_every: usize,
) -> String {
    let what = match t {
        None => "the run would store".to_string(),
        Some(t) => format!("the run stopped at t = {t:.6} s: it has stored"),
    };
    // Every step's size is stored, whatever save_every: when they alone exceed the limit, only
    // a shorter run or longer steps help.
    let remedy = if 8.0 * steps > limit {
        "the step sizes alone exceed it (one is stored per step, whatever save_every or t_eval): \
         shorten the run, take longer steps, or set max_output_bytes"
            .to_string()
    } else {
        format!(
            "raise save_every (now {save_every}), give fewer t_eval times, shorten the run, or \
             set max_output_bytes"
        )
    };
    let gb = |x: f64| {
        let x = x / 1e9;
        if x < 1e4 {
            format!("{x:.3} GB")
        } else {
            format!("{x:.3e} GB")
        }
    };
    format!(
        "{what} about {states:.3e} states of {state_bytes} bytes and {steps:.3e} step sizes of 8 \
         bytes, {}, more than the {} allowed ({source}): {remedy}",
        gb(bytes),
        gb(limit)
    )
}

/// Checks that `value` is finite and strictly positive.
pub fn positive(name: impl Into<String>, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.into(),
            value,
            expected: "must be finite and > 0".into(),
        })
    }
}

/// Checks that `value` is finite and not negative.
pub fn non_negative(name: impl Into<String>, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.into(),
            value,
            expected: "must be finite and >= 0".into(),
        })
    }
}

/// Checks that `value` is finite.
pub fn finite(name: impl Into<String>, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: name.into(),
            value,
            expected: "must be finite".into(),
        })
    }
}

/// Checks that every component of `value` is finite.
pub fn finite_vector(name: impl Into<String>, value: [f64; 3]) -> Result<[f64; 3]> {
    if value.iter().all(|x| x.is_finite()) {
        Ok(value)
    } else {
        Err(Error::InvalidVector {
            name: name.into(),
            value: value.to_vec(),
            expected: "every component must be finite".into(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Number of variants of [`Error`] (the arms of [`ordinal`]).
    const VARIANTS: usize = 21;

    /// The position of a variant. An exhaustive match: a new variant does not compile until it
    /// has an arm here, and then [`one_of_each`] must give an example of it.
    fn ordinal(e: &Error) -> usize {
        match e {
            Error::InvalidParameter { .. } => 0,
            Error::InvalidVector { .. } => 1,
            Error::SameParticle { .. } => 2,
            Error::ConstraintOnFixedParticles { .. } => 3,
            Error::UnknownParticle { .. } => 4,
            Error::LawOutOfDomain { .. } => 5,
            Error::InconsistentInitialState { .. } => 6,
            Error::ProjectionFailed { .. } => 7,
            Error::NewtonFailed { .. } => 8,
            Error::SingularMatrix { .. } => 9,
            Error::RedundantConstraints { .. } => 10,
            Error::NegativeTension { .. } => 11,
            Error::StepSizeTooSmall { .. } => 12,
            Error::UserFunction { .. } => 13,
            Error::UserFunctionOutput { .. } => 14,
            Error::Snapshot { .. } => 15,
            Error::Interrupted { .. } => 16,
            Error::OutputTooLarge { .. } => 17,
            Error::StepBelowTimeResolution { .. } => 18,
            Error::EnergyGrowth { .. } => 19,
            Error::LawNotFinite { .. } => 20,
        }
    }

    /// One error of every variant.
    fn one_of_each() -> Vec<Error> {
        let s = |x: &str| x.to_string();
        vec![
            positive("mass", -1.0).unwrap_err(),
            finite_vector("position", [f64::NAN, 0.0, 0.0]).unwrap_err(),
            Error::SameParticle {
                what: s("distance"),
                particle: 3,
            },
            Error::ConstraintOnFixedParticles {
                what: s("distance 0"),
            },
            Error::UnknownParticle { index: 7, count: 2 },
            Error::LawOutOfDomain {
                what: s("table"),
                start: 0.0,
                end: 1.0,
                t_start: 0.0,
                t_end: 2.0,
            },
            Error::InconsistentInitialState {
                level: s("positions"),
                quantity: s("Phi"),
                constraint: s("distance 0"),
                violation: 0.1,
                scaled: 0.1,
                tolerance: 1e-8,
            },
            Error::ProjectionFailed {
                iterations: 50,
                residual: 1e-3,
                equation: s("distance 0"),
            },
            Error::NewtonFailed {
                t: 0.5,
                dt: 1e-3,
                iterations: 25,
                residual: 1.0,
                equation: s("particle 1"),
            },
            Error::SingularMatrix {
                t: 0.0,
                equation: s("distance 1"),
                detail: s("zero pivot"),
            },
            Error::RedundantConstraints {
                constraint: s("distance 2"),
                index: 2,
                depends_on: vec![s("distance 0"), s("distance 1")],
                depends_on_indices: vec![0, 1],
            },
            Error::NegativeTension {
                t: 0.3,
                constraint: s("string"),
                index: 0,
                tension: -1.0,
            },
            Error::StepSizeTooSmall {
                t: 0.2,
                h: 1e-12,
                h_min: 1e-10,
                error: 3.0,
            },
            Error::UserFunction {
                group: s("g"),
                call: s("force"),
                t: 0.1,
                message: s("boom"),
            },
            Error::UserFunctionOutput {
                group: s("g"),
                call: s("phi"),
                t: 0.1,
                problem: s("returned (2,)"),
            },
            Error::Snapshot {
                what: s("run.snapshot"),
                problem: s("truncated"),
            },
            Error::Interrupted { t: 0.4 },
            Error::OutputTooLarge {
                t: None,
                states: 1e12,
                state_bytes: 112,
                steps: 1e12,
                bytes: 1.2e14,
                limit: 1e9,
                limit_source: s("max_output_bytes"),
                save_every: 1,
            },
            Error::StepBelowTimeResolution {
                t: 1e6,
                h: 1e-12,
                spacing: 1.16e-10,
                smallest: 5.8e-9,
            },
            Error::EnergyGrowth {
                t: 5.0,
                dt: 0.05,
                rho_inf: 0.9,
                energy: 1e3,
                initial: 0.0,
                bound: 9.81,
            },
            Error::LawNotFinite {
                what: s("fixed coordinate #0"),
                t: 1.5,
                detail: s("sqrt(-1) is NaN"),
                user: None,
            },
        ]
    }

    #[test]
    fn every_variant_names_a_specific_exception_class_of_the_python_package() {
        let examples = one_of_each();
        let mut seen: Vec<usize> = examples.iter().map(ordinal).collect();
        seen.sort_unstable();
        assert_eq!(
            seen,
            (0..VARIANTS).collect::<Vec<_>>(),
            "one example of every variant"
        );
        // The Python package's exception classes (the glue raises the class `kind` names): each
        // variant must name one of them, and a specific one, not the root `VinculoError` nor
        // `InternalError` (a bug, which no variant reports).
        let classes = include_str!("../../../python/vinculo/errors.py");
        for e in &examples {
            let kind = e.kind();
            assert!(
                classes.contains(&format!("\nclass {kind}(")),
                "{kind} (of {e:?}) is not a class of python/vinculo/errors.py"
            );
            assert!(
                !["VinculoError", "InternalError"].contains(&kind),
                "{e:?} maps to the generic {kind}"
            );
        }
    }
}
