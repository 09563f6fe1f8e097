//! The iteration matrix's layout: unknowns, sparsity pattern (computed once per model) and, for
//! every element, the positions ("slots") of its local blocks in the matrix's value array, so
//! that each Newton iteration only refills numbers.
//!
//! Unknowns are ordered x = (q of the free particles, 3 each; lambda, one per constraint).

mod axial_added_mass;
mod elements;
mod parallel;
mod pattern;
mod serial;
mod slot_table;

pub use axial_added_mass::{AxialAddedMass, BlockVisit};
pub use elements::{push_column, push_pair_blocks, push_row, ElementOffsets};
pub use parallel::{JacobianTerms, ParallelAssembly, ResidualTerms, MIN_TASK};
pub use pattern::{EntryIndex, Pattern, Storage};
pub use slot_table::SlotTable;

use crate::math::LargestMagnitude;
use crate::model::System;

/// Marks an absent unknown (a fixed particle has no coordinates among the unknowns).
pub const NONE: usize = usize::MAX;

/// Unknowns [`Layout::unknowns_distance`] scans between its tests of the distance so far.
pub const DISTANCE_CHUNK: usize = 256;

/// Position of a matrix entry in the value array. 32 bits: the slot tables are the largest
/// per-element arrays of a model (a chain link has 45 slots), and four billion entries is far
/// beyond any model that fits in memory.
pub type Slot = u32;

/// Marks an absent block entry (a fixed particle, or no coupling).
pub const NO_SLOT: Slot = Slot::MAX;

/// Slots of a 3x3 block, row-major.
pub type Block = [Slot; 9];

/// Where each element writes in the matrix.
#[derive(Debug, Clone)]
pub struct Layout {
    /// First unknown of each particle (NONE for fixed particles).
    pub dof: Vec<usize>,
    /// Number of free particles.
    pub free: usize,
    /// Number of constraint equations.
    pub constraints: usize,
    /// Sparsity pattern (or dense storage for small systems).
    pub pattern: Pattern,
    /// Diagonal block of each particle (all NONE for fixed particles).
    pub particle_block: SlotTable<9>,
    /// Where each constraint's entries start in the tables below.
    pub constraint_offsets: ElementOffsets,
    /// Per constraint and ordered pair (a, b) of its particles: the block of the Hessian term.
    pub constraint_hessian: SlotTable<9>,
    /// Per constraint and particle a: slots of -Phi_q^T (rows of a, the multiplier's column).
    pub constraint_column: SlotTable<3>,
    /// Per constraint and particle a: slots of Phi_q (the constraint's row, columns of a).
    pub constraint_row: SlotTable<3>,
    /// Per constraint: the slot of its multiplier's diagonal entry, which holds the compliance
    /// of a compliant constraint (NO_SLOT for an exact one).
    pub constraint_diagonal: Vec<Slot>,
    /// Where each force's entries start in `force_block`.
    pub force_offsets: ElementOffsets,
    /// Per force and ordered pair (a, b) of its particles: the block of its Jacobian.
    pub force_block: SlotTable<9>,
    /// Where the slots were moved ([`Layout::move_slots`]): the pattern's entry of slot s is
    /// assembled at `moved_to[s]`, in a solver's own storage (empty: at s, in the pattern's
    /// value array; or moved after the pattern's structure was released).
    pub moved_to: Vec<Slot>,
}

