//! Static equilibrium, independent of any time step, and the linearised stiffness at a point
//! (`docs/theory/moorings.md`).
//!
//! The equilibrium of the free particles at time t, with every velocity zero, is
//!
//! ```text
//! m_i g + f_i(q, 0, t) + sum_k Phi_k,q_i^T lambda_k = 0     (each free particle i)
//! Phi_k(q, t) + c_k(t) lambda_k = 0                          (each constraint k)
//! ```
//!
//! (c_k the compliance of an elastic segment, 0 for an exact constraint): the step equations of
//! the index-3 problem with the mass terms dropped. It is solved by Newton's method on the same
//! assembly as a time step, through a "static rule" ([`StaticRule`]) whose kinematics set v = 0
//! and whose inertia row is -m g: the Jacobian is the analytic one, -df/dq - sum lambda Phi_qq
//! and the constraint gradients. Forces that depend on the velocity only (drag, a regularised
//! Coulomb friction) vanish at v = 0, as MoorDyn leaves friction out of its initial conditions.
//!
//! Newton fails where that Jacobian is singular or the first iterate is far from the
//! equilibrium: a slack line whose tension vanishes, a line lying on the seabed. Then the solve
//! falls back on pseudo-transient continuation (Kelley and Keyes 1998, "Convergence analysis of
//! pseudo-transient continuation", SIAM J. Numer. Anal. 35): each pseudo-step adds
//! mu M (q - q_prev) to the dynamics rows (an implicit step of a heavily damped motion, which
//! regularises the Jacobian with mu M), and mu decreases as the residual falls (switched
//! evolution relaxation: mu_{k+1} = mu_k |R_k| / |R_{k-1}|), so that the last steps are
//! Newton's. The solution does not depend on mu: only the path does.
//!
//! Both keep every elastic segment's compliant row, which can push as well as pull, and refuse
//! an equilibrium in which a segment is compressed: the continuation's damped motion buckles
//! such a line down under its weight. Where nothing can buckle, the compression stays and the
//! continuation does not end: a tether longer than the way from its anchor to its float, whose
//! spare length stands on the anchor held straight by its bending stiffness, or a lander among
//! MoorDyn's test inputs (three bridles under a surface float stiff in bending). The
//! solve then runs the continuation again from the initial state with the segments as a run
//! has them ([`StaticRule`]'s `SLACK_SEGMENTS`): a segment that goes slack in a run
//! ([`crate::model::System::set_slack`], every MoorDyn line's) carries no tension while it is
//! shorter than its length, so that the spare length lies slack. That equilibrium is one of the
//! run's own equations, which stays at rest from it. The first two solves keep the compliant
//! rows because a line lying on the seabed at its unstretched length in the catenary start
//! would otherwise leave its nodes without stiffness along it, and Newton's method from that
//! start would fail.
//!
//! The linearised stiffness of the system at a point p, K = -dF/dx_p (F the force of the rest
//! of the system on p, the other particles in equilibrium), is the Schur complement of the
//! equilibrium Jacobian on p's rows and columns divided by the rows' scale: with p free,
//! `(J^-1)_pp = S^-1`, so three solves with the factorised J give it.

use crate::error::{Error, Result};
use crate::integrators::newton::{
    self, JacobianReuse, LinearWork, NewtonFailure, NewtonOptions, NewtonProblem,
};
use crate::integrators::{Index3Rule, StepPoint, StepProblem, StepStart, StepWorkspace};
use crate::linear::{assemble_and_factor, DenseLu, LinearSolver};
use crate::math::{Mat3, Vec3};
use crate::model::System;

/// How the equilibrium was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StaticsMethod {
    /// Newton's method from the initial state.
    Newton,
    /// Pseudo-transient continuation, finished by Newton's method.
    Continuation,
    /// Pseudo-transient continuation with the segments that go slack in a run slack (module
    /// documentation), finished by Newton's method.
    SlackContinuation,
}

impl StaticsMethod {
    /// "newton", "continuation" or "slack continuation".
    pub fn name(&self) -> &'static str {
        match self {
            StaticsMethod::Newton => "newton",
            StaticsMethod::Continuation => "continuation",
            StaticsMethod::SlackContinuation => "slack continuation",
        }
    }
}

/// Options of the static solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticsOptions {
    /// Tolerance on the scaled residual and increment, relative to the model's length scale.
    pub tolerance: f64,
    /// Largest number of Newton iterations in all (continuation included).
    pub max_iterations: usize,
    /// Time at which the laws (winches, prescribed points) are evaluated.
    pub t: f64,
    /// Try Newton's method from the initial state first (`false`: the continuation at once).
    pub newton_first: bool,
}

impl Default for StaticsOptions {
    fn default() -> Self {
        StaticsOptions {
            tolerance: 1e-9,
            max_iterations: 1000,
            t: 0.0,
            newton_first: true,
        }
    }
}

