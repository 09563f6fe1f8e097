//! Rigid bodies as clusters of particles (paper 3.3): an octahedron of six particles around a
//! centre particle, with the body's mass, centre of mass and inertia tensor, held exactly rigid by
//! 15 independent distance constraints.
//!
//! Mass distribution. With the inertia tensor I about the centre of mass, the second moment of
//! the mass is J = sum m x x^T = tr(I)/2 1 - I (since I = tr(J) 1 - J). In the principal axes
//! e_k of J (eigenvalues J_k), a pair of particles of mass mu at +-r_k e_k contributes
//! 2 mu r_k^2 to J_k and nothing elsewhere, and a particle at the centre contributes nothing. So
//! six vertices of mass mu = m/10 at r_k = sqrt(J_k / (2 mu)) and a centre particle of 4 m/10
//! have mass m, centre of mass at the centre and second moment J, hence inertia I, exactly.
//! For a uniform sphere J_k = m R^2 / 5, so r_k = R: the paper's octahedron. A body needs
//! J_k > 0 on every axis (a strict triangle inequality on its principal moments); a flat or
//! linear body cannot be represented and is refused.
//!
//! Constraints. The 12 edges of the octahedron (each vertex to the four on the other axes) make
//! the six vertices rigid: a convex polyhedron with triangular faces is infinitesimally rigid
//! (Dehn), and 6 x 3 - 6 = 12. The centre is held by its distances to the three vertices
//! +e_1, +e_2, +e_3, whose directions are independent: 15 equations for 21 coordinates, leaving
//! the 6 of a rigid body. The builder checks this rank at the initial configuration and refuses a
//! set with a redundant equation.
//!
//! Points fixed on the body (where a string is tied) become particles of the cluster. A point that
//! coincides with a vertex or the centre is that particle. Any other point gets a particle of mass
//! `point_mass_fraction` m, held by distances to the three cluster particles that fix it best (the
//! largest |det| of the unit directions); the octahedron is then rebuilt around the remaining mass
//! so that the total mass, centre of mass and inertia stay exact.

use super::particle::{ConstraintId, ParticleId};
use super::system::System;
use crate::constraints::find_redundant;
use crate::error::{finite_vector, positive, Error, Result};
use crate::math::{add, add_mat, cross, norm, outer, scale, sub, Mat3, Vec3};

/// What a rigid body is made of and how it starts moving.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBodySpec {
    /// Mass (kg, > 0).
    pub mass: f64,
    /// Initial position of the centre of mass (m).
    pub centre: Vec3,
    /// Inertia tensor about the centre of mass in world axes at the initial time (kg m^2).
    pub inertia: Mat3,
    /// Initial velocity of the centre of mass (m/s).
    pub velocity: Vec3,
    /// Initial angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Initial world positions of points fixed on the body (attachment points).
    pub points: Vec<Vec3>,
    /// Mass of each added attachment particle as a fraction of the body's mass.
    pub point_mass_fraction: f64,
}

impl Default for RigidBodySpec {
    fn default() -> Self {
        RigidBodySpec {
            mass: 1.0,
            centre: [0.0; 3],
            inertia: [[0.4, 0.0, 0.0], [0.0, 0.4, 0.0], [0.0, 0.0, 0.4]],
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            points: Vec::new(),
            point_mass_fraction: 0.01,
        }
    }
}

/// Handles to the particles and constraints that make up a rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// The centre particle (at the centre of mass when the body has no added points).
    pub centre: ParticleId,
    /// The octahedron's vertices: +e1, -e1, +e2, -e2, +e3, -e3 along the principal axes.
    pub vertices: [ParticleId; 6],
    /// One particle per requested point, in the order given.
    pub points: Vec<ParticleId>,
    /// Every particle of the body.
    pub particles: Vec<ParticleId>,
    /// The distance constraints that hold it rigid.
    pub constraints: Vec<ConstraintId>,
    /// Principal axes used for the octahedron (columns e1, e2, e3; right-handed).
    pub axes: Mat3,
}

