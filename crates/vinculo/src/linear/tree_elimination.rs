//! Block elimination along a tree: linear cost for chains, ropes, tethers, branched strings and
//! lines with bending stiffness.
//!
//! # Blocks and the tree
//!
//! The unknowns are grouped into blocks: one per free particle (its 3 coordinates, the block's
//! *particle part*), to which are added the multipliers of the constraints that touch only that
//! particle. A constraint between two particles is an edge of the particle graph; so is a force
//! with a Jacobian between two particles. A spanning forest of that graph is built from the
//! constraints' edges first, then from the forces' edges that join particles not yet connected
//! (nearest particle indices first: a line's neighbours before the nodes two apart that its
//! bending couples). Each tree is rooted at its particle with the most multipliers of its own,
//! else at its lowest index (a line's first node, an end of the path). Every edge must then
//! join a particle and one of its *ancestors* (its parent for an edge of the tree, possibly a
//! farther one for the others: the bending of a line at node i couples nodes i-1 and i+1, the
//! grandparent of one of them); an edge between two particles neither of which is an ancestor
//! of the other (siblings, or cousins) makes the analysis decline, except that a force between
//! them first has the analysis made again with every tree rooted at a leaf (a line's bending
//! centred on its most constrained node, in the middle of the line, then couples a node with
//! its grandparent). A two-particle multiplier
//! joins the block of the edge's lower particle (the descendant). So block b couples only with
//! itself and with the particle parts of some of its ancestors u:
//!
//! ```text
//! A_bb = D_b (n_b x n_b),    A_bu (n_b x 3),    A_ub (3 x n_b)
//! ```
//!
//! The blocks are eliminated leaves first (the reverse of a breadth-first order from the roots),
//! so every block comes before all its ancestors.
//!
//! # Fill
//!
//! Let U_b be the ancestors that block b is coupled with when it is eliminated. Eliminating b
//! (block Gaussian elimination) changes the rows and columns of U_b alone:
//!
//! ```text
//! W_b = D_b^-1 [A_bu  for u in U_b]             (n_b x 3|U_b|)
//! A_u1u2 <- A_u1u2 - A_u1b W_b[:, u2]           for u1, u2 in U_b
//! ```
//!
//! where u1 = u2 updates the particle part of D_u, and u1 != u2 the coupling between two
//! ancestors of b, one an ancestor of the other (they lie on the path from b to its root). If
//! that coupling was not in the matrix, it is *fill*: the farther one becomes coupled with the
//! nearer. The sets are therefore computed symbolically, leaves first:
//!
//! ```text
//! U_b = {ancestors u with an entry A_bu or A_ub} (the parent always)
//!       + union over the children c of b of (U_c - {b})
//! ```
//!
//! and then every coupling an elimination updates exists in storage (for u1 nearer than u2 in
//! U_b, u2 is in U_u1: by induction down the path from b to u1). This is the classic
//! elimination-tree rule of sparse factorisation, with the blocks as the nodes. The sets are
//! small: {parent} for a chain (no fill at all), {parent, grandparent} for a line with bending
//! (the fill is the coupling of i+1 with i-1 left by the elimination of i+2, which was already
//! there). A set of more than [`MAX_COUPLED_ANCESTORS`] ancestors (long-range couplings that
//! fill a chain densely) makes the analysis decline.
//!
//! # Factorisation and solve
//!
//! Each D_b (including the updates of its descendants) is factorised by a dense LU with
//! partial pivoting inside the block (a KKT block such as `[M, -s g^T; s g, 0]` has a zero
//! diagonal entry), W_b is solved from the factors, and the updates above are applied to the
//! blocks of U_b. The solve of A x = r is a forward sweep (leaves to roots: `z_b = D_b^-1 r_b`,
//! then `r_u -= A_ub z_b` for u in U_b, with the updated A_ub) and a backward sweep (roots to
//! leaves: `x_b = z_b - sum over u in U_b of W_b[:, u] x_u`), which is the block LU
//! factorisation `A = L D U` with `L_ub = A_ub D_b^-1` and `U_bu = W_b[:, u]`. The work is
//! proportional to the number of blocks times |U_b|^2.
//!
//! # Chains: the solve as matrix-vector products
//!
//! On a chain every block waits for its child's result in both sweeps, so the solve's time is the
//! latency of that dependency, not its arithmetic: a block's triangular solves are eight
//! multiply-subtracts in a row. When every block has N unknowns and is coupled with its parent
//! alone (`uniform`), the factorisation ends by replacing each block's A_Pb with
//! G_b = A_Pb D_b^-1 (its three rows solved with the factors transposed), and the sweeps become
//!
//! ```text
//! forward (leaves first):   r_P -= G_b r_b
//! backward (roots first):   x_b = D_b^-1 r_b - W_b x_P
//! ```
//!
//! the same block LU (z_b = D_b^-1 r_b, r_P -= A_Pb z_b), whose chain of dependencies is one
//! 3 x N product a block forward and one 3-term dot product backward: the solve with the factors
//! D_b^-1 r_b does not wait for the parent. The forward sweep carries a chain's update of the
//! next block in registers (stored and read back as a block, it waits for the stores to reach
//! memory), and G_b r_b is summed one entry of r_b at a time. Measured on chains of 1,000
//! particles at dt = 1 ms (generalised-alpha, blocks of 4, `crates/vinculo/benches/steps.rs`'
//! models): the solve was 40 % of a step of the hanging chain; a step of it went from 81 to
//! 63 us, of the swinging one from 303 to 272 us with Newton's default (one factorisation and
//! three solves a step), and from 426 to 421 us with full Newton (G_b costs each factorisation
//! about what a solve saves).
//!
//! A line held at both ends is such a chain but at its ends: its blocks are a node and the link
//! to its parent, but the node next to an anchor holds the link to the anchor too (a block of
//! 5 among blocks of 4), and an end point moved by constraints on its coordinates is a block of
//! its own (3 coordinates and 3 multipliers), the root. The blocks before `head` and from
//! `tail` on in the elimination order (at most [`MAX_EDGE_BLOCKS`] at either end; none for a
//! chain from one anchor) take the general sweeps, the uniform run between them the products
//! above.
//!
//! # A single block
//!
//! A matrix that is one block (a pendulum's bob and its link, a free particle and its
//! conditions) keeps the block's inverse, made once from its LU factors at each
//! factorisation: a solve is then a product, independent rows of a few terms, where the solve
//! with the factors is a chain of dependent steps through the row interchanges. Measured on the
//! pendulum against Exudyn (`vinculo.bench`'s model, generalised-alpha at 1 ms, 3.05 residuals,
//! 2.05 solves and 0.09 factorisations a step): 0.243-0.263 -> 0.217-0.222 us a step
//! (alternating builds, the least of nine runs each; callgrind: 4,935 -> 4,831 instructions a
//! step, the inverse made by unrolled copies for blocks of 3 to 5). The elimination's pivot
//! test is the LU's, as before. Blocks of a chain keep their factors: with inverses (made in
//! [`TreeElimination::make_explicit`]) a step of a swinging chain of 1,000 particles took 243
//! against 211 us, and the solve of random matrices of a chain's pattern lost digits against
//! the sparse LU's.
//!
//! # Long chains
//!
//! A chain of at least [`TWO_SIDED_FROM`] blocks is eliminated from both ends at once, each end
//! on its own thread, towards a separator block in the middle (`two_sided.rs`).
//!
//! # Singular blocks
//!
//! The elimination pivots only inside a block, so a block may be singular or nearly so while the
//! whole matrix is regular: the end particle of a straight leg whose link to its parent is
//! parallel to its anchor (a chain hung as a V of two straight legs at rest), where the block
//! holds two parallel conditions on one particle and only the parent's freedom makes the matrix
//! regular. A block pivot at round-off ([`NEAR_SINGULAR`] of the terms it was computed from,
//! per unknown: cancellation) stops the elimination, and that factorisation is made by the general sparse LU (partial pivoting
//! across the whole matrix, analysed on first need); only its failure is reported as a singular
//! matrix. The next factorisation tries the tree again (the configuration moves on).
//!
//! # Declining
//!
//! The analysis works on the matrix pattern alone and checks that every structural entry lies
//! inside a block or between a block and the particle part of an ancestor; otherwise (an edge
//! between siblings, a constraint on three particles, coupled multipliers, more than three
//! conditions on a particle's block) it declines and the caller falls back to the general sparse
//! LU.

mod two_sided;

use std::ops::Range;

pub use two_sided::TWO_SIDED_FROM;

use super::block_slots::{BlockSlots, ABSENT};
use super::{LinearSolver, Singular, SparseLu, Stored};
use crate::assembly::{Pattern, Storage};
use crate::math::LargestMagnitude;

/// Smallest pivot of a block that the elimination accepts, relative to the sum of the
/// magnitudes of the terms it was computed from (the block's entry and the products the
/// elimination subtracted from it) and per unknown of the block: a thousand round-offs of that
/// sum. Below it the pivot is cancellation, the block (nearly) singular, and the factorisation
/// falls back to the general sparse LU.
///
/// The bound is relative to the pivot's own terms, not to the block's largest entry nor to a
/// fixed share of the digits, because a block of a particle and its link is a saddle point
/// whose second pivot is naturally tiny against its particle part: |g|^2 beta h^2 / m against
/// m / (beta h^2) (6e-12 on a chain of 0.1 kg particles at dt = 1 ms: a bound of 1e-8 sent every
/// factorisation of a straight hanging chain to the sparse LU, 3.4 times slower a step on 10^4
/// particles, measured), and against the bending stiffness EI / l^3 of a line, which grows as
/// the cube of the number of segments (a bound of a thousand round-offs of the block's largest
/// entry sent most factorisations of a 500-segment cable with bending to the sparse LU,
/// although its pivots were accurate).
pub const NEAR_SINGULAR: f64 = 1e3 * f64::EPSILON;

/// Most ancestors a block may be coupled with (after fill) for the analysis to accept the
/// pattern: the work per block grows as their square, and a pattern that needs more (couplings
/// that reach far up a chain from many particles) is better served by the general sparse LU
/// with its fill-reducing ordering. A line with bending needs 2.
pub const MAX_COUPLED_ANCESTORS: usize = 8;

/// Most blocks the general sweeps may take at either end of the uniform run of a chain (module
/// documentation): the ends of a line held at both ends.
const MAX_EDGE_BLOCKS: usize = 4;

const ROOT: u32 = u32::MAX;

