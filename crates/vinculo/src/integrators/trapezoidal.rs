//! The generalised trapezoidal rule (paper eq. 24) on the index-3 DAE (paper eq. 21).
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
//! and Newton runs on (q, lambda) (formulation.md, "Linear solves"). The Jacobian is
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

use super::newton::{
    self, IterationMatrix, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport,
};
use rayon::prelude::*;

use crate::assembly::{
    add_block, JacobianTerms, Layout, ParallelAssembly, ResidualTerms, MIN_TASK, NONE,
};
use crate::forces::Jacobian;
use crate::linear::{for_layout, LinearSolver, SparseSolver, TreeElimination};
use crate::math::{Mat3, Vec3};
use crate::model::System;

/// The scheme and its parameter alpha in [1/2, 1] (1/2: trapezoidal, 1: backward Euler).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedTrapezoidal {
    /// Weight of the new state in the evaluation point.
    pub alpha: f64,
}

/// Patterns with more entries than this (about 100,000 chain links) are released once the
/// solver has analysed them (see [`crate::assembly::Pattern::release_structure`]).
pub const RELEASE_PATTERN_ABOVE: usize = 1 << 22;

/// Matrices, solver and buffers reused by every step of a run (no allocation per step).
pub struct StepWorkspace {
    /// Unknown numbering, pattern and slots.
    pub layout: Layout,
    /// The factorisation of the iteration matrix.
    pub solver: Box<dyn LinearSolver>,
    /// What that factorisation is (for modified Newton) and how many were made.
    pub matrix: IterationMatrix,
    /// Matrix values in pattern order.
    pub values: Vec<f64>,
    /// Residual / increment.
    pub r: Vec<f64>,
    /// The new state and evaluation-point buffers.
    pub state: StepBuffers,
    /// Reference mass used in the scaling (mean mass of the free particles).
    pub mass_ref: f64,
    /// Inertia of each particle's translation: its mass plus any added mass of fluid elements
    /// (the diagonal of M, constant over the run). Gravity acts on the mass alone.
    pub inertia: Vec<f64>,
    /// s_k of each constraint.
    pub scales: Vec<f64>,
    /// Colouring and buffers of parallel assembly, when the model is large enough for it to
    /// pay (see [`StepWorkspace::assemble_in_parallel_from`]); `None`: serial assembly.
    pub parallel: Option<ParallelAssembly>,
}

/// Per-particle arrays of a step.
#[derive(Debug, Clone)]
pub struct StepBuffers {
    /// q_{n+1} (the Newton iterate).
    pub q: Vec<Vec3>,
    /// v_{n+1}.
    pub v: Vec<Vec3>,
    /// Multipliers.
    pub lambda: Vec<f64>,
    q_alpha: Vec<Vec3>,
    v_alpha: Vec<Vec3>,
}

impl StepWorkspace {
    /// Analyses the system once (solver chosen automatically).
    pub fn new(system: &System, dense_limit: usize) -> StepWorkspace {
        StepWorkspace::with_solver(system, dense_limit, SparseSolver::Auto)
    }

    /// Analyses the system once, with the given choice of sparse solver.
    pub fn with_solver(system: &System, dense_limit: usize, sparse: SparseSolver) -> StepWorkspace {
        // Tree-shaped constraint graphs get the tree elimination at every size (on a pendulum
        // or a 10-link chain it is 3x faster than the dense LU); the dense LU serves small
        // graphs with loops, the sparse LU large ones.
        let tree = match sparse {
            SparseSolver::Auto => {
                let layout = Layout::new(system, 0);
                TreeElimination::analyse(&layout.pattern, 3 * layout.free)
                    .map(|tree| (layout, Box::new(tree) as Box<dyn LinearSolver>))
            }
            SparseSolver::SparseLu => None,
        };
        let (mut layout, solver) = tree.unwrap_or_else(|| {
            let layout = Layout::new(system, dense_limit);
            let solver = for_layout(&layout.pattern, 3 * layout.free, SparseSolver::SparseLu);
            (layout, solver)
        });
        // Assembly uses the slot tables only: large models free the pattern's index arrays.
        if layout.pattern.nnz() > RELEASE_PATTERN_ABOVE {
            layout.pattern.release_structure();
        }
        let n = system.particles().len();
        let free: Vec<f64> = system
            .particles()
            .iter()
            .filter(|p| !p.fixed)
            .map(|p| p.mass)
            .collect();
        let mass_ref = if free.is_empty() {
            1.0
        } else {
            free.iter().sum::<f64>() / free.len() as f64
        };
        StepWorkspace {
            values: vec![0.0; layout.pattern.nnz()],
            r: vec![0.0; layout.unknowns()],
            solver,
            matrix: IterationMatrix::default(),
            state: StepBuffers {
                q: vec![[0.0; 3]; n],
                v: vec![[0.0; 3]; n],
                lambda: vec![0.0; layout.constraints],
                q_alpha: vec![[0.0; 3]; n],
                v_alpha: vec![[0.0; 3]; n],
            },
            scales: system.constraints().iter().map(|c| c.scale()).collect(),
            mass_ref,
            inertia: system.inertia(),
            layout,
            parallel: None,
        }
    }

