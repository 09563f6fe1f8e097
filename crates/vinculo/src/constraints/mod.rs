//! Constraints Phi(q, t) = 0, one equation each, enforced with a Lagrange multiplier.
//!
//! Contract of a constraint (one file per kind):
//! - `particles()`: the particles it touches (any number n >= 1);
//! - `residual(q, t)`: Phi;
//! - `gradient(q, t)`: dPhi/dq_p for each touched particle p (a row 3-vector each, n in all);
//! - `add_hessian(w, out)`: adds w d2Phi/dq_p dq_r for each ordered pair of touched particles
//!   (n x n blocks);
//! - `phi_t(q, t)`: the partial time derivative, so that Phi' = Phi_q v + Phi_t;
//! - `gamma(q, v, t)`: the part of Phi'' that does not contain the accelerations,
//!   Phi'' = Phi_q a + gamma;
//! - `scale()`: s such that s Phi is a length (it scales rows and multipliers of the linear solve).
//!
//! The local values are [`crate::local`]'s: whatever n is, the one assembler places them through
//! the constraint's slot tables, so a kind over three or more particles (a point-on-line
//! constraint, a point of a rigid body) is one file like the others. A kind with several
//! equations (a joint) adds one equation per row, each with its own multiplier.
//!
//! `q` and `v` are the positions and velocities of every particle of the system (fixed ones
//! included). Each kind's doc comment derives its terms; tests check them against finite
//! differences.
//!
//! [`Constraint::User`] equations belong to a group whose terms user functions compute for all
//! its elements at once ([`user`]).

mod distance;
mod dot_product;
mod elastic_distance;
mod fixed_coordinate;
mod on_points;
mod plane;
mod point_distance;
mod redundancy;
mod relative_coordinate;
mod strain_curve;
pub mod user;

pub use distance::Distance;
pub use dot_product::DotProduct;
pub use elastic_distance::ElasticDistance;
pub use fixed_coordinate::FixedCoordinate;
pub use on_points::OnPoints;
pub use plane::Plane;
pub use point_distance::PointDistance;
pub use redundancy::{explain_singular, find_redundant, MAX_ENTRIES, RANK_TOLERANCE};
pub use relative_coordinate::RelativeCoordinate;
pub use strain_curve::StrainCurve;
pub use user::{ConstraintCall, ConstraintGroup, UserConstraint, UserConstraints};

use crate::laws::Law;
use crate::local::{Blocks, PerParticle, Rows};
use crate::math::Vec3;

/// Gradient blocks of one equation, one row 3-vector per touched particle.
pub type Gradient = PerParticle;
/// Hessian blocks of one equation, [p][r] = d2Phi/dq_p dq_r.
pub type Hessian = Blocks;

/// Every built-in constraint kind, dispatched statically.
///
/// The kinds larger than a distance are boxed, so that an element of the constraint array is
/// 32 bytes: each residual and Jacobian reads the array whole, and with a fixed coordinate's
/// law inline (88 bytes an element) the residual of a chain of 10^5 particles took 16 % longer
/// on one thread, residual and Jacobian 20 % (criterion's `assembly` group of
/// `crates/vinculo/benches/kernels.rs`, alternating builds).
#[derive(Debug, Clone, PartialEq)]
pub enum Constraint {
    /// Fixed distance between two particles (paper eq. 17).
    Distance(Distance),
    /// An elastic segment: a compliant distance whose multiplier is the tension.
    ElasticDistance(Box<ElasticDistance>),
    /// Fixed distance from a particle to a point moving by a prescribed law.
    PointDistance(Box<PointDistance>),
    /// Particle on a plane whose normal and point may move (paper eq. 18).
    Plane(Box<Plane>),
    /// One coordinate of a particle follows a prescribed law (constant by default).
    FixedCoordinate(Box<FixedCoordinate>),
    /// One coordinate of a particle relative to another follows a law (a joint's coincidence).
    RelativeCoordinate(Box<RelativeCoordinate>),
    /// The dot product of two particle differences follows a law (a joint's axis equations).
    DotProduct(Box<DotProduct>),
    /// A constraint of another kind over points fixed in bodies or in the ground.
    OnPoints(Box<OnPoints>),
    /// One equation of a group computed by user functions.
    User(UserConstraint),
}

macro_rules! dispatch {
    ($self:ident, $c:ident => $e:expr) => {
        match $self {
            Constraint::Distance($c) => $e,
            Constraint::ElasticDistance($c) => $e,
            Constraint::PointDistance($c) => $e,
            Constraint::Plane($c) => $e,
            Constraint::FixedCoordinate($c) => $e,
            Constraint::RelativeCoordinate($c) => $e,
            Constraint::DotProduct($c) => $e,
            Constraint::OnPoints($c) => $e,
            Constraint::User($c) => $e,
        }
    };
}

