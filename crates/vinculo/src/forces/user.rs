//! Forces computed by a user function for a whole group of elements at once.
//!
//! A group has k elements of arity a (a particles each, any a >= 1) and a [`ForceGroup`], which
//! maps the positions and velocities of every element's particles, arrays k x a x 3, to the
//! forces on them, k x a x 3, and optionally to the Jacobians df/dq and df/dv, k x 3a x 3a
//! (row 3p + l: component l of the force on the element's particle p; column 3r + m: coordinate
//! m of its particle r). Element i's output must depend only on t and row i of the inputs.
//!
//! Without a user Jacobian, forward differences over the whole group: for each of the 3a
//! coordinates j, one call with coordinate j of every element perturbed at once,
//!
//! ```text
//! df_i/dx_j ~ (f_i(x + h e_j) - f_i(x)) / h,   h = sqrt(eps) max(|x_j|, s)
//! ```
//!
//! (s the largest |x| of the group, see [`crate::user`]), for x = q and then x = v: 6a calls per
//! Jacobian, plus the base value f(x), which the residual at the same point has usually cached.
//! The error is of order sqrt(eps) ~ 1e-8 relative to the force's scale; it changes Newton's
//! rate, not the converged point (the residual is exact).
//!
//! See [`crate::user`] for the batching, caching and failure rules.

use super::{Jacobian, Local};
use crate::math::Vec3;
use crate::user::{forward_steps, CallCount, GroupElements, GroupState, UserFailure};
use std::sync::{Arc, Mutex, MutexGuard};

/// The user functions of a force group (no Python in the core: the bindings implement it).
pub trait ForceGroup: Send + Sync {
    /// Writes the forces on every element's particles, k x a x 3 (flat, row-major), at time
    /// `t` for positions `q` and velocities `v` of the same shape.
    fn force(&self, t: f64, q: &[f64], v: &[f64], f: &mut [f64]) -> Result<(), UserFailure>;

    /// True when [`ForceGroup::jacobian`] is supplied (otherwise finite differences).
    fn has_jacobian(&self) -> bool;

    /// Writes df/dq into `dq` and df/dv into `dv`, each k x 3a x 3a (flat, row-major).
    fn jacobian(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), UserFailure>;
}

/// Index of the force function's counter and cache.
const FORCE: usize = 0;
/// Index of the Jacobian function's counter and cache.
const JACOBIAN: usize = 1;

/// A group of user force elements with its batched-evaluation cache and call counters.
pub struct UserForces {
    /// The group's name (used in messages).
    pub name: String,
    /// Each element's particles (any number per element, the same for all).
    pub elements: GroupElements,
    functions: Box<dyn ForceGroup>,
    state: Mutex<GroupState<2>>,
}

impl std::fmt::Debug for UserForces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "UserForces({:?}, {} elements of arity {})",
            self.name,
            self.elements.len(),
            self.elements.arity()
        )
    }
}

impl UserForces {
    /// A group over `elements` (the caller has checked the indices and the arity).
    pub fn new(
        name: String,
        elements: GroupElements,
        functions: Box<dyn ForceGroup>,
    ) -> UserForces {
        UserForces {
            name,
            elements,
            functions,
            state: Mutex::new(GroupState::new()),
        }
    }

    fn lock(&self) -> MutexGuard<'_, GroupState<2>> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Calls of the force and of the Jacobian function since the last reset (the start of the
    /// last run): `[force, jacobian]`. Finite-difference evaluations count as force calls.
    pub fn counts(&self) -> [CallCount; 2] {
        self.lock().counts
    }

    /// Forgets cached values, counts and any failure.
    pub fn reset(&self) {
        self.lock().reset();
    }

    /// The first failure since the last reset, as a run error.
    pub fn failure(&self) -> Option<crate::Error> {
        let st = self.lock();
        let (call, t, f) = st.failure.clone()?;
        Some(f.into_error(&self.name, call, t))
    }

    /// Evaluates the group at the inputs `q`, `v` (k x a x 3) outside a run, with a fresh cache
    /// and without counting: the forces (k x a x 3), df/dq and df/dv (k x 3a x 3a each), the
    /// Jacobian by finite differences when `finite_differences` is set (or no Jacobian is
    /// supplied). For checking a user Jacobian against the finite differences.
    pub fn evaluate(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        finite_differences: bool,
    ) -> crate::Result<[Vec<f64>; 3]> {
        let mut st = GroupState::new();
        let failed = |st: &GroupState<2>| {
            let (call, t, f) = st.failure.clone().expect("a failure");
            f.into_error(&self.name, call, t)
        };
        let f = self
            .call_force(&mut st, t, q, v)
            .ok_or_else(|| failed(&st))?;
        st.memos[FORCE].store(t, q.to_vec(), v.to_vec(), f.clone());
        let both = self
            .call_jacobian(&mut st, t, q, v, finite_differences)
            .ok_or_else(|| failed(&st))?;
        let nn = self.width() * self.width();
        let (mut dq, mut dv) = (Vec::new(), Vec::new());
        for e in both.chunks(2 * nn) {
            dq.extend_from_slice(&e[..nn]);
            dv.extend_from_slice(&e[nn..]);
        }
        Ok([f, dq, dv])
    }

