//! Criterion benchmarks of the kernels of one step, through the crate's public API.
//!
//! Run with `cargo bench -p vinculo --bench kernels` (a filter selects groups, e.g.
//! `cargo bench -p vinculo --bench kernels -- factor`). Groups:
//!
//! - `assembly`: the scaled residual of one step's Newton problem (`residual`), and one Newton
//!   iteration without the linear solve (`residual+jacobian`: two residuals and one Jacobian
//!   refill), for chains of 1,000 and 100,000 point masses. The step's problem is reached through
//!   [`GeneralizedTrapezoidal::step`] with a linear solver that does nothing (returns a zero
//!   increment), so only the assembly is timed; the Jacobian alone is roughly the difference of
//!   the two rows minus one residual. The `parallel` rows are the same on rayon's thread pool
//!   (`StepWorkspace::assemble_in_parallel_from` with threshold 0).
//! - `factor+solve`: factorisation of the step's iteration matrix and one solve, with the values
//!   of a real first Newton iteration: tree elimination (chains of 1,000 and 100,000, and a chain
//!   of 1,000 with bending stiffness, `bent chain`), dense LU (a ring of 10 particles hung from a
//!   fixed point: a loop, 41 unknowns) and the general sparse LU (the same chains forced to
//!   `SparseSolver::SparseLu`).
//! - `step`: one whole step (Newton loop to convergence with the automatically chosen solver) of
//!   a pendulum released horizontally and of a 1,000-link chain released horizontally, taken from
//!   the state after one step so that the predictor carries the previous multipliers.
//!
//! The models are those of `benches/steps.rs` (0.1 m links, 0.1 kg, g = 9.81, dt = 1e-3).

use std::hint::black_box;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, SamplingMode};
use vinculo::integrators::{GeneralizedTrapezoidal, NewtonOptions, StepStart, StepWorkspace};
use vinculo::linear::{LinearSolver, Singular};
use vinculo::math::Vec3;
use vinculo::model::System;
use vinculo::{SimulationOptions, SparseSolver};

const DT: f64 = 1e-3;
const SCHEME: GeneralizedTrapezoidal = GeneralizedTrapezoidal { alpha: 0.5 };

fn pendulum() -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let b = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(a, b, None).unwrap();
    s
}

/// The chain of [`chain`] with bending stiffness (0.05 N m^2) at every interior particle: each
/// particle is also coupled with its second neighbours.
fn bent_chain(n: usize) -> System {
    let mut s = chain(n);
    let ids: Vec<_> = (0..=n).map(|i| s.particle_id(i).unwrap()).collect();
    for i in 1..n {
        s.add_bending(ids[i - 1], ids[i], ids[i + 1], 0.05, None)
            .unwrap();
    }
    s
}

/// N point masses in a horizontal row from a fixed anchor, at rest (released to swing).
fn chain(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    for i in 1..=n {
        let p = s
            .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_distance(prev, p, None).unwrap();
        prev = p;
    }
    s
}

/// `n` point masses on a vertical circle, each linked to its neighbours (a closed loop), the top
/// one linked to a fixed point above it: a constraint graph with a loop.
fn ring(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let radius = 0.5;
    let top = s
        .add_particle(1.0, [0.0, 0.0, radius + 0.2], [0.0; 3], true)
        .unwrap();
    let ids: Vec<_> = (0..n)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / n as f64;
            let position = [radius * phi.sin(), 0.0, radius * phi.cos()];
            s.add_particle(0.1, position, [0.0; 3], false).unwrap()
        })
        .collect();
    for k in 0..n {
        s.add_distance(ids[k], ids[(k + 1) % n], None).unwrap();
    }
    s.add_distance(top, ids[0], None).unwrap();
    s
}

/// What a [`Recorder`] saw: the matrix values and right-hand side of its first factor/solve.
#[derive(Default)]
struct Recorded {
    values: Option<Vec<f64>>,
    rhs: Option<Vec<f64>>,
}

/// A linear solver that solves nothing: records the first matrix and right-hand side it gets and
/// returns a zero increment, so that a Newton iteration costs only its assembly.
struct Recorder(Arc<Mutex<Recorded>>);

impl LinearSolver for Recorder {
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        let mut seen = self.0.lock().unwrap();
        seen.values.get_or_insert_with(|| values.to_vec());
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let mut seen = self.0.lock().unwrap();
        seen.rhs.get_or_insert_with(|| rhs.to_vec());
        rhs.fill(0.0);
    }

    fn name(&self) -> &'static str {
        "recorder"
    }
}

/// A step's starting point: the initial state, and the predictor q = q_n + h v_n, lambda = 0.
struct Start {
    q_n: Vec<Vec3>,
    v_n: Vec<Vec3>,
}

impl Start {
    fn initial(system: &System) -> Start {
        Start {
            q_n: system.initial_positions(),
            v_n: system.initial_velocities(),
        }
    }

