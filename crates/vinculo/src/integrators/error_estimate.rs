//! The local error of one step, estimated from the accelerations the schemes already compute.
//!
//! The local error of a step is what the step adds to the global error: the scheme's state at
//! t_n + h minus the exact solution through the (exact) state at t_n. It is estimated here for
//! positions and velocities (not for the multipliers) from Taylor expansions of the schemes
//! about t_n, written with the acceleration A(t) = q''(t) of the exact motion and its
//! derivatives A', A'' (all Cartesian, constraint forces included):
//!
//! ```text
//! e_q ~ c_q2 h^2 A + c_q3 h^3 A'        e_v ~ c_v2 h^2 A' + c_v3 h^3 A''
//! ```
//!
//! **Generalised trapezoidal rule** (alpha in [1/2, 1], [`super::GeneralizedTrapezoidal`]). With
//! q_a = (1 - alpha) q_n + alpha q_{n+1}, v_a = (q_{n+1} - q_n)/h, t_a = t_n + alpha h it reads
//! q_{n+1} = q_n + h v_n + alpha h (v_{n+1} - v_n) and v_{n+1} = v_n + h a(q_a, v_a, t_a). To first
//! order q_a - q_n = alpha h v_n and v_a - v_n = alpha h A, so a(q_a, v_a, t_a) = A + alpha h A' +
//! O(h^2) and
//!
//! ```text
//! q_{n+1} = q_n + h v_n + alpha h^2 A + alpha^2 h^3 A' + O(h^4)
//! v_{n+1} = v_n + h A + alpha h^2 A' + alpha^2 h^3 A'' + O(h^4)   (h^3 term: for a linear force)
//! ```
//!
//! Against the exact q_n + h v_n + h^2/2 A + h^3/6 A' (and v likewise):
//! c_q2 = c_v2 = alpha - 1/2, c_q3 = c_v3 = alpha^2 - 1/6. Backward Euler (alpha = 1) is first
//! order: e_q ~ h^2 A / 2, e_v ~ h^2 A' / 2. The trapezoidal rule (alpha = 1/2) is the implicit
//! midpoint rule in (q, v): e_q ~ h^3 A'/12, e_v ~ h^3 A''/12 (for a nonlinear force e_v has
//! further h^3 terms in the force's derivatives; the estimate keeps the linear one).
//!
//! **Generalised-alpha** (Arnold and Brüls, [`super::GeneralizedAlpha`]). With
//! delta = alpha_m - alpha_f, the algorithmic accelerations of a smooth motion follow
//! a_n = A(t_n) + delta h A' + kappa h^2 A'' + O(h^3): inserting this in
//! (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) A_{n+1} + alpha_f A_n and matching powers of h
//! gives delta (order h) and kappa = (1 - alpha_f)/2 - (1 - alpha_m)(1/2 + delta) (order h^2). Then
//!
//! ```text
//! q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1})
//!         = q_n + h v_n + h^2/2 A + (beta + delta/2) h^3 A' + O(h^4)
//! v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1})
//!         = v_n + h A + h^2/2 A' + (kappa + gamma (1/2 + delta)) h^3 A'' + O(h^4)
//! ```
//!
//! (gamma = 1/2 - delta makes the h^2 term of v exact), so c_q2 = c_v2 = 0,
//! c_q3 = beta + delta/2 - 1/6, c_v3 = kappa + gamma (1/2 + delta) - 1/6. For rho_inf = 1
//! (alpha_m = alpha_f = gamma = 1/2, beta = 1/4) both are 1/12, as for the trapezoidal rule.
//!
//! For Newmark schemes this is the estimate of Zienkiewicz and Xie, e_q = (beta - 1/6) h^2
//! (a_{n+1} - a_n): here A, A' and A'' come from the history of accelerations instead.
//!
//! **Where A, A', A'' come from: the step-end positions.** The positions of a run of a scheme
//! of order p lie, to O(h^p), on a smooth curve (the solution of the scheme's modified
//! equation), whose derivatives are the exact motion's plus O(h^p). The estimate takes them
//! from the polynomial through the positions at the last five step ends, the new one included
//! (a Newton divided-difference table over their times, any step sizes): its second, third and
//! fourth derivatives at t_n are A, A' and A'' to O(h). Positions are the one state every
//! scheme and formulation computes directly and holds on the constraints at every step end:
//! they carry neither the undamped parasitic solution of the index-3 trapezoidal rule (velocities
//! off the velocity constraints by (-1)^n eps, which cancels from q_{n+1} - q_n = h (v_n +
//! v_{n+1})/2) nor the ringing multipliers, and their round-off eps |q| enters A' h^3 as about
//! 8 eps |q| (and A'' h^3 as 16 eps |q| / h: the velocities' own round-off in the index-3
//! formulation, where they are differences of positions; [`crate::step_control`] gives the
//! velocities a tolerance floor of that size). Accelerations (what an estimate would otherwise
//! difference) would carry both, amplified by 1/h^2.
//!
//! The estimated errors are then cut to their part tangent to the constraints (the run loop
//! does it with the step's factorised Newton matrix, `adaptive.rs`): the local error of the
//! positions normal to the constraints is nil (they hold at every step end), and the normal
//! part of the velocities' error is the drift off the velocity constraints, which the index-3
//! formulation leaves to the scheme's accuracy by design.
//!
//! The run starts with a history of virtual positions before t_0, on the parabola
//! q_0 + s v_0 + s^2/2 a_0 of the consistent start (a jerk of zero): the first steps see only
//! part of the jerk, which the run's small first step ([`crate::step_control`]) covers.
//!
//! Limits: a law whose third derivative jumps (the end of a C2 ramp) shows up in the positions
//! only as the step that crosses it is taken, and a long step across it can be accepted with
//! too small an estimate; h_max bounds that. The velocity part uses the linear-force h^3
//! constant.

