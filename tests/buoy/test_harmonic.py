"""Harmonic fits: exact recovery, the phase convention, whole-period windows, the buoy's phases."""

import math
from dataclasses import replace

import numpy as np
import pytest

from vinculo.buoy.case import BuoyCase
from vinculo.buoy.harmonic import (
    PHASE_CONVENTION,
    fit_harmonic,
    steady_response,
    steady_window,
    wrap_phase,
)
from vinculo.buoy.reference import OneDofModel
from vinculo.errors import InvalidInputError

FREQUENCY = 0.9
OMEGA = 2 * math.pi * FREQUENCY


def samples(periods: int, per_period: int = 200) -> np.ndarray:
    """Uniform times over whole periods of FREQUENCY, both ends included."""
    return np.linspace(0.0, periods / FREQUENCY, periods * per_period + 1)


def test_fit_recovers_an_exact_sinusoid_with_offset():
    # Reference: the signal's own parameters, x = 0.3 + 2 sin(wt + 40 deg); a three-term fit of an
    # exact three-term signal is exact up to rounding.
    t = samples(5)
    x = 0.3 + 2.0 * np.sin(OMEGA * t + math.radians(40.0))
    fit = fit_harmonic(t, x, FREQUENCY, (t[0], t[-1]))
    assert fit.mean == pytest.approx(0.3, abs=1e-12)
    assert fit.amplitude == pytest.approx(2.0, rel=1e-12)
    assert fit.phase_deg == pytest.approx(40.0, abs=1e-10)
    assert fit.residual_rms < 1e-12
    assert fit.samples == t.size


def test_fit_with_noise_is_within_its_standard_error():
    # Reference: least squares with white noise of deviation s over N samples has standard errors
    # s sqrt(2 / N) on the amplitude and s sqrt(2 / N) / A rad on the phase; allow 5 of them.
    rng = np.random.default_rng(12345)
    t = samples(10)
    noise = 0.05
    x = -1.0 + 0.8 * np.sin(OMEGA * t - math.radians(25.0)) + rng.normal(0.0, noise, t.size)
    fit = fit_harmonic(t, x, FREQUENCY, (t[0], t[-1]))
    error = noise * math.sqrt(2.0 / t.size)
    assert fit.amplitude == pytest.approx(0.8, abs=5 * error)
    assert fit.mean == pytest.approx(-1.0, abs=5 * error)
    assert fit.phase_deg == pytest.approx(-25.0, abs=math.degrees(5 * error / 0.8))
    assert fit.residual_rms == pytest.approx(noise, rel=0.05)


def test_other_harmonics_drop_out_over_whole_periods():
    # Reference: over whole periods the 2nd and 3rd harmonics are orthogonal to the fundamental
    # (trapezoidal weights make the discrete sums exact), so the fit returns the fundamental alone.
    t = samples(4, per_period=64)
    x = (
        0.1
        + 1.5 * np.sin(OMEGA * t + 0.3)
        + 0.5 * np.sin(2 * OMEGA * t + 1.0)
        + 0.2 * np.cos(3 * OMEGA * t)
    )
    fit = fit_harmonic(t, x, FREQUENCY, (t[0], t[-1]))
    assert fit.amplitude == pytest.approx(1.5, rel=1e-12)
    assert fit.phase_deg == pytest.approx(math.degrees(0.3), abs=1e-10)
    assert fit.mean == pytest.approx(0.1, abs=1e-12)
    # By hand: the residual is the two other harmonics, rms sqrt((0.5^2 + 0.2^2) / 2).
    assert fit.residual_rms == pytest.approx(math.sqrt((0.25 + 0.04) / 2), rel=1e-12)


@pytest.mark.parametrize(
    ("signal", "phase"),
    [
        (lambda t: np.cos(OMEGA * t), 90.0),  # cos(wt) = sin(wt + 90): peaks a quarter period early
        (lambda t: np.sin(OMEGA * t - math.pi / 6), -30.0),  # peaks 1/12 period late: lags 30
        (lambda t: -np.sin(OMEGA * t), 180.0),
    ],
)
def test_phase_is_the_lead_over_sine(signal, phase):
    # Reference: by hand, the angle phi in sin(wt + phi) for each signal.
    t = samples(3)
    fit = fit_harmonic(t, signal(t), FREQUENCY, (t[0], t[-1]))
    assert fit.phase_deg == pytest.approx(phase, abs=1e-9)


def test_fit_uses_only_the_window():
    # Reference: the signal is 1 sin(wt) before t = 5/f and 3 sin(wt) after; a window of the last
    # five periods sees only the second part (the boundary sample, at a zero of sin, adds nothing).
    t = samples(10)
    x = np.where(t < 5 / FREQUENCY, 1.0, 3.0) * np.sin(OMEGA * t)
    fit = fit_harmonic(t, x, FREQUENCY, (5 / FREQUENCY, 10 / FREQUENCY))
    assert fit.amplitude == pytest.approx(3.0, rel=1e-9)
    assert fit.window == (5 / FREQUENCY, 10 / FREQUENCY)


def test_steady_window_covers_whole_periods_ending_at_t_end():
    # Reference: n periods of 1/f last n/f exactly.
    start, end = steady_window(40.0 / 0.7, 0.7, 10)
    assert end == 40.0 / 0.7
    assert (end - start) * 0.7 == pytest.approx(10.0, rel=1e-14)
    with pytest.raises(InvalidInputError, match="longer than the time history") as caught:
        steady_window(5.0, 0.7, 10)
    assert caught.value.name == "fit_periods"
    with pytest.raises(InvalidInputError) as caught:
        steady_window(50.0, 0.7, 0)
    assert caught.value.name == "fit_periods"


