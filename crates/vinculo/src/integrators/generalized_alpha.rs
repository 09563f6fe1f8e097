//! The generalised-alpha scheme for index-3 constrained systems, in the form of Arnold and Brüls
//! (Multibody System Dynamics 18 (2007) 185-202; `docs/theory/time-rules.md`): its coefficients
//! and state update. The step problems that use them are `step_problem.rs` (index-3) and
//! `stabilized.rs` (GGL).
//!
//! Parameters from the spectral radius at infinite frequency rho_inf in [0, 1] (1: no numerical
//! damping, 0: the high frequencies are annihilated in one step):
//!
//! ```text
//! alpha_m = (2 rho_inf - 1)/(rho_inf + 1),  alpha_f = rho_inf/(rho_inf + 1),
//! gamma = 1/2 + alpha_f - alpha_m,           beta = (gamma + 1/2)^2 / 4
//! ```
//!
//! Besides (q_n, v_n) the scheme carries the true accelerations qdd_n and the algorithmic
//! accelerations a_n (both start at the consistent accelerations of the initial state). A step
//! of size h solves, at t_{n+1}, the equations of motion and the position constraints
//!
//! ```text
//! M qdd_{n+1} = M g + f(q_{n+1}, v_{n+1}, t_{n+1}) + Phi_q(q_{n+1}, t_{n+1})^T lambda_{n+1}
//! Phi(q_{n+1}, t_{n+1}) = 0
//! ```
//!
//! (M here is the inertia, gravity acts on the mass alone; the sign of the multiplier term
//! follows `docs/theory/formulation.md`) together with
//!
//! ```text
//! (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n
//! q_{n+1} = q_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
//! v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
//! ```
//!
//! The last three are linear, so everything is a function of the unknown q = q_{n+1}:
//!
//! ```text
//! a_{n+1}   = (q - q_n - h v_n - h^2 (1/2 - beta) a_n) / (beta h^2)     da/dq   = 1/(beta h^2)
//! v_{n+1}   = v_n + h (1 - gamma) a_n + h gamma a_{n+1}                 dv/dq   = gamma/(beta h)
//! qdd_{n+1} = ((1 - alpha_m) a_{n+1} + alpha_m a_n - alpha_f qdd_n) / (1 - alpha_f)
//!                                                     dqdd/dq = (1 - alpha_m)/((1 - alpha_f) beta h^2) =: c
//! ```
//!
//! and Newton runs on (q, lambda) with the residual
//!
//! ```text
//! R_dyn = M qdd_{n+1} - M g - f(q, v_{n+1}, t_{n+1}) - Phi_q(q, t_{n+1})^T lambda
//! R_con = Phi(q, t_{n+1})
//! ```
//!
//! and the Jacobian
//!
//! ```text
//! dR_dyn/dq      = c M - df/dq - (gamma/(beta h)) df/dv - sum_k lambda_k d2Phi_k/dq2 (q)
//! dR_dyn/dlambda = -Phi_q(q)^T
//! dR_con/dq      = Phi_q(q)
//! ```
//!
//! Scaling as in the trapezoidal rule (`trapezoidal.rs`): dynamics rows are multiplied by
//! sigma = 1/(c m_ref), so that the mass block is M/m_ref, constraint row k by s_k, and
//! multiplier k is solved for in the unit lambda_k sigma / s_k. The scaled matrix has the same
//! pattern `[M/m_ref + O(h^2), -s G^T; s G, 0]` as the trapezoidal rule's, so the tree, dense and
//! sparse solvers serve both.
//!
//! In the GGL form (`docs/theory/ggl.md`), eliminating the algorithmic acceleration
//! a_{n+1} = (v - v_n - h (1 - gamma) a_n)/(gamma h) gives kappa = beta h / gamma,
//! b = q_n + h v_n + h^2 (1/2 - beta) a_n - kappa (v_n + h (1 - gamma) a_n),
//! c_v = (1 - alpha_m)/((1 - alpha_f) gamma h),
//! c = (alpha_m a_n - alpha_f qdd_n - (1 - alpha_m)(v_n + h (1 - gamma) a_n)/(gamma h))/(1 - alpha_f),
//! w = 1 (everything at t_{n+1}).

use super::rule::{
    resolved_rate, GglBase, GglCoefficients, Index3Rule, RuleState, StepPoint, StepStart, TimeRule,
};
use crate::math::Vec3;

