//! Residual and Jacobian assembly on rayon's thread pool, for large models.
//!
//! The residual is assembled without shared writes and in the serial order of operations, so it
//! equals the serial residual bit for bit:
//!
//! 1. in parallel over the elements, each force's local forces and each constraint's gradient
//!    go into per-element buffers (and each constraint's own residual row is written);
//! 2. in parallel over the free particles, each particle's three rows start from the inertia
//!    and gravity terms and subtract its incident forces and then its incident constraints'
//!    gradient terms, each in increasing element index: the serial loops' order.
//!
//! The Jacobian's slots are scattered through the value array, so it is written through a
//! shared pointer, colour by colour (see [`SharedValues`] for the safety argument). The forces
//! and the constraints are cut into chunks of consecutive elements, each assembled by one task
//! in the serial order (writing slots near each other, as the serial loop does), and the chunks
//! are greedily coloured once per run so that no two chunks of a colour touch the same free
//! particle (a chain needs two colours: even and odd chunks). Where two chunks share a particle
//! its diagonal block may receive their contributions in another order than in the serial
//! loops, so the parallel Jacobian equals the serial one to round-off (a unit in the last
//! place), not bit for bit.

use rayon::prelude::*;

use super::{Block, ElementOffsets, Entries, InertiaRows, Layout, Slot, NONE, NO_SLOT};
use crate::constraints::{Constraint, Hessian};
use crate::forces::Jacobian;
use crate::math::{Mat3, Vec3};
use crate::model::System;

/// Elements handed to one rayon task at least (smaller tasks cost more to schedule than they
/// compute).
pub const MIN_TASK: usize = 2048;

/// Consecutive elements one task assembles into the Jacobian, in the serial loops' order (so
/// that a task writes slots near each other, as the serial loop does).
const CHUNK: usize = 1024;

/// The colouring, incidence lists and buffers of parallel assembly, built once per run.
#[derive(Debug, Clone)]
pub struct ParallelAssembly {
    /// Free particles in unknown order (`free[j]` is the particle of unknowns 3j..3j+3).
    free: Vec<usize>,
    /// Per particle, the range of `force_incidence` of the forces touching it.
    force_start: Vec<usize>,
    /// Entries (f, i): force f touches the particle, whose local force is entry i of `forces`;
    /// increasing in f.
    force_incidence: Vec<[u32; 2]>,
    /// Per particle, the range of `constraint_incidence` of the constraints touching it.
    constraint_start: Vec<usize>,
    /// Entries (c, i): constraint c touches the particle, whose gradient is entry i of
    /// `gradients`; increasing in c.
    constraint_incidence: Vec<[u32; 2]>,
    /// Chunks of [`CHUNK`] forces, grouped by colour (`force_colour_start` delimits the
    /// groups).
    force_colours: Vec<usize>,
    force_colour_start: Vec<usize>,
    /// Chunks of [`CHUNK`] constraints, grouped by colour (`constraint_colour_start` delimits
    /// the groups).
    constraint_colours: Vec<usize>,
    constraint_colour_start: Vec<usize>,
    /// Local forces of every force at the current iterate, per force and touched particle
    /// (the layout's `force_offsets`).
    forces: Vec<Vec3>,
    /// Gradient of every constraint at the evaluation point, per constraint and touched
    /// particle (the layout's `constraint_offsets`), but distances': the particle pass makes
    /// those again from the two positions (`Distance::gradient_row`), cheaper than storing 48 bytes
    /// a distance and reading them back (at 10^5 particles the parallel residual took 2.19 to
    /// 2.33 ms with them stored, 1.70 to 1.83 ms without, criterion's `assembly` group; the
    /// buffer's part for distances is then never touched: the 10^6 chain's peak 1,183 -> 1,137
    /// MB).
    gradients: Vec<Vec3>,
    /// The damping tension of each damped segment at the current iterate (written and read for
    /// those alone: the pages of a model without them are never touched).
    damping: Vec<f64>,
}

