//! How step sizes are chosen: fixed, or by a PI controller on a weighted norm of the local error.
//!
//! **Error norm.** The local errors e_q (m) and e_v (m/s) of a step
//! ([`crate::integrators::error_estimate`], step doubling, cut to their parts tangent to the
//! constraints) are weighed component by component, over the free particles' coordinates, with
//! root mean squares:
//!
//! ```text
//! err_q = sqrt( (1/N) sum_i (e_q,i / w_q,i)^2 ),   w_q,i = atol + rtol max(|q_n,i|, |q_{n+1},i|)
//! err_v = sqrt( (1/N) sum_i (e_v,i / w_v,i)^2 ),   w_v,i = atol_v + rtol max(|v_n,i|, |v_{n+1},i|)
//! err = max(err_q max(T / h, 1), err_v)
//! ```
//!
//! atol is a length (m); atol_v = atol U / L, with the length scale L of the model
//! ([`crate::model::System::length_scale`]) and the speed scale U the run already uses for its
//! initial velocity check (the largest initial speed, or sqrt(|g| L)). Positions count per unit
//! step (below), velocities per step: an index-3 run's velocities carry a drift off the velocity
//! constraints, set by earlier steps, of which the velocity estimate keeps O(h) times
//! (`integrators/error_estimate.rs`); per unit step no retry could bring that below the
//! tolerance, per step a smaller step does.
//!
//! **Error per unit step.** The positions count err_q T / h (err_q for steps longer than T =
//! L / U): the error a step adds is measured against the tolerance per time T, not per step. The errors of the N = (t_end - t_start)/h steps of a run add up; with the error per step
//! at the tolerance the run's error would be about N times it, and grow as the tolerance shrinks
//! (N grows as tol^(-1/(p+1)) for a scheme of order p). Per unit step, the run's error is about
//! (t_end - t_start)/T times the tolerance (before the motion's own amplification of errors),
//! proportional to the tolerance: halving the tolerance halves the error.
//!
//! **Controller.** The scaled error err_q T / h of a scheme of order p shrinks as h^k, k = p (the
//! local error as h^(p+1); err_v faster). After an accepted step the next one is
//!
//! ```text
//! h_new = h * clamp( (rho / err_n)^(0.7/k) * (err_{n-1} / rho)^(0.4/k), 1/5, 5 ),  rho = safety^k
//! ```
//!
//! (Gustafsson's PI controller with the gains of Hairer and Wanner, Solving ODEs II, IV.2: with
//! err_{n-1} = err_n it is an I controller of gain 0.3/k whose fixed point is err = rho, the
//! error of the step h safety that an exact power law err = C h^k would give; the second factor
//! damps the oscillation of the step size that a pure I controller shows when stability, not
//! accuracy, limits the step). After a rejected step the I controller alone,
//! h_new = h * max(safety * err^(-1/k), 1/5), and the following step may not grow. A step whose
//! Newton iterations fail is retried with a quarter of its size. A proposal in [h, hold h] keeps
//! h unchanged, so that modified Newton can keep its iteration matrix (its key includes h); the
//! default hold is 1, off ([`DEFAULT_HOLD`] gives the measurement).

use crate::error::{Error, Result};
use crate::math::Vec3;

/// How a run chooses its step sizes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum StepControl {
    /// Steps of the nominal size `dt`, halved where Newton fails (the exact time grid of
    /// [`crate::simulate`]).
    #[default]
    Fixed,
    /// Steps chosen by the error controller; `dt` is the first step.
    Adaptive(AdaptiveOptions),
}

/// Tolerances and limits of error-controlled steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveOptions {
    /// Relative tolerance (> 0).
    pub rtol: f64,
    /// Absolute tolerance of the positions, m (> 0).
    pub atol: f64,
    /// Smallest step, s: a run that would need a smaller one stops with
    /// [`Error::StepSizeTooSmall`].
    pub h_min: f64,
    /// Largest step, s (may be infinite).
    pub h_max: f64,
    /// Proposals between h and `hold` h keep h unchanged (>= 1; 1: always follow the controller).
    pub hold: f64,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        AdaptiveOptions {
            rtol: 1e-6,
            atol: 1e-6,
            h_min: 1e-10,
            h_max: f64::INFINITY,
            hold: DEFAULT_HOLD,
        }
    }
}

