//! The local error of one step, by step doubling (Richardson extrapolation).
//!
//! The local error of a step is what the step adds to the global error: the scheme's state at
//! t_n + h minus the exact solution through the state at t_n. For a one-step scheme of order p it
//! is C h^(p+1) + O(h^(p+2)), with C set by the motion at t_n. The same scheme taken as two steps
//! of h/2 from the same start (the rule's own state included: generalised-alpha's accelerations)
//! makes 2 C (h/2)^(p+1) = 2^-p C h^(p+1), so the difference of the two answers is
//! (1 - 2^-p) C h^(p+1), and
//!
//! ```text
//! e = (y_h - y_{h/2, h/2}) / (1 - 2^-p)        (richardson_factor(p) = 1 / (1 - 2^-p))
//! ```
//!
//! estimates the step's own local error, for positions and velocities alike, with no constant
//! that depends on the rule and nothing carried from earlier steps. The one fact used about a
//! rule is its order ([`super::TimeRule::order`]: 2 for the trapezoidal rule and
//! generalised-alpha, 1 for backward Euler and the generalised trapezoidal rule with
//! alpha != 1/2). The run keeps the two halves' answer y_{h/2, h/2}, the more accurate one (local
//! extrapolation, the usual practice of step doubling): its local error is 2^-p C h^(p+1), a
//! quarter of the estimate for the second-order rules, so the estimate, that of the less
//! accurate answer, is conservative. The cost is two more Newton solves per step
//! (the work-precision table of `python -m vinculo.bench work-precision` counts it in CPU time).
//!
//! An earlier estimate built the rule's Taylor terms (c_q3 h^3 A' and so on) from the history of
//! accelerations of the accepted steps. Differencing accelerations (themselves differences of
//! velocities, which are differences of positions in the index-3 formulation) made its noise
//! grow as 1/h, and per unit step as 1/h^2: at rtol = atol = 1e-8 a pendulum stopped at once
//! with StepSizeTooSmallError. Step doubling differences nothing.
//!
//! What the run loop does with e (`adaptive.rs`): the position error is cut to its part tangent
//! to the constraints (the positions of both answers hold the constraints, so what is left normal
//! to them is Newton's tolerance) and counted per unit step; the velocity error is cut to its
//! part tangent to the constraints at the step's start and counted per step
//! ([`crate::step_control`] says why). In the index-3 formulation the trapezoidal rule's
//! velocities are off the velocity constraints by a drift that alternates in sign from step to
//! step (v_{n+1} = 2 (q_{n+1} - q_n)/h - v_n carries -v_n), so y_h and the two halves differ by
//! twice the start's drift, normal to the constraints at the start: that is what the projection
//! there removes.

/// The factor 1 / (1 - 2^-p) that turns the difference between one step of a rule of order
/// `order` and two half steps into the local error of the one step (module documentation).
pub fn richardson_factor(order: usize) -> f64 {
    1.0 / (1.0 - 0.5f64.powi(order as i32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::{
        index3_step, GeneralizedAlpha, GeneralizedTrapezoidal, NewtonOptions, RuleState, Scheme,
        StepStart, StepWorkspace,
    };
    use crate::laws::VectorLaw;
    use crate::math::Vec3;
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

    /// Steps of `scheme` from (x, x') at t with the rule's state `rule`, `n` of size h / n:
    /// the end (x, x').
    fn steps(
        scheme: Scheme,
        t: f64,
        x: [f64; 2],
        h: f64,
        n: usize,
        rule: &mut RuleState,
    ) -> [f64; 2] {
        let system = oscillator();
        let mut ws = StepWorkspace::new(&system, 48);
        let newton = NewtonOptions {
            tolerance: 1e-15,
            ..Default::default()
        };
        let (mut q, mut v) = (state(x[0]), state(x[1]));
        let dt = h / n as f64;
        for k in 0..n {
            ws.state.q.copy_from_slice(&q);
            ws.state.lambda.fill(0.0);
            let start = StepStart::new(t + k as f64 * dt, &q, &v, dt);
            match scheme {
                Scheme::GeneralizedTrapezoidal { alpha } => {
                    GeneralizedTrapezoidal { alpha }
                        .step(&system, &mut ws, start, &newton)
                        .unwrap();
                }
                Scheme::GeneralizedAlpha { rho_inf } => {
                    let ga = GeneralizedAlpha::new(rho_inf);
                    index3_step(ga, &system, &mut ws, start, rule, &newton).unwrap();
                }
            }
            q.copy_from_slice(&ws.state.q);
            v.copy_from_slice(&ws.state.v);
        }
        [q[1][0], v[1][0]]
    }

    /// One step of size h from the exact state at t_n, and its two halves: (true, estimated)
    /// local errors of x and x' (true: against the closed-form motion).
    fn one_step(scheme: Scheme, t_n: f64, h: f64) -> ([f64; 2], [f64; 2]) {
        let e = exact(t_n);
        // Generalised-alpha starts from the algorithmic acceleration of the exact motion,
        // a_n = A + delta h A' + kappa h^2 A'' (delta = alpha_m - alpha_f, kappa from matching
        // (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) A_{n+1} + alpha_f A_n to order h^2),
        // so that its step is the step of a run on the exact motion.
        let rule = |dt: f64| match scheme {
            Scheme::GeneralizedAlpha { rho_inf } => {
                let k = GeneralizedAlpha::new(rho_inf).coefficients();
                let delta = k.alpha_m - k.alpha_f;
                let kappa = 0.5 * (1.0 - k.alpha_f) - (1.0 - k.alpha_m) * (0.5 + delta);
                let a = e[2] + delta * dt * e[3] + kappa * dt * dt * e[4];
                let mut rule = RuleState::new(&state(a));
                rule.acceleration = state(e[2]);
                rule
            }
            _ => RuleState::new(&state(e[2])),
        };
        let big = steps(scheme, t_n, [e[0], e[1]], h, 1, &mut rule(h));
        let halves = steps(scheme, t_n, [e[0], e[1]], h, 2, &mut rule(0.5 * h));
        let exact_end = exact(t_n + h);
        let factor = richardson_factor(scheme.order());
        (
            [big[0] - exact_end[0], big[1] - exact_end[1]],
            [factor * (big[0] - halves[0]), factor * (big[1] - halves[1])],
        )
    }

    /// The step-doubling estimate of one step from the exact state matches the true local
    /// error of positions and velocities (against the closed-form motion) within 15 % at the
    /// smallest step and a factor 0.6 to 1.6 at every step, for every scheme (the next term of
    /// the error, O(h^(p+2)), is what is left).
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
                    let band = if j == 3 { (0.85, 1.15) } else { (0.6, 1.6) };
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

    /// 1/(1 - 2^-p): 2 for a first-order rule, 4/3 for a second-order one.
    #[test]
    fn richardson_factors() {
        assert_eq!(richardson_factor(1), 2.0);
        assert!((richardson_factor(2) - 4.0 / 3.0).abs() < 1e-15);
    }
}