/// Block `$b`'s part of a sweep: `$fixed::<N, K>` for blocks of 3 to 5 unknowns coupled with one
/// or two ancestors (sizes known at compile time), `$general` for the others.
macro_rules! by_size {
    ($self:ident, $z:expr, $b:expr, $fixed:ident, $general:ident) => {
        match $self.sizes($b) {
            (3, 1) => $self.$fixed::<3, 1>($z, $b),
            (4, 1) => $self.$fixed::<4, 1>($z, $b),
            (5, 1) => $self.$fixed::<5, 1>($z, $b),
            (3, 2) => $self.$fixed::<3, 2>($z, $b),
            (4, 2) => $self.$fixed::<4, 2>($z, $b),
            (5, 2) => $self.$fixed::<5, 2>($z, $b),
            _ => $self.$general($z, $b),
        }
    };
}

/// Tree-structured block LU (see the module documentation).
pub struct TreeElimination {
    /// First local unknown of each block, in elimination order (one past the end last).
    start: Vec<usize>,
    /// First entry of each block's diagonal storage (n_b^2 entries each).
    diag_at: Vec<usize>,
    /// Position of each block's parent block in the elimination order (ROOT for roots).
    parent: Vec<u32>,
    /// The ancestors U_b each block is coupled with, fill included (positions in the
    /// elimination order, nearest first; the parent first): `ancestors[coupled_at[b]..
    /// coupled_at[b + 1]]`.
    coupled_at: Vec<usize>,
    ancestors: Vec<u32>,
    /// For each pair i1 < i2 of a block's ancestors (in the order (0, 1), (0, 2), ..., (1, 2),
    /// ...), the index of the farther one (i2) among the nearer one's (i1) ancestors: where the
    /// Schur update of their coupling goes. `fill_index[pairs_at[b]..pairs_at[b + 1]]`.
    pairs_at: Vec<usize>,
    fill_index: Vec<u32>,
    /// First entry of each block's coupling storage: 3 n_b max(|U_b|, 1) entries in `low` and
    /// in `w` (a root keeps an unused share, so that a chain's blocks are evenly spaced).
    coupling_at: Vec<usize>,
    /// Global unknown of each local unknown.
    unknowns: Vec<u32>,
    /// Whether the local order is the global one (`unknowns[i] == i`, as for a single
    /// particle and its conditions): a one-block solve then works in the right-hand side itself.
    natural_order: bool,
    /// Slots of D_b (row-major), of A_ub for the ancestors u of U_b in turn (3 x n_b each,
    /// row-major) and of [A_bu for u in U_b] (n_b x 3|U_b|, row-major); a uniform chain's
    /// are periodic (`block_slots.rs`).
    diag_slots: BlockSlots,
    low_slots: BlockSlots,
    up_slots: BlockSlots,
    /// LU factors of D_b, the A_ub (G_b = A_Pb D_b^-1 once a uniform chain is factorised, see
    /// the module documentation), and W_b = D_b^-1 [A_bu for u in U_b], in the slots' layout.
    store: BlockStore,
    /// Row interchanges of each block's LU (local indices).
    perm: Vec<u32>,
    /// Work vector in local (block) order.
    z: Vec<f64>,
    /// The common size of the blocks `head..tail` (in the elimination order), each coupled
    /// with its parent alone (a chain), or 0.
    uniform: usize,
    /// The blocks before `head` and from `tail` on take the general sweeps (module
    /// documentation): none for a chain from one anchor; for a line between a fixed anchor
    /// and a point moved by constraints, the node at the anchor (the first block) and the
    /// moved point (the last, the root).
    head: usize,
    tail: usize,
    /// Per block: its storage (D_b, A_ub, A_bu) was gathered in the current factorisation.
    gathered: Vec<bool>,
    factored: bool,
    /// The general sparse LU that factorises the matrices whose blocks are (nearly) singular,
    /// analysed on first need.
    fallback: Option<SparseLu>,
    /// The last factorisation is the fallback's.
    on_fallback: bool,
    /// Factorisations made by the fallback.
    fallbacks: usize,
    /// The matrix is assembled into `store` and factorised there
    /// ([`TreeElimination::assemble_in_place`]).
    in_place: bool,
    /// The local unknown of the (nearly) singular pivot of the last elimination that failed.
    failed: usize,
    /// Entries of the pattern (the storage entries with a slot), counted when the solver is
    /// made to factorise in place: the length of the fallback's value array.
    pattern_entries: usize,
    /// The separator block of a long chain eliminated from both ends on two threads
    /// (`two_sided.rs`), or 0.
    separator: usize,
    /// With a separator, the local unknown of each global one (`unknowns` inverted).
    local_of: Vec<u32>,
}

/// The blocks' storage, one array: the D_b (`diag`), then the A_ub or G_b (`low`), then the
/// W_b (`w`), each in the layout of its slots.
#[derive(Default)]
struct BlockStore {
    values: Vec<f64>,
    /// Where `low` and `w` start.
    low_at: usize,
    w_at: usize,
}

impl BlockStore {
    /// Zeroed storage of `diag` entries of diagonal blocks and `coupling` entries of couplings.
    fn new(diag: usize, coupling: usize) -> BlockStore {
        BlockStore {
            values: vec![0.0; diag + 2 * coupling],
            low_at: diag,
            w_at: diag + coupling,
        }
    }

    fn diag(&self) -> &[f64] {
        &self.values[..self.low_at]
    }

    fn low(&self) -> &[f64] {
        &self.values[self.low_at..self.w_at]
    }

    fn w(&self) -> &[f64] {
        &self.values[self.w_at..]
    }

    /// The three parts, to write.
    fn parts_mut(&mut self) -> (&mut [f64], &mut [f64], &mut [f64]) {
        let (diag, rest) = self.values.split_at_mut(self.low_at);
        let (low, w) = rest.split_at_mut(self.w_at - self.low_at);
        (diag, low, w)
    }
}

/// The storage an elimination writes, borrowed apart from the tree's structure: the three
/// parts of [`BlockStore`] and the row interchanges, whole or from a block on
/// (`two_sided.rs`).
struct Factors<'a> {
    diag: &'a mut [f64],
    low: &'a mut [f64],
    w: &'a mut [f64],
    perm: &'a mut [u32],
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

/// Compressed rows: for each key in 0..n, the values of the (key, value) pairs with that key,
/// in the pairs' order (`(pointers, values)`).
fn compressed(
    n: usize,
    pairs: impl Iterator<Item = (usize, u32)> + Clone,
) -> (Vec<usize>, Vec<u32>) {
    let mut ptr = vec![0usize; n + 1];
    for (key, _) in pairs.clone() {
        ptr[key + 1] += 1;
    }
    for i in 0..n {
        ptr[i + 1] += ptr[i];
    }
    let mut fill = ptr.clone();
    let mut values = vec![0u32; ptr[n]];
    for (key, value) in pairs {
        values[fill[key]] = value;
        fill[key] += 1;
    }
    (ptr, values)
}

/// Where the analysis roots each tree.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rooting {
    /// At its particle with the most multipliers of its own, else its lowest index.
    MostConstrained,
    /// At a leaf (a particle with one neighbour in the tree): the one with the most multipliers
    /// of its own, else the lowest index.
    Leaf,
}

/// Why an analysis declined.
#[derive(PartialEq, Eq)]
enum Decline {
    /// A force couples two particles neither of which is an ancestor of the other.
    AcrossBranches,
    /// Anything else (see the module documentation).
    Other,
}

impl TreeElimination {
    /// Analyses a sparse pattern whose first `particle_unknowns` unknowns come in groups of 3
    /// (one group per free particle) and whose other unknowns are single multipliers.
    /// Returns `None` when the pattern does not suit the elimination (see the module
    /// documentation; the caller then uses a general sparse LU).
    ///
    /// Each tree is rooted at its most constrained particle; when a force then couples two
    /// branches (a line's bending centred on that particle, in the middle of the line), the
    /// analysis is made again with every tree rooted at a leaf, which puts the two ends of such
    /// a coupling on one path when the tree is a path. Loops of constraints (a triangle of
    /// distances, a ring) are declined as they are.
    pub fn analyse(pattern: &Pattern, particle_unknowns: usize) -> Option<TreeElimination> {
        match Self::analyse_rooted(pattern, particle_unknowns, Rooting::MostConstrained) {
            Ok(tree) => Some(tree),
            Err(Decline::AcrossBranches) => {
                Self::analyse_rooted(pattern, particle_unknowns, Rooting::Leaf).ok()
            }
            Err(Decline::Other) => None,
        }
    }

