//! A constraint over points (points fixed in bodies, ground points, particles): a constraint of
//! any kind written for m particles acts on m points through their [`PointMap`].
//!
//! The inner constraint is built over the element's points as if they were particles 0..m-1;
//! it is evaluated at the points' positions and velocities, and its gradient and Hessian reach
//! the particles by the chain rule of [`crate::model::point`]: x_j = offset_j + sum_p w_jp q_p is
//! linear in q with constant weights, so Phi_t and gamma are the inner constraint's own.

use super::{Constraint, Hessian};
use crate::laws::Law;
use crate::local::Blocks;
use crate::math::{Mat3, Vec3, ZERO3};
use crate::model::point::Points;
use crate::model::PointMap;

/// A constraint over points.
#[derive(Debug, Clone, PartialEq)]
pub struct OnPoints {
    /// The constraint over the points, numbered 0..m-1 as particles.
    pub inner: Constraint,
    /// How the points reach the particles.
    pub map: PointMap,
    /// Its name in messages (e.g. "revolute joint #1, axis equation 2").
    pub label: String,
}

impl OnPoints {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.map.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        self.inner.residual(&self.map.positions(q), t)
    }

    pub(crate) fn gradient(&self, q: &[Vec3], t: f64) -> crate::local::Rows {
        crate::local::Rows::Any(self.gradient_at(&self.map.positions(q), t).into_vec())
    }

    pub(crate) fn add_hessian(&self, q: &[Vec3], t: f64, w: f64, out: &mut Hessian) {
        let h = self.hessian_at(&self.map.positions(q), t, w);
        self.map.add_blocks(self.inner.particles(), &h, out);
    }

    /// The inner constraint's gradient at the points' positions `x`, taken to the particles
    /// (on the stack).
    fn gradient_at(&self, x: &[Vec3], t: f64) -> Points {
        let g = self.inner.gradient_rows(x, t);
        self.map.rows_on_stack(self.inner.particles(), &g)
    }

    /// `w` times the inner constraint's Hessian at the points' positions `x`, over its points.
    fn hessian_at(&self, x: &[Vec3], t: f64, w: f64) -> Blocks {
        let mut h = Blocks::zeros(self.inner.particles().len());
        self.inner.add_hessian(x, t, w, &mut h);
        h
    }

    /// [`Constraint::with_hessian_and_gradient`] over points: the points' positions found
    /// once, the inner constraint's Hessian and gradient taken to the particles, the rows on
    /// the stack; no Hessian blocks at all (an empty slice) where the inner one is zero, as for
    /// a joint's coincidence of two points (a joint's equation over the 8 particles of two
    /// bodies would otherwise hand over 64 blocks, zeroed and placed: a chain of 400 rigid
    /// bodies, 2,000 such equations, spent a fourth of its time there).
    #[inline]
    pub(crate) fn with_hessian_and_gradient<R>(
        &self,
        (q, t): (&[Vec3], f64),
        w: f64,
        buffer: &mut Hessian,
        use_it: impl FnOnce(&[Mat3], &[Vec3]) -> R,
    ) -> R {
        let x = self.map.positions(q);
        let h = self.hessian_at(&x, t, w);
        let rows = self.gradient_at(&x, t);
        if h.as_slice().iter().all(|b| *b == ZERO3) {
            return use_it(&[], &rows);
        }
        buffer.reset(self.map.particles.len());
        self.map.add_blocks(self.inner.particles(), &h, buffer);
        use_it(buffer.as_slice(), &rows)
    }

    /// Calls `use_it` with dPhi/dq, the rows on the stack.
    #[inline]
    pub(crate) fn with_gradient<R>(
        &self,
        q: &[Vec3],
        t: f64,
        use_it: impl FnOnce(&[Vec3]) -> R,
    ) -> R {
        use_it(&self.gradient_at(&self.map.positions(q), t))
    }

    /// Calls `use_it` with Phi(q, t) and dPhi/dq from one evaluation of the points'
    /// positions, the rows on the stack.
    #[inline]
    pub(crate) fn with_residual_and_gradient<R>(
        &self,
        q: &[Vec3],
        t: f64,
        use_it: impl FnOnce(f64, &[Vec3]) -> R,
    ) -> R {
        let x = self.map.positions(q);
        use_it(self.inner.residual(&x, t), &self.gradient_at(&x, t))
    }

    pub(crate) fn phi_t(&self, q: &[Vec3], t: f64) -> f64 {
        self.inner.phi_t(&self.map.positions(q), t)
    }

    pub(crate) fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        let x = self.map.positions(q);
        self.inner.gamma(&x, &self.map.velocities(v), t)
    }

    pub(crate) fn scale(&self) -> f64 {
        self.inner.scale()
    }

    pub(crate) fn laws(&self) -> Vec<&Law> {
        self.inner.laws()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Distance, DotProduct};
    use super::*;
    use crate::model::Point;

    #[test]
    fn constraints_over_body_points_match_finite_differences() {
        // Particles 0..3 frame a body, 4..7 another; 8 is a lone particle.
        let (q, v) = crate::model::point::test_state(9);
        let a = Point::in_frame(&[0, 1, 2, 3], &q[0..4], [0.4, -0.2, 0.9]).unwrap();
        let a2 = Point::in_frame(&[0, 1, 2, 3], &q[0..4], [1.4, 0.3, 0.2]).unwrap();
        let b = Point::in_frame(&[4, 5, 6, 7], &q[4..8], [0.1, 0.6, 1.5]).unwrap();
        let ground = Point::ground([0.5, 0.5, 0.5]);
        // A distance between a point of each body.
        let distance = Constraint::OnPoints(Box::new(OnPoints {
            inner: Constraint::Distance(Distance {
                particles: [0, 1],
                length: 1.0,
            }),
            map: PointMap::new(&[a.clone(), b.clone()]),
            label: "test".into(),
        }));
        fd::check(&distance, &q, &v, 0.2);
        // A dot product of a body's direction (a2 - a) with (particle 8 - ground point): the
        // same body's particles appear in two points, merged by the map.
        let dot = Constraint::OnPoints(Box::new(OnPoints {
            inner: Constraint::DotProduct(Box::new(DotProduct {
                particles: [0, 1, 2, 3],
                value: Law::sine(0.1, 1.0, 0.0, 0.2, 0.0, 0.0).unwrap(),
                inverse_length: 1.0,
            })),
            map: PointMap::new(&[a, a2, ground, Point::particle(8)]),
            label: "test".into(),
        }));
        assert_eq!(dot.particles(), &[0, 1, 2, 3, 8]);
        fd::check(&dot, &q, &v, 0.2);
    }
}
