//! One coordinate of a particle relative to another follows a prescribed law c(t): three of
//! them at zero make two points coincide (a spherical joint); one with a moving law drives a
//! slider along a world axis.
//!
//! With particles a, b and the axis e:
//! - Phi = (q_b - q_a) . e - c(t)
//! - Phi_q: dPhi/dq_a = -e^T, dPhi/dq_b = e^T; no Hessian
//! - Phi_t = -c', gamma = -c''
//! - scale 1 (Phi is a length).

use super::Hessian;
use crate::laws::Law;
use crate::math::Vec3;

/// q_b[axis] - q_a[axis] = c(t).
#[derive(Debug, Clone, PartialEq)]
pub struct RelativeCoordinate {
    /// The particles a and b.
    pub particles: [usize; 2],
    /// 0, 1 or 2 for x, y, z.
    pub axis: usize,
    /// The prescribed value (0 for a coincidence).
    pub value: Law,
}

impl RelativeCoordinate {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        let [a, b] = self.particles;
        q[b][self.axis] - q[a][self.axis] - self.value.value(t)
    }

    pub(crate) fn gradient(&self, _q: &[Vec3], _t: f64) -> [Vec3; 2] {
        let mut e = [0.0; 3];
        e[self.axis] = 1.0;
        [[-e[0], -e[1], -e[2]], e]
    }

    pub(crate) fn add_hessian(&self, _q: &[Vec3], _t: f64, _w: f64, _out: &mut Hessian) {}

    pub(crate) fn phi_t(&self, _q: &[Vec3], t: f64) -> f64 {
        -self.value.eval(t).1
    }

    pub(crate) fn gamma(&self, _q: &[Vec3], _v: &[Vec3], t: f64) -> f64 {
        -self.value.eval(t).2
    }

    pub(crate) fn scale(&self) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let c = Constraint::RelativeCoordinate(Box::new(RelativeCoordinate {
            particles: [2, 0],
            axis: 1,
            value: Law::sine(0.2, 1.5, 0.1, 0.3, 0.0, 0.0).unwrap(),
        }));
        let q = [[0.1, 0.2, -0.3], [9.0, 9.0, 9.0], [0.5, -0.4, 0.25]];
        let v = [[0.3, -1.0, 0.2], [0.0; 3], [-0.6, 0.1, 0.9]];
        fd::check(&c, &q, &v, 0.3);
    }
}