impl Layout {
    /// Numbers the unknowns and computes the pattern and slots of `system`.
    /// Systems with at most `dense_limit` unknowns use dense storage.
    pub fn new(system: &System, dense_limit: usize) -> Layout {
        let (dof, free) = number_particles(system);
        let m = system.constraints().len();
        let n = 3 * free + m;
        let lambda = |k: usize| 3 * free + k;

        // Structural entries, column by column (reserved exactly: no doubling overshoot, which
        // dominates the peak memory of million-particle models).
        let count = |parts: &[usize]| {
            let k = parts.iter().filter(|&&p| dof[p] != NONE).count();
            9 * k * k
        };
        let reserve = 9 * free
            + system
                .constraints()
                .iter()
                .map(|c| count(c.particles()) + 2 * 3 * c.particles().len() + 1)
                .sum::<usize>()
            + system
                .forces()
                .iter()
                .filter(|f| f.has_jacobian())
                .map(|f| count(f.particles()))
                .sum::<usize>();
        // 32-bit rows and columns: half the memory of the list, the peak of a large model's
        // set-up (n is below the 32-bit slots' bound, which the pattern checks).
        let at = |k: usize| u32::try_from(k).expect("fewer than 2^32 unknowns");
        let mut entries: Vec<(u32, u32)> = Vec::with_capacity(reserve);
        let block = |entries: &mut Vec<(u32, u32)>, a: usize, b: usize| {
            if a != NONE && b != NONE {
                for r in 0..3 {
                    for c in 0..3 {
                        entries.push((at(a + r), at(b + c)));
                    }
                }
            }
        };
        for &d in &dof {
            block(&mut entries, d, d);
        }
        let pairs = |parts: &[usize]| -> Vec<(usize, usize)> {
            let mut v = Vec::new();
            for &a in parts {
                for &b in parts {
                    v.push((dof[a], dof[b]));
                }
            }
            v
        };
        for (k, c) in system.constraints().iter().enumerate() {
            for (a, b) in pairs(c.particles()) {
                block(&mut entries, a, b);
            }
            for &p in c.particles() {
                if dof[p] != NONE {
                    for r in 0..3 {
                        entries.push((at(dof[p] + r), at(lambda(k))));
                        entries.push((at(lambda(k)), at(dof[p] + r)));
                    }
                }
            }
            if c.is_compliant() {
                entries.push((at(lambda(k)), at(lambda(k))));
            }
        }
        for f in system.forces().iter().filter(|f| f.has_jacobian()) {
            let parts = f.particles();
            for &a in &parts[..f.acting()] {
                for &b in parts {
                    block(&mut entries, dof[a], dof[b]);
                }
            }
        }
        let pattern = Pattern::new(n, entries, n <= dense_limit);
        let particle_block: Vec<Block> = dof.iter().map(|&d| pattern.block_slots(d, d)).collect();
        let constraint_offsets =
            ElementOffsets::new(system.constraints().iter().map(|c| c.particles()));
        let mut constraint_hessian = Vec::with_capacity(constraint_offsets.pair_entries());
        let mut constraint_column = Vec::with_capacity(constraint_offsets.particle_entries());
        let mut constraint_row = Vec::with_capacity(constraint_offsets.particle_entries());
        let constraint_diagonal = (0..m)
            .map(|k| {
                if system.constraints()[k].is_compliant() {
                    pattern.slot32(lambda(k), lambda(k))
                } else {
                    NO_SLOT
                }
            })
            .collect();
        for (k, c) in system.constraints().iter().enumerate() {
            let parts = c.particles();
            push_pair_blocks(
                &mut constraint_hessian,
                &pattern,
                parts,
                parts.len(),
                &dof,
                (0, 0),
            );
            push_column(
                &mut constraint_column,
                &pattern,
                parts,
                &dof,
                (0, lambda(k)),
            );
            push_row(&mut constraint_row, &pattern, parts, &dof, (lambda(k), 0));
        }
        let force_offsets = ElementOffsets::new(system.forces().iter().map(|f| f.particles()));
        let mut force_block = Vec::with_capacity(force_offsets.pair_entries());
        for f in system.forces() {
            if f.has_jacobian() {
                let parts = f.particles();
                push_pair_blocks(&mut force_block, &pattern, parts, f.acting(), &dof, (0, 0));
            } else {
                let n = f.particles().len();
                force_block.extend(std::iter::repeat_n([NO_SLOT; 9], n * n));
            }
        }
        Layout {
            dof,
            free,
            constraints: m,
            pattern,
            particle_block: particle_block.into(),
            constraint_offsets,
            constraint_hessian: constraint_hessian.into(),
            constraint_column: constraint_column.into(),
            constraint_row: constraint_row.into(),
            constraint_diagonal,
            force_offsets,
            force_block: force_block.into(),
            moved_to: Vec::new(),
        }
    }

