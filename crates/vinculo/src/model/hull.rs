//! Hulls of floating and submerged bodies: stacks of axisymmetric sections about the body's
//! axis, cut into layers and cells for [`FloatingBody`] (`docs/theory/ocean.md`).
//!
//! A hull is given in its own frame: z along the body's axis (up when the body is upright),
//! sections between heights z0 < z1: a frustum of radii r0 at z0 and r1 at z1 (a cylinder when
//! they are equal, a cone when one is zero) or a whole sphere. Each section is cut into layers
//! of at most the hull's height over `layers`; a layer's volume is exact
//! (frustum: pi h (r0^2 + r0 r1 + r1^2) / 3, sphere segment: pi (R^2 h - ((z1-c)^3 - (z0-c)^3) / 3)).
//! A layer's cells share its wet fraction as a function of the waterline's height across it,
//! the exact share of the layer's volume below that height (a cubic: the sections' areas are
//! quadratics in z), so that an upright body's displaced volume is exact for any waterline.
//! A layer of volume V_l and thickness h is split into `RINGS` x `SECTORS` cells of equal volume
//! at radii r_e sqrt((k - 1/2) / RINGS), r_e = sqrt(V_l / (pi h)), and angles 2 pi m / SECTORS:
//! the equal-area rings make the cells' second moment of area about any horizontal axis
//! through the axis exactly pi r_e^4 / 4, that of the disk, so the waterplane's restoring
//! moment is right for the sections' radii.

use super::particle::{ForceId, ParticleId};
use super::System;
use crate::error::{finite_vector, non_negative, positive, Error, Result};
use crate::forces::{FloatingBody, Force, HullCell, HullLayer};
use crate::math::{cross, norm, scale, Vec3};
use std::f64::consts::PI;

/// Rings of cells per layer.
pub const RINGS: usize = 3;
/// Sectors of cells per ring.
pub const SECTORS: usize = 8;

/// One section of a hull, in the hull's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HullSection {
    /// A frustum from height `bottom` (radius `r_bottom`) to `top` (radius `r_top`).
    Frustum {
        /// Lower end z0 (m).
        bottom: f64,
        /// Upper end z1 (m).
        top: f64,
        /// Radius at z0 (m).
        r_bottom: f64,
        /// Radius at z1 (m).
        r_top: f64,
    },
    /// A whole sphere of radius `radius` centred at height `centre`.
    Sphere {
        /// Height of the centre (m).
        centre: f64,
        /// Radius (m).
        radius: f64,
    },
}

/// A stack of sections.
#[derive(Debug, Clone, PartialEq)]
pub struct Hull {
    /// The sections.
    pub sections: Vec<HullSection>,
}

/// A layer of a hull: its mid-height, thickness and volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerShape {
    /// Mid-height (m, hull frame).
    pub z: f64,
    /// Thickness (m).
    pub thickness: f64,
    /// Volume (m^3).
    pub volume: f64,
    /// The section's area at height z0 + u h, a0 + a1 u + a2 u^2 (m^2), u from 0 to 1 across
    /// the layer.
    pub area: [f64; 3],
}

impl HullSection {
    fn range(&self) -> (f64, f64) {
        match *self {
            HullSection::Frustum { bottom, top, .. } => (bottom, top),
            HullSection::Sphere { centre, radius } => (centre - radius, centre + radius),
        }
    }

    /// The coefficients of the area at z0 + u (z1 - z0), a quadratic in u.
    fn area_between(&self, z0: f64, z1: f64) -> [f64; 3] {
        let h = z1 - z0;
        match *self {
            HullSection::Frustum {
                bottom,
                top,
                r_bottom,
                r_top,
            } => {
                let r = |z: f64| r_bottom + (r_top - r_bottom) * (z - bottom) / (top - bottom);
                let (a, d) = (r(z0), r(z1) - r(z0));
                [PI * a * a, 2.0 * PI * a * d, PI * d * d]
            }
            HullSection::Sphere { centre, radius } => {
                let w = z0 - centre;
                [
                    PI * (radius * radius - w * w),
                    -2.0 * PI * w * h,
                    -PI * h * h,
                ]
            }
        }
    }

    /// The volume between heights z0 and z1 inside the section: (z1 - z0) times the mean of
    /// the quadratic area, a0 + a1 / 2 + a2 / 3 (exact for both kinds).
    fn volume_between(&self, z0: f64, z1: f64) -> f64 {
        let [a0, a1, a2] = self.area_between(z0, z1);
        (z1 - z0) * (a0 + a1 / 2.0 + a2 / 3.0)
    }
}