/// Default of [`AdaptiveOptions::hold`]: 1, the controller is always followed. Measured on the
/// kicked pendulum of `tests/test_adaptive.py` with modified Newton (`jacobian_reuse`), a hold of
/// 1.1 (proposals up to 10 % above the step keep it) did not pay for the second-order schemes:
/// trapezoidal 383 steps (42 rejected) and 247 factorisations against 222 steps (1 rejected)
/// and 147 without it; generalised-alpha 543 and 375 against 264 and 190. A matrix kept over
/// many steps projects the accelerations of the error estimate with stale constraint gradients,
/// which shows as step error. Backward Euler gained (1012 factorisations against 1916, for 2510
/// steps against 1993).
pub const DEFAULT_HOLD: f64 = 1.0;

/// Safety factor on the controller's proposal.
pub const SAFETY: f64 = 0.9;
/// Largest growth of the step from one step to the next.
pub const MAX_GROWTH: f64 = 5.0;
/// Largest reduction of the step after an error-test failure.
pub const MIN_SHRINK: f64 = 0.2;
/// Reduction of the step after a Newton failure.
pub const NEWTON_SHRINK: f64 = 0.25;

/// Share of the tolerance left to Newton's iteration error (error-controlled steps).
pub const NEWTON_SHARE: f64 = 0.01;
/// Smallest Newton tolerance chosen for error-controlled steps, relative to the length scale
/// (a few hundred times the round-off of a position of the size of the model).
pub const NEWTON_FLOOR: f64 = 1e-13;

impl AdaptiveOptions {
    /// Newton's tolerance relative to the length scale `length` for these tolerances: the run's
    /// `tolerance`, lowered to [`NEWTON_SHARE`] of min(rtol, atol / length) (not below
    /// [`NEWTON_FLOOR`]), so that the iteration error stays below the local error the
    /// controller allows.
    pub fn newton_tolerance(&self, tolerance: f64, length: f64) -> f64 {
        let tied = NEWTON_SHARE * self.rtol.min(self.atol / length);
        tolerance.min(tied.max(NEWTON_FLOOR))
    }

    /// Checks every option and the first step `dt` against them.
    pub fn check(&self, dt: f64) -> Result<()> {
        let bad = |name: &str, value: f64, expected: String| {
            Err(Error::InvalidParameter {
                name: name.into(),
                value,
                expected,
            })
        };
        if !(self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1.0) {
            return bad("rtol", self.rtol, "must be in (0, 1), e.g. 1e-6".into());
        }
        if !(self.atol.is_finite() && self.atol > 0.0) {
            return bad(
                "atol",
                self.atol,
                "must be finite and > 0 (an absolute position error, m)".into(),
            );
        }
        if !(self.h_min.is_finite() && self.h_min > 0.0) {
            return bad("h_min", self.h_min, "must be finite and > 0".into());
        }
        if self.h_max.is_nan() || self.h_max < self.h_min {
            return bad(
                "h_max",
                self.h_max,
                format!("must be >= h_min = {} (or infinite)", self.h_min),
            );
        }
        if !(self.hold.is_finite() && self.hold >= 1.0) {
            return bad("hold", self.hold, "must be finite and >= 1".into());
        }
        if dt < self.h_min || dt > self.h_max {
            return bad(
                "dt",
                dt,
                format!(
                    "the first step must lie in [h_min, h_max] = [{}, {}]",
                    self.h_min, self.h_max
                ),
            );
        }
        Ok(())
    }
}

/// The weights of the error norm: the absolute tolerance of positions, rtol, and the time
/// scale of the error per unit step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorWeights {
    /// Time scale T = L/U (s): the error of a step of size h < T counts T/h times.
    pub time_scale: f64,
    /// Absolute tolerance of positions (m).
    pub atol_q: f64,
    /// Absolute tolerance of velocities (m/s).
    pub atol_v: f64,
    /// Relative tolerance.
    pub rtol: f64,
}

