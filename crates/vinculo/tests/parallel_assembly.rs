//! Parallel assembly (forced on with `parallel_from: 0`) gives the same trajectory as the serial
//! loops: on a swinging chain with the trapezoidal rule and full Newton, the same chain with
//! generalised-alpha and modified Newton, and a ring (a constraint graph with a loop, solved by
//! the sparse LU), a chain with every other particle held in a plane (fixed coordinates among the
//! distances), and a chain stiffened by bending forces on every three consecutive particles
//! (elements of three particles, whose Jacobian blocks couple second neighbours). The residuals are the same bit for bit and the Jacobians agree to round-off,
//! so the Newton iterates agree far below the Newton tolerance.

use vinculo::integrators::{JacobianReuse, NewtonOptions, Scheme};
use vinculo::model::System;
use vinculo::{simulate, SimulationOptions, Solution};

/// A horizontal chain of `n` links (0.1 m, 0.1 kg) from a fixed anchor, released at rest.
fn chain(n: usize) -> System {
    chain_under(n, [0.0, 0.0, -9.81])
}

/// The chain of [`chain`] under the gravity `g`.
fn chain_under(n: usize, g: [f64; 3]) -> System {
    let mut s = System::new(g);
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

/// `n` point masses on a vertical circle, each linked to its neighbours (a closed loop), the
/// top one linked to a fixed point above it, spinning about the circle's axis.
fn ring(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let radius = 0.05 * n as f64 / std::f64::consts::PI;
    let top = s
        .add_particle(1.0, [0.0, 0.0, radius + 0.2], [0.0; 3], true)
        .unwrap();
    let ids: Vec<_> = (0..n)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / n as f64;
            let position = [radius * phi.sin(), 0.0, radius * phi.cos()];
            let velocity = [0.3 * phi.cos(), 0.0, -0.3 * phi.sin()];
            s.add_particle(0.1, position, velocity, false).unwrap()
        })
        .collect();
    for k in 0..n {
        s.add_distance(ids[k], ids[(k + 1) % n], None).unwrap();
    }
    s.add_distance(top, ids[0], None).unwrap();
    s
}

/// The chain of [`chain`] with a bending force (stiffness 0.05 N m^2) at every interior
/// particle, released bent into an arc so that the bending forces act from the start.
fn stiff_chain(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let at = |i: usize| {
        let phi = 0.002 * i as f64;
        [phi.sin() / 0.02, 0.0, (phi.cos() - 1.0) / 0.02]
    };
    let ids: Vec<_> = (0..=n)
        .map(|i| s.add_particle(0.1, at(i), [0.0; 3], i == 0).unwrap())
        .collect();
    for i in 0..n {
        s.add_distance(ids[i], ids[i + 1], None).unwrap();
    }
    for i in 1..n {
        s.add_bending(ids[i - 1], ids[i], ids[i + 1], 0.05, None)
            .unwrap();
    }
    s
}

/// A chain as [`chain`]'s with every other particle held in the plane y = 0 by a fixed
/// coordinate, under a gravity with a y component, which the fixed coordinates carry (non-zero
/// multipliers): constraints of another kind than distances among them, whose gradients the
/// parallel residual stores per element where a distance's are made again per particle.
fn planar_chain(n: usize) -> System {
    let mut s = chain_under(n, [0.0, -3.0, -9.81]);
    for index in (1..=n).step_by(2) {
        let p = s.particle_id(index).unwrap();
        s.add_fixed_coordinate(p, 1, None).unwrap();
    }
    s
}

/// A chain of elastic segments (EA = 2e3 N) with internal axial damping, released horizontally:
/// the damping's tension goes with each segment's multiplier into the particle rows, from the
/// constraint pass in the parallel residual.
fn damped_chain(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    for i in 1..=n {
        let p = s
            .add_particle(0.1, [0.01 * i as f64, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        let c = s
            .add_elastic_distance(prev, p, (vinculo::laws::Law::Constant(0.01), 1.0), 2e3)
            .unwrap();
        s.set_axial_damping(c, 3.0).unwrap();
        prev = p;
    }
    s
}

fn run(system: &System, options: &SimulationOptions, parallel: bool) -> Solution {
    let options = SimulationOptions {
        parallel_from: if parallel { 0 } else { usize::MAX },
        ..options.clone()
    };
    let sol = simulate(system, &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    sol
}

/// Positions and multipliers of the two runs agree to 1e-12 relative to their largest values.
fn assert_same_trajectory(system: &System, options: &SimulationOptions, solver: &str) {
    let serial = run(system, options, false);
    let parallel = run(system, options, true);
    assert_eq!(serial.linear_solver, solver);
    assert_eq!(serial.len(), parallel.len());
    for (a, b) in [
        (&serial.positions, &parallel.positions),
        (&serial.multipliers, &parallel.multipliers),
    ] {
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(worst <= 1e-12 * scale, "differ by {worst} (scale {scale})");
    }
}

#[test]
fn parallel_assembly_gives_the_serial_trajectory() {
    let options = SimulationOptions {
        t_end: 0.02,
        dt: 1e-3,
        ..Default::default()
    };
    assert_same_trajectory(&chain(3_000), &options, "tree elimination");
    let modified = SimulationOptions {
        scheme: Scheme::GeneralizedAlpha { rho_inf: 0.9 },
        newton: NewtonOptions {
            jacobian_reuse: JacobianReuse::Always,
            ..NewtonOptions::default()
        },
        ..options.clone()
    };
    assert_same_trajectory(&chain(3_000), &modified, "tree elimination");
    assert_same_trajectory(&ring(2_500), &options, "sparse LU");
    assert_same_trajectory(&planar_chain(3_000), &options, "tree elimination");
    // Bending couples second neighbours, a particle and its grandparent in the chain's tree:
    // the tree elimination takes them (with fill).
    assert_same_trajectory(&stiff_chain(3_000), &options, "tree elimination");
    assert_same_trajectory(&damped_chain(3_000), &options, "tree elimination");
}
