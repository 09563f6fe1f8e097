//! Consistent initial conditions.
//!
//! Both tasks solve saddle-point systems with the mass matrix and the constraint gradients G
//! (M with the line nodes' axial added-mass correction at q, `assembly/axial_added_mass.rs`),
//! reusing the run's pattern and solver (scaled as in the step: dynamics rows by 1/m_ref,
//! constraint rows by s_k):
//!
//! - accelerations and multipliers at the start: `[M, -G^T; G, 0] [a; lambda] = [M g + f; -gamma]`
//!   (the index-1 form: Phi'' = G a + gamma = 0);
//! - projection of a user's state onto the constraints with the least mass-weighted change:
//!   positions by Gauss-Newton on `min 1/2 dq^T M dq  s.t.  Phi(q + dq) = 0`, each iteration solving
//!   `[M, -G^T; G, 0] [dq; mu] = [0; -Phi]`; then velocities in one solve of
//!   `[M, -G^T; G, 0] [dv; mu] = [0; -(G v + Phi_t)]`.

use crate::assembly::{Layout, NONE};
use crate::constraints::Constraint;
use crate::error::{Error, Result};
use crate::integrators::StepWorkspace;
use crate::linear::{assemble_and_factor, Singular};
use crate::math::{dot, Vec3};
use crate::model::System;

/// Assembles `[M/m_ref, -s G^T; s G, 0]` at positions q, time t, and factorises it in
/// `ws.solver`. The row of a compliant constraint (`docs/theory/moorings.md`) is instead its
/// scaled multiplier lambda / (s m_ref) alone: the multiplier (the tension) follows from the
/// stretch, `c lambda = -Phi`, and puts no condition on the accelerations or on the positions.
/// With `compliant` false, the compliant constraints' rows are exact ones.
fn factor_saddle_rows(
    system: &System,
    ws: &mut StepWorkspace,
    (q, t): (&[Vec3], f64),
    compliant: bool,
) -> std::result::Result<(), Singular> {
    let StepWorkspace {
        layout,
        solver,
        values,
        inertia,
        axial_added_mass: axial,
        scales,
        mass_ref,
        ..
    } = ws;
    let (layout, mass_ref) = (&*layout, *mass_ref);
    let fill = |values: &mut [f64]| {
        for (i, m) in inertia.iter().enumerate() {
            layout.add_to_particle_diagonal(values, i, m / mass_ref);
        }
        // The line nodes' axial added-mass correction at q (`assembly/axial_added_mass.rs`).
        axial.add_mass_blocks(values, &layout.particle_block, q, 1.0 / mass_ref);
        fill_constraint_rows(system, layout, scales, (q, t), compliant, values);
    };
    assemble_and_factor(solver.as_mut(), values, fill)
}

/// The constraints' rows and columns of the saddle matrix (see [`factor_saddle_rows`]).
fn fill_constraint_rows(
    system: &System,
    layout: &Layout,
    scales: &[f64],
    (q, t): (&[Vec3], f64),
    compliant: bool,
    values: &mut [f64],
) {
    for (c, con) in system.constraints().iter().enumerate() {
        let g = con.gradient(q, t);
        // The saddle matrix has no Hessian term: no blocks.
        let s = scales[c];
        if compliant && con.is_compliant() {
            // The row is the unknown lambda / (s m_ref) itself (1 on the diagonal, whatever
            // the compliance: well conditioned as EA grows); its right-hand side says what
            // the multiplier is.
            let none = [[0.0; 3]; 2];
            layout.add_constraint_blocks(values, (c, &[]), s, (&g, &none[..g.len()]));
            crate::assembly::add(values, layout.constraint_diagonal[c], 1.0);
        } else {
            layout.add_constraint_blocks(values, (c, &[]), s, (&g, &g));
        }
    }
}

/// The error for a failed factorisation, naming the equation where it failed.
pub(crate) fn singular_error(system: &System, layout: &Layout, t: f64, s: Singular) -> Error {
    let equation = match s.column {
        Some(c) if c < layout.unknowns() => layout.equation_name(system, c),
        _ => "an unidentified equation".into(),
    };
    Error::SingularMatrix {
        t,
        equation,
        detail: format!(
            "{}; the constraints may be redundant or leave the model under-determined",
            s.detail
        ),
    }
}

