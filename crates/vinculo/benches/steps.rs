//! Steps per second of the simulation loop on the reference models.
//!
//! Run with `cargo bench -p vinculo --bench steps`. Times only `simulate` (model building and
//! analysis included, output included), after one warm-up run, with full Newton, modified
//! Newton and the default reuse of the iteration matrix (`NewtonOptions::jacobian_reuse`).

mod common;

use common::chain;
use std::time::Instant;
use vinculo::integrators::{JacobianReuse, NewtonOptions};
use vinculo::model::System;
use vinculo::{simulate, SimulationOptions};

fn pendulum() -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let b = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(a, b, None).unwrap();
    s
}

fn measure(name: &str, system: &System, t_end: f64, dt: f64) {
    measure_with(
        name,
        system,
        t_end,
        dt,
        SimulationOptions::default().dense_limit,
    );
}

fn measure_with(name: &str, system: &System, t_end: f64, dt: f64, dense_limit: usize) {
    for (jacobian_reuse, mode) in [
        (JacobianReuse::Never, "full"),
        (JacobianReuse::Always, "modified"),
        (JacobianReuse::WhileFast, "default"),
    ] {
        let options = SimulationOptions {
            t_end,
            dt,
            dense_limit,
            newton: NewtonOptions {
                jacobian_reuse,
                ..Default::default()
            },
            ..Default::default()
        };
        simulate(system, &options).unwrap();
        let start = Instant::now();
        let sol = simulate(system, &options).unwrap();
        let elapsed = start.elapsed().as_secs_f64();
        assert!(sol.status.is_ok());
        let steps = sol.len() - 1;
        let iterations: usize = sol.stats.iter().map(|s| s.newton_iterations).sum();
        println!(
            "{name:<42} {mode:<8} {steps:>7} steps  {:>10.0} steps/s  {:>5.2} Newton it./step  \
             {:>5.2} factorisations/step  ({})",
            steps as f64 / elapsed,
            iterations as f64 / steps as f64,
            sol.factorisations as f64 / steps as f64,
            sol.linear_solver
        );
    }
}

fn main() {
    measure("pendulum, dt = 1e-3, 10 s", &pendulum(), 10.0, 1e-3);
    // Small systems: the dense LU against the tree elimination (dense_limit 0).
    measure_with("pendulum, 10 s, no dense LU", &pendulum(), 10.0, 1e-3, 0);
    for (hanging, shape) in [(true, "hanging"), (false, "swinging")] {
        let c = chain(10, 0.1, hanging);
        measure(&format!("{shape} chain N = 10, 1 s"), &c, 1.0, 1e-3);
        measure_with(
            &format!("{shape} chain N = 10, no dense LU"),
            &c,
            1.0,
            1e-3,
            0,
        );
    }
    for n in [100, 10000] {
        for (hanging, shape) in [(true, "hanging"), (false, "swinging")] {
            let name = format!("{shape} chain N = {n}, 0.1 m links, 1 s");
            measure(&name, &chain(n, 0.1, hanging), 1.0, 1e-3);
        }
    }
    measure(
        "hanging chain N = 1000, 0.1 m links, 1 s",
        &chain(1000, 0.1, true),
        1.0,
        1e-3,
    );
    measure(
        "swinging chain N = 1000, 0.1 m links, 1 s",
        &chain(1000, 0.1, false),
        1.0,
        1e-3,
    );
    measure(
        "swinging chain N = 300, 1 m long, 1 s",
        &chain(300, 1.0 / 300.0, false),
        1.0,
        1e-3,
    );
}
