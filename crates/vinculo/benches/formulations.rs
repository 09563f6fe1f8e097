//! Cost of a step of the GGL formulation against the index-3 one, on a chain of 100 point masses
//! (0.1 kg, 0.1 m links) released horizontally, trapezoidal rule, dt = 1e-3, 0.5 s.
//!
//! Run with `cargo bench -p vinculo --bench formulations`. Index-3 runs with the tree elimination
//! (its default on a chain) and with the general sparse LU (the solver GGL needs); each run is
//! timed after one warm-up run, with full and with modified Newton.

use std::time::Instant;
use vinculo::integrators::{Formulation, JacobianReuse, NewtonOptions};
use vinculo::model::System;
use vinculo::{simulate, SimulationOptions, SparseSolver};

fn swinging_chain(n: usize) -> System {
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

fn main() {
    let system = swinging_chain(100);
    let cases = [
        (
            "index-3, tree elimination",
            Formulation::Index3,
            SparseSolver::Auto,
        ),
        (
            "index-3, sparse LU",
            Formulation::Index3,
            SparseSolver::SparseLu,
        ),
        ("ggl", Formulation::Ggl, SparseSolver::Auto),
    ];
    for (name, formulation, sparse_solver) in cases {
        for (jacobian_reuse, mode) in [
            (JacobianReuse::Never, "full"),
            (JacobianReuse::Always, "modified"),
            (JacobianReuse::WhileFast, "default"),
        ] {
            let options = SimulationOptions {
                t_end: 0.5,
                dt: 1e-3,
                formulation,
                sparse_solver,
                newton: NewtonOptions {
                    jacobian_reuse,
                    ..Default::default()
                },
                ..Default::default()
            };
            simulate(&system, &options).unwrap();
            let start = Instant::now();
            let sol = simulate(&system, &options).unwrap();
            let elapsed = start.elapsed().as_secs_f64();
            assert!(sol.status.is_ok());
            let steps = sol.len() - 1;
            let iterations: usize = sol.stats.iter().map(|s| s.newton_iterations).sum();
            let velocity = sol
                .velocity_violation
                .iter()
                .fold(0.0, |m: f64, x| m.max(*x));
            println!(
                "{name:<27} {mode:<8} {:>8.1} us/step  {:>5.2} Newton it./step  \
                 {:>5.2} factorisations/step  max |s (G v + Phi_t)| {velocity:.1e} m/s  ({})",
                1e6 * elapsed / steps as f64,
                iterations as f64 / steps as f64,
                sol.factorisations as f64 / steps as f64,
                sol.linear_solver
            );
        }
    }
}
