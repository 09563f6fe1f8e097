//! A three-particle element through the public API: a cantilever of two segments, clamped by two
//! fixed particles, whose free end (held at distance l from the clamp by a rigid link) swings
//! against the bending force on the three particles.
//!
//! Reference (closed form, derived in `crates/vinculo/src/forces/bending.rs`): with the free
//! segment at angle theta to the clamped one, the bending energy is EI (1 - cos theta) / l, so
//! m l^2 theta'' = -(EI / l) sin theta, a pendulum with omega_0^2 = EI / (m l^3). Its period at
//! amplitude theta_0 is T = (2 pi / omega_0)(1 + theta_0^2 / 16 + ...), exact to 1e-9 here.

use vinculo::model::System;
use vinculo::{simulate, SimulationOptions};

#[test]
fn bent_cantilever_swings_at_the_linearised_frequency() {
    let (l, m, ei, theta0) = (0.5, 0.2, 0.8, 0.01_f64);
    let mut s = System::new([0.0; 3]);
    let a = s.add_particle(1.0, [-l, 0.0, 0.0], [0.0; 3], true).unwrap();
    let b = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    let tip = [l * theta0.cos(), l * theta0.sin(), 0.0];
    let c = s.add_particle(m, tip, [0.0; 3], false).unwrap();
    s.add_distance(b, c, None).unwrap();
    s.add_bending(a, b, c, ei, Some(l)).unwrap();

    let omega = (ei / (m * l.powi(3))).sqrt();
    let period = 2.0 * std::f64::consts::PI / omega * (1.0 + theta0 * theta0 / 16.0);
    let options = SimulationOptions {
        t_end: 3.2 * period,
        dt: period / 2000.0,
        ..Default::default()
    };
    let sol = simulate(&s, &options).unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    // Downward zero crossings of the tip's y, interpolated linearly.
    let y: Vec<f64> = (0..sol.len()).map(|k| sol.position(k, 2)[1]).collect();
    let crossings: Vec<f64> = (1..y.len())
        .filter(|&k| y[k - 1] > 0.0 && y[k] <= 0.0)
        .map(|k| {
            let (t0, t1) = (sol.times[k - 1], sol.times[k]);
            t0 + (t1 - t0) * y[k - 1] / (y[k - 1] - y[k])
        })
        .collect();
    assert_eq!(crossings.len(), 3);
    let measured = (crossings[2] - crossings[0]) / 2.0;
    // Trapezoidal rule at 2000 steps per period: period error ~ (omega h)^2 / 12 ~ 1e-6.
    assert!(
        ((measured - period) / period).abs() < 1e-5,
        "period {measured} against {period}"
    );
}
