//! Steady current profiles over depth (z up, still-water level z = 0, seabed z = -h).
//!
//! - uniform: U(z) = U0;
//! - power law: U(z) = U_s ((z + h) / h)^alpha, the surface value U_s at z = 0 and zero at the
//!   seabed (alpha = 1/7 is the usual tidal profile, DNV-RP-C205 4.1.3);
//! - table: U linear between given depths, constant beyond the first and the last.
//!
//! Above the still-water level every profile keeps its value at z = 0. The current's
//! acceleration is zero; its gradient has only the column d U / dz.

use crate::math::Vec3;

/// A steady current profile.
#[derive(Debug, Clone, PartialEq)]
pub enum Current {
    /// The same velocity at every depth (m/s).
    Uniform(Vec3),
    /// U_s ((z + h) / h)^alpha, zero at and below the seabed.
    PowerLaw {
        /// Velocity at the still-water level U_s (m/s).
        surface: Vec3,
        /// Exponent alpha (> 0).
        exponent: f64,
        /// Water depth h (m).
        depth: f64,
    },
    /// Linear interpolation between (z_i, U_i), z increasing.
    Table {
        /// Heights z_i (m, increasing).
        z: Vec<f64>,
        /// Velocities U_i (m/s).
        velocity: Vec<Vec3>,
    },
}

impl Current {
    /// No current.
    pub fn none() -> Current {
        Current::Uniform([0.0; 3])
    }

    /// Whether the current is zero everywhere.
    #[inline]
    pub fn is_zero(&self) -> bool {
        match self {
            Current::Uniform(u) => *u == [0.0; 3],
            Current::PowerLaw { surface, .. } => *surface == [0.0; 3],
            Current::Table { velocity, .. } => velocity.iter().all(|u| *u == [0.0; 3]),
        }
    }

    /// The velocity at height `z` and its derivative in z.
    pub fn velocity(&self, z: f64) -> (Vec3, Vec3) {
        let z = z.min(0.0);
        match self {
            Current::Uniform(u) => (*u, [0.0; 3]),
            Current::PowerLaw {
                surface,
                exponent,
                depth,
            } => {
                let s = (z + depth) / depth;
                if s <= 0.0 {
                    return ([0.0; 3], [0.0; 3]);
                }
                let f = s.powf(*exponent);
                // d/dz of s^alpha with ds/dz = 1/h; z = 0 is the kink of the extension above
                // the surface, where the derivative from below is kept.
                let df = exponent * f / s / depth;
                (surface.map(|u| u * f), surface.map(|u| u * df))
            }
            Current::Table { z: zs, velocity } => {
                let n = zs.len();
                if z <= zs[0] {
                    return (velocity[0], [0.0; 3]);
                }
                if z >= zs[n - 1] {
                    return (velocity[n - 1], [0.0; 3]);
                }
                let i = zs.partition_point(|&zi| zi <= z) - 1;
                let w = (z - zs[i]) / (zs[i + 1] - zs[i]);
                let du = std::array::from_fn(|k| {
                    (velocity[i + 1][k] - velocity[i][k]) / (zs[i + 1] - zs[i])
                });
                let u = std::array::from_fn(|k| velocity[i][k] + w * (zs[i + 1] - zs[i]) * du[k]);
                (u, du)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The power law at a few heights against the formula, and its derivative against central
    /// differences; the table interpolates linearly and is flat beyond its ends.
    #[test]
    fn profiles_against_their_formulas() {
        let c = Current::PowerLaw {
            surface: [1.2, -0.4, 0.0],
            exponent: 1.0 / 7.0,
            depth: 50.0,
        };
        for z in [-49.0, -25.0, -3.0] {
            let (u, du) = c.velocity(z);
            let f = ((z + 50.0) / 50.0_f64).powf(1.0 / 7.0);
            assert!((u[0] - 1.2 * f).abs() < 1e-15 && (u[1] + 0.4 * f).abs() < 1e-15);
            let h = 1e-6;
            let fd = (c.velocity(z + h).0[0] - c.velocity(z - h).0[0]) / (2.0 * h);
            assert!((fd - du[0]).abs() < 1e-8);
        }
        assert_eq!(c.velocity(2.0).0, c.velocity(0.0).0);
        assert_eq!(c.velocity(-60.0).0, [0.0; 3]);
        let t = Current::Table {
            z: vec![-40.0, -10.0, 0.0],
            velocity: vec![[0.1, 0.0, 0.0], [0.4, 0.0, 0.0], [0.6, 0.2, 0.0]],
        };
        let (u, du) = t.velocity(-25.0);
        assert!((u[0] - 0.25).abs() < 1e-15 && (du[0] - 0.01).abs() < 1e-15);
        assert_eq!(t.velocity(-100.0).0, [0.1, 0.0, 0.0]);
        assert_eq!(t.velocity(3.0).0, [0.6, 0.2, 0.0]);
    }
}
