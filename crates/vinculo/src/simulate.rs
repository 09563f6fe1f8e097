//! The entry point: validate, start consistently, march in time with step retries, keep
//! everything computed even when a step fails.

use crate::assembly::Layout;
use crate::constraints::find_redundant;
use crate::error::{Error, Result};
use crate::initial::{
    consistent_accelerations, scaled_velocity_violation, scaled_violation, singular_error,
};
use crate::integrators::{
    Formulation, NewtonFailure, NewtonOptions, RuleState, Scheme, StabilizedWorkspace,
    StepWorkspace,
};
use crate::linear::SparseSolver;
use crate::math::Vec3;
use crate::model::System;
use crate::solution::{Solution, StepStats};
use crate::step_control::{ErrorWeights, StepControl};

/// Options of a run. Tolerances are relative to the model's length scale
/// ([`System::length_scale`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulationOptions {
    /// Start time (s).
    pub t_start: f64,
    /// End time (s).
    pub t_end: f64,
    /// Nominal step (s).
    pub dt: f64,
    /// The time discretisation (default: the trapezoidal rule, alpha = 1/2).
    pub scheme: Scheme,
    /// The equations discretised (default: the index-3 DAE). [`Formulation::Ggl`] adds the
    /// velocity constraints with a second multiplier (see `integrators/stabilized.rs`); its
    /// steps solve with the dense LU (up to `dense_limit` unknowns) or the general sparse LU,
    /// and assemble serially whatever `parallel_from` says.
    pub formulation: Formulation,
    /// Newton options (tolerance relative to the length scale).
    pub newton: NewtonOptions,
    /// How many times a failing step may be halved before the run stops.
    pub max_halvings: usize,
    /// Largest scaled initial constraint violation accepted, relative to the length scale.
    pub initial_tolerance: f64,
    /// Store every k-th step (the last step is always stored).
    pub save_every: usize,
    /// Systems with at most this many unknowns whose constraint graph has loops use a dense
    /// LU (tree-shaped graphs always get the tree elimination with `SparseSolver::Auto`).
    pub dense_limit: usize,
    /// Solver for larger systems: tree elimination when the constraint graph is a forest
    /// (`Auto`), or always the general sparse LU. [`Solution::linear_solver`] names the one used.
    pub sparse_solver: SparseSolver,
    /// Largest memory the stored states may take (bytes); larger runs are refused up front.
    pub max_output_bytes: f64,
    /// Models with at least this many free particles assemble their residuals and Jacobians
    /// in parallel, on rayon's global thread pool (as many threads as cores, or
    /// `RAYON_NUM_THREADS`): the kinematics and the inertia and gravity rows per particle, the
    /// forces, and the constraints' rows, gradient terms, Hessian blocks and Jacobian rows and
    /// columns. Smaller models, and `usize::MAX`, use the serial loops. The linear solvers and
    /// the rest of a step are serial. The residual is the same bit for bit; the Jacobian equals
    /// the serial one to round-off (its entries are summed in another order).
    pub parallel_from: usize,
    /// Fixed steps (the default) or error-controlled ones ([`StepControl::Adaptive`], where
    /// `dt` is the first step).
    pub step_control: StepControl,
    /// Times at which to store the state (strictly increasing, in [t_start, t_end]; error-controlled
    /// steps only), interpolated inside the steps that contain them (Python: `t_eval`). `None`:
    /// store the end of every step (every `save_every`-th).
    pub output_times: Option<Vec<f64>>,
}

impl Default for SimulationOptions {
    fn default() -> Self {
        SimulationOptions {
            t_start: 0.0,
            t_end: 1.0,
            dt: 1e-3,
            scheme: Scheme::default(),
            formulation: Formulation::default(),
            newton: NewtonOptions::default(),
            max_halvings: 4,
            initial_tolerance: 1e-8,
            save_every: 1,
            dense_limit: 48,
            sparse_solver: SparseSolver::Auto,
            max_output_bytes: 8.0 * (1u64 << 30) as f64,
            parallel_from: PARALLEL_FROM,
            step_control: StepControl::Fixed,
            output_times: None,
        }
    }
}

