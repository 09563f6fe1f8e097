//! Prescribed functions of time (motions of anchors, planes, applied forces), evaluated by the
//! core itself together with their first and second derivatives so that constraints can supply
//! Phi_t and the acceleration terms exactly.
//!
//! Laws compose ([`compose`]): sums, products, quotients and elementary functions of laws keep
//! exact derivatives, so a guide moving as sqrt(L^2 - y(t)^2) is written as that formula rather
//! than tabulated. A law may also be a user function that returns its own derivatives
//! ([`UserLaw`]).

pub mod compose;
mod piecewise;
mod spline;
mod user;

pub use compose::Function;
pub use piecewise::{DrivenLaw, PiecewiseLinear};
pub use spline::{CubicSpline, EndCondition};
pub use user::{LawFunction, UserLaw};

use crate::error::{finite, non_negative, Error, Result};
use std::f64::consts::PI;

/// A scalar law of time with analytic first and second derivatives.
#[derive(Debug, Clone, PartialEq)]
pub enum Law {
    /// A constant value.
    Constant(f64),
    /// c0 + c1 t + c2 t^2 + ... (coefficients in increasing powers of t).
    Polynomial(Vec<f64>),
    /// offset + amplitude s(t) sin(2 pi frequency (t - t_start) + phase).
    ///
    /// `s` is 1 when `ramp_time` is 0; otherwise the C2 quintic ramp
    /// s = 10 tau^3 - 15 tau^4 + 6 tau^5, tau = (t - t_start) / ramp_time clamped to [0, 1],
    /// which starts the motion with zero value, velocity and acceleration.
    Sine {
        /// Amplitude.
        amplitude: f64,
        /// Frequency in Hz.
        frequency: f64,
        /// Phase in radians.
        phase: f64,
        /// Constant offset.
        offset: f64,
        /// Duration of the smooth ramp-up in seconds (0: no ramp).
        ramp_time: f64,
        /// Time at which the sine (and its ramp) starts.
        t_start: f64,
    },
    /// Cubic spline through tabulated samples (C2; natural, clamped or not-a-knot ends). Runs
    /// must stay within the sample range ([`Law::domain`]); evaluated outside it, the spline
    /// continues along its end tangents.
    Tabulated(CubicSpline),
    /// Linear interpolation through tabulated knots (C0; left-continuous first derivative, see
    /// [`PiecewiseLinear`]), constant outside them.
    PiecewiseLinear(PiecewiseLinear),
    /// A piecewise-linear law whose knots are set while the run is stepped ([`DrivenLaw`]).
    Driven(DrivenLaw),
    /// The sum of two laws.
    Sum(Box<[Law; 2]>),
    /// The product of two laws.
    Product(Box<[Law; 2]>),
    /// The quotient of two laws (numerator, denominator).
    Quotient(Box<[Law; 2]>),
    /// An elementary function of a law.
    Apply(Function, Box<Law>),
    /// A user function of time returning its value and two derivatives ([`UserLaw`]).
    User(UserLaw),
}

/// (value, first derivative, second derivative)
pub type Derivatives = (f64, f64, f64);

impl Law {
    /// A constant, validated.
    pub fn constant(value: f64) -> Result<Law> {
        Ok(Law::Constant(finite("constant law value", value)?))
    }

    /// A polynomial in increasing powers, validated.
    pub fn polynomial(coefficients: Vec<f64>) -> Result<Law> {
        if coefficients.is_empty() {
            return Err(Error::InvalidParameter {
                name: "number of polynomial coefficients".into(),
                value: 0.0,
                expected: "give at least one coefficient".into(),
            });
        }
        for (k, c) in coefficients.iter().enumerate() {
            finite(format!("polynomial coefficient c{k}"), *c)?;
        }
        Ok(Law::Polynomial(coefficients))
    }

    /// A sine with optional smooth ramp, validated.
    pub fn sine(
        amplitude: f64,
        frequency: f64,
        phase: f64,
        offset: f64,
        ramp_time: f64,
        t_start: f64,
    ) -> Result<Law> {
        Ok(Law::Sine {
            amplitude: finite("sine amplitude", amplitude)?,
            frequency: non_negative("sine frequency", frequency)?,
            phase: finite("sine phase", phase)?,
            offset: finite("sine offset", offset)?,
            ramp_time: non_negative("sine ramp_time", ramp_time)?,
            t_start: finite("sine t_start", t_start)?,
        })
    }

