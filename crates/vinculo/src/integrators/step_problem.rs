//! The one index-3 step problem: the nonlinear system of one step of any time rule on the
//! index-3 DAE, in Newton's scaled unknowns (q_{n+1}, lambda_{n+1} sigma / s).
//!
//! # Design
//!
//! The residual, the Jacobian, their parallel variants and the update are written once here and
//! parametrised by the rule's per-step object ([`Index3Rule`], see `rule.rs`) and the step's
//! [`StepPoint`] ([`TimeRule::point`]: t_e, t_{n+1} and the scale sigma of the dynamics rows,
//! built by [`StepPoint::new`] as for the GGL step): the rule says how the iterate q becomes
//! v_{n+1} and the evaluation point (q_e, v_e), what the inertia row and the mass block are, and
//! with which weights df/dq, df/dv and the constraint Hessians enter; the step problem applies
//! sigma. Every step starts from a [`StepStart`] (t_n, q_n, v_n, h), the one argument the step
//! functions of both step problems and of the run loop pass on. [`StepProblem`] is generic over it, so each rule gets its own monomorphised loops (no
//! dynamic dispatch per particle). Placing the elements' local values and derivatives is the
//! assembler's job (`assembly/`): the serial loops ([`Layout::residual`], [`Layout::jacobian`])
//! and the parallel ones ([`ParallelAssembly`]) read the same [`ResidualTerms`] and
//! [`JacobianTerms`] built here.
//!
//! Line nodes whose axial added mass differs from their normal one add C_i(q_e) qdd_i to their
//! inertia rows, qdd_i the rule's own acceleration (its inertia row with unit inertia and no
//! gravity), once for every rule (`assembly/axial_added_mass.rs`).
//!
//! The equations, their scaling and the Jacobian with its Hessian term are derived in
//! `docs/theory/formulation.md` and `docs/theory/newton.md`; each rule's module documentation
//! (`trapezoidal.rs`, `generalized_alpha.rs`, `docs/theory/time-rules.md`) gives its kinematics.

use rayon::prelude::*;

use super::newton::{self, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem, NewtonReport};
use super::rule::{Index3Rule, RuleState, StepPoint, StepStart, TimeRule};
use super::workspace::{StepBuffers, StepWorkspace};
use crate::assembly::{
    AxialAddedMass, BlockVisit, InertiaRows, JacobianTerms, Layout, ParallelAssembly,
    ResidualTerms, MIN_TASK,
};
use crate::math::Vec3;
use crate::model::System;

/// One index-3 step's nonlinear problem, for the rule step `R`.
pub struct StepProblem<'a, R: Index3Rule> {
    system: &'a System,
    layout: &'a Layout,
    buffers: &'a mut StepBuffers,
    scales: &'a [f64],
    inertia: &'a [f64],
    mass: &'a [f64],
    axial: &'a AxialAddedMass,
    parallel: Option<&'a mut ParallelAssembly>,
    reads_velocities: bool,
    point: StepPoint,
    rule: R,
}

impl<'a, R: Index3Rule> StepProblem<'a, R> {
    /// The problem of the rule step `rule` ([`TimeRule::index3`]) at `point`
    /// ([`TimeRule::point`]) on the workspace's buffers (the iterate and multipliers in
    /// `ws.state`), and the linear solver's share of the workspace.
    pub fn new(
        system: &'a System,
        ws: &'a mut StepWorkspace,
        (start, point): (&StepStart, StepPoint),
        rule: R,
    ) -> (Self, LinearWork<'a>) {
        for (k, con) in system.constraints().iter().enumerate() {
            if con.is_compliant() {
                ws.state.start_phi[k] = con.residual(start.q_n, start.t_n);
            }
        }
        let problem = StepProblem {
            system,
            layout: &ws.layout,
            buffers: &mut ws.state,
            scales: &ws.scales,
            inertia: &ws.inertia,
            mass: &ws.mass,
            axial: &ws.axial_added_mass,
            parallel: ws.parallel.as_mut(),
            reads_velocities: ws.reads_velocities,
            point,
            rule,
        };
        let work = LinearWork::new(&mut ws.solver, &mut ws.values, &mut ws.r, &mut ws.matrix);
        (problem, work)
    }

    /// Updates v_{n+1} (and the evaluation point, where the rule has one of its own) from the
    /// iterate q: on rayon's pool where the assembly is parallel.
    pub fn kinematics(&mut self) {
        if self.parallel.is_some() {
            self.kinematics_parallel();
        } else {
            self.kinematics_serial();
        }
    }

    /// [`StepProblem::kinematics`] on this thread.
    fn kinematics_serial(&mut self) {
        let b = &mut *self.buffers;
        self.rule
            .kinematics_all(&b.q, &mut b.v, (&mut b.q_eval, &mut b.v_eval));
    }

