//! Constraints computed by user functions for a whole group of elements at once.
//!
//! A group has k elements of arity a (a particles each, any a >= 1), one equation each, and a
//! [`ConstraintGroup`] that evaluates, for positions q (k x a x 3) at time t:
//! - Phi: k values (always supplied);
//! - the gradient dPhi/dq: k x a x 3;
//! - the Hessian d2Phi/dq2: k x 3a x 3a (entry (3p + l, 3r + m): particles p and r, coordinates
//!   l and m);
//! - Phi_t: k values;
//! - gamma = Phi'' - Phi_q a: k values (it also takes the velocities v, k x a x 3).
//!
//! Element i's outputs must depend only on t and row i of the inputs. Whatever is not supplied
//! is computed by finite differences over the whole group (all elements perturbed at once, see
//! [`crate::user`] for the step rule h = c max(|x|, s)), with n = 3a:
//! - gradient: central differences of Phi, c = eps^(1/3): 2n calls of Phi, error ~ 4e-11
//!   relative (the gradient enters the residual, through the constraint forces Phi_q^T lambda,
//!   so its error moves the solution: central rather than forward differences);
//! - Hessian: forward differences of the user gradient, c = sqrt(eps) (n gradient calls, error
//!   ~ 1e-8); without a user gradient, second differences of Phi,
//!   `H_ij ~ (Phi(x + h_i e_i + h_j e_j) - Phi(x + h_i e_i) - Phi(x + h_j e_j) + Phi(x)) / (h_i h_j)`
//!   with c = eps^(1/3): n + n(n + 1)/2 calls, error ~ 1e-5 (the Hessian only enters Newton's
//!   matrix, so it sets the rate, not the converged point);
//! - Phi_t: central difference in t, `(Phi(q, t + h) - Phi(q, t - h)) / 2h`,
//!   h = eps^(1/3) max(|t|, 1 s): 2 calls, error ~ 1e-10;
//! - gamma: the second derivative of Phi along the path (q + s v, t + s), on which q'' = 0, so
//!   that Phi'' = gamma: `(Phi(q + h v, t + h) - 2 Phi(q, t) + Phi(q - h v, t - h)) / h^2`,
//!   h = eps^(1/4) max(|t|, 1 s): 2 calls (plus Phi(q, t), usually cached), error ~ 1e-8.
//!
//! The scale s (s Phi is a length) is given by the user, as for the built-in kinds.

use super::{Gradient, Hessian};
use crate::math::Vec3;
use crate::user::{
    central_steps, forward_steps, CallCount, GroupElements, GroupState, UserFailure,
};
use std::sync::{Arc, Mutex, MutexGuard};

/// The user functions of a constraint group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConstraintCall {
    /// Phi(q, t).
    Phi = 0,
    /// dPhi/dq.
    Gradient = 1,
    /// d2Phi/dq2.
    Hessian = 2,
    /// dPhi/dt.
    PhiT = 3,
    /// gamma(q, v, t) = Phi'' - Phi_q a.
    Gamma = 4,
}

impl ConstraintCall {
    /// Every function, in counter order.
    pub const ALL: [ConstraintCall; 5] = [
        ConstraintCall::Phi,
        ConstraintCall::Gradient,
        ConstraintCall::Hessian,
        ConstraintCall::PhiT,
        ConstraintCall::Gamma,
    ];

    /// The function's name in messages and counters.
    pub fn name(self) -> &'static str {
        ["phi", "gradient", "hessian", "phi_t", "gamma"][self as usize]
    }

    /// Outputs per element for `n` = 3a coordinates per element.
    pub fn width(self, n: usize) -> usize {
        match self {
            ConstraintCall::Gradient => n,
            ConstraintCall::Hessian => n * n,
            _ => 1,
        }
    }
}

/// The user functions of a constraint group (no Python in the core: the bindings implement it).
pub trait ConstraintGroup: Send + Sync {
    /// True when the function is supplied (Phi always is).
    fn supplies(&self, call: ConstraintCall) -> bool;

    /// Writes the function's output for every element (flat, row-major, shapes in the module
    /// docs) at time `t` for positions `q`, k x a x 3; `v` (same shape) is given for
    /// [`ConstraintCall::Gamma`] only, empty otherwise.
    fn evaluate(
        &self,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
        v: &[f64],
        out: &mut [f64],
    ) -> Result<(), UserFailure>;
}

/// A group of user constraint elements with its batched-evaluation cache and call counters.
pub struct UserConstraints {
    /// The group's name (used in messages).
    pub name: String,
    /// Each element's particles (any number per element, the same for all).
    pub elements: GroupElements,
    /// s such that s Phi is a length.
    pub scale: f64,
    functions: Box<dyn ConstraintGroup>,
    state: Mutex<GroupState<5>>,
}

