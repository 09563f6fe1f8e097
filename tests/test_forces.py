"""Applied forces against closed-form solutions: springs, dampers, drag, prescribed forces."""

import numpy as np
import pytest

import vinculo
from vinculo import demos, laws

G = 9.81


def spring_oscillator(stiffness: float, damping: float, mass: float, stretch: float):
    """A particle hanging on a spring-damper from a fixed anchor, no gravity, moving along z."""
    system = vinculo.System()
    anchor = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass, (0.0, 0.0, -1.0 - stretch))
    spring = system.add_spring_damper(anchor, bob, stiffness, damping, rest_length=1.0)
    return system, bob, spring


def test_spring_period_and_energy():
    # Undamped: x'' = -(k/m) x, period 2 pi sqrt(m/k) (k = 40 N/m, m = 0.1 kg: omega = 20 rad/s).
    # The trapezoidal phase error (omega dt)^2 / 12 = 3e-6 at dt = 1e-4; required 1e-5.
    # The motion stays on the spring's line, where its force is linear in the displacement, so
    # the midpoint evaluation conserves 1/2 m v^2 + 1/2 k x^2 exactly (up to Newton's tolerance).
    system, bob, _ = spring_oscillator(stiffness=40.0, damping=0.0, mass=0.1, stretch=0.01)
    solution = vinculo.simulate(system, 1.0, 1e-4)
    x = solution.particle(bob)[:, 2] + 1.0
    v = solution.particle_velocity(bob)[:, 2]
    assert demos.crossing_period(solution.times, x, v) == pytest.approx(2 * np.pi / 20, rel=1e-5)
    energy = solution.energy()
    assert energy[0] == pytest.approx(0.5 * 40.0 * 0.01**2, rel=1e-12)  # all in the spring
    assert np.max(np.abs(energy - energy[0])) < 1e-9 * energy[0]


def test_damped_spring_follows_closed_form():
    # x'' + 2 zeta omega x' + omega^2 x = 0 from x0 at rest:
    #   x = x0 e^{-zeta omega t} (cos wd t + zeta / sqrt(1 - zeta^2) sin wd t),
    # wd = omega sqrt(1 - zeta^2) (any vibrations text).
    # zeta = 0.1, omega = 20 rad/s, c = 2 zeta sqrt(k m).
    # Error bound: the phase error omega t (omega dt)^2 / 12 ~ 1.3e-4 after 2 s at dt = 1e-4.
    k, m, zeta, x0 = 40.0, 0.1, 0.1, 0.01
    omega = np.sqrt(k / m)
    system, bob, _ = spring_oscillator(k, 2 * zeta * np.sqrt(k * m), m, x0)
    solution = vinculo.simulate(system, 2.0, 1e-4)
    t = solution.times
    wd = omega * np.sqrt(1 - zeta**2)
    exact = (
        x0
        * np.exp(-zeta * omega * t)
        * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * t))
    )
    x = -(solution.particle(bob)[:, 2] + 1.0)  # extension of the spring
    np.testing.assert_allclose(x, exact, rtol=0, atol=2e-4 * x0)


def test_linear_drag_decays_exponentially():
    # m v' = -c v: v = v0 exp(-c t / m). The trapezoidal rule's amplification factor
    # (1 - h/2)/(1 + h/2) with h = c dt / m = 2e-3 differs from e^{-h} by h^3/12 per step:
    # ~1e-6 relative after 1000 steps; required 1e-5.
    system = vinculo.System()
    particle = system.add_particle(0.5, (0.0, 0.0, 0.0), velocity=(2.0, -1.0, 0.0))
    system.add_linear_drag(particle, 1.0)
    solution = vinculo.simulate(system, 1.0, 1e-3)
    decay = np.exp(-solution.times / 0.5)
    v = solution.particle_velocity(particle)
    np.testing.assert_allclose(v[:, 0], 2.0 * decay, rtol=1e-5)
    np.testing.assert_allclose(v[:, 1], -1.0 * decay, rtol=1e-5)


def test_quadratic_drag_reaches_terminal_velocity():
    # Falling from rest with f = -c |v| v: v(t) = -v_t tanh(g t / v_t), v_t = sqrt(m g / c).
    mass, c = 0.2, 0.05
    v_terminal = np.sqrt(mass * G / c)
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    particle = system.add_particle(mass, (0.0, 0.0, 0.0))
    system.add_quadratic_drag(particle, c)
    solution = vinculo.simulate(system, 3.0, 1e-3)
    exact = -v_terminal * np.tanh(G * solution.times / v_terminal)
    vz = solution.particle_velocity(particle)[:, 2]
    np.testing.assert_allclose(vz, exact, rtol=0, atol=1e-5 * v_terminal)


def test_prescribed_force_law():
    # F(t) = A sin(w t) along x on a free particle at rest:
    # v = A/(m w) (1 - cos w t), x = A/(m w) (t - sin(w t)/w). O(dt^2) error ~1e-7 at dt = 1e-3.
    amplitude, frequency, mass = 3.0, 0.5, 1.5
    w = 2 * np.pi * frequency
    system = vinculo.System()
    particle = system.add_particle(mass, (0.0, 0.0, 0.0))
    system.add_force(particle, (laws.sine(amplitude, frequency), 0.0, 0.0))
    solution = vinculo.simulate(system, 2.0, 1e-3)
    t = solution.times
    scale = amplitude / (mass * w)
    np.testing.assert_allclose(
        solution.particle_velocity(particle)[:, 0], scale * (1 - np.cos(w * t)), atol=1e-6 * scale
    )
    np.testing.assert_allclose(
        solution.particle(particle)[:, 0], scale * (t - np.sin(w * t) / w), atol=1e-6 * scale
    )