/// Where and with which weights one step's residual is evaluated.
pub struct ResidualTerms<'a> {
    /// Positions, velocities and time at which forces and constraint gradients are evaluated.
    pub q_eval: &'a [Vec3],
    /// Velocities at the evaluation point.
    pub v_eval: &'a [Vec3],
    /// Time of the evaluation point.
    pub t_eval: f64,
    /// Positions and time of the constraint rows (the step's end).
    pub q_end: &'a [Vec3],
    /// Time of the constraint rows.
    pub t_end: f64,
    /// Scale of the dynamics rows.
    pub sigma: f64,
    /// Multipliers.
    pub lambda: &'a [f64],
    /// Scale of each constraint row.
    pub scales: &'a [f64],
    /// w = dq_e/dq: the weight of the step's end in the evaluation point.
    pub end_weight: f64,
    /// Phi_k(q_n, t_n) of each compliant constraint at the step's start (0 for the others).
    pub start_phi: &'a [f64],
    /// Whether slack segments go slack in this problem ([`crate::integrators::Index3Rule::SLACK`]).
    pub slack: bool,
}

/// Where and with which weights one step's Jacobian is evaluated (besides the mass block): at
/// the residual's point, with the weights of the forces' and constraints' derivatives.
pub struct JacobianTerms<'a> {
    /// The point and scales of the residual whose Jacobian this is: forces, Hessians and the
    /// -Phi_q^T columns at its evaluation point, the Phi_q rows at the step's end.
    pub point: ResidualTerms<'a>,
    /// Weight of df/dq.
    pub force_dq: f64,
    /// Weight of df/dv.
    pub force_dv: f64,
    /// Weight of lambda_k d2Phi_k/dq2.
    pub hessian: f64,
}

/// The stretch measure of compliant constraint `c`'s row, w Phi(q_end, t_end) + (1 - w)
/// Phi(q_n, t_n), from Phi(q_end, t_end) = `phi`.
#[inline(always)]
fn stretch_row(end_weight: f64, start_phi: &[f64], c: usize, phi: f64) -> f64 {
    end_weight * phi + (1.0 - end_weight) * start_phi[c]
}

impl ResidualTerms<'_> {
    /// The (unscaled) row of constraint `c` (`con`) whose residual at the step's end is `phi`:
    /// `phi` for an exact constraint; for a compliant one (`docs/theory/moorings.md`)
    /// w Phi(q_end, t_end) + (1 - w) Phi(q_n, t_n) + c(t_e) lambda, the stretch at the
    /// evaluation point where its multiplier, the tension, acts; a slack segment's row
    /// (`constraints/elastic_distance.rs`) is c(t_e) lambda alone while that stretch measure
    /// is positive (shorter than its length).
    #[inline(always)]
    pub fn row(&self, con: &crate::constraints::Constraint, c: usize, phi: f64) -> f64 {
        match con.compliant_segment() {
            Some(segment) => {
                let psi = stretch_row(self.end_weight, self.start_phi, c, phi);
                let held = if self.slack && segment.slack && psi > 0.0 {
                    0.0
                } else {
                    psi
                };
                held + segment.stretch(self.t_eval, self.lambda[c]).0
            }
            None => phi,
        }
    }

    /// sigma times the tension that constraint `c` (`con`)'s gradient `grad` at the forces'
    /// point carries into the dynamics rows: its multiplier, plus a damped segment's damping
    /// tension there (`constraints/elastic_distance.rs`).
    #[inline(always)]
    pub fn gradient_weight(
        &self,
        con: &crate::constraints::Constraint,
        c: usize,
        grad: &[Vec3],
    ) -> f64 {
        match con.damped_segment() {
            None => self.sigma * self.lambda[c],
            Some(s) => self.sigma * (self.lambda[c] + s.damping_tension(grad, self.v_eval)),
        }
    }

    /// True when the constraint rows are evaluated where the gradients are (the same positions
    /// and time), so that one evaluation serves both.
    pub fn same_point(&self) -> bool {
        std::ptr::eq(self.q_eval, self.q_end) && self.t_eval.to_bits() == self.t_end.to_bits()
    }
}

