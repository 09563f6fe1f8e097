//! The system: particles, constraints and forces in arenas, reached through typed handles.

use super::particle::{ConstraintId, ForceId, Particle, ParticleId};
use crate::constraints::{
    Constraint, Distance, DotProduct, ElasticDistance, FixedCoordinate, Plane, PointDistance,
    RelativeCoordinate,
};
use crate::error::{finite_vector, non_negative, positive, Error, Result};
use crate::forces::{
    AppliedForce, Bending, Force, LinearDrag, Morison, MorisonSpec, QuadraticDrag, SpringDamper,
};
use crate::laws::{Law, VectorLaw};
use crate::math::{dot, norm, sub, Vec3};
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT_SYSTEM: AtomicU64 = AtomicU64::new(1);

/// A constrained particle system under uniform gravity.
#[derive(Debug, Clone)]
pub struct System {
    id: u64,
    gravity: Vec3,
    particles: Vec<Particle>,
    pub(crate) constraints: Vec<Constraint>,
    pub(crate) forces: Vec<Force>,
    pub(super) tension_only: Vec<usize>,
    /// Groups of user forces and constraints (their elements are also in `forces` and
    /// `constraints`), see [`super::user_groups`].
    pub(super) user_forces: Vec<std::sync::Arc<crate::forces::UserForces>>,
    pub(super) user_constraints: Vec<std::sync::Arc<crate::constraints::UserConstraints>>,
    /// The user laws of the constraints and forces, with the element each drives (a failed
    /// user function stops the run at once, see [`System::user_failure`]).
    pub(super) user_laws: Vec<(String, crate::laws::UserLaw)>,
    /// How many joints were added (their number in messages).
    pub(super) joints: usize,
    /// The water the line elements are in ([`System::set_water`]).
    pub(super) water: std::sync::Arc<crate::water::Water>,
}

impl System {
    /// An empty system with gravity `g` (m/s^2), e.g. `[0.0, 0.0, -9.81]`.
    ///
    /// # Panics
    /// If `gravity` is not finite; use [`System::try_new`] to get an error instead.
    #[track_caller]
    pub fn new(gravity: Vec3) -> System {
        System::try_new(gravity).expect("gravity must be finite")
    }

    /// An empty system; errors if `gravity` has a non-finite component.
    pub fn try_new(gravity: Vec3) -> Result<System> {
        Ok(System {
            id: NEXT_SYSTEM.fetch_add(1, Ordering::Relaxed),
            gravity: finite_vector("gravity", gravity)?,
            particles: Vec::new(),
            constraints: Vec::new(),
            forces: Vec::new(),
            tension_only: Vec::new(),
            user_forces: Vec::new(),
            user_constraints: Vec::new(),
            user_laws: Vec::new(),
            joints: 0,
            water: std::sync::Arc::new(crate::water::Water::everywhere(crate::math::norm(gravity))),
        })
    }

    /// Adds a particle. `fixed` particles never move.
    pub fn add_particle(
        &mut self,
        mass: f64,
        position: Vec3,
        velocity: Vec3,
        fixed: bool,
    ) -> Result<ParticleId> {
        let index = self.particles.len();
        let mass = positive(format!("mass of particle {index}"), mass)?;
        let position = finite_vector(format!("position of particle {index}"), position)?;
        let velocity = finite_vector(format!("velocity of particle {index}"), velocity)?;
        let velocity = if fixed { [0.0; 3] } else { velocity };
        self.particles.push(Particle {
            mass,
            position,
            velocity,
            fixed,
        });
        Ok(ParticleId {
            system: self.id,
            index,
        })
    }

    /// Checks that a handle belongs to this system and returns its index.
    pub fn check(&self, id: ParticleId) -> Result<usize> {
        if id.system != self.id || id.index >= self.particles.len() {
            return Err(Error::UnknownParticle {
                index: id.index,
                count: self.particles.len(),
            });
        }
        Ok(id.index)
    }