impl Hull {
    /// Checks the sections: finite, positive heights and radii.
    pub fn check(&self) -> Result<()> {
        if self.sections.is_empty() {
            return Err(Error::InvalidParameter {
                name: "hull".into(),
                value: 0.0,
                expected: "needs at least one section".into(),
            });
        }
        for (i, s) in self.sections.iter().enumerate() {
            let name = |f: &str| format!("{f} of hull section #{i}");
            match *s {
                HullSection::Frustum {
                    bottom,
                    top,
                    r_bottom,
                    r_top,
                } => {
                    crate::error::finite(name("bottom"), bottom)?;
                    crate::error::finite(name("top"), top)?;
                    if top <= bottom {
                        return Err(Error::InvalidParameter {
                            name: name("top"),
                            value: top,
                            expected: format!("must be above the bottom ({bottom})"),
                        });
                    }
                    non_negative(name("bottom radius"), r_bottom)?;
                    non_negative(name("top radius"), r_top)?;
                    positive(name("larger radius"), r_bottom.max(r_top))?;
                }
                HullSection::Sphere { centre, radius } => {
                    crate::error::finite(name("centre"), centre)?;
                    positive(name("radius"), radius)?;
                }
            }
        }
        Ok(())
    }

    /// Its volume (m^3; sections that overlap count twice).
    pub fn volume(&self) -> f64 {
        self.sections
            .iter()
            .map(|s| {
                let (a, b) = s.range();
                s.volume_between(a, b)
            })
            .sum()
    }

    /// The layers of every section, each at most `(top - bottom of the hull) / layers` thick.
    pub fn layers(&self, layers: usize) -> Vec<LayerShape> {
        let (lo, hi) = self
            .sections
            .iter()
            .map(HullSection::range)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (c, d)| {
                (a.min(c), b.max(d))
            });
        let target = (hi - lo) / layers.max(1) as f64;
        let mut out = Vec::new();
        for s in &self.sections {
            let (a, b) = s.range();
            let n = ((b - a) / target - 1e-9).ceil().max(1.0) as usize;
            let h = (b - a) / n as f64;
            for j in 0..n {
                let (z0, z1) = (a + h * j as f64, a + h * (j + 1) as f64);
                out.push(LayerShape {
                    z: 0.5 * (z0 + z1),
                    thickness: h,
                    volume: s.volume_between(z0, z1),
                    area: s.area_between(z0, z1),
                });
            }
        }
        out
    }
}

/// The placement and hydrodynamic data of a hull on a body, for
/// [`System::add_floating_body`].
#[derive(Debug, Clone, PartialEq)]
pub struct FloatingSpec {
    /// Where the hull's origin is at the start (m, world).
    pub origin: Vec3,
    /// The hull's axis (its z) at the start (world; normalised).
    pub axis: Vec3,
    /// Water density rho (kg/m^3, > 0).
    pub density: f64,
    /// Added-mass coefficient Ca (>= 0).
    pub ca: f64,
    /// Drag coefficient Cd (>= 0).
    pub cd: f64,
    /// Frontal area A of the drag (m^2, >= 0).
    pub drag_area: f64,
    /// The body's added mass (kg); None: Ca rho V0, V0 the volume under the still-water level
    /// at the start in the system's water (the whole hull in water without a surface),
    /// computed again when the water changes ([`System::set_water`]).
    pub added_mass: Option<f64>,
    /// Layers over the hull's height (>= 1).
    pub layers: usize,
}

