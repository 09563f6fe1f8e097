//! Share of residual and Jacobian assembly in a step, serial and parallel: hanging and swinging
//! chains of 10^4 to 10^6 point masses (0.1 m links, 0.1 kg, dt = 1e-3, the trapezoidal rule),
//! with full and modified Newton.
//!
//! Run with `cargo bench -p vinculo --bench assembly_share` (every case, each in its own
//! process) or `cargo bench -p vinculo --bench assembly_share -- N SHAPE NEWTON ASSEMBLY` for one
//! (SHAPE: hanging | swinging, NEWTON: full | modified, ASSEMBLY: serial | parallel).
//!
//! Per case: seconds per step of a whole run (between its first and last accepted steps),
//! residual evaluations and factorisations per step, the time of one residual and of one
//! Jacobian refill (the Jacobian's zeroing included), measured on their own with a linear solver
//! that does nothing (median of repeats), and the shares of the step they make up: the
//! residuals evaluated and one Jacobian per factorisation.

use std::process::Command;
use std::time::Instant;

use vinculo::integrators::{
    GeneralizedTrapezoidal, JacobianReuse, NewtonOptions, StepStart, StepWorkspace,
};
use vinculo::linear::{LinearSolver, Singular};
use vinculo::model::System;
use vinculo::{simulate_with_observer, SimulationOptions};

mod common;
use common::{chain, Clock};

const DT: f64 = 1e-3;

/// A linear solver that solves nothing (zero increment): a Newton iteration costs its assembly.
struct Nothing;
impl LinearSolver for Nothing {
    fn factor(&mut self, _values: &[f64]) -> Result<(), Singular> {
        Ok(())
    }
    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        rhs.fill(0.0);
    }
    fn name(&self) -> &'static str {
        "nothing"
    }
}

fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    x[x.len() / 2]
}

/// Median time of one residual and of one Jacobian refill (zeroing included).
fn assembly_times(system: &System, parallel_from: usize) -> (f64, f64) {
    let scheme = GeneralizedTrapezoidal { alpha: 0.5 };
    let mut ws = StepWorkspace::new(system, SimulationOptions::default().dense_limit);
    ws.assemble_in_parallel_from(system, parallel_from);
    // The tree elimination assembles into its own storage, whose slots the layout then
    // addresses: the solver that does nothing gets an array of that size instead.
    let slots = ws
        .solver
        .storage()
        .map_or(ws.values.len(), |store| store.len());
    ws.solver = Box::new(Nothing);
    ws.values = vec![0.0; slots];
    let q_n = system.initial_positions();
    let v_n = system.initial_velocities();
    let mut run = |iterations: usize| {
        ws.state.q.copy_from_slice(&q_n);
        ws.state.lambda.fill(1.0);
        // Full Newton: every timed iteration assembles its Jacobian (a kept matrix would be
        // reused from one repeat to the next).
        let options = NewtonOptions {
            max_iterations: iterations,
            jacobian_reuse: JacobianReuse::Never,
            ..NewtonOptions::default()
        };
        let start = Instant::now();
        let _ = scheme.step(
            system,
            &mut ws,
            StepStart::new(0.0, &q_n, &v_n, DT),
            &options,
        );
        start.elapsed().as_secs_f64()
    };
    let repeats = (2_000_000 / q_n.len()).clamp(7, 101);
    let residual = median((0..repeats).map(|_| run(0)).collect());
    let iteration = median((0..repeats).map(|_| run(1)).collect());
    (residual, (iteration - 2.0 * residual).max(0.0))
}

/// One case, in this process: prints "N s/step residuals/step fact/step t_res t_jac".
fn one(n: usize, hanging: bool, modified: bool, parallel: bool) {
    let system = chain(n, 0.1, hanging);
    let parallel_from = if parallel { 0 } else { usize::MAX };
    let steps = (2_000_000 / n).clamp(6, 200);
    let options = SimulationOptions {
        t_end: steps as f64 * DT,
        dt: DT,
        newton: NewtonOptions {
            jacobian_reuse: if modified {
                JacobianReuse::Always
            } else {
                JacobianReuse::Never
            },
            ..NewtonOptions::default()
        },
        parallel_from,
        ..Default::default()
    };
    let mut clock = Clock(Vec::with_capacity(steps + 1));
    let sol = simulate_with_observer(&system, &options, &mut clock).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    let intervals = (clock.0.len() - 1) as f64;
    let per_step = (clock.0[clock.0.len() - 1] - clock.0[0]).as_secs_f64() / intervals;
    let taken = sol.stats.len() - 1;
    // Over the whole run, first step included (the counts are the run's).
    let residuals = sol.residual_evaluations as f64 / (taken + 1) as f64;
    let factorisations = sol.factorisations as f64 / (taken + 1) as f64;
    drop(sol);
    let (t_res, t_jac) = assembly_times(&system, parallel_from);
    println!("{n} {per_step:.6e} {residuals:.2} {factorisations:.2} {t_res:.6e} {t_jac:.6e}");
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    if let Some(n) = args.first().and_then(|a| a.parse::<usize>().ok()) {
        let arg = |k: usize, yes: &str| args.get(k).map(String::as_str) == Some(yes);
        one(
            n,
            !arg(1, "swinging"),
            arg(2, "modified"),
            arg(3, "parallel"),
        );
        return;
    }
    let exe = std::env::current_exe().unwrap();
    println!(
        "{:>9} {:>9} {:>8} {:>8} {:>11} {:>6} {:>6} {:>11} {:>11} {:>6} {:>6}",
        "N",
        "shape",
        "Newton",
        "assembly",
        "s/step",
        "res.",
        "fact.",
        "residual s",
        "Jacobian s",
        "res.%",
        "Jac.%"
    );
    for n in [10_000, 100_000, 1_000_000] {
        for shape in ["hanging", "swinging"] {
            for newton in ["full", "modified"] {
                for assembly in ["serial", "parallel"] {
                    let out = Command::new(&exe)
                        .args([&n.to_string(), shape, newton, assembly])
                        .output()
                        .unwrap();
                    let text = String::from_utf8_lossy(&out.stdout);
                    let f: Vec<f64> = text
                        .split_whitespace()
                        .filter_map(|x| x.parse().ok())
                        .collect();
                    if !out.status.success() || f.len() < 6 {
                        println!("{n:>9} failed: {}", String::from_utf8_lossy(&out.stderr));
                        continue;
                    }
                    let (step, residuals, fact, res, jac) = (f[1], f[2], f[3], f[4], f[5]);
                    println!(
                        "{n:>9} {shape:>9} {newton:>8} {assembly:>8} {step:>11.4e} {residuals:>6.2} \
                         {fact:>6.2} {res:>11.4e} {jac:>11.4e} {:>6.1} {:>6.1}",
                        100.0 * residuals * res / step,
                        100.0 * fact * jac / step
                    );
                }
            }
        }
    }
}