    /// The step of size DT from (t_n, q_n, v_n).
    fn step(&self, t_n: f64) -> StepStart<'_> {
        StepStart::new(t_n, &self.q_n, &self.v_n, DT)
    }

    fn predict(&self, ws: &mut StepWorkspace, lambda: Option<&[f64]>) {
        for ((q, q_n), v_n) in ws.state.q.iter_mut().zip(&self.q_n).zip(&self.v_n) {
            for k in 0..3 {
                q[k] = q_n[k] + DT * v_n[k];
            }
        }
        match lambda {
            Some(l) => ws.state.lambda.copy_from_slice(l),
            None => ws.state.lambda.fill(0.0),
        }
    }

    /// Runs Newton with at most `iterations` iterations (0: the residual only) from the
    /// predictor in `ws`. With the recording solver the increment is zero, so the iterate is
    /// left as it was and the step does not converge (the error is ignored).
    fn assemble(&self, system: &System, ws: &mut StepWorkspace, iterations: usize) {
        let options = NewtonOptions {
            max_iterations: iterations,
            ..NewtonOptions::default()
        };
        let _ = SCHEME.step(system, ws, self.step(0.0), &options);
    }
}

/// A workspace whose solver is a [`Recorder`], and what the recorder saw in one iteration.
fn recording_workspace(system: &System, choice: SparseSolver) -> (StepWorkspace, Recorded) {
    let mut ws = StepWorkspace::with_solver(system, dense_limit(), choice);
    let seen = Arc::new(Mutex::new(Recorded::default()));
    ws.solver = Box::new(Recorder(Arc::clone(&seen)));
    let start = Start::initial(system);
    start.predict(&mut ws, None);
    start.assemble(system, &mut ws, 1);
    let recorded = std::mem::take(&mut *seen.lock().unwrap());
    (ws, recorded)
}

fn dense_limit() -> usize {
    SimulationOptions::default().dense_limit
}

fn assembly(c: &mut Criterion) {
    let mut group = c.benchmark_group("assembly");
    for n in [1_000, 100_000] {
        let system = chain(n);
        let start = Start::initial(&system);
        for path in ["", " parallel"] {
            let (mut ws, _) = recording_workspace(&system, SparseSolver::Auto);
            if !path.is_empty() {
                ws.assemble_in_parallel_from(&system, 0);
            }
            group.bench_function(BenchmarkId::new(format!("residual{path}"), n), |b| {
                b.iter(|| start.assemble(black_box(&system), &mut ws, 0))
            });
            group.bench_function(
                BenchmarkId::new(format!("residual+jacobian{path}"), n),
                |b| b.iter(|| start.assemble(black_box(&system), &mut ws, 1)),
            );
        }
    }
    group.finish();
}

fn factor_and_solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("factor+solve");
    let cases = [
        ("tree elimination", "chain", 1_000, SparseSolver::Auto),
        ("tree elimination", "chain", 100_000, SparseSolver::Auto),
        ("tree elimination", "bent chain", 1_000, SparseSolver::Auto),
        ("dense LU", "ring", 10, SparseSolver::Auto),
        ("sparse LU", "chain", 1_000, SparseSolver::SparseLu),
        ("sparse LU", "chain", 100_000, SparseSolver::SparseLu),
        ("sparse LU", "bent chain", 1_000, SparseSolver::SparseLu),
    ];
    for (label, shape, n, choice) in cases {
        let system = match shape {
            "ring" => ring(n),
            "bent chain" => bent_chain(n),
            _ => chain(n),
        };
        let (_, recorded) = recording_workspace(&system, choice);
        let (values, rhs) = (recorded.values.unwrap(), recorded.rhs.unwrap());
        let mut solver = StepWorkspace::with_solver(&system, dense_limit(), choice).solver;
        assert_eq!(solver.name(), label, "{shape} of {n} got another solver");
        let mut x = rhs.clone();
        if n >= 100_000 {
            group.sampling_mode(SamplingMode::Flat).sample_size(10);
        } else {
            group.sampling_mode(SamplingMode::Auto).sample_size(50);
        }
        group.bench_function(BenchmarkId::new(label, format!("{shape} {n}")), |b| {
            b.iter(|| {
                solver.factor(black_box(&values)).unwrap();
                x.copy_from_slice(&rhs);
                solver.solve_in_place(black_box(&mut x));
            })
        });
    }
    group.finish();
}

fn whole_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    for (name, system) in [("pendulum", pendulum()), ("chain 1000", chain(1_000))] {
        // One step from rest, then time the second step from its result, again and again.
        let mut ws = StepWorkspace::new(&system, dense_limit());
        let initial = Start::initial(&system);
        initial.predict(&mut ws, None);
        let options = NewtonOptions::default();
        SCHEME
            .step(&system, &mut ws, initial.step(0.0), &options)
            .unwrap();
        let start = Start {
            q_n: ws.state.q.clone(),
            v_n: ws.state.v.clone(),
        };
        let lambda = ws.state.lambda.clone();
        start.predict(&mut ws, Some(&lambda));
        let report = SCHEME
            .step(&system, &mut ws, start.step(DT), &options)
            .unwrap();
        let label = format!(
            "{name} ({}, {} Newton it.)",
            ws.solver.name(),
            report.iterations
        );
        group.bench_function(label, |b| {
            b.iter(|| {
                start.predict(&mut ws, Some(&lambda));
                SCHEME
                    .step(black_box(&system), &mut ws, start.step(DT), &options)
                    .unwrap()
            })
        });
    }
    group.finish();
}

fn main() {
    // What `criterion_group!` and `criterion_main!` expand to, written out: the macro's
    // generated function has no doc comment, which the crate's `missing_docs` lint rejects.
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    assembly(&mut c);
    factor_and_solve(&mut c);
    whole_step(&mut c);
    c.final_summary();
}
