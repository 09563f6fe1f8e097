//! The iteration matrix's layout for the stabilised index-2 (GGL) formulation
//! ([`super::stabilized`]): unknowns, equations, pattern (computed once per model) and the slots
//! of every element's local blocks.
//!
//! With f free particles and m constraint equations, the unknowns (columns) are
//!
//! ```text
//! [ q (3f) | v~ (3f) | lambda~ (m) | mu~ (m) ]
//! ```
//!
//! and the equations (rows) are
//!
//! ```text
//! [ kinematics K (3f) | dynamics D (3f) | positions Phi (m) | velocities Psi (m) ]
//! ```
//!
//! (the tildes are the scaled unknowns of [`super::stabilized`]). The blocks that may be non-zero:
//!
//! ```text
//!          q                   v~               lambda~       mu~
//! K   [ I + Hessians of Phi,  -I,               0,            G^T      ]
//! D   [ forces, Hessians,     M + forces,       G^T,          0        ]
//! Phi [ G,                    0,                0,            0        ]
//! Psi [ G,                    G,                0,            0        ]
//! ```
//!
//! A constraint's blocks couple the particles it touches; a force's blocks the particles it acts
//! on. Nothing else is coupled: keeping v as an unknown (rather than eliminating it through the
//! kinematics, which would bring G G^T and f_v G^T fill between neighbouring elements) keeps
//! every block local.

use crate::assembly::{
    number_particles, push_column, push_pair_blocks, push_row, Block, ElementOffsets, Pattern,
    Slot, NONE, NO_SLOT,
};
use crate::model::System;

/// Where each element writes in the stabilised iteration matrix. The per-constraint and
/// per-force tables hold one entry per touched particle (the strips of 3 slots) or per ordered
/// pair of touched particles (the blocks), from the element's offsets
/// ([`crate::assembly::ElementOffsets`]).
#[derive(Debug, Clone)]
pub struct StabilizedLayout {
    /// First position unknown of each particle (NONE for fixed particles); its velocity unknowns
    /// start at `dof + 3 free`.
    pub dof: Vec<usize>,
    /// Number of free particles.
    pub free: usize,
    /// Number of constraint equations.
    pub constraints: usize,
    /// Sparsity pattern (or dense storage for small systems).
    pub pattern: Pattern,
    /// Per particle: kinematic rows, position columns (the identity).
    pub kinematic_q: Vec<Block>,
    /// Per particle: kinematic rows, velocity columns (the diagonal -I).
    pub kinematic_v: Vec<[Slot; 3]>,
    /// Per particle: dynamic rows, velocity columns (the mass).
    pub dynamic_v: Vec<Block>,
    /// Where each constraint's entries start in the tables below.
    pub constraint_offsets: ElementOffsets,
    /// Per constraint and pair of its particles: kinematic rows, position columns (mu Hessian).
    pub kinematic_hessian: Vec<Block>,
    /// Per constraint and pair of its particles: dynamic rows, position columns (lambda Hessian).
    pub dynamic_hessian: Vec<Block>,
    /// Per constraint and particle: kinematic rows of the particle, its mu column.
    pub kinematic_mu: Vec<[Slot; 3]>,
    /// Per constraint and particle: dynamic rows of the particle, its lambda column.
    pub dynamic_lambda: Vec<[Slot; 3]>,
    /// Per constraint and particle: its position row, position columns of the particle.
    pub position_row: Vec<[Slot; 3]>,
    /// Per constraint and particle: its velocity row, position columns of the particle.
    pub velocity_row_q: Vec<[Slot; 3]>,
    /// Per constraint and particle: its velocity row, velocity columns of the particle.
    pub velocity_row_v: Vec<[Slot; 3]>,
    /// Where each force's entries start in the tables below.
    pub force_offsets: ElementOffsets,
    /// Per force and pair of its particles: dynamic rows, position columns.
    pub force_q: Vec<Block>,
    /// Per force and pair of its particles: dynamic rows, velocity columns.
    pub force_v: Vec<Block>,
}

