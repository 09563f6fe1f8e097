//! Contact of a line node with the seabed, with Coulomb friction regularised as MoorDyn does
//! (`docs/theory/seabed-and-line-loads.md`). The seabed is a plane z = z_b (= -depth) or a
//! surface z = z_b(x, y) given by heights on a grid ([`SeabedGrid`], MoorDyn's 3D seafloor).
//!
//! Normal force (MoorDyn: kBot, cBot per unit area; the contact area is the node's projected
//! area A = d l, d the line's diameter and l the node's length, half a segment each side):
//!
//! ```text
//! p = z_b(x, y) - z                 penetration (contact while p > 0)
//! N = A (kBot p - cBot v_z)         f_n = N e_z
//! ```
//!
//! The force is vertical on a sloping seabed too, as MoorDyn's ("vertical-only"): the surface
//! enters through the penetration alone, dp/dq = (dz_b/dx, dz_b/dy, -1), so that
//! dN/dq = A kBot dp/dq (the damping ramp's share as well). On a slope the force is therefore
//! not the gradient of the spring's energy A kBot p^2 / 2 (whose x and y parts it lacks); a
//! line lying on a frictionless slope keeps its horizontal tension, the contact carrying its
//! weight (`docs/theory/catenary.md`, the sloping seabed).
//!
//! As in MoorDyn the damping acts whenever the node penetrates, in either direction of v_z, so
//! N may be negative (the seabed holds a node that leaves it fast); friction uses |N|.
//!
//! Friction (MoorDyn-F's transverse/axial model): the node's velocity along the seabed
//! v_s = (v_x, v_y, 0) splits into the axial part v_a = t (t . v_s) along the line's tangent t
//! ([`super::line_node`]) and the transverse part v_t = v_s - v_a. Each part w with kinetic
//! coefficient mu (mu_t, mu_a) gets
//!
//! ```text
//! f = -mu c_v w                     if c_v |w| <= m_c |N|     (linear, "static" branch)
//! f = -mu |N| w / |w|               otherwise                 (kinetic Coulomb friction)
//! ```
//!
//! with c_v = FricDamp (N s/m) and m_c = StatDynFricScale (>= 1). With m_c = 1 the friction is
//! continuous (a kink where the branches meet); with m_c > 1 it drops from m_c mu |N| to mu |N|
//! there. Without an axial coefficient (MoorDyn-C's single `FrictionCoefficient`), or without a
//! tangent, the whole sliding velocity w = v_s gets the transverse coefficient (isotropic
//! friction, MoorDyn-C's law).
//!
//! Smoothness: the normal force is continuous in q at p = 0 (a kink) but jumps by
//! -A cBot v_z in v_z there, exactly as MoorDyn's; the Jacobian is the one of the branch the
//! state is in (one-sided at the kinks). No regularisation beyond MoorDyn's own.
//!
//! Jacobian (contact, the node local 0): dN/dq = A kBot dp/dq, dN/dv_z = -A cBot; for each friction
//! part, linear branch df/dw = -mu c_v I, kinetic branch df/dw = -mu |N| (I - u u^T)/|w| with
//! u = w/|w|, df/dN = -mu sgn(N) u; dw/dv and dw/dt follow from w = t t^T S v or (I - t t^T) S v,
//! S = diag(1, 1, 0), and dt/dq from [`super::line_node`].

use std::sync::Arc;

use super::line_node::{axial_part_by_tangent, mul, LineNode, Tangent, TangentCache};
use super::seabed_grid::SeabedGrid;
use super::Jacobian;
use crate::local::Rows;
use crate::math::{add, add_mat, diag, dot, norm, outer, scale, scale_mat, sub, Mat3, Vec3};

/// MoorDyn's seabed friction parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SeabedFriction {
    /// Transverse kinetic coefficient mu_t (MoorDyn's FrictionCoefficient, MoorDyn-F's MuKT).
    pub transverse: f64,
    /// Axial kinetic coefficient mu_a (MoorDyn-F's MuKA); `None`: MoorDyn-C's isotropic
    /// friction, mu_t on the whole sliding velocity whatever the line's direction.
    pub axial: Option<f64>,
    /// Slope c_v of the linear branch (N s/m, MoorDyn's FricDamp / MoorDyn-F's CV, default 200).
    pub damping: f64,
    /// Ratio m_c of static to kinetic friction (MoorDyn's StatDynFricScale / MoorDyn-F's MC,
    /// default 1).
    pub static_scale: f64,
}

