//! Compressed sparse column pattern of the iteration matrix, or dense column-major storage for
//! small systems; both give each (row, column) entry a fixed slot in a value array.

use super::{Block, Slot, NONE, NO_SLOT};

/// How the matrix's values are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Compressed sparse columns.
    Sparse,
    /// Dense, column-major.
    Dense,
}

/// Structure of an n x n matrix.
#[derive(Debug, Clone)]
pub struct Pattern {
    /// Dimension.
    pub n: usize,
    /// Column pointers (CSC; for dense storage, k n).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column (CSC; for dense storage, 0..n per column).
    pub row_idx: Vec<usize>,
    /// Storage kind.
    pub storage: Storage,
    /// Number of stored entries (kept when the index arrays are released).
    stored: usize,
}

/// A row or column index of the entries a pattern is built from: `usize`, or `u32` where the
/// entries are many (a model's layout: 58 million entries for a chain of 10^6 particles, whose
/// list at 16 bytes an entry was the peak memory of the run).
pub trait EntryIndex: Copy {
    /// The index.
    fn index(self) -> usize;
}

impl EntryIndex for usize {
    fn index(self) -> usize {
        self
    }
}

impl EntryIndex for u32 {
    fn index(self) -> usize {
        self as usize
    }
}

impl Pattern {
    /// Builds the pattern from (row, column) entries (duplicates allowed).
    ///
    /// # Panics
    /// If the matrix has more entries than 32-bit slots can address (about four billion, far
    /// beyond any model that fits in memory).
    pub fn new<E: EntryIndex>(n: usize, entries: Vec<(E, E)>, dense: bool) -> Pattern {
        let pattern = Pattern::build(n, entries, dense);
        assert!(
            pattern.nnz() < NO_SLOT as usize,
            "the iteration matrix has {} entries, more than 32-bit slots can address",
            pattern.nnz()
        );
        pattern
    }

    fn build<E: EntryIndex>(n: usize, entries: Vec<(E, E)>, dense: bool) -> Pattern {
        if dense {
            return Pattern {
                n,
                col_ptr: (0..=n).map(|c| c * n).collect(),
                row_idx: (0..n * n).map(|k| k % n.max(1)).collect(),
                storage: Storage::Dense,
                stored: n * n,
            };
        }
        // Columns by a counting sort (linear in the entries: a comparison sort of the tens of
        // millions of entries of a million-particle chain took seconds of the run's start),
        // then each column's few rows sorted and their duplicates dropped.
        // end[c] counts column c's entries, then (prefix sums) is where it starts; the scatter
        // advances it to where the column ends, so that column c is end[c - 1]..end[c] after.
        let mut end = vec![0usize; n + 1];
        for &(_, c) in &entries {
            end[c.index() + 1] += 1;
        }
        for c in 0..n {
            end[c + 1] += end[c];
        }
        // Rows as 32 bits while sorting (n is below the 32-bit slots' bound, checked after).
        let mut rows = vec![0u32; entries.len()];
        for &(r, c) in &entries {
            let c = c.index();
            rows[end[c]] = r.index() as u32;
            end[c] += 1;
        }
        drop(entries);
        let mut col_ptr = vec![0; n + 1];
        let mut kept = 0;
        for c in 0..n {
            let first = if c == 0 { 0 } else { end[c - 1] };
            rows[first..end[c]].sort_unstable();
            let mut last = None;
            for k in first..end[c] {
                let r = rows[k];
                if last != Some(r) {
                    last = Some(r);
                    // Compacting in place: `kept` never passes the read position k.
                    rows[kept] = r;
                    kept += 1;
                }
            }
            col_ptr[c + 1] = kept;
        }
        drop(end);
        // A fresh vector of the exact length: truncating `rows` would keep its allocation of
        // every duplicate.
        let row_idx: Vec<usize> = rows[..kept].iter().map(|&r| r as usize).collect();
        drop(rows);
        Pattern {
            n,
            col_ptr,
            stored: row_idx.len(),
            row_idx,
            storage: Storage::Sparse,
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.stored
    }

    /// Frees the index arrays (`col_ptr`, `row_idx`), keeping `n`, `nnz` and the storage kind.
    /// Once the slots are computed and the linear solver has analysed the pattern (it keeps
    /// its own copy of what it needs), nothing reads them; for a million-particle chain they
    /// are a third of a gigabyte. [`Pattern::slot`] panics afterwards.
    pub fn release_structure(&mut self) {
        self.col_ptr = Vec::new();
        self.row_idx = Vec::new();
    }

    /// True once [`Pattern::release_structure`] was called.
    pub fn is_released(&self) -> bool {
        self.col_ptr.is_empty()
    }

    /// Every structural entry as (row, column, slot), column by column (none once released).
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        self.col_ptr
            .windows(2)
            .enumerate()
            .flat_map(move |(col, w)| (w[0]..w[1]).map(move |k| (self.row_idx[k], col, k)))
    }
    /// [`Pattern::slot`] as the layouts' 32-bit [`Slot`] ([`Pattern::new`] checks that every
    /// slot fits).
    pub fn slot32(&self, row: usize, col: usize) -> Slot {
        self.slot(row, col) as Slot
    }

    /// Slots of the 3x3 block whose first row is `a` and first column `b`, row-major (all absent
    /// when either is NONE, a fixed particle).
    pub fn block_slots(&self, a: usize, b: usize) -> Block {
        let mut s = [NO_SLOT; 9];
        if a != NONE && b != NONE {
            for r in 0..3 {
                for c in 0..3 {
                    s[3 * r + c] = self.slot32(a + r, b + c);
                }
            }
        }
        s
    }

    /// Slot of entry (row, col).
    ///
    /// # Panics
    /// If the entry is not in the pattern (a bug in the layout).
    #[track_caller]
    pub fn slot(&self, row: usize, col: usize) -> usize {
        match self.storage {
            Storage::Dense => col * self.n + row,
            Storage::Sparse => {
                assert!(!self.is_released(), "the pattern's structure was released");
                let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
                match self.row_idx[a..b].binary_search(&row) {
                    Ok(k) => a + k,
                    Err(_) => panic!("entry ({row}, {col}) is not in the pattern"),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_hold_each_entry_once_with_rows_in_order() {
        // Entries in a scrambled order with duplicates, empty columns included: the pattern is
        // the sorted, deduplicated set (compared with a BTreeSet of the same entries).
        let n = 9;
        let mut entries = Vec::new();
        for k in 0..200usize {
            let (r, c) = ((k * 7 + 3) % n, (k * 5 + k / 3) % n);
            if c != 4 {
                entries.push((r, c));
            }
        }
        let expected: std::collections::BTreeSet<(usize, usize)> =
            entries.iter().map(|&(r, c)| (c, r)).collect();
        let p = Pattern::new(n, entries, false);
        let got: Vec<(usize, usize)> = p.entries().map(|(r, c, _)| (c, r)).collect();
        assert_eq!(got, expected.into_iter().collect::<Vec<_>>());
        assert_eq!(p.col_ptr[5] - p.col_ptr[4], 0);
        assert_eq!(p.nnz(), got.len());
    }
}