    /// Moves every slot of the tables to `map[slot]`: the matrix is then assembled into another
    /// array, where the pattern's entry of slot s lies at `map[s]` (a solver's own storage, see
    /// [`crate::linear::TreeElimination::assemble_in_place`]). A pattern whose structure is
    /// kept keeps the map too ([`Layout::moved_to`]), to find its entries there.
    pub fn move_slots(&mut self, map: &[Slot]) {
        if !self.pattern.is_released() {
            self.moved_to = map.to_vec();
        }
        let moved = |s: &mut Slot| {
            if *s != NO_SLOT {
                *s = map[*s as usize];
            }
        };
        let blocks = self.particle_block.plain_mut().iter_mut();
        let blocks = blocks
            .chain(self.constraint_hessian.plain_mut())
            .chain(self.force_block.plain_mut());
        blocks.flatten().for_each(moved);
        let strips = self.constraint_column.plain_mut().iter_mut();
        let strips = strips.chain(self.constraint_row.plain_mut());
        strips.flatten().for_each(moved);
        self.constraint_diagonal.iter_mut().for_each(moved);
    }

    /// Compresses the periodic runs of the slot tables ([`SlotTable::compress`]: a chain's,
    /// whose elements' slots advance by a fixed step from one to the next), for large models:
    /// an element of a run then has its slots computed where it is read.
    pub fn compress_slots(&mut self) {
        let (particles, constraints) = (self.dof.len(), self.constraint_offsets.len());
        self.particle_block.compress(particles, |i| i..i + 1);
        let offsets = &self.constraint_offsets;
        self.constraint_hessian
            .compress(constraints, |c| offsets.pairs(c));
        self.constraint_column
            .compress(constraints, |c| offsets.particles(c));
        self.constraint_row
            .compress(constraints, |c| offsets.particles(c));
        let offsets = &self.force_offsets;
        self.force_block
            .compress(offsets.len(), |f| offsets.pairs(f));
    }

    /// Total number of unknowns.
    pub fn unknowns(&self) -> usize {
        3 * self.free + self.constraints
    }

    /// Readable name of unknown / equation `i` (a particle's coordinate or a constraint).
    pub fn equation_name(&self, system: &System, i: usize) -> String {
        if i < 3 * self.free {
            let p = self
                .dof
                .iter()
                .position(|&d| d != NONE && d <= i && i < d + 3)
                .unwrap_or(0);
            format!("dynamics of particle {p} ({})", ["x", "y", "z"][i % 3])
        } else {
            let k = i - 3 * self.free;
            system.constraints()[k].name(k)
        }
    }
}

