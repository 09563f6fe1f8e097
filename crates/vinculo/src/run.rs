//! The one run loop: a running simulation that a caller advances, inspects, drives and
//! snapshots; [`crate::simulate()`] is a thin loop over it.
//!
//! # Design
//!
//! [`Simulation`] holds everything a run carries from step to step (time, positions,
//! velocities, accelerations, multipliers, the time rule's state, the step controller's state)
//! and the workspaces it reuses. One loop ([`Simulation::step_to`]) owns what every run shares,
//! whatever its steps: the predictor (below), the
//! step of the scheme on the chosen formulation ([`crate::integrators::Scheme::step`]), the
//! retries of a failed step (below), the rejected-step bookkeeping, the
//! stored output, the tension check and the observer. What differs between fixed and
//! error-controlled runs is a step-controller object (`Controller`): it proposes the next step,
//! judges a converged step (fixed steps accept every one; the error control of
//! `adaptive.rs` estimates its local error, `docs/theory/adaptive.md`) and answers a failed Newton
//! solve with a smaller step or gives up.
//!
//! A snapshot ([`Simulation::snapshot`]) is a copy of the carried state and of the number of
//! stored rows; restoring it and stepping on repeats the steps bit for bit (the workspaces
//! hold nothing a step reads before writing it, except the factorisation that Newton's default
//! and modified Newton keep, which the snapshot holds and a restore factorises again). A
//! snapshot of either kind of run saves to a file (`snapshot_file.rs`) with the step
//! controller's state; the error control's scratch arrays are not part of it and are sized for
//! the system again on restore.
//!
//! A step whose Newton iterations fail is tried again before it is halved (or, with error
//! control, shortened): with a fresh matrix where it started from a matrix kept from an earlier
//! step; from constant acceleration where it was predicted by extrapolation (below); and last,
//! where the iterations reuse a matrix (modified Newton, and the default that reuses one while
//! it contracts fast), with full Newton, a new matrix at every iterate. Where segments go slack
//! and taut within the step (a line snapping taut), a matrix kept over the iterations can stop
//! contracting where Newton's own converges: an S-mooring whose buoy is jerked by 12 m of surge in
//! 6 s (`tests/data/moordyn/s_mooring.txt`, 60 s of 0.02 s steps, modified Newton) had 399 of its
//! 3,000 steps halved, 29,602 residuals and 7,793 factorisations (0.46 s), and with the last
//! retry none, 25,335 and 5,692 (0.26 s; `tests/mooring/test_snap_retry.py`); a step that
//! fails with full Newton too is halved as before. The benchmark's moorings, whose first
//! retries succeed, take the same steps to the same numbers.
//!
//! Error-controlled steps are never bent to an intermediate stop: [`Simulation::step_to`] ends
//! with the step that reaches or passes it (its state is the current state), so a run stepped to
//! t1 and then to t2 is bit for bit the run straight to t2. Requested output times are
//! interpolated inside the steps as in one call.
//!
//! Fixed steps keep time on an exact grid (every step is dt / 2^j, an integer number of the
//! smallest allowed step, so t = t_grid + units * unit never accumulates round-off); a stop at
//! an intermediate time on the grid does not change the steps, so a run stepped to t1 and then
//! to t2 is bit for bit the run straight to t2. A stop between grid points shortens the step
//! to land on it and starts the grid afresh there.
//!
//! The predictor of a step of size h (Newton's first iterate): with fixed steps, a step of the
//! last accepted step's size starts from the time rule's own end of step with its step
//! accelerations extrapolated linearly from their rate over the last step, where the step
//! resolves their change ([`crate::integrators::TimeRule::predict`],
//! [`crate::integrators::resolved_rate`], an error of O(h^4)), and gets one more attempt at
//! constant acceleration if it fails; a step of another size (the
//! first, the halves of a failed step, a step shortened to a stop or to a contact event), the
//! first step after a contact event's restart and error-controlled steps start from the
//! positions extrapolated at constant acceleration, q_n + h v_n + h^2/2 a_n (O(h^3)): the rate
//! of a step of another size is centred elsewhere in time. Once an extrapolated step has failed
//! (and was retried at constant acceleration), the run keeps to constant acceleration until a
//! contact event's restart (`acc_rate_step` negative). On the benchmark pendulum (generalised-alpha, 10^4 steps of 1 ms) the first residual
//! of a step falls from 2.4e-8 to 2.6e-10 and the default Newton factorises 0.086 times a step
//! instead of 0.51 (`docs/theory/newton.md`).
//!
//! The rate extrapolated with is the last step's, r_n = (a_n - a_{n-1}) / h, or the one before,
//! r_{n-1}, whichever predicted the last step's accelerations better (the sum over the particles
//! of |a_n - a_{n-1} - h r|^2, both rates measured over steps of the same size). The lagged
//! extrapolation a_n + h r_{n-1} = a_n + a_{n-1} - a_{n-2} is exact, as the linear one is, for
//! accelerations constant or linear in time, and also for a part that alternates in sign from
//! one step to the next: the response of modes too stiff for the step to resolve, which the
//! trapezoidal rule does not damp (a mooring line's axial and bending modes), and which the
//! linear extrapolation predicts at three times its size with the wrong sign. Measured on the
//! mooring benchmark's lines at 5 ms steps (modified Newton, 10 s): residuals a step 1.27 ->
//! 1.11 and 2.10 -> 1.63 on the hanging chain of 20 and 100 segments, 2.03 -> 1.68 and 3.62 ->
//! 3.05 on the cable with bending stiffness; the chain on the seabed, the pendulum and the
//! benchmark's chains keep to the linear one (the same residuals a step).
//!
//! The multipliers, with fixed steps, are
//! extrapolated linearly, lambda_n + h (lambda_n - lambda_{n-1}) / h_{n-1} (the rate of the last
//! accepted step; none before the first). Against the last multipliers alone, the linear
//! extrapolation takes the first increment from O(h) to O(h^2) of the tension's change:
//! measured on the benchmark's 100-segment hanging chain at dt = 5 ms (modified Newton,
//! `vinculo.mooring`), 2.0 Newton iterations a step instead of 3.0; on the pendulum of `python -m
//! vinculo.bench`, modified Newton's bob ends 2.8e-6 m from full Newton's instead of 1.0e-4 m
//! (1.1e-6 m with the extrapolated accelerations). Error-controlled steps keep the last
//! multipliers: at their tightest tolerances (rtol = atol = 1e-10, some 10^5 steps) the global
//! error depends on where Newton stops each step, within its tolerance (a hundredth of the error
//! tolerance), and the predictor moves those stops: the pendulum's error (generalised-alpha,
//! `tests/test_adaptive_accuracy.py`) went from 45 to 109 times the tolerance, where with Newton
//! converged to 1e-14 it is 13 to 16 times with either predictor.
//!
//! Contact events: a converged fixed step during which a force jumps
//! ([`Force::switch_time`]: a line node that touches the seabed or leaves it, where the
//! seabed's damping force jumps by A cBot |v_z|) is rejected, and the run steps to the event
//! instead (the earliest over the elements, from each node's Taylor polynomial at the step's
//! start; a step whose predictor already crosses a switch goes there before it is solved),
//! then on from there on a grid started afresh, as after a stop between grid points,
//! until the event's transient is over and the steps are dt again: then one step (or two halves
//! of one) goes back to the run's own grid, its first point at least half a step ahead, with
//! the grid's count of units, so that the steps end on the same times as a run without the
//! event, and output asked on the grid is the steps' own state, not an interpolation between
//! two of them (on a stiff line, the tension computed from interpolated positions by Hooke's
//! law carries EA / l times their error: on the benchmark's chain on the seabed, 100 segments
//! at 0.5 ms, 7,932 of its 40,001 output rows were interpolated, 3.6e-9 off the segments'
//! lengths, and none after).
//! For [`SETTLING_SPANS`] of the event's settling time tau ([`Force::settling_time`]: the
//! seabed's damping stops a node within m / (A cBot), a few milliseconds) the steps stay short,
//! then grow back one level per step: the trapezoidal rule, not L-stable, would turn that fast
//! transient into a ringing that decays slowly at large steps. They start at
//! dt / 2^[`EVENT_HALVINGS`] and double every [`DOUBLING_SPANS`] tau, up to dt / 2 and no
//! further than [`RINGING_SPANS`] tau (where the rule's factor on the transient turns negative,
//! a ringing; unless dt / 2^[`EVENT_HALVINGS`] is longer already): the transient
//! decays as e^(-s/tau) while a step's error on it grows as the square of the step, so that
//! each doubling adds 4 e^-2 = 0.54 of the error of the one before. Measured (`python -m
//! vinculo.mooring.bench --cases chain`, 20 s, errors against each build's own run at 0.5 ms):
//! against steps held at dt / 16 through the whole transient, the same errors (20 segments at
//! 10 ms: 3.79e-3 against 3.77e-3; 100 at 5 ms: 7.1e-4 against 7.0e-4; 1,000 at 5 ms: 8.6e-4
//! against 7.2e-4) at 8 %, 7 % and 25 % less CPU time, and the particle of
//! `tests/test_contact_events.py` ends as close to its closed form (1.21e-4, 2.97e-5, 7.40e-6 m
//! at dt = 0.04, 0.02, 0.01, unchanged); doubling every tau instead (3.0e-4 m at dt = 0.04), or
//! holding dt / 4 throughout (2.1e-3 m), loses it, and so does stepping at dt once the steps
//! have doubled up to it (1,000 segments: 1.1e-3). A step that straddles the jump resolves it
//! only to first order in its size; stepping to it and
//! through its transient keeps the run second order (the error of the particle dropped onto the
//! seabed of `tests/test_contact_events.py` shrinks fourfold when dt halves, against a closed
//! form). A step that ends at an event, or whose event is within a millionth of the step from
//! either end, is accepted as it is. Error-controlled steps need no such rule: their error
//! estimate sees the jump.
//!
//! Two more rules serve the schemes that evaluate the forces at the step's end alone
//! ([`Scheme::evaluates_at_end`]: generalised-alpha, backward Euler), measured on that dropped
//! particle:
//! - A step that ends on the jump has no solution (the residual jumps there by the damping
//!   force, and Newton's iterates go back and forth over it): such a scheme lands `LAND_SHORT`
//!   (a thousandth) of the way short of the event, on the side it came from, and the next steps find what is
//!   left of it, two or three of them closing the gap to within `EVENT_MARGIN`. A step whose
//!   Newton iterations fail with a jump between its start and its predictor goes short of the
//!   jump too, instead of being halved (generalised-alpha at dt = 0.04 and backward Euler at
//!   0.04 stopped with a ConvergenceError before).
//! - Generalised-alpha's algorithmic accelerations carry the state before the jump into the
//!   steps after it, which made it first order through the touchdown (errors 3.7e-3, 1.8e-3,
//!   9.1e-4 m at dt = 0.04, 0.02, 0.01): after a step onto an event or across one, a rule that
//!   carries accelerations starts again, as at t = 0, from the accelerations consistent with
//!   the state on the far side of the jump, and is second order (1.3e-4, 3.2e-5, 7.9e-6 m at
//!   rho_inf = 0.9).
//!
//! [`Force::switch_time`]: crate::forces::Force::switch_time
//! [`Force::settling_time`]: crate::forces::Force::settling_time

