//! `Water`: the core's water (current, linear waves, free surface), built from arrays by
//! `vinculo.ocean.Sea`, evaluated at many points at once, and given to a `System`.

use crate::errors::{invalid, to_py};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vinculo::water::{Current, Stretching, Water, WaveSpec};

/// The water of the core (build it with `vinculo.ocean.Sea`).
#[pyclass(name = "Water", module = "vinculo._core", frozen)]
pub struct PyWater {
    pub inner: Water,
}

fn stretching(name: &str) -> PyResult<Stretching> {
    match name {
        "wheeler" => Ok(Stretching::Wheeler),
        "vertical" => Ok(Stretching::Vertical),
        other => Err(invalid(
            "stretching",
            format!("{other:?}"),
            "give \"wheeler\" or \"vertical\"",
        )),
    }
}

fn current(
    kind: &str,
    velocity: PyReadonlyArray2<'_, f64>,
    heights: PyReadonlyArray1<'_, f64>,
    exponent: f64,
    depth: f64,
) -> PyResult<Current> {
    let rows = velocity.as_array();
    if rows.ncols() != 3 || rows.nrows() == 0 {
        return Err(invalid(
            "current velocity",
            format!("an array of shape {:?}", rows.shape()),
            "give (n, 3) velocities",
        ));
    }
    let vectors: Vec<[f64; 3]> = rows.outer_iter().map(|r| [r[0], r[1], r[2]]).collect();
    match kind {
        "uniform" => Ok(Current::Uniform(vectors[0])),
        "power" => Ok(Current::PowerLaw {
            surface: vectors[0],
            exponent,
            depth,
        }),
        "table" => Ok(Current::Table {
            z: heights.as_array().to_vec(),
            velocity: vectors,
        }),
        other => Err(invalid(
            "current kind",
            format!("{other:?}"),
            "give \"uniform\", \"power\" or \"table\"",
        )),
    }
}

