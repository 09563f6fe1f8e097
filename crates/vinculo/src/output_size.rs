//! The memory a run's stored output ([`crate::Solution`]) takes: estimated before the run starts
//! and watched while it runs, against [`SimulationOptions::max_output_bytes`] (by default a third
//! of the memory available when the run starts), so that a run whose output would not fit is
//! refused instead of exhausting the machine's memory.
//!
//! A stored state takes [`state_bytes`]: its time, 3 positions and 3 velocities per particle, one
//! multiplier per constraint equation, the two violations and the step's statistics
//! ([`crate::StepStats`]); every accepted step, stored or not, adds its size (8 bytes). A run of
//! fixed steps takes `ceil((t_end - t_start) / dt)` steps (more where Newton halves some) and
//! stores every `save_every`-th state, the first and the last; with output times it stores those.
//! The number of error-controlled steps is known only as it runs (at least
//! `(t_end - t_start) / h_max`): the run stops with the same error when its output reaches the
//! limit, keeping what it stored. The default limit is a third of `MemAvailable`
//! (`/proc/meminfo`): the arrays grow by doubling (up to twice their contents) and are copied
//! once when handed to a caller such as the Python package. Where the memory available cannot be
//! read (not Linux) there is no default limit.

use crate::error::{Error, Result};
use crate::model::System;
use crate::options::SimulationOptions;
use crate::step_control::StepControl;

/// Bytes of a step size stored for every accepted step.
const STEP_BYTES: f64 = 8.0;

/// Bytes one stored state takes for `particles` particles and `constraints` constraint
/// equations: 56 + 48 n + 8 m.
pub fn state_bytes(particles: usize, constraints: usize) -> usize {
    let scalars = 1 + 6 * particles + constraints + 2;
    8 * scalars + std::mem::size_of::<crate::StepStats>()
}

/// The memory available for new allocations without swapping, in bytes (`MemAvailable` of
/// `/proc/meminfo`; None where it cannot be read).
pub fn memory_available() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The largest output a run may store, in bytes, and where that figure comes from (None: no
/// limit is known).
#[derive(Debug, Clone)]
pub(crate) struct OutputLimit {
    pub(crate) bytes: f64,
    pub(crate) source: String,
}

impl OutputLimit {
    /// The limit of a run with options `o` (checks `max_output_bytes`).
    pub(crate) fn of(o: &SimulationOptions) -> Result<Option<OutputLimit>> {
        if let Some(bytes) = o.max_output_bytes {
            if bytes.is_nan() || bytes <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "max_output_bytes".into(),
                    value: bytes,
                    expected: "must be > 0 (bytes), or None for a third of the memory available"
                        .into(),
                });
            }
            return Ok(Some(OutputLimit {
                bytes,
                source: "max_output_bytes".into(),
            }));
        }
        Ok(memory_available().map(|available| OutputLimit {
            bytes: available / 3.0,
            source: format!(
                "a third of the {:.3} GB of memory available, MemAvailable of /proc/meminfo; \
                 the arrays grow by doubling and are copied once when returned",
                available / 1e9
            ),
        }))
    }

    /// The error of an output of `states` stored states and `steps` step sizes that exceeds the
    /// limit (None: it fits); `t`: where the run stopped (None: before it started).
    pub(crate) fn exceeded(
        &self,
        system: &System,
        o: &SimulationOptions,
        states: f64,
        steps: f64,
        t: Option<f64>,
    ) -> Option<Error> {
        let per_state = state_bytes(system.particles().len(), system.constraints().len());
        let bytes = states * per_state as f64 + steps * STEP_BYTES;
        (bytes > self.bytes).then(|| Error::OutputTooLarge {
            t,
            states,
            state_bytes: per_state,
            steps,
            bytes,
            limit: self.bytes,
            limit_source: self.source.clone(),
            save_every: o.save_every,
        })
    }

    /// The error of a run whose output would exceed the limit before it starts (None: it fits,
    /// or its size cannot be told beforehand): the estimate of the module documentation, a lower
    /// bound for error-controlled steps.
    pub(crate) fn refused(&self, system: &System, o: &SimulationOptions) -> Option<Error> {
        let span = o.t_end - o.t_start;
        let steps = match &o.step_control {
            StepControl::Fixed => (span / o.dt).ceil(),
            StepControl::Adaptive(a) if a.h_max.is_finite() => (span / a.h_max).ceil(),
            StepControl::Adaptive(_) => 1.0,
        }
        .max(1.0);
        let states = match &o.output_times {
            Some(times) => times.len() as f64 + 1.0,
            None => (steps / o.save_every as f64).floor() + 2.0,
        };
        self.exceeded(system, o, states, steps, None)
    }
}
