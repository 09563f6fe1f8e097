//! Local values of an element (a force or a constraint equation) over any number of particles.
//!
//! An element touches n particles (`particles()`, any n >= 1). Its local values are
//! - one 3-vector per touched particle ([`PerParticle`]): a constraint's gradient
//!   dPhi/dq_x, a force's value on each particle;
//! - one 3x3 block per ordered pair of touched particles ([`Blocks`]): a constraint's Hessian
//!   d2Phi/dq_x dq_y, a force's Jacobians df_x/dq_y and df_x/dv_y.
//!
//! Both keep up to [`INLINE`] particles on the stack, so that the common elements (one to four
//! particles: distances, springs, bending, a point in a body) are evaluated without an
//! allocation, and spill to the heap beyond. The assembler places them through each element's
//! slot tables ([`crate::assembly::ElementOffsets`]), whatever n is.

use crate::math::{Mat3, Vec3};
use smallvec::SmallVec;

/// Touched particles kept inline (without an allocation).
pub const INLINE: usize = 4;

/// One 3-vector per touched particle, in the order of the element's `particles()`.
pub type PerParticle = SmallVec<[Vec3; INLINE]>;

/// One 3x3 block per ordered pair (x, y) of an element's touched particles: `b[x][y]` is the
/// block of particle x's rows and particle y's columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocks {
    n: usize,
    data: SmallVec<[Mat3; INLINE * INLINE]>,
}

impl Blocks {
    /// n x n zero blocks (for an element over n particles).
    #[inline]
    pub fn zeros(n: usize) -> Blocks {
        Blocks {
            n,
            data: SmallVec::from_elem([[0.0; 3]; 3], n * n),
        }
    }

    /// Number of touched particles n.
    #[inline]
    pub fn particles(&self) -> usize {
        self.n
    }

    /// Sets every block to zero, keeping n (reuse between elements of the same size).
    #[inline]
    pub fn clear(&mut self) {
        for b in self.data.iter_mut() {
            *b = [[0.0; 3]; 3];
        }
    }

    /// Resizes to n x n zero blocks.
    #[inline]
    pub fn reset(&mut self, n: usize) {
        self.n = n;
        self.data.clear();
        self.data.resize(n * n, [[0.0; 3]; 3]);
    }
}

impl std::ops::Index<usize> for Blocks {
    type Output = [Mat3];
    /// The row of blocks of particle x: `self[x][y]` is block (x, y).
    #[inline(always)]
    fn index(&self, x: usize) -> &[Mat3] {
        &self.data[x * self.n..(x + 1) * self.n]
    }
}

impl std::ops::IndexMut<usize> for Blocks {
    #[inline(always)]
    fn index_mut(&mut self, x: usize) -> &mut [Mat3] {
        &mut self.data[x * self.n..(x + 1) * self.n]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blocks of more particles than are kept inline are addressed like the inline ones: each
    /// block (x, y) is its own storage (writing one leaves the others zero).
    #[test]
    fn blocks_address_every_pair_beyond_the_inline_size() {
        let n = INLINE + 3;
        let mut b = Blocks::zeros(n);
        for x in 0..n {
            for y in 0..n {
                b[x][y][0][1] = (10 * x + y) as f64;
            }
        }
        for x in 0..n {
            for y in 0..n {
                assert_eq!(b[x][y][0][1], (10 * x + y) as f64);
                assert_eq!(b[x][y][1][0], 0.0);
            }
        }
        b.reset(2);
        assert_eq!(b.particles(), 2);
        assert_eq!(b[1][1], [[0.0; 3]; 3]);
    }
}
