//! The matrices, solver and buffers that every index-3 step of a run reuses, whatever its time
//! rule (allocated once per run; no allocation per step).

use crate::assembly::{AxialAddedMass, Layout, ParallelAssembly};
use crate::linear::{for_layout, LinearSolver, SparseSolver, TreeElimination};
use crate::math::Vec3;
use crate::model::System;

use super::newton::IterationMatrix;

/// Patterns with more entries than this (about 100,000 chain links) are released once the
/// solver has analysed them (see [`crate::assembly::Pattern::release_structure`]) and their
/// slot tables' periodic runs compressed ([`Layout::compress_slots`]).
pub const RELEASE_PATTERN_ABOVE: usize = 1 << 22;

/// The release threshold, and whether tree eliminations are assembled in place (chains at every
/// size, the other trees above the threshold; tests set them for a thread, to run small models
/// as large ones or to keep the matrix in the pattern's order).
fn assembly_settings() -> (usize, bool) {
    #[cfg(test)]
    if let Some(set) = tests::RELEASE.with(|r| r.get()) {
        return set;
    }
    (RELEASE_PATTERN_ABOVE, true)
}

/// Another length from which a chain's tree elimination takes both ends than the analysis'
/// [`crate::linear::TWO_SIDED_FROM`]: tests set one for a thread, to run short chains as long
/// ones (None otherwise).
fn two_sided_override() -> Option<usize> {
    #[cfg(test)]
    return tests::TWO_SIDED.with(|r| r.get());
    #[cfg(not(test))]
    None
}

/// Matrices, solver and buffers reused by every step of a run (no allocation per step).
pub struct StepWorkspace {
    /// Unknown numbering, pattern and slots.
    pub layout: Layout,
    /// The factorisation of the iteration matrix.
    pub solver: Box<dyn LinearSolver>,
    /// What that factorisation is (for modified Newton) and how many were made.
    pub matrix: IterationMatrix,
    /// Matrix values in pattern order (empty when the solver factorises in place: the matrix
    /// is assembled into its storage, see [`crate::linear::assemble_and_factor`]).
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
    /// Each particle's mass, on which gravity acts: the residual's rows read it from this
    /// compact copy rather than from the particles' records (64 bytes each, of which the mass
    /// is 8; a residual of a chain of 10^5 particles on one thread 2.16 -> 1.90 ms, criterion's
    /// `assembly` group: see `docs/guide/benchmarks.md`).
    pub mass: Vec<f64>,
    /// The axial correction of the line nodes' added mass (CaAx != Ca), added to the mass
    /// blocks at each step's evaluation point (`assembly/axial_added_mass.rs`).
    pub axial_added_mass: AxialAddedMass,
    /// s_k of each constraint.
    pub scales: Vec<f64>,
    /// Colouring and buffers of parallel assembly, when the model is large enough for it to
    /// pay (see [`StepWorkspace::assemble_in_parallel_from`]); `None`: serial assembly.
    pub parallel: Option<ParallelAssembly>,
    /// Whether any element reads the velocities of the evaluation point (a force, a damped
    /// segment, a user group): without one, a rule with an evaluation point of its own
    /// (the trapezoidal rule) does not write them on rayon's pool, a third of the writes of
    /// its kinematics at each residual (the swinging chain of 10^6 particles: see
    /// `docs/guide/benchmarks.md`).
    pub reads_velocities: bool,
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
    /// Phi_k(q_n, t_n) of each compliant constraint at the step's start (0 for the others).
    pub start_phi: Vec<f64>,
    /// Positions of the evaluation point of forces and constraint gradients (rules that
    /// evaluate them at the step's end leave it unused).
    pub q_eval: Vec<Vec3>,
    /// Velocities of the evaluation point.
    pub v_eval: Vec<Vec3>,
}

/// Copies `values` into a workspace's `own` and factorises them with `solver`: false when they
/// are not of its pattern (another length) or do not factorise.
pub(crate) fn refactor(own: &mut [f64], solver: &mut dyn LinearSolver, values: &[f64]) -> bool {
    own.len() == values.len() && {
        own.copy_from_slice(values);
        solver.factor(own).is_ok()
    }
}

