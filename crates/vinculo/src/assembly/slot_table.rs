//! One of a layout's slot tables: for each element (a particle, a constraint, a force), where
//! its entries of the iteration matrix lie in the value array, `W` slots an entry (a 3x3
//! block's 9, a gradient strip's 3).
//!
//! A large model keeps a run of equal elements compressed, as the tree elimination keeps its
//! blocks' slots (`linear/block_slots.rs`): on a chain, link k + 1's slots are link k's
//! advanced by a fixed step each, so the run keeps its first element's slots and the steps. On
//! a chain of 10^6 particles the tables are 228 MB of u32 otherwise (a link's four Hessian
//! blocks, its gradient's column and row, a particle's diagonal block: 57 slots), a sixth of
//! the run's memory. An element of the run is read by computing its slots into a buffer on
//! the stack ([`SlotTable::with`]); the others are read where they are stored.

use std::ops::Range;

use super::Slot;
use crate::linear::block_slots::BlockSlots;

/// Largest element (in entries) of a compressed run read into a stack buffer; larger ones are
/// read into a vector.
const STACK_ENTRIES: usize = 16;

/// A layout's slot table (module documentation).
#[derive(Debug, Clone)]
pub struct SlotTable<const W: usize> {
    inner: Inner<W>,
}

#[derive(Debug, Clone)]
enum Inner<const W: usize> {
    /// Every entry's slots.
    Plain(Vec<[Slot; W]>),
    /// A run of elements compressed; `len` entries in all.
    Periodic { slots: BlockSlots, len: usize },
}

impl<const W: usize> From<Vec<[Slot; W]>> for SlotTable<W> {
    fn from(entries: Vec<[Slot; W]>) -> Self {
        SlotTable {
            inner: Inner::Plain(entries),
        }
    }
}

impl<const W: usize> SlotTable<W> {
    /// Number of entries.
    pub fn len(&self) -> usize {
        match &self.inner {
            Inner::Plain(v) => v.len(),
            Inner::Periodic { len, .. } => *len,
        }
    }

    /// True when the table has no entry.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The slots of entry `i`.
    #[inline]
    pub fn get(&self, i: usize) -> [Slot; W] {
        match &self.inner {
            Inner::Plain(v) => v[i],
            Inner::Periodic { slots, .. } => {
                let mut out = [0; W];
                slots.copy(W * i, &mut out);
                out
            }
        }
    }

    /// Every entry's slots, when none is compressed.
    #[inline]
    pub fn as_plain(&self) -> Option<&[[Slot; W]]> {
        match &self.inner {
            Inner::Plain(v) => Some(v),
            Inner::Periodic { .. } => None,
        }
    }

    /// Calls `f` with the slots of the entries `range` (one element's).
    #[inline]
    pub fn with<R>(&self, range: Range<usize>, f: impl FnOnce(&[[Slot; W]]) -> R) -> R {
        match &self.inner {
            Inner::Plain(v) => f(&v[range]),
            Inner::Periodic { slots, .. } => {
                let n = range.len();
                if n <= STACK_ENTRIES {
                    let mut buffer = [[0; W]; STACK_ENTRIES];
                    slots.copy(W * range.start, buffer[..n].as_flattened_mut());
                    f(&buffer[..n])
                } else {
                    let mut buffer = vec![[0; W]; n];
                    slots.copy(W * range.start, buffer.as_flattened_mut());
                    f(&buffer)
                }
            }
        }
    }

    /// Compresses the longest run of consecutive elements with as many entries each (element e
    /// holds the entries `entries(e)`, for e < `elements`) whose slots are periodic, if any
    /// (module documentation).
    pub fn compress(&mut self, elements: usize, entries: impl Fn(usize) -> Range<usize>) {
        let Inner::Plain(plain) = &self.inner else {
            return;
        };
        // The longest stretch of elements of equal size: the candidates for a run.
        let mut best = 0..0;
        let mut from = 0;
        for e in 1..=elements {
            if e == elements || entries(e).len() != entries(from).len() {
                if e - from > best.len() {
                    best = from..e;
                }
                from = e;
            }
        }
        if best.is_empty() {
            return;
        }
        let per_element = W * entries(best.start).len();
        let len = plain.len();
        let flat = plain.as_flattened().to_vec();
        let slots = BlockSlots::new(flat, best, per_element, |e| W * entries(e).start);
        if slots.has_run() {
            self.inner = Inner::Periodic { slots, len };
        }
    }

    /// The plain table, expanded from the compressed run if need be (to change its slots).
    pub fn plain_mut(&mut self) -> &mut Vec<[Slot; W]> {
        if let Inner::Periodic { len, .. } = &self.inner {
            let plain = (0..*len).map(|i| self.get(i)).collect();
            self.inner = Inner::Plain(plain);
        }
        match &mut self.inner {
            Inner::Plain(v) => v,
            Inner::Periodic { .. } => unreachable!("expanded above"),
        }
    }

    /// Whether a run is compressed.
    pub fn is_compressed(&self) -> bool {
        matches!(self.inner, Inner::Periodic { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::NO_SLOT;

    /// A table of 2 + 10 + 1 elements of two entries each, then one of three: the ten in the
    /// middle periodic (steps 7 and 3 in every slot, an absent entry staying absent).
    fn table() -> (Vec<[Slot; 2]>, Vec<Range<usize>>) {
        let mut v = vec![[5, 1], [9, 2], [0, 4], [8, 8]];
        for k in 0..10u32 {
            v.push([100 + 7 * k, NO_SLOT]);
            v.push([300 + 3 * k, 301 + 3 * k]);
        }
        v.extend([[1, 1], [2, 2], [3, 3], [4, 4], [6, 6]]);
        let mut ranges: Vec<Range<usize>> = (0..13).map(|e| 2 * e..2 * e + 2).collect();
        ranges[12] = 24..26;
        ranges.push(26..29);
        (v, ranges)
    }

    /// The compressed table reads every entry and every element as the plain one, and expands
    /// back to it.
    #[test]
    fn a_compressed_table_reads_the_plain_slots() {
        let (plain, ranges) = table();
        let mut t = SlotTable::from(plain.clone());
        t.compress(ranges.len(), |e| ranges[e].clone());
        assert!(t.is_compressed());
        assert_eq!(t.len(), plain.len());
        for (i, s) in plain.iter().enumerate() {
            assert_eq!(&t.get(i), s, "entry {i}");
        }
        for r in &ranges {
            t.with(r.clone(), |got| assert_eq!(got, &plain[r.clone()]));
        }
        assert_eq!(t.plain_mut(), &plain);
        assert!(!t.is_compressed());
    }
}
