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

use crate::assembly::{number_particles, Block, ForceBlocks, Pattern, Slot, NONE, NO_SLOT};
use crate::forces::MAX_FORCE_PARTICLES;
use crate::model::System;

/// Slots of a constraint's 3-vector row or column, per touched particle.
pub type Strip = [[Slot; 3]; 2];
/// Slots of 3x3 blocks between the (at most two) particles an element touches.
pub type PairBlocks = [[Block; 2]; 2];

/// Where each element writes in the stabilised iteration matrix.
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
    /// Per constraint: kinematic rows, position columns, between its particles (mu Hessian).
    pub kinematic_hessian: Vec<PairBlocks>,
    /// Per constraint: dynamic rows, position columns, between its particles (lambda Hessian).
    pub dynamic_hessian: Vec<PairBlocks>,
    /// Per constraint: kinematic rows of its particles, its mu column.
    pub kinematic_mu: Vec<Strip>,
    /// Per constraint: dynamic rows of its particles, its lambda column.
    pub dynamic_lambda: Vec<Strip>,
    /// Per constraint: its position row, position columns of its particles.
    pub position_row: Vec<Strip>,
    /// Per constraint: its velocity row, position columns of its particles.
    pub velocity_row_q: Vec<Strip>,
    /// Per constraint: its velocity row, velocity columns of its particles.
    pub velocity_row_v: Vec<Strip>,
    /// Per force: dynamic rows, position columns.
    pub force_q: Vec<ForceBlocks>,
    /// Per force: dynamic rows, velocity columns.
    pub force_v: Vec<ForceBlocks>,
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
            for &a in f.particles() {
                for &b in f.particles() {
                    block(&mut entries, shift(dof[a], vel), dof[b]);
                    block(&mut entries, shift(dof[a], vel), shift(dof[b], vel));
                }
            }
        }
        let pattern = Pattern::new(n, entries, n <= dense_limit);
        let slot = |row: usize, col: usize| pattern.slot32(row, col);
        let block_slots = |a: usize, b: usize| pattern.block_slots(a, b);
        // Blocks between an element's particles: rows shifted by `row`, columns by `col`.
        let pair_blocks = |parts: &[usize], row: usize, col: usize| -> PairBlocks {
            let mut out = [[[NO_SLOT; 9]; 2]; 2];
            for (x, &a) in parts.iter().enumerate() {
                for (y, &b) in parts.iter().enumerate() {
                    out[x][y] = block_slots(shift(dof[a], row), shift(dof[b], col));
                }
            }
            out
        };
        // A constraint's column (its particles' rows, shifted) and row (their columns, shifted).
        let column = |parts: &[usize], row_shift: usize, col: usize| -> Strip {
            let mut out = [[NO_SLOT; 3]; 2];
            for (x, &p) in parts.iter().enumerate() {
                if dof[p] != NONE {
                    for r in 0..3 {
                        out[x][r] = slot(dof[p] + row_shift + r, col);
                    }
                }
            }
            out
        };
        let row = |parts: &[usize], row: usize, col_shift: usize| -> Strip {
            let mut out = [[NO_SLOT; 3]; 2];
            for (x, &p) in parts.iter().enumerate() {
                if dof[p] != NONE {
                    for c in 0..3 {
                        out[x][c] = slot(row, dof[p] + col_shift + c);
                    }
                }
            }
            out
        };

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
        let forces = system.forces();
        let no_blocks = [[[NO_SLOT; 9]; MAX_FORCE_PARTICLES]; MAX_FORCE_PARTICLES];
        let force_blocks = |parts: &[usize], row: usize, col: usize| -> ForceBlocks {
            let mut out = no_blocks;
            for (x, &a) in parts.iter().enumerate() {
                for (y, &b) in parts.iter().enumerate() {
                    out[x][y] = block_slots(shift(dof[a], row), shift(dof[b], col));
                }
            }
            out
        };
        StabilizedLayout {
            kinematic_q,
            kinematic_v,
            dynamic_v,
            kinematic_hessian: cons
                .iter()
                .map(|c| pair_blocks(c.particles(), 0, 0))
                .collect(),
            dynamic_hessian: cons
                .iter()
                .map(|c| pair_blocks(c.particles(), vel, 0))
                .collect(),
            kinematic_mu: cons
                .iter()
                .enumerate()
                .map(|(k, c)| column(c.particles(), 0, mu + k))
                .collect(),
            dynamic_lambda: cons
                .iter()
                .enumerate()
                .map(|(k, c)| column(c.particles(), vel, lam + k))
                .collect(),
            position_row: cons
                .iter()
                .enumerate()
                .map(|(k, c)| row(c.particles(), lam + k, 0))
                .collect(),
            velocity_row_q: cons
                .iter()
                .enumerate()
                .map(|(k, c)| row(c.particles(), mu + k, 0))
                .collect(),
            velocity_row_v: cons
                .iter()
                .enumerate()
                .map(|(k, c)| row(c.particles(), mu + k, vel))
                .collect(),
            force_q: forces
                .iter()
                .map(|f| {
                    if f.has_jacobian() {
                        force_blocks(f.particles(), vel, 0)
                    } else {
                        no_blocks
                    }
                })
                .collect(),
            force_v: forces
                .iter()
                .map(|f| {
                    if f.has_jacobian() {
                        force_blocks(f.particles(), vel, vel)
                    } else {
                        no_blocks
                    }
                })
                .collect(),
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
        let mut s = System::new([0.0, 0.0, -9.81]);
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s
            .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_distance(a, b, None).unwrap();
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
