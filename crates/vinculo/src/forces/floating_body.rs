//! Hydrostatic, Froude-Krylov, drag and added-mass loads on a rigid body in the water, from its
//! instantaneous submerged volume (`docs/theory/ocean.md`, "Floating bodies").
//!
//! The body's hull is cut into horizontal layers of thickness h (in the body's frame) and each
//! layer into cells ([`crate::model::Hull`]): points fixed in the body, each an affine
//! combination x_c = sum_k w_ck q_k of four frame particles of the body, with a volume dV_c.
//! The water's flow is sampled at each layer's centre on the body's axis, x_l = sum w_lk q_k
//! (the body is small against the wavelength across its width), and the surface near it is the
//! plane through eta(x_l) with the slope s_l = grad eta(x_l). With the wet fraction of a cell
//!
//! ```text
//! F_c = clamp((z_s - z_c) / h + 1/2, 0, 1),    z_s = eta(x_l) + s_l . (x_c - x_l)_h
//! ```
//!
//! (1 in water without a free surface), the water's velocity u and local acceleration a at the
//! layer centre, the cell's velocity v_c and the relative velocity r = u - v_c, a cell carries
//!
//! ```text
//! f_c = F_c [ rho dV_c ((1 + Ca) a - g) + c dV_c |r| r ],     c = 1/2 rho Cd A / V
//! ```
//!
//! buoyancy with the Froude-Krylov force (the pressure of the undisturbed linear wave field
//! integrated over the wetted volume: -grad p = rho (a - g)), the water's share of the added-mass
//! force, and the drag of frontal area A shared among the cells by volume (V the hull's
//! volume). The forces at the cells give the body's force and moment, so the restoring in heave,
//! roll and pitch follows from the geometry. The body's own share of the added mass, Ca rho V0
//! with V0 the displaced volume at the start (or a given mass), joins the inertia of the body's
//! centre particle (translation only, as for a sphere).
//!
//! Jacobian: with f_w the bracket above, B(r) = c dV (|r| I + r r^T / |r|), G_u and G_a the
//! flow's gradients at the layer centre, H the elevation's Hessian there and
//! d = (x_c - x_l) horizontal,
//!
//! ```text
//! df_c/dx_c = f_w (grad_c F)^T,          grad_c F = phi_l' (s_l, -1) / h
//! df_c/dx_l = F [rho dV (1 + Ca) G_a + B G_u] + f_w (grad_l F)^T,   grad_l F = phi_l' (H d, 0) / h
//! df_c/dv_c = -F B
//! ```
//!
//! (grad_l F only inside the ramp of F), and for frame particles p, r:
//! df_p/dq_r = sum_c w_cp (df_c/dx_c w_cr + df_c/dx_l w_lr), df_p/dv_r = sum_c w_cp w_cr df_c/dv_c.

use super::Jacobian;
use crate::local::PerParticle;
use crate::math::{add_mat, diag, norm, outer, scale_mat, Mat3, Vec3};
use crate::water::Water;
use std::sync::Arc;

/// One volume cell of a hull: a point of the body with a volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullCell {
    /// Barycentric weights in the body's frame particles.
    pub weights: [f64; 4],
    /// Volume dV (m^3).
    pub volume: f64,
    /// The layer it belongs to.
    pub layer: usize,
}

/// One layer of a hull: the point on the body's axis where the flow is sampled, its thickness,
/// and the share of its volume below a waterline across it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullLayer {
    /// Barycentric weights of the layer's centre in the body's frame particles.
    pub weights: [f64; 4],
    /// Thickness h (m).
    pub thickness: f64,
    /// The share of the layer's volume below a waterline at u of its thickness from its
    /// bottom: fill[0] u + fill[1] u^2 + fill[2] u^3 (1 at u = 1).
    pub fill: [f64; 3],
}

impl HullLayer {
    /// The wet share at u (clamped to [0, 1]) and its derivative in u (0 outside).
    pub fn fill_fraction(&self, u: f64) -> (f64, f64) {
        if u >= 1.0 {
            (1.0, 0.0)
        } else if u <= 0.0 {
            (0.0, 0.0)
        } else {
            let [c1, c2, c3] = self.fill;
            (
                u * (c1 + u * (c2 + u * c3)),
                c1 + u * (2.0 * c2 + 3.0 * u * c3),
            )
        }
    }
}