    /// Looks a particle up by index, as a handle (errors if out of range).
    pub fn particle_id(&self, index: usize) -> Result<ParticleId> {
        self.check(ParticleId {
            system: self.id,
            index,
        })
        .map(|index| ParticleId {
            system: self.id,
            index,
        })
    }

    pub(super) fn push_constraint(&mut self, c: Constraint) -> Result<ConstraintId> {
        let index = self.constraints.len();
        if c.particles().iter().all(|&p| self.particles[p].fixed) {
            return Err(Error::ConstraintOnFixedParticles {
                what: c.name(index),
            });
        }
        let what = c.name(index);
        self.note_user_laws(what, c.laws());
        self.constraints.push(c);
        Ok(ConstraintId(index))
    }

    /// Keeps the user laws among `laws` (those of the element `what`) for the failure checks.
    pub(super) fn note_user_laws(&mut self, what: String, laws: Vec<&crate::laws::Law>) {
        for law in laws {
            for user in law.user_laws() {
                self.user_laws.push((what.clone(), user.clone()));
            }
        }
    }

    /// The first law of a constraint or force that cannot be used at `t`: a user law whose
    /// function failed, or a law that is not finite there (a square root of a negative value).
    /// Looks at every element: for the failure paths of a run, not every step.
    pub fn law_failure(&self, t: f64) -> Option<Error> {
        // Names are made for the failing element alone (a run checks every element at its start).
        let failing = |laws: Vec<&Law>| {
            laws.iter().find_map(|law| {
                let (t, detail) = law.failure_at(t)?;
                let user = law
                    .user_laws()
                    .iter()
                    .find(|u| u.failure().is_some())
                    .map(|u| u.name().to_string());
                Some((t, detail, user))
            })
        };
        let error = |what: String, (t, detail, user)| Error::LawNotFinite {
            what,
            t,
            detail,
            user,
        };
        for (k, c) in self.constraints.iter().enumerate() {
            if let Some(found) = failing(c.laws()) {
                return Some(error(c.name(k), found));
            }
        }
        for (k, f) in self.forces.iter().enumerate() {
            if let Some(found) = failing(f.laws()) {
                return Some(error(f.name(k), found));
            }
        }
        None
    }

    /// Fixed distance between `a` and `b` (paper eq. 17). `length = None` takes the current distance.
    pub fn add_distance(
        &mut self,
        a: ParticleId,
        b: ParticleId,
        length: Option<f64>,
    ) -> Result<ConstraintId> {
        let (i, j) = (self.check(a)?, self.check(b)?);
        let index = self.constraints.len();
        if i == j {
            return Err(Error::SameParticle {
                what: format!("distance #{index}"),
                particle: i,
            });
        }
        let current = norm(sub(self.particles[i].position, self.particles[j].position));
        let length = positive(
            format!("length of distance #{index} (particles {i}-{j})"),
            length.unwrap_or(current),
        )?;
        self.push_constraint(Constraint::Distance(Distance {
            particles: [i, j],
            length,
        }))
    }

    /// An elastic segment between `a` and `b` of unstretched length `share length(t)` (m;
    /// `length` a law of time for a winch, `share` the segment's share of it, 1 for a segment of
    /// its own) and axial stiffness `ea` (N; `f64::INFINITY`: inextensible), whose multiplier is
    /// its tension (`docs/theory/moorings.md`).
    ///
    /// # Errors
    /// [`Error::SameParticle`] when `a` is `b`; [`Error::InvalidParameter`] when the length is
    /// not > 0 at t = 0, `share` not in (0, 1] or `ea` not > 0.
    pub fn add_elastic_distance(
        &mut self,
        a: ParticleId,
        b: ParticleId,
        (length, share): (Law, f64),
        ea: f64,
    ) -> Result<ConstraintId> {
        let (i, j) = (self.check(a)?, self.check(b)?);
        let index = self.constraints.len();
        if i == j {
            return Err(Error::SameParticle {
                what: format!("elastic segment #{index}"),
                particle: i,
            });
        }
        positive(
            format!("unstretched length of elastic segment #{index} (particles {i}-{j}) at t = 0"),
            share * length.value(0.0),
        )?;
        if !(share > 0.0 && share <= 1.0) {
            return Err(Error::InvalidParameter {
                name: format!("share of the length law of elastic segment #{index}"),
                value: share,
                expected: "must be in (0, 1]".into(),
            });
        }
        if ea.is_nan() || ea <= 0.0 {
            return Err(Error::InvalidParameter {
                name: format!("EA of elastic segment #{index} (particles {i}-{j})"),
                value: ea,
                expected: "must be > 0 (N; infinity for an inextensible segment)".into(),
            });
        }
        self.push_constraint(Constraint::ElasticDistance(Box::new(ElasticDistance {
            particles: [i, j],
            length,
            share,
            ea,
            slack: false,
            damping: 0.0,
            curve: None,
        })))
    }

