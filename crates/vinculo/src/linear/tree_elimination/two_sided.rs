//! A long chain eliminated from both ends at once, on two threads.
//!
//! The tree elimination of a chain is a sequence: each block waits for its child's Schur update
//! (module documentation of [`super`]). The blocks are numbered leaves first, b = 0 .. n-1,
//! block b's parent b + 1; block b holds its particle's coordinates and the multiplier of its
//! link to b + 1 (the last block, the root, its own conditions). Cut the chain at a separator
//! block k: the leaf side, blocks 0 .. k-1, is eliminated as before, towards k; the root side,
//! blocks n-1 down to k+1, the other way, each block towards its child. The separator, the last,
//! is then coupled with nothing, and the two sides touch disjoint storage until they meet at it:
//! each runs on its own thread. This is the block LU of the same matrix in another pivot order
//! (a block's Schur complement in any order of the blocks is the KKT matrix of a connected part
//! of the chain, regular when the matrix is), so it gives the same solution to round-off.
//!
//! # The root side
//!
//! Block b of the root side is coupled with its child c = b - 1 through the entries kept in c's
//! storage, as every coupling with a parent: `L = A_bc` (b's particle rows by c's columns, 3 x
//! n_c: c's `low`) and `U = A_cb` (c's rows by b's particle columns, n_c x 3: c's `w`). Both
//! touch b's particle part alone (the link of b to b + 1 does not involve c), so eliminating b
//! changes D_c by
//!
//! ```text
//! D_c <- D_c - A_cb D_b^-1 A_bc = D_c - U E L,    E = (D_b^-1)_pp (3 x 3)
//! ```
//!
//! with E the particle rows and columns of D_b^-1. The whole of D_c changes (the multiplier of
//! c's link to b too), where the leaf side changes only its parent's particle part. L and U
//! stay as they are, for the solve:
//!
//! ```text
//! forward (root first):   z_b = D_b^-1 r_b,   r_c -= U (z_b)_p
//! backward (leaf first):  x_b = z_b - D_b^-1 [L x_c; 0]
//! ```
//!
//! The root side keeps D_b^-1 itself in D_b's place (made from D_b's LU factors with partial
//! pivoting, which find a negligible pivot as the leaf side's do), not the factors: each sweep
//! then waits from one block to the next for a product of a few terms, as the leaf side's
//! explicit sweeps do (the particle part of z_b = D_b^-1 r_b, carried to the child in
//! registers, forward; L x_c and three columns of D_b^-1, backward), where a solve with the
//! factors is a chain of eight dependent steps. Measured on the 10^6-particle swinging chain:
//! with the factors the root side's sweeps took three times as long a block as the leaf side's,
//! and a step was 5 % faster than on one thread; with the inverse the two sides take about as
//! long, and a step 16 % (0.30 -> 0.25 s on a busy machine).
//!
//! The separator k takes the leaf side's update of its particle part and the root side's of
//! its whole block (from k + 1, after both threads have joined), and is solved by its factors
//! alone. Its storage of the coupling with k + 1 stays as the matrix gave it, as the root
//! side's; the leaf side's blocks turn their A_Pb into G_b = A_Pb D_b^-1 as a uniform chain's.

use std::ops::Range;

use rayon::prelude::*;

use crate::math::{larger_norm, LargestMagnitude};

use super::{invert_in_place, lu_in_place, solve_block, Factors, TreeElimination, MAX_BLOCK};

/// `$self.$method(b, nb, nc, args..)` for block `$b` of the root side, of `nb` unknowns, and its
/// child, of `nc`: constants for equal blocks of 3 to 5 (unrolled copies), else the sizes.
macro_rules! toward_leaf {
    ($self:ident . $method:ident ($b:expr $(, $arg:expr)*)) => {{
        let b = $b;
        let (nb, nc) = (
            $self.start[b + 1] - $self.start[b],
            $self.start[b] - $self.start[b - 1],
        );
        match (nb, nc) {
            (3, 3) => $self.$method(b, 3, 3 $(, $arg)*),
            (4, 4) => $self.$method(b, 4, 4 $(, $arg)*),
            (5, 5) => $self.$method(b, 5, 5 $(, $arg)*),
            _ => $self.$method(b, nb, nc $(, $arg)*),
        }
    }};
}