use crate::adaptive::ErrorControl;
use crate::assembly::Layout;
use crate::constraints::explain_singular;
use crate::dense_output::StepEnds;
use crate::error::{Error, Result};
use crate::initial::{
    consistent_accelerations, rigid_constraints, scaled_velocity_violation_among,
    scaled_violation_among, singular_error,
};
use crate::integrators::energy_guard::EnergyGuard;
use crate::integrators::{
    Formulation, JacobianReuse, NewtonFailure, NewtonOptions, Rule, RuleState, Scheme,
    StabilizedWorkspace, StepStart, StepWorkspace,
};
use crate::math::Vec3;
use crate::model::System;
use crate::options::{check_options, Observer, SimulationOptions};
use crate::output_size::OutputLimit;
use crate::solution::{Solution, StepStats};
use crate::step_control::{ErrorWeights, StepControl};

/// How the next step is chosen and a converged one judged (module documentation).
#[derive(Debug, Clone)]
pub(crate) enum Controller {
    /// Fixed steps on an exact grid, halved on a Newton failure and grown back after success.
    Fixed(FixedSteps),
    /// Error-controlled steps (the PI controller and the local-error estimate).
    Adaptive(Box<ErrorControl>),
}

/// Fixed steps dt / 2^(top - level) on the grid t_grid + units * unit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FixedSteps {
    pub(crate) top: u32,
    pub(crate) unit: f64,
    pub(crate) units: u64,
    pub(crate) level: u32,
    pub(crate) t_grid: f64,
    /// The time of the contact event the next step goes to, once a step found one.
    pub(crate) event_stop: Option<f64>,
    /// The steps stay short until this time, through the transient of the last contact event
    /// ([`SETTLING_SPANS`] of its settling time).
    pub(crate) settle_until: f64,
    /// The settling time of the last contact event (s; 0: none, or a snapshot of a format
    /// without it): the steps of its transient double every [`DOUBLING_SPANS`] of it.
    pub(crate) settle_time: f64,
    /// The run's own grid, origin + k dt: a contact event leaves it for a grid started at the
    /// event, and the run comes back to it after the event's transient (module documentation).
    pub(crate) origin: f64,
    /// Whether the grid is the run's own (t_grid = origin).
    pub(crate) home: bool,
    /// The point of the run's own grid the run is going back to: its time and its units from
    /// the origin.
    pub(crate) rejoin: Option<(f64, u64)>,
}

/// Where a proposed step ends.
#[derive(Debug, Clone, Copy, PartialEq)]
enum StepEnd {
    /// Where the step's size takes it: on the fixed-step grid (t_grid + units * unit after the
    /// step), or t + h for error-controlled steps.
    Natural,
    /// At this time exactly (the stop or the end of the run).
    At(f64),
}

/// Events closer than this share of a step to either end of it are not stepped to (the jump
/// straddles at most this share of the step).
const EVENT_MARGIN: f64 = 1e-6;

/// A scheme that evaluates the forces at the step's end alone ([`Scheme::evaluates_at_end`])
/// steps to this share of the way to a contact event short of it, where the end state is clear
/// of the jump (on the side the step started); the next step then holds the jump within its
/// first thousandth, where it is found again: two or three such steps bring the run within
/// [`EVENT_MARGIN`] of it, and the step across is accepted as it is.
const LAND_SHORT: f64 = 1e-3;

/// Levels of the fixed-step grid below dt for the steps through the transient of a contact event
/// (module documentation): dt / 16. The grid of a run with elements
/// that can switch holds these levels besides the `max_halvings` of Newton failures, so that
/// such a run can halve a failing step up to `max_halvings + EVENT_HALVINGS` times.
pub const EVENT_HALVINGS: u32 = 4;

/// The steps after a contact event stay short for this many of the event's settling time
/// ([`crate::forces::Force::settling_time`]): what remains of the transient, e^-10 of it, is
/// then below what a full step's error on it can matter.
const SETTLING_SPANS: f64 = 10.0;

/// The steps of a contact event's transient double every this many of its settling time, up to
/// dt / 2 (module documentation): the transient, e^(-s/tau), shrinks by e^-2 between doublings
/// while a step's error on it grows fourfold, so that each doubling's share of the error is
/// 4 e^-2 = 0.54 of the one before.
const DOUBLING_SPANS: f64 = 2.0;

/// The steps of a contact event's transient grow no longer than this many of its settling time:
/// the trapezoidal rule's factor on the transient's fast root -1/tau over a step h,
/// (1 - h / 2 tau) / (1 + h / 2 tau), turns negative beyond 2 tau, a ringing from step to step
/// that decays ever more slowly as the step grows (the benchmark's chain on the seabed of 1,000
/// segments at 0.1 s steps took 2.4 times the CPU time with its steps doubled up to dt / 2
/// regardless: real-time factors 0.128 and 0.054).
const RINGING_SPANS: f64 = 2.0;

/// Most halvings the fixed-step grid holds: a step that fails at dt / 2^30 (a billionth of dt)
/// has no step-size problem that further halving would solve, and the grid's count of units of
/// dt / 2^30 stays exact in a float for 2^22 steps of dt; a larger `max_halvings` means 30.
pub(crate) const MAX_GRID_HALVINGS: u32 = 30;

/// Grid units after which the grid is restarted at the current time: beyond 2^52 the count no
/// longer converts exactly to a float (and 2^64 would overflow); with the deepest grid that is
/// every 2^22 steps of dt, and never in practice with the default 4 halvings.
const MAX_GRID_UNITS: u64 = 1 << 52;

/// Fewest floating-point spacings of t a step must span: t + h then advances t by h to within
/// 1 % (the sum rounds by at most half a spacing). A smaller step would repeat times or take
/// steps other than the ones the scheme integrates over.
pub const STEP_IN_TIME_SPACINGS: f64 = 50.0;

/// The spacing of floating-point numbers at `t` (the unit in the last place of |t|).
pub fn time_spacing(t: f64) -> f64 {
    let a = t.abs();
    f64::from_bits(a.to_bits() + 1) - a
}

/// The error of a step `h` from `t` that the floating-point times cannot resolve (it spans fewer
/// than [`STEP_IN_TIME_SPACINGS`] spacings at the larger of |t| and |t + h|), if it is one.
pub(crate) fn unresolved_step(t: f64, h: f64) -> Option<Error> {
    let spacing = time_spacing(t.abs().max((t + h).abs()));
    // Built only when it is returned (an error made and dropped at every step costs a
    // branch on its kind).
    if h < STEP_IN_TIME_SPACINGS * spacing {
        Some(Error::StepBelowTimeResolution {
            t,
            h,
            spacing,
            smallest: STEP_IN_TIME_SPACINGS * spacing,
        })
    } else {
        None
    }
}

impl FixedSteps {
    fn new(dt: f64, max_halvings: usize, t0: f64) -> FixedSteps {
        let top = max_halvings.min(MAX_GRID_HALVINGS as usize) as u32;
        FixedSteps {
            top,
            unit: dt / f64::powi(2.0, top as i32),
            units: 0,
            level: top,
            t_grid: t0,
            event_stop: None,
            settle_until: f64::NEG_INFINITY,
            settle_time: 0.0,
            origin: t0,
            home: true,
            rejoin: None,
        }
    }

    /// The next step from `t` towards `stop` (`t_end`: the run's end, where the last step is
    /// stretched or shortened, by at most a millionth of a step (or the smallest step the times
    /// resolve, [`STEP_IN_TIME_SPACINGS`] spacings of `stop`) or to what remains, to land on
    /// it).
    fn propose(&self, t: f64, stop: f64, t_end: f64) -> (f64, StepEnd) {
        let h_nominal = self.unit * (1u64 << self.level) as f64;
        let remaining = stop - t;
        // The step before a remainder the times cannot resolve is stretched over it too.
        let stretch = (1e-6 * h_nominal).max(STEP_IN_TIME_SPACINGS * time_spacing(stop));
        if remaining > h_nominal + stretch {
            return (h_nominal, StepEnd::Natural);
        }
        if stop < t_end {
            // An intermediate stop on the grid: the step the run would take anyway.
            let grid = self.t_grid + (self.units + (1u64 << self.level)) as f64 * self.unit;
            if (grid - stop).abs() <= 1e-6 * h_nominal {
                return (h_nominal, StepEnd::Natural);
            }
        }
        // A remainder that differs from the step by less than the times resolve (a stop computed
        // as the sum of the steps, rounded) is the step itself: the same step size, so that the
        // iteration matrix made for it serves, and the same numbers as a run through that stop.
        if (remaining - h_nominal).abs() <= time_spacing(stop) {
            return (h_nominal, StepEnd::At(stop));
        }
        (remaining, StepEnd::At(stop))
    }

    /// The step size at the current level (dt after a full recovery from halvings).
    fn nominal(&self) -> f64 {
        self.unit * (1u64 << self.level) as f64
    }

