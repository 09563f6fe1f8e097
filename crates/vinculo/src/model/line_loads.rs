//! Adding the loads of a line's nodes to a system: seabed contact with friction, and the
//! node's hydrodynamics ([`crate::forces::SeabedContact`], [`crate::forces::LineHydro`]).

use super::particle::{ForceId, ParticleId};
use super::System;
use crate::error::{finite, non_negative, positive, Error, Result};
use std::sync::Arc;

use crate::forces::SeabedSurface;
use crate::forces::{Force, LineHydro, LineNode, SeabedContact, SeabedFriction, SeabedGrid};

/// A seabed and its contact law, MoorDyn's parameters, for [`System::add_seabed_contact`].
#[derive(Debug, Clone, PartialEq)]
pub struct SeabedSpec {
    /// Water depth (m): the seabed is the plane z = -depth, unless `grid` is given.
    pub depth: f64,
    /// Heights of a seabed that varies (MoorDyn's 3D seafloor), shared by the nodes; None: the
    /// plane z = -depth.
    pub grid: Option<Arc<SeabedGrid>>,
    /// Volume-equivalent diameter d of the line (m, > 0).
    pub diameter: f64,
    /// Length l of line the node stands for (m, > 0; half a segment each side).
    pub length: f64,
    /// kBot (Pa/m, >= 0), MoorDyn's default 3e6.
    pub stiffness: f64,
    /// cBot (Pa s/m, >= 0), MoorDyn's default 3e5.
    pub damping: f64,
    /// Penetration over which the damping ramps up from zero (m, >= 0); 0: MoorDyn's law.
    pub damping_ramp: f64,
    /// Friction (coefficients >= 0, FricDamp > 0, StatDynFricScale >= 1; no axial
    /// coefficient: MoorDyn-C's isotropic friction).
    pub friction: SeabedFriction,
}

/// A line node's hydrodynamic data, MoorDyn's coefficients, for
/// [`System::add_line_hydrodynamics`].
#[derive(Debug, Clone, PartialEq)]
pub struct LineHydroSpec {
    /// Water density rho (kg/m^3, > 0).
    pub density: f64,
    /// Volume-equivalent diameter d (m, > 0).
    pub diameter: f64,
    /// Length l of line the node stands for (m, > 0).
    pub length: f64,
    /// Normal drag coefficient Cd (>= 0).
    pub cd: f64,
    /// Axial drag coefficient CdAx (>= 0).
    pub cdax: f64,
    /// Normal added-mass coefficient Ca (>= 0).
    pub ca: f64,
    /// Axial added-mass coefficient CaAx (>= 0).
    pub caax: f64,
}

impl System {
    /// The node of a line element: `tangent` (a, b) gives t = unit(q_b - q_a).
    fn line_node(
        &self,
        what: &str,
        node: ParticleId,
        tangent: Option<(ParticleId, ParticleId)>,
    ) -> Result<LineNode> {
        let i = self.check(node)?;
        let tangent = match tangent {
            Some((a, b)) => {
                let (a, b) = (self.check(a)?, self.check(b)?);
                if a == b {
                    return Err(Error::SameParticle {
                        what: format!("tangent of {what} (give two different particles)"),
                        particle: a,
                    });
                }
                Some([a, b])
            }
            None => None,
        };
        Ok(LineNode::new(i, tangent))
    }

    /// Contact of line node `node` with the seabed (the plane z = -depth, or the heights of
    /// `spec.grid`), with MoorDyn's normal
    /// stiffness and damping per unit area and its regularised Coulomb friction, separate along
    /// and across the line. `tangent` = (a, b): the line's direction at the node is the one
    /// from particle a to particle b (MoorDyn: the node's two neighbours, or the node and its
    /// one neighbour at an end); `None`: isotropic friction with the transverse coefficient.
    /// See [`SeabedContact`] for the equations.
    pub fn add_seabed_contact(
        &mut self,
        node: ParticleId,
        tangent: Option<(ParticleId, ParticleId)>,
        spec: &SeabedSpec,
    ) -> Result<ForceId> {
        let index = self.forces.len();
        let what = format!("seabed contact #{index}");
        let element_node = self.line_node(&what, node, tangent)?;
        let field = |f: &str| format!("{f} of {what} (node {})", element_node.node());
        let fr = &spec.friction;
        let static_scale = finite(field("static/dynamic friction scale"), fr.static_scale)?;
        if static_scale < 1.0 {
            return Err(Error::InvalidParameter {
                name: field("static/dynamic friction scale"),
                value: static_scale,
                expected: "must be >= 1 (static friction is at least the kinetic one)".into(),
            });
        }
        let element = SeabedContact {
            seabed: match &spec.grid {
                Some(grid) => SeabedSurface::Grid(Arc::clone(grid)),
                None => SeabedSurface::Flat(-finite(field("water depth"), spec.depth)?),
            },
            area: positive(field("diameter"), spec.diameter)?
                * positive(field("node length"), spec.length)?,
            stiffness: non_negative(field("seabed stiffness kBot"), spec.stiffness)?,
            damping: non_negative(field("seabed damping cBot"), spec.damping)?,
            damping_ramp: non_negative(field("damping ramp"), spec.damping_ramp)?,
            friction: SeabedFriction {
                transverse: non_negative(field("friction coefficient"), fr.transverse)?,
                axial: fr
                    .axial
                    .map(|a| non_negative(field("axial friction coefficient"), a))
                    .transpose()?,
                damping: positive(field("friction damping"), fr.damping)?,
                static_scale,
            },
            node: element_node,
        };
        self.forces.push(Force::SeabedContact(Box::new(element)));
        Ok(ForceId(index))
    }

    /// Buoyancy, normal and axial drag and added mass of line node `node` in water, with
    /// MoorDyn's coefficients, on the velocity relative to the system's water
    /// ([`System::set_water`]: still water everywhere by default). `tangent` as for
    /// [`System::add_seabed_contact`] (`None`: isotropic drag with Cd). See [`LineHydro`] for
    /// the equations and the added mass.
    pub fn add_line_hydrodynamics(
        &mut self,
        node: ParticleId,
        tangent: Option<(ParticleId, ParticleId)>,
        spec: &LineHydroSpec,
    ) -> Result<ForceId> {
        let index = self.forces.len();
        let what = format!("line hydrodynamics #{index}");
        let element_node = self.line_node(&what, node, tangent)?;
        let field = |f: &str| format!("{f} of {what} (node {})", element_node.node());
        let element = LineHydro {
            density: positive(field("water density"), spec.density)?,
            diameter: positive(field("diameter"), spec.diameter)?,
            length: positive(field("node length"), spec.length)?,
            cd: non_negative(field("normal drag coefficient Cd"), spec.cd)?,
            cdax: non_negative(field("axial drag coefficient CdAx"), spec.cdax)?,
            ca: non_negative(field("normal added-mass coefficient Ca"), spec.ca)?,
            caax: non_negative(field("axial added-mass coefficient CaAx"), spec.caax)?,
            water: self.water.clone(),
            gravity: self.gravity(),
            node: element_node,
        };
        self.forces.push(Force::LineHydro(Box::new(element)));
        Ok(ForceId(index))
    }
}