def test_wrap_phase_range():
    # Reference: by hand, shifting by whole turns into (-90, 270].
    np.testing.assert_array_equal(
        wrap_phase(np.array([-90.0, 270.0, 0.0, -100.0, 630.0, 300.0, -89.0])),
        [270.0, 270.0, 0.0, 260.0, 270.0, -60.0, -89.0],
    )
    assert wrap_phase(-180.0) == 180.0
    assert "(-90, 270]" in PHASE_CONVENTION


def test_steady_response_of_a_known_pair_of_signals():
    # Reference: by hand. Tank 5 mm sin(wt); relative motion of twice that amplitude leading it by
    # 200 deg; the absolute motion is their sum, by phasor addition.
    t = samples(20)
    tank = 0.005 * np.sin(OMEGA * t)
    lead = math.radians(200.0)
    relative = 0.010 * np.sin(OMEGA * t + lead)
    response = steady_response(t, tank + relative, tank, FREQUENCY, 10)
    assert response.relative_ratio == pytest.approx(2.0, rel=1e-12)
    assert response.relative_amplitude == pytest.approx(0.010, rel=1e-12)
    assert response.relative_phase_deg == pytest.approx(200.0, abs=1e-9)
    phasor = 1.0 + 2.0 * complex(math.cos(lead), math.sin(lead))
    assert response.absolute_ratio == pytest.approx(abs(phasor), rel=1e-12)
    assert response.absolute_phase_deg == pytest.approx(
        wrap_phase(math.degrees(math.atan2(phasor.imag, phasor.real))), abs=1e-9
    )
    assert response.window == pytest.approx((10 / FREQUENCY, 20 / FREQUENCY), rel=1e-14)
    assert response.settling == pytest.approx(0.0, abs=1e-12)


def test_settling_compares_the_last_two_windows():
    # Reference: by hand, a relative amplitude of 4 mm in the window before the last and 5 mm in
    # the last gives |5 - 4| / 5 = 0.2.
    t = samples(20)
    tank = 0.005 * np.sin(OMEGA * t)
    relative = np.where(t < 15 / FREQUENCY, 0.004, 0.005) * np.sin(OMEGA * t)
    response = steady_response(t, tank + relative, tank, FREQUENCY, 5)
    assert response.settling == pytest.approx(0.2, rel=1e-9)
    # Without room for the earlier window there is no settling figure.
    kept = t <= 15 / FREQUENCY
    short = steady_response(t[kept], tank[kept], tank[kept], FREQUENCY, 10)
    assert math.isnan(short.settling)


def test_steady_response_rejects_a_still_tank_and_a_short_history():
    t = samples(12)
    with pytest.raises(InvalidInputError, match="does not move") as caught:
        steady_response(t, np.sin(OMEGA * t), np.zeros_like(t), FREQUENCY, 10)
    assert caught.value.name == "x_tank"
    with pytest.raises(InvalidInputError, match="after the fit window") as caught:
        late = t[t > 5 / FREQUENCY]
        steady_response(late, np.sin(OMEGA * late), np.sin(OMEGA * late), FREQUENCY, 10)
    assert caught.value.name == "t"


def test_fit_rejects_a_window_without_samples():
    t = samples(2)
    with pytest.raises(InvalidInputError, match="samples fall in the window") as caught:
        fit_harmonic(t, np.sin(OMEGA * t), FREQUENCY, (10.0, 11.0))
    assert caught.value.name == "window"


@pytest.mark.parametrize(
    ("frequency", "relative", "absolute", "tolerance"),
    [
        (0.6, 180.0, 0.0, 3.0),  # below the antiresonance (0.70 Hz): both quasi-static
        (0.8, 180.0, 180.0, 8.0),  # between antiresonance and resonance: absolute flips
        (None, 90.0, None, 10.0),  # at the linear natural frequency
        (1.5, 0.0, 0.0, 3.0),  # above resonance: relative motion in phase with the tank
    ],
)
def test_buoy_phases_follow_the_convention(frequency, relative, absolute, tolerance):
    # Reference: the linear undamped closed form of the point-mass pendulum, x_rel = H X_t with
    # H = -mu w^2 / (mu g / L - m w^2): H < 0 (180 deg) below resonance, H > 0 (0 deg) above; the
    # absolute motion (1 + H) X_t changes sign at the antiresonance; with any damping the phase is
    # 90 deg at resonance. Tolerances: the quadratic drag shifts the phases by a few degrees away
    # from resonance (most near it); at resonance the swing's softening (13 deg) lowers the
    # resonance slightly, leaving the phase a few degrees under 90.
    case = replace(BuoyCase(), ramp_periods=10.0)
    model = OneDofModel(case, include_inertia=False)
    frequency = frequency or model.natural_frequency()
    run = model.simulate(frequency, 30 / frequency, sample_dt=0.005)
    response = steady_response(run.times, run.x_abs, run.x_tank, frequency, 10)
    assert response.relative_phase_deg == pytest.approx(relative, abs=tolerance)
    if absolute is not None:
        assert response.absolute_phase_deg == pytest.approx(absolute, abs=tolerance)
