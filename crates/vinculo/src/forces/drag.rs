//! Velocity drag on one particle.
//!
//! Linear: f = -c v, df/dv = -c I.
//! Quadratic: f = -c |v| v, df/dv = -c (|v| I + v v^T / |v|) (zero at v = 0, where f is C1).
//! Neither depends on q.

use super::Jacobian;
use crate::math::{add_mat, diag, norm, outer, scale, Vec3};

/// f = -c v.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearDrag {
    /// The particle.
    pub particles: [usize; 1],
    /// Coefficient c (N s/m).
    pub coefficient: f64,
}

impl LinearDrag {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn force(&self, _q: &[Vec3], v: &[Vec3], _t: f64) -> [Vec3; 1] {
        [scale(-self.coefficient, v[self.particles[0]])]
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        _dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        dv[0][0] = add_mat(dv[0][0], diag(-self.coefficient));
    }
}

/// f = -c |v| v.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticDrag {
    /// The particle.
    pub particles: [usize; 1],
    /// Coefficient c (N s^2/m^2), e.g. 1/2 rho Cd A.
    pub coefficient: f64,
}

impl QuadraticDrag {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn force(&self, _q: &[Vec3], v: &[Vec3], _t: f64) -> [Vec3; 1] {
        let u = v[self.particles[0]];
        [scale(-self.coefficient * norm(u), u)]
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        v: &[Vec3],
        _t: f64,
        _dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let u = v[self.particles[0]];
        let s = norm(u);
        if s > 0.0 {
            let j = add_mat(
                diag(-self.coefficient * s),
                outer(-self.coefficient / s, u, u),
            );
            dv[0][0] = add_mat(dv[0][0], j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    #[test]
    fn jacobians_match_finite_differences() {
        let q = [[0.0; 3]];
        let v = [[0.3, -1.2, 0.5]];
        fd::check(
            &Force::LinearDrag(LinearDrag {
                particles: [0],
                coefficient: 2.5,
            }),
            &q,
            &v,
            0.0,
        );
        fd::check(
            &Force::QuadraticDrag(QuadraticDrag {
                particles: [0],
                coefficient: 0.7,
            }),
            &q,
            &v,
            0.0,
        );
    }
}