/// Loads of the water on a rigid body from its submerged volume.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatingBody {
    /// Four particles of the body (not coplanar) that frame its cells.
    pub frame: [usize; 4],
    /// The hull's cells.
    pub cells: Vec<HullCell>,
    /// The hull's layers.
    pub layers: Vec<HullLayer>,
    /// Water density rho (kg/m^3).
    pub density: f64,
    /// Added-mass coefficient Ca (the water's share of the added-mass force).
    pub ca: f64,
    /// Drag factor c = 1/2 rho Cd A / V (kg/m^4).
    pub drag: f64,
    /// The body's centre particle and the added mass it carries (kg).
    pub added: Option<(usize, f64)>,
    /// Whether the added mass is Ca rho V0 with V0 the displaced volume at the start (then
    /// recomputed when the system's water changes, [`FloatingBody::default_added_mass`]).
    pub added_from_volume: bool,
    /// The water.
    pub water: Arc<Water>,
    /// Gravity of the system (m/s^2).
    pub gravity: Vec3,
}

/// The water at one layer centre.
struct LayerWater {
    x: Vec3,
    eta: f64,
    slope: [f64; 2],
    hessian: [[f64; 2]; 2],
    u: Vec3,
    a: Vec3,
    gu: Mat3,
    ga: Mat3,
}

fn combine(w: &[f64; 4], frame: &[usize; 4], x: &[Vec3]) -> Vec3 {
    let mut out = [0.0; 3];
    for k in 0..4 {
        for i in 0..3 {
            out[i] += w[k] * x[frame[k]][i];
        }
    }
    out
}

