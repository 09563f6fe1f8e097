//! The run loop with error-controlled steps ([`crate::step_control::StepControl::Adaptive`]).
//!
//! Each attempt takes one step of the scheme from the last accepted state, estimates its local
//! error ([`crate::integrators::error_estimate`]) and weighs it ([`crate::step_control`]): a step
//! with err <= 1 is accepted, one above is rejected and retried with the controller's smaller
//! step, one whose Newton iterations fail is retried with a quarter of its size (after one retry
//! with a fresh matrix in modified Newton, as in the fixed-step loop). A step the controller
//! would make smaller than h_min ends the run with [`Error::StepSizeTooSmall`] (or
//! [`Error::NewtonFailed`] when Newton failed at h_min), keeping everything computed before.
//!
//! Output: at the requested times ([`SimulationOptions::output_times`]), interpolated inside the
//! accepted step that contains them ([`crate::dense_output`]), so the steps never bend to land on
//! them; without requested times, the end of every accepted step (every `save_every`-th). An
//! interpolated row carries the statistics of the step that contains it and the constraint
//! violations of the interpolated state itself.
//!
//! Generalised-alpha keeps its algorithmic accelerations a_n unchanged when the step size changes
//! (the usual choice): a_n approximates the true accelerations at t_n + (alpha_m - alpha_f) h_old,
//! so a new step size h shifts that point by (alpha_m - alpha_f)(h - h_old), an O(h^2 |h - h_old|)
//! position error, of the order of the local error itself as long as the step changes gradually
//! (which the controller's growth limit ensures). The second order survives (checked by
//! `tests/test_adaptive.py`, where the error falls with the tolerance like a second-order scheme's).

use crate::assembly::NONE;
use crate::dense_output::StepEnds;
use crate::error::Error;
use crate::initial::{factor_saddle, scaled_velocity_violation, scaled_violation};
use crate::integrators::{
    AccelerationHistory, ErrorConstants, NewtonOptions, RuleState, StabilizedWorkspace,
    StepWorkspace,
};
use crate::math::Vec3;
use crate::model::System;
use crate::simulate::{negative_tension, step_failure, Observer, SimulationOptions};
use crate::solution::{Solution, StepStats};
use crate::step_control::{AdaptiveOptions, ErrorWeights, PiController};

/// What the loop needs besides the state: the model, the options and the run's scales.
pub(crate) struct AdaptiveRun<'a> {
    pub system: &'a System,
    pub options: &'a SimulationOptions,
    pub control: AdaptiveOptions,
    /// Newton options with the tolerance already in metres.
    pub newton: NewtonOptions,
    pub weights: ErrorWeights,
    pub tension_floor: f64,
}

