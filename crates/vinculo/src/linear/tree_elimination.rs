//! Block elimination along a tree: linear cost for chains, ropes, tethers and branched strings.
//!
//! The unknowns are grouped into blocks: one per free particle (its 3 coordinates), to which
//! are added the multipliers of the constraints that touch only that particle. A constraint
//! between two particles is an edge of the particle graph; so is a force with a Jacobian
//! between two particles. When that graph is a forest, every tree is rooted and each
//! two-particle multiplier joins the block of the edge's child particle. Then block b couples
//! only with itself and with the 3 coordinates of its parent particle P:
//!
//! ```text
//! [ D_b   A_bP ] [x_b]   [r_b]
//! [ A_Pb  D_P  ] [x_P] = [r_P]
//! ```
//!
//! and eliminating the leaves first never creates fill outside the blocks: with
//! `W_b = D_b^-1 A_bP`, the parent's block becomes the Schur complement `D_P - A_Pb W_b`
//! (only its 3x3 particle part changes). Each D_b is factorised by a dense LU with partial
//! pivoting inside the block (a KKT block such as `[M, -s g^T; s g, 0]` has a zero diagonal
//! entry). The solve is a forward sweep (leaves to roots, `z_b = D_b^-1 r_b`,
//! `r_P -= A_Pb z_b`) and a backward sweep (roots to leaves, `x_b = z_b - W_b x_P`).
//!
//! The elimination pivots only inside a block, so a block may be singular or nearly so while the
//! whole matrix is regular: the end particle of a straight leg whose link to its parent is
//! parallel to its anchor (a chain hung as a V of two straight legs at rest), where the block
//! holds two parallel conditions on one particle and only the parent's freedom makes the matrix
//! regular. A block pivot at round-off ([`NEAR_SINGULAR`] of the block's largest entry, per unknown) stops
//! the elimination, and that factorisation is made by the general sparse LU (partial pivoting
//! across the whole matrix, analysed on first need); only its failure is reported as a singular
//! matrix. The next factorisation tries the tree again (the configuration moves on).
//!
//! The analysis works on the matrix pattern alone and checks that every structural entry lies
//! inside a block or between a block and its parent's particle part; otherwise (a loop, a
//! constraint on three particles, coupled multipliers) it declines and the caller falls back to
//! the general sparse LU.

use super::{LinearSolver, Singular, SparseLu};
use crate::assembly::{Pattern, Storage};

/// Smallest pivot of a block, relative to the block's largest entry and per unknown of the
/// block, that the elimination accepts (a thousand round-offs); below it the factorisation
/// falls back to the general sparse LU.
///
/// The bound is relative to round-off, not to a fixed share of the digits: a block of a
/// particle and its link is a saddle point whose second pivot, |g|^2 beta h^2 / m against the
/// largest entry m / (beta h^2), is naturally tiny (6e-12 on a chain of 0.1 kg particles at
/// dt = 1 ms), so a bound of 1e-8 sent every factorisation of a straight hanging chain to the
/// sparse LU (3.4 times slower a step on 10^4 particles, measured) although the tree solve was
/// accurate there.
pub const NEAR_SINGULAR: f64 = 1e3 * f64::EPSILON;

const ABSENT: u32 = u32::MAX;
const ROOT: u32 = u32::MAX;

/// Tree-structured block LU (see the module documentation).
pub struct TreeElimination {
    /// First local unknown of each block, in elimination order (one past the end last).
    start: Vec<usize>,
    /// First entry of each block's diagonal storage (n_b^2 entries each).
    diag_at: Vec<usize>,
    /// Position of each block's parent block in the elimination order (ROOT for roots).
    parent: Vec<u32>,
    /// Global unknown of each local unknown.
    unknowns: Vec<u32>,
    /// Slots of D_b (row-major), A_Pb (3 x n_b, row-major) and A_bP (n_b x 3, row-major).
    diag_slots: Vec<u32>,
    low_slots: Vec<u32>,
    up_slots: Vec<u32>,
    /// LU factors of D_b, A_Pb, and W_b = D_b^-1 A_bP.
    diag: Vec<f64>,
    low: Vec<f64>,
    w: Vec<f64>,
    /// Row interchanges of each block's LU (local indices).
    perm: Vec<u32>,
    /// Work vector in local (block) order.
    z: Vec<f64>,
    /// The common size of every block, or 0 when the sizes differ.
    uniform: usize,
    /// Per block: its diagonal block was gathered in the current factorisation.
    gathered: Vec<bool>,
    factored: bool,
    /// The general sparse LU that factorises the matrices whose blocks are (nearly) singular,
    /// analysed on first need.
    fallback: Option<SparseLu>,
    /// The last factorisation is the fallback's.
    on_fallback: bool,
    /// Factorisations made by the fallback.
    fallbacks: usize,
}

/// Union-find root with path halving.
fn find(set: &mut [usize], mut i: usize) -> usize {
    while set[i] != i {
        set[i] = set[set[i]];
        i = set[i];
    }
    i
}

