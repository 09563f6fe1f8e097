//! Fixed distance between two particles (paper eq. 17).
//!
//! With d = q_i - q_j:
//! - Phi = L^2 - d.d
//! - Phi_q: dPhi/dq_i = -2 d^T, dPhi/dq_j = +2 d^T
//! - Hessian: d2Phi/dq_i2 = d2Phi/dq_j2 = -2 I, d2Phi/dq_i dq_j = +2 I
//! - Phi_t = 0
//! - Phi'' = -2 d.(a_i - a_j) - 2 |v_i - v_j|^2, so gamma = -2 |v_i - v_j|^2
//! - scale 1/(2L): Phi/(2L) is, to first order, the change of length.
//!
//! The constraint force on i is Phi_q^T lambda = -2 lambda d: lambda > 0 pulls i towards j, and the
//! tension of the link is 2 lambda L.

use super::Hessian;
use crate::math::{diag, dot, sub, Mat3, Vec3};

/// |q_i - q_j| = L.
#[derive(Debug, Clone, PartialEq)]
pub struct Distance {
    /// The two particles.
    pub particles: [usize; 2],
    /// The length L > 0.
    pub length: f64,
}

impl Distance {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], _t: f64) -> f64 {
        let d = sub(q[self.particles[0]], q[self.particles[1]]);
        self.length * self.length - dot(d, d)
    }

    pub(crate) fn gradient(&self, q: &[Vec3], _t: f64) -> [Vec3; 2] {
        let d = sub(q[self.particles[0]], q[self.particles[1]]);
        [
            [-2.0 * d[0], -2.0 * d[1], -2.0 * d[2]],
            [2.0 * d[0], 2.0 * d[1], 2.0 * d[2]],
        ]
    }

    /// The gradient row of the constraint's particle `i` at `q`, the same numbers as its row of
    /// [`Distance::gradient`]: what the parallel residual makes again where a particle's rows
    /// gather it (`assembly/parallel.rs`).
    #[inline(always)]
    pub(crate) fn gradient_row(&self, q: &[Vec3], i: usize) -> Vec3 {
        let [a, b] = self.particles;
        let d = sub(q[a], q[b]);
        let s = if i == a { -2.0 } else { 2.0 };
        [s * d[0], s * d[1], s * d[2]]
    }

    #[inline]
    pub(crate) fn residual_and_gradient(&self, q: &[Vec3]) -> (f64, [Vec3; 2]) {
        let d = sub(q[self.particles[0]], q[self.particles[1]]);
        let phi = self.length * self.length - dot(d, d);
        let g = [-2.0 * d[0], -2.0 * d[1], -2.0 * d[2]];
        (phi, [g, [-g[0], -g[1], -g[2]]])
    }

    #[inline]
    pub(crate) fn add_hessian(&self, _q: &[Vec3], _t: f64, w: f64, out: &mut Hessian) {
        for (o, h) in out.as_mut_slice().iter_mut().zip(self.hessian(w)) {
            for r in 0..3 {
                o[r][r] += h[r][r];
            }
        }
    }

    /// `w` times the Hessian blocks (i, i), (i, j), (j, i), (j, j): -2 w I, 2 w I, 2 w I, -2 w I.
    #[inline(always)]
    pub(crate) fn hessian(&self, w: f64) -> [Mat3; 4] {
        let (same, other) = (diag(-2.0 * w), diag(2.0 * w));
        [same, other, other, same]
    }

    pub(crate) fn phi_t(&self, _q: &[Vec3], _t: f64) -> f64 {
        0.0
    }

    pub(crate) fn gamma(&self, _q: &[Vec3], v: &[Vec3], _t: f64) -> f64 {
        let w = sub(v[self.particles[0]], v[self.particles[1]]);
        -2.0 * dot(w, w)
    }

    pub(crate) fn scale(&self) -> f64 {
        0.5 / self.length
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;

    /// Each particle's row made alone is its row of the gradient, bit for bit (the parallel
    /// residual's distances give the serial one's numbers).
    #[test]
    fn a_gradient_row_is_the_gradient_s_row() {
        let d = Distance {
            particles: [2, 0],
            length: 0.7,
        };
        let q = [[0.1, 0.2, -0.3], [9.0, 9.0, 9.0], [0.5, -0.4, 0.25]];
        let rows = d.gradient(&q, 0.0);
        assert_eq!(d.gradient_row(&q, 2), rows[0]);
        assert_eq!(d.gradient_row(&q, 0), rows[1]);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let c = Constraint::Distance(Distance {
            particles: [0, 2],
            length: 0.7,
        });
        let q = [[0.1, 0.2, -0.3], [9.0, 9.0, 9.0], [0.5, -0.4, 0.25]];
        let v = [[0.3, -1.0, 0.2], [0.0; 3], [-0.6, 0.1, 0.9]];
        fd::check(&c, &q, &v, 0.3);
    }
}
