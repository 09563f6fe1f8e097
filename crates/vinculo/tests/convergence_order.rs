//! Every scheme through the same convergence-order test: the horizontally released 1 m pendulum
//! integrated over 1 s with steps h, h/2, h/4, h/8, in full and in modified Newton, on the
//! index-3 and on the stabilised index-2 (GGL) formulation. GGL changes the discrete equations
//! (the velocity constraints hold at every step) but not the order of the time rule.
//!
//! Without a closed-form solution the error of a run at step h is estimated by its distance to
//! the run at h/2: for a method of order p, |q_h - q_{h/2}| ~ C h^p (1 - 2^-p), so successive
//! differences shrink by 2^p. Expected orders: docs/theory/time-rules.md for the generalised trapezoidal
//! rule (2 at alpha = 1/2, 1 otherwise), Arnold and Brüls (2007) for generalised-alpha (2).
//!
//! Modified Newton runs at a tolerance of 1e-13 of the length instead of the default 1e-10: it
//! converges linearly, so it stops with an error close to the tolerance (full Newton stops far
//! below it), and an error delta in q_{n+1} is an error of about delta/h in v_{n+1}; accumulated
//! over the 2000 steps of the finest run, 1e-10 gives a deviation of 6e-6 m, above the scheme's
//! own error at that step (measured on this pendulum).

use vinculo::integrators::{Formulation, JacobianReuse, NewtonOptions, Scheme};
use vinculo::model::System;
use vinculo::{simulate, SimulationOptions};

fn bob_at_one_second(
    scheme: Scheme,
    formulation: Formulation,
    dt: f64,
    jacobian_reuse: JacobianReuse,
) -> [f64; 3] {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let pivot = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let bob = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(pivot, bob, None).unwrap();
    let options = SimulationOptions {
        t_end: 1.0,
        dt,
        scheme,
        formulation,
        newton: NewtonOptions {
            jacobian_reuse,
            // Modified Newton stops with an error near its tolerance (newton.rs).
            tolerance: if jacobian_reuse == JacobianReuse::Always {
                1e-13
            } else {
                1e-10
            },
            ..Default::default()
        },
        ..Default::default()
    };
    let sol = simulate(&s, &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    assert_eq!(sol.scheme, scheme);
    assert_eq!(sol.formulation, formulation);
    sol.position(sol.len() - 1, 1)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max)
}

#[test]
fn every_scheme_has_its_order() {
    let schemes = [
        (Scheme::GeneralizedTrapezoidal { alpha: 0.5 }, 2.0),
        (Scheme::GeneralizedTrapezoidal { alpha: 0.75 }, 1.0),
        (Scheme::GeneralizedTrapezoidal { alpha: 1.0 }, 1.0),
        (Scheme::GeneralizedAlpha { rho_inf: 0.0 }, 2.0),
        (Scheme::GeneralizedAlpha { rho_inf: 0.5 }, 2.0),
        (Scheme::GeneralizedAlpha { rho_inf: 0.9 }, 2.0),
        (Scheme::GeneralizedAlpha { rho_inf: 1.0 }, 2.0),
    ];
    let formulations = [Formulation::Index3, Formulation::Ggl];
    for (scheme, order) in schemes {
        assert_eq!(scheme.order() as f64, order);
        for (formulation, jacobian_reuse) in formulations.into_iter().flat_map(|f| {
            [
                JacobianReuse::Never,
                JacobianReuse::Always,
                JacobianReuse::WhileFast,
            ]
            .map(|j| (f, j))
        }) {
            let runs: Vec<[f64; 3]> = [4e-3, 2e-3, 1e-3, 5e-4]
                .iter()
                .map(|&dt| bob_at_one_second(scheme, formulation, dt, jacobian_reuse))
                .collect();
            let differences: Vec<f64> = runs.windows(2).map(|w| distance(w[0], w[1])).collect();
            for w in differences.windows(2) {
                let observed = (w[0] / w[1]).log2();
                assert!(
                    (observed - order).abs() < 0.2,
                    "{scheme:?} {formulation:?} ({jacobian_reuse:?}): observed order \
                     {observed}, differences {differences:?}"
                );
            }
        }
    }
}