use super::Scheme;
use crate::math::Vec3;

/// The constants c_q2, c_q3, c_v2, c_v3 of a scheme (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorConstants {
    /// Coefficient of h^2 A in the position error.
    pub q2: f64,
    /// Coefficient of h^3 A' in the position error.
    pub q3: f64,
    /// Coefficient of h^2 A' in the velocity error.
    pub v2: f64,
    /// Coefficient of h^3 A'' in the velocity error.
    pub v3: f64,
}

impl ErrorConstants {
    /// The constants of `scheme` ([`super::TimeRule::error_constants`]).
    pub fn of(scheme: &Scheme) -> ErrorConstants {
        scheme.error_constants()
    }
}

/// How many past step ends the estimate uses besides the new one.
pub const HISTORY: usize = 3;

/// The positions and velocities at the last [`HISTORY`] accepted step ends, newest first
/// (module documentation).
#[derive(Debug, Clone)]
pub struct StateHistory {
    /// (time, positions, velocities) of the step ends, newest first.
    pub(crate) nodes: Vec<(f64, Vec<Vec3>, Vec<Vec3>)>,
}

impl StateHistory {
    /// The history at the start of a run at `t0` from (q, v) with the consistent accelerations
    /// `a`: the step end t0 and virtual ones at t0 - k `h` on the parabola through the start
    /// (module documentation).
    pub fn new(t0: f64, h: f64, q: &[Vec3], v: &[Vec3], a: &[Vec3]) -> StateHistory {
        let nodes = (0..HISTORY)
            .map(|k| {
                let s = -(k as f64) * h;
                let mut p = q.to_vec();
                let mut u = v.to_vec();
                for i in 0..q.len() {
                    for c in 0..3 {
                        p[i][c] += s * v[i][c] + 0.5 * s * s * a[i][c];
                        u[i][c] += s * a[i][c];
                    }
                }
                (t0 + s, p, u)
            })
            .collect();
        StateHistory { nodes }
    }