/// Fewest blocks of a chain for its two ends to be eliminated on two threads. Measured on
/// swinging chains (a step, the two-sided elimination against one side, alternated runs): 10 %
/// faster at 300,000 particles (0.074-0.079 against 0.085-0.087 s), the same at 100,000, 6 to
/// 30 % slower at 3,000 to 30,000 (waking the second thread at every factorisation and solve
/// costs more than it saves while the chain's storage fits in the caches, and the residual
/// leaves it asleep below [`crate::options::PARALLEL_FROM`]). Lowered from 200,000 to 100,000
/// with that threshold (measured there: a step of the swinging chain of 10^5 particles 24 %
/// faster with both on a machine whose memory serves one thread less well).
pub const TWO_SIDED_FROM: usize = 100_000;

/// Share of the blocks the leaf side takes: half, both sides taking about as long a block
/// (0.6 measured the same on the 10^6-particle chain).
const LEAF_SIDE_SHARE: f64 = 0.5;

/// The root side's storage during its elimination: D_b and the row interchanges to write, the
/// couplings (which it does not change) to read, all from block `from` on.
struct RootSide<'a> {
    diag: &'a mut [f64],
    low: &'a [f64],
    w: &'a [f64],
    perm: &'a mut [u32],
    from: usize,
}

impl TreeElimination {
    /// Eliminates the matrix from both ends on two threads when it is a chain of at least
    /// `from` blocks ([`TWO_SIDED_FROM`] at the analysis), from one end otherwise; returns
    /// whether it takes both ends. The solutions are the same to round-off.
    pub fn two_sided_from(&mut self, from: usize) -> bool {
        self.separator = self.chain_separator(from);
        self.factored = false;
        // Where each unknown lies in the blocks' order: the solve's result goes back to the
        // right-hand side's order on two threads.
        self.local_of = Vec::new();
        if self.separator > 0 {
            self.local_of = vec![0; self.unknowns.len()];
            for (i, &u) in self.unknowns.iter().enumerate() {
                self.local_of[u as usize] = i as u32;
            }
        }
        self.separator > 0
    }

    /// Solves in place after [`TreeElimination::eliminate_two_sided`]: the right-hand side
    /// gathered into the blocks' order, the sweeps, and the result put back, each on rayon's
    /// pool.
    /// With `measure`, also returns the infinity norm of the solution (NaN where an entry is
    /// NaN), each chunk's taken as the pass that puts the result back writes it (else 0): a
    /// pass of its own over the 32 MB of the 10^6-particle chain's unknowns took 2.5 ms.
    pub(super) fn solve_two_sided(&mut self, rhs: &mut [f64], measure: bool) -> f64 {
        const CHUNK: usize = 1 << 15;
        let mut z = std::mem::take(&mut self.z);
        z.par_chunks_mut(CHUNK)
            .zip(self.unknowns.par_chunks(CHUNK))
            .for_each(|(z, unknowns)| {
                for (z, &u) in z.iter_mut().zip(unknowns) {
                    *z = rhs[u as usize];
                }
            });
        self.sweeps_two_sided(&mut z);
        let norm = rhs
            .par_chunks_mut(CHUNK)
            .zip(self.local_of.par_chunks(CHUNK))
            .map(|(rhs, local)| {
                if !measure {
                    for (r, &i) in rhs.iter_mut().zip(local) {
                        *r = z[i as usize];
                    }
                    return 0.0;
                }
                let mut largest = LargestMagnitude::default();
                for (r, i) in rhs.chunks_mut(4).zip(local.chunks(4)) {
                    for (l, (r, &i)) in r.iter_mut().zip(i).enumerate() {
                        *r = z[i as usize];
                        largest.take(l, *r);
                    }
                }
                largest.norm()
            })
            .reduce(|| 0.0, larger_norm);
        self.z = z;
        norm
    }