    /// The time after an accepted step that ends at `end`.
    fn accepted(&mut self, end: StepEnd) -> f64 {
        let t = match end {
            StepEnd::Natural => {
                self.units += 1u64 << self.level;
                let t = self.t_grid + self.units as f64 * self.unit;
                if self.units >= MAX_GRID_UNITS {
                    self.t_grid = t;
                    self.units = 0;
                    if self.home {
                        self.origin = t;
                    }
                }
                t
            }
            StepEnd::At(t) => match self.rejoin {
                // Back on the run's own grid, with its count of units.
                Some((at, units)) if at == t => {
                    self.t_grid = self.origin;
                    self.units = units;
                    self.home = true;
                    self.rejoin = None;
                    t
                }
                _ => {
                    // Off the grid: start it afresh here (the run's own from now on, unless
                    // the step went to a contact event).
                    self.t_grid = t;
                    self.units = 0;
                    if self.home {
                        self.origin = t;
                    }
                    t
                }
            },
        };
        // Grow back towards the nominal step after a reduction.
        self.level = (self.level + 1).min(self.top);
        t
    }

    /// A contact event at time `at` whose transient settles in `settle` (s): the run steps to
    /// it, then through [`SETTLING_SPANS`] of `settle` in short steps (module documentation).
    fn go_to_event(&mut self, at: f64, settle: f64) {
        self.event_stop = Some(at);
        self.settle_time = settle;
        self.settle_until = at + SETTLING_SPANS * settle;
        self.rejoin = None;
    }

    /// The point of the run's own grid to go back to from `t` once a contact event's transient
    /// is over and the steps are dt again: the first one at least half a step ahead, and
    /// before the end (None: on the run's grid, or not yet).
    fn rejoin_target(&self, t: f64, t_end: f64) -> Option<(f64, u64)> {
        if self.home || self.event_stop.is_some() || t < self.settle_until || self.level < self.top
        {
            return None;
        }
        let per_step = 1u64 << self.top;
        let dt = self.unit * per_step as f64;
        let k = ((t - self.origin) / dt + 0.5).ceil().max(0.0) as u64;
        let units = k.checked_mul(per_step).filter(|&u| u < MAX_GRID_UNITS)?;
        let at = self.origin + units as f64 * self.unit;
        (at > t && at < t_end - 0.5 * dt).then_some((at, units))
    }

    /// The step from `t` towards the point `at` of the run's own grid (between half a step and
    /// one and a half steps ahead): all of it when it is at most a step, else half of it.
    fn toward(&self, t: f64, at: f64) -> (f64, StepEnd) {
        let remaining = at - t;
        if remaining <= self.nominal() * (1.0 + 1e-6) {
            (remaining, StepEnd::At(at))
        } else {
            let half = 0.5 * remaining;
            (half, StepEnd::At(t + half))
        }
    }

    /// During the transient of a contact event that settles in tau, at time `t`: the next step
    /// is at most dt / 2^([`EVENT_HALVINGS`] - k) once k [`DOUBLING_SPANS`] tau have passed since
    /// the event, at most dt / 2, and no longer than [`RINGING_SPANS`] tau unless dt /
    /// 2^[`EVENT_HALVINGS`] is (module documentation); it grows back one level per step after
    /// the transient.
    fn after_event(&mut self, t: f64) {
        let tau = self.settle_time;
        let mut doublings = 0;
        // None without a settling time (a snapshot of a format without it: its steps stay at
        // dt / 2^EVENT_HALVINGS through the transient, as in the run that saved it).
        if tau > 0.0 {
            let since = t - (self.settle_until - SETTLING_SPANS * tau);
            // Whole doublings since the event (none before it: a negative float cast
            // saturates to 0).
            let due = (since / (DOUBLING_SPANS * tau)).floor() as u32;
            let shortest = self.unit * (1u64 << self.top.saturating_sub(EVENT_HALVINGS)) as f64;
            while doublings < due
                && doublings + 1 < EVENT_HALVINGS
                && shortest * f64::from(1u32 << (doublings + 1)) <= RINGING_SPANS * tau
            {
                doublings += 1;
            }
        }
        let below = EVENT_HALVINGS - doublings;
        self.level = self.level.min(self.top.saturating_sub(below));
    }

    /// After a Newton failure: true (and a halved step) while halvings remain.
    fn halve(&mut self) -> bool {
        if self.level > 0 {
            self.level -= 1;
            true
        } else {
            false
        }
    }
}

/// What a run carries from step to step: everything a snapshot copies.
#[derive(Debug, Clone)]
pub(crate) struct Carried {
    pub(crate) t: f64,
    pub(crate) q: Vec<Vec3>,
    pub(crate) v: Vec<Vec3>,
    pub(crate) acc: Vec<Vec3>,
    pub(crate) lambda: Vec<f64>,
    /// (lambda_{n+1} - lambda_n) / h of the last accepted step (zero before the first): the
    /// predictor's rate of the multipliers.
    pub(crate) lambda_rate: Vec<f64>,
    /// (acc_{n+1} - acc_n) / h of the last accepted fixed step: the predictor's rate of the
    /// accelerations, used by a step of the same size only (none before the first step, after
    /// a contact event's restart and with error control: `acc_rate_step` is then 0).
    pub(crate) acc_rate: Vec<Vec3>,
    /// The size h of the step over which `acc_rate` was measured (0: none); -h once an
    /// extrapolated step failed: the run then predicts at constant acceleration until a contact
    /// event's restart.
    pub(crate) acc_rate_step: f64,
    /// `acc_rate` of the step before the last, and the size of that step (0: none): the
    /// lagged rate of the predictor's extrapolation (module documentation).
    pub(crate) acc_rate_before: Vec<Vec3>,
    pub(crate) acc_rate_before_step: f64,
    /// Whether the predictor extrapolates with the lagged rate `acc_rate_before` rather than
    /// `acc_rate`: the lagged rate predicted the last step's accelerations better.
    pub(crate) alternating: bool,
    pub(crate) rule: RuleState,
    pub(crate) controller: Controller,
    /// Accepted steps so far.
    pub(crate) step: usize,
    /// Next requested output time (error-controlled runs with output times).
    pub(crate) next_output: usize,
}

/// A copy of a running simulation's state ([`Simulation::snapshot`]).
#[derive(Debug, Clone)]
///
/// It records the model it belongs to (particle and constraint counts and a fingerprint of the
/// model, [`fingerprint`]) and the run it was taken from: restored into another run (of the
/// same model, for instance after [`Snapshot::load`]), it carries the state but not the stored
/// history before it ([`Simulation::try_restore`]).
pub struct Snapshot {
    pub(crate) carried: Carried,
    pub(crate) rows: usize,
    pub(crate) steps_taken: usize,
    pub(crate) steps_rejected: usize,
    pub(crate) accepted: usize,
    pub(crate) factorisations: usize,
    pub(crate) residual_evaluations: usize,
    pub(crate) status: std::result::Result<(), Error>,
    pub(crate) fingerprint: u64,
    /// The run it was taken from (0: none, a snapshot loaded from a file).
    pub(crate) run: u64,
    /// The iteration matrix whose factorisation the run held, if any.
    pub(crate) matrix: Option<HeldMatrix>,
}

/// The iteration matrix whose factorisation a run held when a snapshot was taken. Restoring
/// the snapshot factorises these values again, so that the steps after the restore reuse the
/// same matrix as the steps after the snapshot did (Newton's default and modified Newton keep a
/// matrix across steps), bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HeldMatrix {
    /// The step size and scheme coefficients it was made for.
    pub(crate) key: [f64; 2],
    /// The last contraction ratio observed with it.
    pub(crate) rate: f64,
    /// The iterate it was assembled at (empty: not recorded).
    pub(crate) point: Vec<f64>,
    /// Whether it is the GGL formulation's matrix (else the index-3 one's).
    pub(crate) ggl: bool,
    /// Whether `values` are the factors of a solver that factorises in place (see
    /// [`crate::linear::LinearSolver::factors`]) rather than the matrix.
    pub(crate) factored: bool,
    /// Its values, in the order of the formulation's pattern (or its factors).
    pub(crate) values: Vec<f64>,
}

impl Snapshot {
    /// Time of the snapshot.
    pub fn time(&self) -> f64 {
        self.carried.t
    }

    /// Number of particles of the model it belongs to.
    pub fn particles(&self) -> usize {
        self.carried.q.len()
    }

    /// Number of constraint equations of the model it belongs to.
    pub fn constraints(&self) -> usize {
        self.carried.lambda.len()
    }

    /// The fingerprint of the model it belongs to ([`fingerprint`]).
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }
}

/// A fingerprint of a model's structure (FNV-1a over the particles' masses and fixed flags,
/// gravity, the constraints' names and scales and the number of forces): two models with the
/// same fingerprint take the same state vector. Initial positions and velocities do not enter.
pub fn fingerprint(system: &System) -> u64 {
    let mut h = Fnv::new();
    for p in system.particles() {
        h.write(&p.mass.to_bits().to_le_bytes());
        h.write(&[p.fixed as u8]);
    }
    for g in system.gravity() {
        h.write(&g.to_bits().to_le_bytes());
    }
    for (k, c) in system.constraints().iter().enumerate() {
        h.write(c.name(k).as_bytes());
        h.write(&c.scale().to_bits().to_le_bytes());
    }
    h.write(&(system.forces().len() as u64).to_le_bytes());
    h.finish()
}

/// The 64-bit FNV-1a hash (fingerprints and the snapshot file's checksum).
pub(crate) struct Fnv(u64);

impl Fnv {
    pub(crate) fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    pub(crate) fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }

    pub(crate) fn finish(&self) -> u64 {
        self.0
    }
}

/// Identifies each simulation (a snapshot remembers its run).
static NEXT_RUN: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// The scratch arrays of a step (written before they are read: not part of a snapshot). A
/// converged step's positions, velocities and multipliers are the workspace's
/// (`ws.state`), swapped with the carried state's when the step is accepted.
struct Scratch {
    acc_new: Vec<Vec3>,
    q_out: Vec<Vec3>,
    v_out: Vec<Vec3>,
    lambda_out: Vec<f64>,
    rule_saved: RuleState,
}