impl Constraint {
    /// Particles touched by the constraint.
    #[inline]
    pub fn particles(&self) -> &[usize] {
        dispatch!(self, c => c.particles())
    }

    /// Phi(q, t).
    #[inline(always)]
    pub fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        dispatch!(self, c => c.residual(q, t))
    }

    /// dPhi/dq for each touched particle.
    #[inline(always)]
    pub fn gradient(&self, q: &[Vec3], t: f64) -> Gradient {
        Gradient::from_slice(&self.gradient_rows(q, t))
    }

    /// dPhi/dq for each touched particle, on the stack for the built-in kinds.
    #[inline(always)]
    // The kinds over points hand over `Rows` already (their size is their points' particles').
    #[allow(clippy::useless_conversion)]
    pub fn gradient_rows(&self, q: &[Vec3], t: f64) -> Rows {
        dispatch!(self, c => c.gradient(q, t).into())
    }

    /// Calls `use_it` with dPhi/dq for each touched particle: the assembler's hot path, where
    /// the built-in kinds hand over their gradients from the stack, whatever their size.
    #[inline(always)]
    pub fn with_gradient<R>(&self, q: &[Vec3], t: f64, use_it: impl FnOnce(&[Vec3]) -> R) -> R {
        match self {
            // Over points (a joint's equation): the rows on the stack, not in a Vec.
            Constraint::OnPoints(c) => c.with_gradient(q, t, use_it),
            other => use_it(&other.gradient_rows(q, t)),
        }
    }

    /// Calls `use_it(hessian, gradient)` with `w` times d2Phi/dq2 (n x n blocks, x-major) and
    /// dPhi/dq at (q, t): the Jacobian's constraint terms in one dispatch. A distance hands
    /// both over from the stack; the other kinds fill `buffer` with their Hessian, except a
    /// constraint over points whose Hessian is zero, which hands over no blocks (an empty
    /// slice: nothing to add).
    #[inline(always)]
    pub fn with_hessian_and_gradient<R>(
        &self,
        (q, t): (&[Vec3], f64),
        w: f64,
        buffer: &mut Hessian,
        use_it: impl FnOnce(&[crate::math::Mat3], &[Vec3]) -> R,
    ) -> R {
        match self {
            Constraint::Distance(c) => use_it(&c.hessian(w), &c.gradient(q, t)),
            Constraint::ElasticDistance(c) => use_it(&c.hessian(q, w), &c.gradient(q, t)),
            Constraint::OnPoints(c) => c.with_hessian_and_gradient((q, t), w, buffer, use_it),
            other => {
                buffer.reset(other.particles().len());
                other.add_hessian(q, t, w, buffer);
                use_it(buffer.as_slice(), &other.gradient_rows(q, t))
            }
        }
    }

    /// Adds `w` times the Hessian d2Phi/dq2 to `out`.
    #[inline(always)]
    pub fn add_hessian(&self, q: &[Vec3], t: f64, w: f64, out: &mut Hessian) {
        dispatch!(self, c => c.add_hessian(q, t, w, out))
    }

    /// Phi(q, t) and dPhi/dq together (one pass over the touched particles where the kinds
    /// share their work).
    #[inline]
    pub fn residual_and_gradient(&self, q: &[Vec3], t: f64) -> (f64, Gradient) {
        self.with_residual_and_gradient(q, t, |phi, g| (phi, Gradient::from_slice(g)))
    }

    /// Calls `use_it` with Phi(q, t) and dPhi/dq (as [`Constraint::with_gradient`]).
    #[inline(always)]
    pub fn with_residual_and_gradient<R>(
        &self,
        q: &[Vec3],
        t: f64,
        use_it: impl FnOnce(f64, &[Vec3]) -> R,
    ) -> R {
        // Chains are made of distances: theirs is taken apart from the other kinds' (whose
        // residual and gradient are evaluated one after the other).
        match self {
            Constraint::Distance(c) => {
                let (phi, g) = c.residual_and_gradient(q);
                use_it(phi, &g)
            }
            // And mooring lines of elastic segments.
            Constraint::ElasticDistance(c) => {
                let (phi, g) = c.residual_and_gradient(q, t);
                use_it(phi, &g)
            }
            // And mechanisms' joints: the points' positions found once.
            Constraint::OnPoints(c) => c.with_residual_and_gradient(q, t, use_it),
            other => use_it(other.residual(q, t), &other.gradient_rows(q, t)),
        }
    }

    /// Partial time derivative Phi_t.
    #[inline]
    pub fn phi_t(&self, q: &[Vec3], t: f64) -> f64 {
        dispatch!(self, c => c.phi_t(q, t))
    }

    /// gamma = Phi'' - Phi_q a.
    #[inline]
    pub fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        dispatch!(self, c => c.gamma(q, v, t))
    }

    /// Scale s: s Phi is a length.
    #[inline]
    pub fn scale(&self) -> f64 {
        dispatch!(self, c => c.scale())
    }

    /// A characteristic length of the constraint (for the model's length scale): the length of
    /// a distance, 0 for the other kinds.
    pub fn length(&self) -> f64 {
        match self {
            Constraint::Distance(c) => c.length,
            Constraint::ElasticDistance(c) => c.share * c.length.value(0.0),
            Constraint::PointDistance(c) => c.length,
            Constraint::OnPoints(c) => c.inner.length(),
            _ => 0.0,
        }
    }

    /// True for the kinds that hold a distance (whose multiplier is a tension 2 lambda L, or the
    /// tension itself for an elastic segment).
    pub fn is_distance(&self) -> bool {
        match self {
            Constraint::Distance(_)
            | Constraint::PointDistance(_)
            | Constraint::ElasticDistance(_) => true,
            Constraint::OnPoints(c) => c.inner.is_distance(),
            _ => false,
        }
    }

    /// The tension (N, > 0 pulling) that multiplier `lambda` means, for the distance kinds:
    /// 2 lambda L for Phi = L^2 - |d|^2, lambda itself for an elastic segment.
    pub fn tension(&self, lambda: f64) -> Option<f64> {
        match self {
            Constraint::ElasticDistance(_) => Some(lambda),
            Constraint::Distance(_) | Constraint::PointDistance(_) => {
                Some(2.0 * lambda * self.length())
            }
            Constraint::OnPoints(c) => c.inner.tension(lambda),
            _ => None,
        }
    }

    /// The compliance c(t) of the equation Phi + c lambda = 0 (`docs/theory/moorings.md`): L/EA
    /// for an elastic segment of finite EA, 0 (an exact constraint) for every other kind.
    #[inline(always)]
    pub fn compliance(&self, t: f64) -> f64 {
        self.compliant_segment().map_or(0.0, |s| s.compliance(t))
    }

    /// The compliance at the tension `lambda`: d(stretch)/d(lambda) of an elastic segment
    /// (its c(t), or L e'(lambda) along a curve), 0 for every other kind.
    #[inline(always)]
    pub fn compliance_at(&self, t: f64, lambda: f64) -> f64 {
        self.compliant_segment()
            .map_or(0.0, |s| s.stretch(t, lambda).1)
    }

    /// True for an elastic segment that goes slack instead of pushing
    /// ([`crate::model::System::set_slack`]).
    #[inline]
    pub fn can_slack(&self) -> bool {
        self.compliant_segment().is_some_and(|s| s.slack)
    }

    /// The elastic segment of finite EA that the constraint is (directly or between points of
    /// bodies), if it is one: what [`Constraint::is_compliant`], [`Constraint::can_slack`] and
    /// [`Constraint::compliance`] answer from, and what the residual's row of every segment
    /// asks once.
    #[inline(always)]
    pub fn compliant_segment(&self) -> Option<&ElasticDistance> {
        match self {
            Constraint::ElasticDistance(c) if c.ea.is_finite() => Some(c.as_ref()),
            Constraint::OnPoints(c) => c.inner.compliant_segment(),
            _ => None,
        }
    }

    /// The elastic segment, if the constraint is one with internal axial damping (its force
    /// goes with the multiplier's, `elastic_distance.rs`).
    #[inline(always)]
    pub fn damped_segment(&self) -> Option<&ElasticDistance> {
        match self {
            Constraint::ElasticDistance(c) if c.damping != 0.0 => Some(c.as_ref()),
            _ => None,
        }
    }

    /// True when the constraint's equation has a compliance (its row gets a diagonal entry).
    #[inline]
    pub fn is_compliant(&self) -> bool {
        self.compliant_segment().is_some()
    }

    /// The prescribed laws of time the constraint follows.
    pub fn laws(&self) -> Vec<&Law> {
        match self {
            Constraint::Distance(_) | Constraint::User(_) => Vec::new(),
            Constraint::ElasticDistance(c) => vec![&c.length],
            Constraint::PointDistance(c) => c.point.components().iter().collect(),
            Constraint::Plane(c) => c
                .normal
                .components()
                .iter()
                .chain(c.point.components())
                .collect(),
            Constraint::FixedCoordinate(c) => vec![&c.value],
            Constraint::RelativeCoordinate(c) => vec![&c.value],
            Constraint::DotProduct(c) => vec![&c.value],
            Constraint::OnPoints(c) => c.laws(),
        }
    }

    /// The time interval on which the constraint's laws are defined.
    pub fn domain(&self) -> (f64, f64) {
        crate::laws::common_domain(self.laws())
    }

    /// A readable name, e.g. "distance #3 (particles 2-3)".
    pub fn name(&self, index: usize) -> String {
        let p = self.particles();
        match self {
            Constraint::Distance(_) => format!("distance #{index} (particles {}-{})", p[0], p[1]),
            Constraint::ElasticDistance(_) => {
                format!("elastic segment #{index} (particles {}-{})", p[0], p[1])
            }
            Constraint::PointDistance(_) => {
                format!("distance to a moving point #{index} (particle {})", p[0])
            }
            Constraint::Plane(_) => format!("plane #{index} (particle {})", p[0]),
            Constraint::FixedCoordinate(c) => {
                format!(
                    "fixed coordinate #{index} (particle {}, axis {})",
                    p[0],
                    ["x", "y", "z"][c.axis]
                )
            }
            Constraint::RelativeCoordinate(c) => format!(
                "relative coordinate #{index} (particles {}-{}, axis {})",
                p[0],
                p[1],
                ["x", "y", "z"][c.axis]
            ),
            Constraint::DotProduct(_) => format!("dot product #{index} (particles {p:?})"),
            Constraint::OnPoints(c) => format!("{} #{index} (particles {p:?})", c.label),
            Constraint::User(c) => format!(
                "user constraint '{}' element {} #{index} (particles {p:?})",
                c.group.name, c.element
            ),
        }
    }
}

