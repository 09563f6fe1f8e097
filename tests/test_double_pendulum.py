"""Small oscillations of a double pendulum against its linear normal modes."""

import numpy as np
import pytest

from vinculo import demos

G, L = 9.81, 1.0
# Equal masses m and lengths l, linearised: omega^2 = (2 -/+ sqrt 2) g / l
# (docs/theory/formulation.md; e.g.
# Goldstein, Classical Mechanics, the double pendulum), with mode shapes th2 / th1 = +/- sqrt 2.
OMEGA_SLOW = np.sqrt((2 - np.sqrt(2)) * G / L)  # 2.3972 rad/s
OMEGA_FAST = np.sqrt((2 + np.sqrt(2)) * G / L)  # 5.7874 rad/s


def test_closed_form_helper():
    assert demos.normal_mode_frequencies(L, G) == pytest.approx((OMEGA_SLOW, OMEGA_FAST), rel=1e-15)


def test_normal_mode_frequencies():
    # Released at rest from th1 = 0.005 rad, th2 = 0: both modes are excited. The angles are
    # projected onto the linear modes and each modal coordinate's period comes from its zero
    # crossings over 20 s (7 slow and 18 fast periods).
    # Tolerance 0.1 %: the amplitude-dependent frequency shift is O(th^2) ~ 1e-4 at most here and
    # the trapezoidal phase error (omega dt)^2 / 12 ~ 3e-6 at dt = 1 ms.
    model = demos.build_double_pendulum(theta1=0.005, theta2=0.0, length=L, mass=1.0, gravity=G)
    result = demos.run_double_pendulum(t_end=20.0, dt=1e-3, alpha=0.5, model=model)
    slow, fast = result.frequencies
    assert slow == pytest.approx(OMEGA_SLOW, rel=1e-3)
    assert fast == pytest.approx(OMEGA_FAST, rel=1e-3)
    # Both modes were really present (the projection did not produce one from noise).
    amplitudes = np.max(np.abs(result.modal), axis=0)
    assert np.all(amplitudes > 0.1 * np.max(amplitudes))


@pytest.mark.parametrize(("mode", "ratio"), [(0, np.sqrt(2)), (1, -np.sqrt(2))])
def test_released_in_a_normal_mode_it_stays_there(mode, ratio):
    # Released in the shape th2 = +/- sqrt 2 th1 of one linear mode, the other modal coordinate
    # stays zero in linear theory; the nonlinear coupling is O(th^2) ~ 1e-4 of the amplitude.
    model = demos.build_double_pendulum(theta1=0.005, theta2=ratio * 0.005, length=L, gravity=G)
    result = demos.run_double_pendulum(t_end=10.0, dt=1e-3, alpha=0.5, model=model)
    amplitudes = np.max(np.abs(result.modal), axis=0)
    assert amplitudes[1 - mode] < 1e-3 * amplitudes[mode]
    expected = (OMEGA_SLOW, OMEGA_FAST)[mode]
    assert result.frequencies[mode] == pytest.approx(expected, rel=1e-3)
