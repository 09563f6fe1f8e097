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

/// One equation of a joint, over its points: for each body, its point at the joint, then its
/// points one unit along each of the joint's directions (in space n, e1, e2; in a plane d, p).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Equation {
    /// x_B - x_A = 0 along a world axis.
    Shared(usize),
    /// A's direction k normal to B's direction l (k, l from 1).
    Normal(usize, usize),
    /// x_B - x_A normal to A's direction k.
    On(usize),
}

/// The equations of a joint (module doc), in space (`plane` None) or in the plane normal to a
/// world axis.
fn equations(kind: JointKind, plane: Option<usize>) -> Vec<Equation> {
    use Equation::{Normal, On, Shared};
    let shared = match plane {
        None => vec![Shared(0), Shared(1), Shared(2)],
        Some(normal) => {
            let (u, v) = super::planar_body::in_plane(normal);
            vec![Shared(u), Shared(v)]
        }
    };
    // In space: the directions n, e1, e2; in a plane: d, p.
    let (orientation, line) = match plane {
        None => (
            vec![Normal(1, 2), Normal(1, 3), Normal(2, 3)],
            vec![On(2), On(3)],
        ),
        Some(_) => (vec![Normal(1, 2)], vec![On(2)]),
    };
    match kind {
        JointKind::Spherical => shared,
        JointKind::Revolute if plane.is_some() => shared,
        JointKind::Revolute => [shared, vec![Normal(1, 2), Normal(1, 3)]].concat(),
        JointKind::Prismatic => [orientation, line].concat(),
        JointKind::Fixed => [shared, orientation].concat(),
        JointKind::Orientation => orientation,
        JointKind::PointOnLine => line,
        JointKind::PointOnPlane => vec![On(1)],
    }
}

impl Equation {
    /// What it holds, for messages, with `directions` the names of the joint's directions.
    fn name(self, directions: &[&str]) -> String {
        match self {
            Equation::Shared(axis) => format!("shared point along {}", ["x", "y", "z"][axis]),
            Equation::Normal(k, l) => format!(
                "A's {} normal to B's {}",
                directions[k - 1],
                directions[l - 1]
            ),
            Equation::On(k) => format!(
                "B's point in the plane through A's normal to A's {}",
                directions[k - 1]
            ),
        }
    }
}

/// The in-plane directions (d, p) of a joint between planar bodies of normal axis `normal`:
/// d the joint's axis for a slider or a line (it must lie in the plane), e_u for a joint that
/// turns (whose axis, for a revolute joint, must be the plane's normal), p = e_normal x d.
fn in_plane_directions(kind: JointKind, n: Vec3, normal: usize, label: &str) -> Result<Vec<Vec3>> {
    let (u, _) = super::planar_body::in_plane(normal);
    let axis_name = ["x", "y", "z"][normal];
    let turning = matches!(
        kind,
        JointKind::Spherical | JointKind::Revolute | JointKind::Fixed | JointKind::Orientation
    );
    let refuse = |expected: String| Error::InvalidVector {
        name: format!("axis of {label}"),
        value: n.to_vec(),
        expected,
    };
    if kind == JointKind::Revolute && (n[normal].abs() - 1.0).abs() >= 1e-12 {
        return Err(refuse(format!(
            "a revolute joint of planar bodies turns about their plane's normal, the {axis_name} axis"
        )));
    }
    let d: Vec3 = if turning {
        std::array::from_fn(|k| if k == u { 1.0 } else { 0.0 })
    } else if n[normal].abs() < 1e-12 {
        n
    } else {
        return Err(refuse(format!(
            "must lie in the bodies' plane (component {axis_name} = 0)"
        )));
    };
    let mut e_normal = [0.0; 3];
    e_normal[normal] = 1.0;
    Ok(vec![d, cross(e_normal, d)])
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
        let (directions, names): (Vec<Vec3>, &[&str]) = match plane {
            None => {
                let (e1, e2) = triad(n);
                (vec![n, e1, e2], &["axis", "e1", "e2"])
            }
            Some(normal) => (in_plane_directions(kind, n, normal, &label)?, &["d", "p"]),
        };
        // For each body: its point at `at`, then at `at` plus each direction.
        let offset = |d: &Vec3| [at[0] + d[0], at[1] + d[1], at[2] + d[2]];
        let mut points = Vec::with_capacity(2 * (1 + directions.len()));
        for frame in [a, b] {
            points.push(self.body_point(frame, at)?);
            for d in &directions {
                points.push(self.body_point(frame, offset(d))?);
            }
        }
        let m = 1 + directions.len(); // B's points start at m
        let equations = equations(kind, plane);
        let zero = || Some(Law::Constant(0.0));
        let (_, built) = self.on_points(&points, &label, |s, p| {
            for &equation in &equations {
                match equation {
                    Equation::Shared(axis) => {
                        s.add_relative_coordinate(p[0], p[m], axis, zero())?
                    }
                    Equation::Normal(k, l) => {
                        s.add_dot_product([p[0], p[k], p[m], p[m + l]], zero())?
                    }
                    Equation::On(k) => s.add_dot_product([p[0], p[m], p[0], p[k]], zero())?,
                };
            }
            Ok(())
        })?;
        // Each equation named by what it holds, for messages and redundancy reports.
        for (c, equation) in built.constraints.iter().zip(&equations) {
            if let crate::constraints::Constraint::OnPoints(e) = &mut self.constraints[c.0] {
                e.label = format!("{label}: {}", equation.name(names));
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
