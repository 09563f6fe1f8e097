//! Planar rigid bodies: a body that moves in a plane normal to a world axis, as three particles
//! (fewer than the seven of a body in space) held rigid by three distances and kept in the plane
//! by fixing their normal coordinate.
//!
//! Mass distribution. In planar motion a body's dynamics depend on its mass m, its centre c and
//! its moment of inertia I about the normal through c. Three particles of mass m/3 at the
//! corners of an equilateral triangle of circumradius rho centred on c have that mass, that
//! centre, and the moment 3 (m/3) rho^2 = m rho^2 about the normal: rho = sqrt(I / m) makes it
//! exact, for any m and I > 0.
//!
//! Constraints. The triangle's three sides hold it rigid in its plane (3 x 2 - 3 = 3 degrees of
//! freedom left: two translations, one rotation); each particle's normal coordinate is fixed.
//! Its frame is its three particles: a point of the body in its plane is their barycentric
//! combination ([`super::point`]), and the joints between planar bodies take the planar forms
//! ([`super::joints`]).

use super::particle::{ConstraintId, ParticleId};
use super::System;
use crate::error::{finite, finite_vector, positive, Error, Result};
use crate::math::{add, scale, Vec3};

/// What a planar body is made of and how it starts moving.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBodySpec {
    /// Mass (kg, > 0).
    pub mass: f64,
    /// Initial position of the centre of mass (m); its normal coordinate is the plane's.
    pub centre: Vec3,
    /// Moment of inertia about the normal through the centre (kg m^2, > 0).
    pub inertia: f64,
    /// The world axis normal to the plane of motion: 0, 1 or 2 (x, y or z).
    pub normal: usize,
    /// Initial velocity of the centre (m/s, in the plane).
    pub velocity: Vec3,
    /// Initial angular velocity about the normal (rad/s).
    pub angular_velocity: f64,
}

/// Handles to a planar body's particles and constraints.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBody {
    /// Its three particles (its frame).
    pub particles: [ParticleId; 3],
    /// The three sides and the three normal coordinates that hold it.
    pub constraints: Vec<ConstraintId>,
    /// The world axis normal to its plane.
    pub normal: usize,
}

/// The two in-plane world axes (u, v) for a normal axis, with e_u x e_v = e_normal.
pub(crate) fn in_plane(normal: usize) -> (usize, usize) {
    ((normal + 1) % 3, (normal + 2) % 3)
}

impl System {
    /// Adds a planar body (module doc).
    pub fn add_planar_body(&mut self, spec: &PlanarBodySpec) -> Result<PlanarBody> {
        let m = positive("mass of the planar body", spec.mass)?;
        let inertia = positive("moment of inertia of the planar body", spec.inertia)?;
        let c = finite_vector("centre of the planar body", spec.centre)?;
        let v = finite_vector("velocity of the planar body", spec.velocity)?;
        let w = finite("angular velocity of the planar body", spec.angular_velocity)?;
        let n = spec.normal;
        if n > 2 {
            return Err(Error::InvalidParameter {
                name: "normal axis of the planar body".into(),
                value: n as f64,
                expected: "must be 0, 1 or 2 (x, y or z)".into(),
            });
        }
        if v[n] != 0.0 {
            return Err(Error::InvalidVector {
                name: "velocity of the planar body".into(),
                value: v.to_vec(),
                expected: format!(
                    "must lie in its plane (component {} = 0)",
                    ["x", "y", "z"][n]
                ),
            });
        }
        let (u, t) = in_plane(n);
        let rho = (inertia / m).sqrt();
        let mut particles = Vec::with_capacity(3);
        for k in 0..3 {
            let angle = 2.0 * std::f64::consts::PI * k as f64 / 3.0;
            let mut r = [0.0; 3];
            r[u] = rho * angle.cos();
            r[t] = rho * angle.sin();
            // omega e_n x r: (r_u, r_v) -> (-r_v, r_u) in the plane.
            let mut spin = [0.0; 3];
            spin[u] = -w * r[t];
            spin[t] = w * r[u];
            particles.push(self.add_particle(
                m / 3.0,
                add(c, r),
                add(v, scale(1.0, spin)),
                false,
            )?);
        }
        let mut constraints = Vec::with_capacity(6);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            constraints.push(self.add_distance(particles[a], particles[b], None)?);
        }
        for &p in &particles {
            constraints.push(self.add_fixed_coordinate(p, n, None)?);
        }
        Ok(PlanarBody {
            particles: [particles[0], particles[1], particles[2]],
            constraints,
            normal: n,
        })
    }

    /// The world axis normal to the plane of the 3 particles of a planar body's frame, or an
    /// error when they do not lie in a plane normal to a world axis.
    pub(crate) fn frame_normal(&self, frame: &[ParticleId]) -> Result<usize> {
        let q: Vec<Vec3> = frame
            .iter()
            .map(|&p| self.check(p).map(|i| self.particles()[i].position))
            .collect::<Result<_>>()?;
        let e1 = crate::math::sub(q[1], q[0]);
        let e2 = crate::math::sub(q[2], q[0]);
        let n = crate::math::cross(e1, e2);
        let size = crate::math::norm(n);
        (0..3)
            .find(|&k| size > 0.0 && (n[k].abs() - size).abs() <= 1e-9 * size)
            .ok_or_else(|| Error::InvalidParameter {
                name: "frame of a planar body".into(),
                value: size,
                expected: "its 3 particles must lie in a plane normal to a world axis (a planar \
                           body of System::add_planar_body)"
                    .into(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_triangle_has_the_mass_centre_and_moment_of_the_body() {
        // Mass, centre and moment about the normal of the three particles are the body's; their
        // velocities are those of the rigid motion (v, omega about the normal).
        let mut s = System::new([0.0, 0.0, -9.81]);
        let spec = PlanarBodySpec {
            mass: 2.5,
            centre: [0.3, -0.2, 1.1],
            inertia: 0.07,
            normal: 1,
            velocity: [0.4, 0.0, -0.3],
            angular_velocity: 1.7,
        };
        let body = s.add_planar_body(&spec).unwrap();
        // Mass, centre (first moment / mass) and the moment about y (the tensor's I_yy).
        let (mass, first, tensor) =
            super::super::rigid_body::moments(&s, &body.particles, spec.centre);
        assert!((mass - 2.5).abs() < 1e-14);
        assert!((0..3).all(|k| (first[k] / mass - spec.centre[k]).abs() < 1e-14));
        assert!((tensor[1][1] - 0.07).abs() < 1e-14);
        let centre = spec.centre;
        let p: Vec<_> = body
            .particles
            .iter()
            .map(|id| s.particles()[id.index()].clone())
            .collect();
        // Angular momentum about the centre: I omega (about y: z x - x z components).
        let h: f64 = p
            .iter()
            .map(|x| {
                let (dz, dx) = (x.position[2] - centre[2], x.position[0] - centre[0]);
                x.mass * (dz * (x.velocity[0] - 0.4) - dx * (x.velocity[2] + 0.3))
            })
            .sum();
        assert!((h - 0.07 * 1.7).abs() < 1e-14);
        assert_eq!(s.frame_normal(&body.particles).unwrap(), 1);
    }
}
