//! The growth guard of index-3 generalised-alpha: a run whose mechanical energy grows beyond
//! what its model can hold stops with [`Error::EnergyGrowth`] instead of reporting success.
//!
//! Index-3 generalised-alpha (Arnold and Brüls 2007) is unstable on constrained systems at
//! large spectral radii and coarse steps: on a 1 m pendulum released from the horizontal, with
//! rho_inf = 0.9 and 47 steps a period, the energy grows to 6e3 m g L within 20 periods, and at
//! rho_inf = 1 it grows at every step size (`docs/theory/time-rules.md` has the measured table,
//! `tools/generalized_alpha_stability.py` the script). The blow-up is a property of the scheme,
//! not of its implementation; the guard makes it visible.
//!
//! The guard watches the models where that instability lives and nothing else can raise the
//! energy: constrained models (at least one constraint; the instability is one of the
//! constraint forces) under gravity and linear or quadratic drag on still air (which only
//! remove energy), whose constraints do not move (distances; fixed coordinates, planes and
//! point distances with constant laws). Their exact mechanical energy never rises above its
//! initial value E0, and a correct run's only rises by its discretisation error, a fraction of
//! the energy the model exchanges between its forms, bounded by
//!
//! ```text
//! S = T0 + m_free |g| D
//! ```
//!
//! (the initial kinetic energy, and the weight of the free particles lifted across the model's
//! extent D, [`System::length_scale`]); the guard fires when E > E0 + S, an energy error as
//! large as everything the model holds, which no correct run approaches.
//!
//! Not watched: models with an energy source (applied, fluid or user forces, moving or user
//! constraints), where the bound would need their work; and models with springs or bending,
//! where a stiff mode the step does not resolve raises the energy of a stable run for a few
//! steps before the scheme's damping removes it (the amplification matrix is not normal: on a
//! mass and spring at omega h = 50 with rho_inf = 0, 900 times the initial energy, measured).

use crate::constraints::Constraint;
use crate::error::Error;
use crate::forces::Force;
use crate::math::{dot, norm, Vec3};
use crate::model::System;

/// The energy bound of a run (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyGuard {
    /// Initial mechanical energy E0 (J).
    initial: f64,
    /// The energy the model can exchange, S (J).
    slack: f64,
    /// The run's spectral radius, for the message.
    rho_inf: f64,
}

/// True when `system` is one the guard watches: constrained, and no element can put energy
/// into it or store it elastically (module documentation).
pub fn watched(system: &System) -> bool {
    let forces = system
        .forces()
        .iter()
        .all(|f| matches!(f, Force::LinearDrag(_) | Force::QuadraticDrag(_)));
    let constraints = system.constraints().iter().all(passive);
    !system.constraints().is_empty() && forces && constraints
}

/// True when the constraint can neither put energy into the model nor store it.
fn passive(c: &Constraint) -> bool {
    let still = |law: &crate::laws::VectorLaw| law.0.iter().all(|l| l.is_constant());
    match c {
        Constraint::Distance(_) => true,
        Constraint::FixedCoordinate(f) => f.value.is_constant(),
        Constraint::RelativeCoordinate(f) => f.value.is_constant(),
        Constraint::DotProduct(f) => f.value.is_constant(),
        Constraint::Plane(p) => still(&p.normal) && still(&p.point),
        Constraint::PointDistance(p) => still(&p.point),
        Constraint::OnPoints(p) => passive(&p.inner),
        // An elastic segment's strain energy lives in its multiplier (the tension), which
        // `System::potential_energy` does not count, and a winch law puts work in: not watched.
        Constraint::ElasticDistance(_) => false,
        Constraint::User(_) => false,
    }
}

impl EnergyGuard {
    /// The guard of a run of index-3 generalised-alpha at `rho_inf` from (q0, v0), or `None`
    /// when the model is not one it watches.
    pub fn new(system: &System, rho_inf: f64, q0: &[Vec3], v0: &[Vec3]) -> Option<EnergyGuard> {
        if !watched(system) {
            return None;
        }
        let kinetic = system.kinetic_energy(v0);
        let mass: f64 = system
            .particles()
            .iter()
            .filter(|p| !p.fixed)
            .map(|p| p.mass)
            .sum();
        let lift = mass * norm(system.gravity()) * system.length_scale();
        let slack = kinetic + lift;
        let initial = kinetic + system.potential_energy(q0);
        (slack > 0.0 && initial.is_finite()).then_some(EnergyGuard {
            initial,
            slack,
            rho_inf,
        })
    }

