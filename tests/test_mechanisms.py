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


@pytest.mark.slow
def test_the_double_pendulum_with_error_controlled_steps_meets_1e_8_directly():
    # The same motion with adaptive steps at rtol = atol = 1e-9 in the GGL form (which holds the
    # velocity constraints; index-3 velocities drift off them, and the second angle then stalls
    # at 2.5e-8 rad whatever the tolerance), without extrapolation: the angles agree with
    # Lagrange's to 1e-8 rad (measured: 2.5e-9 and 6.0e-9 rad, 64,000 steps).
    system, first, second = double_pendulum()
    solution = vinculo.simulate(
        system, t_end=2.0, dt=1e-3, adaptive=True, rtol=1e-9, atol=1e-9, formulation="ggl"
    )
    angles = double_pendulum_angles(solution, first, second)
    reference = np.array(double_pendulum_reference(solution.times))
    assert np.max(np.abs(angles - reference)) < 1e-8


def test_elements_that_act_on_particles_only_refuse_a_point_and_say_so():
    system, first, _ = double_pendulum()
    point = system.point(first, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError, match="acts on particles only"):
        system.add_morison(
            point, volume=1e-3, area=0.01, drag_coefficient=1.0, added_mass_coefficient=0.5
        )


def test_a_redundant_joint_is_named():
    # A third revolute joint at the second bar's pivot repeats all five equations of the second.
    system, first, second = double_pendulum()
    joint = tuple(L1 * direction(THETA0[0]))
    system.add_joint("revolute", first, second, joint, Y)
    with pytest.raises(
        vinculo.RedundantConstraintsError, match="revolute joint #2: shared point along x"
    ):
        vinculo.simulate(system, t_end=0.1, dt=1e-3)