    /// The separator of a chain of blocks eliminated from both ends, or 0: the chain must be
    /// long (`from` blocks or more), each block but the root coupled with its parent alone,
    /// the next block, and the leaf side a uniform run (module documentation).
    pub(super) fn chain_separator(&self, from: usize) -> usize {
        let n = self.blocks();
        if n < from.max(4) || !(3..=5).contains(&self.uniform) {
            return 0;
        }
        let chain = (0..n - 1).all(|b| {
            self.parent[b] as usize == b + 1
                && self.coupled_at[b + 1] - self.coupled_at[b] == 1
                && self.ancestors[self.coupled_at[b]] as usize == b + 1
        }) && self.coupled_at[n] == self.coupled_at[n - 1];
        let k = ((n as f64 * LEAF_SIDE_SHARE) as usize).clamp(1, n - 2);
        if chain && self.head < k && k < self.tail {
            k
        } else {
            0
        }
    }

    /// Eliminates a chain from both ends on two threads (module documentation), the matrix's
    /// entries gathered first from `values` when given; returns the local unknown of a
    /// negligible pivot.
    pub(super) fn eliminate_two_sided(
        &self,
        f: &mut Factors,
        values: Option<&[f64]>,
    ) -> Result<(), usize> {
        let (k, n) = (self.separator, self.blocks());
        if let Some(values) = values {
            for b in 0..n {
                self.gather_block(f, b, values);
            }
        }
        // The leaf side writes blocks 0..=k (its last block updates the separator's particle
        // part), the root side blocks k+1.. (it reads their couplings).
        let (d_cut, c_cut, s_cut) = (
            self.diag_at[k + 1],
            self.coupling_at[k + 1],
            self.start[k + 1],
        );
        let (diag_leaf, diag_root) = f.diag.split_at_mut(d_cut);
        let (low_leaf, low_root) = f.low.split_at_mut(c_cut);
        let (w_leaf, w_root) = f.w.split_at_mut(c_cut);
        let (perm_leaf, perm_root) = f.perm.split_at_mut(s_cut);
        let mut leaf = Factors {
            diag: diag_leaf,
            low: low_leaf,
            w: w_leaf,
            perm: perm_leaf,
        };
        let mut root = RootSide {
            diag: diag_root,
            low: low_root,
            w: w_root,
            perm: perm_root,
            from: k + 1,
        };
        let (leaf_side, root_side) = rayon::join(
            || {
                for b in 0..k {
                    self.eliminate_sized(&mut leaf, b)?;
                }
                self.make_explicit(&mut leaf, self.head..k);
                Ok::<(), usize>(())
            },
            || {
                for b in (k + 2..n).rev() {
                    self.eliminate_toward_leaf(&mut root, b)?;
                }
                Ok::<(), usize>(())
            },
        );
        leaf_side?;
        root_side?;
        let mut whole = RootSide {
            diag: &mut *f.diag,
            low: &*f.low,
            w: &*f.w,
            perm: &mut *f.perm,
            from: 0,
        };
        self.eliminate_toward_leaf(&mut whole, k + 1)?;
        let (s, e) = (self.start[k], self.start[k + 1]);
        let d = &mut f.diag[self.diag_at[k]..self.diag_at[k + 1]];
        lu_in_place(d, e - s, &mut f.perm[s..e]).map_err(|j| s + j)
    }

    /// Eliminates block b of the root side towards its child c = b - 1: factorises D_b and
    /// updates D_c by -U E L (module documentation). Blocks of the uniform run take a copy
    /// unrolled for their size.
    fn eliminate_toward_leaf(&self, side: &mut RootSide, b: usize) -> Result<(), usize> {
        toward_leaf!(self.eliminate_toward_leaf_sized(b, side))
    }