impl SeabedFriction {
    /// True when a coefficient is not zero.
    pub fn acts(&self) -> bool {
        self.transverse > 0.0 || self.axial.is_some_and(|a| a > 0.0)
    }

    /// No friction.
    pub const NONE: SeabedFriction = SeabedFriction {
        transverse: 0.0,
        axial: None,
        damping: 200.0,
        static_scale: 1.0,
    };
}

/// The seabed's surface: a plane, or heights on a grid shared by every node's contact.
#[derive(Debug, Clone, PartialEq)]
pub enum SeabedSurface {
    /// The plane z = z_b (m; -depth).
    Flat(f64),
    /// z = z_b(x, y), bilinear between the heights of a grid.
    Grid(Arc<SeabedGrid>),
}

impl SeabedSurface {
    /// The height z_b under the point q and its slopes dz_b/dx, dz_b/dy.
    #[inline]
    pub fn height_and_slope(&self, q: Vec3) -> (f64, f64, f64) {
        match self {
            SeabedSurface::Flat(z) => (*z, 0.0, 0.0),
            SeabedSurface::Grid(grid) => grid.height_and_slope(q[0], q[1]),
        }
    }

    /// The height of a flat seabed (None for a grid).
    pub fn flat_height(&self) -> Option<f64> {
        match self {
            SeabedSurface::Flat(z) => Some(*z),
            SeabedSurface::Grid(_) => None,
        }
    }
}

/// Seabed contact and friction on one line node.
#[derive(Debug, Clone, PartialEq)]
pub struct SeabedContact {
    /// The node and the particles of its tangent.
    pub node: LineNode,
    /// The seabed's surface.
    pub seabed: SeabedSurface,
    /// Contact area A = d l (m^2).
    pub area: f64,
    /// kBot (Pa/m).
    pub stiffness: f64,
    /// cBot (Pa s/m).
    pub damping: f64,
    /// Penetration over which the damping ramps up linearly from zero (m); 0: MoorDyn's
    /// damping, full as soon as the node touches.
    pub damping_ramp: f64,
    /// Friction parameters.
    pub friction: SeabedFriction,
}

/// One friction part: its velocity w, how w depends on the node's velocity (dw/dv) and on the
/// tangent (dw/dt, None when w does not depend on it).
struct Part {
    mu: f64,
    w: Vec3,
    dw_dv: Mat3,
    dw_dt: Option<Mat3>,
}

/// S = diag(1, 1, 0): the velocity along a flat seabed.
const ALONG: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];

impl SeabedContact {
    pub(crate) fn particles(&self) -> &[usize] {
        self.node.particles()
    }

    /// Normal force N (N, along +z) alone; None out of contact (the residual's path: a node
    /// off the seabed costs one comparison on a flat seabed).
    #[inline(always)]
    fn normal_force(&self, q: Vec3, v: Vec3) -> Option<f64> {
        let zb = match &self.seabed {
            SeabedSurface::Flat(z) => *z,
            SeabedSurface::Grid(grid) => grid.height(q[0], q[1]),
        };
        let p = zb - q[2];
        if p <= 0.0 {
            return None;
        }
        let ramp = if p < self.damping_ramp {
            p / self.damping_ramp
        } else {
            1.0
        };
        Some(self.area * (self.stiffness * p - self.damping * ramp * v[2]))
    }

    /// Normal force N (N, along +z) with dN/dq and dN/dv_z; None out of contact.
    #[inline]
    fn normal(&self, q: Vec3, v: Vec3) -> Option<(f64, Vec3, f64)> {
        let (zb, sx, sy) = self.seabed.height_and_slope(q);
        let p = zb - q[2];
        if p <= 0.0 {
            return None;
        }
        let a = self.area;
        let (ramp, dramp_dp) = if p < self.damping_ramp {
            (p / self.damping_ramp, 1.0 / self.damping_ramp)
        } else {
            (1.0, 0.0)
        };
        let n = a * (self.stiffness * p - self.damping * ramp * v[2]);
        // dN/dp, times dp/dq = (dz_b/dx, dz_b/dy, -1).
        let dn_dp = a * self.stiffness - a * self.damping * dramp_dp * v[2];
        Some((
            n,
            [dn_dp * sx, dn_dp * sy, -dn_dp],
            -a * self.damping * ramp,
        ))
    }

