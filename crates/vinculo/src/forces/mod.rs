//! Applied forces f(q, v, t) with their analytic Jacobians df/dq and df/dv.
//!
//! Contract of a force element (one file per kind):
//! - `particles()`: the particles it acts on (any number n >= 1);
//! - `force(q, v, t)`: the applied force on each touched particle;
//! - `add_jacobian(q, v, t, dq, dv)`: adds df_p/dq_r and df_p/dv_r for each ordered pair of
//!   touched particles (n x n blocks each);
//! - `potential(q)`: the potential energy for conservative elements (0 for dissipative ones).
//!
//! - `added_mass()`: mass added to a particle's inertia (fluid elements only).
//!
//! Line elements ([`SeabedContact`], [`LineHydro`]) act on one node of a line and read its
//! tangent from its neighbours ([`LineNode`]).
//!
//! The local values are [`crate::local`]'s, placed by the one assembler whatever n is.
//!
//! Uniform gravity acts on every particle and lives in the [`System`](crate::model::System) itself.
//! The residual of the dynamics uses F = -f (`docs/theory/formulation.md`), so the assembler subtracts these.
//!
//! [`Force::User`] elements belong to a group whose forces a user function computes for all its
//! elements at once ([`user`]).

mod applied;
mod bending;
mod couple;
mod damping_matrix;
mod drag;
mod floating_body;
mod line_hydro;
mod line_node;
mod morison;
mod on_points;
mod seabed;
mod seabed_grid;
mod spring_damper;
pub mod user;

pub use applied::AppliedForce;
pub use bending::Bending;
pub use couple::Couple;
pub use damping_matrix::DampingMatrix;
pub use drag::{LinearDrag, QuadraticDrag};
pub use floating_body::{FloatingBody, HullCell, HullLayer};
pub use line_hydro::LineHydro;
pub use line_node::LineNode;
pub(crate) use line_node::{unit_chord, TangentCache};
pub use morison::{Morison, MorisonSpec};
pub use on_points::ForceOnPoints;
pub use seabed::{SeabedContact, SeabedFriction, SeabedSurface};
pub use seabed_grid::SeabedGrid;
pub use spring_damper::SpringDamper;
pub use user::{ForceGroup, UserForce, UserForces};

use crate::local::{Blocks, PerParticle, Rows};
use crate::math::Vec3;

/// Forces on the touched particles, one per particle in the order of `particles()`.
pub type Local = PerParticle;
/// Jacobian blocks [p][r] = df_p/dx_r between the touched particles.
pub type Jacobian = Blocks;

/// Every built-in force kind, dispatched statically.
#[derive(Debug, Clone, PartialEq)]
pub enum Force {
    /// Linear spring and dashpot between two particles.
    SpringDamper(SpringDamper),
    /// Prescribed force on a particle.
    Applied(Box<AppliedForce>),
    /// f = -c v.
    LinearDrag(LinearDrag),
    /// f = -c |v| v.
    QuadraticDrag(QuadraticDrag),
    /// Buoyancy, Froude-Krylov, added mass and drag of a fluid in rigid motion.
    Morison(Box<Morison>),
    /// Bending stiffness at the middle of three consecutive particles.
    Bending(Bending),
    /// Seabed contact and friction on a line node.
    SeabedContact(Box<SeabedContact>),
    /// Buoyancy and drag on a line node, in the line's local frame.
    LineHydro(Box<LineHydro>),
    /// The water's loads on a rigid body from its submerged volume.
    FloatingBody(Box<FloatingBody>),
    /// A linear velocity coupling f = -D v over any number of particles.
    DampingMatrix(Box<DampingMatrix>),
    /// A torque about a world axis, as a couple on two points of a body.
    Couple(Box<Couple>),
    /// A force of another kind over points fixed in bodies or in the ground.
    OnPoints(Box<ForceOnPoints>),
    /// One element of a group computed by a user function.
    User(UserForce),
}

macro_rules! dispatch {
    ($self:ident, $f:ident => $e:expr) => {
        match $self {
            Force::SpringDamper($f) => $e,
            Force::Applied($f) => $e,
            Force::LinearDrag($f) => $e,
            Force::QuadraticDrag($f) => $e,
            Force::Morison($f) => $e,
            Force::Bending($f) => $e,
            Force::SeabedContact($f) => $e,
            Force::LineHydro($f) => $e,
            Force::FloatingBody($f) => $e,
            Force::DampingMatrix($f) => $e,
            Force::Couple($f) => $e,
            Force::OnPoints($f) => $e,
            Force::User($f) => $e,
        }
    };
}

impl Force {
    /// Particles the force acts on.
    #[inline]
    pub fn particles(&self) -> &[usize] {
        dispatch!(self, f => f.particles())
    }

