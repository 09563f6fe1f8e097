//! A law computed by a user function of time, which returns the value and its first two
//! derivatives (the constraints need them exactly: Phi_t and the acceleration terms).
//!
//! The element contract has no error channel (as for user force and constraint groups,
//! [`crate::user`]): a function that fails or returns a non-finite number makes the law record
//! the first failure, stop calling the function and return NaN. NaN residuals make the step
//! fail, and the run names the law and the failure ([`crate::error::Error::LawNotFinite`]),
//! keeping the states computed before.

use super::Derivatives;
use std::fmt;
use std::sync::{Arc, Mutex};

/// The user function: t -> (value, first derivative, second derivative), or a message.
pub type LawFunction = dyn Fn(f64) -> Result<Derivatives, String> + Send + Sync;

/// A law computed by a user function; copies share the function and its failure record.
#[derive(Clone)]
pub struct UserLaw {
    name: String,
    function: Arc<LawFunction>,
    failure: Arc<Mutex<Option<(f64, String)>>>,
}

impl UserLaw {
    /// A law named `name` (for messages) computed by `function`.
    pub fn new(name: impl Into<String>, function: Arc<LawFunction>) -> UserLaw {
        UserLaw {
            name: name.into(),
            function,
            failure: Arc::new(Mutex::new(None)),
        }
    }

    /// The law's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// (value, rate, acceleration) at `t`; NaN once the function has failed.
    pub fn eval(&self, t: f64) -> Derivatives {
        let nan = (f64::NAN, f64::NAN, f64::NAN);
        if self.failed() {
            return nan;
        }
        let why = match (self.function)(t) {
            Ok(d) if d.0.is_finite() && d.1.is_finite() && d.2.is_finite() => return d,
            Ok(d) => format!(
                "returned ({}, {}, {}): the value and its two derivatives must be finite",
                d.0, d.1, d.2
            ),
            Err(message) => format!("failed: {message}"),
        };
        self.record(t, why);
        nan
    }

    fn failed(&self) -> bool {
        self.failure.lock().map(|f| f.is_some()).unwrap_or(true)
    }

    fn record(&self, t: f64, why: String) {
        if let Ok(mut slot) = self.failure.lock() {
            slot.get_or_insert((t, format!("user law '{}' {why}", self.name)));
        }
    }

    /// The time and description of the first failure since the last [`UserLaw::reset`].
    pub fn failure(&self) -> Option<(f64, String)> {
        self.failure.lock().ok().and_then(|f| f.clone())
    }

    /// Forgets the recorded failure (done at the start of a run).
    pub fn reset(&self) {
        if let Ok(mut slot) = self.failure.lock() {
            *slot = None;
        }
    }
}

impl fmt::Debug for UserLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "UserLaw({:?})", self.name)
    }
}

/// Two user laws are equal when they are copies of one (the same function and record).
impl PartialEq for UserLaw {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.function, &other.function)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failing_function_is_recorded_once_and_gives_nan() {
        let calls = Arc::new(Mutex::new(0));
        let counted = calls.clone();
        let law = UserLaw::new(
            "guide",
            Arc::new(move |t: f64| {
                *counted.lock().unwrap() += 1;
                if t < 1.0 {
                    Ok((t, 1.0, 0.0))
                } else {
                    Err("out of range".to_string())
                }
            }),
        );
        assert_eq!(law.eval(0.5), (0.5, 1.0, 0.0));
        assert!(law.eval(2.0).0.is_nan());
        // Failed: not called again, even where it would succeed.
        assert!(law.eval(0.5).0.is_nan());
        assert_eq!(*calls.lock().unwrap(), 2);
        let (t, why) = law.failure().unwrap();
        assert_eq!(t, 2.0);
        assert!(
            why.contains("'guide'") && why.contains("out of range"),
            "{why}"
        );
        law.reset();
        assert_eq!(law.eval(0.5), (0.5, 1.0, 0.0));
    }
}
