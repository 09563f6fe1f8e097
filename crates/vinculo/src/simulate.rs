//! The entry point: a run from start to end as one call, a thin loop over the stepping object
//! [`Simulation`] (`run.rs`), which validates, starts consistently, marches with step retries and
//! keeps everything computed even when a step fails.

use crate::error::Result;
use crate::model::System;
use crate::run::Simulation;
use crate::solution::Solution;

pub use crate::options::{Observer, SimulationOptions, PARALLEL_FROM};

/// Integrates `system` from `options.t_start` to `options.t_end`.
///
/// Errors in the input are returned as `Err`. A run that stops part-way (Newton failure after
/// every allowed step halving, singular matrix) returns `Ok` with everything computed so far
/// and the cause in [`Solution::status`].
pub fn simulate(system: &System, options: &SimulationOptions) -> Result<Solution> {
    let mut run = Simulation::new(system, options)?;
    run.step_to(options.t_end);
    Ok(run.into_solution())
}

/// [`simulate`] with an observer that sees each step and may stop the run.
pub fn simulate_with_observer(
    system: &System,
    options: &SimulationOptions,
    observer: &mut dyn Observer,
) -> Result<Solution> {
    let mut run = Simulation::new(system, options)?;
    run.step_to_with_observer(options.t_end, observer);
    Ok(run.into_solution())
}