/// The scheme, given by its spectral radius at infinite frequency rho_inf in [0, 1], with the
/// coefficients derived from it ([`GeneralizedAlpha::new`]): computed once, since a step asks
/// for them several times (their divisions, twenty a step, took 8 % of a pendulum's step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlpha {
    /// Spectral radius at infinite frequency (1: no numerical damping); private, as the
    /// coefficients derived from it are kept beside it ([`GeneralizedAlpha::rho_inf`]).
    rho_inf: f64,
    /// alpha_m, alpha_f, gamma and beta of rho_inf.
    k: AlphaCoefficients,
    /// The weights of [`Predictors`] that do not depend on the step: c_a, c_m and c_f.
    ratios: [f64; 3],
}

/// The coefficients of the scheme derived from rho_inf.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaCoefficients {
    /// Weight of the old algorithmic acceleration.
    pub alpha_m: f64,
    /// Weight of the old true acceleration.
    pub alpha_f: f64,
    /// Newmark gamma.
    pub gamma: f64,
    /// Newmark beta.
    pub beta: f64,
}

impl RuleState {
    /// Computes the predictors p and w of a step from `start` and a_n.
    fn predict(&mut self, k: &AlphaCoefficients, start: &StepStart) {
        let (h, q_n, v_n) = (start.h, start.q_n, start.v_n);
        let (hh, half) = (h * h, 0.5 - k.beta);
        // Zipped, without an index into each array (a pass that the bounds checks of five
        // indexed arrays kept from vectorising).
        let known = q_n.iter().zip(v_n).zip(&self.algorithmic);
        let predicted = self.predicted_q.iter_mut().zip(self.predicted_v.iter_mut());
        for ((p, w), ((q_n, v_n), a_n)) in predicted.zip(known) {
            for x in 0..3 {
                p[x] = q_n[x] + h * v_n[x] + hh * half * a_n[x];
                w[x] = v_n[x] + h * (1.0 - k.gamma) * a_n[x];
            }
        }
    }
}

/// The step's linear relations with what is known before the step gathered per particle,
///
/// ```text
/// p = q_n + h v_n + h^2 (1/2 - beta) a_n,   w = v_n + h (1 - gamma) a_n
/// a_{n+1} = (q - p) / (beta h^2),           v_{n+1} = w + h gamma a_{n+1}
/// sigma (M qdd_{n+1} - m g) = sigma (M (c_a a_{n+1} + c_m a_n - c_f qdd_n) - m g)
/// ```
///
/// with c_a = (1 - alpha_m)/(1 - alpha_f), c_m = alpha_m/(1 - alpha_f), c_f = alpha_f/(1 - alpha_f),
/// so that an iterate costs a subtraction and a few products per coordinate, no division.
#[derive(Debug, Clone, Copy)]
struct Predictors {
    inv_beta_h2: f64,
    h_gamma: f64,
    c_a: f64,
    c_m: f64,
    c_f: f64,
}

impl Predictors {
    /// The predictors of a step of size h of `rule`: one division.
    fn new(rule: &GeneralizedAlpha, h: f64) -> Predictors {
        let [c_a, c_m, c_f] = rule.ratios;
        Predictors {
            inv_beta_h2: 1.0 / (rule.k.beta * h * h),
            h_gamma: h * rule.k.gamma,
            c_a,
            c_m,
            c_f,
        }
    }

    /// a_{n+1} and v_{n+1} of one particle from its iterate q and predictors p, w.
    #[inline(always)]
    fn kinematics(&self, q: &Vec3, p: &Vec3, w: &Vec3) -> (Vec3, Vec3) {
        let a: Vec3 = std::array::from_fn(|x| (q[x] - p[x]) * self.inv_beta_h2);
        let v: Vec3 = std::array::from_fn(|x| w[x] + self.h_gamma * a[x]);
        (a, v)
    }
}

/// One index-3 step of the scheme: the predictors p and w of q_{n+1} and v_{n+1} (module
/// documentation), the old accelerations, and the step's weights.
#[derive(Debug, Clone, Copy)]
pub struct AlphaStep<'a> {
    p: &'a [Vec3],
    w: &'a [Vec3],
    a_n: &'a [Vec3],
    qdd_n: &'a [Vec3],
    known: Predictors,
    /// d(qdd_{n+1})/dq = (1 - alpha_m)/((1 - alpha_f) beta h^2).
    c: f64,
    /// d(v_{n+1})/dq = gamma/(beta h).
    dv_dq: f64,
}