impl System {
    /// Loads of the system's water ([`System::set_water`]) on a rigid body from its submerged
    /// volume: buoyancy, Froude-Krylov and the water's share of the added-mass force, drag
    /// (see [`FloatingBody`]). `frame`: four particles of the body, not coplanar; `centre`: the
    /// body's centre particle, which carries the added mass (needed when it is not zero).
    pub fn add_floating_body(
        &mut self,
        frame: &[ParticleId],
        centre: Option<ParticleId>,
        hull: &Hull,
        spec: &FloatingSpec,
    ) -> Result<ForceId> {
        let index = self.forces.len();
        let what = |f: &str| format!("{f} of floating body #{index}");
        hull.check()?;
        if frame.len() != 4 {
            return Err(Error::InvalidParameter {
                name: what("frame"),
                value: frame.len() as f64,
                expected: "give 4 particles of the body, not coplanar".into(),
            });
        }
        let origin = finite_vector(what("origin"), spec.origin)?;
        let axis = finite_vector(what("axis"), spec.axis)?;
        let length = norm(axis);
        if length == 0.0 {
            return Err(Error::InvalidVector {
                name: what("axis"),
                value: axis.to_vec(),
                expected: "give a non-zero direction".into(),
            });
        }
        let density = positive(what("water density"), spec.density)?;
        let ca = non_negative(what("added-mass coefficient Ca"), spec.ca)?;
        let cd = non_negative(what("drag coefficient Cd"), spec.cd)?;
        let area = non_negative(what("drag area"), spec.drag_area)?;
        if spec.layers == 0 {
            return Err(Error::InvalidParameter {
                name: what("layers"),
                value: 0.0,
                expected: "give at least 1".into(),
            });
        }
        // The hull's frame in the world at the start: e3 along the axis, e1, e2 across it.
        let e3 = scale(1.0 / length, axis);
        let helper = if e3[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = {
            let c = cross(helper, e3);
            scale(1.0 / norm(c), c)
        };
        let e2 = cross(e3, e1);
        let at = |x: f64, y: f64, z: f64| -> Vec3 {
            std::array::from_fn(|k| origin[k] + x * e1[k] + y * e2[k] + z * e3[k])
        };
        let in_frame = |p: Vec3| -> Result<[f64; 4]> {
            let point = self.point_in(frame, p)?;
            Ok([
                point.weights[0],
                point.weights[1],
                point.weights[2],
                point.weights[3],
            ])
        };
        let shapes = hull.layers(spec.layers);
        let mut layers = Vec::with_capacity(shapes.len());
        let mut cells = Vec::with_capacity(shapes.len() * RINGS * SECTORS);
        for (l, s) in shapes.iter().enumerate() {
            let centre_point = at(0.0, 0.0, s.z);
            // The share of the layer's volume below a waterline at u of its thickness,
            // (a0 u + a1 u^2 / 2 + a2 u^3 / 3) h / V_l.
            let scale = s.thickness / s.volume;
            layers.push(HullLayer {
                weights: in_frame(centre_point)?,
                thickness: s.thickness,
                fill: [
                    s.area[0] * scale,
                    s.area[1] * scale / 2.0,
                    s.area[2] * scale / 3.0,
                ],
            });
            let r_e = (s.volume / (PI * s.thickness)).sqrt();
            let dv = s.volume / (RINGS * SECTORS) as f64;
            for k in 0..RINGS {
                let r = r_e * ((k as f64 + 0.5) / RINGS as f64).sqrt();
                for m in 0..SECTORS {
                    let angle = 2.0 * PI * (m as f64 + 0.5 * (k % 2) as f64) / SECTORS as f64;
                    let p = at(r * angle.cos(), r * angle.sin(), s.z);
                    cells.push(HullCell {
                        weights: in_frame(p)?,
                        volume: dv,
                        layer: l,
                    });
                }
            }
        }
        let added_mass = match spec.added_mass {
            Some(m) => non_negative(what("added mass"), m)?,
            None => ca * density * hull.volume(), // the default, set below from the water
        };
        let added = match (centre, added_mass > 0.0) {
            (Some(c), _) => Some((self.check(c)?, added_mass)),
            (None, false) => None,
            (None, true) => {
                return Err(Error::InvalidParameter {
                    name: what("added mass"),
                    value: added_mass,
                    expected: "needs the body's centre particle to carry it: give a body with \
                               a centre particle (7 particles), or Ca = 0"
                        .into(),
                })
            }
        };
        let frame_indices = [
            self.check(frame[0])?,
            self.check(frame[1])?,
            self.check(frame[2])?,
            self.check(frame[3])?,
        ];
        let volume = hull.volume();
        let mut element = FloatingBody {
            frame: frame_indices,
            cells,
            layers,
            density,
            ca,
            drag: 0.5 * density * cd * area / volume,
            added,
            added_from_volume: spec.added_mass.is_none(),
            water: self.water.clone(),
            gravity: self.gravity(),
        };
        element.default_added_mass(&self.initial_positions());
        self.forces.push(Force::FloatingBody(Box::new(element)));
        Ok(ForceId(index))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Layer volumes add up to the closed-form volumes of a sphere and of a cone frustum.
    #[test]
    fn layers_hold_the_sections_volumes() {
        let sphere = Hull {
            sections: vec![HullSection::Sphere {
                centre: 0.3,
                radius: 1.5,
            }],
        };
        let total: f64 = sphere.layers(17).iter().map(|l| l.volume).sum();
        assert!((total - 4.0 / 3.0 * PI * 1.5f64.powi(3)).abs() < 1e-12);
        let frustum = Hull {
            sections: vec![HullSection::Frustum {
                bottom: -2.0,
                top: 1.0,
                r_bottom: 1.0,
                r_top: 0.5,
            }],
        };
        let total: f64 = frustum.layers(9).iter().map(|l| l.volume).sum();
        let exact = PI * 3.0 * (1.0 + 0.5 + 0.25) / 3.0;
        assert!((total - exact).abs() < 1e-12 && (frustum.volume() - exact).abs() < 1e-12);
    }
}