/// Slot of entry (row, col) if it is in the pattern.
fn slot(pattern: &Pattern, row: usize, col: usize) -> u32 {
    let (a, b) = (pattern.col_ptr[col], pattern.col_ptr[col + 1]);
    match pattern.row_idx[a..b].binary_search(&row) {
        Ok(k) => (a + k) as u32,
        Err(_) => ABSENT,
    }
}

impl TreeElimination {
    /// Analyses a sparse pattern whose first `particle_unknowns` unknowns come in groups of 3
    /// (one group per free particle) and whose other unknowns are single multipliers.
    /// Returns `None` when the block graph is not a forest (the caller then uses a general
    /// sparse LU).
    pub fn analyse(pattern: &Pattern, particle_unknowns: usize) -> Option<TreeElimination> {
        let n = pattern.n;
        if pattern.storage != Storage::Sparse
            || particle_unknowns % 3 != 0
            || particle_unknowns > n
            || pattern.nnz() >= ABSENT as usize
        {
            return None;
        }
        let np = particle_unknowns / 3;
        let nl = n - particle_unknowns;
        let particle = |u: usize| (u < particle_unknowns).then_some(u / 3);

        // Particles touched by each multiplier (at most 2), and particle-particle couplings.
        let mut touched = vec![[ABSENT; 2]; nl];
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for col in 0..n {
            for &row in &pattern.row_idx[pattern.col_ptr[col]..pattern.col_ptr[col + 1]] {
                match (particle(row), particle(col)) {
                    (Some(a), Some(b)) if a < b => edges.push((a as u32, b as u32)),
                    (Some(_), Some(_)) => {}
                    (Some(p), None) | (None, Some(p)) => {
                        let k =
                            if row >= particle_unknowns { row } else { col } - particle_unknowns;
                        let t = &mut touched[k];
                        if t[0] == p as u32 || t[1] == p as u32 {
                        } else if t[0] == ABSENT {
                            t[0] = p as u32;
                        } else if t[1] == ABSENT {
                            t[1] = p as u32;
                        } else {
                            return None; // a multiplier on three particles
                        }
                    }
                    (None, None) if row != col => return None, // coupled multipliers
                    (None, None) => {}
                }
            }
        }
        for t in &touched {
            match *t {
                [ABSENT, _] => return None, // a multiplier on no free particle
                [a, b] if b != ABSENT => edges.push((a.min(b), a.max(b))),
                _ => {}
            }
        }
        edges.sort_unstable();
        edges.dedup();
        // A forest has no edge joining two particles already connected.
        let mut set: Vec<usize> = (0..np).collect();
        for &(a, b) in &edges {
            let (ra, rb) = (find(&mut set, a as usize), find(&mut set, b as usize));
            if ra == rb {
                return None;
            }
            set[ra] = rb;
        }
        drop(set);

        // Adjacency (CSR), then breadth-first order from the lowest particle of each tree.
        let mut adj_ptr = vec![0usize; np + 1];
        for &(a, b) in &edges {
            adj_ptr[a as usize + 1] += 1;
            adj_ptr[b as usize + 1] += 1;
        }
        for i in 0..np {
            adj_ptr[i + 1] += adj_ptr[i];
        }
        let mut fill = adj_ptr.clone();
        let mut adj = vec![0u32; 2 * edges.len()];
        for &(a, b) in &edges {
            adj[fill[a as usize]] = b;
            fill[a as usize] += 1;
            adj[fill[b as usize]] = a;
            fill[b as usize] += 1;
        }
        drop(fill);
        drop(edges);
        // Each tree is rooted at its particle with the most multipliers of its own (fixed
        // coordinates, planes, anchors): a particle whose three coordinates are prescribed then
        // keeps the links to its neighbours out of its block, which would otherwise hold four
        // conditions on three coordinates (a singular block in a regular matrix).
        let mut own = vec![0u32; np];
        for t in &touched {
            if t[1] == ABSENT {
                own[t[0] as usize] += 1;
            }
        }
        let mut roots: Vec<u32> = (0..np as u32).collect();
        if own.iter().any(|&k| k > 0) {
            roots.sort_by_key(|&p| std::cmp::Reverse(own[p as usize]));
        }
        drop(own);
        let mut parent_particle = vec![ROOT; np];
        let mut seen = vec![false; np];
        let mut order: Vec<u32> = Vec::with_capacity(np);
        for root in roots.into_iter().map(|p| p as usize) {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            let mut head = order.len();
            order.push(root as u32);
            while head < order.len() {
                let p = order[head] as usize;
                head += 1;
                for &c in &adj[adj_ptr[p]..adj_ptr[p + 1]] {
                    if !seen[c as usize] {
                        seen[c as usize] = true;
                        parent_particle[c as usize] = p as u32;
                        order.push(c);
                    }
                }
            }
        }
        drop(adj);
        drop(seen);
        // Leaves first: the reverse breadth-first order puts every child before its parent.
        order.reverse();
        let mut position = vec![0u32; np];
        for (b, &p) in order.iter().enumerate() {
            position[p as usize] = b as u32;
        }

        // Each multiplier joins its particle, or the child of its edge.
        let owner = |t: [u32; 2]| -> usize {
            if t[1] == ABSENT || parent_particle[t[0] as usize] == t[1] {
                t[0] as usize
            } else {
                t[1] as usize
            }
        };
        let mut size = vec![3usize; np];
        for t in &touched {
            size[owner(*t)] += 1;
        }
        // A block with more than three conditions on its particle's three coordinates is
        // singular whatever the values: the general sparse LU pivots across blocks instead.
        if size.iter().any(|&s| s > 6) {
            return None;
        }
        let mut start = vec![0usize; np + 1];
        let mut diag_at = vec![0usize; np + 1];
        for (b, &p) in order.iter().enumerate() {
            let s = size[p as usize];
            start[b + 1] = start[b] + s;
            diag_at[b + 1] = diag_at[b] + s * s;
        }
        let mut unknowns = vec![0u32; n];
        let mut next: Vec<usize> = (0..np).map(|b| start[b] + 3).collect();
        for (b, &p) in order.iter().enumerate() {
            for r in 0..3 {
                unknowns[start[b] + r] = 3 * p + r as u32;
            }
        }
        for (k, t) in touched.iter().enumerate() {
            let b = position[owner(*t)] as usize;
            unknowns[next[b]] = (particle_unknowns + k) as u32;
            next[b] += 1;
        }
        drop(next);
        drop(touched);
        let parent: Vec<u32> = order
            .iter()
            .map(|&p| match parent_particle[p as usize] {
                ROOT => ROOT,
                q => position[q as usize],
            })
            .collect();
        drop(order);
        drop(position);
        drop(parent_particle);

        // Slots of every block and coupling; the entries they cover must be the whole pattern.
        let blocks = np;
        let mut diag_slots = vec![ABSENT; diag_at[blocks]];
        let mut low_slots = vec![ABSENT; 3 * n];
        let mut up_slots = vec![ABSENT; 3 * n];
        let mut covered = 0usize;
        for b in 0..blocks {
            let local = &unknowns[start[b]..start[b + 1]];
            let nb = local.len();
            for (i, &ui) in local.iter().enumerate() {
                for (j, &uj) in local.iter().enumerate() {
                    let s = slot(pattern, ui as usize, uj as usize);
                    covered += (s != ABSENT) as usize;
                    diag_slots[diag_at[b] + i * nb + j] = s;
                }
            }
            if parent[b] != ROOT {
                let pb = parent[b] as usize;
                for r in 0..3 {
                    let up = unknowns[start[pb] + r] as usize;
                    for (j, &uj) in local.iter().enumerate() {
                        let lo = slot(pattern, up, uj as usize);
                        let hi = slot(pattern, uj as usize, up);
                        covered += (lo != ABSENT) as usize + (hi != ABSENT) as usize;
                        low_slots[3 * start[b] + r * nb + j] = lo;
                        up_slots[3 * start[b] + j * 3 + r] = hi;
                    }
                }
            }
        }
        if covered != pattern.nnz() {
            return None;
        }
        let uniform = match start.windows(2).map(|w| w[1] - w[0]).min() {
            Some(nb) if start[blocks] == nb * blocks => nb,
            _ => 0,
        };
        Some(TreeElimination {
            uniform,
            gathered: vec![false; blocks],
            diag: vec![0.0; diag_at[blocks]],
            low: vec![0.0; 3 * n],
            w: vec![0.0; 3 * n],
            perm: vec![0; n],
            z: vec![0.0; n],
            start,
            diag_at,
            parent,
            unknowns,
            diag_slots,
            low_slots,
            up_slots,
            factored: false,
            fallback: None,
            on_fallback: false,
            fallbacks: 0,
        })
    }

