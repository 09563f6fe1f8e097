//! The generalised-alpha scheme for index-3 constrained systems, in the form of Arnold and Brüls
//! (Multibody System Dynamics 18 (2007) 185-202).
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
//! follows formulation.md) together with
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
//! Scaling as in the trapezoidal rule ([`super::StepProblem`]): dynamics rows are multiplied by
//! sigma = 1/(c m_ref), so that the mass block is M/m_ref, constraint row k by s_k, and
//! multiplier k is solved for in the unit lambda_k sigma / s_k. The scaled matrix has the same
//! pattern `[M/m_ref + O(h^2), -s G^T; s G, 0]` as the trapezoidal rule's, so the tree, dense and
//! sparse solvers serve both.

use super::newton::{self, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport};
use super::trapezoidal::{StepBuffers, StepWorkspace};
use rayon::prelude::*;

use crate::assembly::{
    add_block, JacobianTerms, Layout, ParallelAssembly, ResidualTerms, MIN_TASK, NONE,
};
use crate::forces::Jacobian;
use crate::math::{Mat3, Vec3};
use crate::model::System;

/// The scheme, given by its spectral radius at infinite frequency rho_inf in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlpha {
    /// Spectral radius at infinite frequency (1: no numerical damping).
    pub rho_inf: f64,
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

/// The scheme's state besides positions and velocities.
#[derive(Debug, Clone)]
pub struct AlphaState {
    /// True accelerations qdd_n.
    pub acceleration: Vec<Vec3>,
    /// Algorithmic accelerations a_n.
    pub algorithmic: Vec<Vec3>,
    /// Per step: the parts of q_{n+1} and v_{n+1} known before the step (see [`Predictors`]).
    predicted_q: Vec<Vec3>,
    predicted_v: Vec<Vec3>,
}

impl AlphaState {
    /// The state at the start of a run: a_0 = qdd_0 = the consistent accelerations.
    pub fn new(accelerations: &[Vec3]) -> AlphaState {
        AlphaState {
            acceleration: accelerations.to_vec(),
            algorithmic: accelerations.to_vec(),
            predicted_q: vec![[0.0; 3]; accelerations.len()],
            predicted_v: vec![[0.0; 3]; accelerations.len()],
        }
    }

