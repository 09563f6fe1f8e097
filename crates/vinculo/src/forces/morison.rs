//! Fluid forces on a submerged body whose reference particle is `b` (Morison equation for a body
//! in a fluid that moves as a rigid body with displacement X_f(t): a closed tank on a shake table).
//!
//! With fluid velocity u = X_f'(t), fluid acceleration a = X_f''(t), body volume V, frontal area A,
//! fluid density rho, drag and added-mass coefficients Cd and Ca, gravity g and b' the particle's
//! velocity:
//!
//! ```text
//! f = rho V (a - g)                     buoyancy and Froude-Krylov (pressure field of the fluid)
//!   + Ca rho V a                        added mass: the part of Ca rho V (a - b'') known in advance
//!   + 1/2 rho Cd A |u - b'| (u - b')    drag
//! ```
//!
//! The remaining added-mass term -Ca rho V b'' is not a force: it is inertia. It enters the mass
//! matrix as an extra mass m_a = Ca rho V on the reference particle's translation (and only there:
//! added mass of a sphere has no rotational part), through [`Morison::added_mass`].
//!
//! Jacobian: the force does not depend on q. With r = u - b' and c = 1/2 rho Cd A,
//! d(c |r| r)/dr = c (|r| I + r r^T / |r|), and dr/db' = -I, so
//! df/db' = -c (|r| I + r r^T / |r|) (zero at r = 0, where the drag is C1).

use super::Jacobian;
use crate::laws::VectorLaw;
use crate::math::{add_mat, diag, norm, outer, scale, sub, Vec3};

/// The fluid and body data of a [`Morison`] element, as given to
/// [`System::add_morison`](crate::model::System::add_morison).
#[derive(Debug, Clone, PartialEq)]
pub struct MorisonSpec {
    /// Fluid density rho (kg/m^3, > 0).
    pub density: f64,
    /// Displaced volume V (m^3, > 0).
    pub volume: f64,
    /// Frontal area A for the drag (m^2, >= 0).
    pub area: f64,
    /// Drag coefficient Cd (>= 0).
    pub drag_coefficient: f64,
    /// Added-mass coefficient Ca (>= 0).
    pub added_mass_coefficient: f64,
    /// Displacement of the fluid X_f(t) (m); a constant law for still fluid.
    pub fluid: VectorLaw,
}

/// Buoyancy, Froude-Krylov, added mass and drag of a fluid in rigid motion, on one particle.
#[derive(Debug, Clone, PartialEq)]
pub struct Morison {
    /// The body's reference particle (its centre; for a rigid body, the centre particle).
    pub particles: [usize; 1],
    /// Fluid density rho (kg/m^3).
    pub density: f64,
    /// Displaced volume V (m^3).
    pub volume: f64,
    /// Frontal area A for the drag (m^2).
    pub area: f64,
    /// Drag coefficient Cd.
    pub drag_coefficient: f64,
    /// Added-mass coefficient Ca.
    pub added_mass_coefficient: f64,
    /// Displacement of the fluid X_f(t) (m); its derivatives give u and a.
    pub fluid: VectorLaw,
    /// Gravity of the system (m/s^2).
    pub gravity: Vec3,
}

impl Morison {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    /// Mass of the displaced fluid rho V (kg).
    pub fn displaced_mass(&self) -> f64 {
        self.density * self.volume
    }

    /// Added mass Ca rho V (kg), carried by the reference particle's translation.
    pub fn added_mass(&self) -> f64 {
        self.added_mass_coefficient * self.displaced_mass()
    }

    fn drag_factor(&self) -> f64 {
        0.5 * self.density * self.drag_coefficient * self.area
    }

    pub(crate) fn force(&self, _q: &[Vec3], v: &[Vec3], t: f64) -> [Vec3; 1] {
        let (_, u, a) = self.fluid.eval(t);
        let mf = self.displaced_mass();
        let drag = self.drag_at(u, v[self.particles[0]]);
        let f = std::array::from_fn(|k| {
            mf * (a[k] - self.gravity[k]) + self.added_mass() * a[k] + drag[k]
        });
        [f]
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        v: &[Vec3],
        t: f64,
        _dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let (_, u, _) = self.fluid.eval(t);
        let r = sub(u, v[self.particles[0]]);
        let s = norm(r);
        if s > 0.0 {
            let c = self.drag_factor();
            dv[0][0] = add_mat(dv[0][0], add_mat(diag(-c * s), outer(-c / s, r, r)));
        }
    }

    /// The drag force alone on a body moving at `v` at time `t`, for output.
    pub fn drag(&self, v: Vec3, t: f64) -> Vec3 {
        self.drag_at(self.fluid.eval(t).1, v)
    }

    /// 1/2 rho Cd A |u - v| (u - v) for fluid velocity `u`.
    fn drag_at(&self, u: Vec3, v: Vec3) -> Vec3 {
        let r = sub(u, v);
        scale(self.drag_factor() * norm(r), r)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;
    use crate::laws::Law;

    fn element() -> Morison {
        Morison {
            particles: [0],
            density: 1000.0,
            volume: 5.2e-4,
            area: 7.85e-3,
            drag_coefficient: 0.22,
            added_mass_coefficient: 0.52,
            fluid: VectorLaw([
                Law::sine(0.005, 0.9, 0.0, 0.0, 2.0, 0.0).unwrap(),
                Law::Constant(0.0),
                Law::Constant(0.0),
            ]),
            gravity: [0.0, 0.0, -9.81],
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let f = Force::Morison(Box::new(element()));
        fd::check(&f, &[[0.0, 0.0, 0.2]], &[[0.03, -0.01, 0.02]], 1.3);
        // Also where the fluid and the body move together in one direction only.
        fd::check(&f, &[[0.0, 0.0, 0.2]], &[[0.0, 0.0, 0.0]], 3.7);
    }

    #[test]
    fn still_fluid_gives_archimedes() {
        // Closed form: a body at rest in still fluid feels rho V g upwards and nothing else.
        let mut m = element();
        m.fluid = VectorLaw::constant([0.0; 3]);
        let f = m.force(&[[0.0; 3]], &[[0.0; 3]], 0.0)[0];
        assert_eq!(f, [0.0, 0.0, 1000.0 * 5.2e-4 * 9.81]);
    }

    #[test]
    fn body_moving_with_the_fluid_feels_no_drag() {
        // When b' = u the relative velocity vanishes, so only rho V (1 + Ca) a - rho V g remains.
        let m = element();
        let t = 2.9;
        let (_, u, a) = m.fluid.eval(t);
        let f = m.force(&[[0.0; 3]], &[u], t)[0];
        let mf = 1000.0 * 5.2e-4;
        let expected = [mf * 1.52 * a[0], 0.0, mf * 9.81];
        for k in 0..3 {
            assert!((f[k] - expected[k]).abs() < 1e-12 * (1.0 + expected[k].abs()));
        }
        assert_eq!(m.drag(u, t), [0.0; 3]);
    }
}
