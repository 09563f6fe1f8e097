//! Linear solvers behind one contract: analyse a pattern once ([`LinearSolver`] constructors),
//! factorise new values, solve in place. Symbolic work and workspace are allocated once, so the
//! Newton loop does not allocate.

pub(crate) mod block_slots;
mod dense_lu;
mod sparse_lu;
mod tree_elimination;

pub use dense_lu::DenseLu;
pub use sparse_lu::SparseLu;
pub use tree_elimination::{TreeElimination, TWO_SIDED_FROM};

use rayon::prelude::*;

use crate::assembly::{Pattern, Storage};

/// Why a factorisation failed.
#[derive(Debug, Clone, PartialEq)]
pub struct Singular {
    /// The unknown (column) at which no usable pivot was found, if known.
    pub column: Option<usize>,
    /// What the solver reported.
    pub detail: String,
}

/// A direct solver for matrices of one fixed pattern.
pub trait LinearSolver: Send {
    /// Factorises the matrix with these values (in the pattern's slot order).
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular>;
    /// Overwrites `rhs` with the solution of A x = rhs, using the last factorisation.
    fn solve_in_place(&mut self, rhs: &mut [f64]);
    /// [`LinearSolver::solve_in_place`], returning the infinity norm of the solution (NaN if an
    /// entry is NaN), which Newton's method asks of every increment: a solver that writes the
    /// solution back in a pass of its own takes the norm in that pass instead of another.
    fn solve_in_place_with_norm(&mut self, rhs: &mut [f64]) -> f64 {
        self.solve_in_place(rhs);
        crate::integrators::newton::inf_norm(rhs)
    }
    /// Short name, for statistics.
    fn name(&self) -> &'static str;
    /// Factorisations that a solver specialised to a structure handed to the general sparse LU
    /// because its own pivots were (nearly) singular (see [`TreeElimination`]).
    fn fallbacks(&self) -> usize {
        0
    }
    /// Whether the matrix is assembled into the solver's own storage and factorised there
    /// ([`TreeElimination::assemble_in_place`]), instead of being read from the caller's value
    /// array: see [`assemble_and_factor`].
    fn in_place(&self) -> bool {
        false
    }
    /// The storage to assemble the matrix into, in the layout of the slots the solver gave
    /// (solvers that factorise in place; None for the others).
    fn storage(&mut self) -> Option<&mut [f64]> {
        None
    }
    /// Factorises the matrix assembled in [`LinearSolver::storage`], overwriting it with the
    /// factors.
    fn factor_stored(&mut self) -> Result<Stored, Singular> {
        Err(not_in_place())
    }
    /// After [`Stored::AssembleAgain`], with the matrix assembled into the storage again:
    /// factorises it with the general sparse LU.
    fn factor_stored_by_fallback(&mut self) -> Result<(), Singular> {
        Err(not_in_place())
    }
    /// The last factorisation as numbers, for a snapshot: solvers that factorise in place, whose
    /// matrix no caller keeps (None for the others, and when the factorisation is not in the
    /// storage).
    fn factors(&self) -> Option<Vec<f64>> {
        None
    }
    /// Takes the factors that [`LinearSolver::factors`] gave for a solver of the same analysis;
    /// false (and nothing factorised) when they are not of its size.
    fn adopt_factors(&mut self, _factors: &[f64]) -> bool {
        false
    }
}

fn not_in_place() -> Singular {
    Singular {
        column: None,
        detail: "this solver reads the matrix from the caller's value array".into(),
    }
}

/// What a factorisation of a solver's own storage came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stored {
    /// Factorised.
    Factorised,
    /// A block was (nearly) singular, and the elimination had already overwritten part of the
    /// matrix: assemble it into the storage again and call
    /// [`LinearSolver::factor_stored_by_fallback`].
    AssembleAgain,
}

/// Assembles a matrix and factorises it: `assemble` adds its entries into a zeroed array, the
/// solver's own storage when it factorises in place (a second time when a singular block sends
/// the factorisation to the general sparse LU), else `values`, in the pattern's order.
pub fn assemble_and_factor(
    solver: &mut dyn LinearSolver,
    values: &mut [f64],
    mut assemble: impl FnMut(&mut [f64]),
) -> Result<(), Singular> {
    if !solver.in_place() {
        zero(values);
        assemble(values);
        return solver.factor(values);
    }
    let mut fill = |solver: &mut dyn LinearSolver| {
        let store = solver.storage().expect("a solver in place has a storage");
        zero(store);
        assemble(store);
    };
    fill(solver);
    if solver.factor_stored()? == Stored::AssembleAgain {
        fill(solver);
        solver.factor_stored_by_fallback()?;
    }
    Ok(())
}

/// Length of a matrix storage from which [`zero`] runs on rayon's pool: 2^22 entries (32 MB),
/// far beyond the caches, where waking the pool costs nothing next to the pass. Measured on the
/// 10^6-particle swinging chain (320 MB of storage, 14 factorisations in 13 steps): 0.445 s of
/// zeroing on one thread, 0.236 s on two, 4 % of its steps' time.
pub const PARALLEL_ZERO_FROM: usize = 1 << 22;