    /// Fixed distance from `p` to a point moving by `point(t)`. `length = None`: the current distance.
    pub fn add_distance_to_point(
        &mut self,
        p: ParticleId,
        point: VectorLaw,
        length: Option<f64>,
    ) -> Result<ConstraintId> {
        let i = self.check(p)?;
        let index = self.constraints.len();
        let current = norm(sub(self.particles[i].position, point.value(0.0)));
        let length = positive(
            format!("length of distance to a moving point #{index} (particle {i})"),
            length.unwrap_or(current),
        )?;
        self.push_constraint(Constraint::PointDistance(Box::new(PointDistance {
            particles: [i],
            point,
            length,
        })))
    }

    /// Particle `p` on the plane n(t).(q - p0(t)) = 0.
    pub fn add_plane(
        &mut self,
        p: ParticleId,
        normal: VectorLaw,
        point: VectorLaw,
    ) -> Result<ConstraintId> {
        let i = self.check(p)?;
        let index = self.constraints.len();
        let n0 = normal.value(0.0);
        let length = positive(format!("length of the normal of plane #{index}"), norm(n0))?;
        self.push_constraint(Constraint::Plane(Box::new(Plane {
            particles: [i],
            normal,
            point,
            inverse_normal_length: 1.0 / length,
        })))
    }

    /// Coordinate `axis` (0, 1, 2) of `p` follows `value` (None: stays where it is).
    pub fn add_fixed_coordinate(
        &mut self,
        p: ParticleId,
        axis: usize,
        value: Option<Law>,
    ) -> Result<ConstraintId> {
        let i = self.check(p)?;
        if axis > 2 {
            return Err(Error::InvalidParameter {
                name: "axis of a fixed coordinate".into(),
                value: axis as f64,
                expected: "must be 0, 1 or 2 (x, y or z)".into(),
            });
        }
        let value = value.unwrap_or(Law::Constant(self.particles[i].position[axis]));
        self.push_constraint(Constraint::FixedCoordinate(Box::new(FixedCoordinate {
            particles: [i],
            axis,
            value,
        })))
    }

    /// q_b[axis] - q_a[axis] = value(t) (`None`: the current difference): three at zero make
    /// two points coincide. See [`crate::constraints::RelativeCoordinate`].
    pub fn add_relative_coordinate(
        &mut self,
        a: ParticleId,
        b: ParticleId,
        axis: usize,
        value: Option<Law>,
    ) -> Result<ConstraintId> {
        let (i, j) = (self.check(a)?, self.check(b)?);
        let index = self.constraints.len();
        if i == j {
            return Err(Error::SameParticle {
                what: format!("relative coordinate #{index}"),
                particle: i,
            });
        }
        if axis > 2 {
            return Err(Error::InvalidParameter {
                name: "axis of a relative coordinate".into(),
                value: axis as f64,
                expected: "must be 0, 1 or 2 (x, y or z)".into(),
            });
        }
        let current = self.particles[j].position[axis] - self.particles[i].position[axis];
        self.push_constraint(Constraint::RelativeCoordinate(Box::new(
            RelativeCoordinate {
                particles: [i, j],
                axis,
                value: value.unwrap_or(Law::Constant(current)),
            },
        )))
    }