/// Default of [`SimulationOptions::parallel_from`]: the number of free particles from which
/// parallel assembly did not cost time in whole steps on two cores (shared with other work).
/// Measured on chains (`benches/scaling.rs` with `serial` / `parallel`, repeated): at 10^6
/// particles a hanging chain's step took 10-27 % less time, a swinging chain's between 18 %
/// less and 5 % more; at 300,000 the same to 8 % less; at 100,000 and fewer the same or more.
/// The assembly alone (`benches/kernels.rs`, `assembly`) is 20-27 % faster from 100,000 on, but
/// it is a quarter to a half of a step and the rest (the linear solve above all) is serial,
/// while the residual's per-element buffers and the threads' wake-ups cost a share of the gain.
pub const PARALLEL_FROM: usize = 300_000;

/// Receives progress and may stop a run.
pub trait Observer {
    /// Called after each accepted step; return false to stop the run.
    fn step(&mut self, t: f64, t_end: f64) -> bool;
}

struct Silent;
impl Observer for Silent {
    fn step(&mut self, _t: f64, _t_end: f64) -> bool {
        true
    }
}

fn check_options(system: &System, o: &SimulationOptions) -> Result<()> {
    let bad = |name: &str, value: f64, expected: &str| Error::InvalidParameter {
        name: name.into(),
        value,
        expected: expected.into(),
    };
    if !o.t_start.is_finite() {
        return Err(bad("t_start", o.t_start, "must be finite"));
    }
    if !(o.t_end.is_finite() && o.t_end >= 0.0) {
        return Err(bad("t_end", o.t_end, "must be finite and >= 0"));
    }
    if o.t_end < o.t_start {
        return Err(bad(
            "t_end",
            o.t_end,
            &format!("must be >= t_start = {}", o.t_start),
        ));
    }
    if !(o.dt.is_finite() && o.dt > 0.0) {
        return Err(bad("dt", o.dt, "must be finite and > 0"));
    }
    match o.scheme {
        Scheme::GeneralizedTrapezoidal { alpha } if !(0.5..=1.0).contains(&alpha) => {
            return Err(bad(
                "alpha",
                alpha,
                "must be in [0.5, 1] (0.5: trapezoidal, 1: backward Euler)",
            ));
        }
        Scheme::GeneralizedAlpha { rho_inf } if !(0.0..=1.0).contains(&rho_inf) => {
            return Err(bad(
                "rho_inf",
                rho_inf,
                "must be in [0, 1] (1: no numerical damping, 0: the most)",
            ));
        }
        _ => {}
    }
    if !(o.newton.tolerance.is_finite() && o.newton.tolerance > 0.0) {
        return Err(bad(
            "tolerance",
            o.newton.tolerance,
            "must be finite and > 0",
        ));
    }
    if o.newton.max_iterations == 0 {
        return Err(bad("max_iterations", 0.0, "must be >= 1"));
    }
    if !(o.initial_tolerance.is_finite() && o.initial_tolerance > 0.0) {
        return Err(bad(
            "initial_tolerance",
            o.initial_tolerance,
            "must be finite and > 0",
        ));
    }
    if o.save_every == 0 {
        return Err(bad("save_every", 0.0, "must be >= 1"));
    }
    if let StepControl::Adaptive(control) = &o.step_control {
        control.check(o.dt)?;
    }
    if let Some(times) = &o.output_times {
        check_output_times(o, times)?;
    }
    let constraints = system
        .constraints()
        .iter()
        .enumerate()
        .map(|(k, c)| (c.name(k), c.domain()));
    let forces = system
        .forces()
        .iter()
        .enumerate()
        .map(|(k, f)| (f.name(k), f.domain()));
    for (name, (start, end)) in constraints.chain(forces) {
        if start > o.t_start || end < o.t_end {
            return Err(Error::LawOutOfDomain {
                what: format!("the law of {name}"),
                start,
                end,
                t_start: o.t_start,
                t_end: o.t_end,
            });
        }
    }
    Ok(())
}

