//! The stabilised index-2 formulation of Gear, Gupta and Leimkuhler (GGL), discretised by the
//! generalised trapezoidal rule or by generalised-alpha.
//!
//! # The equations
//!
//! The index-3 DAE (`docs/theory/formulation.md`) enforces the constraints on positions only; its velocities
//! satisfy Phi' = G v + Phi_t = 0 (G = Phi_q) only to the order of the scheme. GGL adds the
//! velocity constraints with a second multiplier mu that acts on the kinematics:
//!
//! ```text
//! M v' = M g + f(q, v, t) + G(q, t)^T lambda
//! q'   = v + G(q, t)^T mu
//! Phi(q, t) = 0
//! G(q, t) v + Phi_t(q, t) = 0
//! ```
//!
//! (M is the inertia, gravity acts on the mass alone; lambda has the sign and meaning of the
//! index-3 multiplier.) Differentiating Phi = 0 along a solution gives G q' + Phi_t =
//! G v + Phi_t + G G^T mu = G G^T mu = 0, so mu = 0 where G has full rank: the exact solution
//! is that of the index-3 system. The discrete mu is not zero; it is the correction that
//! reconciles the position and velocity constraints at the end of each step.
//!
//! # The discretisation
//!
//! Every time rule writes the step from (t_n, q_n, v_n) to q = q_{n+1}, v = v_{n+1} in one common
//! form, linear in v (`docs/theory/ggl.md`):
//!
//! ```text
//! q    = b + kappa v + G(q, t_{n+1})^T mu          (kinematics)
//! qdd  = c + c_v v                                  (the acceleration in the dynamics)
//! q_e = (1 - w) q_n + w q,  v_e = (1 - w) v_n + w v,  t_e = t_n + w h   (evaluation point)
//! ```
//!
//! The rule gives kappa, c_v, w, b and c ([`TimeRule::ggl`]; the formulas of each rule are in its
//! own file, `trapezoidal.rs` and `generalized_alpha.rs`), and updates its state from v_{n+1}
//! after the step ([`TimeRule::advance_ggl`]). The step starts from a [`StepStart`] and is
//! evaluated at the [`StepPoint`] of weight w (built by [`StepPoint::new`], as the index-3
//! step's is). This file is the one GGL step problem,
//! written once for every rule: with mu = 0 and the trapezoidal rule, v_e = (q - q_n)/h and the
//! step is the index-3 one of `step_problem.rs`.
//!
//! Newton runs on (q, v, lambda, mu) with the residual
//!
//! ```text
//! K   = q - b - kappa v - G(q, t_{n+1})^T mu
//! D   = (M + C(q_e)) (c + c_v v) - m g - f(q_e, v_e, t_e) - G(q_e, t_e)^T lambda
//! Phi = Phi(q, t_{n+1})
//! Psi = G(q, t_{n+1}) v + Phi_t(q, t_{n+1})
//! ```
//!
//! Both constraint levels hold at the end of every step, to the Newton tolerance. C(q_e) is the
//! line nodes' axial added-mass correction (`assembly/axial_added_mass.rs`), zero elsewhere:
//! its Jacobian is C / m_ref in the scaled v~ columns and, through the tangent, a force's
//! df/dq weighted as the forces' are.
//!
//! # Why v stays an unknown
//!
//! v is explicit in K and could be eliminated, but it would carry G^T mu into the dynamics and
//! the velocity constraints: f_v G^T would couple a force's particles to the multipliers of
//! every constraint touching them, and G (sum_k mu_k Phi_k,qq) the velocity rows of neighbouring
//! constraints, so the pattern would depend on the elements' neighbourhoods. Kept as an
//! unknown, v makes every block local ([`StabilizedLayout`]) and the Jacobian a sum of each
//! element's own derivatives.
//!
//! # The Jacobian
//!
//! With H_k = Phi_k,qq and Phi_qt,k = d(Phi_t,k)/dq:
//!
//! ```text
//! dK/dq   = I - sum_k mu_k H_k(q, t_{n+1})      dK/dv = -kappa I     dK/dmu_k = -G_k(q, t_{n+1})^T
//! dD/dq   = -w f_q - w sum_k lambda_k H_k(q_e, t_e)
//! dD/dv   = c_v M - w f_v                       dD/dlambda_k = -G_k(q_e, t_e)^T
//! dPhi/dq = G(q, t_{n+1})
//! dPsi/dq = v^T H(q, t_{n+1}) + Phi_qt(q, t_{n+1})      dPsi/dv = G(q, t_{n+1})
//! ```
//!
//! Phi_qt is not part of the constraint contract; it comes from gamma (the part of Phi'' free
//! of accelerations), which for any Phi(q, t) is the quadratic v^T Phi_qq v + 2 Phi_qt v +
//! Phi_tt in v. Its odd part is exact: Phi_qt e = (gamma(q, e, t) - gamma(q, -e, t))/4 for a
//! velocity field e that is a unit vector in one coordinate ([`phi_qt`]).
//!
//! # Scaling
//!
//! As in the index-3 schemes, every scaled unknown and residual is a length and the scaled
//! matrix has O(1) entries for small h. The unknowns are q, v~ = kappa v, lambda~_k =
//! lambda_k sigma / s_k and mu~_k = mu_k / s_k (s_k G_k is dimensionless, s_k the constraint's
//! scale); the rows are K as it is, D times sigma = kappa/(c_v m_ref) (alpha h^2 / m_ref for the
//! trapezoidal rule, the generalised-alpha sigma of [`super::GeneralizedAlpha`]), Phi_k times
//! s_k and Psi_k times s_k kappa. The scaled matrix is
//!
//! ```text
//!          q                          v~                         lambda~       mu~
//! K   [ I + O(mu),                  -I,                          0,          -s G^T ]
//! D   [ O(h^2),                     M/m_ref + O(h),             -s G_e^T,     0     ]
//! Phi [ s G,                        0,                           0,           0     ]
//! Psi [ O(h),                       s G,                         0,           0     ]
//! ```
//!
//! whose limit for h -> 0 is non-singular when G has full rank (v~ and lambda~ from the D and
//! Psi rows, mu~ from the Phi rows through s G s G^T). Its mu~ and v~ blocks couple the
//! constraints that share particles, so the tree elimination does not apply: small systems get
//! the dense LU, others the general sparse LU, analysed once per run.