impl std::fmt::Debug for UserConstraints {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "UserConstraints({:?}, {} elements of arity {})",
            self.name,
            self.elements.len(),
            self.elements.arity()
        )
    }
}

impl UserConstraints {
    /// A group over `elements` (the caller has checked the indices, arity and scale).
    pub fn new(
        name: String,
        elements: GroupElements,
        scale: f64,
        functions: Box<dyn ConstraintGroup>,
    ) -> UserConstraints {
        UserConstraints {
            name,
            elements,
            scale,
            functions,
            state: Mutex::new(GroupState::new()),
        }
    }

    fn lock(&self) -> MutexGuard<'_, GroupState<5>> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Calls of each user function since the last reset (the start of the last run), in the
    /// order of [`ConstraintCall::ALL`]. Finite-difference evaluations count as calls of the
    /// function they call (Phi or the gradient).
    pub fn counts(&self) -> [CallCount; 5] {
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

    fn width(&self) -> usize {
        3 * self.elements.arity()
    }

    /// Evaluates `call` over the group at the inputs `q` (and `v` for gamma), k x a x 3, outside
    /// a run, with a fresh cache and without counting; by finite differences when
    /// `finite_differences` is set (or the function is not supplied). For checking user
    /// derivatives against the finite differences.
    pub fn evaluate(
        &self,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
        v: &[f64],
        finite_differences: bool,
    ) -> crate::Result<Vec<f64>> {
        let mut st = GroupState::new();
        let v = if call == ConstraintCall::Gamma {
            v
        } else {
            &[]
        };
        self.compute(&mut st, call, t, q, v, finite_differences)
            .ok_or_else(|| {
                let (name, t, f) = st.failure.clone().expect("a failure");
                f.into_error(&self.name, name, t)
            })
    }

    /// One call of a user function over the group.
    fn user(
        &self,
        st: &mut GroupState<5>,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
        v: &[f64],
    ) -> Option<Vec<f64>> {
        let w = call.width(self.width());
        let mut out = vec![0.0; self.elements.len() * w];
        let ok = st.call(call as usize, call.name(), t, || {
            self.functions.evaluate(call, t, q, v, &mut out)
        });
        (ok && st.finite(call.name(), t, &out, w)).then_some(out)
    }

    fn phi(&self, st: &mut GroupState<5>, t: f64, q: &[f64]) -> Option<Vec<f64>> {
        self.user(st, ConstraintCall::Phi, t, q, &[])
    }

    /// `call`'s output at exactly (q, t): cached, or by a user call (then cached).
    fn cached(
        &self,
        st: &mut GroupState<5>,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
    ) -> Option<Vec<f64>> {
        if let Some(s) = st.memos[call as usize].find_all(q, &[], t) {
            return Some(s.out.clone());
        }
        let out = self.user(st, call, t, q, &[])?;
        st.memos[call as usize].store(t, q.to_vec(), Vec::new(), out.clone());
        Some(out)
    }

    /// `call` over the group: the user function if supplied, else finite differences.
    fn compute(
        &self,
        st: &mut GroupState<5>,
        call: ConstraintCall,
        t: f64,
        q: &[f64],
        v: &[f64],
        finite_differences: bool,
    ) -> Option<Vec<f64>> {
        let supplied = self.functions.supplies(call) && !finite_differences;
        if call == ConstraintCall::Phi || supplied {
            return self.user(st, call, t, q, v);
        }
        let n = self.width();
        let k = self.elements.len();
        let time_step = |power: f64| {
            let h = f64::EPSILON.powf(power) * t.abs().max(1.0);
            (t + h) - t
        };
        match call {
            ConstraintCall::Phi => unreachable!("Phi is always supplied"),
            ConstraintCall::Gradient => {
                let mut out = vec![0.0; k * n];
                for j in 0..n {
                    let (qp, qm, width) = central_steps(q, n, j);
                    let plus = self.phi(st, t, &qp)?;
                    let minus = self.phi(st, t, &qm)?;
                    for e in 0..k {
                        out[e * n + j] = (plus[e] - minus[e]) / width[e];
                    }
                }
                Some(out)
            }
            ConstraintCall::Hessian if self.functions.supplies(ConstraintCall::Gradient) => {
                let base = self.cached(st, ConstraintCall::Gradient, t, q)?;
                let mut out = vec![0.0; k * n * n];
                for j in 0..n {
                    let (qp, h) = forward_steps(q, n, j, 0.5);
                    let g = self.user(st, ConstraintCall::Gradient, t, &qp, &[])?;
                    for e in 0..k {
                        for i in 0..n {
                            out[e * n * n + i * n + j] = (g[e * n + i] - base[e * n + i]) / h[e];
                        }
                    }
                }
                Some(out)
            }
            ConstraintCall::Hessian => {
                let base = self.cached(st, ConstraintCall::Phi, t, q)?;
                let steps: Vec<(Vec<f64>, Vec<f64>)> =
                    (0..n).map(|i| forward_steps(q, n, i, 1.0 / 3.0)).collect();
                let mut single = Vec::with_capacity(n);
                for (qi, _) in &steps {
                    single.push(self.phi(st, t, qi)?);
                }
                let mut out = vec![0.0; k * n * n];
                for i in 0..n {
                    for j in i..n {
                        let mut x = steps[i].0.clone();
                        for e in 0..k {
                            x[e * n + j] += steps[j].1[e];
                        }
                        let p = self.phi(st, t, &x)?;
                        for e in 0..k {
                            let hij = steps[i].1[e] * steps[j].1[e];
                            let d = (p[e] - single[i][e] - single[j][e] + base[e]) / hij;
                            out[e * n * n + i * n + j] = d;
                            out[e * n * n + j * n + i] = d;
                        }
                    }
                }
                Some(out)
            }
            ConstraintCall::PhiT => {
                let h = time_step(1.0 / 3.0);
                let plus = self.phi(st, t + h, q)?;
                let minus = self.phi(st, t - h, q)?;
                Some((0..k).map(|e| (plus[e] - minus[e]) / (2.0 * h)).collect())
            }
            ConstraintCall::Gamma => {
                let h = time_step(0.25);
                let base = self.cached(st, ConstraintCall::Phi, t, q)?;
                let along =
                    |s: f64| -> Vec<f64> { q.iter().zip(v).map(|(x, u)| x + s * u).collect() };
                let plus = self.phi(st, t + h, &along(h))?;
                let minus = self.phi(st, t - h, &along(-h))?;
                Some(
                    (0..k)
                        .map(|e| (plus[e] - 2.0 * base[e] + minus[e]) / (h * h))
                        .collect(),
                )
            }
        }
    }

    /// Element `e`'s output of `call` at (q, v, t), read with `read`.
    fn value<R>(
        &self,
        call: ConstraintCall,
        e: usize,
        q: &[Vec3],
        v: Option<&[Vec3]>,
        t: f64,
        read: impl FnOnce(&[f64]) -> R,
    ) -> R {
        self.lock().lookup(
            call as usize,
            call.width(self.width()),
            &self.elements,
            e,
            q,
            v,
            t,
            |st, qg, vg| self.compute(st, call, t, qg, vg, false),
            read,
        )
    }
}

/// One element (one equation) of a user constraint group.
#[derive(Clone)]
pub struct UserConstraint {
    /// The group.
    pub group: Arc<UserConstraints>,
    /// The element's position in the group.
    pub element: usize,
}

impl UserConstraint {
    /// Element `element` of `group`.
    pub fn new(group: Arc<UserConstraints>, element: usize) -> UserConstraint {
        UserConstraint { group, element }
    }

