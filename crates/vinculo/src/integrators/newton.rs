//! Newton's method on a scaled nonlinear system R(x) = 0 (paper eqs. 26-30), full or modified.
//!
//! The loop does no I/O and chooses no step size. It stops when both the scaled residual and the
//! last increment are below the tolerance (both are lengths after scaling, see
//! [`StepProblem`](super::StepProblem)); it reports the equation that dominates the residual when
//! it fails.
//!
//! It also stops, converged, when the residual is below the tolerance and the increments have
//! stopped decreasing: an increment made with a fresh matrix that is more than
//! [`FLOOR_CONTRACTION`] of the one before, while the residual no longer falls by more than
//! [`FLOOR_RESIDUAL_DROP`] from one iterate to the next. Newton's increments shrink quadratically until the
//! residual reaches the round-off of the terms that cancel in it; from there each new increment
//! is the matrix's inverse applied to that round-off, a random vector that does not shrink.
//! Near a singular configuration (a mechanism whose bars are all collinear, where the constraint
//! gradients lose rank and the multipliers of a self-stress are not determined) the inverse is
//! large, so that those increments stay above the tolerance while the residual is 1e-15: no
//! iterate is better than the current one, and going on could only fail. A residual above the
//! tolerance counts as converged there only when it is below the round-off of its own evaluation
//! ([`NewtonProblem::round_off`]): the residual's change when every unknown moves by its own
//! rounding, eps |x_j|, summed without cancellation, sum_j |J_ij| eps |x_j|. A stiff element far
//! from the origin (a line with bending stiffness EI at 100 m depth: EI / l^3 times the
//! rounding of a position of 100 m) puts that floor above a tight tolerance, which no iteration
//! can then meet (a step of such a line would otherwise be halved until h^2 shrinks the floor:
//! a 500-segment cable at 0.1 s steps took 50 times more factorisations). A tolerance more than
//! [`ROUND_OFF_REACH`] times below the round-off is not met that way in a time step: it asks for
//! what no arithmetic can give, and the step fails as before. The static equilibrium, which has
//! no step size to make its residual small, accepts its round-off whatever the tolerance.
//!
//! Full Newton ([`JacobianReuse::Never`]) assembles and factorises the iteration matrix J(x_k)
//! at every iteration. Modified Newton ([`JacobianReuse::Always`]) keeps the last factorisation,
//! across iterations and across steps, as long as it was made for the same step size and scheme
//! coefficients (the [`IterationMatrix`] key). The residual is always exact, so the converged
//! point is the same; only the rate changes. With a matrix J~ the iteration
//! x <- x - J~^{-1} R(x) contracts the increments by theta_k = |dx_k| / |dx_{k-1}| ~
//! |I - J~^{-1} J|; the matrix is refreshed at the current iterate when theta_k >
//! [`MAX_CONTRACTION`] or after [`MAX_STALE_ITERATIONS`] iterations with one matrix. Since
//! theta <= 1/2 when the loop stops, the distance to the solution, at most |dx| theta /
//! (1 - theta), is below the last increment: near the tolerance, where full Newton's is far below
//! it (about |dx|^2 times the curvature). That error has the same sign step after step (the
//! iteration approaches the solution from the predictor's side), and it enters the velocities
//! divided by the step: on a pendulum of 10^4 steps of 1 ms at a tolerance of 1e-10 it moves the
//! bob by 1e-4 m.
//!
//! # The floor of ill-determined multipliers
//!
//! A chain of rigid bodies, each a tetrahedron of particles with six distances, hinged to the
//! next by a revolute joint, has multipliers that its equations hardly determine (in a plane the
//! joints' equations and the bodies' distances are nearly dependent): a Newton step takes the
//! residual from 1e-5 to its round-off, 2e-12, where the next increments are the matrix's
//! inverse applied to that round-off, 1e-5 to 2e-4 in the multipliers and 1e-10 in the
//! positions, of sizes that scatter from one to the next. The test above waits for a fresh
//! increment above 0.9 of the one before, which such a scatter meets at random: a step of 400
//! bodies took 7.6 residuals and 2.8 factorisations. So the loop also stops, converged, where
//! the residual is within the tolerance, at its own round-off ([`NewtonProblem::round_off`])
//! and not halved by the last increment, made with a matrix factorised in this solve at that
//! iterate or the one before ([`FLOOR_STAGNATION`]): no increment can then make the residual
//! smaller, and the iterate is the one the first test would have stopped at, as far from the
//! solution as the arithmetic lets it be. A Newton step still converging cuts the residual by
//! far more than half. The 400 bodies: 5.7 residuals and 2.2 factorisations a step, 22 % less
//! time (`vinculo.bench.rigid_chain`, `docs/guide/benchmarks.md`).
//!
//! # Reuse while the matrix contracts fast (the default)
//!
//! [`JacobianReuse::WhileFast`] keeps a factorisation across iterations and steps only while it
//! contracts the increments fast, and stops an iteration made with a kept matrix on a bound of
//! the distance to the solution far below the tolerance:
//!
//! - an increment made with a matrix factorised at that iterate is Newton's, and the stop is full
//!   Newton's (increment and residual below the tolerance; the distance left is about the
//!   increment squared times the curvature); so is the first increment of a solve with a kept
//!   matrix assembled within the tolerance of the solve's start in every unknown
//!   ([`NewtonProblem::distance_from`]: a model at rest, whose predictor differs from the last
//!   state by round-off and whose matrix is the same; a static hanging chain takes one iteration
//!   a step instead of two, as in full Newton);
//! - more generally, an increment dx made with a matrix J(x_p) assembled at a distance
//!   delta = |x - x_p| from the iterate x differs from Newton's J(x)^-1 R(x) by about
//!   |J^-1 (J(x) - J(x_p)) dx| <= L delta |dx|, L the relative rate of change of the Jacobian,
//!   while Newton's own stop (|dx| <= tolerance) leaves about L |dx|^2 <= L tolerance^2. Such an
//!   increment counts as Newton's when delta |dx| <= tolerance^2, with delta bounded by the
//!   distance measured at the solve's first iteration (0 for a matrix factorised in the solve)
//!   plus the increments applied since. A long chain at rest whose multipliers carry the
//!   trapezoidal rule's undamped round-off (10^5 particles: the top tension, 4.9e5 N, wobbling
//!   by 0.3 N from one step to the next) has its predictor farther than the tolerance from the
//!   kept matrix's point, so that its first increment is no longer Newton's; its second, with
//!   delta |dx| ~ 1e-6 x 1e-9, is (400 steps: 1.91 residuals a step instead of 2.37);
//! - an increment made with a kept matrix that contracts by theta leaves x within
//!   theta / (1 - theta) |dx| of the solution, at most |dx| while theta <= 1/2: the stop asks
//!   |dx| <= [`REUSED_ERROR_SHARE`] tolerance (and the residual below the tolerance), or that
//!   share of the solve's first increment where it is smaller, down to
//!   [`FIRST_INCREMENT_FLOOR`] of the tolerance. The errors these stops leave add up over the
//!   run with one sign, and at small steps over many steps, counting more in the velocities
//!   (divided by h) and the multipliers (solved for in lambda sigma / s, sigma ~ h^2 / m); the
//!   first increment, the predictor's error (O(h^4)), shrinks with the step as they must. The
//!   pendulum of `tests/test_solution.py` (60 degrees, trapezoidal, 0.1 ms, 2 s): its tension
//!   2.2e-4 of itself off the closed form with the tolerance's share alone, 1.0e-6 with this
//!   (full Newton: 5.6e-7), at 2.68 residuals a step instead of 2.77; at 1 ms, where the first
//!   increment is near the tolerance, the benchmark pendulum takes 3.09 residuals a step
//!   instead of 3.05 and the buoy 2.46 instead of 2.35, the chains, mooring lines and rigid
//!   bodies as many as before. The bound
//!   with the observed theta would stop sooner, but theta measured on the norm of the whole
//!   increment misjudges unknowns that converge at their own rate: the tension of an elastic
//!   segment of EA = 1e15 N drifted 1e-3 of its weight from full Newton's over 3,000 steps with
//!   it, 4e-6 with the bound |dx| (`tests/elastic_segment.rs`).
//!
//! The matrix is refreshed at the next iteration (and at the next solve's first) when it
//! contracts by less than [`FAST_CONTRACTION`], or when the next increment, theta |dx|, is not
//! predicted to stop the loop: a kept matrix costs one more iteration at most. A static hanging
//! chain then factorises once for the whole run and a swinging one once a step (measured:
//! 0.002 and 1.0 factorisations a step on 1,000 particles at dt = 1 ms, against 1.0 and 2.3 in
//! full Newton), and the pendulum of 10^4 steps of 1 ms ends 4e-10 m from full Newton's bob
//! (modified Newton: 1e-4 m).
//!
//! # Stopping on the increment
//!
//! Both tests of a stop, on the residual and on the increment, can be made one residual sooner:
//! when the residual R(x_k) that the increment dx_{k+1} is solved from is within the tolerance and
//! dx_{k+1} passes the test above, the loop applies it and stops, without evaluating
//! R(x_{k+1}). The iterate returned is the one the next iteration would have returned: its stop
//! asks R(x_{k+1}) within the tolerance, and with J~ dx_{k+1} = R(x_k) (the update is
//! x <- x - dx), R(x_{k+1}) = R(x_k) - J dx_{k+1} + O(|dx|^2) = (J~ - J) dx_{k+1} + O(|dx|^2),
//! far below R(x_k) for an increment this small (zero to first order with a matrix factorised at
//! x_k; a kept one contracts). Where
//! R(x_k) is above the tolerance the loop goes on as before. It saves one residual of a step's
//! two to four: a 100-segment mooring line at 5 ms steps (modified Newton, two iterations a
//! step) evaluates two residuals a step instead of three, with the same iterates bit for bit.
//! The residual evaluation also updates what the problem derives from the iterate (a step's
//! velocities), so only a problem whose caller does that after the solve may stop so
//! ([`NewtonProblem::stops_on_increment`]: the index-3 steps, and the GGL steps, whose velocities
//! are unknowns of their own).