    /// The particles the force acts on, the first of [`Force::particles`]. Every kind acts on
    /// all its particles except the line-node elements ([`LineHydro`], [`SeabedContact`]),
    /// which act on their node alone and read their neighbours only for the node's tangent.
    /// Their Jacobian then has the node's rows alone, so the matrix pattern holds no block
    /// between the two neighbours and a line stays a chain for the tree elimination.
    #[inline]
    pub fn acting_particles(&self) -> &[usize] {
        match self {
            Force::SeabedContact(f) => &f.particles()[..1],
            Force::LineHydro(f) => &f.particles()[..1],
            other => other.particles(),
        }
    }

    /// How many particles the force acts on ([`Force::acting_particles`]).
    #[inline]
    pub fn acting(&self) -> usize {
        self.acting_particles().len()
    }

    /// Applied force on each touched particle.
    #[inline]
    pub fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Local {
        Local::from_slice(&self.force_rows(q, v, t))
    }

    /// Applied force on each touched particle, on the stack for the built-in kinds.
    #[inline(always)]
    // The line elements hand over `Rows` already (their size depends on the node's tangent).
    #[allow(clippy::useless_conversion)]
    pub fn force_rows(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Rows {
        dispatch!(self, f => f.force(q, v, t).into())
    }

    /// Calls `use_it` with the applied force on each touched particle: the assembler's hot path,
    /// where the built-in kinds hand over their forces from the stack, whatever their size.
    #[inline(always)]
    pub fn with_force<R>(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        use_it: impl FnOnce(&[Vec3]) -> R,
    ) -> R {
        use_it(&self.force_rows(q, v, t))
    }

    /// Calls `put(particle, f)` with the applied force on each particle the force acts on
    /// ([`Force::acting_particles`], in order): the assembler's residual loop. The same values as
    /// [`Force::with_force`]; springs and line elements hand them over directly (no local rows
    /// built and read back), and consecutive line elements on one node share its tangent through
    /// `tangents` (one cache per configuration).
    #[inline(always)]
    pub(crate) fn for_each_acting(
        &self,
        (q, v, t): (&[Vec3], &[Vec3], f64),
        tangents: &mut TangentCache,
        mut put: impl FnMut(usize, Vec3),
    ) {
        match self {
            Force::SpringDamper(s) => {
                let [fa, fb] = s.force(q, v, t);
                put(s.particles[0], fa);
                put(s.particles[1], fb);
            }
            Force::Bending(b) => {
                let f = b.force(q, v, t);
                for (&p, f) in b.particles.iter().zip(f) {
                    put(p, f);
                }
            }
            Force::LineHydro(h) => put(h.node.node(), h.node_force_with(q, v, t, tangents)),
            Force::SeabedContact(s) => put(s.node.node(), s.node_force_with(q, v, tangents)),
            other => {
                let acting = other.acting_particles();
                other.with_force(q, v, t, |rows| {
                    for (&p, &f) in acting.iter().zip(rows) {
                        put(p, f);
                    }
                })
            }
        }
    }

    /// Adds df/dq into `dq` and df/dv into `dv`.
    #[inline]
    pub fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        dispatch!(self, f => f.add_jacobian(q, v, t, dq, dv))
    }

    /// When the element's force jumps during a step of size `h` from the state (`q0`, `v0`,
    /// `a0`) to the positions `q1` (a seabed contact that begins or ends): the time after the
    /// step's start, the run loop's contact event ([`crate::run`]); None for every element
    /// whose force is continuous.
    #[inline]
    pub fn switch_time(
        &self,
        start: (&[Vec3], &[Vec3], &[Vec3]),
        q1: &[Vec3],
        h: f64,
    ) -> Option<f64> {
        match self {
            Force::SeabedContact(f) => f.switch_time(start.0, start.1, start.2, q1, h),
            _ => None,
        }
    }

    /// The particle and the height across which the element switches (a seabed contact's node
    /// and the seabed: [`Force::switch_time`] is None while the particle stays on one side;
    /// NaN for a seabed whose height varies, which only [`Force::switch_time`] can tell), None
    /// for every element whose force is continuous.
    pub fn switch_height(&self) -> Option<(usize, f64)> {
        match self {
            Force::SeabedContact(f) => {
                Some((f.node.node(), f.seabed.flat_height().unwrap_or(f64::NAN)))
            }
            _ => None,
        }
    }

    /// The time scale of the transient that the element's jump starts on a node of inertia
    /// `m` (0 for an element without jumps): the run loop's steps stay short for a few of it
    /// after a contact event ([`crate::run`]).
    pub fn settling_time(&self, inertia: &[f64]) -> f64 {
        match self {
            Force::SeabedContact(f) => f.settling_time(inertia[f.node.node()]),
            _ => 0.0,
        }
    }

    /// Whether [`Force::switch_time`] can ever be `Some` for this element.
    pub fn has_events(&self) -> bool {
        matches!(self, Force::SeabedContact(_))
    }

