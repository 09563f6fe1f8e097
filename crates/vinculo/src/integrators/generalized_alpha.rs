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
        let k = self.coefficients();
        let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
        let mut problem = AlphaStepProblem {
            system,
            layout: &ws.layout,
            buffers: &mut ws.state,
            scales: &ws.scales,
            inertia: &ws.inertia,
            parallel: ws.parallel.as_mut(),
            q_n,
            v_n,
            a_n: &state.algorithmic,
            qdd_n: &state.acceleration,
            t_n,
            h,
            k,
            sigma: 1.0 / (c * ws.mass_ref),
        };
        let work = LinearWork {
            solver: ws.solver.as_mut(),
            values: &mut ws.values,
            r: &mut ws.r,
            matrix: &mut ws.matrix,
        };
        let report = newton::solve(&mut problem, work, self.matrix_key(h), options)?;
        problem.kinematics();
        let hh = h * h;
        for (i, q) in ws.state.q.iter().enumerate() {
            for x in 0..3 {
                let a_n = state.algorithmic[i][x];
                let a =
                    (q[x] - q_n[i][x] - h * v_n[i][x] - hh * (0.5 - k.beta) * a_n) / (k.beta * hh);
                state.acceleration[i][x] = ((1.0 - k.alpha_m) * a + k.alpha_m * a_n
                    - k.alpha_f * state.acceleration[i][x])
                    / (1.0 - k.alpha_f);
                state.algorithmic[i][x] = a;
            }
        }
        Ok(report)
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
    q_n: &'a [Vec3],
    v_n: &'a [Vec3],
    a_n: &'a [Vec3],
    qdd_n: &'a [Vec3],
    t_n: f64,
    h: f64,
    k: AlphaCoefficients,
    sigma: f64,
}

impl AlphaStepProblem<'_> {
    /// a_{n+1} of coordinate x of particle i at the current iterate.
    fn algorithmic(&self, i: usize, x: usize) -> f64 {
        let q = self.buffers.q[i][x];
        algorithmic(
            q,
            self.q_n[i][x],
            self.v_n[i][x],
            self.a_n[i][x],
            self.h,
            self.k.beta,
        )
    }

    /// The residual on rayon's thread pool (same result as the serial loops, bit for bit).
    fn residual_parallel(&mut self, r: &mut [f64]) {
        let (h, sigma, k) = (self.h, self.sigma, self.k);
        let (q_n, v_n, a_n, qdd_n, inertia) =
            (self.q_n, self.v_n, self.a_n, self.qdd_n, self.inertia);
        let (system, layout) = (self.system, self.layout);
        let b = &mut *self.buffers;
        b.q.par_iter()
            .zip(b.v.par_iter_mut())
            .zip(q_n.par_iter().zip(v_n.par_iter()).zip(a_n.par_iter()))
            .with_min_len(MIN_TASK)
            .for_each(|((q, v), ((q_n, v_n), a_n))| {
                for x in 0..3 {
                    let a = algorithmic(q[x], q_n[x], v_n[x], a_n[x], h, k.beta);
                    v[x] = v_n[x] + h * (1.0 - k.gamma) * a_n[x] + h * k.gamma * a;
                }
            });
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
            let a = algorithmic(b.q[i][x], q_n[i][x], v_n[i][x], a_n[i][x], h, k.beta);
            let qdd = ((1.0 - k.alpha_m) * a + k.alpha_m * a_n[i][x] - k.alpha_f * qdd_n[i][x])
                / (1.0 - k.alpha_f);
            sigma * (inertia[i] * qdd - particles[i].mass * g[x])
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

    /// Updates v_{n+1} from the iterate q.
    fn kinematics(&mut self) {
        let (h, gamma) = (self.h, self.k.gamma);
        for i in 0..self.buffers.q.len() {
            for x in 0..3 {
                let a = self.algorithmic(i, x);
                self.buffers.v[i][x] =
                    self.v_n[i][x] + h * (1.0 - gamma) * self.a_n[i][x] + h * gamma * a;
            }
        }
    }
}

/// a_{n+1} of one coordinate from its iterate q and its old values.
#[inline]
fn algorithmic(q: f64, q_n: f64, v_n: f64, a_n: f64, h: f64, beta: f64) -> f64 {
    (q - q_n - h * v_n - h * h * (0.5 - beta) * a_n) / (beta * h * h)
}

impl NewtonProblem for AlphaStepProblem<'_> {
    fn residual(&mut self, r: &mut [f64]) {
        if self.parallel.is_some() {
            return self.residual_parallel(r);
        }
        self.kinematics();
        let (system, layout, sigma, k) = (self.system, self.layout, self.sigma, self.k);
        let t1 = self.t_n + self.h;
        let g = system.gravity();
        for (i, p) in system.particles().iter().enumerate() {
            let d = layout.dof[i];
            if d != NONE {
                for x in 0..3 {
                    let qdd = ((1.0 - k.alpha_m) * self.algorithmic(i, x)
                        + k.alpha_m * self.a_n[i][x]
                        - k.alpha_f * self.qdd_n[i][x])
                        / (1.0 - k.alpha_f);
                    r[d + x] = sigma * (self.inertia[i] * qdd - p.mass * g[x]);
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
            let grad = con.gradient(&b.q, t1);
            for (x, &p) in con.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    for y in 0..3 {
                        r[d + y] -= sigma * grad[x][y] * b.lambda[c];
                    }
                }
            }
            r[m3 + c] = self.scales[c] * con.residual(&b.q, t1);
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
            let blk = &layout.particle_block[i];
            if blk[0] != NONE {
                let m = sigma * c * self.inertia[i];
                for x in 0..3 {
                    values[blk[4 * x]] += m;
                }
            }
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
                let scheme = GeneralizedAlpha { rho_inf };
                let k = scheme.coefficients();
                let h = 0.01;
                let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
                perturbed_iterate(&mut ws, &q_n);
                let mut problem = AlphaStepProblem {
                    system: &s,
                    layout: &ws.layout,
                    buffers: &mut ws.state,
                    scales: &ws.scales,
                    inertia: &ws.inertia,
                    parallel: None,
                    q_n: &q_n,
                    v_n: &v_n,
                    a_n: &a_n,
                    qdd_n: &qdd_n,
                    t_n: 0.3,
                    h,
                    k,
                    sigma: 1.0 / (c * ws.mass_ref),
                };
                assert_jacobian_matches(&mut problem, &ws.layout);
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
            let k = GeneralizedAlpha { rho_inf: 0.6 }.coefficients();
            let h = 0.01;
            let c = (1.0 - k.alpha_m) / ((1.0 - k.alpha_f) * k.beta * h * h);
            let assemble = |parallel: bool| {
                let mut ws = StepWorkspace::new(&s, 48);
                if parallel {
                    ws.assemble_in_parallel_from(&s, 0);
                }
                wiggled_iterate(&mut ws, &q_n);
                let mut problem = AlphaStepProblem {
                    system: &s,
                    layout: &ws.layout,
                    buffers: &mut ws.state,
                    scales: &ws.scales,
                    inertia: &ws.inertia,
                    parallel: ws.parallel.as_mut(),
                    q_n: &q_n,
                    v_n: &v_n,
                    a_n: &a_n,
                    qdd_n: &qdd_n,
                    t_n: 0.3,
                    h,
                    k,
                    sigma: 1.0 / (c * ws.mass_ref),
                };
                let mut r = vec![0.0; ws.layout.unknowns()];
                let mut values = vec![0.0; ws.layout.pattern.nnz()];
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
