//! A run stopped by its observer (a keyboard interrupt in the bindings) keeps the state where it
//! stopped, and a run whose stored output would exceed `max_output_bytes` is refused before it
//! starts or, with error-controlled steps, stops when it reaches it, keeping what it stored.
//!
//! References: the uninterrupted run to the same time (the same fixed steps, so bit for bit),
//! the rod's constraint |q| = L of a pendulum, and the byte count of the solution's own arrays.

use vinculo::model::System;
use vinculo::output_size::state_bytes;
use vinculo::{
    simulate, simulate_with_observer, AdaptiveOptions, Error, Observer, SimulationOptions,
    Solution, StepControl,
};

fn pendulum() -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let pivot = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let bob = s
        .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
        .unwrap();
    s.add_distance(pivot, bob, None).unwrap();
    s
}

/// Stops the run after a number of accepted steps.
struct StopAfter(usize);

impl Observer for StopAfter {
    fn step(&mut self, _t: f64, _t_end: f64) -> bool {
        self.0 -= 1;
        self.0 > 0
    }
}

/// The bytes of a solution's arrays.
fn stored_bytes(sol: &Solution) -> usize {
    sol.len() * state_bytes(sol.particles, sol.constraints) + 8 * sol.accepted_step_sizes.len()
}

#[test]
fn a_stopped_run_keeps_the_state_where_it_stopped_between_two_stored_rows() {
    let s = pendulum();
    let options = SimulationOptions {
        t_end: 1.0,
        dt: 1e-3,
        save_every: 10,
        ..Default::default()
    };
    let sol = simulate_with_observer(&s, &options, &mut StopAfter(123)).unwrap();
    let t = 0.123;
    assert!(matches!(sol.status, Err(Error::Interrupted { t: stop }) if (stop - t).abs() < 1e-12));
    assert!((sol.times.last().unwrap() - t).abs() < 1e-12);
    // The uninterrupted run to that time stores the same rows (every 10th step and the last).
    let reference = simulate(
        &s,
        &SimulationOptions {
            t_end: *sol.times.last().unwrap(),
            ..options
        },
    )
    .unwrap();
    assert_eq!(reference.times, sol.times);
    assert_eq!(reference.positions, sol.positions);
}

#[test]
fn a_run_whose_output_would_not_fit_is_refused_before_it_starts() {
    let options = SimulationOptions {
        t_end: 1.0,
        dt: 1e-3,
        save_every: 7,
        max_output_bytes: Some(1000.0),
        ..Default::default()
    };
    let Err(Error::OutputTooLarge { bytes, t: None, .. }) = simulate(&pendulum(), &options) else {
        panic!("not refused");
    };
    // The same run with room: the estimate is the size of what it stores.
    let roomy = SimulationOptions {
        max_output_bytes: Some(1e12),
        ..options
    };
    let sol = simulate(&pendulum(), &roomy).unwrap();
    assert!(sol.status.is_ok());
    assert_eq!(bytes, stored_bytes(&sol) as f64);
    for bad in [0.0, -1.0, f64::NAN] {
        let options = SimulationOptions {
            max_output_bytes: Some(bad),
            ..Default::default()
        };
        assert!(matches!(
            simulate(&pendulum(), &options),
            Err(Error::InvalidParameter { name, .. }) if name == "max_output_bytes"
        ));
    }
}

#[test]
fn an_adaptive_run_stops_when_its_output_reaches_the_limit() {
    let limit = 20_000.0;
    let options = SimulationOptions {
        t_end: 100.0,
        dt: 1e-3,
        step_control: StepControl::Adaptive(AdaptiveOptions::default()),
        max_output_bytes: Some(limit),
        ..Default::default()
    };
    let sol = simulate(&pendulum(), &options).unwrap();
    let Err(Error::OutputTooLarge {
        bytes, t: Some(t), ..
    }) = &sol.status
    else {
        panic!("{:?}", sol.status);
    };
    let stored = stored_bytes(&sol) as f64;
    assert_eq!(*bytes, stored);
    // Stopped at the first step past the limit.
    assert!(stored > limit && stored <= limit + (state_bytes(2, 1) + 8) as f64);
    assert_eq!(sol.times.last(), Some(t));
    for k in 0..sol.len() {
        let q = sol.position(k, 1);
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        assert!((r - 1.0).abs() < 1e-9, "|q| = {r} at row {k}");
    }
}