    pub(crate) fn particles(&self) -> &[usize] {
        self.group.elements.get(self.element)
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        self.group
            .value(ConstraintCall::Phi, self.element, q, None, t, |x| x[0])
    }

    pub(crate) fn gradient(&self, q: &[Vec3], t: f64) -> Gradient {
        self.group
            .value(ConstraintCall::Gradient, self.element, q, None, t, |x| {
                x.chunks_exact(3).map(|g| [g[0], g[1], g[2]]).collect()
            })
    }

    pub(crate) fn add_hessian(&self, q: &[Vec3], t: f64, w: f64, out: &mut Hessian) {
        let arity = self.group.elements.arity();
        let n = 3 * arity;
        self.group
            .value(ConstraintCall::Hessian, self.element, q, None, t, |x| {
                for p in 0..arity {
                    for r in 0..arity {
                        for l in 0..3 {
                            for m in 0..3 {
                                out[p][r][l][m] += w * x[(3 * p + l) * n + 3 * r + m];
                            }
                        }
                    }
                }
            })
    }

    pub(crate) fn phi_t(&self, q: &[Vec3], t: f64) -> f64 {
        self.group
            .value(ConstraintCall::PhiT, self.element, q, None, t, |x| x[0])
    }

    pub(crate) fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        self.group
            .value(ConstraintCall::Gamma, self.element, q, Some(v), t, |x| x[0])
    }

    pub(crate) fn scale(&self) -> f64 {
        self.group.scale
    }
}

impl PartialEq for UserConstraint {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.group, &other.group) && self.element == other.element
    }
}

impl std::fmt::Debug for UserConstraint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "UserConstraint({:?} element {}, particles {:?})",
            self.group.name,
            self.element,
            self.particles()
        )
    }
}