    /// A natural cubic spline through samples, validated.
    pub fn tabulated(times: Vec<f64>, values: Vec<f64>) -> Result<Law> {
        Ok(Law::Tabulated(CubicSpline::new(times, values)?))
    }

    /// A cubic spline through samples with the given end condition, validated.
    pub fn tabulated_with(times: Vec<f64>, values: Vec<f64>, ends: EndCondition) -> Result<Law> {
        Ok(Law::Tabulated(CubicSpline::with_ends(times, values, ends)?))
    }

    /// a + b.
    pub fn sum(a: Law, b: Law) -> Law {
        Law::Sum(Box::new([a, b]))
    }

    /// a b.
    pub fn product(a: Law, b: Law) -> Law {
        Law::Product(Box::new([a, b]))
    }

    /// a / b.
    pub fn quotient(a: Law, b: Law) -> Law {
        Law::Quotient(Box::new([a, b]))
    }

    /// f(a).
    pub fn apply(f: Function, a: Law) -> Result<Law> {
        if let Function::Power(p) = f {
            finite("power exponent", p)?;
        }
        Ok(Law::Apply(f, Box::new(a)))
    }

    /// Linear interpolation through knots, validated (see [`PiecewiseLinear`]).
    pub fn piecewise_linear(times: Vec<f64>, values: Vec<f64>) -> Result<Law> {
        Ok(Law::PiecewiseLinear(PiecewiseLinear::new(times, values)?))
    }

