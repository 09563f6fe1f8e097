//! Residual and Jacobian assembly in one thread: the elements' local values and derivatives
//! placed into the scaled residual and the iteration matrix's value array, from the same
//! [`ResidualTerms`] and [`JacobianTerms`] as the parallel assembly (`parallel.rs`), whose
//! residual equals this one bit for bit.

use super::JacobianTerms;
use super::{InertiaRows, Layout, ResidualTerms, NONE};
use crate::constraints::Hessian;
use crate::forces::{Jacobian, TangentCache};
use crate::math::Vec3;
use crate::model::System;

impl Layout {
    /// Writes the scaled residual: `row.rows(i)` is the start of the three rows of free particle i
    /// (its inertia and gravity terms); then each force's local forces and each constraint's
    /// gradient term at the evaluation point are subtracted, and each constraint's row
    /// s_k Phi_k(q_end, t_end) written (a compliant constraint's row is
    /// s_k (w Phi_k(q_end, t_end) + (1 - w) Phi_k(q_n, t_n) + c_k lambda_k) instead, see
    /// [`ResidualTerms::row`]).
    #[inline(always)]
    pub fn residual(
        &self,
        system: &System,
        at: &ResidualTerms<'_>,
        r: &mut [f64],
        row: &impl InertiaRows,
    ) {
        let sigma = at.sigma;
        for (i, &d) in self.dof.iter().enumerate() {
            if d != NONE {
                r[d..d + 3].copy_from_slice(&row.rows(i));
            }
        }
        // The rows of the particles each force acts on (a line node's loads act on the node
        // alone, its neighbours only giving the tangent).
        let mut tangents = TangentCache::for_configuration();
        let point = (at.q_eval, at.v_eval, at.t_eval);
        for f in system.forces() {
            f.for_each_acting(point, &mut tangents, |p, fp| {
                self.subtract_row(r, p, sigma, fp)
            });
        }
        let same_point = at.same_point();
        let m3 = 3 * self.free;
        for (c, con) in system.constraints().iter().enumerate() {
            let parts = con.particles();
            // One evaluation serves the rows and the gradients where they share a point; a
            // damped segment's damping tension, which joins its multiplier's, takes the other
            // path, so that this closure stays small enough to be inlined into each constraint
            // kind's arm (the pendulum's step: 4,997 -> 4,868 instructions).
            let phi = if same_point && con.damped_segment().is_none() {
                let weight = sigma * at.lambda[c];
                con.with_residual_and_gradient(at.q_end, at.t_end, |phi, grad| {
                    self.subtract_rows(r, parts, weight, grad);
                    phi
                })
            } else {
                con.with_gradient(at.q_eval, at.t_eval, |grad| {
                    let weight = at.gradient_weight(con, c, grad);
                    self.subtract_rows(r, parts, weight, grad)
                });
                con.residual(at.q_end, at.t_end)
            };
            r[m3 + c] = at.scales[c] * at.row(con, c, phi);
        }
    }

    /// Adds the scaled Jacobian into `values` (zeroed by the caller): `mass(i)` on the diagonal
    /// of particle i's block, then the forces' and constraints' terms.
    pub fn jacobian(
        &self,
        system: &System,
        at: &JacobianTerms<'_>,
        values: &mut [f64],
        mass: impl Fn(usize) -> f64,
    ) {
        for i in 0..self.dof.len() {
            self.add_to_particle_diagonal(values, i, mass(i));
        }
        // One buffer of local blocks for all elements, reset to each one's size.
        let (mut dq, mut dv) = (Jacobian::zeros(0), Jacobian::zeros(0));
        for (fi, f) in system.forces().iter().enumerate() {
            self.add_force_terms(values, (fi, f), (&mut dq, &mut dv), at);
        }
        let mut hess = Hessian::zeros(0);
        for (c, con) in system.constraints().iter().enumerate() {
            self.add_constraint_terms(values, (c, con, &mut hess), at);
        }
    }

    /// Subtracts `weight f` from the dynamics rows of particle `p` (nothing for a fixed one).
    #[inline(always)]
    fn subtract_row(&self, r: &mut [f64], p: usize, weight: f64, f: Vec3) {
        let d = self.dof[p];
        if d != NONE {
            let row: &mut [f64; 3] = (&mut r[d..d + 3]).try_into().expect("3 rows");
            row[0] -= weight * f[0];
            row[1] -= weight * f[1];
            row[2] -= weight * f[2];
        }
    }

    /// Subtracts `weight rows[x]` from the dynamics rows of each free particle `parts[x]`.
    #[inline(always)]
    fn subtract_rows(&self, r: &mut [f64], parts: &[usize], weight: f64, rows: &[Vec3]) {
        for (x, &p) in parts.iter().enumerate() {
            self.subtract_row(r, p, weight, rows[x]);
        }
    }
}
