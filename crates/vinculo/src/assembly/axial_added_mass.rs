//! The axial correction of line nodes' added mass (`docs/theory/seabed-and-line-loads.md`):
//! MoorDyn's node mass matrix m I + rho V (Ca (I - t t^T) + CaAx t t^T) is the particle's
//! scalar inertia m + Ca rho V plus C_i(q) = -e_i t t^T, e_i = (Ca - CaAx) rho V
//! ([`LineHydro::axial_excess`]), with t the node's tangent at the positions the forces use.
//!
//! # In a step
//!
//! A step problem's dynamics row of particle i is sigma (inertia_i qdd_i(q) - m_i g - f_i - ...),
//! qdd_i the rule's acceleration, linear in the iterate q_i with slope c (the rule's
//! `mass_diagonal(1, 1)`). The corrected row adds sigma C_i(q_e) qdd_i(q), whose derivatives are
//!
//! ```text
//! d/dq_i (through qdd)        sigma c C_i(q_e)                 (the mass block's slope)
//! d/dq_y (through t, y = the particles of the tangent)
//!                             sigma w d(C_i a)/dq_e,y = -sigma w d(-C_i a)/dq_e,y at a = qdd_i
//! ```
//!
//! with w = dq_e/dq the evaluation point's weight: -C_i a = e_i t (t . a) is placed as a force
//! of the node would be, with the weight of df/dq (-sigma w), into the blocks of the node's
//! [`LineHydro`] element (its row, the columns of its tangent's particles).
//!
//! The correction is evaluated at q_e, not at q: like the forces, so that the trapezoidal rule
//! keeps its order, and a step's Jacobian has no other blocks than the forces'. The kinetic
//! energy ([`crate::model::System::kinetic_energy`]) stays 1/2 m |v|^2 with the particle's own
//! mass: the added mass's energy is the fluid's, not counted.

use super::{Block, Entries, SlotTable, NONE};
use crate::forces::{unit_chord, Force, Jacobian, LineHydro};
use crate::math::{dot, scale, Mat3, Vec3};
use crate::model::System;

/// What receives a table's blocks (see [`AxialAddedMass::add_jacobian`]).
pub type BlockVisit<'a> = dyn FnMut(&[Block]) + 'a;

/// The line nodes whose added mass is anisotropic (CaAx != Ca), found once per run.
#[derive(Debug, Clone, Default)]
pub struct AxialAddedMass {
    /// (index of the [`LineHydro`] force, the element).
    nodes: Vec<(usize, LineHydro)>,
    /// What the residual's rows need of each node, in the order of `nodes`.
    rows: Vec<AxialRow>,
}

/// One node's correction in the residual: C_i a = -e t (t . a), t = unit(q_b - q_a).
#[derive(Debug, Clone, Copy)]
struct AxialRow {
    /// The node's particle i.
    node: usize,
    /// The particles (a, b) of its tangent.
    ends: [usize; 2],
    /// e_i = (Ca - CaAx) rho V ([`LineHydro::axial_excess`]).
    excess: f64,
}

impl AxialAddedMass {
    /// The [`LineHydro`] elements of `system` with (Ca - CaAx) rho V != 0 and a tangent.
    pub fn new(system: &System) -> AxialAddedMass {
        let nodes = system
            .forces()
            .iter()
            .enumerate()
            .filter_map(|(k, f)| match f {
                Force::LineHydro(h) if h.axial_excess() != 0.0 && h.node.tangent.is_some() => {
                    Some((k, (**h).clone()))
                }
                _ => None,
            })
            .collect::<Vec<_>>();
        let rows = nodes
            .iter()
            .filter_map(|(_, h)| {
                let [a, b] = h.node.tangent?;
                let p = &h.node.particles;
                Some(AxialRow {
                    node: h.node.node(),
                    ends: [p[a], p[b]],
                    excess: h.axial_excess(),
                })
            })
            .collect();
        AxialAddedMass { nodes, rows }
    }

    /// The number of corrected nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when every node's added mass is isotropic (nothing to correct).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Adds `weight` C_i(q) a_i into the rows `r[dof[i]..]` of each free node i, with a_i =
    /// `acceleration(i)`: the correction's inertia term (weight sigma in a step's residual,
    /// 1/m_ref in a right-hand side M a / m_ref).
    pub fn add_rows(
        &self,
        dof: &[usize],
        r: &mut [f64],
        (q, weight): (&[Vec3], f64),
        acceleration: impl Fn(usize) -> Vec3,
    ) {
        // The correction's inertia term C_i(q) a = -e t (t . a) from the node's own data (its
        // tangent at q as [`LineHydro`]'s, zero without one).
        for row in &self.rows {
            let d = dof[row.node];
            if d != NONE {
                let a = acceleration(row.node);
                let ca = match unit_chord(q[row.ends[0]], q[row.ends[1]]) {
                    Some((t, _)) => scale(-row.excess * dot(t, a), t),
                    None => [0.0; 3],
                };
                for k in 0..3 {
                    r[d + k] += weight * ca[k];
                }
            }
        }
    }

    /// Adds `weight` C_i(q) into the diagonal block of each free node i (the mass blocks of a
    /// saddle matrix [M/m_ref, ...], weight 1/m_ref).
    pub fn add_mass_blocks<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        diagonal: &SlotTable<9>,
        q: &[Vec3],
        weight: f64,
    ) {
        for (_, h) in &self.nodes {
            values.add_block(&diagonal.get(h.node.node()), weight, &h.axial_correction(q));
        }
    }

    /// Adds the correction's part of a step's iteration matrix (module documentation): for each
    /// free node i at the evaluation point `q_eval`, `mass_weight` C_i into its diagonal block
    /// `diagonal(i)`, and `force_weight` d(-C_i a_i)/dq into the node's row of its
    /// [`LineHydro`] element's blocks (`force_row(k, n, f)` calls f with the first n blocks of
    /// force k's table, k the force's index), a_i = `acceleration(i)`.
    pub fn add_jacobian<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        (diagonal, force_row): (
            impl Fn(usize) -> Block,
            impl Fn(usize, usize, &mut BlockVisit),
        ),
        (q_eval, mass_weight, force_weight): (&[Vec3], f64, f64),
        acceleration: impl Fn(usize) -> Vec3,
    ) {
        let mut dq = Jacobian::zeros(0);
        for (k, h) in &self.nodes {
            let i = h.node.node();
            let diagonal = diagonal(i);
            if diagonal[0] == super::NO_SLOT {
                continue;
            }
            let n = h.node.particles().len();
            dq.reset(n);
            let c: Mat3 = h.axial_inertia_jacobian(q_eval, acceleration(i), &mut dq);
            values.add_block(&diagonal, mass_weight, &c);
            // The node's row: blocks (0, y) of the element's n x n table.
            force_row(*k, n, &mut |blocks| {
                for (b, m) in blocks.iter().zip(&dq[0][..n]) {
                    values.add_block(b, force_weight, m);
                }
            });
        }
    }
}
