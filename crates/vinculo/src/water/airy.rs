//! One linear (Airy) wave component in water of depth h (`docs/theory/ocean.md`).
//!
//! z points up, the still-water level is z = 0 and the seabed z = -h. A component of amplitude
//! a, angular frequency omega, direction beta (the unit vector e = (cos beta, sin beta) along
//! which it travels) and phase eps has the phase angle theta = k e . x - omega t + eps, with k
//! the root of the dispersion relation omega^2 = g k tanh(k h) ([`wave_number`]). Its velocity
//! potential phi = (g a / omega) cosh(k (z + h)) / cosh(k h) sin(theta) gives (Dean and
//! Dalrymple, *Water Wave Mechanics for Engineers and Scientists*, 1991, ch. 4):
//!
//! ```text
//! eta   = a cos(theta)                                  elevation
//! u_h   = a omega C(z) cos(theta) e                     horizontal velocity
//! w     = a omega S(z) sin(theta)                       vertical velocity
//! du_h/dt = a omega^2 C(z) sin(theta) e                 local accelerations
//! dw/dt = -a omega^2 S(z) cos(theta)
//! p     = rho g a K(z) cos(theta)                       dynamic pressure, -rho dphi/dt
//! ```
//!
//! with C = cosh(k(z+h))/sinh(kh), S = sinh(k(z+h))/sinh(kh), K = cosh(k(z+h))/cosh(kh),
//! written as (e^{kz} +- e^{-k(z+2h)}) / (1 -+ e^{-2kh}) so that deep water (large kh, or h
//! infinite) neither overflows nor loses digits. Their z-derivatives are C' = k S, S' = k C.
//!
//! The gradients (needed by the Jacobians of the forces that use the flow) follow from
//! d theta / dx = k e (horizontal) and the z-derivatives above.

use crate::math::{Mat3, Vec3};

/// One wave component, its wave number solved for the depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveComponent {
    /// Amplitude a (m).
    pub amplitude: f64,
    /// Angular frequency omega (rad/s).
    pub omega: f64,
    /// Wave number k (rad/m), the root of omega^2 = g k tanh(k h).
    pub k: f64,
    /// Direction of travel (cos beta, sin beta).
    pub direction: [f64; 2],
    /// Phase eps (rad).
    pub phase: f64,
    /// e^{-2 k h} (0 in deep water), for the depth profiles.
    pub deep: f64,
}

/// The wave number k of angular frequency `omega` in depth `depth` (infinite: deep water) under
/// gravity `g`: the root of omega^2 = g k tanh(k h), by Newton's method from the deep-water
/// value omega^2 / g corrected as Eckart (1952) suggests, k0 / sqrt(tanh(k0 h)); the function
/// g k tanh(k h) is increasing and concave in k, so the iterates approach the root from one side
/// and stop at round-off.
pub fn wave_number(omega: f64, depth: f64, g: f64) -> f64 {
    let k0 = omega * omega / g;
    if !depth.is_finite() || k0 * depth > 20.0 {
        // tanh(20) = 1 - 8e-18: the deep-water value is exact in double precision.
        return k0;
    }
    let mut k = k0 / (k0 * depth).tanh().sqrt();
    for _ in 0..50 {
        let t = (k * depth).tanh();
        let f = g * k * t - omega * omega;
        let df = g * t + g * k * depth * (1.0 - t * t);
        let step = f / df;
        k -= step;
        if step.abs() <= 1e-15 * k {
            break;
        }
    }
    k
}

/// C, S, K of the module documentation and k at height `z` (<= a little above 0).
#[derive(Debug, Clone, Copy)]
struct Profiles {
    c: f64,
    s: f64,
    k: f64,
}

/// The profiles at height `z` for the wave number `k` and `deep` = e^{-2kh}: with
/// up = e^{kz}, e^{-k(z+2h)} = deep / up (one exponential a point and component).
fn profiles(k: f64, z: f64, deep: f64) -> Profiles {
    let up = (k * z).exp();
    let down = if deep > 0.0 && up > 0.0 {
        deep / up
    } else {
        0.0
    };
    Profiles {
        c: (up + down) / (1.0 - deep),
        s: (up - down) / (1.0 - deep),
        k: (up + down) / (1.0 + deep),
    }
}

/// The flow of linear waves at one point: velocity, local acceleration, dynamic pressure over
/// rho, and their gradients.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinearFlow {
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Local acceleration du/dt (m/s^2).
    pub acceleration: Vec3,
    /// Dynamic pressure over the density, g a K cos(theta) summed (m^2/s^2).
    pub pressure: f64,
    /// d velocity_i / d x_j.
    pub velocity_gradient: Mat3,
    /// d acceleration_i / d x_j.
    pub acceleration_gradient: Mat3,
}