    /// Adds the state (`q`, `v`) of the accepted step end at `t` (dropping the oldest).
    pub fn push(&mut self, t: f64, q: &[Vec3], v: &[Vec3]) {
        let mut oldest = self.nodes.pop().expect("a full history");
        oldest.0 = t;
        oldest.1.copy_from_slice(q);
        oldest.2.copy_from_slice(v);
        self.nodes.insert(0, oldest);
    }

    /// Writes the estimated local errors of positions and velocities of the step of size `h`
    /// from `t_n` (the newest step end of the history) to the state (`q_new`, `v_new`) (module
    /// documentation).
    pub fn estimate(
        &self,
        constants: &ErrorConstants,
        (t_n, h): (f64, f64),
        (q_new, v_new): (&[Vec3], &[Vec3]),
        e_q: &mut [Vec3],
        e_v: &mut [Vec3],
    ) {
        // Nodes x_0 = t_n + h (the new end), x_1 = t_n, ... (newest first).
        let mut x = [0.0; HISTORY + 1];
        x[0] = t_n + h;
        for (j, node) in self.nodes.iter().enumerate() {
            x[j + 1] = node.0;
        }
        // Derivatives 1 to 3 at t_n of the Newton basis w_m(t) = prod_{j<m} (t - x_j).
        let basis = newton_basis_derivatives(&x, t_n);
        let derivatives = |new: f64, past: &dyn Fn(usize) -> f64| {
            let mut table = [0.0; HISTORY + 1];
            table[0] = new;
            for (j, value) in table.iter_mut().enumerate().skip(1) {
                *value = past(j - 1);
            }
            // In-place divided differences: table[m] = f[x_0, ..., x_m].
            for level in 1..=HISTORY {
                for m in (level..=HISTORY).rev() {
                    table[m] = (table[m] - table[m - 1]) / (x[m] - x[m - level]);
                }
            }
            let mut out = [0.0; 3];
            for (d, value) in out.iter_mut().enumerate() {
                *value = (0..=HISTORY).map(|m| table[m] * basis[m][d]).sum();
            }
            out
        };
        let (h2, h3) = (h * h, h * h * h);
        for i in 0..q_new.len() {
            for k in 0..3 {
                let [_, acceleration, jerk] = derivatives(q_new[i][k], &|j| self.nodes[j].1[i][k]);
                e_q[i][k] = constants.q2 * h2 * acceleration + constants.q3 * h3 * jerk;
                let [_, jerk_v, snap] = derivatives(v_new[i][k], &|j| self.nodes[j].2[i][k]);
                e_v[i][k] = constants.v2 * h2 * jerk_v + constants.v3 * h3 * snap;
            }
        }
    }
}

