//! The memory a run's stored output ([`crate::Solution`]) takes: estimated before the run starts
//! and watched while it runs, against [`SimulationOptions::max_output_bytes`] (by default a third
//! of the memory available), so that a run whose output would not fit is
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
//! once when handed to a caller such as the Python package. It is read once, when the output
//! could first exceed [`UNCHECKED_BYTES`] (16 MiB): before the run for a run of fixed steps, when
//! its output reaches that size for an error-controlled one; a smaller output is not checked.
//! Where the memory available cannot be read (not Linux) there is no default limit.

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

/// Outputs up to this size (bytes) are not checked against the memory available: reading it
/// (`/proc/meminfo`) takes some 15 us, 0.6 % of a 10^4-step pendulum run, and 16 MiB is a third
/// of the memory available on any machine with 48 MiB to spare.
pub(crate) const UNCHECKED_BYTES: f64 = 16.0 * 1024.0 * 1024.0;

/// The largest output a run may store: `max_output_bytes`, or by default a third of the memory
/// available, read once, when the output could first exceed [`UNCHECKED_BYTES`].
#[derive(Debug, Clone)]
pub(crate) enum OutputLimit {
    /// `max_output_bytes` (bytes).
    Given(f64),
    /// `MemAvailable` (bytes) once read (`Some(None)` where it cannot be read: no limit).
    Memory(Option<Option<f64>>),
}

impl OutputLimit {
    /// The limit of a run with options `o` (checks `max_output_bytes`).
    pub(crate) fn of(o: &SimulationOptions) -> Result<OutputLimit> {
        match o.max_output_bytes {
            Some(bytes) if bytes.is_nan() || bytes <= 0.0 => Err(Error::InvalidParameter {
                name: "max_output_bytes".into(),
                value: bytes,
                expected: "must be > 0 (bytes), or None for a third of the memory available".into(),
            }),
            Some(bytes) => Ok(OutputLimit::Given(bytes)),
            None => Ok(OutputLimit::Memory(None)),
        }
    }

    /// The limit (bytes) for an output of `bytes` (None: the output is not checked, or no limit
    /// is known).
    #[inline]
    fn limit_for(&mut self, bytes: f64) -> Option<f64> {
        match self {
            OutputLimit::Given(limit) => Some(*limit),
            OutputLimit::Memory(_) if bytes <= UNCHECKED_BYTES => None,
            OutputLimit::Memory(read) => {
                let available = (*read.get_or_insert_with(memory_available))?;
                Some(available / 3.0)
            }
        }
    }

    /// Where the limit comes from, for the error's message.
    fn source(&self) -> String {
        match self {
            OutputLimit::Given(_) => "max_output_bytes".into(),
            OutputLimit::Memory(read) => format!(
                "a third of the {:.3} GB of memory available, MemAvailable of /proc/meminfo; the \
                 arrays grow by doubling and are copied once when returned",
                read.flatten().unwrap_or(f64::NAN) / 1e9
            ),
        }
    }

    /// The error of an output of `states` stored states and `steps` step sizes that exceeds the
    /// limit (None: it fits); `t`: where the run stopped (None: before it started).
    #[inline]
    pub(crate) fn exceeded(
        &mut self,
        system: &System,
        o: &SimulationOptions,
        states: f64,
        steps: f64,
        t: Option<f64>,
    ) -> Option<Error> {
        let per_state = state_bytes(system.particles().len(), system.constraints().len());
        let bytes = states * per_state as f64 + steps * STEP_BYTES;
        let limit = self.limit_for(bytes)?;
        (bytes > limit).then(|| Error::OutputTooLarge {
            t,
            states,
            state_bytes: per_state,
            steps,
            bytes,
            limit,
            limit_source: self.source(),
            save_every: o.save_every,
        })
    }

    /// The error of a run whose output would exceed the limit before it starts (None: it fits,
    /// or its size cannot be told beforehand): the estimate of the module documentation, a lower
    /// bound for error-controlled steps.
    pub(crate) fn refused(&mut self, system: &System, o: &SimulationOptions) -> Option<Error> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The default limit reads the memory available only for an output that could exceed
    /// [`UNCHECKED_BYTES`], and then once; `max_output_bytes` is compared as given.
    #[test]
    fn the_memory_available_is_read_only_for_outputs_that_could_exceed_16_mib() {
        let mut limit = OutputLimit::Memory(None);
        assert!(limit.limit_for(UNCHECKED_BYTES).is_none());
        assert!(matches!(limit, OutputLimit::Memory(None)), "{limit:?}");
        let read = limit.limit_for(2.0 * UNCHECKED_BYTES);
        let OutputLimit::Memory(Some(available)) = limit else {
            panic!("not read: {limit:?}");
        };
        // Where /proc/meminfo can be read, the limit is a third of what it says.
        assert_eq!(read, available.map(|a| a / 3.0));
        let mut given = OutputLimit::Given(10.0);
        assert_eq!(given.limit_for(1.0), Some(10.0));
    }
}