impl JacobianTerms<'_> {
    /// True when compliant constraint `c` (`con`) is a slack segment shorter than its length
    /// at this iterate: its row then does not depend on the positions ([`ResidualTerms::row`]).
    pub fn is_slack(&self, con: &crate::constraints::Constraint, c: usize) -> bool {
        let at = &self.point;
        at.slack
            && con.can_slack()
            && stretch_row(
                at.end_weight,
                at.start_phi,
                c,
                con.residual(at.q_end, at.t_end),
            ) > 0.0
    }
}

/// The matrix's value array shared by the tasks of one colour.
///
/// Safety argument: every slot is an entry (row, column) of the matrix, and every slot written
/// through this type is written by one task only, because it is partitioned by its row:
/// - a particle's mass block (rows of that particle) is written by that particle's task alone;
/// - an element's blocks (rows of its free particles) and -Phi_q^T entries (rows of its free
///   particles, its multiplier's column) are written by the task of the element's chunk;
///   within one colour no two chunks touch the same free particle, so no two tasks share such
///   a row, and colours are processed one after the other (each colour's parallel loop returns
///   before the next starts, as the mass pass returns before the first colour);
/// - a constraint's Phi_q entries (its multiplier's row) are written by the task of its chunk,
///   and no other task writes that row.
///
/// Slots are bounds-checked against the array's length before every write.
struct SharedValues {
    ptr: *mut f64,
    len: usize,
}

// SAFETY: see the type's documentation: concurrent tasks write disjoint slots only.
unsafe impl Sync for SharedValues {}

impl SharedValues {
    fn new(values: &mut [f64]) -> SharedValues {
        SharedValues {
            ptr: values.as_mut_ptr(),
            len: values.len(),
        }
    }

    /// Adds `value` at `slot` unless the slot is absent.
    ///
    /// # Safety
    /// No other task may access `slot` concurrently (see the type's documentation).
    #[inline]
    unsafe fn add(&self, slot: Slot, value: f64) {
        if slot != NO_SLOT {
            let slot = slot as usize;
            assert!(slot < self.len, "slot {slot} outside the value array");
            // SAFETY: in bounds (checked above); exclusive by the caller's contract.
            unsafe { *self.ptr.add(slot) += value };
        }
    }

    /// Adds `s m` into the block `b`.
    ///
    /// # Safety
    /// As for [`SharedValues::add`], for every slot of the block.
    #[inline]
    unsafe fn add_block(&self, b: &Block, s: f64, m: &Mat3) {
        if b[0] == NO_SLOT {
            return;
        }
        for r in 0..3 {
            for c in 0..3 {
                // SAFETY: forwarded from the caller.
                unsafe { self.add(b[3 * r + c], s * m[r][c]) };
            }
        }
    }
}

/// The [`Entries`] of one task of a colour: additions into the shared value array.
struct ChunkEntries<'a>(&'a SharedValues);

impl<'a> ChunkEntries<'a> {
    /// # Safety
    /// The caller adds only at slots that no other task accesses concurrently (see
    /// [`SharedValues`]): the rows of its chunk's free particles and its elements' own rows.
    unsafe fn new(shared: &'a SharedValues) -> ChunkEntries<'a> {
        ChunkEntries(shared)
    }
}

impl Entries for ChunkEntries<'_> {
    #[inline(always)]
    fn add(&mut self, slot: Slot, value: f64) {
        // SAFETY: the slots are this task's alone, as promised to `ChunkEntries::new`.
        unsafe { self.0.add(slot, value) }
    }
    #[inline(always)]
    fn add_block(&mut self, b: &Block, s: f64, m: &Mat3) {
        // SAFETY: as for `add`.
        unsafe { self.0.add_block(b, s, m) }
    }
}

