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
//! **Where A, A', A'' come from.** Each accepted step leaves one raw acceleration sample at a
//! known time tau: the trapezoidal rules the mean acceleration (v_{n+1} - v_n)/h = a(q_a, v_a, t_a),
//! which is A(t_n + alpha h) + O(h^2); generalised-alpha the true acceleration qdd_{n+1} at
//! t_n + h; the run starts with the consistent accelerations at t_0.
//!
//! The raw samples are smoothed before they are differenced: each is averaged with the previous
//! one, weighted by their steps, S = (h_n a_n + h_{n-1} a_{n-1})/(h_n + h_{n-1}) at the likewise
//! weighted time (still A + O(h^2) there). The reason is the undamped parasitic solution of the
//! index-3 trapezoidal rule (and of generalised-alpha at rho_inf = 1): velocities off by
//! (-1)^n eps, which every change of step size excites and nothing damps, put (-1)^n 2 eps/h into
//! the mean accelerations. Differenced twice it would give an h^3 A'' term of about eps whatever
//! the step, and the controller would shrink the step without end. The average of two
//! consecutive mean accelerations is (v_{n+1} - v_{n-1})/(h_n + h_{n-1}), from which the
//! oscillation cancels exactly for any steps. (The oscillation does not grow; the estimate
//! measures what each step adds.)
//!
//! The samples are also cut to their part tangent to the constraints before they enter the
//! history (the run loop does it with the step's factorised Newton matrix, one extra solve): the
//! part normal to the constraints is what the multipliers impose, and in an index-3 solve it
//! depends on the step itself (backward Euler's velocities are chords, off the velocity
//! constraints by O(h); the trapezoidal multipliers ring), so it jumps whenever the step size
//! changes and would make the estimate, and the step, collapse. The positions' local error normal
//! to the constraints is nil anyway (they hold at every step end); the tangential part follows
//! the motion along the constraints, which is what errors propagate in.
//!
//! With the new smoothed sample and the last two, divided differences give A'' (from three
//! samples; 0 while only two exist) and A' at the midpoint tau_bar of the two newest, and Taylor
//! steps move A' and A to t_n:
//!
//! ```text
//! d1 = (S_new - S_1)/(tau_new - tau_1),    d2 = 2 (d1 - (S_1 - S_2)/(tau_1 - tau_2))/(tau_new - tau_2)
//! A'(t_n) = d1 - (tau_bar - t_n) d2,         A(t_n) = S_new - s A'(t_n) - s^2/2 d2,  s = tau_new - t_n
//! ```
//!
//! Limits: a law whose third derivative jumps (the end of a C2 ramp) shows up in the samples only
//! as the step that crosses it is taken, and a long step across it can be accepted with too
//! small an estimate; h_max bounds that. The velocity part uses the linear-force h^3 constant.

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

/// Where, after t_n, a step of size `h` of `scheme` leaves its acceleration sample: t_n + alpha h
/// for the trapezoidal rules (the mean acceleration), t_n + h for generalised-alpha
/// ([`super::TimeRule::sample_offset`]).
pub fn sample_offset(scheme: &Scheme, h: f64) -> f64 {
    scheme.sample_offset(h)
}

/// The acceleration samples of the accepted steps, smoothed (module documentation).
#[derive(Debug, Clone)]
pub struct AccelerationHistory {
    /// The last accepted raw sample: time, values and weight (its step; 0 for the start).
    pub(crate) raw: (f64, Vec<Vec3>, f64),
    /// The last two smoothed samples (time, values), newest first.
    pub(crate) newest: (f64, Vec<Vec3>),
    pub(crate) older: Option<(f64, Vec<Vec3>)>,
}

impl AccelerationHistory {
    /// A history holding one sample: the accelerations `a` at time `tau` (the consistent
    /// accelerations of the initial state, which need no smoothing).
    pub fn new(tau: f64, a: &[Vec3]) -> AccelerationHistory {
        AccelerationHistory {
            raw: (tau, a.to_vec(), 0.0),
            newest: (tau, a.to_vec()),
            older: None,
        }
    }

    /// The smoothed sample's time and the weights of the new raw sample (of a step `h`) and of
    /// the last one.
    fn smoothing(&self, tau: f64, h: f64) -> (f64, f64, f64) {
        let w_raw = self.raw.2;
        let (w_new, w_old) = (h / (h + w_raw), w_raw / (h + w_raw));
        (w_new * tau + w_old * self.raw.0, w_new, w_old)
    }

    /// Adds the raw sample `a` at `tau` of an accepted step of size `h` (after the newest).
    pub fn push(&mut self, tau: f64, a: &[Vec3], h: f64) {
        let (tau_s, w_new, w_old) = self.smoothing(tau, h);
        let mut buffer = match self.older.take() {
            Some((_, buffer)) => buffer,
            None => vec![[0.0; 3]; a.len()],
        };
        for (b, (a, r)) in buffer.iter_mut().zip(a.iter().zip(&self.raw.1)) {
            for k in 0..3 {
                b[k] = w_new * a[k] + w_old * r[k];
            }
        }
        let previous = std::mem::replace(&mut self.newest, (tau_s, buffer));
        self.older = Some(previous);
        self.raw.0 = tau;
        self.raw.1.copy_from_slice(a);
        self.raw.2 = h;
    }