    /// [`StepProblem::kinematics`] on rayon's thread pool (the same numbers).
    fn kinematics_parallel(&mut self) {
        let rule = &self.rule;
        let b = &mut *self.buffers;
        if R::AT_END {
            b.q.par_iter()
                .zip(b.v.par_iter_mut())
                .enumerate()
                .with_min_len(MIN_TASK)
                .for_each(|(i, (q, v))| *v = rule.kinematics(i, q).0);
        } else if self.reads_velocities {
            b.q.par_iter()
                .zip(b.v.par_iter_mut())
                .zip(b.q_eval.par_iter_mut().zip(b.v_eval.par_iter_mut()))
                .enumerate()
                .with_min_len(MIN_TASK)
                .for_each(|(i, ((q, v), (qe, ve)))| (*v, *qe, *ve) = rule.kinematics(i, q));
        } else {
            // No element reads the evaluation point's velocities (`StepWorkspace::reads_velocities`).
            b.q.par_iter()
                .zip(b.v.par_iter_mut().zip(b.q_eval.par_iter_mut()))
                .enumerate()
                .with_min_len(MIN_TASK)
                .for_each(|(i, (q, (v, qe)))| (*v, *qe, _) = rule.kinematics(i, q));
        }
    }

    /// Assembles the scaled Jacobian at the current iterate into `values` (zeroed by the
    /// caller), at the layout's slots.
    fn assemble_jacobian(&self, values: &mut [f64]) {
        let b = &*self.buffers;
        let (q_eval, _) = Self::eval_point(b);
        let rule = &self.rule;
        let point = self.point;
        let (force_dq, force_dv, hessian) = rule.weights(point.sigma);
        let terms = JacobianTerms {
            point: Self::residual_terms(b, (rule, point), self.scales),
            force_dq,
            force_dv,
            hessian,
        };
        let inertia = self.inertia;
        let mass = |i: usize| rule.mass_diagonal(point.sigma, inertia[i]);
        match self.parallel.as_deref() {
            Some(parallel) => parallel.jacobian(self.system, self.layout, &terms, values, mass),
            None => self.layout.jacobian(self.system, &terms, values, mass),
        }
        if !self.axial.is_empty() {
            let layout = self.layout;
            let diagonal = |i| layout.particle_block.get(i);
            let force_row = |k, n, f: &mut BlockVisit| {
                let pairs = layout.force_offsets.pairs(k);
                layout.force_block.with(k, pairs.start..pairs.start + n, f)
            };
            let weights = (q_eval, rule.mass_diagonal(point.sigma, 1.0), force_dq);
            let qdd = |i: usize| acceleration(rule, b, i);
            self.axial
                .add_jacobian(values, (diagonal, force_row), weights, qdd);
        }
    }

    /// Where the step's residual is evaluated, and its weights, from the buffers `b`: the
    /// evaluation point and the step's end, the scales of the rows and the multipliers (also
    /// the point of its Jacobian).
    fn residual_terms<'b>(
        b: &'b StepBuffers,
        (rule, point): (&R, StepPoint),
        scales: &'b [f64],
    ) -> ResidualTerms<'b> {
        let (q_eval, v_eval) = Self::eval_point(b);
        ResidualTerms {
            q_eval,
            v_eval,
            t_eval: point.t_eval,
            q_end: &b.q,
            t_end: point.t_end,
            sigma: point.sigma,
            lambda: &b.lambda,
            scales,
            end_weight: -rule.weights(point.sigma).2 / point.sigma,
            start_phi: &b.start_phi,
            slack: R::SLACK,
        }
    }

    /// Positions and velocities of the evaluation point in the buffers `b`.
    fn eval_point(b: &StepBuffers) -> (&[Vec3], &[Vec3]) {
        if R::AT_END {
            (&b.q, &b.v)
        } else {
            (&b.q_eval, &b.v_eval)
        }
    }
}