impl Layout {
    /// Adds force `fi` (`f`)'s Jacobian, weighted by the terms' `force_dq` and `force_dv`, to
    /// `values` (nothing for a force without one); `dq` and `dv` are reusable block buffers.
    #[inline(always)]
    pub fn add_force_terms<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        (fi, f): (usize, &crate::forces::Force),
        (dq, dv): (&mut crate::local::Blocks, &mut crate::local::Blocks),
        at: &JacobianTerms<'_>,
    ) {
        if !f.has_jacobian() {
            return;
        }
        let n = f.particles().len();
        dq.reset(n);
        dv.reset(n);
        let point = &at.point;
        f.add_jacobian(point.q_eval, point.v_eval, point.t_eval, dq, dv);
        // The rows of the particles the force acts on come first (x-major blocks); the others
        // are zero (a line node's neighbours) and have no slots.
        let acting = f.acting() * n;
        let mut place = |blocks: &[Block]| {
            let (blocks, weights) = (&blocks[..acting], (at.force_dq, &*dq));
            add_force_blocks(values, (blocks, blocks), weights, (at.force_dv, &*dv))
        };
        let pairs = self.force_offsets.pairs(fi);
        match self.force_block.as_plain() {
            Some(blocks) => place(&blocks[pairs]),
            None => self.force_block.with(fi, pairs, place),
        }
    }

    /// Adds constraint `c` (`con`)'s part of the iteration matrix `values` at the Jacobian's
    /// evaluation points `at`: its Hessian-term blocks `hess`, the gradient at the evaluation
    /// point in its multiplier's column and the gradient at the step's end in its row (one
    /// evaluation when the two points are the same), as [`Layout::add_constraint_blocks`].
    #[inline(always)]
    pub fn add_constraint_terms<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        (c, con, buffer): (
            usize,
            &crate::constraints::Constraint,
            &mut crate::local::Blocks,
        ),
        at: &JacobianTerms<'_>,
    ) {
        let point = &at.point;
        let s = point.scales[c];
        let w = at.hessian * point.lambda[c];
        // A compliant row (`docs/theory/moorings.md`) weights Phi(q_end) by w = dq_e/dq, the
        // Hessian term's weight over -sigma, and has its compliance in its own column,
        // d(s c lambda)/d(lambda sigma / s).
        let row = if con.is_compliant() {
            let compliance = con.compliance_at(point.t_eval, point.lambda[c]);
            let diagonal = s * s * compliance / point.sigma;
            values.add(self.constraint_diagonal[c], diagonal);
            if at.is_slack(con, c) {
                0.0
            } else {
                s * (-at.hessian / point.sigma)
            }
        } else {
            s
        };
        let eval = (point.q_eval, point.t_eval);
        con.with_hessian_and_gradient(eval, w, buffer, |hess, grad_eval| {
            // A damped segment's damping force (`constraints/elastic_distance.rs`) has its
            // derivatives in the same four blocks as the Hessian term.
            let damped;
            let hess = match con.damped_segment() {
                Some(segment) => {
                    let weights = (at.force_dq, at.force_dv);
                    let mut blocks = segment.damping_blocks(point.q_eval, point.v_eval, weights);
                    for (b, h) in blocks.iter_mut().zip(hess) {
                        *b = crate::math::add_mat(*b, *h);
                    }
                    damped = blocks;
                    &damped[..]
                }
                None => hess,
            };
            if point.same_point() {
                let grads = (grad_eval, grad_eval);
                self.add_constraint_blocks_weighted(values, (c, hess), (s, row), grads);
            } else {
                con.with_gradient(point.q_end, point.t_end, |grad_end| {
                    let grads = (grad_eval, grad_end);
                    self.add_constraint_blocks_weighted(values, (c, hess), (s, row), grads);
                });
            }
        });
    }

    /// Adds constraint `c`'s part of the iteration matrix `values` ([`Entries`], which skip
    /// absent slots): its Hessian-term blocks `hess` between its touched particles,
    /// `-s grad_column` into its multiplier's column (the -Phi_q^T block) and `s grad_row` into
    /// its row (the Phi_q block). The schemes differ only in where they evaluate the two
    /// gradients and the Hessian.
    #[inline(always)]
    pub fn add_constraint_blocks<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        (c, hess): (usize, &[crate::math::Mat3]),
        s: f64,
        grads: (&[crate::math::Vec3], &[crate::math::Vec3]),
    ) {
        self.add_constraint_blocks_weighted(values, (c, hess), (s, s), grads)
    }

    /// [`Layout::add_constraint_blocks`] with the column's gradient weighted by `-s_column`
    /// and the row's by `s_row`.
    #[inline(always)]
    pub fn add_constraint_blocks_weighted<V: Entries + ?Sized>(
        &self,
        values: &mut V,
        (c, hess): (usize, &[crate::math::Mat3]),
        s: (f64, f64),
        (grad_column, grad_row): (&[crate::math::Vec3], &[crate::math::Vec3]),
    ) {
        let (pairs, range) = (
            self.constraint_offsets.pairs(c),
            self.constraint_offsets.particles(c),
        );
        let grads = (grad_column, grad_row);
        let (hessian, columns, rows) = (
            &self.constraint_hessian,
            &self.constraint_column,
            &self.constraint_row,
        );
        match (hessian.as_plain(), columns.as_plain(), rows.as_plain()) {
            (Some(blocks), Some(columns), Some(rows)) => {
                let strips = (&columns[range.clone()], &rows[range]);
                place_element(values, (&blocks[pairs], hess), s, strips, grads)
            }
            // Compressed tables (a large model's): the element's slots computed, into arrays
            // for a distance's two particles.
            _ if pairs.len() == 4 && range.len() == 2 => {
                let mut blocks = [[0; 9]; 4];
                let mut strips = ([[0; 3]; 2], [[0; 3]; 2]);
                hessian.fill(c, pairs.start, &mut blocks);
                columns.fill(c, range.start, &mut strips.0);
                rows.fill(c, range.start, &mut strips.1);
                let strips = (&strips.0[..], &strips.1[..]);
                place_element(values, (&blocks, hess), s, strips, grads)
            }
            _ => hessian.with(c, pairs, |blocks| {
                columns.with(c, range.clone(), |columns| {
                    rows.with(c, range.clone(), |rows| {
                        place_element(values, (blocks, hess), s, (columns, rows), grads)
                    })
                })
            }),
        }
    }
}