    /// Number of blocks (free particles).
    pub fn blocks(&self) -> usize {
        self.parent.len()
    }

    /// The matrix pattern, rebuilt from the slots of the blocks and couplings (which cover it
    /// entry for entry, so the slots are the same), for the fallback's analysis.
    fn pattern(&self) -> Pattern {
        let n = self.unknowns.len();
        let mut entries = Vec::with_capacity(self.diag_slots.len() + 2 * self.low_slots.len());
        for b in 0..self.blocks() {
            let local = &self.unknowns[self.start[b]..self.start[b + 1]];
            let nb = local.len();
            for (i, &ui) in local.iter().enumerate() {
                for (j, &uj) in local.iter().enumerate() {
                    if self.diag_slots[self.diag_at[b] + i * nb + j] != ABSENT {
                        entries.push((ui as usize, uj as usize));
                    }
                }
            }
            if self.parent[b] != ROOT {
                let pb = self.parent[b] as usize;
                for r in 0..3 {
                    let up = self.unknowns[self.start[pb] + r] as usize;
                    for (j, &uj) in local.iter().enumerate() {
                        if self.low_slots[3 * self.start[b] + r * nb + j] != ABSENT {
                            entries.push((up, uj as usize));
                        }
                        if self.up_slots[3 * self.start[b] + j * 3 + r] != ABSENT {
                            entries.push((uj as usize, up));
                        }
                    }
                }
            }
        }
        Pattern::new(n, entries, false)
    }