/// The state at the start of the loop (the consistent initial state).
pub(crate) struct StartState {
    pub q: Vec<Vec3>,
    pub v: Vec<Vec3>,
    pub acceleration: Vec<Vec3>,
    pub lambda: Vec<f64>,
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

/// Stores a state with its violations and the statistics of the step that produced it.
fn store(
    sol: &mut Solution,
    system: &System,
    t: f64,
    (q, v, lambda): (&[Vec3], &[Vec3], &[f64]),
    stats: StepStats,
) {
    let position = scaled_violation(system, q, t).0;
    let velocity = scaled_velocity_violation(system, q, v, t).0;
    sol.push(t, q, v, lambda, position, velocity, stats);
}

/// Marches from `options.t_start` to `options.t_end` with error-controlled steps, appending to
/// `sol` (which holds the initial state as its first row).
pub(crate) fn march(
    run: &AdaptiveRun,
    ws: &mut StepWorkspace,
    mut stabilized: Option<&mut StabilizedWorkspace>,
    sol: &mut Solution,
    start: StartState,
    observer: &mut dyn Observer,
) {
    let (system, options, control) = (run.system, run.options, run.control);
    let scheme = options.scheme;
    let newton = &run.newton;
    let StartState {
        mut q,
        mut v,
        acceleration: mut acc,
        mut lambda,
    } = start;
    let t0 = options.t_start;
    let n = q.len();
    let free: Vec<bool> = system.particles().iter().map(|p| !p.fixed).collect();
    let constants: ErrorConstants = scheme.error_constants();
    // Built at the first attempt, once a factorisation can project the initial accelerations.
    let mut history = AccelerationHistory::new(t0, &acc);
    let mut projection = vec![0.0; ws.layout.unknowns()];
    let mut initial = acc.clone();
    let mut controller = PiController::new(scheme.order(), control.hold);

    // Requested output times: the initial row stays only when t_start is one of them.
    let outputs: &[f64] = options.output_times.as_deref().unwrap_or(&[]);
    let dense = options.output_times.is_some();
    let mut next_output = 0;
    if dense {
        if outputs.first() == Some(&t0) {
            next_output = 1;
        } else {
            sol.truncate(0);
        }
    }

    let mut rule_state = RuleState::new(&acc);
    let mut rule_saved = rule_state.clone();
    let (mut q_new, mut v_new, mut lambda_new) = (q.clone(), v.clone(), lambda.clone());
    let (mut a_sample, mut e_q, mut e_v) = (acc.clone(), acc.clone(), acc.clone());
    let mut full = acc.clone();
    let mut q_end = q.clone();
    let (mut q_out, mut v_out, mut lambda_out) = (q.clone(), v.clone(), lambda.clone());

    let mut t = t0;
    let mut h = options.dt;
    let mut step = 0usize;
    let mut fresh_retry = false;
    while t < options.t_end {
        let remaining = options.t_end - t;
        // Stretch a step by up to 10 % rather than leave a sliver of the run for a last step.
        let last = remaining <= 1.1 * h;
        let h_try = if last { remaining } else { h };
        for i in 0..n {
            for k in 0..3 {
                ws.state.q[i][k] = q[i][k] + h_try * v[i][k] + 0.5 * h_try * h_try * acc[i][k];
            }
        }
        ws.state.lambda.copy_from_slice(&lambda);
        if !fresh_retry {
            sol.steps_taken += 1;
        }
        let stale = newton.jacobian_reuse && ws.matrix.holds(scheme.matrix_key(h_try));
        rule_saved.copy_from(&rule_state);
        let attempt = scheme.step(
            system,
            ws,
            stabilized.as_deref_mut(),
            t,
            &q,
            &v,
            &mut rule_state,
            h_try,
            newton,
        );
        sol.factorisations = ws.matrix.factorisations;
        fresh_retry = false;
        // A failed user function stops the run at once (NaN terms would only fail again).
        if let Some(e) = system.user_failure() {
            sol.status = Err(e);
            return;
        }
        let report = match attempt {
            Ok(report) => report,
            Err(_) if stale => {
                ws.matrix.invalidate();
                fresh_retry = true;
                continue;
            }
            Err(failure) => {
                sol.steps_rejected += 1;
                let proposal = controller.newton_failed(h_try);
                if h_try > control.h_min {
                    h = proposal.max(control.h_min);
                    continue;
                }
                sol.status = Err(step_failure(system, &ws.layout, failure, t, h_try));
                return;
            }
        };

        // The step's acceleration sample (kept whole for the next predictor) and its error.
        scheme.end_acceleration(&rule_state, h_try, &v, &ws.state.v, &mut a_sample);
        full.copy_from_slice(&a_sample);
        if stabilized.is_some() {
            // The GGL step factorised its own matrix: the projection needs the index-3
            // workspace's [M/m_ref, -s G^T; s G, 0] at the step's end.
            q_end.copy_from_slice(&ws.state.q);
            if let Err(e) = factor_saddle(system, ws, &q_end, t + h_try) {
                sol.status = Err(e);
                return;
            }
        }
        tangential(ws, &mut a_sample, &mut projection);
        if step == 0 {
            initial.copy_from_slice(&acc);
            tangential(ws, &mut initial, &mut projection);
            history = AccelerationHistory::new(t0, &initial);
        }
        let tau = t + scheme.sample_offset(h_try);
        history.estimate(&constants, t, h_try, tau, &a_sample, &mut e_q, &mut e_v);
        let err = run
            .weights
            .norm(h_try, &free, &e_q, &e_v, &q, &ws.state.q, &v, &ws.state.v);
        if err.is_nan() || err > 1.0 {
            sol.steps_rejected += 1;
            rule_state.copy_from(&rule_saved);
            let proposal = controller.rejected(h_try, err);
            if proposal >= control.h_min || h_try > control.h_min {
                h = proposal.max(control.h_min);
                continue;
            }
            sol.status = Err(Error::StepSizeTooSmall {
                t,
                h: proposal,
                h_min: control.h_min,
                error: err,
            });
            return;
        }

        // Accepted.
        history.push(tau, &a_sample, h_try);
        acc.copy_from_slice(&full);
        q_new.copy_from_slice(&ws.state.q);
        v_new.copy_from_slice(&ws.state.v);
        lambda_new.copy_from_slice(&ws.state.lambda);
        let t_new = if last { options.t_end } else { t + h_try };
        step += 1;
        sol.accepted_step_sizes.push(h_try);
        let stats = StepStats {
            newton_iterations: report.iterations,
            step_size: h_try,
            residual_norm: report.residual,
            increment_norm: report.increment,
        };
        let slack = negative_tension(system, &lambda_new, t_new, run.tension_floor);
        if dense {
            let ends = StepEnds {
                t,
                h: t_new - t,
                q_0: &q,
                v_0: &v,
                lambda_0: &lambda,
                q_1: &q_new,
                v_1: &v_new,
                lambda_1: &lambda_new,
            };
            while next_output < outputs.len() && outputs[next_output] <= t_new {
                let t_out = outputs[next_output];
                ends.interpolate(t_out, &mut q_out, &mut v_out, &mut lambda_out);
                store(sol, system, t_out, (&q_out, &v_out, &lambda_out), stats);
                next_output += 1;
            }
            // A run that stops here shows the state where it stopped.
            if slack.is_some() && sol.times.last() != Some(&t_new) {
                store(sol, system, t_new, (&q_new, &v_new, &lambda_new), stats);
            }
        } else if step % options.save_every == 0 || last || slack.is_some() {
            store(sol, system, t_new, (&q_new, &v_new, &lambda_new), stats);
        }
        std::mem::swap(&mut q, &mut q_new);
        std::mem::swap(&mut v, &mut v_new);
        std::mem::swap(&mut lambda, &mut lambda_new);
        t = t_new;
        if let Some(e) = slack {
            sol.status = Err(e);
            return;
        }
        h = controller
            .accepted(h_try, err)
            .clamp(control.h_min, control.h_max);
        if !observer.step(t, options.t_end) {
            sol.status = Err(Error::Interrupted { t });
            return;
        }
    }
}