    /// Assembles residuals and Jacobians on rayon's thread pool when the model has at least
    /// `threshold` free particles, serially otherwise (`usize::MAX`: always serially). The
    /// colouring this needs is computed here, once. Models with user force or constraint groups
    /// always assemble serially (their elements read a shared cache, see [`crate::user`]).
    pub fn assemble_in_parallel_from(&mut self, system: &System, threshold: usize) {
        self.parallel = (self.layout.free >= threshold && !system.has_user_groups())
            .then(|| ParallelAssembly::new(system, &self.layout));
    }
}

/// One step's nonlinear problem.
pub struct StepProblem<'a> {
    system: &'a System,
    layout: &'a Layout,
    buffers: &'a mut StepBuffers,
    scales: &'a [f64],
    inertia: &'a [f64],
    parallel: Option<&'a mut ParallelAssembly>,
    q_n: &'a [Vec3],
    v_n: &'a [Vec3],
    t_n: f64,
    h: f64,
    alpha: f64,
    sigma: f64,
}

/// The rule's kinematic relations with the divisions done once per step:
/// v_a = (q - q_n)/h, v_{n+1} = (v_a - (1 - alpha) v_n)/alpha, q_a = (1 - alpha) q_n + alpha q.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    alpha: f64,
    inv_h: f64,
    inv_alpha: f64,
}

impl Kinematics {
    fn new(alpha: f64, h: f64) -> Kinematics {
        Kinematics {
            alpha,
            inv_h: 1.0 / h,
            inv_alpha: 1.0 / alpha,
        }
    }

    /// (v_{n+1}, q_a, v_a) of one particle from its iterate q and (q_n, v_n).
    #[inline(always)]
    fn of(&self, q: &Vec3, q_n: &Vec3, v_n: &Vec3) -> (Vec3, Vec3, Vec3) {
        let a = self.alpha;
        let va: Vec3 = std::array::from_fn(|k| (q[k] - q_n[k]) * self.inv_h);
        let v = std::array::from_fn(|k| (va[k] - (1.0 - a) * v_n[k]) * self.inv_alpha);
        let qa = std::array::from_fn(|k| (1.0 - a) * q_n[k] + a * q[k]);
        (v, qa, va)
    }
}

