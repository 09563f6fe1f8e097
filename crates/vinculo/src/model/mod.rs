//! The model: particles and the system that owns them with their constraints and forces, and
//! rigid bodies built from particles.

mod cluster;
pub mod hull;
mod joints;
mod line_loads;
mod on_points;
mod particle;
mod planar_body;
pub(crate) mod point;
mod rigid_body;
mod system;
mod tetrahedron_body;
pub mod user_groups;

pub use cluster::RigidCluster;
pub use hull::{FloatingSpec, Hull, HullSection};
pub use joints::JointKind;
pub use line_loads::{LineHydroSpec, SeabedSpec};
pub use on_points::{Built, OnPointsId};
pub use particle::{ConstraintId, ForceId, Particle, ParticleId};
pub use planar_body::{PlanarBody, PlanarBodySpec};
pub use point::{Point, PointMap};
pub use rigid_body::{RigidBody, RigidBodySpec};
pub use system::System;
pub use tetrahedron_body::TetrahedronBody;
