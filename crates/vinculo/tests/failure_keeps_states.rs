//! A run that cannot converge stops with a typed error naming time, residual and equation, and
//! keeps every state computed before, on both formulations (GGL names the particle or constraint
//! whose kinematic, dynamic, position or velocity row failed).

use vinculo::integrators::{Formulation, NewtonOptions};
use vinculo::model::System;
use vinculo::{simulate, Error, SimulationOptions};

#[test]
fn newton_failure_reports_and_keeps_the_partial_run() {
    for formulation in [Formulation::Index3, Formulation::Ggl] {
        fails_and_keeps_the_partial_run(formulation);
    }
}

fn fails_and_keeps_the_partial_run(formulation: Formulation) {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let pivot = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let bob = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(pivot, bob, None).unwrap();
    // One Newton iteration cannot meet a 1e-15 tolerance once the pendulum moves fast.
    let options = SimulationOptions {
        t_end: 1.0,
        dt: 1e-2,
        newton: NewtonOptions {
            tolerance: 1e-15,
            max_iterations: 1,
            ..Default::default()
        },
        max_halvings: 2,
        formulation,
        ..Default::default()
    };
    let sol = simulate(&s, &options).unwrap();
    match &sol.status {
        Err(Error::NewtonFailed {
            t,
            residual,
            equation,
            ..
        }) => {
            assert!(*t >= 0.0 && *t < 1.0);
            // The residual can already be tiny while the last increment is not: report it as is.
            assert!(residual.is_finite() && *residual >= 0.0);
            assert!(
                equation.contains("particle 1") || equation.contains("distance #0"),
                "{equation}"
            );
            // Everything up to the failing step is kept.
            assert!((sol.times.last().unwrap() - t).abs() < 1e-12);
        }
        other => panic!("{formulation:?}: expected NewtonFailed, got {other:?}"),
    }
    assert!(sol.steps_rejected >= 3);
}