    /// The error when the energy at (q, v), reached by a step of size `h` ending at `t`, is
    /// beyond the bound.
    pub fn check(
        &self,
        system: &System,
        mass: &[f64],
        (q, v): (&[Vec3], &[Vec3]),
        (t, h): (f64, f64),
    ) -> Option<Error> {
        let energy = energy(system, mass, q, v);
        if !(energy.is_nan() || energy > self.initial + self.slack) {
            return None;
        }
        Some(Error::EnergyGrowth {
            t,
            dt: h,
            rho_inf: self.rho_inf,
            energy,
            initial: self.initial,
            bound: self.initial + self.slack,
        })
    }
}

/// The kinetic and potential energy, [`System::kinetic_energy`] plus
/// [`System::potential_energy`], in one pass over the particles with their masses from `mass`
/// (the step workspace's array): sum m (|v|^2 / 2 - g . x) in four running sums (another order
/// of the terms: their rounding), plus the forces' potential. The guard asks it after every
/// step: the two passes of those methods, each summing one term after the other and reading
/// each mass from its particle's record, took 5 % of a step of the hanging chain of 10^4
/// particles (generalised-alpha at 1 ms).
pub fn energy(system: &System, mass: &[f64], q: &[Vec3], v: &[Vec3]) -> f64 {
    let g = system.gravity();
    let term = |m: f64, x: &Vec3, v: &Vec3| m * (0.5 * dot(*v, *v) - dot(g, *x));
    let n = mass.len().min(q.len()).min(v.len());
    let (mass, q, v) = (&mass[..n], &q[..n], &v[..n]);
    let mut sums = [0.0f64; 4];
    let quads = mass
        .chunks_exact(4)
        .zip(q.chunks_exact(4))
        .zip(v.chunks_exact(4));
    for ((m, x), v) in quads {
        for k in 0..4 {
            sums[k] += term(m[k], &x[k], &v[k]);
        }
    }
    // The last n mod 4 particles in a sum of their own: added into the lanes by index, they
    // made the lanes go through memory (a stalled store and load: 6 % of a pendulum's step).
    let rest = n - n % 4;
    let mut tail = 0.0;
    for ((&m, x), v) in mass[rest..].iter().zip(&q[rest..]).zip(&v[rest..]) {
        tail += term(m, x, v);
    }
    let particles = (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail;
    particles + system.forces().iter().map(|f| f.potential(q)).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::{every_kind, pendulum};
    use crate::integrators::Scheme;
    use crate::{simulate, SimulationOptions};

    /// The guard's energy, one pass with four running sums, is the kinetic plus the potential
    /// energy summed term after term, to the rounding of the sums: on the model with every kind
    /// of element (springs among its forces, gravity off the axes), moved and set moving.
    #[test]
    fn the_energy_in_one_pass_is_kinetic_plus_potential() {
        let s = every_kind();
        let q: Vec<Vec3> = s
            .initial_positions()
            .iter()
            .enumerate()
            .map(|(i, x)| [x[0] + 0.01 * i as f64, x[1] - 0.02, x[2] + 0.003 * i as f64])
            .collect();
        let v: Vec<Vec3> = (0..q.len())
            .map(|i| [0.3 * i as f64, -0.1, 0.05 * (i % 3) as f64])
            .collect();
        let (kinetic, potential) = (s.kinetic_energy(&v), s.potential_energy(&q));
        let scale = kinetic.abs() + potential.abs();
        assert!(kinetic > 0.1 && scale > 1.0, "{kinetic} {potential}");
        let mass: Vec<f64> = s.particles().iter().map(|p| p.mass).collect();
        let difference = (energy(&s, &mass, &q, &v) - (kinetic + potential)).abs();
        assert!(difference <= 1e-14 * scale, "{difference} of {scale}");
    }

    /// The pendulum's period from the horizontal, 4 sqrt(L/g) K(1/2) with K(1/2) = 1.854075
    /// (the complete elliptic integral of the first kind at m = 1/2).
    const PERIOD: f64 = 4.0 * 0.319_275_737_453_604_5 * 1.854_074_677_301_372;

    /// rho_inf = 1 at 100 steps a period blows up (measured: the energy error reaches 2.5e6
    /// m g L in 20 periods without the guard): the run stops with the growth error, holding
    /// the steps before. rho_inf = 0.5 at the same step is stable (energy error 2.4e-2 m g L)
    /// and runs to the end.
    #[test]
    fn an_unstable_run_stops_and_a_stable_one_does_not() {
        let system = pendulum();
        let run = |rho_inf| {
            let options = SimulationOptions {
                t_end: 20.0 * PERIOD,
                dt: PERIOD / 100.0,
                scheme: Scheme::GeneralizedAlpha { rho_inf },
                ..Default::default()
            };
            simulate(&system, &options).unwrap()
        };
        let unstable = run(1.0);
        match &unstable.status {
            Err(Error::EnergyGrowth { energy, bound, .. }) => assert!(energy > bound),
            other => panic!("expected an energy growth, got {other:?}"),
        }
        assert!(unstable.times.len() > 2);
        assert!(run(0.5).status.is_ok());
    }
}