#[cfg(test)]
pub(crate) mod fd {
    //! Finite-difference checks shared by the constraint tests.
    use super::*;

    /// Checks gradient, Hessian, Phi_t and gamma of `c` against central differences at (q, v, t).
    pub fn check(c: &Constraint, q: &[Vec3], v: &[Vec3], t: f64) {
        let h = 1e-6;
        let parts = c.particles().to_vec();
        let g = c.gradient(q, t);
        // The combined evaluation is the same as the separate ones, bit for bit.
        assert_eq!(c.residual_and_gradient(q, t), (c.residual(q, t), g.clone()));
        let mut hess = Hessian::zeros(parts.len());
        c.add_hessian(q, t, 1.0, &mut hess);
        for (a, &pa) in parts.iter().enumerate() {
            for k in 0..3 {
                let mut qp = q.to_vec();
                let mut qm = q.to_vec();
                qp[pa][k] += h;
                qm[pa][k] -= h;
                let fd = (c.residual(&qp, t) - c.residual(&qm, t)) / (2.0 * h);
                assert!(
                    (fd - g[a][k]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "gradient {a},{k}: {} vs fd {fd}",
                    g[a][k]
                );
                let gp = c.gradient(&qp, t);
                let gm = c.gradient(&qm, t);
                for b in 0..parts.len() {
                    for l in 0..3 {
                        let fd2 = (gp[b][l] - gm[b][l]) / (2.0 * h);
                        assert!(
                            (fd2 - hess[b][a][l][k]).abs() < 1e-5 * (1.0 + fd2.abs()),
                            "hessian"
                        );
                    }
                }
            }
        }
        // Phi_t and gamma from the total derivatives along a trajectory q(t + s) = q + s v + s^2/2 a.
        let acc: Vec<Vec3> = (0..q.len()).map(|i| [0.3 * i as f64, -0.2, 0.7]).collect();
        let at = |s: f64| -> Vec<Vec3> {
            (0..q.len())
                .map(|i| std::array::from_fn(|k| q[i][k] + s * v[i][k] + 0.5 * s * s * acc[i][k]))
                .collect()
        };
        let hs = 1e-4;
        let phi = |s: f64| c.residual(&at(s), t + s);
        let d1 = (phi(hs) - phi(-hs)) / (2.0 * hs);
        let d2 = (phi(hs) - 2.0 * phi(0.0) + phi(-hs)) / (hs * hs);
        let gv: f64 = parts
            .iter()
            .enumerate()
            .map(|(a, &p)| crate::math::dot(g[a], v[p]))
            .sum();
        let ga: f64 = parts
            .iter()
            .enumerate()
            .map(|(a, &p)| crate::math::dot(g[a], acc[p]))
            .sum();
        let pt = c.phi_t(q, t);
        assert!(
            (d1 - (gv + pt)).abs() < 1e-6 * (1.0 + d1.abs()),
            "Phi' {d1} vs {}",
            gv + pt
        );
        let gm = c.gamma(q, v, t);
        assert!(
            (d2 - (ga + gm)).abs() < 1e-4 * (1.0 + d2.abs()),
            "Phi'' {d2} vs {}",
            ga + gm
        );
    }
}
