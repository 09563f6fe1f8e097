//! Time integration: the generalised trapezoidal rule (paper eq. 24) and the Newton loop it
//! shares with any later scheme.

pub mod newton;
mod trapezoidal;

pub use newton::{
    IterationMatrix, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport,
};
pub use trapezoidal::{GeneralizedTrapezoidal, StepProblem, StepWorkspace};
