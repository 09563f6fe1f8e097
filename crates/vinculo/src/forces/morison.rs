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
//!
//! In the system's water instead ([`MorisonSpec::in_water`]: a MoorDyn point in a current),
//! u and a are the water's velocity and local acceleration at the particle,
//! [`crate::water::Water::flow`] (the point counted as submerged), and the force depends on
//! the particle's position through them: df/db = c (|r| I + r r^T / |r|) du/db
//! + (1 + Ca) rho V da/db.

use std::sync::Arc;

use super::line_node::mul as mat_mul;
use super::Jacobian;
use crate::laws::VectorLaw;
use crate::math::{add_mat, diag, norm, outer, scale, scale_mat, sub, Mat3, Vec3};
use crate::water::Water;

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
    /// Displacement of the fluid X_f(t) (m); a constant law for still fluid. Unused in water.
    pub fluid: VectorLaw,
    /// In the system's water (its current and waves at the particle,
    /// [`System::set_water`](crate::model::System::set_water)) instead of the fluid's rigid
    /// motion; the volume may then be 0 (drag alone).
    pub in_water: bool,
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
    /// The system's water, when the element is in it (module documentation); None: the
    /// fluid's rigid motion `fluid`.
    pub water: Option<Arc<Water>>,
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

    /// The fluid's velocity and acceleration at the particle at `q`, time `t`, and their
    /// gradients (zero for the rigid motion) when asked.
    #[inline]
    fn flow(&self, q: Vec3, t: f64, gradients: bool) -> (Vec3, Vec3, Mat3, Mat3) {
        match &self.water {
            Some(water) => {
                let f = water.flow(q, t, gradients);
                (
                    f.velocity,
                    f.acceleration,
                    f.velocity_gradient,
                    f.acceleration_gradient,
                )
            }
            None => {
                let (_, u, a) = self.fluid.eval(t);
                (u, a, [[0.0; 3]; 3], [[0.0; 3]; 3])
            }
        }
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> [Vec3; 1] {
        let (u, a, _, _) = self.flow(q[self.particles[0]], t, false);
        let mf = self.displaced_mass();
        let drag = self.drag_at(u, v[self.particles[0]]);
        let f = std::array::from_fn(|k| {
            mf * (a[k] - self.gravity[k]) + self.added_mass() * a[k] + drag[k]
        });
        [f]
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let p = self.particles[0];
        let in_water = self.water.is_some();
        let (u, _, du, da) = self.flow(q[p], t, in_water);
        let r = sub(u, v[p]);
        let s = norm(r);
        // d(drag)/du = c (|r| I + r r^T / |r|) = -d(drag)/db'.
        let dd_du = if s > 0.0 {
            let c = self.drag_factor();
            add_mat(diag(c * s), outer(c / s, r, r))
        } else {
            [[0.0; 3]; 3]
        };
        dv[0][0] = add_mat(dv[0][0], scale_mat(-1.0, dd_du));
        if in_water {
            let inertia = self.displaced_mass() + self.added_mass();
            let df_dq = add_mat(mat_mul(dd_du, du), scale_mat(inertia, da));
            dq[0][0] = add_mat(dq[0][0], df_dq);
        }
    }

    /// The drag force alone on a body at `q` moving at `v` at time `t`, for output.
    pub fn drag(&self, q: Vec3, v: Vec3, t: f64) -> Vec3 {
        self.drag_at(self.flow(q, t, false).0, v)
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
            water: None,
        }
    }

    /// A point in water with a sheared current (0.2 m/s at -40 m to 1 m/s at 0, along x and
    /// y) and a regular wave: its force depends on its position through the flow.
    fn in_water() -> Morison {
        use crate::water::{Current, Stretching, WaveSpec};
        let mut m = element();
        let current = Current::Table {
            z: vec![-40.0, 0.0],
            velocity: vec![[0.2, 0.1, 0.0], [1.0, 0.5, 0.0]],
        };
        let wave = WaveSpec {
            amplitude: 0.4,
            omega: 0.9,
            direction: 0.3,
            phase: 0.2,
        };
        let mut water = Water::new(60.0, 9.81, current, &[wave], Stretching::Wheeler).unwrap();
        water.free_surface = false;
        m.water = Some(Arc::new(water));
        m
    }

    /// In water the Jacobian's position part (through the current's shear and the wave's
    /// gradients) meets central differences too, on both sides of the drag's kink, and a
    /// point held still in a uniform current feels 1/2 rho Cd A U^2 along it.
    #[test]
    fn in_water_the_jacobian_and_the_drag_follow_the_flow() {
        let f = Force::Morison(Box::new(in_water()));
        for v in [[0.03, -0.01, 0.02], [0.9, 0.4, -0.1]] {
            fd::check(&f, &[[1.0, -2.0, -15.0]], &[v], 1.3);
        }
        let mut m = element();
        let current = crate::water::Current::Uniform([0.5, 0.0, 0.0]);
        let still = Water::new(60.0, 9.81, current, &[], crate::water::Stretching::Wheeler);
        m.water = Some(Arc::new(still.unwrap()));
        let drag = m.drag([3.0, 0.0, -10.0], [0.0; 3], 0.0);
        let expected = 0.5 * 1000.0 * 0.22 * 7.85e-3 * 0.25;
        assert!(
            (drag[0] - expected).abs() < 1e-15 && drag[1] == 0.0,
            "{drag:?}"
        );
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
        assert_eq!(m.drag([0.0; 3], u, t), [0.0; 3]);
    }
}