impl RigidBody {
    /// Four of its particles that frame it (the centre and the +e1, +e2, +e3 vertices, not
    /// coplanar): every point fixed in the body is an affine combination of them
    /// ([`System::point_in`]).
    pub fn frame(&self) -> [ParticleId; 4] {
        [
            self.centre,
            self.vertices[0],
            self.vertices[2],
            self.vertices[4],
        ]
    }
}

/// Mass and position of the 7 octahedron particles: centre, then +-e1, +-e2, +-e3.
struct Octahedron {
    masses: [f64; 7],
    positions: [Vec3; 7],
    axes: Mat3,
}

fn column(a: &Mat3, k: usize) -> Vec3 {
    [a[0][k], a[1][k], a[2][k]]
}

fn det(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Principal axes and second moments of a symmetric 3 x 3 matrix (ascending), world axes when it
/// is isotropic, always right-handed.
fn principal(j: &Mat3) -> Result<(Vec3, Mat3)> {
    let m = faer::Mat::<f64>::from_fn(3, 3, |r, c| j[r][c]);
    let evd = m
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::InvalidParameter {
            name: "inertia tensor".into(),
            value: f64::NAN,
            expected: format!("must have a symmetric eigendecomposition ({e:?})"),
        })?;
    let s = evd.S().column_vector();
    let u = evd.U();
    let values = [s[0], s[1], s[2]];
    let spread = values[2] - values[0];
    let mut axes: Mat3 = std::array::from_fn(|r| std::array::from_fn(|c| u[(r, c)]));
    if spread <= 1e-12 * values[2].abs() {
        axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    if det(column(&axes, 0), column(&axes, 1), column(&axes, 2)) < 0.0 {
        for row in axes.iter_mut() {
            row[2] = -row[2];
        }
    }
    Ok((values, axes))
}

/// The validated mass, centre, velocity, angular velocity and second moment of mass
/// J = tr(I)/2 1 - I about the centre (module doc) of a body.
pub(super) fn checked(spec: &RigidBodySpec) -> Result<(f64, Vec3, Vec3, Vec3, Mat3)> {
    let m = positive("mass of the rigid body", spec.mass)?;
    let c = finite_vector("centre of the rigid body", spec.centre)?;
    let v = finite_vector("velocity of the rigid body", spec.velocity)?;
    let w = finite_vector("angular velocity of the rigid body", spec.angular_velocity)?;
    let inertia = spec.inertia;
    let size = inertia
        .iter()
        .flatten()
        .fold(0.0_f64, |a, x| a.max(x.abs()));
    for r in 0..3 {
        finite_vector(format!("row {r} of the inertia tensor"), inertia[r])?;
        for k in 0..3 {
            if (inertia[r][k] - inertia[k][r]).abs() > 1e-12 * size {
                return Err(Error::InvalidVector {
                    name: format!("row {r} of the inertia tensor"),
                    value: inertia[r].to_vec(),
                    expected: format!(
                        "the tensor must be symmetric, but I[{r}][{k}] = {} and I[{k}][{r}] = {}",
                        inertia[r][k], inertia[k][r]
                    ),
                });
            }
        }
    }
    let trace = inertia[0][0] + inertia[1][1] + inertia[2][2];
    let j: Mat3 = std::array::from_fn(|r| {
        std::array::from_fn(|k| if r == k { 0.5 * trace } else { 0.0 } - inertia[r][k])
    });

    Ok((m, c, v, w, j))
}

/// The principal second moments and axes of `j` ([`principal`]), all > 0 as a solid's are;
/// otherwise an error saying the body cannot be made of `shape` (the message's end).
pub(super) fn solid_principal(j: &Mat3, shape: &str) -> Result<(Vec3, Mat3)> {
    let (moments, axes) = principal(j)?;
    for k in 0..3 {
        if moments[k] <= 1e-12 * moments[2].abs().max(f64::MIN_POSITIVE) {
            return Err(Error::InvalidParameter {
                name: format!(
                    "principal second moment {k} of the body's mass (from its inertia tensor)"
                ),
                value: moments[k],
                expected: format!(
                    "must be > 0: each principal moment of inertia must be smaller than the sum \
                     of the other two (a flat or linear body cannot be made of {shape}"
                ),
            });
        }
    }
    Ok((moments, axes))
}

/// The octahedron with mass `m`, centre `c` and second moment `j` about `c`.
fn octahedron(m: f64, c: Vec3, j: &Mat3) -> Result<Octahedron> {
    let (moments, axes) = solid_principal(
        j,
        "an octahedron of particles); or the attachment points are too heavy or too far out: \
         lower point_mass_fraction",
    )?;
    let mu = m / 10.0;
    let mut positions = [c; 7];
    let mut masses = [mu; 7];
    masses[0] = 0.4 * m;
    for k in 0..3 {
        let r = (moments[k] / (2.0 * mu)).sqrt();
        let e = column(&axes, k);
        positions[1 + 2 * k] = add(c, scale(r, e));
        positions[2 + 2 * k] = sub(c, scale(r, e));
    }
    Ok(Octahedron {
        masses,
        positions,
        axes,
    })
}

impl System {
    /// Adds a rigid body made of particles (see the module documentation): same mass, centre of
    /// mass and inertia tensor as `spec`, exactly rigid, with no redundant constraint.
    ///
    /// # Errors
    /// Invalid mass, non-finite or non-symmetric inertia, a flat or linear body, a bad
    /// `point_mass_fraction`, or (should the geometry be degenerate) redundant constraints.
    pub fn add_rigid_body(&mut self, spec: &RigidBodySpec) -> Result<RigidBody> {
        let (m, c, v, w, j) = checked(spec)?;
        let fraction = spec.point_mass_fraction;
        if !(fraction.is_finite() && fraction > 0.0 && fraction <= 0.1) {
            return Err(Error::InvalidParameter {
                name: "point_mass_fraction of the rigid body".into(),
                value: fraction,
                expected: "must be in (0, 0.1]".into(),
            });
        }
        for (k, p) in spec.points.iter().enumerate() {
            finite_vector(format!("point {k} of the rigid body"), *p)?;
        }
        // Points on a vertex or the centre of the plain octahedron are those particles.
        let plain = octahedron(m, c, &j)?;
        let extent = (0..7)
            .map(|k| norm(sub(plain.positions[k], c)))
            .fold(0.0, f64::max);
        let tolerance = 1e-9 * extent.max(f64::MIN_POSITIVE);
        let on_particle = |positions: &[Vec3; 7], x: Vec3| {
            (0..7).find(|&k| norm(sub(positions[k], x)) <= tolerance)
        };
        let extras: Vec<Vec3> = spec
            .points
            .iter()
            .copied()
            .filter(|p| on_particle(&plain.positions, *p).is_none())
            .collect();
        // Other points carry a little mass; the octahedron takes the rest, moved and reshaped so
        // that the totals stay exact.
        let shape = if extras.is_empty() {
            plain
        } else {
            let mu = fraction * m;
            let rest = m - mu * extras.len() as f64;
            if rest <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "point_mass_fraction of the rigid body".into(),
                    value: fraction,
                    expected: format!(
                        "the {} attachment particles would carry the whole mass: lower it",
                        extras.len()
                    ),
                });
            }
            let first: Vec3 = extras
                .iter()
                .fold([0.0; 3], |a, p| add(a, scale(mu, sub(*p, c))));
            let shift = scale(-1.0 / rest, first);
            let mut jr = j;
            for p in &extras {
                let d = sub(*p, c);
                jr = add_mat(jr, outer(-mu, d, d));
            }
            jr = add_mat(jr, outer(-rest, shift, shift));
            octahedron(rest, add(c, shift), &jr)?
        };

        let velocity = |x: Vec3| add(v, cross(w, sub(x, c)));
        let mut particles = Vec::with_capacity(7 + extras.len());
        for k in 0..7 {
            let x = shape.positions[k];
            particles.push(self.add_particle(shape.masses[k], x, velocity(x), false)?);
        }
        let mut constraints = Vec::with_capacity(15 + 3 * extras.len());
        for a in 1..7 {
            for b in (a + 1)..7 {
                if (a - 1) / 2 != (b - 1) / 2 {
                    constraints.push(self.add_distance(particles[a], particles[b], None)?);
                }
            }
        }
        for k in 0..3 {
            constraints.push(self.add_distance(particles[0], particles[1 + 2 * k], None)?);
        }
        let mut points = Vec::with_capacity(spec.points.len());
        for p in &spec.points {
            if let Some(k) = on_particle(&shape.positions, *p) {
                points.push(particles[k]);
                continue;
            }
            let id = self.add_particle(fraction * m, *p, velocity(*p), false)?;
            let anchors = best_anchors(&shape.positions, *p);
            for a in anchors {
                constraints.push(self.add_distance(id, particles[a], None)?);
            }
            particles.push(id);
            points.push(id);
        }
        let indices: Vec<usize> = constraints.iter().map(|k| k.0).collect();
        if let Some(e) = find_redundant(self, &self.initial_positions(), 0.0, Some(&indices)) {
            return Err(e);
        }
        Ok(RigidBody {
            centre: particles[0],
            vertices: std::array::from_fn(|k| particles[1 + k]),
            points,
            particles,
            constraints,
            axes: shape.axes,
        })
    }
}

