//! Hydrodynamic loads on a node of a lumped-mass line, in the line's local frame, with
//! MoorDyn's conventions (`docs/theory/seabed-and-line-loads.md`).
//!
//! The node stands for a length l of line of diameter d (half a segment each side), volume
//! V = pi d^2 / 4 l. With the water density rho, gravity g, a uniform current U, the node's
//! velocity v and the tangent t ([`super::line_node`]), the relative velocity r = U - v splits
//! into its axial part r_a = t (t . r) and its normal part r_n = r - r_a, and
//!
//! ```text
//! f = -rho V g                                      buoyancy (g the gravity vector)
//!   + 1/2 rho Cd    d l    |r_n| r_n                normal drag
//!   + 1/2 rho CdAx pi d l  |r_a| r_a                axial drag (MoorDyn v2: the area pi d l)
//! ```
//!
//! (MoorDyn-F `Line_GetStateDeriv`: `Dp = 0.25 rhoW Cdn d (l_i + l_{i+1}) |Vp| Vp`,
//! `Dq = 0.25 rhoW Cdt pi d (l_i + l_{i+1}) |Vq| Vq`; the node length is (l_i + l_{i+1})/2.)
//!
//! Added mass: MoorDyn adds rho V (Ca (I - t t^T) + CaAx t t^T) to the node's mass matrix.
//! It is split in two: the isotropic part Ca rho V joins the particle's scalar inertia
//! ([`LineHydro::added_mass`], constant during a run), and the axial correction
//!
//! ```text
//! C(q) = -(Ca - CaAx) rho V t t^T                  (t at the positions the forces use)
//! ```
//!
//! is added to the node's mass block by the step problems ([`LineHydro::axial_excess`] gives
//! (Ca - CaAx) rho V; `assembly/axial_added_mass.rs` places it), so that the node's inertia is
//! m + Ca rho V across the line and m + CaAx rho V along it. Still water or a uniform current:
//! the fluid's acceleration is zero, so there is no Froude-Krylov term besides buoyancy.
//!
//! Jacobian: with D(x) = c (|x| I + x x^T / |x|) the derivative of c |x| x (0 at x = 0),
//! P = I - t t^T and dr_a/dt = t r^T + (t . r) I:
//!
//! ```text
//! df/dv = -D_n(r_n) P - D_a(r_a) t t^T
//! df/dt = -D_n(r_n) dr_a/dt + D_a(r_a) dr_a/dt       (then dt/dq from line_node)
//! ```

use super::line_node::{axial_part_by_tangent, LineNode};
use super::Jacobian;
use crate::local::Rows;
use crate::math::{add, add_mat, diag, dot, norm, outer, scale, scale_mat, sub, Mat3, Vec3};

/// Hydrodynamic loads on one line node.
#[derive(Debug, Clone, PartialEq)]
pub struct LineHydro {
    /// The node and the particles of its tangent.
    pub node: LineNode,
    /// Water density rho (kg/m^3).
    pub density: f64,
    /// Volume-equivalent diameter d (m).
    pub diameter: f64,
    /// Node length l (m).
    pub length: f64,
    /// Normal drag coefficient Cd.
    pub cd: f64,
    /// Axial drag coefficient CdAx.
    pub cdax: f64,
    /// Normal added-mass coefficient Ca.
    pub ca: f64,
    /// Axial added-mass coefficient CaAx.
    pub caax: f64,
    /// Uniform current U (m/s).
    pub current: Vec3,
    /// Gravity of the system (m/s^2).
    pub gravity: Vec3,
}

/// The product m x.
#[inline]
fn mat_vec(m: &Mat3, x: Vec3) -> Vec3 {
    [dot(m[0], x), dot(m[1], x), dot(m[2], x)]
}

/// c |x| x.
#[inline]
fn quadratic(c: f64, x: Vec3) -> Vec3 {
    scale(c * norm(x), x)
}

/// d(c |x| x)/dx = c (|x| I + x x^T / |x|), zero at x = 0.
#[inline]
fn quadratic_derivative(c: f64, x: Vec3) -> Mat3 {
    let s = norm(x);
    if s > 0.0 {
        add_mat(diag(c * s), outer(c / s, x, x))
    } else {
        [[0.0; 3]; 3]
    }
}

