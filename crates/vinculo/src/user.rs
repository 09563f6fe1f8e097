//! What user-defined force and constraint groups share: the batched evaluation cache, the call
//! counters, the finite-difference step rules and the failure report.
//!
//! A user *group* is a set of k elements of one arity (one or two particles each) whose terms
//! are computed by one vectorised user function for the whole group at once
//! ([`forces::ForceGroup`](crate::forces::ForceGroup),
//! [`constraints::ConstraintGroup`](crate::constraints::ConstraintGroup)). The group's elements
//! enter the system as ordinary force or constraint elements, so the assembly, the schemes, the
//! consistent start and the redundancy analysis use them through the usual element contract.
//!
//! Batching. An element asked for its term at (q, v, t) looks it up in its group's [`Memo`]: a
//! slot matches when it was evaluated at the same t and at the same positions (and velocities)
//! of *this element's* particles, bit for bit. On a miss the whole group is evaluated once at the
//! caller's (q, v, t) and the result replaces the least recently used slot, so one element loop
//! over the group costs one user call. This is exact under the group contract that element i's
//! output depends only on t and on row i of the inputs (the functions are vectorised
//! elementwise): an element whose own inputs match a slot reads the value it would get from a
//! fresh call. Two slots per quantity serve the schemes that alternate two evaluation points in
//! one loop (the trapezoidal rule's gradients at q_alpha and at q_{n+1}).
//!
//! Concurrency. The cache is behind a mutex; models with user groups are assembled by the
//! serial loops (see [`StepWorkspace::assemble_in_parallel_from`](crate::integrators::StepWorkspace::assemble_in_parallel_from)),
//! where the lock is never contended.
//!
//! Failures. The element contract has no error channel: a user function that fails (raises,
//! returns a wrong shape or a non-finite value) makes its group record the first
//! [`UserFailure`], stop calling the function, and return NaN terms. NaN residuals make Newton
//! fail, and the run loop turns the recorded failure into [`Error::UserFunction`] (keeping the
//! states computed before).

use crate::error::Error;
use crate::math::Vec3;
use std::time::Instant;

/// Why a user function failed.
#[derive(Debug, Clone, PartialEq)]
pub enum UserFailure {
    /// The function raised an error; the text of it.
    Raised(String),
    /// The function returned an array of another shape than the one expected.
    Shape {
        /// What was returned, e.g. "an array of shape (10, 2)".
        returned: String,
        /// The shape expected, e.g. "(10, 3)".
        expected: String,
    },
    /// The output holds NaN or infinity.
    NonFinite {
        /// The first element whose output is not finite.
        element: usize,
    },
}

impl UserFailure {
    /// The run error for a failure of `call` of `group` at time `t`.
    pub fn into_error(self, group: &str, call: &str, t: f64) -> Error {
        match self {
            UserFailure::Raised(message) => Error::UserFunction {
                group: group.into(),
                call: call.into(),
                t,
                message,
            },
            UserFailure::Shape { returned, expected } => Error::UserFunctionOutput {
                group: group.into(),
                call: call.into(),
                t,
                problem: format!("returned {returned}, expected {expected}"),
            },
            UserFailure::NonFinite { element } => Error::UserFunctionOutput {
                group: group.into(),
                call: call.into(),
                t,
                problem: format!(
                    "returned a non-finite value (NaN or infinity) for element {element}"
                ),
            },
        }
    }
}

/// Calls of one user function over a run: how many, and the wall time spent in them (the
/// function itself plus the crossing: copying the inputs in and the outputs out).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CallCount {
    /// Number of calls.
    pub calls: usize,
    /// Total wall time in seconds.
    pub seconds: f64,
}