    /// Computes the predictors p and w of a step of size `h` from (q_n, v_n) and a_n.
    fn predict(&mut self, k: &AlphaCoefficients, h: f64, q_n: &[Vec3], v_n: &[Vec3]) {
        let (hh, half) = (h * h, 0.5 - k.beta);
        for i in 0..q_n.len() {
            let a_n = self.algorithmic[i];
            for x in 0..3 {
                self.predicted_q[i][x] = q_n[i][x] + h * v_n[i][x] + hh * half * a_n[x];
                self.predicted_v[i][x] = v_n[i][x] + h * (1.0 - k.gamma) * a_n[x];
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
    fn new(k: &AlphaCoefficients, h: f64) -> Predictors {
        Predictors {
            inv_beta_h2: 1.0 / (k.beta * h * h),
            h_gamma: h * k.gamma,
            c_a: (1.0 - k.alpha_m) / (1.0 - k.alpha_f),
            c_m: k.alpha_m / (1.0 - k.alpha_f),
            c_f: k.alpha_f / (1.0 - k.alpha_f),
        }
    }

    /// a_{n+1} and v_{n+1} of one particle from its iterate q and predictors p, w.
    #[inline(always)]
    fn kinematics(&self, q: &Vec3, p: &Vec3, w: &Vec3) -> (Vec3, Vec3) {
        let a: Vec3 = std::array::from_fn(|x| (q[x] - p[x]) * self.inv_beta_h2);
        let v: Vec3 = std::array::from_fn(|x| w[x] + self.h_gamma * a[x]);
        (a, v)
    }

    /// The scaled inertia-and-gravity row of one coordinate, sigma (M qdd_{n+1} - m g).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn inertia_row(
        &self,
        sigma: f64,
        inertia: f64,
        mass: f64,
        g: f64,
        a: f64,
        a_n: f64,
        qdd_n: f64,
    ) -> f64 {
        sigma * (inertia * (self.c_a * a + self.c_m * a_n - self.c_f * qdd_n) - mass * g)
    }
}

impl GeneralizedAlpha {
    /// The coefficients alpha_m, alpha_f, gamma, beta (see the module documentation).
    pub fn coefficients(&self) -> AlphaCoefficients {
        let rho = self.rho_inf;
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        AlphaCoefficients {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }

    /// Order of accuracy of the positions (2 for every rho_inf).
    pub fn order(&self) -> usize {
        2
    }

    /// What identifies the iteration matrix of a step of size `h` (for its reuse).
    pub fn matrix_key(&self, h: f64) -> [f64; 2] {
        [h, self.rho_inf]
    }

    /// Takes one step of size `h` from (t_n, q_n, v_n, state). The caller sets the predictor in
    /// `ws.state.q` and `ws.state.lambda`; on success they hold q_{n+1} and lambda_{n+1},
    /// `ws.state.v` holds v_{n+1} and `state` holds qdd_{n+1} and a_{n+1}. On failure `state`
    /// is unchanged.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &self,
        system: &System,
        ws: &mut StepWorkspace,
        t_n: f64,
        q_n: &[Vec3],
        v_n: &[Vec3],
        state: &mut AlphaState,
        h: f64,
        options: &NewtonOptions,
    ) -> Result<NewtonReport, NewtonFailure> {
        let (mut problem, work) = self.problem(system, ws, state, t_n, q_n, v_n, h);
        let known = problem.known;
        let report = newton::solve(&mut problem, work, self.matrix_key(h), options)?;
        let b = &mut ws.state;
        for i in 0..b.q.len() {
            let (a, v) = known.kinematics(&b.q[i], &state.predicted_q[i], &state.predicted_v[i]);
            b.v[i] = v;
            for x in 0..3 {
                state.acceleration[i][x] = known.c_a * a[x] + known.c_m * state.algorithmic[i][x]
                    - known.c_f * state.acceleration[i][x];
            }
            state.algorithmic[i] = a;
        }
        Ok(report)
    }

    /// The nonlinear problem of a step of size `h` from (t_n, q_n, v_n, state), with the
    /// predictors computed into `state`, and the linear solver's share of the workspace.
    #[allow(clippy::too_many_arguments)]
    fn problem<'a>(
        &self,
        system: &'a System,
        ws: &'a mut StepWorkspace,
        state: &'a mut AlphaState,
        t_n: f64,
        q_n: &[Vec3],
        v_n: &[Vec3],
        h: f64,
    ) -> (AlphaStepProblem<'a>, LinearWork<'a>) {
        let k = self.coefficients();
        let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
        state.predict(&k, h, q_n, v_n);
        let state = &*state;
        let problem = AlphaStepProblem {
            system,
            layout: &ws.layout,
            buffers: &mut ws.state,
            scales: &ws.scales,
            inertia: &ws.inertia,
            parallel: ws.parallel.as_mut(),
            p: &state.predicted_q,
            w: &state.predicted_v,
            a_n: &state.algorithmic,
            qdd_n: &state.acceleration,
            t_n,
            h,
            k,
            known: Predictors::new(&k, h),
            sigma: 1.0 / (c * ws.mass_ref),
        };
        let work = LinearWork {
            solver: ws.solver.as_mut(),
            values: &mut ws.values,
            r: &mut ws.r,
            matrix: &mut ws.matrix,
        };
        (problem, work)
    }
}

/// One generalised-alpha step's nonlinear problem.
pub struct AlphaStepProblem<'a> {
    system: &'a System,
    layout: &'a Layout,
    buffers: &'a mut StepBuffers,
    scales: &'a [f64],
    inertia: &'a [f64],
    parallel: Option<&'a mut ParallelAssembly>,
    /// The predictors p and w of q_{n+1} and v_{n+1} (see [`Predictors`]).
    p: &'a [Vec3],
    w: &'a [Vec3],
    a_n: &'a [Vec3],
    qdd_n: &'a [Vec3],
    t_n: f64,
    h: f64,
    k: AlphaCoefficients,
    known: Predictors,
    sigma: f64,
}