use super::newton::{self, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport};
use super::rule::{GglBase, RuleState, StepPoint, StepStart, TimeRule};
use super::stabilized_layout::StabilizedLayout;
use super::workspace::{refactor, StepBuffers, StepWorkspace};

use crate::assembly::{add, add_block, add_force_blocks, BlockVisit, NONE};
use crate::constraints::{Constraint, Gradient, Hessian};
use crate::forces::Jacobian;
use crate::linear::{for_layout, LinearSolver, SparseSolver};
use crate::math::Vec3;
use crate::model::System;

/// The equations a run discretises, chosen by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Formulation {
    /// The index-3 DAE: position constraints only ("index-3").
    #[default]
    Index3,
    /// The stabilised index-2 formulation of Gear, Gupta and Leimkuhler: position and velocity
    /// constraints, with a second multiplier on the kinematics ("ggl").
    Ggl,
}

impl Formulation {
    /// Name of the formulation: "index-3" or "ggl".
    pub fn name(&self) -> &'static str {
        match self {
            Formulation::Index3 => "index-3",
            Formulation::Ggl => "ggl",
        }
    }
}

/// The coefficients of one step in the common form of the module documentation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StepRule {
    /// dq/dv in the kinematics.
    kappa: f64,
    /// d(qdd)/dv in the dynamics.
    c_v: f64,
    /// Weight of the new state in the evaluation point.
    w: f64,
    /// Evaluation point, end, and the scale of the dynamic rows sigma = kappa/(c_v m_ref).
    point: StepPoint,
}

