//! Laws built from laws: sums, products, quotients and elementary functions of laws, with their
//! first and second time derivatives by the chain and product rules (exact, no differencing).
//!
//! With a = (a, a', a'') and b = (b, b', b'') the derivatives of the two laws at t:
//! - sum: (a + b, a' + b', a'' + b'');
//! - product: (a b, a' b + a b', a'' b + 2 a' b' + a b'');
//! - quotient q = a / b: q' = (a' - q b') / b, q'' = (a'' - 2 q' b' - q b'') / b
//!   (from differentiating a = q b twice);
//! - function f of a law u: (f(u), f'(u) u', f''(u) u'^2 + f'(u) u'').
//!
//! A function taken outside its domain (the square root or logarithm of a negative value, a
//! quotient by zero) gives NaN or infinity; the run names the law and the time
//! ([`crate::error::Error::LawNotFinite`]).

use super::Derivatives;

/// An elementary function applied to a law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Function {
    /// sqrt(u) (u >= 0; its derivative is infinite at u = 0).
    Sqrt,
    /// sin(u).
    Sin,
    /// cos(u).
    Cos,
    /// exp(u).
    Exp,
    /// ln(u) (u > 0).
    Log,
    /// u^p for a real p (u >= 0 unless p is an integer).
    Power(f64),
}

impl Function {
    /// f(u), f'(u), f''(u).
    #[inline]
    pub fn derivatives(self, u: f64) -> Derivatives {
        match self {
            Function::Sqrt => {
                let f = u.sqrt();
                (f, 0.5 / f, -0.25 / (f * u))
            }
            Function::Sin => {
                let (s, c) = u.sin_cos();
                (s, c, -s)
            }
            Function::Cos => {
                let (s, c) = u.sin_cos();
                (c, -s, -c)
            }
            Function::Exp => {
                let e = u.exp();
                (e, e, e)
            }
            Function::Log => (u.ln(), 1.0 / u, -1.0 / (u * u)),
            Function::Power(p) => {
                if p == 0.0 {
                    return (1.0, 0.0, 0.0);
                }
                let power = |e: f64| {
                    if e.fract() == 0.0 && e.abs() < i32::MAX as f64 {
                        u.powi(e as i32)
                    } else {
                        u.powf(e)
                    }
                };
                (power(p), p * power(p - 1.0), p * (p - 1.0) * power(p - 2.0))
            }
        }
    }

    /// The function's name as written in a formula.
    pub fn name(self) -> String {
        match self {
            Function::Sqrt => "sqrt".into(),
            Function::Sin => "sin".into(),
            Function::Cos => "cos".into(),
            Function::Exp => "exp".into(),
            Function::Log => "log".into(),
            Function::Power(p) => format!("pow(., {p})"),
        }
    }
}

/// Derivatives of a + b.
#[inline]
pub fn sum(a: Derivatives, b: Derivatives) -> Derivatives {
    (a.0 + b.0, a.1 + b.1, a.2 + b.2)
}

/// Derivatives of a b.
#[inline]
pub fn product(a: Derivatives, b: Derivatives) -> Derivatives {
    (
        a.0 * b.0,
        a.1 * b.0 + a.0 * b.1,
        a.2 * b.0 + 2.0 * a.1 * b.1 + a.0 * b.2,
    )
}

/// Derivatives of a / b.
#[inline]
pub fn quotient(a: Derivatives, b: Derivatives) -> Derivatives {
    let q = a.0 / b.0;
    let q1 = (a.1 - q * b.1) / b.0;
    let q2 = (a.2 - 2.0 * q1 * b.1 - q * b.2) / b.0;
    (q, q1, q2)
}

/// Derivatives of f(u).
#[inline]
pub fn apply(f: Function, u: Derivatives) -> Derivatives {
    let (f0, f1, f2) = f.derivatives(u.0);
    (f0, f1 * u.1, f2 * u.1 * u.1 + f1 * u.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn functions_match_their_closed_form_derivatives_by_differences() {
        // Each f'(u) and f''(u) against central differences of f and f'.
        let h = 1e-6;
        let cases = [
            (Function::Sqrt, 0.7),
            (Function::Sin, 1.3),
            (Function::Cos, -0.4),
            (Function::Exp, 0.9),
            (Function::Log, 2.5),
            (Function::Power(2.5), 1.7),
            (Function::Power(-3.0), -1.2),
            (Function::Power(3.0), -0.8),
        ];
        for (f, u) in cases {
            let (_, d1, d2) = f.derivatives(u);
            let fd1 = (f.derivatives(u + h).0 - f.derivatives(u - h).0) / (2.0 * h);
            let fd2 = (f.derivatives(u + h).1 - f.derivatives(u - h).1) / (2.0 * h);
            assert!(
                (d1 - fd1).abs() < 1e-7 * (1.0 + d1.abs()),
                "{f:?}: {d1} vs {fd1}"
            );
            assert!(
                (d2 - fd2).abs() < 1e-7 * (1.0 + d2.abs()),
                "{f:?}: {d2} vs {fd2}"
            );
        }
        // Outside the domain: not finite, so that the run can name the law.
        assert!(Function::Sqrt.derivatives(-1.0).0.is_nan());
        assert!(Function::Log.derivatives(-1.0).0.is_nan());
        assert!(Function::Power(0.5).derivatives(-1.0).0.is_nan());
    }
}