def planar_bar(system, mass, start, end, **kwargs):
    """A planar bar (in the x-z plane) from `start` to `end`: inertia m L^2 / 12 about y."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    length = np.linalg.norm(end - start)
    return system.add_planar_body(
        mass, tuple((start + end) / 2), mass * length**2 / 12, normal="y", **kwargs
    )


def xz(x, z):
    return (x, 0.0, z)


def driven_crank(system, crank, pin, phi0, omega):
    """Drives the crank's pin (at angle phi from +x, in the x-z plane) at phi = phi0 + omega t:
    the pin stays on the plane through the origin of normal (-sin phi, 0, cos phi)."""
    phi = vinculo.laws.polynomial([phi0, omega])
    normal = (-vinculo.laws.sin(phi), 0.0, vinculo.laws.cos(phi))
    return system.add_plane(system.point(crank, pin), normal, (0.0, 0.0, 0.0))


def test_a_four_bar_linkage_follows_its_closed_form_kinematics():
    # A crank-rocker (Grashof: 0.25 + 0.8 <= 0.7 + 0.5) of planar bars and four revolute joints,
    # the crank turned at 1 rev/s. The coupler's far end B is where the circles about the crank
    # pin A (radius r3) and the rocker's pivot O4 (radius r4) meet: the linkage is driven, so its
    # positions are the constraints' alone, to the solver's tolerance.
    r2, r3, r4, d = 0.25, 0.7, 0.5, 0.8
    omega, phi0 = 2 * math.pi, 0.3

    def closed_form(phi):
        a = np.array([r2 * math.cos(phi), r2 * math.sin(phi)])
        gap = np.array([d, 0.0]) - a
        dist = np.linalg.norm(gap)
        along = (r3**2 - r4**2 + dist**2) / (2 * dist)
        height = math.sqrt(r3**2 - along**2)
        b = a + along * gap / dist + height * np.array([-gap[1], gap[0]]) / dist
        return a, b

    a0, b0 = closed_form(phi0)
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    crank = planar_bar(system, 0.5, xz(0, 0), xz(*a0))
    coupler = planar_bar(system, 1.2, xz(*a0), xz(*b0))
    rocker = planar_bar(system, 0.9, xz(d, 0), xz(*b0))
    system.add_joint("revolute", None, crank, xz(0, 0), Y)
    system.add_joint("revolute", crank, coupler, xz(*a0), Y)
    system.add_joint("revolute", coupler, rocker, xz(*b0), Y)
    system.add_joint("revolute", rocker, None, xz(d, 0), Y)
    driven_crank(system, crank, xz(*a0), phi0, omega)
    # The bodies start at rest: the projection gives them the velocities of the driven motion.
    system.project_initial_state()
    tip = system.point(coupler, xz(*b0))
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-3)
    q = solution.positions
    for k in range(0, len(solution.times), 50):
        _, b = closed_form(phi0 + omega * solution.times[k])
        assert np.allclose(tip.position(q[k]), xz(*b), rtol=0, atol=1e-10)
    # One full turn of the crank brings every body back.
    np.testing.assert_allclose(q[-1], q[0], rtol=0, atol=1e-10)


def test_a_slider_crank_follows_its_closed_form_kinematics():
    # Crank r, rod l, slider on the x axis: x_B = r cos(phi) + sqrt(l^2 - r^2 sin(phi)^2) and its
    # rate x_B' = -r w sin(phi) (1 + r cos(phi) / sqrt(l^2 - r^2 sin(phi)^2)). Positions to the
    # solver's tolerance; the slider's velocity to the trapezoidal rule's O(dt^2).
    r, rod, omega, phi0 = 0.2, 0.6, 2 * math.pi, 0.0
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    a0 = (r * math.cos(phi0), r * math.sin(phi0))
    b0 = (a0[0] + math.sqrt(rod**2 - a0[1] ** 2), 0.0)
    crank = planar_bar(system, 0.4, xz(0, 0), xz(*a0))
    connecting_rod = planar_bar(system, 1.0, xz(*a0), xz(*b0))
    slider = system.add_planar_body(2.0, xz(*b0), 0.01, normal="y")
    system.add_joint("revolute", None, crank, xz(0, 0), Y)
    system.add_joint("revolute", crank, connecting_rod, xz(*a0), Y)
    system.add_joint("revolute", connecting_rod, slider, xz(*b0), Y)
    system.add_joint("prismatic", None, slider, xz(*b0), (1.0, 0.0, 0.0))
    driven_crank(system, crank, xz(*a0), phi0, omega)
    system.project_initial_state()
    errors = []
    for dt in (2e-3, 1e-3):
        solution = vinculo.simulate(system, t_end=1.0, dt=dt)
        t = solution.times
        phi = phi0 + omega * t
        root = np.sqrt(rod**2 - (r * np.sin(phi)) ** 2)
        # The slider's centre: the mean of its three particles of equal mass.
        x = np.mean([solution.particle(p)[:, 0] for p in slider["particles"]], axis=0)
        np.testing.assert_allclose(x, r * np.cos(phi) + root, rtol=0, atol=1e-10)
        rate = -r * omega * np.sin(phi) * (1 + r * np.cos(phi) / root)
        velocity = np.mean(
            [solution.particle_velocity(p)[:, 0] for p in slider["particles"]], axis=0
        )
        errors.append(np.max(np.abs(velocity - rate)))
    assert errors[1] < 1e-3 * r * omega
    assert 3.5 < errors[0] / errors[1] < 4.5


def test_a_torque_turns_a_pinned_bar_at_its_closed_form_rate():
    # A bar pinned at one end, no gravity, a constant torque tau about the pin's axis:
    # theta = tau t^2 / (2 I_O), I_O = m L^2 / 3.
    mass, length, tau = 1.5, 0.8, 0.4
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    rod = planar_bar(system, mass, xz(0, 0), xz(length, 0))
    system.add_joint("revolute", None, rod, xz(0, 0), Y)
    system.add_torque(rod, tau, Y, xz(0, 0))
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-3)
    centre = np.mean([solution.particle(p) for p in rod["particles"]], axis=0)
    # A positive torque about +y turns +x towards -z.
    theta = np.unwrap(np.arctan2(-centre[:, 2], centre[:, 0]))
    expected = tau * solution.times**2 / (2 * mass * length**2 / 3)
    np.testing.assert_allclose(theta, expected, rtol=0, atol=1e-6)


def test_a_tumbling_body_flips_about_its_intermediate_axis_as_eulers_equations_say():
    # A free rigid body (principal moments 1, 2, 2.5 kg m^2) spun about its intermediate axis
    # with a small perturbation: the spin flips (the tennis-racket instability). Its angular
    # velocity in the body's axes against Euler's equations
    # I1 w1' = (I2 - I3) w2 w3 (and cyclic), integrated by scipy at 1e-12; the trapezoidal
    # rule conserves the kinetic energy.
    moments = np.array([1.0, 2.0, 2.5])
    omega0 = np.array([0.02, 3.0, 0.02])
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    body = system.add_rigid_body(
        4.0, (0.0, 0.0, 0.0), np.diag(moments).tolist(), angular_velocity=tuple(omega0)
    )
    solution = vinculo.simulate(system, t_end=8.0, dt=2e-3)
    q = solution.positions
    v = solution.velocities
    vertices = [p.index for p in body["vertices"]]
    # Body axes from the octahedron's opposite vertices; w = 1/2 sum_k e_k x e_k'.
    spans = [q[:, vertices[2 * k]] - q[:, vertices[2 * k + 1]] for k in range(3)]
    rates = [v[:, vertices[2 * k]] - v[:, vertices[2 * k + 1]] for k in range(3)]
    lengths = [np.linalg.norm(s[0]) for s in spans]
    axes = [s / n for s, n in zip(spans, lengths, strict=True)]
    omega = 0.5 * sum(np.cross(e, r / n) for e, r, n in zip(axes, rates, lengths, strict=True))
    body_omega = np.stack([np.sum(omega * e, axis=1) for e in axes], axis=1)
    # The octahedron's axes are principal and right-handed: Euler's equations hold in them, with
    # the moments and the initial spin projected on them.
    inertia = np.array([e[0] @ np.diag(moments) @ e[0] for e in axes])
    initial = np.array([e[0] @ omega0 for e in axes])

    def euler(_t, w):
        i1, i2, i3 = inertia
        return [
            (i2 - i3) * w[1] * w[2] / i1,
            (i3 - i1) * w[2] * w[0] / i2,
            (i1 - i2) * w[0] * w[1] / i3,
        ]

    reference = scipy.integrate.solve_ivp(
        euler,
        (0.0, 8.0),
        initial,
        t_eval=solution.times,
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
    ).y.T
    # The spin about the intermediate axis reverses within the run ...
    middle = int(np.argmin(np.abs(inertia - 2.0)))
    assert abs(initial[middle]) == pytest.approx(3.0)
    assert (reference[:, middle] * initial[middle]).min() < -0.9 * 9.0
    # ... and the particles follow: the trapezoidal rule's O(dt^2) error, here 1e-3 of the spin.
    assert np.max(np.abs(body_omega - reference)) < 3e-3 * omega0[1]
    # The particles' kinetic energy (the body's, exactly) is conserved to round-off (measured:
    # 8e-13 of it over the 4,000 steps).
    masses = system.masses()
    energy = 0.5 * np.einsum("i,tij,tij->t", masses, v, v)
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-10


def test_a_triangle_of_particles_made_rigid_swings_as_a_compound_pendulum():
    # Particles O (fixed pivot), A and B made one rigid body, released at rest in the x-z plane:
    # it turns about y by alpha with I_O alpha'' = g sum m_i (x_i0 cos(alpha) + z_i0 sin(alpha))
    # (Lagrange: T = 1/2 I_O alpha'^2, I_O = sum m_i (x_i0^2 + z_i0^2), V = g sum m_i z_i), and
    # every particle is its start turned by alpha.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    start = {"a": (1.0, (0.3, 0.0, -0.1)), "b": (0.6, (0.1, 0.0, -0.4))}
    ids = {k: system.add_particle(m, x) for k, (m, x) in start.items()}
    cluster = system.add_rigid_cluster([pivot, ids["a"], ids["b"]])
    assert len(cluster["constraints"]) == 3
    masses = np.array([m for m, _ in start.values()])
    x0 = np.array([x for _, x in start.values()])
    inertia = np.sum(masses * (x0[:, 0] ** 2 + x0[:, 2] ** 2))

    def rhs(_t, y):
        a = y[0]
        torque = G * np.sum(masses * (x0[:, 0] * math.cos(a) + x0[:, 2] * math.sin(a)))
        return [y[1], torque / inertia]

    solution = vinculo.simulate(system, t_end=2.0, dt=5e-4)
    alpha = scipy.integrate.solve_ivp(
        rhs, (0, 2.0), [0.0, 0.0], t_eval=solution.times, rtol=1e-12, atol=1e-12
    ).y[0]
    for k, key in enumerate(start):
        # R_y(alpha) (x, z) = (x cos(alpha) + z sin(alpha), -x sin(alpha) + z cos(alpha)).
        x, z = x0[k, 0], x0[k, 2]
        expected = np.stack(
            [
                x * np.cos(alpha) + z * np.sin(alpha),
                0 * alpha,
                -x * np.sin(alpha) + z * np.cos(alpha),
            ],
            axis=1,
        )
        np.testing.assert_allclose(solution.particle(ids[key]), expected, rtol=0, atol=2e-5)


def test_bodies_that_share_a_particle_are_joined_there_by_a_spherical_joint():
    # Two clusters of four particles in space with one in common: 7 particles, 6 + 6 distances,
    # 21 - 12 = 9 degrees of freedom: a body in space (6) and a spherical joint (3). The start
    # analysis finds no redundant equation, and during the run each cluster stays rigid.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    shared = system.add_particle(1.0, (0.0, 0.0, 0.0))
    first = [shared] + [
        system.add_particle(1.0, x) for x in [(0.4, 0.0, 0.1), (0.1, 0.3, 0.0), (0.0, 0.1, 0.5)]
    ]
    second = [shared] + [
        system.add_particle(0.5, x)
        for x in [(-0.4, 0.1, 0.0), (-0.1, -0.3, 0.2), (-0.2, 0.0, -0.5)]
    ]
    one = system.add_rigid_cluster(first)
    two = system.add_rigid_cluster(second)
    assert len(one["constraints"]) + len(two["constraints"]) == 12
    assert 3 * system.num_particles - system.num_constraints == 9
    system.add_joint("spherical", None, one, (0.1, 0.1, 0.2))
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-3)
    for cluster in (first, second):
        q = np.array([solution.particle(p) for p in cluster])
        gaps = np.linalg.norm(q[:, None] - q[None, :], axis=-1)
        np.testing.assert_allclose(gaps, gaps[:, :, :1] * np.ones_like(gaps), rtol=0, atol=1e-9)
    # The second body swung about the shared particle (it is not welded to the first).
    q = np.array([solution.particle(p) for p in first + second[1:]])
    angle = lambda k: np.arccos(  # noqa: E731
        np.dot(q[4, k] - q[0, k], q[1, k] - q[0, k])
        / np.linalg.norm(q[4, k] - q[0, k])
        / np.linalg.norm(q[1, k] - q[0, k])
    )
    assert abs(angle(-1) - angle(0)) > 0.1


@pytest.mark.parametrize("particles", [7, 4])
def test_a_body_on_an_inclined_prismatic_joint_slides_as_a_block_on_a_ramp(particles):
    # A body on a frictionless prismatic joint to the ground along d = (cos 30, 0, -sin 30): its
    # centre moves along d by s = g sin(30) t^2 / 2 and it does not turn. The trapezoidal rule
    # is exact for a constant acceleration, so the only error is the solver's tolerance.
    slope = math.radians(30.0)
    d = np.array([math.cos(slope), 0.0, -math.sin(slope)])
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    inertia = np.diag([0.02, 0.03, 0.04]).tolist()
    body = system.add_rigid_body(2.0, (0.0, 0.0, 0.0), inertia, particles=particles)
    system.add_joint("prismatic", None, body, (0.0, 0.0, 0.0), tuple(d))
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-2)
    centre = solution.point(body["centre"]) if particles == 4 else solution.particle(body["centre"])
    s = 0.5 * G * math.sin(slope) * solution.times**2
    np.testing.assert_allclose(centre, np.outer(s, d), rtol=0, atol=1e-9)
    # Every particle moved by the same displacement: no rotation.
    for p in body["particles"]:
        shift = solution.particle(p) - solution.particle(p)[0]
        np.testing.assert_allclose(shift, np.outer(s, d), rtol=0, atol=1e-9)


def test_a_body_with_its_orientation_held_translates_under_an_off_centre_force():
    # An orientation joint to the ground (3 equations) leaves the three translations: a constant
    # force F at a point off the centre, which alone would also turn the body, moves it by
    # (F / m + g) t^2 / 2 without turning (the trapezoidal rule is exact for a constant
    # acceleration).
    mass, force = 2.0, np.array([3.0, -1.0, 4.0])
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    inertia = np.diag([0.02, 0.03, 0.04]).tolist()
    body = system.add_rigid_body(mass, (0.0, 0.0, 0.0), inertia, particles=4)
    equations = system.add_joint("orientation", None, body, (0.0, 0.0, 0.0))
    assert len(equations) == 3
    system.add_force(system.point(body, (0.1, 0.05, -0.2)), tuple(force))
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-2)
    acceleration = force / mass + np.array([0.0, 0.0, -G])
    expected = 0.5 * np.outer(solution.times**2, acceleration)
    for p in body["particles"]:
        shift = solution.particle(p) - solution.particle(p)[0]
        np.testing.assert_allclose(shift, expected, rtol=0, atol=1e-9)
