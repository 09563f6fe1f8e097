//! The error control of error-controlled runs ([`crate::step_control::StepControl::Adaptive`]):
//! the step controller that the run loop (`run.rs`) consults when its steps are error-controlled
//! (`docs/theory/adaptive.md`).
//!
//! Each converged step's local error is estimated by step doubling (two half steps from the same
//! start, [`crate::integrators::error_estimate`]; the two halves' answer is kept) and weighed
//! ([`crate::step_control`]): Newton's tolerance follows rtol and atol
//! ([`crate::step_control::AdaptiveOptions::newton_tolerance`]); a step with err <= 1 is accepted, one above is rejected and
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
//! `tests/test_adaptive.py` and `tests/test_adaptive_accuracy.py`, where the error falls with the
//! tolerance like a second-order scheme's).

use crate::assembly::NONE;
use crate::error::{Error, Result};
use crate::initial::factor_saddle;
use crate::integrators::{
    richardson_factor, NewtonOptions, Rule, RuleState, Scheme, StabilizedWorkspace, StepStart,
    StepWorkspace,
};
use crate::math::Vec3;
use crate::model::System;
use crate::step_control::{AdaptiveOptions, ErrorWeights, PiController};

/// The error control's state (carried from step to step, copied by a snapshot and saved in a
/// snapshot file) and its scratch arrays (written before they are read: not saved; sized for the
/// system by [`ErrorControl::fit`]).
#[derive(Debug, Clone)]
pub(crate) struct ErrorControl {
    pub(crate) scheme: Scheme,
    /// The scheme's rule, its coefficients computed once ([`Scheme::rule`]).
    pub(crate) rule: Rule,
    pub(crate) control: AdaptiveOptions,
    pub(crate) weights: ErrorWeights,
    /// The PI controller's memory (last error norm, last attempt rejected).
    pub(crate) pi: PiController,
    /// The next step size.
    pub(crate) h: f64,
    /// The rule's state along the two half steps (a copy of the state before the step).
    pub(crate) rule_half: Option<RuleState>,
    /// Error norm of the step being judged.
    pub(crate) err: f64,
    pub(crate) free: Vec<bool>,
    pub(crate) projection: Vec<f64>,
    pub(crate) e_q: Vec<Vec3>,
    pub(crate) e_v: Vec<Vec3>,
    pub(crate) q_big: Vec<Vec3>,
    pub(crate) v_big: Vec<Vec3>,
    pub(crate) lambda_big: Vec<f64>,
    /// The state between the two half steps (t + h/2) of the step last judged: the accepted
    /// step's dense output interpolates through it.
    pub(crate) q_mid: Vec<Vec3>,
    pub(crate) v_mid: Vec<Vec3>,
    pub(crate) lambda_mid: Vec<f64>,
}