impl FloatingBody {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.frame
    }

    /// The water at every layer centre (gradients only when `gradients`).
    fn layer_water(&self, q: &[Vec3], t: f64, gradients: bool) -> Vec<LayerWater> {
        let w = &*self.water;
        let moving = w.needs_flow();
        self.layers
            .iter()
            .map(|l| {
                let x = combine(&l.weights, &self.frame, q);
                let mut lw = LayerWater {
                    x,
                    eta: 0.0,
                    slope: [0.0; 2],
                    hessian: [[0.0; 2]; 2],
                    u: [0.0; 3],
                    a: [0.0; 3],
                    gu: [[0.0; 3]; 3],
                    ga: [[0.0; 3]; 3],
                };
                if moving {
                    let f = w.flow(x, t, gradients);
                    (lw.u, lw.a, lw.gu, lw.ga) = (
                        f.velocity,
                        f.acceleration,
                        f.velocity_gradient,
                        f.acceleration_gradient,
                    );
                    lw.eta = f.elevation;
                    lw.slope = f.elevation_gradient;
                    if gradients {
                        lw.hessian = w.surface_hessian(x[0], x[1], t);
                    }
                }
                lw
            })
            .collect()
    }

    /// The wet fraction of a cell at `x` in `layer` under the water `lw`, and its derivative
    /// in u (0 outside the layer's waterline range).
    fn wet(&self, x: Vec3, layer: &HullLayer, lw: &LayerWater) -> (f64, f64) {
        if !self.water.free_surface {
            return (1.0, 0.0);
        }
        let zs = lw.eta + lw.slope[0] * (x[0] - lw.x[0]) + lw.slope[1] * (x[1] - lw.x[1]);
        layer.fill_fraction((zs - x[2]) / layer.thickness + 0.5)
    }

    /// The bracket f_w of a cell of volume `dv` and velocity `vc`.
    fn cell_force(&self, dv: f64, vc: Vec3, lw: &LayerWater) -> Vec3 {
        let r: Vec3 = std::array::from_fn(|i| lw.u[i] - vc[i]);
        let speed = norm(r);
        std::array::from_fn(|i| {
            self.density * dv * ((1.0 + self.ca) * lw.a[i] - self.gravity[i])
                + self.drag * dv * speed * r[i]
        })
    }

    pub(crate) fn force(&self, q: &[Vec3], v: &[Vec3], t: f64) -> PerParticle {
        let water = self.layer_water(q, t, false);
        let mut out = PerParticle::from_elem([0.0; 3], 4);
        for c in &self.cells {
            let lw = &water[c.layer];
            let x = combine(&c.weights, &self.frame, q);
            let (wet, _) = self.wet(x, &self.layers[c.layer], lw);
            if wet == 0.0 {
                continue;
            }
            let vc = combine(&c.weights, &self.frame, v);
            let f = self.cell_force(c.volume, vc, lw);
            for k in 0..4 {
                for i in 0..3 {
                    out[k][i] += c.weights[k] * wet * f[i];
                }
            }
        }
        out
    }

    pub(crate) fn add_jacobian(
        &self,
        q: &[Vec3],
        v: &[Vec3],
        t: f64,
        dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let water = self.layer_water(q, t, true);
        for c in &self.cells {
            let lw = &water[c.layer];
            let layer = &self.layers[c.layer];
            let h = layer.thickness;
            let x = combine(&c.weights, &self.frame, q);
            let (wet, rate) = self.wet(x, layer, lw);
            if wet == 0.0 {
                continue;
            }
            let vc = combine(&c.weights, &self.frame, v);
            let r: Vec3 = std::array::from_fn(|i| lw.u[i] - vc[i]);
            let speed = norm(r);
            let b = if speed > 0.0 {
                add_mat(
                    diag(self.drag * c.volume * speed),
                    outer(self.drag * c.volume / speed, r, r),
                )
            } else {
                [[0.0; 3]; 3]
            };
            let mut by_cell = [[0.0; 3]; 3];
            let mut by_layer = scale_mat(
                wet,
                add_mat(
                    scale_mat(self.density * c.volume * (1.0 + self.ca), lw.ga),
                    crate::forces::line_node::mul(b, lw.gu),
                ),
            );
            if rate != 0.0 {
                let fw = self.cell_force(c.volume, vc, lw);
                by_cell = outer(rate / h, fw, [lw.slope[0], lw.slope[1], -1.0]);
                let d = [x[0] - lw.x[0], x[1] - lw.x[1]];
                let hd = [
                    lw.hessian[0][0] * d[0] + lw.hessian[0][1] * d[1],
                    lw.hessian[1][0] * d[0] + lw.hessian[1][1] * d[1],
                ];
                by_layer = add_mat(by_layer, outer(rate / h, fw, [hd[0], hd[1], 0.0]));
            }
            let by_velocity = scale_mat(-wet, b);
            for p in 0..4 {
                let wp = c.weights[p];
                if wp == 0.0 {
                    continue;
                }
                for s in 0..4 {
                    let jq = add_mat(
                        scale_mat(wp * c.weights[s], by_cell),
                        scale_mat(wp * layer.weights[s], by_layer),
                    );
                    dq[p][s] = add_mat(dq[p][s], jq);
                    dv[p][s] = add_mat(dv[p][s], scale_mat(wp * c.weights[s], by_velocity));
                }
            }
        }
    }

    /// The added mass on the body's centre particle.
    pub(crate) fn added_mass(&self) -> Option<(usize, f64)> {
        self.added
    }

    /// The hull's volume below the still-water level z = 0 at positions `q` (by the cells' wet
    /// fractions with eta = 0), or the whole hull in water without a surface.
    pub fn displaced_volume(&self, q: &[Vec3]) -> f64 {
        self.cells
            .iter()
            .map(|c| {
                let wet = if self.water.free_surface {
                    let layer = &self.layers[c.layer];
                    let z = combine(&c.weights, &self.frame, q)[2];
                    layer.fill_fraction(-z / layer.thickness + 0.5).0
                } else {
                    1.0
                };
                wet * c.volume
            })
            .sum()
    }

    /// Ca rho V0 ([`FloatingBody::displaced_volume`] at `q`) when the added mass is the
    /// default one: the system sets it when the body is added and when its water changes.
    pub(crate) fn default_added_mass(&mut self, q: &[Vec3]) {
        if let (true, Some((centre, _))) = (self.added_from_volume, self.added) {
            self.added = Some((centre, self.ca * self.density * self.displaced_volume(q)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use crate::math::{cross, dot, sub};
    use crate::model::{FloatingSpec, Hull, HullSection, System};
    use crate::water::{Current, Stretching, Water, WaveSpec};
    use std::f64::consts::PI;

    const RHO: f64 = 1025.0;
    const G: f64 = 9.80665;

    /// Four particles framing a body whose hull's origin is at `origin`, axis `axis`, in
    /// `water` of density `RHO`; returns the element and the particles' positions.
    fn body(hull: Hull, origin: [f64; 3], axis: [f64; 3], water: Water) -> (Force, Vec<[f64; 3]>) {
        body_in(hull, origin, axis, water, RHO)
    }

    fn body_in(
        hull: Hull,
        origin: [f64; 3],
        axis: [f64; 3],
        water: Water,
        density: f64,
    ) -> (Force, Vec<[f64; 3]>) {
        let mut s = System::new([0.0, 0.0, -G]);
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let frame: Vec<_> = corners
            .iter()
            .map(|c| {
                // A frame as large as the hulls: barycentric weights of order one, so that the
                // finite differences of forces of 1e4 N keep their digits.
                let p = std::array::from_fn(|k| origin[k] + 2.0 * c[k] - 0.6);
                s.add_particle(1.0, p, [0.0; 3], false).unwrap()
            })
            .collect();
        s.set_water(water);
        let spec = FloatingSpec {
            origin,
            axis,
            density,
            ca: 0.4,
            cd: 0.8,
            drag_area: 1.5,
            added_mass: Some(0.0),
            layers: 30,
        };
        s.add_floating_body(&frame, None, &hull, &spec).unwrap();
        let q = s.particles().iter().map(|p| p.position).collect();
        (s.forces()[0].clone(), q)
    }

    fn still() -> Water {
        Water::new(60.0, G, Current::none(), &[], Stretching::Wheeler).unwrap()
    }

    fn cylinder(radius: f64, bottom: f64, top: f64) -> Hull {
        Hull {
            sections: vec![HullSection::Frustum {
                bottom,
                top,
                r_bottom: radius,
                r_top: radius,
            }],
        }
    }

    /// The total force and the moment about `about` of the element's particle forces.
    fn resultant(f: &Force, q: &[[f64; 3]], about: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let v = vec![[0.0; 3]; q.len()];
        let forces = f.force(q, &v, 0.0);
        let (mut total, mut moment) = ([0.0; 3], [0.0; 3]);
        for (k, &p) in f.particles().iter().enumerate() {
            let m = cross(sub(q[p], about), forces[k]);
            for i in 0..3 {
                total[i] += forces[k][i];
                moment[i] += m[i];
            }
        }
        (total, moment)
    }

    /// Archimedes for a sphere floating at a draft: the buoyancy rho g V_cap with the cap
    /// volume pi d^2 (3R - d) / 3, to the layers' resolution (the ramp is exact for the
    /// waterline layer's mean section); no moment about the centre.
    #[test]
    fn sphere_buoyancy_is_the_cap_volume() {
        let r = 1.2;
        for z_centre in [-0.5, 0.0, 0.7] {
            let hull = Hull {
                sections: vec![HullSection::Sphere {
                    centre: 0.0,
                    radius: r,
                }],
            };
            let (f, q) = body(hull, [0.3, -0.2, z_centre], [0.0, 0.0, 1.0], still());
            let (total, moment) = resultant(&f, &q, [0.3, -0.2, z_centre]);
            let d = r - z_centre;
            let cap = PI * d * d * (3.0 * r - d) / 3.0;
            let expected = RHO * G * cap;
            // Exact: the waterline layer's wet share is the volume below the waterline.
            assert!(
                (total[2] / expected - 1.0).abs() < 1e-12,
                "{} {expected}",
                total[2]
            );
            assert!(total[0].abs() < 1e-9 * expected && total[1].abs() < 1e-9 * expected);
            assert!(norm3(moment) < 1e-9 * expected, "{moment:?}");
        }
    }

    fn norm3(x: [f64; 3]) -> f64 {
        dot(x, x).sqrt()
    }

    /// A vertical cylinder heeled by phi: its righting moment about the centre of gravity G is
    /// rho g V GZ with the wall-sided formula GZ = sin(phi) (GM + BM tan^2(phi) / 2),
    /// GM = KB + BM - KG, BM = R^2 / (4 T) (exact while the waterline stays on the walls).
    #[test]
    fn heeled_cylinder_rights_itself_by_the_wall_sided_formula() {
        let (radius, draft, height, kg) = (1.0, 2.0, 4.0, 0.6);
        let phi: f64 = 0.12;
        // The keel at K; the hull's origin at K, G at kg above it along the axis.
        let axis = [0.0, phi.sin(), phi.cos()];
        // The keel so that the axis crosses the waterplane at T from it: the volume below
        // z = 0 is then pi R^2 T, the upright volume (the oblique cut of a cylinder holds the
        // volume of its length at the axis).
        let keel = [0.0, 0.0, -draft * phi.cos()];
        let hull = cylinder(radius, 0.0, height);
        let (f, q) = body(hull, keel, axis, still());
        let g_point: [f64; 3] = std::array::from_fn(|k| keel[k] + kg * axis[k]);
        let (total, moment) = resultant(&f, &q, g_point);
        let volume = PI * radius * radius * draft;
        let bm = radius * radius / (4.0 * draft);
        let gm = draft / 2.0 + bm - kg;
        let gz = phi.sin() * (gm + bm * phi.tan().powi(2) / 2.0);
        let expected = RHO * G * volume * gz;
        assert!(
            (total[2] / (RHO * G * volume) - 1.0).abs() < 2e-3,
            "{total:?}"
        );
        // The moment about +x turns the axis, heeled towards +y, back towards +z.
        assert!(
            (moment[0] / expected - 1.0).abs() < 0.01,
            "{moment:?} {expected}"
        );
    }

    /// The analytic Jacobian against central differences: a heeled cylinder half out of the
    /// water in waves and a current (with both stretchings), moving, and a sphere deep below
    /// water without a surface, in waves that are still growing (the ramp). The density is 1 kg/m^3: every term is proportional to it, and
    /// at sea water's the forces (1e5 N, sums of 700 cells) would leave the differences at
    /// h = 1e-6 with round-off of 1e-5, the check's tolerance.
    #[test]
    fn jacobian_matches_finite_differences() {
        let waves = [
            WaveSpec {
                amplitude: 0.8,
                omega: 0.9,
                direction: 0.4,
                phase: 0.1,
            },
            WaveSpec {
                amplitude: 0.3,
                omega: 1.4,
                direction: -0.3,
                phase: 2.0,
            },
        ];
        let current = Current::Uniform([0.3, 0.1, 0.0]);
        // Velocities far from the water's, so that no cell sits at the kink of |r| r.
        let v = vec![
            [2.2, -1.1, 1.3],
            [2.1, -1.0, 1.2],
            [2.3, -0.9, 1.1],
            [2.0, -1.2, 1.25],
        ];
        for stretching in [Stretching::Wheeler, Stretching::Vertical] {
            let mut water = Water::new(40.0, G, current.clone(), &waves, stretching).unwrap();
            water.ramp = 2.0; // t = 0.6 is inside the ramp: its rate enters the acceleration
            let hull = cylinder(0.8, -2.0, 1.5);
            let (f, q) = body_in(hull, [0.5, 0.2, 0.1], [0.1, 0.2, 1.0], water, 1.0);
            fd::check(&f, &q, &v, 0.6);
        }
        let mut deep = Water::everywhere(G);
        deep.current = Current::Uniform([0.5, 0.0, 0.1]);
        let sphere = Hull {
            sections: vec![HullSection::Sphere {
                centre: 0.0,
                radius: 0.5,
            }],
        };
        let (f, q) = body_in(sphere, [0.0, 0.0, -5.0], [0.0, 0.0, 1.0], deep, 1.0);
        fd::check(&f, &q, &v, 0.0);
    }
}