/// The layout, solver and buffers of the GGL steps of a run (allocated once).
pub struct StabilizedWorkspace {
    /// Unknown numbering, pattern and slots.
    pub layout: StabilizedLayout,
    /// The factorisation of the iteration matrix (dense or general sparse LU).
    pub solver: Box<dyn LinearSolver>,
    values: Vec<f64>,
    r: Vec<f64>,
    /// The velocity multipliers mu of the last step.
    pub mu: Vec<f64>,
    base_q: Vec<Vec3>,
    base_a: Vec<Vec3>,
    q_eval: Vec<Vec3>,
    v_eval: Vec<Vec3>,
    probe: Vec<Vec3>,
}

impl StabilizedWorkspace {
    /// The values of the last iteration matrix assembled (the one factorised last).
    pub(crate) fn values(&self) -> &[f64] {
        &self.values
    }

    /// Factorises the iteration matrix `values` again; false when they are not of this
    /// workspace's pattern (another length) or do not factorise.
    pub(crate) fn refactor(&mut self, values: &[f64]) -> bool {
        refactor(&mut self.values, self.solver.as_mut(), values)
    }

    /// Analyses the system once: dense LU up to `dense_limit` unknowns, general sparse LU above.
    pub fn new(system: &System, dense_limit: usize) -> StabilizedWorkspace {
        let layout = StabilizedLayout::new(system, dense_limit);
        let solver = for_layout(&layout.pattern, 0, SparseSolver::SparseLu);
        let n = system.particles().len();
        StabilizedWorkspace {
            values: vec![0.0; layout.pattern.nnz()],
            r: vec![0.0; layout.unknowns()],
            mu: vec![0.0; layout.constraints],
            base_q: vec![[0.0; 3]; n],
            base_a: vec![[0.0; 3]; n],
            q_eval: vec![[0.0; 3]; n],
            v_eval: vec![[0.0; 3]; n],
            probe: vec![[0.0; 3]; n],
            solver,
            layout,
        }
    }

    /// The coefficients of a step of `rule` from `start` and `state`, with b and c in
    /// `base_q` and `base_a`; `mass_ref` sets the scaling.
    fn prepare<T: TimeRule>(
        &mut self,
        rule: T,
        mass_ref: f64,
        start: StepStart,
        state: &RuleState,
    ) -> StepRule {
        let base = GglBase {
            b: &mut self.base_q,
            c: &mut self.base_a,
        };
        let k = rule.ggl(state, start, base);
        StepRule {
            kappa: k.kappa,
            c_v: k.c_v,
            w: k.w,
            point: StepPoint::new(&start, k.w, k.kappa / (k.c_v * mass_ref)),
        }
    }