/// [`place_constraint`], with loops of fixed length for the two particles of most constraints
/// (distances).
#[inline(always)]
fn place_element<V: Entries + ?Sized>(
    values: &mut V,
    (blocks, hess): (&[Block], &[crate::math::Mat3]),
    s: (f64, f64),
    strips: Strips<'_>,
    grads: Grads<'_>,
) {
    match two_particles(blocks, hess, strips, grads) {
        Some((blocks, hess, (columns, rows), (gc, gr))) => {
            let (strips, grads) = ((&columns[..], &rows[..]), (&gc[..], &gr[..]));
            place_constraint(values, (blocks, hess), s, strips, grads)
        }
        None => place_constraint(values, (blocks, hess), s, strips, grads),
    }
}

/// A constraint's column and row slots, per touched particle.
type Strips<'a> = (&'a [[Slot; 3]], &'a [[Slot; 3]]);
/// A constraint's two gradients (for its column and its row), per touched particle.
type Grads<'a> = (&'a [crate::math::Vec3], &'a [crate::math::Vec3]);

/// The local tables of a two-particle element as arrays (their lengths known to the compiler),
/// or None for another size.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn two_particles<'a>(
    blocks: &'a [Block],
    hess: &'a [crate::math::Mat3],
    (columns, rows): Strips<'a>,
    (grad_column, grad_row): Grads<'a>,
) -> Option<(
    &'a [Block; 4],
    &'a [crate::math::Mat3; 4],
    (&'a [[Slot; 3]; 2], &'a [[Slot; 3]; 2]),
    (&'a [crate::math::Vec3; 2], &'a [crate::math::Vec3; 2]),
)> {
    Some((
        blocks.try_into().ok()?,
        hess.try_into().ok()?,
        (columns.try_into().ok()?, rows.try_into().ok()?),
        (grad_column.try_into().ok()?, grad_row.try_into().ok()?),
    ))
}

/// The placement of [`Layout::add_constraint_blocks`] on an element's tables.
#[inline(always)]
fn place_constraint<V: Entries + ?Sized>(
    values: &mut V,
    (blocks, hess): (&[Block], &[crate::math::Mat3]),
    (s_column, s_row): (f64, f64),
    (columns, rows): Strips<'_>,
    (grad_column, grad_row): Grads<'_>,
) {
    for (b, m) in blocks.iter().zip(hess) {
        // An element over many particles (a joint's equation over the particles of two
        // bodies) has mostly zero blocks: skipped, not added entry by entry.
        if *m != crate::math::ZERO3 {
            values.add_block(b, 1.0, m);
        }
    }
    for (x, (column, row)) in columns.iter().zip(rows).enumerate() {
        for k in 0..3 {
            values.add(column[k], -s_column * grad_column[x][k]);
            values.add(row[k], s_row * grad_row[x][k]);
        }
    }
}

impl Layout {
    /// Adds `m` to the three diagonal entries of particle `i`'s block (nothing for a fixed
    /// particle): the mass term of the iteration matrix.
    #[inline]
    pub fn add_to_particle_diagonal(&self, values: &mut [f64], i: usize, m: f64) {
        let diagonal = self.particle_block.picked(i, [0, 4, 8]);
        if diagonal[0] != NO_SLOT {
            for slot in diagonal {
                values[slot as usize] += m;
            }
        }
    }

    /// The scaled unknowns of [`Layout::apply_increment`]: q of each free particle's
    /// coordinates and lambda_k sigma / s_k of each multiplier, into `out`.
    pub fn scaled_unknowns(
        &self,
        q: &[crate::math::Vec3],
        lambda: &[f64],
        scales: &[f64],
        sigma: f64,
        out: &mut [f64],
    ) {
        for (i, qi) in q.iter().enumerate() {
            let d = self.dof[i];
            if d != NONE {
                out[d..d + 3].copy_from_slice(qi);
            }
        }
        let m3 = 3 * self.free;
        for (c, l) in lambda.iter().enumerate() {
            out[m3 + c] = l * sigma / scales[c];
        }
    }