impl StabilizedLayout {
    /// Numbers the unknowns and computes the pattern and slots of `system`. Systems with at most
    /// `dense_limit` unknowns use dense storage.
    pub fn new(system: &System, dense_limit: usize) -> StabilizedLayout {
        let (dof, free) = number_particles(system);
        let m = system.constraints().len();
        let n3 = 3 * free;
        let n = 2 * n3 + 2 * m;
        // Offsets of the velocity unknowns / dynamic rows, multipliers, and velocity rows.
        let (vel, lam, mu) = (n3, 2 * n3, 2 * n3 + m);
        let shift = |d: usize, by: usize| if d == NONE { NONE } else { d + by };

        let mut entries: Vec<(usize, usize)> = Vec::new();
        let block = |entries: &mut Vec<(usize, usize)>, a: usize, b: usize| {
            if a != NONE && b != NONE {
                for r in 0..3 {
                    for c in 0..3 {
                        entries.push((a + r, b + c));
                    }
                }
            }
        };
        for &d in &dof {
            block(&mut entries, d, d);
            if d != NONE {
                for r in 0..3 {
                    entries.push((d + r, vel + d + r));
                }
            }
            block(&mut entries, shift(d, vel), shift(d, vel));
        }
        for (k, c) in system.constraints().iter().enumerate() {
            for &a in c.particles() {
                for &b in c.particles() {
                    block(&mut entries, dof[a], dof[b]);
                    block(&mut entries, shift(dof[a], vel), dof[b]);
                }
                if dof[a] != NONE {
                    for r in 0..3 {
                        entries.push((dof[a] + r, mu + k));
                        entries.push((vel + dof[a] + r, lam + k));
                        entries.push((lam + k, dof[a] + r));
                        entries.push((mu + k, dof[a] + r));
                        entries.push((mu + k, vel + dof[a] + r));
                    }
                }
            }
        }
        for f in system.forces().iter().filter(|f| f.has_jacobian()) {
            for &a in &f.particles()[..f.acting()] {
                for &b in f.particles() {
                    block(&mut entries, shift(dof[a], vel), dof[b]);
                    block(&mut entries, shift(dof[a], vel), shift(dof[b], vel));
                }
            }
        }
        let pattern = Pattern::new(n, entries, n <= dense_limit);
        let slot = |row: usize, col: usize| pattern.slot32(row, col);
        let block_slots = |a: usize, b: usize| pattern.block_slots(a, b);
        let kinematic_q = dof.iter().map(|&d| block_slots(d, d)).collect();
        let kinematic_v = dof
            .iter()
            .map(|&d| {
                if d == NONE {
                    [NO_SLOT; 3]
                } else {
                    [0, 1, 2].map(|r| slot(d + r, vel + d + r))
                }
            })
            .collect();
        let dynamic_v = dof
            .iter()
            .map(|&d| block_slots(shift(d, vel), shift(d, vel)))
            .collect();
        let cons = system.constraints();
        let constraint_offsets = ElementOffsets::new(cons.iter().map(|c| c.particles()));
        let pairs = || Vec::with_capacity(constraint_offsets.pair_entries());
        let strips = || Vec::with_capacity(constraint_offsets.particle_entries());
        let (mut kinematic_hessian, mut dynamic_hessian) = (pairs(), pairs());
        let (mut kinematic_mu, mut dynamic_lambda) = (strips(), strips());
        let (mut position_row, mut velocity_row_q, mut velocity_row_v) =
            (strips(), strips(), strips());
        for (k, c) in cons.iter().enumerate() {
            let parts = c.particles();
            push_pair_blocks(
                &mut kinematic_hessian,
                &pattern,
                parts,
                parts.len(),
                &dof,
                (0, 0),
            );
            push_pair_blocks(
                &mut dynamic_hessian,
                &pattern,
                parts,
                parts.len(),
                &dof,
                (vel, 0),
            );
            push_column(&mut kinematic_mu, &pattern, parts, &dof, (0, mu + k));
            push_column(&mut dynamic_lambda, &pattern, parts, &dof, (vel, lam + k));
            push_row(&mut position_row, &pattern, parts, &dof, (lam + k, 0));
            push_row(&mut velocity_row_q, &pattern, parts, &dof, (mu + k, 0));
            push_row(&mut velocity_row_v, &pattern, parts, &dof, (mu + k, vel));
        }
        let forces = system.forces();
        let force_offsets = ElementOffsets::new(forces.iter().map(|f| f.particles()));
        let (mut force_q, mut force_v) = (
            Vec::with_capacity(force_offsets.pair_entries()),
            Vec::with_capacity(force_offsets.pair_entries()),
        );
        for f in forces {
            let parts = f.particles();
            if f.has_jacobian() {
                push_pair_blocks(&mut force_q, &pattern, parts, f.acting(), &dof, (vel, 0));
                push_pair_blocks(&mut force_v, &pattern, parts, f.acting(), &dof, (vel, vel));
            } else {
                let none = std::iter::repeat_n([NO_SLOT; 9], parts.len() * parts.len());
                force_q.extend(none.clone());
                force_v.extend(none);
            }
        }
        StabilizedLayout {
            kinematic_q,
            kinematic_v,
            dynamic_v,
            constraint_offsets,
            kinematic_hessian,
            dynamic_hessian,
            kinematic_mu,
            dynamic_lambda,
            position_row,
            velocity_row_q,
            velocity_row_v,
            force_offsets,
            force_q,
            force_v,
            dof,
            free,
            constraints: m,
            pattern,
        }
    }