    /// The problem of the step `rule` from `start` on these buffers and `ws.state` (the
    /// iterate), and the linear solver's share of the workspace.
    fn problem<'a>(
        &'a mut self,
        system: &'a System,
        ws: &'a mut StepWorkspace,
        start: StepStart<'a>,
        rule: StepRule,
    ) -> (StabilizedProblem<'a>, LinearWork<'a>) {
        let problem = StabilizedProblem {
            system,
            layout: &self.layout,
            state: &mut ws.state,
            mu: &mut self.mu,
            scales: &ws.scales,
            inertia: &ws.inertia,
            axial: &ws.axial_added_mass,
            start,
            base_q: &self.base_q,
            base_a: &self.base_a,
            q_eval: &mut self.q_eval,
            v_eval: &mut self.v_eval,
            probe: &mut self.probe,
            rule,
        };
        let work = LinearWork::new(
            &mut self.solver,
            &mut self.values,
            &mut self.r,
            &mut ws.matrix,
        );
        (problem, work)
    }

    /// Takes one GGL step of `time_rule` from `start` and `state` (the rule's state). The caller
    /// sets the predictor in `ws.state.q` and `ws.state.lambda`; the velocities start from the
    /// kinematics with mu = 0. On success `ws.state` holds q_{n+1}, v_{n+1} and lambda_{n+1},
    /// `self.mu` the velocity multipliers and `state` the rule's new state; on failure `state`
    /// is unchanged. `ws.matrix` tracks this
    /// solver's factorisation for modified Newton; failures name equations in the index-3
    /// numbering of `ws.layout` ([`StabilizedLayout::index3_equation`]).
    pub fn step<T: TimeRule>(
        &mut self,
        system: &System,
        ws: &mut StepWorkspace,
        time_rule: T,
        start: StepStart,
        state: &mut RuleState,
        options: &NewtonOptions,
    ) -> Result<NewtonReport, NewtonFailure> {
        let rule = self.prepare(time_rule, ws.mass_ref, start, state);
        for (v, (q, b)) in ws
            .state
            .v
            .iter_mut()
            .zip(ws.state.q.iter().zip(&self.base_q))
        {
            for x in 0..3 {
                v[x] = (q[x] - b[x]) / rule.kappa;
            }
        }
        self.mu.fill(0.0);
        let (mut problem, work) = self.problem(system, ws, start, rule);
        let report = newton::solve(&mut problem, work, time_rule.matrix_key(start.h), options)
            .map_err(|failure| match failure {
                NewtonFailure::NotConverged {
                    iterations,
                    residual,
                    worst,
                } => NewtonFailure::NotConverged {
                    iterations,
                    residual,
                    worst: self.layout.index3_equation(worst),
                },
                NewtonFailure::Singular(mut s) => {
                    s.column = s.column.map(|c| self.layout.index3_equation(c));
                    NewtonFailure::Singular(s)
                }
            })?;
        time_rule.advance_ggl(state, start.h, start.v_n, &ws.state.v);
        Ok(report)
    }
}

/// Phi_qt of constraint `con` at (q, t), one row 3-vector per touched particle, from the odd
/// part of gamma in v (module documentation). `probe` is a zero velocity field of the system's
/// size, left zero.
pub fn phi_qt(con: &Constraint, q: &[Vec3], t: f64, probe: &mut [Vec3]) -> Gradient {
    let mut out: Gradient = smallvec::smallvec![[0.0; 3]; con.particles().len()];
    for (x, &p) in con.particles().iter().enumerate() {
        for j in 0..3 {
            probe[p][j] = 1.0;
            let plus = con.gamma(q, probe, t);
            probe[p][j] = -1.0;
            let minus = con.gamma(q, probe, t);
            probe[p][j] = 0.0;
            out[x][j] = 0.25 * (plus - minus);
        }
    }
    out
}

/// One GGL step's nonlinear problem in the scaled unknowns (q, v~, lambda~, mu~).
pub struct StabilizedProblem<'a> {
    system: &'a System,
    layout: &'a StabilizedLayout,
    state: &'a mut StepBuffers,
    mu: &'a mut [f64],
    scales: &'a [f64],
    inertia: &'a [f64],
    axial: &'a crate::assembly::AxialAddedMass,
    start: StepStart<'a>,
    base_q: &'a [Vec3],
    base_a: &'a [Vec3],
    q_eval: &'a mut [Vec3],
    v_eval: &'a mut [Vec3],
    probe: &'a mut [Vec3],
    rule: StepRule,
}

impl StabilizedProblem<'_> {
    /// The acceleration qdd_i = c_i + c_v v_i of the dynamics rows at the iterate.
    fn acceleration(&self) -> impl Fn(usize) -> Vec3 + '_ {
        let (c, c_v, v) = (self.base_a, self.rule.c_v, &self.state.v);
        move |i| std::array::from_fn(|x| c[i][x] + c_v * v[i][x])
    }
}

