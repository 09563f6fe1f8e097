//! The scheme contract: what a time rule is to the rest of the integrator.
//!
//! # Design
//!
//! A time rule (the generalised trapezoidal rule, with backward Euler as its alpha = 1 case; the
//! generalised-alpha scheme) is data: its coefficients, and how it turns the unknown end-of-step
//! positions into velocities and accelerations. It owns no matrix, no buffer and no loop. Each
//! rule is one file implementing [`TimeRule`], registered once as a variant of
//! [`super::Scheme`] (whose `with_rule!` dispatch is the only `match` on the scheme):
//!
//! - every step is given by its [`StepStart`] (t_n, q_n, v_n and the size h), and evaluated at
//!   a [`StepPoint`] (t_e = t_n + w h, the end t_n + h, the scale of the dynamics rows) that
//!   [`StepPoint::new`] builds for the index-3 and the GGL step problems alike;
//! - [`TimeRule::point`] gives an index-3 step's point and scale, and [`TimeRule::index3`]
//!   folds what is known before a step (q_n, v_n, the rule's own state) into a per-step object
//!   implementing [`Index3Rule`]; the one index-3 step problem ([`super::StepProblem`], see
//!   `step_problem.rs`) is generic over it and monomorphised per rule, so the per-particle
//!   kinematics inline into the assembly loops;
//! - [`TimeRule::ggl`] gives the coefficients of the common linear form of the stabilised step
//!   (`stabilized.rs`), the one GGL step problem;
//! - [`TimeRule::advance`] and [`TimeRule::advance_ggl`] update the rule's state after a
//!   converged step, and [`TimeRule::end_acceleration`] gives the acceleration that the run
//!   loop's predictor uses;
//! - order (which the error control's step doubling needs) and the key of the iteration matrix
//!   (for modified Newton) complete the contract.
//!
//! The equations each rule discretises are derived in `docs/theory/time-rules.md` (the index-3
//! form in `docs/theory/formulation.md`, the stabilised form in `docs/theory/ggl.md`); the
//! module documentation of each rule's file repeats the formulas it implements.

use crate::math::Vec3;

/// The state a rule carries from step to step besides (q, v): generalised-alpha's true and
/// algorithmic accelerations (the trapezoidal rules carry none and leave it untouched), and the
/// per-step predictors it folds into its step.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleState {
    /// True accelerations qdd_n.
    pub acceleration: Vec<Vec3>,
    /// Algorithmic accelerations a_n.
    pub algorithmic: Vec<Vec3>,
    /// Per step: the parts of q_{n+1} and v_{n+1} known before the step (generalised-alpha).
    pub(crate) predicted_q: Vec<Vec3>,
    pub(crate) predicted_v: Vec<Vec3>,
}

impl RuleState {
    /// The state at the start of a run: a_0 = qdd_0 = the consistent accelerations.
    pub fn new(accelerations: &[Vec3]) -> RuleState {
        RuleState {
            acceleration: accelerations.to_vec(),
            algorithmic: accelerations.to_vec(),
            predicted_q: vec![[0.0; 3]; accelerations.len()],
            predicted_v: vec![[0.0; 3]; accelerations.len()],
        }
    }

    /// Copies the carried accelerations of `other` (not the per-step predictors), without
    /// allocating: how a run loop restores the state of a rejected step.
    pub fn copy_from(&mut self, other: &RuleState) {
        self.acceleration.copy_from_slice(&other.acceleration);
        self.algorithmic.copy_from_slice(&other.algorithmic);
    }
}

/// Where a step starts and how long it is: (t_n, q_n, v_n) and h, what every step of a rule
/// and of the step problems starts from.
#[derive(Debug, Clone, Copy)]
pub struct StepStart<'a> {
    /// t_n.
    pub t_n: f64,
    /// Positions q_n.
    pub q_n: &'a [Vec3],
    /// Velocities v_n.
    pub v_n: &'a [Vec3],
    /// The step size h.
    pub h: f64,
}

impl<'a> StepStart<'a> {
    /// The step of size `h` from (`t_n`, `q_n`, `v_n`).
    pub fn new(t_n: f64, q_n: &'a [Vec3], v_n: &'a [Vec3], h: f64) -> StepStart<'a> {
        StepStart { t_n, q_n, v_n, h }
    }
}

