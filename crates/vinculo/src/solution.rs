//! What a run returns: stored states, multipliers, constraint health and per-step statistics.

use crate::error::Error;
use crate::integrators::{Formulation, Scheme};

/// Statistics of one stored step (for a state interpolated at a requested output time: of the
/// step that contains that time).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepStats {
    /// Newton iterations of the step (0 for the initial state).
    pub newton_iterations: usize,
    /// Step size used (0 for the initial state).
    pub step_size: f64,
    /// The last scaled residual norm Newton evaluated (m): at the step's answer, or at the iterate
    /// before its last increment when Newton stopped on that increment (`integrators/newton.rs`).
    pub residual_norm: f64,
    /// Last scaled Newton increment norm (m).
    pub increment_norm: f64,
}

/// The result of [`simulate`](crate::simulate). Arrays are flat, row-major:
/// `positions[(s * n + i) * 3 + k]` is coordinate k of particle i at stored time s.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Number of particles.
    pub particles: usize,
    /// Number of constraint equations.
    pub constraints: usize,
    /// Stored times.
    pub times: Vec<f64>,
    /// Positions, steps x particles x 3.
    pub positions: Vec<f64>,
    /// Velocities, steps x particles x 3.
    pub velocities: Vec<f64>,
    /// Multipliers, steps x constraints (row 0: from the consistent initial accelerations).
    pub multipliers: Vec<f64>,
    /// max_k |s_k Phi_k| at each stored time (a length, m): the position-level violation.
    pub constraint_residual: Vec<f64>,
    /// max_k |s_k (Phi_q v + Phi_t)| at each stored time (a speed, m/s): the velocity-level
    /// violation. The index-3 formulation enforces only the positions, so this is not zero but
    /// shrinks with the step (see [`crate::initial::scaled_velocity_violation`]); the GGL
    /// formulation enforces it at every step, to the Newton tolerance.
    pub velocity_violation: Vec<f64>,
    /// Per stored step.
    pub stats: Vec<StepStats>,
    /// Steps taken (stored or not), including retries with smaller steps.
    pub steps_taken: usize,
    /// Steps rejected because Newton failed (then retried with a smaller step) or, with
    /// error-controlled steps, because their error estimate exceeded the tolerance.
    pub steps_rejected: usize,
    /// Size of every accepted step, in order (whether its state was stored or not).
    pub accepted_step_sizes: Vec<f64>,
    /// Factorisations of Newton iteration matrices (one per iteration in full Newton; fewer with
    /// [`NewtonOptions::jacobian_reuse`](crate::integrators::NewtonOptions::jacobian_reuse)).
    pub factorisations: usize,
    /// Evaluations of the step equations' residual by Newton's iterations (at most one more
    /// than the iterations of a step: the loop may stop on an increment without the residual
    /// at the iterate it gives, `integrators/newton.rs`).
    pub residual_evaluations: usize,
    /// The time discretisation used ([`Scheme::name`] names it).
    pub scheme: Scheme,
    /// The equations discretised ([`Formulation::name`] names them).
    pub formulation: Formulation,
    /// Name of the linear solver used for the steps.
    pub linear_solver: &'static str,
    /// `Ok` when the run reached its end; otherwise the error that stopped it (the arrays hold
    /// everything computed before).
    pub status: Result<(), Error>,
}

impl Solution {
    /// An empty solution for `particles` particles and `constraints` equations.
    pub fn new(particles: usize, constraints: usize, linear_solver: &'static str) -> Solution {
        Solution {
            particles,
            constraints,
            times: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
            multipliers: Vec::new(),
            constraint_residual: Vec::new(),
            velocity_violation: Vec::new(),
            stats: Vec::new(),
            steps_taken: 0,
            steps_rejected: 0,
            accepted_step_sizes: Vec::new(),
            factorisations: 0,
            residual_evaluations: 0,
            scheme: Scheme::default(),
            formulation: Formulation::default(),
            linear_solver,
            status: Ok(()),
        }
    }

    /// Number of stored states.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when nothing was stored.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Position of particle `i` at stored state `s`.
    pub fn position(&self, s: usize, i: usize) -> [f64; 3] {
        let b = (s * self.particles + i) * 3;
        [
            self.positions[b],
            self.positions[b + 1],
            self.positions[b + 2],
        ]
    }

    /// Velocity of particle `i` at stored state `s`.
    pub fn velocity(&self, s: usize, i: usize) -> [f64; 3] {
        let b = (s * self.particles + i) * 3;
        [
            self.velocities[b],
            self.velocities[b + 1],
            self.velocities[b + 2],
        ]
    }

    /// Keeps the first `len` stored states only.
    pub(crate) fn truncate(&mut self, len: usize) {
        let (n, m) = (self.particles, self.constraints);
        self.times.truncate(len);
        self.positions.truncate(len * n * 3);
        self.velocities.truncate(len * n * 3);
        self.multipliers.truncate(len * m);
        self.constraint_residual.truncate(len);
        self.velocity_violation.truncate(len);
        self.stats.truncate(len);
    }

    /// Stores a state with its position- and velocity-level violations and statistics.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn push(
        &mut self,
        t: f64,
        q: &[[f64; 3]],
        v: &[[f64; 3]],
        lambda: &[f64],
        residual: f64,
        velocity_violation: f64,
        stats: StepStats,
    ) {
        self.times.push(t);
        self.positions.extend_from_slice(q.as_flattened());
        self.velocities.extend_from_slice(v.as_flattened());
        self.multipliers.extend_from_slice(lambda);
        self.constraint_residual.push(residual);
        self.velocity_violation.push(velocity_violation);
        self.stats.push(stats);
    }
}
