"""Prescribed functions of time ("laws") for moving points, planes and coordinates.

A :class:`Law` is evaluated by the compiled core with its first and second derivatives, which the
integrator needs for the constraints' time derivatives. Anywhere the model takes a scalar that may
move (a point's coordinate, a plane's normal or point, a fixed coordinate's value, a force
component), a ``Law`` may stand in for a plain float.

Example:
    >>> from vinculo import laws
    >>> x = laws.sine(amplitude=0.005, frequency=0.9, ramp_time=3.0)
    >>> value, rate, acceleration = x.derivatives(1.0)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vinculo._core import Law

__all__ = ["Law", "constant", "polynomial", "sine", "tabulated"]


def _floats(name: str, values: Sequence[float] | np.ndarray) -> list[float]:
    """Convert a one-dimensional sequence of numbers to a list of Python floats."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1:
        from vinculo.errors import InvalidInputError

        raise InvalidInputError(
            f"{name} must be a one-dimensional sequence of numbers, got shape {array.shape}",
            name=name,
            value=values,
        )
    return [float(v) for v in array]


def constant(value: float) -> Law:
    """A law that keeps the same value at all times.

    Arguments:
        value: the value (its derivatives are zero).

    Returns:
        The law.

    Raises:
        InvalidInputError: if ``value`` is not finite.
    """
    return Law.constant(float(value))


def polynomial(coefficients: Sequence[float] | np.ndarray) -> Law:
    """The polynomial ``c0 + c1 t + c2 t^2 + ...``.

    Arguments:
        coefficients: ``c0, c1, ...`` in increasing powers of t (at least one).

    Returns:
        The law.

    Raises:
        InvalidInputError: if there is no coefficient or one is not finite.
    """
    return Law.polynomial(_floats("coefficients", coefficients))


def sine(
    amplitude: float,
    frequency: float,
    phase: float = 0.0,
    offset: float = 0.0,
    ramp_time: float = 0.0,
    t_start: float = 0.0,
) -> Law:
    """A harmonic law with an optional smooth start.

    The value is ``offset + amplitude * s(t) * sin(2 pi frequency (t - t_start) + phase)``, where
    the ramp ``s`` rises from 0 at ``t_start`` to 1 at ``t_start + ramp_time`` as the C2 quintic
    ``10 u^3 - 15 u^4 + 6 u^5`` with ``u = (t - t_start) / ramp_time`` (``s = 1`` when
    ``ramp_time = 0``, the abrupt start).

    Arguments:
        amplitude: peak value of the oscillation.
        frequency: in Hz (cycles per second, not rad/s).
        phase: in radians.
        offset: value around which the law oscillates.
        ramp_time: duration of the smooth start, in s (0 for none).
        t_start: time at which the oscillation (and its ramp) starts.

    Returns:
        The law.

    Raises:
        InvalidInputError: if an argument is not finite or ``ramp_time`` is negative.
    """
    return Law.sine(
        float(amplitude),
        float(frequency),
        phase=float(phase),
        offset=float(offset),
        ramp_time=float(ramp_time),
        t_start=float(t_start),
    )


def tabulated(times: Sequence[float] | np.ndarray, values: Sequence[float] | np.ndarray) -> Law:
    """A natural cubic spline through samples (twice continuously differentiable).

    The law is defined on ``[times[0], times[-1]]`` only (see ``Law.domain``). A natural spline
    reproduces linear data exactly; smooth data are reproduced to O(h^4) away from the ends, where
    the natural end conditions (zero second derivative) apply.

    Arguments:
        times: strictly increasing sample times.
        values: the samples, one per time.

    Returns:
        The law.

    Raises:
        InvalidInputError: if the lengths differ, there are fewer than two samples, the times are
            not strictly increasing, or a number is not finite.
    """
    return Law.tabulated(_floats("times", times), _floats("values", values))