/// A static equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct Statics {
    /// Positions of every particle (fixed ones unchanged).
    pub positions: Vec<Vec3>,
    /// The multipliers (an elastic segment's is its tension, N).
    pub multipliers: Vec<f64>,
    /// The final scaled residual (m).
    pub residual: f64,
    /// Newton iterations made in all.
    pub iterations: usize,
    /// How it was found.
    pub method: StaticsMethod,
    /// The time at which it holds.
    pub t: f64,
}

/// The static rule (module documentation): v = 0, inertia row
/// mu M (q - q_prev) - m g, the mass term mu M (mu = 0: the equilibrium equations).
/// `SLACK_SEGMENTS`: whether the segments that go slack in a run do so here (the last
/// fallback of [`solve_statics`]); false: every segment keeps its compliant row.
pub struct StaticRule<'a, const SLACK_SEGMENTS: bool = false> {
    /// The pseudo-time coefficient mu (1/s^2); 0 for the equilibrium itself.
    pub mu: f64,
    /// The positions of the previous pseudo-step.
    pub previous: &'a [Vec3],
}

impl<const SLACK_SEGMENTS: bool> Index3Rule for StaticRule<'_, SLACK_SEGMENTS> {
    const AT_END: bool = true;
    /// No step size makes the equilibrium's residual small: a stiff element far from the origin
    /// (a finely divided line with bending stiffness at depth) puts its round-off above any
    /// tolerance that suits the rest of the model.
    const ROUND_OFF_REACH: f64 = f64::INFINITY;
    /// Without `SLACK_SEGMENTS` the equilibrium keeps every segment's compliant row: a
    /// segment lying on the seabed at its unstretched length in the first iterate would
    /// otherwise leave its nodes without stiffness along it, and Newton's method from the
    /// catenary start would fail; compressed segments are refused (and buckled down by the
    /// continuation) on their own (module documentation).
    const SLACK: bool = SLACK_SEGMENTS;

    #[inline(always)]
    fn kinematics(&self, _i: usize, q: &Vec3) -> (Vec3, Vec3, Vec3) {
        ([0.0; 3], *q, [0.0; 3])
    }

    #[inline(always)]
    fn inertia_row(
        &self,
        i: usize,
        q: &Vec3,
        _v: &Vec3,
        inertia: f64,
        mass: f64,
        g: &Vec3,
    ) -> Vec3 {
        let p = &self.previous[i];
        std::array::from_fn(|k| self.mu * inertia * (q[k] - p[k]) - mass * g[k])
    }

    #[inline(always)]
    fn mass_diagonal(&self, sigma: f64, inertia: f64) -> f64 {
        sigma * self.mu * inertia
    }

    #[inline(always)]
    fn weights(&self, sigma: f64) -> (f64, f64, f64) {
        (-sigma, 0.0, -sigma)
    }
}

/// The scale sigma of the dynamics rows: a length per newton, l / (m_ref |g|) (1/m_ref when
/// there is no gravity), so that the rows are lengths like the constraint rows.
fn row_scale(system: &System, mass_ref: f64) -> f64 {
    let g = crate::math::norm(system.gravity());
    if g > 0.0 {
        system.length_scale() / (mass_ref * g)
    } else {
        1.0 / mass_ref
    }
}

