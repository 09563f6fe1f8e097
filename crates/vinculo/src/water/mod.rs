//! The water around the particles: a current profile and linear waves, and the flow they make
//! at any point and time (`docs/theory/ocean.md`).
//!
//! z points up; the still-water level is z = 0 and the seabed z = -h (h may be infinite). The
//! flow at (x, t) is the sum of the wave components' linear (Airy) flow ([`airy`]) and the
//! current ([`current`]). Linear theory gives the flow below z = 0; above it, up to the wave
//! crest, the flow is continued by one of two [`Stretching`] rules:
//!
//! - Wheeler: the linear flow at the stretched height z' = h (z - eta) / (h + eta) (deep water:
//!   z - eta), which maps the instantaneous surface z = eta to z = 0 and keeps the seabed;
//! - vertical: the flow at z = 0 for every z > 0 (OrcaFlex calls this vertical stretching).
//!
//! Above the instantaneous surface there is no water; [`Water::flow`] then gives the flow at
//! the surface (z' = 0 for Wheeler), and the forces that use it decide how much of an element
//! is wet from the elevation it also returns. The accelerations are the local ones, du/dt at a
//! fixed point of the linear field, evaluated at the stretched height.
//!
//! The gradients are those of the flow as evaluated, stretching included: with
//! J = grad z', d u_i / d x_j = (d u_i / d x_j)_lin + (d u_i / d z)_lin J_j (j horizontal) and
//! (d u_i / d z)_lin J_z, where for Wheeler J = (-h (h + z) / (h + eta)^2 grad eta, h / (h + eta))
//! below the surface and 0 above it.

pub mod airy;
pub mod current;

pub use airy::{wave_number, LinearFlow, WaveComponent};
pub use current::Current;

use crate::error::{finite, non_negative, positive, Error, Result};
use crate::math::{Mat3, Vec3};

/// How the linear wave flow is continued above the still-water level (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stretching {
    /// Wheeler (1970): the flow at z' = h (z - eta) / (h + eta).
    #[default]
    Wheeler,
    /// The flow at z = 0 for every z above it.
    Vertical,
}

/// One wave component as given: amplitude (m), angular frequency (rad/s), direction of travel
/// (rad from the x axis towards y), phase (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveSpec {
    /// Amplitude a (m, >= 0).
    pub amplitude: f64,
    /// Angular frequency omega (rad/s, > 0).
    pub omega: f64,
    /// Direction beta (rad).
    pub direction: f64,
    /// Phase eps (rad).
    pub phase: f64,
}

/// Still water, a current, waves: everything that makes the flow.
#[derive(Debug, Clone, PartialEq)]
pub struct Water {
    /// Depth h (m; infinite: deep water).
    pub depth: f64,
    /// Gravity g (m/s^2).
    pub g: f64,
    /// The current profile.
    pub current: Current,
    /// The wave components.
    pub waves: Vec<WaveComponent>,
    /// Above the still-water level.
    pub stretching: Stretching,
    /// Whether the water has its free surface at z = eta (above it there is no water); false
    /// for water that fills all space ([`Water::everywhere`]).
    pub free_surface: bool,
    /// The waves grow from nothing over this time (s; 0: full from the start): every wave
    /// quantity is multiplied by s(t) = (1 - cos(pi t / T)) / 2 for t < T, so that a run
    /// started from still-water equilibrium meets no sudden load.
    pub ramp: f64,
}

/// The flow at one point and time (module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flow {
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Local acceleration (m/s^2).
    pub acceleration: Vec3,
    /// Dynamic pressure of the waves over the density (m^2/s^2).
    pub pressure: f64,
    /// d velocity_i / d x_j (filled when asked for).
    pub velocity_gradient: Mat3,
    /// d acceleration_i / d x_j (filled when asked for).
    pub acceleration_gradient: Mat3,
    /// The surface elevation eta above the point (m).
    pub elevation: f64,
    /// Its horizontal gradient.
    pub elevation_gradient: [f64; 2],
}

impl Water {
    /// Still water that fills all space, without a surface (a system's water until it is
    /// given another, [`crate::model::System::set_water`]).
    pub fn everywhere(g: f64) -> Water {
        Water {
            depth: f64::INFINITY,
            g,
            current: Current::none(),
            waves: Vec::new(),
            stretching: Stretching::Wheeler,
            free_surface: false,
            ramp: 0.0,
        }
    }

