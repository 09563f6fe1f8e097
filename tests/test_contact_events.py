"""Fixed steps through a contact event: a particle dropped onto MoorDyn's seabed (a spring kBot
and a dashpot cBot per unit area, acting while the particle penetrates), against the closed-form
motion.

Reference (derived here): free fall from rest at height h0 above the seabed z_b until
t_c = sqrt(2 h0 / g), arriving at v_c = -g t_c; then, with the penetration p = z_b - z >= 0 and
the contact area A, m p'' + A cBot p' + A kBot p = m g from p(t_c) = 0, p'(t_c) = -v_c, a linear
equation with constant coefficients: p = p_s + C1 e^(r1 s) + C2 e^(r2 s), s = t - t_c,
p_s = m g / (A kBot), r1,2 = (-c +- sqrt(c^2 - 4 m k)) / (2 m) (c = A cBot, k = A kBot; here
overdamped: r1 = -5.1 /s, r2 = -195 /s), C1 + C2 = -p_s and r1 C1 + r2 C2 = -v_c. The particle
stays in contact (p rises to about 1.6 cm and settles to p_s = 1 cm).

The damping force jumps from 0 to A cBot |v_c| = 63 kN at touchdown. A step straddling the jump
resolves it to first order (the error halves with dt); the run steps to the touchdown and
through its transient in short steps (crates/vinculo/src/run.rs, contact events), and the error
falls fourfold when dt halves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import vinculo

MASS, G, DEPTH, HEIGHT = 100.0, 9.81, 10.0, 0.5
KBOT, CBOT = 1.0e5, 2.0e4  # with d = l = 1 m, A = 1 m^2


def _exact_height(t: float) -> float:
    t_c = math.sqrt(2.0 * HEIGHT / G)
    if t <= t_c:
        return -DEPTH + HEIGHT - 0.5 * G * t * t
    v_c = -G * t_c
    root = math.sqrt(CBOT * CBOT - 4.0 * MASS * KBOT)
    r1, r2 = (-CBOT + root) / (2.0 * MASS), (-CBOT - root) / (2.0 * MASS)
    p_s = MASS * G / KBOT
    c2 = (-v_c + r1 * p_s) / (r2 - r1)
    c1 = -p_s - c2
    s = t - t_c
    return -DEPTH - (p_s + c1 * math.exp(r1 * s) + c2 * math.exp(r2 * s))


def _largest_error(dt: float, t_end: float = 0.8, **scheme) -> tuple[float, vinculo.Solution]:
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    ball = system.add_particle(mass=MASS, position=(0.0, 0.0, -DEPTH + HEIGHT))
    system.add_seabed_contact(ball, depth=DEPTH, diameter=1.0, length=1.0, kbot=KBOT, cbot=CBOT)
    solution = vinculo.simulate(system, t_end, dt, **scheme)
    z = np.asarray(solution.particle(ball))[:, 2]
    exact = np.array([_exact_height(t) for t in solution.times])
    return float(np.max(np.abs(z - exact))), solution


def test_a_particle_dropped_on_the_seabed_converges_at_second_order():
    errors = [_largest_error(dt)[0] for dt in (0.04, 0.02, 0.01)]
    # Measured 1.2e-4, 3.0e-5, 7.4e-6 m: ratios 4.1 and 4.0. Steps of dt straddling the
    # touchdown and through its transient gave 0.17 m at dt = 0.04 (the trapezoidal rule's
    # ringing of the contact's fast root, -195 /s, at r2 dt = -7.8).
    assert errors[0] < 3e-4
    assert errors[0] / errors[1] > 3.5
    assert errors[1] / errors[2] > 3.5


@pytest.mark.parametrize("rho_inf", [0.9, 0.5])
def test_generalised_alpha_is_second_order_through_the_touchdown(rho_inf):
    # Generalised-alpha evaluates the forces at the step's end, where the damping's jump has no
    # value to end on: its steps land a thousandth short of the touchdown (the gap closes in two
    # or three steps) and the rule starts again on the far side with the consistent
    # accelerations (crates/vinculo/src/run.rs, contact events). Measured: 1.3e-4, 3.2e-5,
    # 7.9e-6 m (rho_inf = 0.9) and 3.5e-4, 9.5e-5, 2.5e-5 m (0.5). Before, its algorithmic
    # accelerations carried the jump on: 3.7e-3, 1.8e-3, 9.1e-4 m, first order, and a Newton
    # failure at dt = 0.04 with rho_inf = 0.9 (the iterates went back and forth over the jump).
    errors = [_largest_error(dt, scheme="generalized-alpha", rho_inf=rho_inf)[0]
              for dt in (0.04, 0.02, 0.01)]
    assert errors[0] < 5e-4
    assert errors[0] / errors[1] > 3.5
    assert errors[1] / errors[2] > 3.5


def test_backward_euler_steps_through_the_touchdown():
    # Backward Euler is first order (the error halves with dt: measured 5.7e-2, 3.0e-2,
    # 1.5e-2 m); at dt = 0.04 its Newton iterations failed across the jump, and the run
    # stopped with a ConvergenceError: a failed step across a jump now goes short of it.
    errors = [_largest_error(dt, scheme="backward-euler")[0] for dt in (0.04, 0.02, 0.01)]
    assert errors[0] < 0.1
    assert 1.8 < errors[0] / errors[1] < 2.2
    assert 1.8 < errors[1] / errors[2] < 2.2


def test_a_chain_landing_on_the_seabed_keeps_its_velocities_on_the_constraints():
    # The benchmark's chain on the seabed (20 segments, fairlead surging 2 m) with
    # generalised-alpha at 10 ms: each node that lands restarts the rule on the far side of
    # the jump, so the velocities stay on the segments' constraints (measured: at most
    # 7.3e-6 (scaled velocity violation); before, the stale algorithmic accelerations put them
    # 2.2e-2 off, and the output rows interpolated between steps 4.4e-6 off the segments'
    # lengths, which the tensions computed from the positions carry times EA / l).
    from vinculo.mooring import bench
    from vinculo.mooring.analysis import run

    model = bench.chain_on_seabed(20)
    result = run(model, bench.motion_for(model), 20.0, dt=0.01, plots=False,
                 scheme="generalized-alpha", rho_inf=0.5)
    solution = result.solution
    assert solution.steps_rejected > 0  # nodes landed
    assert np.max(solution.velocity_violation) < 1e-4
    assert np.max(solution.position_violation) < 1e-7


def test_the_steps_come_back_to_the_grid_after_the_touchdown():
    # The step to the touchdown leaves the grid of multiples of dt; after the transient the run
    # goes back to it, so that the steps end on the multiples of dt again (the same floats as
    # a run without the event), and output asked there is the steps' own state rather than an
    # interpolation between steps.
    dt = 0.04
    _, solution = _largest_error(dt, save_every=1)
    times = np.asarray(solution.times)
    later = times[times > 0.6]
    assert later.size >= 5
    np.testing.assert_array_equal(later, np.round(later / dt) * dt)
    grid = np.arange(0.0, 0.8 + 1e-9, dt)
    _, on_grid = _largest_error(dt, t_eval=grid)
    rows = np.asarray(on_grid.times) > 0.6
    # The rows asked for after 0.6 s are the steps' own states, bit for bit those of the run
    # that stores every step.
    np.testing.assert_array_equal(np.asarray(on_grid.positions)[rows],
                                  np.asarray(solution.positions)[times > 0.6])


def test_the_run_lands_on_the_touchdown():
    # The step that found the touchdown is replaced by one that ends there: a stored time at
    # t_c = sqrt(2 h0 / g), with the particle on the seabed (free fall is a quadratic, which the
    # event's Taylor polynomial holds exactly).
    _, solution = _largest_error(0.04)
    times = np.asarray(solution.times)
    t_c = math.sqrt(2.0 * HEIGHT / G)
    k = int(np.argmin(np.abs(times - t_c)))
    assert times[k] == pytest.approx(t_c, abs=1e-12)
    assert solution.positions[k, 0, 2] == pytest.approx(-DEPTH, abs=1e-9)
    assert solution.steps_rejected >= 1


def test_a_snapshot_taken_during_a_contact_event_restores_bit_for_bit(tmp_path):
    # The contact event's state (a pending event, the short steps of its transient) belongs to
    # the step controller: a snapshot taken 0.01 s after the touchdown (within the transient's
    # ten settling times of 5 ms), saved, loaded into a new simulation and stepped on, repeats
    # the steps of the simulation it was taken from.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    ball = system.add_particle(mass=MASS, position=(0.0, 0.0, -DEPTH + HEIGHT))
    system.add_seabed_contact(ball, depth=DEPTH, diameter=1.0, length=1.0, kbot=KBOT, cbot=CBOT)
    first = vinculo.Simulation(system, 0.8, 0.04)
    first.step_to(math.sqrt(2.0 * HEIGHT / G) + 0.01)
    path = tmp_path / "touchdown.snap"
    first.save_snapshot(path)
    second = vinculo.Simulation(system, 0.8, 0.04)
    second.load_snapshot(path)
    first.step_to(0.8)
    second.step_to(0.8)
    a, b = first.solution(), second.solution()
    assert a.times[-1] == b.times[-1] == pytest.approx(0.8, abs=1e-12)
    np.testing.assert_array_equal(a.positions[-5:], b.positions[-5:])
    np.testing.assert_array_equal(a.times[-5:], b.times[-5:])
