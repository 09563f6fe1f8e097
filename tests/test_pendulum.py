"""A simple pendulum: period and rod tension against closed forms."""

import numpy as np
import pytest

import vinculo
from vinculo import demos

# docs/theory/formulation.md, "Checks that any implementation must pass": L = 1 m, g = 9.81,
# released horizontally at rest: T = 4 sqrt(L/g) K(1/sqrt 2) = 2.367841947576237 s.
EXACT_PERIOD = 2.367841947576237


def test_exact_period_helper_matches_reference_value():
    # The elliptic-integral formula used by the demos reproduces the reference value, and tends to
    # the small-amplitude period 2 pi sqrt(L/g) (textbook limit).
    assert demos.exact_pendulum_period(1.0, 9.81, np.pi / 2) == pytest.approx(
        EXACT_PERIOD, rel=1e-14
    )
    assert demos.exact_pendulum_period(1.0, 9.81, 1e-6) == pytest.approx(
        2 * np.pi / np.sqrt(9.81), rel=1e-12
    )


def test_zero_crossing_period_of_a_sampled_sine():
    # The period-measurement tool itself: a sine of known period sampled coarsely (30 samples per
    # period). Hermite interpolation with the derivative locates crossings to O(h^4).
    period = 1.7
    t = np.arange(0.0, 10.0, period / 30)
    x = np.sin(2 * np.pi * t / period + 0.3)
    v = 2 * np.pi / period * np.cos(2 * np.pi * t / period + 0.3)
    assert demos.crossing_period(t, x, v) == pytest.approx(period, rel=1e-6)
    # Linear interpolation alone is only O(h^2) but exact here by symmetry within 1e-3.
    assert demos.crossing_period(t, x) == pytest.approx(period, rel=1e-3)


def test_period_of_horizontally_released_pendulum():
    # Trapezoidal rule (alpha = 1/2) at dt = 2e-4: the phase error is about (omega dt)^2 / 12 per
    # unit time with omega <= sqrt(2 g / L) = 4.4 rad/s, i.e. ~1e-7 relative; required 1e-6.
    result = demos.run_pendulum(periods=3, dt=2e-4, alpha=0.5)
    assert result.exact_period == pytest.approx(EXACT_PERIOD, rel=1e-14)
    assert abs(result.period - EXACT_PERIOD) / EXACT_PERIOD < 1e-6
    # The rod keeps its length to round-off, in metres (constraint_residual = |Phi| / (2L)).
    assert np.max(result.solution.constraint_residual) < 1e-12


def test_rod_tension_from_multiplier_matches_energy_closed_form():
    # Closed form: v^2 = 2 g L (cos th - cos th0) from energy conservation, so the rod tension is
    # T = m g cos th + m v^2 / L = m g (3 cos th - 2 cos th0), with cos th = -z / L.
    # docs/theory/formulation.md: Phi = L^2 - |q - p|^2 gives the force -2 lambda (q - p), tension
    # 2 lambda L.
    model = demos.build_pendulum(length=1.0, mass=2.0, amplitude=np.pi / 3)
    dt = 1e-3
    solution = vinculo.simulate(model.system, t_end=3.0, dt=dt, alpha=0.5)
    tension = solution.distance_tension(model.rod, model.length)
    positions = solution.particle(model.bob)
    scale = 3 * model.mass * model.gravity  # the largest tension, m g (3 - 2 cos th0)

    # Row 0 comes from the consistent initial accelerations: at rest T = m g cos th0 exactly.
    assert tension[0] == pytest.approx(model.mass * model.gravity * np.cos(np.pi / 3), rel=1e-9)

    # The multiplier of step n -> n+1 is the constraint force in the dynamics equation, which the
    # generalised trapezoidal rule evaluates at t^n + alpha dt, i.e. at the configuration
    # (1 - alpha) q^n + alpha q^{n+1}. There the closed form holds up to the scheme's O(dt^2)
    # error, bounded by about (omega dt)^2 = 1.3e-5 of the largest tension (omega <= 3.6 rad/s).
    # Comparing with the end-of-step configuration instead would be off by O(dt): ~7e-4 here.
    z_alpha = 0.5 * (positions[:-1, 2] + positions[1:, 2])
    expected = model.mass * model.gravity * (3 * (-z_alpha / model.length) - 2 * np.cos(np.pi / 3))
    sample = np.linspace(1, len(expected) - 1, 25).astype(int)  # several times over 3 s
    np.testing.assert_allclose(tension[1:][sample], expected[sample], rtol=0, atol=2e-5 * scale)
    # ... and over the whole run, not only at the samples.
    assert np.max(np.abs(tension[1:] - expected)) < 2e-5 * scale
