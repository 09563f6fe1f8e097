//! Residual and Jacobian assembly in one thread: the elements' local values and derivatives
//! placed into the scaled residual and the iteration matrix's value array, from the same
//! [`ResidualTerms`] and [`JacobianTerms`] as the parallel assembly (`parallel.rs`), whose
//! residual equals this one bit for bit.

use super::JacobianTerms;
use super::{add_force_blocks, InertiaRows, Layout, ResidualTerms, NONE};
use crate::constraints::Hessian;
use crate::forces::Jacobian;
use crate::model::System;

impl Layout {
    /// Writes the scaled residual: `row.rows(i)` is the start of the three rows of free particle i
    /// (its inertia and gravity terms); then each force's local forces and each constraint's
    /// gradient term at the evaluation point are subtracted, and each constraint's row
    /// s_k Phi_k(q_end, t_end) written.
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
        for f in system.forces() {
            let fl = f.force(at.q_eval, at.v_eval, at.t_eval);
            for (x, &p) in f.particles().iter().enumerate() {
                let d = self.dof[p];
                if d != NONE {
                    for k in 0..3 {
                        r[d + k] -= sigma * fl[x][k];
                    }
                }
            }
        }
        let same_point = at.same_point();
        let m3 = 3 * self.free;
        for (c, con) in system.constraints().iter().enumerate() {
            let (phi, grad) = if same_point {
                con.residual_and_gradient(at.q_end, at.t_end)
            } else {
                let grad = con.gradient(at.q_eval, at.t_eval);
                (con.residual(at.q_end, at.t_end), grad)
            };
            let weight = sigma * at.lambda[c];
            for (x, &p) in con.particles().iter().enumerate() {
                let d = self.dof[p];
                if d != NONE {
                    let row = &mut r[d..d + 3];
                    for k in 0..3 {
                        row[k] -= weight * grad[x][k];
                    }
                }
            }
            r[m3 + c] = at.scales[c] * phi;
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
        for (fi, f) in system.forces().iter().enumerate() {
            if !f.has_jacobian() {
                continue;
            }
            let n = f.particles().len();
            let mut dq = Jacobian::zeros(n);
            let mut dv = Jacobian::zeros(n);
            f.add_jacobian(at.q_eval, at.v_eval, at.t_eval, &mut dq, &mut dv);
            let blocks = &self.force_block[self.force_offsets.pairs(fi)];
            add_force_blocks(
                blocks,
                blocks,
                (at.force_dq, &dq),
                (at.force_dv, &dv),
                |b, s, m| super::add_block(values, b, s, m),
            );
        }
        let same_point = at.same_point();
        for (c, con) in system.constraints().iter().enumerate() {
            let mut hess = Hessian::zeros(con.particles().len());
            con.add_hessian(at.q_eval, at.t_eval, at.hessian * at.lambda[c], &mut hess);
            let grad_eval = con.gradient(at.q_eval, at.t_eval);
            let grad_end = if same_point {
                None
            } else {
                Some(con.gradient(at.q_end, at.t_end))
            };
            let grads = (&grad_eval[..], grad_end.as_deref().unwrap_or(&grad_eval));
            self.add_constraint_blocks(c, &hess, at.scales[c], grads, |slot, v| {
                super::add(values, slot, v)
            });
        }
    }
}
