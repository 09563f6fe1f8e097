//! Models, iterates and checks shared by the tests of the step problems (index-3 and GGL) and
//! of the time rules.

use super::newton::NewtonProblem;
use super::StepWorkspace;
use crate::assembly::Layout;
use crate::laws::{Law, VectorLaw};
use crate::math::Vec3;
use crate::model::System;

/// A line node of mass 3 kg at the origin between two fixed neighbours at x = -1 and 1 m, in
/// water without gravity nor drag, with Ca = 1 and CaAx = 0.25 (diameter 0.08 m, length 1 m);
/// returns the system, the node and its displaced mass rho V (kg).
pub(crate) fn line_node_between_fixed_neighbours() -> (System, crate::model::ParticleId, f64) {
    use crate::model::LineHydroSpec;
    let mut s = System::new([0.0; 3]);
    let a = s
        .add_particle(1.0, [-1.0, 0.0, 0.0], [0.0; 3], true)
        .unwrap();
    let n = s.add_particle(3.0, [0.0; 3], [0.0; 3], false).unwrap();
    let b = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], true)
        .unwrap();
    let spec = LineHydroSpec {
        density: 1025.0,
        diameter: 0.08,
        length: 1.0,
        cd: 0.0,
        cdax: 0.0,
        ca: 1.0,
        caax: 0.25,
    };
    s.add_line_hydrodynamics(n, Some((a, b)), &spec).unwrap();
    (s, n, 1025.0 * std::f64::consts::PI * 0.08 * 0.08 / 4.0)
}

/// A system with every constraint and force kind (a bending force among them, over three
/// particles), fixed particles, added mass and time-dependent laws.
pub(crate) fn every_kind() -> System {
    let mut s = System::new([0.1, -0.2, -9.81]);
    let a = s
        .add_particle(1.0, [0.0, 0.0, 0.0], [0.0; 3], true)
        .unwrap();
    let b = s
        .add_particle(0.7, [0.5, 0.1, -0.2], [0.3, 0.1, 0.0], false)
        .unwrap();
    let c = s
        .add_particle(1.3, [0.9, -0.1, -0.4], [-0.2, 0.4, 0.1], false)
        .unwrap();
    let d = s
        .add_particle(0.4, [0.2, 0.6, 0.1], [0.0, -0.3, 0.5], false)
        .unwrap();
    s.add_distance(a, b, None).unwrap();
    s.add_distance(b, c, None).unwrap();
    let point = VectorLaw([
        Law::sine(0.1, 0.7, 0.0, 0.0, 0.0, 0.0).unwrap(),
        Law::Constant(0.6),
        Law::Constant(0.5),
    ]);
    s.add_distance_to_point(d, point, None).unwrap();
    s.add_plane(
        c,
        VectorLaw::constant([0.0, 0.3, 1.0]),
        VectorLaw::constant([0.9, -0.1, -0.4]),
    )
    .unwrap();
    s.add_fixed_coordinate(d, 0, None).unwrap();
    s.add_spring_damper(c, d, 40.0, 1.5, Some(0.5)).unwrap();
    // A three-particle element, over a fixed and two free particles.
    s.add_bending(a, b, c, 0.3, None).unwrap();
    s.add_quadratic_drag(b, 0.8).unwrap();
    s.add_linear_drag(c, 0.3).unwrap();
    // Fluid forces with added mass (which enters the mass matrix) on a constrained particle.
    s.add_morison(
        b,
        crate::forces::MorisonSpec {
            density: 1000.0,
            volume: 2e-4,
            area: 0.01,
            drag_coefficient: 0.4,
            added_mass_coefficient: 0.5,
            fluid: VectorLaw([
                Law::sine(0.05, 0.9, 0.0, 0.0, 0.5, 0.0).unwrap(),
                Law::Constant(0.0),
                Law::Constant(0.0),
            ]),
            in_water: false,
        },
    )
    .unwrap();
    s.add_force(
        d,
        VectorLaw([
            Law::Constant(1.0),
            Law::sine(2.0, 1.0, 0.0, 0.0, 0.0, 0.0).unwrap(),
            Law::Constant(0.0),
        ]),
    )
    .unwrap();

    s
}

