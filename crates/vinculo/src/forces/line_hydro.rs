//! Hydrodynamic loads on a node of a lumped-mass line, in the line's local frame, with
//! MoorDyn's conventions (`docs/theory/seabed-and-line-loads.md`; in waves and currents
//! `docs/theory/ocean.md`).
//!
//! The node stands for a length l of line of diameter d (half a segment each side), volume
//! V = pi d^2 / 4 l. With the water density rho, gravity g, the water's velocity u and local
//! acceleration a at the node ([`crate::water::Water::flow`]), the node's velocity v and the
//! tangent t ([`super::line_node`]), the relative velocity r = u - v splits into its axial part
//! r_a = t (t . r) and its normal part r_n = r - r_a, the water's acceleration likewise into
//! a_a and a_n, and
//!
//! ```text
//! f = F [ -rho V g                                  buoyancy (g the gravity vector)
//!       + 1/2 rho Cd    d l    |r_n| r_n            normal drag
//!       + 1/2 rho CdAx pi d l  |r_a| r_a            axial drag (MoorDyn v2: the area pi d l)
//!       + rho V ((1 + Ca) a_n + (1 + CaAx) a_a) ]   Froude-Krylov and the water's share of
//!                                                   the added mass (MoorDyn v2)
//! ```
//!
//! (MoorDyn-F `Line_GetStateDeriv`: `Dp = 0.25 rhoW Cdn d (l_i + l_{i+1}) |Vp| Vp`,
//! `Dq = 0.25 rhoW Cdt pi d (l_i + l_{i+1}) |Vq| Vq`; the node length is (l_i + l_{i+1})/2.)
//! F is the node's wet fraction: 1 in water that fills all space (the default). Under a free
//! surface it is MoorDyn's: the mean of the submerged fractions of the node's segments (one for
//! an end node), each segment's volume shared equally by its two nodes. A segment from z_a to
//! z_b, taken as a rod of diameter d, spans heights from lo = min(z_a, z_b) - d/2 over
//! span = |z_a - z_b| + d, and is wet by s = clamp((eta - lo) / span, 0, 1), eta the elevation
//! above the node (0 in still water; MoorDyn takes the mean of the segment's two nodes'). Inside
//! the ramp, ds/deta = 1/span, ds/dz = -(1 - s)/span at the segment's lower end and -s/span at
//! its upper one, and eta's horizontal gradient enters through the node's x and y. A node
//! without a tangent (no neighbours known) is a horizontal segment: s = (eta - z)/d + 1/2. A
//! vertical line piercing the surface is then buoyant over its wet length, its nodes crossing
//! one by one without a jump (with the node's own (eta - z)/d + 1/2, a node lost the buoyancy
//! of its whole length over its diameter's travel: steps of 1 kN in the top tension of a
//! jumper heaving through the surface, `tests/mooring/test_lowe_langley.py`).
//!
//! Added mass: MoorDyn adds rho V (Ca (I - t t^T) + CaAx t t^T) to the node's mass matrix.
//! It is split in two: the isotropic part Ca rho V joins the particle's scalar inertia
//! ([`LineHydro::added_mass`], constant during a run, the whole of it also for a node that
//! is partly out of the water), and the axial correction
//!
//! ```text
//! C(q) = -(Ca - CaAx) rho V t t^T                  (t at the positions the forces use)
//! ```
//!
//! is added to the node's mass block by the step problems ([`LineHydro::axial_excess`] gives
//! (Ca - CaAx) rho V; `assembly/axial_added_mass.rs` places it), so that the node's inertia is
//! m + Ca rho V across the line and m + CaAx rho V along it.
//!
//! Jacobian: with D(x) = c (|x| I + x x^T / |x|) the derivative of c |x| x (0 at x = 0),
//! P = I - t t^T, dr_a/dt = t r^T + (t . r) I, B = D_n P + D_a t t^T, the water's gradients
//! G_u = du/dx, G_a = da/dx at the node and f_w the bracket above:
//!
//! ```text
//! df/dv = -F B
//! df/dt = F [ (D_a - D_n) dr_a/dt + rho V (CaAx - Ca) (t a^T + (t . a) I) ]   (then dt/dq)
//! df/dx = F [ B G_u + rho V ((1 + Ca) P + (1 + CaAx) t t^T) G_a ] + f_w (grad F)^T
//! ```
//!
//! where x is the node's own position and grad F = (grad eta, -1) / d inside the ramp of F.