impl AlphaStepProblem<'_> {
    /// The residual on rayon's thread pool (same result as the serial loops, bit for bit).
    fn residual_parallel(&mut self, r: &mut [f64]) {
        let (h, sigma, known) = (self.h, self.sigma, self.known);
        let (p, w, a_n, qdd_n, inertia) = (self.p, self.w, self.a_n, self.qdd_n, self.inertia);
        let (system, layout) = (self.system, self.layout);
        let b = &mut *self.buffers;
        b.q.par_iter()
            .zip(b.v.par_iter_mut())
            .zip(p.par_iter().zip(w.par_iter()))
            .with_min_len(MIN_TASK)
            .for_each(|((q, v), (p, w))| *v = known.kinematics(q, p, w).1);
        let b = &*self.buffers;
        let g = system.gravity();
        let particles = system.particles();
        let t1 = self.t_n + h;
        let terms = ResidualTerms {
            q_eval: &b.q,
            v_eval: &b.v,
            t_eval: t1,
            q_end: &b.q,
            t_end: t1,
            sigma,
            lambda: &b.lambda,
            scales: self.scales,
        };
        let parallel = self.parallel.as_deref_mut().expect("parallel assembly");
        parallel.residual(system, layout, &terms, r, |i, x| {
            let a = (b.q[i][x] - p[i][x]) * known.inv_beta_h2;
            let mass = particles[i].mass;
            known.inertia_row(sigma, inertia[i], mass, g[x], a, a_n[i][x], qdd_n[i][x])
        });
    }

    /// The Jacobian on rayon's thread pool (equal to the serial one to round-off).
    fn jacobian_parallel(&mut self, values: &mut [f64]) {
        let (h, sigma, k, inertia) = (self.h, self.sigma, self.k, self.inertia);
        let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
        let b = &*self.buffers;
        let t1 = self.t_n + h;
        let terms = JacobianTerms {
            q_eval: &b.q,
            v_eval: &b.v,
            t_eval: t1,
            q_end: &b.q,
            t_end: t1,
            force_dq: -sigma,
            force_dv: -sigma * (k.gamma / (k.beta * h)),
            hessian: -sigma,
            lambda: &b.lambda,
            scales: self.scales,
        };
        let parallel = self.parallel.as_deref().expect("parallel assembly");
        parallel.jacobian(self.system, self.layout, &terms, values, |i| {
            sigma * c * inertia[i]
        });
    }
}