    /// Writes the estimated local errors of positions and velocities of a step of size `h` from
    /// `t_n` whose raw acceleration sample is `a_new` at `tau_new` (module documentation).
    #[allow(clippy::too_many_arguments)]
    pub fn estimate(
        &self,
        constants: &ErrorConstants,
        t_n: f64,
        h: f64,
        tau_new: f64,
        a_new: &[Vec3],
        e_q: &mut [Vec3],
        e_v: &mut [Vec3],
    ) {
        let (tau_s, w_new, w_old) = self.smoothing(tau_new, h);
        let (tau_1, a_1) = (&self.newest.0, &self.newest.1);
        let span = tau_s - tau_1;
        let tau_bar = 0.5 * (tau_s + tau_1);
        let s = tau_s - t_n;
        let (h2, h3) = (h * h, h * h * h);
        for i in 0..a_new.len() {
            for k in 0..3 {
                let a_s = w_new * a_new[i][k] + w_old * self.raw.1[i][k];
                let d1 = (a_s - a_1[i][k]) / span;
                let d2 = match &self.older {
                    Some((tau_2, a_2)) => {
                        let d1_old = (a_1[i][k] - a_2[i][k]) / (tau_1 - tau_2);
                        2.0 * (d1 - d1_old) / (tau_s - tau_2)
                    }
                    None => 0.0,
                };
                let jerk = d1 - (tau_bar - t_n) * d2;
                let acceleration = a_s - s * jerk - 0.5 * s * s * d2;
                e_q[i][k] = constants.q2 * h2 * acceleration + constants.q3 * h3 * jerk;
                e_v[i][k] = constants.v2 * h2 * jerk + constants.v3 * h3 * d2;
            }
        }
    }
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

    /// One step of size h from the exact state at t_n with an exact history: (true, estimated)
    /// local errors of x and x'.
    fn one_step(scheme: Scheme, t_n: f64, h: f64) -> ([f64; 2], [f64; 2]) {
        let system = oscillator();
        let mut ws = StepWorkspace::new(&system, 48);
        let e = exact(t_n);
        let (q_n, v_n) = (state(e[0]), state(e[1]));
        let newton = NewtonOptions {
            tolerance: 1e-15,
            ..Default::default()
        };
        ws.state.q.copy_from_slice(&q_n);
        ws.state.lambda.fill(0.0);
        // The samples a uniform run of step h would have left, from the exact motion.
        let offset = sample_offset(&scheme, h);
        let tau_1 = t_n - h + offset;
        let mut history =
            AccelerationHistory::new(tau_1 - 3.0 * h, &state(exact(tau_1 - 3.0 * h)[2]));
        for j in (0..3).rev() {
            let tau = tau_1 - j as f64 * h;
            history.push(tau, &state(exact(tau)[2]), h);
        }
        let start = StepStart::new(t_n, &q_n, &v_n, h);
        let a_new = match scheme {
            Scheme::GeneralizedTrapezoidal { alpha } => {
                GeneralizedTrapezoidal { alpha }
                    .step(&system, &mut ws, start, &newton)
                    .unwrap();
                state((ws.state.v[1][0] - v_n[1][0]) / h)
            }
            Scheme::GeneralizedAlpha { rho_inf } => {
                let ga = GeneralizedAlpha { rho_inf };
                let k = ga.coefficients();
                let delta = k.alpha_m - k.alpha_f;
                let kappa = 0.5 * (1.0 - k.alpha_f) - (1.0 - k.alpha_m) * (0.5 + delta);
                // The algorithmic acceleration of the exact motion (module documentation).
                let a = e[2] + delta * h * e[3] + kappa * h * h * e[4];
                let mut alpha_state = RuleState::new(&state(a));
                alpha_state.acceleration = state(e[2]);
                index3_step(ga, &system, &mut ws, start, &mut alpha_state, &newton).unwrap();
                alpha_state.acceleration.clone()
            }
        };
        let exact_end = exact(t_n + h);
        let truth = [
            ws.state.q[1][0] - exact_end[0],
            ws.state.v[1][0] - exact_end[1],
        ];
        let (mut e_q, mut e_v) = (state(0.0), state(0.0));
        history.estimate(
            &ErrorConstants::of(&scheme),
            t_n,
            h,
            t_n + offset,
            &a_new,
            &mut e_q,
            &mut e_v,
        );
        (truth, [e_q[1][0], e_v[1][0]])
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

    /// A history with one sample (the start) gives A' from two samples and no A'' term.
    #[test]
    fn a_single_sample_gives_the_first_difference() {
        let history = AccelerationHistory::new(0.0, &[[1.0, 2.0, 3.0]]);
        let constants = ErrorConstants {
            q2: 0.0,
            q3: 1.0,
            v2: 1.0,
            v3: 1.0,
        };
        let (mut e_q, mut e_v) = ([[0.0; 3]], [[0.0; 3]]);
        // A linear acceleration 1 + 2 t in x: A' = 2 exactly.
        history.estimate(
            &constants,
            0.0,
            0.5,
            0.5,
            &[[2.0, 2.0, 3.0]],
            &mut e_q,
            &mut e_v,
        );
        assert!((e_q[0][0] - 2.0 * 0.125).abs() < 1e-15);
        assert!((e_v[0][0] - 2.0 * 0.25).abs() < 1e-15);
        assert_eq!(e_q[0][1], 0.0);
    }
}
