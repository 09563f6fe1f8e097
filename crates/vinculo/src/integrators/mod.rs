//! Time integration: the time rules (the generalised trapezoidal rule of paper eq. 24 with
//! backward Euler as its alpha = 1 case, the generalised-alpha scheme of Arnold and Brüls), each
//! a small object behind one contract ([`TimeRule`], `rule.rs`); the one index-3 step problem
//! ([`StepProblem`]) and the one GGL step problem ([`StabilizedWorkspace`]) written once for
//! every rule; and the Newton loop they share. The equations discretised are chosen by
//! [`Formulation`].
//!
//! A new rule is one file implementing [`TimeRule`] and its registration: a variant of
//! [`Scheme`] (the run's setting) and of [`Rule`] (the rule object a run holds), the arm that
//! builds the one from the other in [`Scheme::rule`], and its arm in `with_rule!` below, the
//! only `match` on the rules.

pub mod energy_guard;
pub mod error_estimate;
#[cfg(test)]
pub(crate) mod fixtures;
mod generalized_alpha;
pub mod newton;
mod rule;
mod stabilized;
mod stabilized_layout;
mod step_problem;
mod trapezoidal;
mod workspace;

pub use error_estimate::richardson_factor;
pub use generalized_alpha::{AlphaCoefficients, AlphaStep, GeneralizedAlpha};

pub use newton::{
    IterationMatrix, JacobianReuse, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem,
    NewtonReport,
};
pub use rule::{
    resolved_rate, GglBase, GglCoefficients, Index3Rule, RuleState, StepPoint, StepStart, TimeRule,
    RESOLVED_CHANGE,
};
pub use stabilized::{phi_qt, Formulation, StabilizedWorkspace};
pub use stabilized_layout::StabilizedLayout;
pub use step_problem::{index3_step, StepProblem};
pub use trapezoidal::{GeneralizedTrapezoidal, TrapezoidalStep};
pub use workspace::{StepBuffers, StepWorkspace, RELEASE_PATTERN_ABOVE};

use crate::math::Vec3;
use crate::model::System;

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

/// Evaluates `$body` with `$rule` bound to the [`TimeRule`] object of the [`Rule`] `$built`
/// (statically dispatched: the body is compiled once per rule).
macro_rules! with_rule {
    ($built:expr, $rule:ident => $body:expr) => {
        match $built {
            $crate::integrators::Rule::GeneralizedTrapezoidal($rule) => $body,
            $crate::integrators::Rule::GeneralizedAlpha($rule) => $body,
        }
    };
}
#[cfg(test)]
pub(crate) use with_rule;

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

    /// True when the forces of a step are evaluated at its end alone (generalised-alpha and
    /// backward Euler), where a force that jumps with the positions (a seabed contact's damping)
    /// has no value a step could end on: the run's contact events land such a step short of
    /// the jump (`run.rs`).
    pub fn evaluates_at_end(&self) -> bool {
        match *self {
            Scheme::GeneralizedTrapezoidal { alpha } => alpha >= 1.0,
            Scheme::GeneralizedAlpha { .. } => true,
        }
    }

    /// The scheme's rule object, its coefficients computed: what a run holds, so that its
    /// steps do not derive them again (the registry of the rules).
    pub fn rule(&self) -> Rule {
        match *self {
            Scheme::GeneralizedTrapezoidal { alpha } => {
                Rule::GeneralizedTrapezoidal(GeneralizedTrapezoidal { alpha })
            }
            Scheme::GeneralizedAlpha { rho_inf } => {
                Rule::GeneralizedAlpha(GeneralizedAlpha::new(rho_inf))
            }
        }
    }

    /// Order of accuracy of the positions.
    pub fn order(&self) -> usize {
        self.rule().order()
    }

    /// The rule's state at the start of a run with the consistent accelerations `acc`.
    pub fn initial_state(&self, acc: &[Vec3]) -> RuleState {
        self.rule().initial_state(acc)
    }
}

/// A [`Scheme`]'s rule object ([`Scheme::rule`]), dispatched statically by `with_rule!`, the
/// only `match` on the rules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// The generalised trapezoidal rule.
    GeneralizedTrapezoidal(GeneralizedTrapezoidal),
    /// Generalised-alpha.
    GeneralizedAlpha(GeneralizedAlpha),
}

impl Rule {
    /// Order of accuracy of the positions.
    pub fn order(&self) -> usize {
        with_rule!(*self, rule => rule.order())
    }

    /// What identifies the iteration matrix of a step of size `h` (for its reuse).
    pub fn matrix_key(&self, h: f64) -> [f64; 2] {
        with_rule!(*self, rule => rule.matrix_key(h))
    }

    /// The rule's state at the start of a run with the consistent accelerations `acc`.
    pub fn initial_state(&self, acc: &[Vec3]) -> RuleState {
        with_rule!(*self, rule => rule.initial_state(acc))
    }

    /// Takes one step from `start` and `state` (the rule's state): on the GGL formulation when
    /// `stabilized` is given, on the index-3 DAE otherwise ([`index3_step`],
    /// [`StabilizedWorkspace::step`] say what the buffers hold before and after).
    pub fn step(
        &self,
        system: &System,
        ws: &mut StepWorkspace,
        stabilized: Option<&mut StabilizedWorkspace>,
        start: StepStart,
        state: &mut RuleState,
        options: &NewtonOptions,
    ) -> Result<NewtonReport, NewtonFailure> {
        with_rule!(*self, rule => match stabilized {
            Some(ggl) => ggl.step(system, ws, rule, start, state, options),
            None => index3_step(rule, system, ws, start, state, options),
        })
    }

    /// Newton's first iterate of a fixed step from `start` into `out`, from the last step's end
    /// acceleration and its rate `acc` ([`rule::TimeRule::predict`]).
    pub fn predict(
        &self,
        state: &RuleState,
        start: StepStart,
        acc: (&[Vec3], &[Vec3]),
        out: &mut [Vec3],
    ) {
        with_rule!(*self, rule => rule.predict(state, start, acc, out))
    }

    /// The acceleration of a converged step from `start` to v_{n+1} = `v` (the rule's `state`
    /// already advanced), into `out`: the run loop's predictor and error sample.
    pub fn end_acceleration(
        &self,
        state: &RuleState,
        start: StepStart,
        v: &[Vec3],
        out: &mut [Vec3],
    ) {
        with_rule!(*self, rule => rule.end_acceleration(state, start, v, out))
    }
}

impl GeneralizedTrapezoidal {
    /// Takes one index-3 step from `start` ([`index3_step`]; the rule carries no state of its
    /// own).
    pub fn step(
        &self,
        system: &System,
        ws: &mut StepWorkspace,
        start: StepStart,
        options: &NewtonOptions,
    ) -> Result<NewtonReport, NewtonFailure> {
        let mut none = RuleState::new(&[]);
        index3_step(*self, system, ws, start, &mut none, options)
    }
}