impl StepProblem<'_> {
    /// Updates v_{n+1}, q_a, v_a from the iterate q.
    fn kinematics(&mut self) {
        let rule = Kinematics::new(self.alpha, self.h);
        let b = &mut *self.buffers;
        for i in 0..b.q.len() {
            (b.v[i], b.q_alpha[i], b.v_alpha[i]) = rule.of(&b.q[i], &self.q_n[i], &self.v_n[i]);
        }
    }

    fn t_alpha(&self) -> f64 {
        self.t_n + self.alpha * self.h
    }

    /// The residual on rayon's thread pool (same result as the serial loops, bit for bit).
    fn residual_parallel(&mut self, r: &mut [f64]) {
        let (a, h, sigma) = (self.alpha, self.h, self.sigma);
        let (q_n, v_n, inertia) = (self.q_n, self.v_n, self.inertia);
        let (system, layout) = (self.system, self.layout);
        let ta = self.t_alpha();
        let b = &mut *self.buffers;
        let rule = Kinematics::new(a, h);
        b.q.par_iter()
            .zip(b.v.par_iter_mut())
            .zip(b.v_alpha.par_iter_mut())
            .zip(b.q_alpha.par_iter_mut())
            .zip(q_n.par_iter().zip(v_n.par_iter()))
            .with_min_len(MIN_TASK)
            .for_each(|((((q, v), v_alpha), q_alpha), (q_n, v_n))| {
                (*v, *q_alpha, *v_alpha) = rule.of(q, q_n, v_n);
            });
        let b = &*self.buffers;
        let g = system.gravity();
        let particles = system.particles();
        let terms = ResidualTerms {
            q_eval: &b.q_alpha,
            v_eval: &b.v_alpha,
            t_eval: ta,
            q_end: &b.q,
            t_end: self.t_n + h,
            sigma,
            lambda: &b.lambda,
            scales: self.scales,
        };
        let parallel = self.parallel.as_deref_mut().expect("parallel assembly");
        let inv_h = 1.0 / h;
        parallel.residual(system, layout, &terms, r, |i, k| {
            sigma * (inertia[i] * ((b.v[i][k] - v_n[i][k]) * inv_h) - particles[i].mass * g[k])
        });
    }

    /// The Jacobian on rayon's thread pool (equal to the serial one to round-off).
    fn jacobian_parallel(&mut self, values: &mut [f64]) {
        let (a, h, sigma, inertia) = (self.alpha, self.h, self.sigma, self.inertia);
        let b = &*self.buffers;
        let terms = JacobianTerms {
            q_eval: &b.q_alpha,
            v_eval: &b.v_alpha,
            t_eval: self.t_alpha(),
            q_end: &b.q,
            t_end: self.t_n + h,
            force_dq: -sigma * a,
            force_dv: -sigma / h,
            hessian: -sigma * a,
            lambda: &b.lambda,
            scales: self.scales,
        };
        let parallel = self.parallel.as_deref().expect("parallel assembly");
        parallel.jacobian(self.system, self.layout, &terms, values, |i| {
            sigma * inertia[i] / (a * h * h)
        });
    }
}