/// One step of a rule as the index-3 step problem sees it: the kinematics of the unknown q =
/// q_{n+1} and the weights of the scaled residual and Jacobian (`docs/theory/time-rules.md`,
/// scaling in `docs/theory/formulation.md`), for the step's scale sigma ([`StepPoint`]).
///
/// The residual of the step is, per free particle and coordinate,
/// `sigma (inertia_row(..) - f(q_e, v_e, t_e) - Phi_q(q_e, t_e)^T lambda)` (plus, at a line
/// node, the axial added-mass term that the step problem adds for every rule), and
/// `s_k Phi_k(q, t_end)` per constraint; its Jacobian is `mass_diagonal` on the diagonal of the
/// mass block plus `force_dq df/dq + force_dv df/dv + hessian sum_k lambda_k Phi_k,qq` at the
/// evaluation point, `-s G(q_e)^T` and `s G(q, t_end)`.
pub trait Index3Rule: Sync {
    /// True when forces and constraint gradients are evaluated at the step's end (q_e = q,
    /// v_e = v_{n+1}, t_e = t_{n+1}); false: at a point of their own (stored by the step problem
    /// in its evaluation buffers).
    const AT_END: bool;
    /// The largest ratio of the residual's round-off to the tolerance at which Newton stops at
    /// that round-off ([`NewtonProblem::round_off_reach`](super::newton::NewtonProblem::round_off_reach)).
    const ROUND_OFF_REACH: f64 = super::newton::ROUND_OFF_REACH;
    /// True when slack segments ([`crate::model::System::set_slack`]) go slack in this
    /// problem; false: their rows stay the compliant ones (the static equilibrium, which
    /// refuses compressed segments by itself, `statics.rs`).
    const SLACK: bool = true;
    /// (v_{n+1}, q_e, v_e) of particle `i` at the iterate `q` (q_e and v_e unused when
    /// [`Index3Rule::AT_END`]).
    fn kinematics(&self, i: usize, q: &Vec3) -> (Vec3, Vec3, Vec3);
    /// [`Index3Rule::kinematics`] of every particle: v_{n+1} into `v` and, unless
    /// [`Index3Rule::AT_END`], (q_e, v_e) into `eval` (the same numbers, particle by particle;
    /// a rule may override it with a pass the compiler sees whole).
    #[inline(always)]
    fn kinematics_all(&self, q: &[Vec3], v: &mut [Vec3], eval: (&mut [Vec3], &mut [Vec3])) {
        let (qe, ve) = eval;
        for i in 0..q.len() {
            let (vi, qi, wi) = self.kinematics(i, &q[i]);
            v[i] = vi;
            if !Self::AT_END {
                (qe[i], ve[i]) = (qi, wi);
            }
        }
    }
    /// The inertia and gravity terms M qdd_{n+1} - m g of particle `i`, from its iterate `q` and
    /// new velocity `v` (unscaled: the step problem multiplies them by sigma).
    fn inertia_row(&self, i: usize, q: &Vec3, v: &Vec3, inertia: f64, mass: f64, g: &Vec3) -> Vec3;
    /// The scaled mass term sigma (d qdd / dq) M of a particle of inertia `inertia`.
    fn mass_diagonal(&self, sigma: f64, inertia: f64) -> f64;
    /// The weights (of df/dq, of df/dv, of lambda_k Phi_k,qq) in the Jacobian scaled by sigma.
    fn weights(&self, sigma: f64) -> (f64, f64, f64);
}

/// Where an index-3 step is evaluated and how its dynamics rows are scaled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPoint {
    /// Time of the evaluation point t_e.
    pub t_eval: f64,
    /// t_{n+1}.
    pub t_end: f64,
    /// Scale of the dynamics rows.
    pub sigma: f64,
}

impl StepPoint {
    /// The point of a step from `start` at the weight `w` of the new state (t_e = t_n + w h,
    /// w = 1: the step's end), its dynamics rows scaled by `sigma`.
    pub fn new(start: &StepStart, w: f64, sigma: f64) -> StepPoint {
        StepPoint {
            t_eval: start.t_n + w * start.h,
            t_end: start.t_n + start.h,
            sigma,
        }
    }
}

/// The coefficients of a stabilised (GGL) step in its common linear form
/// (`docs/theory/ggl.md`): q = b + kappa v + G^T mu, qdd = c + c_v v, evaluation point
/// (1 - w) x_n + w x_{n+1}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GglCoefficients {
    /// dq/dv in the kinematics.
    pub kappa: f64,
    /// d(qdd)/dv in the dynamics.
    pub c_v: f64,
    /// Weight of the new state in the evaluation point.
    pub w: f64,
}