    /// [`TreeElimination::eliminate_toward_leaf`] for blocks b of `nb` unknowns and c of `nc`.
    #[inline(always)]
    fn eliminate_toward_leaf_sized(
        &self,
        b: usize,
        nb: usize,
        nc: usize,
        side: &mut RootSide,
    ) -> Result<(), usize> {
        let (d0, c0, s0) = (
            self.diag_at[side.from],
            self.coupling_at[side.from],
            self.start[side.from],
        );
        let c = b - 1;
        let (before, own) = side.diag.split_at_mut(self.diag_at[b] - d0);
        let d = &mut own[..nb * nb];
        let perm = &mut side.perm[self.start[b] - s0..][..nb];
        lu_in_place(d, nb, perm).map_err(|j| self.start[b] + j)?;
        // D_b^-1, kept in D_b's place (module documentation).
        invert_in_place(d, nb, perm);
        let inverse = &*d;
        let at = self.coupling_at[c] - c0;
        let (l, u) = (&side.low[at..at + 3 * nc], &side.w[at..at + 3 * nc]);
        // F = E L (3 x n_c), then D_c -= U F.
        let mut f = [0.0; 3 * MAX_BLOCK];
        for r in 0..3 {
            // E's row r: the particle columns of D_b^-1's row r.
            let e = &inverse[nb * r..nb * r + 3];
            for j in 0..nc {
                f[r * nc + j] = e[0] * l[j] + e[1] * l[nc + j] + e[2] * l[2 * nc + j];
            }
        }
        let dc = &mut before[self.diag_at[c] - d0..][..nc * nc];
        for i in 0..nc {
            let ui = &u[3 * i..3 * i + 3];
            for j in 0..nc {
                dc[i * nc + j] -= ui[0] * f[j] + ui[1] * f[nc + j] + ui[2] * f[2 * nc + j];
            }
        }
        Ok(())
    }

    /// The solve's sweeps on the work vector `z` after [`TreeElimination::eliminate_two_sided`]:
    /// each side's forward sweep on its own thread, the separator, then each side's backward
    /// sweep on its own thread.
    fn sweeps_two_sided(&self, z: &mut [f64]) {
        match self.uniform {
            3 => self.sweeps_two_sided_sized::<3>(z),
            4 => self.sweeps_two_sided_sized::<4>(z),
            _ => self.sweeps_two_sided_sized::<5>(z),
        }
    }

    fn sweeps_two_sided_sized<const N: usize>(&self, z: &mut [f64]) {
        let (k, n) = (self.separator, self.blocks());
        let cut = self.start[k + 1];
        let root_blocks = k + 2..n;
        {
            let (leaf, root) = z.split_at_mut(cut);
            rayon::join(
                || self.forward_explicit::<N>(leaf, k),
                || self.forward_toward_leaf(root, k + 1, root_blocks.clone()),
            );
        }
        self.forward_toward_leaf(z, 0, k + 1..k + 2);
        let (s, e) = (self.start[k], self.start[k + 1]);
        let d = &self.store.diag()[self.diag_at[k]..self.diag_at[k + 1]];
        solve_block(d, &self.perm[s..e], &mut z[s..e]);
        self.backward_toward_leaf(z, 0, k + 1..k + 2);
        let (leaf, root) = z.split_at_mut(cut);
        rayon::join(
            || self.backward_explicit::<N>(leaf, k),
            || self.backward_toward_leaf(root, k + 1, root_blocks),
        );
    }

