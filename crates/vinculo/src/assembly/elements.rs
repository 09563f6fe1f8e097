//! Per-element tables of any size: an element (a force or a constraint equation) over n
//! particles owns n entries of a flat per-particle table (its gradient, its local forces, its
//! column and row slots) and n^2 entries of a flat per-pair table (its Hessian or Jacobian
//! blocks, x-major: pair (x, y) is entry x n + y). [`ElementOffsets`] says where each element's
//! entries start, so that one assembler places elements of one, two, three or more particles
//! alike, and a model of small elements pays no padding for the largest kind.

use super::{Block, Pattern, Slot, NONE, NO_SLOT};
use std::ops::Range;

/// Where each element's entries start in the flat per-particle and per-pair tables. When every
/// element touches the same number of particles (a chain of distances, a line of bending nodes)
/// the starts are multiples of it and nothing is stored; otherwise two arrays of starts.
#[derive(Debug, Clone, Default)]
pub struct ElementOffsets {
    /// Number of elements k.
    count: usize,
    /// The particle count shared by every element, if it is shared.
    uniform: Option<usize>,
    /// Otherwise: element e's per-particle entries are `start[e]..start[e + 1]` (k + 1 values).
    start: Vec<usize>,
    /// Otherwise: element e's per-pair entries are `pair_start[e]..pair_start[e + 1]`.
    pair_start: Vec<usize>,
}

impl ElementOffsets {
    /// The offsets of elements touching the given particles, in order.
    pub fn new<'a>(elements: impl Iterator<Item = &'a [usize]> + Clone) -> ElementOffsets {
        let count = elements.clone().count();
        let first = elements.clone().next().map_or(0, |p| p.len());
        if elements.clone().all(|p| p.len() == first) {
            return ElementOffsets {
                count,
                uniform: Some(first),
                start: Vec::new(),
                pair_start: Vec::new(),
            };
        }
        let mut start = Vec::with_capacity(count + 1);
        let mut pair_start = Vec::with_capacity(count + 1);
        start.push(0);
        pair_start.push(0);
        let (mut s, mut p) = (0, 0);
        for parts in elements {
            s += parts.len();
            p += parts.len() * parts.len();
            start.push(s);
            pair_start.push(p);
        }
        ElementOffsets {
            count,
            uniform: None,
            start,
            pair_start,
        }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when there is no element.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Start of element e's entries in a per-particle table (e may be k: the table's length).
    #[inline(always)]
    fn start(&self, e: usize) -> usize {
        match self.uniform {
            Some(n) => e * n,
            None => self.start[e],
        }
    }

    /// Start of element e's entries in a per-pair table (e may be k: the table's length).
    #[inline(always)]
    fn pair_start(&self, e: usize) -> usize {
        match self.uniform {
            Some(n) => e * n * n,
            None => self.pair_start[e],
        }
    }

    /// Element e's entries in a per-particle table.
    #[inline(always)]
    pub fn particles(&self, e: usize) -> Range<usize> {
        self.start(e)..self.start(e + 1)
    }

    /// Element e's entries in a per-pair table.
    #[inline(always)]
    pub fn pairs(&self, e: usize) -> Range<usize> {
        self.pair_start(e)..self.pair_start(e + 1)
    }

    /// Length of a per-particle table (the sum of the elements' particle counts).
    pub fn particle_entries(&self) -> usize {
        self.start(self.count)
    }

    /// Length of a per-pair table (the sum of the squares of the elements' particle counts).
    pub fn pair_entries(&self) -> usize {
        self.pair_start(self.count)
    }

    /// The per-particle entries of elements `first..last` (contiguous).
    pub fn particles_of(&self, elements: Range<usize>) -> Range<usize> {
        self.start(elements.start)..self.start(elements.end)
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
/// `col` (absent where either is fixed, and for the rows of the particles from `acting` on: an
/// element that does not act on them), x-major.
pub fn push_pair_blocks(
    out: &mut Vec<Block>,
    pattern: &Pattern,
    parts: &[usize],
    acting: usize,
    dof: &[usize],
    (row, col): (usize, usize),
) {
    for (x, &a) in parts.iter().enumerate() {
        for &b in parts {
            out.push(if x < acting {
                pattern.block_slots(shift(dof[a], row), shift(dof[b], col))
            } else {
                [NO_SLOT; 9]
            });
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

    /// Elements of one size store no starts, and give the same ranges as the general case
    /// would: element e of n particles starts at e n (particles) and e n^2 (pairs).
    #[test]
    fn offsets_of_elements_of_one_size_are_multiples() {
        let parts: [&[usize]; 3] = [&[0, 1, 2], &[1, 2, 3], &[2, 3, 4]];
        let o = ElementOffsets::new(parts.iter().copied());
        assert!(o.start.is_empty() && o.pair_start.is_empty());
        assert_eq!(o.particles(1), 3..6);
        assert_eq!(o.pairs(2), 18..27);
        assert_eq!((o.particle_entries(), o.pair_entries()), (9, 27));
        assert_eq!(o.particles_of(1..3), 3..9);
        let none = ElementOffsets::new(std::iter::empty::<&[usize]>());
        assert_eq!(
            (none.len(), none.particle_entries(), none.pair_entries()),
            (0, 0, 0)
        );
    }
}