/// A mooring line in water whose added mass is anisotropic (Ca = 1, CaAx = 0.3 on all nodes
/// but one, CaAx = 1.6 > Ca there): a fixed anchor and five free nodes off a straight line,
/// moving, linked by distances, each node with its hydrodynamics in a current (the anchor's
/// and the free end's tangents from their one segment, the others' from their neighbours).
pub(crate) fn line_in_water() -> System {
    use crate::model::LineHydroSpec;
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut ids = vec![s.add_particle(2.0, [0.0; 3], [0.0; 3], true).unwrap()];
    for i in 1..=5 {
        let u = i as f64;
        let x = [0.9 * u, 0.05 * (1.7 * u).sin(), 0.4 * u - 0.06 * u * u];
        let v = [
            0.1 * (0.3 * u).cos(),
            -0.2 + 0.05 * u,
            0.3 * (0.8 * u).sin(),
        ];
        ids.push(s.add_particle(1.5 + 0.1 * u, x, v, false).unwrap());
    }
    for w in ids.windows(2) {
        s.add_distance(w[0], w[1], None).unwrap();
    }
    let last = ids.len() - 1;
    for (i, &p) in ids.iter().enumerate() {
        let tangent = match i {
            0 => (ids[0], ids[1]),
            _ if i == last => (ids[i - 1], ids[i]),
            _ => (ids[i - 1], ids[i + 1]),
        };
        let spec = LineHydroSpec {
            density: 1025.0,
            diameter: 0.05,
            length: 0.9,
            cd: 1.2,
            cdax: 0.1,
            ca: 1.0,
            caax: if i == 3 { 1.6 } else { 0.3 },
        };
        s.add_line_hydrodynamics(p, Some(tangent), &spec).unwrap();
    }
    let mut water = crate::water::Water::everywhere(9.81);
    water.current = crate::water::Current::Uniform([0.2, 0.1, 0.0]);
    s.set_water(water);
    s
}

/// Asserts that the problem's assembled Jacobian equals central finite differences of its
/// residual, column by column, at the current iterate (which it leaves unchanged).
pub(crate) fn assert_jacobian_matches(problem: &mut impl NewtonProblem, layout: &Layout) {
    assert_pattern_jacobian_matches(problem, &layout.pattern);
}

/// [`assert_jacobian_matches`] for any problem whose matrix has the given pattern.
pub(crate) fn assert_pattern_jacobian_matches(
    problem: &mut impl NewtonProblem,
    pattern: &crate::assembly::Pattern,
) {
    let n = pattern.n;
    let mut r = vec![0.0; n];
    problem.residual(&mut r); // refreshes the evaluation point
    let mut values = vec![0.0; pattern.nnz()];
    problem.jacobian(&mut values);
    let mut dense = vec![vec![0.0; n]; n];
    for (row, col, k) in pattern.entries() {
        dense[row][col] += values[k];
    }
    let eps = 1e-7;
    for col in 0..n {
        let mut dx = vec![0.0; n];
        dx[col] = -eps; // update() subtracts
        let mut rp = vec![0.0; n];
        let mut rm = vec![0.0; n];
        problem.update(&dx);
        problem.residual(&mut rp);
        dx[col] = 2.0 * eps;
        problem.update(&dx);
        problem.residual(&mut rm);
        dx[col] = -eps;
        problem.update(&dx);
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * eps);
            assert!(
                (fd - dense[row][col]).abs() < 1e-6 * (1.0 + fd.abs()),
                "J[{row}][{col}] = {} but finite differences give {fd}",
                dense[row][col]
            );
        }
    }
}

/// A perturbed iterate off the constraints, and non-zero multipliers.
pub(crate) fn perturbed_iterate(ws: &mut StepWorkspace, q_n: &[Vec3]) {
    ws.state.q = q_n
        .iter()
        .enumerate()
        .map(|(i, x)| {
            if i == 0 {
                *x
            } else {
                [x[0] + 0.01, x[1] - 0.02 * i as f64, x[2] + 0.005]
            }
        })
        .collect();
    ws.state.lambda = vec![0.8, -1.2, 0.5, 2.0, -0.7];
}

/// A 1 m pendulum released from the horizontal: a 1 kg particle at (1, 0, 0), at rest, on a
/// distance to a fixed anchor at the origin (particle 0), under g = 9.81 m/s^2 along -z.
pub(crate) fn pendulum() -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let b = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(a, b, None).unwrap();
    s
}