    /// The largest distance of a scaled unknown ([`Layout::scaled_unknowns`]) of `q` and
    /// `lambda` from `x` when none is farther than `cap`, else infinity (also when one is not a
    /// number). The scan goes by chunks of [`DISTANCE_CHUNK`] unknowns, each without a branch
    /// that ends it, and stops after the first chunk that holds one beyond `cap` (in a model in
    /// motion, the first): a model at rest is scanned whole, and a loop that could end at every
    /// unknown took as long as a residual evaluation (13.7 % of a step of the hanging chain of
    /// 10^4 particles, generalised-alpha at 1 ms).
    pub fn unknowns_distance(
        &self,
        (q, lambda): (&[crate::math::Vec3], &[f64]),
        (scales, sigma): (&[f64], f64),
        x: &[f64],
        cap: f64,
    ) -> f64 {
        let m3 = 3 * self.free;
        if x.len() != m3 + lambda.len() {
            return f64::INFINITY;
        }
        let (x_q, x_lambda) = x.split_at(m3);
        let mut far = 0.0f64;
        // Each chunk's largest distance; the scan ends at a chunk beyond `cap` or not a number.
        let mut within = |chunk: LargestMagnitude| {
            let near = chunk.norm();
            far = far.max(near);
            near <= cap
        };
        for (qc, dc) in q
            .chunks(DISTANCE_CHUNK)
            .zip(self.dof.chunks(DISTANCE_CHUNK))
        {
            let mut largest = LargestMagnitude::default();
            for (qi, &d) in qc.iter().zip(dc) {
                if d != NONE {
                    let xi: &[f64; 3] = x_q[d..d + 3].try_into().expect("3 unknowns a particle");
                    for k in 0..3 {
                        largest.take(k, qi[k] - xi[k]);
                    }
                }
            }
            if !within(largest) {
                return f64::INFINITY;
            }
        }
        let chunks = lambda
            .chunks(DISTANCE_CHUNK)
            .zip(scales.chunks(DISTANCE_CHUNK))
            .zip(x_lambda.chunks(DISTANCE_CHUNK));
        for ((lc, sc), xc) in chunks {
            let mut largest = LargestMagnitude::default();
            for (j, ((l, s), xk)) in lc.iter().zip(sc).zip(xc).enumerate() {
                largest.take(j % 4, l * sigma / s - xk);
            }
            if !within(largest) {
                return f64::INFINITY;
            }
        }
        far
    }

    /// Applies a Newton increment `dx` (in scaled unknowns) to the positions of the free
    /// particles and to the multipliers, whose unknowns are lambda_k sigma / s_k.
    #[inline]
    pub fn apply_increment(
        &self,
        q: &mut [crate::math::Vec3],
        lambda: &mut [f64],
        dx: &[f64],
        scales: &[f64],
        sigma: f64,
    ) {
        for (qi, &d) in q.iter_mut().zip(&self.dof) {
            if d != NONE {
                let step: &[f64; 3] = dx[d..d + 3].try_into().expect("3 unknowns a particle");
                for k in 0..3 {
                    qi[k] -= step[k];
                }
            }
        }
        let m3 = 3 * self.free;
        for ((l, &step), &s) in lambda.iter_mut().zip(&dx[m3..]).zip(scales) {
            *l -= step * s / sigma;
        }
    }

    /// [`Layout::apply_increment`] on rayon's thread pool (the same numbers), for large models.
    pub fn apply_increment_parallel(
        &self,
        q: &mut [crate::math::Vec3],
        lambda: &mut [f64],
        dx: &[f64],
        scales: &[f64],
        sigma: f64,
    ) {
        use rayon::prelude::*;
        let m3 = 3 * self.free;
        let (positions, multipliers) = dx.split_at(m3);
        rayon::join(
            || {
                q.par_iter_mut()
                    .zip(self.dof.par_iter())
                    .with_min_len(MIN_TASK)
                    .for_each(|(qi, &d)| {
                        if d != NONE {
                            for k in 0..3 {
                                qi[k] -= positions[d + k];
                            }
                        }
                    })
            },
            || {
                lambda
                    .par_iter_mut()
                    .zip(multipliers.par_iter().zip(scales.par_iter()))
                    .with_min_len(MIN_TASK)
                    .for_each(|(l, (&step, &s))| *l -= step * s / sigma)
            },
        );
    }