impl<R: Index3Rule> NewtonProblem for StepProblem<'_, R> {
    /// [`index3_step`] updates the velocities from the returned positions.
    fn stops_on_increment(&self) -> bool {
        true
    }

    fn residual(&mut self, r: &mut [f64]) {
        self.kinematics();
        let b = &*self.buffers;
        let (q_eval, _) = Self::eval_point(b);
        let (rule, point) = (&self.rule, self.point);
        let terms = Self::residual_terms(b, (rule, point), self.scales);
        let (system, layout, inertia) = (self.system, self.layout, self.inertia);
        let g = system.gravity();
        let row = Rows {
            rule,
            sigma: point.sigma,
            q: &b.q,
            v: &b.v,
            inertia,
            mass: self.mass,
            g,
        };
        match self.parallel.as_deref_mut() {
            Some(parallel) => parallel.residual(system, layout, &terms, r, &row),
            None => layout.residual(system, &terms, r, &row),
        }
        if !self.axial.is_empty() {
            // sigma C_i(q_e) qdd_i (`assembly/axial_added_mass.rs`), after the elements: the
            // serial and parallel residuals stay equal bit for bit.
            let qdd = |i: usize| acceleration(rule, b, i);
            self.axial
                .add_rows(&layout.dof, r, (q_eval, point.sigma), qdd);
        }
    }

    fn jacobian(&mut self, values: &mut [f64]) {
        self.assemble_jacobian(values);
    }

    fn update(&mut self, dx: &[f64]) {
        let b = &mut *self.buffers;
        let (scales, sigma) = (self.scales, self.point.sigma);
        if self.parallel.is_some() {
            self.layout
                .apply_increment_parallel(&mut b.q, &mut b.lambda, dx, scales, sigma);
        } else {
            self.layout
                .apply_increment(&mut b.q, &mut b.lambda, dx, scales, sigma);
        }
    }

    /// `ROUND_OFF_ULPS eps max_i sum_j |J_ij| |x_j|` over the scaled unknowns: positions (m) and
    /// multipliers `lambda sigma / s`, with J the matrix `values` in the pattern's order; a
    /// matrix assembled into the solver's storage (which holds its factors by now) is assembled
    /// again at the iterate, into an array of its own read through [`Layout::moved_to`] (0 when
    /// the pattern's structure was released).
    fn round_off(&self, values: &[f64]) -> f64 {
        let (pattern, moved) = (&self.layout.pattern, &self.layout.moved_to);
        if pattern.is_released() {
            return 0.0;
        }
        let again;
        let matrix: &[f64] = if !moved.is_empty() {
            let len = moved.iter().max().map_or(0, |&s| s as usize + 1);
            let mut assembled = vec![0.0; len];
            self.assemble_jacobian(&mut assembled);
            again = assembled;
            &again
        } else if values.len() == pattern.nnz() {
            values
        } else {
            return 0.0;
        };
        let at = |k: usize| {
            if moved.is_empty() {
                k
            } else {
                moved[k] as usize
            }
        };
        let b = &*self.buffers;
        let mut x = vec![0.0; pattern.n];
        let (scales, sigma) = (self.scales, self.point.sigma);
        self.layout
            .scaled_unknowns(&b.q, &b.lambda, scales, sigma, &mut x);
        let mut rows = vec![0.0f64; pattern.n];
        for (row, col, k) in pattern.entries() {
            rows[row] += matrix[at(k)].abs() * x[col].abs();
        }
        let largest = rows.iter().fold(0.0f64, |m, r| m.max(*r));
        super::newton::ROUND_OFF_ULPS * f64::EPSILON * largest
    }

    fn round_off_reach(&self) -> f64 {
        R::ROUND_OFF_REACH
    }

    /// The scaled unknowns ([`Layout::scaled_unknowns`]).
    fn iterate(&self, x: &mut Vec<f64>) -> bool {
        let b = &*self.buffers;
        x.resize(self.layout.unknowns(), 0.0);
        let (scales, sigma) = (self.scales, self.point.sigma);
        self.layout
            .scaled_unknowns(&b.q, &b.lambda, scales, sigma, x);
        true
    }

    fn distance_from(&self, x: &[f64], cap: f64) -> f64 {
        let b = &*self.buffers;
        let scaling = (self.scales, self.point.sigma);
        if self.parallel.is_some() {
            self.layout
                .unknowns_distance_parallel((&b.q, &b.lambda), scaling, x, cap)
        } else {
            self.layout
                .unknowns_distance((&b.q, &b.lambda), scaling, x, cap)
        }
    }
}

/// The acceleration qdd_i(q) of particle i at the iterate in `b` that the rule's inertia row
/// multiplies by the inertia (the row with unit inertia and no gravity).
#[inline]
fn acceleration<R: Index3Rule>(rule: &R, b: &StepBuffers, i: usize) -> Vec3 {
    rule.inertia_row(i, &b.q[i], &b.v[i], 1.0, 0.0, &[0.0; 3])
}

/// The scaled inertia and gravity rows of a step of the rule step `R` at the current iterate.
struct Rows<'b, R> {
    rule: &'b R,
    sigma: f64,
    q: &'b [Vec3],
    v: &'b [Vec3],
    inertia: &'b [f64],
    mass: &'b [f64],
    g: Vec3,
}

impl<R: Index3Rule> InertiaRows for Rows<'_, R> {
    #[inline(always)]
    fn rows(&self, i: usize) -> Vec3 {
        let (q, v) = (&self.q[i], &self.v[i]);
        let row = self
            .rule
            .inertia_row(i, q, v, self.inertia[i], self.mass[i], &self.g);
        row.map(|x| self.sigma * x)
    }
}

