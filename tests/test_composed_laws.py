"""Laws that compose, spline end conditions and Python laws, against hand-derived derivatives,
scipy's splines and an independent pendulum ODE."""

import math

import numpy as np
import pytest
import scipy.integrate
import scipy.interpolate

import vinculo
from vinculo import laws

G = 9.81

# A guide moving as x_B(t) = sqrt(L^2 - y(t)^2), y(t) = A sin(w t + phi): the foot of a rod of
# length L whose other end is driven along y (the moving-guide benchmark's motion).
L, A, FREQUENCY, PHASE = 2.0, 0.7, 0.4, 0.5
W = 2 * math.pi * FREQUENCY


def guide_by_hand(t: float) -> tuple[float, float, float]:
    """x_B, x_B', x_B'' differentiated by hand: with u = L^2 - y^2, u' = -2 y y',
    u'' = -2 (y'^2 + y y''), x = sqrt(u), x' = u' / (2 x), x'' = u'' / (2 x) - u'^2 / (4 x^3)."""
    y = A * math.sin(W * t + PHASE)
    y1 = A * W * math.cos(W * t + PHASE)
    y2 = -W * W * y
    u, u1, u2 = L * L - y * y, -2 * y * y1, -2 * (y1 * y1 + y * y2)
    x = math.sqrt(u)
    return x, u1 / (2 * x), u2 / (2 * x) - u1 * u1 / (4 * x**3)


def guide_law() -> vinculo.Law:
    """The same guide as a formula of laws."""
    y = laws.sine(amplitude=A, frequency=FREQUENCY, phase=PHASE)
    return laws.sqrt(L**2 - y**2)


def test_a_composed_law_has_the_derivatives_derived_by_hand():
    law = guide_law()
    for t in np.linspace(0.0, 3.0, 13):
        np.testing.assert_allclose(law.derivatives(t), guide_by_hand(t), rtol=1e-13, atol=1e-14)


def test_operators_follow_the_product_and_quotient_rules():
    # p = 1 + t^2 (p' = 2 t, p'' = 2), s = sin t: closed forms of p s, s / p, 3 - p, p ** 1.5,
    # exp(-t) cos(2 t) and log(p), differentiated by hand.
    t_law = laws.time()
    p = 1.0 + t_law**2
    s = laws.sin(t_law)
    for t in (0.0, 0.4, 1.3, -0.8):
        sn, cs, pv = math.sin(t), math.cos(t), 1 + t * t
        cases = [
            (p * s, (pv * sn, 2 * t * sn + pv * cs, 2 * sn + 4 * t * cs - pv * sn)),
            (
                s / p,
                (
                    sn / pv,
                    cs / pv - 2 * t * sn / pv**2,
                    -sn / pv - 4 * t * cs / pv**2 - 2 * sn / pv**2 + 8 * t * t * sn / pv**3,
                ),
            ),
            (3 - p, (3 - pv, -2 * t, -2.0)),
            (-p, (-pv, -2 * t, -2.0)),
            (
                p**1.5,
                (pv**1.5, 3 * t * pv**0.5, 3 * pv**0.5 + 3 * t * t * pv**-0.5),
            ),
            (
                laws.exp(-t_law) * laws.cos(2 * t_law),
                (
                    math.exp(-t) * math.cos(2 * t),
                    math.exp(-t) * (-math.cos(2 * t) - 2 * math.sin(2 * t)),
                    math.exp(-t) * (-3 * math.cos(2 * t) + 4 * math.sin(2 * t)),
                ),
            ),
            (laws.log(p), (math.log(pv), 2 * t / pv, (2 * pv - 4 * t * t) / pv**2)),
        ]
        for law, expected in cases:
            np.testing.assert_allclose(law.derivatives(t), expected, rtol=1e-13, atol=1e-13)
    # Numbers stand in for constant laws on either side; other operands are a TypeError.
    assert (2.0 * laws.constant(3.0) / 4.0)(0.0) == 1.5
    with pytest.raises(TypeError):
        laws.time() + "1"