/// Where a rule writes the parts of a GGL step known before it, per particle: b of
/// q = b + kappa v + G^T mu and c of qdd = c + c_v v ([`GglCoefficients`]).
pub struct GglBase<'a> {
    /// b.
    pub b: &'a mut [Vec3],
    /// c.
    pub c: &'a mut [Vec3],
}

/// The share of a particle's acceleration by which it may change over a step for the predictor
/// to extrapolate it ([`resolved_rate`]).
pub const RESOLVED_CHANGE: f64 = 0.1;

/// The rate `r` of a particle's step acceleration `a` that the predictor extrapolates with over
/// a step `h`: `r` where the acceleration changes by at most [`RESOLVED_CHANGE`] of itself
/// over the step (|h r| <= 0.1 |a|: motion the steps resolve), zero elsewhere (constant
/// acceleration). Where the acceleration turns within a few steps (the tip of a long chain
/// whipping) the extrapolation is no better founded than constant acceleration and can start
/// Newton farther off, towards another root of the step's equations: a 1 m chain of 10,000
/// links released horizontally at 0.5 ms steps failed with it after 0.46 s, and runs through
/// with this limit.
#[inline(always)]
pub fn resolved_rate(h: f64, a: &Vec3, r: &Vec3) -> Vec3 {
    let change = h * h * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    let size = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    if change <= RESOLVED_CHANGE * RESOLVED_CHANGE * size {
        *r
    } else {
        [0.0; 3]
    }
}

/// A time rule: its coefficients and its state update (module documentation).
pub trait TimeRule: Copy + Send + Sync {
    /// One index-3 step of this rule, with what is known before the step folded in.
    type Step<'a>: Index3Rule;

    /// Order of accuracy of the positions.
    fn order(&self) -> usize;

    /// What identifies the iteration matrix of a step of size `h` (for its reuse).
    fn matrix_key(&self, h: f64) -> [f64; 2];

    /// The state at the start of a run with the consistent accelerations `acc`
    /// ([`RuleState::new`]; rules that carry no accelerations may leave it empty).
    fn initial_state(&self, acc: &[Vec3]) -> RuleState {
        RuleState::new(acc)
    }

    /// Where the index-3 step from `start` is evaluated, and the scale of its dynamics rows for
    /// the reference mass `mass_ref`.
    fn point(&self, start: &StepStart, mass_ref: f64) -> StepPoint;

    /// The kinematics of the index-3 step from `start` and `state` (computing its predictors
    /// into `state` first).
    fn index3<'a>(&self, state: &'a mut RuleState, start: StepStart<'a>) -> Self::Step<'a>;

    /// After a converged index-3 step of size `h` to q_{n+1} = `q` (from the predictors that
    /// [`TimeRule::index3`] left in `state`): the rule's new state.
    fn advance(&self, state: &mut RuleState, h: f64, q: &[Vec3]);

    /// The GGL step from `start` and `state`: its coefficients, with b and c written into
    /// `base`.
    fn ggl(&self, state: &RuleState, start: StepStart, base: GglBase) -> GglCoefficients;

    /// After a converged GGL step of size `h` from v_n to v_{n+1} = `v`: the rule's new state.
    fn advance_ggl(&self, state: &mut RuleState, h: f64, v_n: &[Vec3], v: &[Vec3]);

    /// Newton's first iterate of a step from `start` into `out`: the step's own end,
    /// q_{n+1} = q_n + h v_n + h^2 (w_n A_n + w A_{n+1}) in the rule's step accelerations A,
    /// with A_{n+1} extrapolated linearly, A_n + h `rate`, from the last step's end acceleration
    /// `acc` ([`TimeRule::end_acceleration`]) and its rate over that step (zero: constant
    /// acceleration). Its error is O(h^4) where the constant-acceleration extrapolation
    /// q_n + h v_n + h^2/2 qdd_n is O(h^3) (`docs/theory/newton.md`, "The predictor").
    fn predict(
        &self,
        state: &RuleState,
        start: StepStart,
        acc: (&[Vec3], &[Vec3]),
        out: &mut [Vec3],
    );

    /// The acceleration of a converged step from `start` to v_{n+1} = `v` (with the state
    /// already advanced), into `out`: what the run loop's predictor extrapolates with.
    fn end_acceleration(&self, state: &RuleState, start: StepStart, v: &[Vec3], out: &mut [Vec3]);
}