/// Takes one index-3 step of `rule` from `start` and `state` (the rule's state). The caller
/// sets the predictor in `ws.state.q` and `ws.state.lambda`; on success they hold q_{n+1} and
/// lambda_{n+1}, `ws.state.v` holds v_{n+1} and `state` the rule's new state. On failure the
/// rule's carried state (its accelerations) is unchanged.
pub fn index3_step<T: TimeRule>(
    rule: T,
    system: &System,
    ws: &mut StepWorkspace,
    start: StepStart,
    state: &mut RuleState,
    options: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    let h = start.h;
    let report = {
        let point = rule.point(&start, ws.mass_ref);
        let step = rule.index3(state, start);
        let (mut problem, work) = StepProblem::new(system, ws, (&start, point), step);
        let report = newton::solve(&mut problem, work, rule.matrix_key(h), options)?;
        problem.kinematics();
        report
    };
    rule.advance(state, h, &ws.state.q);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::{
        assert_jacobian_matches, assert_same_assembly, chain, cloth, every_kind, line_in_water,
        perturbed_iterate, wiggled_iterate,
    };
    use crate::integrators::{GeneralizedAlpha, GeneralizedTrapezoidal};
    use crate::linear::SparseSolver;

    /// A workspace whose matrix is assembled in the pattern's order (read by its entries, as
    /// the checks below do), with the sparse solver `solver`.
    fn gathered(s: &System, dense_limit: usize, solver: SparseSolver) -> StepWorkspace {
        super::super::workspace::tests::in_pattern_order(|| {
            StepWorkspace::with_solver(s, dense_limit, solver)
        })
    }

    /// The residual and Jacobian of a step of `rule` (h = 0.01 from t_n = 0.3) at the
    /// workspace's iterate.
    /// The parallel assembly of `rule`'s step gives the serial one's residual and Jacobian at a
    /// wiggled iterate.
    fn assert_parallel_assembly_is_serial<T: TimeRule + Copy>(s: &System, rule: T) {
        let q_n = s.initial_positions();
        let run = |parallel: bool| {
            let mut ws = gathered(s, 48, SparseSolver::Auto);
            if parallel {
                ws.assemble_in_parallel_from(s, 0);
            }
            wiggled_iterate(&mut ws, &q_n);
            let mut state = alpha_state(q_n.len());
            assemble(rule, s, &mut ws, &mut state)
        };
        assert_same_assembly(&run(false), &run(true));
    }

    fn assemble<T: TimeRule>(
        rule: T,
        s: &System,
        ws: &mut StepWorkspace,
        state: &mut RuleState,
    ) -> (Vec<f64>, Vec<f64>) {
        let (q_n, v_n) = (s.initial_positions(), s.initial_velocities());
        let (unknowns, nnz) = (ws.layout.unknowns(), ws.layout.pattern.nnz());
        let (mut problem, _) = problem_at(rule, s, ws, state, start(&q_n, &v_n));
        let mut r = vec![0.0; unknowns];
        let mut values = vec![0.0; nnz];
        problem.residual(&mut r);
        problem.jacobian(&mut values);
        (r, values)
    }

    /// The Jacobian of a step of `rule` (h = 0.01 from the system's initial state) at the
    /// iterate of `ws` equals central finite differences of its residual.
    fn assert_step_jacobian_matches<T: TimeRule>(
        s: &System,
        mut ws: StepWorkspace,
        rule: T,
        state: &mut RuleState,
    ) {
        let (q_n, v_n) = (s.initial_positions(), s.initial_velocities());
        let layout = ws.layout.clone();
        let (mut problem, _) = problem_at(rule, s, &mut ws, state, start(&q_n, &v_n));
        assert_jacobian_matches(&mut problem, &layout);
    }

    /// The problem of the step of `rule` from `start` and `state`.
    fn problem_at<'a, T: TimeRule>(
        rule: T,
        s: &'a System,
        ws: &'a mut StepWorkspace,
        state: &'a mut RuleState,
        start: StepStart<'a>,
    ) -> (StepProblem<'a, T::Step<'a>>, LinearWork<'a>) {
        let point = rule.point(&start, ws.mass_ref);
        StepProblem::new(s, ws, (&start, point), rule.index3(state, start))
    }

    /// The step of size h = 0.01 from (t_n = 0.3, q_n, v_n).
    fn start<'a>(q_n: &'a [Vec3], v_n: &'a [Vec3]) -> StepStart<'a> {
        StepStart::new(0.3, q_n, v_n, 0.01)
    }

    /// Generalised-alpha's state with non-zero old accelerations.
    fn alpha_state(n: usize) -> RuleState {
        let a_n: Vec<Vec3> = (0..n).map(|i| [0.3, -1.0, 0.01 * i as f64]).collect();
        let mut state = RuleState::new(&a_n);
        state.acceleration = (0..n)
            .map(|i| [-0.1, 0.4, 0.7 / (1.0 + i as f64)])
            .collect();
        state
    }

    /// A chain's matrix assembled into the elimination's storage (the default, with the
    /// pattern's structure kept) gives the round-off of the residual that the same matrix in
    /// the pattern's order gives, bit for bit (the same sums of the same entries, read through
    /// `Layout::moved_to`), and not zero: a line in water and a chain at a wiggled iterate.
    #[test]
    fn round_off_reads_a_matrix_assembled_in_place() {
        for (name, s) in [("line in water", line_in_water()), ("chain", chain(40))] {
            let (q_n, v_n) = (s.initial_positions(), s.initial_velocities());
            let round_off = |mut ws: StepWorkspace| {
                wiggled_iterate(&mut ws, &q_n);
                let mut state = alpha_state(q_n.len());
                let rule = GeneralizedAlpha::new(0.6);
                let (mut problem, work) =
                    problem_at(rule, &s, &mut ws, &mut state, start(&q_n, &v_n));
                problem.residual(work.r);
                let jacobian = |values: &mut [f64]| problem.jacobian(values);
                crate::linear::assemble_and_factor(work.solver, work.values, jacobian).unwrap();
                problem.round_off(work.values)
            };
            let ws = StepWorkspace::new(&s, 48);
            assert!(
                ws.solver.in_place() && !ws.layout.moved_to.is_empty(),
                "{name}"
            );
            let (in_place, gathered) = (
                round_off(ws),
                round_off(gathered(&s, 48, SparseSolver::Auto)),
            );
            assert!(in_place > 0.0, "{name}");
            assert_eq!(
                in_place.to_bits(),
                gathered.to_bits(),
                "{name}: {in_place:e} {gathered:e}"
            );
        }
    }

    /// Parallel assembly (forced by a zero threshold) gives the serial residual and Jacobian,
    /// on a chain and a cloth large enough to be split among threads, on the system with
    /// every constraint and force kind and on a line in water (whose node elements the serial
    /// residual places on their node alone, the parallel one on all three particles, zero on
    /// the neighbours), for the trapezoidal rule (alpha = 0.6) and generalised-alpha
    /// (rho_inf = 0.6).
    #[test]
    fn parallel_assembly_matches_serial() {
        for (name, s) in [
            ("every kind", every_kind()),
            ("chain", chain(5_000)),
            ("cloth", cloth(50)),
            ("line in water", line_in_water()),
        ] {
            let q_n = s.initial_positions();
            let run = |parallel: bool, trapezoidal: bool| {
                let mut ws = gathered(&s, 48, SparseSolver::Auto);
                if parallel {
                    ws.assemble_in_parallel_from(&s, 0);
                    let colours = ws.parallel.as_ref().unwrap().constraint_colours();
                    assert!(colours >= 1 && (name != "chain" || colours == 2), "{name}");
                }
                wiggled_iterate(&mut ws, &q_n);
                let mut state = alpha_state(q_n.len());
                if trapezoidal {
                    assemble(
                        GeneralizedTrapezoidal { alpha: 0.6 },
                        &s,
                        &mut ws,
                        &mut state,
                    )
                } else {
                    assemble(GeneralizedAlpha::new(0.6), &s, &mut ws, &mut state)
                }
            };
            for trapezoidal in [true, false] {
                assert_same_assembly(&run(false, trapezoidal), &run(true, trapezoidal));
            }
        }
    }

    /// A fixed anchor and two free particles, moving, of the elastic chains below.
    fn chain_particles(s: &mut System) -> [crate::model::ParticleId; 3] {
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s
            .add_particle(0.7, [0.5, 0.1, -0.2], [0.3, 0.1, 0.0], false)
            .unwrap();
        let c = s
            .add_particle(1.3, [0.9, -0.1, -0.4], [-0.2, 0.4, 0.1], false)
            .unwrap();
        [a, b, c]
    }

    /// An elastic chain: a fixed anchor, three free particles, segments of EA = 2e3 N (one
    /// paid out by a winch law), and one inextensible elastic segment (EA = infinity).
    fn elastic_chain() -> System {
        use crate::laws::Law;
        let mut s = System::new([0.1, -0.2, -9.81]);
        let [a, b, c] = chain_particles(&mut s);
        let d = s
            .add_particle(0.4, [1.2, 0.6, -0.1], [0.0, -0.3, 0.5], false)
            .unwrap();
        s.add_elastic_distance(a, b, (Law::Constant(0.5), 1.0), 2e3)
            .unwrap();
        let winch = Law::polynomial(vec![0.45, 0.1, -0.05]).unwrap();
        s.add_elastic_distance(b, c, (winch, 1.0), 2e3).unwrap();
        s.add_elastic_distance(c, d, (Law::Constant(0.8), 1.0), f64::INFINITY)
            .unwrap();
        s
    }

    /// The elastic chain's first two segments able to go slack, the first one longer (0.7 m)
    /// than its particles' distance (0.55 m): slack, the second stretched.
    fn slack_chain() -> System {
        use crate::laws::Law;
        use crate::model::ConstraintId;
        let mut s = System::new([0.1, -0.2, -9.81]);
        let [a, b, c] = chain_particles(&mut s);
        let slack = s
            .add_elastic_distance(a, b, (Law::Constant(0.7), 1.0), 2e3)
            .unwrap();
        let taut = s
            .add_elastic_distance(b, c, (Law::Constant(0.45), 1.0), 2e3)
            .unwrap();
        for k in [slack, taut] {
            s.set_slack(ConstraintId(k.0)).unwrap();
        }
        s
    }

    /// A slack segment's row is c lambda alone (no position terms), a stretched one's the
    /// compliant row: the Jacobian equals finite differences of the residual in both states,
    /// for both rules, with the sparse LU's and the tree elimination's layouts.
    #[test]
    fn slack_segments_jacobian_matches_finite_differences() {
        let solvers = [(0, SparseSolver::SparseLu), (0, SparseSolver::Auto)];
        assert_compliant_jacobians_match(&slack_chain(), 2, &solvers);
    }

    /// For each layout in `solvers`, the Jacobian of a chain of compliant segments with its
    /// first `multipliers` multipliers non-zero against finite differences of the residual,
    /// for the trapezoidal rule (alpha = 0.6) and generalised-alpha (rho_inf = 0.6).
    fn assert_compliant_jacobians_match(
        s: &System,
        multipliers: usize,
        solvers: &[(usize, SparseSolver)],
    ) {
        let (q_n, v_n) = (s.initial_positions(), s.initial_velocities());
        for &(dense_limit, solver) in solvers {
            let workspace = || {
                let mut ws = gathered(s, dense_limit, solver);
                perturbed_iterate(&mut ws, &q_n);
                ws.state.lambda.truncate(multipliers);
                ws
            };
            let mut ws = workspace();
            let layout = ws.layout.clone();
            let mut state = RuleState::new(&q_n);
            let rule = GeneralizedTrapezoidal { alpha: 0.6 };
            let (mut problem, _) = problem_at(rule, s, &mut ws, &mut state, start(&q_n, &v_n));
            assert_jacobian_matches(&mut problem, &layout);
            let mut ws = workspace();
            let mut state = alpha_state(q_n.len());
            let rule = GeneralizedAlpha::new(0.6);
            let (mut problem, _) = problem_at(rule, s, &mut ws, &mut state, start(&q_n, &v_n));
            assert_jacobian_matches(&mut problem, &layout);
        }
    }

    /// The serial residual hands springs', bending's and line elements' forces over directly
    /// and lets a node's hydrodynamics and seabed contact share its tangent
    /// (`Force::for_each_acting`); the parallel one reads each element's local rows. The two
    /// are equal bit for bit on a line in a current lying partly on a seabed with anisotropic
    /// friction, with internal damping and bending stiffness.
    #[test]
    fn line_elements_assemble_as_their_local_rows() {
        use crate::forces::{Force, SeabedFriction};
        use crate::model::{ParticleId, SeabedSpec};
        let mut s = line_in_water();
        let n = s.particles().len();
        let system = s.id();
        let id = |index: usize| ParticleId { system, index };
        // The seabed 0.55 m up: the anchor and the first and last free nodes touch it.
        let spec = SeabedSpec {
            depth: -0.55,
            grid: None,
            diameter: 0.05,
            length: 0.9,
            stiffness: 3e6,
            damping: 3e5,
            damping_ramp: 0.0,
            friction: SeabedFriction {
                transverse: 1.0,
                axial: Some(0.5),
                damping: 200.0,
                static_scale: 1.0,
            },
        };
        for i in 0..n {
            let tangent = match i {
                0 => (id(0), id(1)),
                _ if i == n - 1 => (id(i - 1), id(i)),
                _ => (id(i - 1), id(i + 1)),
            };
            s.add_seabed_contact(id(i), Some(tangent), &spec).unwrap();
        }
        for i in 0..n - 1 {
            s.add_spring_damper(id(i), id(i + 1), 0.0, 40.0, None)
                .unwrap();
        }
        for i in 1..n - 1 {
            s.add_bending(id(i - 1), id(i), id(i + 1), 50.0, None)
                .unwrap();
        }
        let (q, v) = (s.initial_positions(), s.initial_velocities());
        let touching = s.forces().iter().filter(|f| match f {
            Force::SeabedContact(c) => c.node_force(&q, &v) != [0.0; 3],
            _ => false,
        });
        assert_eq!(touching.count(), 3);
        assert_parallel_assembly_is_serial(&s, GeneralizedTrapezoidal { alpha: 0.6 });
        assert_parallel_assembly_is_serial(&s, GeneralizedAlpha::new(0.6));
    }

    /// The Jacobian with compliant rows (the compliance on the multipliers' diagonal, a winch's
    /// time-dependent compliance) equals finite differences of the residual, for both rules, with
    /// the sparse LU's layout, dense storage and the tree elimination's layout; and the parallel
    /// assembly gives the serial one.
    #[test]
    fn elastic_segments_jacobian_matches_finite_differences() {
        let s = elastic_chain();
        let solvers = [
            (0, SparseSolver::SparseLu),
            (1000, SparseSolver::SparseLu),
            (0, SparseSolver::Auto),
        ];
        assert_compliant_jacobians_match(&s, 3, &solvers);
        assert_parallel_assembly_is_serial(&s, GeneralizedTrapezoidal { alpha: 0.6 });
    }

    /// Segments along tension-strain curves (`constraints/strain_curve.rs`): their rows'
    /// compliance is L e'(lambda) at the multiplier (0.8 N on the curve's second piece, -1.2 N
    /// beyond its first point), and the Jacobian equals finite differences of the residual,
    /// stretched and slack, with the sparse LU's and the tree elimination's layouts.
    #[test]
    fn nonlinear_segments_jacobian_matches_finite_differences() {
        use crate::constraints::StrainCurve;
        use crate::model::ConstraintId;
        let curve = std::sync::Arc::new(
            StrainCurve::new(vec![0.0, 1e-4, 5e-4], vec![0.0, 0.5, 3.0]).unwrap(),
        );
        for mut s in [elastic_chain(), slack_chain()] {
            for c in 0..2 {
                s.set_strain_curve(ConstraintId(c), curve.clone()).unwrap();
            }
            let solvers = [(0, SparseSolver::SparseLu), (0, SparseSolver::Auto)];
            assert_compliant_jacobians_match(&s, s.constraints().len(), &solvers);
            assert_parallel_assembly_is_serial(&s, GeneralizedTrapezoidal { alpha: 0.6 });
        }
    }

    /// The assembled Jacobian equals finite differences of the assembled residual, for a system
    /// with every constraint and force kind, fixed particles and non-zero multipliers (and, for
    /// generalised-alpha, non-zero old accelerations), over the range of each rule's parameter,
    /// with the general sparse LU's layout and dense storage.
    #[test]
    fn jacobian_matches_finite_differences_of_the_residual() {
        let s = every_kind();
        let q_n = s.initial_positions();
        for dense_limit in [0, 1000] {
            let workspace = || {
                let mut ws = gathered(&s, dense_limit, SparseSolver::SparseLu);
                perturbed_iterate(&mut ws, &q_n);
                ws
            };
            for alpha in [0.6, 1.0] {
                let mut state = RuleState::new(&q_n);
                let rule = GeneralizedTrapezoidal { alpha };
                assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
            }
            for rho_inf in [0.0, 0.6, 1.0] {
                let a_n: Vec<Vec3> = (0..q_n.len())
                    .map(|i| [0.3 * i as f64, -1.0, 0.2])
                    .collect();
                let mut state = RuleState::new(&a_n);
                state.acceleration = (0..q_n.len())
                    .map(|i| [-0.1, 0.4 * i as f64, 0.7])
                    .collect();
                let rule = GeneralizedAlpha::new(rho_inf);
                assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
            }
        }
    }

    /// The Jacobian with the line nodes' axial added-mass correction (C_i = -(Ca - CaAx) rho V
    /// t t^T at the evaluation point, times the rule's acceleration; Ca != CaAx on every node,
    /// CaAx > Ca on one) equals central finite differences of the residual, on a line of five
    /// free nodes, for the trapezoidal rule (alpha = 0.6, 1) and generalised-alpha
    /// (rho_inf = 0, 0.6), with the sparse LU's layout, dense storage and the tree
    /// elimination's layout; and the parallel assembly gives the serial one.
    #[test]
    fn axial_added_mass_jacobian_matches_finite_differences() {
        let s = line_in_water();
        assert_eq!(StepWorkspace::new(&s, 48).axial_added_mass.len(), 6);
        let q_n = s.initial_positions();
        let solvers = [
            (0, SparseSolver::SparseLu),
            (1000, SparseSolver::SparseLu),
            (0, SparseSolver::Auto),
        ];
        for (dense_limit, solver) in solvers {
            let workspace = || {
                let mut ws = gathered(&s, dense_limit, solver);
                perturbed_iterate(&mut ws, &q_n);
                ws
            };
            for alpha in [0.6, 1.0] {
                let mut state = RuleState::new(&q_n);
                let rule = GeneralizedTrapezoidal { alpha };
                assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
            }
            for rho_inf in [0.0, 0.6] {
                let mut state = alpha_state(q_n.len());
                let rule = GeneralizedAlpha::new(rho_inf);
                assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
            }
        }
        assert_parallel_assembly_is_serial(&s, GeneralizedAlpha::new(0.6));
    }

    /// The Jacobian of a chain of two four-particle rigid bodies, hinged to the ground and to
    /// each other by revolute joints (equations over points of the bodies: a coincidence of
    /// points, whose Hessian is zero and hands over no blocks, and the axes' dot products,
    /// whose Hessian does), moving and turning, equals central finite differences of the
    /// residual for the trapezoidal rule and generalised-alpha, with the sparse LU's and the
    /// dense layout; and the parallel assembly gives the serial one.
    #[test]
    fn jacobian_with_joints_between_bodies_matches_finite_differences() {
        use crate::model::{JointKind, RigidBodySpec};
        let mut s = System::new([0.0, 0.0, -9.81]);
        let inertia = [[0.02, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.06]];
        let spec = |centre: Vec3, spin: Vec3| RigidBodySpec {
            mass: 1.5,
            centre,
            inertia,
            velocity: [0.1, -0.2, 0.3],
            angular_velocity: spin,
            ..RigidBodySpec::default()
        };
        let a = s
            .add_rigid_tetrahedron(&spec([0.25, 0.0, 0.0], [0.2, 1.0, -0.1]))
            .unwrap();
        let b = s
            .add_rigid_tetrahedron(&spec([0.75, 0.02, 0.0], [-0.3, 0.6, 0.2]))
            .unwrap();
        let hinge = JointKind::Revolute;
        s.add_joint(hinge, (&[], &a.particles), [0.0; 3], [0.0, 1.0, 0.0])
            .unwrap();
        s.add_joint(
            hinge,
            (&a.particles, &b.particles),
            [0.5, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        )
        .unwrap();
        let q_n = s.initial_positions();
        for dense_limit in [0, 1000] {
            // An iterate off the step's start and every multiplier non-zero (each Hessian
            // weighted).
            let workspace = || {
                let mut ws = gathered(&s, dense_limit, SparseSolver::SparseLu);
                let (q, lambda) = (&mut ws.state.q, &mut ws.state.lambda);
                for (i, (x, x_n)) in q.iter_mut().zip(&q_n).enumerate() {
                    let i = i as f64;
                    *x = [
                        x_n[0] + 0.003 * i,
                        x_n[1] - 0.002,
                        x_n[2] + 0.001 * (i % 3.0),
                    ];
                }
                for (k, l) in lambda.iter_mut().enumerate() {
                    *l = 0.3 * (k as f64 + 1.0).sin();
                }
                ws
            };
            let mut state = RuleState::new(&q_n);
            let rule = GeneralizedTrapezoidal { alpha: 0.6 };
            assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
            let mut state = alpha_state(q_n.len());
            let rule = GeneralizedAlpha::new(0.6);
            assert_step_jacobian_matches(&s, workspace(), rule, &mut state);
        }
        assert_parallel_assembly_is_serial(&s, GeneralizedAlpha::new(0.6));
    }

    /// Closed form: a node of mass m between two fixed neighbours on the x axis, in water
    /// without gravity nor drag, displaced by d from rest in one backward-Euler step
    /// (qdd = d/h^2): its scaled residual is sigma (m + CaAx rho V) d_x / h^2 along the line
    /// and sigma (m + Ca rho V) d_y / h^2 across it (MoorDyn's node mass matrix
    /// m I + rho V (Ca (I - t t^T) + CaAx t t^T), t = x).
    #[test]
    fn axial_added_mass_makes_the_inertia_along_the_line_m_plus_caax_rho_v() {
        let (s, _, rho_v) = crate::integrators::fixtures::line_node_between_fixed_neighbours();
        let (q_n, v_n) = (s.initial_positions(), s.initial_velocities());
        let mut ws = StepWorkspace::new(&s, 48);
        let d = [0.002, -0.003, 0.001];
        ws.state.q = q_n.clone();
        ws.state.q[1] = d;
        let mut state = RuleState::new(&q_n);
        let rule = GeneralizedTrapezoidal { alpha: 1.0 };
        let h = 0.01;
        let sigma = h * h / ws.mass_ref;
        let (mut problem, _) = problem_at(rule, &s, &mut ws, &mut state, start(&q_n, &v_n));
        let mut r = vec![0.0; 3];
        problem.residual(&mut r);
        let expected = [
            sigma * (3.0 + 0.25 * rho_v) * d[0] / (h * h),
            sigma * (3.0 + rho_v) * d[1] / (h * h),
            sigma * (3.0 + rho_v) * d[2] / (h * h),
        ];
        for k in 0..3 {
            assert!(
                (r[k] - expected[k]).abs() < 1e-13 * expected[k].abs(),
                "{r:?} vs {expected:?}"
            );
        }
    }
}