    /// [`Layout::unknowns_distance`] on rayon's thread pool, for large models: the same
    /// distance, from a scan of every unknown (infinity when one is beyond `cap` or not a
    /// number).
    pub fn unknowns_distance_parallel(
        &self,
        (q, lambda): (&[crate::math::Vec3], &[f64]),
        (scales, sigma): (&[f64], f64),
        x: &[f64],
        cap: f64,
    ) -> f64 {
        use rayon::prelude::*;
        let m3 = 3 * self.free;
        if x.len() != m3 + lambda.len() {
            return f64::INFINITY;
        }
        // NaN counts as infinitely far (f64::max would drop it).
        let far = |e: f64| if e.is_nan() { f64::INFINITY } else { e };
        let (positions, multipliers) = rayon::join(
            || {
                q.par_iter()
                    .zip(self.dof.par_iter())
                    .with_min_len(MIN_TASK)
                    .map(|(qi, &d)| match d {
                        NONE => 0.0,
                        d => (0..3).fold(0.0f64, |m, k| m.max(far((qi[k] - x[d + k]).abs()))),
                    })
                    .reduce(|| 0.0, f64::max)
            },
            || {
                lambda
                    .par_iter()
                    .zip(scales.par_iter().zip(x[m3..].par_iter()))
                    .with_min_len(MIN_TASK)
                    .map(|(l, (s, xk))| far((l * sigma / s - xk).abs()))
                    .reduce(|| 0.0, f64::max)
            },
        );
        let largest = positions.max(multipliers);
        if largest <= cap {
            largest
        } else {
            f64::INFINITY
        }
    }
}

/// The first unknown of each particle, 3 per free particle in order (NONE for fixed ones), and
/// the number of free particles.
pub fn number_particles(system: &System) -> (Vec<usize>, usize) {
    let mut dof = Vec::with_capacity(system.particles().len());
    let mut free = 0;
    for p in system.particles() {
        if p.fixed {
            dof.push(NONE);
        } else {
            dof.push(3 * free);
            free += 1;
        }
    }
    (dof, free)
}

/// The start of each free particle's three residual rows: its scaled inertia and gravity terms
/// (what a time rule contributes to the residual besides the elements).
pub trait InertiaRows: Sync {
    /// The three rows of particle `i`.
    fn rows(&self, i: usize) -> crate::math::Vec3;
}

/// Where assembled entries of the iteration matrix are added: the value array itself (one
/// thread), or a value array shared by the tasks of the parallel assembly (`parallel.rs`).
pub trait Entries {
    /// Adds `value` at `slot` unless the slot is absent.
    fn add(&mut self, slot: Slot, value: f64);
    /// Adds the 3x3 matrix `m`, scaled by `s`, into the block `b` unless it is absent.
    fn add_block(&mut self, b: &Block, s: f64, m: &crate::math::Mat3);
}

impl Entries for [f64] {
    #[inline(always)]
    fn add(&mut self, slot: Slot, value: f64) {
        add(self, slot, value)
    }
    #[inline(always)]
    fn add_block(&mut self, b: &Block, s: f64, m: &crate::math::Mat3) {
        add_block(self, b, s, m)
    }
}

/// Adds `value` at `slot` unless the slot is absent.
#[inline(always)]
pub fn add(values: &mut [f64], slot: Slot, value: f64) {
    if slot != NO_SLOT {
        values[slot as usize] += value;
    }
}