    /// The root side's forward sweep over `blocks`, the last first: z_b = D_b^-1 r_b, then
    /// r_c -= U (z_b)_p, the update of the next block carried to it in registers (written to
    /// memory past the last); `z` holds the unknowns from block `from` on.
    fn forward_toward_leaf(&self, z: &mut [f64], from: usize, blocks: Range<usize>) {
        let mut carry = [0.0; MAX_BLOCK];
        for b in blocks.clone().rev() {
            toward_leaf!(self.forward_toward_leaf_sized(b, z, from, &mut carry));
        }
        if !blocks.is_empty() {
            let c = blocks.start - 1;
            let z0 = self.start[from];
            let zc = &mut z[self.start[c] - z0..self.start[c + 1] - z0];
            for (zi, u) in zc.iter_mut().zip(&carry) {
                *zi -= u;
            }
        }
    }

    /// Block b's part of [`TreeElimination::forward_toward_leaf`], b of `nb` unknowns, its
    /// child of `nc`: `carry` holds r_b's pending update on entry, r_c's on return.
    #[inline(always)]
    fn forward_toward_leaf_sized(
        &self,
        b: usize,
        nb: usize,
        nc: usize,
        z: &mut [f64],
        from: usize,
        carry: &mut [f64; MAX_BLOCK],
    ) {
        let s = self.start[b] - self.start[from];
        let inverse = &self.store.diag()[self.diag_at[b]..self.diag_at[b] + nb * nb];
        let zb = &mut z[s..s + nb];
        let mut r = [0.0; MAX_BLOCK];
        for i in 0..nb {
            r[i] = zb[i] - carry[i];
        }
        // The particle part first: the next block waits for it alone.
        let mut p = [0.0; 3];
        for (i, pi) in p.iter_mut().enumerate() {
            *pi = (0..nb).map(|j| inverse[i * nb + j] * r[j]).sum();
        }
        let at = self.coupling_at[b - 1];
        let u = &self.store.w()[at..at + 3 * nc];
        for i in 0..nc {
            carry[i] = u[3 * i] * p[0] + u[3 * i + 1] * p[1] + u[3 * i + 2] * p[2];
        }
        zb[..3].copy_from_slice(&p);
        for i in 3..nb {
            zb[i] = (0..nb).map(|j| inverse[i * nb + j] * r[j]).sum();
        }
    }

    /// The root side's backward sweep over `blocks`, the first first: x_b = z_b - D_b^-1
    /// [L x_c; 0], each block's x carried to the next in registers; `z` holds the unknowns from
    /// block `from` on (the child's of the first block among them).
    fn backward_toward_leaf(&self, z: &mut [f64], from: usize, blocks: Range<usize>) {
        let Some(first) = blocks.clone().next() else {
            return;
        };
        let z0 = self.start[from];
        let mut x = [0.0; MAX_BLOCK];
        let c = first - 1;
        let xc = &z[self.start[c] - z0..self.start[c + 1] - z0];
        x[..xc.len()].copy_from_slice(xc);
        for b in blocks {
            toward_leaf!(self.backward_toward_leaf_sized(b, z, from, &mut x));
        }
    }

    /// Block b's part of [`TreeElimination::backward_toward_leaf`], b of `nb` unknowns, its
    /// child of `nc`: `x` holds x_c on entry, x_b on return.
    #[inline(always)]
    fn backward_toward_leaf_sized(
        &self,
        b: usize,
        nb: usize,
        nc: usize,
        z: &mut [f64],
        from: usize,
        x: &mut [f64; MAX_BLOCK],
    ) {
        let at = self.coupling_at[b - 1];
        let l = &self.store.low()[at..at + 3 * nc];
        let mut y = [0.0; 3];
        for (r, yr) in y.iter_mut().enumerate() {
            *yr = (0..nc).map(|j| l[r * nc + j] * x[j]).sum();
        }
        let inverse = &self.store.diag()[self.diag_at[b]..self.diag_at[b] + nb * nb];
        let s = self.start[b] - self.start[from];
        let zb = &mut z[s..s + nb];
        for (zi, row) in zb.iter_mut().zip(inverse.chunks_exact(nb)) {
            *zi -= row[0] * y[0] + row[1] * y[1] + row[2] * y[2];
        }
        x[..nb].copy_from_slice(zb);
    }
}