/// Solves the saddle system at (q, t) for the right-hand side in `ws.r`, leaving the solution there.
/// Fills [M/m_ref, -s G^T; s G, 0] at (q, t) and factorises it in `ws.solver`. The caller says
/// what the solver held before (see [`IterationMatrix::invalidate`](crate::integrators::IterationMatrix::invalidate)).
pub(crate) fn factor_saddle(
    system: &System,
    ws: &mut StepWorkspace,
    q: &[Vec3],
    t: f64,
) -> Result<()> {
    factor_saddle_rows(system, ws, (q, t), true)
        .map_err(|s| singular_error(system, &ws.layout, t, s))
}

fn solve_saddle(system: &System, ws: &mut StepWorkspace, q: &[Vec3], t: f64) -> Result<()> {
    // The solver no longer holds a step's iteration matrix.
    ws.matrix.invalidate();
    factor_saddle(system, ws, q, t)?;
    ws.solver.solve_in_place(&mut ws.r);
    if ws.r.iter().any(|x| !x.is_finite()) {
        return Err(Error::SingularMatrix {
            t,
            equation: "an unidentified equation".into(),
            detail: "the solution is not finite; the constraints may be redundant or leave the \
                     model under-determined"
                .into(),
        });
    }
    Ok(())
}

/// Adds the free-particle part of `x` (3 unknowns per free particle) to `out`.
fn add_free(layout: &Layout, x: &[f64], out: &mut [Vec3]) {
    for (i, o) in out.iter_mut().enumerate() {
        let d = layout.dof[i];
        if d != NONE {
            for k in 0..3 {
                o[k] += x[d + k];
            }
        }
    }
}

/// The multipliers of the system at rest at (q, t) with every constraint held exact (elastic
/// segments as inextensible ones): a first iterate of the static equilibrium.
pub(crate) fn rigid_multipliers(
    system: &System,
    ws: &mut StepWorkspace,
    q: &[Vec3],
    t: f64,
) -> Result<Vec<f64>> {
    let v = vec![[0.0; 3]; q.len()];
    rest_right_hand_side(system, ws, q, &v, t, false);
    ws.matrix.invalidate();
    factor_saddle_rows(system, ws, (q, t), false)
        .map_err(|s| singular_error(system, &ws.layout, t, s))?;
    ws.solver.solve_in_place(&mut ws.r);
    let m3 = 3 * ws.layout.free;
    let lambda: Vec<f64> = (0..system.constraints().len())
        .map(|c| ws.r[m3 + c] * ws.scales[c] * ws.mass_ref)
        .collect();
    if lambda.iter().all(|x| x.is_finite()) {
        Ok(lambda)
    } else {
        Err(Error::SingularMatrix {
            t,
            equation: "an unidentified equation".into(),
            detail: "the solution is not finite".into(),
        })
    }
}

/// The right-hand side [M g + f; -gamma] / m_ref of the consistent start into `ws.r`; a
/// compliant constraint's row gets its multiplier from the stretch when `compliant`.
fn rest_right_hand_side(
    system: &System,
    ws: &mut StepWorkspace,
    q: &[Vec3],
    v: &[Vec3],
    t: f64,
    compliant: bool,
) {
    let g = system.gravity();
    let m3 = 3 * ws.layout.free;
    ws.r.fill(0.0);
    for (i, p) in system.particles().iter().enumerate() {
        let d = ws.layout.dof[i];
        if d != NONE {
            for k in 0..3 {
                ws.r[d + k] = p.mass * g[k] / ws.mass_ref;
            }
        }
    }
    for f in system.forces() {
        let fl = f.force(q, v, t);
        for (x, &p) in f.particles().iter().enumerate() {
            let d = ws.layout.dof[p];
            if d != NONE {
                for k in 0..3 {
                    ws.r[d + k] += fl[x][k] / ws.mass_ref;
                }
            }
        }
    }
    for (c, con) in system.constraints().iter().enumerate() {
        ws.r[m3 + c] = if compliant && con.is_compliant() {
            // The tension of the stretch, none for a slack segment shorter than its length.
            let phi = con.residual(q, t);
            let phi = if con.can_slack() { phi.min(0.0) } else { phi };
            match con.compliant_segment() {
                // A nonlinear line: its curve's tension at that stretch.
                Some(segment) if segment.curve.is_some() => {
                    segment.tension_of(t, -phi) / (ws.scales[c] * ws.mass_ref)
                }
                _ => -phi / (con.compliance(t) * ws.scales[c] * ws.mass_ref),
            }
        } else {
            -ws.scales[c] * con.gamma(q, v, t)
        };
    }
}

