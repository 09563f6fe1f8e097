"""The tank driven by a measured displacement record: reading, smoothing, and the models it drives.

References: the harmonic motion ``X0 s(t) sin(2 pi f t)`` of :func:`tank_motion`, whose exact
derivatives are known in closed form; records are sampled from it (with and without added white
noise of known sigma), so every fitted quantity has an independent exact value.
"""

from __future__ import annotations

import csv
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from vinculo.buoy import (
    BuoyCase,
    MeasuredTankMotion,
    SweepSettings,
    TwoDofModel,
    read_tank_motion,
    tank_motion,
)
from vinculo.buoy.csv_table import read_table
from vinculo.buoy.study import run_study, run_task
from vinculo.buoy.tank import (
    MOTION_COLUMNS,
    decimate,
    decimation_factor,
    discrepancy_smoothing,
    noise_level,
    raw_dominant_frequency,
)
from vinculo.errors import InvalidInputError

CASE = BuoyCase()
FREQUENCY = 0.9
SAMPLE = 0.01  # s: a 100 Hz displacement sensor


def _record(duration: float, sigma: float = 0.0, seed: int = 1, frequency: float = FREQUENCY):
    """Samples of the study's ramped harmonic motion, with white noise of std ``sigma``."""
    t = np.arange(0.0, duration + 1e-9, SAMPLE)
    x, _, _ = tank_motion(CASE, frequency)(t)
    return t, x + sigma * np.random.default_rng(seed).standard_normal(t.size)


