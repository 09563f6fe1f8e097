//! The static equilibrium and the linearised stiffness at a point (`vinculo::statics`), for
//! `vinculo.mooring.statics`.

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use vinculo::statics::{self, Statics, StaticsMethod, StaticsOptions};

use crate::errors::to_py;
use crate::system::PySystem;

/// The arrays of an equilibrium: (positions (n, 3), multipliers (m,), residual, iterations,
/// method name).
type StaticsTuple<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    f64,
    usize,
    &'static str,
);

/// Solves the static equilibrium of `system` at time `t` from its initial positions.
#[pyfunction]
#[pyo3(signature = (system, tolerance=1e-9, max_iterations=1000, t=0.0, newton_first=true))]
pub fn solve_statics<'py>(
    py: Python<'py>,
    system: Bound<'py, PySystem>,
    tolerance: f64,
    max_iterations: usize,
    t: f64,
    newton_first: bool,
) -> PyResult<StaticsTuple<'py>> {
    let this = system.borrow();
    let model = &this.inner;
    let options = StaticsOptions {
        tolerance,
        max_iterations,
        t,
        newton_first,
    };
    let st = py
        .detach(|| statics::solve_statics(model, &options))
        .map_err(to_py)?;
    let flat: Vec<f64> = st.positions.iter().flatten().copied().collect();
    let positions = PyArray1::from_vec(py, flat).reshape([st.positions.len(), 3])?;
    Ok((
        positions,
        PyArray1::from_vec(py, st.multipliers),
        st.residual,
        st.iterations,
        st.method.name(),
    ))
}

/// The equilibrium given by its arrays.
fn equilibrium(
    positions: PyReadonlyArray2<'_, f64>,
    multipliers: PyReadonlyArray1<'_, f64>,
    t: f64,
) -> PyResult<Statics> {
    let p = positions.as_array();
    if p.ncols() != 3 {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "positions must have shape (particles, 3), not {:?}",
            p.shape()
        )));
    }
    Ok(Statics {
        positions: p.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect(),
        multipliers: multipliers.as_array().to_vec(),
        residual: 0.0,
        iterations: 0,
        method: StaticsMethod::Newton,
        t,
    })
}

/// Checks the equilibrium's sizes against the system's.
fn check_sizes(system: &vinculo::model::System, st: &Statics) -> PyResult<()> {
    let (n, m) = (system.particles().len(), system.constraints().len());
    if st.positions.len() != n || st.multipliers.len() != m {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "the equilibrium has {} positions and {} multipliers; the system has {n} particles \
             and {m} constraints: solve the statics of this system",
            st.positions.len(),
            st.multipliers.len()
        )));
    }
    Ok(())
}

/// The system and its equilibrium from the arrays, their sizes checked against each other.
fn system_in_equilibrium<'py>(
    system: &'py Bound<'py, PySystem>,
    positions: PyReadonlyArray2<'py, f64>,
    multipliers: PyReadonlyArray1<'py, f64>,
    t: f64,
) -> PyResult<(PyRef<'py, PySystem>, Statics)> {
    let st = equilibrium(positions, multipliers, t)?;
    let this = system.borrow();
    check_sizes(&this.inner, &st)?;
    Ok((this, st))
}

/// The 3x3 linearised stiffness K = -dF/dx (N/m) at `particle` in an equilibrium.
#[pyfunction]
#[pyo3(signature = (system, positions, multipliers, particle, t=0.0))]
pub fn point_stiffness<'py>(
    py: Python<'py>,
    system: Bound<'py, PySystem>,
    positions: PyReadonlyArray2<'py, f64>,
    multipliers: PyReadonlyArray1<'py, f64>,
    particle: usize,
    t: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (this, st) = system_in_equilibrium(&system, positions, multipliers, t)?;
    let k = statics::point_stiffness(&this.inner, &st, particle).map_err(to_py)?;
    let flat: Vec<f64> = k.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([3, 3])
}

/// The joint 3n x 3n linearised stiffness (N/m) at the points `particles` in an equilibrium.
#[pyfunction]
#[pyo3(signature = (system, positions, multipliers, particles, t=0.0))]
pub fn points_stiffness<'py>(
    py: Python<'py>,
    system: Bound<'py, PySystem>,
    positions: PyReadonlyArray2<'py, f64>,
    multipliers: PyReadonlyArray1<'py, f64>,
    particles: Vec<usize>,
    t: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (this, st) = system_in_equilibrium(&system, positions, multipliers, t)?;
    let k = statics::points_stiffness(&this.inner, &st, &particles).map_err(to_py)?;
    let n = 3 * particles.len();
    PyArray1::from_vec(py, k).reshape([n, n])
}

/// The force (N) that the system's elements exert on `particle` in an equilibrium.
#[pyfunction]
#[pyo3(signature = (system, positions, multipliers, particle, t=0.0))]
pub fn point_force(
    system: Bound<'_, PySystem>,
    positions: PyReadonlyArray2<'_, f64>,
    multipliers: PyReadonlyArray1<'_, f64>,
    particle: usize,
    t: f64,
) -> PyResult<(f64, f64, f64)> {
    let (this, st) = system_in_equilibrium(&system, positions, multipliers, t)?;
    if particle >= this.inner.particles().len() {
        return Err(pyo3::exceptions::PyIndexError::new_err(format!(
            "particle {particle} is not one of the system's {} particles",
            this.inner.particles().len()
        )));
    }
    let f = statics::point_force(&this.inner, &st, particle);
    Ok((f[0], f[1], f[2]))
}
