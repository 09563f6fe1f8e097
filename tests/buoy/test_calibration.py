"""Calibration of Cd and Ca: synthetic measurements made by the model with known coefficients
plus Gaussian noise of known standard deviation must be fitted back within the reported
uncertainty (3 standard uncertainties: a 99.7 % interval for a well-posed linearised fit)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vinculo.buoy import BuoyCase, SweepSettings, read_measurements
from vinculo.buoy.calibration import calibrate, model_curve, wrap_phase_difference
from vinculo.buoy.data import Measurements
from vinculo.cli import main
from vinculo.errors import InvalidInputError

# Short runs around the resonance, where the amplitude depends on Cd and the phase on Ca.
SETTINGS = SweepSettings(settle_periods=10, fit_periods=4, dt=5e-3)
FREQUENCIES = np.array([0.7, 0.85, 0.9, 0.95, 1.2])
TRUE = {"drag_coefficient": 0.35, "added_mass_coefficient": 0.7}


def _synthetic(seed: int = 11) -> Measurements:
    case = dataclasses.replace(BuoyCase(), **TRUE)
    amplitude, phase = model_curve(case, SETTINGS, FREQUENCIES)
    rng = np.random.default_rng(seed)
    amplitude_sd = 0.01 * amplitude + 2e-5  # 1 % plus 20 micrometres
    phase_sd = np.full(FREQUENCIES.size, 1.0)  # degrees
    return Measurements(
        FREQUENCIES,
        amplitude + amplitude_sd * rng.standard_normal(FREQUENCIES.size),
        phase + phase_sd * rng.standard_normal(FREQUENCIES.size),
        "absolute",
        "synthetic",
        amplitude_sd,
        phase_sd,
    )


@pytest.mark.slow  # about 16 s: 20 model sweeps of 5 runs
def test_recovers_drag_and_added_mass_within_their_uncertainty():
    data = _synthetic()
    result = calibrate(data, settings=SETTINGS, workers=2, progress=False)
    assert result.success and result.absolute_weights
    for name, value, sd in zip(result.names, result.values, result.uncertainties, strict=True):
        assert abs(value - TRUE[name]) < 3.0 * sd, (name, value, sd)
        assert sd < 0.1 * TRUE[name]  # informative: the data do pin the coefficient down
    # the fit explains the data to the noise: chi-square near its 5 degrees of freedom
    assert result.chi_square < 20.0
    assert result.fitted_amplitude == pytest.approx(
        model_curve(result.case, SETTINGS, FREQUENCIES)[0], rel=1e-12
    )


def test_bad_requests_are_refused():
    data = Measurements(np.array([0.9]), np.array([0.01]), np.array([90.0]), "absolute", "x")
    with pytest.raises(InvalidInputError, match="cannot calibrate 'gravity'"):
        calibrate(data, parameters=["gravity"], progress=False)
    with pytest.raises(InvalidInputError, match="not enough to fit 2 parameters"):
        calibrate(data, progress=False)
    with pytest.raises(InvalidInputError, match="unknown model"):
        calibrate(data, parameters=["drag_coefficient"], model="cfd", progress=False)


def test_phase_differences_wrap_to_a_half_turn():
    # Reference: the wrapped difference is the representative of d modulo 360 in (-180, 180].
    assert wrap_phase_difference(np.array([350.0, -350.0, 180.0, -180.0, 10.0])) == (
        pytest.approx([-10.0, 10.0, 180.0, 180.0, 10.0])
    )


def test_cli_calibrate_writes_results(tmp_path, capsys):
    data = _synthetic(seed=3)
    path = tmp_path / "measured.csv"
    lines = ["frequency, amplitude, phase, amplitude_sd, phase_sd"] + [
        f"{f}, {float(a)!r}, {float(p)!r}, {float(sa)!r}, {float(sp)!r}"
        for f, a, p, sa, sp in zip(data.frequency, data.amplitude, data.phase_deg,
                                   data.amplitude_sd, data.phase_sd, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")
    assert read_measurements(path).amplitude_sd == pytest.approx(data.amplitude_sd)
    output = tmp_path / "cal"
    code = main([
        "buoy", "calibrate", "--data", str(path), "--fit", "drag_coefficient",
        "--settle-periods", "10", "--fit-periods", "4", "--dt", "5e-3",
        "--added-mass-coefficient", "0.7", "-o", str(output), "--no-progress",
        "--curve-points", "3",
    ])
    assert code == 0
    rows = (output / "calibration.csv").read_text().splitlines()
    name, start, value, sd = rows[1].split(",")
    assert name == "drag_coefficient" and float(start) == 0.22
    assert abs(float(value) - TRUE["drag_coefficient"]) < 3.0 * float(sd)
    assert (output / "calibration.png").is_file()
    # the fitted curve at the measured ends equals the fitted model there (same runs)
    curve = (output / "calibration_fitted_curve.csv").read_text().splitlines()[1:]
    assert len(curve) == 3
    fitted = (output / "calibration_curves.csv").read_text().splitlines()[1:]
    first = {float(r.split(",")[0]): float(r.split(",")[7]) for r in fitted}
    assert float(curve[0].split(",")[1]) == pytest.approx(first[0.7], rel=1e-12)
    assert not list(output.glob(".*partial"))
    assert "drag_coefficient" in capsys.readouterr().out
    assert math.isfinite(float(sd))


def _oscillator(case, settings, frequencies, *, model="particle", motion="absolute", pool=None):
    """A closed-form stand-in for a model sweep: a linear oscillator of mass m_s + Ca m_f,
    damping proportional to Cd and the buoyant stiffness of the 1-DOF pendulum, forced by
    (m_f - m_s) X0 w^2 (amplitude and phase of x = A sin(w t + phase), the steady state of
    m x'' + c x' + k x = F sin(w t))."""
    w = 2.0 * np.pi * np.asarray(frequencies, dtype=float)
    mass = case.sphere_mass + case.added_mass
    stiffness = (case.displaced_mass - case.sphere_mass) * case.gravity / case.pendulum_length
    damping = 4.0 * case.drag_coefficient
    force = (case.displaced_mass - case.sphere_mass) * case.amplitude * w**2
    denominator = (stiffness - mass * w**2) + 1j * damping * w
    response = force / denominator
    return np.abs(response), np.degrees(np.angle(response))


def test_max_evaluations_bounds_every_model_sweep(tmp_path, monkeypatch, capsys):
    # Before, least_squares' max_nfev left out the sweeps of its finite differences (and the
    # fitted curve came on top): --max-evaluations 10 ran 17 sweeps. Counted here by wrapping
    # the one function that runs a sweep; the model is the closed-form oscillator above, so
    # the fit itself is exact and quick.
    from vinculo.buoy import calibration

    calls: list[int] = []

    def counted(*args, **kwargs):
        calls.append(len(args[2]))
        return _oscillator(*args, **kwargs)

    monkeypatch.setattr(calibration, "model_curve", counted)
    truth = dataclasses.replace(BuoyCase(), **TRUE)
    amplitude, phase = _oscillator(truth, SETTINGS, FREQUENCIES)
    path = tmp_path / "measured.csv"
    path.write_text("frequency, amplitude, phase\n" + "".join(
        f"{f!r}, {float(a)!r}, {float(p)!r}\n"
        for f, a, p in zip(FREQUENCIES.tolist(), amplitude, phase, strict=True)
    ))
    code = main(["buoy", "calibrate", "--data", str(path), "--max-evaluations", "10",
                 "--workers", "1", "-o", str(tmp_path / "cal"), "--no-progress"])
    assert code in (0, 1)  # 1: stopped by the budget before convergence
    assert 1 <= len(calls) <= 10
    assert f"{len(calls)} model sweeps" in capsys.readouterr().out
    # With room to converge, the same fit recovers the coefficients of the exact data (the
    # optimiser's tolerance, 1e-8 relative in cost, leaves them to about 1e-6), within budget.
    calls.clear()
    data = read_measurements(path)
    result = calibrate(data, workers=1, progress=False, max_evaluations=40)
    assert result.success and 1 <= len(calls) <= 40 and result.evaluations == len(calls)
    for name, value in zip(result.names, result.values, strict=True):
        assert value == pytest.approx(TRUE[name], rel=1e-5)
    # Too small a budget for one Jacobian is refused before anything runs.
    calls.clear()
    with pytest.raises(InvalidInputError, match="max_evaluations = 3"):
        calibrate(data, workers=1, progress=False, max_evaluations=3)
    assert calls == []