/// A horizontal chain of `n` point masses (0.1 m links, 0.1 kg) from a fixed anchor.
pub(crate) fn chain(n: usize) -> System {
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

/// An `n` x `n` cloth: a square grid of point masses hung from its two top corners, linked
/// to their row and column neighbours by distance constraints (a constraint graph full of
/// loops) and along the diagonals by spring-dampers (two-particle forces), with drag on
/// every particle (one-particle forces).
pub(crate) fn cloth(n: usize) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut id = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let fixed = j == 0 && (i == 0 || i == n - 1);
            let x = [0.1 * i as f64, 0.01 * (i * j % 7) as f64, -0.1 * j as f64];
            id.push(s.add_particle(0.05, x, [0.0, 0.2, 0.0], fixed).unwrap());
        }
    }
    for j in 0..n {
        for i in 0..n {
            let p = id[j * n + i];
            if i + 1 < n {
                s.add_distance(p, id[j * n + i + 1], None).unwrap();
            }
            if j + 1 < n {
                s.add_distance(p, id[(j + 1) * n + i], None).unwrap();
            }
            if i + 1 < n && j + 1 < n {
                s.add_spring_damper(p, id[(j + 1) * n + i + 1], 30.0, 0.2, None)
                    .unwrap();
            }
            s.add_quadratic_drag(p, 0.01).unwrap();
        }
    }
    s
}

/// An iterate off the constraints with non-zero multipliers, for any system.
pub(crate) fn wiggled_iterate(ws: &mut StepWorkspace, q_n: &[Vec3]) {
    for (i, (q, x)) in ws.state.q.iter_mut().zip(q_n).enumerate() {
        let u = i as f64;
        *q = [
            x[0] + 0.01 * (0.7 * u).sin(),
            x[1] - 0.02 * (1.3 * u).cos(),
            x[2] + 0.005 * (0.3 * u).sin(),
        ];
    }
    for (k, l) in ws.state.lambda.iter_mut().enumerate() {
        *l = 1.5 * (0.9 * k as f64).sin() - 0.2;
    }
}

/// Asserts that the parallel residuals are the serial ones bit for bit, and the Jacobians
/// equal to 1e-14 (relative to the entry, or to 1 for small entries: the scaled matrix's
/// entries are O(1)).
pub(crate) fn assert_same_assembly(serial: &(Vec<f64>, Vec<f64>), parallel: &(Vec<f64>, Vec<f64>)) {
    assert_eq!(serial.0.len(), parallel.0.len());
    for (i, (s, p)) in serial.0.iter().zip(&parallel.0).enumerate() {
        assert_eq!(
            s.to_bits(),
            p.to_bits(),
            "residual {i}: serial {s}, parallel {p}"
        );
    }
    assert_eq!(serial.1.len(), parallel.1.len());
    for (k, (s, p)) in serial.1.iter().zip(&parallel.1).enumerate() {
        assert!(
            (s - p).abs() <= 1e-14 * s.abs().max(1.0),
            "Jacobian slot {k}: serial {s}, parallel {p}"
        );
    }
}

/// Well-posed chains whose tree blocks are singular. `pinned` false: a chain hung from two
/// anchors 2 m apart as a V of two straight legs of `n` links each, at rest (the end particle
/// of the leg eliminated first holds two parallel conditions, its anchor and its link).
/// `pinned` true: a chain of `n` links hanging straight down from a free particle whose
/// three coordinates are prescribed, released with a sideways speed (the pinned particle's
/// block would hold four conditions on three coordinates, were it not the root).
pub(crate) fn awkward_chain(n: usize, pinned: bool) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    if pinned {
        // The tip first, the pinned top last (not the first particle, which the analysis
        // used to take as the root).
        let mut below = None;
        for i in (1..=n).rev() {
            let z = -(i as f64) / n as f64;
            let v = [0.5 * i as f64 / n as f64, 0.0, 0.0];
            let p = s.add_particle(0.1, [0.0, 0.0, z], v, false).unwrap();
            if let Some(b) = below {
                s.add_distance(p, b, None).unwrap();
            }
            below = Some(p);
        }
        let top = s.add_particle(1.0, [0.0; 3], [0.0; 3], false).unwrap();
        for axis in 0..3 {
            s.add_fixed_coordinate(top, axis, None).unwrap();
        }
        s.add_distance(top, below.unwrap(), None).unwrap();
        return s;
    }
    let left = s
        .add_particle(1.0, [-1.0, 0.0, 0.0], [0.0; 3], true)
        .unwrap();
    let right = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], true)
        .unwrap();
    let mut prev = left;
    for i in 1..2 * n {
        let x = -1.0 + i as f64 / n as f64;
        let z = -(1.0 - x.abs());
        let p = s.add_particle(0.1, [x, 0.0, z], [0.0; 3], false).unwrap();
        s.add_distance(prev, p, None).unwrap();
        prev = p;
    }
    s.add_distance(prev, right, None).unwrap();
    s
}
