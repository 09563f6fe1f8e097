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
//! - orientation: the three orientation equations alone (3: translations free);
//! - point on a line of A: the two line equations; point on a plane of A (normal n): one.
//!
//! Between planar bodies (or a planar body and the ground) of one plane, a joint keeps only its
//! in-plane equations: with u, v the in-plane world axes, d the joint's in-plane direction and
//! p = e_normal x d, spherical and revolute are the two relative coordinates along u and v;
//! prismatic is d^A . p^B = 0 and (x_B - x_A) . p^A = 0; fixed is the two coordinates and
//! d^A . p^B = 0; orientation is d^A . p^B = 0 alone; point on a line (along d) is (x_B - x_A) . p^A = 0; point on a "plane" of
//! normal n (a line in the plane) is (x_B - x_A) . n^A = 0.
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
    /// A shared orientation, translations free (3).
    Orientation,
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
            JointKind::Orientation => "orientation joint",
            JointKind::PointOnLine => "point-on-line joint",
            JointKind::PointOnPlane => "point-on-plane joint",
        }
    }
}

/// What each equation of a joint holds, in the order the joint adds them (module doc).
fn equation_names(kind: JointKind, plane: Option<usize>) -> Vec<String> {
    let axes = ["x", "y", "z"];
    let coincide: Vec<String> = match plane {
        None => (0..3)
            .map(|k| format!("shared point along {}", axes[k]))
            .collect(),
        Some(normal) => {
            let (u, v) = super::planar_body::in_plane(normal);
            vec![
                format!("shared point along {}", axes[u]),
                format!("shared point along {}", axes[v]),
            ]
        }
    };
    let s = |x: &str| x.to_string();
    let mut names = Vec::new();
    match (kind, plane) {
        (JointKind::Spherical, _) => names.extend(coincide),
        (JointKind::Revolute, None) => {
            names.extend(coincide);
            names.extend([s("axis normal to B's e1"), s("axis normal to B's e2")]);
        }
        (JointKind::Prismatic, None) => names.extend([
            s("axis normal to B's e1"),
            s("axis normal to B's e2"),
            s("A's e1 normal to B's e2"),
            s("B's point on A's line (along e1)"),
            s("B's point on A's line (along e2)"),
        ]),
        (JointKind::Fixed, None) => {
            names.extend(coincide);
            names.extend([
                s("axis normal to B's e1"),
                s("axis normal to B's e2"),
                s("A's e1 normal to B's e2"),
            ]);
        }
        (JointKind::Orientation, None) => names.extend([
            s("axis normal to B's e1"),
            s("axis normal to B's e2"),
            s("A's e1 normal to B's e2"),
        ]),
        (JointKind::Orientation, Some(_)) => names.push(s("no relative rotation")),
        (JointKind::PointOnLine, None) => names.extend([
            s("B's point on A's line (along e1)"),
            s("B's point on A's line (along e2)"),
        ]),
        (JointKind::PointOnPlane, _) => names.push(s("B's point on A's plane")),
        (JointKind::Revolute, Some(_)) => names.extend(coincide),
        (JointKind::Prismatic, Some(_)) => {
            names.extend([s("no relative rotation"), s("B's point on A's line")])
        }
        (JointKind::Fixed, Some(_)) => {
            names.extend(coincide);
            names.push(s("no relative rotation"));
        }
        (JointKind::PointOnLine, Some(_)) => names.push(s("B's point on A's line")),
    }
    names
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
        let plane = self.plane_of(&label, a, b)?;
        let built = match plane {
            None => self.joint_in_space(kind, (a, b), at, n, &label)?,
            Some(normal) => self.joint_in_plane(kind, (a, b), at, (n, normal), &label)?,
        };
        // Each equation named by what it holds, for messages and redundancy reports.
        for (c, what) in built.constraints.iter().zip(equation_names(kind, plane)) {
            if let crate::constraints::Constraint::OnPoints(e) = &mut self.constraints[c.0] {
                e.label = format!("{label}: {what}");
            }
        }
        self.joints += 1;
        Ok(built.constraints)
    }

    /// The normal axis of the plane of a joint between planar bodies (None in space).
    fn plane_of(&self, label: &str, a: &[ParticleId], b: &[ParticleId]) -> Result<Option<usize>> {
        let normal = |f: &[ParticleId]| -> Result<Option<usize>> {
            match f.len() {
                0 | 4 => Ok(None),
                3 => self.frame_normal(f).map(Some),
                n => Err(Error::InvalidParameter {
                    name: format!("frame of a body of {label}"),
                    value: n as f64,
                    expected: "give a rigid body's 4 frame particles, a planar body's 3, or \
                               none (the ground)"
                        .into(),
                }),
            }
        };
        let (na, nb) = (normal(a)?, normal(b)?);
        let mixed =
            |planar: &[ParticleId], other: &[ParticleId]| planar.len() == 3 && other.len() == 4;
        if mixed(a, b) || mixed(b, a) || matches!((na, nb), (Some(x), Some(y)) if x != y) {
            return Err(Error::InvalidParameter {
                name: format!("bodies of {label}"),
                value: f64::NAN,
                expected: "a planar body joins the ground or planar bodies of the same plane \
                           normal"
                    .into(),
            });
        }
        Ok(na.or(nb))
    }

    /// The equations of a joint in space (module doc).
    fn joint_in_space(
        &mut self,
        kind: JointKind,
        (a, b): (&[ParticleId], &[ParticleId]),
        at: Vec3,
        n: Vec3,
        label: &str,
    ) -> Result<Built> {
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
        let (_, built) = self.on_points(&points, label, |s, p| {
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
                JointKind::Orientation => {
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
        Ok(built)
    }

    /// The equations of a joint between planar bodies of normal axis `normal` (module doc):
    /// in the plane, a shared point is 2 equations and a shared direction 1.
    fn joint_in_plane(
        &mut self,
        kind: JointKind,
        (a, b): (&[ParticleId], &[ParticleId]),
        at: Vec3,
        (n, normal): (Vec3, usize),
        label: &str,
    ) -> Result<Built> {
        let (u, v) = super::planar_body::in_plane(normal);
        let along_normal = (n[normal].abs() - 1.0).abs() < 1e-12;
        let turning = matches!(
            kind,
            JointKind::Spherical | JointKind::Revolute | JointKind::Fixed | JointKind::Orientation
        );
        // The in-plane direction d of a slider or line (e_u for a joint that turns), and its
        // normal p in the plane.
        let d = if turning {
            std::array::from_fn(|k| if k == u { 1.0 } else { 0.0 })
        } else if n[normal].abs() < 1e-12 {
            n
        } else {
            return Err(Error::InvalidVector {
                name: format!("axis of {label}"),
                value: n.to_vec(),
                expected: format!(
                    "must lie in the bodies' plane (component {} = 0)",
                    ["x", "y", "z"][normal]
                ),
            });
        };
        if turning && !along_normal && kind == JointKind::Revolute {
            return Err(Error::InvalidVector {
                name: format!("axis of {label}"),
                value: n.to_vec(),
                expected: format!(
                    "a revolute joint of planar bodies turns about their plane's normal, the {} axis",
                    ["x", "y", "z"][normal]
                ),
            });
        }
        let mut e_normal = [0.0; 3];
        e_normal[normal] = 1.0;
        let p = cross(e_normal, d);
        let offset = |x: Vec3| [at[0] + x[0], at[1] + x[1], at[2] + x[2]];
        // Points 0..2: A at `at`, +d, +p; 3..5: the same of B.
        let mut points = Vec::with_capacity(6);
        for frame in [a, b] {
            points.push(self.body_point(frame, at)?);
            points.push(self.body_point(frame, offset(d))?);
            points.push(self.body_point(frame, offset(p))?);
        }
        let (_, built) = self.on_points(&points, label, |s, q| {
            let zero = || Some(Law::Constant(0.0));
            let coincide = |s: &mut System| -> Result<()> {
                s.add_relative_coordinate(q[0], q[3], u, zero())?;
                s.add_relative_coordinate(q[0], q[3], v, zero())?;
                Ok(())
            };
            // d^A . p^B = 0: no relative rotation.
            let aligned = |s: &mut System| s.add_dot_product([q[0], q[1], q[3], q[5]], zero());
            // (x_B - x_A) . p^A = 0: B's point on A's line along d.
            let on_line = |s: &mut System| s.add_dot_product([q[0], q[3], q[0], q[2]], zero());
            match kind {
                JointKind::Spherical | JointKind::Revolute => coincide(s)?,
                JointKind::Prismatic => {
                    aligned(s)?;
                    on_line(s)?;
                }
                JointKind::Fixed => {
                    coincide(s)?;
                    aligned(s)?;
                }
                JointKind::Orientation => {
                    aligned(s)?;
                }
                JointKind::PointOnLine => {
                    on_line(s)?;
                }
                JointKind::PointOnPlane => {
                    // In the plane, a "plane" of normal n through `at` is the line along p.
                    s.add_dot_product([q[0], q[3], q[0], q[1]], zero())?;
                }
            }
            Ok(())
        })?;
        Ok(built)
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