    /// Value at `t`.
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        self.eval(t).0
    }

    /// Value, first and second derivative at `t`. A constant is answered where it is asked (the
    /// unstretched length of every segment of a line, at every evaluation of a residual), the
    /// other kinds out of line (`Law::eval_varying`).
    #[inline(always)]
    pub fn eval(&self, t: f64) -> Derivatives {
        match self {
            Law::Constant(c) => (*c, 0.0, 0.0),
            _ => self.eval_varying(t),
        }
    }

    /// [`Law::eval`] of the kinds other than a constant.
    #[inline(never)]
    fn eval_varying(&self, t: f64) -> Derivatives {
        match self {
            Law::Constant(c) => (*c, 0.0, 0.0),
            Law::Polynomial(c) => {
                // Horner's scheme for p, p', p'' together.
                let (mut p, mut d1, mut d2) = (0.0, 0.0, 0.0);
                for &ck in c.iter().rev() {
                    d2 = d2 * t + 2.0 * d1;
                    d1 = d1 * t + p;
                    p = p * t + ck;
                }
                (p, d1, d2)
            }
            Law::Sine {
                amplitude,
                frequency,
                phase,
                offset,
                ramp_time,
                t_start,
            } => {
                let w = 2.0 * PI * frequency;
                let arg = w * (t - t_start) + phase;
                let (sn, cs) = arg.sin_cos();
                let (g, g1, g2) = (sn, w * cs, -w * w * sn);
                let (s, s1, s2) = ramp(t - t_start, *ramp_time);
                (
                    offset + amplitude * s * g,
                    amplitude * (s1 * g + s * g1),
                    amplitude * (s2 * g + 2.0 * s1 * g1 + s * g2),
                )
            }
            Law::Tabulated(spline) => spline.eval(t),
            Law::PiecewiseLinear(table) => table.eval(t),
            Law::Driven(driven) => driven.eval(t),
            Law::Sum(ab) => compose::sum(ab[0].eval(t), ab[1].eval(t)),
            Law::Product(ab) => compose::product(ab[0].eval(t), ab[1].eval(t)),
            Law::Quotient(ab) => compose::quotient(ab[0].eval(t), ab[1].eval(t)),
            Law::Apply(f, a) => compose::apply(*f, a.eval(t)),
            Law::User(user) => user.eval(t),
        }
    }

    /// The laws this one is made of (none for a law that is not composed).
    fn parts(&self) -> &[Law] {
        match self {
            Law::Sum(ab) | Law::Product(ab) | Law::Quotient(ab) => &ab[..],
            Law::Apply(_, a) => std::slice::from_ref(a),
            _ => &[],
        }
    }

    /// Interval of time on which the law is defined (for a composed law, the intersection of
    /// its parts').
    pub fn domain(&self) -> (f64, f64) {
        match self {
            Law::Tabulated(s) => s.domain(),
            other => common_domain(other.parts()),
        }
    }

    /// True when the law does not depend on time.
    pub fn is_constant(&self) -> bool {
        match self {
            Law::Constant(_) => true,
            Law::Polynomial(c) => c.len() == 1,
            Law::Sum(_) | Law::Product(_) | Law::Quotient(_) | Law::Apply(..) => {
                self.parts().iter().all(Law::is_constant)
            }
            _ => false,
        }
    }

    /// Why the law cannot be used at `t`, and when: a user function that failed (since its last
    /// [`UserLaw::reset`], at the time it failed), or a value or derivative that is not finite at
    /// `t` (a square root of a negative value, a quotient by zero). None when it evaluates to
    /// finite numbers.
    pub fn failure_at(&self, t: f64) -> Option<(f64, String)> {
        let (x, d1, d2) = self.eval(t);
        // A user function that failed (now or before) is the cause of whatever is not finite.
        if let Some(failure) = self.user_laws().iter().find_map(|u| u.failure()) {
            return Some(failure);
        }
        if let Some(why) = self.parts().iter().find_map(|l| l.failure_at(t)) {
            return Some(why);
        }
        (!(x.is_finite() && d1.is_finite() && d2.is_finite())).then(|| {
            let formula = self.formula();
            (
                t,
                format!("{formula} is ({x}, {d1}, {d2}) (value, rate, acceleration)"),
            )
        })
    }

    /// The user laws this law is made of (itself, when it is one).
    pub fn user_laws(&self) -> Vec<&UserLaw> {
        match self {
            Law::User(user) => vec![user],
            other => other.parts().iter().flat_map(Law::user_laws).collect(),
        }
    }

    /// The law as a formula, e.g. `sqrt((4 + -1 * sine(...)^2))`, for messages.
    pub fn formula(&self) -> String {
        match self {
            Law::Constant(c) => format!("{c}"),
            Law::Polynomial(c) => format!("polynomial{c:?}"),
            Law::Sine {
                amplitude,
                frequency,
                ..
            } => format!("sine(amplitude={amplitude}, frequency={frequency})"),
            Law::Tabulated(s) => format!("tabulated(on {:?})", s.domain()),
            Law::PiecewiseLinear(_) => "piecewise_linear(...)".into(),
            Law::Driven(_) => "driven(...)".into(),
            Law::Sum(ab) => format!("({} + {})", ab[0].formula(), ab[1].formula()),
            Law::Product(ab) => format!("{} * {}", ab[0].formula(), ab[1].formula()),
            Law::Quotient(ab) => format!("{} / ({})", ab[0].formula(), ab[1].formula()),
            Law::Apply(Function::Power(p), a) => format!("({})^{p}", a.formula()),
            Law::Apply(f, a) => format!("{}({})", f.name(), a.formula()),
            Law::User(user) => format!("user law '{}'", user.name()),
        }
    }
}

/// The interval on which all of `laws` are defined (the whole line when there is none).
pub fn common_domain<'a>(laws: impl IntoIterator<Item = &'a Law>) -> (f64, f64) {
    laws.into_iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(a, b), l| {
            let (c, d) = l.domain();
            (a.max(c), b.min(d))
        })
}

/// The C2 quintic ramp s(tau) and its time derivatives for elapsed time `dt` over `duration`.
fn ramp(elapsed: f64, duration: f64) -> Derivatives {
    if duration <= 0.0 {
        return (1.0, 0.0, 0.0);
    }
    if elapsed <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if elapsed >= duration {
        return (1.0, 0.0, 0.0);
    }
    let tau = elapsed / duration;
    let t2 = tau * tau;
    let t3 = t2 * tau;
    (
        t3 * (10.0 - 15.0 * tau + 6.0 * t2),
        30.0 * t2 * (1.0 - 2.0 * tau + t2) / duration,
        60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2) / (duration * duration),
    )
}