    /// (q_b - q_a) . (q_d - q_c) = value(t) (`None`: the current value): zero keeps two
    /// directions perpendicular. Particles may repeat (two vectors from one point). See
    /// [`crate::constraints::DotProduct`].
    pub fn add_dot_product(
        &mut self,
        [a, b, c, d]: [ParticleId; 4],
        value: Option<Law>,
    ) -> Result<ConstraintId> {
        let ids = [
            self.check(a)?,
            self.check(b)?,
            self.check(c)?,
            self.check(d)?,
        ];
        let index = self.constraints.len();
        let q = |k: usize| self.particles[ids[k]].position;
        let (u, w) = (sub(q(1), q(0)), sub(q(3), q(2)));
        // u may vanish (a point on a line through it, at the start); w sets the scale.
        if norm(w) == 0.0 {
            return Err(Error::SameParticle {
                what: format!("dot product #{index} (second vector)"),
                particle: ids[2],
            });
        }
        let distinct = (0..4).all(|x| (0..x).all(|y| ids[x] != ids[y]));
        if !distinct {
            // A shared particle: over points, whose map merges its two slots.
            let points: Vec<_> = ids.iter().map(|&i| super::Point::particle(i)).collect();
            let label = format!("dot product #{index}");
            return self
                .on_points(&points, &label, |s, p| {
                    s.add_dot_product([p[0], p[1], p[2], p[3]], value)
                })
                .map(|(id, _)| id);
        }
        self.push_constraint(Constraint::DotProduct(Box::new(DotProduct {
            particles: ids,
            value: value.unwrap_or(Law::Constant(dot(u, w))),
            inverse_length: 1.0 / norm(w),
        })))
    }

    /// Adds bending stiffness at the middle particle `b` of three consecutive particles
    /// (a, b, c) of a line: the energy EI/(2 l^3) |q_a - 2 q_b + q_c|^2 of a beam of bending
    /// stiffness `ei` (N m^2) with node spacing `spacing` (m; `None`: the mean of the current
    /// distances a-b and b-c). See [`crate::forces::Bending`].
    pub fn add_bending(
        &mut self,
        a: ParticleId,
        b: ParticleId,
        c: ParticleId,
        ei: f64,
        spacing: Option<f64>,
    ) -> Result<ForceId> {
        let (i, j, k) = (self.check(a)?, self.check(b)?, self.check(c)?);
        let index = self.forces.len();
        if let Some(p) = [(i, j), (j, k), (i, k)].iter().find(|(x, y)| x == y) {
            return Err(Error::SameParticle {
                what: format!("bending #{index} (give three different particles)"),
                particle: p.0,
            });
        }
        let ei = non_negative(format!("bending stiffness EI of bending #{index}"), ei)?;
        let at = |x: usize| self.particles[x].position;
        let current = 0.5 * (norm(sub(at(i), at(j))) + norm(sub(at(j), at(k))));
        let spacing = positive(
            format!("node spacing of bending #{index}"),
            spacing.unwrap_or(current),
        )?;
        self.forces.push(Force::Bending(Bending {
            particles: [i, j, k],
            stiffness: ei / spacing.powi(3),
        }));
        Ok(ForceId(index))
    }

    /// Spring (stiffness k, rest length L0; None: the current distance) with a parallel dashpot c.
    pub fn add_spring_damper(
        &mut self,
        a: ParticleId,
        b: ParticleId,
        stiffness: f64,
        damping: f64,
        rest_length: Option<f64>,
    ) -> Result<ForceId> {
        let (i, j) = (self.check(a)?, self.check(b)?);
        let index = self.forces.len();
        if i == j {
            return Err(Error::SameParticle {
                what: format!("spring-damper #{index}"),
                particle: i,
            });
        }
        let stiffness = non_negative(format!("stiffness of spring-damper #{index}"), stiffness)?;
        let damping = non_negative(format!("damping of spring-damper #{index}"), damping)?;
        let current = norm(sub(self.particles[i].position, self.particles[j].position));
        let rest_length = non_negative(
            format!("rest length of spring-damper #{index}"),
            rest_length.unwrap_or(current),
        )?;
        self.forces.push(Force::SpringDamper(SpringDamper {
            particles: [i, j],
            stiffness,
            damping,
            rest_length,
        }));
        Ok(ForceId(index))
    }

