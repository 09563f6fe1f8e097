//! A torque tau(t) about a world axis n, applied to a body as a couple on two of its points:
//! an origin o and an arm point p with r = q_p - q_o normal to n (the body turns about n, as a
//! link driven at a revolute joint does).
//!
//! - f_p = tau (n x r) / |r|^2, f_o = -f_p: no net force, and the moment about o is
//!   r x f_p = tau (n |r|^2 - r (r . n)) / |r|^2 = tau n while r . n = 0;
//! - df_p/dq_p = tau ([n]x / |r|^2 - 2 (n x r) r^T / |r|^4) with [n]x r = n x r,
//!   df_p/dq_o = -df_p/dq_p, and the rows of f_o the negatives; no velocity terms;
//! - no potential (the law puts work in).

use super::Jacobian;
use crate::laws::Law;
use crate::math::{cross, dot, sub, Mat3, Vec3};

/// A torque about a world axis on the points o, p of a body.
#[derive(Debug, Clone, PartialEq)]
pub struct Couple {
    /// The origin o and the arm point p.
    pub particles: [usize; 2],
    /// The unit axis n.
    pub axis: Vec3,
    /// The torque tau(t) (N m).
    pub torque: Law,
}

impl Couple {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    fn arm(&self, q: &[Vec3]) -> (Vec3, f64) {
        let r = sub(q[self.particles[1]], q[self.particles[0]]);
        (r, dot(r, r))
    }

    pub(crate) fn force(&self, q: &[Vec3], _v: &[Vec3], t: f64) -> [Vec3; 2] {
        let (r, s) = self.arm(q);
        let tau = self.torque.value(t);
        let f: Vec3 = cross(self.axis, r).map(|x| tau * x / s);
        [f.map(|x| -x), f]
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        _v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        _dv: &mut Jacobian,
    ) {
        let (r, s) = self.arm(q);
        let tau = self.torque.value(t);
        let n = self.axis;
        let skew = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
        let nr = cross(n, r);
        let k: Mat3 = std::array::from_fn(|a| {
            std::array::from_fn(|b| tau * (skew[a][b] / s - 2.0 * nr[a] * r[b] / (s * s)))
        });
        // Blocks (o, o), (o, p), (p, o), (p, p): f_p depends on q_p - q_o.
        let blocks = dq.as_mut_slice();
        for (slot, sign) in [(0, 1.0), (1, -1.0), (2, -1.0), (3, 1.0)] {
            for a in 0..3 {
                for b in 0..3 {
                    blocks[slot][a][b] += sign * k[a][b];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    #[test]
    fn derivatives_match_finite_differences_and_the_moment_is_the_torque() {
        let n = [0.0, 0.6, 0.8];
        let c = Force::Couple(Box::new(Couple {
            particles: [2, 0],
            axis: n,
            torque: Law::sine(3.0, 0.5, 0.2, 1.0, 0.0, 0.0).unwrap(),
        }));
        // r = q_0 - q_2 normal to n.
        let q = [[1.0, 0.8, -0.6], [9.0, 9.0, 9.0], [0.5, 0.0, 0.0]];
        let v = [[0.0; 3]; 3];
        fd::check(&c, &q, &v, 0.7);
        let f = c.force(&q, &v, 0.7);
        let tau = Law::sine(3.0, 0.5, 0.2, 1.0, 0.0, 0.0).unwrap().value(0.7);
        let moment = cross(sub(q[0], q[2]), f[1]);
        for k in 0..3 {
            assert!((moment[k] - tau * n[k]).abs() < 1e-12);
            assert!((f[0][k] + f[1][k]).abs() < 1e-15);
        }
    }
}
