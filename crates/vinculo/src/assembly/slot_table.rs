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
//! the stack ([`SlotTable::fill`] for an element of known size, [`SlotTable::with`] for any);
//! the others are read where they are stored. Measured on a swinging chain of 10^6 particles
//! (`cargo bench -p vinculo --bench scaling -- 1000000 swinging`, three runs each, alternated):
//! peak 1,363 -> 1,153 MB, a step 0.46 to 0.52 s against 0.50 to 0.59 s with the plain tables
//! (the machine's noise); the Jacobian's instructions rise by about 240 an element (callgrind,
//! 150,000 particles), for 228 bytes of tables an element no longer read from memory.

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
    /// A run of elements compressed, the elements `run` (consecutive); `len` entries in all.
    Periodic {
        slots: BlockSlots,
        run: Range<usize>,
        len: usize,
    },
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

    /// The slots of entry `i`, of a table of one entry an element.
    #[inline]
    pub fn get(&self, i: usize) -> [Slot; W] {
        let mut out = [[0; W]; 1];
        self.fill(i, i, &mut out);
        out[0]
    }

    /// Every entry's slots, when none is compressed.
    #[inline]
    pub fn as_plain(&self) -> Option<&[[Slot; W]]> {
        match &self.inner {
            Inner::Plain(v) => Some(v),
            Inner::Periodic { .. } => None,
        }
    }

    /// Slots `picked` of entry `i`, of a table of one entry an element (a particle's diagonal
    /// entries of its block: 0, 4 and 8).
    #[inline(always)]
    pub fn picked<const P: usize>(&self, i: usize, picked: [usize; P]) -> [Slot; P] {
        let mut out = [0; P];
        match &self.inner {
            Inner::Plain(v) => {
                for (o, &j) in out.iter_mut().zip(&picked) {
                    *o = v[i][j];
                }
            }
            Inner::Periodic { slots, run, .. } if run.contains(&i) => {
                for (o, &j) in out.iter_mut().zip(&picked) {
                    slots.copy_run(i - run.start, j, std::slice::from_mut(o));
                }
            }
            Inner::Periodic { .. } => {
                let all = self.get(i);
                for (o, &j) in out.iter_mut().zip(&picked) {
                    *o = all[j];
                }
            }
        }
        out
    }

    /// The slots of the `N` entries from `start` into `out`: element `element`'s, or the
    /// first of them (an element of known size, read without a call: a distance's four
    /// blocks).
    #[inline(always)]
    pub fn fill<const N: usize>(&self, element: usize, start: usize, out: &mut [[Slot; W]; N]) {
        match &self.inner {
            Inner::Plain(v) => out.copy_from_slice(&v[start..start + N]),
            Inner::Periodic { slots, run, .. } => copy(slots, run, element, start, out),
        }
    }

    /// Calls `f` with the slots of the entries `range`: element `element`'s, or the first of
    /// them.
    #[inline]
    pub fn with<R>(
        &self,
        element: usize,
        range: Range<usize>,
        f: impl FnOnce(&[[Slot; W]]) -> R,
    ) -> R {
        match &self.inner {
            Inner::Plain(v) => f(&v[range]),
            Inner::Periodic { slots, run, .. } => {
                let copy = |out: &mut [[Slot; W]]| copy(slots, run, element, range.start, out);
                let n = range.len();
                if n <= 4 {
                    // A two-particle element's blocks, or a particle's strip of one.
                    let mut buffer = [[0; W]; 4];
                    copy(&mut buffer[..n]);
                    f(&buffer[..n])
                } else if n <= STACK_ENTRIES {
                    let mut buffer = [[0; W]; STACK_ENTRIES];
                    copy(&mut buffer[..n]);
                    f(&buffer[..n])
                } else {
                    let mut buffer = vec![[0; W]; n];
                    copy(&mut buffer);
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
        let first = W * entries(best.start).start;
        let slots = BlockSlots::new(flat, best.clone(), per_element, |e| W * entries(e).start);
        if let Some(found) = slots.run_entries() {
            // The elements of the run (of equal size, consecutive among the candidates).
            let start = best.start + (found.start - first) / per_element;
            let run = start..start + found.len() / per_element;
            self.inner = Inner::Periodic { slots, run, len };
        }
    }

    /// The plain table, expanded from the compressed run if need be (to change its slots).
    pub fn plain_mut(&mut self) -> &mut Vec<[Slot; W]> {
        if let Inner::Periodic { slots, len, .. } = &self.inner {
            let mut plain = vec![[0; W]; *len];
            for (i, entry) in plain.iter_mut().enumerate() {
                slots.copy(W * i, entry);
            }
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

/// The slots of the entries from `start` (element `element`'s, or the first of them) into
/// `out`: computed from the run's first element's for an element of the run `run`, read for
/// another.
#[inline(always)]
fn copy<const W: usize>(
    slots: &BlockSlots,
    run: &Range<usize>,
    element: usize,
    start: usize,
    out: &mut [[Slot; W]],
) {
    if run.contains(&element) {
        slots.copy_run(element - run.start, 0, out.as_flattened_mut());
    } else {
        slots.copy(W * start, out.as_flattened_mut());
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

    /// The compressed table reads every element as the plain one, and expands back to it.
    #[test]
    fn a_compressed_table_reads_the_plain_slots() {
        let (plain, ranges) = table();
        let mut t = SlotTable::from(plain.clone());
        t.compress(ranges.len(), |e| ranges[e].clone());
        assert!(t.is_compressed());
        assert_eq!(t.len(), plain.len());
        for (e, r) in ranges.iter().enumerate() {
            t.with(e, r.clone(), |got| assert_eq!(got, &plain[r.clone()]));
            if r.len() == 2 {
                let mut got = [[0; 2]; 2];
                t.fill(e, r.start, &mut got);
                assert_eq!(&got[..], &plain[r.clone()], "element {e}");
            }
        }
        assert_eq!(t.plain_mut(), &plain);
        assert!(!t.is_compressed());
        // One entry an element (a particle's block): read by `get`; elements 2 to 11 periodic.
        let single: Vec<[Slot; 1]> = (0..12u32)
            .map(|k| [if k < 2 { 7 - k } else { 50 + 4 * k }])
            .collect();
        let mut u = SlotTable::from(single.clone());
        u.compress(single.len(), |i| i..i + 1);
        assert!(u.is_compressed());
        for (i, s) in single.iter().enumerate() {
            assert_eq!(&u.get(i), s, "element {i}");
            assert_eq!(u.picked(i, [0]), *s, "element {i}");
        }
    }
}