impl ErrorWeights {
    /// The error norm of a step of size `h` with the position and velocity errors `e` over the
    /// particles marked `free`, with the states (q, v) at both ends of the step `ends`: the
    /// larger of the positions' weighted RMS norm per unit step and the velocities' per step
    /// (module documentation).
    pub fn norm(
        &self,
        h: f64,
        free: &[bool],
        (e_q, e_v): (&[Vec3], &[Vec3]),
        [(q_0, v_0), (q_1, v_1)]: [(&[Vec3], &[Vec3]); 2],
    ) -> f64 {
        let (mut sum_q, mut sum_v) = (0.0, 0.0);
        let mut count = 0usize;
        for i in (0..free.len()).filter(|&i| free[i]) {
            for k in 0..3 {
                let w_q = self.atol_q + self.rtol * q_0[i][k].abs().max(q_1[i][k].abs());
                let w_v = self.atol_v + self.rtol * v_0[i][k].abs().max(v_1[i][k].abs());
                sum_q += (e_q[i][k] / w_q).powi(2);
                sum_v += (e_v[i][k] / w_v).powi(2);
                count += 1;
            }
        }
        if count == 0 {
            return 0.0;
        }
        let n = count as f64;
        let positions = (sum_q / n).sqrt() * (self.time_scale / h).max(1.0);
        positions.max((sum_v / n).sqrt())
    }
}

/// The PI step-size controller (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PiController {
    /// Power of h in the scaled error (the scheme order, module documentation).
    pub(crate) k: f64,
    /// Error norm of the last accepted step (1 before the first).
    pub(crate) previous: f64,
    /// True when the last attempt was rejected (the next accepted step may not grow).
    pub(crate) rejected: bool,
    /// Error norms below this hold the step (module documentation).
    pub(crate) hold: f64,
}

/// Error norms below this count as this (a step with no error grows by the most allowed).
const ERROR_FLOOR: f64 = 1e-10;

impl PiController {
    /// A controller for scaled errors that shrink as h^k.
    pub fn new(k: usize, hold: f64) -> PiController {
        PiController {
            k: k as f64,
            previous: 1.0,
            rejected: false,
            hold,
        }
    }

    /// The step after an accepted step of size `h` with error norm `err` (<= 1).
    pub fn accepted(&mut self, h: f64, err: f64) -> f64 {
        let err = err.max(ERROR_FLOOR);
        let target = SAFETY.powf(self.k);
        let mut factor = (target / err).powf(0.7 / self.k)
            * (self.previous.max(ERROR_FLOOR) / target).powf(0.4 / self.k);
        factor = factor.clamp(MIN_SHRINK, MAX_GROWTH);
        if self.rejected {
            factor = factor.min(1.0);
        }
        self.previous = err;
        self.rejected = false;
        if (1.0..=self.hold).contains(&factor) {
            h
        } else {
            h * factor
        }
    }

    /// The step to retry with after a step of size `h` failed the error test with norm `err`.
    pub fn rejected(&mut self, h: f64, err: f64) -> f64 {
        self.rejected = true;
        let factor = if err.is_finite() {
            (SAFETY * err.powf(-1.0 / self.k)).max(MIN_SHRINK)
        } else {
            MIN_SHRINK
        };
        h * factor
    }

