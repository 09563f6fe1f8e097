//! The options of a run ([`SimulationOptions`]), their checks, and the observer of a run's
//! progress.

use crate::error::{Error, Result};
use crate::integrators::{Formulation, NewtonOptions, Scheme};
use crate::linear::SparseSolver;
use crate::model::System;
use crate::step_control::StepControl;

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
    /// How many times a failing step may be halved before the run stops (at most 30 are
    /// made, larger values mean 30; a halved step below the resolution of the time stops the
    /// run with [`Error::StepBelowTimeResolution`]).
    pub max_halvings: usize,
    /// Largest scaled initial constraint violation accepted, relative to the length scale.
    pub initial_tolerance: f64,
    /// Store every k-th step (the last step is always stored).
    pub save_every: usize,
    /// Systems with at most this many unknowns whose constraint graph has loops use a dense
    /// LU (tree-shaped graphs always get the tree elimination with `SparseSolver::Auto`).
    pub dense_limit: usize,
    /// Solver for larger systems: tree elimination when the pattern allows it (`Auto`: a tree
    /// of constraints whose other couplings join particles to their ancestors, see
    /// [`crate::linear::TreeElimination`]), or always the general sparse LU. [`crate::Solution::linear_solver`] names the one used.
    pub sparse_solver: SparseSolver,
    /// Largest memory the stored output may take, in bytes (None: a third of the memory
    /// available when the run starts, no limit where it cannot be read): a run whose output
    /// would exceed it is refused before it starts, and a run whose output reaches it (error
    /// controlled steps, whose number is known only as they go) stops with the states stored
    /// (`output_size.rs`).
    pub max_output_bytes: Option<f64>,
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
    /// Times at which to store the state (strictly increasing, in [t_start, t_end]), interpolated
    /// inside the steps that contain them, fixed or error-controlled (Python: `t_eval`): a time on
    /// a step's end is that step's state. `None`: store the end of every step (every
    /// `save_every`-th).
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
            max_output_bytes: None,
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
/// it was a quarter to a half of a step and the rest (the linear solve above all) serial,
/// while the residual's per-element buffers and the threads' wake-ups cost a share of the gain.
/// On a machine whose memory serves one thread less well (an Intel Xeon at 2.6 GHz under KVM,
/// where a swinging chain of 10^6 takes 0.38 s a step against 0.20 s on the machine of the
/// figures above), 100,000 with [`crate::linear::TWO_SIDED_FROM`] at 100,000 too
/// (`python -m vinculo.bench.scaling swinging --sizes 100000,200000 --repeat 2`, builds
/// alternated): a step of the swinging chain of 10^5 particles 64 -> 48.5 ms, of 2 x 10^5
/// 101 -> 76.5 ms, of the hanging chain 9.7-11.5 -> 7.7-8.7 ms and 24-27 -> 20.5-21 ms; at
/// 60,000 the parallel step was 7 to 16 % faster still, at 30,000 the hanging chain's 12 %
/// slower.
/// Where the assembly is parallel, so are the Newton loop's passes over the unknowns; a chain
/// of [`crate::linear::TWO_SIDED_FROM`] particles or more is also solved from both ends on two
/// threads, whatever this option says (`RAYON_NUM_THREADS=1` keeps a run on one thread).
pub const PARALLEL_FROM: usize = 100_000;

/// Receives progress and may stop a run.
pub trait Observer {
    /// Called after each accepted step; return false to stop the run.
    fn step(&mut self, t: f64, t_end: f64) -> bool;
}

/// Checks the options of a run of `system` (values, ranges, and that every law covers the run).
pub(crate) fn check_options(system: &System, o: &SimulationOptions) -> Result<()> {
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
    if o.formulation == crate::integrators::Formulation::Ggl {
        let segment =
            |c: &crate::constraints::Constraint| c.is_compliant() || c.damped_segment().is_some();
        if let Some(k) = system.constraints().iter().position(segment) {
            return Err(Error::InvalidParameter {
                name: format!(
                    "formulation 'ggl' with the compliant or damped {}",
                    system.constraints()[k].name(k)
                ),
                value: f64::NAN,
                expected: "elastic segments (finite EA, or axial damping) run on the index-3 \
                           formulation: use formulation 'index-3'"
                    .into(),
            });
        }
    }
    // An element's name is made only when its laws do not cover the run.
    let out_of_domain = |(start, end): (f64, f64), name: &dyn Fn() -> String| {
        (start > o.t_start || end < o.t_end).then(|| Error::LawOutOfDomain {
            what: format!("the law of {}", name()),
            start,
            end,
            t_start: o.t_start,
            t_end: o.t_end,
        })
    };
    for (k, c) in system.constraints().iter().enumerate() {
        if let Some(e) = out_of_domain(c.domain(), &|| c.name(k)) {
            return Err(e);
        }
    }
    for (k, f) in system.forces().iter().enumerate() {
        if let Some(e) = out_of_domain(f.domain(), &|| f.name(k)) {
            return Err(e);
        }
    }
    Ok(())
}

/// Requested output times: finite, strictly increasing, within the run (fixed or
/// error-controlled steps alike).
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
