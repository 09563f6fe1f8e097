//! Where a block storage of the tree elimination reads its entries in the matrix's value array:
//! one slot per storage entry, except over a run of equal blocks whose slots advance by a fixed
//! step from one block to the next.
//!
//! The tree elimination ([`super::TreeElimination`]) keeps each block's dense storage (its
//! diagonal block D_b, its couplings A_ub and A_bu) and gathers the matrix's entries into it at
//! every factorisation, from the slot of each storage entry in the pattern's value array. On a
//! chain of N equal blocks those slots are periodic: block b + 1's entry e lies a fixed number of
//! slots after (or before) block b's, because every column of the pattern holds the same entries
//! shifted by one block. A run of such blocks keeps the slots of its first block and the step of
//! each entry, `slot(b, e) = slot(first, e) + (b - first) step(e)`, instead of 3 N n_b (n_b + 2)
//! slots: on a chain of 10^6 particles 160 MB of u32 that each factorisation also had to read.
//! [`BlockSlots::new`] finds the longest periodic run among the blocks it is offered and checks
//! every entry of it; the other blocks keep their slots one by one.

use std::ops::Range;

/// A storage entry with no slot: a fill entry, zero in the matrix.
pub(crate) const ABSENT: u32 = u32::MAX;

/// A run of consecutive blocks of equal storage whose slots are periodic.
#[derive(Debug, Clone, PartialEq)]
struct Run {
    /// The storage entries of the run: `entries.start` is its first block's first entry.
    entries: Range<usize>,
    /// Storage entries per block.
    per_block: usize,
    /// The slots of the first block's entries (ABSENT for fill).
    first: Vec<u32>,
    /// The change of each entry's slot from one block to the next.
    step: Vec<i64>,
    /// The steps modulo 2^32 (0 for fill): `first + block step` in wrapping u32 arithmetic is
    /// the slot (every slot is below 2^32, and fill stays ABSENT), a loop without branches.
    wrapping_step: Vec<u32>,
}

/// The slots of one block storage (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BlockSlots {
    /// The slots of the storage entries before the run, then of those after it (all of them
    /// without a run).
    explicit: Vec<u32>,
    run: Option<Run>,
}

/// Fewest blocks a run must have to be kept as one (shorter runs keep their slots).
const MIN_RUN: usize = 4;

impl BlockSlots {
    /// The slots `slots` of a storage whose block b holds the entries
    /// `first_entry(b)..first_entry(b + 1)`, with the longest periodic run found among the
    /// blocks `candidates` (consecutive blocks of `per_block` entries each).
    pub(crate) fn new(
        slots: Vec<u32>,
        candidates: Range<usize>,
        per_block: usize,
        first_entry: impl Fn(usize) -> usize,
    ) -> BlockSlots {
        let run = longest_run(&slots, candidates, per_block, &first_entry);
        match run {
            Some(run) => {
                let explicit = [&slots[..run.entries.start], &slots[run.entries.end..]].concat();
                BlockSlots {
                    explicit,
                    run: Some(run),
                }
            }
            None => BlockSlots {
                explicit: slots,
                run: None,
            },
        }
    }

    /// The slot of storage entry `e` (ABSENT for fill).
    pub(crate) fn get(&self, e: usize) -> u32 {
        match &self.run {
            Some(run) if e >= run.entries.end => self.explicit[e - run.entries.len()],
            Some(run) if e >= run.entries.start => {
                let (block, k) = (
                    (e - run.entries.start) / run.per_block,
                    (e - run.entries.start) % run.per_block,
                );
                run.slot(block, k)
            }
            _ => self.explicit[e],
        }
    }