    /// The friction parts (transverse, axial) at velocity v and tangent t.
    fn parts(&self, v: Vec3, tangent: Option<&Tangent>) -> [Option<Part>; 2] {
        let fr = &self.friction;
        let vs = [v[0], v[1], 0.0];
        match tangent.zip(fr.axial) {
            None => [
                (fr.transverse > 0.0).then_some(Part {
                    mu: fr.transverse,
                    w: vs,
                    dw_dv: ALONG,
                    dw_dt: None,
                }),
                None,
            ],
            Some((tg, axial)) => {
                let t = tg.t;
                let tt = outer(1.0, t, t);
                let va = scale(dot(t, vs), t);
                let da_dt = axial_part_by_tangent(t, vs);
                let da_dv = mul(tt, ALONG);
                [
                    (fr.transverse > 0.0).then(|| Part {
                        mu: fr.transverse,
                        w: sub(vs, va),
                        dw_dv: add_mat(ALONG, scale_mat(-1.0, da_dv)),
                        dw_dt: Some(scale_mat(-1.0, da_dt)),
                    }),
                    (axial > 0.0).then_some(Part {
                        mu: axial,
                        w: va,
                        dw_dv: da_dv,
                        dw_dt: Some(da_dt),
                    }),
                ]
            }
        }
    }

    /// The friction of a part of coefficient `mu` sliding at `w` under normal force `n`: f, and
    /// whether it is on the kinetic branch.
    fn friction_of(&self, mu: f64, w: Vec3, n: f64) -> (Vec3, bool) {
        let fr = &self.friction;
        let s = norm(w);
        if fr.damping * s > fr.static_scale * n.abs() {
            (scale(-mu * n.abs() / s, w), true)
        } else {
            (scale(-mu * fr.damping, w), false)
        }
    }

    /// The contact force on the node (normal and friction) at its position and velocity.
    pub(crate) fn node_force(&self, q: &[Vec3], v: &[Vec3]) -> Vec3 {
        self.node_force_with(q, v, &mut TangentCache::default())
    }

    /// [`SeabedContact::node_force`], the node's tangent (where friction needs it) taken from
    /// `tangents` (shared with the element before it on the same node in the assembler's loop).
    #[inline(always)]
    pub(crate) fn node_force_with(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        tangents: &mut TangentCache,
    ) -> Vec3 {
        let i = self.node.node();
        let Some(n) = self.normal_force(q[i], v[i]) else {
            return [0.0; 3];
        };
        let mut f = [0.0, 0.0, n];
        if self.friction.acts() {
            let tangent = tangents.tangent(&self.node, q);
            for (mu, w) in self.sliding(v[i], tangent.as_ref()).iter().flatten() {
                f = add(f, self.friction_of(*mu, *w, n).0);
            }
        }
        f
    }

    /// The friction parts' coefficients and sliding velocities (mu, w) at velocity v and
    /// tangent t: [`SeabedContact::parts`] without the derivatives, for the force alone.
    fn sliding(&self, v: Vec3, tangent: Option<&Tangent>) -> [Option<(f64, Vec3)>; 2] {
        let fr = &self.friction;
        let vs = [v[0], v[1], 0.0];
        match tangent.zip(fr.axial) {
            None => [(fr.transverse > 0.0).then_some((fr.transverse, vs)), None],
            Some((tg, axial)) => {
                let va = scale(dot(tg.t, vs), tg.t);
                [
                    (fr.transverse > 0.0).then(|| (fr.transverse, sub(vs, va))),
                    (axial > 0.0).then_some((axial, va)),
                ]
            }
        }
    }

