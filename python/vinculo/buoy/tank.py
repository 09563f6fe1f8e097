"""The tank's motion: the harmonic shake of the study, or a measured displacement record.

Both kinds give the displacement ``X_t(t)`` along x with its velocity and acceleration, vectorised
(``motion(t) -> (X, X', X'')``) and scalar (``motion.at(t)``), the ``frequency`` the buoy's
response is fitted at, and the same displacement as a core law (``motion.law()``) for the particle
model. The fluid moves rigidly with the tank, so ``X_t'`` and ``X_t''`` are also its velocity and
acceleration.

A measured record (:func:`read_tank_motion`) is a CSV file of time and displacement. Measured
displacements carry noise, which differentiating twice would amplify, so the record is fitted with
a smoothing spline (:func:`scipy.interpolate.make_smoothing_spline`) and velocity and acceleration
are the derivatives of that fit. The smoothing spline is a natural cubic spline with knots at the
sample times, so the core's natural-spline law through the fit's values at those times
(:func:`vinculo.tabulated`) is the same function: the particle model and the scipy reference
models see the same tank.

The smoothing penalty ``lam`` is chosen by the discrepancy principle (Reinsch, 1967): the largest
``lam`` whose fit stays within the noise, ``rms(samples - fit) = sigma``. The noise level sigma is
estimated from the third differences of the samples, which remove a smooth signal sampled finely
and multiply the variance of white noise by 20: ``sigma = 1.4826 median|d3 - median d3| / sqrt(20)``
(the median absolute deviation, robust to outliers). scipy's own choice by generalised
cross-validation searches ``lam`` in ``(0, n)`` and, for records of thousands of samples of a slow
oscillation, lands on a straight line; the penalty can also be given explicitly.

Format of a record: two comma-separated columns, ``time`` (s, strictly increasing) and
``displacement`` (m, along the shaking direction); an optional header names them (any order, a
unit in parentheses allowed, other columns ignored); ``#`` starts a comment::

    # shake table, 0.9 Hz, run 2
    time (s), displacement (m)
    0.000, 0.00000
    0.005, 0.00001
    ...

Before anything is smoothed, the record's dominant frequency is read off the spectrum of the raw
samples (resampled uniformly), and a record with fewer than :data:`MIN_SAMPLES_PER_PERIOD`
samples per period of it is refused: smoothing such a record would remove the oscillation itself.

A long, finely sampled record (more than :data:`MAX_FIT_SAMPLES` samples) is decimated before the
fit, by averaging runs of ``m`` consecutive samples (times and displacements alike), with ``m``
chosen so that each run spans at most 1/:data:`DECIMATED_PER_PERIOD` of the dominant period.
Averaging is linear and removes no more than ``(w_f W)^2 / 24`` of the amplitude of an oscillation
at ``w_f = 2 pi f`` over a run of width ``W`` for uniform sampling (the boxcar's response,
``sin(x)/x`` at ``x = w_f W / 2``), ``(w_f W)^2 / 8`` for any sampling: at most 1.6e-4 and 4.9e-4
of the tank's amplitude. It also divides white noise by ``sqrt(m)``.

The record is shifted to start at ``t = 0`` with ``X_t(0) = 0`` (the buoy starts at rest above the
anchor; a constant offset of the table changes nothing). It should start at rest, like the
study's ramped start, and be long enough for the start-up transient to die out before the last
``fit_periods`` periods, over which the response is fitted.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import BSpline, PPoly, make_smoothing_spline
from scipy.optimize import brentq, minimize_scalar

import vinculo
from vinculo.buoy.case import BuoyCase
from vinculo.buoy.csv_table import read_table, table_error
from vinculo.errors import InvalidInputError

__all__ = [
    "MOTION_COLUMNS",
    "MeasuredTankMotion",
    "TankMotion",
    "decimate",
    "decimation_factor",
    "discrepancy_smoothing",
    "noise_level",
    "raw_dominant_frequency",
    "read_tank_motion",
    "tank_motion",
]

#: The columns of a measured record, in their order when the file has no header.
MOTION_COLUMNS = ("time", "displacement")
#: Fewest samples a record may have (a smoothing spline needs 5; a period needs more).
MIN_SAMPLES = 16
#: Fewest samples per period of the dominant frequency for the record to resolve it.
MIN_SAMPLES_PER_PERIOD = 8
#: Records with more samples than this are decimated before the fit (module docstring).
MAX_FIT_SAMPLES = 20_000
#: Samples per period of the dominant frequency that a decimated record keeps, at least.
DECIMATED_PER_PERIOD = 100


@dataclass(frozen=True)
class TankMotion:
    """The displacement of the tank, ``X_t(t) = X0 s(t) sin(2 pi f t)``, with its derivatives.

    ``s`` is the C2 quintic ramp ``10 u^3 - 15 u^4 + 6 u^5``, ``u = t / ramp_time`` clamped to
    [0, 1]; ``ramp_time = 0`` gives ``s = 1`` (the abrupt start). Before ``t = 0`` the tank is at
    rest when there is a ramp.

    Arguments:
        amplitude: X0, in m.
        frequency: f, in Hz.
        ramp_time: duration of the ramp, in s (0: none).
    """

    amplitude: float
    frequency: float
    ramp_time: float

    def __call__(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Evaluate the motion at one time or an array of times.

        Arguments:
            t: time(s), in s.

        Returns:
            ``(X, X', X'')``, arrays of the shape of ``t``, in m, m/s and m/s^2 (exact derivatives
            of the product ``X0 s(t) sin(2 pi f t)``).
        """
        t = np.asarray(t, dtype=np.float64)
        omega = 2.0 * math.pi * self.frequency
        sine, cosine = np.sin(omega * t), np.cos(omega * t)
        if self.ramp_time > 0.0:
            u = np.clip(t / self.ramp_time, 0.0, 1.0)
            s = u**3 * (10.0 + u * (-15.0 + 6.0 * u))
            s1 = 30.0 * u**2 * (1.0 - u) ** 2 / self.ramp_time
            s2 = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / self.ramp_time**2
        else:
            s, s1, s2 = np.ones_like(t), np.zeros_like(t), np.zeros_like(t)
        x0 = self.amplitude
        position = x0 * s * sine
        velocity = x0 * (s1 * sine + s * omega * cosine)
        acceleration = x0 * (s2 * sine + 2.0 * s1 * omega * cosine - s * omega**2 * sine)
        return position, velocity, acceleration

    @property
    def duration(self) -> float:
        """The motion goes on for ever: ``inf``."""
        return math.inf

    def law(self) -> vinculo.Law:
        """The displacement as a core law, :func:`vinculo.sine` with the same ramp.

        Returns:
            The law; its value and derivatives equal ``self(t)``.
        """
        return vinculo.sine(self.amplitude, self.frequency, ramp_time=self.ramp_time)

    def at(self, t: float) -> tuple[float, float, float]:
        """Scalar evaluation of ``(X, X', X'')`` at one time (fast path for the integrators).

        Arguments:
            t: time, in s.

        Returns:
            ``(X, X', X'')`` as floats, equal to ``self(t)``.
        """
        omega = 2.0 * math.pi * self.frequency
        sine, cosine = math.sin(omega * t), math.cos(omega * t)
        if self.ramp_time > 0.0:
            u = min(max(t / self.ramp_time, 0.0), 1.0)
            s = u**3 * (10.0 + u * (-15.0 + 6.0 * u))
            s1 = 30.0 * u**2 * (1.0 - u) ** 2 / self.ramp_time
            s2 = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / self.ramp_time**2
        else:
            s, s1, s2 = 1.0, 0.0, 0.0
        x0 = self.amplitude
        return (
            x0 * s * sine,
            x0 * (s1 * sine + s * omega * cosine),
            x0 * (s2 * sine + 2.0 * s1 * omega * cosine - s * omega**2 * sine),
        )


