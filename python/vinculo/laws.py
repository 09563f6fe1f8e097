"""Prescribed functions of time ("laws") for moving points, planes and coordinates.

A :class:`Law` is evaluated by the compiled core with its first and second derivatives, which the
integrator needs for the constraints' time derivatives. Anywhere the model takes a scalar that may
move (a point's coordinate, a plane's normal or point, a fixed coordinate's value, a force
component), a ``Law`` may stand in for a plain float.

Laws compose: ``+``, ``-``, ``*``, ``/`` and ``**`` (a number exponent) between laws and numbers,
and :func:`sqrt`, :func:`sin`, :func:`cos`, :func:`exp`, :func:`log` of a law, give laws whose
derivatives are exact (chain and product rules, no differencing). :func:`function` makes a law of
a Python function that returns its own derivatives.

Example:
    >>> from vinculo import laws
    >>> x = laws.sine(amplitude=0.005, frequency=0.9, ramp_time=3.0)
    >>> value, rate, acceleration = x.derivatives(1.0)
    >>> guide = laws.sqrt(2.0**2 - laws.sine(amplitude=0.7, frequency=0.4) ** 2)
    >>> round(guide(0.0), 12)
    2.0
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from vinculo._core import Law

__all__ = [
    "Law",
    "constant",
    "cos",
    "driven",
    "exp",
    "function",
    "log",
    "piecewise_linear",
    "polynomial",
    "sin",
    "sine",
    "sqrt",
    "tabulated",
    "time",
]


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


def tabulated(
    times: Sequence[float] | np.ndarray,
    values: Sequence[float] | np.ndarray,
    ends: str = "natural",
    slopes: tuple[float, float] | None = None,
) -> Law:
    """A cubic spline through samples (twice continuously differentiable).

    The law is defined on ``[times[0], times[-1]]`` only (see ``Law.domain``). The end condition
    closes the spline at the first and last samples:

    - ``"natural"``: zero second derivative at both ends. It reproduces linear data exactly, but
      where the data curve at an end its slope is only first-order accurate there (a slope error
      that does not vanish as fast as the samples get closer).
    - ``"clamped"``: the slopes at both ends are ``slopes=(first, last)``, when they are known
      (a motion that starts and ends at rest: ``(0, 0)``).
    - ``"not-a-knot"``: the first two and the last two pieces are one cubic each (no condition
      on the data beyond the samples; with 3 samples, the parabola through them).

    Clamped and not-a-knot splines reproduce cubic data exactly and are fourth-order accurate up to
    the ends.

    Arguments:
        times: strictly increasing sample times.
        values: the samples, one per time.
        ends: ``"natural"``, ``"clamped"`` or ``"not-a-knot"``.
        slopes: the end slopes (first, last) of a clamped spline, in value per second.

    Returns:
        The law.

    Raises:
        InvalidInputError: if the lengths differ, there are fewer than two samples, the times are
            not strictly increasing, a number is not finite, ``ends`` is unknown, or ``slopes`` is
            missing for a clamped spline (or given for another).
    """
    pair = None if slopes is None else (float(slopes[0]), float(slopes[1]))
    return Law.spline(_floats("times", times), _floats("values", values), ends, pair)


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


def time() -> Law:
    """The law ``t`` itself, to write laws as formulas of time: ``laws.sin(3 * laws.time())``.

    Returns:
        The law.
    """
    return Law.polynomial([0.0, 1.0])


def _apply(name: str, law: Law | float) -> Law:
    """``name(law)`` for one of the elementary functions of the core."""
    return Law.apply(name, law)


def sqrt(law: Law | float) -> Law:
    """The square root of a law, with exact derivatives.

    Where the argument is negative (or zero, where the rate is infinite) the law has no finite
    value; a run that reaches such a time stops with an ``InvalidInputError`` naming the law, the
    element it drives and the time.

    Arguments:
        law: a law or a number.

    Returns:
        The law ``sqrt(law)``.
    """
    return _apply("sqrt", law)


def sin(law: Law | float) -> Law:
    """The sine of a law (radians), with exact derivatives.

    Arguments:
        law: a law or a number.

    Returns:
        The law ``sin(law)``.
    """
    return _apply("sin", law)


def cos(law: Law | float) -> Law:
    """The cosine of a law (radians), with exact derivatives.

    Arguments:
        law: a law or a number.

    Returns:
        The law ``cos(law)``.
    """
    return _apply("cos", law)


def exp(law: Law | float) -> Law:
    """The exponential of a law, with exact derivatives.

    Arguments:
        law: a law or a number.

    Returns:
        The law ``exp(law)``.
    """
    return _apply("exp", law)


def log(law: Law | float) -> Law:
    """The natural logarithm of a law (defined where the law is positive), with exact derivatives.

    Arguments:
        law: a law or a number.

    Returns:
        The law ``log(law)``.
    """
    return _apply("log", law)


def function(f: Callable[[float], tuple[float, float, float]], name: str | None = None) -> Law:
    """A law computed by a Python function of time that returns its value and two derivatives.

    The constraints need the rate and acceleration of a prescribed motion exactly (they enter the
    consistent start and every step), so ``f`` returns all three: ``f(t) -> (value, rate,
    acceleration)``. The function is called from the run's thread, with the Python interpreter
    held, at every evaluation: a law made of :func:`sine`, :func:`polynomial` and the operators is
    evaluated by the compiled core and is much faster.

    A function that raises, or returns something other than three finite numbers, stops the run
    with a ``UserFunctionError`` naming the law, the element it drives, the time and the
    exception's text; the states computed before are kept on the error's ``solution``.

    Arguments:
        f: the function of time ``t`` (s).
        name: the law's name in messages (``f.__name__`` by default).

    Returns:
        The law.

    Raises:
        InvalidInputError: if ``f`` is not callable.
    """
    return Law.function(f, name)