    /// When the node comes into contact or leaves it during a step of size `h` from the state
    /// (`q0`, `v0`, `a0`) to the positions `q1` (its penetration changes sign: the normal force
    /// jumps by A cBot |v_z| there, a discontinuity that a step straddling it resolves only to
    /// first order): the time after the step's start, None when it does not switch.
    ///
    /// The time is the first root in (0, h] of the height's Taylor polynomial from the start,
    /// z(s) = z0 + v0 s + a0 s^2 / 2 - z_b (its error O(h^3) in z, so that a step to that time
    /// lands within O(h^3) of the seabed), or, when the polynomial does not cross in the step
    /// although the step did, the chord's root h p0 / (p0 - p1). Under a sloping seabed z_b is
    /// its tangent plane at the start, z_b0 + (dz_b/dx, dz_b/dy) . (x(s) - x0, y(s) - y0): the
    /// root is exact on a plane, and within O(h^2) of the curvature's share elsewhere.
    pub(crate) fn switch_time(
        &self,
        q0: &[Vec3],
        v0: &[Vec3],
        a0: &[Vec3],
        q1: &[Vec3],
        h: f64,
    ) -> Option<f64> {
        let i = self.node.node();
        let (zb0, sx, sy) = self.seabed.height_and_slope(q0[i]);
        let zb1 = self.seabed.height_and_slope(q1[i]).0;
        let (p0, p1) = (zb0 - q0[i][2], zb1 - q1[i][2]);
        if (p0 > 0.0) == (p1 > 0.0) {
            return None;
        }
        // The height above the seabed's tangent plane at the start (exact on a plane).
        let (v, acc) = (v0[i], a0[i]);
        let (c, b, a) = (
            q0[i][2] - zb0,
            v[2] - sx * v[0] - sy * v[1],
            0.5 * (acc[2] - sx * acc[0] - sy * acc[1]),
        );
        let chord = h * p0 / (p0 - p1);
        Some(first_root(a, b, c, h).unwrap_or(chord))
    }

    /// The time scale of the transient a touchdown starts for a node of inertia `m`: the
    /// seabed's damping stops the node within m / (A cBot) (the fast root of the overdamped
    /// contact, MoorDyn's cBot being above critical damping for line nodes), or, without
    /// damping, sqrt(m / (A kBot)), a radian of the contact's oscillation.
    pub(crate) fn settling_time(&self, m: f64) -> f64 {
        if self.damping > 0.0 {
            m / (self.area * self.damping)
        } else if self.stiffness > 0.0 {
            (m / (self.area * self.stiffness)).sqrt()
        } else {
            0.0
        }
    }

    /// Energy of the seabed's spring, A kBot p^2 / 2 while the node penetrates (the damping
    /// and the friction dissipate; on a sloping seabed the vertical force is not its gradient,
    /// module documentation).
    pub(crate) fn potential(&self, q: &[Vec3]) -> f64 {
        let q = q[self.node.node()];
        let p = (self.seabed.height_and_slope(q).0 - q[2]).max(0.0);
        0.5 * self.area * self.stiffness * p * p
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
        let i = self.node.node();
        let Some((n, dn_dq, dn_dvz)) = self.normal(q[i], v[i]) else {
            return;
        };
        for (c, d) in dn_dq.iter().enumerate() {
            dq[0][0][2][c] += d;
        }
        dv[0][0][2][2] += dn_dvz;
        if !self.friction.acts() {
            return;
        }
        let tangent = self.node.tangent(q);
        let fr = &self.friction;
        for part in self.parts(v[i], tangent.as_ref()).iter().flatten() {
            let (f, kinetic) = self.friction_of(part.mu, part.w, n);
            // df/dw
            let df_dw = if kinetic {
                let s = norm(part.w);
                let u = scale(1.0 / s, part.w);
                let c = -part.mu * n.abs() / s;
                // df/dN: f = -mu |N| u, so df/dN = f / N (N != 0 on this branch as |w| > 0).
                if n != 0.0 {
                    let df_dn = scale(1.0 / n, f);
                    for r in 0..3 {
                        for (c, d) in dn_dq.iter().enumerate() {
                            dq[0][0][r][c] += df_dn[r] * d;
                        }
                        dv[0][0][r][2] += df_dn[r] * dn_dvz;
                    }
                }
                add_mat(diag(c), outer(-c, u, u))
            } else {
                diag(-part.mu * fr.damping)
            };
            dv[0][0] = add_mat(dv[0][0], mul(df_dw, part.dw_dv));
            if let (Some(dw_dt), Some(tg)) = (part.dw_dt, tangent.as_ref()) {
                tg.add_chain(mul(df_dw, dw_dt), dq);
            }
        }
    }
}

