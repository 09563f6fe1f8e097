"""Constraints hold along the motion: distances, moving points, moving planes, fixed coordinates."""

import itertools

import numpy as np
import pytest

import vinculo
from vinculo import demos, laws

G = 9.81


def test_chain_constraint_residual_stays_at_round_off():
    # The positions are solved so that Phi(q^{n+1}, t^{n+1}) = 0 at each step end
    # (docs/theory/formulation.md),
    # to Newton tolerance; Newton converges quadratically, so what is left is round-off: we ask for
    # 1e-12 of the link length at dt = 1e-4 over 1 s of a 5-link chain swinging from 60 degrees.
    model = demos.build_hanging_chain(num_links=5, length=1.0, angle=np.pi / 3)
    solution = vinculo.simulate(model.system, t_end=1.0, dt=1e-4)
    link = model.link_length
    assert np.max(solution.constraint_residual) < 1e-12 * link

    # Checked independently of the core's own residual, from the stored positions.
    chain = [model.anchor, *model.particles]
    for a, b in itertools.pairwise(chain):
        gap = np.linalg.norm(solution.particle(a) - solution.particle(b), axis=1)
        assert np.max(np.abs(gap - link)) < 1e-12 * link
    # The reported residual is max_k |s_k Phi_k| with s_k = 1/(2L) for a distance.
    final = solution.positions[-1]
    scaled = model.system.constraint_residual(final, solution.times[-1])
    scaled = np.abs(scaled * model.system.constraint_scales())
    assert solution.constraint_residual[-1] == pytest.approx(np.max(scaled), abs=1e-15)
    # The fixed anchor did not move.
    np.testing.assert_array_equal(solution.particle(model.anchor), 0.0)


def test_distance_to_a_moving_point():
    # A pendulum hung from a point p(t) = (X0 s(t) sin(2 pi f t), 0, 0) moving with a prescribed
    # law (the buoy's tank anchor): |q - p(t)| = L at every stored time.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    length = 0.5
    bob = system.add_particle(1.0, (0.0, 0.0, -length))
    x_anchor = laws.sine(amplitude=0.05, frequency=1.3, ramp_time=0.5)
    rod = system.add_distance_to_point(bob, (x_anchor, 0.0, 0.0), length)
    solution = vinculo.simulate(system, t_end=3.0, dt=1e-3)
    anchor = np.array([[x_anchor(t), 0.0, 0.0] for t in solution.times])
    gap = np.linalg.norm(solution.particle(bob) - anchor, axis=1)
    assert np.max(np.abs(gap - length)) < 1e-12 * length
    # The bob was dragged along (it moved by a good part of the anchor's amplitude) ...
    assert np.ptp(solution.particle(bob)[:, 0]) > 0.02
    # ... and the rod stayed in tension near m g (small swing).
    tension = solution.distance_tension(rod, length)
    assert np.all(tension > 0.8 * G) and np.all(tension < 1.3 * G)