/// A running simulation (module documentation).
pub struct Simulation<'a> {
    system: &'a System,
    options: SimulationOptions,
    /// The time rule of `options.scheme`, its coefficients computed once.
    rule: Rule,
    newton: NewtonOptions,
    tension_floor: f64,
    /// The constraints whose violations a stored state reports ([`rigid_constraints`]).
    rigid: Vec<usize>,
    ws: StepWorkspace,
    stabilized: Option<StabilizedWorkspace>,
    carried: Carried,
    scratch: Scratch,
    sol: Solution,
    fingerprint: u64,
    run: u64,
    /// The largest stored output allowed (`output_size.rs`).
    output_limit: OutputLimit,
    /// The growth guard of index-3 generalised-alpha (`integrators/energy_guard.rs`).
    guard: Option<EnergyGuard>,
    /// The forces that can switch within a step (contact events, module documentation).
    event_forces: Vec<EventForce>,
    /// A law that was not finite at the end of a failed attempt of the current step (a square
    /// root of a negative value): the cause to report if the step finally fails.
    law_trouble: Option<Error>,
}

impl<'a> Simulation<'a> {
    /// Validates `options`, checks that the initial state satisfies the constraints, computes
    /// the consistent accelerations and multipliers, and stores the initial state.
    ///
    /// Errors in the input are returned as `Err`. A start that fails (a singular matrix,
    /// redundant constraints, a string that would have to push) returns a simulation whose
    /// [`Simulation::status`] holds the cause and which takes no step.
    pub fn new(system: &'a System, options: &SimulationOptions) -> Result<Simulation<'a>> {
        check_options(system, options)?;
        // Fixed steps of dt must be resolved by the times of the whole run.
        if options.step_control == StepControl::Fixed && options.t_end > options.t_start {
            let far = options.t_start.abs().max(options.t_end.abs());
            let spacing = time_spacing(far);
            if options.dt < STEP_IN_TIME_SPACINGS * spacing {
                return Err(Error::InvalidParameter {
                    name: "dt".into(),
                    value: options.dt,
                    expected: format!(
                        "must be at least {STEP_IN_TIME_SPACINGS} times the spacing of \
                         floating-point times at t = {far:e} s ({spacing:.3e} s), i.e. >= \
                         {:.3e} s, or t + dt does not advance t by dt; use a larger dt or \
                         count time from nearer 0 (a smaller t_start)",
                        STEP_IN_TIME_SPACINGS * spacing
                    ),
                });
            }
        }
        // A run whose stored output would not fit in memory is refused before it starts.
        let mut output_limit = OutputLimit::of(options)?;
        if let Some(e) = output_limit.refused(system, options) {
            return Err(e);
        }
        // User groups start the run with empty caches and counters.
        system.reset_user_groups();
        let length = system.length_scale();
        let t0 = options.t_start;
        let q = system.initial_positions();
        let v = system.initial_velocities();
        // Positions are compared with the model's length scale; velocities with a speed scale,
        // the largest initial speed or the speed of a fall through the length scale, sqrt(|g| l).
        let g = system.gravity();
        let speed = v
            .iter()
            .map(|x| crate::math::norm(*x))
            .fold((crate::math::norm(g) * length).sqrt(), f64::max);
        let speed = if speed > 0.0 { speed } else { length };
        // A law that cannot be evaluated at the start (a square root of a negative value) is named
        // before the checks it would spoil.
        if let Some(e) = system.law_failure(t0) {
            return Err(e);
        }
        let rigid = rigid_constraints(system);
        let (worst, k) = scaled_violation_among(system, &rigid, &q, t0);
        let velocity_worst = scaled_velocity_violation_among(system, &rigid, &q, &v, t0);
        if let Some(e) = system.user_failure() {
            return Err(e);
        }
        let checks = [
            ("positions", "Phi", (worst, k), length),
            ("velocities", "Phi_q v + Phi_t", velocity_worst, speed),
        ];
        for (level, quantity, (violation, k), scale) in checks {
            let tolerance = options.initial_tolerance * scale;
            if violation.is_nan() || violation > tolerance {
                let c = &system.constraints()[k];
                return Err(Error::InconsistentInitialState {
                    level: level.into(),
                    quantity: quantity.into(),
                    constraint: c.name(k),
                    violation: violation / c.scale(),
                    scaled: violation,
                    tolerance,
                });
            }
        }

        let mut ws = StepWorkspace::with_solver(system, options.dense_limit, options.sparse_solver);
        ws.assemble_in_parallel_from(system, options.parallel_from);
        // Error-controlled steps tie Newton's tolerance to theirs (`step_control.rs`).
        let relative = match options.step_control {
            StepControl::Adaptive(control) => {
                control.newton_tolerance(options.newton.tolerance, length)
            }
            StepControl::Fixed => options.newton.tolerance,
        };
        // The default reuse serves index-3 fixed steps; error-controlled steps project their
        // error estimate with the step's last matrix, which must be the end's, and GGL's
        // multipliers and velocities take the iterate's error divided by h^2 (newton.rs).
        let jacobian_reuse = match options.newton.jacobian_reuse {
            JacobianReuse::WhileFast
                if options.formulation == Formulation::Ggl
                    || matches!(options.step_control, StepControl::Adaptive(_)) =>
            {
                JacobianReuse::Never
            }
            policy => policy,
        };
        let newton = NewtonOptions {
            tolerance: relative * length,
            jacobian_reuse,
            ..options.newton
        };
        // The GGL steps have their own unknowns and solver; the index-3 workspace still serves
        // the consistent start and carries the step's state in and out.
        let stabilized = (options.formulation == Formulation::Ggl)
            .then(|| StabilizedWorkspace::new(system, options.dense_limit));
        let solver_name = match &stabilized {
            Some(g) => g.solver.name(),
            None => ws.solver.name(),
        };
        let mut sol = Solution::new(q.len(), system.constraints().len(), solver_name);
        sol.scheme = options.scheme;
        sol.formulation = options.formulation;
        let start = consistent_accelerations(system, &mut ws, &q, &v, t0).map_err(|e| match e {
            // Name the culprits when the matrix is singular because constraints are redundant.
            e @ Error::SingularMatrix { .. } => explain_singular(system, &q, t0, e),
            e => e,
        });
        // A failed user function is the cause of whatever else went wrong at the start.
        let start = match (start, system.user_failure()) {
            (_, Some(e)) => Err(e),
            (start, None) => start,
        };
        let (acc, lambda, status) = match start {
            Ok((acc, lambda)) => (acc, lambda, Ok(())),
            Err(e) => (
                vec![[0.0; 3]; q.len()],
                vec![f64::NAN; sol.constraints],
                Err(e),
            ),
        };
        sol.push(
            t0,
            &q,
            &v,
            &lambda,
            worst,
            velocity_worst.0,
            StepStats::default(),
        );
        sol.status = status;
        let weight = system
            .particles()
            .iter()
            .map(|p| p.mass * crate::math::norm(g))
            .sum::<f64>();
        let tension_floor = -1e-9 * if weight > 0.0 { weight } else { 1.0 };
        if sol.status.is_ok() {
            if let Some(e) = negative_tension(system, &lambda, t0, tension_floor) {
                sol.status = Err(e);
            }
        }
        // The forces that can switch within a step (contact events, module documentation).
        let event_forces: Vec<EventForce> = (system.forces().iter().enumerate())
            .filter(|(_, f)| f.has_events())
            .map(|(force, f)| {
                let (particle, height) = f.switch_height().expect("a force with events");
                EventForce {
                    force,
                    particle,
                    height,
                }
            })
            .collect();
        let controller = match options.step_control {
            StepControl::Fixed => {
                // The steps after a contact event take levels of their own below dt, so that a
                // Newton failure there still has its max_halvings.
                let extra = if event_forces.is_empty() {
                    0
                } else {
                    EVENT_HALVINGS as usize
                };
                Controller::Fixed(FixedSteps::new(
                    options.dt,
                    options.max_halvings + extra,
                    t0,
                ))
            }
            StepControl::Adaptive(control) => {
                let weights = ErrorWeights {
                    time_scale: length / speed,
                    atol_q: control.atol,
                    atol_v: control.atol * speed / length,
                    rtol: control.rtol,
                };
                Controller::Adaptive(Box::new(ErrorControl::new(
                    system,
                    options.scheme,
                    control,
                    weights,
                    options.dt,
                    &acc,
                    ws.layout.unknowns(),
                )))
            }
        };
        // Requested output times: the initial row stays only when t_start is one of them.
        let mut next_output = 0;
        if let Some(outputs) = &options.output_times {
            if outputs.first() == Some(&t0) {
                next_output = 1;
            } else if sol.status.is_ok() {
                sol.truncate(0);
            }
        }
        let rule = options.scheme.initial_state(&acc);
        let guard = match (options.scheme, options.formulation) {
            (Scheme::GeneralizedAlpha { rho_inf }, Formulation::Index3) => {
                EnergyGuard::new(system, rho_inf, &q, &v)
            }
            _ => None,
        };
        // Buffers of what only some runs do (allocated empty otherwise: at 10^6 particles each
        // array of 3-vectors is 24 MB).
        let adaptive = matches!(controller, Controller::Adaptive(_));
        let dense = options.output_times.is_some();
        let if_dense = |x: &Vec<Vec3>| if dense { x.clone() } else { Vec::new() };
        let scratch = Scratch {
            acc_new: acc.clone(),
            q_out: if_dense(&q),
            v_out: if_dense(&v),
            lambda_out: if dense { lambda.clone() } else { Vec::new() },
            rule_saved: if adaptive || !event_forces.is_empty() {
                rule.clone()
            } else {
                RuleState::new(&[])
            },
        };
        Ok(Simulation {
            system,
            options: options.clone(),
            rule: options.scheme.rule(),
            newton,
            tension_floor,
            rigid,
            ws,
            stabilized,
            carried: Carried {
                t: t0,
                q,
                v,
                acc_rate: vec![[0.0; 3]; acc.len()],
                acc_rate_step: 0.0,
                acc_rate_before: vec![[0.0; 3]; acc.len()],
                acc_rate_before_step: 0.0,
                alternating: false,
                acc,
                lambda_rate: vec![0.0; lambda.len()],
                lambda,
                rule,
                controller,
                step: 0,
                next_output,
            },
            scratch,
            sol,
            guard,
            event_forces,
            law_trouble: None,
            fingerprint: fingerprint(system),
            run: NEXT_RUN.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            output_limit,
        })
    }

    /// Current time.
    pub fn time(&self) -> f64 {
        self.carried.t
    }

    /// Current positions, one 3-vector per particle.
    pub fn positions(&self) -> &[Vec3] {
        &self.carried.q
    }

    /// Current velocities, one 3-vector per particle.
    pub fn velocities(&self) -> &[Vec3] {
        &self.carried.v
    }

    /// Current multipliers (constraint forces, one per constraint equation; sign convention in
    /// `docs/theory/formulation.md`).
    pub fn multipliers(&self) -> &[f64] {
        &self.carried.lambda
    }

    /// The states stored so far and the run's statistics.
    pub fn solution(&self) -> &Solution {
        &self.sol
    }

    /// `Ok` while the run can go on; the cause once it stopped (the states computed before
    /// stay in [`Simulation::solution`]).
    pub fn status(&self) -> &std::result::Result<(), Error> {
        &self.sol.status
    }

    /// The run's workspace (its solver's statistics, for tests).
    #[cfg(test)]
    pub(crate) fn workspace(&self) -> &StepWorkspace {
        &self.ws
    }

    /// The stored states and statistics, ending the simulation.
    pub fn into_solution(self) -> Solution {
        self.sol
    }

    /// A copy of the running state (module documentation).
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            carried: self.carried.clone(),
            rows: self.sol.len(),
            steps_taken: self.sol.steps_taken,
            steps_rejected: self.sol.steps_rejected,
            accepted: self.sol.accepted_step_sizes.len(),
            factorisations: self.sol.factorisations,
            residual_evaluations: self.sol.residual_evaluations,
            status: self.sol.status.clone(),
            fingerprint: self.fingerprint,
            run: self.run,
            matrix: self.ws.matrix.held().and_then(|(key, rate, point)| {
                let (values, factored) = match &self.stabilized {
                    Some(g) => (g.values().to_vec(), false),
                    None => self.ws.matrix_record()?,
                };
                Some(HeldMatrix {
                    key,
                    rate,
                    point: point.to_vec(),
                    ggl: self.stabilized.is_some(),
                    factored,
                    values,
                })
            }),
        }
    }

    /// [`Simulation::restore`] after checking that `snapshot` belongs to this model (its
    /// particle and constraint counts and fingerprint) and to a run of the same kind (fixed or
    /// error-controlled steps, a time rule with the same state). A snapshot of another run of
    /// the model (another simulation's, or one loaded from a file) carries the state but not the
    /// history before it: the stored states restart with the snapshot's (stored as a row of its
    /// own unless the run has requested output times, with the statistics of no step).
    ///
    /// # Errors
    /// [`Error::Snapshot`] for a snapshot of another model, or of a run with the other step
    /// control or another time rule.
    pub fn try_restore(&mut self, snapshot: &Snapshot) -> Result<()> {
        let (n, m) = (self.carried.q.len(), self.carried.lambda.len());
        if (snapshot.particles(), snapshot.constraints()) != (n, m)
            || snapshot.fingerprint != self.fingerprint
        {
            return Err(Error::Snapshot {
                what: "snapshot".into(),
                problem: format!(
                    "a snapshot of another system ({} particles, {} constraint equations, \
                     fingerprint {:016x}; this one has {n}, {m}, {:016x}): restore only \
                     snapshots of simulations of the same system",
                    snapshot.particles(),
                    snapshot.constraints(),
                    snapshot.fingerprint,
                    self.fingerprint
                ),
            });
        }
        if let Some(problem) = self.other_run_kind(snapshot) {
            return Err(Error::Snapshot {
                what: "snapshot".into(),
                problem,
            });
        }
        if snapshot.run == self.run {
            self.restore(snapshot);
            return Ok(());
        }
        self.restore(snapshot);
        self.sol.truncate(0);
        self.sol.accepted_step_sizes.clear();
        if self.options.output_times.is_none() {
            let c = &self.carried;
            store(
                &mut self.sol,
                (self.system, &self.rigid),
                c.t,
                (&c.q, &c.v, &c.lambda),
                StepStats::default(),
            );
        }
        Ok(())
    }

    /// Factorises the snapshot's iteration matrix `held` again and marks it held, when it is a
    /// matrix of this run's formulation and pattern (a snapshot of a run with other solver
    /// settings leaves no matrix held: the next step makes its own).
    fn adopt_matrix(&mut self, held: &HeldMatrix) {
        let factored = match &mut self.stabilized {
            Some(g) if held.ggl => g.refactor(&held.values),
            None if !held.ggl => self.ws.refactor(&held.values, held.factored),
            _ => false,
        };
        if factored {
            self.ws.matrix.adopt(held.key, held.rate, &held.point);
        }
    }

    /// What makes `snapshot` (of this model) a snapshot of another kind of run than this one:
    /// the other step control, or a time rule with another state.
    fn other_run_kind(&self, snapshot: &Snapshot) -> Option<String> {
        let scheme = self.options.scheme;
        match (&snapshot.carried.controller, &self.carried.controller) {
            (Controller::Fixed(_), Controller::Fixed(_)) => {}
            (Controller::Adaptive(theirs), Controller::Adaptive(_)) if theirs.scheme != scheme => {
                return Some(format!(
                    "a snapshot of a run with the scheme {:?} restored into one with {scheme:?}: \
                     create the simulation with the snapshot's scheme",
                    theirs.scheme
                ))
            }
            (Controller::Adaptive(_), Controller::Adaptive(_)) => {}
            (theirs, _) => {
                let adaptive = matches!(theirs, Controller::Adaptive(_));
                return Some(format!(
                    "a snapshot of a run with {} steps restored into one with {} steps: create \
                     the simulation with the snapshot's step control (adaptive = {adaptive})",
                    if adaptive {
                        "error-controlled"
                    } else {
                        "fixed"
                    },
                    if adaptive {
                        "fixed"
                    } else {
                        "error-controlled"
                    },
                ));
            }
        }
        let (theirs, ours) = (&snapshot.carried.rule, &self.carried.rule);
        if theirs.acceleration.len() != ours.acceleration.len() {
            return Some(format!(
                "a snapshot of a run whose time rule carries {} accelerations restored into one \
                 whose rule ({}) carries {}: create the simulation with the snapshot's scheme",
                theirs.acceleration.len(),
                scheme.name(),
                ours.acceleration.len()
            ));
        }
        None
    }

    /// Returns to the state of `snapshot` (taken from this simulation): later stored states
    /// are dropped, and stepping on repeats the steps that followed the snapshot bit for bit
    /// (the iteration matrix the run held is factorised again from the snapshot's values).
    ///
    /// # Panics
    /// If the snapshot's model size differs from this simulation's.
    #[track_caller]
    pub fn restore(&mut self, snapshot: &Snapshot) {
        assert_eq!(
            snapshot.carried.q.len(),
            self.carried.q.len(),
            "a snapshot of another model"
        );
        assert_eq!(snapshot.carried.lambda.len(), self.carried.lambda.len());
        self.carried.clone_from(&snapshot.carried);
        if let Controller::Adaptive(control) = &mut self.carried.controller {
            control.fit(self.system, self.ws.layout.unknowns());
        }
        self.sol.truncate(snapshot.rows);
        self.sol.accepted_step_sizes.truncate(snapshot.accepted);
        self.sol.steps_taken = snapshot.steps_taken;
        self.sol.steps_rejected = snapshot.steps_rejected;
        self.sol.factorisations = snapshot.factorisations;
        self.sol.status = snapshot.status.clone();
        self.ws.matrix.invalidate();
        self.ws.matrix.factorisations = snapshot.factorisations;
        self.sol.residual_evaluations = snapshot.residual_evaluations;
        self.ws.matrix.residuals = snapshot.residual_evaluations;
        if let Some(held) = &snapshot.matrix {
            self.adopt_matrix(held);
        }
        self.system.reset_user_groups();
    }
}