/// The smallest root s in (0, h] of a s^2 + b s + c, if any (the numerically stable form of
/// the quadratic formula).
fn first_root(a: f64, b: f64, c: f64, h: f64) -> Option<f64> {
    let mut roots = [f64::NAN; 2];
    if a == 0.0 {
        roots[0] = -c / b;
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        roots = [q / a, c / q];
    }
    roots
        .into_iter()
        .filter(|s| s.is_finite() && *s > 0.0 && *s <= h)
        .reduce(f64::min)
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    fn contact(tangent: Option<[usize; 2]>, friction: SeabedFriction) -> SeabedContact {
        SeabedContact {
            node: LineNode::new(1, tangent),
            seabed: SeabedSurface::Flat(-50.0),
            area: 0.08 * 1.7,
            stiffness: 3.0e6,
            damping: 3.0e5,
            damping_ramp: 0.0,
            friction,
        }
    }

    fn friction(mc: f64) -> SeabedFriction {
        SeabedFriction {
            transverse: 0.8,
            axial: Some(0.45),
            damping: 200.0,
            static_scale: mc,
        }
    }

    /// Positions of a node 2 mm into the seabed between two neighbours, and velocities.
    fn state() -> (Vec<Vec3>, Vec<Vec3>) {
        let q = vec![
            [-1.6, 0.3, -49.95],
            [0.05, 0.1, -50.002],
            [1.7, -0.2, -50.01],
        ];
        let v = vec![[0.1, 0.0, 0.0], [0.0; 3], [0.0, 0.3, 0.0]];
        (q, v)
    }

    /// The analytic Jacobian equals central differences of the force on every branch: the
    /// linear friction branch (slow sliding), the kinetic branch (fast sliding) in both parts
    /// or in one, static friction above the kinetic one (m_c > 1), a node without a tangent,
    /// an end node whose tangent runs from or to itself, and a node out of contact.
    /// The event time of a node falling freely onto the seabed is the root of its height's
    /// Taylor polynomial (exact for constant acceleration), the earlier root when the
    /// polynomial crosses twice in the step, and the chord's root when it does not cross.
    #[test]
    fn switch_time_is_the_touchdown_of_the_taylor_polynomial() {
        let c = contact(None, SeabedFriction::NONE);
        let zb = c.seabed.flat_height().unwrap();
        // From 0.5 m above at rest, g = 9.81: touchdown at sqrt(2 0.5 / 9.81) = 0.3193 s.
        let q0 = vec![[0.0; 3], [0.0, 0.0, zb + 0.5], [0.0; 3]];
        let v0 = vec![[0.0; 3]; 3];
        let a0 = vec![[0.0, 0.0, -9.81]; 3];
        let q1 = vec![[0.0; 3], [0.0, 0.0, zb - 0.01], [0.0; 3]];
        let s = c.switch_time(&q0, &v0, &a0, &q1, 0.4).unwrap();
        assert!((s - (2.0 * 0.5 / 9.81f64).sqrt()).abs() < 1e-14, "{s}");
        // No sign change of the penetration: no event.
        assert!(c.switch_time(&q0, &v0, &a0, &q0, 0.4).is_none());
        // Rising through the seabed and decelerating: of the roots 0.1 and 0.3 s of
        // z - zb = -0.03 + 0.4 s - s^2, the first.
        let below = vec![[0.0; 3], [0.0, 0.0, zb - 0.03], [0.0; 3]];
        let up = vec![[0.0; 3], [0.0, 0.0, 0.4], [0.0; 3]];
        let down = vec![[0.0, 0.0, -2.0]; 3];
        let above = vec![[0.0; 3], [0.0, 0.0, zb + 0.01], [0.0; 3]];
        let s = c.switch_time(&below, &up, &down, &above, 0.2).unwrap();
        assert!((s - 0.1).abs() < 1e-14, "{s}");
        // A polynomial that stays below although the step ended above: the chord,
        // 0.2 * 0.03 / 0.04.
        let slow = vec![[0.0; 3], [0.0, 0.0, 0.01], [0.0; 3]];
        let s = c.switch_time(&below, &slow, &down, &above, 0.2).unwrap();
        assert!((s - 0.15).abs() < 1e-14, "{s}");
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let (q, mut v) = state();
        // |N| = 816 N here: with c_v = 200 N s/m the kinetic branch starts at 4 m/s.
        for (vel, kinetic) in [
            ([1e-4, -2e-4, 1e-5], false),
            ([6.1, -8.2, 0.01], true),
            ([0.3, 9.0, 0.002], true),
        ] {
            v[1] = vel;
            let c = contact(None, friction(1.0));
            let n = c.normal(q[1], vel).unwrap().0;
            let part = c.parts(vel, None)[0].take().unwrap();
            assert_eq!(
                c.friction_of(part.mu, part.w, n).1,
                kinetic,
                "branch at {vel:?}"
            );
            for tangent in [Some([0, 2]), None, Some([1, 0]), Some([2, 1])] {
                for mc in [1.0, 1.5] {
                    let f = Force::SeabedContact(Box::new(contact(tangent, friction(mc))));
                    fd::check(&f, &q, &v, 0.0);
                    // MoorDyn-C's isotropic friction (no axial coefficient).
                    let mut isotropic = friction(mc);
                    isotropic.axial = None;
                    let f = Force::SeabedContact(Box::new(contact(tangent, isotropic)));
                    fd::check(&f, &q, &v, 0.0);
                }
            }
        }
        // Inside the damping ramp (p = 2 mm < 5 mm), moving down and up.
        for vz in [-0.3, 0.2] {
            v[1] = [0.2, 0.1, vz];
            let mut c = contact(Some([0, 2]), friction(1.0));
            c.damping_ramp = 0.005;
            fd::check(&Force::SeabedContact(Box::new(c)), &q, &v, 0.0);
        }
        let mut above = q.clone();
        above[1][2] = -49.9;
        let f = Force::SeabedContact(Box::new(contact(Some([0, 2]), friction(1.0))));
        fd::check(&f, &above, &v, 0.0);
    }

    /// The contact of `contact` under a seabed of varying height: a twisted (bilinear, not
    /// planar) cell whose height under the node of `state`, (0.05, 0.1), is -49.999 (the node
    /// 3 mm in), sloping in x and y there.
    fn on_grid(tangent: Option<[usize; 2]>, friction: SeabedFriction) -> SeabedContact {
        let mut c = contact(tangent, friction);
        let z = [-50.8, -49.6, -50.1, -48.2];
        // The bilinear height at the node's shares of the cell [-4, 4] x [-4, 4].
        let (fx, fy) = (4.05 / 8.0, 4.1 / 8.0);
        let at_node = (1.0 - fx) * (1.0 - fy) * z[0]
            + (1.0 - fx) * fy * z[1]
            + fx * (1.0 - fy) * z[2]
            + fx * fy * z[3];
        let shift = -49.999 - at_node;
        let grid = SeabedGrid::new(
            vec![-4.0, 4.0],
            vec![-4.0, 4.0],
            z.iter().map(|h| h + shift).collect(),
        )
        .unwrap();
        c.seabed = SeabedSurface::Grid(Arc::new(grid));
        c
    }

    /// Under a sloping seabed the penetration's slopes enter the Jacobian (the normal force's
    /// row and, through |N|, the friction's): central differences agree on both friction
    /// branches, with and without a tangent, in the damping ramp and out of contact.
    #[test]
    fn jacobian_on_a_sloping_seabed_matches_finite_differences() {
        let (q, mut v) = state();
        let c = on_grid(None, SeabedFriction::NONE);
        let (_, dn_dq, _) = c.normal(q[1], [0.0; 3]).unwrap();
        assert!(dn_dq[0].abs() > 1e3 && dn_dq[1].abs() > 1e3, "{dn_dq:?}");
        for vel in [[1e-4, -2e-4, 1e-5], [6.1, -8.2, 0.01]] {
            v[1] = vel;
            for tangent in [Some([0, 2]), None] {
                for mc in [1.0, 1.5] {
                    let f = Force::SeabedContact(Box::new(on_grid(tangent, friction(mc))));
                    fd::check(&f, &q, &v, 0.0);
                }
            }
        }
        v[1] = [0.2, 0.1, -0.3];
        let mut c = on_grid(Some([0, 2]), friction(1.0));
        c.damping_ramp = 0.005;
        fd::check(&Force::SeabedContact(Box::new(c)), &q, &v, 0.0);
        let mut above = q.clone();
        above[1][2] = -49.9;
        let f = Force::SeabedContact(Box::new(on_grid(Some([0, 2]), friction(1.0))));
        fd::check(&f, &above, &v, 0.0);
    }

    /// On a planar slope z_b = -50 + 0.3 x, a node moving at 2 m/s along x and falling from
    /// 0.5 m above it touches down at the root of 0.5 - 0.6 s - 4.905 s^2 (its height above
    /// the slope): the event time is exact there.
    #[test]
    fn switch_time_under_a_slope_is_the_touchdown_on_the_plane() {
        let mut c = contact(None, SeabedFriction::NONE);
        let grid = SeabedGrid::new(vec![-100.0, 100.0], vec![0.0], vec![-80.0, -20.0]).unwrap();
        c.seabed = SeabedSurface::Grid(Arc::new(grid));
        let q0 = vec![[0.0; 3], [0.0, 0.0, -49.5], [0.0; 3]];
        let v0 = vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0; 3]];
        let a0 = vec![[0.0, 0.0, -9.81]; 3];
        let h = 0.4;
        let q1 = vec![[0.0; 3], [2.0 * h, 0.0, -49.5 - 4.905 * h * h], [0.0; 3]];
        let s = c.switch_time(&q0, &v0, &a0, &q1, h).unwrap();
        let exact = (-0.6 + (0.36f64 + 4.0 * 4.905 * 0.5).sqrt()) / (2.0 * 4.905);
        assert!((s - exact).abs() < 1e-14, "{s} vs {exact}");
        // The flat seabed at the start's height (-50) would put it later, at sqrt(0.5 / 4.905).
        assert!((0.5f64 / 4.905).sqrt() - s > 0.05);
    }

    /// At rest without friction the force is minus the gradient of the spring's energy.
    #[test]
    fn force_at_rest_is_minus_the_gradient_of_the_potential() {
        let c = contact(None, SeabedFriction::NONE);
        let (q, _) = state();
        let rest = vec![[0.0; 3]; 3];
        let f = c.node_force(&q, &rest);
        let h = 1e-7;
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[1][2] += h;
        qm[1][2] -= h;
        let grad = (c.potential(&qp) - c.potential(&qm)) / (2.0 * h);
        assert!((f[2] + grad).abs() < 1e-6 * f[2], "{} vs {}", f[2], -grad);
    }

    /// Out of contact the force is zero; in contact at rest it is A kBot p upwards, the closed
    /// form of MoorDyn's law.
    #[test]
    fn normal_force_is_the_spring_of_the_penetration() {
        let c = contact(Some([0, 2]), friction(1.0));
        let (mut q, v) = state();
        let f = c.node_force(&q, &v);
        let expected = 0.08 * 1.7 * 3.0e6 * 0.002;
        assert!((f[2] - expected).abs() < 1e-9 * expected, "{f:?}");
        assert_eq!([f[0], f[1]], [0.0, 0.0]);
        q[1][2] = -49.999;
        assert_eq!(c.node_force(&q, &v), [0.0; 3]);
    }

    /// Sliding fast along the tangent meets mu_a |N|, across it mu_t |N| (Coulomb's law on the
    /// kinetic branch, past |N| / c_v = 2 m/s here), each opposing the motion.
    #[test]
    fn kinetic_friction_is_coulomb_with_axial_and_transverse_coefficients() {
        let mut c = contact(Some([0, 2]), friction(1.0));
        c.node = LineNode::new(1, Some([0, 2]));
        let q = vec![[-1.0, 0.0, -50.0], [0.0, 0.0, -50.001], [1.0, 0.0, -50.0]];
        let n = c.area * c.stiffness * 0.001;
        let mut v = vec![[0.0; 3]; 3];
        v[1] = [5.0, 0.0, 0.0];
        let f = c.node_force(&q, &v);
        assert!((f[0] + 0.45 * n).abs() < 1e-9 * n, "axial {f:?}");
        v[1] = [0.0, -5.0, 0.0];
        let f = c.node_force(&q, &v);
        assert!((f[1] - 0.8 * n).abs() < 1e-9 * n, "transverse {f:?}");
    }
}
