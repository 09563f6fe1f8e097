"""Output times with fixed steps (``t_eval`` without adaptive steps): the states at requested
times, against the run's own steps and against the pendulum in minimal coordinates
(``pendulum_reference``: DOP853 at 1e-12)."""

from __future__ import annotations

import numpy as np

import vinculo
from pendulum_reference import angle_history

DT, T_END, THETA0 = 0.01, 1.0, 1.0


def _pendulum() -> tuple[vinculo.System, vinculo.ParticleId]:
    # A 1 m, 1 kg pendulum released at rest THETA0 from the downward vertical (pivot at 0).
    system = vinculo.System(gravity=(0.0, 0.0, -vinculo.demos.GRAVITY))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=1.0, position=(np.sin(THETA0), 0.0, -np.cos(THETA0)))
    system.add_distance(pivot, bob, length=1.0)
    return system, bob


def _error(solution: vinculo.Solution, bob: vinculo.ParticleId) -> np.ndarray:
    times = np.asarray(solution.times)
    theta, _ = angle_history(THETA0, times)
    exact = np.column_stack([np.sin(theta), np.zeros_like(theta), -np.cos(theta)])
    return np.linalg.norm(np.asarray(solution.particle(bob)) - exact, axis=1)


def test_output_times_on_the_grid_are_the_steps_own_states():
    system, _ = _pendulum()
    plain = vinculo.simulate(system, T_END, DT)
    grid = np.asarray(plain.times)[::5]
    sampled = vinculo.simulate(system, T_END, DT, t_eval=grid)
    np.testing.assert_array_equal(sampled.times, grid)
    np.testing.assert_array_equal(sampled.positions, plain.positions[::5])
    np.testing.assert_array_equal(sampled.velocities, plain.velocities[::5])


def test_output_times_between_steps_are_as_accurate_as_the_steps():
    # Times in the middle of the steps: the cubic Hermite interpolant of a step (error O(h^4))
    # adds nothing visible to the trapezoidal rule's own O(h^2) error; measured 2.02e-4 m at the
    # steps' ends and 2.02e-4 m at their middles.
    system, bob = _pendulum()
    plain = vinculo.simulate(system, T_END, DT)
    middles = np.arange(0.5, 100) * DT
    sampled = vinculo.simulate(system, T_END, DT, t_eval=middles)
    at_steps, between = _error(plain, bob).max(), _error(sampled, bob).max()
    assert between < 1.2 * at_steps
    assert at_steps > 1e-5  # the scheme's error, not round-off: a comparison with meaning
