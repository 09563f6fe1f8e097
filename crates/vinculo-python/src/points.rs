//! `Point`: a point fixed in a body or in the ground, accepted wherever a particle is; the
//! reading of bodies (a rigid body's dict, a frame of particles, None for the ground) and of
//! particle-or-point arguments.

use crate::errors::{invalid, to_py};
use crate::system::PySystem;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vinculo::model::{OnPointsId, ParticleId, Point, System};

/// A point fixed in a body (an affine combination of its particles) or in the ground.
#[pyclass(name = "Point", module = "vinculo._core", frozen)]
#[derive(Clone)]
pub struct PyPoint {
    pub inner: Point,
    /// The system whose particles it combines (0 for a ground point, valid in any).
    pub system: u64,
}

#[pymethods]
impl PyPoint {
    /// The particles it combines and their weights, as (index, weight) pairs.
    #[getter]
    fn weights(&self) -> Vec<(usize, f64)> {
        self.inner
            .particles
            .iter()
            .copied()
            .zip(self.inner.weights.iter().copied())
            .collect()
    }

    /// Its world position for the positions (n, 3) of every particle.
    fn position(&self, positions: Vec<[f64; 3]>) -> PyResult<(f64, f64, f64)> {
        if let Some(&p) = self.inner.particles.iter().find(|&&p| p >= positions.len()) {
            return Err(invalid(
                "positions",
                format!("{} rows", positions.len()),
                &format!("expected the positions of every particle (the point uses particle {p})"),
            ));
        }
        let x = self.inner.position(&positions);
        Ok((x[0], x[1], x[2]))
    }

    fn __repr__(&self) -> String {
        if self.inner.particles.is_empty() {
            format!("Point(ground at {:?})", self.inner.offset)
        } else {
            format!("Point(of particles {:?})", self.inner.particles)
        }
    }
}

/// A particle or a point argument.
pub enum Target {
    /// A particle.
    Particle(ParticleId),
    /// A point of a body or of the ground.
    Point(Point),
}

impl PySystem {
    /// Reads a ParticleId or a Point of this system.
    pub fn target(&self, obj: &Bound<'_, PyAny>) -> PyResult<Target> {
        if let Ok(point) = obj.cast::<PyPoint>() {
            let point = point.get();
            if point.system != 0 && point.system != self.inner.id() {
                return Err(invalid(
                    "point",
                    point.__repr__(),
                    "belongs to another System (make it with this system's point())",
                ));
            }
            return Ok(Target::Point(point.inner.clone()));
        }
        Ok(Target::Particle(self.particle(obj)?))
    }

    /// Adds with `add` the element over `objs` (ParticleIds or Points): directly when they are
    /// all particles, otherwise over the points (`System::on_points`, named `label`).
    pub fn over<I: OnPointsId>(
        &mut self,
        objs: &[&Bound<'_, PyAny>],
        label: &str,
        add: impl FnOnce(&mut System, &[ParticleId]) -> vinculo::error::Result<I>,
    ) -> PyResult<I> {
        let targets = objs
            .iter()
            .map(|o| self.target(o))
            .collect::<PyResult<Vec<_>>>()?;
        if targets.iter().all(|t| matches!(t, Target::Particle(_))) {
            let ids: Vec<ParticleId> = targets
                .iter()
                .map(|t| match t {
                    Target::Particle(id) => *id,
                    Target::Point(_) => unreachable!(),
                })
                .collect();
            return add(&mut self.inner, &ids).map_err(to_py);
        }
        let points: Vec<Point> = targets
            .into_iter()
            .map(|t| match t {
                Target::Particle(id) => Point::particle(id.index()),
                Target::Point(p) => p,
            })
            .collect();
        // Each element's name adds its own number: "distance over points #12 (particles ...)".
        let label = format!("{label} over points");
        self.inner
            .on_points(&points, &label, add)
            .map(|(id, _)| id)
            .map_err(to_py)
    }

    /// A body argument: a rigid body's dict (its "frame"), a sequence of 3 or 4 ParticleIds,
    /// or None for the ground.
    pub fn frame(&self, body: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Vec<ParticleId>> {
        let Some(body) = body else {
            return Ok(Vec::new());
        };
        let items = if let Ok(d) = body.cast::<PyDict>() {
            d.get_item("frame")?.ok_or_else(|| {
                invalid(what, "a dict without 'frame'", "expected a rigid body (System.add_rigid_body's dict), a frame of 3 or 4 ParticleIds, or None for the ground")
            })?
        } else {
            body.clone()
        };
        let items: Vec<Bound<'_, PyAny>> = items.extract().map_err(|_| {
            invalid(
                what,
                body.repr().map(|r| r.to_string()).unwrap_or_default(),
                "expected a rigid body (System.add_rigid_body's dict), a frame of 3 or 4 ParticleIds, or None for the ground",
            )
        })?;
        items.iter().map(|i| self.particle(i)).collect()
    }

    /// A Point of this system.
    pub fn make_point(&self, inner: Point) -> PyPoint {
        let system = if inner.particles.is_empty() {
            0
        } else {
            self.inner.id()
        };
        PyPoint { inner, system }
    }
}