impl LineHydro {
    pub(crate) fn particles(&self) -> &[usize] {
        self.node.particles()
    }

    /// Displaced volume V = pi d^2 / 4 l (m^3).
    pub fn volume(&self) -> f64 {
        std::f64::consts::PI * self.diameter * self.diameter / 4.0 * self.length
    }

    /// Added mass Ca rho V (kg) carried by the node's translation (see the module's note on
    /// the axial part).
    pub fn added_mass(&self) -> f64 {
        self.ca * self.density * self.volume()
    }

    /// (Ca - CaAx) rho V (kg): by how much the isotropic added mass [`LineHydro::added_mass`]
    /// overstates the node's inertia along the line (negative when CaAx > Ca). The step
    /// problems subtract it along the tangent (module documentation).
    pub fn axial_excess(&self) -> f64 {
        (self.ca - self.caax) * self.density * self.volume()
    }

    /// 1/2 rho Cd d l and 1/2 rho CdAx pi d l.
    fn drag_factors(&self) -> (f64, f64) {
        let base = 0.5 * self.density * self.diameter * self.length;
        (base * self.cd, base * std::f64::consts::PI * self.cdax)
    }

    /// Buoyancy and drag on the node.
    pub(crate) fn node_force(&self, q: &[Vec3], v: &[Vec3]) -> Vec3 {
        let buoyancy = scale(-self.density * self.volume(), self.gravity);
        let r = sub(self.current, v[self.node.node()]);
        let (cn, ca) = self.drag_factors();
        let drag = match self.node.tangent(q) {
            Some(tg) => {
                let ra = scale(dot(tg.t, r), tg.t);
                add(quadratic(cn, sub(r, ra)), quadratic(ca, ra))
            }
            None => quadratic(cn, r),
        };
        add(buoyancy, drag)
    }

    /// The axial correction of the node's mass block at positions `q`, C = -e t t^T with
    /// e = [`LineHydro::axial_excess`] (zero without a tangent).
    pub(crate) fn axial_correction(&self, q: &[Vec3]) -> Mat3 {
        match self.node.tangent(q) {
            Some(tg) => outer(-self.axial_excess(), tg.t, tg.t),
            None => [[0.0; 3]; 3],
        }
    }

    /// The correction's inertia term C(q) a = -e t (t . a) for the node's acceleration `a`.
    pub(crate) fn axial_inertia(&self, q: &[Vec3], a: Vec3) -> Vec3 {
        match self.node.tangent(q) {
            Some(tg) => scale(-self.axial_excess() * dot(tg.t, a), tg.t),
            None => [0.0; 3],
        }
    }

    /// For the node's acceleration `a`: adds into `dq` (the node's row, as a force's Jacobian)
    /// the derivative of the force-like -C(q) a = e t (t . a) with respect to the positions
    /// through t at fixed a, e (t a^T + (t . a) I) dt/dq, and returns C(q) (zero without a
    /// tangent, `dq` then untouched).
    pub(crate) fn axial_inertia_jacobian(&self, q: &[Vec3], a: Vec3, dq: &mut Jacobian) -> Mat3 {
        match self.node.tangent(q) {
            Some(tg) => {
                let e = self.axial_excess();
                tg.add_chain(scale_mat(e, axial_part_by_tangent(tg.t, a)), dq);
                outer(-e, tg.t, tg.t)
            }
            None => [[0.0; 3]; 3],
        }
    }

