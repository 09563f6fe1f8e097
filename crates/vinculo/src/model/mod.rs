//! The model: particles and the system that owns them with their constraints and forces.

mod particle;
mod system;

pub use particle::{ConstraintId, ForceId, Particle, ParticleId};
pub use system::System;
