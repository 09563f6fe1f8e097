"""Prescribed laws: values and derivatives against closed forms and finite differences."""

import math

import numpy as np
import pytest
import scipy.interpolate

import vinculo
from vinculo import Law, laws

TIMES = [-1.3, 0.0, 0.25, 0.7, 1.9, 3.2]


def finite_differences(law: Law, t: float, h: float = 1e-4) -> tuple[float, float]:
    """Central differences of the law's value: first and second derivative, O(h^2) accurate."""
    f_minus, f_0, f_plus = law(t - h), law(t), law(t + h)
    return (f_plus - f_minus) / (2 * h), (f_plus - 2 * f_0 + f_minus) / (h * h)


def test_constant():
    law = laws.constant(2.5)
    for t in TIMES:
        assert law.derivatives(t) == (2.5, 0.0, 0.0)
    assert law.domain() == (-math.inf, math.inf)


def test_polynomial_matches_closed_form():
    # p(t) = 1 - 2 t + 3 t^2 + 0.5 t^3, p' = -2 + 6 t + 1.5 t^2, p'' = 6 + 3 t.
    law = laws.polynomial([1.0, -2.0, 3.0, 0.5])
    for t in TIMES:
        value, first, second = law.derivatives(t)
        assert value == pytest.approx(1 - 2 * t + 3 * t**2 + 0.5 * t**3, rel=1e-14, abs=1e-14)
        assert first == pytest.approx(-2 + 6 * t + 1.5 * t**2, rel=1e-14, abs=1e-14)
        assert second == pytest.approx(6 + 3 * t, rel=1e-14, abs=1e-14)
        assert law(t) == value
    # Accepts numpy arrays, as Law.polynomial accepts lists.
    assert laws.polynomial(np.array([1.0, -2.0])).derivatives(0.5) == (0.0, -2.0, 0.0)


def test_sine_without_ramp_matches_closed_form():
    amplitude, frequency, phase, offset = 0.3, 1.7, 0.4, -0.2
    law = laws.sine(amplitude, frequency, phase=phase, offset=offset)
    w = 2 * np.pi * frequency
    for t in TIMES:
        value, first, second = law.derivatives(t)
        assert value == pytest.approx(offset + amplitude * np.sin(w * t + phase), abs=1e-14)
        assert first == pytest.approx(amplitude * w * np.cos(w * t + phase), abs=1e-13)
        assert second == pytest.approx(-amplitude * w**2 * np.sin(w * t + phase), abs=1e-12)


def quintic_ramp(u: float) -> tuple[float, float, float]:
    """The C2 ramp from 0 to 1 on [0, 1]: 10 u^3 - 15 u^4 + 6 u^5 and its derivatives in u.

    It is the unique quintic with s(0) = 0, s(1) = 1 and zero first and second derivatives at
    both ends.
    """
    if u <= 0:
        return 0.0, 0.0, 0.0
    if u >= 1:
        return 1.0, 0.0, 0.0
    return (
        10 * u**3 - 15 * u**4 + 6 * u**5,
        30 * u**2 - 60 * u**3 + 30 * u**4,
        60 * u - 180 * u**2 + 120 * u**3,
    )


def test_sine_with_ramp_matches_closed_form_and_finite_differences():
    amplitude, frequency, ramp, start = 0.005, 0.9, 2.0, 0.5
    law = laws.sine(amplitude, frequency, ramp_time=ramp, t_start=start)
    w = 2 * np.pi * frequency
    for t in np.linspace(start, start + ramp + 1.0, 23):
        s, s1, s2 = quintic_ramp((t - start) / ramp)
        s1, s2 = s1 / ramp, s2 / ramp**2
        phase = w * (t - start)
        g, g1, g2 = np.sin(phase), w * np.cos(phase), -(w**2) * np.sin(phase)
        value, first, second = law.derivatives(t)
        scale = amplitude * w**2
        assert value == pytest.approx(amplitude * s * g, abs=1e-15)
        assert first == pytest.approx(amplitude * (s1 * g + s * g1), abs=1e-14 * scale)
        expected_second = amplitude * (s2 * g + 2 * s1 * g1 + s * g2)
        assert second == pytest.approx(expected_second, abs=1e-13 * scale)
        # The analytic derivatives agree with differences of the values (O(h^2) ~ 1e-8 here).
        d1, d2 = finite_differences(law, t, h=1e-4)
        assert first == pytest.approx(d1, abs=1e-7 * scale)
        assert second == pytest.approx(d2, abs=1e-5 * scale)