#[pymethods]
impl PyWater {
    /// Water of depth `depth` (inf: deep) under gravity `g`: wave components (amplitude m,
    /// angular frequency rad/s, direction rad, phase rad: arrays of one length), a current
    /// (`current_kind` "uniform" | "power" | "table" with (n, 3) velocities, the table's
    /// heights, the power law's exponent), the stretching above the still-water level, and
    /// whether the water has a free surface at z = eta (False: it fills all space).
    #[new]
    #[pyo3(signature = (depth, g, amplitudes, omegas, directions, phases, current_kind, current_velocity, current_heights, current_exponent, stretching_name, free_surface, ramp=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        depth: f64,
        g: f64,
        amplitudes: PyReadonlyArray1<'_, f64>,
        omegas: PyReadonlyArray1<'_, f64>,
        directions: PyReadonlyArray1<'_, f64>,
        phases: PyReadonlyArray1<'_, f64>,
        current_kind: &str,
        current_velocity: PyReadonlyArray2<'_, f64>,
        current_heights: PyReadonlyArray1<'_, f64>,
        current_exponent: f64,
        stretching_name: &str,
        free_surface: bool,
        ramp: f64,
    ) -> PyResult<Self> {
        let (a, w, d, p) = (
            amplitudes.as_array(),
            omegas.as_array(),
            directions.as_array(),
            phases.as_array(),
        );
        if w.len() != a.len() || d.len() != a.len() || p.len() != a.len() {
            return Err(invalid(
                "wave components",
                format!(
                    "{} amplitudes, {} frequencies, {} directions, {} phases",
                    a.len(),
                    w.len(),
                    d.len(),
                    p.len()
                ),
                "give one of each per component",
            ));
        }
        let waves: Vec<WaveSpec> = (0..a.len())
            .map(|i| WaveSpec {
                amplitude: a[i],
                omega: w[i],
                direction: d[i],
                phase: p[i],
            })
            .collect();
        let current = current(
            current_kind,
            current_velocity,
            current_heights,
            current_exponent,
            depth,
        )?;
        let mut inner =
            Water::new(depth, g, current, &waves, stretching(stretching_name)?).map_err(to_py)?;
        inner.free_surface = free_surface;
        inner.ramp = vinculo::error::non_negative("ramp time of the waves", ramp).map_err(to_py)?;
        Ok(PyWater { inner })
    }

    /// The wave numbers k of the components (rad/m).
    #[getter]
    fn wave_numbers<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let k: Vec<f64> = self.inner.waves.iter().map(|c| c.k).collect();
        PyArray1::from_vec(py, k)
    }

    /// The flow at `points` ((n, 3), m) at time `t` (s): a dict of velocity (n, 3),
    /// acceleration (n, 3), pressure (n,: the waves' dynamic pressure over the density),
    /// elevation (n,: eta above each point), velocity_gradient (n, 3, 3) when `gradients`.
    #[pyo3(signature = (points, t, gradients=false))]
    fn flow<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'_, f64>,
        t: f64,
        gradients: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let x = points.as_array();
        if x.ncols() != 3 {
            return Err(invalid(
                "points",
                format!("an array of shape {:?}", x.shape()),
                "give (n, 3) positions",
            ));
        }
        let n = x.nrows();
        let flows: Vec<_> = py.detach(|| {
            (0..n)
                .map(|i| {
                    self.inner
                        .flow([x[[i, 0]], x[[i, 1]], x[[i, 2]]], t, gradients)
                })
                .collect()
        });
        let rows = |f: &dyn Fn(&vinculo::water::Flow) -> [f64; 3]| {
            let mut a = Array2::<f64>::zeros((n, 3));
            for (i, fl) in flows.iter().enumerate() {
                for (k, v) in f(fl).into_iter().enumerate() {
                    a[[i, k]] = v;
                }
            }
            a
        };
        let out = PyDict::new(py);
        out.set_item("velocity", rows(&|f| f.velocity).into_pyarray(py))?;
        out.set_item("acceleration", rows(&|f| f.acceleration).into_pyarray(py))?;
        let scalars = |f: &dyn Fn(&vinculo::water::Flow) -> f64| {
            Array1::from_iter(flows.iter().map(f)).into_pyarray(py)
        };
        out.set_item("pressure", scalars(&|f| f.pressure))?;
        out.set_item("elevation", scalars(&|f| f.elevation))?;
        if gradients {
            let flat: Vec<f64> = flows
                .iter()
                .flat_map(|f| f.velocity_gradient.into_iter().flatten())
                .collect();
            let array =
                numpy::ndarray::Array3::from_shape_vec((n, 3, 3), flat).expect("n 3x3 gradients");
            out.set_item("velocity_gradient", array.into_pyarray(py))?;
        }
        Ok(out)
    }

    /// The elevation eta at horizontal positions `xy` ((n, 2), m) at times `t` ((m,), s):
    /// an (m, n) array.
    fn elevation<'py>(
        &self,
        py: Python<'py>,
        xy: PyReadonlyArray2<'_, f64>,
        t: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (xy, t) = (xy.as_array(), t.as_array());
        if xy.ncols() != 2 {
            return Err(invalid(
                "xy",
                format!("an array of shape {:?}", xy.shape()),
                "give (n, 2) horizontal positions",
            ));
        }
        let mut out = Array2::<f64>::zeros((t.len(), xy.nrows()));
        py.detach(|| {
            for (j, &tj) in t.iter().enumerate() {
                for i in 0..xy.nrows() {
                    out[[j, i]] = self.inner.surface(xy[[i, 0]], xy[[i, 1]], tj).0;
                }
            }
        });
        Ok(out.into_pyarray(py))
    }
}

/// A hull from `vinculo.ocean.Hull.sections()`: a list of ("frustum", bottom, top, r_bottom,
/// r_top) and ("sphere", centre, radius) tuples.
pub fn hull(obj: &Bound<'_, PyAny>) -> PyResult<vinculo::model::Hull> {
    let sections = obj.call_method0("sections").unwrap_or_else(|_| obj.clone());
    let items: Vec<Bound<'_, PyAny>> = sections.extract().map_err(|_| {
        invalid(
            "hull",
            obj.repr().map(|r| r.to_string()).unwrap_or_default(),
            "give a vinculo.ocean.Hull",
        )
    })?;
    let mut out = Vec::with_capacity(items.len());
    for item in items {
        let bad = || {
            invalid(
                "hull section",
                item.repr().map(|r| r.to_string()).unwrap_or_default(),
                "give (\"frustum\", bottom, top, r_bottom, r_top) or (\"sphere\", centre, radius)",
            )
        };
        let kind: String = item
            .get_item(0)
            .and_then(|k| k.extract())
            .map_err(|_| bad())?;
        let number = |i: usize| -> PyResult<f64> {
            item.get_item(i)
                .and_then(|k| k.extract())
                .map_err(|_| bad())
        };
        out.push(match kind.as_str() {
            "frustum" => vinculo::model::HullSection::Frustum {
                bottom: number(1)?,
                top: number(2)?,
                r_bottom: number(3)?,
                r_top: number(4)?,
            },
            "sphere" => vinculo::model::HullSection::Sphere {
                centre: number(1)?,
                radius: number(2)?,
            },
            _ => return Err(bad()),
        });
    }
    Ok(vinculo::model::Hull { sections: out })
}
