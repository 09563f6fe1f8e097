//! What the chain benchmarks share: the chain of point masses they time and the observer that
//! clocks its steps (each benchmark uses what it needs of them).
#![allow(dead_code)]

use std::time::Instant;

use vinculo::model::System;
use vinculo::Observer;

/// A chain of `n` point masses of 0.1 kg joined by distance constraints of length `link` (m)
/// to a fixed anchor at the origin, at rest along -z (`hanging`: its equilibrium) or along +x
/// (swinging down when released), under gravity.
pub fn chain(n: usize, link: f64, hanging: bool) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut prev = s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap();
    for i in 1..=n {
        let x = i as f64 * link;
        let pos = if hanging {
            [0.0, 0.0, -x]
        } else {
            [x, 0.0, 0.0]
        };
        let p = s.add_particle(0.1, pos, [0.0; 3], false).unwrap();
        s.add_distance(prev, p, None).unwrap();
        prev = p;
    }
    s
}

/// Records the wall-clock time of every accepted step.
pub struct Clock(pub Vec<Instant>);
impl Observer for Clock {
    fn step(&mut self, _t: f64, _t_end: f64) -> bool {
        self.0.push(Instant::now());
        true
    }
}