def _check_frequency(frequency: float) -> float:
    """Return ``frequency`` as a float, or raise if it is not finite and positive."""
    value = float(frequency)
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidInputError(
            f"frequency must be a finite positive number of Hz, got {frequency!r}",
            name="frequency",
            value=frequency,
        )
    return value


def tank_motion(case: BuoyCase, frequency: float) -> TankMotion:
    """The tank's motion at ``frequency`` for ``case``: amplitude X0, ramp over ramp_periods.

    Arguments:
        case: the buoy case (``amplitude`` and ``ramp_periods`` are used).
        frequency: excitation frequency, in Hz.

    Returns:
        A callable ``t -> (X, X', X'')``, vectorised over ``t``.

    Raises:
        InvalidInputError: if ``frequency`` is not finite and positive.
    """
    frequency = _check_frequency(frequency)
    return TankMotion(case.amplitude, frequency, case.ramp_periods / frequency)




class MeasuredTankMotion:
    """A measured tank displacement, smoothed by a spline, with its velocity and acceleration.

    Arguments:
        times: sample times, in s, strictly increasing (shifted so that the first is 0).
        displacement: the displacements, in m (shifted so that the fit is 0 at the first time).
        smoothing: the penalty ``lam`` of :func:`scipy.interpolate.make_smoothing_spline` (in
            s^3: it weighs the integral of the squared acceleration, m^2/s^3, against the sum of
            squared residuals, m^2); ``0`` interpolates the samples; default (``None``): the
            discrepancy principle (module docstring).
        frequency: the excitation frequency, in Hz; default: the record's dominant frequency
            (:meth:`dominant_frequency`).
        source: where the record came from (a file name), for labels and messages.

    Attributes:
        times: the shifted sample times, in s (after decimation).
        samples: the shifted displacements, in m (after decimation).
        spline: the smoothing fit, a :class:`scipy.interpolate.BSpline` of time.
        smoothing: the penalty ``lam`` used.
        noise: the estimated noise level sigma of the samples, in m.
        frequency: the excitation frequency, in Hz.
        duration: the record's length, in s (runs may not go beyond it).
        residual_rms: root mean square of the samples minus the fit, in m (the noise removed).
        time_offset, displacement_offset: what was subtracted from the times and displacements.
        recorded_samples: the number of samples in the record.
        decimation: how many consecutive samples were averaged into each of :attr:`samples`
            (1: none; module docstring).
        source: the label.

    Raises:
        InvalidInputError: for fewer than :data:`MIN_SAMPLES` samples, times not strictly
            increasing, a non-finite value, a bad ``smoothing`` or ``frequency``, a record with no
            oscillation, or one sampled too coarsely for its frequency.
    """

    def __init__(
        self,
        times: Any,
        displacement: Any,
        *,
        smoothing: float | None = None,
        frequency: float | None = None,
        source: str = "measured tank motion",
    ) -> None:
        t = np.asarray(times, dtype=np.float64).reshape(-1)
        x = np.asarray(displacement, dtype=np.float64).reshape(-1)
        if t.shape != x.shape:
            raise InvalidInputError(
                f"{source}: times ({t.size}) and displacement ({x.size}) differ in length",
                name="displacement",
                value=x.size,
            )
        if t.size < MIN_SAMPLES:
            raise InvalidInputError(
                f"{source}: a tank motion record needs at least {MIN_SAMPLES} samples, got "
                f"{t.size}",
                name="times",
                value=t.size,
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
            raise InvalidInputError(
                f"{source}: times and displacements must be finite numbers",
                name="displacement",
                value=None,
            )
        steps = np.diff(t)
        if np.any(steps <= 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise InvalidInputError(
                f"{source}: times must increase strictly, but sample {k + 1} is at "
                f"{t[k + 1]!r} s after {t[k]!r} s",
                name="times",
                value=float(t[k + 1]),
            )
        if smoothing is not None and not (math.isfinite(smoothing) and smoothing >= 0.0):
            raise InvalidInputError(
                f"smoothing must be a finite number >= 0 (0 interpolates), got {smoothing!r}",
                name="smoothing",
                value=smoothing,
            )
        self.source = source
        self.recorded_samples = int(t.size)
        if frequency is not None:
            frequency = _check_frequency(frequency)
        peak = frequency if frequency is not None else raw_dominant_frequency(t, x, source)
        largest = float(np.max(steps))
        per_period = 1.0 / (peak * largest)
        if per_period < MIN_SAMPLES_PER_PERIOD:
            raise InvalidInputError(
                f"{source}: the record is too coarse for its frequency: the largest sampling "
                f"interval, {largest:.4g} s, gives only {per_period:.1f} samples per period at "
                f"{peak:.4g} Hz (the raw samples' dominant frequency); a record needs at least "
                f"{MIN_SAMPLES_PER_PERIOD} per period: sample it at least every "
                f"{1.0 / (MIN_SAMPLES_PER_PERIOD * peak):.3g} s",
                name="times",
                value=largest,
            )
        self.decimation = decimation_factor(t.size, largest, peak)
        t, x = decimate(t, x, self.decimation)
        self.time_offset = float(t[0])
        t = t - t[0]
        self.noise = noise_level(x)
        if smoothing is None:
            smoothing = discrepancy_smoothing(t, x, self.noise)
        self.smoothing = float(smoothing)
        fit = make_smoothing_spline(t, x, lam=self.smoothing)
        # B-splines sum to one, so shifting the coefficients shifts the function.
        self.displacement_offset = float(fit(0.0))
        self.spline = BSpline(fit.t, fit.c - self.displacement_offset, fit.k)
        self.times = t
        self.samples = x - self.displacement_offset
        self._pieces: tuple[list[float], list[list[float]]] | None = None
        self._velocity = self.spline.derivative(1)
        self._acceleration = self.spline.derivative(2)
        self.duration = float(t[-1])
        self.residual_rms = float(np.sqrt(np.mean((self.spline(t) - self.samples) ** 2)))
        if frequency is None:
            frequency = self.dominant_frequency(near=peak)
        self.frequency = float(frequency)

    def __repr__(self) -> str:
        return (
            f"MeasuredTankMotion({self.source!r}, {self.times.size} samples over "
            f"{self.duration:g} s, {self.frequency:.4f} Hz)"
        )

    def __call__(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(X, X', X'')`` of the fit at one time or an array of times (in s, from the start).

        Beyond the record the fit continues along its end tangents (natural spline); runs are
        refused there (:attr:`duration`).
        """
        t = np.asarray(t, dtype=np.float64)
        return self.spline(t), self._velocity(t), self._acceleration(t)

    def at(self, t: float) -> tuple[float, float, float]:
        """Scalar ``(X, X', X'')`` at one time, in s (equal to ``self(t)``).

        The integrators of the reference models call this at every stage, so it evaluates the
        fit's piecewise-cubic form with plain floats (about 20 times faster than three
        :class:`~scipy.interpolate.BSpline` calls).
        """
        if self._pieces is None:
            pieces = PPoly.from_spline(self.spline)
            keep = np.concatenate([[True], np.diff(pieces.x) > 0.0])  # drop repeated end knots
            self._pieces = (pieces.x[keep][:-1].tolist(), pieces.c[:, keep[:-1]].T.tolist())
        starts, coefficients = self._pieces
        k = min(max(bisect_right(starts, t) - 1, 0), len(starts) - 1)
        c3, c2, c1, c0 = coefficients[k]
        s = t - starts[k]
        return (
            ((c3 * s + c2) * s + c1) * s + c0,
            (3.0 * c3 * s + 2.0 * c2) * s + c1,
            6.0 * c3 * s + 2.0 * c2,
        )

    def law(self) -> vinculo.Law:
        """The fit as a core law: the natural spline through its values at the sample times.

        Both are natural cubic splines with knots at the sample times and the same values there,
        so they are the same function, derivatives included (to round-off).
        """
        return vinculo.tabulated(self.times, self.spline(self.times))

    def dominant_frequency(self, near: float | None = None) -> float:
        """The frequency of the record's strongest oscillation, in Hz.

        The peak of the Hann-windowed, zero-padded spectrum of the fit resampled uniformly over
        the record (or ``near``, when given), refined by the least-squares sine fit over the
        record's second half (the frequency minimising the residual of
        ``a + b cos(wt) + c sin(wt)``, within one spectral bin of the peak).

        Arguments:
            near: a first estimate, in Hz (the raw samples' peak, :func:`raw_dominant_frequency`).

        Raises:
            InvalidInputError: if the record does not oscillate (no peak away from zero).
        """
        count = max(self.times.size, 64)
        grid = np.linspace(0.0, self.duration, count)
        values = self.spline(grid)
        values = values - values.mean()
        padded = 8 * (1 << (count - 1).bit_length())
        spectrum = np.abs(np.fft.rfft(values * np.hanning(count), n=padded))
        step = grid[1] - grid[0]
        frequencies = np.fft.rfftfreq(padded, step)
        bin_width = 1.0 / self.duration
        lowest = int(np.searchsorted(frequencies, 1.5 * bin_width))
        if lowest >= len(spectrum) - 1 or not np.any(spectrum[lowest:] > 0.0):
            raise InvalidInputError(
                f"{self.source}: the record shows no oscillation to take a frequency from; give "
                f"the frequency explicitly",
                name="displacement",
                value=None,
            )
        peak = lowest + int(np.argmax(spectrum[lowest:]))
        coarse = float(frequencies[peak]) if near is None else float(near)
        second_half = grid >= 0.5 * self.duration
        t_half, x_half = grid[second_half], values[second_half]

        def residual(frequency: float) -> float:
            w = 2.0 * math.pi * frequency * t_half
            basis = np.column_stack([np.ones_like(t_half), np.cos(w), np.sin(w)])
            _, rss, *_ = np.linalg.lstsq(basis, x_half, rcond=None)
            return float(rss[0]) if len(rss) else 0.0

        low, high = max(coarse - bin_width, 0.5 * coarse), coarse + bin_width
        refined = minimize_scalar(
            residual, bounds=(low, high), method="bounded", options={"xatol": 1e-9 * coarse}
        )
        return float(refined.x) if refined.success else coarse


def raw_dominant_frequency(times: Any, samples: Any, source: str = "record") -> float:
    """The frequency of the strongest oscillation of raw samples, in Hz.

    The samples (linearly resampled onto a uniform grid of as many points, which changes
    nothing for a uniformly sampled record) lose their mean and least-squares line, are
    Hann-windowed and zero-padded, and the largest peak of their spectrum above 1.5 bins is
    returned, up to the Nyquist frequency of the mean sampling interval. Read before any
    smoothing, it is the frequency the record actually shows, however coarse its sampling.

    Arguments:
        times: sample times, in s, strictly increasing.
        samples: the displacements.
        source: the record's name, for messages.

    Returns:
        The peak frequency, in Hz (to a fraction of ``1 / duration``).

    Raises:
        InvalidInputError: if the record shows no oscillation.
    """
    t = np.asarray(times, dtype=np.float64)
    x = np.asarray(samples, dtype=np.float64)
    count = t.size
    grid = np.linspace(t[0], t[-1], count)
    values = np.interp(grid, t, x)
    values = values - np.polyval(np.polyfit(grid - grid[0], values, 1), grid - grid[0])
    padded = min(8, max(1, (1 << 23) // count)) * (1 << (count - 1).bit_length())
    spectrum = np.abs(np.fft.rfft(values * np.hanning(count), n=padded))
    frequencies = np.fft.rfftfreq(padded, grid[1] - grid[0])
    lowest = int(np.searchsorted(frequencies, 1.5 / (t[-1] - t[0])))
    if lowest >= len(spectrum) - 1 or not np.any(spectrum[lowest:] > 0.0):
        raise InvalidInputError(
            f"{source}: the record shows no oscillation to take a frequency from; give the "
            f"frequency explicitly",
            name="displacement",
            value=None,
        )
    return float(frequencies[lowest + int(np.argmax(spectrum[lowest:]))])


def decimation_factor(count: int, largest_step: float, frequency: float) -> int:
    """How many consecutive samples to average into one (1: keep the record as it is).

    Arguments:
        count: the record's number of samples.
        largest_step: its largest sampling interval, in s.
        frequency: its dominant frequency, in Hz.

    Returns:
        ``m >= 1``: the smallest that brings the record to :data:`MAX_FIT_SAMPLES` samples, but
        no larger than keeps a run of ``m`` intervals within 1/:data:`DECIMATED_PER_PERIOD` of a
        period (module docstring: the amplitude changes by at most 4.9e-4).
    """
    if count <= MAX_FIT_SAMPLES:
        return 1
    wanted = math.ceil(count / MAX_FIT_SAMPLES)
    allowed = math.floor(1.0 / (DECIMATED_PER_PERIOD * frequency * largest_step))
    return max(1, min(wanted, allowed))


def decimate(times: Any, samples: Any, factor: int) -> tuple[np.ndarray, np.ndarray]:
    """Average runs of ``factor`` consecutive samples, times and values alike.

    Arguments:
        times: sample times, strictly increasing.
        samples: the values.
        factor: samples per run (1 returns the inputs); a shorter last run is averaged too.

    Returns:
        ``(times, samples)`` of the run means (times still strictly increasing).
    """
    t = np.asarray(times, dtype=np.float64)
    x = np.asarray(samples, dtype=np.float64)
    if factor <= 1:
        return t, x
    full = t.size // factor * factor
    t_out = t[:full].reshape(-1, factor).mean(axis=1)
    x_out = x[:full].reshape(-1, factor).mean(axis=1)
    if full < t.size:
        t_out = np.append(t_out, t[full:].mean())
        x_out = np.append(x_out, x[full:].mean())
    return t_out, x_out


def noise_level(samples: Any) -> float:
    """Estimate the standard deviation of white noise on finely sampled smooth data.

    Third differences remove a smooth signal (to ``(w h)^3`` of its amplitude for an oscillation
    at ``w`` sampled every ``h``) and turn white noise of variance sigma^2 into noise of variance
    ``20 sigma^2``; the median absolute deviation makes the estimate robust to outliers. Quantised
    data, whose third differences are mostly zero, fall back to their root mean square.

    Arguments:
        samples: the samples, shape (n,), n >= 4.

    Returns:
        sigma, in the unit of the samples (0 for data without noise, such as a polynomial of
        degree <= 2).
    """
    d3 = np.diff(np.asarray(samples, dtype=np.float64), 3)
    sigma = 1.4826 * float(np.median(np.abs(d3 - np.median(d3)))) / math.sqrt(20.0)
    if sigma == 0.0:
        sigma = float(np.sqrt(np.mean(d3**2) / 20.0))
    return sigma


def discrepancy_smoothing(times: Any, samples: Any, sigma: float) -> float:
    """The smoothing penalty whose fit leaves residuals of root mean square ``sigma``.

    The residual of :func:`scipy.interpolate.make_smoothing_spline` grows with ``lam``, from 0
    (interpolation) to that of the least-squares line; the root is found by Brent's method on
    ``log(lam)``, from a bracket around ``h^3`` (h the mean sample spacing: the penalty's time
    scale) widened as needed.

    Arguments:
        times: sample times, strictly increasing.
        samples: the samples.
        sigma: the target residual (the noise level, see :func:`noise_level`).

    Returns:
        ``lam`` (0 when ``sigma`` is 0: the fit interpolates).
    """
    t = np.asarray(times, dtype=np.float64)
    x = np.asarray(samples, dtype=np.float64)
    if sigma <= 0.0:
        return 0.0

    def excess(log_lam: float) -> float:
        fit = make_smoothing_spline(t, x, lam=math.exp(log_lam))
        return math.log(max(float(np.sqrt(np.mean((fit(t) - x) ** 2))), 1e-300) / sigma)

    scale = math.log(((t[-1] - t[0]) / (t.size - 1)) ** 3)
    low, high = scale - 14.0, scale + 14.0
    for _ in range(8):
        if excess(low) < 0.0:
            break
        low -= 14.0
    else:
        return 0.0  # even a tiny penalty leaves more than sigma: interpolate
    for _ in range(8):
        if excess(high) > 0.0:
            break
        high += 14.0
    else:
        return math.exp(high)  # no penalty reaches sigma: the smoothest fit found
    return math.exp(brentq(excess, low, high, xtol=0.02))


def read_tank_motion(
    path: str | Path,
    *,
    smoothing: float | None = None,
    frequency: float | None = None,
) -> MeasuredTankMotion:
    """Read a measured tank displacement record from CSV (format in the module docstring).

    Arguments:
        path: the CSV file of time (s) and displacement (m).
        smoothing: the smoothing spline's penalty (see :class:`MeasuredTankMotion`); default:
            the discrepancy principle.
        frequency: the excitation frequency, in Hz; default: the record's dominant frequency.

    Returns:
        The smoothed motion, labelled with the file's name.

    Raises:
        InvalidInputError: (``name="tank_motion"``, with ``path`` and ``line``) for a missing,
            unreadable or malformed file (the line is named and quoted), times that do not
            increase (naming the line), too few samples, or a record too coarse for its frequency.
    """
    path = Path(path)
    table = read_table(path, MOTION_COLUMNS, what="tank motion file", name="tank_motion")
    times = table.values[:, 0]
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        row = int(np.argmax(steps <= 0.0)) + 1
        raise table.error(
            row,
            f"time {times[row]:g} s does not come after the previous sample's {times[row - 1]:g} "
            f"s; times must increase strictly",
        )
    if times.size < MIN_SAMPLES:
        raise table_error(
            f"a tank motion record needs at least {MIN_SAMPLES} samples, found {times.size}",
            path,
            None,
            "tank_motion",
        )
    try:
        return MeasuredTankMotion(
            times, table.values[:, 1], smoothing=smoothing, frequency=frequency, source=path.name
        )
    except InvalidInputError as error:
        if error.details.get("name") in ("smoothing", "frequency"):
            raise  # the caller's argument, not the file
        message = str(error).removeprefix(f"{path.name}: ")
        raise table_error(message, path, None, "tank_motion") from None
