//! The dot product of two vectors, each the difference of two particles, follows a prescribed
//! law c(t): zero makes them perpendicular (the axis equations of a revolute or prismatic
//! joint, a point on a line or a plane of a body), a constant keeps their angle.
//!
//! With u = q_1 - q_0, w = q_3 - q_2 (particles 0..3 of the element, any of them shared):
//! - Phi = u . w - c(t)
//! - Phi_q: dPhi/dq_0 = -w^T, dPhi/dq_1 = w^T, dPhi/dq_2 = -u^T, dPhi/dq_3 = u^T
//! - Hessian: d2Phi/dq_0 dq_2 = d2Phi/dq_1 dq_3 = I, d2Phi/dq_0 dq_3 = d2Phi/dq_1 dq_2 = -I
//!   (and the transposed pairs); the blocks within one vector vanish
//! - Phi_t = -c'
//! - Phi'' = u'' . w + 2 u' . w' + u . w'' - c'', so gamma = 2 u' . w' - c''
//! - scale 1 / |w_0| (|w_0| the length of w at the start): Phi / |w_0| is, to first order, how
//!   far the end of u leaves the plane normal to w.
//!
//! The four particles are distinct; vectors that share a particle (u = q_1 - q_0 and
//! w = q_0 - q_2) are an element over points ([`super::OnPoints`]), whose map merges the two
//! slots by the chain rule.

use super::Hessian;
use crate::laws::Law;
use crate::math::{dot, sub, Vec3};

/// (q_1 - q_0) . (q_3 - q_2) = c(t).
#[derive(Debug, Clone, PartialEq)]
pub struct DotProduct {
    /// The particles 0, 1 (u = q_1 - q_0) and 2, 3 (w = q_3 - q_2).
    pub particles: [usize; 4],
    /// The prescribed value.
    pub value: Law,
    /// 1 / |w| at the start.
    pub inverse_length: f64,
}

impl DotProduct {
    fn vectors(&self, q: &[Vec3]) -> (Vec3, Vec3) {
        let [a, b, c, d] = self.particles;
        (sub(q[b], q[a]), sub(q[d], q[c]))
    }

    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        let (u, w) = self.vectors(q);
        dot(u, w) - self.value.value(t)
    }

    pub(crate) fn gradient(&self, q: &[Vec3], _t: f64) -> crate::local::PerParticle {
        let (u, w) = self.vectors(q);
        let minus = |x: Vec3| [-x[0], -x[1], -x[2]];
        crate::local::PerParticle::from_slice(&[minus(w), w, minus(u), u])
    }

    pub(crate) fn add_hessian(&self, _q: &[Vec3], _t: f64, w: f64, out: &mut Hessian) {
        let blocks = out.as_mut_slice();
        for (x, y, sign) in [(0, 2, 1.0), (1, 3, 1.0), (0, 3, -1.0), (1, 2, -1.0)] {
            for (r, c) in [(x, y), (y, x)] {
                for k in 0..3 {
                    blocks[r * 4 + c][k][k] += sign * w;
                }
            }
        }
    }

    pub(crate) fn phi_t(&self, _q: &[Vec3], t: f64) -> f64 {
        -self.value.eval(t).1
    }

    pub(crate) fn gamma(&self, _q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        let (du, dw) = self.vectors(v);
        2.0 * dot(du, dw) - self.value.eval(t).2
    }

    pub(crate) fn scale(&self) -> f64 {
        self.inverse_length
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let q = [
            [0.1, 0.2, -0.3],
            [9.0, 9.0, 9.0],
            [0.5, -0.4, 0.25],
            [1.0, 0.3, 0.7],
            [-0.2, 0.8, 0.1],
        ];
        let v = [
            [0.3, -1.0, 0.2],
            [0.0; 3],
            [-0.6, 0.1, 0.9],
            [0.4, 0.4, -0.1],
            [0.2, -0.3, 0.5],
        ];
        for particles in [[0, 2, 3, 4], [4, 0, 3, 2]] {
            let c = Constraint::DotProduct(Box::new(DotProduct {
                particles,
                value: Law::polynomial(vec![0.1, 0.4, -0.3]).unwrap(),
                inverse_length: 2.0,
            }));
            fd::check(&c, &q, &v, 0.3);
        }
    }
}
