//! Rigid clusters: existing particles made one rigid body, so that bodies can share particles
//! (two clusters with a particle in common are joined there by a spherical joint, the seed
//! paper's way of linking bodies).
//!
//! The cluster's inertia is its particles' own: the user's masses and positions. Its frame is
//! chosen among its particles for conditioning: p0 the first, p1 the farthest from p0, p2 the
//! farthest from the line p0 p1, p3 the farthest from the plane p0 p1 p2.
//!
//! - In space (p3 off the plane): the tetrahedron p0..p3 is held by its 6 edges; every other
//!   particle by its distances to the 3 frame particles whose unit directions from it are the
//!   most independent (the largest |det|). 3 n - 6 equations for n particles: 6 degrees of
//!   freedom left.
//! - In a plane normal to a world axis k (all particles in it): the triangle p0 p1 p2 by its 3
//!   sides, every other particle by its distances to the 2 frame particles whose directions from
//!   it are the most independent. In space such a cluster of more than 3 particles could fold
//!   about a line of it (a triangle cannot), so each particle must already be held in the plane (fixed, or with its k coordinate fixed:
//!   a planar model); the cluster checks this.
//!
//! The equations are checked for redundancy at the initial configuration.

use super::particle::{ConstraintId, ParticleId};
use super::System;
use crate::constraints::{find_redundant, Constraint};
use crate::error::{Error, Result};
use crate::math::{cross, dot, norm, scale, sub, Vec3};

/// Handles of a rigid cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidCluster {
    /// Its frame: 4 particles in space, 3 in a plane.
    pub frame: Vec<ParticleId>,
    /// The distances that hold it.
    pub constraints: Vec<ConstraintId>,
}

impl System {
    /// Makes `particles` one rigid body (module doc).
    pub fn add_rigid_cluster(&mut self, particles: &[ParticleId]) -> Result<RigidCluster> {
        let ids = particles
            .iter()
            .map(|&p| self.check(p))
            .collect::<Result<Vec<_>>>()?;
        for (k, &i) in ids.iter().enumerate() {
            if ids[..k].contains(&i) {
                return Err(Error::SameParticle {
                    what: "rigid cluster".into(),
                    particle: i,
                });
            }
        }
        if ids.len() < 3 {
            return Err(Error::InvalidParameter {
                name: "number of particles of a rigid cluster".into(),
                value: ids.len() as f64,
                expected: "give at least 3 (a distance holds 2)".into(),
            });
        }
        let positions: Vec<Vec3> = self.particles().iter().map(|p| p.position).collect();
        let x = |i: usize| positions[i];
        let size = ids
            .iter()
            .map(|&i| norm(sub(x(i), x(ids[0]))))
            .fold(0.0, f64::max);
        let farthest = |score: &dyn Fn(Vec3) -> f64| -> (usize, f64) {
            ids.iter()
                .map(|&i| (i, score(x(i))))
                .fold(
                    (ids[0], -1.0),
                    |best, c| if c.1 > best.1 { c } else { best },
                )
        };
        let p0 = ids[0];
        let (p1, _) = farthest(&|y| norm(sub(y, x(p0))));
        let axis = sub(x(p1), x(p0));
        let (p2, off_line) = farthest(&|y| norm(cross(axis, sub(y, x(p0)))) / norm(axis));
        if off_line <= 1e-9 * size {
            return Err(Error::InvalidParameter {
                name: "particles of a rigid cluster".into(),
                value: off_line,
                expected: "are collinear: a line of particles cannot be held rigid by distances"
                    .into(),
            });
        }
        let normal = cross(axis, sub(x(p2), x(p0)));
        let normal = scale(1.0 / norm(normal), normal);
        let (p3, off_plane) = farthest(&|y| dot(normal, sub(y, x(p0))).abs());
        let planar = off_plane <= 1e-9 * size;
        let frame: Vec<usize> = if planar {
            vec![p0, p1, p2]
        } else {
            vec![p0, p1, p2, p3]
        };
        if planar && ids.len() > 3 {
            self.check_held_in_plane(&ids, normal)?;
        }
        let mut pairs = Vec::new();
        for a in 0..frame.len() {
            for b in (a + 1)..frame.len() {
                pairs.push((frame[a], frame[b]));
            }
        }
        let frame_positions: Vec<Vec3> = frame.iter().map(|&f| x(f)).collect();
        for &i in ids.iter().filter(|i| !frame.contains(i)) {
            for anchor in best_anchors(&frame_positions, x(i)) {
                pairs.push((i, frame[anchor]));
            }
        }
        let mut constraints = Vec::with_capacity(pairs.len());
        for (a, b) in pairs {
            let (a, b) = (self.particle_id(a)?, self.particle_id(b)?);
            constraints.push(self.add_distance(a, b, None)?);
        }
        let indices: Vec<usize> = constraints.iter().map(|k| k.0).collect();
        if let Some(e) = find_redundant(self, &self.initial_positions(), 0.0, Some(&indices)) {
            return Err(e);
        }
        Ok(RigidCluster {
            frame: frame
                .iter()
                .map(|&i| self.particle_id(i))
                .collect::<Result<_>>()?,
            constraints,
        })
    }

    /// Errors unless every particle of a planar cluster (plane normal `normal`) is fixed or has
    /// its coordinate along that world axis fixed.
    fn check_held_in_plane(&self, ids: &[usize], normal: Vec3) -> Result<()> {
        let axis = (0..3).find(|&k| (normal[k].abs() - 1.0).abs() < 1e-9);
        let held = |i: usize| {
            self.particles()[i].fixed
                || axis.is_some_and(|k| {
                    self.constraints().iter().any(|c| {
                        matches!(c, Constraint::FixedCoordinate(f) if f.particles[0] == i && f.axis == k)
                    })
                })
        };
        match ids.iter().find(|&&i| !held(i)) {
            None => Ok(()),
            Some(&i) => Err(Error::InvalidParameter {
                name: format!("particle {i} of a planar rigid cluster"),
                value: i as f64,
                expected: "must be held in the cluster's plane first (the plane normal to a world \
                           axis: fix that coordinate with add_fixed_coordinate), or the cluster \
                           could fold about a line of it; give a particle off the plane for a \
                           body in space"
                    .into(),
            }),
        }
    }
}

/// The frame particles (2 of a planar frame of 3, 3 of a frame of 4) whose unit directions from
/// `p` are the most independent.
fn best_anchors(frame: &[Vec3], p: Vec3) -> Vec<usize> {
    let unit = |k: usize| {
        let d = sub(frame[k], p);
        scale(1.0 / norm(d), d)
    };
    let n = frame.len();
    let mut best = (Vec::new(), -1.0);
    if n == 3 {
        for a in 0..3 {
            for b in (a + 1)..3 {
                let s = norm(cross(unit(a), unit(b)));
                if s > best.1 {
                    best = (vec![a, b], s);
                }
            }
        }
    } else {
        for a in 0..n {
            for b in (a + 1)..n {
                for c in (b + 1)..n {
                    let d = dot(unit(a), cross(unit(b), unit(c))).abs();
                    if d > best.1 {
                        best = (vec![a, b, c], d);
                    }
                }
            }
        }
    }
    best.0
}
