//! `System` and the typed handles, wrapping the core's builder.

use crate::errors::{invalid, to_py};
use crate::laws::{scalar, vector};
use crate::points::PyPoint;
use crate::seabed::PySeabedGrid;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vinculo::forces::{MorisonSpec, SeabedFriction};
use vinculo::model::{LineHydroSpec, ParticleId, RigidBodySpec, SeabedSpec, System};

/// Handle to a particle of one System.
#[pyclass(name = "ParticleId", module = "vinculo._core", frozen, eq, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct PyParticleId {
    pub inner: ParticleId,
}

#[pymethods]
impl PyParticleId {
    /// Position of the particle in the arrays of a Solution.
    #[getter]
    fn index(&self) -> usize {
        self.inner.index()
    }
    fn __repr__(&self) -> String {
        format!("ParticleId({})", self.inner.index())
    }
}

/// Handle to a constraint: the index of its multiplier.
#[pyclass(name = "ConstraintId", module = "vinculo._core", frozen, eq, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct PyConstraintId {
    #[pyo3(get)]
    index: usize,
}

#[pymethods]
impl PyConstraintId {
    fn __repr__(&self) -> String {
        format!("ConstraintId({})", self.index)
    }
}

/// The constraint of a `ConstraintId` handle (`made_by` names the methods that return one, for
/// the error).
fn constraint_id(obj: &Bound<'_, PyAny>, made_by: &str) -> PyResult<vinculo::model::ConstraintId> {
    let c = obj.cast::<PyConstraintId>().map_err(|_| {
        invalid(
            "constraint",
            obj.repr().map(|r| r.to_string()).unwrap_or_default(),
            &format!("expected a ConstraintId returned by {made_by}"),
        )
    })?;
    Ok(vinculo::model::ConstraintId(c.get().index))
}

/// Handle to a force element.
#[pyclass(name = "ForceId", module = "vinculo._core", frozen, eq, hash)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct PyForceId {
    #[pyo3(get)]
    index: usize,
}

#[pymethods]
impl PyForceId {
    fn __repr__(&self) -> String {
        format!("ForceId({})", self.index)
    }
}

/// Positions or velocities of every particle at one instant.
type Frame = Vec<[f64; 3]>;

/// A constrained particle system under uniform gravity.
#[pyclass(name = "System", module = "vinculo._core")]
pub struct PySystem {
    pub inner: System,
    /// The first exception raised by a user function (for the run to chain).
    pub user_errors: crate::user_physics::PendingError,
}

/// Python handles of particles.
fn particle_handles(ids: &[ParticleId]) -> Vec<PyParticleId> {
    ids.iter().map(|&inner| PyParticleId { inner }).collect()
}

/// Python handles of constraints.
fn constraint_handles(ids: &[vinculo::model::ConstraintId]) -> Vec<PyConstraintId> {
    ids.iter().map(|c| PyConstraintId { index: c.0 }).collect()
}

/// An axis given as 0, 1, 2 or "x", "y", "z".
fn axis_index(axis: &Bound<'_, PyAny>) -> PyResult<usize> {
    if let Ok(s) = axis.extract::<String>() {
        return match s.as_str() {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            _ => Err(invalid("axis", s, "expected 0, 1, 2 or 'x', 'y', 'z'")),
        };
    }
    axis.extract::<usize>()
        .map_err(|_| invalid("axis", axis, "expected 0, 1, 2 or 'x', 'y', 'z'"))
}

fn vec3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; 3]> {
    let v: Vec<f64> = obj.extract().map_err(|_| {
        invalid(
            what,
            obj.repr().map(|r| r.to_string()).unwrap_or_default(),
            "expected 3 numbers",
        )
    })?;
    if v.len() != 3 {
        return Err(invalid(
            what,
            format!("{v:?}"),
            "expected exactly 3 numbers",
        ));
    }
    Ok([v[0], v[1], v[2]])
}

impl PySystem {
    /// A line tangent given as a pair (a, b) of particles, or None.
    fn tangent(
        &self,
        tangent: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<(ParticleId, ParticleId)>> {
        let Some(pair) = tangent else {
            return Ok(None);
        };
        let items: Vec<Bound<'_, PyAny>> = pair.extract().map_err(|_| {
            invalid(
                "tangent",
                pair.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected a pair (a, b) of ParticleIds: the tangent points from a to b",
            )
        })?;
        if items.len() != 2 {
            return Err(invalid(
                "tangent",
                pair.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected exactly two ParticleIds (a, b)",
            ));
        }
        Ok(Some((self.particle(&items[0])?, self.particle(&items[1])?)))
    }

    pub fn particle(&self, obj: &Bound<'_, PyAny>) -> PyResult<ParticleId> {
        if obj.cast::<PyPoint>().is_ok() {
            return Err(invalid(
                "particle",
                obj.repr().map(|r| r.to_string()).unwrap_or_default(),
                "this element acts on particles only (fluid forces, line loads, seabed contact, \
                 user groups, tangents, clusters, frames): give a ParticleId, such as a body's \
                 centre particle",
            ));
        }
        let id = obj.cast::<PyParticleId>().map_err(|_| {
            Python::attach(|py| {
                let d = PyDict::new(py);
                let _ = d.set_item("value", obj.clone());
                crate::errors::raise(
                    py,
                    "UnknownHandleError",
                    format!(
                        "expected a ParticleId returned by System.add_particle, got {}",
                        obj.repr().map(|r| r.to_string()).unwrap_or_default()
                    ),
                    d,
                )
            })
        })?;
        let id = id.get().inner;
        self.inner.check(id).map_err(to_py)?;
        Ok(id)
    }

    /// Reads an (..., n, 3) array as a list of (n, 3) frames.
    fn frames(
        &self,
        array: &PyReadonlyArrayDyn<'_, f64>,
        what: &str,
    ) -> PyResult<(Vec<usize>, Vec<Frame>)> {
        let a = array.as_array();
        let shape = a.shape().to_vec();
        let n = self.inner.particles().len();
        if shape.len() < 2 || shape[shape.len() - 1] != 3 || shape[shape.len() - 2] != n {
            return Err(invalid(
                what,
                format!("array of shape {shape:?}"),
                &format!("expected shape (..., {n}, 3)"),
            ));
        }
        let flat: Vec<f64> = a.iter().copied().collect();
        let frames = flat
            .chunks(3 * n)
            .map(|c| c.chunks(3).map(|x| [x[0], x[1], x[2]]).collect())
            .collect();
        Ok((shape[..shape.len() - 2].to_vec(), frames))
    }
}

