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
use crate::math::{norm, Vec3};
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
    pub fn check(&self, system: &System, q: &[Vec3], v: &[Vec3], t: f64, h: f64) -> Option<Error> {
        let energy = system.kinetic_energy(v) + system.potential_energy(q);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::fixtures::pendulum;
    use crate::integrators::Scheme;
    use crate::{simulate, SimulationOptions};

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