    /// The slots of the entries `entries.start..entries.start + out.len()`, which lie in one
    /// block, into `out`.
    #[inline]
    pub(crate) fn copy(&self, start: usize, out: &mut [u32]) {
        match &self.run {
            Some(run) if start >= run.entries.start && start < run.entries.end => {
                let offset = start - run.entries.start;
                self.copy_run(offset / run.per_block, offset % run.per_block, out);
            }
            Some(run) if start >= run.entries.end => {
                let at = start - run.entries.len();
                out.copy_from_slice(&self.explicit[at..at + out.len()]);
            }
            _ => out.copy_from_slice(&self.explicit[start..start + out.len()]),
        }
    }

    /// The storage entries of the periodic run, if one was found.
    pub(crate) fn run_entries(&self) -> Option<Range<usize>> {
        self.run.as_ref().map(|run| run.entries.clone())
    }

    /// The slots of the entries `k..k + out.len()` of block `block` of the run (counted from
    /// its first), into `out`.
    #[inline(always)]
    pub(crate) fn copy_run(&self, block: usize, k: usize, out: &mut [u32]) {
        let run = self.run.as_ref().expect("a run");
        let n = out.len();
        let block = block as u32;
        let (first, step) = (&run.first[k..k + n], &run.wrapping_step[k..k + n]);
        for ((o, &s), &d) in out.iter_mut().zip(first).zip(step) {
            *o = s.wrapping_add(block.wrapping_mul(d));
        }
    }

    /// Slots kept one by one (the run's are computed).
    #[cfg(test)]
    pub(crate) fn explicit_len(&self) -> usize {
        self.explicit.len()
    }

    /// Gathers the values of the storage entries `entries` (one block's) into `out`: fill
    /// entries are zero.
    pub(super) fn gather(&self, entries: Range<usize>, out: &mut [f64], values: &[f64]) {
        match &self.run {
            Some(run) if entries.start >= run.entries.start && entries.start < run.entries.end => {
                let offset = entries.start - run.entries.start;
                let block = (offset / run.per_block) as u32;
                // A fill entry's slot stays ABSENT, past the end of `values` (every slot is
                // below ABSENT): one bounds test reads a slot or gives the fill's zero.
                let (first, step) = (&run.first[..out.len()], &run.wrapping_step[..out.len()]);
                for ((o, &s), &d) in out.iter_mut().zip(first).zip(step) {
                    let slot = s.wrapping_add(block.wrapping_mul(d)) as usize;
                    *o = values.get(slot).copied().unwrap_or(0.0);
                }
            }
            Some(run) if entries.start >= run.entries.end => {
                let shift = run.entries.len();
                gather(
                    out,
                    &self.explicit[entries.start - shift..entries.end - shift],
                    values,
                )
            }
            _ => gather(out, &self.explicit[entries], values),
        }
    }
}

impl Run {
    /// The slot of entry `k` of the run's block `block` (counted from its first).
    fn slot(&self, block: usize, k: usize) -> u32 {
        let s = self.first[k];
        if s == ABSENT {
            ABSENT
        } else {
            (s as i64 + block as i64 * self.step[k]) as u32
        }
    }
}

/// Gathers `values` at `slots` into `out` (absent entries, whose slot ABSENT lies past the end
/// of `values`, are zero).
fn gather(out: &mut [f64], slots: &[u32], values: &[f64]) {
    for (o, &s) in out.iter_mut().zip(slots) {
        *o = values.get(s as usize).copied().unwrap_or(0.0);
    }
}