/// The first, second and third derivatives at `t` of the Newton basis polynomials
/// w_m(t) = prod_{j<m} (t - x_j), m = 0..=HISTORY (Leibniz's rule on each new linear factor).
fn newton_basis_derivatives(x: &[f64; HISTORY + 1], t: f64) -> [[f64; 3]; HISTORY + 1] {
    // Value and derivatives 0..=3 of w_m at t.
    let mut w = [1.0, 0.0, 0.0, 0.0];
    let mut out = [[0.0; 3]; HISTORY + 1];
    for (m, row) in out.iter_mut().enumerate() {
        *row = [w[1], w[2], w[3]];
        let g = t - x[m];
        for d in (0..4).rev() {
            w[d] = w[d] * g + if d > 0 { d as f64 * w[d - 1] } else { 0.0 };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::{
        index3_step, GeneralizedAlpha, GeneralizedTrapezoidal, NewtonOptions, RuleState, StepStart,
        StepWorkspace,
    };
    use crate::laws::VectorLaw;
    use crate::model::System;

    // A linear oscillator: a 1 kg particle on a spring (k = 4 N/m, rest length 1 m) to a fixed
    // anchor, kept on the plane z = 0 by a constraint, no gravity. Exact motion (closed form):
    // x(t) = 1 + X cos(w t), w = 2 rad/s.
    const X: f64 = 0.3;
    const W: f64 = 2.0;

    fn oscillator() -> System {
        let mut s = System::new([0.0; 3]);
        let anchor = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let p = s
            .add_particle(1.0, [1.0 + X, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_spring_damper(anchor, p, W * W, 0.0, Some(1.0))
            .unwrap();
        s.add_plane(
            p,
            VectorLaw::constant([0.0, 0.0, 1.0]),
            VectorLaw::constant([0.0; 3]),
        )
        .unwrap();
        s
    }

    /// The exact x, x', x'', x''', x'''' at t.
    fn exact(t: f64) -> [f64; 5] {
        let (c, s) = ((W * t).cos(), (W * t).sin());
        [
            1.0 + X * c,
            -X * W * s,
            -X * W * W * c,
            X * W.powi(3) * s,
            X * W.powi(4) * c,
        ]
    }

    fn state(x: f64) -> Vec<Vec3> {
        vec![[0.0; 3], [x, 0.0, 0.0]]
    }

    /// The exact motion at t_n + s through the state (x, x') at t_n (closed form): x and x'.
    fn flow(x: f64, v: f64, s: f64) -> [f64; 2] {
        let (c, sn) = ((W * s).cos(), (W * s).sin());
        [
            1.0 + (x - 1.0) * c + v / W * sn,
            -(x - 1.0) * W * sn + v * c,
        ]
    }

    /// A uniform run of `scheme` with steps h from the exact state at t_n - 4 h to t_n + h, its
    /// history fed with the step ends as in a run: (true, estimated) local errors of x and x' of
    /// the last step (true: against the exact motion through the run's state at t_n).
    fn one_step(scheme: Scheme, t_n: f64, h: f64) -> ([f64; 2], [f64; 2]) {
        let system = oscillator();
        let mut ws = StepWorkspace::new(&system, 48);
        let t_0 = t_n - HISTORY as f64 * h;
        let e = exact(t_0);
        let (mut q, mut v) = (state(e[0]), state(e[1]));
        let newton = NewtonOptions {
            tolerance: 1e-15,
            ..Default::default()
        };
        let mut history = StateHistory::new(t_0, h, &q, &v, &state(e[2]));
        // Generalised-alpha's algorithmic acceleration of the exact motion (module
        // documentation).
        let mut alpha_state = match scheme {
            Scheme::GeneralizedAlpha { rho_inf } => {
                let k = GeneralizedAlpha { rho_inf }.coefficients();
                let delta = k.alpha_m - k.alpha_f;
                let kappa = 0.5 * (1.0 - k.alpha_f) - (1.0 - k.alpha_m) * (0.5 + delta);
                let mut rule =
                    RuleState::new(&state(e[2] + delta * h * e[3] + kappa * h * h * e[4]));
                rule.acceleration = state(e[2]);
                rule
            }
            _ => RuleState::new(&state(e[2])),
        };
        let (mut e_q, mut e_v) = (state(0.0), state(0.0));
        for n in 0..=HISTORY {
            let t = t_0 + n as f64 * h;
            ws.state.q.copy_from_slice(&q);
            ws.state.lambda.fill(0.0);
            let start = StepStart::new(t, &q, &v, h);
            match scheme {
                Scheme::GeneralizedTrapezoidal { alpha } => {
                    GeneralizedTrapezoidal { alpha }
                        .step(&system, &mut ws, start, &newton)
                        .unwrap();
                }
                Scheme::GeneralizedAlpha { rho_inf } => {
                    let ga = GeneralizedAlpha { rho_inf };
                    index3_step(ga, &system, &mut ws, start, &mut alpha_state, &newton).unwrap();
                }
            }
            if n == HISTORY {
                let constants = ErrorConstants::of(&scheme);
                history.estimate(
                    &constants,
                    (t, h),
                    (&ws.state.q, &ws.state.v),
                    &mut e_q,
                    &mut e_v,
                );
                let exact_end = flow(q[1][0], v[1][0], h);
                let truth = [
                    ws.state.q[1][0] - exact_end[0],
                    ws.state.v[1][0] - exact_end[1],
                ];
                return (truth, [e_q[1][0], e_v[1][0]]);
            }
            q.copy_from_slice(&ws.state.q);
            v.copy_from_slice(&ws.state.v);
            history.push(t + h, &q, &v);
        }
        unreachable!()
    }

    /// The estimate of one step from the exact state matches the true local error of positions
    /// and velocities (the exact one-step error against the closed-form motion) within a factor
    /// 0.5-2 at every step size, and within 15 % at the smallest, for every scheme. Measured at
    /// h = 0.005: ratios 0.98-1.03, except the trapezoidal rule's velocities, 1.13: its mean
    /// acceleration a(q_a) samples the motion at the chord's midpoint, off the exact one by
    /// h^2/8 q'', a bias of h^2/8 A'' that the exact history lacks and that enters A'' whole (in a
    /// run every sample carries it and it cancels from the differences).
    #[test]
    fn estimate_matches_the_true_local_error() {
        let schemes = [
            Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
            Scheme::GeneralizedTrapezoidal { alpha: 0.7 },
            Scheme::GeneralizedTrapezoidal { alpha: 1.0 },
            Scheme::GeneralizedAlpha { rho_inf: 0.0 },
            Scheme::GeneralizedAlpha { rho_inf: 0.5 },
            Scheme::GeneralizedAlpha { rho_inf: 0.9 },
        ];
        for scheme in schemes {
            for (j, h) in [0.04, 0.02, 0.01, 0.005].into_iter().enumerate() {
                // t_n where x' and x''' are far from zero (0.4 rad into the cycle).
                let (truth, estimate) = one_step(scheme, 0.2, h);
                for c in 0..2 {
                    let ratio = estimate[c] / truth[c];
                    let band = if j == 3 { (0.85, 1.15) } else { (0.5, 2.0) };
                    assert!(
                        ratio > band.0 && ratio < band.1,
                        "{scheme:?} h = {h}, {}: estimate {} vs true {} (ratio {ratio})",
                        ["positions", "velocities"][c],
                        estimate[c],
                        truth[c]
                    );
                }
            }
        }
    }

    /// On a cubic motion the divided differences are exact: a history of x(t) = t^3 (and its
    /// velocity 3 t^2... for the velocity table, v(t) = t^3 too) at uneven times gives
    /// A, A' = 6 t, 6 at t_n from positions and A', A'' = 6 t, 6 from v = t^3 (by hand).
    #[test]
    fn derivatives_of_a_cubic_are_exact() {
        let x = |t: f64| [t.powi(3), 0.0, 0.0];
        let mut history = StateHistory::new(-1.0, 0.1, &[x(-1.0)], &[x(-1.0)], &[[0.0; 3]]);
        for t in [-0.4, -0.25, 0.1] {
            history.push(t, &[x(t)], &[x(t)]);
        }
        let (t_n, h) = (0.1, 0.3);
        let new = [x(t_n + h)];
        let (mut e_q, mut e_v) = ([[0.0; 3]], [[0.0; 3]]);
        let only = |q2, q3, v2, v3| ErrorConstants { q2, q3, v2, v3 };
        history.estimate(
            &only(1.0, 0.0, 1.0, 0.0),
            (t_n, h),
            (&new, &new),
            &mut e_q,
            &mut e_v,
        );
        assert!((e_q[0][0] / (h * h) - 6.0 * t_n).abs() < 1e-12);
        assert!((e_v[0][0] / (h * h) - 6.0 * t_n).abs() < 1e-12);
        history.estimate(
            &only(0.0, 1.0, 0.0, 1.0),
            (t_n, h),
            (&new, &new),
            &mut e_q,
            &mut e_v,
        );
        assert!((e_q[0][0] / (h * h * h) - 6.0).abs() < 1e-10);
        assert!((e_v[0][0] / (h * h * h) - 6.0).abs() < 1e-10);
        assert_eq!(e_q[0][1], 0.0);
    }
}