use rayon::prelude::*;

use crate::math::{larger_norm, LargestMagnitude};

use crate::linear::{assemble_and_factor, LinearSolver, Singular};

/// Options of the Newton loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Tolerance on the infinity norms of the scaled residual and increment (absolute, in the
    /// problem's scaled units).
    pub tolerance: f64,
    /// Maximum number of iterations (linear solves).
    pub max_iterations: usize,
    /// When the factorised iteration matrix is reused (module documentation): never (full
    /// Newton), always while it contracts (modified Newton), or while it contracts fast with a
    /// stop on the distance to the solution (the default).
    pub jacobian_reuse: JacobianReuse,
}

/// When Newton's iteration reuses a factorised iteration matrix instead of assembling and
/// factorising a new one (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JacobianReuse {
    /// Full Newton: a new matrix at every iteration.
    Never,
    /// Modified Newton: the matrix is kept across iterations and steps while the increments
    /// shrink by half or better, and the loop stops when the last increment is below the
    /// tolerance (an error near the tolerance, which enters the velocities divided by the step:
    /// small steps call for a smaller tolerance).
    Always,
    /// The matrix is kept across iterations and steps while the increments shrink by
    /// [`FAST_CONTRACTION`] or better and one more iteration is predicted to stop the loop, and
    /// an increment made with a kept matrix must be below [`REUSED_ERROR_SHARE`] of the
    /// tolerance to stop it (with a new matrix, as full Newton).
    #[default]
    WhileFast,
}