def test_plane_moving_along_its_normal():
    # Horizontal plane z = z0(t) = t^2 / 2 carrying a particle: z(t) = z0(t) exactly (the
    # trapezoidal rule is exact for constant acceleration), and the plane pushes with
    # n lambda = m (z0'' + g), so lambda = m (1 + g) with n = (0, 0, 1).
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    mass = 3.0
    block = system.add_particle(mass, (0.2, -0.1, 0.0), velocity=(0.5, 0.0, 0.0))
    plane = system.add_plane(block, (0.0, 0.0, 1.0), (0.0, 0.0, laws.polynomial([0.0, 0.0, 0.5])))
    solution = vinculo.simulate(system, t_end=2.0, dt=1e-2)
    t = solution.times
    q = solution.particle(block)
    np.testing.assert_allclose(q[:, 2], 0.5 * t**2, rtol=0, atol=1e-12)
    # Nothing acts along the plane: x moves uniformly, y stays.
    np.testing.assert_allclose(q[:, 0], 0.2 + 0.5 * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[:, 1], -0.1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(solution.multiplier(plane), mass * (1.0 + G), rtol=1e-10)


def test_plane_with_rotating_normal():
    # A plane through the origin whose normal n(t) = (sin wt, 0, cos wt) turns about y: the
    # particle stays on it, n(t) . q(t) = 0 at every stored time.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    frequency = 0.2
    normal = (
        laws.sine(amplitude=1.0, frequency=frequency),
        0.0,
        laws.sine(amplitude=1.0, frequency=frequency, phase=np.pi / 2),
    )
    block = system.add_particle(1.0, (0.0, 0.3, 0.0))
    system.add_plane(block, normal, (0.0, 0.0, 0.0))
    solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
    angle = 2 * np.pi * frequency * solution.times
    n = np.stack([np.sin(angle), np.zeros_like(angle), np.cos(angle)], axis=1)
    q = solution.particle(block)
    assert np.max(np.abs(np.sum(n * q, axis=1))) < 1e-12
    assert np.max(np.abs(q[:, 0])) > 0.01  # the tilting plane really moved it


@pytest.mark.parametrize("axis", [2, "z"])
def test_fixed_coordinate_holds(axis):
    # Phi = q_z - z_fixed: the particle keeps its height while moving freely in x and y; the
    # multiplier carries its weight, Phi_q^T lambda = (0, 0, lambda) = (0, 0, m g).
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    mass = 0.7
    particle = system.add_particle(mass, (0.0, 0.0, 1.25), velocity=(1.0, -2.0, 0.0))
    holder = system.add_fixed_coordinate(particle, axis)
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-2)
    t = solution.times
    q = solution.particle(particle)
    np.testing.assert_allclose(q[:, 2], 1.25, rtol=0, atol=1e-13)
    np.testing.assert_allclose(q[:, 0], t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[:, 1], -2.0 * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(solution.multiplier(holder), mass * G, rtol=1e-10)


def test_fixed_coordinate_following_a_law():
    # q_x(t) = 0.1 sin(2 pi t) prescribed, no force along x: the particle follows the law and the
    # multiplier is the force needed, Phi_q^T lambda = (lambda, 0, 0) = m x''.
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    mass, amplitude = 2.0, 0.1
    law = laws.sine(amplitude=amplitude, frequency=1.0)
    particle = system.add_particle(mass, (0.0, 0.0, 0.0), velocity=(law.derivatives(0.0)[1], 0, 0))
    driver = system.add_fixed_coordinate(particle, "x", law)
    dt = 1e-3
    solution = vinculo.simulate(system, t_end=2.0, dt=dt)
    t = solution.times
    x = solution.particle(particle)[:, 0]
    np.testing.assert_allclose(x, [law(s) for s in t], rtol=0, atol=1e-12)
    # The velocities follow the law's derivative to the scheme's O(dt^2) accuracy.
    rate = np.array([law.derivatives(s)[1] for s in t])
    v = solution.particle_velocity(particle)[:, 0]
    assert np.max(np.abs(v - rate)) < 1e-5
    # Step n -> n+1 balances m (v1 - v0) / dt = lambda, i.e. the mean of m x'' over the step.
    # With alpha = 1/2 the multipliers of an index-3 problem ring (docs/theory/formulation.md): an
    # undamped
    # (-1)^n oscillation rides on them (here about 0.1 % of the peak force). Averaging two
    # consecutive steps removes it; what remains is the O(dt^2) error, ~1e-5 of the peak force
    # m A (2 pi)^2, well below the 1e-4 required.
    force = mass * np.diff(rate) / dt
    multiplier = solution.multiplier(driver)[1:]
    peak = mass * amplitude * (2 * np.pi) ** 2
    np.testing.assert_allclose(
        0.5 * (multiplier[:-1] + multiplier[1:]), 0.5 * (force[:-1] + force[1:]), atol=1e-4 * peak
    )
    # Row 0 comes from the consistent initial accelerations: m x''(0) = 0 for a sine at phase 0.
    initial_force = mass * law.derivatives(0.0)[2]
    assert solution.multiplier(driver)[0] == pytest.approx(initial_force, abs=1e-12)
