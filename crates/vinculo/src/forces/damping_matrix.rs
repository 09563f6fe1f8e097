//! A linear velocity coupling over any number of particles: f = -D v with a constant
//! (3n x 3n) matrix D, row 3p + k the force component k on particle p, column 3r + l the
//! velocity component l of particle r. df/dv = -D (its 3x3 blocks), df/dq = 0.
//!
//! Besides damping matrices (a dashpot network, a linearised drag), it carries linear
//! first-order systems x' = A x + B u whose states are velocities of auxiliary particles of
//! mass mu: their rows mu (A x + B u) are such a coupling (`vinculo.ocean.bem`, the radiation
//! memory of a floating body as a state-space model).

use super::Jacobian;
use crate::local::PerParticle;
use crate::math::Vec3;

/// f = -D v over `particles`.
#[derive(Debug, Clone, PartialEq)]
pub struct DampingMatrix {
    /// The particles, in the order of D's blocks.
    pub particles: Vec<usize>,
    /// D, row-major, (3n)^2 entries (N s/m).
    pub matrix: Vec<f64>,
}

impl DampingMatrix {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn force(&self, _q: &[Vec3], v: &[Vec3], _t: f64) -> PerParticle {
        let n = 3 * self.particles.len();
        let u: Vec<f64> = self.particles.iter().flat_map(|&p| v[p]).collect();
        let mut out = PerParticle::from_elem([0.0; 3], self.particles.len());
        for row in 0..n {
            let d = &self.matrix[row * n..(row + 1) * n];
            out[row / 3][row % 3] = -d.iter().zip(&u).map(|(a, b)| a * b).sum::<f64>();
        }
        out
    }

    pub(crate) fn add_jacobian(
        &self,
        _q: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        _dq: &mut Jacobian,
        dv: &mut Jacobian,
    ) {
        let n = 3 * self.particles.len();
        for row in 0..n {
            for col in 0..n {
                dv[row / 3][col / 3][row % 3][col % 3] -= self.matrix[row * n + col];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Force};
    use super::*;

    /// The force is -D v for a general (non-symmetric) D over three particles, one of them
    /// repeated elsewhere in the system's order, and the Jacobian matches finite differences.
    #[test]
    fn force_and_jacobian_of_a_general_matrix() {
        let n = 9;
        let matrix: Vec<f64> = (0..n * n)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) * 0.3)
            .collect();
        let element = DampingMatrix {
            particles: vec![2, 0, 3],
            matrix: matrix.clone(),
        };
        let q = vec![[0.0; 3]; 4];
        let v = vec![
            [0.1, -0.2, 0.3],
            [9.0, 9.0, 9.0],
            [-0.4, 0.5, 0.6],
            [0.7, 0.8, -0.9],
        ];
        let f = element.force(&q, &v, 0.0);
        let u: Vec<f64> = [2, 0, 3].iter().flat_map(|&p| v[p]).collect();
        for row in 0..n {
            let expected: f64 = -(0..n).map(|c| matrix[row * n + c] * u[c]).sum::<f64>();
            assert!((f[row / 3][row % 3] - expected).abs() < 1e-15);
        }
        fd::check(&Force::DampingMatrix(Box::new(element)), &q, &v, 0.0);
    }
}