/// What the loop does after an attempt.
enum Next {
    /// Take another attempt (or stop if the target is reached).
    Go,
    /// The run stopped (its status says why).
    Stop,
}

impl Simulation<'_> {
    /// Advances to time `t` (at most the run's `t_end`), step by step; stops early when the run
    /// fails (see [`Simulation::status`]). Fixed steps land on `t` (on the grid when `t` is a
    /// grid time, otherwise with a shortened step); error-controlled steps stop at the end of
    /// the step that reaches or passes `t` ([`Simulation::time`] says where). Stored output
    /// follows the options (`save_every`, output times); an intermediate stop stores nothing of
    /// its own, so the stored states are those of one call to [`crate::simulate()`].
    pub fn step_to(&mut self, t: f64) -> &std::result::Result<(), Error> {
        self.step_to_with_observer(t, &mut Silent)
    }

    /// [`Simulation::step_to`] with an observer that sees each accepted step and may stop the
    /// run.
    pub fn step_to_with_observer(
        &mut self,
        t: f64,
        observer: &mut dyn Observer,
    ) -> &std::result::Result<(), Error> {
        if t.is_nan() {
            return &self.sol.status;
        }
        let t_end = self.options.t_end;
        // A stop within a millionth of a fixed step of the end is the end (the run lands there).
        let near_end = match &self.carried.controller {
            Controller::Fixed(fixed) => t_end - t <= 1e-6 * fixed.nominal(),
            Controller::Adaptive(_) => false,
        };
        let stop = if near_end { t_end } else { t };
        while self.sol.status.is_ok() && !self.reached(stop) {
            if let Next::Stop = self.attempt(stop, observer) {
                break;
            }
        }
        if let (Ok(()), Some(e)) = (&self.sol.status, self.system.user_failure()) {
            self.sol.status = Err(e);
        }
        &self.sol.status
    }

    /// Whether the run is at `stop`: past it, or (fixed steps, a stop before the end) on the
    /// grid point within a millionth of a step before it, where [`FixedSteps::propose`] lands
    /// a step meant for it (a stop computed as k dt by the caller may differ from the grid
    /// time in the last bits; another step of that difference would be a step of ~1e-17 s).
    fn reached(&self, stop: f64) -> bool {
        let c = &self.carried;
        match &c.controller {
            // The end is reached only when landed on (its step stores the last state).
            Controller::Fixed(_) if stop >= self.options.t_end => c.t >= stop,
            Controller::Fixed(fixed) => stop - c.t <= 1e-6 * fixed.nominal(),
            Controller::Adaptive(_) => c.t >= stop,
        }
    }

    /// One attempt at a step towards `stop`: the shared loop body.
    fn attempt(&mut self, stop: f64, observer: &mut dyn Observer) -> Next {
        let (system, time_rule, t_end) = (self.system, self.rule, self.options.t_end);
        let scheme = self.options.scheme;
        let c = &mut self.carried;
        let event_stop = match &c.controller {
            Controller::Fixed(fixed) => fixed.event_stop.filter(|&te| te > c.t && te < stop),
            Controller::Adaptive(_) => None,
        };
        // After a contact event's transient, back to the run's own grid.
        let rejoin = match &mut c.controller {
            Controller::Fixed(fixed) if event_stop.is_none() => {
                if fixed.rejoin.is_none() {
                    fixed.rejoin = fixed.rejoin_target(c.t, t_end);
                }
                fixed.rejoin.filter(|&(at, _)| at > c.t && at < stop)
            }
            _ => None,
        };
        let (h_try, end) = match &c.controller {
            Controller::Fixed(fixed) => match rejoin {
                Some((at, _)) => fixed.toward(c.t, at),
                None => fixed.propose(c.t, event_stop.unwrap_or(stop), t_end),
            },
            Controller::Adaptive(control) => {
                // Error-controlled steps are not bent to an intermediate stop: the run stops at
                // the end of the step that reaches or passes it.
                let (h, at) = control.propose(c.t, t_end);
                (h, at.map_or(StepEnd::Natural, StepEnd::At))
            }
        };
        let ends_run = end == StepEnd::At(t_end);
        // A step the times cannot resolve (a halved step, or an error-controlled one, far from
        // t = 0) stops the run rather than repeat times.
        if let Some(e) = unresolved_step(c.t, h_try) {
            self.sol.status = Err(e);
            return Next::Stop;
        }
        let mut fresh_retry = false;
        // Whether this attempt is the one at constant acceleration after an extrapolated
        // attempt that failed.
        let mut plain_retry = false;
        // Whether this attempt is full Newton's, after the attempts that reuse a matrix failed
        // (module documentation).
        let mut full_retry = false;
        let full_newton = NewtonOptions {
            jacobian_reuse: JacobianReuse::Never,
            ..self.newton
        };
        loop {
            // Predictor: the rule's own step end with the accelerations extrapolated linearly
            // (a fixed step of the last step's size), else constant-acceleration extrapolation;
            // the multipliers extrapolated linearly (fixed steps) or the last ones (error
            // control; module documentation).
            let ws = &mut self.ws;
            let extrapolated = c.acc_rate_step == h_try && !plain_retry;
            if extrapolated {
                let start = StepStart::new(c.t, &c.q, &c.v, h_try);
                let rate = if c.alternating {
                    &c.acc_rate_before
                } else {
                    &c.acc_rate
                };
                time_rule.predict(&c.rule, start, (&c.acc, rate), &mut ws.state.q);
            } else {
                extrapolate((&c.q, &c.v, &c.acc), h_try, &mut ws.state.q);
            }
            let ahead = match c.controller {
                Controller::Fixed(_) => h_try,
                Controller::Adaptive(_) => 0.0,
            };
            for (l, (&a, &r)) in ws
                .state
                .lambda
                .iter_mut()
                .zip(c.lambda.iter().zip(&c.lambda_rate))
            {
                *l = a + ahead * r;
            }
            if !fresh_retry {
                self.sol.steps_taken += 1;
            }
            // Modified Newton starting from a matrix of an earlier step gets one more attempt
            // with a fresh matrix before the step counts as failed.
            let stale = self.newton.jacobian_reuse.across_steps()
                && ws.matrix.holds(time_rule.matrix_key(h_try));
            // A step to an event found before is not searched for events again.
            let to_event = event_stop.is_some_and(|te| end == StepEnd::At(te));
            let events = matches!(c.controller, Controller::Fixed(_))
                && !self.event_forces.is_empty()
                && !to_event;
            // A step whose predictor already switches a force goes to the switch without
            // solving the whole step first (the time is found as after a solve: the root of
            // the Taylor polynomial from the step's start): on the benchmark's chain on the
            // seabed of 1,000 segments at 5 ms, 3.10 -> 2.91 s, the same error.
            if events && !fresh_retry {
                let start = (&c.q[..], &c.v[..], &c.acc[..]);
                let switch = first_event(system, &self.event_forces, start, &ws.state.q, h_try);
                if let (Some(at), Controller::Fixed(fixed)) =
                    (inside_step(switch, c.t, h_try), &mut c.controller)
                {
                    // Counted as a step rejected, as a solved step that found the switch.
                    self.sol.steps_rejected += 1;
                    go_to_switch(fixed, (system, scheme, &ws.inertia), c.t, at);
                    return Next::Go;
                }
            }
            let may_reject = matches!(c.controller, Controller::Adaptive(_)) || events;
            if may_reject {
                self.scratch.rule_saved.copy_from(&c.rule);
            }
            let start = StepStart::new(c.t, &c.q, &c.v, h_try);
            let stabilized = self.stabilized.as_mut();
            let newton = if full_retry {
                &full_newton
            } else {
                &self.newton
            };
            let attempt = time_rule.step(system, ws, stabilized, start, &mut c.rule, newton);
            self.sol.factorisations = ws.matrix.factorisations;
            self.sol.residual_evaluations = ws.matrix.residuals;
            // A failed user function stops the run at once (NaN terms would only fail again).
            if let Some(e) = system.user_failure() {
                self.sol.status = Err(e);
                return Next::Stop;
            }
            match attempt {
                Ok(report) => {
                    self.law_trouble = None;
                    let start = (&c.q[..], &c.v[..], &c.acc[..]);
                    let switch = events
                        .then(|| first_event(system, &self.event_forces, start, &ws.state.q, h_try))
                        .flatten();
                    let event = inside_step(switch, c.t, h_try);
                    // A step accepted across a jump (within EVENT_MARGIN of an end) or onto one
                    // starts the rule again on the jump's far side.
                    let restart = to_event || (switch.is_some() && event.is_none());
                    let mut settling = false;
                    if let Controller::Fixed(fixed) = &mut c.controller {
                        if let Some(at) = event {
                            // A force jumped within the step: the run steps to the jump instead,
                            // then through the transient it starts in short steps.
                            self.sol.steps_rejected += 1;
                            c.rule.copy_from(&self.scratch.rule_saved);
                            go_to_switch(fixed, (system, scheme, &ws.inertia), c.t, at);
                            return Next::Go;
                        }
                        if to_event {
                            fixed.event_stop = None;
                            fixed.home = false;
                        }
                        settling = c.t < fixed.settle_until;
                    }
                    let next = self.converged(h_try, end, ends_run, report, observer);
                    if restart && self.sol.status.is_ok() {
                        self.restart_after_event();
                    }
                    if settling {
                        if let Controller::Fixed(fixed) = &mut self.carried.controller {
                            fixed.after_event(self.carried.t);
                        }
                    }
                    return next;
                }
                Err(_) if stale => {
                    ws.matrix.invalidate();
                    fresh_retry = true;
                }
                // A step predicted from the extrapolated accelerations gets one more attempt
                // from the constant-acceleration predictor (and a fresh matrix) before it counts
                // as failed: where the accelerations turn faster than the steps resolve (the
                // tip of a long chain whipping), the extrapolation can start Newton farther
                // off than constant acceleration does.
                // (A failed attempt leaves the rule's state as it was, `index3_step`.) The run
                // then keeps to constant acceleration until a contact event's restart (a
                // negative `acc_rate_step`): a model whose extrapolated steps fail does not pay
                // for a failed attempt every other step (a cable with bending stiffness at 0.07 s
                // steps, 20 s: 8.8 residuals and 1.85 factorisations a step, against 6.5 and
                // 0.25).
                Err(_) if extrapolated => {
                    ws.matrix.invalidate();
                    fresh_retry = true;
                    plain_retry = true;
                    c.acc_rate_step = -h_try;
                }
                // Last, full Newton, a new matrix at every iterate, before the step is halved:
                // where segments go slack and taut within the step, a matrix kept over the
                // iterations can stop contracting where Newton's own converges.
                Err(_) if !full_retry && self.newton.jacobian_reuse != JacobianReuse::Never => {
                    ws.matrix.invalidate();
                    fresh_retry = true;
                    full_retry = true;
                }
                Err(failure) => {
                    self.sol.steps_rejected += 1;
                    // A step whose Newton iterations failed across a force's jump (going back
                    // and forth over the jump of a contact's damping, which the iterates cross)
                    // goes short of the jump instead, where its predictor, the step's Taylor
                    // polynomial, switches the force.
                    if events {
                        let mut predicted = vec![[0.0; 3]; c.q.len()];
                        let start = (&c.q[..], &c.v[..], &c.acc[..]);
                        extrapolate(start, h_try, &mut predicted);
                        let found =
                            first_event(system, &self.event_forces, start, &predicted, h_try);
                        let switch = inside_step(found, c.t, h_try);
                        if let (Some((s, f)), Controller::Fixed(fixed)) =
                            (switch, &mut c.controller)
                        {
                            c.rule.copy_from(&self.scratch.rule_saved);
                            let settle = system.forces()[f].settling_time(&ws.inertia);
                            fixed.go_to_event(c.t + s * (1.0 - LAND_SHORT), settle);
                            return Next::Go;
                        }
                    }
                    if self.law_trouble.is_none() {
                        self.law_trouble = system.law_failure(c.t + h_try);
                    }
                    let retry = match &mut c.controller {
                        Controller::Fixed(fixed) => {
                            // A failed step back to the run's grid is halved like any other;
                            // the way back is found again once the steps are dt.
                            fixed.rejoin = None;
                            fixed.halve()
                        }
                        Controller::Adaptive(control) => control.newton_failed(h_try),
                    };
                    if may_reject {
                        c.rule.copy_from(&self.scratch.rule_saved);
                    }
                    if retry {
                        return Next::Go;
                    }
                    // A law that was not finite at the end of an attempt is why the step failed.
                    let e = match self.law_trouble.take() {
                        Some(law) => law,
                        None => step_failure(system, &ws.layout, failure, c.t, h_try),
                    };
                    self.sol.status = Err(explain_singular(system, &c.q, c.t, e));
                    return Next::Stop;
                }
            }
        }
    }

    /// After a step that landed on a contact event or was accepted across one: a time rule
    /// that carries accelerations (generalised-alpha's a_n and qdd_n) starts again from the
    /// accelerations consistent with the state on the far side of the jump (module
    /// documentation), and so does the predictor. The far side is the state [`EVENT_MARGIN`]
    /// of a step on, q + delta v, across the last gap that landing short of the jump leaves
    /// ([`LAND_SHORT`]): a node that landed on the seabed is inside it there (one that left it,
    /// outside). The rules without such a state (the trapezoidal rules) go on unchanged.
    fn restart_after_event(&mut self) {
        let c = &mut self.carried;
        if c.rule.acceleration.is_empty() {
            return;
        }
        let delta = match &c.controller {
            Controller::Fixed(fixed) => EVENT_MARGIN * fixed.nominal(),
            Controller::Adaptive(_) => return,
        };
        let ahead: Vec<Vec3> = (c.q.iter().zip(&c.v))
            .map(|(q, v)| std::array::from_fn(|k| q[k] + delta * v[k]))
            .collect();
        let start = consistent_accelerations(self.system, &mut self.ws, &ahead, &c.v, c.t + delta);
        // The solve overwrote the workspace's factorisation.
        self.ws.matrix.invalidate();
        if let Ok((acc, _)) = start {
            c.rule = self.options.scheme.initial_state(&acc);
            c.acc = acc;
            c.acc_rate_step = 0.0;
            c.acc_rate_before_step = 0.0;
            c.alternating = false;
        }
    }

    /// A converged step of size `h` that ends at `end`: judged by the controller, then accepted
    /// (stored, checked, observed) or rejected.
    fn converged(
        &mut self,
        h: f64,
        end: StepEnd,
        ends_run: bool,
        report: crate::integrators::NewtonReport,
        observer: &mut dyn Observer,
    ) -> Next {
        let (system, time_rule) = (self.system, self.rule);
        let c = &mut self.carried;
        let s = &mut self.scratch;
        let ws = &mut self.ws;
        let start = StepStart::new(c.t, &c.q, &c.v, h);
        time_rule.end_acceleration(&c.rule, start, &ws.state.v, &mut s.acc_new);
        let t_new = match &mut c.controller {
            Controller::Fixed(fixed) => fixed.accepted(end),
            Controller::Adaptive(control) => {
                let judged = control.judge(
                    system,
                    ws,
                    self.stabilized.as_mut(),
                    &self.newton,
                    &s.rule_saved,
                    (c.t, h),
                    (&c.q, &c.v, &c.acc),
                );
                match judged {
                    Ok(true) => {
                        // The run goes on from the two half steps' end (`ws.state`).
                        control.adopt(c.t, h, &ws.state.v, &mut c.rule, &mut s.acc_new);
                        match end {
                            StepEnd::At(t) => t,
                            StepEnd::Natural => c.t + h,
                        }
                    }
                    Ok(false) => {
                        self.sol.steps_rejected += 1;
                        c.rule.copy_from(&s.rule_saved);
                        return match control.rejected(c.t, h) {
                            Ok(()) => Next::Go,
                            Err(e) => {
                                self.sol.status = Err(e);
                                Next::Stop
                            }
                        };
                    }
                    Err(e) => {
                        self.sol.status = Err(e);
                        return Next::Stop;
                    }
                }
            }
        };
        if matches!(c.controller, Controller::Fixed(_)) {
            // The rates of this step and of the one before, and which extrapolation predicted
            // this step's accelerations better, linear or lagged (module documentation): the
            // summed squares of a_{n+1} - (a_n + h r) over the particles, for r the last rate
            // and the one before, both measured over steps of this size.
            let judged = c.acc_rate_step.abs() == h && c.acc_rate_before_step == h;
            // The two sums in scalars (in an array they went through memory).
            let (mut linear, mut lagged) = (0.0f64, 0.0f64);
            let rates = c.acc_rate.iter_mut().zip(c.acc_rate_before.iter_mut());
            for ((rate, before), (end, old)) in rates.zip(s.acc_new.iter().zip(&c.acc)) {
                let new: Vec3 = std::array::from_fn(|k| (end[k] - old[k]) / h);
                if judged {
                    for k in 0..3 {
                        linear += (new[k] - rate[k]) * (new[k] - rate[k]);
                        lagged += (new[k] - before[k]) * (new[k] - before[k]);
                    }
                }
                *before = *rate;
                *rate = new;
            }
            c.alternating = judged && lagged < linear;
            c.acc_rate_before_step = c.acc_rate_step.abs();
            // Negative: the run no longer extrapolates (a failed extrapolated attempt).
            c.acc_rate_step = if c.acc_rate_step < 0.0 { -h } else { h };
        }
        std::mem::swap(&mut c.acc, &mut s.acc_new);
        // The step's end: the workspace's state (swapped into the carried state below; the
        // next step's predictor overwrites what the swap leaves there).
        let new = &mut ws.state;
        c.step += 1;
        self.sol.accepted_step_sizes.push(h);
        let stats = StepStats {
            newton_iterations: report.iterations,
            step_size: h,
            residual_norm: report.residual,
            increment_norm: report.increment,
        };
        let slack = negative_tension(system, &new.lambda, t_new, self.tension_floor);
        let sol = &mut self.sol;
        let rigid = &self.rigid[..];
        let end_stored = if let Some(outputs) = self.options.output_times.as_deref() {
            let whole = StepEnds {
                t: c.t,
                h: t_new - c.t,
                q_0: &c.q,
                v_0: &c.v,
                lambda_0: &c.lambda,
                q_1: &new.q,
                v_1: &new.v,
                lambda_1: &new.lambda,
            };
            // An error-controlled step ends with its two half steps: interpolated in each (on the
            // kicked pendulum of tests/test_adaptive.py the largest velocity error is 119 times
            // rtol, against 132 interpolated over the whole step).
            let halves = match &c.controller {
                Controller::Adaptive(control) => {
                    let (q_mid, v_mid, lambda_mid) = control.midpoint();
                    let t_mid = c.t + 0.5 * h;
                    let first = StepEnds {
                        h: t_mid - c.t,
                        q_1: q_mid,
                        v_1: v_mid,
                        lambda_1: lambda_mid,
                        ..whole
                    };
                    let second = StepEnds {
                        t: t_mid,
                        h: t_new - t_mid,
                        q_0: q_mid,
                        v_0: v_mid,
                        lambda_0: lambda_mid,
                        ..whole
                    };
                    Some((t_mid, first, second))
                }
                Controller::Fixed(_) => None,
            };
            while c.next_output < outputs.len() && outputs[c.next_output] <= t_new {
                let t_out = outputs[c.next_output];
                let ends = match halves {
                    Some((t_mid, first, _)) if t_out <= t_mid => first,
                    Some((_, _, second)) => second,
                    None => whole,
                };
                if t_out == t_new {
                    // A time on the step's end (a fixed step's grid time): its state itself.
                    store(
                        sol,
                        (system, rigid),
                        t_out,
                        (&new.q, &new.v, &new.lambda),
                        stats,
                    );
                } else {
                    ends.interpolate(t_out, &mut s.q_out, &mut s.v_out, &mut s.lambda_out);
                    store(
                        sol,
                        (system, rigid),
                        t_out,
                        (&s.q_out, &s.v_out, &s.lambda_out),
                        stats,
                    );
                }
                c.next_output += 1;
            }
            // A run that stops here shows the state where it stopped.
            slack.is_some() && sol.times.last() != Some(&t_new)
        } else {
            c.step % self.options.save_every == 0 || ends_run || slack.is_some()
        };
        if end_stored {
            let state = (&new.q[..], &new.v[..], &new.lambda[..]);
            store(sol, (system, rigid), t_new, state, stats);
        }
        std::mem::swap(&mut c.q, &mut new.q);
        std::mem::swap(&mut c.v, &mut new.v);
        for (rate, (&end, &old)) in c
            .lambda_rate
            .iter_mut()
            .zip(new.lambda.iter().zip(&c.lambda))
        {
            *rate = (end - old) / h;
        }
        std::mem::swap(&mut c.lambda, &mut new.lambda);
        c.t = t_new;
        if let Some(e) = slack {
            sol.status = Err(e);
            return Next::Stop;
        }
        let guarded = self.guard.as_ref();
        if let Some(e) = guarded.and_then(|g| g.check(system, &ws.mass, (&c.q, &c.v), (c.t, h))) {
            sol.status = Err(e);
            return Next::Stop;
        }
        if let Controller::Adaptive(control) = &mut c.controller {
            control.accepted(h);
        }
        // A run whose number of steps could not be told beforehand stops when its output
        // reaches the memory allowed, keeping what it stored.
        let (states, steps) = (sol.len() as f64, sol.accepted_step_sizes.len() as f64);
        let limit = &mut self.output_limit;
        if let Some(e) = limit.exceeded(system, &self.options, states, steps, Some(c.t)) {
            sol.status = Err(e);
            return Next::Stop;
        }
        if !observer.step(c.t, self.options.t_end) {
            // The state where the run stopped is kept, stored or not by `save_every`.
            if sol.times.last() != Some(&c.t) {
                store(sol, (system, rigid), c.t, (&c.q, &c.v, &c.lambda), stats);
            }
            sol.status = Err(Error::Interrupted { t: c.t });
            return Next::Stop;
        }
        Next::Go
    }
}