/// Incidence lists: for each free particle, entries (e, i) of the elements e touching it, i its
/// entry in the elements' per-particle tables (the elements' particle counts summed before e,
/// plus its position among e's particles), in increasing e.
fn incidence<'a>(
    particles: usize,
    elements: impl Iterator<Item = &'a [usize]> + Clone,
    dof: &[usize],
) -> (Vec<usize>, Vec<[u32; 2]>) {
    let keep = |p: usize| dof[p] != NONE;
    let mut start = vec![0usize; particles + 1];
    for parts in elements.clone() {
        for &p in parts.iter().filter(|&&p| keep(p)) {
            start[p + 1] += 1;
        }
    }
    for i in 0..particles {
        start[i + 1] += start[i];
    }
    let mut next = start.clone();
    let mut entries = vec![[0u32; 2]; start[particles]];
    let mut offset = 0;
    for (e, parts) in elements.enumerate() {
        for (x, &p) in parts.iter().enumerate().filter(|&(_, &p)| keep(p)) {
            entries[next[p]] = [e as u32, (offset + x) as u32];
            next[p] += 1;
        }
        offset += parts.len();
    }
    (start, entries)
}

/// Greedy colouring of the chunks of [`CHUNK`] consecutive elements (given by their particles;
/// elements that write nothing have none) such that no two chunks of a colour touch the same
/// free particle. Returns the chunks grouped by colour, and the start of each group.
fn colour_chunks<'a>(
    particles: usize,
    elements: impl Iterator<Item = &'a [usize]> + Clone,
    dof: &[usize],
) -> (Vec<usize>, Vec<usize>) {
    let (start, entries) = incidence(particles, elements.clone(), dof);
    let chunks = elements.clone().count().div_ceil(CHUNK);
    let mut colours = vec![0usize; chunks];
    let mut taken: Vec<usize> = Vec::new();
    let mut parts = elements.enumerate().peekable();
    for k in 0..chunks {
        // Colours of the earlier (already coloured) chunks sharing a free particle with chunk k.
        taken.clear();
        while let Some((_, ps)) = parts.next_if(|&(e, _)| e / CHUNK == k) {
            for &p in ps.iter().filter(|&&p| dof[p] != NONE) {
                for &entry in &entries[start[p]..start[p + 1]] {
                    let other = entry[0] as usize / CHUNK;
                    if other < k {
                        taken.push(colours[other]);
                    }
                }
            }
        }
        taken.sort_unstable();
        taken.dedup();
        // The smallest colour not taken.
        colours[k] = taken
            .iter()
            .enumerate()
            .find(|&(c, &t)| c != t)
            .map_or(taken.len(), |(c, _)| c);
    }
    let groups = colours.iter().max().map_or(0, |&c| c + 1);
    let mut group_start = vec![0usize; groups + 1];
    for &c in &colours {
        group_start[c + 1] += 1;
    }
    for g in 0..groups {
        group_start[g + 1] += group_start[g];
    }
    let mut next = group_start.clone();
    let mut order = vec![0usize; chunks];
    for (k, &c) in colours.iter().enumerate() {
        order[next[c]] = k;
        next[c] += 1;
    }
    (order, group_start)
}

impl ParallelAssembly {
    /// Colours the elements of `system` and allocates the buffers (once per run).
    pub fn new(system: &System, layout: &Layout) -> ParallelAssembly {
        let n = system.particles().len();
        let dof = &layout.dof;
        let free = (0..n).filter(|&i| dof[i] != NONE).collect();
        let forces = system.forces();
        let constraints = system.constraints();
        let (force_start, force_incidence) =
            incidence(n, forces.iter().map(|f| f.particles()), dof);
        let (constraint_start, constraint_incidence) =
            incidence(n, constraints.iter().map(|c| c.particles()), dof);
        let none: &[usize] = &[];
        let (force_colours, force_colour_start) = colour_chunks(
            n,
            forces.iter().map(|f| {
                if f.has_jacobian() {
                    f.particles()
                } else {
                    none
                }
            }),
            dof,
        );
        let (constraint_colours, constraint_colour_start) =
            colour_chunks(n, constraints.iter().map(|c| c.particles()), dof);
        ParallelAssembly {
            free,
            force_start,
            force_incidence,
            constraint_start,
            constraint_incidence,
            force_colours,
            force_colour_start,
            constraint_colours,
            constraint_colour_start,
            forces: vec![[0.0; 3]; layout.force_offsets.particle_entries()],
            gradients: vec![[0.0; 3]; layout.constraint_offsets.particle_entries()],
            damping: vec![0.0; constraints.len()],
        }
    }