    /// Water below a free surface at z = eta, with a current and waves, every value checked: depth > 0 (or infinite), g > 0,
    /// g > 0 when there are waves, amplitudes >= 0, frequencies > 0, finite directions and phases, a power law's exponent
    /// > 0, a table's heights increasing.
    pub fn new(
        depth: f64,
        g: f64,
        current: Current,
        waves: &[WaveSpec],
        stretching: Stretching,
    ) -> Result<Water> {
        if depth.is_nan() || depth <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "water depth".into(),
                value: depth,
                expected: "must be > 0 (infinite for deep water)".into(),
            });
        }
        let g = if waves.is_empty() {
            non_negative("gravity g of the water", g)?
        } else {
            positive("gravity g of the water (waves need it)", g)?
        };
        check_current(&current)?;
        let waves = waves
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let name = |f: &str| format!("{f} of wave component #{i}");
                Ok(WaveComponent::new(
                    non_negative(name("amplitude"), w.amplitude)?,
                    positive(name("angular frequency"), w.omega)?,
                    finite(name("direction"), w.direction)?,
                    finite(name("phase"), w.phase)?,
                    depth,
                    g,
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Water {
            depth,
            g,
            current,
            waves,
            stretching,
            free_surface: true,
            ramp: 0.0,
        })
    }

    /// Whether the water is still (no current, no waves): its flow is zero everywhere.
    #[inline]
    pub fn is_still(&self) -> bool {
        self.waves.is_empty() && self.current.is_zero()
    }

    /// Whether the elements in this water must evaluate its flow: it moves, or it has a free
    /// surface (whose elevation decides what is wet).
    #[inline]
    pub fn needs_flow(&self) -> bool {
        self.free_surface || !self.is_still()
    }

    /// The ramp factor s(t) of the waves and its rate ([`Water::ramp`]).
    pub fn ramp_factor(&self, t: f64) -> (f64, f64) {
        if self.ramp <= 0.0 || t >= self.ramp {
            return (1.0, 0.0);
        }
        if t <= 0.0 {
            return (0.0, 0.0);
        }
        let w = std::f64::consts::PI / self.ramp;
        (0.5 * (1.0 - (w * t).cos()), 0.5 * w * (w * t).sin())
    }

    /// The elevation eta, its horizontal gradient and its rate at (x, y, t).
    pub fn surface(&self, x: f64, y: f64, t: f64) -> (f64, [f64; 2], f64) {
        let mut out = (0.0, [0.0; 2], 0.0);
        for c in &self.waves {
            let (e, g, r) = c.surface(x, y, t);
            out.0 += e;
            out.1[0] += g[0];
            out.1[1] += g[1];
            out.2 += r;
        }
        let (s, ds) = self.ramp_factor(t);
        (
            s * out.0,
            [s * out.1[0], s * out.1[1]],
            s * out.2 + ds * out.0,
        )
    }

    /// The Hessian of the elevation at (x, y, t) (horizontal second derivatives).
    pub fn surface_hessian(&self, x: f64, y: f64, t: f64) -> [[f64; 2]; 2] {
        let mut out = [[0.0; 2]; 2];
        let (s, _) = self.ramp_factor(t);
        for c in &self.waves {
            let h = c.surface_hessian(x, y, t);
            for i in 0..2 {
                for j in 0..2 {
                    out[i][j] += s * h[i][j];
                }
            }
        }
        out
    }

    /// The flow at `point` and time `t` (gradients only when `gradients`).
    pub fn flow(&self, point: Vec3, t: f64, gradients: bool) -> Flow {
        let mut flow = Flow::default();
        if !self.waves.is_empty() {
            // The components' phase angles, once: for the elevation, then the flow.
            let (s, ds) = self.ramp_factor(t);
            let mut angles =
                smallvec::SmallVec::<[(f64, f64); 64]>::with_capacity(self.waves.len());
            let (mut eta, mut slope) = (0.0, [0.0; 2]);
            for c in &self.waves {
                let angle = c.angle(point[0], point[1], t).sin_cos();
                angles.push(angle);
                let (e, g, _) = c.surface_at(angle);
                eta += e;
                slope[0] += g[0];
                slope[1] += g[1];
            }
            let (eta, slope) = (s * eta, [s * slope[0], s * slope[1]]);
            flow.elevation = eta;
            flow.elevation_gradient = slope;
            let (zs, jac) = self.stretched(point[2], eta, slope);
            let mut lin = LinearFlow::default();
            for (c, &angle) in self.waves.iter().zip(&angles) {
                c.add_flow_at(angle, zs, self.g, gradients, &mut lin);
            }
            // The ramp: s u, s a + s' u, s p, and the gradients likewise.
            flow.velocity = lin.velocity.map(|u| s * u);
            flow.acceleration =
                std::array::from_fn(|i| s * lin.acceleration[i] + ds * lin.velocity[i]);
            flow.pressure = s * lin.pressure;
            if gradients {
                let gu = chain(&lin.velocity_gradient, jac);
                let ga = chain(&lin.acceleration_gradient, jac);
                flow.velocity_gradient = gu.map(|r| r.map(|g| s * g));
                flow.acceleration_gradient =
                    std::array::from_fn(|i| std::array::from_fn(|j| s * ga[i][j] + ds * gu[i][j]));
            }
        }
        let (u, du) = self.current.velocity(point[2]);
        for i in 0..3 {
            flow.velocity[i] += u[i];
            if gradients && point[2] < 0.0 {
                flow.velocity_gradient[i][2] += du[i];
            }
        }
        flow
    }

    /// The height z' at which the linear flow is evaluated for a point at height `z` under the
    /// elevation `eta` of slope `slope`, and its gradient J (module documentation).
    fn stretched(&self, z: f64, eta: f64, slope: [f64; 2]) -> (f64, Vec3) {
        match self.stretching {
            Stretching::Vertical => {
                if z <= 0.0 {
                    (z, [0.0, 0.0, 1.0])
                } else {
                    (0.0, [0.0; 3])
                }
            }
            Stretching::Wheeler => {
                if z >= eta {
                    return (0.0, [0.0; 3]);
                }
                let h = self.depth;
                if !h.is_finite() {
                    return (z - eta, [-slope[0], -slope[1], 1.0]);
                }
                let d = h + eta;
                let dh = -h * (h + z) / (d * d);
                (h * (z - eta) / d, [dh * slope[0], dh * slope[1], h / d])
            }
        }
    }
}

