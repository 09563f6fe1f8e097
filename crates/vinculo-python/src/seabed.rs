//! `SeabedGrid`: a seabed of varying height for line nodes' seabed contact, built from the
//! ticks and heights of a grid (by `vinculo.mooring.Seafloor`) and shared by every node.

use crate::errors::{invalid, to_py};
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use std::sync::Arc;
use vinculo::forces::SeabedGrid;

/// Heights of the seabed on a grid of x and y ticks (m), bilinear in each cell and held at the
/// edge's height beyond it.
#[pyclass(name = "SeabedGrid", module = "vinculo._core", frozen)]
pub struct PySeabedGrid {
    pub inner: Arc<SeabedGrid>,
}

#[pymethods]
impl PySeabedGrid {
    /// `x` (nx) and `y` (ny) strictly increasing ticks, `z` (nx, ny) heights (m).
    #[new]
    fn new(
        x: PyReadonlyArray1<'_, f64>,
        y: PyReadonlyArray1<'_, f64>,
        z: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<Self> {
        let (x, y, z) = (x.as_array(), y.as_array(), z.as_array());
        if z.shape() != [x.len(), y.len()] {
            return Err(invalid(
                "seabed grid heights",
                format!("an array of shape {:?}", z.shape()),
                &format!(
                    "give ({}, {}) heights, one a pair of ticks",
                    x.len(),
                    y.len()
                ),
            ));
        }
        let heights = z.iter().copied().collect();
        let grid = SeabedGrid::new(x.to_vec(), y.to_vec(), heights).map_err(to_py)?;
        Ok(PySeabedGrid {
            inner: Arc::new(grid),
        })
    }

    /// The height z_b at (x, y) and its slopes dz_b/dx, dz_b/dy.
    fn height_and_slope(&self, x: f64, y: f64) -> (f64, f64, f64) {
        self.inner.height_and_slope(x, y)
    }

    /// The heights at the points (x[k], y[k]).
    fn heights_at(&self, x: Vec<f64>, y: Vec<f64>) -> PyResult<Vec<f64>> {
        if x.len() != y.len() {
            return Err(invalid(
                "points",
                format!("{} x and {} y coordinates", x.len(), y.len()),
                "give as many of each",
            ));
        }
        Ok(x.iter()
            .zip(&y)
            .map(|(&a, &b)| self.inner.height(a, b))
            .collect())
    }
}
