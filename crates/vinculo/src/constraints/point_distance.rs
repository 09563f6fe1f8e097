//! Fixed distance from a particle to a point p(t) that moves by a prescribed law (an anchor on a
//! moving tank floor, a pivot on a shaker).
//!
//! With d = q - p(t):
//! - Phi = L^2 - d.d
//! - Phi_q = -2 d^T, Hessian -2 I
//! - Phi_t = 2 d.p'
//! - Phi'' = -2 d.(a - p'') - 2 |v - p'|^2, so gamma = 2 d.p'' - 2 |v - p'|^2
//! - scale 1/(2L).

use super::Hessian;
use crate::laws::VectorLaw;
use crate::math::{dot, sub, Vec3};

/// |q - p(t)| = L.
#[derive(Debug, Clone, PartialEq)]
pub struct PointDistance {
    /// The particle.
    pub particles: [usize; 1],
    /// The moving point p(t).
    pub point: VectorLaw,
    /// The length L > 0.
    pub length: f64,
}

impl PointDistance {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        let d = sub(q[self.particles[0]], self.point.value(t));
        self.length * self.length - dot(d, d)
    }

    pub(crate) fn gradient(&self, q: &[Vec3], t: f64) -> [Vec3; 1] {
        let d = sub(q[self.particles[0]], self.point.value(t));
        [[-2.0 * d[0], -2.0 * d[1], -2.0 * d[2]]]
    }

    pub(crate) fn add_hessian(&self, _q: &[Vec3], _t: f64, w: f64, out: &mut Hessian) {
        for r in 0..3 {
            out[0][0][r][r] -= 2.0 * w;
        }
    }

    pub(crate) fn phi_t(&self, q: &[Vec3], t: f64) -> f64 {
        let (p, p1, _) = self.point.eval(t);
        2.0 * dot(sub(q[self.particles[0]], p), p1)
    }

    pub(crate) fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        let (p, p1, p2) = self.point.eval(t);
        let d = sub(q[self.particles[0]], p);
        let w = sub(v[self.particles[0]], p1);
        2.0 * dot(d, p2) - 2.0 * dot(w, w)
    }

    pub(crate) fn scale(&self) -> f64 {
        0.5 / self.length
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;
    use crate::laws::Law;

    #[test]
    fn derivatives_match_finite_differences() {
        let point = VectorLaw([
            Law::sine(0.2, 0.8, 0.1, 0.0, 1.0, 0.0).unwrap(),
            Law::polynomial(vec![0.1, -0.3, 0.5]).unwrap(),
            Law::Constant(-0.2),
        ]);
        let c = Constraint::PointDistance(Box::new(PointDistance {
            particles: [1],
            point,
            length: 0.4,
        }));
        let q = [[9.0; 3], [0.3, 0.2, 0.1]];
        let v = [[0.0; 3], [0.5, -0.7, 0.2]];
        fd::check(&c, &q, &v, 0.45);
    }
}