    /// Total number of unknowns, 6 per free particle and 2 per constraint.
    pub fn unknowns(&self) -> usize {
        6 * self.free + 2 * self.constraints
    }

    /// The index-3 numbering ([`crate::assembly::Layout`]) of equation `i`, by which failures are
    /// reported: a particle's kinematic and dynamic rows map to its dynamics, a constraint's
    /// position and velocity rows to the constraint.
    pub fn index3_equation(&self, i: usize) -> usize {
        let (n3, m) = (3 * self.free, self.constraints);
        if i < n3 {
            i
        } else if i < 2 * n3 + m {
            // Dynamic rows of the particles, then the position rows of the constraints.
            i - n3
        } else {
            i - n3 - m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::every_kind;

    /// Every slot is in the pattern (a missing entry panics in `Pattern::slot`), and the pattern
    /// has exactly the structural entries counted by hand for a pendulum (1 free particle, one
    /// distance to a fixed anchor): 9 in (K,q) for the identity and the mu Hessian, 3 on the
    /// (K,v) diagonal, 9 in (D,v), 9 in (D,q) for the lambda Hessian, and 3 each in (K,mu),
    /// (D,lambda), (Phi,q), (Psi,q) and (Psi,v): 45 in all.
    #[test]
    fn pendulum_pattern_has_the_expected_entries() {
        let s = crate::integrators::fixtures::pendulum();
        let layout = StabilizedLayout::new(&s, 0);
        assert_eq!(layout.unknowns(), 8);
        assert_eq!(layout.pattern.nnz(), 45);
        // Index-3 numbering: the constraint is unknown 3 there.
        assert_eq!(
            (0..8)
                .map(|i| layout.index3_equation(i))
                .collect::<Vec<_>>(),
            vec![0, 1, 2, 0, 1, 2, 3, 3]
        );
        // Slots of every kind of element exist for the system with every kind.
        let layout = StabilizedLayout::new(&every_kind(), 0);
        assert_eq!(layout.unknowns(), 6 * 3 + 2 * 5);
    }
}
