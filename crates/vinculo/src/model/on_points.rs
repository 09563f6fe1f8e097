//! Building elements over points: any constraint or force the system can add over particles,
//! added over points fixed in bodies or in the ground ([`super::point`]).
//!
//! [`System::on_points`] gives a builder function a scratch system whose particle j stands for
//! point j (at the point's position and velocity now; fixed when the point does not move), so
//! that every builder validates and sizes its element as it does for particles (a distance
//! takes its current length, a plane its normal). Each element the builder adds there joins
//! this system over the points it touches ([`crate::constraints::OnPoints`],
//! [`crate::forces::ForceOnPoints`]).

use super::particle::{ConstraintId, ForceId, ParticleId};
use super::point::{Point, PointMap};
use super::System;
use crate::constraints::{Constraint, OnPoints};
use crate::error::{finite_vector, Error, Result};
use crate::forces::{Force, ForceOnPoints};

/// The elements a builder added over points, as elements of this system.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Built {
    /// The constraints, in the order the builder added them.
    pub constraints: Vec<ConstraintId>,
    /// The forces, in the order the builder added them.
    pub forces: Vec<ForceId>,
}

/// An element handle of the scratch system, translated to this system's.
pub trait OnPointsId: Sized {
    /// The handle in this system of the scratch system's element `self`.
    fn in_system(self, built: &Built) -> Self;
}

impl OnPointsId for ConstraintId {
    fn in_system(self, built: &Built) -> ConstraintId {
        built.constraints[self.0]
    }
}

impl OnPointsId for ForceId {
    fn in_system(self, built: &Built) -> ForceId {
        built.forces[self.0]
    }
}

impl OnPointsId for () {
    fn in_system(self, _: &Built) {}
}

impl System {
    /// A particle as a point.
    pub fn particle_point(&self, p: ParticleId) -> Result<Point> {
        Ok(Point::particle(self.check(p)?))
    }

    /// The point of the body framed by `frame` (4 particles of a rigid body, 3 of a planar
    /// body) that is at world position `at` now (module doc of [`super::point`]).
    pub fn point_in(&self, frame: &[ParticleId], at: [f64; 3]) -> Result<Point> {
        let at = finite_vector("point of a body", at)?;
        let indices = frame
            .iter()
            .map(|&p| self.check(p))
            .collect::<Result<Vec<_>>>()?;
        let positions: Vec<_> = indices
            .iter()
            .map(|&i| self.particles()[i].position)
            .collect();
        Point::in_frame(&indices, &positions, at)
    }

    /// Adds, over `points`, the elements that `build` adds over a scratch system's particles
    /// (particle j of it stands for `points[j]`); `label` names them in messages. Returns what
    /// `build` returned, with its handles translated, and every element added.
    pub fn on_points<R: OnPointsId>(
        &mut self,
        points: &[Point],
        label: &str,
        build: impl FnOnce(&mut System, &[ParticleId]) -> Result<R>,
    ) -> Result<(R, Built)> {
        let q = self.initial_positions();
        let v = self.initial_velocities();
        let mut scratch = System::try_new(self.gravity())?;
        let mut ids = Vec::with_capacity(points.len());
        for (j, point) in points.iter().enumerate() {
            for (&p, &w) in point.particles.iter().zip(&point.weights) {
                if p >= self.particles().len() || !w.is_finite() {
                    return Err(Error::InvalidParameter {
                        name: format!("point #{j} of {label}"),
                        value: w,
                        expected: format!(
                            "must combine particles of this system (< {}) with finite weights",
                            self.particles().len()
                        ),
                    });
                }
            }
            let fixed = point.particles.iter().all(|&p| self.particles()[p].fixed);
            let position = finite_vector(format!("point #{j} of {label}"), point.position(&q))?;
            ids.push(scratch.add_particle(1.0, position, point.velocity(&v), fixed)?);
        }
        let result = build(&mut scratch, &ids)?;
        // User groups act on particles (their functions see particle arrays); user laws are
        // laws like the others and stay with their elements (noted again below).
        if !(scratch.user_forces.is_empty() && scratch.user_constraints.is_empty()) {
            return Err(Error::InvalidParameter {
                name: format!("elements of {label}"),
                value: f64::NAN,
                expected: "user groups act on particles: give particles, or describe the \
                           element with the built-in kinds"
                    .into(),
            });
        }
        let mut built = Built::default();
        let (constraints, forces) = (scratch.constraints, scratch.forces);
        let several = constraints.len() + forces.len() > 1;
        let name = |k: usize| {
            if several {
                format!("{label}, equation {}", k + 1)
            } else {
                label.to_string()
            }
        };
        for (k, inner) in constraints.into_iter().enumerate() {
            if inner.damped_segment().is_some() {
                return Err(Error::InvalidParameter {
                    name: format!("elements of {label}"),
                    value: f64::NAN,
                    expected: "axial damping acts on segments between particles: between \
                               points of bodies, add a spring-damper of zero stiffness"
                        .into(),
                });
            }
            let map = PointMap::for_points(points, inner.particles());
            let element = OnPoints {
                inner,
                map,
                label: name(k),
            };
            built
                .constraints
                .push(self.push_constraint(Constraint::OnPoints(Box::new(element)))?);
        }
        for (k, inner) in forces.into_iter().enumerate() {
            if inner.added_mass().is_some()
                || inner.has_events()
                || inner.acting() < inner.particles().len()
            {
                return Err(Error::InvalidParameter {
                    name: format!("elements of {label}"),
                    value: f64::NAN,
                    expected: "fluid forces, seabed contact and line loads act on particles \
                               only: give the body's particle"
                        .into(),
                });
            }
            let map = PointMap::for_points(points, inner.particles());
            let element = Force::OnPoints(Box::new(ForceOnPoints {
                inner,
                map,
                label: name(k),
            }));
            let index = self.forces.len();
            self.note_user_laws(element.name(index), element.laws());
            self.forces.push(element);
            built.forces.push(ForceId(index));
        }
        for &c in &scratch.tension_only {
            self.set_tension_only(built.constraints[c])?;
        }
        Ok((result.in_system(&built), built))
    }
}