impl StepWorkspace {
    /// The last iteration matrix factorised, for a snapshot: its values in the pattern's order
    /// (false), or the factors of a solver that factorised it in place (true); None when
    /// neither is at hand (a factorisation in place made by the fallback).
    pub(crate) fn matrix_record(&self) -> Option<(Vec<f64>, bool)> {
        if self.solver.in_place() {
            self.solver.factors().map(|f| (f, true))
        } else {
            Some((self.values.clone(), false))
        }
    }

    /// Factorises the iteration matrix `values` again (`factored`: takes the factors a
    /// solver in place gave); false when they are not of this workspace's pattern (another
    /// length) or do not factorise.
    pub(crate) fn refactor(&mut self, values: &[f64], factored: bool) -> bool {
        match (factored, self.solver.in_place()) {
            (true, _) => self.solver.adopt_factors(values),
            // A solver in place gathers a matrix in the pattern's order too.
            (false, true) => {
                values.len() == self.layout.pattern.nnz() && self.solver.factor(values).is_ok()
            }
            (false, false) => refactor(&mut self.values, self.solver.as_mut(), values),
        }
    }

    /// Analyses the system once (solver chosen automatically).
    pub fn new(system: &System, dense_limit: usize) -> StepWorkspace {
        StepWorkspace::with_solver(system, dense_limit, SparseSolver::Auto)
    }

