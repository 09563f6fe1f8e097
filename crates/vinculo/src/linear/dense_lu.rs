//! Dense LU with partial pivoting (faer), for small systems where sparse bookkeeping costs more
//! than it saves (a pendulum, a rigid body or two).

use super::{LinearSolver, Singular};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, MatMut, MatRef, Par};

/// Dense LU of an n x n matrix stored column-major.
pub struct DenseLu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    work: MemBuffer,
}

impl DenseLu {
    /// Allocates storage and workspace for n x n matrices.
    pub fn new(n: usize) -> DenseLu {
        let req = factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default())
            .or(solve::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq));
        DenseLu {
            n,
            lu: vec![0.0; n * n],
            perm: vec![0; n],
            perm_inv: vec![0; n],
            work: MemBuffer::new(req),
        }
    }
}

impl LinearSolver for DenseLu {
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        let n = self.n;
        self.lu.copy_from_slice(values);
        let a = MatMut::from_column_major_slice_mut(&mut self.lu, n, n);
        factor::lu_in_place(
            a,
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.work),
            Default::default(),
        );
        // A zero or non-finite pivot, or one at the round-off of the largest (n eps of it),
        // means a singular matrix. Small pivots above that are legitimate: a particle of 1e-9 kg
        // in a chain of 1e3 kg ones has a pivot 1e-12 of the largest in a direction its links
        // do not hold, and partial pivoting solves such a system to round-off (backward stable).
        let pivots: Vec<f64> = (0..n).map(|i| self.lu[i * n + i].abs()).collect();
        let largest = pivots.iter().cloned().fold(0.0, f64::max);
        for (i, &p) in pivots.iter().enumerate() {
            if !p.is_finite() || p <= largest * f64::EPSILON * n as f64 {
                return Err(Singular {
                    column: Some(i),
                    detail: format!("pivot {p:.3e} in column {i} (largest {largest:.3e})"),
                });
            }
        }
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let n = self.n;
        let lu = MatRef::from_column_major_slice(&self.lu, n, n);
        let perm = unsafe { PermRef::new_unchecked(&self.perm, &self.perm_inv, n) };
        let b = MatMut::from_column_major_slice_mut(rhs, n, 1);
        solve::solve_in_place_with_conj(
            lu,
            lu,
            perm,
            Conj::No,
            b,
            Par::Seq,
            MemStack::new(&mut self.work),
        );
    }

    fn name(&self) -> &'static str {
        "dense LU"
    }
}