    /// The step to retry with after Newton failed on a step of size `h`.
    pub fn newton_failed(&mut self, h: f64) -> f64 {
        self.rejected = true;
        h * NEWTON_SHRINK
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a model error err = C h^k the controller settles on the step that gives
    /// err = safety^k (C h^k = safety^k solved by hand), and after a rejection the I controller
    /// lands on it in one go.
    #[test]
    fn controller_targets_the_tolerance_on_a_power_law() {
        let (c, k) = (1e6, 3usize);
        let target = (SAFETY.powi(k as i32) / c).powf(1.0 / k as f64);
        let mut control = PiController::new(k, 1.0);
        let h = 0.5 * target;
        // With err_{n-1} = err_n, the PI law is err^(-0.3/k): iterate to its fixed point.
        let mut h_n = h;
        for _ in 0..200 {
            let err = c * h_n.powi(k as i32);
            h_n = control.accepted(h_n, err);
        }
        assert!((h_n / target - 1.0).abs() < 1e-6, "{h_n} vs {target}");
        // A rejected step of twice the target is cut to the target in one go.
        let mut control = PiController::new(k, 1.0);
        let h_big = 2.0 * target;
        let retry = control.rejected(h_big, c * h_big.powi(k as i32));
        assert!((retry / target - 1.0).abs() < 1e-12, "{retry} vs {target}");
        // ... and the next accepted step does not grow.
        assert!(control.accepted(retry, 1e-3) <= retry);
    }

    /// Growth and reduction are limited, and proposals within the hold band keep the step.
    #[test]
    fn limits_and_hold() {
        let mut control = PiController::new(3, 1.0);
        assert_eq!(control.accepted(1.0, 0.0), MAX_GROWTH);
        assert_eq!(control.rejected(1.0, 1e30), MIN_SHRINK);
        assert_eq!(control.rejected(1.0, f64::NAN), MIN_SHRINK);
        let mut control = PiController::new(3, 1.5);
        // err = 0.5 from previous = 1: factor (0.729/0.5)^(0.7/3) (1/0.729)^(0.4/3) = 1.139,
        // inside [1, 1.5].
        assert_eq!(control.accepted(0.1, 0.5), 0.1);
    }

    /// The RMS norm of errors equal to their weights is 1 for steps longer than the time scale;
    /// fixed particles do not count; positions count per unit step, velocities per step.
    #[test]
    fn weighted_norm() {
        let weights = ErrorWeights {
            time_scale: 0.5,
            atol_q: 1e-3,
            atol_v: 1e-2,
            rtol: 0.1,
        };
        let q = [[1.0, 0.0, 0.0], [5.0, 5.0, 5.0]];
        let v = [[0.0, 2.0, 0.0], [0.0; 3]];
        // Weights of the free particle: q: 0.101, 0.001, 0.001; v: 0.01, 0.21, 0.01.
        let e_q = [[0.101, -0.001, 0.001], [9.0; 3]];
        let e_v = [[0.01, 0.21, -0.01], [9.0; 3]];
        let ends = [(&q[..], &v[..]), (&q[..], &v[..])];
        let err = weights.norm(1.0, &[true, false], (&e_q, &e_v), ends);
        assert!((err - 1.0).abs() < 1e-12, "{err}");
        // Per unit step: a step of a tenth of the time scale counts the positions ten times.
        let err = weights.norm(0.05, &[true, false], (&e_q, &e_v), ends);
        assert!((err - 10.0).abs() < 1e-11, "{err}");
        // The velocities count per step: without position errors the norm stays 1.
        let none = [[0.0; 3]; 2];
        let err = weights.norm(0.05, &[true, false], (&none, &e_v), ends);
        assert!((err - 1.0).abs() < 1e-12, "{err}");
    }

    /// Newton's tolerance is the run's unless a hundredth of the error tolerance (relative to
    /// the length scale) is smaller, and never below the floor.
    #[test]
    fn newton_tolerance_follows_the_error_tolerance() {
        let tight = |rtol: f64, atol: f64| AdaptiveOptions {
            rtol,
            atol,
            ..AdaptiveOptions::default()
        };
        assert_eq!(tight(1e-3, 1e-3).newton_tolerance(1e-10, 1.0), 1e-10);
        assert!((tight(1e-8, 1e-8).newton_tolerance(1e-10, 1.0) - 1e-10).abs() < 1e-25);
        assert!((tight(1e-9, 1e-6).newton_tolerance(1e-10, 1.0) - 1e-11).abs() < 1e-26);
        // atol is a length: 1e-9 m on a 10 m model is 1e-10 of it.
        assert!((tight(1e-6, 1e-9).newton_tolerance(1e-10, 10.0) - 1e-12).abs() < 1e-27);
        assert_eq!(
            tight(1e-14, 1e-14).newton_tolerance(1e-10, 1.0),
            NEWTON_FLOOR
        );
    }

    /// Every bad option is refused with its name.
    #[test]
    fn bad_options_are_named() {
        let ok = AdaptiveOptions::default();
        let cases = [
            ("rtol", AdaptiveOptions { rtol: 0.0, ..ok }),
            ("atol", AdaptiveOptions { atol: -1.0, ..ok }),
            ("h_min", AdaptiveOptions { h_min: 0.0, ..ok }),
            (
                "h_max",
                AdaptiveOptions {
                    h_min: 0.1,
                    h_max: 0.01,
                    ..ok
                },
            ),
            ("hold", AdaptiveOptions { hold: 0.5, ..ok }),
        ];
        for (name, options) in cases {
            match options.check(1e-3) {
                Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
                other => panic!("{name}: {other:?}"),
            }
        }
        assert!(
            matches!(ok.check(0.0), Err(Error::InvalidParameter { ref name, .. }) if name == "dt")
        );
    }
}