/// A prescribed vector: one scalar law per component.
#[derive(Debug, Clone, PartialEq)]
pub struct VectorLaw(pub [Law; 3]);

impl VectorLaw {
    /// A constant vector.
    pub fn constant(v: [f64; 3]) -> VectorLaw {
        VectorLaw([
            Law::Constant(v[0]),
            Law::Constant(v[1]),
            Law::Constant(v[2]),
        ])
    }

    /// Value, first and second derivatives at `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let mut p = [0.0; 3];
        let mut d1 = [0.0; 3];
        let mut d2 = [0.0; 3];
        for k in 0..3 {
            (p[k], d1[k], d2[k]) = self.0[k].eval(t);
        }
        (p, d1, d2)
    }

    /// Value at `t`.
    #[inline]
    pub fn value(&self, t: f64) -> [f64; 3] {
        [self.0[0].value(t), self.0[1].value(t), self.0[2].value(t)]
    }

    /// The three components.
    pub fn components(&self) -> &[Law] {
        &self.0
    }

    /// Why a component cannot be used at `t` ([`Law::failure_at`]).
    pub fn failure_at(&self, t: f64) -> Option<(f64, String)> {
        self.0.iter().find_map(|l| l.failure_at(t))
    }

    /// Intersection of the components' domains.
    pub fn domain(&self) -> (f64, f64) {
        common_domain(&self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central finite differences of the value and of the first derivative.
    fn check_fd(law: &Law, t: f64) {
        let h = 1e-5;
        let (_, d1, d2) = law.eval(t);
        let fd1 = (law.value(t + h) - law.value(t - h)) / (2.0 * h);
        let fd2 = (law.eval(t + h).1 - law.eval(t - h).1) / (2.0 * h);
        let scale = 1.0 + d1.abs() + d2.abs();
        assert!((d1 - fd1).abs() < 1e-6 * scale, "d1 {d1} vs fd {fd1}");
        assert!((d2 - fd2).abs() < 1e-6 * scale, "d2 {d2} vs fd {fd2}");
    }

    #[test]
    fn polynomial_derivatives_match_closed_form() {
        // p = 1 + 2t + 3t^2 + 4t^3: p' = 2 + 6t + 12t^2, p'' = 6 + 24t.
        let p = Law::polynomial(vec![1.0, 2.0, 3.0, 4.0]).unwrap();
        let t = 0.7;
        let (v, d1, d2) = p.eval(t);
        assert!((v - (1.0 + 2.0 * t + 3.0 * t * t + 4.0 * t * t * t)).abs() < 1e-14);
        assert!((d1 - (2.0 + 6.0 * t + 12.0 * t * t)).abs() < 1e-14);
        assert!((d2 - (6.0 + 24.0 * t)).abs() < 1e-14);
    }

    #[test]
    fn ramped_sine_derivatives_match_finite_differences() {
        let s = Law::sine(0.005, 0.9, 0.3, 0.1, 2.0, 0.5).unwrap();
        for &t in &[0.6, 1.0, 1.7, 2.4, 3.0] {
            check_fd(&s, t);
        }
        // Before the start: offset only, at rest.
        assert_eq!(s.eval(0.2), (0.1, 0.0, 0.0));
        // After the ramp: the plain sine.
        let t = 3.1;
        let w = 2.0 * PI * 0.9;
        assert!((s.value(t) - (0.1 + 0.005 * (w * (t - 0.5) + 0.3).sin())).abs() < 1e-15);
    }

    #[test]
    fn a_moving_guide_law_has_the_derivatives_of_its_closed_form() {
        // x(t) = sqrt(L^2 - y(t)^2), y = a sin(w t): with u = L^2 - y^2, u' = -2 y y',
        // u'' = -2 (y'^2 + y y''), x' = u' / (2 x), x'' = u'' / (2 x) - u'^2 / (4 x^3)
        // (differentiated by hand, independently of the chain rule in `compose`).
        let (l, a, f) = (2.0, 0.7, 0.4);
        let w = 2.0 * PI * f;
        let y = Law::sine(a, f, 0.0, 0.0, 0.0, 0.0).unwrap();
        let square = Law::apply(Function::Power(2.0), y).unwrap();
        let u = Law::sum(
            Law::Constant(l * l),
            Law::product(Law::Constant(-1.0), square),
        );
        let x = Law::apply(Function::Sqrt, u).unwrap();
        for &t in &[0.0, 0.3, 0.9, 1.7, 2.2] {
            let (y0, y1, y2) = (
                a * (w * t).sin(),
                a * w * (w * t).cos(),
                -a * w * w * (w * t).sin(),
            );
            let u0 = l * l - y0 * y0;
            let (u1, u2) = (-2.0 * y0 * y1, -2.0 * (y1 * y1 + y0 * y2));
            let x0 = u0.sqrt();
            let expected = (
                x0,
                u1 / (2.0 * x0),
                u2 / (2.0 * x0) - u1 * u1 / (4.0 * x0.powi(3)),
            );
            let got = x.eval(t);
            assert!((got.0 - expected.0).abs() < 1e-14, "{t}");
            assert!((got.1 - expected.1).abs() < 1e-13, "{t}");
            assert!((got.2 - expected.2).abs() < 1e-12, "{t}");
            check_fd(&x, t);
        }
        assert!(!x.is_constant() && x.domain() == (f64::NEG_INFINITY, f64::INFINITY));
        assert!(x.failure_at(0.5).is_none());
    }

    #[test]
    fn products_quotients_and_functions_match_finite_differences() {
        let p = Law::polynomial(vec![1.0, -0.5, 0.25]).unwrap();
        let s = Law::sine(0.3, 0.7, 0.2, 2.0, 0.0, 0.0).unwrap();
        let laws = [
            Law::product(p.clone(), s.clone()),
            Law::quotient(s.clone(), p.clone()),
            Law::apply(Function::Exp, Law::product(p.clone(), Law::Constant(0.3))).unwrap(),
            Law::apply(Function::Log, s.clone()).unwrap(),
            Law::apply(Function::Cos, Law::quotient(p.clone(), s.clone())).unwrap(),
            Law::apply(Function::Power(1.5), s.clone()).unwrap(),
        ];
        for law in &laws {
            for &t in &[0.1, 0.8, 1.6] {
                check_fd(law, t);
            }
        }
        // Constant parts make a constant law; a table's domain carries through.
        let c = Law::apply(Function::Sqrt, Law::Constant(4.0)).unwrap();
        assert!(c.is_constant() && c.value(3.0) == 2.0);
        let table = Law::tabulated(vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.0]).unwrap();
        assert_eq!(Law::sum(table, s).domain(), (0.0, 2.0));
    }

    #[test]
    fn a_law_outside_its_functions_domain_names_itself_and_the_time() {
        // sqrt(1 - t): defined up to t = 1; at t = 1.5 the value is NaN.
        let u = Law::polynomial(vec![1.0, -1.0]).unwrap();
        let x = Law::apply(Function::Sqrt, u).unwrap();
        assert!(x.failure_at(0.5).is_none());
        let (t, why) = x.failure_at(1.5).unwrap();
        assert_eq!(t, 1.5);
        assert!(why.starts_with("sqrt(polynomial[1.0, -1.0])"), "{why}");
        assert!(Law::apply(Function::Power(f64::NAN), Law::Constant(1.0)).is_err());
    }

    #[test]
    fn ramp_is_c2_at_both_ends() {
        // s, s', s'' are continuous at tau = 0 and tau = 1 (values 0,0,0 and 1,0,0).
        let (a, b, c) = ramp(1e-9, 1.0);
        assert!(a.abs() < 1e-20 && b.abs() < 1e-15 && c.abs() < 1e-7);
        let (a, b, c) = ramp(1.0 - 1e-9, 1.0);
        assert!((a - 1.0).abs() < 1e-15 && b.abs() < 1e-15 && c.abs() < 1e-7);
    }
}