@pytest.mark.parametrize(
    ("ends", "scipy_bc"),
    [
        ("natural", "natural"),
        ("not-a-knot", "not-a-knot"),
        ("clamped", ((1, 0.3), (1, -1.1))),
    ],
)
def test_spline_end_conditions_match_scipy(ends, scipy_bc):
    # scipy.interpolate.CubicSpline with the same boundary conditions is the reference.
    rng = np.random.default_rng(7)
    times = np.cumsum(rng.uniform(0.05, 0.3, size=12))
    values = np.sin(3 * times) + rng.normal(0, 0.1, size=12)
    slopes = (0.3, -1.1) if ends == "clamped" else None
    law = laws.tabulated(times, values, ends=ends, slopes=slopes)
    reference = scipy.interpolate.CubicSpline(times, values, bc_type=scipy_bc)
    for t in np.linspace(times[0], times[-1], 97):
        expected = (reference(t), reference(t, 1), reference(t, 2))
        np.testing.assert_allclose(law.derivatives(t), expected, rtol=1e-10, atol=1e-10)


def test_a_tabulated_guide_needs_its_end_condition():
    # The guide sampled every h on [0, 2]: a natural table's slope at t = 0 is first-order
    # accurate (its zero end curvature is not the guide's), so halving h only halves its error;
    # a not-a-knot table's falls at least four times, and a clamped table, given the slopes,
    # has the right one. The natural table's wrong rate is what made a consistent start fail.
    rate = guide_by_hand(0.0)[1]

    def end_slope_errors(h):
        times = np.arange(0.0, 2.0 + h / 2, h)
        values = [guide_by_hand(t)[0] for t in times]
        return [
            abs(laws.tabulated(times, values, ends=ends).derivatives(0.0)[1] - rate)
            for ends in ("natural", "not-a-knot")
        ]

    (natural_1, not_a_knot_1), (natural_2, not_a_knot_2) = (
        end_slope_errors(0.1),
        end_slope_errors(0.05),
    )
    assert 1.8 < natural_1 / natural_2 < 2.2
    assert not_a_knot_1 / not_a_knot_2 > 3.5
    assert not_a_knot_2 < natural_2 / 20
    times = np.arange(0.0, 2.05, 0.1)
    clamped = laws.tabulated(
        times,
        [guide_by_hand(t)[0] for t in times],
        ends="clamped",
        slopes=(rate, guide_by_hand(2.0)[1]),
    )
    assert clamped.derivatives(0.0)[1] == pytest.approx(rate, rel=1e-14)


def test_spline_end_condition_errors_name_the_argument():
    with pytest.raises(vinculo.InvalidInputError, match="slopes"):
        laws.tabulated([0, 1, 2], [0, 1, 0], ends="clamped")
    with pytest.raises(vinculo.InvalidInputError, match="ends"):
        laws.tabulated([0, 1, 2], [0, 1, 0], ends="periodic")


def pendulum_on_guide(law: vinculo.Law, theta0: float, t_end: float, dt: float):
    """A bob hung by a rod of length l from a pivot moving along x by `law`, released at angle
    theta0 moving with the pivot; returns (solution, bob)."""
    length = 0.8
    x0, v0, _ = guide_by_hand(0.0)
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = system.add_particle(
        1.5,
        (x0 + length * math.sin(theta0), 0.0, -length * math.cos(theta0)),
        velocity=(v0, 0.0, 0.0),
    )
    system.add_distance_to_point(bob, (law, 0.0, 0.0), length)
    return vinculo.simulate(system, t_end=t_end, dt=dt), bob, length


def reference_angle(theta0: float, length: float, times: np.ndarray) -> np.ndarray:
    """The pendulum with a horizontally moving pivot in its angle alone:
    l theta'' = -g sin(theta) - x_B''(t) cos(theta) (Lagrange's equation in theta)."""

    def rhs(t, y):
        return [y[1], -(G * math.sin(y[0]) + guide_by_hand(t)[2] * math.cos(y[0])) / length]

    out = scipy.integrate.solve_ivp(
        rhs, (times[0], times[-1]), [theta0, 0.0], t_eval=times, rtol=1e-12, atol=1e-12
    )
    return out.y[0]