    /// Factorises with the general sparse LU (analysed on first use), after the block of local
    /// unknown `failed` had a (nearly) singular pivot. The sparse LU's factors are checked by a
    /// solve of a vector of ones: a zero pivot (an exactly singular matrix, which the numeric
    /// factorisation does not report) makes it non-finite, and the matrix is then reported
    /// singular at the block where the tree elimination stopped.
    fn factor_by_fallback(&mut self, values: &[f64], failed: usize) -> Result<(), Singular> {
        if self.fallback.is_none() {
            self.fallback = Some(SparseLu::new(&self.pattern()));
        }
        let lu = self.fallback.as_mut().expect("analysed above");
        self.fallbacks += 1;
        let column = self.unknowns[failed] as usize;
        let singular = |detail: String| Singular {
            column: Some(column),
            detail,
        };
        lu.factor(values).map_err(|e| {
            singular(format!(
                "negligible pivot in the block of unknown {column} (tree elimination), and the \
                 general sparse LU failed too: {}",
                e.detail
            ))
        })?;
        self.z.fill(1.0);
        lu.solve_in_place(&mut self.z);
        if self.z.iter().any(|x| !x.is_finite()) {
            return Err(singular(format!(
                "negligible pivot in the block of unknown {column} (tree elimination), and a \
                 zero pivot in the general sparse LU"
            )));
        }
        self.on_fallback = true;
        self.factored = true;
        Ok(())
    }
}

/// Gathers `values` at `slots` into `out` (absent entries are zero).
fn gather(out: &mut [f64], slots: &[u32], values: &[f64]) {
    for (o, &s) in out.iter_mut().zip(slots) {
        *o = if s == ABSENT { 0.0 } else { values[s as usize] };
    }
}

/// In-place LU with partial pivoting of the n x n row-major matrix `a`; returns the local
/// column of a pivot below [`NEAR_SINGULAR`] x n of the largest entry. On return the strict lower triangle holds L (unit diagonal),
/// the strict upper triangle U, and the diagonal the reciprocals of U's pivots, so that the
/// solves multiply where they would divide.
#[inline(always)]
fn lu_in_place(a: &mut [f64], n: usize, perm: &mut [u32]) -> Result<(), usize> {
    // Slices of known length let the unrolled copies drop their bounds checks.
    let (a, perm) = (&mut a[..n * n], &mut perm[..n]);
    let largest = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tiny = largest * NEAR_SINGULAR * n as f64;
    for k in 0..n {
        let mut p = k;
        for i in k + 1..n {
            if a[i * n + k].abs() > a[p * n + k].abs() {
                p = i;
            }
        }
        perm[k] = p as u32;
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let pivot = a[k * n + k];
        if !pivot.is_finite() || pivot.abs() <= tiny {
            return Err(k);
        }
        let inv = 1.0 / pivot;
        for i in k + 1..n {
            let l = a[i * n + k] * inv;
            a[i * n + k] = l;
            if l != 0.0 {
                for j in k + 1..n {
                    a[i * n + j] -= l * a[k * n + j];
                }
            }
        }
        a[k * n + k] = inv;
    }
    Ok(())
}

/// Solves with the factors of `lu_in_place` for the n x m row-major right-hand side `x` (the
/// factorisation's W = D^-1 A with m = 3, and the solve of blocks larger than 5). Zero entries
/// of L are skipped: a KKT block's mass part gives many.
#[inline(always)]
fn lu_solve(a: &[f64], n: usize, perm: &[u32], x: &mut [f64], m: usize) {
    let (a, perm, x) = (&a[..n * n], &perm[..n], &mut x[..n * m]);
    for k in 0..n {
        let p = (perm[k] as usize).min(n - 1);
        for c in 0..m {
            x.swap(k * m + c, p * m + c);
        }
    }
    for i in 1..n {
        for j in 0..i {
            let l = a[i * n + j];
            if l != 0.0 {
                for c in 0..m {
                    x[i * m + c] -= l * x[j * m + c];
                }
            }
        }
    }
    for i in (0..n).rev() {
        for j in i + 1..n {
            let u = a[i * n + j];
            for c in 0..m {
                x[i * m + c] -= u * x[j * m + c];
            }
        }
        let inv = a[i * n + i];
        for c in 0..m {
            x[i * m + c] *= inv;
        }
    }
}

/// A block's coupling to its parent during factorisation: W_b (holding A_bP on entry), A_Pb,
/// the parent's diagonal storage and the parent's block size.
type Coupling<'a> = Option<(&'a mut [f64], &'a [f64], &'a mut [f64], usize)>;