impl Index3Rule for AlphaStep<'_> {
    /// Everything at t_{n+1}.
    const AT_END: bool = true;

    /// v_{n+1} = w + h gamma a_{n+1}, and the evaluation point is the step's end.
    #[inline(always)]
    fn kinematics(&self, i: usize, q: &Vec3) -> (Vec3, Vec3, Vec3) {
        let v = self.known.kinematics(q, &self.p[i], &self.w[i]).1;
        (v, *q, v)
    }

    /// v_{n+1} of every particle over zipped slices (the evaluation point is the step's end).
    #[inline(always)]
    fn kinematics_all(&self, q: &[Vec3], v: &mut [Vec3], _eval: (&mut [Vec3], &mut [Vec3])) {
        for (v, (q, (p, w))) in v.iter_mut().zip(q.iter().zip(self.p.iter().zip(self.w))) {
            *v = self.known.kinematics(q, p, w).1;
        }
    }

    /// M qdd_{n+1} - m g, qdd_{n+1} from a_{n+1} (module documentation).
    #[inline(always)]
    fn inertia_row(&self, i: usize, q: &Vec3, _: &Vec3, inertia: f64, mass: f64, g: &Vec3) -> Vec3 {
        let known = &self.known;
        let (p, a_n, qdd_n) = (&self.p[i], &self.a_n[i], &self.qdd_n[i]);
        std::array::from_fn(|k| {
            let a = (q[k] - p[k]) * known.inv_beta_h2;
            let inertial = known.c_a * a + known.c_m * a_n[k] - known.c_f * qdd_n[k];
            inertia * inertial - mass * g[k]
        })
    }

    /// sigma c M = M/m_ref: the scaled mass block.
    #[inline(always)]
    fn mass_diagonal(&self, sigma: f64, inertia: f64) -> f64 {
        sigma * self.c * inertia
    }

    fn weights(&self, sigma: f64) -> (f64, f64, f64) {
        (-sigma, -sigma * self.dv_dq, -sigma)
    }
}

impl GeneralizedAlpha {
    /// The scheme of spectral radius `rho_inf`, its coefficients computed.
    pub fn new(rho_inf: f64) -> GeneralizedAlpha {
        let rho = rho_inf;
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        let k = AlphaCoefficients {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        };
        let ratios = [
            (1.0 - alpha_m) / (1.0 - alpha_f),
            alpha_m / (1.0 - alpha_f),
            alpha_f / (1.0 - alpha_f),
        ];
        GeneralizedAlpha { rho_inf, k, ratios }
    }

    /// Spectral radius at infinite frequency (1: no numerical damping).
    pub fn rho_inf(&self) -> f64 {
        self.rho_inf
    }

    /// The coefficients alpha_m, alpha_f, gamma, beta (see the module documentation).
    pub fn coefficients(&self) -> AlphaCoefficients {
        self.k
    }
}

impl TimeRule for GeneralizedAlpha {
    type Step<'a> = AlphaStep<'a>;

    /// 2 for every rho_inf.
    fn order(&self) -> usize {
        2
    }

    fn matrix_key(&self, h: f64) -> [f64; 2] {
        [h, self.rho_inf]
    }

    /// At t_{n+1}, rows scaled by 1/(c m_ref) (module documentation).
    fn point(&self, start: &StepStart, mass_ref: f64) -> StepPoint {
        let (k, h) = (self.k, start.h);
        let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
        StepPoint::new(start, 1.0, 1.0 / (c * mass_ref))
    }

    fn index3<'a>(&self, state: &'a mut RuleState, start: StepStart<'a>) -> AlphaStep<'a> {
        let (k, h) = (self.coefficients(), start.h);
        state.predict(&k, &start);
        let state = &*state;
        let known = Predictors::new(self, h);
        AlphaStep {
            p: &state.predicted_q,
            w: &state.predicted_v,
            a_n: &state.algorithmic,
            qdd_n: &state.acceleration,
            known,
            c: (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h),
            dv_dq: k.gamma / (k.beta * h),
        }
    }