    /// Potential energy of the conservative part (0 for non-conservative elements).
    pub fn potential(&self, q: &[Vec3]) -> f64 {
        match self {
            Force::SpringDamper(f) => f.potential(q),
            Force::Bending(f) => f.potential(q),
            Force::SeabedContact(f) => f.potential(q),
            Force::LineHydro(f) => f.potential(q),
            Force::OnPoints(f) => f.potential(q),
            _ => 0.0,
        }
    }

    /// True when the Jacobian is identically zero (the element adds nothing to the matrix).
    pub fn has_jacobian(&self) -> bool {
        match self {
            Force::Applied(_) => false,
            Force::OnPoints(f) => f.inner.has_jacobian(),
            _ => true,
        }
    }

    /// Mass the element adds to the inertia of a particle's translation: (particle, mass).
    /// The mass matrix is constant, so this is read once per run.
    pub fn added_mass(&self) -> Option<(usize, f64)> {
        match self {
            Force::Morison(f) => Some((f.particles[0], f.added_mass())),
            Force::LineHydro(f) => Some((f.node.node(), f.added_mass())),
            Force::FloatingBody(f) => f.added_mass(),
            _ => None,
        }
    }

    /// The time interval on which the force's laws are defined.
    pub fn domain(&self) -> (f64, f64) {
        crate::laws::common_domain(self.laws())
    }

    /// The prescribed laws of time the force follows.
    pub fn laws(&self) -> Vec<&crate::laws::Law> {
        match self {
            Force::Applied(f) => f.force.components().iter().collect(),
            Force::Morison(f) => f.fluid.components().iter().collect(),
            Force::Couple(f) => vec![&f.torque],
            Force::OnPoints(f) => f.laws(),
            _ => Vec::new(),
        }
    }

    /// A readable name.
    pub fn name(&self, index: usize) -> String {
        let p = self.particles();
        match self {
            Force::SpringDamper(_) => {
                format!("spring-damper #{index} (particles {}-{})", p[0], p[1])
            }
            Force::Applied(_) => format!("applied force #{index} (particle {})", p[0]),
            Force::LinearDrag(_) => format!("linear drag #{index} (particle {})", p[0]),
            Force::QuadraticDrag(_) => format!("quadratic drag #{index} (particle {})", p[0]),
            Force::Morison(_) => format!("fluid forces #{index} (particle {})", p[0]),
            Force::Bending(_) => format!("bending #{index} (particles {p:?})"),
            Force::SeabedContact(_) => format!("seabed contact #{index} (node {})", p[0]),
            Force::LineHydro(_) => format!("line hydrodynamics #{index} (node {})", p[0]),
            Force::FloatingBody(_) => format!("floating body #{index} (particles {p:?})"),
            Force::DampingMatrix(_) => format!("damping matrix #{index} (particles {p:?})"),
            Force::Couple(_) => format!("torque #{index} (particles {p:?})"),
            Force::OnPoints(f) => format!("{} #{index} (particles {p:?})", f.label),
            Force::User(f) => format!(
                "user force '{}' element {} #{index} (particles {p:?})",
                f.group.name, f.element
            ),
        }
    }
}

#[cfg(test)]
pub(crate) mod fd {
    //! Finite-difference check shared by the force tests.
    use super::*;

    /// Checks df/dq and df/dv of `f` against central differences at (q, v, t).
    pub fn check(f: &Force, q: &[Vec3], v: &[Vec3], t: f64) {
        let h = 1e-6;
        let parts = f.particles().to_vec();
        let mut dq = Jacobian::zeros(parts.len());
        let mut dv = Jacobian::zeros(parts.len());
        f.add_jacobian(q, v, t, &mut dq, &mut dv);
        for (r, &pr) in parts.iter().enumerate() {
            for k in 0..3 {
                for (which, jac) in [(0, &dq), (1, &dv)] {
                    let mut xp = if which == 0 { q.to_vec() } else { v.to_vec() };
                    let mut xm = xp.clone();
                    xp[pr][k] += h;
                    xm[pr][k] -= h;
                    let (fp, fm) = if which == 0 {
                        (f.force(&xp, v, t), f.force(&xm, v, t))
                    } else {
                        (f.force(q, &xp, t), f.force(q, &xm, t))
                    };
                    for p in 0..parts.len() {
                        for l in 0..3 {
                            let fd = (fp[p][l] - fm[p][l]) / (2.0 * h);
                            let an = jac[p][r][l][k];
                            assert!(
                                (fd - an).abs() < 1e-6 * (1.0 + fd.abs()),
                                "{} d f[{p}][{l}] / d{}[{r}][{k}]: analytic {an} vs fd {fd}",
                                f.name(0),
                                if which == 0 { "q" } else { "v" }
                            );
                        }
                    }
                }
            }
        }
    }
}
