"""A particle sliding on a frictionless inclined plane: acceleration and normal force."""

import numpy as np
import pytest

import vinculo
from vinculo import demos

G = 9.81


@pytest.mark.parametrize("degrees", [0.0, 30.0, 60.0])
def test_sliding_particle_follows_closed_form(degrees):
    # Plane through the origin with normal n = (-sin th, 0, cos th), gravity -z, particle at rest
    # at the origin. Newton's law along the slope gives the constant acceleration g sin th
    # downhill, so q(t) = -(1/2) g sin th t^2 (cos th, 0, sin th). The trapezoidal rule integrates
    # constant acceleration exactly, so positions and velocities match to round-off.
    theta = np.radians(degrees)
    model = demos.build_inclined_plane(angle=theta, mass=2.0, gravity=G)
    result = demos.run_inclined_plane(t_end=1.0, dt=1e-2, alpha=0.5, model=model)
    t = result.solution.times
    downhill = -np.array([np.cos(theta), 0.0, np.sin(theta)])
    expected = 0.5 * G * np.sin(theta) * t[:, None] ** 2 * downhill
    np.testing.assert_allclose(result.solution.particle(model.block), expected, rtol=0, atol=1e-12)
    velocity = result.solution.particle_velocity(model.block)
    np.testing.assert_allclose(velocity, G * np.sin(theta) * t[:, None] * downhill, atol=1e-12)
    assert result.acceleration == pytest.approx(G * np.sin(theta), rel=1e-10, abs=1e-12)


@pytest.mark.parametrize("alpha", [0.5, 0.75, 1.0])
def test_multiplier_is_the_normal_force(alpha):
    # docs/theory/formulation.md: Phi = n . (q - p0), so Phi_q^T lambda = n lambda is the
    # constraint force.
    # Balancing gravity across the plane: n lambda . n / |n| = m g cos th, i.e.
    # lambda = m g cos th / |n| (positive: the plane pushes the particle out along n, upwards).
    # Holds at every stored time including row 0 (consistent initial accelerations) and for any
    # alpha, because the motion has constant acceleration.
    theta, mass = np.radians(30.0), 2.0
    model = demos.build_inclined_plane(angle=theta, mass=mass, gravity=G)
    solution = vinculo.simulate(model.system, 1.0, 1e-2, alpha)
    np.testing.assert_allclose(
        solution.multiplier(model.plane), mass * G * np.cos(theta), rtol=1e-10
    )


def test_multiplier_scales_with_the_normal_given():
    # The plane equation uses the normal as given (n need not be unit): doubling n halves lambda
    # while the force n lambda, the normal force m g cos th, stays the same.
    theta, mass = np.radians(30.0), 1.5
    model = demos.build_inclined_plane(angle=theta, mass=mass, gravity=G, normal_scale=2.0)
    result = demos.run_inclined_plane(t_end=0.5, dt=1e-2, model=model)
    multiplier = result.solution.multiplier(model.plane)
    np.testing.assert_allclose(multiplier, mass * G * np.cos(theta) / 2.0, rtol=1e-10)
    np.testing.assert_allclose(result.normal_force, mass * G * np.cos(theta), rtol=1e-10)
    # The motion does not depend on the normal's length.
    assert result.acceleration == pytest.approx(G * np.sin(theta), rel=1e-10)
