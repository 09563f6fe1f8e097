"""The Solution object: shapes, energies and statistics match what they claim."""

import io

import numpy as np
import pytest

import vinculo
from vinculo import demos
from vinculo.simulate import ProgressBar


@pytest.fixture(scope="module")
def chain_run():
    model = demos.build_hanging_chain(num_links=3, length=0.9, mass=1.5)
    solution = vinculo.simulate(model.system, t_end=0.5, dt=1e-2)
    return model, solution


def test_shapes_and_steps(chain_run):
    model, solution = chain_run
    s, n, m = 51, 4, 3  # 50 steps of 10 ms plus the initial state; 3 particles + anchor; 3 links
    assert solution.success and solution.error is None
    assert solution.num_steps == 50
    assert solution.times.shape == (s,)
    assert solution.positions.shape == solution.velocities.shape == (s, n, 3)
    assert solution.multipliers.shape == (s, m)
    np.testing.assert_allclose(solution.times, np.linspace(0.0, 0.5, s), atol=1e-12)
    # Row 0 is the initial state: no iterations, no step.
    assert solution.newton_iterations[0] == 0 and solution.step_sizes[0] == 0
    np.testing.assert_array_equal(solution.positions[0], model.system.initial_positions())
    # An easy run takes every step at the requested size, each with at least one iteration.
    np.testing.assert_allclose(solution.step_sizes[1:], 1e-2, rtol=1e-12)
    assert np.all(solution.newton_iterations[1:] >= 1)
    assert solution.particle(model.particles[-1]).shape == (s, 3)


def test_arrays_are_read_only(chain_run):
    _, solution = chain_run
    with pytest.raises(ValueError):
        solution.positions[0, 0, 0] = 1.0


def test_energies_match_their_definitions(chain_run):
    # Kinetic 1/2 sum m |v|^2 and gravity potential -sum m g.q (g = (0, 0, -9.81): m g z),
    # computed here directly from the arrays.
    model, solution = chain_run
    masses = model.system.masses()
    kinetic = 0.5 * np.einsum("sij,i->s", solution.velocities**2, masses)
    potential = 9.81 * np.einsum("s i,i->s", solution.positions[:, :, 2], masses)
    np.testing.assert_allclose(solution.kinetic_energy(), kinetic, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(solution.potential_energy(), potential, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(solution.energy(), kinetic + potential, rtol=1e-13, atol=1e-13)


def test_multiplier_and_tension_of_a_hanging_particle():
    # A particle hanging at rest below a fixed point: the string carries its weight m g, so
    # 2 lambda L = m g (tension positive) at every time.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(0.4, (0.0, 0.0, -0.75))
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), 0.75)
    solution = vinculo.simulate(system, 0.2, 1e-2)
    np.testing.assert_allclose(solution.multiplier(rod), 0.4 * 9.81 / (2 * 0.75), rtol=1e-10)
    np.testing.assert_allclose(solution.distance_tension(rod, 0.75), 0.4 * 9.81, rtol=1e-10)
    np.testing.assert_allclose(solution.particle(bob), [[0.0, 0.0, -0.75]] * 21, atol=1e-12)


def test_summary_reports_the_statistics(chain_run):
    _, solution = chain_run
    text = solution.summary()
    assert "steps: 50" in text
    assert f"{np.max(solution.constraint_residual):.3e}" in text
    assert f"max {int(np.max(solution.newton_iterations))}" in text
    assert "min step size: 0.01" in text


def test_progress_bar_draws_the_fraction_done():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar(1.5, 3.0)
    assert "[#####-----]" in stream.getvalue() and "50.0%" in stream.getvalue()
    bar(3.0, 3.0)
    bar.close()
    assert stream.getvalue().endswith("\n") and "100.0%" in stream.getvalue()


def test_progress_callable_receives_times_up_to_t_end():
    # The core reports about twice a second of wall time: a run of a few seconds reports.
    seen = []
    model = demos.build_hanging_chain(num_links=20)
    vinculo.simulate(model.system, 4.0, 1e-4, progress=lambda t, t_end: seen.append((t, t_end)))
    if seen:  # a very fast machine may finish before the first report
        times = [t for t, _ in seen]
        assert all(t_end == 4.0 for _, t_end in seen)
        assert times == sorted(times) and 0 < times[0] <= 4.0
