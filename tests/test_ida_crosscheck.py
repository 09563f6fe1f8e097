"""Cross-check against SUNDIALS IDA (through scikit-sundae) on the index-1 form of the problem.

The pendulum whose pivot moves (``test_schemes.py``) written in Cartesian coordinates with its
multiplier, y = (x, z, vx, vz, lambda), for a bob of mass m on a link of length L to the pivot
p(t) = (a sin(w t), 0, 0), with vinculo's constraint Phi = L^2 - |q - p|^2 and d = q - p:

    x' = vx,   z' = vz
    m vx' = -2 lambda d_x,   m vz' = -m g - 2 lambda d_z
    0 = d . (q'' - p'') + |v - p'|^2                  (Phi'' = 0 divided by -2)

The last equation is algebraic in lambda once q'' is replaced by the dynamics, so the system
has index 1; IDA integrates it with variable order and step (BDF) at rtol = 1e-10. Skipped when
scikit-sundae is not installed.
"""

import numpy as np
import pytest

import vinculo
from vinculo import demos

sksundae = pytest.importorskip("sksundae")

GRAVITY = demos.GRAVITY
AMPLITUDE, OMEGA, LENGTH, MASS, THETA0, T_END = 0.1, 2.0 * np.pi, 1.0, 1.0, np.pi / 6, 1.0


def pivot(t):
    """Pivot position, velocity and acceleration along x."""
    s, c = np.sin(OMEGA * t), np.cos(OMEGA * t)
    return AMPLITUDE * s, AMPLITUDE * OMEGA * c, -AMPLITUDE * OMEGA**2 * s


def lambda_of(t, x, z, vx, vz):
    """The multiplier that makes Phi'' = 0 at (t, q, v): solves the algebraic equation."""
    p, pv, pa = pivot(t)
    dx, dz = x - p, z
    # d . (g_vec - 2 lambda d / m - p'') + |v - p'|^2 = 0 with g_vec = (0, -g).
    known = dx * (-pa) + dz * (-GRAVITY) + (vx - pv) ** 2 + vz**2
    return known * MASS / (2.0 * (dx * dx + dz * dz))


def residual(t, y, yp, res):
    x, z, vx, vz, lam = y
    p, _, _ = pivot(t)
    dx, dz = x - p, z
    res[0] = yp[0] - vx
    res[1] = yp[1] - vz
    res[2] = MASS * yp[2] + 2.0 * lam * dx
    res[3] = MASS * yp[3] + MASS * GRAVITY + 2.0 * lam * dz
    res[4] = lam - lambda_of(t, x, z, vx, vz)


def ida_solution(times):
    """IDA's (x, z, lambda) at ``times`` from a consistent start (at rest relative to the pivot)."""
    x0, z0 = np.sin(THETA0), -np.cos(THETA0)
    vx0, vz0 = AMPLITUDE * OMEGA, 0.0
    lam0 = lambda_of(0.0, x0, z0, vx0, vz0)
    y0 = np.array([x0, z0, vx0, vz0, lam0])
    yp0 = np.array([vx0, vz0, -2.0 * lam0 * x0 / MASS, -GRAVITY - 2.0 * lam0 * z0 / MASS, 0.0])
    solver = sksundae.ida.IDA(
        residual, algebraic_idx=[4], rtol=1e-10, atol=1e-12, max_num_steps=100_000
    )
    result = solver.solve(times, y0, yp0)
    assert result.success, result.message
    return result.y[:, 0], result.y[:, 1], result.y[:, 4]


def vinculo_solution(dt, **kwargs):
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    bob = system.add_particle(
        MASS, [np.sin(THETA0), 0.0, -np.cos(THETA0)], velocity=[AMPLITUDE * OMEGA, 0.0, 0.0]
    )
    link = system.add_distance_to_point(bob, (vinculo.sine(AMPLITUDE, 1.0), 0.0, 0.0), LENGTH)
    solution = vinculo.simulate(system, T_END, dt, **kwargs)
    return solution.times, solution.particle(bob), solution.multiplier(link)


def test_positions_converge_to_ida_at_second_order():
    # The bob every 10 ms against IDA: second order for both rules (the error falls fourfold when
    # the step halves, within 0.3 in log2), and at dt = 2.5e-4 below 2e-7 m (measured: 6e-8 m
    # trapezoidal, 1e-7 m generalised-alpha).
    for kwargs in ({"scheme": "trapezoidal"}, {"scheme": "generalized-alpha", "rho_inf": 0.5}):
        errors = []
        for dt in (5e-4, 2.5e-4):
            times, bob, _ = vinculo_solution(dt, **kwargs)
            every = slice(round(0.01 / dt), None, round(0.01 / dt))
            x, z, _ = ida_solution(np.concatenate([[0.0], times[every]]))
            gap = np.concatenate([bob[every, 0] - x[1:], bob[every, 2] - z[1:]])
            errors.append(np.abs(gap).max())
        assert abs(np.log2(errors[0] / errors[1]) - 2.0) < 0.3, (kwargs, errors)
        assert errors[1] < 2e-7, (kwargs, errors)


def test_multipliers_match_ida():
    # Generalised-alpha's multipliers at the step ends: 2.4e-6 N/m^2 from IDA's at dt = 2.5e-4
    # (the multiplier is about 7 N/m^2). The trapezoidal rule applies the multipliers at the
    # step's midpoint t_n + h/2 and, as index-3 multipliers of that rule do, they converge at
    # first order only: 2.6e-4 from IDA's at the midpoints (1e-3 at 1 ms).
    dt = 2.5e-4
    every = slice(40, None, 40)
    times, _, lam = vinculo_solution(dt, scheme="generalized-alpha", rho_inf=0.5)
    _, _, reference = ida_solution(np.concatenate([[0.0], times[every]]))
    assert np.max(np.abs(lam[every] - reference[1:])) < 1e-5
    times, _, lam = vinculo_solution(dt, scheme="trapezoidal")
    _, _, reference = ida_solution(np.concatenate([[0.0], times[every] - dt / 2]))
    assert np.max(np.abs(lam[every] - reference[1:])) < 5e-4


def test_ida_agrees_with_the_minimal_coordinate_reference():
    # The index-1 setup itself against the angle ODE of test_schemes (DOP853 at 1e-12): the two
    # independent references agree to 1e-8 m at t = 1 s.
    from pendulum_reference import angle_reference

    x, z, _ = ida_solution(np.array([0.0, T_END]))
    theta = angle_reference(THETA0, T_END, lambda t: pivot(t)[2])
    assert abs(x[-1] - (pivot(T_END)[0] + np.sin(theta))) < 1e-8
    assert abs(z[-1] + np.cos(theta)) < 1e-8
