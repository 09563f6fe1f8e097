"""Constraint health per step, and modified Newton against full Newton."""

import numpy as np
import pytest

import vinculo
from vinculo import demos


def test_velocity_violation_matches_an_independent_computation():
    # A 1 m pendulum whose pivot moves as p(t) = (A sin(w t), 0, 0). For the constraint
    # Phi = L^2 - |q - p|^2 with scale s = 1/(2L) (System.constraint_scales()),
    # s (Phi_q v + Phi_t) = -(q - p).(v - p') / L: computed here from the stored states alone.
    amplitude, omega, length = 0.1, 2.0 * np.pi, 1.0
    system = vinculo.System(gravity=(0.0, 0.0, -demos.GRAVITY))
    bob = system.add_particle(1.0, [0.5, 0.0, -np.sqrt(0.75)], velocity=[amplitude * omega, 0, 0])
    system.add_distance_to_point(bob, (vinculo.sine(amplitude, 1.0), 0.0, 0.0), length)
    assert system.constraint_scales()[0] == pytest.approx(1.0 / (2.0 * length))
    solution = vinculo.simulate(system, 1.0, 2e-3, scheme="generalized-alpha")
    t = solution.times
    pivot = np.stack([amplitude * np.sin(omega * t), 0 * t, 0 * t], axis=1)
    pivot_velocity = np.stack([amplitude * omega * np.cos(omega * t), 0 * t, 0 * t], axis=1)
    q, v = solution.particle(bob), solution.particle_velocity(bob)
    expected = np.abs(np.sum((q - pivot) * (v - pivot_velocity), axis=1)) / length
    np.testing.assert_allclose(solution.velocity_violation, expected, rtol=1e-9, atol=1e-14)
    # The position level is held to the Newton tolerance (1e-10 of the length scale).
    assert np.array_equal(solution.position_violation, solution.constraint_residual)
    assert np.max(solution.position_violation) < 1e-10 * system.length_scale()


@pytest.mark.parametrize(
    ("kwargs", "order"),
    [
        ({"scheme": "trapezoidal"}, 2.0),
        ({"scheme": "backward-euler"}, 1.0),
        ({"scheme": "generalized-alpha", "rho_inf": 0.0}, 2.0),
        ({"scheme": "generalized-alpha", "rho_inf": 0.9}, 2.0),
    ],
)
def test_velocity_violation_shrinks_with_the_order_of_the_scheme(kwargs, order):
    # The exact motion satisfies Phi_q v + Phi_t = 0, and the index-3 schemes' velocities converge
    # with the order of the positions (docs/theory/time-rules.md; Arnold and Brüls 2007 for
    # generalised-alpha), so the largest violation over 1 s of the horizontally released pendulum
    # is divided by about 2^order when the step is halved.
    largest = []
    for dt in (2e-3, 1e-3):
        solution = vinculo.simulate(demos.build_pendulum().system, 1.0, dt, **kwargs)
        assert solution.velocity_violation[0] == 0.0  # consistent start
        largest.append(np.max(solution.velocity_violation))
    assert np.log2(largest[0] / largest[1]) == pytest.approx(order, abs=0.2), largest


def test_step_sizes_and_iterations_describe_each_step():
    model = demos.build_pendulum()
    solution = vinculo.simulate(model.system, 0.5, 1e-2, max_halvings=3, jacobian_reuse=False)
    np.testing.assert_allclose(solution.step_sizes[1:], np.diff(solution.times), rtol=1e-12)
    assert solution.newton_iterations[0] == 0
    assert np.all(solution.newton_iterations[1:] >= 1)
    # Full Newton factorises once per iteration (no step was retried: every step is stored).
    assert solution.factorisations == int(np.sum(solution.newton_iterations))


def test_modified_newton_takes_the_same_step_to_the_newton_tolerance():
    # Both iterations solve the same equations; full Newton stops with an increment below the
    # tolerance and a quadratically smaller error, modified Newton (contraction <= 1/2) with an
    # error below its last increment, itself below the tolerance. So one step from the same
    # state agrees to within twice the tolerance.
    model = demos.build_hanging_chain(num_links=10, length=1.0, angle=np.pi / 3)
    tolerance = 1e-10
    ends = []
    for reuse in (False, True):
        solution = vinculo.simulate(
            model.system, 1e-2, 1e-2, tolerance=tolerance, jacobian_reuse=reuse
        )
        ends.append(solution.positions[-1])
    bound = 2 * tolerance * model.system.length_scale()
    assert np.max(np.abs(ends[0] - ends[1])) < bound


def test_modified_newton_trajectory_matches_full_newton_with_fewer_factorisations():
    # Over 1 s (1000 steps) of a swinging 10-link chain the per-step differences of at most the
    # Newton tolerance accumulate, but stay far below the scheme's own error, estimated by the
    # change of the full-Newton trajectory when the step is halved.
    model = demos.build_hanging_chain(num_links=10, length=1.0, angle=np.pi / 3)
    full = vinculo.simulate(model.system, 1.0, 1e-3)
    modified = vinculo.simulate(model.system, 1.0, 1e-3, jacobian_reuse=True)
    finer = vinculo.simulate(model.system, 1.0, 5e-4, save_every=2)
    newton_difference = np.max(np.abs(full.positions - modified.positions))
    scheme_error = np.max(np.abs(full.positions - finer.positions))
    assert newton_difference < 1e-2 * scheme_error, (newton_difference, scheme_error)
    assert modified.factorisations < 0.1 * full.factorisations
    assert np.max(modified.position_violation) < 1e-10 * model.system.length_scale()