/// The gradient of u(x, y, z'(x, y, z)) from the linear gradient `g` (in x, y, z') and
/// J = grad z'.
fn chain(g: &Mat3, jac: Vec3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        out[i][0] = g[i][0] + g[i][2] * jac[0];
        out[i][1] = g[i][1] + g[i][2] * jac[1];
        out[i][2] = g[i][2] * jac[2];
    }
    out
}

fn check_current(current: &Current) -> Result<()> {
    let vector = |name: &str, u: Vec3| crate::error::finite_vector(name, u).map(|_| ());
    match current {
        Current::Uniform(u) => vector("current velocity", *u),
        Current::PowerLaw {
            surface,
            exponent,
            depth,
        } => {
            vector("current velocity at the surface", *surface)?;
            positive("exponent of the current's power law", *exponent)?;
            positive("depth of the current's power law", *depth)?;
            Ok(())
        }
        Current::Table { z, velocity } => {
            if z.is_empty() || z.len() != velocity.len() {
                return Err(Error::InvalidParameter {
                    name: "current table".into(),
                    value: z.len() as f64,
                    expected: format!(
                        "needs one velocity per height and at least one height (got {} heights, \
                         {} velocities)",
                        z.len(),
                        velocity.len()
                    ),
                });
            }
            for (i, (&zi, &u)) in z.iter().zip(velocity).enumerate() {
                finite(format!("height #{i} of the current table"), zi)?;
                vector(&format!("velocity #{i} of the current table"), u)?;
                if i > 0 && zi <= z[i - 1] {
                    return Err(Error::InvalidParameter {
                        name: format!("height #{i} of the current table"),
                        value: zi,
                        expected: format!("must be above the one before ({})", z[i - 1]),
                    });
                }
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sea(stretching: Stretching) -> Water {
        let waves = [
            WaveSpec {
                amplitude: 1.2,
                omega: 0.7,
                direction: 0.2,
                phase: 0.5,
            },
            WaveSpec {
                amplitude: 0.6,
                omega: 1.1,
                direction: -0.4,
                phase: 2.0,
            },
        ];
        let current = Current::PowerLaw {
            surface: [0.8, 0.1, 0.0],
            exponent: 1.0 / 7.0,
            depth: 40.0,
        };
        Water::new(40.0, 9.81, current, &waves, stretching).unwrap()
    }

    /// The stretched flow's gradients against central differences, below the still-water level,
    /// between it and a crest, and above the surface; for both stretchings.
    #[test]
    fn stretched_gradients_match_finite_differences() {
        for stretching in [Stretching::Wheeler, Stretching::Vertical] {
            let w = sea(stretching);
            let t = 1.7;
            let (x, y) = (3.0, -1.0);
            let (eta, _, _) = w.surface(x, y, t);
            assert!(eta > 0.3, "the test wants a crest: eta = {eta}");
            for z in [-12.0, 0.5 * eta, eta + 0.4] {
                let p = [x, y, z];
                let f = w.flow(p, t, true);
                let h = 1e-6;
                for j in 0..3 {
                    let (mut pp, mut pm) = (p, p);
                    pp[j] += h;
                    pm[j] -= h;
                    let (fp, fm) = (w.flow(pp, t, false), w.flow(pm, t, false));
                    for i in 0..3 {
                        let du = (fp.velocity[i] - fm.velocity[i]) / (2.0 * h);
                        let da = (fp.acceleration[i] - fm.acceleration[i]) / (2.0 * h);
                        let what = format!("{stretching:?} z {z} d{i}/dx{j}");
                        assert!((du - f.velocity_gradient[i][j]).abs() < 1e-7, "u {what}");
                        assert!(
                            (da - f.acceleration_gradient[i][j]).abs() < 1e-7,
                            "a {what}"
                        );
                    }
                }
            }
        }
    }

    /// Wheeler's stretching puts the still-water level's flow at the crest, and leaves the
    /// seabed's flow where it was.
    #[test]
    fn wheeler_maps_the_surface_to_the_still_water_level() {
        let w = sea(Stretching::Wheeler);
        let mut waves_only = w.clone();
        waves_only.current = Current::none();
        let (x, y, t) = (3.0, -1.0, 1.7);
        let (eta, _, _) = w.surface(x, y, t);
        let at_crest = waves_only.flow([x, y, eta], t, false);
        let mut linear = LinearFlow::default();
        for c in &w.waves {
            c.add_flow([x, y, 0.0], t, w.g, false, &mut linear);
        }
        assert_eq!(at_crest.velocity, linear.velocity);
        let bottom = waves_only.flow([x, y, -40.0], t, false);
        assert!(bottom.velocity[2].abs() < 1e-15);
    }

    /// With a ramp, the acceleration is the time derivative of the ramped velocity, the rate
    /// of the elevation that of the ramped elevation (central differences), and the waves are
    /// whole after the ramp.
    #[test]
    fn ramped_waves_keep_their_derivatives() {
        let mut w = sea(Stretching::Vertical);
        w.current = Current::none();
        w.ramp = 6.0;
        let p = [2.0, 1.0, -5.0];
        let h = 1e-6;
        for t in [0.7, 3.0, 5.9] {
            let f = w.flow(p, t, false);
            let (fp, fm) = (w.flow(p, t + h, false), w.flow(p, t - h, false));
            for i in 0..3 {
                let dudt = (fp.velocity[i] - fm.velocity[i]) / (2.0 * h);
                assert!((dudt - f.acceleration[i]).abs() < 1e-7, "t {t} du{i}/dt");
            }
            let (_, _, rate) = w.surface(p[0], p[1], t);
            let fd = (w.surface(p[0], p[1], t + h).0 - w.surface(p[0], p[1], t - h).0) / (2.0 * h);
            assert!((fd - rate).abs() < 1e-7);
        }
        let mut whole = w.clone();
        whole.ramp = 0.0;
        assert_eq!(w.flow(p, 6.5, true), whole.flow(p, 6.5, true));
        assert_eq!(w.flow(p, 0.0, false).velocity, [0.0; 3]);
    }

    #[test]
    fn bad_input_is_named() {
        let bad = WaveSpec {
            amplitude: 1.0,
            omega: -1.0,
            direction: 0.0,
            phase: 0.0,
        };
        let e = Water::new(10.0, 9.81, Current::none(), &[bad], Stretching::Wheeler).unwrap_err();
        assert!(
            e.to_string()
                .contains("angular frequency of wave component #0"),
            "{e}"
        );
        let e = Water::new(-1.0, 9.81, Current::none(), &[], Stretching::Wheeler).unwrap_err();
        assert!(e.to_string().contains("water depth"), "{e}");
        let table = Current::Table {
            z: vec![-10.0, -20.0],
            velocity: vec![[0.0; 3]; 2],
        };
        let e = Water::new(30.0, 9.81, table, &[], Stretching::Wheeler).unwrap_err();
        assert!(
            e.to_string().contains("height #1 of the current table"),
            "{e}"
        );
    }
}