    /// Analyses the system once, with the given choice of sparse solver.
    pub fn with_solver(system: &System, dense_limit: usize, sparse: SparseSolver) -> StepWorkspace {
        // Tree-shaped constraint graphs get the tree elimination at every size (on a pendulum
        // or a 10-link chain it is 3x faster than the dense LU); the dense LU serves small
        // graphs with loops, the sparse LU large ones.
        let (above, in_place) = assembly_settings();
        let tree = match sparse {
            SparseSolver::Auto => {
                let mut layout = Layout::new(system, 0);
                TreeElimination::analyse(&layout.pattern, 3 * layout.free).map(|mut tree| {
                    if let Some(from) = two_sided_override() {
                        tree.two_sided_from(from);
                    }
                    // Chains whose blocks couple with their parent alone are assembled into
                    // the elimination's own storage, whose layout is the blocks': no matrix in
                    // the pattern's order is kept nor gathered from at each factorisation (a
                    // step of a swinging chain of 1,000 particles 235-238 -> 204-209 us, of
                    // 10^4 3.06-3.09 -> 2.68-2.72 ms, of 10^5 42-43 -> 27 ms: its elimination
                    // from both ends gathered every block on one thread first). Trees with
                    // fill (a line's bending) keep the matrix in the pattern's order below the
                    // release threshold: held, it gives Newton's round-off floor, which a
                    // matrix factorised in place has to assemble again (a cable of 1,000
                    // segments at 0.1 s steps, at its floor at every step, took 0.49 s in
                    // place against 0.39-0.40 s). A large pattern's structure is released
                    // first; a small one's is kept, to read the matrix by its entries where it
                    // is needed (`Layout::moved_to`).
                    let large = layout.pattern.nnz() > above;
                    if in_place && (large || tree.coupled_ancestors() <= 1) {
                        if large {
                            layout.pattern.release_structure();
                        }
                        layout.move_slots(&tree.assemble_in_place());
                    }
                    (layout, Box::new(tree) as Box<dyn LinearSolver>)
                })
            }
            SparseSolver::SparseLu => None,
        };
        let (mut layout, solver) = tree.unwrap_or_else(|| {
            let layout = Layout::new(system, dense_limit);
            let solver = for_layout(&layout.pattern, 3 * layout.free, SparseSolver::SparseLu);
            (layout, solver)
        });
        // Assembly uses the slot tables only: large models free the pattern's index arrays,
        // and keep the slots of a chain's elements as periodic runs.
        if layout.pattern.nnz() > above {
            layout.pattern.release_structure();
            layout.compress_slots();
        }
        let entries = if solver.in_place() {
            0
        } else {
            layout.pattern.nnz()
        };
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
            values: vec![0.0; entries],
            r: vec![0.0; layout.unknowns()],
            solver,
            matrix: IterationMatrix::default(),
            state: StepBuffers {
                q: vec![[0.0; 3]; n],
                v: vec![[0.0; 3]; n],
                lambda: vec![0.0; layout.constraints],
                start_phi: vec![0.0; layout.constraints],
                q_eval: vec![[0.0; 3]; n],
                v_eval: vec![[0.0; 3]; n],
            },
            scales: system.constraints().iter().map(|c| c.scale()).collect(),
            mass_ref,
            inertia: system.inertia(),
            mass: system.particles().iter().map(|p| p.mass).collect(),
            axial_added_mass: AxialAddedMass::new(system),
            layout,
            parallel: None,
            reads_velocities: !system.forces().is_empty()
                || system.constraints().iter().any(|c| {
                    c.damped_segment().is_some()
                        || matches!(c, crate::constraints::Constraint::User(_))
                }),
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::integrators::fixtures::{awkward_chain, chain};
    use crate::laws::Law;
    use crate::run::Snapshot;
    use crate::statics::{point_stiffness, solve_statics, StaticsOptions};
    use crate::{Simulation, SimulationOptions, Solution};
    use std::cell::Cell;

    thread_local! {
        /// The release threshold and in-place switch of this thread's workspaces (None: the
        /// defaults, [`RELEASE_PATTERN_ABOVE`] and trees in place).
        pub(crate) static RELEASE: Cell<Option<(usize, bool)>> = const { Cell::new(None) };
        /// The length from which this thread's chains are eliminated from both ends (None:
        /// [`crate::linear::TWO_SIDED_FROM`]).
        pub(crate) static TWO_SIDED: Cell<Option<usize>> = const { Cell::new(None) };
    }

    /// `f` with workspaces that release every pattern (and compress the slot tables'
    /// periodic runs), and assemble trees in place or not (None: workspaces that release
    /// nothing and assemble every matrix in the pattern's order, the plain tables).
    fn released<T>(in_place: Option<bool>, f: impl FnOnce() -> T) -> T {
        let set = in_place.map_or((usize::MAX, false), |p| (0, p));
        RELEASE.with(|r| r.set(Some(set)));
        let out = f();
        RELEASE.with(|r| r.set(None));
        out
    }

    /// `f` with workspaces that assemble every matrix in the pattern's order (the Jacobian
    /// read by the pattern's entries, as the finite-difference checks do).
    pub(crate) fn in_pattern_order<T>(f: impl FnOnce() -> T) -> T {
        released(None, f)
    }

    /// A line of `n` elastic segments between a fixed anchor and a fixed end, with bending
    /// stiffness, line hydrodynamics in a current (the axial added mass unlike the normal one:
    /// the nodes' axial correction), a spring-damper across two segments and drag on its
    /// middle node, released from a straight span shorter than the line (it sags and swings).
    fn line(n: usize) -> System {
        let mut s = System::new([0.0, 0.0, -9.81]);
        let mut ids = vec![s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap()];
        for i in 1..=n {
            let x = [0.9 * i as f64 / n as f64, 0.0, 0.0];
            ids.push(s.add_particle(0.1, x, [0.0; 3], i == n).unwrap());
            let segment = (Law::Constant(1.0 / n as f64), 1.0);
            s.add_elastic_distance(ids[i - 1], ids[i], segment, 1e5)
                .unwrap();
        }
        for i in 1..n {
            s.add_bending(ids[i - 1], ids[i], ids[i + 1], 1e-3, None)
                .unwrap();
        }
        for i in 1..n {
            let spec = crate::model::LineHydroSpec {
                density: 1025.0,
                diameter: 0.02,
                length: 1.0 / n as f64,
                cd: 1.2,
                cdax: 0.1,
                ca: 1.0,
                caax: 0.3,
            };
            s.add_line_hydrodynamics(ids[i], Some((ids[i - 1], ids[i + 1])), &spec)
                .unwrap();
        }
        let mut water = crate::water::Water::everywhere(9.81);
        water.current = crate::water::Current::Uniform([0.2, 0.1, 0.0]);
        s.set_water(water);
        s.add_spring_damper(ids[2], ids[4], 5.0, 0.1, None).unwrap();
        s.add_quadratic_drag(ids[n / 2], 0.05).unwrap();
        s
    }

    /// Asserts that two runs stored the same numbers, bit for bit, with the same work.
    fn assert_same(a: &Solution, b: &Solution, what: &str) {
        let pairs = [
            (&a.times, &b.times, "times"),
            (&a.positions, &b.positions, "positions"),
            (&a.velocities, &b.velocities, "velocities"),
            (&a.multipliers, &b.multipliers, "multipliers"),
        ];
        for (x, y, name) in pairs {
            assert_eq!(x.len(), y.len(), "{what}: {name}");
            for (k, (u, v)) in x.iter().zip(y.iter()).enumerate() {
                assert_eq!(u.to_bits(), v.to_bits(), "{what}: {name}[{k}]: {u} vs {v}");
            }
        }
        assert_eq!(a.factorisations, b.factorisations, "{what}: factorisations");
        assert_eq!(a.residual_evaluations, b.residual_evaluations, "{what}");
        assert_eq!(a.status, b.status, "{what}: status");
    }

    /// The matrix assembled into the tree elimination's storage and factorised there, and the
    /// slots of periodic elements computed from a run's first ones, give the runs of the plain
    /// tables and of the matrix gathered from the pattern's value array, bit for bit (the same
    /// sums in the same order, at other addresses): a line with bending and forces across
    /// particles, a uniform chain, and a V chain whose singular blocks send factorisations to
    /// the sparse LU (after the matrix is assembled again), under the three Newton policies.
    #[test]
    fn assembling_in_place_changes_no_number() {
        use crate::integrators::JacobianReuse;
        // A uniform chain (the elimination's explicit sweeps), and a chain hung as a V whose
        // bottom block holds two parallel conditions at rest.
        let systems = [
            ("line", line(16)),
            ("chain", chain(30)),
            ("V", awkward_chain(8, false)),
        ];
        for (name, system) in &systems {
            for reuse in [
                JacobianReuse::WhileFast,
                JacobianReuse::Never,
                JacobianReuse::Always,
            ] {
                let mut options = SimulationOptions {
                    t_end: 0.1,
                    dt: 2e-3,
                    ..Default::default()
                };
                options.newton.jacobian_reuse = reuse;
                let run = |in_place: Option<bool>| {
                    released(in_place, || {
                        let ws = StepWorkspace::new(system, options.dense_limit);
                        let tables = &ws.layout.constraint_hessian;
                        assert_eq!(tables.is_compressed(), in_place.is_some(), "{name}");
                        assert_eq!(ws.solver.in_place(), in_place == Some(true), "{name}");
                        assert_eq!(ws.values.is_empty(), in_place == Some(true), "{name}");
                        let mut sim = Simulation::new(system, &options).unwrap();
                        sim.step_to(options.t_end);
                        let fallbacks = sim.workspace().solver.fallbacks();
                        (sim.into_solution(), fallbacks)
                    })
                };
                let (plain, fell) = run(None);
                assert!(plain.status.is_ok(), "{name}: {:?}", plain.status);
                assert_eq!(plain.linear_solver, "tree elimination");
                for in_place in [false, true] {
                    let (other, fell_other) = run(Some(in_place));
                    let what = format!("{name}, {reuse:?}, in place {in_place}");
                    assert_same(&plain, &other, &what);
                    assert_eq!(fell, fell_other, "{what}: fallbacks");
                }
                if *name == "V" {
                    assert!(fell > 0, "the V chain's blocks fell back");
                }
            }
        }
    }

    /// A chain whose tree elimination takes both ends at once (`two_sided.rs`, on two threads)
    /// runs as the one eliminated from one end, to round-off: a swinging chain of 60 links and
    /// a V chain whose singular blocks send factorisations to the sparse LU, the matrix
    /// gathered or assembled in place, under full and modified Newton. The same iterations
    /// (residuals, factorisations, fallbacks) and positions within 2e-11 m over 0.1 s: the
    /// solves differ by round-off, and Newton accepts an iterate anywhere within its
    /// tolerance, 1e-10 of the length scale (measured: 3.4e-12 m on the V under modified
    /// Newton, 0 to 1e-15 m otherwise); the chains' time-step errors are about 1e-6 m.
    #[test]
    fn chains_eliminated_from_both_ends_run_as_from_one() {
        use crate::integrators::JacobianReuse;
        let systems = [("chain", chain(60)), ("V", awkward_chain(8, false))];
        for (name, system) in &systems {
            for reuse in [JacobianReuse::Never, JacobianReuse::Always] {
                let mut options = SimulationOptions {
                    t_end: 0.1,
                    dt: 2e-3,
                    ..Default::default()
                };
                options.newton.jacobian_reuse = reuse;
                for in_place in [false, true] {
                    let run = |two_sided: bool| {
                        TWO_SIDED.with(|t| t.set(two_sided.then_some(0)));
                        let out = released(Some(in_place), || {
                            let mut sim = Simulation::new(system, &options).unwrap();
                            sim.step_to(options.t_end);
                            let fallbacks = sim.workspace().solver.fallbacks();
                            (sim.into_solution(), fallbacks)
                        });
                        TWO_SIDED.with(|t| t.set(None));
                        out
                    };
                    let what = format!("{name}, {reuse:?}, in place {in_place}");
                    let ((one, fell), (both, fell_both)) = (run(false), run(true));
                    assert!(one.status.is_ok() && both.status.is_ok(), "{what}");
                    assert_eq!(fell, fell_both, "{what}: fallbacks");
                    assert_eq!(one.factorisations, both.factorisations, "{what}");
                    assert_eq!(
                        one.residual_evaluations, both.residual_evaluations,
                        "{what}"
                    );
                    let far = one
                        .positions
                        .iter()
                        .zip(&both.positions)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(far < 2e-11, "{what}: {far:e} m apart");
                    if *name == "V" {
                        assert!(fell > 0, "{what}: the V chain's blocks fell back");
                    }
                }
            }
        }
    }

    /// A run snapshotted with its factors held in place, saved and loaded, and restored into
    /// a new simulation steps on as the run that went straight on, bit for bit: a swinging
    /// chain under modified Newton, which keeps its factors across steps (26 factorisations in
    /// 200 steps), so that a restored run that factorised afresh would take other iterates;
    /// eliminated from one end and from both (whose root side keeps its blocks' inverses).
    #[test]
    fn a_snapshot_in_place_holds_the_factors() {
        let system = chain(30);
        let mut options = SimulationOptions {
            t_end: 0.2,
            dt: 1e-3,
            ..Default::default()
        };
        options.newton.jacobian_reuse = crate::integrators::JacobianReuse::Always;
        for two_sided in [None, Some(0)] {
            TWO_SIDED.with(|t| t.set(two_sided));
            snapshot_holds_the_factors(&system, &options);
            TWO_SIDED.with(|t| t.set(None));
        }
    }

    fn snapshot_holds_the_factors(system: &System, options: &SimulationOptions) {
        released(Some(true), || {
            let mut straight = Simulation::new(system, options).unwrap();
            straight.step_to(0.1);
            let snapshot = straight.snapshot();
            let held = snapshot.matrix.as_ref().expect("a matrix is held");
            assert!(held.factored, "the factors, not the matrix");
            straight.step_to(options.t_end);
            let path = std::env::temp_dir()
                .join(format!("vinculo-in-place-{}.snapshot", std::process::id()));
            snapshot.save(&path).unwrap();
            let loaded = Snapshot::load(&path).unwrap();
            std::fs::remove_file(&path).unwrap();
            for restored in [&snapshot, &loaded] {
                let mut again = Simulation::new(system, options).unwrap();
                again.step_to(0.05);
                again.try_restore(restored).unwrap();
                again.step_to(options.t_end);
                let (a, b) = (straight.solution(), again.solution());
                let last =
                    |s: &Solution| s.positions[s.positions.len() - 3 * s.particles..].to_vec();
                assert_eq!(
                    last(a).iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    last(b).iter().map(|x| x.to_bits()).collect::<Vec<_>>()
                );
                assert_eq!(a.factorisations, b.factorisations);
            }
        });
    }

    /// The static equilibrium (the continuation from a V, then Newton) and the stiffness at
    /// the fairlead are those of the matrix in the pattern's order, bit for bit.
    #[test]
    fn statics_in_place_are_the_same() {
        let system = line(12);
        let options = StaticsOptions {
            newton_first: false,
            ..StaticsOptions::default()
        };
        let solve = |in_place| {
            released(in_place, || {
                let st = solve_statics(&system, &options).unwrap();
                let k = point_stiffness(&system, &st, 12).unwrap();
                (st, k)
            })
        };
        let (a, ka) = solve(None);
        for in_place in [false, true] {
            let (b, kb) = solve(Some(in_place));
            assert_eq!(a, b);
            assert_eq!(ka, kb);
        }
    }
}