/// Factorises D_b and, for a block with a parent, forms W_b = D_b^-1 A_bP and applies the
/// Schur complement to the parent's particle part: D_P[0..3, 0..3] -= A_Pb W_b.
#[inline(always)]
fn eliminate(d: &mut [f64], nb: usize, perm: &mut [u32], coupling: Coupling) -> Result<(), usize> {
    lu_in_place(d, nb, perm)?;
    if let Some((w, low, dp, np)) = coupling {
        let (w, low, dp) = (&mut w[..3 * nb], &low[..3 * nb], &mut dp[..2 * np + 3]);
        lu_solve(d, nb, perm, w, 3);
        for r in 0..3 {
            for c in 0..3 {
                let mut acc = 0.0;
                for j in 0..nb {
                    acc += low[r * nb + j] * w[j * 3 + c];
                }
                dp[r * np + c] -= acc;
            }
        }
    }
    Ok(())
}

/// Forward step of the solve for one block: z_b = D_b^-1 z_b, then z_P -= A_Pb z_b.
#[inline(always)]
fn forward(
    d: &[f64],
    nb: usize,
    perm: &[u32],
    zb: &mut [f64],
    coupling: Option<(&[f64], &mut [f64])>,
) {
    let zb = &mut zb[..nb];
    lu_solve(d, nb, perm, zb, 1);
    if let Some((low, zp)) = coupling {
        let (low, zp) = (&low[..3 * nb], &mut zp[..3]);
        for r in 0..3 {
            let mut acc = 0.0;
            for j in 0..nb {
                acc += low[r * nb + j] * zb[j];
            }
            zp[r] -= acc;
        }
    }
}

/// [`forward`] for a block of N unknowns known at compile time: the same operations on
/// fixed-size arrays, unrolled, with the running sums kept in registers.
#[inline(always)]
fn forward_fixed<const N: usize>(
    d: &[f64],
    perm: &[u32],
    zb: &mut [f64],
    coupling: Option<(&[f64], &mut [f64])>,
) {
    let z: &mut [f64; N] = (&mut zb[..N]).try_into().expect("block of N unknowns");
    let (d, perm) = (&d[..N * N], &perm[..N]);
    for k in 0..N {
        z.swap(k, (perm[k] as usize).min(N - 1));
    }
    for i in 1..N {
        let mut s = z[i];
        for j in 0..i {
            s -= d[i * N + j] * z[j];
        }
        z[i] = s;
    }
    for i in (0..N).rev() {
        let mut s = z[i];
        for j in i + 1..N {
            s -= d[i * N + j] * z[j];
        }
        z[i] = s * d[i * N + i];
    }
    if let Some((low, zp)) = coupling {
        let (low, zp) = (&low[..3 * N], &mut zp[..3]);
        for r in 0..3 {
            let mut acc = 0.0;
            for j in 0..N {
                acc += low[r * N + j] * z[j];
            }
            zp[r] -= acc;
        }
    }
}

/// Backward step of the solve for one block: x_b = z_b - W_b x_P.
#[inline(always)]
fn backward(w: &[f64], xp: [f64; 3], zb: &mut [f64]) {
    for (x, wj) in zb.iter_mut().zip(w.chunks_exact(3)) {
        *x -= wj[0] * xp[0] + wj[1] * xp[1] + wj[2] * xp[2];
    }
}

/// [`backward`] for a block of N unknowns known at compile time.
#[inline(always)]
fn backward_fixed<const N: usize>(w: &[f64], xp: [f64; 3], zb: &mut [f64]) {
    let (w, zb) = (&w[..3 * N], &mut zb[..N]);
    for j in 0..N {
        zb[j] -= w[3 * j] * xp[0] + w[3 * j + 1] * xp[1] + w[3 * j + 2] * xp[2];
    }
}