/// Accelerations and multipliers consistent with (q, v) at time t.
pub fn consistent_accelerations(
    system: &System,
    ws: &mut StepWorkspace,
    q: &[Vec3],
    v: &[Vec3],
    t: f64,
) -> Result<(Vec<Vec3>, Vec<f64>)> {
    let m3 = 3 * ws.layout.free;
    rest_right_hand_side(system, ws, q, v, t, true);
    solve_saddle(system, ws, q, t)?;
    let mut a = vec![[0.0; 3]; q.len()];
    add_free(&ws.layout, &ws.r, &mut a);
    let lambda = (0..system.constraints().len())
        .map(|c| ws.r[m3 + c] * ws.scales[c] * ws.mass_ref)
        .collect();
    Ok((a, lambda))
}

/// How far a projection moved the initial state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionReport {
    /// Largest change of a position coordinate (m).
    pub position_change: f64,
    /// Largest change of a velocity coordinate (m/s).
    pub velocity_change: f64,
    /// Gauss-Newton iterations on the positions.
    pub iterations: usize,
}

/// The largest absolute value and its index (a NaN counts as the largest).
fn worst(values: impl Iterator<Item = f64>) -> (f64, usize) {
    let mut worst = (0.0, 0);
    for (k, x) in values.enumerate() {
        let a = x.abs();
        if a > worst.0 || a.is_nan() {
            worst = (a, k);
        }
    }
    worst
}

/// Phi' = Phi_q v + Phi_t of one constraint.
pub fn velocity_residual(c: &Constraint, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
    let g = c.gradient(q, t);
    let gv: f64 = c
        .particles()
        .iter()
        .enumerate()
        .map(|(x, &p)| dot(g[x], v[p]))
        .sum();
    gv + c.phi_t(q, t)
}

/// The constraints whose violations a state reports: all but the compliant ones, which any
/// stretch satisfies with its tension (a mooring line's elastic segments). A run finds them
/// once: looked at per stored state, the test cost a mooring line's step about as much as its
/// constraint rows (two passes over every constraint's kind).
pub fn rigid_constraints(system: &System) -> Vec<usize> {
    let constraints = system.constraints().iter().enumerate();
    constraints
        .filter(|(_, c)| !c.is_compliant())
        .map(|(k, _)| k)
        .collect()
}

/// Largest scaled constraint residual max_k |s_k Phi_k(q, t)| and its index (compliant
/// constraints, which any stretch satisfies with its tension, count as 0).
pub fn scaled_violation(system: &System, q: &[Vec3], t: f64) -> (f64, usize) {
    scaled_violation_among(system, &rigid_constraints(system), q, t)
}

/// [`scaled_violation`] over the constraints `rigid` ([`rigid_constraints`]).
pub fn scaled_violation_among(
    system: &System,
    rigid: &[usize],
    q: &[Vec3],
    t: f64,
) -> (f64, usize) {
    worst_among(system, rigid, |c| c.scale() * c.residual(q, t))
}

/// The largest `value` over the constraints `rigid` and the index of its constraint.
fn worst_among(
    system: &System,
    rigid: &[usize],
    value: impl Fn(&crate::constraints::Constraint) -> f64,
) -> (f64, usize) {
    let constraints = system.constraints();
    let (largest, k) = worst(rigid.iter().map(|&c| value(&constraints[c])));
    (largest, rigid.get(k).copied().unwrap_or(0))
}

/// Largest scaled velocity-constraint residual max_k |s_k (Phi_q v + Phi_t)| and its index
/// (compliant constraints count as 0).
pub fn scaled_velocity_violation(system: &System, q: &[Vec3], v: &[Vec3], t: f64) -> (f64, usize) {
    scaled_velocity_violation_among(system, &rigid_constraints(system), q, v, t)
}

/// [`scaled_velocity_violation`] over the constraints `rigid` ([`rigid_constraints`]).
pub fn scaled_velocity_violation_among(
    system: &System,
    rigid: &[usize],
    q: &[Vec3],
    v: &[Vec3],
    t: f64,
) -> (f64, usize) {
    worst_among(system, rigid, |c| c.scale() * velocity_residual(c, q, v, t))
}