    /// A prescribed force F(t) on `p`.
    pub fn add_force(&mut self, p: ParticleId, force: VectorLaw) -> Result<ForceId> {
        let i = self.check(p)?;
        let index = self.forces.len();
        let element = Force::Applied(Box::new(AppliedForce {
            particles: [i],
            force,
        }));
        self.note_user_laws(element.name(index), element.laws());
        self.forces.push(element);
        Ok(ForceId(index))
    }

    /// Linear drag f = -c v on `p`.
    pub fn add_linear_drag(&mut self, p: ParticleId, coefficient: f64) -> Result<ForceId> {
        let i = self.check(p)?;
        let index = self.forces.len();
        let coefficient =
            non_negative(format!("coefficient of linear drag #{index}"), coefficient)?;
        self.forces.push(Force::LinearDrag(LinearDrag {
            particles: [i],
            coefficient,
        }));
        Ok(ForceId(index))
    }

    /// A linear velocity coupling f = -D v over `particles` ([`crate::forces::DampingMatrix`]):
    /// `matrix` row-major, (3n)^2 entries, row 3p + k the force component k on particle p,
    /// column 3r + l the velocity component l of particle r.
    pub fn add_damping_matrix(
        &mut self,
        particles: &[ParticleId],
        matrix: &[f64],
    ) -> Result<ForceId> {
        let index = self.forces.len();
        let indices = particles
            .iter()
            .map(|&p| self.check(p))
            .collect::<Result<Vec<_>>>()?;
        let n = 3 * indices.len();
        if n == 0 || matrix.len() != n * n {
            return Err(Error::InvalidParameter {
                name: format!("matrix of damping matrix #{index}"),
                value: matrix.len() as f64,
                expected: format!(
                    "needs (3 x {} particles)^2 = {} entries, row-major",
                    indices.len(),
                    n * n
                ),
            });
        }
        for (k, &d) in matrix.iter().enumerate() {
            crate::error::finite(
                format!("entry ({}, {}) of damping matrix #{index}", k / n, k % n),
                d,
            )?;
        }
        for (a, &p) in indices.iter().enumerate() {
            if indices[..a].contains(&p) {
                return Err(Error::SameParticle {
                    what: format!("damping matrix #{index} (each particle once)"),
                    particle: p,
                });
            }
        }
        self.forces.push(Force::DampingMatrix(Box::new(
            crate::forces::DampingMatrix {
                particles: indices,
                matrix: matrix.to_vec(),
            },
        )));
        Ok(ForceId(index))
    }

    /// Quadratic drag f = -c |v| v on `p`.
    pub fn add_quadratic_drag(&mut self, p: ParticleId, coefficient: f64) -> Result<ForceId> {
        let i = self.check(p)?;
        let index = self.forces.len();
        let coefficient = non_negative(
            format!("coefficient of quadratic drag #{index}"),
            coefficient,
        )?;
        self.forces.push(Force::QuadraticDrag(QuadraticDrag {
            particles: [i],
            coefficient,
        }));
        Ok(ForceId(index))
    }