impl LinearSolver for TreeElimination {
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        self.factored = false;
        self.on_fallback = false;
        // The matrix's entries are gathered block by block as the elimination reaches them (a
        // parent's diagonal block when its first child updates it), so that each block's numbers
        // are used while they are in cache: on a 10^6-particle chain the three separate passes
        // over 40 values per block cost as much as the elimination itself.
        self.gathered.fill(false);
        for b in 0..self.blocks() {
            let (s, nb) = (self.start[b], self.start[b + 1] - self.start[b]);
            let (da, db) = (self.diag_at[b], self.diag_at[b + 1]);
            if !self.gathered[b] {
                gather(&mut self.diag[da..db], &self.diag_slots[da..db], values);
            }
            let (ls, le) = (3 * s, 3 * s + 3 * nb);
            gather(&mut self.low[ls..le], &self.low_slots[ls..le], values);
            gather(&mut self.w[ls..le], &self.up_slots[ls..le], values);
            let pb = self.parent[b];
            if pb != ROOT && !self.gathered[pb as usize] {
                let (pa, pe) = (self.diag_at[pb as usize], self.diag_at[pb as usize + 1]);
                gather(&mut self.diag[pa..pe], &self.diag_slots[pa..pe], values);
                self.gathered[pb as usize] = true;
            }
            let (own, rest) = self.diag.split_at_mut(db);
            let d = &mut own[da..];
            let perm = &mut self.perm[s..s + nb];
            let coupling = if pb == ROOT {
                None
            } else {
                let pb = pb as usize;
                let np = self.start[pb + 1] - self.start[pb];
                Some((
                    &mut self.w[ls..le],
                    &self.low[ls..le],
                    &mut rest[self.diag_at[pb] - db..],
                    np,
                ))
            };
            // Blocks of 3 (a free particle) and 4 (a particle and its link) get unrolled copies.
            let result = match nb {
                3 => eliminate(d, 3, perm, coupling),
                4 => eliminate(d, 4, perm, coupling),
                5 => eliminate(d, 5, perm, coupling),
                _ => eliminate(d, nb, perm, coupling),
            };
            if let Err(k) = result {
                // A (nearly) singular block need not mean a singular matrix: the sparse LU
                // pivots across blocks, and its failure is the one reported.
                return self.factor_by_fallback(values, s + k);
            }
        }
        self.factored = true;
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorisation");
        if self.on_fallback {
            let lu = self.fallback.as_mut().expect("the fallback factorised");
            lu.solve_in_place(rhs);
            return;
        }
        for (z, &u) in self.z.iter_mut().zip(&self.unknowns) {
            *z = rhs[u as usize];
        }
        match self.uniform {
            3 => self.sweeps_uniform::<3>(),
            4 => self.sweeps_uniform::<4>(),
            5 => self.sweeps_uniform::<5>(),
            _ => self.sweeps(),
        }
        for (z, &u) in self.z.iter().zip(&self.unknowns) {
            rhs[u as usize] = *z;
        }
    }

    fn name(&self) -> &'static str {
        "tree elimination"
    }

    fn fallbacks(&self) -> usize {
        self.fallbacks
    }
}

impl TreeElimination {
    /// The forward and backward sweeps of the solve on the work vector `z` (blocks of any size).
    fn sweeps(&mut self) {
        for b in 0..self.blocks() {
            let (s, e) = (self.start[b], self.start[b + 1]);
            let nb = e - s;
            let d = &self.diag[self.diag_at[b]..self.diag_at[b + 1]];
            let (head, tail) = self.z.split_at_mut(e);
            let zb = &mut head[s..];
            let perm = &self.perm[s..e];
            let pb = self.parent[b];
            let coupling = if pb == ROOT {
                None
            } else {
                Some((
                    &self.low[3 * s..3 * e],
                    &mut tail[self.start[pb as usize] - e..],
                ))
            };
            // Blocks of 3 (a free particle), 4 (a particle and its link) and 5 get unrolled copies.
            match nb {
                3 => forward_fixed::<3>(d, perm, zb, coupling),
                4 => forward_fixed::<4>(d, perm, zb, coupling),
                5 => forward_fixed::<5>(d, perm, zb, coupling),
                _ => forward(d, nb, perm, zb, coupling),
            }
        }
        for b in (0..self.blocks()).rev() {
            let pb = self.parent[b];
            if pb == ROOT {
                continue;
            }
            let (s, e) = (self.start[b], self.start[b + 1]);
            let (head, tail) = self.z.split_at_mut(e);
            let zp = &tail[self.start[pb as usize] - e..];
            let xp = [zp[0], zp[1], zp[2]];
            let (w, zb) = (&self.w[3 * s..3 * e], &mut head[s..]);
            match e - s {
                3 => backward_fixed::<3>(w, xp, zb),
                4 => backward_fixed::<4>(w, xp, zb),
                5 => backward_fixed::<5>(w, xp, zb),
                _ => backward(w, xp, zb),
            }
        }
    }

