//! Time integration: the generalised trapezoidal rule (paper eq. 24), the generalised-alpha
//! scheme of Arnold and Brüls, and the Newton loop they share; each on the index-3 DAE or on the
//! stabilised index-2 (GGL) formulation ([`Formulation`]).

pub mod error_estimate;
mod generalized_alpha;
pub mod newton;
mod stabilized;
mod stabilized_layout;
mod trapezoidal;

pub use error_estimate::{AccelerationHistory, ErrorConstants};
pub use generalized_alpha::{AlphaCoefficients, AlphaState, GeneralizedAlpha};

pub use newton::{
    IterationMatrix, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport,
};
pub use stabilized::{phi_qt, Formulation, StabilizedWorkspace};
pub use stabilized_layout::StabilizedLayout;
pub use trapezoidal::{GeneralizedTrapezoidal, StepProblem, StepWorkspace};

/// The time discretisation of a run, chosen by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    /// The generalised trapezoidal rule with alpha in [1/2, 1] (1/2: trapezoidal, second order,
    /// no numerical damping; 1: backward Euler, first order, strongly damped).
    GeneralizedTrapezoidal {
        /// Weight of the new state in the evaluation point.
        alpha: f64,
    },
    /// Generalised-alpha for index-3 systems (Arnold and Brüls 2007), second order, with
    /// numerical damping of the high frequencies set by rho_inf in [0, 1] (1: none).
    GeneralizedAlpha {
        /// Spectral radius at infinite frequency.
        rho_inf: f64,
    },
}

impl Default for Scheme {
    fn default() -> Self {
        Scheme::GeneralizedTrapezoidal { alpha: 0.5 }
    }
}

impl Scheme {
    /// Name of the scheme: "trapezoidal" (any alpha < 1), "backward-euler" (alpha = 1) or
    /// "generalized-alpha".
    pub fn name(&self) -> &'static str {
        match *self {
            Scheme::GeneralizedTrapezoidal { alpha: 1.0 } => "backward-euler",
            Scheme::GeneralizedTrapezoidal { .. } => "trapezoidal",
            Scheme::GeneralizedAlpha { .. } => "generalized-alpha",
        }
    }

    /// Order of accuracy of the positions.
    pub fn order(&self) -> usize {
        match *self {
            Scheme::GeneralizedTrapezoidal { alpha } => GeneralizedTrapezoidal { alpha }.order(),
            Scheme::GeneralizedAlpha { rho_inf } => GeneralizedAlpha { rho_inf }.order(),
        }
    }

    /// What identifies the iteration matrix of a step of size `h` (for its reuse).
    pub fn matrix_key(&self, h: f64) -> [f64; 2] {
        match *self {
            Scheme::GeneralizedTrapezoidal { alpha } => {
                GeneralizedTrapezoidal { alpha }.matrix_key(h)
            }
            Scheme::GeneralizedAlpha { rho_inf } => GeneralizedAlpha { rho_inf }.matrix_key(h),
        }
    }
}