/// Moves the system's initial positions and velocities onto Phi = 0 and G v + Phi_t = 0 at time t
/// with the least mass-weighted change. `tolerance` is relative to the model's length scale.
pub fn project_initial_state(
    system: &mut System,
    t: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<ProjectionReport> {
    let mut ws = StepWorkspace::new(system, 64);
    let q0 = system.initial_positions();
    let v0 = system.initial_velocities();
    let mut q = q0.clone();
    let mut v = v0.clone();
    let m3 = 3 * ws.layout.free;
    let target = tolerance * system.length_scale();
    let mut iterations = 0;
    loop {
        let (worst, k) = scaled_violation(system, &q, t);
        if worst <= target {
            break;
        }
        if iterations == max_iterations || !worst.is_finite() {
            return Err(Error::ProjectionFailed {
                iterations,
                residual: worst,
                equation: system.constraints()[k].name(k),
            });
        }
        ws.r.fill(0.0);
        for (c, con) in system.constraints().iter().enumerate() {
            if !con.is_compliant() {
                ws.r[m3 + c] = -ws.scales[c] * con.residual(&q, t);
            }
        }
        solve_saddle(system, &mut ws, &q, t)?;
        add_free(&ws.layout, &ws.r, &mut q);
        iterations += 1;
    }
    ws.r.fill(0.0);
    for (c, con) in system.constraints().iter().enumerate() {
        if !con.is_compliant() {
            ws.r[m3 + c] = -ws.scales[c] * velocity_residual(con, &q, &v, t);
        }
    }
    solve_saddle(system, &mut ws, &q, t)?;
    add_free(&ws.layout, &ws.r, &mut v);
    let change = |a: &[Vec3], b: &[Vec3]| {
        a.iter()
            .zip(b)
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0, f64::max)
    };
    let report = ProjectionReport {
        position_change: change(&q, &q0),
        velocity_change: change(&v, &v0),
        iterations,
    };
    system.set_initial_state(&q, &v);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_lands_on_the_constraints_to_round_off() {
        // A two-link chain whose second link is 10 % too long, with a velocity along a link.
        let mut s = System::new([0.0, 0.0, -9.81]);
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s
            .add_particle(1.0, [1.0, 0.0, 0.0], [1.0, 0.5, 0.0], false)
            .unwrap();
        let c = s
            .add_particle(2.0, [2.1, 0.0, 0.0], [0.0, 0.0, 0.3], false)
            .unwrap();
        s.add_distance(a, b, Some(1.0)).unwrap();
        s.add_distance(b, c, Some(1.0)).unwrap();
        let report = project_initial_state(&mut s, 0.0, 1e-14, 50).unwrap();
        let q = s.initial_positions();
        let v = s.initial_velocities();
        assert!(scaled_violation(&s, &q, 0.0).0 < 1e-14, "position residual");
        for con in s.constraints() {
            let r = velocity_residual(con, &q, &v, 0.0);
            assert!(r.abs() < 1e-13, "velocity constraint residual {r}");
        }
        assert!(
            (report.position_change - 0.1).abs() < 0.05,
            "moved {}",
            report.position_change
        );
    }

    #[test]
    fn pendulum_multiplier_at_rest_balances_gravity() {
        // Hanging at rest: the link carries m g, so 2 lambda L = m g (docs/theory/formulation.md sign convention).
        let mut s = System::new([0.0, 0.0, -9.81]);
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s
            .add_particle(2.0, [0.0, 0.0, -1.5], [0.0; 3], false)
            .unwrap();
        s.add_distance(a, b, None).unwrap();
        let mut ws = StepWorkspace::new(&s, 64);
        let (acc, lambda) = consistent_accelerations(
            &s,
            &mut ws,
            &s.initial_positions(),
            &s.initial_velocities(),
            0.0,
        )
        .unwrap();
        assert!((2.0 * lambda[0] * 1.5 - 2.0 * 9.81).abs() < 1e-12);
        assert!(acc[1].iter().all(|x| x.abs() < 1e-12));
    }

    /// A line node between two fixed neighbours on the x axis, pushed by a force F: its
    /// consistent acceleration is F_x / (m + CaAx rho V) along the line and
    /// F_y / (m + Ca rho V) across it (MoorDyn's node mass matrix, Newton's second law).
    #[test]
    fn consistent_acceleration_of_a_line_node_has_the_axial_added_mass() {
        use crate::laws::VectorLaw;
        let (mut s, n, rho_v) = crate::integrators::fixtures::line_node_between_fixed_neighbours();
        let force = [2.0, -5.0, 0.0];
        s.add_force(n, VectorLaw::constant(force)).unwrap();
        let mut ws = StepWorkspace::new(&s, 64);
        let (q, v) = (s.initial_positions(), s.initial_velocities());
        let (acc, _) = consistent_accelerations(&s, &mut ws, &q, &v, 0.0).unwrap();
        let expected = [
            force[0] / (3.0 + 0.25 * rho_v),
            force[1] / (3.0 + rho_v),
            0.0,
        ];
        for k in 0..3 {
            assert!(
                (acc[1][k] - expected[k]).abs() < 1e-14,
                "{:?} vs {expected:?}",
                acc[1]
            );
        }
    }
}