def test_a_pendulum_on_a_composed_guide_law_follows_the_angle_ode():
    # The law's second derivative drives the bob; its first derivative makes the start
    # consistent (the bob moves with the pivot). The trapezoidal rule's error at dt = 1 ms is
    # O(dt^2) ~ 1e-6 rad here; halving dt divides it by 4.
    errors = []
    for dt in (2e-3, 1e-3):
        solution, bob, length = pendulum_on_guide(guide_law(), 0.3, 3.0, dt)
        q = solution.particle(bob)
        pivot = np.array([guide_by_hand(t)[0] for t in solution.times])
        theta = np.arctan2(q[:, 0] - pivot, -q[:, 2])
        errors.append(np.max(np.abs(theta - reference_angle(0.3, length, solution.times))))
    assert errors[1] < 5e-6
    assert 3.5 < errors[0] / errors[1] < 4.5


def test_a_python_law_gives_the_run_of_the_same_formula():
    calls = []

    def guide(t):
        calls.append(t)
        return guide_by_hand(t)

    composed, bob, _ = pendulum_on_guide(guide_law(), 0.3, 1.0, 1e-2)
    python, bob_p, _ = pendulum_on_guide(laws.function(guide), 0.3, 1.0, 1e-2)
    # The same derivatives to rounding: the same trajectory to rounding.
    np.testing.assert_allclose(python.particle(bob_p), composed.particle(bob), rtol=0, atol=1e-12)
    assert len(calls) > 100


def test_a_failing_python_law_stops_the_run_and_keeps_its_steps():
    def guide(t):
        if t > 0.5:
            raise ValueError("the table ends at 0.5 s")
        return guide_by_hand(t)

    with pytest.raises(vinculo.UserFunctionError, match=r"the table ends at 0\.5 s") as caught:
        pendulum_on_guide(laws.function(guide, name="guide"), 0.3, 1.0, 1e-2)
    error = caught.value
    assert error.group == "guide" and error.call == "law"
    assert 0.5 < error.time <= 0.51
    assert error.solution.times[-1] == pytest.approx(0.5)


def test_a_python_law_must_return_three_numbers():
    with pytest.raises(vinculo.UserFunctionError, match=r"three numbers, returned 1\.0"):
        pendulum_on_guide(laws.function(lambda t: 1.0), 0.3, 0.1, 1e-2)
    with pytest.raises(vinculo.InvalidInputError, match="callable"):
        laws.function(3.0)


def test_a_law_leaving_its_domain_is_named_with_the_time():
    # sqrt(1 - t): the guide runs out of its domain at t = 1 (infinite rate, then NaN). The run
    # stops at the first step that needs it beyond, with the law, the element and the time
    # named, and keeps the steps before.
    guide = 2.0 + laws.sqrt(1.0 - laws.time())
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = system.add_particle(1.0, (3.0, 0.0, -1.0), velocity=(-0.5, 0.0, 0.0))
    system.add_distance_to_point(bob, (guide, 0.0, 0.0), 1.0)
    with pytest.raises(vinculo.InvalidInputError, match=r"sqrt\(\(1 \+ -1 \* polynomial") as caught:
        vinculo.simulate(system, t_end=2.0, dt=0.05)
    error = caught.value
    assert "distance to a moving point #0" in str(error)
    # The step to t = 1 needs only the value there (0, finite); the next one's end is outside.
    assert error.time == pytest.approx(1.05)
    assert error.solution.times[-1] == pytest.approx(1.0)


def test_a_python_law_drives_a_point_of_a_body():
    # The centre of a four-particle body follows the guide in x (a Python law) and stays at
    # y = z = 0: the body translates without turning (nothing turns it), its centre exactly on
    # the law, and the start is consistent because the body starts at the law's rate.
    x0, rate, _ = guide_by_hand(0.0)
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    inertia = np.diag([0.02, 0.03, 0.04]).tolist()
    body = system.add_rigid_body(
        1.5, (x0, 0.0, 0.0), inertia, velocity=(rate, 0.0, 0.0), particles=4
    )
    centre = body["centre"]
    system.add_fixed_coordinate(centre, "x", laws.function(guide_by_hand, name="guide"))
    system.add_fixed_coordinate(centre, "y", 0.0)
    system.add_fixed_coordinate(centre, "z", 0.0)
    solution = vinculo.simulate(system, t_end=1.0, dt=1e-2)
    expected = [guide_by_hand(t)[0] for t in solution.times]
    np.testing.assert_allclose(solution.point(centre)[:, 0], expected, rtol=0, atol=1e-12)
    shift = solution.positions - solution.positions[0]
    np.testing.assert_allclose(shift[:, :, 0] - shift[:, :1, 0], 0.0, atol=1e-9)