    /// Number of colours of the chunks of constraints (two for a long chain).
    pub fn constraint_colours(&self) -> usize {
        self.constraint_colour_start.len() - 1
    }

    /// Writes the scaled residual: `row.rows(i)` is the start of the three rows of particle i (its
    /// inertia and gravity terms), then forces and constraint gradients are subtracted and the
    /// constraint rows written, as in the serial loops and with the same result.
    pub fn residual(
        &mut self,
        system: &System,
        layout: &Layout,
        at: &ResidualTerms<'_>,
        r: &mut [f64],
        row: &impl InertiaRows,
    ) {
        let m3 = 3 * layout.free;
        let (dynamics, constraint_rows) = r.split_at_mut(m3);
        let forces = system.forces();
        split_by_elements(&mut self.forces, &layout.force_offsets)
            .into_par_iter()
            .for_each(|(first, out)| {
                let mut i = 0;
                for f in &forces[first..(first + MIN_TASK).min(forces.len())] {
                    f.with_force(at.q_eval, at.v_eval, at.t_eval, |fl| {
                        copy_rows(&mut out[i..i + fl.len()], fl);
                        i += fl.len();
                    });
                }
            });
        let constraints = system.constraints();
        split_by_elements(&mut self.gradients, &layout.constraint_offsets)
            .into_par_iter()
            .zip(constraint_rows.par_chunks_mut(MIN_TASK))
            .zip(self.damping.par_chunks_mut(MIN_TASK))
            .for_each(|(((first, out), rows), damping)| {
                let mut i = 0;
                for ((c, r), td) in (first..).zip(rows.iter_mut()).zip(damping) {
                    let con = &constraints[c];
                    // A distance's gradient is made again in the particle pass, from the two
                    // positions, rather than stored here and read back there (`Distance::gradient_row`).
                    if let Constraint::Distance(d) = con {
                        i += d.particles.len();
                    } else {
                        con.with_gradient(at.q_eval, at.t_eval, |grad| {
                            copy_rows(&mut out[i..i + grad.len()], grad);
                            i += grad.len();
                            if let Some(s) = con.damped_segment() {
                                *td = s.damping_tension(grad, at.v_eval);
                            }
                        });
                    }
                    *r = at.scales[c] * at.row(con, c, con.residual(at.q_end, at.t_end));
                }
            });
        let sigma = at.sigma;
        let this = &*self;
        dynamics
            .par_chunks_mut(3)
            .zip(this.free.par_iter())
            .with_min_len(MIN_TASK)
            .for_each(|(out, &i)| {
                let out: &mut [f64; 3] = out.try_into().expect("3 rows a particle");
                *out = row.rows(i);
                for &[_, e] in &this.force_incidence[this.force_start[i]..this.force_start[i + 1]] {
                    let fl = &this.forces[e as usize];
                    for k in 0..3 {
                        out[k] -= sigma * fl[k];
                    }
                }
                let incident = &this.constraint_incidence
                    [this.constraint_start[i]..this.constraint_start[i + 1]];
                for &[c, e] in incident {
                    let con = &constraints[c as usize];
                    let lambda = at.lambda[c as usize];
                    // As `ResidualTerms::gradient_weight`, with the damping tension of the
                    // constraint pass (distances have none).
                    let (grad, weight) = match con {
                        Constraint::Distance(d) => (&d.gradient_row(at.q_eval, i), sigma * lambda),
                        _ if con.damped_segment().is_some() => (
                            &this.gradients[e as usize],
                            sigma * (lambda + this.damping[c as usize]),
                        ),
                        _ => (&this.gradients[e as usize], sigma * lambda),
                    };
                    for k in 0..3 {
                        out[k] -= weight * grad[k];
                    }
                }
            });
    }