/// A group's state behind its mutex: caches, counters and the first failure.
#[derive(Debug)]
pub(crate) struct GroupState<const N: usize> {
    /// One cache per cached quantity.
    pub memos: [Memo; N],
    /// One counter per user function.
    pub counts: [CallCount; N],
    /// The first failure (name of the call, time, what went wrong).
    pub failure: Option<(&'static str, f64, UserFailure)>,
}

impl<const N: usize> GroupState<N> {
    pub fn new() -> Self {
        GroupState {
            memos: std::array::from_fn(|_| Memo::default()),
            counts: [CallCount::default(); N],
            failure: None,
        }
    }

    /// Forgets cached values, counts and failures (at the start of a run).
    pub fn reset(&mut self) {
        *self = GroupState::new();
    }

    /// Runs `call` (user function number `which`, named `name`), counting and timing it.
    /// Records the first failure; returns false on failure (or after an earlier one, without
    /// calling).
    pub fn call(
        &mut self,
        which: usize,
        name: &'static str,
        t: f64,
        call: impl FnOnce() -> Result<(), UserFailure>,
    ) -> bool {
        if self.failure.is_some() {
            return false;
        }
        let start = Instant::now();
        let result = call();
        self.counts[which].calls += 1;
        self.counts[which].seconds += start.elapsed().as_secs_f64();
        match result {
            Ok(()) => true,
            Err(f) => {
                self.failure = Some((name, t, f));
                false
            }
        }
    }

    /// Checks that the output `out` of `name` (`width` values per element) is finite; records
    /// a failure naming the first bad element otherwise.
    pub fn finite(&mut self, name: &'static str, t: f64, out: &[f64], width: usize) -> bool {
        match out.iter().position(|x| !x.is_finite()) {
            None => true,
            Some(i) => {
                if self.failure.is_none() {
                    let element = i / width.max(1);
                    self.failure = Some((name, t, UserFailure::NonFinite { element }));
                }
                false
            }
        }
    }

    /// Reads element `e`'s `width` outputs of quantity `memo` at (q, v, t) with `read`: from a
    /// cached batched evaluation whose inputs for this element match, or else from a new one,
    /// `compute(state, q_group, v_group)` over the whole group (stored in the cache). NaN
    /// outputs after a failure.
    #[allow(clippy::too_many_arguments)]
    pub fn lookup<R>(
        &mut self,
        memo: usize,
        width: usize,
        elements: &GroupElements,
        e: usize,
        q: &[Vec3],
        v: Option<&[Vec3]>,
        t: f64,
        compute: impl FnOnce(&mut Self, &[f64], &[f64]) -> Option<Vec<f64>>,
        read: impl FnOnce(&[f64]) -> R,
    ) -> R {
        let parts = elements.get(e);
        if let Some(s) = self.memos[memo].find(e, parts, q, v, t) {
            return read(&s.out[e * width..(e + 1) * width]);
        }
        if self.failure.is_some() {
            return read(&vec![f64::NAN; width]);
        }
        let qg = gather(elements, q);
        let vg = v.map(|v| gather(elements, v)).unwrap_or_default();
        match compute(self, &qg, &vg) {
            Some(out) => {
                let s = self.memos[memo].store(t, qg, vg, out);
                read(&s.out[e * width..(e + 1) * width])
            }
            None => read(&vec![f64::NAN; width]),
        }
    }
}

/// The inputs of one batched evaluation and its outputs.
#[derive(Debug, Clone, Default)]
pub(crate) struct Slot {
    pub t: f64,
    /// Positions of the elements' particles, k x arity x 3.
    pub q: Vec<f64>,
    /// Velocities likewise (empty for quantities of q and t only).
    pub v: Vec<f64>,
    /// Outputs, laid out by the quantity.
    pub out: Vec<f64>,
    used: u64,
}

/// Two-slot least-recently-used cache of one quantity of a group.
#[derive(Debug, Default)]
pub(crate) struct Memo {
    slots: Vec<Slot>,
    clock: u64,
}

/// Slots kept per quantity.
const SLOTS: usize = 2;

impl Memo {
    /// The slot whose inputs for element `e` (particles `parts`) equal q (and v) at t.
    pub fn find(
        &mut self,
        e: usize,
        parts: &[usize],
        q: &[Vec3],
        v: Option<&[Vec3]>,
        t: f64,
    ) -> Option<&Slot> {
        let n = 3 * parts.len();
        let hit = self.slots.iter().position(|s| {
            s.t == t
                && parts.iter().enumerate().all(|(x, &p)| {
                    let at = e * n + 3 * x;
                    s.q[at..at + 3] == q[p] && v.is_none_or(|v| s.v[at..at + 3] == v[p])
                })
        })?;
        self.clock += 1;
        self.slots[hit].used = self.clock;
        Some(&self.slots[hit])
    }