impl NewtonProblem for StepProblem<'_> {
    fn residual(&mut self, r: &mut [f64]) {
        if self.parallel.is_some() {
            return self.residual_parallel(r);
        }
        self.kinematics();
        let (system, layout, h, sigma) = (self.system, self.layout, self.h, self.sigma);
        let ta = self.t_alpha();
        let g = system.gravity();
        let b = &*self.buffers;
        let inv_h = 1.0 / h;
        for (i, p) in system.particles().iter().enumerate() {
            let d = layout.dof[i];
            if d != NONE {
                for k in 0..3 {
                    r[d + k] = sigma
                        * (self.inertia[i] * ((b.v[i][k] - self.v_n[i][k]) * inv_h)
                            - p.mass * g[k]);
                }
            }
        }
        for f in system.forces() {
            let fl = f.force(&b.q_alpha, &b.v_alpha, ta);
            for (x, &p) in f.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    for k in 0..3 {
                        r[d + k] -= sigma * fl[x][k];
                    }
                }
            }
        }
        let t1 = self.t_n + h;
        let m3 = 3 * layout.free;
        for (c, con) in system.constraints().iter().enumerate() {
            let grad = con.gradient(&b.q_alpha, ta);
            let weight = sigma * b.lambda[c];
            for (x, &p) in con.particles().iter().enumerate() {
                let d = layout.dof[p];
                if d != NONE {
                    let row = &mut r[d..d + 3];
                    for k in 0..3 {
                        row[k] -= weight * grad[x][k];
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
        let (system, layout, h, a, sigma) =
            (self.system, self.layout, self.h, self.alpha, self.sigma);
        let ta = self.t_alpha();
        let t1 = self.t_n + h;
        let b = &*self.buffers;
        for i in 0..system.particles().len() {
            layout.add_to_particle_diagonal(values, i, sigma * self.inertia[i] / (a * h * h));
        }
        for (fi, f) in system.forces().iter().enumerate() {
            if !f.has_jacobian() {
                continue;
            }
            let mut dq: Jacobian = Default::default();
            let mut dv: Jacobian = Default::default();
            f.add_jacobian(&b.q_alpha, &b.v_alpha, ta, &mut dq, &mut dv);
            let n = f.particles().len();
            for x in 0..n {
                for y in 0..n {
                    let blk = &layout.force_block[fi][x][y];
                    add_block(values, blk, -sigma * a, &dq[x][y]);
                    add_block(values, blk, -sigma / h, &dv[x][y]);
                }
            }
        }
        for (c, con) in system.constraints().iter().enumerate() {
            let n = con.particles().len();
            let mut hess: [[Mat3; 2]; 2] = Default::default();
            con.add_hessian(&b.q_alpha, ta, -sigma * a * b.lambda[c], &mut hess);
            let grad_a = con.gradient(&b.q_alpha, ta);
            let grad_1 = con.gradient(&b.q, t1);
            layout.add_constraint_blocks(values, c, n, &hess, self.scales[c], &grad_a, &grad_1);
        }
    }

    fn update(&mut self, dx: &[f64]) {
        let b = &mut *self.buffers;
        self.layout
            .apply_increment(&mut b.q, &mut b.lambda, dx, self.scales, self.sigma);
    }
}

impl GeneralizedTrapezoidal {
    /// Order of accuracy of the positions: 2 for alpha = 1/2, otherwise 1.
    pub fn order(&self) -> usize {
        if (self.alpha - 0.5).abs() < 1e-12 {
            2
        } else {
            1
        }
    }

    /// What identifies the iteration matrix of a step of size `h` (for its reuse).
    pub fn matrix_key(&self, h: f64) -> [f64; 2] {
        [h, self.alpha]
    }

    /// Takes one step of size `h` from (t_n, q_n, v_n). The caller sets the predictor in
    /// `ws.state.q` and `ws.state.lambda`; on success they hold q_{n+1}, lambda and `ws.state.v`
    /// holds v_{n+1}.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &self,
        system: &System,
        ws: &mut StepWorkspace,
        t_n: f64,
        q_n: &[Vec3],
        v_n: &[Vec3],
        h: f64,
        options: &NewtonOptions,
    ) -> Result<NewtonReport, NewtonFailure> {
        let sigma = self.alpha * h * h / ws.mass_ref;
        let mut problem = StepProblem {
            system,
            layout: &ws.layout,
            buffers: &mut ws.state,
            scales: &ws.scales,
            inertia: &ws.inertia,
            parallel: ws.parallel.as_mut(),
            q_n,
            v_n,
            t_n,
            h,
            alpha: self.alpha,
            sigma,
        };
        let work = LinearWork {
            solver: ws.solver.as_mut(),
            values: &mut ws.values,
            r: &mut ws.r,
            matrix: &mut ws.matrix,
        };
        let report = newton::solve(&mut problem, work, self.matrix_key(h), options)?;
        problem.kinematics();
        Ok(report)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::laws::{Law, VectorLaw};

    /// A system with every constraint and force kind, fixed particles, added mass and
    /// time-dependent laws.
    pub(crate) fn every_kind() -> System {
        let mut s = System::new([0.1, -0.2, -9.81]);
        let a = s
            .add_particle(1.0, [0.0, 0.0, 0.0], [0.0; 3], true)
            .unwrap();
        let b = s
            .add_particle(0.7, [0.5, 0.1, -0.2], [0.3, 0.1, 0.0], false)
            .unwrap();
        let c = s
            .add_particle(1.3, [0.9, -0.1, -0.4], [-0.2, 0.4, 0.1], false)
            .unwrap();
        let d = s
            .add_particle(0.4, [0.2, 0.6, 0.1], [0.0, -0.3, 0.5], false)
            .unwrap();
        s.add_distance(a, b, None).unwrap();
        s.add_distance(b, c, None).unwrap();
        let point = VectorLaw([
            Law::sine(0.1, 0.7, 0.0, 0.0, 0.0, 0.0).unwrap(),
            Law::Constant(0.6),
            Law::Constant(0.5),
        ]);
        s.add_distance_to_point(d, point, None).unwrap();
        s.add_plane(
            c,
            VectorLaw::constant([0.0, 0.3, 1.0]),
            VectorLaw::constant([0.9, -0.1, -0.4]),
        )
        .unwrap();
        s.add_fixed_coordinate(d, 0, None).unwrap();
        s.add_spring_damper(c, d, 40.0, 1.5, Some(0.5)).unwrap();
        s.add_quadratic_drag(b, 0.8).unwrap();
        s.add_linear_drag(c, 0.3).unwrap();
        // Fluid forces with added mass (which enters the mass matrix) on a constrained particle.
        s.add_morison(
            b,
            crate::forces::MorisonSpec {
                density: 1000.0,
                volume: 2e-4,
                area: 0.01,
                drag_coefficient: 0.4,
                added_mass_coefficient: 0.5,
                fluid: VectorLaw([
                    Law::sine(0.05, 0.9, 0.0, 0.0, 0.5, 0.0).unwrap(),
                    Law::Constant(0.0),
                    Law::Constant(0.0),
                ]),
            },
        )
        .unwrap();
        s.add_force(
            d,
            VectorLaw([
                Law::Constant(1.0),
                Law::sine(2.0, 1.0, 0.0, 0.0, 0.0, 0.0).unwrap(),
                Law::Constant(0.0),
            ]),
        )
        .unwrap();

        s
    }

    /// Asserts that the problem's assembled Jacobian equals central finite differences of its
    /// residual, column by column, at the current iterate (which it leaves unchanged).
    pub(crate) fn assert_jacobian_matches(problem: &mut impl NewtonProblem, layout: &Layout) {
        assert_pattern_jacobian_matches(problem, &layout.pattern);
    }

    /// [`assert_jacobian_matches`] for any problem whose matrix has the given pattern.
    pub(crate) fn assert_pattern_jacobian_matches(
        problem: &mut impl NewtonProblem,
        pattern: &crate::assembly::Pattern,
    ) {
        let n = pattern.n;
        let mut r = vec![0.0; n];
        problem.residual(&mut r); // refreshes the evaluation point
        let mut values = vec![0.0; pattern.nnz()];
        problem.jacobian(&mut values);
        let mut dense = vec![vec![0.0; n]; n];
        for col in 0..n {
            for k in pattern.col_ptr[col]..pattern.col_ptr[col + 1] {
                dense[pattern.row_idx[k]][col] += values[k];
            }
        }
        let eps = 1e-7;
        for col in 0..n {
            let mut dx = vec![0.0; n];
            dx[col] = -eps; // update() subtracts
            let mut rp = vec![0.0; n];
            let mut rm = vec![0.0; n];
            problem.update(&dx);
            problem.residual(&mut rp);
            dx[col] = 2.0 * eps;
            problem.update(&dx);
            problem.residual(&mut rm);
            dx[col] = -eps;
            problem.update(&dx);
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * eps);
                assert!(
                    (fd - dense[row][col]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "J[{row}][{col}] = {} but finite differences give {fd}",
                    dense[row][col]
                );
            }
        }
    }

    /// A perturbed iterate off the constraints, and non-zero multipliers.
    pub(crate) fn perturbed_iterate(ws: &mut StepWorkspace, q_n: &[Vec3]) {
        ws.state.q = q_n
            .iter()
            .enumerate()
            .map(|(i, x)| {
                if i == 0 {
                    *x
                } else {
                    [x[0] + 0.01, x[1] - 0.02 * i as f64, x[2] + 0.005]
                }
            })
            .collect();
        ws.state.lambda = vec![0.8, -1.2, 0.5, 2.0, -0.7];
    }

    /// A horizontal chain of `n` point masses (0.1 m links, 0.1 kg) from a fixed anchor.
    pub(crate) fn chain(n: usize) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        for i in 1..=n {
            let p = s
                .add_particle(0.1, [0.1 * i as f64, 0.0, 0.0], [0.0; 3], false)
                .unwrap();
            s.add_distance(prev, p, None).unwrap();
            prev = p;
        }
        s
    }

    /// An `n` x `n` cloth: a square grid of point masses hung from its two top corners, linked
    /// to their row and column neighbours by distance constraints (a constraint graph full of
    /// loops) and along the diagonals by spring-dampers (two-particle forces), with drag on
    /// every particle (one-particle forces).
    pub(crate) fn cloth(n: usize) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        let mut id = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let fixed = j == 0 && (i == 0 || i == n - 1);
                let x = [0.1 * i as f64, 0.01 * (i * j % 7) as f64, -0.1 * j as f64];
                id.push(s.add_particle(0.05, x, [0.0, 0.2, 0.0], fixed).unwrap());
            }
        }
        for j in 0..n {
            for i in 0..n {
                let p = id[j * n + i];
                if i + 1 < n {
                    s.add_distance(p, id[j * n + i + 1], None).unwrap();
                }
                if j + 1 < n {
                    s.add_distance(p, id[(j + 1) * n + i], None).unwrap();
                }
                if i + 1 < n && j + 1 < n {
                    s.add_spring_damper(p, id[(j + 1) * n + i + 1], 30.0, 0.2, None)
                        .unwrap();
                }
                s.add_quadratic_drag(p, 0.01).unwrap();
            }
        }
        s
    }

    /// An iterate off the constraints with non-zero multipliers, for any system.
    pub(crate) fn wiggled_iterate(ws: &mut StepWorkspace, q_n: &[Vec3]) {
        for (i, (q, x)) in ws.state.q.iter_mut().zip(q_n).enumerate() {
            let u = i as f64;
            *q = [
                x[0] + 0.01 * (0.7 * u).sin(),
                x[1] - 0.02 * (1.3 * u).cos(),
                x[2] + 0.005 * (0.3 * u).sin(),
            ];
        }
        for (k, l) in ws.state.lambda.iter_mut().enumerate() {
            *l = 1.5 * (0.9 * k as f64).sin() - 0.2;
        }
    }

    /// Asserts that the parallel residuals are the serial ones bit for bit, and the Jacobians
    /// equal to 1e-14 (relative to the entry, or to 1 for small entries: the scaled matrix's
    /// entries are O(1)).
    pub(crate) fn assert_same_assembly(
        serial: &(Vec<f64>, Vec<f64>),
        parallel: &(Vec<f64>, Vec<f64>),
    ) {
        assert_eq!(serial.0.len(), parallel.0.len());
        for (i, (s, p)) in serial.0.iter().zip(&parallel.0).enumerate() {
            assert_eq!(
                s.to_bits(),
                p.to_bits(),
                "residual {i}: serial {s}, parallel {p}"
            );
        }
        assert_eq!(serial.1.len(), parallel.1.len());
        for (k, (s, p)) in serial.1.iter().zip(&parallel.1).enumerate() {
            assert!(
                (s - p).abs() <= 1e-14 * s.abs().max(1.0),
                "Jacobian slot {k}: serial {s}, parallel {p}"
            );
        }
    }

    /// Parallel assembly (forced by a zero threshold) gives the serial residual and Jacobian,
    /// on a chain and a cloth large enough to be split among threads and on the system with
    /// every constraint and force kind.
    #[test]
    fn parallel_assembly_matches_serial() {
        for (name, s) in [
            ("every kind", every_kind()),
            ("chain", chain(5_000)),
            ("cloth", cloth(50)),
        ] {
            let q_n = s.initial_positions();
            let v_n = s.initial_velocities();
            let assemble = |parallel: bool| {
                let mut ws = StepWorkspace::new(&s, 48);
                if parallel {
                    ws.assemble_in_parallel_from(&s, 0);
                    let colours = ws.parallel.as_ref().unwrap().constraint_colours();
                    assert!(colours >= 1 && (name != "chain" || colours == 2), "{name}");
                }
                wiggled_iterate(&mut ws, &q_n);
                let (h, alpha) = (0.01, 0.6);
                let mut problem = StepProblem {
                    system: &s,
                    layout: &ws.layout,
                    buffers: &mut ws.state,
                    scales: &ws.scales,
                    inertia: &ws.inertia,
                    parallel: ws.parallel.as_mut(),
                    q_n: &q_n,
                    v_n: &v_n,
                    t_n: 0.3,
                    h,
                    alpha,
                    sigma: alpha * h * h / ws.mass_ref,
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

    /// The assembled Jacobian equals finite differences of the assembled residual, for a system
    /// with every constraint and force kind, fixed particles and non-zero multipliers.
    #[test]
    fn jacobian_matches_finite_differences_of_the_residual() {
        let s = every_kind();
        for dense_limit in [0, 1000] {
            // The general sparse LU's layout (dense storage for dense_limit 1000).
            let mut ws = StepWorkspace::with_solver(&s, dense_limit, SparseSolver::SparseLu);
            let q_n = s.initial_positions();
            let v_n = s.initial_velocities();
            let (h, alpha) = (0.01, 0.6);
            let sigma = alpha * h * h / ws.mass_ref;
            perturbed_iterate(&mut ws, &q_n);
            let mut problem = StepProblem {
                system: &s,
                layout: &ws.layout,
                buffers: &mut ws.state,
                scales: &ws.scales,
                inertia: &ws.inertia,
                parallel: None,
                q_n: &q_n,
                v_n: &v_n,
                t_n: 0.3,
                h,
                alpha,
                sigma,
            };
            assert_jacobian_matches(&mut problem, &ws.layout);
        }
    }
}