impl JacobianReuse {
    /// True when a factorisation may be carried from one solve to the next.
    pub fn across_steps(self) -> bool {
        self != JacobianReuse::Never
    }
}

/// Largest contraction ratio |dx_k| / |dx_{k-1}| accepted before modified Newton refreshes its
/// iteration matrix.
pub const MAX_CONTRACTION: f64 = 0.5;

/// Iterations modified Newton makes with one matrix before refreshing it.
pub const MAX_STALE_ITERATIONS: usize = 8;

/// Largest contraction ratio |dx_k| / |dx_{k-1}| with which [`JacobianReuse::WhileFast`] keeps
/// its matrix: each reused iteration gains a digit at least.
pub const FAST_CONTRACTION: f64 = 0.1;

/// Share of the tolerance below which the last increment made with a kept matrix must be for
/// [`JacobianReuse::WhileFast`] to stop (module documentation). The errors left add up step
/// after step with one sign (the iteration approaches the solution from the predictor's side);
/// measured on a pendulum of 10^4 steps of 1 ms (generalised-alpha, tolerance 1e-10): the bob
/// 4e-10 m from full Newton's at 1e-3, 2e-11 m at 1e-4 (0.51 and 0.54 us a step), where the
/// scheme's own error is about 1e-4 m.
pub const REUSED_ERROR_SHARE: f64 = 1e-3;

/// The least share of the tolerance that the stop of [`JacobianReuse::WhileFast`] on a kept
/// matrix's increment takes as the scale of a solve whose first increment is smaller (module
/// documentation, "Reuse while the matrix contracts fast"): with [`REUSED_ERROR_SHARE`], a stop
/// at 1e-5 of the tolerance at least, 1e-15 m on a model of a metre, above the round-off of its
/// coordinates.
pub const FIRST_INCREMENT_FLOOR: f64 = 1e-2;

/// Ratio |dx_k| / |dx_{k-1}| (with a fresh matrix for dx_k) above which the increments count as
/// no longer decreasing: with the residual below the tolerance, the iteration has reached the
/// round-off floor and stops, converged (module documentation). Newton's method converges at
/// least linearly with ratio 1/2 even at a singular solution, so a ratio above 0.9 is not
/// convergence still under way.
pub const FLOOR_CONTRACTION: f64 = 0.9;

/// Ratio |R(x_k)| / |R(x_{k-1})| below which the residual is still falling, so that increments
/// that stopped shrinking are not yet the round-off floor: at the floor the residual is the
/// round-off of its own evaluation, which does not fall by a hundred from one iterate to the
/// next. An increment the size of the one before, made from a residual a thousand times smaller,
/// is a step along a direction the matrix barely resists (a long chain under tension, whose
/// multipliers are ill-determined by the residual), and the iteration goes on (module
/// documentation).
pub const FLOOR_RESIDUAL_DROP: f64 = 1e-2;

/// Ratio |R(x_k)| / |R(x_{k-1})| above which an increment made with a matrix factorised in the
/// same solve did not reduce the residual: within the tolerance and at the residual's
/// round-off, the iteration is at its floor (module documentation, "The floor of
/// ill-determined multipliers"). A Newton step that still converges cuts the residual by far
/// more (by 87 in a static equilibrium of a slack line, `tests/mooring/test_slack_statics.py`,
/// whose residual was 30 times below the round-off's estimate, a bound without
/// cancellation).
pub const FLOOR_STAGNATION: f64 = 0.5;

/// Relative difference of two step sizes below which an iteration matrix made for one serves
/// the other ([`IterationMatrix::holds`]): far above the rounding of a step computed from two
/// times (1e-12 of a 3 ms step at t = 15 s), far below any change that moves a kept matrix's
/// contraction (the mass term's share of the matrix changes by twice it).
pub const SAME_STEP: f64 = 1e-9;

/// What the linear solver's current factorisation is, for reuse by modified Newton.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct IterationMatrix {
    /// Step size and scheme coefficients the factorisation was assembled for; `None` when the
    /// solver holds no reusable factorisation (nothing factorised yet, or another matrix).
    key: Option<[f64; 2]>,
    /// Factorisations of iteration matrices made so far.
    pub factorisations: usize,
    /// Residual evaluations made so far by the solves that used it.
    pub residuals: usize,
    /// The last contraction ratio observed with the held factorisation (0 when none was).
    rate: f64,
    /// The iterate the held matrix was assembled at ([`NewtonProblem::iterate`]; empty when
    /// the problem does not say).
    point: Vec<f64>,
}

impl IterationMatrix {
    /// True when the current factorisation was made for `key`: the same scheme coefficient,
    /// and a step size within [`SAME_STEP`] of its own (a step computed as the difference of
    /// two times, such as the second half of a step back to the run's grid, differs from the
    /// first half by the rounding of those times; the matrix made for one serves the other).
    pub fn holds(&self, key: [f64; 2]) -> bool {
        self.key.is_some_and(|[h, c]| {
            c == key[1] && (h == key[0] || (h - key[0]).abs() <= SAME_STEP * h.abs())
        })
    }

    /// Marks the factorisation as unusable (the solver was used for another matrix, or the
    /// caller wants a fresh one).
    pub fn invalidate(&mut self) {
        self.key = None;
    }

    /// The key, last contraction ratio and assembly point of the held factorisation, if any.
    pub(crate) fn held(&self) -> Option<([f64; 2], f64, &[f64])> {
        self.key.map(|key| (key, self.rate, &self.point[..]))
    }