impl WaveComponent {
    /// The component of amplitude `amplitude` (m), angular frequency `omega` (rad/s),
    /// direction of travel `direction` (rad from x towards y) and phase `phase` (rad) in water
    /// of depth `depth` (infinite: deep) under gravity `g`.
    pub fn new(amplitude: f64, omega: f64, direction: f64, phase: f64, depth: f64, g: f64) -> Self {
        let k = wave_number(omega, depth, g);
        WaveComponent {
            amplitude,
            omega,
            k,
            direction: [direction.cos(), direction.sin()],
            phase,
            deep: if depth.is_finite() {
                (-2.0 * k * depth).exp()
            } else {
                0.0
            },
        }
    }

    /// The phase angle theta at horizontal position (x, y) and time t.
    #[inline]
    pub fn angle(&self, x: f64, y: f64, t: f64) -> f64 {
        self.k * (self.direction[0] * x + self.direction[1] * y) - self.omega * t + self.phase
    }

    /// Elevation eta, its horizontal gradient and its rate at (x, y, t).
    pub fn surface(&self, x: f64, y: f64, t: f64) -> (f64, [f64; 2], f64) {
        self.surface_at(self.angle(x, y, t).sin_cos())
    }

    /// [`WaveComponent::surface`] with the phase angle's (sin, cos) already known.
    #[inline]
    pub fn surface_at(&self, (s, c): (f64, f64)) -> (f64, [f64; 2], f64) {
        let a = self.amplitude;
        let dx = -a * s * self.k;
        (
            a * c,
            [dx * self.direction[0], dx * self.direction[1]],
            a * self.omega * s,
        )
    }

    /// The Hessian of the elevation at (x, y, t): -a k^2 cos(theta) e e^T.
    pub fn surface_hessian(&self, x: f64, y: f64, t: f64) -> [[f64; 2]; 2] {
        let c = -self.amplitude * self.k * self.k * self.angle(x, y, t).cos();
        let e = self.direction;
        [
            [c * e[0] * e[0], c * e[0] * e[1]],
            [c * e[1] * e[0], c * e[1] * e[1]],
        ]
    }

    /// Adds this component's flow at (x, y, z, t) to `flow` (gradients too when `gradients`).
    pub fn add_flow(&self, point: Vec3, t: f64, g: f64, gradients: bool, flow: &mut LinearFlow) {
        let angle = self.angle(point[0], point[1], t).sin_cos();
        self.add_flow_at(angle, point[2], g, gradients, flow);
    }

