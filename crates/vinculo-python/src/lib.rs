//! `vinculo._core`: PyO3 glue between the Rust core and the Python package. Conversions,
//! exceptions and thin wrappers only; the physics lives in the `vinculo` crate.

mod errors;
mod laws;
mod points;
mod reentry;
mod run;
mod run_result;
mod seabed;
mod statics;
mod stepping;
mod system;
mod user_physics;
mod water;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<laws::PyLaw>()?;
    m.add_class::<system::PySystem>()?;
    m.add_class::<system::PyParticleId>()?;
    m.add_class::<points::PyPoint>()?;
    m.add_class::<system::PyConstraintId>()?;
    m.add_class::<system::PyForceId>()?;
    m.add_class::<user_physics::PyUserGroup>()?;
    m.add_class::<stepping::PySimulation>()?;
    m.add_class::<stepping::PySnapshot>()?;
    m.add_class::<run::PyRunSettings>()?;
    m.add_class::<run_result::PyRunResult>()?;
    m.add_class::<water::PyWater>()?;
    m.add_class::<seabed::PySeabedGrid>()?;
    m.add_function(wrap_pyfunction!(run::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(run::time_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(statics::solve_statics, m)?)?;
    m.add_function(wrap_pyfunction!(statics::point_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(statics::points_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(statics::point_force, m)?)?;
    Ok(())
}
