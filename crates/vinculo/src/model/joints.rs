//! Joints between bodies, made of relative-coordinate and dot-product equations over points
//! fixed in the bodies (natural coordinates; `docs/theory/mechanisms.md`).
//!
//! A body is given by its frame: 4 of its particles (a rigid body's [`super::RigidBody::frame`]),
//! or none for the ground. A joint is placed at a world point `at` with a unit axis `n` at the
//! initial configuration; e1, e2 complete n to an orthonormal triad. With x_A, x_B the points
//! of the two bodies at `at`, and u^A the direction u fixed in body A (the difference of two of
//! its points), the equations are:
//! - spherical: x_B - x_A = 0 (3 relative coordinates);
//! - revolute: spherical, and n^A . e1^B = 0, n^A . e2^B = 0 (the axis stays normal to B's
//!   e1, e2: 5 equations, 1 relative rotation left);
//! - prismatic: n^A . e1^B = 0, n^A . e2^B = 0, e1^A . e2^B = 0 (no relative rotation), and
//!   (x_B - x_A) . e1^A = 0, (x_B - x_A) . e2^A = 0 (x_B on A's line through `at` along n):
//!   5 equations, 1 relative translation left;
//! - fixed: spherical and the three orientation equations (6);
//! - point on a line of A: the two line equations; point on a plane of A (normal n): one.
//!
//! The orientation equations hold for a small relative rotation w, e1^B = e1 + w x e1, ...:
//! n . (w x e1) = -w . e2, n . (w x e2) = w . e1, e1 . (w x e2) = -w . n, so together they
//! fix every relative rotation and the two axis equations leave only the one about n.

use super::on_points::Built;
use super::particle::{ConstraintId, ForceId, ParticleId};
use super::point::Point;
use super::System;
use crate::error::{Error, Result};
use crate::forces::{Couple, Force};
use crate::laws::Law;
use crate::math::{cross, norm, scale, Vec3};

/// The joints [`System::add_joint`] builds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// A shared point (3 equations).
    Spherical,
    /// A shared point and axis (5).
    Revolute,
    /// A shared line and orientation (5).
    Prismatic,
    /// A shared point and orientation (6).
    Fixed,
    /// B's point on A's line (2).
    PointOnLine,
    /// B's point on A's plane, normal to the axis (1).
    PointOnPlane,
}

impl JointKind {
    /// The name in messages.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Spherical => "spherical joint",
            JointKind::Revolute => "revolute joint",
            JointKind::Prismatic => "prismatic joint",
            JointKind::Fixed => "fixed joint",
            JointKind::PointOnLine => "point-on-line joint",
            JointKind::PointOnPlane => "point-on-plane joint",
        }
    }
}

/// A unit vector normal to `n` (unit), and the third of the right-handed triad (n, e1, e2).
fn triad(n: Vec3) -> (Vec3, Vec3) {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = cross(n, helper);
    let e1 = scale(1.0 / norm(e1), e1);
    (e1, cross(n, e1))
}

impl System {
    /// The point of the body `frame` (no particle: the ground) at world position `at`.
    fn body_point(&self, frame: &[ParticleId], at: Vec3) -> Result<Point> {
        if frame.is_empty() {
            Ok(Point::ground(at))
        } else {
            self.point_in(frame, at)
        }
    }

    /// A joint of `kind` between body A (`a`, its frame) and body B (`b`) at world point `at`
    /// with axis `axis` (module doc); returns its equations, named by the joint and `index`.
    pub fn add_joint(
        &mut self,
        kind: JointKind,
        (a, b): (&[ParticleId], &[ParticleId]),
        at: Vec3,
        axis: Vec3,
    ) -> Result<Vec<ConstraintId>> {
        let index = self.joints;
        let label = format!("{} #{index}", kind.name());
        if a.is_empty() && b.is_empty() {
            return Err(Error::ConstraintOnFixedParticles { what: label });
        }
        let length = norm(axis);
        if !(length.is_finite() && length > 0.0) {
            return Err(Error::InvalidVector {
                name: format!("axis of {label}"),
                value: axis.to_vec(),
                expected: "must be a finite, non-zero direction".into(),
            });
        }
        let n = scale(1.0 / length, axis);
        let (e1, e2) = triad(n);
        let offset = |d: Vec3| [at[0] + d[0], at[1] + d[1], at[2] + d[2]];
        // Points 0..3: A at `at`, +n, +e1, +e2; 4..7: the same of B.
        let mut points = Vec::with_capacity(8);
        for frame in [a, b] {
            points.push(self.body_point(frame, at)?);
            for d in [n, e1, e2] {
                points.push(self.body_point(frame, offset(d))?);
            }
        }
        let (_, built) = self.on_points(&points, &label, |s, p| {
            let coincide = |s: &mut System| -> Result<()> {
                for axis in 0..3 {
                    s.add_relative_coordinate(p[0], p[4], axis, Some(Law::Constant(0.0)))?;
                }
                Ok(())
            };
            // (x_B - x_A) . d^A = 0 for A's direction to point k.
            let on = |s: &mut System, k: usize| {
                s.add_dot_product([p[0], p[4], p[0], p[k]], Some(Law::Constant(0.0)))
            };
            // d^A(k) . d^B(l) = 0.
            let normal = |s: &mut System, k: usize, l: usize| {
                s.add_dot_product([p[0], p[k], p[4], p[l]], Some(Law::Constant(0.0)))
            };
            match kind {
                JointKind::Spherical => coincide(s)?,
                JointKind::Revolute => {
                    coincide(s)?;
                    normal(s, 1, 6)?;
                    normal(s, 1, 7)?;
                }
                JointKind::Prismatic => {
                    normal(s, 1, 6)?;
                    normal(s, 1, 7)?;
                    normal(s, 2, 7)?;
                    on(s, 2)?;
                    on(s, 3)?;
                }
                JointKind::Fixed => {
                    coincide(s)?;
                    normal(s, 1, 6)?;
                    normal(s, 1, 7)?;
                    normal(s, 2, 7)?;
                }
                JointKind::PointOnLine => {
                    on(s, 2)?;
                    on(s, 3)?;
                }
                JointKind::PointOnPlane => {
                    on(s, 1)?;
                }
            }
            Ok(())
        })?;
        self.joints += 1;
        Ok(built.constraints)
    }

    /// A torque `torque(t)` (N m) about the world axis `axis` on the body `frame`, turning about
    /// it, as a couple on two of its points (`forces::Couple`); returns the force.
    pub fn add_torque(
        &mut self,
        frame: &[ParticleId],
        at: Vec3,
        axis: Vec3,
        torque: Law,
    ) -> Result<ForceId> {
        let index = self.forces().len();
        let label = format!("torque #{index}");
        let length = norm(axis);
        if frame.is_empty() || !(length.is_finite() && length > 0.0) {
            return Err(Error::InvalidVector {
                name: format!("axis of {label}"),
                value: axis.to_vec(),
                expected: "must be a finite, non-zero direction, on a body (not the ground)".into(),
            });
        }
        let n = scale(1.0 / length, axis);
        let (e1, _) = triad(n);
        let arm = [at[0] + e1[0], at[1] + e1[1], at[2] + e1[2]];
        let points = [self.body_point(frame, at)?, self.body_point(frame, arm)?];
        let (_, built): ((), Built) = self.on_points(&points, &label, |s, p| {
            s.forces.push(Force::Couple(Box::new(Couple {
                particles: [p[0].index(), p[1].index()],
                axis: n,
                torque,
            })));
            Ok(())
        })?;
        Ok(built.forces[0])
    }
}