use super::line_node::{axial_part_by_tangent, mul, LineNode, Tangent, TangentCache};
use super::Jacobian;
use crate::local::Rows;
use crate::math::{add, add_mat, diag, dot, norm, outer, scale, scale_mat, sub, Mat3, Vec3};
use crate::water::{Flow, Water};
use std::sync::Arc;

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
    /// The water: its current and waves, and whether it has a free surface.
    pub water: Arc<Water>,
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

    /// The water's flow at the node (none in still water, whose surface, if it has one, is
    /// the plane z = 0).
    #[inline(always)]
    fn flow(&self, q: &[Vec3], t: f64, gradients: bool) -> Option<Flow> {
        let w = &*self.water;
        (!w.is_still()).then(|| w.flow(q[self.node.node()], t, gradients))
    }

    /// The wet fraction F (module documentation) and, inside a ramp, its gradient with respect
    /// to the positions of the node's particles (by local index): 1 in water without a
    /// surface; under a free surface at the elevation eta above the node (0 with a level
    /// gradient in still water), the mean over the node's segments of their wet fractions.
    #[inline(always)]
    fn wet_fraction(&self, q: &[Vec3], flow: Option<&Flow>) -> (f64, Option<[Vec3; 3]>) {
        if !self.water.free_surface {
            return (1.0, None);
        }
        // Half a diameter below the surface with its segments (the usual case): all wet.
        let eta = flow.map_or(0.0, |f| f.elevation);
        // (The entries past the node's count hold the node itself.)
        let [i, a, b] = self.node.particles;
        let top = q[i][2].max(q[a][2]).max(q[b][2]);
        if top + 0.5 * self.diameter <= eta {
            return (1.0, None);
        }
        self.wet_fraction_near_surface(q, flow)
    }

    /// [`LineHydro::wet_fraction`] of a node whose segments reach the surface's ramp.
    #[inline(never)]
    fn wet_fraction_near_surface(
        &self,
        q: &[Vec3],
        flow: Option<&Flow>,
    ) -> (f64, Option<[Vec3; 3]>) {
        let (eta, [ex, ey]) = flow.map_or((0.0, [0.0; 2]), |f| (f.elevation, f.elevation_gradient));
        let z = q[self.node.node()][2];
        let half = 0.5 * self.diameter;
        let others = &self.node.particles()[1..];
        // A node alone (no tangent) stands for a horizontal piece of line: one segment whose
        // ends are both at the node.
        let ends: &[usize] = if others.is_empty() {
            std::slice::from_ref(&self.node.particles()[0])
        } else {
            others
        };
        let share = 1.0 / ends.len() as f64;
        let (mut wet, mut gradient, mut ramp) = (0.0, [[0.0; 3]; 3], false);
        for (k, &j) in ends.iter().enumerate() {
            let zj = q[j][2];
            let (low, span) = (z.min(zj) - half, (z - zj).abs() + 2.0 * half);
            let s = (eta - low) / span;
            if s >= 1.0 {
                wet += share;
            } else if s > 0.0 {
                wet += share * s;
                ramp = true;
                // ds/deta = 1/span; ds/dz = -(1 - s)/span at the lower end, -s/span at the
                // upper one (their sum -1/span: the segment lowered as a whole).
                let (at_node, at_other) = if z <= zj {
                    (-(1.0 - s) / span, -s / span)
                } else {
                    (-s / span, -(1.0 - s) / span)
                };
                let g = &mut gradient[0];
                g[0] += share * ex / span;
                g[1] += share * ey / span;
                if others.is_empty() {
                    g[2] += share * (at_node + at_other);
                } else {
                    g[2] += share * at_node;
                    gradient[k + 1][2] += share * at_other;
                }
            }
        }
        (wet, ramp.then_some(gradient))
    }

    /// The loads on the node over its wet fraction (the bracket of the module documentation).
    #[inline(always)]
    fn wet_force(&self, q: &[Vec3], v: &[Vec3], flow: Option<&Flow>) -> Vec3 {
        self.wet_force_with(v, flow, self.node.tangent(q))
    }

    /// [`LineHydro::wet_force`] with the node's tangent given.
    #[inline(always)]
    fn wet_force_with(&self, v: &[Vec3], flow: Option<&Flow>, tangent: Option<Tangent>) -> Vec3 {
        let buoyancy = scale(-self.density * self.volume(), self.gravity);
        let u = flow.map_or([0.0; 3], |f| f.velocity);
        let r = sub(u, v[self.node.node()]);
        let (cn, ca) = self.drag_factors();
        let drag = match &tangent {
            Some(tg) => {
                // |r_a| = |t . r| (t a unit vector): no square root for the axial part.
                let along = dot(tg.t, r);
                let ra = scale(along, tg.t);
                add(quadratic(cn, sub(r, ra)), scale(ca * along.abs(), ra))
            }
            None => quadratic(cn, r),
        };
        let mut f = add(buoyancy, drag);
        if let Some(flow) = flow {
            f = add(
                f,
                self.inertia_force(tangent.as_ref().map(|tg| tg.t), flow.acceleration),
            );
        }
        f
    }

    /// rho V ((1 + Ca) a_n + (1 + CaAx) a_a) = rho V ((1 + Ca) a + (CaAx - Ca) t (t . a)).
    #[inline(always)]
    fn inertia_force(&self, t: Option<Vec3>, a: Vec3) -> Vec3 {
        let m = self.density * self.volume();
        let f = scale(m * (1.0 + self.ca), a);
        match t {
            Some(t) => add(f, scale(m * (self.caax - self.ca) * dot(t, a), t)),
            None => f,
        }
    }

    /// Buoyancy, drag and the water's inertia force on the node at time `t`.
    #[inline(always)]
    pub(crate) fn node_force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Vec3 {
        self.node_force_with(q, v, t, &mut TangentCache::default())
    }

    /// [`LineHydro::node_force`], the node's tangent taken from `tangents` (shared with the
    /// next element on the same node in the assembler's loop).
    #[inline(always)]
    pub(crate) fn node_force_with(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        tangents: &mut TangentCache,
    ) -> Vec3 {
        let flow = self.flow(q, t, false);
        // Under a free surface the wet fraction, unless every particle of the configuration
        // lies half a diameter below it (a line deep in the water: wet).
        if self.water.free_surface {
            let eta = flow.as_ref().map_or(0.0, |f| f.elevation);
            let deep = tangents
                .top(q)
                .is_some_and(|top| top + 0.5 * self.diameter <= eta);
            if !deep {
                let (wet, _) = self.wet_fraction(q, flow.as_ref());
                if wet < 1.0 {
                    if wet == 0.0 {
                        return [0.0; 3];
                    }
                    let tangent = tangents.tangent(&self.node, q);
                    return scale(wet, self.wet_force_with(v, flow.as_ref(), tangent));
                }
            }
        }
        let tangent = tangents.tangent(&self.node, q);
        self.wet_force_with(v, flow.as_ref(), tangent)
    }

    /// The axial correction of the node's mass block at positions `q`, C = -e t t^T with
    /// e = [`LineHydro::axial_excess`] (zero without a tangent).
    pub(crate) fn axial_correction(&self, q: &[Vec3]) -> Mat3 {
        match self.node.tangent(q) {
            Some(tg) => outer(-self.axial_excess(), tg.t, tg.t),
            None => [[0.0; 3]; 3],
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

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> Rows {
        self.node.rows(self.node_force(q, v, t))
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let flow = self.flow(q, t, true);
        let (wet, wet_gradient) = self.wet_fraction(q, flow.as_ref());
        if let Some(g) = wet_gradient {
            // f_w (grad F)^T on the positions of the node and of its neighbours.
            let fw = self.wet_force(q, v, flow.as_ref());
            for (k, gk) in g.iter().enumerate().take(self.node.count) {
                dq[0][k] = add_mat(dq[0][k], outer(1.0, fw, *gk));
            }
        }
        if wet == 0.0 {
            return;
        }
        let u = flow.as_ref().map_or([0.0; 3], |f| f.velocity);
        let r = sub(u, v[self.node.node()]);
        let (cn, ca) = self.drag_factors();
        // B = D_n P + D_a t t^T (df/dv = -F B, df/du = F B).
        let tangent = self.node.tangent(q);
        let b = match &tangent {
            Some(tg) => {
                // The products with P = I - t t^T and t t^T as products with t (module
                // documentation): D_n P + D_a t t^T = D_n + (D_a t - D_n t) t^T, and with
                // M = D_a - D_n, M (t r^T + (t . r) I) = (M t) r^T + (t . r) M.
                let t = tg.t;
                let along = dot(t, r);
                let ra = scale(along, t);
                let dn = quadratic_derivative(cn, sub(r, ra));
                // d(c |r_a| r_a)/dr_a with r_a = (t . r) t: c |t . r| (I + t t^T).
                let da = scale_mat(ca * along.abs(), add_mat(diag(1.0), outer(1.0, t, t)));
                let m = add_mat(da, scale_mat(-1.0, dn));
                let mt = mat_vec(&m, t);
                let mut df_dt = add_mat(outer(1.0, mt, r), scale_mat(along, m));
                if let Some(f) = &flow {
                    let e = self.density * self.volume() * (self.caax - self.ca);
                    df_dt = add_mat(
                        df_dt,
                        scale_mat(e, axial_part_by_tangent(t, f.acceleration)),
                    );
                }
                tg.add_chain(scale_mat(wet, df_dt), dq);
                add_mat(dn, outer(1.0, mt, t))
            }
            None => quadratic_derivative(cn, r),
        };
        dv[0][0] = add_mat(dv[0][0], scale_mat(-wet, b));
        if let Some(f) = &flow {
            let m = self.density * self.volume();
            let inertia = match &tangent {
                Some(tg) => add_mat(
                    diag(m * (1.0 + self.ca)),
                    outer(m * (self.caax - self.ca), tg.t, tg.t),
                ),
                None => diag(m * (1.0 + self.ca)),
            };
            let dx = add_mat(
                mul(b, f.velocity_gradient),
                mul(inertia, f.acceleration_gradient),
            );
            dq[0][0] = add_mat(dq[0][0], scale_mat(wet, dx));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    use crate::water::{Current, Stretching, WaveSpec};

    fn element(tangent: Option<[usize; 2]>, water: Water) -> LineHydro {
        LineHydro {
            node: LineNode::new(1, tangent),
            density: 1025.0,
            diameter: 0.09,
            length: 2.5,
            cd: 1.2,
            cdax: 0.08,
            ca: 1.0,
            caax: 0.5,
            water: Arc::new(water),
            gravity: [0.0, 0.0, -9.80665],
        }
    }

    fn in_current(current: Vec3) -> Water {
        let mut w = Water::everywhere(9.80665);
        w.current = Current::Uniform(current);
        w
    }

    /// Two wave components and a sheared current, 40 m deep, its surface at eta.
    fn sea(stretching: Stretching) -> Water {
        let waves = [
            WaveSpec {
                amplitude: 1.0,
                omega: 0.8,
                direction: 0.3,
                phase: 0.2,
            },
            WaveSpec {
                amplitude: 0.4,
                omega: 1.3,
                direction: -0.5,
                phase: 1.1,
            },
        ];
        let current = Current::PowerLaw {
            surface: [0.5, 0.2, 0.0],
            exponent: 1.0 / 7.0,
            depth: 40.0,
        };
        Water::new(40.0, 9.80665, current, &waves, stretching).unwrap()
    }

    /// The analytic Jacobian equals central differences of the force, for an interior node, an
    /// end node (its tangent from itself), a node without a tangent, in still water, in a
    /// current, and in waves (deep below the surface, near a crest with Wheeler's and vertical
    /// stretching, and half out of the water).
    #[test]
    fn jacobian_matches_finite_differences() {
        let q = vec![[-2.0, 0.4, -30.0], [0.1, 0.0, -29.2], [2.2, -0.3, -27.9]];
        let v = vec![[0.1, 0.2, 0.0], [0.3, -0.7, 0.4], [0.0, 0.0, 0.5]];
        let t = 0.8;
        let waters = [in_current([0.0; 3]), in_current([0.6, 0.2, 0.0])];
        for water in waters {
            for tangent in [Some([0, 2]), Some([1, 2]), Some([0, 1]), None] {
                let f = Force::LineHydro(Box::new(element(tangent, water.clone())));
                fd::check(&f, &q, &v, t);
            }
        }
        // Still water under its surface z = 0 (a MoorDyn file's water): deep, and a node
        // partly out of the water (the wet fraction's gradient, with no flow to evaluate).
        let calm = Water::new(40.0, 9.80665, Current::none(), &[], Stretching::Wheeler).unwrap();
        for z in [-29.2, -0.3 * 0.09, 0.2 * 0.09] {
            let q: Vec<Vec3> = q.iter().map(|p| [p[0], p[1], p[2] + z + 29.2]).collect();
            for tangent in [Some([0, 2]), Some([1, 2]), None] {
                let f = Force::LineHydro(Box::new(element(tangent, calm.clone())));
                fd::check(&f, &q, &v, t);
            }
        }
        for stretching in [Stretching::Wheeler, Stretching::Vertical] {
            let w = sea(stretching);
            let (eta, _, _) = w.surface(0.1, 0.0, t);
            // Below, at mid-crest (eta > 0 here), partly out of the water (not at z = eta
            // itself, where Wheeler's stretching has a kink).
            for z in [-29.2, 0.5 * eta, eta - 0.3 * 0.09, eta + 0.2 * 0.09] {
                let mut q = q.clone();
                for p in q.iter_mut() {
                    p[2] += z + 29.2;
                }
                for tangent in [Some([0, 2]), Some([1, 2]), None] {
                    let f = Force::LineHydro(Box::new(element(tangent, w.clone())));
                    fd::check(&f, &q, &v, t);
                }
            }
        }
    }

    /// In waves, a node held still deep under a regular wave feels the Froude-Krylov and added
    /// mass force rho V (1 + Ca) a of the water's acceleration across the line, rho V (1 + CaAx)
    /// a along it (MoorDyn v2), beside its buoyancy; out of the water it feels nothing, and half
    /// out of it half of everything.
    #[test]
    fn inertia_force_and_wet_fraction_in_waves() {
        let wave = WaveSpec {
            amplitude: 0.5,
            omega: 1.0,
            direction: 0.0,
            phase: 0.0,
        };
        let still = Current::none();
        let w = Water::new(f64::INFINITY, 9.80665, still, &[wave], Stretching::Vertical).unwrap();
        // Line along y: the wave's x and z accelerations are across it.
        let e = element(Some([0, 2]), w.clone());
        let z: f64 = -3.0;
        let q = vec![[0.0, -1.0, z], [0.0, 0.0, z], [0.0, 1.0, z]];
        let (t, rest): (f64, Vec<Vec3>) = (0.9, vec![[0.0; 3]; 3]);
        let k = 1.0 / 9.80665;
        let decay = (k * z).exp();
        // Deep water: a_x = a w^2 e^{kz} sin(-w t), a_z = -a w^2 e^{kz} cos(-w t) (airy.rs).
        let (ax, az) = (0.5 * decay * (-t).sin(), -0.5 * decay * (-t).cos());
        let (ux, uz) = (0.5 * decay * (-t).cos(), 0.5 * decay * (-t).sin());
        let m = 1025.0 * e.volume();
        let f = e.node_force(&q, &rest, t);
        // The node at rest sees r = u: the normal drag 1/2 rho Cd d l |u| u (u is across).
        let speed = ux.hypot(uz);
        let drag = 0.5 * 1025.0 * 1.2 * 0.09 * 2.5 * speed;
        let fx = m * 2.0 * ax + drag * ux;
        let fz = m * 2.0 * az + drag * uz + m * 9.80665;
        assert!((f[0] - fx).abs() < 1e-10 * fx.abs(), "{} {fx}", f[0]);
        assert!((f[2] - fz).abs() < 1e-10 * fz.abs(), "{} {fz}", f[2]);
        // Above the crest: dry; at the surface: half wet.
        let (eta, _, _) = w.surface(0.0, 0.0, t);
        let lift = |dz: f64| {
            q.iter()
                .map(|p| [p[0], p[1], p[2] - z + dz])
                .collect::<Vec<_>>()
        };
        assert_eq!(e.node_force(&lift(eta + 0.05), &rest, t), [0.0; 3]);
        let half = e.node_force(&lift(eta), &rest, t);
        let mut at_surface = e.clone();
        at_surface.water = Arc::new(Water {
            free_surface: false,
            ..w
        });
        let full = at_surface.node_force(&lift(eta), &rest, t);
        for i in 0..3 {
            assert!((half[i] - 0.5 * full[i]).abs() < 1e-12 * full[i].abs().max(1.0));
        }
    }

    /// Still water with its surface at z = 0 (MoorDyn's): a node at rest a diameter below it
    /// feels the whole buoyancy rho g V, one at the surface half of it, one half a diameter
    /// above it nothing; its drag goes with it (half at the surface).
    #[test]
    fn still_water_surface_takes_nodes_out_of_the_water() {
        let calm = Water::new(40.0, 9.80665, Current::none(), &[], Stretching::Wheeler).unwrap();
        let e = element(Some([0, 2]), calm);
        let b = 1025.0 * 9.80665 * e.volume();
        let at = |z: f64| vec![[-1.0, 0.0, z], [0.0, 0.0, z], [1.0, 0.0, z]];
        let rest = vec![[0.0; 3]; 3];
        assert_eq!(e.node_force(&at(-0.09), &rest, 0.0), [0.0, 0.0, b]);
        let half = e.node_force(&at(0.0), &rest, 0.0);
        assert!((half[2] - 0.5 * b).abs() < 1e-12 * b, "{half:?}");
        assert_eq!(e.node_force(&at(0.045), &rest, 0.0), [0.0; 3]);
        // Moving across the line at 1 m/s at the surface: half of 1/2 rho Cd d l u^2.
        let moving = vec![[0.0; 3], [0.0, 1.0, 0.0], [0.0; 3]];
        let f = e.node_force(&at(0.0), &moving, 0.0);
        let drag = 0.5 * 0.5 * 1025.0 * 1.2 * 0.09 * 2.5;
        assert!((f[1] + drag).abs() < 1e-12 * drag, "{f:?}");
    }

    /// Closed forms: at rest in still water only the buoyancy rho g pi d^2/4 l acts (upwards);
    /// moving across the line at speed u, the drag is 1/2 rho Cd d l u^2 against the motion;
    /// along it, 1/2 rho CdAx pi d l u^2.
    #[test]
    fn buoyancy_and_drag_match_moordyn_closed_forms() {
        let e = element(Some([0, 2]), in_current([0.0; 3]));
        let q = vec![[-1.0, 0.0, -30.0], [0.0, 0.0, -30.0], [1.0, 0.0, -30.0]];
        let rest = vec![[0.0; 3]; 3];
        let vol = std::f64::consts::PI * 0.09 * 0.09 / 4.0 * 2.5;
        let b = 1025.0 * 9.80665 * vol;
        let f = e.node_force(&q, &rest, 0.0);
        assert!((f[2] - b).abs() < 1e-12 * b && f[0] == 0.0 && f[1] == 0.0);
        // The buoyancy is minus the gradient of its potential rho V g . q.
        let mut up = q.clone();
        up[1][2] += 1.0;
        assert!((e.potential(&q) - e.potential(&up) - b).abs() < 1e-9 * b);
        let u = 0.7;
        let mut v = rest.clone();
        v[1] = [0.0, u, 0.0];
        let f = e.node_force(&q, &v, 0.0);
        let normal = 0.5 * 1025.0 * 1.2 * 0.09 * 2.5 * u * u;
        assert!((f[1] + normal).abs() < 1e-12 * normal, "{f:?}");
        v[1] = [u, 0.0, 0.0];
        let f = e.node_force(&q, &v, 0.0);
        let axial = 0.5 * 1025.0 * 0.08 * std::f64::consts::PI * 0.09 * 2.5 * u * u;
        assert!((f[0] + axial).abs() < 1e-12 * axial, "{f:?}");
    }
}