    /// Adds the scaled Jacobian into `values` (zeroed by the caller): `mass(i)` on the diagonal
    /// of particle i's block, then the forces' and constraints' terms.
    pub fn jacobian(
        &self,
        system: &System,
        layout: &Layout,
        at: &JacobianTerms<'_>,
        values: &mut [f64],
        mass: impl Fn(usize) -> f64 + Sync,
    ) {
        let shared = SharedValues::new(values);
        let shared = &shared;
        self.free.par_iter().with_min_len(MIN_TASK).for_each(|&i| {
            let m = mass(i);
            for slot in layout.particle_block.picked(i, [0, 4, 8]) {
                // SAFETY: particle i's own diagonal entries, written by this task only.
                unsafe { shared.add(slot, m) };
            }
        });
        let forces = system.forces();
        for g in 0..self.force_colour_start.len() - 1 {
            let group =
                &self.force_colours[self.force_colour_start[g]..self.force_colour_start[g + 1]];
            group.par_iter().for_each(|&chunk| {
                let end = (chunk * CHUNK + CHUNK).min(forces.len());
                let (mut dq, mut dv) = (Jacobian::zeros(0), Jacobian::zeros(0));
                // SAFETY: the blocks of this chunk's forces are in rows of its free particles,
                // which no other chunk of this colour touches (see `SharedValues`).
                let mut entries = unsafe { ChunkEntries::new(shared) };
                for (fi, f) in forces.iter().enumerate().take(end).skip(chunk * CHUNK) {
                    layout.add_force_terms(&mut entries, (fi, f), (&mut dq, &mut dv), at);
                }
            });
        }
        let constraints = system.constraints();
        for g in 0..self.constraint_colour_start.len() - 1 {
            let group = &self.constraint_colours
                [self.constraint_colour_start[g]..self.constraint_colour_start[g + 1]];
            group.par_iter().for_each(|&chunk| {
                let end = (chunk * CHUNK + CHUNK).min(constraints.len());
                let mut hess = Hessian::zeros(0);
                for c in chunk * CHUNK..end {
                    let con = &constraints[c];
                    // SAFETY: the Hessian blocks and the column entries are in rows of this
                    // chunk's free particles, which no other chunk of this colour touches; the
                    // row entries are in this constraint's own row (see `SharedValues`).
                    let mut entries = unsafe { ChunkEntries::new(shared) };
                    layout.add_constraint_terms(&mut entries, (c, con, &mut hess), at);
                }
            });
        }
    }
}

/// The per-particle table `values` of `offsets`' elements cut into the pieces of [`MIN_TASK`]
/// consecutive elements (contiguous in the table), each with its first element: the tasks of
/// the residual's element pass, each writing its own piece.
fn split_by_elements<'a>(
    mut values: &'a mut [Vec3],
    offsets: &ElementOffsets,
) -> Vec<(usize, &'a mut [Vec3])> {
    let mut pieces = Vec::with_capacity(offsets.len().div_ceil(MIN_TASK));
    for first in (0..offsets.len()).step_by(MIN_TASK) {
        let entries = offsets.particles_of(first..(first + MIN_TASK).min(offsets.len()));
        let (piece, rest) = std::mem::take(&mut values).split_at_mut(entries.len());
        pieces.push((first, piece));
        values = rest;
    }
    pieces
}

/// Copies an element's local rows into `out` (of the same length) one 3-vector at a time: a
/// `copy_from_slice` of a length known only at run time calls the C library's `memmove`: with
/// it, those calls (and the one for each particle's three inertia rows) took 4.9 % of a step of
/// the swinging chain of 10^6 particles (perf), 0.284 s a step against 0.271 s without.
#[inline(always)]
fn copy_rows(out: &mut [Vec3], rows: &[Vec3]) {
    for (o, r) in out.iter_mut().zip(rows) {
        *o = *r;
    }
}