/// The three of the seven octahedron particles whose directions from `p` are the most
/// independent (largest |det| of the unit vectors).
fn best_anchors(positions: &[Vec3; 7], p: Vec3) -> [usize; 3] {
    let unit = |k: usize| {
        let d = sub(positions[k], p);
        scale(1.0 / norm(d), d)
    };
    let mut best = ([0, 1, 2], -1.0);
    for a in 0..7 {
        for b in (a + 1)..7 {
            for c in (b + 1)..7 {
                let d = det(unit(a), unit(b), unit(c)).abs();
                if d > best.1 {
                    best = ([a, b, c], d);
                }
            }
        }
    }
    best.0
}

/// Mass, first moment about the origin and inertia tensor about `c` of a set of particles (the
/// tests of the bodies made of particles).
#[cfg(test)]
pub(super) fn moments(s: &System, ids: &[ParticleId], c: Vec3) -> (f64, Vec3, Mat3) {
    let mut m = 0.0;
    let mut first = [0.0; 3];
    let mut inertia = [[0.0; 3]; 3];
    for id in ids {
        let p = &s.particles()[id.index()];
        m += p.mass;
        first = add(first, scale(p.mass, p.position));
        let d = sub(p.position, c);
        for r in 0..3 {
            for k in 0..3 {
                let dd = crate::math::dot(d, d);
                inertia[r][k] += p.mass * (if r == k { dd } else { 0.0 } - d[r] * d[k]);
            }
        }
    }
    (m, first, inertia)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::dot;

    fn assert_body_matches(s: &System, body: &RigidBody, spec: &RigidBodySpec) {
        let (m, first, inertia) = moments(s, &body.particles, spec.centre);
        let scale_i = spec
            .inertia
            .iter()
            .flatten()
            .fold(0.0_f64, |a, x| a.max(x.abs()));
        assert!((m - spec.mass).abs() < 1e-14 * spec.mass);
        for k in 0..3 {
            assert!((first[k] / m - spec.centre[k]).abs() < 1e-13);
            for r in 0..3 {
                assert!(
                    (inertia[r][k] - spec.inertia[r][k]).abs() < 1e-13 * scale_i,
                    "I[{r}][{k}] = {} vs {}",
                    inertia[r][k],
                    spec.inertia[r][k]
                );
            }
        }
    }

    #[test]
    fn sphere_is_the_papers_octahedron() {
        // Reference: a uniform sphere, I = 2/5 m R^2 (closed form); the octahedron has vertices at
        // distance R carrying m/10 each and a centre of 4 m/10 (docs/theory/hydrodynamics.md).
        let (m, r) = (0.192, 0.05);
        let i = 0.4 * m * r * r;
        let spec = RigidBodySpec {
            mass: m,
            centre: [0.1, 0.0, 0.21],
            inertia: [[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]],
            points: vec![[0.1, 0.0, 0.16]],
            ..Default::default()
        };
        let mut s = System::new([0.0, 0.0, -9.81]);
        let body = s.add_rigid_body(&spec).unwrap();
        assert_eq!(body.particles.len(), 7);
        assert_eq!(body.constraints.len(), 15);
        assert_body_matches(&s, &body, &spec);
        // The lowest point is the -e3 vertex, at R below the centre.
        assert_eq!(body.points[0], body.vertices[5]);
        let p = s.particles()[body.points[0].index()].position;
        assert!(norm(sub(p, [0.1, 0.0, 0.16])) < 1e-15);
    }

    #[test]
    fn general_body_with_attachment_points_keeps_mass_centre_and_inertia() {
        // A rotated box-like tensor (principal moments 1, 2, 2.5 rotated about a skew axis) and two
        // points off the octahedron: the added particles must not change the totals.
        let (c, s_) = (0.6_f64.cos(), 0.6_f64.sin());
        let rot: Mat3 = [
            [c, -s_, 0.0],
            [s_ * 0.8, c * 0.8, 0.6],
            [-s_ * 0.6, -c * 0.6, 0.8],
        ];
        let d = [1.0, 2.0, 2.5];
        let inertia: Mat3 = std::array::from_fn(|r| {
            std::array::from_fn(|k| (0..3).map(|l| rot[r][l] * d[l] * rot[k][l]).sum())
        });
        let spec = RigidBodySpec {
            mass: 7.0,
            centre: [1.0, -2.0, 0.5],
            inertia,
            velocity: [0.1, 0.2, -0.3],
            angular_velocity: [0.5, -1.0, 2.0],
            points: vec![[1.3, -2.0, 0.2], [0.8, -1.7, 0.9]],
            point_mass_fraction: 0.02,
        };
        let mut s = System::new([0.0, 0.0, -9.81]);
        let body = s.add_rigid_body(&spec).unwrap();
        assert_eq!(body.particles.len(), 9);
        assert_eq!(body.constraints.len(), 21);
        assert_body_matches(&s, &body, &spec);
        for (k, p) in spec.points.iter().enumerate() {
            let x = s.particles()[body.points[k].index()].position;
            assert!(norm(sub(x, *p)) < 1e-15);
        }
        // Velocities are those of a rigid motion: v + w x (x - c) (so the constraints' rates vanish).
        let q = s.initial_positions();
        let v = s.initial_velocities();
        for &k in &body.constraints {
            let con = &s.constraints()[k.0];
            let g = con.gradient(&q, 0.0);
            let rate: f64 = con
                .particles()
                .iter()
                .enumerate()
                .map(|(x, &p)| dot(g[x], v[p]))
                .sum();
            assert!(rate.abs() < 1e-13, "constraint {} rate {rate}", k.0);
        }
    }

    #[test]
    fn flat_body_is_refused() {
        // A thin disc: I3 = I1 + I2, so the second moment along its axis is zero.
        let spec = RigidBodySpec {
            inertia: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]],
            ..Default::default()
        };
        let e = System::new([0.0; 3]).add_rigid_body(&spec).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
        assert!(e.to_string().contains("flat or linear"), "{e}");
    }

    #[test]
    fn an_extra_edge_is_named_redundant() {
        // Any further distance inside a rigid body adds no condition: the analysis names it.
        let mut s = System::new([0.0, 0.0, -9.81]);
        let body = s.add_rigid_body(&RigidBodySpec::default()).unwrap();
        let extra = s
            .add_distance(body.vertices[0], body.vertices[1], None)
            .unwrap();
        let mut all: Vec<usize> = body.constraints.iter().map(|c| c.0).collect();
        all.push(extra.0);
        match find_redundant(&s, &s.initial_positions(), 0.0, Some(&all)) {
            Some(Error::RedundantConstraints {
                index,
                depends_on_indices,
                ..
            }) => {
                assert_eq!(index, extra.0);
                assert!(!depends_on_indices.is_empty());
            }
            other => panic!("expected a redundancy, got {other:?}"),
        }
    }
}