/// q + h v + h^2/2 a of every particle from `(q, v, a)` into `out`: the predictor of a step of
/// size `h` (constant-acceleration extrapolation), the Taylor polynomial along which contact
/// events are found.
pub(crate) fn extrapolate((q, v, a): (&[Vec3], &[Vec3], &[Vec3]), h: f64, out: &mut [Vec3]) {
    for (o, ((q, v), a)) in out.iter_mut().zip(q.iter().zip(v).zip(a)) {
        for k in 0..3 {
            o[k] = q[k] + h * v[k] + 0.5 * h * h * a[k];
        }
    }
}

/// Sends the fixed steps from `t` to the switch of force `f` at `s` into the step, and through
/// its transient after it: a scheme that evaluates the forces at the step's end alone lands
/// [`LAND_SHORT`] of the way short of it (module documentation).
fn go_to_switch(
    fixed: &mut FixedSteps,
    (system, scheme, inertia): (&System, Scheme, &[f64]),
    t: f64,
    (s, f): (f64, usize),
) {
    let settle = system.forces()[f].settling_time(inertia);
    let s = if scheme.evaluates_at_end() {
        s * (1.0 - LAND_SHORT)
    } else {
        s
    };
    fixed.go_to_event(t + s, settle);
}

/// A force's switch at `s` into a step of size `h` from `t` (`found`), when a step can go to
/// it: more than [`EVENT_MARGIN`] of the step from either end, and a step the times resolve.
fn inside_step(found: Option<(f64, usize)>, t: f64, h: f64) -> Option<(f64, usize)> {
    found
        .filter(|&(s, _)| s > EVENT_MARGIN * h && s < (1.0 - EVENT_MARGIN) * h)
        .filter(|&(s, _)| unresolved_step(t, s).is_none())
}