/// Places a force's local Jacobians into `values`: `dq[x][y]` weighted by `wq` into block
/// x n + y of `blocks_q` and `dv[x][y]` weighted by `wv` into that of `blocks_v`, for its n
/// particles (as many as the blocks given: the rows of the particles a force acts on come first).
/// The index-3 layout has one block per pair (`blocks_q` and `blocks_v` the same slice: both
/// are placed in one pass, wq dq + wv dv, skipping absent blocks), the GGL layout one in the
/// position and one in the velocity columns.
#[inline(always)]
pub fn add_force_blocks<V: Entries + ?Sized>(
    values: &mut V,
    (blocks_q, blocks_v): (&[Block], &[Block]),
    (wq, dq): (f64, &crate::forces::Jacobian),
    (wv, dv): (f64, &crate::forces::Jacobian),
) {
    if std::ptr::eq(blocks_q, blocks_v) {
        let local = dq.as_slice().iter().zip(dv.as_slice());
        for (b, (mq, mv)) in blocks_q.iter().zip(local) {
            if b[0] != NO_SLOT {
                let m =
                    std::array::from_fn(|r| std::array::from_fn(|c| wq * mq[r][c] + wv * mv[r][c]));
                values.add_block(b, 1.0, &m);
            }
        }
        return;
    }
    let pairs = blocks_q.iter().zip(blocks_v);
    for ((bq, bv), (mq, mv)) in pairs.zip(dq.as_slice().iter().zip(dv.as_slice())) {
        values.add_block(bq, wq, mq);
        values.add_block(bv, wv, mv);
    }
}

/// Adds the 3x3 matrix `m` (scaled by `s`) into the block `b`.
#[inline(always)]
pub fn add_block(values: &mut [f64], b: &Block, s: f64, m: &crate::math::Mat3) {
    if b[0] == NO_SLOT {
        return;
    }
    for r in 0..3 {
        for c in 0..3 {
            values[b[3 * r + c] as usize] += s * m[r][c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::chain;
    use crate::math::Vec3;

    /// The largest distance of the scaled unknowns of `(q, lambda)` from `x`, by a plain scan
    /// of every unknown (NaN where one is NaN).
    fn scanned(layout: &Layout, (q, lambda): (&[Vec3], &[f64]), scales: &[f64], x: &[f64]) -> f64 {
        let mut at = vec![0.0; x.len()];
        layout.scaled_unknowns(q, lambda, scales, 0.3, &mut at);
        at.iter()
            .zip(x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, crate::math::larger_norm)
    }

    /// The distance of a model's unknowns from a point (the kept matrix's), serial and on the
    /// pool: the largest over every unknown when none is beyond the cap, infinity when one is,
    /// however far into the scan, or when one is not a number. A chain of 1,000 links behind a
    /// fixed particle spans several chunks of the serial scan.
    #[test]
    fn unknowns_distance_is_the_largest_within_the_cap_else_infinite() {
        let s = chain(1000);
        let layout = Layout::new(&s, 0);
        let q = s.initial_positions();
        let m = layout.constraints;
        let mut lambda: Vec<f64> = (0..m).map(|c| 1.0 + c as f64).collect();
        let scales: Vec<f64> = (0..m).map(|c| 2.0 + 0.5 * c as f64).collect();
        let mut x = vec![0.0; layout.unknowns()];
        layout.scaled_unknowns(&q, &lambda, &scales, 0.3, &mut x);
        for (i, xi) in x.iter_mut().enumerate() {
            *xi += 1e-9 * ((i * 7919) % 13) as f64;
        }
        let distance = |q: &[Vec3], lambda: &[f64], x: &[f64], cap: f64| {
            let serial = layout.unknowns_distance((q, lambda), (&scales, 0.3), x, cap);
            let parallel = layout.unknowns_distance_parallel((q, lambda), (&scales, 0.3), x, cap);
            assert_eq!(serial.to_bits(), parallel.to_bits(), "serial and parallel");
            serial
        };
        let largest = scanned(&layout, (&q, &lambda), &scales, &x);
        assert!(largest > 1e-8 && largest < 1.3e-8, "{largest}");
        assert_eq!(distance(&q, &lambda, &x, 1e-6), largest);
        assert_eq!(distance(&q, &lambda, &x, 1.1e-8), f64::INFINITY);
        // One unknown beyond the cap, the last multiplier's, and then the last particle's.
        let last = x.len() - 1;
        x[last] += 1e-3;
        assert_eq!(distance(&q, &lambda, &x, 1e-6), f64::INFINITY);
        x[last] -= 1e-3;
        let mut moved = q.clone();
        moved[1000][2] += 1e-3;
        assert_eq!(distance(&moved, &lambda, &x, 1e-6), f64::INFINITY);
        // A multiplier that is not a number.
        lambda[500] = f64::NAN;
        assert!(scanned(&layout, (&q, &lambda), &scales, &x).is_nan());
        assert_eq!(distance(&q, &lambda, &x, 1e-6), f64::INFINITY);
    }
}