    /// The slot evaluated at exactly these gathered inputs (every element), if any.
    pub fn find_all(&self, q: &[f64], v: &[f64], t: f64) -> Option<&Slot> {
        self.slots
            .iter()
            .find(|s| s.t == t && s.q == q && (v.is_empty() || s.v == v))
    }

    /// Stores an evaluation, replacing the least recently used slot; returns it.
    pub fn store(&mut self, t: f64, q: Vec<f64>, v: Vec<f64>, out: Vec<f64>) -> &Slot {
        self.clock += 1;
        let slot = Slot {
            t,
            q,
            v,
            out,
            used: self.clock,
        };
        let i = if self.slots.len() < SLOTS {
            self.slots.push(slot);
            self.slots.len() - 1
        } else {
            let i = (0..SLOTS).min_by_key(|&i| self.slots[i].used).unwrap_or(0);
            self.slots[i] = slot;
            i
        };
        &self.slots[i]
    }
}

/// The particles of a group's k elements, the same number a >= 1 ("arity") per element, stored
/// flat: element e touches `particles[e a..(e + 1) a]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GroupElements {
    arity: usize,
    particles: Vec<usize>,
}

impl GroupElements {
    /// Elements of `arity` particles each from the flat list `particles` (k a entries).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] when `arity` is 0 or the list's length is not a
    /// multiple of it. (The indices are checked against a system when the group is added.)
    pub fn new(arity: usize, particles: Vec<usize>) -> crate::Result<GroupElements> {
        if arity == 0 {
            return Err(crate::Error::InvalidParameter {
                name: "arity of a user group".into(),
                value: 0.0,
                expected: "must be >= 1: the number of particles of each element".into(),
            });
        }
        if particles.len() % arity != 0 {
            return Err(crate::Error::InvalidParameter {
                name: "number of particle indices of a user group".into(),
                value: particles.len() as f64,
                expected: format!(
                    "must be a multiple of the arity {arity}: {arity} particles per element"
                ),
            });
        }
        Ok(GroupElements { arity, particles })
    }

    /// Elements given as rows of A particles each.
    pub fn from_rows<const A: usize>(rows: &[[usize; A]]) -> GroupElements {
        assert!(A >= 1, "elements need at least one particle");
        GroupElements {
            arity: A,
            particles: rows.iter().flatten().copied().collect(),
        }
    }

    /// Particles per element.
    pub fn arity(&self) -> usize {
        self.arity
    }

    /// Number of elements k.
    pub fn len(&self) -> usize {
        self.particles.len() / self.arity
    }

    /// True when the group has no element.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// The particles of element `e`.
    #[inline]
    pub fn get(&self, e: usize) -> &[usize] {
        &self.particles[e * self.arity..(e + 1) * self.arity]
    }

    /// Every element's particles, in element order.
    pub fn iter(&self) -> std::slice::ChunksExact<'_, usize> {
        self.particles.chunks_exact(self.arity)
    }
}

/// The k x arity x 3 array of `x` at the elements' particles.
pub(crate) fn gather(elements: &GroupElements, x: &[Vec3]) -> Vec<f64> {
    let mut out = Vec::with_capacity(elements.particles.len() * 3);
    for &p in &elements.particles {
        out.extend_from_slice(&x[p]);
    }
    out
}

