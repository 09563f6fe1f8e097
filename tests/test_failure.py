"""A run that cannot converge raises ConvergenceError and keeps what it computed."""

import numpy as np
import pytest

import vinculo
from vinculo import demos, laws


def test_unreachable_tolerance_fails_at_the_first_step():
    # A Newton tolerance of 1e-30 is below round-off: no step can converge, even halved
    # max_halvings times. The partial solution still holds the initial state.
    model = demos.build_hanging_chain(num_links=10)
    dt, halvings = 1e-3, 4
    with pytest.raises(vinculo.ConvergenceError) as info:
        vinculo.simulate(model.system, 1.0, dt, tolerance=1e-30, max_halvings=halvings)
    error = info.value
    assert isinstance(error, vinculo.VinculoError) and isinstance(error, RuntimeError)
    solution = error.solution
    assert isinstance(solution, vinculo.Solution)
    assert not solution.success and solution.error is not None
    assert len(solution.times) >= 1 and solution.times[0] == 0.0
    np.testing.assert_array_equal(solution.positions[0], model.system.initial_positions())
    assert error.time == pytest.approx(solution.times[-1], abs=dt)
    # The last attempt used the smallest step allowed.
    assert error.step_size == pytest.approx(dt / 2**halvings, rel=1e-12)
    assert error.iterations >= 1
    assert isinstance(error.equation, str) and error.equation
    assert str(error)  # a message for the user


def test_constraints_that_stop_intersecting():
    # A particle held on the plane z = 0 and at distance 0.5 m from a point rising as p = (0, 0, t):
    # the two constraints meet on a circle of radius sqrt(0.25 - t^2), which shrinks ever faster
    # and vanishes at t = 0.5 s. No step can cross that time, but every step before it is kept.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    particle = system.add_particle(1.0, (0.5, 0.0, 0.0))
    plane = system.add_plane(particle, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0))
    string = system.add_distance_to_point(particle, (0.0, 0.0, laws.polynomial([0.0, 1.0])), 0.5)
    dt = 1e-3
    with pytest.raises(vinculo.ConvergenceError) as info:
        vinculo.simulate(system, 1.0, dt)
    error = info.value
    solution = error.solution
    times = solution.times
    assert len(times) > 100  # it got most of the way
    assert np.all(np.diff(times) > 0)
    assert 0.3 < times[-1] <= 0.5
    assert times[-1] <= error.time + 1e-12 and error.time <= times[-1] + dt
    # Everything it kept satisfies both constraints, on the shrinking circle.
    q = solution.particle(particle)
    np.testing.assert_allclose(q[:, 2], 0.0, atol=1e-12)
    distance = np.sqrt(q[:, 0] ** 2 + q[:, 1] ** 2 + (q[:, 2] - times) ** 2)
    np.testing.assert_allclose(distance, 0.5, rtol=0, atol=1e-12)
    # The equation named is one of the model's (a constraint or a particle's dynamics).
    names = system.constraint_names()
    assert error.equation in names or "particle" in error.equation
    assert names[plane.index] != names[string.index]
    # The arrays of the partial solution have one row per stored time.
    for field in ("positions", "velocities", "multipliers", "newton_iterations", "step_sizes"):
        assert len(getattr(solution, field)) == len(times)