    /// [`TreeElimination::analyse`] with the trees rooted as `rooting` says.
    fn analyse_rooted(
        pattern: &Pattern,
        particle_unknowns: usize,
        rooting: Rooting,
    ) -> Result<TreeElimination, Decline> {
        let n = pattern.n;
        if pattern.storage != Storage::Sparse
            || particle_unknowns % 3 != 0
            || particle_unknowns > n
            || pattern.nnz() >= ABSENT as usize
        {
            return Err(Decline::Other);
        }
        let np = particle_unknowns / 3;
        let nl = n - particle_unknowns;
        let particle = |u: usize| (u < particle_unknowns).then_some(u / 3);

        // Particles touched by each multiplier (at most 2), and particle-particle couplings.
        let mut touched = vec![[ABSENT; 2]; nl];
        let mut forces: Vec<(u32, u32)> = Vec::new();
        for col in 0..n {
            for &row in &pattern.row_idx[pattern.col_ptr[col]..pattern.col_ptr[col + 1]] {
                match (particle(row), particle(col)) {
                    (Some(a), Some(b)) if a < b => forces.push((a as u32, b as u32)),
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
                            return Err(Decline::Other); // a multiplier on three particles
                        }
                    }
                    (None, None) if row != col => return Err(Decline::Other), // coupled multipliers
                    (None, None) => {}
                }
            }
        }
        let mut links: Vec<(u32, u32)> = Vec::new();
        for t in &touched {
            match *t {
                [ABSENT, _] => return Err(Decline::Other), // a multiplier on no free particle
                [a, b] if b != ABSENT => links.push((a.min(b), a.max(b))),
                _ => {}
            }
        }
        links.sort_unstable();
        links.dedup();
        forces.sort_unstable();
        forces.dedup();
        // Forces by span (nearest indices first), for the spanning forest.
        forces.sort_by_key(|&(a, b)| (b - a, a));

        // Spanning forest: the constraints' edges, then the forces' that join two trees.
        let mut set: Vec<usize> = (0..np).collect();
        let mut tree_edges: Vec<(u32, u32)> = Vec::with_capacity(np);
        for &(a, b) in links.iter().chain(&forces) {
            let (ra, rb) = (find(&mut set, a as usize), find(&mut set, b as usize));
            if ra != rb {
                set[ra] = rb;
                tree_edges.push((a, b));
            }
        }
        drop(set);

        // Adjacency (CSR) of the forest, then breadth-first order from each tree's root.
        let (adj_ptr, adj) = compressed(
            np,
            tree_edges
                .iter()
                .flat_map(|&(a, b)| [(a as usize, b), (b as usize, a)]),
        );
        drop(tree_edges);
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
        match rooting {
            Rooting::MostConstrained if own.iter().any(|&k| k > 0) => {
                roots.sort_by_key(|&p| std::cmp::Reverse(own[p as usize]));
            }
            Rooting::MostConstrained => {}
            Rooting::Leaf => {
                let inner = |p: u32| adj_ptr[p as usize + 1] - adj_ptr[p as usize] > 1;
                roots.sort_by_key(|&p| (inner(p), std::cmp::Reverse(own[p as usize])));
            }
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
        drop(adj_ptr);
        drop(seen);

        // Preorder numbers and subtree sizes: u is an ancestor of v when v's number lies in
        // u's subtree range. Sizes leaves first (reverse breadth-first order), numbers roots
        // first, each child taking the next range of its parent's.
        let mut subtree = vec![1u32; np];
        for &p in order.iter().rev() {
            let q = parent_particle[p as usize];
            if q != ROOT {
                subtree[q as usize] += subtree[p as usize];
            }
        }
        let mut preorder = vec![0u32; np];
        let mut next = vec![0u32; np];
        let mut numbered = 0u32;
        for &p in &order {
            let p = p as usize;
            preorder[p] = match parent_particle[p] {
                ROOT => {
                    numbered += subtree[p];
                    numbered - subtree[p]
                }
                q => {
                    next[q as usize] += subtree[p];
                    next[q as usize] - subtree[p]
                }
            };
            next[p] = preorder[p] + 1;
        }
        drop(next);
        let is_ancestor = |u: u32, v: u32| {
            let (u, v) = (u as usize, v as usize);
            preorder[u] < preorder[v] && preorder[v] < preorder[u] + subtree[u]
        };

        // Leaves first: the reverse breadth-first order puts every child before its parent.
        order.reverse();
        let mut position = vec![0u32; np];
        for (b, &p) in order.iter().enumerate() {
            position[p as usize] = b as u32;
        }

        // Every edge joins a particle (the descendant) and one of its ancestors: the pairs
        // (descendant's block, ancestor's block), from which the sets U_b grow.
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(links.len() + forces.len());
        for (k, &(a, b)) in links.iter().chain(&forces).enumerate() {
            let (d, u) = if is_ancestor(a, b) {
                (b, a)
            } else if is_ancestor(b, a) {
                (a, b)
            } else if k >= links.len() {
                // Siblings or cousins coupled by a force: another root may join them.
                return Err(Decline::AcrossBranches);
            } else {
                // A loop of constraints (a triangle of distances, a ring).
                return Err(Decline::Other);
            };
            pairs.push((position[d as usize], position[u as usize]));
        }
        drop(links);
        drop(forces);
        pairs.sort_unstable();
        pairs.dedup();

        // Each multiplier joins its particle, or the descendant of its edge.
        let owner = |t: [u32; 2]| -> usize {
            if t[1] == ABSENT || is_ancestor(t[1], t[0]) {
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
            return Err(Decline::Other);
        }
        let blocks = np;
        let mut start = vec![0usize; np + 1];
        let mut diag_at = vec![0usize; np + 1];
        for (b, &p) in order.iter().enumerate() {
            let s = size[p as usize];
            start[b + 1] = start[b] + s;
            diag_at[b + 1] = diag_at[b] + s * s;
        }
        drop(size);
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
        drop(preorder);
        drop(subtree);
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

        // The sets U_b, leaves first: b's own couplings (its parent among them) and its
        // children's sets less b itself.
        let (children_at, children) = compressed(
            blocks,
            parent
                .iter()
                .enumerate()
                .filter(|&(_, &p)| p != ROOT)
                .map(|(b, &p)| (p as usize, b as u32)),
        );
        let mut coupled_at = vec![0usize; blocks + 1];
        let mut ancestors: Vec<u32> = Vec::with_capacity(pairs.len());
        let mut set: Vec<u32> = Vec::new();
        let mut k = 0;
        for b in 0..blocks {
            set.clear();
            while k < pairs.len() && pairs[k].0 as usize == b {
                set.push(pairs[k].1);
                k += 1;
            }
            for &c in &children[children_at[b]..children_at[b + 1]] {
                let c = c as usize;
                let of_child = &ancestors[coupled_at[c]..coupled_at[c + 1]];
                set.extend(of_child.iter().filter(|&&u| u as usize != b));
            }
            set.sort_unstable();
            set.dedup();
            if set.len() > MAX_COUPLED_ANCESTORS {
                return Err(Decline::Other);
            }
            ancestors.extend_from_slice(&set);
            coupled_at[b + 1] = ancestors.len();
        }
        drop(pairs);
        drop(children);
        drop(children_at);
        let coupled = |b: usize| &ancestors[coupled_at[b]..coupled_at[b + 1]];
        // Where the Schur updates between two ancestors of a block go.
        let mut pairs_at = vec![0usize; blocks + 1];
        let mut fill_index: Vec<u32> = Vec::new();
        for b in 0..blocks {
            let set = coupled(b);
            for (i1, &u1) in set.iter().enumerate() {
                for &u2 in &set[i1 + 1..] {
                    // Present by construction of the sets (see the module documentation).
                    let at = coupled(u1 as usize)
                        .binary_search(&u2)
                        .map_err(|_| Decline::Other)?;
                    fill_index.push(at as u32);
                }
            }
            pairs_at[b + 1] = fill_index.len();
        }
        let mut coupling_at = vec![0usize; blocks + 1];
        for b in 0..blocks {
            let nb = start[b + 1] - start[b];
            coupling_at[b + 1] = coupling_at[b] + 3 * nb * coupled(b).len().max(1);
        }

        // Slots of every block and coupling; the entries they cover must be the whole pattern.
        let mut diag_slots = vec![ABSENT; diag_at[blocks]];
        let mut low_slots = vec![ABSENT; coupling_at[blocks]];
        let mut up_slots = vec![ABSENT; coupling_at[blocks]];
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
            let set = coupled(b);
            let k = set.len();
            for (i, &u) in set.iter().enumerate() {
                for r in 0..3 {
                    let up = unknowns[start[u as usize] + r] as usize;
                    for (j, &uj) in local.iter().enumerate() {
                        let lo = slot(pattern, up, uj as usize);
                        let hi = slot(pattern, uj as usize, up);
                        covered += (lo != ABSENT) as usize + (hi != ABSENT) as usize;
                        low_slots[coupling_at[b] + 3 * nb * i + r * nb + j] = lo;
                        up_slots[coupling_at[b] + j * 3 * k + 3 * i + r] = hi;
                    }
                }
            }
        }
        if covered != pattern.nnz() {
            return Err(Decline::Other);
        }
        // The uniform run: the blocks around the middle of the elimination order that have the
        // middle block's size and at most a parent, when they are most of the blocks and at
        // most MAX_EDGE_BLOCKS others are left at either end.
        let size = |b: usize| start[b + 1] - start[b];
        let mid = blocks / 2;
        let (uniform, head, tail) = match (blocks > 0).then(|| size(mid)) {
            Some(nb) if (3..=5).contains(&nb) && coupled(mid).len() <= 1 => {
                let regular = |b: &usize| size(*b) == nb && coupled(*b).len() <= 1;
                let head = (0..mid).rev().find(|b| !regular(b)).map_or(0, |b| b + 1);
                let tail = (mid + 1..blocks).find(|b| !regular(b)).unwrap_or(blocks);
                let most = 2 * (tail - head) > blocks;
                if most && head <= MAX_EDGE_BLOCKS && blocks - tail <= MAX_EDGE_BLOCKS {
                    (nb, head, tail)
                } else {
                    (0, 0, 0)
                }
            }
            _ => (0, 0, 0),
        };
        // The uniform run's slots are periodic: kept as its first block's and their steps.
        let candidates = if uniform > 0 { head..tail } else { 0..0 };
        let diag_slots = BlockSlots::new(diag_slots, candidates.clone(), uniform * uniform, |b| {
            diag_at[b]
        });
        let low_slots = BlockSlots::new(low_slots, candidates.clone(), 3 * uniform, |b| {
            coupling_at[b]
        });
        let up_slots = BlockSlots::new(up_slots, candidates, 3 * uniform, |b| coupling_at[b]);
        let mut tree = TreeElimination {
            uniform,
            head,
            tail,
            gathered: vec![false; blocks],
            store: BlockStore::new(diag_at[blocks], coupling_at[blocks]),
            perm: vec![0; n],
            z: vec![0.0; n],
            start,
            diag_at,
            parent,
            coupled_at,
            ancestors,
            pairs_at,
            fill_index,
            coupling_at,
            natural_order: unknowns.iter().enumerate().all(|(i, &u)| u as usize == i),
            unknowns,
            diag_slots,
            low_slots,
            up_slots,
            factored: false,
            fallback: None,
            on_fallback: false,
            fallbacks: 0,
            in_place: false,
            failed: 0,
            pattern_entries: 0,
            separator: 0,
            local_of: Vec::new(),
        };
        tree.two_sided_from(TWO_SIDED_FROM);
        Ok(tree)
    }

    /// Number of blocks (free particles).
    pub fn blocks(&self) -> usize {
        self.parent.len()
    }

    /// The largest number of ancestors a block is coupled with (1 for a chain, 2 for a line
    /// with bending; 0 when no block has a parent).
    pub fn coupled_ancestors(&self) -> usize {
        self.coupled_at
            .windows(2)
            .map(|w| w[1] - w[0])
            .max()
            .unwrap_or(0)
    }

    /// The matrix pattern, rebuilt from the slots of the blocks and couplings (which cover it
    /// entry for entry, so the slots are the same), for the fallback's analysis.
    fn pattern(&self) -> Pattern {
        let n = self.unknowns.len();
        let mut entries = Vec::with_capacity(self.store.values.len());
        for b in 0..self.blocks() {
            let local = &self.unknowns[self.start[b]..self.start[b + 1]];
            let nb = local.len();
            for (i, &ui) in local.iter().enumerate() {
                for (j, &uj) in local.iter().enumerate() {
                    if self.diag_slots.get(self.diag_at[b] + i * nb + j) != ABSENT {
                        entries.push((ui as usize, uj as usize));
                    }
                }
            }
            let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b + 1]];
            let (k, at) = (set.len(), self.coupling_at[b]);
            for (i, &u) in set.iter().enumerate() {
                for r in 0..3 {
                    let up = self.unknowns[self.start[u as usize] + r] as usize;
                    for (j, &uj) in local.iter().enumerate() {
                        if self.low_slots.get(at + 3 * nb * i + r * nb + j) != ABSENT {
                            entries.push((up, uj as usize));
                        }
                        if self.up_slots.get(at + j * 3 * k + 3 * i + r) != ABSENT {
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

    /// Eliminates the blocks in order (module documentation): from the matrix `values` in the
    /// pattern's order, gathered block by block, or (None) from the matrix assembled in the
    /// storage. Returns the local unknown of a (nearly) singular pivot.
    fn eliminate_blocks(&mut self, values: Option<&[f64]>) -> Result<(), usize> {
        self.factored = false;
        self.on_fallback = false;
        // The storage is borrowed apart from the structure while the blocks are eliminated
        // (the two sides of a long chain are eliminated on two threads, `two_sided.rs`).
        let mut store = std::mem::take(&mut self.store);
        let mut perm = std::mem::take(&mut self.perm);
        let mut gathered = std::mem::take(&mut self.gathered);
        let (diag, low, w) = store.parts_mut();
        let mut f = Factors {
            diag,
            low,
            w,
            perm: &mut perm,
        };
        let result = if self.separator > 0 {
            self.eliminate_two_sided(&mut f, values)
        } else {
            self.eliminate_in_order(&mut f, &mut gathered, values)
        };
        self.store = store;
        self.perm = perm;
        self.gathered = gathered;
        result?;
        self.factored = true;
        Ok(())
    }

    /// Eliminates the blocks in order, then makes the uniform run's couplings explicit.
    fn eliminate_in_order(
        &self,
        f: &mut Factors,
        gathered: &mut [bool],
        values: Option<&[f64]>,
    ) -> Result<(), usize> {
        if let Some(values) = values {
            // The matrix's entries are gathered block by block as the elimination reaches them
            // (an ancestor's storage when the first of its descendants updates it), so that each
            // block's numbers are used while they are in cache: on a 10^6-particle chain the
            // three separate passes over 40 values per block cost as much as the elimination.
            gathered.fill(false);
            for b in 0..self.blocks() {
                self.gather_for(f, gathered, b, values);
                self.eliminate_sized(f, b)?;
            }
        } else {
            for b in 0..self.blocks() {
                self.eliminate_sized(f, b)?;
            }
        }
        self.make_explicit(f, self.head..self.tail);
        if self.blocks() == 1 {
            // One block (a pendulum's bob and its link): its inverse, which a solve multiplies
            // by (module documentation).
            let n = self.unknowns.len();
            invert_block(&mut f.diag[..n * n], &f.perm[..n]);
        }
        Ok(())
    }

    /// Gathers the storage of block b and of its coupled ancestors, where not yet gathered.
    fn gather_for(&self, f: &mut Factors, gathered: &mut [bool], b: usize, values: &[f64]) {
        if !gathered[b] {
            self.gather_block(f, b, values);
            gathered[b] = true;
        }
        for i in self.coupled_at[b]..self.coupled_at[b + 1] {
            let u = self.ancestors[i] as usize;
            if !gathered[u] {
                self.gather_block(f, u, values);
                gathered[u] = true;
            }
        }
    }

    /// [`TreeElimination::eliminate`] for block b, with unrolled copies for blocks of 3 (a
    /// free particle), 4 (a particle and its link) and 5 coupled with no ancestor (a root), one
    /// (a chain) or two (a line with bending). Returns the local unknown of a negligible pivot.
    fn eliminate_sized(&self, f: &mut Factors, b: usize) -> Result<(), usize> {
        let (s, nb) = (self.start[b], self.start[b + 1] - self.start[b]);
        let k = self.coupled_at[b + 1] - self.coupled_at[b];
        let result = match (nb, k) {
            (3, 0) => self.eliminate(f, b, 3, 0),
            (4, 0) => self.eliminate(f, b, 4, 0),
            (5, 0) => self.eliminate(f, b, 5, 0),
            (3, 1) => self.eliminate(f, b, 3, 1),
            (4, 1) => self.eliminate(f, b, 4, 1),
            (5, 1) => self.eliminate(f, b, 5, 1),
            (3, 2) => self.eliminate(f, b, 3, 2),
            (4, 2) => self.eliminate(f, b, 4, 2),
            (5, 2) => self.eliminate(f, b, 5, 2),
            _ => self.eliminate(f, b, nb, k),
        };
        result.map_err(|k| s + k)
    }

    /// Makes the solver factorise the matrix where it is assembled: in its own storage
    /// ([`LinearSolver::storage`]), whose layout is that of the blocks, so that no separate
    /// value array in the pattern's order is kept nor gathered from (on a chain of 10^6
    /// particles, 312 MB and a pass over them at every factorisation). Returns where each
    /// entry of the pattern (its slot in the pattern's value array) lies in the storage: the
    /// caller's assembly writes there instead. A block that turns out (nearly) singular then
    /// overwrites part of the matrix before it is found, so the fallback needs the matrix
    /// assembled again ([`Stored::AssembleAgain`]).
    pub fn assemble_in_place(&mut self) -> Vec<u32> {
        self.in_place = true;
        let (low_at, w_at) = (self.store.low_at, self.store.w_at);
        let mut at = vec![ABSENT; self.store.values.len()];
        for e in 0..low_at {
            at[e] = self.diag_slots.get(e);
        }
        for e in 0..w_at - low_at {
            at[low_at + e] = self.low_slots.get(e);
            at[w_at + e] = self.up_slots.get(e);
        }
        let entries = at.iter().filter(|&&s| s != ABSENT).count();
        self.pattern_entries = entries;
        let mut map = vec![ABSENT; entries];
        for (e, &slot) in at.iter().enumerate() {
            if slot != ABSENT {
                map[slot as usize] = u32::try_from(e).expect("storage within 32-bit slots");
            }
        }
        debug_assert!(
            map.iter().all(|&e| e != ABSENT),
            "the blocks cover the pattern"
        );
        map
    }

    /// The matrix in the storage, in the pattern's order (for the fallback).
    fn stored_matrix(&self) -> Vec<f64> {
        let (low_at, w_at) = (self.store.low_at, self.store.w_at);
        let mut values = vec![0.0; self.pattern_entries];
        let mut put = |slot: u32, x: f64| {
            if slot != ABSENT {
                values[slot as usize] = x;
            }
        };
        for (e, &x) in self.store.diag().iter().enumerate() {
            put(self.diag_slots.get(e), x);
        }
        for e in 0..w_at - low_at {
            put(self.low_slots.get(e), self.store.low()[e]);
            put(self.up_slots.get(e), self.store.w()[e]);
        }
        values
    }

    /// Gathers the matrix entries of block b's storage: D_b, the A_ub and the A_bu (fill
    /// entries are zero).
    fn gather_block(&self, f: &mut Factors, b: usize, values: &[f64]) {
        let (da, db) = (self.diag_at[b], self.diag_at[b + 1]);
        let (ca, cb) = (self.coupling_at[b], self.coupling_at[b + 1]);
        self.diag_slots.gather(da..db, &mut f.diag[da..db], values);
        self.low_slots.gather(ca..cb, &mut f.low[ca..cb], values);
        self.up_slots.gather(ca..cb, &mut f.w[ca..cb], values);
    }

    /// Eliminates block b of `nb` unknowns coupled with `k` ancestors (their storage gathered;
    /// the sizes as arguments, so that callers with constants get unrolled copies): factorises D_b,
    /// forms W_b = D_b^-1 [A_bu for u in U_b] and applies the Schur updates
    /// A_u1u2 -= A_u1b W_b[:, u2] to the ancestors' storage. Returns the local column of a
    /// negligible pivot.
    #[inline(always)]
    fn eliminate(&self, f: &mut Factors, b: usize, nb: usize, k: usize) -> Result<(), usize> {
        let s = self.start[b];
        let (da, db) = (self.diag_at[b], self.diag_at[b + 1]);
        let (diag, low, w) = (&mut *f.diag, &mut *f.low, &mut *f.w);
        let (own_diag, rest_diag) = diag.split_at_mut(db);
        let d = &mut own_diag[da..];
        let perm = &mut f.perm[s..s + nb];
        lu_in_place(d, nb, perm)?;
        let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b + 1]];
        let set = &set[..k];
        if k == 0 {
            return Ok(());
        }
        let (ca, cb) = (self.coupling_at[b], self.coupling_at[b + 1]);
        let (own_w, rest_w) = w.split_at_mut(cb);
        let (own_low, rest_low) = low.split_at_mut(cb);
        let (w, low) = (
            &mut own_w[ca..ca + 3 * nb * k],
            &own_low[ca..ca + 3 * nb * k],
        );
        lu_solve(d, nb, perm, w, 3 * k);
        let fill = &self.fill_index[self.pairs_at[b]..self.pairs_at[b + 1]];
        let mut pair = 0;
        for (i1, &u1) in set.iter().enumerate() {
            let u1 = u1 as usize;
            let n1 = self.start[u1 + 1] - self.start[u1];
            let low1 = &low[3 * nb * i1..3 * nb * (i1 + 1)];
            // The particle part of D_u1.
            let update = schur_product(low1, w, nb, 3 * k, 3 * i1);
            let du = &mut rest_diag[self.diag_at[u1] - db..];
            for r in 0..3 {
                for c in 0..3 {
                    du[r * n1 + c] -= update[r][c];
                }
            }
            // The couplings of u1 with the farther ancestors u2: A_u1u2 (the first three rows
            // of u1's [A_u1u for u in U_u1]) and A_u2u1 (the first three columns of its A_u2u1).
            let k1 = self.coupled_at[u1 + 1] - self.coupled_at[u1];
            let at = self.coupling_at[u1] - cb;
            for i2 in i1 + 1..k {
                let at2 = fill[pair] as usize;
                pair += 1;
                let up = schur_product(low1, w, nb, 3 * k, 3 * i2);
                let low2 = &low[3 * nb * i2..3 * nb * (i2 + 1)];
                let lo = schur_product(low2, w, nb, 3 * k, 3 * i1);
                for r in 0..3 {
                    for c in 0..3 {
                        rest_w[at + r * 3 * k1 + 3 * at2 + c] -= up[r][c];
                        rest_low[at + 3 * n1 * at2 + r * n1 + c] -= lo[r][c];
                    }
                }
            }
        }
        Ok(())
    }
}

/// The 3x3 product of `low` (3 x nb, row-major) and the columns `col..col + 3` of `w` (nb rows
/// of `stride` entries): one Schur update A_u1b W_b[:, u2].
#[inline(always)]
fn schur_product(low: &[f64], w: &[f64], nb: usize, stride: usize, col: usize) -> [[f64; 3]; 3] {
    let low = &low[..3 * nb];
    let mut s = [[0.0; 3]; 3];
    for j in 0..nb {
        let wj = &w[j * stride + col..j * stride + col + 3];
        for r in 0..3 {
            let l = low[r * nb + j];
            for c in 0..3 {
                s[r][c] += l * wj[c];
            }
        }
    }
    s
}

/// Largest block: a particle's 3 coordinates and at most 3 conditions on them (the analysis
/// declines larger ones).
const MAX_BLOCK: usize = 6;

/// In-place LU with partial pivoting of the n x n row-major matrix `a` (n <= [`MAX_BLOCK`]);
/// returns the local column of a pivot at round-off: at most [`NEAR_SINGULAR`] x n of the sum
/// of the magnitudes of the terms it was computed from, `|a_pk| + sum_j<k |l_kj| |u_jk|` (p the
/// pivot's row in `a`: the bound on its round-off of the LU's backward error analysis). On return
/// the strict lower triangle holds L (unit diagonal), the strict upper triangle U, and the
/// diagonal the reciprocals of U's pivots, so that the solves multiply where they would divide.
#[inline(always)]
fn lu_in_place(a: &mut [f64], n: usize, perm: &mut [u32]) -> Result<(), usize> {
    // Slices of known length let the unrolled copies drop their bounds checks.
    let (a, perm) = (&mut a[..n * n], &mut perm[..n]);
    // The entries as given, and the given row of each row of `a` as rows are interchanged.
    let mut given = [0.0f64; MAX_BLOCK * MAX_BLOCK];
    let given = &mut given[..n * n];
    given.copy_from_slice(a);
    let mut row = [0usize; MAX_BLOCK];
    let row = &mut row[..n];
    for (i, r) in row.iter_mut().enumerate() {
        *r = i;
    }
    let relative = NEAR_SINGULAR * n as f64;
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
            row.swap(k, p);
        }
        let pivot = a[k * n + k];
        let mut size = given[row[k] * n + k].abs();
        for j in 0..k {
            size += (a[k * n + j] * a[j * n + k]).abs();
        }
        if !pivot.is_finite() || pivot.abs() <= relative * size {
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
/// factorisation's W = D^-1 [A_bu ...] with m = 3 |U_b|, and the solve of blocks larger than
/// 5). Zero entries of L are skipped: a KKT block's mass part gives many.
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

/// Replaces the factors of `lu_in_place` of an n x n block `d` (row interchanges `perm`) by
/// the block's inverse, solved column by column of the identity.
#[inline(always)]
pub(super) fn invert_in_place(d: &mut [f64], n: usize, perm: &[u32]) {
    let mut x = [0.0; MAX_BLOCK * MAX_BLOCK];
    for r in 0..n {
        x[n * r + r] = 1.0;
    }
    lu_solve(d, n, perm, &mut x, n);
    d[..n * n].copy_from_slice(&x[..n * n]);
}

/// [`invert_in_place`] for a block of `perm.len()` unknowns: unrolled copies for blocks of 3
/// to 5, as [`solve_block`].
fn invert_block(d: &mut [f64], perm: &[u32]) {
    match perm.len() {
        3 => invert_in_place(d, 3, perm),
        4 => invert_in_place(d, 4, perm),
        5 => invert_in_place(d, 5, perm),
        n => invert_in_place(d, n, perm),
    }
}

/// z = D^-1 z in place, for a block whose storage holds D^-1 (`invert_in_place`): copies
/// unrolled for blocks of 3 to 5 unknowns.
#[inline(always)]
fn inverse_times(inverse: &[f64], z: &mut [f64]) {
    match z.len() {
        3 => inverse_times_fixed::<3>(inverse, z),
        4 => inverse_times_fixed::<4>(inverse, z),
        5 => inverse_times_fixed::<5>(inverse, z),
        n => {
            let mut r = [0.0; MAX_BLOCK];
            r[..n].copy_from_slice(z);
            for (zi, row) in z.iter_mut().zip(inverse.chunks_exact(n)) {
                *zi = row.iter().zip(&r).map(|(a, b)| a * b).sum();
            }
        }
    }
}

/// [`inverse_times`] for N unknowns known at compile time.
#[inline(always)]
fn inverse_times_fixed<const N: usize>(inverse: &[f64], z: &mut [f64]) {
    let inverse = &inverse[..N * N];
    let r: [f64; N] = z[..N].try_into().expect("N unknowns");
    for (i, zi) in z[..N].iter_mut().enumerate() {
        let mut s = 0.0;
        for j in 0..N {
            s += inverse[i * N + j] * r[j];
        }
        *zi = s;
    }
}

/// Solves D z = z in place with the factors of `lu_in_place`, for a block of N unknowns known
/// at compile time: unrolled, with the running sums kept in registers.
#[inline(always)]
fn block_solve_fixed<const N: usize>(d: &[f64], perm: &[u32], zb: &mut [f64]) {
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
}

/// Solves D z = z in place with the factors of `lu_in_place` for a block of `zb.len()`
/// unknowns: blocks of 3 (a free particle), 4 (a particle and its link) and 5 get unrolled
/// copies.
#[inline(always)]
fn solve_block(d: &[f64], perm: &[u32], zb: &mut [f64]) {
    match zb.len() {
        3 => block_solve_fixed::<3>(d, perm, zb),
        4 => block_solve_fixed::<4>(d, perm, zb),
        5 => block_solve_fixed::<5>(d, perm, zb),
        nb => lu_solve(d, nb, perm, zb, 1),
    }
}

/// z_u -= A_ub z_b for one ancestor u: `low` is A_ub (3 x nb, row-major), `zu` the particle
/// part of z_u.
#[inline(always)]
fn subtract_coupling(low: &[f64], zb: &[f64], zu: &mut [f64]) {
    let nb = zb.len();
    let (low, zu) = (&low[..3 * nb], &mut zu[..3]);
    for r in 0..3 {
        let mut acc = 0.0;
        for j in 0..nb {
            acc += low[r * nb + j] * zb[j];
        }
        zu[r] -= acc;
    }
}

/// The row vector `a` times D^-1, in place, with the factors of `lu_in_place` (D = P^-1 L U,
/// U's diagonal stored inverted): a U^-1, then times L^-1, then times P (the row interchanges
/// undone last to first).
#[inline(always)]
fn row_times_inverse<const N: usize>(d: &[f64], perm: &[u32], a: &mut [f64; N]) {
    let (d, perm) = (&d[..N * N], &perm[..N]);
    for j in 0..N {
        let mut t = a[j];
        for i in 0..j {
            t -= a[i] * d[i * N + j];
        }
        a[j] = t * d[j * N + j];
    }
    for j in (0..N).rev() {
        let mut t = a[j];
        for i in j + 1..N {
            t -= a[i] * d[i * N + j];
        }
        a[j] = t;
    }
    for k in (0..N).rev() {
        a.swap(k, (perm[k] as usize).min(N - 1));
    }
}

impl LinearSolver for TreeElimination {
    fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        match self.eliminate_blocks(Some(values)) {
            Ok(()) => Ok(()),
            // A (nearly) singular block need not mean a singular matrix: the sparse LU pivots
            // across blocks, and its failure is the one reported.
            Err(failed) => self.factor_by_fallback(values, failed),
        }
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.solve_and_measure(rhs, false);
    }

    fn solve_in_place_with_norm(&mut self, rhs: &mut [f64]) -> f64 {
        self.solve_and_measure(rhs, true)
    }

    fn name(&self) -> &'static str {
        "tree elimination"
    }

    fn fallbacks(&self) -> usize {
        self.fallbacks
    }

    fn in_place(&self) -> bool {
        self.in_place
    }

    fn storage(&mut self) -> Option<&mut [f64]> {
        self.in_place.then_some(&mut self.store.values[..])
    }

    fn factor_stored(&mut self) -> Result<Stored, Singular> {
        assert!(self.in_place, "factor_stored without assemble_in_place");
        match self.eliminate_blocks(None) {
            Ok(()) => Ok(Stored::Factorised),
            Err(failed) => {
                self.failed = failed;
                Ok(Stored::AssembleAgain)
            }
        }
    }

    fn factor_stored_by_fallback(&mut self) -> Result<(), Singular> {
        let values = self.stored_matrix();
        self.factor_by_fallback(&values, self.failed)
    }

    /// The storage, then each unknown's row interchange (exact as f64).
    fn factors(&self) -> Option<Vec<f64>> {
        (self.in_place && self.factored && !self.on_fallback).then(|| {
            let mut f = self.store.values.clone();
            f.extend(self.perm.iter().map(|&p| p as f64));
            f
        })
    }

    fn adopt_factors(&mut self, factors: &[f64]) -> bool {
        let n = self.store.values.len();
        if !self.in_place || factors.len() != n + self.perm.len() {
            return false;
        }
        self.store.values.copy_from_slice(&factors[..n]);
        for (p, &f) in self.perm.iter_mut().zip(&factors[n..]) {
            *p = f as u32;
        }
        self.on_fallback = false;
        self.factored = true;
        true
    }
}