impl NewtonProblem for AlphaStepProblem<'_> {
    fn residual(&mut self, r: &mut [f64]) {
        if self.parallel.is_some() {
            return self.residual_parallel(r);
        }
        let (system, layout, sigma, known) = (self.system, self.layout, self.sigma, self.known);
        let t1 = self.t_n + self.h;
        let g = system.gravity();
        let b = &mut *self.buffers;
        for (i, p) in system.particles().iter().enumerate() {
            let (a, v) = known.kinematics(&b.q[i], &self.p[i], &self.w[i]);
            b.v[i] = v;
            let d = layout.dof[i];
            if d != NONE {
                let (a_n, qdd_n) = (self.a_n[i], self.qdd_n[i]);
                for x in 0..3 {
                    r[d + x] = known.inertia_row(
                        sigma,
                        self.inertia[i],
                        p.mass,
                        g[x],
                        a[x],
                        a_n[x],
                        qdd_n[x],
                    );
                }
            }
        }
        let b = &*self.buffers;
        for f in system.forces() {
            let fl = f.force(&b.q, &b.v, t1);
            for (x, &p) in f.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    for y in 0..3 {
                        r[d + y] -= sigma * fl[x][y];
                    }
                }
            }
        }
        let m3 = 3 * layout.free;
        for (c, con) in system.constraints().iter().enumerate() {
            let (phi, grad) = con.residual_and_gradient(&b.q, t1);
            let weight = sigma * b.lambda[c];
            for (x, &p) in con.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    let row = &mut r[d..d + 3];
                    for y in 0..3 {
                        row[y] -= weight * grad[x][y];
                    }
                }
            }
            r[m3 + c] = self.scales[c] * phi;
        }
    }

    fn jacobian(&mut self, values: &mut [f64]) {
        if self.parallel.is_some() {
            return self.jacobian_parallel(values);
        }
        let (system, layout, h, sigma, k) = (self.system, self.layout, self.h, self.sigma, self.k);
        let t1 = self.t_n + h;
        let b = &*self.buffers;
        // sigma c = 1/m_ref: the scaled mass block is M/m_ref.
        let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
        let dv_dq = k.gamma / (k.beta * h);
        for i in 0..system.particles().len() {
            layout.add_to_particle_diagonal(values, i, sigma * c * self.inertia[i]);
        }
        for (fi, f) in system.forces().iter().enumerate() {
            if !f.has_jacobian() {
                continue;
            }
            let mut dq: Jacobian = Default::default();
            let mut dv: Jacobian = Default::default();
            f.add_jacobian(&b.q, &b.v, t1, &mut dq, &mut dv);
            let n = f.particles().len();
            for x in 0..n {
                for y in 0..n {
                    let blk = &layout.force_block[fi][x][y];
                    add_block(values, blk, -sigma, &dq[x][y]);
                    add_block(values, blk, -sigma * dv_dq, &dv[x][y]);
                }
            }
        }
        for (ci, con) in system.constraints().iter().enumerate() {
            let n = con.particles().len();
            let mut hess: [[Mat3; 2]; 2] = Default::default();
            con.add_hessian(&b.q, t1, -sigma * b.lambda[ci], &mut hess);
            let grad = con.gradient(&b.q, t1);
            layout.add_constraint_blocks(values, ci, n, &hess, self.scales[ci], &grad, &grad);
        }
    }

    fn update(&mut self, dx: &[f64]) {
        let b = &mut *self.buffers;
        self.layout
            .apply_increment(&mut b.q, &mut b.lambda, dx, self.scales, self.sigma);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::trapezoidal::tests::{
        assert_jacobian_matches, assert_same_assembly, chain, cloth, every_kind, perturbed_iterate,
        wiggled_iterate,
    };
    use crate::linear::SparseSolver;

    /// The assembled Jacobian equals finite differences of the assembled residual, for every
    /// constraint and force kind, non-zero old accelerations and multipliers, over the range of
    /// rho_inf.
    #[test]
    fn jacobian_matches_finite_differences_of_the_residual() {
        let s = every_kind();
        for rho_inf in [0.0, 0.6, 1.0] {
            for dense_limit in [0, 1000] {
                let mut ws = StepWorkspace::with_solver(&s, dense_limit, SparseSolver::SparseLu);
                let q_n = s.initial_positions();
                let v_n = s.initial_velocities();
                let a_n: Vec<Vec3> = (0..q_n.len())
                    .map(|i| [0.3 * i as f64, -1.0, 0.2])
                    .collect();
                let qdd_n: Vec<Vec3> = (0..q_n.len())
                    .map(|i| [-0.1, 0.4 * i as f64, 0.7])
                    .collect();
                let mut state = AlphaState::new(&a_n);
                state.acceleration = qdd_n;
                perturbed_iterate(&mut ws, &q_n);
                let layout = ws.layout.clone();
                let scheme = GeneralizedAlpha { rho_inf };
                let (mut problem, _) =
                    scheme.problem(&s, &mut ws, &mut state, 0.3, &q_n, &v_n, 0.01);
                assert_jacobian_matches(&mut problem, &layout);
            }
        }
    }

    /// Parallel assembly (forced by a zero threshold) gives the serial residual and Jacobian.
    #[test]
    fn parallel_assembly_matches_serial() {
        for s in [every_kind(), chain(5_000), cloth(50)] {
            let q_n = s.initial_positions();
            let v_n = s.initial_velocities();
            let a_n: Vec<Vec3> = (0..q_n.len())
                .map(|i| [0.3, -1.0, 0.01 * i as f64])
                .collect();
            let qdd_n: Vec<Vec3> = (0..q_n.len())
                .map(|i| [-0.1, 0.4, 0.7 / (1.0 + i as f64)])
                .collect();
            let mut start = AlphaState::new(&a_n);
            start.acceleration = qdd_n;
            let assemble = |parallel: bool| {
                let mut ws = StepWorkspace::new(&s, 48);
                if parallel {
                    ws.assemble_in_parallel_from(&s, 0);
                }
                wiggled_iterate(&mut ws, &q_n);
                let (unknowns, nnz) = (ws.layout.unknowns(), ws.layout.pattern.nnz());
                let mut state = start.clone();
                let scheme = GeneralizedAlpha { rho_inf: 0.6 };
                let (mut problem, _) =
                    scheme.problem(&s, &mut ws, &mut state, 0.3, &q_n, &v_n, 0.01);
                let mut r = vec![0.0; unknowns];
                let mut values = vec![0.0; nnz];
                problem.residual(&mut r);
                problem.jacobian(&mut values);
                (r, values)
            };
            assert_same_assembly(&assemble(false), &assemble(true));
        }
    }

    /// The coefficients of Arnold and Brüls (2007), eqs. for rho_inf = 1 (the trapezoidal-like
    /// Newmark scheme, gamma = 1/2, beta = 1/4) and rho_inf = 0 (alpha_m = -1, gamma = 3/2,
    /// beta = 1), and second-order accuracy gamma = 1/2 + alpha_f - alpha_m in between.
    #[test]
    fn coefficients_at_the_ends_of_the_range() {
        let one = GeneralizedAlpha { rho_inf: 1.0 }.coefficients();
        assert_eq!(
            (one.alpha_m, one.alpha_f, one.gamma, one.beta),
            (0.5, 0.5, 0.5, 0.25)
        );
        let zero = GeneralizedAlpha { rho_inf: 0.0 }.coefficients();
        assert_eq!(
            (zero.alpha_m, zero.alpha_f, zero.gamma, zero.beta),
            (-1.0, 0.0, 1.5, 1.0)
        );
    }
}
