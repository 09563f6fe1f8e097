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


@pytest.mark.parametrize(("t_end", "dt"), [(2.0, 1e-4), (1.1, 1e-4), (3.0, 1e-3), (0.7, 1e-3)])
def test_states_are_stored_on_the_time_grid(t_end, dt):
    # t_end a multiple of dt (to round-off): exactly round(t_end / dt) steps of size dt, stored at
    # t_k = k dt. Accumulating t += dt leaves t_end - t ~ 1e-13 short at the end; that remainder
    # must not become an extra sliver step (a step of 1e-13 s makes the iteration matrix
    # M / dt^2 singular to working precision and corrupts the last velocities and multipliers).
    model = demos.build_pendulum(amplitude=np.pi / 3)
    solution = vinculo.simulate(model.system, t_end, dt)
    steps = round(t_end / dt)
    assert solution.num_steps == steps
    np.testing.assert_allclose(solution.times, dt * np.arange(steps + 1), rtol=0, atol=1e-12)
    np.testing.assert_allclose(solution.step_sizes[1:], dt, rtol=1e-9)
    # The last multiplier is still the rod tension m g (3 cos th - 2 cos th0) / (2 L) (see
    # test_pendulum.py), to the scheme's accuracy.
    z = solution.particle(model.bob)[-2:, 2].mean()
    expected = model.mass * model.gravity * (-3 * z - 2 * np.cos(model.amplitude))
    assert solution.distance_tension(model.rod, 1.0)[-1] == pytest.approx(expected, rel=1e-3)


def test_last_step_is_shortened_to_reach_t_end():
    # t_end not a multiple of dt: the last step is shorter and the run ends exactly at t_end.
    model = demos.build_pendulum()
    solution = vinculo.simulate(model.system, 0.105, 1e-2)
    assert solution.num_steps == 11
    assert solution.times[-1] == pytest.approx(0.105, abs=1e-15)
    assert solution.step_sizes[-1] == pytest.approx(0.005, rel=1e-9)


ARRAYS = (
    "times positions velocities multipliers constraint_residual velocity_violation "
    "newton_iterations step_sizes residual_norms increment_norms accepted_step_sizes"
).split()


@pytest.mark.parametrize("name", ARRAYS)
def test_arrays_are_read_only(chain_run, name):
    _, solution = chain_run
    array = getattr(solution, name)
    assert not array.flags.writeable
    with pytest.raises(ValueError):
        array[(0,) * array.ndim] = 1


def test_energies_match_their_definitions(chain_run):
    # Kinetic 1/2 sum m |v|^2 and gravity potential -sum m g.q (g = (0, 0, -9.81): m g z),
    # computed here directly from the arrays.
    model, solution = chain_run
    masses = model.system.masses()
    kinetic = 0.5 * np.einsum("sij,i->s", solution.velocities**2, masses)
    potential = 9.81 * np.einsum("si,i->s", solution.positions[:, :, 2], masses)
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


def test_a_solution_keeps_working_after_its_system_is_edited(tmp_path):
    # A pendulum bob of 0.4 kg on a 0.75 m string; after the run the user adds a particle, a
    # spring and a link to the same System. Before, the solution read the edited system: its
    # energies, counts and tensions no longer described the run.
    # References: the energies from their definitions with the run's masses, and the static
    # tension 2 lambda L with the run's length.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(0.4, (0.45, 0.0, -0.6))  # 0.75 m from the pivot
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), 0.75)
    solution = vinculo.simulate(system, 0.3, 1e-2)
    kinetic_before = solution.kinetic_energy().copy()
    other = system.add_particle(2.0, (1.0, 0.0, 0.0))
    system.add_spring_damper(bob, other, 10.0)
    system.add_distance(bob, other, 0.8)
    assert system.num_particles == 2 and solution.system.num_particles == 1
    assert solution.system.num_constraints == 1
    kinetic = 0.5 * 0.4 * np.sum(solution.velocities[:, 0] ** 2, axis=1)
    potential = 0.4 * 9.81 * solution.positions[:, 0, 2]
    np.testing.assert_allclose(solution.kinetic_energy(), kinetic, rtol=1e-13, atol=1e-15)
    np.testing.assert_array_equal(solution.kinetic_energy(), kinetic_before)
    np.testing.assert_allclose(solution.potential_energy(), potential, rtol=1e-13, atol=1e-15)
    tension = solution.distance_tension(rod)  # the run's length, 0.75 m
    np.testing.assert_allclose(tension, 2.0 * 0.75 * solution.multiplier(rod), rtol=1e-15)
    assert "(1 particles, 1 constraint equations)" in solution.summary()
