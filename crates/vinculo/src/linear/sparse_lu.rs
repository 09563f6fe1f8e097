//! General sparse LU (faer): fill-reducing ordering and symbolic factorisation once per pattern,
//! numeric factorisation with partial pivoting per Newton iteration into reused storage.

use super::{LinearSolver, Singular};
use crate::assembly::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// Entries a column beyond which the supernodal factorisation is taken (see [`SparseLu::new`]).
const DENSE_COLUMN: usize = 20;

/// Sparse LU of matrices sharing one pattern.
pub struct SparseLu {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factored: bool,
    work: MemBuffer,
}

impl SparseLu {
    /// Symbolic analysis of `pattern`.
    ///
    /// # Panics
    /// If faer cannot analyse the pattern (out of memory).
    pub fn new(pattern: &Pattern) -> SparseLu {
        let n = pattern.n;
        let structure =
            SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        // The supernodal factorisation for matrices with dense columns: faer's automatic choice
        // takes the simplicial one for the matrices of mechanisms (bodies of 4 to 7 particles
        // joined by 8-particle joint equations, 25 or more entries a column), which factorises
        // them about twice as slowly (a chain of 50 rigid bodies, 1,150 unknowns: 1.6 ms against
        // 0.8 ms a factorisation; 3 bodies: 0.05 against 0.03 ms; `python -m vinculo.bench
        // rigid-chain`), while it is the faster one for chains (11 entries a column: 0.78
        // against 1.15 ms at 1,000 particles, `cargo bench --bench kernels -- sparse`).
        let dense_columns = pattern.row_idx.len() > DENSE_COLUMN * n;
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: if dense_columns {
                SupernodalThreshold::FORCE_SUPERNODAL
            } else {
                SupernodalThreshold::AUTO
            },
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_lu(structure, params).expect("symbolic LU analysis failed");
        let req = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        SparseLu {
            n,
            col_ptr: pattern.col_ptr.clone(),
            row_idx: pattern.row_idx.clone(),
            symbolic,
            numeric: NumericLu::new(),
            factored: false,
            work: MemBuffer::new(req),
        }
    }
}

impl LinearSolver for SparseLu {
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        let n = self.n;
        let structure = unsafe {
            SymbolicSparseColMatRef::new_unchecked(n, n, &self.col_ptr, None, &self.row_idx)
        };
        let a = SparseColMatRef::new(structure, values);
        self.factored = false;
        match self.symbolic.factorize_numeric_lu(
            &mut self.numeric,
            a,
            Par::Seq,
            MemStack::new(&mut self.work),
            Default::default(),
        ) {
            Ok(_) => {
                self.factored = true;
                Ok(())
            }
            Err(LuError::SymbolicSingular { index }) => {
                let column = self.symbolic.col_perm().arrays().0.get(index).copied();
                Err(Singular {
                    column,
                    detail: format!("no pivot found at elimination step {index}"),
                })
            }
            Err(e) => Err(Singular {
                column: None,
                detail: format!("{e:?}"),
            }),
        }
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorisation");
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let b = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        lu.solve_in_place_with_conj(Conj::No, b, Par::Seq, MemStack::new(&mut self.work));
    }

    fn name(&self) -> &'static str {
        "sparse LU"
    }
}