/// A force that can switch within a step ([`crate::forces::Force::has_events`]): its index,
/// and the particle and the height across which it switches (a seabed contact's node and the
/// seabed, [`crate::forces::Force::switch_height`]), for a quick look before its switch time.
#[derive(Debug, Clone, Copy)]
struct EventForce {
    force: usize,
    particle: usize,
    height: f64,
}

/// The earliest time after the start of a step of size `h` from `start` (positions,
/// velocities, accelerations) to the positions `q1` at which one of the forces `event_forces` of
/// `system` jumps, if any.
fn first_event(
    system: &System,
    event_forces: &[EventForce],
    start: (&[Vec3], &[Vec3], &[Vec3]),
    q1: &[Vec3],
    h: f64,
) -> Option<(f64, usize)> {
    let forces = system.forces();
    let q0 = start.0;
    event_forces
        .iter()
        // A force whose particle stays on one side of its height does not switch (the test
        // [`crate::forces::Force::switch_time`] makes first), looked at here without it.
        .filter(|e| {
            let (i, z) = (e.particle, e.height);
            // NaN: a seabed of varying height, which the force's own test looks at.
            z.is_nan() || ((z - q0[i][2]) > 0.0) != ((z - q1[i][2]) > 0.0)
        })
        .filter_map(|e| {
            forces[e.force]
                .switch_time(start, q1, h)
                .map(|s| (s, e.force))
        })
        .reduce(|a, b| if b.0 < a.0 { b } else { a })
}