fn positions_array<'py>(py: Python<'py>, x: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((x.len(), 3), x.iter().flatten().copied().collect())
        .expect("shape")
        .into_pyarray(py)
}

#[pymethods]
impl PySystem {
    #[new]
    #[pyo3(signature = (gravity=None))]
    fn new(gravity: Option<&Bound<'_, PyAny>>) -> PyResult<PySystem> {
        let g = match gravity {
            Some(g) => vec3(g, "gravity")?,
            None => [0.0; 3],
        };
        Ok(PySystem {
            inner: System::try_new(g).map_err(to_py)?,
            user_errors: Default::default(),
        })
    }

    /// An independent copy of the system as it is now (particles, constraints, forces, initial
    /// state); later edits of either leave the other unchanged. Handles of this system work with
    /// the copy. A `Solution` holds such a copy, taken when its run ended.
    fn copy(&self) -> PySystem {
        PySystem {
            inner: self.inner.clone(),
            // The user groups (cloned with `inner`) report their exceptions to this slot.
            user_errors: self.user_errors.clone(),
        }
    }

    fn __copy__(&self) -> PySystem {
        self.copy()
    }

    /// Adds a point mass; returns its handle. Fixed particles never move.
    #[pyo3(signature = (mass, position, velocity=None, fixed=false))]
    fn add_particle(
        &mut self,
        mass: f64,
        position: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        fixed: bool,
    ) -> PyResult<PyParticleId> {
        let index = self.inner.particles().len();
        let x = vec3(position, &format!("position of particle {index}"))?;
        let v = match velocity {
            Some(v) => vec3(v, &format!("velocity of particle {index}"))?,
            None => [0.0; 3],
        };
        Ok(PyParticleId {
            inner: self.inner.add_particle(mass, x, v, fixed).map_err(to_py)?,
        })
    }