impl TreeElimination {
    /// The solve in place, and the infinity norm of the solution when `measure` (NaN where an
    /// entry is NaN; else 0), taken as the solution is put back in the right-hand side's order.
    fn solve_and_measure(&mut self, rhs: &mut [f64], measure: bool) -> f64 {
        assert!(self.factored, "solve before a successful factorisation");
        let norm_of = |rhs: &[f64]| {
            if measure {
                crate::integrators::newton::inf_norm(rhs)
            } else {
                0.0
            }
        };
        if self.on_fallback {
            let lu = self.fallback.as_mut().expect("the fallback factorised");
            lu.solve_in_place(rhs);
            return norm_of(rhs);
        }
        if self.blocks() == 1 {
            // One block (a single particle and its conditions, as a pendulum's bob): its
            // factors' solve alone, without the sweeps' bookkeeping (a third of a step's
            // instructions on the pendulum went to it).
            self.solve_single_block(rhs);
            return norm_of(rhs);
        }
        if self.separator > 0 {
            return self.solve_two_sided(rhs, measure);
        }
        let mut z = std::mem::take(&mut self.z);
        for (z, &u) in z.iter_mut().zip(&self.unknowns) {
            *z = rhs[u as usize];
        }
        let n = self.blocks();
        match self.uniform {
            3 => self.sweeps_explicit::<3>(&mut z, n),
            4 => self.sweeps_explicit::<4>(&mut z, n),
            5 => self.sweeps_explicit::<5>(&mut z, n),
            _ => self.sweeps(&mut z),
        }
        let norm = scatter(&z, &self.unknowns, rhs, measure);
        self.z = z;
        norm
    }
}

