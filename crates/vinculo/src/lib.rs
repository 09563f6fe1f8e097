//! # vinculo
//!
//! Constrained particle systems written as index-3 differential-algebraic equations
//! (paper eqs. 16-21):
//!
//! ```text
//! M v' - f(q, v, t) - Phi_q(q, t)^T lambda = 0
//! v - q'                                 = 0
//! Phi(q, t)                              = 0
//! ```
//!
//! Point masses ([`model::System`]) are linked by constraints ([`constraints::Constraint`]) enforced
//! with Lagrange multipliers and loaded by forces ([`forces::Force`]). The generalised trapezoidal
//! rule ([`integrators::GeneralizedTrapezoidal`]) or the generalised-alpha scheme
//! ([`integrators::GeneralizedAlpha`]), chosen by [`integrators::Scheme`], on this system or on its
//! stabilised index-2 form ([`integrators::Formulation`]), turns each step into a
//! nonlinear system that a Newton loop ([`integrators::newton`], full or modified) solves with the
//! analytic Jacobian, assembled into a sparsity pattern computed once ([`assembly`]) and
//! factorised by faer ([`linear`]).
//!
//! Forces and constraints that the built-in kinds do not cover can be supplied as groups whose
//! terms one user function computes for all their elements at once ([`user`],
//! [`forces::ForceGroup`], [`constraints::ConstraintGroup`]); the Python bindings implement
//! them with Python callables.
//!
//! The entry point is [`simulate`], which returns a [`Solution`].
//!
//! ```
//! use vinculo::{model::System, simulate, SimulationOptions};
//! let mut s = System::new([0.0, 0.0, -9.81]);
//! let a = s.add_particle(1.0, [0.0, 0.0, 0.0], [0.0; 3], true).unwrap();
//! let b = s.add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false).unwrap();
//! s.add_distance(a, b, None).unwrap();
//! let sol = simulate(&s, &SimulationOptions { t_end: 0.1, dt: 1e-3, ..Default::default() }).unwrap();
//! assert!(sol.status.is_ok());
//! ```
#![warn(missing_docs)]
// Index loops over 3-vector components and local blocks mirror the derivations in the doc comments.
#![allow(clippy::needless_range_loop)]

mod adaptive;
pub mod assembly;
pub mod constraints;
pub mod dense_output;
pub mod error;
pub mod forces;
pub mod initial;
pub mod integrators;
pub mod laws;
pub mod linear;
pub mod local;
pub mod math;
pub mod model;
mod options;
pub mod output_size;
pub mod run;
pub mod simulate;
pub mod snapshot_file;
pub mod solution;
pub mod statics;
pub mod step_control;
pub mod user;
pub mod water;

pub use error::{Error, Result};
pub use linear::SparseSolver;
pub use run::{Simulation, Snapshot};
pub use simulate::{simulate, simulate_with_observer, Observer, SimulationOptions};
pub use solution::{Solution, StepStats};
pub use step_control::{AdaptiveOptions, StepControl};
