//! A force over points (points fixed in bodies, ground points, particles): a force element of
//! any kind written for m particles acts on m points through their [`PointMap`].
//!
//! The inner force f_j(x, x', t) is evaluated at the points' positions and velocities; a point
//! x_j = offset_j + sum_p w_jp q_p carries its force to its particles as F_p = sum_j w_jp f_j
//! (the virtual work f_j . dx_j = sum_p w_jp f_j . dq_p), and the Jacobians follow by the chain
//! rule: dF_p/dq_r = sum_jl w_jp (df_j/dx_l) w_lr, the same for df/dv
//! ([`crate::model::point`]). The potential is the inner element's at the points.
//!
//! Kinds that add mass (fluid forces), read a line's neighbours (line-node elements) or switch
//! (seabed contact) act on particles only: the builder refuses them on points.

use super::{Force, Jacobian};
use crate::laws::Law;
use crate::local::{Blocks, Rows};
use crate::math::Vec3;
use crate::model::PointMap;

/// A force over points.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceOnPoints {
    /// The force over the points, numbered 0..m-1 as particles.
    pub inner: Force,
    /// How the points reach the particles.
    pub map: PointMap,
    /// Its name in messages.
    pub label: String,
}

impl ForceOnPoints {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.map.particles
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Rows {
        let (x, xv) = (self.map.positions(q), self.map.velocities(v));
        let f = self.inner.force_rows(&x, &xv, t);
        Rows::Any(self.map.rows(self.inner.particles(), &f))
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let (x, xv) = (self.map.positions(q), self.map.velocities(v));
        let n = self.inner.particles().len();
        let (mut hq, mut hv) = (Blocks::zeros(n), Blocks::zeros(n));
        self.inner.add_jacobian(&x, &xv, t, &mut hq, &mut hv);
        self.map.add_blocks(self.inner.particles(), &hq, dq);
        self.map.add_blocks(self.inner.particles(), &hv, dv);
    }

    pub(crate) fn potential(&self, q: &[Vec3]) -> f64 {
        self.inner.potential(&self.map.positions(q))
    }

    pub(crate) fn laws(&self) -> Vec<&Law> {
        self.inner.laws()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, SpringDamper};
    use super::*;
    use crate::model::Point;

    #[test]
    fn a_spring_between_body_points_matches_finite_differences() {
        // Particles 0..3 frame one body, 4..7 another; the spring joins a point of each, and
        // a second spring joins a body point to a ground point.
        let (q, v) = crate::model::point::test_state(8);
        let a = Point::in_frame(&[0, 1, 2, 3], &q[0..4], [0.4, -0.2, 0.9]).unwrap();
        let b = Point::in_frame(&[4, 5, 6, 7], &q[4..8], [0.1, 0.6, 1.5]).unwrap();
        let spring = |points: &[Point]| {
            Force::OnPoints(Box::new(ForceOnPoints {
                inner: Force::SpringDamper(SpringDamper {
                    particles: [0, 1],
                    stiffness: 30.0,
                    damping: 2.0,
                    rest_length: 0.5,
                }),
                map: PointMap::new(points),
                label: "test".into(),
            }))
        };
        fd::check(&spring(&[a.clone(), b]), &q, &v, 0.0);
        let tied = spring(&[Point::ground([1.0, 2.0, 0.0]), a.clone()]);
        fd::check(&tied, &q, &v, 0.0);
        // The forces on the particles add up to the force at the point, and their moment about
        // the origin to the point's moment (the virtual-work transfer is statically exact).
        let f = tied.force(&q, &v, 0.0);
        let x = a.position(&q);
        let Force::OnPoints(on_points) = &tied else {
            unreachable!()
        };
        let f_point =
            on_points
                .inner
                .force(&[[1.0, 2.0, 0.0], x], &[[0.0; 3], a.velocity(&v)], 0.0)[1];
        let total: Vec3 = std::array::from_fn(|k| f.iter().map(|r| r[k]).sum());
        let moment = |r: Vec3, f: Vec3| crate::math::cross(r, f);
        let mut m = [0.0; 3];
        for (&p, fp) in tied.particles().iter().zip(f.iter()) {
            let mp = moment(q[p], *fp);
            (0..3).for_each(|k| m[k] += mp[k]);
        }
        let m_point = moment(x, f_point);
        for k in 0..3 {
            assert!((total[k] - f_point[k]).abs() < 1e-12);
            assert!((m[k] - m_point[k]).abs() < 1e-11);
        }
    }
}