    /// [`TreeElimination::sweeps`] when every block has N unknowns (a chain whose links each
    /// join a particle's block): block b starts at N b and its factors at N^2 b, so the loops
    /// walk the arrays in chunks of fixed size.
    fn sweeps_uniform<const N: usize>(&mut self) {
        let z = &mut self.z;
        let blocks = self
            .diag
            .chunks_exact(N * N)
            .zip(self.perm.chunks_exact(N))
            .zip(self.low.chunks_exact(3 * N))
            .zip(&self.parent);
        for (b, (((d, perm), low), &pb)) in blocks.enumerate() {
            let (head, tail) = z.split_at_mut(N * b + N);
            let zb = &mut head[N * b..];
            let coupling = (pb != ROOT).then(|| (low, &mut tail[N * pb as usize - N * b - N..]));
            forward_fixed::<N>(d, perm, zb, coupling);
        }
        for (b, (w, &pb)) in self
            .w
            .chunks_exact(3 * N)
            .zip(&self.parent)
            .enumerate()
            .rev()
        {
            if pb == ROOT {
                continue;
            }
            let p = N * pb as usize;
            let xp = [z[p], z[p + 1], z[p + 2]];
            backward_fixed::<N>(w, xp, &mut z[N * b..N * b + N]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Layout;
    use crate::laws::VectorLaw;
    use crate::linear::{for_layout, SparseLu, SparseSolver};
    use crate::model::System;

    /// Deterministic pseudo-random numbers in [-1, 1) (a 64-bit linear congruential generator).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// A chain of `n` links from a fixed anchor, with a side branch of 3 particles at the
    /// middle, a plane under the tip, a fixed coordinate and a spring along the branch: a tree
    /// with every kind of coupling.
    fn branched_string(n: usize) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let mut middle = prev;
        for i in 1..=n {
            let p = s
                .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0; 3], false)
                .unwrap();
            s.add_distance(prev, p, None).unwrap();
            if i == n / 2 {
                middle = p;
            }
            prev = p;
        }
        let tip = prev;
        s.add_plane(
            tip,
            VectorLaw::constant([0.0, 0.0, 1.0]),
            VectorLaw::constant([0.1 * n as f64, 0.0, 0.0]),
        )
        .unwrap();
        let mut prev = middle;
        for j in 1..=3 {
            let p = s
                .add_particle(0.2, [0.05 * n as f64, 0.1 * j as f64, 0.0], [0.0; 3], false)
                .unwrap();
            s.add_distance(prev, p, None).unwrap();
            if j == 2 {
                s.add_spring_damper(prev, p, 50.0, 0.5, None).unwrap();
                s.add_fixed_coordinate(p, 2, None).unwrap();
            }
            prev = p;
        }
        s
    }

    /// Values for the pattern of `layout`: dominant particle diagonal blocks, random couplings.
    fn values(layout: &Layout, seed: u64) -> Vec<f64> {
        let p = &layout.pattern;
        let mut rng = Lcg(seed);
        let mut v = vec![0.0; p.nnz()];
        for col in 0..p.n {
            for k in p.col_ptr[col]..p.col_ptr[col + 1] {
                let row = p.row_idx[k];
                v[k] = rng.next();
                if row == col && row < 3 * layout.free {
                    v[k] += 6.0;
                }
            }
        }
        v
    }

    fn solve(solver: &mut dyn LinearSolver, values: &[f64], b: &[f64]) -> Vec<f64> {
        solver.factor(values).unwrap();
        let mut x = b.to_vec();
        solver.solve_in_place(&mut x);
        x
    }

    /// Tree elimination and faer's general sparse LU give the same solution (to 1e-12 relative)
    /// on random matrices with the patterns of a chain and of a branched string; the reference
    /// is the sparse LU, and the residual of both against the matrix is checked too.
    #[test]
    fn tree_elimination_matches_sparse_lu() {
        for (system, seed) in [(branched_string(1), 1), (branched_string(40), 7)] {
            let layout = Layout::new(&system, 0);
            let mut tree = TreeElimination::analyse(&layout.pattern, 3 * layout.free)
                .expect("a branched string is a tree");
            let mut lu = SparseLu::new(&layout.pattern);
            let n = layout.unknowns();
            let mut rng = Lcg(seed + 100);
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            for round in 0..3 {
                let v = values(&layout, seed + round);
                let x = solve(&mut tree, &v, &b);
                let y = solve(&mut lu, &v, &b);
                let scale = y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for i in 0..n {
                    assert!(
                        (x[i] - y[i]).abs() <= 1e-12 * scale,
                        "unknown {i}: tree {} vs sparse LU {}",
                        x[i],
                        y[i]
                    );
                }
                let p = &layout.pattern;
                let mut r = b.clone();
                for col in 0..n {
                    for k in p.col_ptr[col]..p.col_ptr[col + 1] {
                        r[p.row_idx[k]] -= v[k] * x[col];
                    }
                }
                assert!(r.iter().all(|e| e.abs() < 1e-12), "residual {r:?}");
            }
        }
    }

    /// Closing a loop (a spring from the tip back to the first particle, or a triangle of
    /// distances) makes the solver fall back to the general sparse LU; a chain gets the tree.
    #[test]
    fn loops_fall_back_to_sparse_lu() {
        let name = |s: &System| {
            let layout = Layout::new(s, 0);
            for_layout(&layout.pattern, 3 * layout.free, SparseSolver::Auto).name()
        };
        let mut s = branched_string(10);
        assert_eq!(name(&s), "tree elimination");
        let first = s.particle_id(1).unwrap();
        let tip = s.particle_id(10).unwrap();
        s.add_spring_damper(first, tip, 1.0, 0.0, None).unwrap();
        assert_eq!(name(&s), "sparse LU");

        let mut t = System::new([0.0, 0.0, -9.81]);
        let p: Vec<_> = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
            .iter()
            .map(|&x| t.add_particle(1.0, x, [0.0; 3], false).unwrap())
            .collect();
        t.add_distance(p[0], p[1], None).unwrap();
        t.add_distance(p[1], p[2], None).unwrap();
        assert_eq!(name(&t), "tree elimination");
        t.add_distance(p[2], p[0], None).unwrap();
        assert_eq!(name(&t), "sparse LU");
    }