    /// Records that the solver holds a factorisation made for `key` (restored from a
    /// snapshot: not counted as a new factorisation), with the contraction ratio and assembly
    /// point it had.
    pub(crate) fn adopt(&mut self, key: [f64; 2], rate: f64, point: &[f64]) {
        self.key = Some(key);
        self.rate = rate;
        self.point.clear();
        self.point.extend_from_slice(point);
    }
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tolerance: 1e-10,
            max_iterations: 25,
            jacobian_reuse: JacobianReuse::default(),
        }
    }
}

/// A nonlinear system in scaled form, holding its own iterate.
pub trait NewtonProblem {
    /// Writes the scaled residual at the current iterate.
    fn residual(&mut self, r: &mut [f64]);
    /// Writes the scaled Jacobian at the current iterate into the pattern's value array.
    fn jacobian(&mut self, values: &mut [f64]);
    /// Applies x <- x - dx (dx in scaled unknowns).
    fn update(&mut self, dx: &[f64]);
    /// The round-off of the scaled residual at the current iterate, from the Jacobian `values`
    /// assembled at (or next to) it: `max_i ROUND_OFF_ULPS eps sum_j |J_ij| |x_j|` (module
    /// documentation). 0 (the default): no estimate, the tolerance alone decides.
    fn round_off(&self, _values: &[f64]) -> f64 {
        0.0
    }
    /// Writes the current iterate into `x` (resized) in the unknowns of the increments, so that
    /// [`NewtonProblem::distance_from`] can tell later how far an iterate is from it; false
    /// (the default) when the problem does not say.
    fn iterate(&self, _x: &mut Vec<f64>) -> bool {
        false
    }
    /// The largest distance of an unknown of the current iterate from `x`, written by
    /// [`NewtonProblem::iterate`], when no unknown is farther than `cap`; infinity otherwise
    /// (found at the first unknown beyond `cap`: in a model in motion, at once), and when the
    /// problem does not say (the default).
    fn distance_from(&self, _x: &[f64], _cap: f64) -> f64 {
        f64::INFINITY
    }
    /// The largest ratio of [`NewtonProblem::round_off`] to the tolerance at which the round-off
    /// counts as meeting it ([`ROUND_OFF_REACH`] unless the problem says otherwise).
    fn round_off_reach(&self) -> f64 {
        ROUND_OFF_REACH
    }
    /// Whether the loop may stop on an increment without evaluating the residual at the
    /// iterate it gives (module documentation, "Stopping on the increment"): true for a problem
    /// whose caller brings what the residual derives from the iterate (a step's velocities) up
    /// to date after the solve. False (the default): every stop is checked on a residual at
    /// the returned iterate.
    fn stops_on_increment(&self) -> bool {
        false
    }
}

/// The largest ratio of a residual's round-off to the tolerance at which the round-off counts as
/// meeting the tolerance (module documentation).
pub const ROUND_OFF_REACH: f64 = 1e3;

/// Round-offs per unknown in the estimate of a residual's round-off ([`NewtonProblem::round_off`]):
/// the rounding of the unknowns themselves and of the arithmetic on them.
pub const ROUND_OFF_ULPS: f64 = 2.0;

/// Outcome of a converged solve.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NewtonReport {
    /// Number of iterations (linear solves).
    pub iterations: usize,
    /// Factorisations made (equal to `iterations` in full Newton).
    pub factorisations: usize,
    /// The last scaled residual norm evaluated: at the returned iterate, or, when the loop
    /// stopped on the increment, at the iterate that increment was solved from.
    pub residual: f64,
    /// Last scaled increment norm.
    pub increment: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// No convergence within the iteration limit, or a non-finite residual.
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// Last scaled residual norm.
        residual: f64,
        /// Index of the equation with the largest residual.
        worst: usize,
    },
    /// The iteration matrix could not be factorised.
    Singular(Singular),
}

/// Entries from which [`inf_norm`] runs on rayon's pool (a model of about 250,000 particles
/// and their links; a pass over 8 MB or more, where waking the pool costs far less).
const PARALLEL_NORM_FROM: usize = 1 << 20;

/// The infinity norm of `x`, NaN if any entry is NaN: chunks on rayon's pool for long vectors
/// (the same number: the largest entry does not depend on the order).
#[inline]
pub(crate) fn inf_norm(x: &[f64]) -> f64 {
    if x.len() < PARALLEL_NORM_FROM {
        return inf_norm_serial(x);
    }
    x.par_chunks(1 << 16)
        .map(inf_norm_serial)
        .reduce(|| 0.0, larger_norm)
}

/// [`inf_norm`] on this thread. Four independent running maxima and a NaN flag, with no early
/// exit, so that the compiler turns the pass into vector instructions.
#[inline]
fn inf_norm_serial(x: &[f64]) -> f64 {
    if x.len() < 8 {
        // A small system (a pendulum's four unknowns): one running maximum, without the
        // setting up and combining of the four lanes.
        let (mut m, mut nan) = (0.0f64, false);
        for v in x {
            let a = v.abs();
            m = if a > m { a } else { m };
            nan |= a.is_nan();
        }
        return if nan { f64::NAN } else { m };
    }
    let mut largest = LargestMagnitude::default();
    let chunks = x.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for (l, &v) in c.iter().enumerate() {
            largest.take(l, v);
        }
    }
    for (l, &v) in rest.iter().enumerate() {
        largest.take(l, v);
    }
    largest.norm()
}

/// The index of the entry of `x` of largest magnitude (the first NaN, if any).
pub(crate) fn worst_entry(x: &[f64]) -> usize {
    let mut m = 0.0;
    let mut k = 0;
    for (i, v) in x.iter().enumerate() {
        let a = v.abs();
        if a.is_nan() {
            return i;
        }
        if a > m {
            m = a;
            k = i;
        }
    }
    k
}

