//! The error control of error-controlled runs ([`crate::step_control::StepControl::Adaptive`]):
//! the step controller that the run loop (`run.rs`) consults when its steps are error-controlled
//! (`docs/theory/adaptive.md`).
//!
//! Each converged step's local error is estimated ([`crate::integrators::error_estimate`]) and
//! weighed ([`crate::step_control`]): a step with err <= 1 is accepted, one above is rejected and
//! retried with the PI controller's smaller step, one whose Newton iterations fail is retried with
//! a quarter of its size (after one retry with a fresh matrix in modified Newton, as with fixed
//! steps). A step the controller would make smaller than h_min ends the run with
//! [`Error::StepSizeTooSmall`] (or [`Error::NewtonFailed`] when Newton failed at h_min), keeping
//! everything computed before.
//!
//! Output: at the requested times ([`crate::SimulationOptions::output_times`]), interpolated
//! inside the accepted step that contains them ([`crate::dense_output`]), so the steps never bend
//! to land on them; without requested times, the end of every accepted step (every
//! `save_every`-th). An interpolated row carries the statistics of the step that contains it and
//! the constraint violations of the interpolated state itself.
//!
//! Generalised-alpha keeps its algorithmic accelerations a_n unchanged when the step size changes
//! (the usual choice): a_n approximates the true accelerations at t_n + (alpha_m - alpha_f) h_old,
//! so a new step size h shifts that point by (alpha_m - alpha_f)(h - h_old), an O(h^2 |h - h_old|)
//! position error, of the order of the local error itself as long as the step changes gradually
//! (which the controller's growth limit ensures). The second order survives (checked by
//! `tests/test_adaptive.py`, where the error falls with the tolerance like a second-order scheme's).

use crate::assembly::NONE;
use crate::error::{Error, Result};
use crate::initial::factor_saddle;
use crate::integrators::{AccelerationHistory, ErrorConstants, Scheme, StepWorkspace};
use crate::math::Vec3;
use crate::model::System;
use crate::step_control::{AdaptiveOptions, ErrorWeights, PiController};

/// The error control's state (carried from step to step, copied by a snapshot and saved in a
/// snapshot file) and its scratch arrays (written before they are read: not saved; sized for the
/// system by [`ErrorControl::fit`]).
#[derive(Debug, Clone)]
pub(crate) struct ErrorControl {
    pub(crate) scheme: Scheme,
    pub(crate) control: AdaptiveOptions,
    pub(crate) weights: ErrorWeights,
    /// The PI controller's memory (last error norm, last attempt rejected).
    pub(crate) pi: PiController,
    /// The next step size.
    pub(crate) h: f64,
    pub(crate) constants: ErrorConstants,
    /// Built at the first attempt, once a factorisation can project the initial accelerations.
    pub(crate) history: AccelerationHistory,
    /// Error norm of the step being judged.
    pub(crate) err: f64,
    pub(crate) free: Vec<bool>,
    pub(crate) projection: Vec<f64>,
    pub(crate) initial: Vec<Vec3>,
    pub(crate) a_sample: Vec<Vec3>,
    pub(crate) e_q: Vec<Vec3>,
    pub(crate) e_v: Vec<Vec3>,
    pub(crate) q_end: Vec<Vec3>,
}

