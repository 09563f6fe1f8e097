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

/// An element's per-particle values as its kind computes them: a fixed-size array on the stack
/// for the built-in kinds (one to three particles), a [`PerParticle`] for the others (user
/// groups). Read as a slice; the assembler's hot loops take it without copying.
#[derive(Debug, Clone, PartialEq)]
pub enum Rows {
    /// One particle.
    One([Vec3; 1]),
    /// Two particles.
    Two([Vec3; 2]),
    /// Three particles.
    Three([Vec3; 3]),
    /// Any number of particles (on the heap: only user groups, whose evaluation costs far more).
    Any(Vec<Vec3>),
}

impl std::ops::Deref for Rows {
    type Target = [Vec3];
    #[inline(always)]
    fn deref(&self) -> &[Vec3] {
        match self {
            Rows::One(x) => x,
            Rows::Two(x) => x,
            Rows::Three(x) => x,
            Rows::Any(x) => x,
        }
    }
}

impl From<[Vec3; 1]> for Rows {
    #[inline(always)]
    fn from(x: [Vec3; 1]) -> Rows {
        Rows::One(x)
    }
}

impl From<[Vec3; 2]> for Rows {
    #[inline(always)]
    fn from(x: [Vec3; 2]) -> Rows {
        Rows::Two(x)
    }
}

impl From<[Vec3; 3]> for Rows {
    #[inline(always)]
    fn from(x: [Vec3; 3]) -> Rows {
        Rows::Three(x)
    }
}

impl From<PerParticle> for Rows {
    #[inline(always)]
    fn from(x: PerParticle) -> Rows {
        Rows::Any(x.into_vec())
    }
}

/// One 3x3 block per ordered pair (x, y) of an element's touched particles: `b[x][y]` is the
/// block of particle x's rows and particle y's columns. Up to [`INLINE`] particles the blocks
/// live in a fixed array (no allocation, and the compiler sees them as one), beyond it on the
/// heap.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocks {
    n: usize,
    inline: [Mat3; INLINE * INLINE],
    heap: Vec<Mat3>,
}

const ZERO: Mat3 = [[0.0; 3]; 3];

impl Blocks {
    /// n x n zero blocks (for an element over n particles).
    #[inline]
    pub fn zeros(n: usize) -> Blocks {
        Blocks {
            n,
            inline: [ZERO; INLINE * INLINE],
            heap: if n > INLINE {
                vec![ZERO; n * n]
            } else {
                Vec::new()
            },
        }
    }

    /// The blocks in one slice, x-major: block (x, y) is entry x n + y.
    #[inline(always)]
    pub fn as_slice(&self) -> &[Mat3] {
        if self.n <= INLINE {
            &self.inline[..self.n * self.n]
        } else {
            &self.heap
        }
    }

    /// The blocks in one mutable slice, x-major.
    #[inline(always)]
    pub fn as_mut_slice(&mut self) -> &mut [Mat3] {
        if self.n <= INLINE {
            &mut self.inline[..self.n * self.n]
        } else {
            &mut self.heap
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
        self.as_mut_slice().fill(ZERO);
    }

    /// Makes these n x n zero blocks, reusing the storage (the assembler keeps one buffer for
    /// all its elements).
    #[inline]
    pub fn reset(&mut self, n: usize) {
        self.n = n;
        if n > INLINE {
            self.heap.clear();
            self.heap.resize(n * n, ZERO);
        } else {
            self.clear();
        }
    }
}

impl std::ops::Index<usize> for Blocks {
    type Output = [Mat3];
    /// The row of blocks of particle x: `self[x][y]` is block (x, y).
    #[inline(always)]
    fn index(&self, x: usize) -> &[Mat3] {
        &self.as_slice()[x * self.n..(x + 1) * self.n]
    }
}

impl std::ops::IndexMut<usize> for Blocks {
    #[inline(always)]
    fn index_mut(&mut self, x: usize) -> &mut [Mat3] {
        let n = self.n;
        &mut self.as_mut_slice()[x * n..(x + 1) * n]
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