/// Requested output times: error-controlled steps only, finite, strictly increasing, within the
/// run.
fn check_output_times(o: &SimulationOptions, times: &[f64]) -> Result<()> {
    let bad = |k: usize, expected: String| {
        Err(Error::InvalidParameter {
            name: format!("output time t_eval[{k}]"),
            value: times[k],
            expected,
        })
    };
    if times.is_empty() {
        return Err(Error::InvalidParameter {
            name: "t_eval".into(),
            value: 0.0,
            expected: "no output time given: give at least one, or none (None) for every step"
                .into(),
        });
    }
    if o.step_control == StepControl::Fixed {
        return bad(
            0,
            "output times need error-controlled steps (adaptive); with fixed steps every step \
             (or every save_every-th) is stored"
                .into(),
        );
    }
    for k in 0..times.len() {
        if !(times[k] >= o.t_start && times[k] <= o.t_end) {
            return bad(
                k,
                format!(
                    "must lie in [t_start, t_end] = [{}, {}]",
                    o.t_start, o.t_end
                ),
            );
        }
        if k > 0 && times[k] <= times[k - 1] {
            return bad(
                k,
                format!(
                    "output times must be strictly increasing: t_eval[{}] = {}; sort them and \
                     drop repeats",
                    k - 1,
                    times[k - 1]
                ),
            );
        }
    }
    Ok(())
}

/// The first tension-only constraint whose tension is below `floor` (N), as an error.
pub(crate) fn negative_tension(
    system: &System,
    lambda: &[f64],
    t: f64,
    floor: f64,
) -> Option<Error> {
    system.tension_only().iter().find_map(|&c| {
        let tension = system.tension(c, lambda[c])?;
        (tension < floor).then(|| Error::NegativeTension {
            t,
            constraint: system.constraints()[c].name(c),
            index: c,
            tension,
        })
    })
}

/// The error of a step from `t` of size `h` that failed at the smallest step allowed, naming the
/// equation that dominated the residual or where the matrix was singular.
pub(crate) fn step_failure(
    system: &System,
    layout: &Layout,
    failure: NewtonFailure,
    t: f64,
    h: f64,
) -> Error {
    match failure {
        NewtonFailure::NotConverged {
            iterations,
            residual,
            worst,
        } => Error::NewtonFailed {
            t,
            dt: h,
            iterations,
            residual,
            equation: layout.equation_name(system, worst),
        },
        NewtonFailure::Singular(s) => singular_error(system, layout, t, s),
    }
}

/// Integrates `system` from `options.t_start` to `options.t_end`.
///
/// Errors in the input are returned as `Err`. A run that stops part-way (Newton failure after
/// every allowed step halving, singular matrix) returns `Ok` with everything computed so far
/// and the cause in [`Solution::status`].
pub fn simulate(system: &System, options: &SimulationOptions) -> Result<Solution> {
    simulate_with_observer(system, options, &mut Silent)
}

