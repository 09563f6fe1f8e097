//! States between the ends of a step: output at requested times without steps landing on them.
//!
//! Positions: the cubic Hermite interpolant of (q_n, v_n) at t_n and (q_{n+1}, v_{n+1}) at
//! t_{n+1} = t_n + h. With theta = (t - t_n)/h in [0, 1],
//!
//! ```text
//! q(theta) = H00 q_n + h H10 v_n + H01 q_{n+1} + h H11 v_{n+1}
//! H00 = 2 th^3 - 3 th^2 + 1,  H10 = th^3 - 2 th^2 + th,  H01 = -2 th^3 + 3 th^2,  H11 = th^3 - th^2
//! ```
//!
//! It matches positions and velocities at both ends and interpolates a smooth motion to O(h^4).
//!
//! Velocities: the time derivative of the same cubic,
//! v(theta) = (H00' q_n + H01' q_{n+1})/h + H10' v_n + H11' v_{n+1} (primes: d/dtheta), accurate to
//! O(h^3). That is the order of the local error of the second-order schemes (and better than
//! backward Euler's h^2), it needs no accelerations (the trapezoidal rules have only mean ones), and
//! the interpolated velocities are exactly the rate of the interpolated positions, so the output
//! is one consistent motion. A quintic through the accelerations would gain an order the schemes'
//! own errors do not have.
//!
//! Multipliers: linear in time between the step's ends (they are the least smooth unknowns of an
//! index-3 solve, and a higher-order interpolant would amplify their step-to-step noise).

use crate::math::Vec3;

/// The four cubic Hermite weights (H00, H10, H01, H11) at theta and their theta-derivatives.
fn weights(theta: f64) -> ([f64; 4], [f64; 4]) {
    let (t2, t3) = (theta * theta, theta * theta * theta);
    (
        [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + theta,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ],
        [
            6.0 * t2 - 6.0 * theta,
            3.0 * t2 - 4.0 * theta + 1.0,
            -6.0 * t2 + 6.0 * theta,
            3.0 * t2 - 2.0 * theta,
        ],
    )
}

/// The two ends of an accepted step.
#[derive(Debug, Clone, Copy)]
pub struct StepEnds<'a> {
    /// Start time t_n.
    pub t: f64,
    /// Step size h.
    pub h: f64,
    /// q_n.
    pub q_0: &'a [Vec3],
    /// v_n.
    pub v_0: &'a [Vec3],
    /// lambda_n.
    pub lambda_0: &'a [f64],
    /// q_{n+1}.
    pub q_1: &'a [Vec3],
    /// v_{n+1}.
    pub v_1: &'a [Vec3],
    /// lambda_{n+1}.
    pub lambda_1: &'a [f64],
}

impl StepEnds<'_> {
    /// Writes the interpolated positions, velocities and multipliers at time `t` (in the step).
    pub fn interpolate(&self, t: f64, q: &mut [Vec3], v: &mut [Vec3], lambda: &mut [f64]) {
        let h = self.h;
        let theta = ((t - self.t) / h).clamp(0.0, 1.0);
        let (w, d) = weights(theta);
        for i in 0..q.len() {
            for k in 0..3 {
                let (q0, v0, q1, v1) = (
                    self.q_0[i][k],
                    self.v_0[i][k],
                    self.q_1[i][k],
                    self.v_1[i][k],
                );
                q[i][k] = w[0] * q0 + h * w[1] * v0 + w[2] * q1 + h * w[3] * v1;
                v[i][k] = (d[0] * q0 + d[2] * q1) / h + d[1] * v0 + d[3] * v1;
            }
        }
        for (c, l) in lambda.iter_mut().enumerate() {
            *l = (1.0 - theta) * self.lambda_0[c] + theta * self.lambda_1[c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest interpolation errors of positions and velocities over a step of size h from
    /// t = 0.3 of the motion x = sin(t) (exact ends; closed-form reference in between).
    fn errors(h: f64) -> (f64, f64) {
        let t0: f64 = 0.3;
        let (q0, v0) = ([[t0.sin(), 0.0, 0.0]], [[t0.cos(), 0.0, 0.0]]);
        let t1 = t0 + h;
        let (q1, v1) = ([[t1.sin(), 0.0, 0.0]], [[t1.cos(), 0.0, 0.0]]);
        let ends = StepEnds {
            t: t0,
            h,
            q_0: &q0,
            v_0: &v0,
            lambda_0: &[1.0],
            q_1: &q1,
            v_1: &v1,
            lambda_1: &[3.0],
        };
        let (mut q, mut v, mut l) = ([[0.0; 3]], [[0.0; 3]], [0.0]);
        let mut worst = (0.0f64, 0.0f64);
        for j in 0..=20 {
            let t = t0 + h * j as f64 / 20.0;
            ends.interpolate(t, &mut q, &mut v, &mut l);
            worst.0 = worst.0.max((q[0][0] - t.sin()).abs());
            worst.1 = worst.1.max((v[0][0] - t.cos()).abs());
            // Multipliers: the straight line between the ends.
            assert!((l[0] - (1.0 + 2.0 * (t - t0) / h)).abs() < 1e-12);
        }
        worst
    }

    /// Halving the step divides the position error by 2^4 and the velocity error by 2^3
    /// (within 0.2 in log2), and the ends are reproduced.
    #[test]
    fn orders_of_the_interpolant() {
        let (coarse, fine) = (errors(0.2), errors(0.1));
        let order_q = (coarse.0 / fine.0).log2();
        let order_v = (coarse.1 / fine.1).log2();
        assert!((order_q - 4.0).abs() < 0.2, "positions: {order_q}");
        assert!((order_v - 3.0).abs() < 0.2, "velocities: {order_v}");
        assert!(fine.0 < 1e-5 && fine.1 < 1e-3, "{fine:?}");
    }
}
