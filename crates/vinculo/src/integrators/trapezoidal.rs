//! The generalised trapezoidal rule (paper eq. 24; `docs/theory/time-rules.md`), with backward
//! Euler as its alpha = 1 case: its coefficients and kinematics. The step problems that use them
//! are `step_problem.rs` (index-3) and `stabilized.rs` (GGL).
//!
//! For a step of size h from (t_n, q_n, v_n), with q = q_{n+1} and lambda the unknowns:
//!
//! ```text
//! v_{n+1} = ((q - q_n)/h - (1 - alpha) v_n) / alpha        (kinematics, exact)
//! q_a = (1 - alpha) q_n + alpha q,  v_a = (q - q_n)/h,  t_a = t_n + alpha h
//! R_dyn = M (v_{n+1} - v_n)/h - M g - f(q_a, v_a, t_a) - Phi_q(q_a, t_a)^T lambda
//! R_con = Phi(q, t_{n+1})                                   (constraints hold at the step end)
//! ```
//!
//! The kinematic equation v_a = (q - q_n)/h is linear, so the velocities are eliminated exactly
//! and Newton runs on (q, lambda) (`docs/theory/newton.md`). The Jacobian is
//!
//! ```text
//! dR_dyn/dq      = M/(alpha h^2) - alpha df/dq - (1/h) df/dv - alpha sum_k lambda_k d2Phi_k/dq2 (q_a)
//! dR_dyn/dlambda = -Phi_q(q_a)^T
//! dR_con/dq      = Phi_q(q)
//! ```
//!
//! Scaling (so that entries of size m/h^2 and O(1) do not mix): dynamics rows are multiplied by
//! sigma = alpha h^2 / m_ref, constraint row k by s_k (s_k Phi_k is a length), and multiplier k is
//! solved for in the unit lambda_k sigma / s_k. The scaled matrix is
//! `[M/m_ref + O(h^2), -s G^T; s G, 0]`, and every scaled residual and increment is a length.
//!
//! In the GGL form (`docs/theory/ggl.md`): kappa = alpha h, b = q_n + (1 - alpha) h v_n,
//! c_v = 1/h, c = -v_n/h, w = alpha.

use super::error_estimate::ErrorConstants;
use super::rule::{GglCoefficients, Index3Rule, RuleState, StepPoint, TimeRule};
use crate::math::Vec3;

/// The rule and its parameter alpha in [1/2, 1] (1/2: trapezoidal, 1: backward Euler).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedTrapezoidal {
    /// Weight of the new state in the evaluation point.
    pub alpha: f64,
}

/// One index-3 step of the rule, with the divisions done once per step:
/// v_a = (q - q_n)/h, v_{n+1} = (v_a - (1 - alpha) v_n)/alpha, q_a = (1 - alpha) q_n + alpha q.
#[derive(Debug, Clone, Copy)]
pub struct TrapezoidalStep<'a> {
    q_n: &'a [Vec3],
    v_n: &'a [Vec3],
    h: f64,
    alpha: f64,
    inv_h: f64,
    inv_alpha: f64,
    point: StepPoint,
}

impl Index3Rule for TrapezoidalStep<'_> {
    const AT_END: bool = false;

    fn point(&self) -> StepPoint {
        self.point
    }

    #[inline(always)]
    fn kinematics(&self, i: usize, q: &Vec3) -> (Vec3, Vec3, Vec3) {
        let (q_n, v_n) = (&self.q_n[i], &self.v_n[i]);
        let a = self.alpha;
        let va: Vec3 = std::array::from_fn(|k| (q[k] - q_n[k]) * self.inv_h);
        let v = std::array::from_fn(|k| (va[k] - (1.0 - a) * v_n[k]) * self.inv_alpha);
        let qa = std::array::from_fn(|k| (1.0 - a) * q_n[k] + a * q[k]);
        (v, qa, va)
    }

    #[inline(always)]
    fn inertia_row(
        &self,
        i: usize,
        _q: &Vec3,
        v: &Vec3,
        inertia: f64,
        mass: f64,
        g: &Vec3,
    ) -> Vec3 {
        let v_n = &self.v_n[i];
        let sigma = self.point.sigma;
        std::array::from_fn(|k| sigma * (inertia * ((v[k] - v_n[k]) * self.inv_h) - mass * g[k]))
    }

    #[inline(always)]
    fn mass_diagonal(&self, inertia: f64) -> f64 {
        self.point.sigma * inertia / (self.alpha * self.h * self.h)
    }

    fn weights(&self) -> (f64, f64, f64) {
        let sigma = self.point.sigma;
        (-sigma * self.alpha, -sigma / self.h, -sigma * self.alpha)
    }
}

impl TimeRule for GeneralizedTrapezoidal {
    type Step<'a> = TrapezoidalStep<'a>;

    /// 2 for alpha = 1/2, otherwise 1.
    fn order(&self) -> usize {
        if (self.alpha - 0.5).abs() < 1e-12 {
            2
        } else {
            1
        }
    }

    fn matrix_key(&self, h: f64) -> [f64; 2] {
        [h, self.alpha]
    }

    fn error_constants(&self) -> ErrorConstants {
        let alpha = self.alpha;
        ErrorConstants {
            q2: alpha - 0.5,
            q3: alpha * alpha - 1.0 / 6.0,
            v2: alpha - 0.5,
            v3: alpha * alpha - 1.0 / 6.0,
        }
    }

    /// t_n + alpha h: the mean acceleration of the step.
    fn sample_offset(&self, h: f64) -> f64 {
        self.alpha * h
    }

    fn index3<'a>(
        &self,
        _state: &'a mut RuleState,
        t_n: f64,
        q_n: &'a [Vec3],
        v_n: &'a [Vec3],
        h: f64,
        mass_ref: f64,
    ) -> TrapezoidalStep<'a> {
        TrapezoidalStep {
            q_n,
            v_n,
            h,
            alpha: self.alpha,
            inv_h: 1.0 / h,
            inv_alpha: 1.0 / self.alpha,
            point: StepPoint {
                t_eval: t_n + self.alpha * h,
                t_end: t_n + h,
                sigma: self.alpha * h * h / mass_ref,
            },
        }
    }

    /// Empty: the rule carries no state besides (q, v).
    fn initial_state(&self, _acc: &[Vec3]) -> RuleState {
        RuleState::new(&[])
    }

    fn advance(&self, _state: &mut RuleState, _h: f64, _q: &[Vec3]) {}

    fn ggl(
        &self,
        _state: &RuleState,
        h: f64,
        q_n: &[Vec3],
        v_n: &[Vec3],
        base_q: &mut [Vec3],
        base_a: &mut [Vec3],
    ) -> GglCoefficients {
        let a = self.alpha;
        for i in 0..q_n.len() {
            for x in 0..3 {
                base_q[i][x] = q_n[i][x] + (1.0 - a) * h * v_n[i][x];
                base_a[i][x] = -v_n[i][x] / h;
            }
        }
        GglCoefficients {
            kappa: a * h,
            c_v: 1.0 / h,
            w: a,
        }
    }

    fn advance_ggl(&self, _state: &mut RuleState, _h: f64, _v_n: &[Vec3], _v: &[Vec3]) {}

    /// The step's mean acceleration (v_{n+1} - v_n)/h.
    fn end_acceleration(
        &self,
        _state: &RuleState,
        h: f64,
        v_n: &[Vec3],
        v: &[Vec3],
        out: &mut [Vec3],
    ) {
        for i in 0..out.len() {
            for k in 0..3 {
                out[i][k] = (v[i][k] - v_n[i][k]) / h;
            }
        }
    }
}