    /// Buoyancy, Froude-Krylov, added mass and drag of a fluid moving as a rigid body by
    /// `spec.fluid`, acting on `p` (a body's centre). See [`Morison`] for the equations.
    pub fn add_morison(&mut self, p: ParticleId, spec: MorisonSpec) -> Result<ForceId> {
        let i = self.check(p)?;
        let index = self.forces.len();
        let what = |field: &str| format!("{field} of fluid forces #{index} (particle {i})");
        let volume = if spec.in_water {
            // In water a point may have drag alone (MoorDyn's point with CdA and no volume).
            non_negative(what("volume"), spec.volume)?
        } else {
            positive(what("volume"), spec.volume)?
        };
        let element = Morison {
            particles: [i],
            density: positive(what("fluid density"), spec.density)?,
            volume,
            area: non_negative(what("frontal area"), spec.area)?,
            drag_coefficient: non_negative(what("drag coefficient"), spec.drag_coefficient)?,
            added_mass_coefficient: non_negative(
                what("added-mass coefficient"),
                spec.added_mass_coefficient,
            )?,
            fluid: spec.fluid,
            gravity: self.gravity,
            water: spec.in_water.then(|| self.water.clone()),
        };
        let element = Force::Morison(Box::new(element));
        self.note_user_laws(element.name(index), element.laws());
        self.forces.push(element);
        Ok(ForceId(index))
    }

    /// Declares constraint `c` a string or cable: it may pull but never push. A run stops with
    /// [`Error::NegativeTension`] at the first time the constraint would have to push, instead of
    /// returning the motion of a rod. Only distance constraints can be tension-only.
    pub fn set_tension_only(&mut self, c: ConstraintId) -> Result<()> {
        match self.constraints.get(c.0) {
            Some(con) if con.is_distance() => {
                if !self.tension_only.contains(&c.0) {
                    self.tension_only.push(c.0);
                }
                Ok(())
            }
            Some(other) => Err(Error::InvalidParameter {
                name: format!("tension-only constraint ({})", other.name(c.0)),
                value: c.0 as f64,
                expected: "must be a distance constraint (a string can only be a distance)".into(),
            }),
            None => Err(self.unknown_constraint(c)),
        }
    }

    /// The error for a constraint handle that is not one of this system's.
    fn unknown_constraint(&self, c: ConstraintId) -> Error {
        Error::InvalidParameter {
            name: "constraint handle".into(),
            value: c.0 as f64,
            expected: format!(
                "must be one of the system's {} constraints",
                self.constraints.len()
            ),
        }
    }

    /// Lets elastic segment `c` go slack: shorter than its unstretched length it carries no
    /// tension (and no compression), as MoorDyn's segments (`docs/theory/moorings.md`).
    pub fn set_slack(&mut self, c: ConstraintId) -> Result<()> {
        match self.constraints.get_mut(c.0) {
            Some(Constraint::ElasticDistance(e)) if e.ea.is_finite() => {
                e.slack = true;
                Ok(())
            }
            Some(other) => Err(Error::InvalidParameter {
                name: format!("slack segment ({})", other.name(c.0)),
                value: c.0 as f64,
                expected: "must be an elastic segment of finite EA (add_elastic_distance); an \
                           inextensible string is made tension-only with set_tension_only"
                    .into(),
            }),
            None => Err(self.unknown_constraint(c)),
        }
    }

    /// Gives elastic segment `c` a nonlinear tension-strain curve (MoorDyn's EA table): its
    /// tension follows `curve` instead of Hooke's law, and its EA becomes the curve's
    /// stiffest piece's (the scale the static solve uses; `constraints/strain_curve.rs`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `c` is not an elastic segment of finite EA between
    /// two particles.
    pub fn set_strain_curve(
        &mut self,
        c: ConstraintId,
        curve: std::sync::Arc<crate::constraints::StrainCurve>,
    ) -> Result<()> {
        match self.constraints.get_mut(c.0) {
            Some(Constraint::ElasticDistance(e)) if e.ea.is_finite() => {
                e.ea = curve.stiffest();
                e.curve = Some(curve);
                Ok(())
            }
            Some(other) => Err(Error::InvalidParameter {
                name: format!("nonlinear segment ({})", other.name(c.0)),
                value: c.0 as f64,
                expected: "must be an elastic segment of finite EA between two particles \
                           (add_elastic_distance)"
                    .into(),
            }),
            None => Err(self.unknown_constraint(c)),
        }
    }