/// [`simulate`] with an observer that sees each step and may stop the run.
pub fn simulate_with_observer(
    system: &System,
    options: &SimulationOptions,
    observer: &mut dyn Observer,
) -> Result<Solution> {
    check_options(system, options)?;
    // User groups start the run with empty caches and counters.
    system.reset_user_groups();
    let length = system.length_scale();
    let t0 = options.t_start;
    let mut q = system.initial_positions();
    let mut v = system.initial_velocities();
    // Positions are compared with the model's length scale; velocities with a speed scale, the
    // largest initial speed or the speed of a fall through the length scale, sqrt(|g| l).
    let g = system.gravity();
    let speed = v
        .iter()
        .map(|x| crate::math::norm(*x))
        .fold((crate::math::norm(g) * length).sqrt(), f64::max);
    let speed = if speed > 0.0 { speed } else { length };
    let (worst, k) = scaled_violation(system, &q, t0);
    let velocity_worst = scaled_velocity_violation(system, &q, &v, t0);
    if let Some(e) = system.user_failure() {
        return Err(e);
    }
    let checks = [
        ("positions", "Phi", (worst, k), length),
        ("velocities", "Phi_q v + Phi_t", velocity_worst, speed),
    ];
    for (level, quantity, (violation, k), scale) in checks {
        let tolerance = options.initial_tolerance * scale;
        if violation.is_nan() || violation > tolerance {
            let c = &system.constraints()[k];
            return Err(Error::InconsistentInitialState {
                level: level.into(),
                quantity: quantity.into(),
                constraint: c.name(k),
                violation: violation / c.scale(),
                scaled: violation,
                tolerance,
            });
        }
    }

    let mut ws = StepWorkspace::with_solver(system, options.dense_limit, options.sparse_solver);
    ws.assemble_in_parallel_from(system, options.parallel_from);
    let scheme = options.scheme;
    let newton = NewtonOptions {
        tolerance: options.newton.tolerance * length,
        ..options.newton
    };
    // The GGL steps have their own unknowns and solver; the index-3 workspace still serves the
    // consistent start and carries the step's state in and out.
    let mut stabilized = (options.formulation == Formulation::Ggl)
        .then(|| StabilizedWorkspace::new(system, options.dense_limit));
    let solver_name = match &stabilized {
        Some(g) => g.solver.name(),
        None => ws.solver.name(),
    };
    let mut sol = Solution::new(q.len(), system.constraints().len(), solver_name);
    sol.scheme = scheme;
    sol.formulation = options.formulation;
    let start = consistent_accelerations(system, &mut ws, &q, &v, t0).map_err(|e| match e {
        // Name the culprits when the matrix is singular because constraints are redundant.
        Error::SingularMatrix { .. } => find_redundant(system, &q, t0, None).unwrap_or(e),
        e => e,
    });
    // A failed user function is the cause of whatever else went wrong at the start.
    let start = match (start, system.user_failure()) {
        (_, Some(e)) => Err(e),
        (start, None) => start,
    };
    let (mut acc, mut lambda) = match start {
        Ok(x) => x,
        Err(e) => {
            sol.push(
                t0,
                &q,
                &v,
                &vec![f64::NAN; sol.constraints],
                worst,
                velocity_worst.0,
                StepStats::default(),
            );
            sol.status = Err(e);
            return Ok(sol);
        }
    };
    sol.push(
        t0,
        &q,
        &v,
        &lambda,
        worst,
        velocity_worst.0,
        StepStats::default(),
    );
    let weight = system
        .particles()
        .iter()
        .map(|p| p.mass * crate::math::norm(g))
        .sum::<f64>();
    let tension_floor = -1e-9 * if weight > 0.0 { weight } else { 1.0 };
    if let Some(e) = negative_tension(system, &lambda, t0, tension_floor) {
        sol.status = Err(e);
        return Ok(sol);
    }
    if let StepControl::Adaptive(control) = options.step_control {
        let run = crate::adaptive::AdaptiveRun {
            system,
            options,
            control,
            newton,
            weights: ErrorWeights {
                time_scale: length / speed,
                atol_q: control.atol,
                atol_v: control.atol * speed / length,
                rtol: control.rtol,
            },
            tension_floor,
        };
        let start = crate::adaptive::StartState {
            q,
            v,
            acceleration: acc,
            lambda,
        };
        crate::adaptive::march(
            &run,
            &mut ws,
            stabilized.as_mut(),
            &mut sol,
            start,
            observer,
        );
        if let (Ok(()), Some(e)) = (&sol.status, system.user_failure()) {
            sol.status = Err(e);
        }
        return Ok(sol);
    }

    // Times are kept on an exact grid: every step is dt / 2^j, an integer number of the smallest
    // allowed step, so t = t_start + units * unit never accumulates round-off. The last step is
    // stretched or shortened (by at most a millionth of a step, or to what remains) to land on t_end.
    let top = options.max_halvings as u32;
    let unit = options.dt / f64::powi(2.0, top as i32);
    let mut units: u64 = 0;
    let mut level = top;
    let mut t = t0;
    let mut step = 0usize;
    let mut q_new: Vec<Vec3> = q.clone();
    // Generalised-alpha starts with a_0 = qdd_0, the consistent accelerations.
    let mut rule_state = RuleState::new(&acc);
    let mut fresh_retry = false;
    while t < options.t_end {
        let h_nominal = unit * (1u64 << level) as f64;
        let remaining = options.t_end - t;
        let last = remaining <= h_nominal * (1.0 + 1e-6);
        let h_try = if last { remaining } else { h_nominal };
        // Predictor: constant-acceleration extrapolation, last multipliers.
        for i in 0..q.len() {
            for k in 0..3 {
                ws.state.q[i][k] = q[i][k] + h_try * v[i][k] + 0.5 * h_try * h_try * acc[i][k];
            }
        }
        ws.state.lambda.copy_from_slice(&lambda);
        if !fresh_retry {
            sol.steps_taken += 1;
        }
        // Modified Newton starting from a matrix of an earlier step gets one more attempt with a
        // fresh matrix before the step counts as failed.
        let stale = newton.jacobian_reuse && ws.matrix.holds(scheme.matrix_key(h_try));
        let attempt = scheme.step(
            system,
            &mut ws,
            stabilized.as_mut(),
            t,
            &q,
            &v,
            &mut rule_state,
            h_try,
            &newton,
        );
        sol.factorisations = ws.matrix.factorisations;
        fresh_retry = false;
        // A failed user function stops the run at once (NaN terms would only fail again).
        if let Some(e) = system.user_failure() {
            sol.status = Err(e);
            break;
        }
        match attempt {
            Ok(report) => {
                scheme.end_acceleration(&rule_state, h_try, &v, &ws.state.v, &mut acc);
                q_new.copy_from_slice(&ws.state.q);
                std::mem::swap(&mut q, &mut q_new);
                v.copy_from_slice(&ws.state.v);
                lambda.copy_from_slice(&ws.state.lambda);
                units += 1u64 << level;
                t = if last {
                    options.t_end
                } else {
                    t0 + units as f64 * unit
                };
                step += 1;
                sol.accepted_step_sizes.push(h_try);
                let slack = negative_tension(system, &lambda, t, tension_floor);
                if step % options.save_every == 0 || last || slack.is_some() {
                    let stats = StepStats {
                        newton_iterations: report.iterations,
                        step_size: h_try,
                        residual_norm: report.residual,
                        increment_norm: report.increment,
                    };
                    let position = scaled_violation(system, &q, t).0;
                    let velocity = scaled_velocity_violation(system, &q, &v, t).0;
                    sol.push(t, &q, &v, &lambda, position, velocity, stats);
                }
                if let Some(e) = slack {
                    sol.status = Err(e);
                    break;
                }
                // Grow back towards the nominal step after a reduction.
                level = (level + 1).min(top);
                if !observer.step(t, options.t_end) {
                    sol.status = Err(Error::Interrupted { t });
                    break;
                }
            }
            Err(_) if stale => {
                ws.matrix.invalidate();
                fresh_retry = true;
            }
            Err(failure) => {
                sol.steps_rejected += 1;
                if level > 0 {
                    level -= 1;
                    continue;
                }
                sol.status = Err(step_failure(system, &ws.layout, failure, t, h_try));
                break;
            }
        }
    }
    if let (Ok(()), Some(e)) = (&sol.status, system.user_failure()) {
        sol.status = Err(e);
    }
    Ok(sol)
}
