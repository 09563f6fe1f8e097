//! The tree elimination chosen automatically for tree-shaped constraint graphs gives the same
//! trajectory as the general sparse LU (the reference), on a chain and on a branched string.

use vinculo::model::System;
use vinculo::{simulate, SimulationOptions, Solution, SparseSolver};

/// A horizontal chain of `n` links from a fixed anchor, with a branch of `branch` particles
/// leaving its middle along y, released at rest.
fn string(n: usize, branch: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let mut middle = prev;
    for i in 1..=n {
        let p = s
            .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_distance(prev, p, None).unwrap();
        if i == n / 2 {
            middle = p;
        }
        prev = p;
    }
    let x = 0.1 * (n / 2) as f64;
    let mut prev = middle;
    for j in 1..=branch {
        let p = s
            .add_particle(0.05, [x, 0.1 * j as f64, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_distance(prev, p, None).unwrap();
        prev = p;
    }
    s
}

fn run(system: &System, sparse_solver: SparseSolver) -> Solution {
    let sol = simulate(
        system,
        &SimulationOptions {
            t_end: 0.2,
            dt: 1e-3,
            sparse_solver,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    sol
}

#[test]
fn chain_and_branched_string_give_the_same_trajectory_with_either_solver() {
    for (n, branch) in [(60, 0), (40, 10)] {
        let system = string(n, branch);
        let tree = run(&system, SparseSolver::Auto);
        let lu = run(&system, SparseSolver::SparseLu);
        assert_eq!(tree.linear_solver, "tree elimination");
        assert_eq!(lu.linear_solver, "sparse LU");
        assert_eq!(tree.len(), lu.len());
        // Positions agree to 1e-12 of the chain's extent (Newton stops at 1e-10 of the length
        // scale, but both solvers take the same iterates up to round-off).
        let extent = 0.1 * n as f64;
        let worst = tree
            .positions
            .iter()
            .zip(&lu.positions)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            worst < 1e-12 * extent,
            "largest position difference {worst:e}"
        );
        // Multipliers agree to 1e-9 of the largest (they are differences of large numbers).
        let largest = lu.multipliers.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = tree
            .multipliers
            .iter()
            .zip(&lu.multipliers)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            worst < 1e-9 * largest,
            "largest multiplier difference {worst:e}"
        );
        let its = |s: &Solution| s.stats.iter().map(|x| x.newton_iterations).sum::<usize>();
        assert_eq!(its(&tree), its(&lu));
    }
}
