//! Per-element tables of any size: an element (a force or a constraint equation) over n
//! particles owns n entries of a flat per-particle table (its gradient, its local forces, its
//! column and row slots) and n^2 entries of a flat per-pair table (its Hessian or Jacobian
//! blocks, x-major: pair (x, y) is entry x n + y). [`ElementOffsets`] says where each element's
//! entries start, so that one assembler places elements of one, two, three or more particles
//! alike, and a model of small elements pays no padding for the largest kind.

use super::{Block, Pattern, Slot, NONE, NO_SLOT};
use std::ops::Range;

/// Where each element's entries start in the flat per-particle and per-pair tables.
#[derive(Debug, Clone, Default)]
pub struct ElementOffsets {
    /// Element e's per-particle entries are `start[e]..start[e + 1]` (k + 1 values).
    start: Vec<usize>,
    /// Element e's per-pair entries are `pair_start[e]..pair_start[e + 1]` (k + 1 values).
    pair_start: Vec<usize>,
}

impl ElementOffsets {
    /// The offsets of elements touching the given particles, in order.
    pub fn new<'a>(elements: impl Iterator<Item = &'a [usize]>) -> ElementOffsets {
        let (lower, _) = elements.size_hint();
        let mut start = Vec::with_capacity(lower + 1);
        let mut pair_start = Vec::with_capacity(lower + 1);
        start.push(0);
        pair_start.push(0);
        let (mut s, mut p) = (0, 0);
        for parts in elements {
            s += parts.len();
            p += parts.len() * parts.len();
            start.push(s);
            pair_start.push(p);
        }
        ElementOffsets { start, pair_start }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// True when there is no element.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Element e's entries in a per-particle table.
    #[inline(always)]
    pub fn particles(&self, e: usize) -> Range<usize> {
        self.start[e]..self.start[e + 1]
    }

    /// Element e's entries in a per-pair table.
    #[inline(always)]
    pub fn pairs(&self, e: usize) -> Range<usize> {
        self.pair_start[e]..self.pair_start[e + 1]
    }

    /// Length of a per-particle table (the sum of the elements' particle counts).
    pub fn particle_entries(&self) -> usize {
        self.start[self.len()]
    }

    /// Length of a per-pair table (the sum of the squares of the elements' particle counts).
    pub fn pair_entries(&self) -> usize {
        self.pair_start[self.len()]
    }

    /// The per-particle entries of elements `first..last` (contiguous).
    pub fn particles_of(&self, elements: Range<usize>) -> Range<usize> {
        self.start[elements.start]..self.start[elements.end]
    }
}

/// `d + by`, or NONE for a fixed particle's NONE.
#[inline]
fn shift(d: usize, by: usize) -> usize {
    if d == NONE {
        NONE
    } else {
        d + by
    }
}

/// Appends the slots of the blocks between an element's particles `parts`: block (x, y) has the
/// rows of particle x's unknowns shifted by `row` and the columns of particle y's shifted by
/// `col` (absent where either is fixed), x-major.
pub fn push_pair_blocks(
    out: &mut Vec<Block>,
    pattern: &Pattern,
    parts: &[usize],
    dof: &[usize],
    (row, col): (usize, usize),
) {
    for &a in parts {
        for &b in parts {
            out.push(pattern.block_slots(shift(dof[a], row), shift(dof[b], col)));
        }
    }
}

/// Appends, per particle of `parts`, the slots of a constraint's column: rows of the particle's
/// unknowns shifted by `row_shift`, column `col` (absent for a fixed particle).
pub fn push_column(
    out: &mut Vec<[Slot; 3]>,
    pattern: &Pattern,
    parts: &[usize],
    dof: &[usize],
    (row_shift, col): (usize, usize),
) {
    for &p in parts {
        out.push(if dof[p] == NONE {
            [NO_SLOT; 3]
        } else {
            [0, 1, 2].map(|r| pattern.slot32(dof[p] + row_shift + r, col))
        });
    }
}

/// Appends, per particle of `parts`, the slots of a constraint's row: row `row`, columns of the
/// particle's unknowns shifted by `col_shift` (absent for a fixed particle).
pub fn push_row(
    out: &mut Vec<[Slot; 3]>,
    pattern: &Pattern,
    parts: &[usize],
    dof: &[usize],
    (row, col_shift): (usize, usize),
) {
    for &p in parts {
        out.push(if dof[p] == NONE {
            [NO_SLOT; 3]
        } else {
            [0, 1, 2].map(|c| pattern.slot32(row, dof[p] + col_shift + c))
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Offsets of elements of 2, 1 and 3 particles: 2 + 1 + 3 particle entries and
    /// 4 + 1 + 9 pair entries, each element's range starting where the previous one ends.
    #[test]
    fn offsets_count_particles_and_pairs() {
        let parts: [&[usize]; 3] = [&[0, 1], &[4], &[1, 2, 3]];
        let o = ElementOffsets::new(parts.iter().copied());
        assert_eq!(o.len(), 3);
        assert_eq!(o.particles(2), 3..6);
        assert_eq!(o.pairs(2), 5..14);
        assert_eq!(o.particle_entries(), 6);
        assert_eq!(o.pair_entries(), 14);
        assert_eq!(o.particles_of(1..3), 2..6);
    }
}