/// Sets every entry of a matrix storage to zero: on rayon's pool from [`PARALLEL_ZERO_FROM`]
/// entries on.
pub fn zero(values: &mut [f64]) {
    if values.len() < PARALLEL_ZERO_FROM {
        values.fill(0.0);
    } else {
        values
            .par_chunks_mut(1 << 16)
            .for_each(|chunk| chunk.fill(0.0));
    }
}

/// Which solver a sparse pattern gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SparseSolver {
    /// Tree elimination when the pattern allows it (a tree of constraints whose other couplings
    /// join particles to their ancestors: linear cost), otherwise the general sparse LU.
    #[default]
    Auto,
    /// Always the general sparse LU.
    SparseLu,
}

/// The solver that suits the pattern's storage: dense LU for dense storage; for sparse storage,
/// block elimination along the tree when the pattern allows it (see [`TreeElimination`]) and
/// `choice` is `Auto`, else the general sparse LU. The first `particle_unknowns` unknowns are
/// the free particles' coordinates, 3 each.
pub fn for_layout(
    pattern: &Pattern,
    particle_unknowns: usize,
    choice: SparseSolver,
) -> Box<dyn LinearSolver> {
    match (pattern.storage, choice) {
        (Storage::Dense, _) => Box::new(DenseLu::new(pattern.n)),
        (Storage::Sparse, SparseSolver::SparseLu) => Box::new(SparseLu::new(pattern)),
        (Storage::Sparse, SparseSolver::Auto) => {
            match TreeElimination::analyse(pattern, particle_unknowns) {
                Some(tree) => Box::new(tree),
                None => Box::new(SparseLu::new(pattern)),
            }
        }
    }
}

/// The solver that suits the pattern's storage (dense LU or general sparse LU).
pub fn for_pattern(pattern: &Pattern) -> Box<dyn LinearSolver> {
    for_layout(pattern, 0, SparseSolver::SparseLu)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A storage long enough to be zeroed on the pool is zeroed in every entry, the chunks'
    /// seams and the short last chunk included.
    #[test]
    fn a_long_storage_is_zeroed_everywhere() {
        let mut values: Vec<f64> = (0..PARALLEL_ZERO_FROM + 3)
            .map(|i| i as f64 + 1.0)
            .collect();
        zero(&mut values);
        assert!(values.iter().all(|&x| x == 0.0));
    }

    /// A 5x5 saddle-point matrix with a zero diagonal block, like the KKT systems solved here.
    fn kkt() -> (Vec<(usize, usize, f64)>, Vec<f64>) {
        let e = vec![
            (0, 0, 4.0),
            (1, 1, 3.0),
            (2, 2, 5.0),
            (0, 1, 0.5),
            (1, 0, 0.5),
            (0, 3, -1.0),
            (3, 0, 1.0),
            (1, 3, 2.0),
            (3, 1, -2.0),
            (2, 4, 1.5),
            (4, 2, 1.5),
            (1, 4, 0.3),
            (4, 1, 0.3),
        ];
        (e, vec![1.0, -2.0, 0.5, 0.25, 3.0])
    }

    fn residual(e: &[(usize, usize, f64)], x: &[f64], b: &[f64]) -> f64 {
        let mut r = b.to_vec();
        for &(i, j, v) in e {
            r[i] -= v * x[j];
        }
        r.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    #[test]
    fn sparse_and_dense_solve_a_saddle_point_system() {
        let (e, b) = kkt();
        for dense in [false, true] {
            let p = Pattern::new(5, e.iter().map(|&(i, j, _)| (i, j)).collect(), dense);
            let mut values = vec![0.0; p.nnz()];
            for &(i, j, v) in &e {
                values[p.slot(i, j)] += v;
            }
            let mut s = for_pattern(&p);
            s.factor(&values).unwrap();
            let mut x = b.clone();
            s.solve_in_place(&mut x);
            // Residual of the computed solution against the original matrix.
            assert!(residual(&e, &x, &b) < 1e-13, "{} residual", s.name());
        }
    }

    #[test]
    fn singular_matrix_is_reported() {
        // Two identical constraint rows: rank deficient.
        let e = vec![
            (0, 0, 1.0),
            (1, 1, 1.0),
            (0, 2, 1.0),
            (2, 0, 1.0),
            (0, 3, 1.0),
            (3, 0, 1.0),
        ];
        for dense in [false, true] {
            let p = Pattern::new(4, e.iter().map(|&(i, j, _)| (i, j)).collect(), dense);
            let mut values = vec![0.0; p.nnz()];
            for &(i, j, v) in &e {
                values[p.slot(i, j)] += v;
            }
            let mut s = for_pattern(&p);
            assert!(
                s.factor(&values).is_err(),
                "{} accepted a singular matrix",
                s.name()
            );
        }
    }
}
