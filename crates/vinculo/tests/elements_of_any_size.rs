//! Constraint equations over three and over six particles, written as user groups through the
//! public API and integrated against closed forms. Six particles are more than an element keeps
//! inline ([`vinculo::local::INLINE`]), so the second test also goes through the heap-backed
//! local values. Each model is run with every sparse solver the pattern admits and with dense
//! storage: the answers agree whichever the solver.

use vinculo::constraints::{ConstraintCall, ConstraintGroup};
use vinculo::integrators::Scheme;
use vinculo::model::System;
use vinculo::user::{GroupElements, UserFailure};
use vinculo::{simulate, SimulationOptions, Solution, SparseSolver};

/// A linear constraint group: element e's equation is sum_x c_x . q_x - b = 0 over its a
/// particles, with coefficients `rows[e]` (3a values: particle x, coordinate l at 3x + l).
/// Gradient constant, Hessian, Phi_t and gamma zero.
struct Linear {
    rows: Vec<Vec<f64>>,
    offset: Vec<f64>,
}

impl ConstraintGroup for Linear {
    fn supplies(&self, _call: ConstraintCall) -> bool {
        true
    }

    fn evaluate(
        &self,
        call: ConstraintCall,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        out: &mut [f64],
    ) -> Result<(), UserFailure> {
        let n = self.rows[0].len();
        match call {
            ConstraintCall::Phi => {
                for (e, row) in self.rows.iter().enumerate() {
                    let x = &q[e * n..(e + 1) * n];
                    out[e] = row.iter().zip(x).map(|(c, x)| c * x).sum::<f64>() - self.offset[e];
                }
            }
            ConstraintCall::Gradient => {
                for (e, row) in self.rows.iter().enumerate() {
                    out[e * n..(e + 1) * n].copy_from_slice(row);
                }
            }
            ConstraintCall::Hessian | ConstraintCall::PhiT | ConstraintCall::Gamma => out.fill(0.0),
        }
        Ok(())
    }
}

/// The runs of `system` under every linear solver: sparse storage with the automatic choice
/// (tree elimination where the pattern allows it) and with the sparse LU, and dense storage.
fn every_solver(system: &System, options: &SimulationOptions) -> Vec<Solution> {
    [
        (0, SparseSolver::Auto),
        (0, SparseSolver::SparseLu),
        (usize::MAX, SparseSolver::Auto),
    ]
    .into_iter()
    .map(|(dense_limit, sparse_solver)| {
        let o = SimulationOptions {
            dense_limit,
            sparse_solver,
            ..options.clone()
        };
        let sol = simulate(system, &o).unwrap();
        assert!(
            sol.status.is_ok(),
            "{}: {:?}",
            sol.linear_solver,
            sol.status
        );
        sol
    })
    .collect()
}

/// The complete elliptic integral of the first kind K(k), by the arithmetic-geometric mean:
/// K(k) = pi / (2 AGM(1, sqrt(1 - k^2))) (Abramowitz and Stegun 17.6), to round-off.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    while (a - b).abs() > 1e-15 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

