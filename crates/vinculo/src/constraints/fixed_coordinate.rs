//! One coordinate of a particle follows a prescribed law c(t) (a constant by default).
//!
//! - Phi = q[axis] - c(t)
//! - Phi_q = e_axis^T, no Hessian
//! - Phi_t = -c'
//! - gamma = -c''
//! - scale 1.

use super::Hessian;
use crate::laws::Law;
use crate::math::Vec3;

/// q[axis] = c(t).
#[derive(Debug, Clone, PartialEq)]
pub struct FixedCoordinate {
    /// The particle.
    pub particles: [usize; 1],
    /// 0, 1 or 2 for x, y, z.
    pub axis: usize,
    /// The prescribed value.
    pub value: Law,
}

impl FixedCoordinate {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        q[self.particles[0]][self.axis] - self.value.value(t)
    }

    pub(crate) fn gradient(&self, _q: &[Vec3], _t: f64) -> [Vec3; 1] {
        let mut g = [0.0; 3];
        g[self.axis] = 1.0;
        [g]
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
        let c = Constraint::FixedCoordinate(Box::new(FixedCoordinate {
            particles: [0],
            axis: 2,
            value: Law::sine(0.1, 2.0, 0.3, 1.0, 0.0, 0.0).unwrap(),
        }));
        fd::check(&c, &[[0.1, 0.2, 1.05]], &[[0.4, 0.0, -0.3]], 0.2);
    }
}