def _write(path: Path, t: np.ndarray, x: np.ndarray, header: str = "time (s), displacement (m)"):
    rows = [f"{a:.6f}, {b:.9e}" for a, b in zip(t, x, strict=True)]
    lines = ["# synthetic record", header, *rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_noise_level_recovers_the_standard_deviation_of_white_noise():
    # Reference: the sigma the noise was drawn with; the MAD estimate of 4000 third differences
    # has a relative standard error of about 2-3 %.
    _, x = _record(40.0, sigma=2e-5)
    assert noise_level(x) == pytest.approx(2e-5, rel=0.06)


@pytest.mark.parametrize("sigma", [0.0, 1e-5])
def test_fit_derivatives_match_the_exact_motion(sigma):
    # Reference: the closed-form velocity and acceleration of the sampled motion. Without noise
    # the fit is a cubic spline at h = 0.01 s (acceleration error ~ (w h)^2 / 12 ~ 3e-4); with
    # noise of 0.2 % of X0 the smoothing keeps the acceleration within 5 % of its peak (away from
    # the record's natural ends, where the fit's second derivative is forced to zero).
    t, x = _record(30.0, sigma)
    motion = MeasuredTankMotion(t, x)
    inner = (t > 2.0) & (t < t[-1] - 2.0)
    exact = tank_motion(CASE, FREQUENCY)(t)
    fitted = motion(t)
    tolerances = (2e-4, 1e-3, 1e-3) if sigma == 0.0 else (5e-3, 1e-2, 5e-2)
    for got, want, tolerance in zip(fitted, exact, tolerances, strict=True):
        peak = np.max(np.abs(want))
        assert np.max(np.abs(got - want)[inner]) < tolerance * peak
    # the residual of the fit is the noise it removed (discrepancy principle)
    assert motion.residual_rms == pytest.approx(motion.noise, rel=0.05) if sigma else True


def test_scalar_evaluation_equals_the_spline():
    # Reference: scipy's BSpline and its derivatives (the same fit, evaluated another way).
    t, x = _record(20.0, 1e-5)
    motion = MeasuredTankMotion(t, x)
    times = np.random.default_rng(3).uniform(0.0, motion.duration, 200)
    scalar = np.array([motion.at(s) for s in times])
    vector = np.array(motion(times)).T
    np.testing.assert_allclose(scalar, vector, rtol=0, atol=1e-12)


def test_core_law_is_the_same_function_as_the_fit():
    # Reference: the smoothing spline is the natural cubic spline with knots at the samples, so
    # the core's natural spline through its values there is identical, derivatives included.
    t, x = _record(20.0, 1e-5)
    motion = MeasuredTankMotion(t, x)
    law = motion.law()
    times = np.linspace(0.0, motion.duration, 157)
    got = np.array([law.derivatives(s) for s in times])
    want = np.array(motion(times)).T
    for k, scale in enumerate((CASE.amplitude, 0.03, 0.2)):
        np.testing.assert_allclose(got[:, k], want[:, k], rtol=0, atol=1e-9 * scale)


def test_dominant_frequency_is_found_to_a_small_fraction_of_a_bin():
    # Reference: the frequency the record was sampled at; one spectral bin is 1/40 Hz = 2.8 %.
    for f in (0.55, FREQUENCY, 1.37):
        t, x = _record(40.0, 1e-5, frequency=f)
        assert MeasuredTankMotion(t, x).frequency == pytest.approx(f, rel=1e-5)


def test_record_is_shifted_to_start_at_zero():
    # Reference: a constant offset in time and displacement changes only the offsets.
    t, x = _record(20.0)
    moved = MeasuredTankMotion(t + 7.5, x + 0.3, smoothing=0.0)
    plain = MeasuredTankMotion(t, x, smoothing=0.0)
    assert moved.time_offset == 7.5
    assert moved.displacement_offset == pytest.approx(0.3, abs=1e-12)
    np.testing.assert_allclose(moved(t)[0], plain(t)[0], atol=1e-12)
    assert moved(0.0)[0] == pytest.approx(0.0, abs=1e-15)


def test_discrepancy_smoothing_leaves_residuals_at_the_noise_level():
    # Reference: the target sigma; the root is solved to 2 % in log(lam).
    t, x = _record(20.0, 3e-5)
    lam = discrepancy_smoothing(t, x, 3e-5)
    motion = MeasuredTankMotion(t, x, smoothing=lam)
    assert motion.residual_rms == pytest.approx(3e-5, rel=0.02)
    assert discrepancy_smoothing(t, x, 0.0) == 0.0


def test_measured_drive_reproduces_the_harmonic_response(tmp_path):
    # Reference: the same models driven by the closed-form harmonic motion (validated against
    # the 2-DOF theory in test_model.py). A 100 Hz record with 0.2 % noise must give the steady
    # amplitude within 0.5 % and the phase within 0.5 deg, for the particle model and the 2-DOF
    # scipy model alike.
    settings = SweepSettings(settle_periods=25, fit_periods=10)
    f = 1.1
    duration = settings.t_end(f)
    t, x = _record(duration + SAMPLE, 1e-5, frequency=f)
    motion = read_tank_motion(_write(tmp_path / "run.csv", t, x))
    assert motion.frequency == pytest.approx(f, rel=1e-5)
    for model in ("particle", "two-dof"):
        measured = run_task(CASE, settings, model, 0.0, motion=motion)
        harmonic = run_task(CASE, settings, model, f)
        assert measured.error is None and measured.record == "run.csv"
        m, h = measured.response, harmonic.response
        assert m.relative_amplitude == pytest.approx(h.relative_amplitude, rel=5e-3)
        assert m.relative_phase_deg == pytest.approx(h.relative_phase_deg, abs=0.5)
        assert m.tank_amplitude == pytest.approx(CASE.amplitude, rel=2e-3)


def test_reference_model_refuses_to_run_past_the_record():
    t, x = _record(10.0)
    motion = MeasuredTankMotion(t, x)
    with pytest.raises(InvalidInputError, match="beyond the tank motion record") as caught:
        TwoDofModel(CASE).simulate(None, 12.0, tank=motion)
    assert caught.value.name == "t_end"


def test_study_refuses_a_record_shorter_than_the_fit_window():
    t, x = _record(5.0)
    motion = MeasuredTankMotion(t, x, frequency=FREQUENCY)
    with pytest.raises(InvalidInputError, match="shorter than the fit window"):
        run_study(CASE, SweepSettings(fit_periods=10), motions=[motion], progress=False)


def test_bad_records_name_the_line(tmp_path):
    t, x = _record(10.0)
    rows = [f"{a:.3f}, {b:.6e}" for a, b in zip(t, x, strict=True)]
    rows[40] = rows[38]  # time goes back at data row 41
    path = tmp_path / "back.csv"
    path.write_text("time, displacement\n" + "\n".join(rows) + "\n")
    with pytest.raises(InvalidInputError, match=r"line 42: time .* does not come after") as caught:
        read_tank_motion(path)
    assert caught.value.name == "tank_motion" and caught.value.line == 42

    rows = [f"{a:.3f}, {b:.6e}" for a, b in zip(t, x, strict=True)]
    rows[9] = "0.09, oops"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(InvalidInputError, match=r"line 10: displacement 'oops' is not a number"):
        read_tank_motion(path)

    path.write_text("time (s), height (m)\n0, 0\n")
    with pytest.raises(InvalidInputError, match=r"lacks the column\(s\) displacement"):
        read_tank_motion(path)

    path.write_text("0, 0\n0.1, 0.001\n")
    with pytest.raises(InvalidInputError, match="at least 16 samples"):
        read_tank_motion(path)

    with pytest.raises(InvalidInputError, match="no such tank motion file"):
        read_tank_motion(tmp_path / "missing.csv")


def test_coarse_or_flat_records_are_refused():
    t = np.arange(0.0, 20.0, 0.2)  # 5 Hz sampling: 5.6 samples per period at 0.9 Hz
    x = 0.005 * np.sin(2.0 * math.pi * FREQUENCY * t)
    with pytest.raises(InvalidInputError, match="samples per period"):
        MeasuredTankMotion(t, x)
    with pytest.raises(InvalidInputError, match="no oscillation"):
        MeasuredTankMotion(np.arange(0.0, 10.0, 0.01), np.zeros(1000))
    with pytest.raises(InvalidInputError, match="smoothing must be"):
        MeasuredTankMotion(*_record(10.0), smoothing=-1.0)


def test_cli_runs_the_models_on_a_record(tmp_path):
    # Reference: the 2-DOF model under the harmonic motion the record samples (same tolerance as
    # above); the CLI must pick up the record's frequency and fit over its end.
    from vinculo.cli import main

    case = replace(CASE)
    settings = SweepSettings(settle_periods=25, fit_periods=10)
    f = 1.1
    t, x = _record(settings.t_end(f) + SAMPLE, 1e-5, frequency=f)
    record = _write(tmp_path / "shake_1.csv", t, x)
    output = tmp_path / "out"
    code = main([
        "buoy", "--output", str(output), "--tank-motion", str(record), "--models", "two-dof",
        "--workers", "1", "--no-progress", "--fit-periods", "10",
    ])
    assert code == 0
    assert (output / "history_shake_1.png").is_file()

    with (output / "sweep.csv").open() as table:
        rows = list(csv.DictReader(table))
    assert [r["tank_record"] for r in rows] == ["shake_1.csv"]
    harmonic = run_task(case, settings, "two-dof", f).response
    assert float(rows[0]["frequency_hz"]) == pytest.approx(f, rel=1e-5)
    assert float(rows[0]["relative_amplitude"]) == pytest.approx(
        harmonic.relative_amplitude, rel=5e-3
    )


@pytest.mark.parametrize("sigma", [0.0, 2e-5])
def test_a_record_too_coarse_for_its_frequency_is_refused(tmp_path, sigma):
    # 0.9 Hz sampled every 0.5 s: 2.2 samples per period, below the Nyquist-safe 8. Before,
    # smoothing removed the oscillation and the record passed with a "dominant frequency" of
    # 0.027 Hz; the check now reads the frequency off the raw samples (reference: the
    # frequency the samples were made with).
    t = np.arange(0.0, 120.0, 0.5)
    x = 0.005 * np.sin(2.0 * math.pi * FREQUENCY * t)
    x = x + sigma * np.random.default_rng(5).standard_normal(t.size)
    with pytest.raises(InvalidInputError, match=r"too coarse.*2\.2 samples per period at 0\.9"):
        read_tank_motion(_write(tmp_path / "coarse.csv", t, x))


def test_raw_dominant_frequency_is_the_sampled_one_to_a_bin():
    # A fine record: the raw spectrum's peak is the sine's frequency within one bin (1/T).
    t, x = _record(60.0, sigma=2e-5)
    assert raw_dominant_frequency(t, x) == pytest.approx(FREQUENCY, abs=1.0 / 60.0)


def test_decimation_of_a_long_record_stays_within_its_stated_bound():
    # 200 000 samples at 1 kHz of an exact 0.9 Hz sine (no ramp, no noise): the record is
    # averaged in runs of m samples. Reference: the exact sine at the runs' mean times; the
    # averaging's error is the boxcar's, 1 - sin(m w h / 2) / (m sin(w h / 2)) of the
    # amplitude, below the module's bound (w m h)^2 / 24 <= (2 pi / 100)^2 / 24 = 1.6e-4.
    h, n = 1e-3, 200_000
    t = np.arange(n) * h
    amplitude, w = 0.005, 2.0 * math.pi * FREQUENCY
    x = amplitude * np.sin(w * t)
    m = decimation_factor(n, h, FREQUENCY)
    assert m == 10  # ceil(200 000 / 20 000), and 10 ms is within T / 100 = 11 ms
    t_run, x_run = decimate(t, x, m)
    assert t_run.size == n // m
    boxcar = 1.0 - math.sin(m * w * h / 2.0) / (m * math.sin(w * h / 2.0))
    error = np.max(np.abs(x_run - amplitude * np.sin(w * t_run))) / amplitude
    assert error == pytest.approx(boxcar, rel=1e-3)
    assert error <= (w * m * h) ** 2 / 24.0 <= (2.0 * math.pi / 100.0) ** 2 / 24.0
    # The whole fit of the decimated record keeps frequency and amplitude of the sine.
    motion = MeasuredTankMotion(t, x)
    assert motion.decimation == m and motion.recorded_samples == n
    assert motion.frequency == pytest.approx(FREQUENCY, rel=1e-6)
    window = np.linspace(20.0, motion.duration - 1.0, 5000)
    values = motion(window)[0] + motion.displacement_offset
    exact = amplitude * np.sin(w * (window + motion.time_offset))
    assert np.max(np.abs(values - exact)) < 3e-4 * amplitude


def test_a_record_needing_no_decimation_keeps_every_sample():
    t, x = _record(60.0)
    assert decimation_factor(t.size, SAMPLE, FREQUENCY) == 1
    assert MeasuredTankMotion(t, x).times.size == t.size


@pytest.mark.slow  # about 15 s on 2 busy cores (writing the file takes 4 s more)
def test_a_record_of_a_million_samples_is_read_and_fitted_quickly(tmp_path):
    # Before, reading 10^6 lines did not finish in 240 s. The bound is generous for a loaded
    # machine: measured 1.6 s to read and 15 s to read and fit, with 90 910 samples after
    # decimation by 11 (0.9 Hz at 1 kHz over 1000 s).
    n = 1_000_000
    t = np.arange(n) * 1e-3
    rng = np.random.default_rng(1)
    x = 0.005 * np.sin(2.0 * math.pi * FREQUENCY * t) * np.clip(t / 10.0, 0.0, 1.0) ** 3
    path = tmp_path / "long.csv"
    with path.open("w") as f:
        f.write("time (s), displacement (m)\n")
        np.savetxt(f, np.column_stack([t, x + 2e-5 * rng.standard_normal(n)]),
                   fmt="%.6f,%.8e")
    started = time.perf_counter()
    motion = read_tank_motion(path)
    elapsed = time.perf_counter() - started
    assert elapsed < 90.0
    assert motion.recorded_samples == n and motion.decimation == 11
    assert motion.frequency == pytest.approx(FREQUENCY, rel=1e-5)


def test_reading_a_table_by_numpy_gives_the_line_by_line_values(tmp_path):
    # The fast path (numpy.loadtxt) and the line-by-line reader (Python's float) must agree bit
    # for bit; a row the fast path cannot take (a quoted field) sends the file to the slow one.
    t, x = _record(5.0, sigma=2e-5)
    plain = _write(tmp_path / "plain.csv", t, x)
    quoted = tmp_path / "quoted.csv"
    quoted.write_text(plain.read_text().replace(f"{t[3]:.6f},", f'"{t[3]:.6f}",', 1))
    fast = read_table(plain, MOTION_COLUMNS, what="record")
    slow = read_table(quoted, MOTION_COLUMNS, what="record")
    assert np.array_equal(fast.values, slow.values)
    expected = [[float(f"{a:.6f}"), float(f"{b:.9e}")] for a, b in zip(t, x, strict=True)]
    assert fast.values.tolist() == expected
    assert fast.lines[0] == 3 and fast.lines[-1] == t.size + 2  # after the comment and header