/// Work arrays and the factorisation state one solve uses.
pub struct LinearWork<'a> {
    /// The solver holding the factorisation.
    pub solver: &'a mut dyn LinearSolver,
    /// Matrix values in pattern order.
    pub values: &'a mut [f64],
    /// Residual / increment.
    pub r: &'a mut [f64],
    /// What the solver's factorisation is.
    pub matrix: &'a mut IterationMatrix,
}

impl<'a> LinearWork<'a> {
    /// A workspace's `solver` and its arrays `values` and `r`, with the run's `matrix` state.
    pub fn new(
        solver: &'a mut Box<dyn LinearSolver>,
        values: &'a mut [f64],
        r: &'a mut [f64],
        matrix: &'a mut IterationMatrix,
    ) -> LinearWork<'a> {
        LinearWork {
            solver: solver.as_mut(),
            values,
            r,
            matrix,
        }
    }
}

/// Solves `problem` by Newton's method with the given linear solver and work arrays. `key`
/// identifies the iteration matrix (step size and scheme coefficients): modified Newton reuses
/// a factorisation only when it was made for the same key.
pub fn solve(
    problem: &mut impl NewtonProblem,
    work: LinearWork<'_>,
    key: [f64; 2],
    options: &NewtonOptions,
) -> Result<NewtonReport, NewtonFailure> {
    let LinearWork {
        solver,
        values,
        r,
        matrix,
    } = work;
    let policy = options.jacobian_reuse;
    let while_fast = policy == JacobianReuse::WhileFast;
    let mut refresh = !(policy.across_steps() && matrix.holds(key))
        || (while_fast && matrix.rate > FAST_CONTRACTION);
    // Solves made with the current matrix in this call (0: the matrix is an earlier call's).
    let mut solves_with_matrix = 0usize;
    let mut stale_iterations = 0;
    let mut previous = f64::INFINITY;
    let mut factorisations = 0;
    let mut increment = f64::INFINITY;
    let mut residual = f64::INFINITY;
    let mut worst = 0;
    // The last increment and the one before, and whether the last one was made with a matrix
    // factorised at that iteration.
    let mut increment_before = f64::INFINITY;
    let mut fresh = false;
    // An upper bound of the distance (largest unknown) of the iterate from the point the held
    // matrix was assembled at, and whether the last increment leaves the iterate as close to
    // the solution as Newton's would (module documentation, "Reuse while the matrix contracts
    // fast").
    let mut apart = f64::INFINITY;
    let mut newton_like = false;
    // The solve's first increment (infinite before it).
    let mut first = f64::INFINITY;
    // Whether an increment leaves the iterate close enough to the solution (module
    // documentation): one made with a matrix factorised at its iterate as full Newton's, one
    // made with a kept matrix far below the tolerance and the solve's first increment.
    let close_enough = |increment: f64, fresh: bool, first: f64| {
        if !while_fast || fresh {
            increment <= options.tolerance
        } else {
            // The share of the tolerance, or of the solve's first increment where that is
            // smaller, down to FIRST_INCREMENT_FLOOR of the tolerance (module documentation).
            let floor = FIRST_INCREMENT_FLOOR * options.tolerance;
            let scale = options.tolerance.min(first.max(floor));
            increment <= REUSED_ERROR_SHARE * scale
        }
    };
    for iteration in 0..=options.max_iterations {
        problem.residual(r);
        matrix.residuals += 1;
        let residual_before = residual;
        residual = inf_norm(r);
        if !residual.is_finite() {
            return Err(NewtonFailure::NotConverged {
                iterations: iteration,
                residual,
                worst: worst_entry(r),
            });
        }
        // Within the tolerance, a residual that the last increment, made with a matrix
        // factorised in this solve at that iterate or the one before, did not halve, and that
        // is at its own round-off, is the floor too, whatever the increments (module
        // documentation, "The floor of ill-determined multipliers").
        let recent = factorisations > 0 && solves_with_matrix <= 2;
        let at_floor = (fresh
            && increment > FLOOR_CONTRACTION * increment_before
            && residual > FLOOR_RESIDUAL_DROP * residual_before)
            || (recent
                && residual > FLOOR_STAGNATION * residual_before
                && residual <= options.tolerance
                && residual <= problem.round_off(values));
        // At the floor, a residual the evaluation cannot resolve is as good as zero.
        let floor = if at_floor && residual > options.tolerance {
            problem.round_off(values)
        } else {
            0.0
        };
        let reachable = if floor <= problem.round_off_reach() * options.tolerance {
            options.tolerance.max(floor)
        } else {
            options.tolerance
        };
        let close = close_enough(increment, newton_like, first);
        if iteration > 0 && residual <= reachable && (close || at_floor) {
            return Ok(NewtonReport {
                iterations: iteration,
                factorisations,
                residual,
                increment,
            });
        }
        if iteration == options.max_iterations {
            worst = worst_entry(r);
            break;
        }
        fresh = refresh || stale_iterations >= MAX_STALE_ITERATIONS;
        if fresh {
            matrix.invalidate();
            assemble_and_factor(solver, values, |values| problem.jacobian(values))
                .map_err(NewtonFailure::Singular)?;
            matrix.key = Some(key);
            matrix.factorisations += 1;
            factorisations += 1;
            stale_iterations = 0;
            previous = f64::INFINITY;
            solves_with_matrix = 0;
            apart = 0.0;
            if while_fast && !problem.iterate(&mut matrix.point) {
                matrix.point.clear();
            }
        } else if while_fast && solves_with_matrix == 0 && !matrix.point.is_empty() {
            // A kept matrix: how far this iterate is from where it was assembled (farther than
            // the reach of the test below counts as infinitely far). Within the tolerance in
            // every unknown (a model at rest), its increment is Newton's (module
            // documentation).
            apart = problem.distance_from(&matrix.point, options.tolerance / REUSED_ERROR_SHARE);
            fresh = apart <= options.tolerance;
        }
        let solved = solver.solve_in_place_with_norm(r);
        increment_before = increment;
        increment = solved;
        if iteration == 0 {
            first = solved;
        }
        stale_iterations += 1;
        solves_with_matrix += 1;
        refresh = match policy {
            JacobianReuse::Never => true,
            JacobianReuse::Always => increment > MAX_CONTRACTION * previous,
            // Kept while fast, and while the next increment, theta |dx|, is predicted to stop
            // the loop; a matrix used once in this solve has no contraction to judge yet.
            JacobianReuse::WhileFast if solves_with_matrix >= 2 => {
                let rate = increment / previous;
                matrix.rate = rate;
                rate > FAST_CONTRACTION || rate * increment > REUSED_ERROR_SHARE * options.tolerance
            }
            JacobianReuse::WhileFast => {
                if fresh {
                    matrix.rate = 0.0;
                }
                false
            }
        };
        previous = increment;
        if !increment.is_finite() {
            return Err(NewtonFailure::Singular(Singular {
                column: None,
                detail: "the Newton increment is not finite (numerically singular matrix)".into(),
            }));
        }
        // Stopping on the increment (module documentation): the residual it was solved from
        // is within the tolerance and the increment leaves the iterate close enough, by the
        // same test the next iteration would make; its residual need not be evaluated.
        // An increment made with a matrix assembled at distance `apart` leaves the iterate
        // within about L apart |dx| of Newton's, L the Jacobian's relative rate of change:
        // within the L tolerance^2 that Newton's own stop allows when apart |dx| <=
        // tolerance^2 (module documentation).
        newton_like =
            fresh || (while_fast && apart * increment <= options.tolerance * options.tolerance);
        apart += increment;
        let stop = close_enough(increment, newton_like, first)
            && residual <= options.tolerance
            && problem.stops_on_increment();
        problem.update(r);
        if stop {
            return Ok(NewtonReport {
                iterations: iteration + 1,
                factorisations,
                residual,
                increment,
            });
        }
    }
    Err(NewtonFailure::NotConverged {
        iterations: options.max_iterations,
        residual,
        worst,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linear::DenseLu;

    /// R(x) = a (x - 1) + e_k on one unknown, where e_k alternates between +e and -e: a residual
    /// whose evaluation carries an error e (the round-off of terms that cancel) and a slope `a`.
    struct Noisy {
        x: f64,
        slope: f64,
        noise: f64,
        calls: usize,
    }

    impl NewtonProblem for Noisy {
        fn residual(&mut self, r: &mut [f64]) {
            self.calls += 1;
            let sign = if self.calls % 2 == 0 { 1.0 } else { -1.0 };
            r[0] = self.slope * (self.x - 1.0) + sign * self.noise;
        }
        fn jacobian(&mut self, values: &mut [f64]) {
            values[0] = self.slope;
        }
        fn update(&mut self, dx: &[f64]) {
            self.x -= dx[0];
        }
    }

    /// [`Noisy`] that knows its residual's round-off: its noise.
    struct NoisyWithFloor(Noisy);

    impl NewtonProblem for NoisyWithFloor {
        fn residual(&mut self, r: &mut [f64]) {
            self.0.residual(r)
        }
        fn jacobian(&mut self, values: &mut [f64]) {
            self.0.jacobian(values)
        }
        fn update(&mut self, dx: &[f64]) {
            self.0.update(dx)
        }
        fn round_off(&self, _values: &[f64]) -> f64 {
            // The residual at x = 1 -+ noise / slope is up to twice the noise; a margin above.
            3.0 * self.0.noise
        }
    }

    /// [`NoisyWithFloor`] from x = 0 with a slope of 1e-7 (a nearly singular matrix) and the
    /// residual's round-off `noise`.
    fn with_floor(noise: f64) -> NoisyWithFloor {
        NoisyWithFloor(Noisy {
            x: 0.0,
            slope: 1e-7,
            noise,
            calls: 0,
        })
    }

    fn solve_one(problem: &mut impl NewtonProblem) -> Result<NewtonReport, NewtonFailure> {
        let mut solver: Box<dyn LinearSolver> = Box::new(DenseLu::new(1));
        let (mut values, mut r) = (vec![0.0], vec![0.0]);
        let mut matrix = IterationMatrix::default();
        let work = LinearWork::new(&mut solver, &mut values, &mut r, &mut matrix);
        solve(problem, work, [1.0, 1.0], &NewtonOptions::default())
    }

    /// A matrix made for the first half of a step back to the run's grid serves its second
    /// half, computed as the rest of the span from the rounded midpoint (t = 15.003 s: they
    /// differ by 2.8e-13 of the step), not a step 1e-6 longer nor another scheme coefficient.
    #[test]
    fn a_kept_matrix_serves_a_step_that_differs_by_the_rounding_of_times() {
        let mut matrix = IterationMatrix::default();
        let (t, at) = (15.003_f64, 15.009352680000001_f64);
        let h1 = 0.5 * (at - t);
        let h2 = at - (t + h1);
        assert_ne!(h1, h2, "the two halves differ by rounding");
        matrix.adopt([h1, 0.5], 0.0, &[]);
        assert!(matrix.holds([h1, 0.5]));
        assert!(matrix.holds([h2, 0.5]));
        assert!(!matrix.holds([h1 * (1.0 + 1e-6), 0.5]));
        assert!(!matrix.holds([h1, 0.6]));
        matrix.invalidate();
        assert!(!matrix.holds([h1, 0.5]));
    }

    /// A residual whose round-off (4e-9 an evaluation) is above the tolerance: unattainable, so a
    /// problem that reports that round-off converges at it, within 3 noise / slope of the root.
    #[test]
    fn a_residual_at_its_reported_round_off_converges_above_the_tolerance() {
        let mut problem = with_floor(4e-9);
        let report = solve_one(&mut problem).expect("converged at the reported round-off");
        assert!(
            report.residual > 1e-10 && report.residual <= 3.0 * 4e-9,
            "{report:?}"
        );
        let x = problem.0.x;
        // |slope (x - 1)| <= residual + noise <= 3 noise.
        assert!(
            (x - 1.0).abs() <= 3.0 * 4e-9 / 1e-7 * (1.0 + 1e-12),
            "x = {x}"
        );
    }

    /// A round-off more than ROUND_OFF_REACH times the tolerance is not taken as meeting it: the
    /// tolerance asks for what the arithmetic cannot give, and the solve fails.
    #[test]
    fn a_round_off_far_above_the_tolerance_still_fails() {
        let mut problem = with_floor(4e-6);
        // Round-off 1.2e-5 > 1e3 x 1e-10.
        let result = solve_one(&mut problem);
        assert!(
            matches!(result, Err(NewtonFailure::NotConverged { .. })),
            "{result:?}"
        );
    }

    fn run(slope: f64, noise: f64) -> (Result<NewtonReport, NewtonFailure>, f64) {
        let mut problem = Noisy {
            x: 0.0,
            slope,
            noise,
            calls: 0,
        };
        let mut solver: Box<dyn LinearSolver> = Box::new(DenseLu::new(1));
        let (mut values, mut r) = (vec![0.0], vec![0.0]);
        let mut matrix = IterationMatrix::default();
        let work = LinearWork::new(&mut solver, &mut values, &mut r, &mut matrix);
        let result = solve(&mut problem, work, [1.0, 1.0], &NewtonOptions::default());
        (result, problem.x)
    }

    /// A slope of 1e-7 (a nearly singular matrix) and a residual round-off of 4e-15: the
    /// increments bounce at noise / slope = 4e-8, above the tolerance 1e-10, while the residual
    /// holds below it. The solve stops converged at the round-off floor, with x within
    /// 2 noise / slope of the root x = 1 (the exact solution of the perturbed equation).
    #[test]
    fn a_residual_at_round_off_converges_even_when_the_increment_cannot_shrink() {
        let (result, x) = run(1e-7, 4e-15);
        let report = result.expect("converged at the round-off floor");
        assert!(report.residual <= 1e-10, "{report:?}");
        assert!(report.increment > 1e-10, "{report:?}");
        assert!((x - 1.0).abs() <= 2.0 * 4e-15 / 1e-7, "x = {x}");
    }

    /// The floor of ill-determined unknowns (module documentation): a slope of 1e-7 and a
    /// residual round-off of 4e-15, which the problem reports (1.2e-14). The first increment,
    /// with a fresh matrix, brings the residual to its round-off (8e-15); the next, with the
    /// same matrix, is noise / slope, 8e-8, and leaves the residual where it was. That residual,
    /// within the tolerance and at its round-off, ends the solve: three residuals and one
    /// factorisation (the ratio of two fresh increments alone took a second factorisation and
    /// two more residuals to see the floor), x within 2 noise / slope of the root.
    #[test]
    fn a_residual_left_at_its_round_off_by_a_recent_matrix_ends_the_solve() {
        let mut problem = with_floor(4e-15);
        let report = solve_one(&mut problem).expect("converged at the round-off floor");
        assert_eq!(
            (report.factorisations, problem.0.calls),
            (1, 3),
            "{report:?}"
        );
        assert!(report.residual <= 1e-10, "{report:?}");
        let x = problem.0.x;
        assert!(
            (x - 1.0).abs() <= 2.0 * 4e-15 / 1e-7 * (1.0 + 1e-9),
            "x = {x}"
        );
    }

    /// A residual that stagnates above the tolerance is still a failure: the floor is accepted
    /// only where the equations hold to the tolerance.
    #[test]
    fn a_stagnating_residual_above_the_tolerance_fails() {
        let (result, _) = run(1e-7, 4e-9);
        assert!(
            matches!(result, Err(NewtonFailure::NotConverged { .. })),
            "{result:?}"
        );
    }

    /// R(x) = x^3 + x - c on one unknown, for a sequence of c as a run's steps give: the root
    /// moves a little from one solve to the next.
    struct Cubic {
        x: f64,
        c: f64,
    }

    impl NewtonProblem for Cubic {
        fn residual(&mut self, r: &mut [f64]) {
            r[0] = self.x.powi(3) + self.x - self.c;
        }
        fn jacobian(&mut self, values: &mut [f64]) {
            values[0] = 3.0 * self.x * self.x + 1.0;
        }
        fn update(&mut self, dx: &[f64]) {
            self.x -= dx[0];
        }
    }

    /// [`Cubic`] counting its residual evaluations, which may stop on an increment.
    struct CountedCubic {
        cubic: Cubic,
        stops_on_increment: bool,
        residuals: usize,
    }

    impl NewtonProblem for CountedCubic {
        fn residual(&mut self, r: &mut [f64]) {
            self.residuals += 1;
            self.cubic.residual(r);
        }
        fn jacobian(&mut self, values: &mut [f64]) {
            self.cubic.jacobian(values);
        }
        fn update(&mut self, dx: &[f64]) {
            self.cubic.update(dx);
        }
        fn stops_on_increment(&self) -> bool {
            self.stops_on_increment
        }
    }

    /// A run of 200 solves of x^3 + x = c for c = 1.001, 1.002, ..., 1.2, each from the
    /// previous root.
    struct CubicRun {
        /// The root found by each solve.
        roots: Vec<f64>,
        residuals: usize,
        solves: usize,
        factorisations: usize,
    }

    /// The run of [`CubicRun`] with `policy`, stopping on increments or not.
    fn counted_sequence(policy: JacobianReuse, on_increment: bool) -> CubicRun {
        let options = NewtonOptions {
            jacobian_reuse: policy,
            ..Default::default()
        };
        let mut solver: Box<dyn LinearSolver> = Box::new(DenseLu::new(1));
        let (mut values, mut r) = (vec![0.0], vec![0.0]);
        let mut matrix = IterationMatrix::default();
        let mut problem = CountedCubic {
            cubic: Cubic {
                x: cubic_root(1.0),
                c: 1.0,
            },
            stops_on_increment: on_increment,
            residuals: 0,
        };
        let (mut roots, mut solves) = (Vec::new(), 0);
        for k in 1..=200 {
            problem.cubic.c = 1.0 + 1e-3 * k as f64;
            let work = LinearWork::new(&mut solver, &mut values, &mut r, &mut matrix);
            let report = solve(&mut problem, work, [1e-3, 1.0], &options).expect("converged");
            solves += report.iterations;
            roots.push(problem.cubic.x);
        }
        CubicRun {
            roots,
            residuals: problem.residuals,
            solves,
            factorisations: matrix.factorisations,
        }
    }

    /// Stopping on the increment finds the same iterate as the stop on the residual at it
    /// (bit for bit, under each policy: the residual there is far below the tolerance) with
    /// fewer residual evaluations: without it every solve evaluates one residual more than it
    /// makes linear solves; with it, a solve whose residual before its last increment is within
    /// the tolerance does not (measured: full Newton 600 instead of 800 residuals, all 200
    /// solves; the default 800 instead of 825; modified Newton 1,324 instead of 1,460).
    #[test]
    fn stopping_on_the_increment_saves_the_last_residual_and_finds_the_same_root() {
        for policy in [
            JacobianReuse::Never,
            JacobianReuse::WhileFast,
            JacobianReuse::Always,
        ] {
            let checked = counted_sequence(policy, false);
            let early = counted_sequence(policy, true);
            let (residuals, solves) = (checked.residuals, checked.solves);
            assert_eq!(checked.roots, early.roots, "{policy:?}");
            assert_eq!(solves, early.solves, "{policy:?}");
            assert_eq!(residuals, solves + 200, "{policy:?}");
            assert!(
                early.residuals >= solves && early.residuals < residuals,
                "{policy:?}: {} residuals against {residuals}, {solves} solves",
                early.residuals
            );
        }
        // Full Newton's residual before its last increment is already within the tolerance
        // (quadratic convergence): every solve stops on that increment.
        let full = counted_sequence(JacobianReuse::Never, true);
        assert_eq!(full.residuals, full.solves);
    }

    /// The root of x^3 + x = c >= 0 by bisection on [0, max(c, 1)], to round-off: the
    /// reference.
    fn cubic_root(c: f64) -> f64 {
        let (mut lo, mut hi) = (0.0f64, c.max(1.0));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid.powi(3) + mid < c {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The run of [`CubicRun`] with `policy` (every stop checked on a residual): the largest
    /// distance to the bisection root and the factorisations made.
    fn cubic_sequence(policy: JacobianReuse) -> (f64, usize) {
        let run = counted_sequence(policy, false);
        let worst = (1..=200).zip(&run.roots).fold(0.0f64, |worst, (k, x)| {
            worst.max((x - cubic_root(1.0 + 1e-3 * k as f64)).abs())
        });
        (worst, run.factorisations)
    }

    /// The default keeps a matrix while it contracts fast (here from each solve's first
    /// iteration to its next: measured 201 factorisations for 200 solves, full Newton's 600),
    /// and each solve ends within REUSED_ERROR_SHARE of the tolerance of the root (the
    /// contraction bound theta / (1 - theta) |dx| <= |dx| for theta <= 1/2); full Newton ends at
    /// round-off; modified Newton keeps its matrix longest (2) and ends only within the
    /// tolerance (1e-11).
    #[test]
    fn the_default_keeps_a_fast_matrix_and_stops_far_below_the_tolerance() {
        let tolerance = NewtonOptions::default().tolerance;
        let (full_error, full_factorisations) = cubic_sequence(JacobianReuse::Never);
        let (error, factorisations) = cubic_sequence(JacobianReuse::WhileFast);
        let (modified_error, modified_factorisations) = cubic_sequence(JacobianReuse::Always);
        assert!(full_factorisations >= 200, "{full_factorisations}");
        assert!(
            factorisations < full_factorisations / 2,
            "{factorisations} against {full_factorisations}"
        );
        assert!(modified_factorisations <= factorisations);
        assert!(full_error <= 1e-15, "{full_error}");
        assert!(error <= REUSED_ERROR_SHARE * tolerance, "{error}");
        assert!(modified_error <= tolerance, "{modified_error}");
    }

    /// The norm of a vector long enough for rayon's pool is the largest magnitude, found
    /// wherever it lies (the first entry, one in the middle, the last, a chunk's remainder),
    /// and NaN when any entry is NaN, as on one thread.
    #[test]
    fn the_norm_of_a_long_vector_is_its_largest_magnitude_or_nan() {
        let n = PARALLEL_NORM_FROM + 5;
        let base: Vec<f64> = (0..n).map(|i| ((i * 7919) % 1000) as f64 * 1e-3).collect();
        for at in [0, n / 2 + 3, n - 1, n - 3] {
            let mut x = base.clone();
            x[at] = -2.5;
            assert_eq!(inf_norm(&x), 2.5, "largest at {at}");
            assert_eq!(inf_norm(&x), inf_norm_serial(&x));
            x[(at + n / 3) % n] = f64::NAN;
            assert!(inf_norm(&x).is_nan(), "NaN with the largest at {at}");
        }
    }
}