/// Puts `z` (in the blocks' order) back into `rhs` at `unknowns`, and returns the infinity norm
/// of `z` when `measure` (NaN where an entry is NaN; else 0), taken in the same pass.
fn scatter(z: &[f64], unknowns: &[u32], rhs: &mut [f64], measure: bool) -> f64 {
    if !measure {
        for (z, &u) in z.iter().zip(unknowns) {
            rhs[u as usize] = *z;
        }
        return 0.0;
    }
    let mut largest = LargestMagnitude::default();
    for (z, u) in z.chunks(4).zip(unknowns.chunks(4)) {
        for (l, (&x, &u)) in z.iter().zip(u).enumerate() {
            rhs[u as usize] = x;
            largest.take(l, x);
        }
    }
    largest.norm()
}

impl TreeElimination {
    /// The solve of a matrix that is one block: z = D^-1 r, in place, by the inverse the
    /// factorisation left (module documentation, "A single block").
    fn solve_single_block(&mut self, rhs: &mut [f64]) {
        let n = self.unknowns.len();
        let inverse = &self.store.diag()[self.diag_at[0]..self.diag_at[1]];
        if self.natural_order {
            inverse_times(inverse, &mut rhs[..n]);
            return;
        }
        let z = &mut self.z[..n];
        for (z, &u) in z.iter_mut().zip(&self.unknowns) {
            *z = rhs[u as usize];
        }
        inverse_times(inverse, z);
        for (z, &u) in z.iter().zip(&self.unknowns) {
            rhs[u as usize] = *z;
        }
    }