def test_sine_ramp_is_twice_continuously_differentiable():
    # C2 at both ends of the ramp: value, rate and acceleration continuous across t_start and
    # t_start + ramp_time (the point of the smooth start: no jump in the force it implies).
    law = laws.sine(1.0, 1.0, ramp_time=1.5, t_start=0.5)
    for joint in (0.5, 2.0):
        before, after = law.derivatives(joint - 1e-9), law.derivatives(joint + 1e-9)
        np.testing.assert_allclose(before, after, rtol=0, atol=1e-6)
    # Before the start the oscillation is off: s = 0.
    assert law.derivatives(0.2) == (0.0, 0.0, 0.0)


def test_tabulated_reproduces_linear_data_exactly():
    # A natural cubic spline through samples of a straight line is that line (its second
    # derivative, zero at the ends, is zero throughout).
    times = [0.0, 0.3, 1.0, 1.2, 2.5]
    law = laws.tabulated(times, [2.0 - 3.0 * t for t in times])
    for t in np.linspace(0.0, 2.5, 17):
        value, first, second = law.derivatives(t)
        assert value == pytest.approx(2.0 - 3.0 * t, abs=1e-13)
        assert first == pytest.approx(-3.0, abs=1e-12)
        assert second == pytest.approx(0.0, abs=1e-11)
    assert law.domain() == (0.0, 2.5)


def test_tabulated_is_the_natural_cubic_spline():
    # Reference: scipy's CubicSpline with natural end conditions through the same samples.
    times = np.array([0.0, 0.2, 0.5, 0.6, 1.1, 1.5, 2.0])
    values = np.cos(3 * times)
    law = laws.tabulated(times, values)
    reference = scipy.interpolate.CubicSpline(times, values, bc_type="natural")
    for t in np.linspace(0.0, 2.0, 41):
        value, first, second = law.derivatives(t)
        assert value == pytest.approx(float(reference(t)), abs=1e-12)
        assert first == pytest.approx(float(reference(t, 1)), abs=1e-11)
        assert second == pytest.approx(float(reference(t, 2)), abs=1e-10)


def test_tabulated_approximates_a_smooth_function():
    # sin(t) sampled every 0.05 on [0, 3]: a natural spline is O(h^4) accurate in the interior
    # (about h^4 / 384 max|f''''| ~ 2e-8); the ends, where the natural condition forces f'' = 0
    # while sin'' = -sin(3) = -0.14 at t = 3, are less accurate, hence the margin kept below.
    times = np.linspace(0.0, 3.0, 61)
    law = laws.tabulated(times, np.sin(times))
    inner = np.linspace(0.5, 2.5, 101)
    errors = [abs(law(t) - np.sin(t)) for t in inner]
    assert max(errors) < 1e-6
    rate_errors = [abs(law.derivatives(t)[1] - np.cos(t)) for t in inner]
    assert max(rate_errors) < 1e-4


def test_law_constructors_are_the_core_constructors():
    # The friendly functions build the same laws as Law's static constructors.
    assert isinstance(laws.constant(1.0), vinculo.Law)
    a = laws.sine(0.2, 1.1, phase=0.3, offset=0.1, ramp_time=0.5, t_start=0.2)
    b = Law.sine(0.2, 1.1, 0.3, 0.1, 0.5, 0.2)
    for t in TIMES:
        assert a.derivatives(t) == b.derivatives(t)


@pytest.mark.parametrize(
    ("times", "values"),
    [
        ([0.0, 1.0, 0.5], [1.0, 2.0, 3.0]),  # not increasing
        ([0.0, 1.0, 1.0], [1.0, 2.0, 3.0]),  # repeated time
        ([0.0, 1.0], [1.0, 2.0, 3.0]),  # lengths differ
        ([0.0], [1.0]),  # a single sample
        ([0.0, float("nan")], [1.0, 2.0]),
    ],
)
def test_tabulated_rejects_bad_tables(times, values):
    with pytest.raises(vinculo.InvalidInputError):
        laws.tabulated(times, values)
