//! The matrices, solver and buffers that every index-3 step of a run reuses, whatever its time
//! rule (allocated once per run; no allocation per step).

use crate::assembly::{AxialAddedMass, Layout, ParallelAssembly};
use crate::linear::{for_layout, LinearSolver, SparseSolver, TreeElimination};
use crate::math::Vec3;
use crate::model::System;

use super::newton::IterationMatrix;

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
    /// The axial correction of the line nodes' added mass (CaAx != Ca), added to the mass
    /// blocks at each step's evaluation point (`assembly/axial_added_mass.rs`).
    pub axial_added_mass: AxialAddedMass,
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
    /// The values of the last iteration matrix assembled (the one factorised last).
    pub(crate) fn values(&self) -> &[f64] {
        &self.values
    }

    /// Factorises the iteration matrix `values` again; false when they are not of this
    /// workspace's pattern (another length) or do not factorise.
    pub(crate) fn refactor(&mut self, values: &[f64]) -> bool {
        refactor(&mut self.values, self.solver.as_mut(), values)
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
                start_phi: vec![0.0; layout.constraints],
                q_eval: vec![[0.0; 3]; n],
                v_eval: vec![[0.0; 3]; n],
            },
            scales: system.constraints().iter().map(|c| c.scale()).collect(),
            mass_ref,
            inertia: system.inertia(),
            axial_added_mass: AxialAddedMass::new(system),
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