    /// The forward and backward sweeps of the solve on the work vector `z` (blocks of any size,
    /// any number of coupled ancestors).
    fn sweeps(&self, z: &mut [f64]) {
        for b in 0..self.blocks() {
            by_size!(self, z, b, forward_fixed, forward_general);
        }
        for b in (0..self.blocks()).rev() {
            by_size!(self, z, b, backward_fixed, backward_general);
        }
    }

    /// Both sweeps of a uniform chain over the blocks before `end` (all of them, or one side
    /// of a chain eliminated from both ends, `two_sided.rs`), whose parents' unknowns are
    /// final before the backward sweep reaches them.
    fn sweeps_explicit<const N: usize>(&self, z: &mut [f64], end: usize) {
        self.forward_explicit::<N>(z, end);
        self.backward_explicit::<N>(z, end);
    }

    /// Block b's number of unknowns and of coupled ancestors.
    #[inline(always)]
    fn sizes(&self, b: usize) -> (usize, usize) {
        let nb = self.start[b + 1] - self.start[b];
        (nb, self.coupled_at[b + 1] - self.coupled_at[b])
    }

    /// [`TreeElimination::forward_general`] for a block of N unknowns coupled with K ancestors
    /// known at compile time (a line with bending: 4 and 2), the same operations unrolled.
    #[inline(always)]
    fn forward_fixed<const N: usize, const K: usize>(&self, z: &mut [f64], b: usize) {
        let (s, e) = (self.start[b], self.start[b + 1]);
        let d = &self.store.diag()[self.diag_at[b]..self.diag_at[b + 1]];
        let (head, tail) = z.split_at_mut(e);
        let zb = &mut head[s..];
        block_solve_fixed::<N>(d, &self.perm[s..e], zb);
        let zb: &[f64; N] = (&zb[..N]).try_into().expect("N unknowns");
        let ca = self.coupling_at[b];
        let low = &self.store.low()[ca..ca + 3 * N * K];
        let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b] + K];
        for (&u, low) in set.iter().zip(low.chunks_exact(3 * N)) {
            subtract_coupling(low, zb, &mut tail[self.start[u as usize] - e..]);
        }
    }

    /// [`TreeElimination::backward_general`] for a block of N unknowns coupled with K ancestors
    /// known at compile time, the same operations unrolled.
    #[inline(always)]
    fn backward_fixed<const N: usize, const K: usize>(&self, z: &mut [f64], b: usize) {
        let (s, e) = (self.start[b], self.start[b + 1]);
        let (head, tail) = z.split_at_mut(e);
        let zb = &mut head[s..s + N];
        let ca = self.coupling_at[b];
        let w = &self.store.w()[ca..ca + 3 * K * N];
        let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b] + K];
        for (i, &u) in set.iter().enumerate() {
            let at = self.start[u as usize] - e;
            let xu = [tail[at], tail[at + 1], tail[at + 2]];
            for (x, wj) in zb.iter_mut().zip(w.chunks_exact(3 * K)) {
                let wj = &wj[3 * i..3 * i + 3];
                *x -= wj[0] * xu[0] + wj[1] * xu[1] + wj[2] * xu[2];
            }
        }
    }

    /// Block b's part of the forward sweep: z_b = D_b^-1 r_b, then r_u -= A_ub z_b for u in U_b.
    #[inline]
    fn forward_general(&self, z: &mut [f64], b: usize) {
        let (s, e) = (self.start[b], self.start[b + 1]);
        let d = &self.store.diag()[self.diag_at[b]..self.diag_at[b + 1]];
        let (head, tail) = z.split_at_mut(e);
        let zb = &mut head[s..];
        solve_block(d, &self.perm[s..e], zb);
        let nb = e - s;
        let low = &self.store.low()[self.coupling_at[b]..self.coupling_at[b + 1]];
        let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b + 1]];
        for (i, &u) in set.iter().enumerate() {
            let zu = &mut tail[self.start[u as usize] - e..];
            subtract_coupling(&low[3 * nb * i..], zb, zu);
        }
    }

    /// Block b's part of the backward sweep: x_b = z_b - sum over u in U_b of W_b[:, u] x_u.
    #[inline]
    fn backward_general(&self, z: &mut [f64], b: usize) {
        let set = &self.ancestors[self.coupled_at[b]..self.coupled_at[b + 1]];
        let k = set.len();
        if k == 0 {
            return;
        }
        let (s, e) = (self.start[b], self.start[b + 1]);
        let (head, tail) = z.split_at_mut(e);
        let zb = &mut head[s..];
        let w = &self.store.w()[self.coupling_at[b]..self.coupling_at[b] + 3 * k * (e - s)];
        for (i, &u) in set.iter().enumerate() {
            let at = self.start[u as usize] - e;
            let xu = [tail[at], tail[at + 1], tail[at + 2]];
            for (x, wj) in zb.iter_mut().zip(w.chunks_exact(3 * k)) {
                let wj = &wj[3 * i..3 * i + 3];
                *x -= wj[0] * xu[0] + wj[1] * xu[1] + wj[2] * xu[2];
            }
        }
    }

    /// After the elimination of a uniform chain (module documentation): the A_Pb of each block
    /// of `blocks` (a part of the uniform run) becomes G_b = A_Pb D_b^-1, each of its rows
    /// solved from the factors transposed.
    fn make_explicit(&self, f: &mut Factors, blocks: Range<usize>) {
        match self.uniform {
            3 => self.make_explicit_sized::<3>(f, blocks),
            4 => self.make_explicit_sized::<4>(f, blocks),
            5 => self.make_explicit_sized::<5>(f, blocks),
            _ => {}
        }
    }

    /// [`TreeElimination::make_explicit`] for blocks of N unknowns.
    fn make_explicit_sized<const N: usize>(&self, f: &mut Factors, blocks: Range<usize>) {
        let (h, t) = (blocks.start, blocks.end);
        if h >= t {
            return;
        }
        let blocks = f.diag[self.diag_at[h]..self.diag_at[t]]
            .chunks_exact(N * N)
            .zip(f.perm[self.start[h]..self.start[t]].chunks_exact(N))
            .zip(f.low[self.coupling_at[h]..self.coupling_at[t]].chunks_exact_mut(3 * N));
        for ((d, perm), low) in blocks {
            for row in low.chunks_exact_mut(N) {
                let row: &mut [f64; N] = row.try_into().expect("N entries");
                row_times_inverse::<N>(d, perm, row);
            }
        }
    }

    /// The forward sweep of a uniform chain after [`TreeElimination::make_explicit`] (module
    /// documentation) over the blocks before `end`: the general sweep for the blocks before
    /// `head` and from `tail` on, products for the others, block head + k starting at N k past
    /// the head's unknowns, its LU factors at N^2 k past the head's, its G_b and W_b at 3 N k
    /// past the head's.
    fn forward_explicit<const N: usize>(&self, z: &mut [f64], end: usize) {
        let (h, t) = (self.head.min(end), self.tail.min(end));
        for b in 0..h {
            self.forward_general(z, b);
        }
        let (z0, c0) = (self.start[h], self.coupling_at[h]);
        let start = &self.start;
        // Forward, leaves first: r_P -= G_b r_b (block b's r is final: its children came first).
        // The update of a parent that comes next (a chain's) is carried in registers to it:
        // written to memory and read back at once as a block, it would wait for the stores.
        let mut carry = [0.0f64; 3];
        let mut carried_to = usize::MAX;
        let low = self.store.low()[c0..].chunks_exact(3 * N);
        for (k, (g, &pb)) in low.zip(&self.parent[h..t]).enumerate() {
            let b = h + k;
            if carried_to != b {
                carry = [0.0; 3];
            }
            // r_b (with the carried update) and G_b r_b, one entry of r_b at a time in
            // registers (an array of them would go through memory).
            let zb = &mut z[z0 + N * k..z0 + N * k + N];
            let g = &g[..3 * N];
            let mut update = [0.0f64; 3];
            for i in 0..N {
                let ri = zb[i] - if i < 3 { carry[i] } else { 0.0 };
                zb[i] = ri;
                update[0] += g[i] * ri;
                update[1] += g[N + i] * ri;
                update[2] += g[2 * N + i] * ri;
            }
            if pb == ROOT {
                continue;
            }
            let p = pb as usize;
            if p == b + 1 && p < t {
                (carry, carried_to) = (update, p);
            } else {
                for r in 0..3 {
                    z[start[p] + r] -= update[r];
                }
            }
        }
        for b in t.max(self.tail)..end {
            self.forward_general(z, b);
        }
    }

    /// The backward sweep matching [`TreeElimination::forward_explicit`] over the blocks before
    /// `end` (their parents' unknowns already final): x_b = D_b^-1 r_b - W_b x_P (the solve
    /// with the factors does not wait for x_P).
    fn backward_explicit<const N: usize>(&self, z: &mut [f64], end: usize) {
        let (h, t) = (self.head.min(end), self.tail.min(end));
        for b in (t.max(self.tail)..end).rev() {
            self.backward_general(z, b);
        }
        let (z0, d0, c0) = (self.start[h], self.diag_at[h], self.coupling_at[h]);
        let start = &self.start;
        let blocks = self.store.diag()[d0..]
            .chunks_exact(N * N)
            .zip(self.perm[z0..].chunks_exact(N))
            .zip(self.store.w()[c0..].chunks_exact(3 * N))
            .zip(&self.parent[h..t]);
        for (k, (((d, perm), w), &pb)) in blocks.enumerate().rev() {
            let (before, after) = z.split_at_mut(z0 + N * k + N);
            let zb = &mut before[z0 + N * k..];
            block_solve_fixed::<N>(d, perm, zb);
            if pb != ROOT {
                // The parent's unknowns, past this block's end: by the run's layout when it is
                // in the run (a chain's next block), from the table at the run's end.
                let pb = pb as usize;
                let at = if pb < self.tail {
                    z0 + N * (pb - h)
                } else {
                    start[pb]
                };
                let p = at - (z0 + N * k + N);
                let xp = [after[p], after[p + 1], after[p + 2]];
                for i in 0..N {
                    zb[i] -= w[3 * i] * xp[0] + w[3 * i + 1] * xp[1] + w[3 * i + 2] * xp[2];
                }
            }
        }
        for b in (0..h).rev() {
            self.backward_general(z, b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Layout;
    use crate::laws::VectorLaw;
    use crate::linear::{for_layout, DenseLu, SparseLu, SparseSolver};
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
        for (row, col, k) in p.entries() {
            v[k] = rng.next();
            if row == col && row < 3 * layout.free {
                v[k] += 6.0;
            }
        }
        v
    }

    impl TreeElimination {
        /// Slots kept one by one, and the storage entries.
        fn slots_kept(&self) -> (usize, usize) {
            let kept = self.diag_slots.explicit_len()
                + self.low_slots.explicit_len()
                + self.up_slots.explicit_len();
            (kept, self.store.values.len())
        }
    }

    fn solve(solver: &mut dyn LinearSolver, values: &[f64], b: &[f64]) -> Vec<f64> {
        solver.factor(values).unwrap();
        let mut x = b.to_vec();
        solver.solve_in_place(&mut x);
        assert_measured(solver, b, &x);
        x
    }

    /// The solve that also measures its solution gives the same solution, bit for bit, and its
    /// infinity norm (the largest entry does not depend on the order it is taken in), and NaN
    /// for a right-hand side with a NaN.
    fn assert_measured(solver: &mut dyn LinearSolver, b: &[f64], x: &[f64]) {
        let mut y = b.to_vec();
        let norm = solver.solve_in_place_with_norm(&mut y);
        assert_eq!(x, &y[..]);
        assert_eq!(norm, crate::integrators::newton::inf_norm(x));
        let mut y = b.to_vec();
        y[b.len() / 2] = f64::NAN;
        assert!(solver.solve_in_place_with_norm(&mut y).is_nan());
    }

    /// Tree elimination and faer's general sparse LU give the same solution (to 1e-12 relative)
    /// on random matrices with the patterns of a chain, of a chain held at both ends, of a
    /// chain whose far end is moved by constraints and of a branched string (row interchanges
    /// inside the blocks included); the reference is the sparse LU, and the residual against
    /// the matrix is checked too. The chain's blocks (a particle and its link, each coupled with
    /// its parent alone) are solved by matrix-vector products (module documentation), and so
    /// are those of the other two chains but their ends' (the block of 5 of the node next to a
    /// second anchor, the block of 6 of an end with its three coordinates prescribed, the
    /// root), the branched string's by the general sweeps; a pendulum's one block (its bob and
    /// link, in the global order) is solved in the right-hand side itself. The chains' slots are periodic
    /// over their uniform run (`block_slots.rs`): at most six blocks keep theirs one by one.
    /// The fixture's chain of `n` links with its far end tied to a second anchor (`held`), or
    /// to a particle whose three coordinates are prescribed (the end of a line moved by its
    /// fairlead).
    fn chain_to(n: usize, held: bool) -> System {
        let mut s = crate::integrators::fixtures::chain(n);
        let last = s.particle_id(n).unwrap();
        let x = [0.1 * n as f64 + 0.05, 0.0, 0.0];
        let end = s.add_particle(1.0, x, [0.0; 3], held).unwrap();
        s.add_distance(last, end, None).unwrap();
        if !held {
            for axis in 0..3 {
                s.add_fixed_coordinate(end, axis, None).unwrap();
            }
        }
        s
    }

    /// A chain of `n` particles joined by spring-dampers alone, the first to a fixed anchor: a
    /// chain of blocks of 3 (a particle, no multiplier) coupled by the forces' Jacobians.
    fn spring_chain(n: usize) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        for i in 1..=n {
            let x = [0.1 * i as f64, 0.0, 0.0];
            let p = s.add_particle(0.1, x, [0.0; 3], false).unwrap();
            s.add_spring_damper(prev, p, 100.0, 0.5, None).unwrap();
            prev = p;
        }
        s
    }

    /// The solution of `b` with the matrix `v` is the sparse LU's to 1e-12 relative, and its
    /// residual against the matrix below 1e-12 of the solution's size.
    fn check_solution(layout: &Layout, v: &[f64], b: &[f64], x: &[f64], what: &str) {
        let mut lu = SparseLu::new(&layout.pattern);
        let y = solve(&mut lu, v, b);
        let scale = y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..b.len() {
            assert!(
                (x[i] - y[i]).abs() <= 1e-12 * scale,
                "{what}, unknown {i}: tree {} vs sparse LU {}",
                x[i],
                y[i]
            );
        }
        let mut r = b.to_vec();
        for (row, col, k) in layout.pattern.entries() {
            r[row] -= v[k] * x[col];
        }
        // Relative to the solution's size (x up to 550 on these random matrices).
        let bound = 1e-12 * scale.max(1.0);
        assert!(r.iter().all(|e| e.abs() < bound), "{what}: residual {r:?}");
    }

    #[test]
    fn tree_elimination_matches_sparse_lu() {
        use crate::integrators::fixtures::chain;
        let (held, moved) = (chain_to(30, true), chain_to(30, false));
        let cases = [
            (chain(1), 2, (4, 0, 1)),
            (chain(30), 5, (4, 0, 30)),
            (held, 3, (4, 1, 30)),
            (moved, 9, (4, 1, 30)),
            (branched_string(1), 1, (0, 0, 0)),
            (branched_string(40), 7, (0, 0, 0)),
        ];
        for (system, seed, (uniform, head, tail)) in cases {
            let layout = Layout::new(&system, 0);
            let mut tree = TreeElimination::analyse(&layout.pattern, 3 * layout.free)
                .expect("a chain and a branched string are trees");
            assert_eq!((tree.uniform, tree.head, tree.tail), (uniform, head, tail));
            assert_eq!(tree.natural_order, tree.blocks() == 1);
            let (kept, entries) = tree.slots_kept();
            if uniform > 0 {
                assert!(kept <= 6 * entries / tree.blocks(), "{kept} of {entries}");
            } else {
                assert_eq!(kept, entries);
            }
            let n = layout.unknowns();
            let mut rng = Lcg(seed + 100);
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            for round in 0..3 {
                let v = values(&layout, seed + round);
                let x = solve(&mut tree, &v, &b);
                check_solution(&layout, &v, &b, &x, "one side");
            }
        }
    }

    /// A chain eliminated from both ends (`two_sided.rs`), with the separator anywhere along
    /// its uniform run, solves as faer's general sparse LU does (to 1e-12 relative, and the
    /// residual against the matrix): a chain from one anchor, one held by a second anchor, one
    /// whose far end is moved by constraints (the root side then holds the blocks of 5 and 6 at
    /// its end), a chain of springs (blocks of 3), from the matrix in the pattern's order and assembled in place, and three
    /// factorisations in a row (the storage holds the last one's factors when the next is
    /// assembled). The chains are far shorter than the default length for two threads: the
    /// separator is set here.
    #[test]
    fn chains_eliminated_from_both_ends_match_sparse_lu() {
        use crate::integrators::fixtures::chain;
        // The seeds of the one-sided test's matrices (random matrices of a chain's pattern
        // can be ill-conditioned: the one-sided elimination's residual is 6e-10 on another).
        let cases = [
            (chain(30), 5),
            (chain_to(30, true), 3),
            (chain_to(30, false), 9),
            (spring_chain(30), 5),
        ];
        for (system, seed) in &cases {
            let layout = Layout::new(system, 0);
            let n = layout.unknowns();
            let mut rng = Lcg(seed + 100);
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            for (separator, in_place) in [(2, false), (15, false), (27, false), (13, true)] {
                let mut tree = TreeElimination::analyse(&layout.pattern, 3 * layout.free).unwrap();
                assert_eq!(tree.separator, 0, "a short chain takes one side");
                assert!(tree.two_sided_from(0), "seed {seed}: a chain");
                tree.separator = separator;
                let map = in_place.then(|| tree.assemble_in_place());
                for round in 0..3 {
                    let v = values(&layout, seed + round);
                    let x = match &map {
                        None => solve(&mut tree, &v, &b),
                        Some(map) => {
                            let storage = tree.storage().unwrap();
                            storage.fill(0.0);
                            for (slot, &e) in map.iter().enumerate() {
                                storage[e as usize] = v[slot];
                            }
                            assert_eq!(tree.factor_stored().unwrap(), Stored::Factorised);
                            let mut x = b.clone();
                            tree.solve_in_place(&mut x);
                            assert_measured(&mut tree, &b, &x);
                            x
                        }
                    };
                    let what = format!("seed {seed}, separator {separator}, round {round}");
                    check_solution(&layout, &v, &b, &x, &what);
                }
            }
        }
    }

    /// A loop between particles neither of which is an ancestor of the other (a spring from the
    /// tip of the main chain to the end of the side branch, or a triangle of distances) makes
    /// the solver fall back to the general sparse LU; a chain gets the tree, and so does a loop
    /// that joins a particle to an ancestor (a spring from the tip back to the first particle,
    /// the root), which couples every particle of the path with the root (fill).
    #[test]
    fn loops_between_siblings_fall_back_to_sparse_lu() {
        let name = |s: &System| {
            let layout = Layout::new(s, 0);
            for_layout(&layout.pattern, 3 * layout.free, SparseSolver::Auto).name()
        };
        let mut s = branched_string(10);
        assert_eq!(name(&s), "tree elimination");
        let tip = s.particle_id(10).unwrap();
        let branch_end = s.particle_id(13).unwrap();
        let mut cousins = s.clone();
        cousins
            .add_spring_damper(tip, branch_end, 1.0, 0.0, None)
            .unwrap();
        assert_eq!(name(&cousins), "sparse LU");
        let first = s.particle_id(1).unwrap();
        s.add_spring_damper(first, tip, 1.0, 0.0, None).unwrap();
        let layout = Layout::new(&s, 0);
        let tree = TreeElimination::analyse(&layout.pattern, 3 * layout.free)
            .expect("a loop through the root is an ancestor coupling");
        // The particles between the tip and the root are coupled with their parent and the
        // root.
        assert_eq!(tree.coupled_ancestors(), 2);

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

    /// A KKT-like matrix on `particles` particles (3 unknowns each): a dense 3x3 diagonal block
    /// per particle (dominant), dense 3x3 blocks both ways for each particle pair of
    /// `couplings`, and one multiplier per entry of `multipliers` (its particles: one, or two
    /// for a link), with a row and a column on each of its particles' coordinates and a
    /// diagonal entry when it is compliant (`true`), none otherwise (a saddle point). Returns
    /// the sparse pattern, the entries (row, column, value) and the number of particle
    /// unknowns.
    #[allow(clippy::type_complexity)]
    fn kkt_matrix(
        particles: usize,
        couplings: &[(usize, usize)],
        multipliers: &[(usize, Option<usize>, bool)],
        seed: u64,
    ) -> (Pattern, Vec<(usize, usize, f64)>, usize) {
        let mut rng = Lcg(seed);
        let mut entries = Vec::new();
        let mut block = |entries: &mut Vec<(usize, usize, f64)>, a: usize, b: usize| {
            for r in 0..3 {
                for c in 0..3 {
                    let dominant = if a == b && r == c { 20.0 } else { 0.0 };
                    entries.push((3 * a + r, 3 * b + c, dominant + rng.next()));
                }
            }
        };
        for p in 0..particles {
            block(&mut entries, p, p);
        }
        for &(a, b) in couplings {
            block(&mut entries, a, b);
            block(&mut entries, b, a);
        }
        let mut rng = Lcg(seed + 1);
        for (k, &(a, b, compliant)) in multipliers.iter().enumerate() {
            let m = 3 * particles + k;
            for p in std::iter::once(a).chain(b) {
                for r in 0..3 {
                    let g = rng.next();
                    // A constraint's gradient as a row, and (scaled) as a column.
                    entries.push((m, 3 * p + r, g));
                    entries.push((3 * p + r, m, -0.5 * g + 0.1 * rng.next()));
                }
            }
            if compliant {
                entries.push((m, m, -0.05 - 0.05 * rng.next().abs()));
            }
        }
        let n = 3 * particles + multipliers.len();
        let pattern = Pattern::new(n, entries.iter().map(|&(i, j, _)| (i, j)).collect(), false);
        (pattern, entries, 3 * particles)
    }

    /// Solves A x = b with `solver` for the entries of `kkt_matrix`; returns x and the residual
    /// |b - A x|_inf relative to |A|_inf |x|_inf.
    fn kkt_solve(
        solver: &mut dyn LinearSolver,
        pattern: &Pattern,
        entries: &[(usize, usize, f64)],
        b: &[f64],
    ) -> (Vec<f64>, f64) {
        let mut values = vec![0.0; pattern.nnz()];
        for &(i, j, v) in entries {
            values[pattern.slot(i, j)] += v;
        }
        let x = solve(solver, &values, b);
        let mut r = b.to_vec();
        let mut row_sums = vec![0.0; b.len()];
        for &(i, j, v) in entries {
            r[i] -= v * x[j];
            row_sums[i] += v.abs();
        }
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let residual = norm(&r) / (norm(&row_sums) * norm(&x));
        (x, residual)
    }

    /// The tree elimination of `kkt_matrix` agrees with the dense LU (faer, partial pivoting on
    /// the whole matrix: the reference) to 1e-12 relative, and both residuals are at round-off.
    fn check_against_dense_lu(
        particles: usize,
        couplings: &[(usize, usize)],
        multipliers: &[(usize, Option<usize>, bool)],
        ancestors: usize,
    ) {
        for seed in [3, 11, 29] {
            let (pattern, entries, particle_unknowns) =
                kkt_matrix(particles, couplings, multipliers, seed);
            let mut tree = TreeElimination::analyse(&pattern, particle_unknowns)
                .expect("couplings to ancestors only");
            assert_eq!(tree.coupled_ancestors(), ancestors);
            let n = pattern.n;
            let dense = Pattern::new(n, entries.iter().map(|&(i, j, _)| (i, j)).collect(), true);
            let mut lu = DenseLu::new(n);
            let mut rng = Lcg(seed + 7);
            let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let (x, rx) = kkt_solve(&mut tree, &pattern, &entries, &b);
            let (y, ry) = kkt_solve(&mut lu, &dense, &entries, &b);
            assert_eq!(tree.fallbacks(), 0, "the tree elimination made the solve");
            assert!(
                rx < 1e-14 && ry < 1e-14,
                "residuals {rx:.2e} (tree), {ry:.2e} (LU)"
            );
            let scale = y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for i in 0..n {
                assert!(
                    (x[i] - y[i]).abs() <= 1e-12 * scale,
                    "seed {seed}, unknown {i}: tree {} vs dense LU {}",
                    x[i],
                    y[i]
                );
            }
        }
    }

    /// A line of 30 nodes with bending (couplings of nodes i and i + 2 besides neighbours), the
    /// first node anchored by a distance to a fixed point (a multiplier on it alone), links
    /// between neighbours every other one compliant, and a fixed coordinate on the last node:
    /// each node is coupled with its parent and grandparent.
    #[test]
    fn line_with_bending_matches_dense_lu() {
        let n = 30;
        let couplings: Vec<_> = (0..n - 1)
            .map(|i| (i, i + 1))
            .chain((0..n - 2).map(|i| (i, i + 2)))
            .collect();
        let mut multipliers = vec![(0, None, false)];
        multipliers.extend((0..n - 1).map(|i| (i, Some(i + 1), i % 2 == 1)));
        multipliers.push((n - 1, None, false));
        check_against_dense_lu(n, &couplings, &multipliers, 2);
    }

    /// A branched tree (a main line 0-1-...-11 with branches 12-13-14 from node 4 and 15-16
    /// from node 8, in links, some compliant) with every node coupled with its grandparent,
    /// and the end of a branch coupled with the main line's first node (its great-great-...
    /// grandparent), which couples the whole path with that node.
    #[test]
    fn branched_tree_with_couplings_to_ancestors_matches_dense_lu() {
        let parent: Vec<Option<usize>> = (0..17)
            .map(|p| match p {
                0 => None,
                12 => Some(4),
                15 => Some(8),
                p => Some(p - 1),
            })
            .collect();
        let mut couplings: Vec<(usize, usize)> = Vec::new();
        let mut multipliers = vec![(0, None, false), (13, None, true)];
        for (p, q) in parent.iter().enumerate() {
            if let Some(q) = *q {
                multipliers.push((q, Some(p), p % 3 == 0));
                if let Some(g) = parent[q] {
                    couplings.push((g, p));
                }
            }
        }
        couplings.push((16, 0));
        // Node 16's path to the root: 15, 8, 7, ..., 0; after fill its blocks are coupled
        // with their parent, grandparent and the root (3 ancestors).
        check_against_dense_lu(17, &couplings, &multipliers, 3);
    }

    /// A bending triple centred on the most constrained particle, in the middle of a line (the
    /// middle node of a 3-node line holds a fixed coordinate, so it would be the root, and the
    /// bending couples its two neighbours, siblings): the analysis roots the line at an end
    /// instead, and the elimination agrees with the dense LU.
    #[test]
    fn bending_centred_on_the_most_constrained_particle_is_rooted_at_an_end() {
        let bent = [(0, 1), (1, 2), (0, 2)];
        let links = [(0, Some(1), false), (1, Some(2), true), (1, None, false)];
        check_against_dense_lu(3, &bent, &links, 2);
    }

    /// Couplings between branches that no root puts on one path (each pair of three legs of a
    /// star: wherever the root, two legs are siblings) make the analysis decline.
    #[test]
    fn couplings_across_branches_are_declined() {
        let links = [
            (0, Some(1), false),
            (0, Some(2), false),
            (0, Some(3), false),
        ];
        let (pattern, _, particle_unknowns) = kkt_matrix(4, &[(1, 2), (2, 3), (1, 3)], &links, 1);
        assert!(TreeElimination::analyse(&pattern, particle_unknowns).is_none());
        // Without the couplings between the legs, the same star is a tree.
        let (pattern, _, particle_unknowns) = kkt_matrix(4, &[], &links, 1);
        assert!(TreeElimination::analyse(&pattern, particle_unknowns).is_some());
    }

    /// A V chain and a chain hanging from a pinned particle run with the tree elimination and
    /// agree with the general sparse LU run to round-off (the reference: the same steps with
    /// partial pivoting across the whole matrix), the chains having moved.
    #[test]
    fn singular_blocks_of_a_regular_matrix_fall_back_to_sparse_lu() {
        for pinned in [false, true] {
            let system = crate::integrators::fixtures::awkward_chain(12, pinned);
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