    /// [`WaveComponent::add_flow`] with the phase angle's (sin, cos) at the point and time
    /// already known (the angle does not depend on z: a sum of components computes it once
    /// for the elevation and the flow), at height `z`.
    pub fn add_flow_at(
        &self,
        (sin, cos): (f64, f64),
        z: f64,
        g: f64,
        gradients: bool,
        flow: &mut LinearFlow,
    ) {
        let p = profiles(self.k, z, self.deep);
        let (a, w, k) = (self.amplitude, self.omega, self.k);
        let e = [self.direction[0], self.direction[1], 0.0];
        let (uh, uz) = (a * w * p.c * cos, a * w * p.s * sin);
        let (ah, az) = (a * w * w * p.c * sin, -a * w * w * p.s * cos);
        for i in 0..2 {
            flow.velocity[i] += uh * e[i];
            flow.acceleration[i] += ah * e[i];
        }
        flow.velocity[2] += uz;
        flow.acceleration[2] += az;
        flow.pressure += g * a * p.k * cos;
        if !gradients {
            return;
        }
        // Horizontal derivatives: d theta/dx_j = k e_j; vertical: C' = k S, S' = k C.
        let du_h = [-a * w * p.c * sin * k, a * w * k * p.s * cos]; // d u_h / (theta-dir, z)
        let dw = [a * w * p.s * cos * k, a * w * k * p.c * sin];
        let da_h = [a * w * w * p.c * cos * k, a * w * w * k * p.s * sin];
        let da_z = [a * w * w * p.s * sin * k, -a * w * w * k * p.c * cos];
        for j in 0..2 {
            for i in 0..2 {
                flow.velocity_gradient[i][j] += du_h[0] * e[i] * e[j];
                flow.acceleration_gradient[i][j] += da_h[0] * e[i] * e[j];
            }
            flow.velocity_gradient[2][j] += dw[0] * e[j];
            flow.acceleration_gradient[2][j] += da_z[0] * e[j];
        }
        for i in 0..2 {
            flow.velocity_gradient[i][2] += du_h[1] * e[i];
            flow.acceleration_gradient[i][2] += da_h[1] * e[i];
        }
        flow.velocity_gradient[2][2] += dw[1];
        flow.acceleration_gradient[2][2] += da_z[1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 9.81;

    fn component(depth: f64) -> WaveComponent {
        WaveComponent::new(1.5, 2.0 * std::f64::consts::PI / 8.0, 0.6, 0.3, depth, G)
    }

    fn flow_at(c: &WaveComponent, x: Vec3, t: f64) -> LinearFlow {
        let mut f = LinearFlow::default();
        c.add_flow(x, t, G, true, &mut f);
        f
    }

    /// The dispersion relation holds at the root, in shallow, intermediate and deep water;
    /// shallow water tends to k = omega / sqrt(g h) (long waves).
    #[test]
    fn wave_number_solves_the_dispersion_relation() {
        for depth in [0.5, 5.0, 30.0, 200.0, 5000.0, f64::INFINITY] {
            for period in [2.0, 8.0, 20.0] {
                let w = 2.0 * std::f64::consts::PI / period;
                let k = wave_number(w, depth, G);
                let lhs = if depth.is_finite() {
                    G * k * (k * depth).tanh()
                } else {
                    G * k
                };
                assert!((lhs - w * w).abs() <= 1e-13 * w * w, "h {depth} T {period}");
            }
        }
        let w = 2.0 * std::f64::consts::PI / 60.0;
        let k = wave_number(w, 1.0, G);
        assert!((k / (w / (G * 1.0_f64).sqrt()) - 1.0).abs() < 1e-3);
    }

    /// The flow is that of a potential: divergence-free (Laplace's equation) and irrotational
    /// (a symmetric velocity gradient); the linear free-surface conditions hold at z = 0:
    /// d eta/dt = w (kinematic) and p/rho = g eta (dynamic, the pressure of the potential).
    #[test]
    fn flow_is_a_potential_flow_with_the_linear_surface_conditions() {
        for depth in [12.0, 60.0, f64::INFINITY] {
            let c = component(depth);
            for (x, t) in [([3.0, -2.0, -4.0], 0.7), ([-10.0, 5.0, 0.0], 3.1)] {
                let f = flow_at(&c, x, t);
                let g = f.velocity_gradient;
                let scale = c.amplitude * c.omega * c.k;
                let div = g[0][0] + g[1][1] + g[2][2];
                assert!(div.abs() < 1e-13 * scale, "divergence {div}");
                for (i, j) in [(0, 1), (0, 2), (1, 2)] {
                    assert!((g[i][j] - g[j][i]).abs() < 1e-13 * scale, "curl {i}{j}");
                }
            }
            let (x, y, t) = (4.0, 1.0, 2.2);
            let (eta, _, rate) = c.surface(x, y, t);
            let f = flow_at(&c, [x, y, 0.0], t);
            assert!((rate - f.velocity[2]).abs() < 1e-13);
            assert!((f.pressure - G * eta).abs() < 1e-12);
        }
    }

    /// Gradients, accelerations and the surface's slope and rate against central differences.
    #[test]
    fn derivatives_match_finite_differences() {
        let depth = 25.0;
        let c = component(depth);
        let (x, t) = ([2.0, -1.0, -3.0], 1.3);
        let f = flow_at(&c, x, t);
        let h = 1e-5;
        for j in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let (fp, fm) = (flow_at(&c, xp, t), flow_at(&c, xm, t));
            for i in 0..3 {
                let du = (fp.velocity[i] - fm.velocity[i]) / (2.0 * h);
                let da = (fp.acceleration[i] - fm.acceleration[i]) / (2.0 * h);
                assert!((du - f.velocity_gradient[i][j]).abs() < 1e-8, "du{i}/dx{j}");
                assert!(
                    (da - f.acceleration_gradient[i][j]).abs() < 1e-8,
                    "da{i}/dx{j}"
                );
            }
        }
        let (fp, fm) = (flow_at(&c, x, t + h), flow_at(&c, x, t - h));
        for i in 0..3 {
            let dudt = (fp.velocity[i] - fm.velocity[i]) / (2.0 * h);
            assert!((dudt - f.acceleration[i]).abs() < 1e-8, "du{i}/dt");
        }
        let (_, slope, rate) = c.surface(x[0], x[1], t);
        let eta = |x: f64, y: f64, t: f64| c.surface(x, y, t).0;
        let fd = |d: [f64; 3]| {
            (eta(x[0] + d[0], x[1] + d[1], t + d[2]) - eta(x[0] - d[0], x[1] - d[1], t - d[2]))
                / (2.0 * h)
        };
        assert!((fd([h, 0.0, 0.0]) - slope[0]).abs() < 1e-8);
        assert!((fd([0.0, h, 0.0]) - slope[1]).abs() < 1e-8);
        assert!((fd([0.0, 0.0, h]) - rate).abs() < 1e-8);
    }

    /// The seabed is impermeable (w = 0 at z = -h) and the deep-water profiles are e^{kz}.
    #[test]
    fn seabed_and_deep_water_limits() {
        let depth = 15.0;
        let c = component(depth);
        let f = flow_at(&c, [1.0, 2.0, -depth], 0.4);
        assert!(f.velocity[2].abs() < 1e-15);
        let deep = component(f64::INFINITY);
        let z = -7.0;
        let f = flow_at(&deep, [0.0, 0.0, z], 0.0);
        let th = deep.phase;
        let expected = deep.amplitude * deep.omega * (deep.k * z).exp() * th.cos();
        let horizontal = f.velocity[0].hypot(f.velocity[1]);
        assert!((horizontal - expected).abs() < 1e-14);
    }
}