    /// Potential of the buoyancy, rho V g . q (the drag dissipates).
    pub(crate) fn potential(&self, q: &[Vec3]) -> f64 {
        self.density * self.volume() * dot(self.gravity, q[self.node.node()])
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], _t: f64) -> Rows {
        self.node.rows(self.node_force(q, v))
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        _t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let r = sub(self.current, v[self.node.node()]);
        let (cn, ca) = self.drag_factors();
        match self.node.tangent(q) {
            Some(tg) => {
                // The products with P = I - t t^T and t t^T as products with t (module
                // documentation): D_n P + D_a t t^T = D_n + (D_a t - D_n t) t^T, and with
                // M = D_a - D_n, M (t r^T + (t . r) I) = (M t) r^T + (t . r) M.
                let t = tg.t;
                let along = dot(t, r);
                let ra = scale(along, t);
                let dn = quadratic_derivative(cn, sub(r, ra));
                let da = quadratic_derivative(ca, ra);
                let m = add_mat(da, scale_mat(-1.0, dn));
                let mt = mat_vec(&m, t);
                // dr/dv = -I
                let df_dv = add_mat(scale_mat(-1.0, dn), outer(-1.0, mt, t));
                dv[0][0] = add_mat(dv[0][0], df_dv);
                let df_dt = add_mat(outer(1.0, mt, r), scale_mat(along, m));
                tg.add_chain(df_dt, dq);
            }
            None => {
                dv[0][0] = add_mat(dv[0][0], scale_mat(-1.0, quadratic_derivative(cn, r)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    fn element(tangent: Option<[usize; 2]>, current: Vec3) -> LineHydro {
        LineHydro {
            node: LineNode::new(1, tangent),
            density: 1025.0,
            diameter: 0.09,
            length: 2.5,
            cd: 1.2,
            cdax: 0.08,
            ca: 1.0,
            caax: 0.5,
            current,
            gravity: [0.0, 0.0, -9.80665],
        }
    }

    /// The analytic Jacobian equals central differences of the force, for an interior node, an
    /// end node (its tangent from itself), a node without a tangent, in still water and in a
    /// current.
    #[test]
    fn jacobian_matches_finite_differences() {
        let q = vec![[-2.0, 0.4, -30.0], [0.1, 0.0, -29.2], [2.2, -0.3, -27.9]];
        let v = vec![[0.1, 0.2, 0.0], [0.3, -0.7, 0.4], [0.0, 0.0, 0.5]];
        for current in [[0.0; 3], [0.6, 0.2, 0.0]] {
            for tangent in [Some([0, 2]), Some([1, 2]), Some([0, 1]), None] {
                let f = Force::LineHydro(Box::new(element(tangent, current)));
                fd::check(&f, &q, &v, 0.0);
            }
        }
    }

    /// Closed forms: at rest in still water only the buoyancy rho g pi d^2/4 l acts (upwards);
    /// moving across the line at speed u, the drag is 1/2 rho Cd d l u^2 against the motion;
    /// along it, 1/2 rho CdAx pi d l u^2.
    #[test]
    fn buoyancy_and_drag_match_moordyn_closed_forms() {
        let e = element(Some([0, 2]), [0.0; 3]);
        let q = vec![[-1.0, 0.0, -30.0], [0.0, 0.0, -30.0], [1.0, 0.0, -30.0]];
        let rest = vec![[0.0; 3]; 3];
        let vol = std::f64::consts::PI * 0.09 * 0.09 / 4.0 * 2.5;
        let b = 1025.0 * 9.80665 * vol;
        let f = e.node_force(&q, &rest);
        assert!((f[2] - b).abs() < 1e-12 * b && f[0] == 0.0 && f[1] == 0.0);
        // The buoyancy is minus the gradient of its potential rho V g . q.
        let mut up = q.clone();
        up[1][2] += 1.0;
        assert!((e.potential(&q) - e.potential(&up) - b).abs() < 1e-9 * b);
        let u = 0.7;
        let mut v = rest.clone();
        v[1] = [0.0, u, 0.0];
        let f = e.node_force(&q, &v);
        let normal = 0.5 * 1025.0 * 1.2 * 0.09 * 2.5 * u * u;
        assert!((f[1] + normal).abs() < 1e-12 * normal, "{f:?}");
        v[1] = [u, 0.0, 0.0];
        let f = e.node_force(&q, &v);
        let axial = 0.5 * 1025.0 * 0.08 * std::f64::consts::PI * 0.09 * 2.5 * u * u;
        assert!((f[0] + axial).abs() < 1e-12 * axial, "{f:?}");
    }
}