impl NewtonProblem for StabilizedProblem<'_> {
    /// The iterate holds the velocities (unknowns of their own), and the evaluation point the
    /// residual derives serves only the Jacobian at the same iterate, which Newton assembles
    /// after a residual there: nothing needs the residual at the returned iterate.
    fn stops_on_increment(&self) -> bool {
        true
    }

    fn residual(&mut self, r: &mut [f64]) {
        let (system, layout, rule) = (self.system, self.layout, self.rule);
        let point = rule.point;
        let (n3, m) = (3 * layout.free, layout.constraints);
        let b = &*self.state;
        for i in 0..b.q.len() {
            for x in 0..3 {
                self.q_eval[i][x] = (1.0 - rule.w) * self.start.q_n[i][x] + rule.w * b.q[i][x];
                self.v_eval[i][x] = (1.0 - rule.w) * self.start.v_n[i][x] + rule.w * b.v[i][x];
            }
        }
        let g = system.gravity();
        for (i, p) in system.particles().iter().enumerate() {
            let d = layout.dof[i];
            if d != NONE {
                for x in 0..3 {
                    r[d + x] = b.q[i][x] - self.base_q[i][x] - rule.kappa * b.v[i][x];
                    let qdd = self.base_a[i][x] + rule.c_v * b.v[i][x];
                    r[n3 + d + x] = point.sigma * (self.inertia[i] * qdd - p.mass * g[x]);
                }
            }
        }
        for f in system.forces() {
            let fl = f.force(self.q_eval, self.v_eval, point.t_eval);
            for (x, &p) in f.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    for y in 0..3 {
                        r[n3 + d + y] -= point.sigma * fl[x][y];
                    }
                }
            }
        }
        if !self.axial.is_empty() {
            // The line nodes' axial added-mass correction sigma C(q_e) qdd.
            let (dynamics, qdd) = (&mut r[n3..2 * n3], self.acceleration());
            let q_eval = &*self.q_eval;
            self.axial
                .add_rows(&layout.dof, dynamics, (q_eval, point.sigma), qdd);
        }
        for (c, con) in system.constraints().iter().enumerate() {
            let grad_e = con.gradient(self.q_eval, point.t_eval);
            let grad_1 = con.gradient(&b.q, point.t_end);
            let mut gv = 0.0;
            for (x, &p) in con.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    for y in 0..3 {
                        r[d + y] -= grad_1[x][y] * self.mu[c];
                        r[n3 + d + y] -= point.sigma * grad_e[x][y] * b.lambda[c];
                    }
                }
                for y in 0..3 {
                    gv += grad_1[x][y] * b.v[p][y];
                }
            }
            let s = self.scales[c];
            r[2 * n3 + c] = s * con.residual(&b.q, point.t_end);
            r[2 * n3 + m + c] = s * rule.kappa * (gv + con.phi_t(&b.q, point.t_end));
        }
    }

    fn jacobian(&mut self, values: &mut [f64]) {
        let (system, layout, rule) = (self.system, self.layout, self.rule);
        let point = rule.point;
        let b = &*self.state;
        let mass_ref = rule.kappa / (rule.c_v * point.sigma);
        for i in 0..system.particles().len() {
            if layout.dof[i] == NONE {
                continue;
            }
            let m = self.inertia[i] / mass_ref;
            for x in 0..3 {
                add(values, layout.kinematic_q[i][4 * x], 1.0);
                add(values, layout.kinematic_v[i][x], -1.0);
                add(values, layout.dynamic_v[i][4 * x], m);
            }
        }
        // One buffer of local blocks for all elements, reset to each one's size.
        let (mut dq, mut dv) = (Jacobian::zeros(0), Jacobian::zeros(0));
        let (mut dyn_hess, mut hess) = (Hessian::zeros(0), Hessian::zeros(0));
        for (fi, f) in system.forces().iter().enumerate() {
            if !f.has_jacobian() {
                continue;
            }
            let n = f.particles().len();
            dq.reset(n);
            dv.reset(n);
            f.add_jacobian(self.q_eval, self.v_eval, point.t_eval, &mut dq, &mut dv);
            let (wq, wv) = (-point.sigma * rule.w, -point.sigma * rule.w / rule.kappa);
            let pairs = layout.force_offsets.pairs(fi);
            let (blocks_q, blocks_v) = (&layout.force_q[pairs.clone()], &layout.force_v[pairs]);
            add_force_blocks(values, (blocks_q, blocks_v), (wq, &dq), (wv, &dv));
        }
        if !self.axial.is_empty() {
            // d(sigma C qdd)/dv~ = sigma c_v C / kappa = C / m_ref; through t, as a force.
            let diagonal = |i| layout.dynamic_v[i];
            let force_row = |k, n, f: &mut BlockVisit| {
                let pairs = layout.force_offsets.pairs(k);
                f(&layout.force_q[pairs.start..pairs.start + n])
            };
            let blocks = (diagonal, force_row);
            let weights = (&*self.q_eval, 1.0 / mass_ref, -point.sigma * rule.w);
            self.axial
                .add_jacobian(values, blocks, weights, self.acceleration());
        }
        for (c, con) in system.constraints().iter().enumerate() {
            let parts = con.particles();
            let n = parts.len();
            let s = self.scales[c];
            dyn_hess.reset(n);
            let w_lambda = -point.sigma * rule.w * b.lambda[c];
            con.add_hessian(self.q_eval, point.t_eval, w_lambda, &mut dyn_hess);
            hess.reset(n);
            con.add_hessian(&b.q, point.t_end, 1.0, &mut hess);
            let grad_e = con.gradient(self.q_eval, point.t_eval);
            let grad_1 = con.gradient(&b.q, point.t_end);
            let qt = phi_qt(con, &b.q, point.t_end, self.probe);
            let pairs = layout.constraint_offsets.pairs(c);
            let (dynamic_hessian, kinematic_hessian) = (
                &layout.dynamic_hessian[pairs.clone()],
                &layout.kinematic_hessian[pairs],
            );
            let strips = layout.constraint_offsets.particles(c);
            let kinematic_mu = &layout.kinematic_mu[strips.clone()];
            let dynamic_lambda = &layout.dynamic_lambda[strips.clone()];
            let position_row = &layout.position_row[strips.clone()];
            let velocity_row_v = &layout.velocity_row_v[strips.clone()];
            let velocity_row_q = &layout.velocity_row_q[strips];
            for x in 0..n {
                for y in 0..n {
                    add_block(values, &dynamic_hessian[x * n + y], 1.0, &dyn_hess[x][y]);
                    let kin = &kinematic_hessian[x * n + y];
                    add_block(values, kin, -self.mu[c], &hess[x][y]);
                }
                // d(G v)/dq_x = sum_y H[x][y] v_y.
                let mut dpsi = qt[x];
                for y in 0..n {
                    let v = b.v[parts[y]];
                    for r in 0..3 {
                        for k in 0..3 {
                            dpsi[r] += hess[x][y][r][k] * v[k];
                        }
                    }
                }
                for k in 0..3 {
                    add(values, kinematic_mu[x][k], -s * grad_1[x][k]);
                    add(values, dynamic_lambda[x][k], -s * grad_e[x][k]);
                    add(values, position_row[x][k], s * grad_1[x][k]);
                    add(values, velocity_row_v[x][k], s * grad_1[x][k]);
                    let dq = s * rule.kappa * dpsi[k];
                    add(values, velocity_row_q[x][k], dq);
                }
            }
        }
    }

    fn update(&mut self, dx: &[f64]) {
        let layout = self.layout;
        let (n3, m) = (3 * layout.free, layout.constraints);
        let b = &mut *self.state;
        for (i, &d) in layout.dof.iter().enumerate() {
            if d != NONE {
                for x in 0..3 {
                    b.q[i][x] -= dx[d + x];
                    b.v[i][x] -= dx[n3 + d + x] / self.rule.kappa;
                }
            }
        }
        for c in 0..m {
            let s = self.scales[c];
            b.lambda[c] -= dx[2 * n3 + c] * s / self.rule.point.sigma;
            self.mu[c] -= dx[2 * n3 + m + c] * s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::{
        assert_pattern_jacobian_matches, every_kind, line_in_water, perturbed_iterate,
    };
    use crate::integrators::Scheme;

    /// The assembled Jacobian equals central finite differences of the assembled residual, for
    /// every constraint kind (a moving point, so Phi_t and Phi_qt are not zero) and force kind
    /// (Morison with added mass, quadratic and linear drag, spring-damper, a time-dependent
    /// force), fixed particles, non-zero lambda, mu and old accelerations, with both time rules
    /// and both storages (sparse, dense).
    #[test]
    fn jacobian_matches_finite_differences_of_the_residual() {
        assert_jacobian_matches_on(&every_kind());
    }

    /// As above on a line of five free nodes in water whose added mass is anisotropic
    /// (Ca != CaAx: the axial correction C(q_e) qdd in the dynamics rows).
    #[test]
    fn axial_added_mass_jacobian_matches_finite_differences() {
        assert_jacobian_matches_on(&line_in_water());
    }

    /// The finite-difference check of the two tests above on the system `s`.
    fn assert_jacobian_matches_on(s: &System) {
        let q_n = s.initial_positions();
        let v_n = s.initial_velocities();
        let schemes = [
            Scheme::GeneralizedTrapezoidal { alpha: 0.6 },
            Scheme::GeneralizedTrapezoidal { alpha: 1.0 },
            Scheme::GeneralizedAlpha { rho_inf: 0.7 },
        ];
        for scheme in schemes {
            for dense_limit in [0, 1000] {
                let mut ws = StepWorkspace::with_solver(s, 0, SparseSolver::SparseLu);
                let mut ggl = StabilizedWorkspace::new(s, dense_limit);
                let algorithmic: Vec<Vec3> = q_n.iter().map(|x| [0.2, x[2], -x[0]]).collect();
                let mut alpha = RuleState::new(&algorithmic);
                alpha.acceleration = q_n.iter().map(|x| [x[1], -x[0], 0.3]).collect();
                let h = 0.01;
                let mass_ref = ws.mass_ref;
                let start = StepStart::new(0.3, &q_n, &v_n, h);
                let rule = crate::integrators::with_rule!(scheme.rule(), r => {
                    ggl.prepare(r, mass_ref, start, &alpha)
                });
                perturbed_iterate(&mut ws, &q_n);
                for (i, v) in ws.state.v.iter_mut().enumerate() {
                    *v = [0.3 * i as f64, -0.2, 0.1 + v_n[i][0]];
                }
                for (k, mu) in ggl.mu.iter_mut().enumerate() {
                    *mu = 1e-3 * (k as f64 - 1.5);
                }
                let pattern = ggl.layout.pattern.clone();
                let (mut problem, _) = ggl.problem(s, &mut ws, start, rule);
                assert_pattern_jacobian_matches(&mut problem, &pattern);
            }
        }
    }

    /// Phi_qt from gamma's odd part equals central finite differences in q of Phi_t for the
    /// constraint on a moving point (Phi_t = 2 d.p', so Phi_qt = 2 p').
    #[test]
    fn phi_qt_matches_finite_differences_of_phi_t() {
        let s = every_kind();
        let q = s.initial_positions();
        let mut probe = vec![[0.0; 3]; q.len()];
        for con in s.constraints() {
            let t = 0.37;
            let qt = phi_qt(con, &q, t, &mut probe);
            for (x, &p) in con.particles().iter().enumerate() {
                for j in 0..3 {
                    let eps = 1e-6;
                    let mut qp = q.clone();
                    qp[p][j] += eps;
                    let mut qm = q.clone();
                    qm[p][j] -= eps;
                    let fd = (con.phi_t(&qp, t) - con.phi_t(&qm, t)) / (2.0 * eps);
                    assert!((fd - qt[x][j]).abs() < 1e-8, "{fd} vs {}", qt[x][j]);
                }
            }
            assert!(probe.iter().all(|v| *v == [0.0; 3]));
        }
    }
}