    /// Well-posed chains whose tree blocks are singular. `pinned` false: a chain hung from two
    /// anchors 2 m apart as a V of two straight legs of `n` links each, at rest (the end particle
    /// of the leg eliminated first holds two parallel conditions, its anchor and its link).
    /// `pinned` true: a chain of `n` links hanging straight down from a free particle whose
    /// three coordinates are prescribed, released with a sideways speed (the pinned particle's
    /// block would hold four conditions on three coordinates, were it not the root).
    fn awkward_chain(n: usize, pinned: bool) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        if pinned {
            // The tip first, the pinned top last (not the first particle, which the analysis
            // used to take as the root).
            let mut below = None;
            for i in (1..=n).rev() {
                let z = -(i as f64) / n as f64;
                let v = [0.5 * i as f64 / n as f64, 0.0, 0.0];
                let p = s.add_particle(0.1, [0.0, 0.0, z], v, false).unwrap();
                if let Some(b) = below {
                    s.add_distance(p, b, None).unwrap();
                }
                below = Some(p);
            }
            let top = s.add_particle(1.0, [0.0; 3], [0.0; 3], false).unwrap();
            for axis in 0..3 {
                s.add_fixed_coordinate(top, axis, None).unwrap();
            }
            s.add_distance(top, below.unwrap(), None).unwrap();
            return s;
        }
        let left = s
            .add_particle(1.0, [-1.0, 0.0, 0.0], [0.0; 3], true)
            .unwrap();
        let right = s
            .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], true)
            .unwrap();
        let mut prev = left;
        for i in 1..2 * n {
            let x = -1.0 + i as f64 / n as f64;
            let z = -(1.0 - x.abs());
            let p = s.add_particle(0.1, [x, 0.0, z], [0.0; 3], false).unwrap();
            s.add_distance(prev, p, None).unwrap();
            prev = p;
        }
        s.add_distance(prev, right, None).unwrap();
        s
    }

    /// A V chain and a chain hanging from a pinned particle run with the tree elimination and
    /// agree with the general sparse LU run to round-off (the reference: the same steps with
    /// partial pivoting across the whole matrix), the chains having moved.
    #[test]
    fn singular_blocks_of_a_regular_matrix_fall_back_to_sparse_lu() {
        for pinned in [false, true] {
            let system = awkward_chain(12, pinned);
            let run = |sparse_solver| {
                let options = crate::SimulationOptions {
                    t_end: 0.05,
                    dt: 1e-3,
                    sparse_solver,
                    ..Default::default()
                };
                crate::simulate(&system, &options).unwrap()
            };
            let tree = run(SparseSolver::Auto);
            let lu = run(SparseSolver::SparseLu);
            assert_eq!(tree.linear_solver, "tree elimination");
            assert!(tree.status.is_ok(), "pinned {pinned}: {:?}", tree.status);
            assert!(lu.status.is_ok(), "pinned {pinned}: {:?}", lu.status);
            let (a, b) = (&tree.positions, &lu.positions);
            assert_eq!(a.len(), b.len());
            let gap = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(
                gap < 1e-9,
                "pinned {pinned}: positions differ by {gap:.3e} m"
            );
            // The chain moved (the legs sag): a run that stood still would agree trivially.
            let last = &a[a.len() - 3 * tree.particles..];
            let moved = last
                .iter()
                .zip(&a[..3 * tree.particles])
                .fold(0.0f64, |m, (x, x0)| m.max((x - x0).abs()));
            assert!(moved > 1e-4, "pinned {pinned}: moved {moved:.3e} m");
        }
    }

    /// A rank-deficient tree matrix (a particle held by two identical fixed coordinates) is
    /// reported as singular, naming an unknown of that particle's block.
    #[test]
    fn singular_block_is_reported() {
        let mut s = crate::integrators::fixtures::pendulum();
        let b = s.particle_id(1).unwrap();
        s.add_fixed_coordinate(b, 1, None).unwrap();
        s.add_fixed_coordinate(b, 1, None).unwrap();
        let layout = Layout::new(&s, 0);
        let mut tree = TreeElimination::analyse(&layout.pattern, 3).unwrap();
        let mut v = values(&layout, 3);
        // Make the two fixed-coordinate rows and columns identical.
        let (k1, k2) = (4, 5);
        for j in 0..3 {
            v[layout.pattern.slot(k2, j)] = v[layout.pattern.slot(k1, j)];
            v[layout.pattern.slot(j, k2)] = v[layout.pattern.slot(j, k1)];
        }
        let err = tree.factor(&v).unwrap_err();
        assert!(err.column.is_some_and(|c| c < 6), "{err:?}");
    }
}