impl ErrorControl {
    /// The control of a run of `scheme` from `t0` with the consistent accelerations `acc`, first
    /// step `dt`, on an index-3 system of `unknowns` unknowns.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        system: &System,
        scheme: Scheme,
        control: AdaptiveOptions,
        weights: ErrorWeights,
        dt: f64,
        t0: f64,
        acc: &[Vec3],
        unknowns: usize,
    ) -> ErrorControl {
        ErrorControl {
            scheme,
            control,
            weights,
            pi: PiController::new(scheme.order(), control.hold),
            h: dt,
            constants: scheme.error_constants(),
            history: AccelerationHistory::new(t0, acc),
            err: 0.0,
            free: system.particles().iter().map(|p| !p.fixed).collect(),
            projection: vec![0.0; unknowns],
            initial: acc.to_vec(),
            a_sample: acc.to_vec(),
            e_q: acc.to_vec(),
            e_v: acc.to_vec(),
            q_end: vec![[0.0; 3]; acc.len()],
        }
    }

    /// Sizes the scratch arrays for `system` with `unknowns` index-3 unknowns (a control loaded
    /// from a snapshot file carries none); nothing changes when they already fit.
    pub(crate) fn fit(&mut self, system: &System, unknowns: usize) {
        let n = system.particles().len();
        if self.free.len() != n {
            self.free = system.particles().iter().map(|p| !p.fixed).collect();
        }
        self.projection.resize(unknowns, 0.0);
        for a in [
            &mut self.initial,
            &mut self.a_sample,
            &mut self.e_q,
            &mut self.e_v,
            &mut self.q_end,
        ] {
            a.resize(n, [0.0; 3]);
        }
    }

    /// The next step from `t` towards `stop`: stretched by up to 10 % rather than leave a
    /// sliver for a last step; `Some(stop)` when it lands there.
    pub(crate) fn propose(&self, t: f64, stop: f64) -> (f64, Option<f64>) {
        let remaining = stop - t;
        if remaining <= 1.1 * self.h {
            (remaining, Some(stop))
        } else {
            (self.h, None)
        }
    }

    /// After Newton failed on a step of size `h`: true (with a smaller next step) unless `h` was
    /// already the smallest allowed.
    pub(crate) fn newton_failed(&mut self, h: f64) -> bool {
        let proposal = self.pi.newton_failed(h);
        if h > self.control.h_min {
            self.h = proposal.max(self.control.h_min);
            true
        } else {
            false
        }
    }

    /// Judges a converged step of size `h` from (t, q, v) with end acceleration `acc_new` (the
    /// end state in `ws.state`): `Ok(true)` when its weighted error is at most 1 (the history then
    /// takes its sample), `Ok(false)` when it must be retried. `step` counts the accepted steps
    /// before it; `stabilized` says the step was a GGL step (whose matrix is not the index-3 one
    /// the projection needs).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn judge(
        &mut self,
        system: &System,
        ws: &mut StepWorkspace,
        stabilized: bool,
        step: usize,
        (t, h): (f64, f64),
        (q, v, acc): (&[Vec3], &[Vec3], &[Vec3]),
        acc_new: &[Vec3],
    ) -> Result<bool> {
        self.a_sample.copy_from_slice(acc_new);
        if stabilized {
            // The GGL step factorised its own matrix: the projection needs the index-3
            // workspace's [M/m_ref, -s G^T; s G, 0] at the step's end.
            self.q_end.copy_from_slice(&ws.state.q);
            factor_saddle(system, ws, &self.q_end, t + h)?;
        }
        tangential(ws, &mut self.a_sample, &mut self.projection);
        if step == 0 {
            self.initial.copy_from_slice(acc);
            tangential(ws, &mut self.initial, &mut self.projection);
            self.history = AccelerationHistory::new(t, &self.initial);
        }
        let tau = t + self.scheme.sample_offset(h);
        let (e_q, e_v) = (&mut self.e_q, &mut self.e_v);
        self.history
            .estimate(&self.constants, t, h, tau, &self.a_sample, e_q, e_v);
        let (q_new, v_new) = (&ws.state.q, &ws.state.v);
        self.err = self
            .weights
            .norm(h, &self.free, &self.e_q, &self.e_v, q, q_new, v, v_new);
        if self.err.is_nan() || self.err > 1.0 {
            return Ok(false);
        }
        self.history.push(tau, &self.a_sample, h);
        Ok(true)
    }

    /// After a step of size `h` from `t` failed the error test: `Ok` with a smaller next step,
    /// or the error when it would fall below h_min.
    pub(crate) fn rejected(&mut self, t: f64, h: f64) -> Result<()> {
        let (h_min, err) = (self.control.h_min, self.err);
        let proposal = self.pi.rejected(h, err);
        if proposal >= h_min || h > h_min {
            self.h = proposal.max(h_min);
            return Ok(());
        }
        Err(Error::StepSizeTooSmall {
            t,
            h: proposal,
            h_min,
            error: err,
        })
    }

    /// After the step of size `h` was accepted: the next step.
    pub(crate) fn accepted(&mut self, h: f64) {
        self.h = self
            .pi
            .accepted(h, self.err)
            .clamp(self.control.h_min, self.control.h_max);
    }
}

/// Replaces the accelerations `a` by their part tangent to the constraints, with the
/// factorisation of the step's last Newton matrix `[M/m_ref + K, -s G^T; s G, 0]` (K = O(h^2)):
/// solving it with the right-hand side `[M a / m_ref; 0]` gives x with G x = 0 and
/// (M/m_ref + K) x = M a / m_ref + s G^T mu, the M-orthogonal projection of a onto the tangent
/// space up to O(h^2). What is left out is the acceleration the multipliers impose normal to the
/// constraints (see `integrators::error_estimate` for why the estimate needs it gone).
fn tangential(ws: &mut StepWorkspace, a: &mut [Vec3], rhs: &mut [f64]) {
    rhs.fill(0.0);
    let mass_ref = ws.mass_ref;
    for (i, &d) in ws.layout.dof.iter().enumerate() {
        if d != NONE {
            for k in 0..3 {
                rhs[d + k] = ws.inertia[i] / mass_ref * a[i][k];
            }
        }
    }
    ws.solver.solve_in_place(rhs);
    for (i, &d) in ws.layout.dof.iter().enumerate() {
        for k in 0..3 {
            a[i][k] = if d != NONE { rhs[d + k] } else { 0.0 };
        }
    }
}