impl ErrorControl {
    /// The control of a run of `scheme` (`acc`: the start's accelerations, for the sizes), first
    /// step `dt`, on an index-3 system of `unknowns` unknowns.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        system: &System,
        scheme: Scheme,
        control: AdaptiveOptions,
        weights: ErrorWeights,
        dt: f64,
        acc: &[Vec3],
        unknowns: usize,
    ) -> ErrorControl {
        ErrorControl {
            scheme,
            rule: scheme.rule(),
            control,
            weights,
            pi: PiController::new(scheme.order(), control.hold),
            h: dt,
            rule_half: None,
            err: 0.0,
            free: system.particles().iter().map(|p| !p.fixed).collect(),
            projection: vec![0.0; unknowns],
            e_q: acc.to_vec(),
            e_v: acc.to_vec(),
            q_big: acc.to_vec(),
            v_big: acc.to_vec(),
            lambda_big: Vec::new(),
            q_mid: acc.to_vec(),
            v_mid: acc.to_vec(),
            lambda_mid: Vec::new(),
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
            &mut self.e_q,
            &mut self.e_v,
            &mut self.q_big,
            &mut self.v_big,
            &mut self.q_mid,
            &mut self.v_mid,
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

    /// Judges a converged step of size `h` from (t, q, v) (the end state in `ws.state`) by
    /// step doubling ([`crate::integrators::error_estimate`]): two steps of h/2 from the same
    /// start with the rule's state before the step `rule`, whose difference from the step gives
    /// its local error. `Ok(true)` when the weighted error is at most 1: `ws.state` then holds
    /// the two half steps' end state (the more accurate answer, which the run keeps: its rule
    /// state and end accelerations come from [`ErrorControl::adopt`], its state at t + h/2 from
    /// [`ErrorControl::midpoint`]). `Ok(false)` when the step must be retried (a half step whose
    /// Newton iterations fail counts as an infinite error). `acc`: the start's accelerations,
    /// for the half steps' predictor; `newton`: the run's Newton options; `stabilized`: the GGL
    /// workspace of a GGL run (whose matrix is not the index-3 one the projection needs).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn judge(
        &mut self,
        system: &System,
        ws: &mut StepWorkspace,
        mut stabilized: Option<&mut StabilizedWorkspace>,
        newton: &NewtonOptions,
        rule: &RuleState,
        (t, h): (f64, f64),
        (q, v, acc): (&[Vec3], &[Vec3], &[Vec3]),
    ) -> Result<bool> {
        self.q_big.copy_from_slice(&ws.state.q);
        self.v_big.copy_from_slice(&ws.state.v);
        self.lambda_big.clear();
        self.lambda_big.extend_from_slice(&ws.state.lambda);
        match &mut self.rule_half {
            Some(r) if r.acceleration.len() == rule.acceleration.len() => r.copy_from(rule),
            other => *other = Some(rule.clone()),
        }
        let rule_half = self.rule_half.as_mut().expect("set above");
        let half = 0.5 * h;
        let mut converged = true;
        for k in 0..2 {
            let t_k = t + k as f64 * half;
            if k == 1 {
                self.q_mid.copy_from_slice(&ws.state.q);
                self.v_mid.copy_from_slice(&ws.state.v);
                self.lambda_mid.clear();
                self.lambda_mid.extend_from_slice(&ws.state.lambda);
            }
            let (q_k, v_k): (&[Vec3], &[Vec3]) = if k == 0 {
                (q, v)
            } else {
                (&self.q_mid, &self.v_mid)
            };
            crate::run::extrapolate((q_k, v_k, acc), half, &mut ws.state.q);
            let start = StepStart::new(t_k, q_k, v_k, half);
            let stab = stabilized.as_deref_mut();
            if self
                .rule
                .step(system, ws, stab, start, rule_half, newton)
                .is_err()
            {
                converged = false;
                break;
            }
        }
        if !converged {
            self.err = f64::INFINITY;
            return Ok(false);
        }
        // Richardson: the step's error C h^(p+1) exceeds that of the two halves by
        // (1 - 2^-p) C h^(p+1).
        let factor = richardson_factor(self.rule.order());
        for i in 0..q.len() {
            for c in 0..3 {
                self.e_q[i][c] = factor * (self.q_big[i][c] - ws.state.q[i][c]);
                self.e_v[i][c] = factor * (self.v_big[i][c] - ws.state.v[i][c]);
            }
        }
        if stabilized.is_some() {
            // The GGL steps factorised their own matrix: the projection needs the index-3
            // workspace's [M/m_ref, -s G^T; s G, 0] at the step's end (the one step's positions
            // serve: both answers hold the constraints).
            factor_saddle(system, ws, &self.q_big, t + h)?;
        }
        tangential(ws, &mut self.e_q, &mut self.projection, &self.q_big);
        // The velocities' difference holds twice the start's drift off the velocity constraints
        // (index 3: v_{n+1} = 2 (q_{n+1} - q_n)/h - v_n carries -v_n's normal part, two half
        // steps +v_n's), normal to the constraints at the start: projected there, what is left
        // of it is O(h) times the drift.
        factor_saddle(system, ws, q, t)?;
        ws.matrix.invalidate();
        tangential(ws, &mut self.e_v, &mut self.projection, q);
        let ends = [(q, v), (&ws.state.q[..], &ws.state.v[..])];
        self.err = self
            .weights
            .norm(h, &self.free, (&self.e_q, &self.e_v), ends);
        Ok(!self.err.is_nan() && self.err <= 1.0)
    }

    /// After [`ErrorControl::judge`] accepted a step of size `h` from `t` whose two half steps
    /// ended with velocities `v`: the rule's state after them into `rule`, and the end
    /// accelerations (the next step's predictor) into `acc`.
    pub(crate) fn adopt(&self, t: f64, h: f64, v: &[Vec3], rule: &mut RuleState, acc: &mut [Vec3]) {
        let rule_half = self.rule_half.as_ref().expect("set by judge");
        rule.copy_from(rule_half);
        let start = StepStart::new(t + 0.5 * h, &self.q_mid, &self.v_mid, 0.5 * h);
        self.rule.end_acceleration(rule_half, start, v, acc);
    }

    /// The state (q, v, lambda) at t + h/2 of the step last accepted, between its half steps.
    pub(crate) fn midpoint(&self) -> (&[Vec3], &[Vec3], &[f64]) {
        (&self.q_mid, &self.v_mid, &self.lambda_mid)
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

/// Replaces the vectors `a` (one per particle) by their part tangent to the constraints, with the
/// factorised matrix of the workspace: the step's last Newton matrix
/// `[M/m_ref + K, -s G^T; s G, 0]` (K = O(h^2)) or the saddle matrix `[M/m_ref, -s G^T; s G, 0]`
/// of [`factor_saddle`]. Solving it with the right-hand side `[M a / m_ref; 0]` gives x with
/// G x = 0 and (M/m_ref + K) x = M a / m_ref + s G^T mu, the M-orthogonal projection of a onto
/// the tangent space (up to O(h^2) with K). What is left out is the part of a normal to the
/// constraints (see `integrators::error_estimate` for why the estimate needs it gone). M holds
/// the line nodes' axial added-mass correction at the positions `q` (the matrix's own, or
/// within a step of them: the projection is then M-orthogonal up to O(h)).
fn tangential(ws: &mut StepWorkspace, a: &mut [Vec3], rhs: &mut [f64], q: &[Vec3]) {
    rhs.fill(0.0);
    let mass_ref = ws.mass_ref;
    for (i, &d) in ws.layout.dof.iter().enumerate() {
        if d != NONE {
            for k in 0..3 {
                rhs[d + k] = ws.inertia[i] / mass_ref * a[i][k];
            }
        }
    }
    // M holds the line nodes' axial added-mass correction, at q as in the matrix.
    let axial = &ws.axial_added_mass;
    axial.add_rows(&ws.layout.dof, rhs, (q, 1.0 / mass_ref), |i| a[i]);
    ws.solver.solve_in_place(rhs);
    for (i, &d) in ws.layout.dof.iter().enumerate() {
        for k in 0..3 {
            a[i][k] = if d != NONE { rhs[d + k] } else { 0.0 };
        }
    }
}
