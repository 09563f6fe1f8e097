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

__all__ = ["Law", "constant", "driven", "piecewise_linear", "polynomial", "sine", "tabulated"]


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


def piecewise_linear(
    times: Sequence[float] | np.ndarray, values: Sequence[float] | np.ndarray
) -> Law:
    """Linear interpolation between knots, at rest before the first and after the last.

    At a knot the rate is that of the segment ending there (left-continuous), so a driven law
    (:func:`driven`) set knot by knot evaluates as this table of the same knots.

    Arguments:
        times: strictly increasing knot times (at least one).
        values: the value at each knot.

    Returns:
        The law.

    Raises:
        InvalidInputError: if the lengths differ, there is no knot, the times are not strictly
            increasing, or a number is not finite.
    """
    return Law.piecewise_linear(_floats("times", times), _floats("values", values))


def driven(x0: float, t0: float = 0.0) -> Law:
    """A law set while a :class:`vinculo.Simulation` is stepped (a coupling loop's input).

    It starts as the value ``x0`` at ``t0`` (and before); ``law.set(t, x)`` adds the value at a
    later time, and the law moves linearly to it (a :func:`piecewise_linear` law growing knot by
    knot). Use it where a law is accepted; set the value at a time before stepping to it.

    Arguments:
        x0: the value at ``t0``.
        t0: the time of the first value, in s.

    Returns:
        The law (its ``set(t, x)`` sets the next value).

    Raises:
        InvalidInputError: if a number is not finite.
    """
    return Law.driven(float(x0), float(t0))
