"""Mechanisms of rigid bodies linked by joints at points fixed in them, against minimal-coordinate
equations of motion and closed-form kinematics."""

import math

import numpy as np
import pytest
import scipy.integrate

import vinculo

G = 9.81
Y = (0.0, 1.0, 0.0)


def bar(system, mass, length, centre, angle, radius=0.02, angular_velocity=0.0):
    """A slender bar in the x-z plane at `angle` from the downward vertical, as a rigid body:
    inertia m L^2 / 12 about its normals, m r^2 / 2 about its axis (a rod of radius r)."""
    d = np.array([math.sin(angle), 0.0, -math.cos(angle)])
    normal = mass * length**2 / 12
    axial = mass * radius**2 / 2
    inertia = normal * (np.eye(3) - np.outer(d, d)) + axial * np.outer(d, d)
    return system.add_rigid_body(
        mass, tuple(centre), inertia.tolist(), angular_velocity=(0.0, angular_velocity, 0.0)
    )


def direction(angle):
    return np.array([math.sin(angle), 0.0, -math.cos(angle)])


# The double physical pendulum: bar 1 (m1, L1) on a ground pivot at the origin, bar 2 (m2, L2)
# pinned at bar 1's end, both turning about y.
M1, L1, M2, L2 = 1.3, 0.9, 0.8, 0.6
THETA0 = (0.9, -0.5)


def double_pendulum_reference(times):
    """The angles from the downward vertical by Lagrange's equations in (theta1, theta2):
    M(theta) theta'' = f with c_i = L_i / 2, I_i = m_i L_i^2 / 12 about the centre,
    M = [[I1 + m1 c1^2 + m2 L1^2, m2 L1 c2 cos(t1 - t2)], [m2 L1 c2 cos(t1 - t2), I2 + m2 c2^2]],
    f = [-m2 L1 c2 sin(t1 - t2) t2'^2 - (m1 c1 + m2 L1) g sin t1,
         m2 L1 c2 sin(t1 - t2) t1'^2 - m2 c2 g sin t2]."""
    c1, c2 = L1 / 2, L2 / 2
    i1, i2 = M1 * L1**2 / 12, M2 * L2**2 / 12

    def rhs(_t, y):
        t1, t2, w1, w2 = y
        s, c = math.sin(t1 - t2), math.cos(t1 - t2)
        mass = np.array(
            [[i1 + M1 * c1**2 + M2 * L1**2, M2 * L1 * c2 * c], [M2 * L1 * c2 * c, i2 + M2 * c2**2]]
        )
        force = np.array(
            [
                -M2 * L1 * c2 * s * w2**2 - (M1 * c1 + M2 * L1) * G * math.sin(t1),
                M2 * L1 * c2 * s * w1**2 - M2 * c2 * G * math.sin(t2),
            ]
        )
        return [w1, w2, *np.linalg.solve(mass, force)]

    out = scipy.integrate.solve_ivp(
        rhs,
        (times[0], times[-1]),
        [*THETA0, 0.0, 0.0],
        t_eval=times,
        method="DOP853",
        rtol=1e-13,
        atol=1e-13,
    )
    return out.y[0], out.y[1]


def double_pendulum():
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    t1, t2 = THETA0
    joint = L1 * direction(t1)
    first = bar(system, M1, L1, 0.5 * L1 * direction(t1), t1)
    second = bar(system, M2, L2, joint + 0.5 * L2 * direction(t2), t2)
    system.add_joint("revolute", None, first, (0.0, 0.0, 0.0), Y)
    system.add_joint("revolute", first, second, tuple(joint), Y)
    return system, first, second


def double_pendulum_angles(solution, first, second):
    """The bars' angles from their centres' positions relative to their pivots."""
    c1 = solution.particle(first["centre"])
    c2 = solution.particle(second["centre"])
    joint = 2 * c1
    theta1 = np.arctan2(c1[:, 0], -c1[:, 2])
    theta2 = np.arctan2(c2[:, 0] - joint[:, 0], -(c2[:, 2] - joint[:, 2]))
    return np.array([theta1, theta2])


def test_a_double_physical_pendulum_of_two_bars_and_revolute_joints_follows_lagranges_equations():
    # Two bars, 14 particles, 30 rigid-body distances and 10 joint equations leave the 2 degrees
    # of freedom of Lagrange's equations. The trapezoidal rule is second order and symmetric, so
    # its error expands in even powers of dt: halving dt divides it by 4, and the Richardson
    # extrapolation (4 theta(dt/2) - theta(dt)) / 3 is fourth order. Over 2 s (a few swings,
    # before the motion turns chaotic) the extrapolated angles agree with Lagrange's to 1e-8 rad
    # (measured: 3e-10 and 1.1e-9).
    system, first, second = double_pendulum()
    times = np.linspace(0.0, 2.0, 101)
    angles = {}
    for dt in (1e-3, 5e-4):
        solution = vinculo.simulate(system, t_end=2.0, dt=dt, t_eval=times)
        angles[dt] = double_pendulum_angles(solution, first, second)
        # The motion is planar: the centres stay in y = 0 (the joints hold the axes along y).
        for body in (first, second):
            assert np.max(np.abs(solution.particle(body["centre"])[:, 1])) < 1e-12
    reference = np.array(double_pendulum_reference(times))
    coarse, fine = (np.max(np.abs(angles[dt] - reference)) for dt in (1e-3, 5e-4))
    assert 3.8 < coarse / fine < 4.2
    assert fine < 3e-5
    extrapolated = (4 * angles[5e-4] - angles[1e-3]) / 3
    assert np.max(np.abs(extrapolated - reference)) < 1e-8


def test_a_redundant_joint_is_named():
    # A third revolute joint at the second bar's pivot repeats all five equations of the second.
    system, first, second = double_pendulum()
    joint = tuple(L1 * direction(THETA0[0]))
    system.add_joint("revolute", first, second, joint, Y)
    with pytest.raises(vinculo.RedundantConstraintsError, match="revolute joint #2"):
        vinculo.simulate(system, t_end=0.1, dt=1e-3)
