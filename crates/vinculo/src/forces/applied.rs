//! A prescribed force F(t) on one particle (constant or any law of time). Its Jacobian is zero.

use super::Jacobian;
use crate::laws::VectorLaw;
use crate::math::Vec3;

/// f = F(t) on one particle.
#[derive(Debug, Clone, PartialEq)]
pub struct AppliedForce {
    /// The particle.
    pub particles: [usize; 1],
    /// The force components as laws of time (N).
    pub force: VectorLaw,
}

impl AppliedForce {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn force(&self, _q: &[Vec3], _v: &[Vec3], t: f64) -> [Vec3; 1] {
        [self.force.value(t)]
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        _dq: &mut Jacobian,
        _dv: &mut Jacobian,
    ) {
    }
}