/// Runs `f` on the (pseudo-)static problem of parameter `mu` at time `t`, from the positions
/// `previous` of the last pseudo-step, at the workspace's iterate.
fn with_static_problem<'p, T, const S: bool>(
    system: &System,
    ws: &mut StepWorkspace,
    (t, mu, previous): (f64, f64, &'p [Vec3]),
    f: impl FnOnce(StepProblem<'_, StaticRule<'p, S>>, LinearWork<'_>) -> T,
) -> T {
    let sigma = row_scale(system, ws.mass_ref);
    let zero = vec![[0.0; 3]; previous.len()];
    let start = StepStart::new(t, previous, &zero, 1.0);
    let point = StepPoint {
        t_eval: t,
        t_end: t,
        sigma,
    };
    let rule = StaticRule::<S> { mu, previous };
    let (problem, work) = StepProblem::new(system, ws, (&start, point), rule);
    f(problem, work)
}

/// One Newton solve of the (pseudo-)static equations from the workspace's iterate.
fn newton_solve<const S: bool>(
    system: &System,
    ws: &mut StepWorkspace,
    (t, mu, previous): (f64, f64, &[Vec3]),
    options: &NewtonOptions,
) -> std::result::Result<newton::NewtonReport, NewtonFailure> {
    ws.matrix.invalidate();
    with_static_problem::<_, S>(system, ws, (t, mu, previous), |mut problem, work| {
        newton::solve(&mut problem, work, [mu, f64::NAN], options)
    })
}

/// The largest scaled residual of the equilibrium equations (mu = 0) at the workspace's iterate.
fn static_residual<const S: bool>(
    system: &System,
    ws: &mut StepWorkspace,
    t: f64,
    previous: &[Vec3],
) -> f64 {
    let mut r = std::mem::take(&mut ws.r);
    with_static_problem::<_, S>(system, ws, (t, 0.0, previous), |mut problem, _| {
        problem.residual(&mut r)
    });
    let largest = newton::inf_norm(&r);
    ws.r = r;
    largest
}

/// The static equilibrium of `system` at time `options.t`, from its initial positions
/// (module documentation): Newton's method, pseudo-transient continuation when Newton fails,
/// and the continuation with slack segments when that does not end.
///
/// # Errors
/// [`Error::InvalidParameter`] for a tolerance that is not > 0, a time that is not finite or
/// no iteration; [`Error::NewtonFailed`] (with a zero step) when none converges: Newton's
/// method and the first continuation within `options.max_iterations` iterations in all, the
/// continuation with slack segments within as many of its own.
pub fn solve_statics(system: &System, options: &StaticsOptions) -> Result<Statics> {
    crate::error::positive("statics tolerance", options.tolerance)?;
    crate::error::finite("statics time t", options.t)?;
    if options.max_iterations == 0 {
        return Err(Error::InvalidParameter {
            name: "statics max_iterations".into(),
            value: 0.0,
            expected: "must be >= 1".into(),
        });
    }
    let t = options.t;
    let mut ws = StepWorkspace::new(system, 48);
    let q0 = system.initial_positions();
    // Initial multipliers: those of the initial state at rest with every segment held at its
    // length (an elastic segment's tension from the stretch would be zero on an unstretched
    // start, which leaves the line without transverse stiffness).
    let lambda0 = crate::initial::rigid_multipliers(system, &mut ws, &q0, t)
        .unwrap_or_else(|_| vec![0.0; system.constraints().len()]);
    let newton = NewtonOptions {
        tolerance: options.tolerance * system.length_scale(),
        max_iterations: 25.min(options.max_iterations),
        jacobian_reuse: JacobianReuse::Never,
    };
    let start = (&q0[..], &lambda0[..]);
    ws.state.q.clone_from(&q0);
    ws.state.lambda.clone_from(&lambda0);
    let mut used = 0;
    let first = if options.newton_first {
        newton_solve::<false>(system, &mut ws, (t, 0.0, &q0), &newton)
    } else {
        Err(NewtonFailure::NotConverged {
            iterations: 0,
            residual: f64::NAN,
            worst: 0,
        })
    };
    match first {
        // An equilibrium with compressed lines is an arch, not a hanging line: it goes on to the
        // continuation, whose damped motion buckles it down.
        Ok(report) if !compressed(system, &ws.state.lambda) => {
            return Ok(finish(&ws, report, StaticsMethod::Newton, t));
        }
        Ok(report) => used += report.iterations,
        Err(NewtonFailure::NotConverged { iterations, .. }) => used += iterations,
        Err(NewtonFailure::Singular(_)) => used += 1,
    }
    let budget = options.max_iterations.saturating_sub(used);
    match continuation::<false>(system, &mut ws, (t, start), &newton, budget) {
        Ok(mut report) => {
            report.iterations += used;
            return Ok(finish(&ws, report, StaticsMethod::Continuation, t));
        }
        Err(spent) => used += spent,
    }
    match continuation::<true>(system, &mut ws, (t, start), &newton, options.max_iterations) {
        Ok(mut report) => {
            report.iterations += used;
            Ok(finish(&ws, report, StaticsMethod::SlackContinuation, t))
        }
        Err(iterations) => {
            let previous = ws.state.q.clone();
            let residual = static_residual::<true>(system, &mut ws, t, &previous);
            let worst = newton::worst_entry(&ws.r);
            Err(Error::NewtonFailed {
                t,
                dt: 0.0,
                iterations: used + iterations,
                residual,
                equation: format!(
                    "{} (static equilibrium: Newton, pseudo-transient continuation, and the \
                     continuation with slack segments)",
                    ws.layout.equation_name(system, worst)
                ),
            })
        }
    }
}

/// Pseudo-transient continuation (module documentation) from the positions and multipliers
/// `start`, then Newton's method on the equilibrium itself, within `budget` iterations; with
/// `S` the segments that go slack in a run do so (the rows of [`StaticRule`]). The equilibrium
/// is left in the workspace; on failure the iterations made (the workspace holds the last
/// pseudo-step's positions).
fn continuation<const S: bool>(
    system: &System,
    ws: &mut StepWorkspace,
    (t, (q0, lambda0)): (f64, (&[Vec3], &[f64])),
    newton: &NewtonOptions,
    budget: usize,
) -> std::result::Result<newton::NewtonReport, usize> {
    ws.state.q.clear();
    ws.state.q.extend_from_slice(q0);
    ws.state.lambda.clear();
    ws.state.lambda.extend_from_slice(lambda0);
    let mut used = 0;
    let l = system.length_scale();
    let g = crate::math::norm(system.gravity()).max(1e-12);
    // mu0: the inverse square of the time a fall through the model's length takes, ten times
    // over, plus the stiffest segment's EA / (L m_ref): the first pseudo-steps are short on the
    // time scale of every mode, so that they follow the damped motion (a compressed line
    // buckles down under its weight) rather than Newton's jump.
    let stiffest = system
        .constraints()
        .iter()
        .filter(|c| c.is_compliant())
        .map(|c| 1.0 / (c.compliance(t) * ws.mass_ref))
        .fold(0.0, f64::max);
    let mut mu = 100.0 * g / l + stiffest;
    let largest_mu = 1e4 * mu;
    // A pseudo-step need not be solved tightly (only the last, plain Newton solve is), and
    // its mu M (q - q_prev) rows put a round-off floor of about sigma mu M eps |q| on it.
    let step_options = NewtonOptions {
        max_iterations: 12,
        tolerance: 1e3 * newton.tolerance,
        ..*newton
    };
    let mut previous = ws.state.q.clone();
    let mut lambda_previous = ws.state.lambda.clone();
    let mut residual_previous = static_residual::<S>(system, ws, t, &previous);
    while used < budget {
        match newton_solve::<S>(system, ws, (t, mu, &previous), &step_options) {
            Ok(report) => {
                used += report.iterations;
                previous.clone_from(&ws.state.q);
                lambda_previous.clone_from(&ws.state.lambda);
                let residual = static_residual::<S>(system, ws, t, &previous);
                // Switched evolution relaxation (at most a tenfold decrease per step, at least
                // a halving after a converged pseudo-step: the slow modes of a line, a
                // pendulum's g / l, would take mu / omega^2 pseudo-steps otherwise), kept
                // above the negative stiffness of compressed segments, |T| / (L m_ref), so that
                // the pseudo-step's matrix stays definite while a line buckles.
                let ratio = (residual / residual_previous).clamp(0.1, 0.5);
                mu *= if ratio.is_finite() { ratio } else { 0.5 };
                mu = mu.max(2.0 * compression(system, &ws.state.lambda, t) / ws.mass_ref);
                residual_previous = residual;
                let close = residual < 1e3 * newton.tolerance || mu < 1e-6 * g / l;
                if close && !compressed(system, &ws.state.lambda) {
                    // Close: Newton on the equilibrium itself.
                    let remaining = NewtonOptions {
                        max_iterations: 50.min(budget.saturating_sub(used).max(1)),
                        ..*newton
                    };
                    match newton_solve::<S>(system, ws, (t, 0.0, &previous), &remaining) {
                        Ok(report) if !compressed(system, &ws.state.lambda) => {
                            let mut report = report;
                            report.iterations += used;
                            return Ok(report);
                        }
                        Ok(report) => used += report.iterations,
                        Err(NewtonFailure::NotConverged { iterations, .. }) => {
                            used += iterations;
                        }
                        Err(NewtonFailure::Singular(_)) => used += 1,
                    }
                    // Not there yet: more pseudo-steps, longer ones.
                    mu = mu.max(g / l);
                    ws.state.q.clone_from(&previous);
                    ws.state.lambda.clone_from(&lambda_previous);
                }
            }
            Err(failure) => {
                used += match failure {
                    NewtonFailure::NotConverged { iterations, .. } => iterations,
                    NewtonFailure::Singular(_) => 1,
                };
                ws.state.q.clone_from(&previous);
                ws.state.lambda.clone_from(&lambda_previous);
                mu *= 10.0;
                if mu > largest_mu {
                    break;
                }
            }
        }
    }
    ws.state.q.clone_from(&previous);
    Err(used)
}

/// True when an elastic segment (a line's) carries a compression beyond round-off.
fn compressed(system: &System, lambda: &[f64]) -> bool {
    let largest = lambda.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    system
        .constraints()
        .iter()
        .zip(lambda)
        .any(|(c, &l)| c.is_compliant() && l < -1e-6 * largest)
}

/// The largest |T| / L (N/m) of the compressed segments (T < 0), 0 when none is.
fn compression(system: &System, lambda: &[f64], t: f64) -> f64 {
    system
        .constraints()
        .iter()
        .zip(lambda)
        .filter(|(c, &l)| c.is_compliant() && l < 0.0)
        .map(|(c, &l)| {
            -l / (c.compliance(t)
                * match c {
                    crate::constraints::Constraint::ElasticDistance(e) => e.ea,
                    _ => f64::INFINITY,
                })
        })
        .fold(0.0, f64::max)
}

/// The equilibrium held in the workspace.
fn finish(
    ws: &StepWorkspace,
    report: newton::NewtonReport,
    method: StaticsMethod,
    t: f64,
) -> Statics {
    Statics {
        positions: ws.state.q.clone(),
        multipliers: ws.state.lambda.clone(),
        residual: report.residual,
        iterations: report.iterations,
        method,
        t,
    }
}

/// True when constraint `c` touches `particle` alone: one of the point's supports (the
/// prescribed coordinates of a coupled point), not an element acting on it.
fn support_of(c: &crate::constraints::Constraint, particle: usize) -> bool {
    c.particles().iter().all(|&p| p == particle)
}

/// The force (N) that the elements of `system` (its constraints, through their multipliers,
/// and its forces at v = 0) exert on `particle` in the equilibrium `statics`; gravity on the
/// particle itself and the constraints on it alone (its supports) are not included.
pub fn point_force(system: &System, statics: &Statics, particle: usize) -> Vec3 {
    let (q, t) = (&statics.positions, statics.t);
    let zero = vec![[0.0; 3]; q.len()];
    let mut f = [0.0; 3];
    for (k, con) in system.constraints().iter().enumerate() {
        if support_of(con, particle) {
            continue;
        }
        if let Some(x) = con.particles().iter().position(|&p| p == particle) {
            let g = con.gradient(q, t);
            for r in 0..3 {
                f[r] += g[x][r] * statics.multipliers[k];
            }
        }
    }
    for force in system.forces() {
        if let Some(x) = force.particles().iter().position(|&p| p == particle) {
            let fl = force.force(q, &zero, t);
            for r in 0..3 {
                f[r] += fl[x][r];
            }
        }
    }
    f
}

/// The linearised stiffness K = -dF/dx (N/m) of `system` at `particle` in the equilibrium
/// `statics`: F is [`point_force`], the other free particles staying in equilibrium as the
/// point moves (module documentation). A fixed particle is freed for the computation.
///
/// # Errors
/// [`Error::InvalidParameter`] for a particle index out of range;
/// [`Error::SingularMatrix`] when the equilibrium's Jacobian, or its Schur complement on the
/// point, is singular (an inextensible taut line is infinitely stiff along itself).
pub fn point_stiffness(system: &System, statics: &Statics, particle: usize) -> Result<Mat3> {
    let (x, sigma) = inverse_on_points(system, statics, &[particle])?;
    let x: Mat3 = std::array::from_fn(|i| std::array::from_fn(|k| x[3 * i + k]));
    let s = inverse(&x).ok_or_else(|| {
        stiffness_singular(
            statics.t,
            &[particle],
            "the point's block of J^-1 is singular",
        )
    })?;
    Ok(std::array::from_fn(|i| {
        std::array::from_fn(|k| s[i][k] / sigma)
    }))
}

/// The joint linearised stiffness (N/m) of `system` at the points `particles` in the
/// equilibrium `statics`: the 3n x 3n matrix, row-major, of blocks K_ij = -dF_i/dx_j, F_i the
/// [`point_force`] on point i, as point j moves while the other points stay where they are and
/// every other free particle stays in equilibrium: the Schur complement of the equilibrium's
/// Jacobian on the points' rows, [(J^-1)_PP]^-1 / sigma (module documentation). Its diagonal
/// blocks are [`point_stiffness`] of each point with the others held; the off-diagonal ones
/// couple points joined through the system (a bridle's two fairleads). The points are freed
/// for the computation, and the constraints on one of them alone (its supports) left out.
///
/// # Errors
/// [`Error::InvalidParameter`] for no points, an index out of range or a point listed twice;
/// [`Error::SingularMatrix`] when the equilibrium's Jacobian, or its block on the points of
/// its inverse, is singular (an inextensible taut line between two of them).
pub fn points_stiffness(
    system: &System,
    statics: &Statics,
    particles: &[usize],
) -> Result<Vec<f64>> {
    let (x, sigma) = inverse_on_points(system, statics, particles)?;
    let n = 3 * particles.len();
    // S = X^-1, column by column of the identity, X factorised by partial pivoting (in the
    // column-major order of the factorisation).
    let mut lu = DenseLu::new(n);
    let column_major: Vec<f64> = (0..n * n).map(|e| x[(e % n) * n + e / n]).collect();
    lu.factor(&column_major).map_err(|s| {
        stiffness_singular(
            statics.t,
            particles,
            &format!("the points' block of J^-1: {}", s.detail),
        )
    })?;
    let mut k = vec![0.0; n * n];
    let mut e = vec![0.0; n];
    for c in 0..n {
        e.fill(0.0);
        e[c] = 1.0;
        lu.solve_in_place(&mut e);
        for r in 0..n {
            k[r * n + c] = e[r] / sigma;
        }
    }
    Ok(k)
}

/// The error of a stiffness whose matrix is singular.
fn stiffness_singular(t: f64, particles: &[usize], detail: &str) -> Error {
    let which = match particles {
        [p] => format!("particle {p}"),
        _ => format!("particles {particles:?}"),
    };
    Error::SingularMatrix {
        t,
        equation: format!("the static equilibrium's stiffness at {which}"),
        detail: detail.into(),
    }
}

/// (J^-1)_PP, the block on the rows of the points `particles` of the inverse of the
/// equilibrium's Jacobian with those points freed and their supports left out (3n x 3n,
/// row-major), and the rows' scale sigma: the inverse of the Schur complement on the points.
fn inverse_on_points(
    system: &System,
    statics: &Statics,
    particles: &[usize],
) -> Result<(Vec<f64>, f64)> {
    let count = system.particles().len();
    let invalid = |value: f64, expected: String| Error::InvalidParameter {
        name: "particle of a stiffness".into(),
        value,
        expected,
    };
    if particles.is_empty() {
        return Err(invalid(0.0, "give at least one point".into()));
    }
    for (k, &p) in particles.iter().enumerate() {
        if p >= count {
            return Err(invalid(
                p as f64,
                format!("must be one of the system's {count} particles"),
            ));
        }
        if particles[..k].contains(&p) {
            return Err(invalid(p as f64, "each point once".into()));
        }
    }
    // The points are freed, and the constraints on one of them alone (the supports that
    // prescribe a coupled point's coordinates) are left out: F is the force of the other
    // elements.
    let mut free = system.clone();
    for &p in particles {
        free.set_fixed(p, false);
    }
    let kept = free.retain_constraints(|c| !particles.iter().any(|&p| support_of(c, p)));
    free.set_initial_state(&statics.positions, &vec![[0.0; 3]; statics.positions.len()]);
    let mut ws = StepWorkspace::new(&free, 48);
    ws.state.q.clone_from(&statics.positions);
    ws.state.lambda = kept.iter().map(|&k| statics.multipliers[k]).collect();
    let t = statics.t;
    let sigma = row_scale(&free, ws.mass_ref);
    let zero = vec![[0.0; 3]; statics.positions.len()];
    let start = StepStart::new(t, &statics.positions, &zero, 1.0);
    let point = StepPoint {
        t_eval: t,
        t_end: t,
        sigma,
    };
    // The rows of a run: a segment that goes slack and is shorter than its length (an
    // equilibrium of the continuation with slack segments) adds no stiffness; every segment of
    // the other equilibria is stretched, where the two rows are the same.
    let rule = StaticRule::<true> {
        mu: 0.0,
        previous: &statics.positions,
    };
    let rows: Vec<usize> = particles
        .iter()
        .flat_map(|&p| {
            let d = ws.layout.dof[p];
            [d, d + 1, d + 2]
        })
        .collect();
    let (mut problem, work) = StepProblem::new(&free, &mut ws, (&start, point), rule);
    let newton::LinearWork {
        solver, values, r, ..
    } = work;
    problem.residual(r);
    assemble_and_factor(solver, values, |values| problem.jacobian(values))
        .map_err(|s| stiffness_singular(t, particles, &s.detail))?;
    // (J^-1)_PP, column by column.
    let n = rows.len();
    let mut x = vec![0.0; n * n];
    for (k, &column) in rows.iter().enumerate() {
        r.fill(0.0);
        r[column] = 1.0;
        solver.solve_in_place(r);
        for (i, &row) in rows.iter().enumerate() {
            x[i * n + k] = r[row];
        }
    }
    Ok((x, sigma))
}

/// The inverse of a 3x3 matrix, or None when it is singular or not finite.
fn inverse(a: &Mat3) -> Option<Mat3> {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
    };
    let det = a[0][0] * c(0, 0) + a[0][1] * c(0, 1) + a[0][2] * c(0, 2);
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if !det.is_finite() || det.abs() <= 1e-14 * scale.powi(3) {
        return None;
    }
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| c(j, i) / det)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laws::Law;

    const G: f64 = 9.81;

    /// A line of `n` elastic segments (each of unstretched length `length / n`, stiffness `ea`,
    /// node masses `w length / n` with w = 2 kg/m) from a fixed anchor at the origin to a fixed
    /// fairlead at `end`, its nodes placed by `shape(s)` for s in (0, 1).
    fn line(n: usize, length: f64, ea: f64, end: Vec3, shape: impl Fn(f64) -> Vec3) -> System {
        let mut s = System::new([0.0, 0.0, -G]);
        let node = 2.0 * length / n as f64;
        let mut prev = s.add_particle(node, [0.0; 3], [0.0; 3], true).unwrap();
        for i in 1..=n {
            let p = if i == n {
                s.add_particle(node, end, [0.0; 3], true).unwrap()
            } else {
                let x = shape(i as f64 / n as f64);
                s.add_particle(node, x, [0.0; 3], false).unwrap()
            };
            s.add_elastic_distance(prev, p, (Law::Constant(length / n as f64), 1.0), ea)
                .unwrap();
            prev = p;
        }
        s
    }

    /// A mass hanging by one segment: the static stretch is m g L / EA (Hooke) and the tension
    /// m g, found by Newton from the unstretched length.
    #[test]
    fn hanging_mass_stretches_by_m_g_l_over_ea() {
        let (m, l, ea) = (3.0, 2.0, 1e4);
        let mut s = System::new([0.0, 0.0, -G]);
        let a = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
        let b = s.add_particle(m, [0.0, 0.0, -l], [0.0; 3], false).unwrap();
        s.add_elastic_distance(a, b, (Law::Constant(l), 1.0), ea)
            .unwrap();
        let st = solve_statics(&s, &StaticsOptions::default()).unwrap();
        assert_eq!(st.method, StaticsMethod::Newton);
        let z = st.positions[1][2];
        assert!((z + l + m * G * l / ea).abs() < 1e-12, "z {z}");
        assert!((st.multipliers[0] - m * G).abs() < 1e-9 * m * G);
    }

    /// A line started in a V (its nodes on two straight lines through a point 5 m below the
    /// middle of the span: 12.8 m of arc for 10 m of line) reaches, by the continuation alone,
    /// the equilibrium that Newton's method reaches from a sagging parabola, to the tolerance;
    /// its tension is positive and its ends carry its weight.
    #[test]
    fn continuation_reaches_newtons_equilibrium() {
        let (n, length, ea) = (12, 10.0, 1e6);
        let end = [8.0, 0.0, 0.0];
        let v_shape = line(n, length, ea, end, |u| {
            [8.0 * u, 0.0, -10.0 * u.min(1.0 - u)]
        });
        let sagging = line(n, length, ea, end, |u| {
            [8.0 * u, 0.0, -12.0 * u * (1.0 - u)]
        });
        let continuation = StaticsOptions {
            newton_first: false,
            ..StaticsOptions::default()
        };
        let a = solve_statics(&v_shape, &continuation).unwrap();
        let b = solve_statics(&sagging, &StaticsOptions::default()).unwrap();
        assert_eq!(a.method, StaticsMethod::Continuation);
        assert_eq!(b.method, StaticsMethod::Newton);
        assert!(
            a.multipliers.iter().all(|&t| t > 0.0),
            "{:?}",
            a.multipliers
        );
        let worst = a
            .positions
            .iter()
            .zip(&b.positions)
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1e-7, "{worst} m");
        // Vertical balance: the ends carry the line's weight (2 kg/m x 10 m) less the end
        // nodes' own halves, which rest on the fixed ends.
        let fa = point_force(&v_shape, &a, 0);
        let fb = point_force(&v_shape, &a, n);
        let weight = 2.0 * length * G * (n - 1) as f64 / n as f64;
        assert!(
            (fa[2] + fb[2] + weight).abs() < 1e-6 * weight,
            "{fa:?} {fb:?}"
        );
    }

    /// A bridle: a line of 8 segments from an anchor at the origin to a free node, which two
    /// 1.5 m segments hold from two fixed fairleads. The joint stiffness of the two fairleads
    /// (6 x 6) equals central differences of both fairleads' forces over re-solved equilibria
    /// (each fairlead moved by +-1 mm along each axis, the other held), its diagonal blocks
    /// [`point_stiffness`] of each fairlead, and its off-diagonal blocks, the coupling through
    /// the bridle, are not small (the point of the joint matrix); it is symmetric.
    #[test]
    fn joint_stiffness_of_a_bridle_matches_finite_differences_of_the_statics() {
        let (n, ea) = (8, 5e4);
        let mut s = System::new([0.0, 0.0, -G]);
        let node = 2.0 * 10.0 / n as f64;
        let mut prev = s.add_particle(node, [0.0; 3], [0.0; 3], true).unwrap();
        for i in 1..=n {
            let u = i as f64 / n as f64;
            let x = [8.0 * u, 0.0, 2.0 * u - 5.0 * u * (1.0 - u)];
            let p = s.add_particle(node, x, [0.0; 3], false).unwrap();
            s.add_elastic_distance(prev, p, (Law::Constant(10.0 / n as f64), 1.0), ea)
                .unwrap();
            prev = p;
        }
        let fairleads = [n + 1, n + 2];
        for y in [1.0, -1.0] {
            let b = s.add_particle(1.0, [9.0, y, 3.0], [0.0; 3], true).unwrap();
            s.add_elastic_distance(prev, b, (Law::Constant(1.5), 1.0), ea)
                .unwrap();
        }
        let st = solve_statics(&s, &StaticsOptions::default()).unwrap();
        let k = points_stiffness(&s, &st, &fairleads).unwrap();
        let scale = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let h = 1e-3;
        let mut worst = 0.0f64;
        for (jp, &pj) in fairleads.iter().enumerate() {
            for j in 0..3 {
                let forces = |sign: f64| {
                    let mut moved = s.clone();
                    let mut q = st.positions.clone();
                    q[pj][j] += sign * h;
                    moved.set_initial_state(&q, &vec![[0.0; 3]; q.len()]);
                    let eq = solve_statics(&moved, &StaticsOptions::default()).unwrap();
                    fairleads.map(|p| point_force(&moved, &eq, p))
                };
                let (fp, fm) = (forces(1.0), forces(-1.0));
                for ip in 0..2 {
                    for i in 0..3 {
                        let fd = -(fp[ip][i] - fm[ip][i]) / (2.0 * h);
                        let analytic = k[(3 * ip + i) * 6 + 3 * jp + j];
                        worst = worst.max((fd - analytic).abs() / scale);
                    }
                }
            }
        }
        // Central differences: O(h^2) truncation, as for one fairlead below (measured 5.2e-7;
        // the coupling blocks' largest entry 0.91 of the largest).
        assert!(worst < 1e-5, "relative difference {worst}, K = {k:?}");
        for (ip, &p) in fairleads.iter().enumerate() {
            let alone = point_stiffness(&s, &st, p).unwrap();
            for i in 0..3 {
                for j in 0..3 {
                    let joint = k[(3 * ip + i) * 6 + 3 * ip + j];
                    assert!(
                        (joint - alone[i][j]).abs() < 1e-9 * scale,
                        "{joint} {alone:?}"
                    );
                }
            }
        }
        let coupling = (0..3)
            .flat_map(|i| (3..6).map(move |j| (i, j)))
            .fold(0.0f64, |m, (i, j)| m.max(k[i * 6 + j].abs()));
        assert!(coupling > 0.1 * scale, "coupling {coupling} of {scale}");
        for i in 0..6 {
            for j in 0..6 {
                assert!((k[i * 6 + j] - k[j * 6 + i]).abs() < 1e-8 * scale);
            }
        }
        // A point listed twice is refused, naming it.
        let twice = points_stiffness(&s, &st, &[n + 1, n + 1]).unwrap_err();
        assert!(format!("{twice}").contains("each point once"), "{twice}");
    }

    /// The stiffness at the fairlead equals central differences of the fairlead force over
    /// re-solved equilibria (the fairlead moved by +-1 mm along each axis).
    #[test]
    fn fairlead_stiffness_matches_finite_differences_of_the_statics() {
        let (n, length, ea) = (10, 10.0, 5e4);
        let end = [8.0, 1.0, 2.0];
        let shape = |u: f64| [8.0 * u, 1.0 * u, 2.0 * u - 6.0 * u * (1.0 - u)];
        let s = line(n, length, ea, end, shape);
        let st = solve_statics(&s, &StaticsOptions::default()).unwrap();
        let k = point_stiffness(&s, &st, n).unwrap();
        let h = 1e-3;
        let mut worst = 0.0f64;
        let scale = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for j in 0..3 {
            let force = |sign: f64| {
                let mut moved = s.clone();
                let mut q = st.positions.clone();
                q[n][j] += sign * h;
                moved.set_initial_state(&q, &vec![[0.0; 3]; q.len()]);
                let eq = solve_statics(&moved, &StaticsOptions::default()).unwrap();
                point_force(&moved, &eq, n)
            };
            let (fp, fm) = (force(1.0), force(-1.0));
            for i in 0..3 {
                // K = -dF/dx.
                let fd = -(fp[i] - fm[i]) / (2.0 * h);
                worst = worst.max((fd - k[i][j]).abs() / scale);
            }
        }
        // Central differences: O(h^2) truncation, ~1e-6 of the largest entry at h = 1 mm.
        assert!(worst < 1e-5, "relative difference {worst}, K = {k:?}");
        // A coupled fairlead (free, its three coordinates prescribed) has the same stiffness
        // and the same force: its supports are not elements acting on it.
        let mut coupled = s.clone();
        coupled.set_fixed(n, false);
        let id = coupled.particle_id(n).unwrap();
        for axis in 0..3 {
            coupled.add_fixed_coordinate(id, axis, None).unwrap();
        }
        let st_coupled = solve_statics(&coupled, &StaticsOptions::default()).unwrap();
        let k_coupled = point_stiffness(&coupled, &st_coupled, n).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                assert!((k_coupled[i][j] - k[i][j]).abs() < 1e-7 * scale);
            }
            let (f, g) = (
                point_force(&s, &st, n),
                point_force(&coupled, &st_coupled, n),
            );
            assert!((f[i] - g[i]).abs() < 1e-7 * scale);
        }
        // A conservative system's stiffness is symmetric.
        for i in 0..3 {
            for j in 0..3 {
                assert!((k[i][j] - k[j][i]).abs() < 1e-9 * scale);
            }
        }
    }
}
