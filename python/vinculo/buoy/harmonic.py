"""Steady-state amplitude and phase of a sampled oscillation, by least squares over whole periods.

The phase convention, shared by the plots and the measurement files, is :data:`PHASE_CONVENTION`:
a positive phase means the buoy reaches its maximum before the tank does. Wrapped to (-90, 270],
the relative motion of a buoy reads 180 deg at low frequency (it leans against the tank's
acceleration), about 90 deg at resonance and about 0 deg at high frequency, without a jump.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = [
    "PHASE_CONVENTION",
    "HarmonicFit",
    "SteadyResponse",
    "fit_harmonic",
    "steady_response",
    "steady_window",
    "wrap_phase",
]

#: One-line statement of the phase convention, usable as a plot label.
PHASE_CONVENTION = "phase lead of the buoy over the tank, degrees, wrapped to (-90, 270]"

# Relative slack on window ends, so that samples on a period boundary are kept despite rounding.
_EDGE = 1e-9


def wrap_phase(phase_deg: float | np.ndarray) -> float | np.ndarray:
    """Wrap phases in degrees into (-90, 270], the range of :data:`PHASE_CONVENTION`.

    Arguments:
        phase_deg: phase(s) in degrees.

    Returns:
        The same angles, shifted by whole turns into (-90, 270].
    """
    wrapped = 270.0 - np.mod(270.0 - np.asarray(phase_deg, dtype=np.float64), 360.0)
    return float(wrapped) if np.ndim(wrapped) == 0 else wrapped


@dataclass(frozen=True)
class HarmonicFit:
    """Result of fitting ``mean + amplitude sin(w t + phase)`` to samples.

    Attributes:
        mean: the constant term a, in the unit of the samples.
        amplitude: ``hypot(b, c)`` of the fit ``a + b cos(wt) + c sin(wt)``.
        phase_deg: the angle by which the signal leads ``sin(w t)``, ``atan2(b, c)``, in degrees in
            (-180, 180].
        residual_rms: root mean square (time-weighted) of the samples minus the fit.
        window: ``(t_start, t_end)`` of the samples used, in s.
        samples: number of samples used.
    """

    mean: float
    amplitude: float
    phase_deg: float
    residual_rms: float
    window: tuple[float, float]
    samples: int


def _check_positive(name: str, value: float, unit: str) -> None:
    """Raise unless ``value`` is finite and positive."""
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidInputError(
            f"{name} must be a finite positive number ({unit}), got {value!r}",
            name=name,
            value=value,
        )


def fit_harmonic(
    t: np.ndarray, x: np.ndarray, frequency: float, window: tuple[float, float]
) -> HarmonicFit:
    """Least-squares fit of ``a + b cos(w t) + c sin(w t)``, ``w = 2 pi frequency``.

    Only samples with ``window[0] <= t <= window[1]`` are used (with a relative slack of 1e-9 on
    both ends, so that samples on the boundaries count). Each sample is weighted by its
    trapezoidal-rule weight (half an interval at each end), so that over whole periods the fit
    minimises the time-integral of the squared residual and other harmonics leave it exactly
    unbiased. Time is not shifted: the phase is relative to ``sin(w t)`` with the given ``t``.

    Arguments:
        t: sample times, in s, shape (n,).
        x: samples, shape (n,).
        frequency: the frequency of the harmonic, in Hz.
        window: ``(t_start, t_end)``, in s.

    Returns:
        The fit.

    Raises:
        InvalidInputError: if the shapes differ, a value is not finite, the frequency is not
            positive, fewer than 4 samples fall in the window, or their times are not
            increasing.
    """
    t = np.asarray(t, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    if t.ndim != 1 or t.shape != x.shape:
        raise InvalidInputError(
            f"t and x must be one-dimensional arrays of equal length, got shapes {t.shape} and "
            f"{x.shape}",
            name="x",
            value=x.shape,
        )
    _check_positive("frequency", frequency, "Hz")
    start, end = float(window[0]), float(window[1])
    if not (math.isfinite(start) and math.isfinite(end) and end > start):
        raise InvalidInputError(
            f"window must be (t_start, t_end) with t_end > t_start, got {window!r}",
            name="window",
            value=window,
        )
    slack = _EDGE * max(1.0, abs(start), abs(end))
    inside = (t >= start - slack) & (t <= end + slack)
    count = int(inside.sum())
    if count < 4:
        raise InvalidInputError(
            f"only {count} samples fall in the window [{start:g}, {end:g}] s (samples span "
            f"[{t.min() if t.size else float('nan'):g}, {t.max() if t.size else float('nan'):g}] "
            f"s); at least 4 are needed: sample more finely or widen the window",
            name="window",
            value=window,
        )
    ts, xs = t[inside], x[inside]
    if not (np.all(np.isfinite(ts)) and np.all(np.isfinite(xs))):
        raise InvalidInputError(
            "the samples in the window contain NaN or infinity; check the time history",
            name="x",
            value=window,
        )
    if np.any(np.diff(ts) <= 0.0):
        raise InvalidInputError(
            "the sample times in the window are not strictly increasing; sort the samples",
            name="t",
            value=window,
        )
    # Trapezoidal-rule weights: the weighted sums are then the trapezoidal rule of the integrals,
    # exact over whole periods for every harmonic below the Nyquist frequency, so other harmonics
    # and the end samples (one period apart, same phase) do not bias the fit.
    weights = np.empty_like(ts)
    weights[0], weights[-1] = 0.5 * (ts[1] - ts[0]), 0.5 * (ts[-1] - ts[-2])
    weights[1:-1] = 0.5 * (ts[2:] - ts[:-2])
    root = np.sqrt(weights)
    omega = 2.0 * math.pi * frequency
    basis = np.column_stack([np.ones_like(ts), np.cos(omega * ts), np.sin(omega * ts)])
    (a, b, c), *_ = np.linalg.lstsq(basis * root[:, None], xs * root, rcond=None)
    residual = xs - basis @ np.array([a, b, c])
    return HarmonicFit(
        mean=float(a),
        amplitude=float(math.hypot(b, c)),
        phase_deg=float(180.0 - (180.0 - math.degrees(math.atan2(b, c))) % 360.0),
        residual_rms=float(np.sqrt(np.sum(weights * residual**2) / np.sum(weights))),
        window=(start, end),
        samples=count,
    )


def steady_window(t_end: float, frequency: float, fit_periods: int) -> tuple[float, float]:
    """The last ``fit_periods`` whole periods ending at ``t_end``.

    Arguments:
        t_end: end of the time history, in s.
        frequency: in Hz.
        fit_periods: number of whole periods (>= 1).

    Returns:
        ``(t_end - fit_periods / frequency, t_end)``.

    Raises:
        InvalidInputError: if ``frequency`` is not positive, ``fit_periods`` is not a whole number
            >= 1, or the window would start before ``t = 0``.
    """
    _check_positive("frequency", frequency, "Hz")
    if isinstance(fit_periods, bool) or int(fit_periods) != fit_periods or fit_periods < 1:
        raise InvalidInputError(
            f"fit_periods must be a whole number >= 1, got {fit_periods!r}",
            name="fit_periods",
            value=fit_periods,
        )
    start = t_end - int(fit_periods) / frequency
    if start < -_EDGE * max(1.0, abs(t_end)):
        raise InvalidInputError(
            f"{fit_periods} periods at {frequency:g} Hz last {fit_periods / frequency:g} s, "
            f"longer than the time history (t_end = {t_end:g} s); simulate longer or fit fewer "
            f"periods",
            name="fit_periods",
            value=fit_periods,
        )
    return (max(start, 0.0), float(t_end))


@dataclass(frozen=True)
class SteadyResponse:
    """Steady-state harmonic response of the buoy to the tank's motion at one frequency.

    Phases follow :data:`PHASE_CONVENTION`: buoy phase minus tank phase, in (-90, 270].

    Attributes:
        frequency: in Hz.
        window: the fit window ``(t_start, t_end)``, in s.
        tank_amplitude: fitted amplitude of the tank's displacement, in m.
        absolute_amplitude: amplitude of the buoy's displacement in the laboratory, in m.
        absolute_ratio: ``absolute_amplitude / tank_amplitude``.
        absolute_phase_deg: phase of the buoy's absolute displacement relative to the tank's.
        relative_amplitude: amplitude of the buoy's displacement relative to the tank, in m.
        relative_ratio: ``relative_amplitude / tank_amplitude``.
        relative_phase_deg: phase of the relative displacement relative to the tank's.
        settling: relative change of the relative amplitude between the window before this one and
            this one, ``|A_last - A_before| / A_last``: a small value means the transient has died
            out (NaN when the history is too short for the earlier window).
        residual_rms: rms residual of the fit of the relative displacement, in m (non-harmonic
            content: transient, higher harmonics).
        phase_change_deg: change of the relative phase between the window before this one and
            this one, ``|phi_last - phi_before|`` in degrees (NaN when there is no earlier window).
        converged: whether ``settling`` and ``phase_change_deg`` meet the tolerances of the
            steady-state check (:class:`vinculo.buoy.case.SweepSettings`); None when unchecked.
        periods: periods of the excitation simulated by the run (NaN when not recorded).
    """

    frequency: float
    window: tuple[float, float]
    tank_amplitude: float
    absolute_amplitude: float
    absolute_ratio: float
    absolute_phase_deg: float
    relative_amplitude: float
    relative_ratio: float
    relative_phase_deg: float
    settling: float
    residual_rms: float
    phase_change_deg: float = math.nan
    converged: bool | None = None
    periods: float = math.nan


def steady_response(
    t: np.ndarray,
    x_buoy: np.ndarray,
    x_tank: np.ndarray,
    frequency: float,
    fit_periods: int,
) -> SteadyResponse:
    """Amplitude and phase of the buoy's absolute and relative motion over the last periods.

    Arguments:
        t: sample times, in s (the window ends at ``t[-1]``).
        x_buoy: horizontal displacement of the buoy's centre in the laboratory, in m.
        x_tank: horizontal displacement of the tank, in m.
        frequency: excitation frequency, in Hz.
        fit_periods: whole periods in the fit window.

    Returns:
        The response; ``settling`` and ``phase_change_deg`` report how far the transient has died
        out (they do not fail; ``converged`` is left None).

    Raises:
        InvalidInputError: if the arrays do not match, the window does not fit in the history, or
            the tank does not move (zero fitted amplitude).
    """
    t = np.asarray(t, dtype=np.float64)
    x_buoy = np.asarray(x_buoy, dtype=np.float64)
    x_tank = np.asarray(x_tank, dtype=np.float64)
    if x_tank.shape != t.shape:
        raise InvalidInputError(
            f"x_tank must have the shape of t {t.shape}, got {x_tank.shape}",
            name="x_tank",
            value=x_tank.shape,
        )
    if x_buoy.shape != t.shape:
        raise InvalidInputError(
            f"x_buoy must have the shape of t {t.shape}, got {x_buoy.shape}",
            name="x_buoy",
            value=x_buoy.shape,
        )
    t_end = float(t[-1])
    window = steady_window(t_end, frequency, fit_periods)
    if t[0] > window[0] + _EDGE * max(1.0, abs(window[0])):
        raise InvalidInputError(
            f"the history starts at t = {t[0]:g} s, after the fit window's start "
            f"{window[0]:g} s; simulate longer or fit fewer periods",
            name="t",
            value=float(t[0]),
        )
    tank = fit_harmonic(t, x_tank, frequency, window)
    if not tank.amplitude > 0.0:
        raise InvalidInputError(
            f"the tank does not move in the window {window} (fitted amplitude "
            f"{tank.amplitude!r} m), so no ratio or phase can be formed",
            name="x_tank",
            value=tank.amplitude,
        )
    x_rel = x_buoy - x_tank
    absolute = fit_harmonic(t, x_buoy, frequency, window)
    relative = fit_harmonic(t, x_rel, frequency, window)
    earlier = (window[0] - (window[1] - window[0]), window[0])
    if earlier[0] >= t[0] - _EDGE * max(1.0, abs(earlier[0])):
        before = fit_harmonic(t, x_rel, frequency, earlier)
        settling = abs(relative.amplitude - before.amplitude) / relative.amplitude
        turn = (relative.phase_deg - before.phase_deg + 180.0) % 360.0 - 180.0
        phase_change = abs(turn)
    else:
        settling = phase_change = math.nan
    return SteadyResponse(
        frequency=float(frequency),
        window=window,
        tank_amplitude=tank.amplitude,
        absolute_amplitude=absolute.amplitude,
        absolute_ratio=absolute.amplitude / tank.amplitude,
        absolute_phase_deg=wrap_phase(absolute.phase_deg - tank.phase_deg),
        relative_amplitude=relative.amplitude,
        relative_ratio=relative.amplitude / tank.amplitude,
        relative_phase_deg=wrap_phase(relative.phase_deg - tank.phase_deg),
        settling=float(settling),
        residual_rms=relative.residual_rms,
        phase_change_deg=float(phase_change),
    )
