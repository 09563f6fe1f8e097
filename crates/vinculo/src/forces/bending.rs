//! Bending stiffness of a line at one of its nodes: a force on three consecutive particles
//! (a, b, c), the discrete elastic-line energy of the second difference
//!
//! ```text
//! d = q_a - 2 q_b + q_c,        E = k/2 |d|^2,        k = EI / l^3
//! ```
//!
//! with EI the bending stiffness (N m^2) and l the node spacing (the rest length of the two
//! segments). For segments of length l that meet at a small angle theta, |d| = 2 l sin(theta/2)
//! ~ l theta, so E ~ EI theta^2 / (2 l): the energy EI kappa^2 l / 2 of a beam element of length
//! l and curvature kappa = theta / l. E is unchanged by rigid motions of the three particles
//! (d rotates with them, translations cancel) and is zero on a straight, evenly spaced line.
//!
//! Forces f_x = -dE/dq_x = -k w_x d with weights w = (1, -2, 1):
//!
//! ```text
//! f_a = -k d,     f_b = 2 k d,     f_c = -k d
//! ```
//!
//! and, since d is linear in q, the Jacobian is constant: df_x/dq_y = -k w_x w_y I (a symmetric,
//! negative semi-definite 9x9 matrix, as for any conservative force); df/dv = 0.

use super::Jacobian;
use crate::math::{add_mat, diag, scale, Vec3};

/// Weights of the three particles in the second difference d.
const WEIGHTS: [f64; 3] = [1.0, -2.0, 1.0];

/// Bending stiffness at the middle node of three consecutive particles.
#[derive(Debug, Clone, PartialEq)]
pub struct Bending {
    /// The three particles (a, b, c), b the middle node.
    pub particles: [usize; 3],
    /// k = EI / l^3 (N/m).
    pub stiffness: f64,
}

impl Bending {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    /// The second difference d = q_a - 2 q_b + q_c.
    fn difference(&self, q: &[Vec3]) -> Vec3 {
        let [a, b, c] = self.particles;
        std::array::from_fn(|k| q[a][k] - 2.0 * q[b][k] + q[c][k])
    }

    #[inline]
    pub(crate) fn force(&self, q: &[Vec3], _v: &[Vec3], _t: f64) -> [Vec3; 3] {
        let d = self.difference(q);
        WEIGHTS.map(|w| scale(-self.stiffness * w, d))
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        dq: &mut Jacobian,
        _dv: &mut Jacobian,
    ) {
        for x in 0..3 {
            for y in 0..3 {
                let block = diag(-self.stiffness * WEIGHTS[x] * WEIGHTS[y]);
                dq[x][y] = add_mat(dq[x][y], block);
            }
        }
    }

    /// Potential energy k/2 |d|^2.
    pub(crate) fn potential(&self, q: &[Vec3]) -> f64 {
        let d = self.difference(q);
        0.5 * self.stiffness * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    /// The Jacobian equals central finite differences of the forces, and the forces are minus
    /// the gradient of the potential (central differences of E), at a bent, stretched, moving
    /// configuration.
    #[test]
    fn jacobian_and_forces_match_finite_differences() {
        let f = Force::Bending(Bending {
            particles: [2, 0, 1],
            stiffness: 3.7,
        });
        let q = vec![[0.1, 0.2, -0.1], [0.6, 0.35, 0.2], [-0.4, 0.1, 0.05]];
        let v = vec![[0.3, -0.2, 0.1], [0.0, 0.5, -0.4], [0.2, 0.2, 0.2]];
        fd::check(&f, &q, &v, 0.0);
        let Force::Bending(b) = &f else {
            unreachable!()
        };
        let forces = b.force(&q, &v, 0.0);
        let h = 1e-6;
        for (x, &p) in b.particles.iter().enumerate() {
            for k in 0..3 {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[p][k] += h;
                qm[p][k] -= h;
                let grad = (b.potential(&qp) - b.potential(&qm)) / (2.0 * h);
                assert!((forces[x][k] + grad).abs() < 1e-7, "f[{x}][{k}]");
            }
        }
    }
}