    /// Fixed distance between two particles, Phi = L^2 - |q_a - q_b|^2 (length=None: current).
    #[pyo3(signature = (a, b, length=None))]
    fn add_distance(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        length: Option<f64>,
    ) -> PyResult<PyConstraintId> {
        let id = self.over(&[a, b], "distance", |s, p| {
            s.add_distance(p[0], p[1], length)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// Elastic segment: |q_a - q_b| = l(t) + (l(t)/EA) T, its multiplier the tension T (N), with
    /// l(t) = share length(t); `length` a number or a law of time (a winch), `share` the
    /// segment's share of it; `ea` in N, `math.inf`: inextensible.
    #[pyo3(signature = (a, b, length, ea, share=1.0))]
    fn add_elastic_distance(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        length: &Bound<'_, PyAny>,
        ea: f64,
        share: f64,
    ) -> PyResult<PyConstraintId> {
        let length = scalar(length, "unstretched length")?;
        let id = self.over(&[a, b], "elastic segment", |s, p| {
            s.add_elastic_distance(p[0], p[1], (length, share), ea)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// Fixed distance from a particle to a prescribed point p(t), Phi = L^2 - |q - p(t)|^2.
    #[pyo3(signature = (particle, point, length=None))]
    fn add_distance_to_point(
        &mut self,
        particle: &Bound<'_, PyAny>,
        point: &Bound<'_, PyAny>,
        length: Option<f64>,
    ) -> PyResult<PyConstraintId> {
        let point = vector(point, "point")?;
        let id = self.over(&[particle], "distance to a moving point", |s, p| {
            s.add_distance_to_point(p[0], point, length)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// Particle on the plane n(t).(q - p0(t)) = 0.
    fn add_plane(
        &mut self,
        particle: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        point: &Bound<'_, PyAny>,
    ) -> PyResult<PyConstraintId> {
        let (n, p0) = (
            vector(normal, "plane normal")?,
            vector(point, "plane point")?,
        );
        let id = self.over(&[particle], "plane", |s, p| s.add_plane(p[0], n, p0))?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// q[axis] = value(t); axis 0/1/2 or "x"/"y"/"z"; value=None keeps the current coordinate.
    #[pyo3(signature = (particle, axis, value=None))]
    fn add_fixed_coordinate(
        &mut self,
        particle: &Bound<'_, PyAny>,
        axis: &Bound<'_, PyAny>,
        value: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyConstraintId> {
        let axis = axis_index(axis)?;
        let value = value
            .map(|v| scalar(v, "fixed coordinate value"))
            .transpose()?;
        let id = self.over(&[particle], "fixed coordinate", |s, p| {
            s.add_fixed_coordinate(p[0], axis, value)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// Linear spring (stiffness, rest_length; None: current distance) with a parallel dashpot.
    #[pyo3(signature = (a, b, stiffness, damping=0.0, rest_length=None))]
    fn add_spring_damper(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        stiffness: f64,
        damping: f64,
        rest_length: Option<f64>,
    ) -> PyResult<PyForceId> {
        let id = self.over(&[a, b], "spring-damper", |s, p| {
            s.add_spring_damper(p[0], p[1], stiffness, damping, rest_length)
        })?;
        Ok(PyForceId { index: id.0 })
    }

    /// Bending stiffness ei (N m^2) at the middle particle b of three consecutive particles of a
    /// line, with node spacing `spacing` (m; None: the mean current distance a-b, b-c).
    #[pyo3(signature = (a, b, c, ei, spacing=None))]
    fn add_bending(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        c: &Bound<'_, PyAny>,
        ei: f64,
        spacing: Option<f64>,
    ) -> PyResult<PyForceId> {
        let id = self.over(&[a, b, c], "bending", |s, p| {
            s.add_bending(p[0], p[1], p[2], ei, spacing)
        })?;
        Ok(PyForceId { index: id.0 })
    }

    /// A prescribed force (3 numbers or Laws, N) on a particle.
    fn add_force(
        &mut self,
        particle: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
    ) -> PyResult<PyForceId> {
        let f = vector(force, "force")?;
        let id = self.over(&[particle], "applied force", |s, p| s.add_force(p[0], f))?;
        Ok(PyForceId { index: id.0 })
    }

    /// Linear drag f = -c v.
    fn add_linear_drag(
        &mut self,
        particle: &Bound<'_, PyAny>,
        coefficient: f64,
    ) -> PyResult<PyForceId> {
        let id = self.over(&[particle], "linear drag", |s, p| {
            s.add_linear_drag(p[0], coefficient)
        })?;
        Ok(PyForceId { index: id.0 })
    }

    /// Quadratic drag f = -c |v| v.
    fn add_quadratic_drag(
        &mut self,
        particle: &Bound<'_, PyAny>,
        coefficient: f64,
    ) -> PyResult<PyForceId> {
        let id = self.over(&[particle], "quadratic drag", |s, p| {
            s.add_quadratic_drag(p[0], coefficient)
        })?;
        Ok(PyForceId { index: id.0 })
    }

    /// q_b[axis] - q_a[axis] = value(t) (None: the current difference), over particles or points.
    #[pyo3(signature = (a, b, axis, value=None))]
    fn add_relative_coordinate(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        axis: &Bound<'_, PyAny>,
        value: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyConstraintId> {
        let axis = axis_index(axis)?;
        let value = value
            .map(|v| scalar(v, "relative coordinate value"))
            .transpose()?;
        let id = self.over(&[a, b], "relative coordinate", |s, p| {
            s.add_relative_coordinate(p[0], p[1], axis, value)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// (q_b - q_a) . (q_d - q_c) = value(t) (None: the current value), over particles or points.
    #[pyo3(signature = (a, b, c, d, value=None))]
    fn add_dot_product(
        &mut self,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        c: &Bound<'_, PyAny>,
        d: &Bound<'_, PyAny>,
        value: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyConstraintId> {
        let value = value.map(|v| scalar(v, "dot product value")).transpose()?;
        let id = self.over(&[a, b, c, d], "dot product", |s, p| {
            s.add_dot_product([p[0], p[1], p[2], p[3]], value)
        })?;
        Ok(PyConstraintId { index: id.0 })
    }

    /// The point of `body` (a rigid body's dict, a frame of 3 or 4 ParticleIds) at world
    /// position `position` now; with body None, the ground point there.
    fn point(
        &self,
        body: Option<&Bound<'_, PyAny>>,
        position: &Bound<'_, PyAny>,
    ) -> PyResult<PyPoint> {
        let frame = self.frame(body, "body")?;
        let at = vec3(position, "position")?;
        let point = if frame.is_empty() {
            vinculo::model::Point::ground(at)
        } else {
            self.inner.point_in(&frame, at).map_err(to_py)?
        };
        Ok(self.make_point(point))
    }

    /// A joint of `kind` ("spherical", "revolute", "prismatic", "fixed", "orientation",
    /// "point-on-line", "point-on-plane") between bodies a and b (None: the ground) at world point `at` with
    /// axis `axis`; returns its equations' ConstraintIds.
    #[pyo3(signature = (kind, a, b, at, axis=None))]
    fn add_joint(
        &mut self,
        kind: &str,
        a: Option<&Bound<'_, PyAny>>,
        b: Option<&Bound<'_, PyAny>>,
        at: &Bound<'_, PyAny>,
        axis: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<PyConstraintId>> {
        use vinculo::model::JointKind;
        let kind = match kind {
            "spherical" => JointKind::Spherical,
            "revolute" => JointKind::Revolute,
            "prismatic" => JointKind::Prismatic,
            "fixed" => JointKind::Fixed,
            "orientation" => JointKind::Orientation,
            "point-on-line" => JointKind::PointOnLine,
            "point-on-plane" => JointKind::PointOnPlane,
            other => {
                return Err(invalid(
                    "kind",
                    other,
                    "expected 'spherical', 'revolute', 'prismatic', 'fixed', 'orientation', 'point-on-line' or 'point-on-plane'",
                ))
            }
        };
        let needs_axis = !matches!(
            kind,
            JointKind::Spherical | JointKind::Fixed | JointKind::Orientation
        );
        let axis = match axis {
            Some(a) => vec3(a, "axis")?,
            None if needs_axis => {
                return Err(invalid(
                    "axis",
                    "None",
                    &format!("a {} needs its axis (3 numbers)", kind.name()),
                ))
            }
            None => [0.0, 0.0, 1.0],
        };
        let (fa, fb) = (self.frame(a, "a")?, self.frame(b, "b")?);
        let at = vec3(at, "at")?;
        let ids = self
            .inner
            .add_joint(kind, (&fa, &fb), at, axis)
            .map_err(to_py)?;
        Ok(constraint_handles(&ids))
    }

    /// A torque (N m; a number or a Law) about the world axis `axis` through `at` on `body`.
    #[pyo3(signature = (body, torque, axis, at))]
    fn add_torque(
        &mut self,
        body: &Bound<'_, PyAny>,
        torque: &Bound<'_, PyAny>,
        axis: &Bound<'_, PyAny>,
        at: &Bound<'_, PyAny>,
    ) -> PyResult<PyForceId> {
        let frame = self.frame(Some(body), "body")?;
        let torque = scalar(torque, "torque")?;
        let (axis, at) = (vec3(axis, "axis")?, vec3(at, "at")?);
        let id = self
            .inner
            .add_torque(&frame, at, axis, torque)
            .map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// A planar rigid body moving in the plane normal to axis `normal` ("x", "y", "z"): three
    /// particles with its mass, centre and moment of inertia about the normal.
    #[pyo3(signature = (mass, centre, inertia, normal=None, velocity=None, angular_velocity=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn add_planar_body<'py>(
        &mut self,
        py: Python<'py>,
        mass: f64,
        centre: &Bound<'_, PyAny>,
        inertia: f64,
        normal: Option<&Bound<'_, PyAny>>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let spec = vinculo::model::PlanarBodySpec {
            mass,
            centre: vec3(centre, "centre")?,
            inertia,
            normal: normal.map(axis_index).transpose()?.unwrap_or(1),
            velocity: velocity
                .map(|v| vec3(v, "velocity"))
                .transpose()?
                .unwrap_or([0.0; 3]),
            angular_velocity,
        };
        let body = self.inner.add_planar_body(&spec).map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("particles", particle_handles(&body.particles))?;
        d.set_item("frame", particle_handles(&body.particles))?;
        d.set_item("constraints", constraint_handles(&body.constraints))?;
        d.set_item("normal", ["x", "y", "z"][body.normal])?;
        Ok(d)
    }

    /// Makes existing particles one rigid body (bodies may share particles); returns its frame
    /// and constraints.
    fn add_rigid_cluster<'py>(
        &mut self,
        py: Python<'py>,
        particles: Vec<Bound<'_, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ids = particles
            .iter()
            .map(|p| self.particle(p))
            .collect::<PyResult<Vec<_>>>()?;
        let cluster = self.inner.add_rigid_cluster(&ids).map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("particles", particle_handles(&ids))?;
        d.set_item("frame", particle_handles(&cluster.frame))?;
        d.set_item("constraints", constraint_handles(&cluster.constraints))?;
        Ok(d)
    }

    /// A rigid body made of particles: same mass, centre and inertia tensor, exactly rigid.
    ///
    /// Returns a dict with "centre", "vertices", "points", "particles" (ParticleIds),
    /// "constraints" (ConstraintIds) and "axes" (principal axes as columns).
    #[pyo3(signature = (mass, centre, inertia, velocity=None, angular_velocity=None, points=None, point_mass_fraction=0.01, particles=7))]
    #[allow(clippy::too_many_arguments)]
    fn add_rigid_body<'py>(
        &mut self,
        py: Python<'py>,
        mass: f64,
        centre: &Bound<'_, PyAny>,
        inertia: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
        points: Option<Vec<Bound<'_, PyAny>>>,
        point_mass_fraction: f64,
        particles: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let rows: Vec<Vec<f64>> = inertia.extract().map_err(|_| {
            invalid(
                "inertia",
                inertia.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected a 3 x 3 tensor (kg m^2)",
            )
        })?;
        if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
            return Err(invalid(
                "inertia",
                format!("{rows:?}"),
                "expected a 3 x 3 tensor",
            ));
        }
        let spec = RigidBodySpec {
            mass,
            centre: vec3(centre, "centre")?,
            inertia: std::array::from_fn(|r| [rows[r][0], rows[r][1], rows[r][2]]),
            velocity: velocity
                .map(|v| vec3(v, "velocity"))
                .transpose()?
                .unwrap_or([0.0; 3]),
            angular_velocity: angular_velocity
                .map(|v| vec3(v, "angular_velocity"))
                .transpose()?
                .unwrap_or([0.0; 3]),
            points: points
                .unwrap_or_default()
                .iter()
                .map(|p| vec3(p, "points"))
                .collect::<PyResult<_>>()?,
            point_mass_fraction,
        };
        let ids = particle_handles;
        match particles {
            7 => {}
            4 => {
                let body = self.inner.add_rigid_tetrahedron(&spec).map_err(to_py)?;
                let d = PyDict::new(py);
                d.set_item("particles", ids(&body.particles))?;
                d.set_item("frame", ids(&body.particles))?;
                let centre = self
                    .inner
                    .point_in(&body.particles, spec.centre)
                    .map_err(to_py)?;
                d.set_item("centre", self.make_point(centre))?;
                d.set_item("constraints", constraint_handles(&body.constraints))?;
                d.set_item("axes", body.axes.map(|r| r.to_vec()).to_vec())?;
                return Ok(d);
            }
            n => {
                return Err(invalid(
                    "particles",
                    n,
                    "expected 7 (an octahedron and its centre) or 4 (a tetrahedron)",
                ))
            }
        }
        let body = self.inner.add_rigid_body(&spec).map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("centre", PyParticleId { inner: body.centre })?;
        d.set_item("vertices", ids(&body.vertices))?;
        d.set_item("points", ids(&body.points))?;
        d.set_item("particles", ids(&body.particles))?;
        d.set_item("frame", ids(&body.frame()))?;
        d.set_item("constraints", constraint_handles(&body.constraints))?;
        d.set_item("axes", body.axes.map(|r| r.to_vec()).to_vec())?;
        Ok(d)
    }

    /// Fluid forces on a body's centre: buoyancy and Froude-Krylov, added mass, Morison drag,
    /// for a fluid moving as a rigid body with displacement `fluid_motion` (3 numbers or Laws),
    /// or, with `in_water`, in the system's water (`set_water`: its current and waves).
    #[pyo3(signature = (particle, *, volume, area, drag_coefficient, added_mass_coefficient, density=1000.0, fluid_motion=None, in_water=false))]
    #[allow(clippy::too_many_arguments)]
    fn add_morison(
        &mut self,
        particle: &Bound<'_, PyAny>,
        volume: f64,
        area: f64,
        drag_coefficient: f64,
        added_mass_coefficient: f64,
        density: f64,
        fluid_motion: Option<&Bound<'_, PyAny>>,
        in_water: bool,
    ) -> PyResult<PyForceId> {
        let p = self.particle(particle)?;
        if in_water && fluid_motion.is_some() {
            return Err(invalid(
                "fluid_motion",
                "a fluid motion with in_water=True",
                "give one: the fluid's rigid motion or the system's water",
            ));
        }
        let fluid = match fluid_motion {
            Some(f) => vector(f, "fluid_motion")?,
            None => vinculo::laws::VectorLaw::constant([0.0; 3]),
        };
        let spec = MorisonSpec {
            density,
            volume,
            area,
            drag_coefficient,
            added_mass_coefficient,
            fluid,
            in_water,
        };
        let id = self.inner.add_morison(p, spec).map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// Seabed contact and friction of a line node (MoorDyn's kBot, cBot, friction model), on
    /// the plane z = -depth or, with `grid`, on the heights of a `SeabedGrid`.
    #[pyo3(signature = (node, *, depth, diameter, length, kbot=3.0e6, cbot=3.0e5, tangent=None, friction=0.0, axial_friction=None, friction_damping=200.0, static_dynamic_scale=1.0, damping_ramp=0.0, grid=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_seabed_contact(
        &mut self,
        node: &Bound<'_, PyAny>,
        depth: f64,
        diameter: f64,
        length: f64,
        kbot: f64,
        cbot: f64,
        tangent: Option<&Bound<'_, PyAny>>,
        friction: f64,
        axial_friction: Option<f64>,
        friction_damping: f64,
        static_dynamic_scale: f64,
        damping_ramp: f64,
        grid: Option<Bound<'_, PySeabedGrid>>,
    ) -> PyResult<PyForceId> {
        let n = self.particle(node)?;
        let tangent = self.tangent(tangent)?;
        let spec = SeabedSpec {
            depth,
            grid: grid.map(|g| std::sync::Arc::clone(&g.get().inner)),
            diameter,
            length,
            stiffness: kbot,
            damping: cbot,
            damping_ramp,
            friction: SeabedFriction {
                transverse: friction,
                axial: axial_friction,
                damping: friction_damping,
                static_scale: static_dynamic_scale,
            },
        };
        let id = self
            .inner
            .add_seabed_contact(n, tangent, &spec)
            .map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// Buoyancy, drag and added mass of a line node in water (MoorDyn's Cd, CdAx, Ca, CaAx).
    /// In the system's water (`set_water`; still water everywhere by default).
    #[pyo3(signature = (node, *, diameter, length, cd=0.0, cdax=0.0, ca=0.0, caax=0.0, density=1025.0, tangent=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_line_hydrodynamics(
        &mut self,
        node: &Bound<'_, PyAny>,
        diameter: f64,
        length: f64,
        cd: f64,
        cdax: f64,
        ca: f64,
        caax: f64,
        density: f64,
        tangent: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyForceId> {
        let n = self.particle(node)?;
        let tangent = self.tangent(tangent)?;
        let spec = LineHydroSpec {
            density,
            diameter,
            length,
            cd,
            cdax,
            ca,
            caax,
        };
        let id = self
            .inner
            .add_line_hydrodynamics(n, tangent, &spec)
            .map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// A linear velocity coupling f = -D v over particles (see the stub).
    fn add_damping_matrix(
        &mut self,
        particles: Vec<Bound<'_, PyAny>>,
        matrix: numpy::PyReadonlyArray2<'_, f64>,
    ) -> PyResult<PyForceId> {
        let ids = particles
            .iter()
            .map(|p| self.particle(p))
            .collect::<PyResult<Vec<_>>>()?;
        let m = matrix.as_array();
        if m.nrows() != m.ncols() {
            return Err(invalid(
                "matrix",
                format!("an array of shape {:?}", m.shape()),
                "give a square (3n, 3n) matrix",
            ));
        }
        let flat: Vec<f64> = m.iter().copied().collect();
        let id = self.inner.add_damping_matrix(&ids, &flat).map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// The water's loads on a rigid body from its submerged volume (see the stub).
    #[pyo3(signature = (body, hull, *, origin=None, axis=None, density=1025.0, ca=0.0, cd=0.0, drag_area=0.0, added_mass=None, layers=40))]
    #[allow(clippy::too_many_arguments)]
    fn add_floating_body(
        &mut self,
        body: &Bound<'_, PyAny>,
        hull: &Bound<'_, PyAny>,
        origin: Option<&Bound<'_, PyAny>>,
        axis: Option<&Bound<'_, PyAny>>,
        density: f64,
        ca: f64,
        cd: f64,
        drag_area: f64,
        added_mass: Option<f64>,
        layers: usize,
    ) -> PyResult<PyForceId> {
        let frame = self.frame(Some(body), "body")?;
        let centre = match body.cast::<PyDict>() {
            Ok(d) => match d.get_item("centre")? {
                Some(c) => c.extract::<PyRef<'_, PyParticleId>>().ok().map(|c| c.inner),
                None => None,
            },
            Err(_) => None,
        };
        let hull = crate::water::hull(hull)?;
        let origin = match origin {
            Some(o) => vec3(o, "origin")?,
            None => match centre {
                Some(c) => self.inner.particles()[self.inner.check(c).map_err(to_py)?].position,
                None => {
                    return Err(invalid(
                        "origin",
                        "None",
                        "give the hull's origin (m) for a body without a centre particle",
                    ))
                }
            },
        };
        let spec = vinculo::model::FloatingSpec {
            origin,
            axis: axis
                .map(|a| vec3(a, "axis"))
                .transpose()?
                .unwrap_or([0.0, 0.0, 1.0]),
            density,
            ca,
            cd,
            drag_area,
            added_mass,
            layers,
        };
        let id = self
            .inner
            .add_floating_body(&frame, centre, &hull, &spec)
            .map_err(to_py)?;
        Ok(PyForceId { index: id.0 })
    }

    /// Puts the line elements and floating bodies (those added before and after) in `water`
    /// (a `vinculo._core.Water`, made by `vinculo.ocean.Sea`): its current, waves and surface.
    fn set_water(&mut self, water: PyRef<'_, crate::water::PyWater>) {
        self.inner.set_water(water.inner.clone());
    }

    /// Forces computed by one Python function for a whole group of elements at once.
    ///
    /// `particles`: (k,) integer array (one particle per element) or (k, a) (a particles per
    /// element, any a) of particle indices. `force(t, q, v)` gets the elements' positions and
    /// velocities, (k, 3) or (k, a, 3), and returns the forces on those particles in the same shape; element i's
    /// result may depend only on t and row i. It is called once per residual evaluation.
    /// `jacobian(t, q, v)` returns (df_dq, df_dv), each (k, 3a, 3a) (a the arity; row 3p + l:
    /// component l of the force on particle p, column 3r + m: coordinate m of particle r);
    /// None: forward differences over the group (6a force calls per Jacobian). Returns a
    /// `UserGroup` (calls and seconds of the last run). During a run, an exception stops it with
    /// `UserFunctionError` (the exception chained), a wrong shape or NaN with
    /// `UserFunctionOutputError`. Bad particles or a non-callable raise `InvalidInputError`,
    /// an index out of range `UnknownHandleError`.
    #[pyo3(signature = (particles, force, jacobian=None, name=None))]
    fn add_force_group(
        &mut self,
        particles: &Bound<'_, PyAny>,
        force: &Bound<'_, PyAny>,
        jacobian: Option<&Bound<'_, PyAny>>,
        name: Option<String>,
    ) -> PyResult<crate::user_physics::PyUserGroup> {
        use crate::user_physics as up;
        let elements = up::elements(particles)?;
        let arity = elements.arity();
        let force = up::callable("force", Some(force))?
            .ok_or_else(|| invalid("force", "None", "expected a function force(t, q, v)"))?;
        let jacobian = up::callable("jacobian", jacobian)?;
        let functions = up::force_functions(
            elements.len(),
            arity,
            self.user_errors.clone(),
            force,
            jacobian,
        );
        let group = self
            .inner
            .add_user_force_group(elements, Box::new(functions), name)
            .map_err(to_py)?;
        Ok(up::PyUserGroup::force(group, self.user_errors.clone()))
    }

    /// Constraint equations Phi_i(q, t) = 0, one per element, computed by Python functions for
    /// a whole group of elements at once.
    ///
    /// `particles` as for `add_force_group`. `phi(t, q)` returns the k residuals. Optional
    /// (finite differences over the group when None): `gradient(t, q)` (k, a, 3),
    /// `hessian(t, q)` (k, 3a, 3a), `phi_t(t, q)` (k,), `gamma(t, q, v)` (k,), gamma being
    /// Phi'' - Phi_q q''. `scale`: s such that s Phi is a length (default 1). The group's
    /// equations are `UserGroup.constraint_indices` (columns of Solution.multipliers). Errors as
    /// for `add_force_group`; a scale that is not finite and positive, or an element touching
    /// only fixed particles, raises `InvalidInputError`.
    #[pyo3(signature = (particles, phi, gradient=None, hessian=None, phi_t=None, gamma=None, scale=None, name=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_constraint_group(
        &mut self,
        particles: &Bound<'_, PyAny>,
        phi: &Bound<'_, PyAny>,
        gradient: Option<&Bound<'_, PyAny>>,
        hessian: Option<&Bound<'_, PyAny>>,
        phi_t: Option<&Bound<'_, PyAny>>,
        gamma: Option<&Bound<'_, PyAny>>,
        scale: Option<f64>,
        name: Option<String>,
    ) -> PyResult<crate::user_physics::PyUserGroup> {
        use crate::user_physics as up;
        let elements = up::elements(particles)?;
        let arity = elements.arity();
        let phi = up::callable("phi", Some(phi))?
            .ok_or_else(|| invalid("phi", "None", "expected a function phi(t, q)"))?;
        let functions = [
            Some(phi),
            up::callable("gradient", gradient)?,
            up::callable("hessian", hessian)?,
            up::callable("phi_t", phi_t)?,
            up::callable("gamma", gamma)?,
        ];
        let functions =
            up::constraint_functions(elements.len(), arity, self.user_errors.clone(), functions);
        let (group, first) = self
            .inner
            .add_user_constraint_group(elements, Box::new(functions), scale.unwrap_or(1.0), name)
            .map_err(to_py)?;
        Ok(up::PyUserGroup::constraint(
            group,
            first,
            self.user_errors.clone(),
        ))
    }

    /// Lets an elastic segment go slack instead of pushing (see the stub).
    fn set_slack(&mut self, constraint: &Bound<'_, PyAny>) -> PyResult<()> {
        let c = constraint_id(constraint, "System.add_elastic_distance")?;
        self.inner.set_slack(c).map_err(to_py)
    }

    /// Gives an elastic segment internal axial damping (N s/m; see the stub).
    fn set_axial_damping(&mut self, constraint: &Bound<'_, PyAny>, damping: f64) -> PyResult<()> {
        let c = constraint_id(constraint, "System.add_elastic_distance")?;
        self.inner.set_axial_damping(c, damping).map_err(to_py)
    }

    /// Gives an elastic segment a tension-strain curve (MoorDyn's nonlinear EA; see the stub).
    fn set_strain_curve(
        &mut self,
        constraint: &Bound<'_, PyAny>,
        strains: Vec<f64>,
        tensions: Vec<f64>,
    ) -> PyResult<()> {
        let c = constraint_id(constraint, "System.add_elastic_distance")?;
        let curve = vinculo::constraints::StrainCurve::new(strains, tensions).map_err(to_py)?;
        self.inner
            .set_strain_curve(c, std::sync::Arc::new(curve))
            .map_err(to_py)
    }

    /// Declares a distance constraint a string: a run stops with NegativeTensionError when it
    /// would have to push.
    fn set_tension_only(&mut self, constraint: &Bound<'_, PyAny>) -> PyResult<()> {
        let c = constraint_id(constraint, "System.add_distance or add_distance_to_point")?;
        self.inner.set_tension_only(c).map_err(to_py)
    }

    /// Lengths of the constraints (m; NaN for constraints that are not distances).
    #[getter]
    fn constraint_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = (0..self.inner.constraints().len())
            .map(|c| {
                let con = &self.inner.constraints()[c];
                if con.is_distance() {
                    con.length()
                } else {
                    f64::NAN
                }
            })
            .collect();
        Array1::from(v).into_pyarray(py)
    }

    /// Inertia of each particle's translation (kg): mass plus added mass of fluid elements (a
    /// line node's normal added mass; the step problems correct it along the line to CaAx).
    #[getter]
    fn inertia<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.inner.inertia()).into_pyarray(py)
    }

    /// Number of particles.
    #[getter]
    fn num_particles(&self) -> usize {
        self.inner.particles().len()
    }

    /// Number of constraint equations (length of the multiplier vector).
    #[getter]
    fn num_constraints(&self) -> usize {
        self.inner.constraints().len()
    }

    /// Gravity vector.
    #[getter]
    fn gravity(&self) -> (f64, f64, f64) {
        let g = self.inner.gravity();
        (g[0], g[1], g[2])
    }

    /// Handles of all particles, in order.
    fn particles(&self) -> PyResult<Vec<PyParticleId>> {
        (0..self.inner.particles().len())
            .map(|i| {
                Ok(PyParticleId {
                    inner: self.inner.particle_id(i).map_err(to_py)?,
                })
            })
            .collect()
    }

    /// Masses (n,).
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.particles().iter().map(|p| p.mass)).into_pyarray(py)
    }

    /// Which particles are fixed (n,).
    fn fixed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        Array1::from_iter(self.inner.particles().iter().map(|p| p.fixed)).into_pyarray(py)
    }

    /// The force each of the force elements `forces` (handles or indices) exerts on the
    /// particles it acts on, at each of the states `positions` and `velocities` (m, n, 3) at
    /// `times` (m,): an (m, k, 3) array (see the stub).
    fn element_forces<'py>(
        &self,
        py: Python<'py>,
        forces: Vec<Bound<'py, PyAny>>,
        positions: numpy::PyReadonlyArray3<'py, f64>,
        velocities: numpy::PyReadonlyArray3<'py, f64>,
        times: numpy::PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
        let (q, v, t) = (
            positions.as_array(),
            velocities.as_array(),
            times.as_array(),
        );
        let n = self.inner.particles().len();
        if q.shape() != [t.len(), n, 3] || v.shape() != q.shape() {
            return Err(invalid(
                "positions and velocities",
                format!(
                    "shapes {:?} and {:?} for {} times",
                    q.shape(),
                    v.shape(),
                    t.len()
                ),
                &format!("give (times, {n}, 3) arrays of this system's states"),
            ));
        }
        let indices = forces
            .iter()
            .map(|f| match f.extract::<PyRef<'_, PyForceId>>() {
                Ok(id) => Ok(id.index),
                Err(_) => f.extract::<usize>().map_err(|_| {
                    invalid("forces", f.to_string(), "give ForceIds or force indices")
                }),
            })
            .collect::<PyResult<Vec<usize>>>()?;
        let mut out = numpy::ndarray::Array3::<f64>::zeros((t.len(), indices.len(), 3));
        let row = |a: &numpy::ndarray::ArrayView3<'_, f64>, j: usize| -> Vec<[f64; 3]> {
            (0..n)
                .map(|i| [a[[j, i, 0]], a[[j, i, 1]], a[[j, i, 2]]])
                .collect()
        };
        for j in 0..t.len() {
            let (qj, vj) = (row(&q, j), row(&v, j));
            for (k, &f) in indices.iter().enumerate() {
                let value = self.inner.element_force(f, &qj, &vj, t[j]).map_err(to_py)?;
                for c in 0..3 {
                    out[[j, k, c]] = value[c];
                }
            }
        }
        Ok(out.into_pyarray(py))
    }

    /// Initial positions (n, 3).
    fn initial_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        positions_array(py, &self.inner.initial_positions())
    }

    /// Initial velocities (n, 3).
    fn initial_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        positions_array(py, &self.inner.initial_velocities())
    }

    /// One readable name per constraint equation.
    fn constraint_names(&self) -> Vec<String> {
        self.inner.constraint_names()
    }

    /// Per equation, s_k such that s_k Phi_k is a length.
    fn constraint_scales<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from_iter(self.inner.constraints().iter().map(|c| c.scale())).into_pyarray(py)
    }

    /// Characteristic length of the model (tolerances are relative to it).
    fn length_scale(&self) -> f64 {
        self.inner.length_scale()
    }

    /// Phi(q, t) per equation for (n, 3) positions.
    #[pyo3(signature = (positions, t=0.0))]
    fn constraint_residual<'py>(
        &self,
        py: Python<'py>,
        positions: PyReadonlyArrayDyn<'py, f64>,
        t: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        crate::reentry::refuse_reentry(py, &self.user_errors, "System.constraint_residual")?;
        let (outer, frames) = self.frames(&positions, "positions")?;
        if !outer.is_empty() {
            return Err(invalid(
                "positions",
                format!("array with {} leading dimensions", outer.len()),
                "expected a single (n, 3) frame",
            ));
        }
        Ok(Array1::from(self.inner.constraint_residual(&frames[0], t)).into_pyarray(py))
    }

    /// Kinetic energy of (..., n, 3) velocities.
    fn kinetic_energy<'py>(
        &self,
        py: Python<'py>,
        velocities: PyReadonlyArrayDyn<'py, f64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (outer, frames) = self.frames(&velocities, "velocities")?;
        let e: Vec<f64> = frames
            .iter()
            .map(|v| self.inner.kinetic_energy(v))
            .collect();
        Ok(numpy::ndarray::ArrayD::from_shape_vec(outer, e)
            .expect("shape")
            .into_pyarray(py))
    }

    /// Potential energy (gravity and springs) of (..., n, 3) positions.
    fn potential_energy<'py>(
        &self,
        py: Python<'py>,
        positions: PyReadonlyArrayDyn<'py, f64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (outer, frames) = self.frames(&positions, "positions")?;
        let e: Vec<f64> = frames
            .iter()
            .map(|q| self.inner.potential_energy(q))
            .collect();
        Ok(numpy::ndarray::ArrayD::from_shape_vec(outer, e)
            .expect("shape")
            .into_pyarray(py))
    }

    /// Sets the initial positions (n, 3) and velocities (n, 3; None: at rest) of every particle,
    /// fixed ones included (a static equilibrium as the start of a run).
    #[pyo3(signature = (positions, velocities=None))]
    fn set_initial_state(
        &mut self,
        positions: PyReadonlyArrayDyn<'_, f64>,
        velocities: Option<PyReadonlyArrayDyn<'_, f64>>,
    ) -> PyResult<()> {
        let (outer, q) = self.frames(&positions, "positions")?;
        if !outer.is_empty() {
            return Err(invalid(
                "positions",
                format!("{outer:?} frames"),
                "expected one (n, 3) array",
            ));
        }
        let v = match velocities {
            Some(v) => {
                let (outer, v) = self.frames(&v, "velocities")?;
                if !outer.is_empty() {
                    return Err(invalid(
                        "velocities",
                        format!("{outer:?} frames"),
                        "expected one (n, 3) array",
                    ));
                }
                v.into_iter().next().unwrap_or_default()
            }
            None => vec![[0.0; 3]; self.inner.particles().len()],
        };
        let q = q.into_iter().next().unwrap_or_default();
        if q.iter().chain(&v).any(|x| x.iter().any(|c| !c.is_finite())) {
            return Err(invalid(
                "initial state",
                "non-finite values",
                "give finite positions and velocities",
            ));
        }
        self.inner.set_initial_state(&q, &v);
        Ok(())
    }

    /// Moves the initial state onto the position and velocity constraints with the least
    /// mass-weighted change; returns how far it moved.
    #[pyo3(signature = (tolerance=1e-12, max_iterations=50, t=0.0))]
    fn project_initial_state<'py>(
        &mut self,
        py: Python<'py>,
        tolerance: f64,
        max_iterations: usize,
        t: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        crate::reentry::refuse_reentry(py, &self.user_errors, "System.project_initial_state")?;
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(invalid("tolerance", tolerance, "must be finite and > 0"));
        }
        let system = &mut self.inner;
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            vinculo::initial::project_initial_state(system, t, tolerance, max_iterations)
        }))
        .map_err(crate::errors::internal)?;
        let r = result.map_err(to_py)?;
        let d = PyDict::new(py);
        d.set_item("position_change", r.position_change)?;
        d.set_item("velocity_change", r.velocity_change)?;
        d.set_item("iterations", r.iterations)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "System({} particles, {} constraints, {} forces, gravity={:?})",
            self.inner.particles().len(),
            self.inner.constraints().len(),
            self.inner.forces().len(),
            self.inner.gravity()
        )
    }
}
