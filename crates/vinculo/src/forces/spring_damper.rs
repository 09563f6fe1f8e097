//! Linear spring and dashpot between two particles.
//!
//! With d = q_a - q_b, l = |d|, e = d/l, w = v_a - v_b, l' = e.w and the axial force
//! T = k (l - L0) + c l', the applied forces are f_a = -T e, f_b = +T e.
//!
//! Using de/dq_a = P/l with P = I - e e^T and dl'/dq_a = w^T P / l, dl'/dv_a = e^T:
//! - df_a/dq_a = -k e e^T - (c/l) e w^T P - (T/l) P,   df_a/dq_b = -df_a/dq_a,
//! - df_a/dv_a = -c e e^T,                              df_a/dv_b = +c e e^T,
//! - f_b = -f_a gives the other two rows.
//!
//! Potential energy 1/2 k (l - L0)^2.

use super::Jacobian;
use crate::math::{add_mat, diag, dot, norm, outer, scale, scale_mat, sub, Mat3, Vec3};

/// Spring of stiffness k and rest length L0 with a parallel dashpot c.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringDamper {
    /// The two particles.
    pub particles: [usize; 2],
    /// Stiffness k (N/m).
    pub stiffness: f64,
    /// Damping c (N s/m).
    pub damping: f64,
    /// Rest length L0 (m).
    pub rest_length: f64,
}

impl SpringDamper {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    fn axial(&self, q: &[Vec3], v: &[Vec3]) -> (Vec3, f64, Vec3, f64) {
        let [a, b] = self.particles;
        let d = sub(q[a], q[b]);
        let l = norm(d).max(f64::MIN_POSITIVE);
        let e = scale(1.0 / l, d);
        let w = sub(v[a], v[b]);
        let tension = self.stiffness * (l - self.rest_length) + self.damping * dot(e, w);
        (e, l, w, tension)
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], _t: f64) -> [Vec3; 2] {
        let (e, _, _, tension) = self.axial(q, v);
        [scale(-tension, e), scale(tension, e)]
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        _t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let (e, l, w, tension) = self.axial(q, v);
        let p = add_mat(diag(1.0), outer(-1.0, e, e));
        let mut wp = [0.0; 3];
        for (c, x) in wp.iter_mut().enumerate() {
            *x = (0..3).map(|r| w[r] * p[r][c]).sum();
        }
        let kaa: Mat3 = add_mat(
            add_mat(
                outer(-self.stiffness, e, e),
                outer(-self.damping / l, e, wp),
            ),
            scale_mat(-tension / l, p),
        );
        let caa = outer(-self.damping, e, e);
        for (x, y, s) in [(0, 0, 1.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)] {
            dq[x][y] = add_mat(dq[x][y], scale_mat(s, kaa));
            dv[x][y] = add_mat(dv[x][y], scale_mat(s, caa));
        }
    }

    pub(crate) fn potential(&self, q: &[Vec3]) -> f64 {
        let l = norm(sub(q[self.particles[0]], q[self.particles[1]]));
        0.5 * self.stiffness * (l - self.rest_length).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    #[test]
    fn jacobians_match_finite_differences() {
        let f = Force::SpringDamper(SpringDamper {
            particles: [0, 1],
            stiffness: 120.0,
            damping: 3.5,
            rest_length: 0.3,
        });
        let q = [[0.1, -0.2, 0.3], [0.4, 0.1, -0.2]];
        let v = [[0.5, 0.2, -0.1], [-0.3, 0.4, 0.6]];
        fd::check(&f, &q, &v, 0.0);
    }

    #[test]
    fn force_is_minus_gradient_of_potential() {
        let s = SpringDamper {
            particles: [0, 1],
            stiffness: 50.0,
            damping: 0.0,
            rest_length: 0.5,
        };
        let q = [[0.1, 0.0, 0.2], [0.9, -0.3, 0.1]];
        let f = s.force(&q, &[[0.0; 3]; 2], 0.0);
        let h = 1e-6;
        for k in 0..3 {
            let mut qp = q;
            let mut qm = q;
            qp[0][k] += h;
            qm[0][k] -= h;
            let de = (s.potential(&qp) - s.potential(&qm)) / (2.0 * h);
            assert!((f[0][k] + de).abs() < 1e-6);
        }
    }
}