    /// Gives elastic segment `c` an internal axial damping `damping` (N s/m; MoorDyn's BA / l):
    /// the tension `damping` u.(v_a - v_b) along it, whether stretched or slack
    /// (`constraints/elastic_distance.rs`). One element for the segment's elasticity and its
    /// damping: the same force as a spring-damper of zero stiffness between its particles.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when `c` is not an elastic segment between two particles (a
    /// segment between points of bodies takes a spring-damper of zero stiffness), or when
    /// `damping` is not finite and >= 0.
    pub fn set_axial_damping(&mut self, c: ConstraintId, damping: f64) -> Result<()> {
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(Error::InvalidParameter {
                name: format!("axial damping of constraint #{}", c.0),
                value: damping,
                expected: "must be finite and >= 0 (N s/m)".into(),
            });
        }
        match self.constraints.get_mut(c.0) {
            Some(Constraint::ElasticDistance(e)) => {
                e.damping = damping;
                Ok(())
            }
            Some(other) => Err(Error::InvalidParameter {
                name: format!("damped segment ({})", other.name(c.0)),
                value: c.0 as f64,
                expected: "must be an elastic segment between two particles \
                           (add_elastic_distance); between points of bodies, add a \
                           spring-damper of zero stiffness"
                    .into(),
            }),
            None => Err(self.unknown_constraint(c)),
        }
    }

    /// The constraints declared tension-only.
    pub fn tension_only(&self) -> &[usize] {
        &self.tension_only
    }

    /// Tension (N, > 0 pulling) of distance constraint `c` carrying multiplier `lambda`:
    /// with Phi = L^2 - |d|^2 the force on the first particle is -2 lambda d, so the tension is
    /// 2 lambda L; an elastic segment's multiplier is its tension. `None` for constraints that
    /// are not distances.
    pub fn tension(&self, c: usize, lambda: f64) -> Option<f64> {
        self.constraints[c].tension(lambda)
    }

    /// Keeps the constraints for which `keep` is true (in order) and returns the indices they
    /// had; the tension-only marks are dropped. How the linearised stiffness at a point removes
    /// the point's own supports.
    pub(crate) fn retain_constraints(&mut self, keep: impl Fn(&Constraint) -> bool) -> Vec<usize> {
        let kept: Vec<usize> = (0..self.constraints.len())
            .filter(|&k| keep(&self.constraints[k]))
            .collect();
        self.constraints.retain(|c| keep(c));
        self.tension_only.clear();
        kept
    }

    /// Fixes or frees particle `i` (an index of this system): how the linearised stiffness at a
    /// point frees that point.
    pub(crate) fn set_fixed(&mut self, i: usize, fixed: bool) {
        self.particles[i].fixed = fixed;
    }

    /// Inertia of each particle's translation: its mass plus the added mass of fluid elements
    /// (a line node's normal added mass Ca rho V; along the line the step problems correct it
    /// to CaAx rho V, `assembly/axial_added_mass.rs`).
    pub fn inertia(&self) -> Vec<f64> {
        let mut m: Vec<f64> = self.particles.iter().map(|p| p.mass).collect();
        for f in &self.forces {
            if let Some((i, a)) = f.added_mass() {
                m[i] += a;
            }
        }
        m
    }

    /// Identifier of this system (handles remember it).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Gravity vector.
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }

    /// The water the line elements are in: still water that fills all space until
    /// [`System::set_water`] gives another.
    pub fn water(&self) -> &crate::water::Water {
        &self.water
    }

    /// Puts the system's line elements ([`System::add_line_hydrodynamics`]) and floating
    /// bodies ([`System::add_floating_body`]), those added before and after, in `water`: its
    /// current and waves, and its free surface. A floating body's default added mass, Ca rho V0,
    /// follows: V0 is the volume below the new water's still-water level at the start.
    pub fn set_water(&mut self, water: crate::water::Water) {
        self.water = std::sync::Arc::new(water);
        let q = self.initial_positions();
        for f in &mut self.forces {
            match f {
                Force::LineHydro(h) => h.water = self.water.clone(),
                Force::Morison(m) if m.water.is_some() => m.water = Some(self.water.clone()),
                Force::FloatingBody(b) => {
                    b.water = self.water.clone();
                    b.default_added_mass(&q);
                }
                _ => {}
            }
        }
    }

    /// The force that force element `index` exerts on the particles it acts on
    /// ([`Force::acting`]: a line element's node alone) at positions `q`, velocities `v` and
    /// time `t`, summed: the element's share of the load on those particles (a line end's
    /// hydrodynamic and seabed loads, for the force of the line on its end point).
    pub fn element_force(&self, index: usize, q: &[Vec3], v: &[Vec3], t: f64) -> Result<Vec3> {
        let force = self
            .forces
            .get(index)
            .ok_or_else(|| Error::InvalidParameter {
                name: "force element".into(),
                value: index as f64,
                expected: format!("this system has {} force elements", self.forces.len()),
            })?;
        let rows = force.force(q, v, t);
        let mut f = [0.0; 3];
        for row in rows.iter().take(force.acting()) {
            for k in 0..3 {
                f[k] += row[k];
            }
        }
        Ok(f)
    }

    /// The particles.
    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// The constraints (one equation each).
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }

    /// The force elements.
    pub fn forces(&self) -> &[Force] {
        &self.forces
    }

    /// Replaces the initial positions and velocities (used by the projection).
    pub fn set_initial_state(&mut self, positions: &[Vec3], velocities: &[Vec3]) {
        for (p, (x, v)) in self
            .particles
            .iter_mut()
            .zip(positions.iter().zip(velocities))
        {
            p.position = *x;
            p.velocity = if p.fixed { [0.0; 3] } else { *v };
        }
    }

    /// Initial positions.
    pub fn initial_positions(&self) -> Vec<Vec3> {
        self.particles.iter().map(|p| p.position).collect()
    }

    /// Initial velocities.
    pub fn initial_velocities(&self) -> Vec<Vec3> {
        self.particles.iter().map(|p| p.velocity).collect()
    }

    /// Readable names of the constraint equations.
    pub fn constraint_names(&self) -> Vec<String> {
        self.constraints
            .iter()
            .enumerate()
            .map(|(k, c)| c.name(k))
            .collect()
    }

    /// A length that characterises the model: the largest constraint length or extent of the
    /// initial positions (1 m if the model has neither). Newton tolerances are relative to it.
    pub fn length_scale(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.particles {
            for k in 0..3 {
                lo[k] = lo[k].min(p.position[k]);
                hi[k] = hi[k].max(p.position[k]);
            }
        }
        let extent = if self.particles.is_empty() {
            0.0
        } else {
            norm(sub(hi, lo))
        };
        let longest = self
            .constraints
            .iter()
            .map(|c| c.length())
            .fold(0.0, f64::max);
        let l = extent.max(longest);
        if l > 0.0 {
            l
        } else {
            1.0
        }
    }

    /// Kinetic energy sum 1/2 m |v|^2.
    pub fn kinetic_energy(&self, v: &[Vec3]) -> f64 {
        self.particles
            .iter()
            .zip(v)
            .map(|(p, v)| 0.5 * p.mass * dot(*v, *v))
            .sum()
    }

    /// Potential energy of gravity and springs.
    pub fn potential_energy(&self, q: &[Vec3]) -> f64 {
        let gravity: f64 = self
            .particles
            .iter()
            .zip(q)
            .map(|(p, x)| -p.mass * dot(self.gravity, *x))
            .sum();
        gravity + self.forces.iter().map(|f| f.potential(q)).sum::<f64>()
    }

    /// Constraint residuals Phi(q, t), one per equation.
    pub fn constraint_residual(&self, q: &[Vec3], t: f64) -> Vec<f64> {
        self.constraints.iter().map(|c| c.residual(q, t)).collect()
    }
}