/// Forward-difference steps for the coordinates `x` (all elements, one array):
/// h_i = sqrt(eps) max(|x_i|, s), s the largest |x| of the array (1 if it is all zero), rounded so
/// that x_i + h_i - x_i = h_i exactly. Returns the perturbed array for coordinate `j` of every
/// element (`n` coordinates per element) and the steps.
///
/// With this step the truncation error h |f''| / 2 and the rounding error 2 eps |f| / h of a
/// forward difference are both of order sqrt(eps) ~ 1.5e-8 relative to the scale of f and its
/// derivatives.
pub(crate) fn forward_steps(x: &[f64], n: usize, j: usize, power: f64) -> (Vec<f64>, Vec<f64>) {
    let s = x.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let s = if s > 0.0 { s } else { 1.0 };
    let rel = f64::EPSILON.powf(power);
    let k = x.len() / n;
    let mut xp = x.to_vec();
    let mut h = vec![0.0; k];
    for e in 0..k {
        let i = e * n + j;
        let step = rel * x[i].abs().max(s);
        xp[i] = x[i] + step;
        h[e] = xp[i] - x[i];
    }
    (xp, h)
}

/// Central-difference points for coordinate `j` of every element: x + h and x - h with
/// h = eps^(1/3) max(|x_j|, s) (s as in [`forward_steps`]), and the exact widths (x + h) - (x - h).
/// The truncation error h^2 |f^(3)| / 6 and the rounding error eps |f| / h are both of order
/// eps^(2/3) ~ 4e-11 relative.
pub(crate) fn central_steps(x: &[f64], n: usize, j: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (xp, h) = forward_steps(x, n, j, 1.0 / 3.0);
    let mut xm = x.to_vec();
    let width = (0..h.len())
        .map(|e| {
            let i = e * n + j;
            xm[i] = x[i] - h[e];
            xp[i] - xm[i]
        })
        .collect();
    (xp, xm, width)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memo_matches_per_element_and_evicts_the_least_recent() {
        let elements = GroupElements::from_rows(&[[0, 1], [2, 3]]);
        let q: Vec<Vec3> = (0..4).map(|i| [i as f64, 0.5, -1.0]).collect();
        let mut m = Memo::default();
        m.store(0.1, gather(&elements, &q), vec![], vec![1.0, 2.0]);
        assert!(m.find(1, &[2, 3], &q, None, 0.1).is_some());
        assert!(m.find(1, &[2, 3], &q, None, 0.2).is_none());
        // Element 0 still matches when only element 1's particles moved.
        let mut q2 = q.clone();
        q2[3][0] += 1e-12;
        assert!(m.find(0, &[0, 1], &q2, None, 0.1).is_some());
        assert!(m.find(1, &[2, 3], &q2, None, 0.1).is_none());
        m.store(0.1, gather(&elements, &q2), vec![], vec![3.0, 4.0]);
        m.find(1, &[2, 3], &q, None, 0.1); // touch the first slot
        m.store(0.3, gather(&elements, &q), vec![], vec![5.0, 6.0]);
        // The second slot (least recently used) was replaced.
        assert!(m.find(1, &[2, 3], &q2, None, 0.1).is_none());
        assert_eq!(
            m.find(1, &[2, 3], &q, None, 0.1).unwrap().out,
            vec![1.0, 2.0]
        );
    }

    #[test]
    fn forward_steps_are_exact_and_scaled() {
        let x = [0.0, 3.0, 1e-9, -2.0];
        let (xp, h) = forward_steps(&x, 2, 0, 0.5);
        // Both elements' first coordinates (0 and 1e-9) are below the array's scale 3.
        assert_eq!(h.len(), 2);
        assert_eq!(xp[0] - x[0], h[0]);
        assert!((h[0] / (f64::EPSILON.sqrt() * 3.0) - 1.0).abs() < 1e-6);
        assert!((h[1] / (f64::EPSILON.sqrt() * 3.0) - 1.0).abs() < 1e-6);
        assert_eq!(xp[1], x[1]);
    }
}