    /// qdd_{n+1} and a_{n+1} from q_{n+1} and the step's predictors.
    fn advance(&self, state: &mut RuleState, h: f64, q: &[Vec3]) {
        let known = Predictors::new(self, h);
        let predicted = state.predicted_q.iter().zip(&state.predicted_v);
        let carried = state
            .acceleration
            .iter_mut()
            .zip(state.algorithmic.iter_mut());
        for ((qdd, a_n), (q, (p, w))) in carried.zip(q.iter().zip(predicted)) {
            let (a, _) = known.kinematics(q, p, w);
            for x in 0..3 {
                qdd[x] = known.c_a * a[x] + known.c_m * a_n[x] - known.c_f * qdd[x];
            }
            *a_n = a;
        }
    }

    /// q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}) in the algorithmic
    /// accelerations, with a_{n+1} = a_n + h `rate`: the true accelerations' rate stands for
    /// the algorithmic ones' (a_n follows qdd at a shift of (alpha_m - alpha_f) h, and the two
    /// rates differ by O(h)), so q_n + h v_n + h^2 a_n / 2 + beta h^3 rate.
    fn predict(
        &self,
        state: &RuleState,
        start: StepStart,
        (_, rate): (&[Vec3], &[Vec3]),
        out: &mut [Vec3],
    ) {
        let (h, beta) = (start.h, self.coefficients().beta);
        let (half, w) = (0.5 * h * h, beta * h * h * h);
        for (o, (((q, v), a), r)) in out.iter_mut().zip(
            start
                .q_n
                .iter()
                .zip(start.v_n)
                .zip(&state.algorithmic)
                .zip(rate),
        ) {
            let r = resolved_rate(h, a, r);
            for k in 0..3 {
                o[k] = q[k] + h * v[k] + half * a[k] + w * r[k];
            }
        }
    }

    fn ggl(&self, state: &RuleState, start: StepStart, base: GglBase) -> GglCoefficients {
        let (k, h) = (self.coefficients(), start.h);
        let kappa = k.beta * h / k.gamma;
        for (i, (q_n, v_n)) in start.q_n.iter().zip(start.v_n).enumerate() {
            for x in 0..3 {
                let (a_n, qdd_n) = (state.algorithmic[i][x], state.acceleration[i][x]);
                let old = v_n[x] + h * (1.0 - k.gamma) * a_n;
                base.b[i][x] = q_n[x] + h * v_n[x] + h * h * (0.5 - k.beta) * a_n - kappa * old;
                base.c[i][x] =
                    (k.alpha_m * a_n - k.alpha_f * qdd_n - (1.0 - k.alpha_m) * old / (k.gamma * h))
                        / (1.0 - k.alpha_f);
            }
        }
        GglCoefficients {
            kappa,
            c_v: (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.gamma * h),
            w: 1.0,
        }
    }

    /// a_{n+1} = (v - v_n - h (1 - gamma) a_n)/(gamma h), then qdd_{n+1}.
    fn advance_ggl(&self, state: &mut RuleState, h: f64, v_n: &[Vec3], v: &[Vec3]) {
        let k = self.coefficients();
        for (i, v) in v.iter().enumerate() {
            for x in 0..3 {
                let a_n = state.algorithmic[i][x];
                let a = (v[x] - v_n[i][x] - h * (1.0 - k.gamma) * a_n) / (k.gamma * h);
                state.acceleration[i][x] = ((1.0 - k.alpha_m) * a + k.alpha_m * a_n
                    - k.alpha_f * state.acceleration[i][x])
                    / (1.0 - k.alpha_f);
                state.algorithmic[i][x] = a;
            }
        }
    }

    /// The true acceleration qdd_{n+1}.
    fn end_acceleration(&self, state: &RuleState, _: StepStart, _: &[Vec3], out: &mut [Vec3]) {
        out.copy_from_slice(&state.acceleration);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coefficients of Arnold and Brüls (2007), eqs. for rho_inf = 1 (the trapezoidal-like
    /// Newmark scheme, gamma = 1/2, beta = 1/4) and rho_inf = 0 (alpha_m = -1, gamma = 3/2,
    /// beta = 1), and second-order accuracy gamma = 1/2 + alpha_f - alpha_m in between.
    #[test]
    fn coefficients_at_the_ends_of_the_range() {
        let one = GeneralizedAlpha::new(1.0).coefficients();
        assert_eq!(
            (one.alpha_m, one.alpha_f, one.gamma, one.beta),
            (0.5, 0.5, 0.5, 0.25)
        );
        let zero = GeneralizedAlpha::new(0.0).coefficients();
        assert_eq!(
            (zero.alpha_m, zero.alpha_f, zero.gamma, zero.beta),
            (-1.0, 0.0, 1.5, 1.0)
        );
    }
}
