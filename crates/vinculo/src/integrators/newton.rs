//! Newton's method on a scaled nonlinear system R(x) = 0 (paper eqs. 26-30).
//!
//! The loop does no I/O and chooses no step size. It stops when both the scaled residual and the
//! last increment are below the tolerance (both are lengths after scaling, see
//! [`StepProblem`](super::StepProblem)); it reports the equation that dominates the residual when
//! it fails.

use crate::linear::{LinearSolver, Singular};

/// Options of the Newton loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Tolerance on the infinity norms of the scaled residual and increment (absolute, in the
    /// problem's scaled units).
    pub tolerance: f64,
    /// Maximum number of iterations (matrix factorisations).
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-10,
            max_iterations: 25,
        }
    }
}

/// A nonlinear system in scaled form, holding its own iterate.
pub trait NewtonProblem {
    /// Writes the scaled residual at the current iterate.
    fn residual(&mut self, r: &mut [f64]);
    /// Writes the scaled Jacobian at the current iterate into the pattern's value array.
    fn jacobian(&mut self, values: &mut [f64]);
    /// Applies x <- x - dx (dx in scaled unknowns).
    fn update(&mut self, dx: &[f64]);
}

/// Outcome of a converged solve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NewtonReport {
    /// Number of iterations (factorisations).
    pub iterations: usize,
    /// Final scaled residual norm.
    pub residual: f64,
    /// Last scaled increment norm.
    pub increment: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// No convergence within the iteration limit, or a non-finite residual.
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// Last scaled residual norm.
        residual: f64,
        /// Index of the equation with the largest residual.
        worst: usize,
    },
    /// The iteration matrix could not be factorised.
    Singular(Singular),
}

fn inf_norm(x: &[f64]) -> (f64, usize) {
    let mut m = 0.0;
    let mut k = 0;
    for (i, v) in x.iter().enumerate() {
        let a = v.abs();
        if a > m || a.is_nan() {
            m = a;
            k = i;
            if a.is_nan() {
                break;
            }
        }
    }
    (m, k)
}

/// Solves `problem` by Newton's method with the given linear solver and work arrays.
pub fn solve(
    problem: &mut impl NewtonProblem,
    solver: &mut dyn LinearSolver,
    values: &mut [f64],
    r: &mut [f64],
    options: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    let mut increment = f64::INFINITY;
    let mut residual = f64::INFINITY;
    let mut worst = 0;
    for iteration in 0..=options.max_iterations {
        problem.residual(r);
        (residual, worst) = inf_norm(r);
        if !residual.is_finite() {
            return Err(NewtonFailure::NotConverged {
                iterations: iteration,
                residual,
                worst,
            });
        }
        if iteration > 0 && residual <= options.tolerance && increment <= options.tolerance {
            return Ok(NewtonReport {
                iterations: iteration,
                residual,
                increment,
            });
        }
        if iteration == options.max_iterations {
            break;
        }
        values.fill(0.0);
        problem.jacobian(values);
        solver.factor(values).map_err(NewtonFailure::Singular)?;
        solver.solve_in_place(r);
        increment = inf_norm(r).0;
        if !increment.is_finite() {
            return Err(NewtonFailure::Singular(Singular {
                column: None,
                detail: "the Newton increment is not finite (numerically singular matrix)".into(),
            }));
        }
        problem.update(r);
    }
    Err(NewtonFailure::NotConverged {
        iterations: options.max_iterations,
        residual,
        worst,
    })
}
