//! Point masses and the typed handles that name particles, constraints and forces.

use crate::math::Vec3;

/// A point mass with its initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct Particle {
    /// Mass in kg (> 0).
    pub mass: f64,
    /// Initial position in m.
    pub position: Vec3,
    /// Initial velocity in m/s.
    pub velocity: Vec3,
    /// A fixed particle never moves: it is not an unknown of the equations.
    pub fixed: bool,
}

/// Handle to a particle of one [`System`](super::System).
///
/// It remembers which system made it, so that a handle from another system is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ParticleId {
    pub(crate) system: u64,
    pub(crate) index: usize,
}

impl ParticleId {
    /// Position of the particle in the system's arrays.
    pub fn index(&self) -> usize {
        self.index
    }

    /// Identifier of the system that made the handle.
    pub fn system(&self) -> u64 {
        self.system
    }
}

/// Handle to a constraint: the index of its equation in the multiplier vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ConstraintId(pub usize);

/// Handle to a force element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ForceId(pub usize);
