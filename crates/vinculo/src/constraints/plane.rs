//! A particle on a plane through a point p0(t) with normal n(t) (paper eq. 18, with motion).
//!
//! With d = q - p0:
//! - Phi = n.d
//! - Phi_q = n^T, no Hessian
//! - Phi_t = n'.d - n.p0'
//! - Phi'' = n.(a - p0'') + 2 n'.(v - p0') + n''.d, so gamma = n''.d + 2 n'.(v - p0') - n.p0''
//! - scale 1/|n(t0)|: Phi/|n| is the signed distance to the plane.
//!
//! The constraint force is n lambda: with a unit normal, lambda is the normal force.

use super::Hessian;
use crate::laws::VectorLaw;
use crate::math::{dot, sub, Vec3};

/// n(t).(q - p0(t)) = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// The particle.
    pub particles: [usize; 1],
    /// Normal n(t) (need not be unit).
    pub normal: VectorLaw,
    /// A point p0(t) of the plane.
    pub point: VectorLaw,
    /// 1/|n| at the start of the run.
    pub inverse_normal_length: f64,
}

impl Plane {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        dot(
            self.normal.value(t),
            sub(q[self.particles[0]], self.point.value(t)),
        )
    }

    pub(crate) fn gradient(&self, _q: &[Vec3], t: f64) -> [Vec3; 1] {
        [self.normal.value(t)]
    }

    pub(crate) fn add_hessian(&self, _q: &[Vec3], _t: f64, _w: f64, _out: &mut Hessian) {}

    pub(crate) fn phi_t(&self, q: &[Vec3], t: f64) -> f64 {
        let (n, n1, _) = self.normal.eval(t);
        let (p, p1, _) = self.point.eval(t);
        dot(n1, sub(q[self.particles[0]], p)) - dot(n, p1)
    }

    pub(crate) fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        let (n, n1, n2) = self.normal.eval(t);
        let (p, p1, p2) = self.point.eval(t);
        let i = self.particles[0];
        dot(n2, sub(q[i], p)) + 2.0 * dot(n1, sub(v[i], p1)) - dot(n, p2)
    }

    pub(crate) fn scale(&self) -> f64 {
        self.inverse_normal_length
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;
    use crate::laws::Law;

    #[test]
    fn derivatives_match_finite_differences() {
        let normal = VectorLaw([
            Law::sine(0.3, 0.5, 0.0, 0.1, 0.0, 0.0).unwrap(),
            Law::Constant(0.2),
            Law::polynomial(vec![1.0, 0.2, -0.1]).unwrap(),
        ]);
        let point = VectorLaw([
            Law::Constant(0.1),
            Law::sine(0.05, 1.1, 0.4, 0.0, 0.0, 0.0).unwrap(),
            Law::polynomial(vec![0.0, 0.3, 0.2]).unwrap(),
        ]);
        let c = Constraint::Plane(Box::new(Plane {
            particles: [0],
            normal,
            point,
            inverse_normal_length: 1.0,
        }));
        let q = [[0.3, -0.2, 0.4]];
        let v = [[0.1, 0.8, -0.5]];
        fd::check(&c, &q, &v, 0.7);
    }
}