/// The longest run of consecutive blocks among `candidates` whose slots are periodic, if it
/// has at least [`MIN_RUN`] blocks: each entry's slot changes by the same step from one block
/// to the next (a fill entry stays fill).
fn longest_run(
    slots: &[u32],
    candidates: Range<usize>,
    per_block: usize,
    first_entry: &impl Fn(usize) -> usize,
) -> Option<Run> {
    if per_block == 0 || candidates.len() < MIN_RUN {
        return None;
    }
    let block = |b: usize| &slots[first_entry(b)..first_entry(b) + per_block];
    // The step of each entry from block a to a + 1 (a fill entry stays fill: step 0), into `d`;
    // false when a fill entry becomes a slot or back.
    let step_into = |a: usize, d: &mut Vec<i64>| {
        d.clear();
        for (&s, &t) in block(a).iter().zip(block(a + 1)) {
            match (s == ABSENT, t == ABSENT) {
                (true, true) => d.push(0),
                (false, false) => d.push(t as i64 - s as i64),
                _ => return false,
            }
        }
        true
    };
    // Whether block a + 1's slots are block a's advanced by `d`.
    let same_step = |a: usize, d: &[i64]| {
        block(a)
            .iter()
            .zip(block(a + 1))
            .zip(d)
            .all(|((&s, &t), &d)| {
                if s == ABSENT {
                    t == ABSENT
                } else {
                    t != ABSENT && t as i64 - s as i64 == d
                }
            })
    };
    // Scan the candidates: a run grows while the step between neighbours stays the same.
    let mut best: Option<(usize, usize, Vec<i64>)> = None;
    let mut d = Vec::with_capacity(per_block);
    let mut b = candidates.start;
    while b + 1 < candidates.end {
        if !step_into(b, &mut d) {
            b += 1;
            continue;
        }
        let mut end = b + 2;
        while end < candidates.end && same_step(end - 1, &d) {
            end += 1;
        }
        if best.as_ref().is_none_or(|(s, e, _)| end - b > e - s) {
            best = Some((b, end, d.clone()));
        }
        b = end - 1;
    }
    let (from, to, step) = best.filter(|(s, e, _)| e - s >= MIN_RUN)?;
    Some(Run {
        entries: first_entry(from)..first_entry(to),
        per_block,
        first: block(from).to_vec(),
        wrapping_step: step.iter().map(|&d| d as u32).collect(),
        step,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blocks of 3 entries: blocks 0 and 1 irregular, 2..8 periodic (steps 5, -2 and fill), 8
    /// irregular.
    fn slots() -> Vec<u32> {
        let mut s = vec![7, 3, ABSENT, 9, 100, 1];
        for b in 0..6u32 {
            s.extend([10 + 5 * b, 60 - 2 * b, ABSENT]);
        }
        s.extend([2, 2, 2]);
        s
    }

    /// The compressed slots are the slots, entry for entry, and gather the same values; the run
    /// is the six periodic blocks.
    #[test]
    fn a_periodic_run_keeps_its_first_block_and_steps_and_reads_the_same_slots() {
        let full = slots();
        let compressed = BlockSlots::new(full.clone(), 0..9, 3, |b| 3 * b);
        assert_eq!(compressed.explicit_len(), 9, "blocks 0, 1 and 8");
        for (e, &s) in full.iter().enumerate() {
            assert_eq!(compressed.get(e), s, "entry {e}");
        }
        let values: Vec<f64> = (0..200).map(|x| x as f64 + 0.5).collect();
        for b in 0..9 {
            let (mut a, mut c) = ([0.0; 3], [0.0; 3]);
            compressed.gather(3 * b..3 * b + 3, &mut a, &values);
            gather(&mut c, &full[3 * b..3 * b + 3], &values);
            assert_eq!(a, c, "block {b}");
        }
    }

    /// Runs shorter than MIN_RUN blocks, or a fill entry that becomes a slot, are not runs.
    #[test]
    fn short_or_broken_runs_keep_every_slot() {
        let full = slots();
        let short = BlockSlots::new(full.clone(), 2..5, 3, |b| 3 * b);
        assert_eq!(short.explicit_len(), full.len());
        let mut broken = full.clone();
        broken[3 * 5 + 2] = 42;
        let split = BlockSlots::new(broken.clone(), 0..9, 3, |b| 3 * b);
        for (e, &s) in broken.iter().enumerate() {
            assert_eq!(split.get(e), s, "entry {e}");
        }
        assert!(split.explicit_len() > 9);
    }
}
