//! Rigid bodies of four particles: the fewest that frame a body in space (natural
//! coordinates), for mechanisms of many bodies.
//!
//! Mass distribution. With J = sum m x x^T the second moment of the mass about the centre of
//! mass (J = tr(I)/2 1 - I, [`super::rigid_body`]) and e_k, J_k its principal axes and moments,
//! four particles of mass m/4 at the corners s = (s_1, s_2, s_3) of the box
//! |x . e_k| = a_k with an even number of minus signs, (+,+,+), (+,-,-), (-,+,-), (-,-,+),
//! have centre 0 (each sign sums to zero over the four), no product of inertia in the axes
//! (sum s_i s_k = 0 for i != k), and sum (m/4) a_k^2 = m a_k^2 on the diagonal: a_k =
//! sqrt(J_k / m) makes mass, centre and inertia exact. They form a tetrahedron (not coplanar,
//! since every a_k > 0), held rigid by its six edges (4 x 3 - 6 = 6 degrees of freedom), and
//! they are the body's frame: its points are their barycentric combinations
//! ([`super::point`]), its centre of mass is their mean.
//!
//! A body of seven particles ([`super::rigid_body`], the octahedron of the buoy study) has 21
//! coordinates and 15 equations; this one has 12 and 6, which makes the matrix of a chain of
//! bodies about four times cheaper to factorise.

use super::particle::{ConstraintId, ParticleId};
use super::rigid_body::{checked, solid_principal, RigidBodySpec};
use super::System;
use crate::error::{Error, Result};
use crate::math::{add, cross, scale, sub, Mat3, Vec3};

/// Handles to a four-particle rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct TetrahedronBody {
    /// Its four particles (its frame).
    pub particles: [ParticleId; 4],
    /// The six edges that hold it rigid.
    pub constraints: Vec<ConstraintId>,
    /// Its principal axes (columns, right-handed).
    pub axes: Mat3,
}

impl System {
    /// Adds a rigid body of four particles with the mass, centre and inertia of `spec` (module
    /// doc); `spec.points` must be empty (points of the body are [`System::point_in`] its
    /// frame).
    pub fn add_rigid_tetrahedron(&mut self, spec: &RigidBodySpec) -> Result<TetrahedronBody> {
        if !spec.points.is_empty() {
            return Err(Error::InvalidParameter {
                name: "points of a four-particle rigid body".into(),
                value: spec.points.len() as f64,
                expected: "must be empty: take points of the body with System.point(body, \
                           position), which add no particle"
                    .into(),
            });
        }
        let (m, c, v, w, j) = checked(spec)?;
        let (moments, axes) = solid_principal(&j, "a tetrahedron of particles)")?;
        let half: Vec3 = std::array::from_fn(|k| (moments[k] / m).sqrt());
        let axis = |k: usize| -> Vec3 { [axes[0][k], axes[1][k], axes[2][k]] };
        let mut particles = Vec::with_capacity(4);
        for signs in [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ] {
            let r = (0..3).fold([0.0; 3], |r, k| add(r, scale(signs[k] * half[k], axis(k))));
            let x = add(c, r);
            let velocity = add(v, cross(w, sub(x, c)));
            particles.push(self.add_particle(m / 4.0, x, velocity, false)?);
        }
        let mut constraints = Vec::with_capacity(6);
        for a in 0..4 {
            for b in (a + 1)..4 {
                constraints.push(self.add_distance(particles[a], particles[b], None)?);
            }
        }
        Ok(TetrahedronBody {
            particles: [particles[0], particles[1], particles[2], particles[3]],
            constraints,
            axes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_four_particles_have_the_mass_centre_and_inertia_of_the_body() {
        // A general inertia tensor (not diagonal in the world axes): the particles' mass,
        // centre, inertia tensor sum m (|r|^2 1 - r r^T) and angular momentum are the body's.
        let inertia = [[2.0, 0.3, -0.2], [0.3, 1.5, 0.1], [-0.2, 0.1, 1.2]];
        let spec = RigidBodySpec {
            mass: 3.0,
            centre: [0.5, -1.0, 2.0],
            inertia,
            velocity: [0.1, 0.2, -0.3],
            angular_velocity: [0.7, -0.4, 1.1],
            ..RigidBodySpec::default()
        };
        let mut s = System::new([0.0; 3]);
        let body = s.add_rigid_tetrahedron(&spec).unwrap();
        // The moments about the given centre: the mass, the first moment m c (so the centre
        // is c) and the inertia tensor.
        let (mass, first, tensor) =
            super::super::rigid_body::moments(&s, &body.particles, spec.centre);
        assert!((mass - 3.0).abs() < 1e-14);
        assert!((0..3).all(|k| (first[k] / mass - spec.centre[k]).abs() < 1e-13));
        let mut h = [0.0; 3];
        for id in &body.particles {
            let x = &s.particles()[id.index()];
            let hr = cross(sub(x.position, spec.centre), sub(x.velocity, spec.velocity));
            (0..3).for_each(|k| h[k] += x.mass * hr[k]);
        }
        for a in 0..3 {
            for b in 0..3 {
                assert!((tensor[a][b] - inertia[a][b]).abs() < 1e-12, "I[{a}][{b}]");
            }
            let iw: f64 = (0..3)
                .map(|b| inertia[a][b] * spec.angular_velocity[b])
                .sum();
            assert!((h[a] - iw).abs() < 1e-12, "H[{a}]");
        }
    }
}