/// Stores a state with its violations and the statistics of the step that produced it.
fn store(
    sol: &mut Solution,
    (system, rigid): (&System, &[usize]),
    t: f64,
    (q, v, lambda): (&[Vec3], &[Vec3], &[f64]),
    stats: StepStats,
) {
    let position = scaled_violation_among(system, rigid, q, t).0;
    let velocity = scaled_velocity_violation_among(system, rigid, q, v, t).0;
    sol.push(t, q, v, lambda, position, velocity, stats);
}

/// An observer that lets the run go on.
struct Silent;
impl Observer for Silent {
    fn step(&mut self, _t: f64, _t_end: f64) -> bool {
        true
    }
}

/// The first tension-only constraint whose tension is below `floor` (N), as an error.
#[inline]
pub(crate) fn negative_tension(
    system: &System,
    lambda: &[f64],
    t: f64,
    floor: f64,
) -> Option<Error> {
    // Asked after every step: a model without strings answers here, inlined in the run loop.
    if system.tension_only().is_empty() {
        return None;
    }
    system.tension_only().iter().find_map(|&c| {
        let tension = system.tension(c, lambda[c])?;
        (tension < floor).then(|| Error::NegativeTension {
            t,
            constraint: system.constraints()[c].name(c),
            index: c,
            tension,
        })
    })
}

/// The error of a step from `t` of size `h` that failed at the smallest step allowed, naming the
/// equation that dominated the residual or where the matrix was singular.
pub(crate) fn step_failure(
    system: &System,
    layout: &Layout,
    failure: NewtonFailure,
    t: f64,
    h: f64,
) -> Error {
    match failure {
        NewtonFailure::NotConverged {
            iterations,
            residual,
            worst,
        } => Error::NewtonFailed {
            t,
            dt: h,
            iterations,
            residual,
            equation: layout.equation_name(system, worst),
        },
        NewtonFailure::Singular(s) => singular_error(system, layout, t, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::pendulum;
    use crate::integrators::NewtonOptions;

    /// The largest coordinate distance between Newton's first iterate of the step from `t0` of
    /// the 1 m pendulum released horizontally (steps of `h`) and the step's converged end: from
    /// the rule's extrapolated accelerations (`extrapolated`) or at constant acceleration.
    fn predictor_distance(scheme: Scheme, h: f64, t0: f64, extrapolated: bool) -> f64 {
        let system = pendulum();
        let options = SimulationOptions {
            t_end: 1.0,
            dt: h,
            scheme,
            newton: NewtonOptions {
                tolerance: 1e-13,
                ..Default::default()
            },
            ..Default::default()
        };
        let mut run = Simulation::new(&system, &options).unwrap();
        run.step_to(t0).clone().unwrap();
        let c = &run.carried;
        assert_eq!(c.acc_rate_step, h, "the rate of a step of this size");
        let mut predicted = vec![[0.0; 3]; c.q.len()];
        if extrapolated {
            let start = StepStart::new(c.t, &c.q, &c.v, h);
            scheme
                .rule()
                .predict(&c.rule, start, (&c.acc, &c.acc_rate), &mut predicted);
        } else {
            extrapolate((&c.q, &c.v, &c.acc), h, &mut predicted);
        }
        run.step_to(t0 + h).clone().unwrap();
        predicted
            .iter()
            .zip(&run.carried.q)
            .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
            .fold(0.0, f64::max)
    }

    /// The predictor's order (docs/theory/newton.md, "The predictor"): the rule's own end of
    /// step with its accelerations extrapolated linearly is O(h^4) off the converged step, so
    /// halving the step divides the distance by about 16; the constant-acceleration
    /// extrapolation is O(h^3) off (the rule's local error), a ratio of about 8. Measured at
    /// t = 0.2 s with h = 10 and 5 ms, for the trapezoidal rule and generalised-alpha.
    #[test]
    fn the_extrapolated_predictor_is_of_order_four() {
        for scheme in [
            Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
            Scheme::GeneralizedAlpha { rho_inf: 0.9 },
        ] {
            let [new, old] = [true, false].map(|extrapolated| {
                [0.01, 0.005].map(|h| predictor_distance(scheme, h, 0.2, extrapolated))
            });
            let (new_ratio, old_ratio) = (new[0] / new[1], old[0] / old[1]);
            assert!(
                (14.0..18.0).contains(&new_ratio),
                "{scheme:?}: ratio {new_ratio}"
            );
            assert!(
                (7.0..9.0).contains(&old_ratio),
                "{scheme:?}: ratio {old_ratio}"
            );
            assert!(new[1] < 0.1 * old[1], "{scheme:?}: {new:?} {old:?}");
        }
    }

    /// The default Newton's stops add up over a run with one sign; at small steps many of them,
    /// each counting more in the velocities and multipliers (newton.rs, FIRST_INCREMENT_FLOOR).
    /// The pendulum released from the horizontal, the trapezoidal rule at 0.1 ms for 1 s: the
    /// rod's tension 2 lambda L against the closed form of energy conservation,
    /// T = m g (3 cos theta) = -3 m g z (L = 1), within 1e-5 of itself at the end with the
    /// default as with full Newton (measured: 1.9e-6 and 7.9e-7; 2.5e-4 with the stop on a
    /// share of the tolerance alone).
    #[test]
    fn the_default_newton_keeps_the_tension_at_small_steps() {
        let system = pendulum();
        for jacobian_reuse in [JacobianReuse::WhileFast, JacobianReuse::Never] {
            let options = SimulationOptions {
                t_end: 1.0,
                dt: 1e-4,
                newton: NewtonOptions {
                    jacobian_reuse,
                    ..Default::default()
                },
                ..Default::default()
            };
            let sol = crate::simulate(&system, &options).unwrap();
            assert!(sol.status.is_ok(), "{:?}", sol.status);
            // The trapezoidal rule's multipliers live at the step's middle: z there, the mean
            // of the last two states' (docs/theory/time-rules.md).
            let last = sol.len() - 1;
            let z = 0.5 * (sol.positions[6 * last + 5] + sol.positions[6 * (last - 1) + 5]);
            let tension = 2.0 * sol.multipliers[last].abs();
            let closed = -3.0 * 9.81 * z;
            let off = (tension / closed - 1.0).abs();
            assert!(
                off < 1e-5,
                "{jacobian_reuse:?}: {tension} N against {closed} N"
            );
        }
    }

    /// The longest step allowed `t` after a contact event that settles in `tau`, for a nominal
    /// step `dt` (the grid holds `EVENT_HALVINGS` levels below it, as a run with contacts'):
    /// the level `after_event` leaves from a step at dt.
    fn transient_step(dt: f64, tau: f64, t: f64) -> f64 {
        let mut fixed = FixedSteps::new(dt, EVENT_HALVINGS as usize, 0.0);
        fixed.go_to_event(0.0, tau);
        fixed.after_event(t);
        fixed.nominal()
    }

    /// The steps of a contact event's transient (module documentation): dt / 16 for the first
    /// two settling times, doubling every two, up to dt / 2 for the rest of the ten; and no
    /// doubling beyond two settling times where dt / 16 is already near them.
    #[test]
    fn the_steps_of_a_transient_double_every_two_settling_times_up_to_half_a_step() {
        let (dt, tau) = (0.005, 0.0034);
        let expected = [
            (0.5, dt / 16.0),
            (1.9, dt / 16.0),
            (2.1, dt / 8.0),
            (4.1, dt / 4.0),
            (6.1, dt / 2.0),
            (9.9, dt / 2.0),
        ];
        for (spans, h) in expected {
            assert_eq!(transient_step(dt, tau, spans * tau), h, "{spans} tau");
        }
        // dt = 0.1 s: dt / 16 = 6.25 ms, within two settling times (6.8 ms); its double is not.
        for spans in [0.5, 2.1, 4.1, 6.1, 9.9] {
            assert_eq!(
                transient_step(0.1, tau, spans * tau),
                0.1 / 16.0,
                "{spans} tau"
            );
        }
        // dt = 0.04 s and tau = 5 ms (the dropped particle): 2.5, 5 and 10 ms, then no further.
        let steps = [0.5, 2.1, 4.1, 6.1].map(|spans| transient_step(0.04, 0.005, spans * 0.005));
        assert_eq!(steps, [0.0025, 0.005, 0.01, 0.01]);
    }
}