    /// Number of coordinates of one element, 3a.
    fn width(&self) -> usize {
        3 * self.elements.arity()
    }

    /// One call of the force function over the group.
    fn call_force(&self, st: &mut GroupState<2>, t: f64, q: &[f64], v: &[f64]) -> Option<Vec<f64>> {
        let mut f = vec![0.0; q.len()];
        let ok = st.call(FORCE, "force", t, || self.functions.force(t, q, v, &mut f));
        (ok && st.finite("force", t, &f, self.width())).then_some(f)
    }

    /// df/dq and df/dv over the group, laid out per element as [its dq (n n), its dv (n n)].
    fn call_jacobian(
        &self,
        st: &mut GroupState<2>,
        t: f64,
        q: &[f64],
        v: &[f64],
        finite_differences: bool,
    ) -> Option<Vec<f64>> {
        let n = self.width();
        let k = self.elements.len();
        let mut dq = vec![0.0; k * n * n];
        let mut dv = vec![0.0; k * n * n];
        if self.functions.has_jacobian() && !finite_differences {
            let ok = st.call(JACOBIAN, "jacobian", t, || {
                self.functions.jacobian(t, q, v, &mut dq, &mut dv)
            });
            if !(ok && st.finite("jacobian", t, &dq, n * n) && st.finite("jacobian", t, &dv, n * n))
            {
                return None;
            }
        } else {
            let base = match st.memos[FORCE].find_all(q, v, t) {
                Some(s) => s.out.clone(),
                None => {
                    let f = self.call_force(st, t, q, v)?;
                    st.memos[FORCE].store(t, q.to_vec(), v.to_vec(), f.clone());
                    f
                }
            };
            for (which, out) in [&mut dq, &mut dv].into_iter().enumerate() {
                for j in 0..n {
                    let (xp, h) = forward_steps(if which == 0 { q } else { v }, n, j, 0.5);
                    let fp = if which == 0 {
                        self.call_force(st, t, &xp, v)?
                    } else {
                        self.call_force(st, t, q, &xp)?
                    };
                    for e in 0..k {
                        for i in 0..n {
                            out[e * n * n + i * n + j] = (fp[e * n + i] - base[e * n + i]) / h[e];
                        }
                    }
                }
            }
        }
        // Per element: its df/dq block, then its df/dv block.
        let mut out = Vec::with_capacity(2 * k * n * n);
        for e in 0..k {
            out.extend_from_slice(&dq[e * n * n..(e + 1) * n * n]);
            out.extend_from_slice(&dv[e * n * n..(e + 1) * n * n]);
        }
        Some(out)
    }
}

/// One element of a user force group.
#[derive(Clone)]
pub struct UserForce {
    /// The group.
    pub group: Arc<UserForces>,
    /// The element's position in the group.
    pub element: usize,
}

impl UserForce {
    /// Element `element` of `group`.
    pub fn new(group: Arc<UserForces>, element: usize) -> UserForce {
        UserForce { group, element }
    }

    pub(crate) fn particles(&self) -> &[usize] {
        self.group.elements.get(self.element)
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Local {
        let g = &*self.group;
        let n = g.width();
        g.lock().lookup(
            FORCE,
            n,
            &g.elements,
            self.element,
            q,
            Some(v),
            t,
            |st, qg, vg| g.call_force(st, t, qg, vg),
            |f| f.chunks_exact(3).map(|x| [x[0], x[1], x[2]]).collect(),
        )
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let g = &*self.group;
        let n = g.width();
        let arity = g.elements.arity();
        g.lock().lookup(
            JACOBIAN,
            2 * n * n,
            &g.elements,
            self.element,
            q,
            Some(v),
            t,
            |st, qg, vg| g.call_jacobian(st, t, qg, vg, false),
            |local| {
                for (half, out) in [(0, dq), (1, dv)] {
                    for p in 0..arity {
                        for r in 0..arity {
                            for l in 0..3 {
                                for m in 0..3 {
                                    out[p][r][l][m] +=
                                        local[half * n * n + (3 * p + l) * n + 3 * r + m];
                                }
                            }
                        }
                    }
                }
            },
        )
    }
}

impl PartialEq for UserForce {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.group, &other.group) && self.element == other.element
    }
}

impl std::fmt::Debug for UserForce {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "UserForce({:?} element {}, particles {:?})",
            self.group.name,
            self.element,
            self.particles()
        )
    }
}
