//! Linear solvers behind one contract: analyse a pattern once ([`LinearSolver`] constructors),
//! factorise new values, solve in place. Symbolic work and workspace are allocated once, so the
//! Newton loop does not allocate.

mod dense_lu;
mod sparse_lu;

pub use dense_lu::DenseLu;
pub use sparse_lu::SparseLu;

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
    /// Short name, for statistics.
    fn name(&self) -> &'static str;
}

/// The solver that suits the pattern's storage.
pub fn for_pattern(pattern: &Pattern) -> Box<dyn LinearSolver> {
    match pattern.storage {
        Storage::Dense => Box::new(DenseLu::new(pattern.n)),
        Storage::Sparse => Box::new(SparseLu::new(pattern)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