/// A rod from a fixed pivot A to a bob B (a distance constraint), with a second bob C held at
/// the rod's midpoint by three equations over the triple (A, B, C):
/// q_C - (q_A + q_B) / 2 = 0, one per axis.
///
/// Reference (closed form): a compound pendulum of point masses m_B at L and m_C at L/2, whose
/// angle obeys I theta'' = -g (m_B L + m_C L / 2) sin theta with I = m_B L^2 + m_C L^2 / 4, so
/// omega_0^2 = g (m_B + m_C / 2) / (L (m_B + m_C / 4)), and whose period at amplitude theta_0 is
/// T = 4 K(sin(theta_0 / 2)) / omega_0 (the exact pendulum period).
#[test]
fn a_midpoint_held_by_triples_swings_as_a_compound_pendulum() {
    let (g, l, m_b, m_c, theta0) = (9.81, 0.8, 0.3, 0.5, 0.6_f64);
    let mut s = System::new([0.0, 0.0, -g]);
    let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let tip = [l * theta0.sin(), 0.0, -l * theta0.cos()];
    let b = s.add_particle(m_b, tip, [0.0; 3], false).unwrap();
    let c = s
        .add_particle(m_c, tip.map(|x| 0.5 * x), [0.0; 3], false)
        .unwrap();
    s.add_distance(a, b, None).unwrap();
    let rows = (0..3)
        .map(|axis| {
            let mut row = vec![0.0; 9];
            row[axis] = -0.5;
            row[3 + axis] = -0.5;
            row[6 + axis] = 1.0;
            row
        })
        .collect();
    let triples = GroupElements::from_rows(&[[a.index(), b.index(), c.index()]; 3]);
    let group = Linear {
        rows,
        offset: vec![0.0; 3],
    };
    s.add_user_constraint_group(triples, Box::new(group), 1.0, Some("midpoint".into()))
        .unwrap();

    let omega0 = (g * (m_b + 0.5 * m_c) / (l * (m_b + 0.25 * m_c))).sqrt();
    let period = 4.0 * elliptic_k((0.5 * theta0).sin()) / omega0;
    let options = SimulationOptions {
        t_end: 2.3 * period,
        dt: period / 4000.0,
        ..Default::default()
    };
    for sol in every_solver(&s, &options) {
        // Crossings of the vertical by B (x from + to -), interpolated linearly.
        let x: Vec<f64> = (0..sol.len())
            .map(|k| sol.position(k, b.index())[0])
            .collect();
        let crossings: Vec<f64> = (1..x.len())
            .filter(|&k| x[k - 1] > 0.0 && x[k] <= 0.0)
            .map(|k| {
                let (t0, t1) = (sol.times[k - 1], sol.times[k]);
                t0 + (t1 - t0) * x[k - 1] / (x[k - 1] - x[k])
            })
            .collect();
        // At T/4, 5T/4 and 9T/4.
        assert_eq!(crossings.len(), 3, "{}", sol.linear_solver);
        let measured = (crossings[2] - crossings[0]) / 2.0;
        // Trapezoidal rule at 4000 steps per period: relative period error ~ (omega h)^2 / 12
        // ~ 2e-7; the linear interpolation of the crossings adds less than that.
        assert!(
            ((measured - period) / period).abs() < 2e-6,
            "{}: period {measured} against the closed form {period}",
            sol.linear_solver
        );
        // C stays at the midpoint to the Newton tolerance.
        let last = sol.len() - 1;
        let (qb, qc) = (sol.position(last, b.index()), sol.position(last, c.index()));
        for k in 0..3 {
            assert!((qc[k] - 0.5 * qb[k]).abs() < 1e-9, "{}", sol.linear_solver);
        }
    }
}

/// Six free particles of masses m_i = 0.1 (i + 1) kg under gravity, their mean height held
/// fixed by one equation over all six: Phi = sum_i z_i / 6 - z_mean.
///
/// Reference (closed form): with the multiplier's force lambda/6 on each particle,
/// m_i z_i'' = -m_i g + lambda / 6, and sum_i z_i'' = 0 gives lambda / 6 = 6 g / sum_j (1/m_j),
/// so each particle accelerates uniformly, a_i = -g + 6 g / (m_i sum_j 1/m_j), and
/// z_i(t) = z_i(0) + a_i t^2 / 2, while x_i(t) = x_i(0) + u_i t. Both rules integrate
/// constant accelerations exactly, so only round-off and the Newton tolerance remain.
#[test]
fn six_particles_held_at_a_mean_height_fall_and_rise_as_the_closed_form() {
    let g = 9.81;
    let mut s = System::new([0.0, 0.0, -g]);
    let masses: Vec<f64> = (0..6).map(|i| 0.1 * (i + 1) as f64).collect();
    let mut ids = Vec::new();
    for (i, &m) in masses.iter().enumerate() {
        let q = [0.3 * i as f64, 0.0, 0.1 * (i % 3) as f64];
        let u = [0.05 * i as f64, 0.0, 0.0];
        ids.push(s.add_particle(m, q, u, false).unwrap());
    }
    let z_mean = (0..6).map(|i| 0.1 * (i % 3) as f64).sum::<f64>() / 6.0;
    let mut row = vec![0.0; 18];
    for x in 0..6 {
        row[3 * x + 2] = 1.0 / 6.0;
    }
    let all: Vec<usize> = ids.iter().map(|p| p.index()).collect();
    let elements = GroupElements::new(6, all).unwrap();
    let group = Linear {
        rows: vec![row],
        offset: vec![z_mean],
    };
    s.add_user_constraint_group(elements, Box::new(group), 1.0, None)
        .unwrap();

    let inverse: f64 = masses.iter().map(|m| 1.0 / m).sum();
    let t_end = 0.5;
    for scheme in [
        Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
        Scheme::GeneralizedAlpha { rho_inf: 0.8 },
    ] {
        let options = SimulationOptions {
            t_end,
            dt: 0.01,
            scheme,
            ..Default::default()
        };
        for sol in every_solver(&s, &options) {
            let last = sol.len() - 1;
            let t = sol.times[last];
            for (i, &m) in masses.iter().enumerate() {
                let a = -g + 6.0 * g / (m * inverse);
                let z = 0.1 * (i % 3) as f64 + 0.5 * a * t * t;
                let x = 0.3 * i as f64 + 0.05 * i as f64 * t;
                let q = sol.position(last, i);
                assert!(
                    (q[2] - z).abs() < 1e-9 && (q[0] - x).abs() < 1e-12,
                    "{scheme:?} {}: particle {i} at {q:?}, closed form x {x}, z {z}",
                    sol.linear_solver
                );
            }
        }
    }
}
